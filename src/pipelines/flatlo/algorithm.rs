//! Algorithms 1 (FLATLO) and 2 (move_forward) of the FLATLO paper: the
//! manoeuvres that take aircraft i of a latitudinal line of N to its place in
//! the longitudinal line.
//!
//! Numbering (Figs. 2-3, lines 32-40): mirrored pairs from the middle out.
//! For even N, aircraft 2j and 2j+1 fly Δ = Δ_d/2 + jΔ_d left and right of the
//! centre line; for odd N, aircraft 0 flies on it and 2j-1, 2j fly jΔ_d left
//! and right. The pair's first member is on the LEFT (the figures that fix the
//! side are lost; the mirror image gives the same distances).

use std::f64::consts::{FRAC_PI_4, PI, SQRT_2};

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::maneuver::{Primitive, angles, direction};

/// Where an aircraft starts relative to the squadron's centre line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    Left,
    Right,
    /// The middle aircraft of an odd squadron: already on the line.
    Centre,
}

/// get_side(i, N) of Algorithm 1, line 5.
pub fn side(i: usize, n: usize) -> Side {
    if n.is_multiple_of(2) {
        if i.is_multiple_of(2) {
            Side::Left
        } else {
            Side::Right
        }
    } else if i == 0 {
        Side::Centre
    } else if i % 2 == 1 {
        Side::Left
    } else {
        Side::Right
    }
}

/// Algorithm 2: Δ_m, how far aircraft i goes forward before it turns.
pub fn move_forward(i: usize, n: usize, spacing: f64) -> f64 {
    let staggered = |k: usize| k as f64 * spacing + 2.0 * (k as f64 - 1.0) * spacing;
    let paired = || 3.0 * spacing * ((n - i - 1) / 2) as f64;
    let odd_i = i % 2 == 1;
    if n % 2 == 1 {
        if odd_i {
            staggered((n - i) / 2)
        } else {
            paired()
        }
    } else if odd_i {
        paired()
    } else {
        staggered((n - i) / 2)
    }
}

/// Δ of Algorithm 1, lines 32-40: aircraft i's distance from the centre line.
pub fn lateral_distance(i: usize, n: usize, spacing: f64) -> f64 {
    if n.is_multiple_of(2) {
        spacing / 2.0 + (i / 2) as f64 * spacing
    } else if i != 0 {
        // Δ_d ⌊(i + 1)/2⌋
        spacing * i.div_ceil(2) as f64
    } else {
        0.0
    }
}

/// Signed lateral offset from the centre line at the start, metres, positive to the left.
pub fn lateral_offset(i: usize, n: usize, spacing: f64) -> f64 {
    let d = lateral_distance(i, n, spacing);
    match side(i, n) {
        Side::Left => d,
        Side::Right => -d,
        Side::Centre => 0.0,
    }
}

/// What Algorithm 1 produces for one aircraft.
#[derive(Debug, Clone, PartialEq)]
pub struct Manoeuvres {
    /// FW(Δ_m), C, FW(Δ₂), C: the transition (empty FW(0) left out).
    pub transition: Vec<Primitive>,
    /// FW(K₂): the flight on the longitudinal line (line 51).
    pub final_leg: Primitive,
}

/// The squadron-wide inputs of Algorithm 1 (angles in radians, lengths in metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Squadron {
    /// N.
    pub n: usize,
    /// Δ_d.
    pub spacing: f64,
    /// r, the radius of the turns.
    pub radius: f64,
    /// φ, the heading before and after.
    pub heading: f64,
    /// β, the climb angle.
    pub climb: f64,
    /// K₂, the final leg on the longitudinal line.
    pub final_leg: f64,
}

impl Squadron {
    pub fn from_params(p: &crate::mission::FlatloParams) -> Self {
        Squadron {
            n: p.aircraft,
            spacing: p.spacing,
            radius: p.turn_radius,
            heading: p.heading_deg.to_radians(),
            climb: p.climb_deg.to_radians(),
            final_leg: p.final_leg,
        }
    }
}

/// Algorithm 1, FLATLO(i, Δ_d, vel, r, φ, β, P), for aircraft i of the
/// squadron starting at `p`.
///
/// Readings (docs/flatlo.md): φ₂, β₂ (lines 15-24) are the exact direction at
/// the end of the previous manoeuvre (the printed chord of the last two samples
/// tends to it as T → 0). Line 47 sets φ₃ = −φ₂ for the right wing's second
/// turn: that is the mirrored frame's heading; in the common frame the turn
/// starts from the aircraft's own heading φ₂, otherwise the reference would
/// kink by 2φ₂; and it turns back onto t(φ, β) in the plane of the first turn
/// (the same as the printed turn when level, exact when climbing). The middle aircraft of an odd squadron (Δ = 0, where line 41
/// would give a negative Δ₂) flies straight for the other aircraft's forward
/// extent of the three manoeuvres, 2r sin(π/4) − 2r(1 − cos(π/4)), which is
/// what keeps it Δ_d ahead of its followers.
pub fn flatlo(i: usize, q: &Squadron, p: Point3<f64>) -> Manoeuvres {
    let Squadron {
        n,
        spacing,
        radius: r,
        heading: phi,
        climb: beta,
        final_leg: k2,
    } = *q;
    let mut transition = Vec::with_capacity(4);
    let delta_m = move_forward(i, n, spacing);
    let side = side(i, n);
    if delta_m > 0.0 {
        transition.push(Primitive::forward(p, phi, beta, delta_m));
    }
    // Where the last manoeuvre ended and in which direction (lines 15-24).
    let here = |ms: &[Primitive]| match ms.last() {
        Some(m) => {
            let end = m.end();
            let (phi2, beta2) = angles(&end.tangent);
            (end.position, phi2, beta2)
        }
        None => (p, phi, beta),
    };
    let turn_lateral = 2.0 * r * (1.0 - FRAC_PI_4.cos());
    if side == Side::Centre {
        let (p1, phi2, beta2) = here(&transition);
        let extent = 2.0 * r * FRAC_PI_4.sin() - turn_lateral;
        transition.push(Primitive::forward(p1, phi2, beta2, extent));
    } else {
        let toward_centre = if side == Side::Left { PI } else { 0.0 };
        // k = 0: turn 45° toward the centre line.
        let (p1, phi2, beta2) = here(&transition);
        transition.push(Primitive::turn(
            p1,
            phi2,
            beta2,
            toward_centre,
            FRAC_PI_4,
            r,
        ));
        // k = 1: the diagonal (line 41).
        let delta = lateral_distance(i, n, spacing);
        let delta2 = SQRT_2 * (delta - turn_lateral);
        let (p1, phi2, beta2) = here(&transition);
        transition.push(Primitive::forward(p1, phi2, beta2, delta2));
        // k = 2: turn back onto the original direction t(φ, β), in the plane
        // of the first turn. Level (β = 0) this is C(P₁, φ₂, β₂, θ, π/4) with
        // θ = 0 (left wing) or π (right wing); climbing, C's horizontal normal
        // would leave the aircraft off t(φ, β) (−0.22° and 4.98° for β = 10°).
        let (p1, _, _) = here(&transition);
        let dir = transition
            .last()
            .map_or(direction(phi, beta), |m| m.end().tangent);
        transition.push(Primitive::turn_onto(p1, dir, direction(phi, beta), r));
    }
    // k = 3: along the longitudinal line.
    let (p1, phi2, beta2) = here(&transition);
    Manoeuvres {
        transition,
        final_leg: Primitive::forward(p1, phi2, beta2, k2),
    }
}

/// Start position of aircraft i: aircraft 0 at `start0`, the others on the
/// latitudinal line through it, across the heading φ.
pub fn start_position(
    i: usize,
    n: usize,
    spacing: f64,
    phi: f64,
    start0: Point3<f64>,
) -> Point3<f64> {
    let left = Vector3::new(-phi.sin(), phi.cos(), 0.0);
    let centre = start0 - left * lateral_offset(0, n, spacing);
    centre + left * lateral_offset(i, n, spacing)
}

/// The squadron's common direction of travel before and after: t(φ, β).
pub fn line_direction(phi: f64, beta: f64) -> Vector3<f64> {
    direction(phi, beta)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Algorithm 2 by hand for N = 2..9, in units of Δ_d. Odd i (even N) and
    /// even i (odd N): 3·⌊(N−i−1)/2⌋; the others: k + 2(k−1), k = ⌊(N−i)/2⌋.
    #[test]
    fn move_forward_matches_hand_computed_values() {
        let table: &[(usize, &[f64])] = &[
            (2, &[1.0, 0.0]),
            (3, &[3.0, 1.0, 0.0]),
            (4, &[4.0, 3.0, 1.0, 0.0]),
            (5, &[6.0, 4.0, 3.0, 1.0, 0.0]),
            (6, &[7.0, 6.0, 4.0, 3.0, 1.0, 0.0]),
            (7, &[9.0, 7.0, 6.0, 4.0, 3.0, 1.0, 0.0]),
            (8, &[10.0, 9.0, 7.0, 6.0, 4.0, 3.0, 1.0, 0.0]),
            (9, &[12.0, 10.0, 9.0, 7.0, 6.0, 4.0, 3.0, 1.0, 0.0]),
        ];
        for (n, expected) in table {
            let got: Vec<f64> = (0..*n).map(|i| move_forward(i, *n, 1.0)).collect();
            assert_eq!(&got, expected, "N = {n}");
            // Scaled by Δ_d.
            assert_eq!(move_forward(0, *n, 18_300.0), expected[0] * 18_300.0);
        }
    }

    #[test]
    fn the_start_line_is_evenly_spaced_and_mirrored() {
        for n in 2..=9 {
            let mut offsets: Vec<f64> = (0..n).map(|i| lateral_offset(i, n, 10.0)).collect();
            offsets.sort_by(f64::total_cmp);
            for w in offsets.windows(2) {
                assert!((w[1] - w[0] - 10.0).abs() < 1e-12, "N = {n}: {offsets:?}");
            }
            let sum: f64 = offsets.iter().sum();
            assert!(sum.abs() < 1e-9, "centred: N = {n}");
        }
        assert_eq!(side(0, 3), Side::Centre);
        assert_eq!((side(1, 3), side(2, 3)), (Side::Left, Side::Right));
        assert_eq!((side(0, 4), side(1, 4)), (Side::Left, Side::Right));
    }

    #[test]
    fn every_aircraft_ends_its_transition_on_the_centre_line_heading_phi() {
        let (spacing, r) = (18_300.0, 4_575.0);
        for n in 2..=9 {
            for i in 0..n {
                let start = start_position(i, n, spacing, 0.0, Point3::origin());
                let q = Squadron {
                    n,
                    spacing,
                    radius: r,
                    heading: 0.0,
                    climb: 0.0,
                    final_leg: 1000.0,
                };
                let m = flatlo(i, &q, start);
                let end = m.transition.last().unwrap().end();
                let centre_y = start_position(0, n, spacing, 0.0, Point3::origin()).y
                    - lateral_offset(0, n, spacing);
                assert!(
                    (end.position.y - centre_y).abs() < 1e-6,
                    "N={n} i={i}: y {}",
                    end.position.y
                );
                assert!((end.tangent - Vector3::x()).norm() < 1e-12, "N={n} i={i}");
                // Continuous direction from one manoeuvre to the next.
                for w in m.transition.windows(2) {
                    assert!((w[0].end().tangent - w[1].at(0.0).tangent).norm() < 1e-12);
                    assert!((w[0].end().position - w[1].at(0.0).position).norm() < 1e-6);
                }
            }
        }
    }
}
