//! The two encodings of a path for the SPSO benchmark, and each one's
//! published swarm settings (the benchmark's README).
//!
//! A particle decodes into the n free nodes x1..xn, y1..yn, z1..zn (z above
//! the ground), the order `Model::cost` takes.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

use crate::base::swarm::{SearchSpace, SequentialConfig};
use crate::mission::{Encoding, Mission};

/// (−1)^k / (2k + 1)!, k = 0..10: the Taylor coefficients of sine to θ²¹.
const SINE_TAYLOR: [f64; 11] = [
    1.0,
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
    -1.0 / 121_645_100_408_832_000.0,
    1.0 / 51_090_942_171_709_440_000.0,
];

/// sin θ for |θ| ≤ π/2, the angle encoding's box: the Taylor series to θ²¹
/// (its remainder there is below 2e-18) in Horner form. libm's `sin` is a
/// call per angle and was an eighth of a whole run; this inlines and
/// vectorises over a particle's angles, within a few ulp of `f64::sin`
/// (tested).
#[inline]
fn sin_within_quarter_turn(theta: f64) -> f64 {
    theta * horner(&SINE_TAYLOR, theta * theta)
}

/// Σ c_k t^k in Horner form, the last coefficient first.
#[inline(always)]
fn horner(coefficients: &[f64], t: f64) -> f64 {
    let (&last, rest) = coefficients.split_last().unwrap_or((&0.0, &[]));
    rest.iter().rev().fold(last, |p, &c| p * t + c)
}

/// |δ| up to which [`series_sin_cos`] is used: a little over π/4, the
/// spherical encoding's half-width in ψ and about φ0.
const SERIES_RANGE: f64 = 0.8;

/// sin and cos of δ for |δ| ≤ [`SERIES_RANGE`]: Taylor series to δ¹⁷ and
/// δ¹⁸ (remainders below 2e-19 there) in Horner form, within a few ulp of
/// libm (tested).
///
/// libm's `sin_cos` was a seventh of a whole spherical run (two calls per
/// node, each saving and restoring the rounding mode); this inlines, has no
/// branch, and vectorises over a particle's nodes.
#[inline(always)]
fn series_sin_cos(delta: f64) -> (f64, f64) {
    let d2 = delta * delta;
    // Sine: (−1)^k / (2k + 1)!, k = 0..8; cosine: (−1)^k / (2k)!, k = 0..9.
    (
        delta * horner(&SINE_TAYLOR[..9], d2),
        horner(&COSINE_TAYLOR, d2),
    )
}

/// (−1)^k / (2k)!, k = 0..9: the Taylor coefficients of cosine to δ¹⁸.
const COSINE_TAYLOR: [f64; 10] = [
    1.0,
    -1.0 / 2.0,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
    -1.0 / 6_402_373_705_728_000.0,
];

/// Decodes particles of one encoding for one scenario.
#[derive(Debug, Clone)]
pub struct Decoder {
    encoding: Encoding,
    nodes: usize,
    /// [x_min, x_max], [y_min, y_max], [z_min, z_max] (z above the ground).
    bounds: [[f64; 2]; 3],
    start: [f64; 3],
    goal: [f64; 3],
    /// φ0 = atan2(Δy, Δx), start to goal (the middle of the φ box), and its
    /// sine and cosine: once here rather than in every decoding.
    heading: [f64; 3],
}

impl Decoder {
    pub fn new(mission: &Mission, encoding: Encoding) -> Self {
        let b = &mission.bounds;
        let (s, g) = (mission.route.start, mission.route.goal);
        Self::from_parts(
            encoding,
            mission.theta_pso.waypoints,
            [b.x, b.y, b.z],
            [s.x, s.y, s.z],
            [g.x, g.y, g.z],
        )
    }

    /// A decoder of `nodes` free nodes in `bounds` between `start` and
    /// `goal` (z above the ground).
    pub fn from_parts(
        encoding: Encoding,
        nodes: usize,
        bounds: [[f64; 2]; 3],
        start: [f64; 3],
        goal: [f64; 3],
    ) -> Self {
        let phi0 = (goal[1] - start[1]).atan2(goal[0] - start[0]);
        let (sin_phi0, cos_phi0) = phi0.sin_cos();
        Decoder {
            encoding,
            nodes,
            bounds,
            start,
            goal,
            heading: [phi0, sin_phi0, cos_phi0],
        }
    }

    /// n, the free nodes a particle decodes into.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// [x_min, x_max], [y_min, y_max], [z_min, z_max] (z above the ground).
    pub fn bounds(&self) -> [[f64; 2]; 3] {
        self.bounds
    }

    /// The box and velocity limits.
    ///
    /// Angle: θ ∈ [−π/2, π/2] per coordinate, |Δθ| ≤ π/2. Spherical
    /// (`SPSO_MAIN.m`): r ∈ [0, 2 |goal − start| / n] (3-D norm),
    /// ψ ∈ [−π/4, π/4], φ ∈ [φ0 − π/4, φ0 + π/4] with
    /// φ0 = atan2(Δy, Δx); velocity limit half of each range.
    pub fn space(&self) -> SearchSpace {
        let n = self.nodes;
        match self.encoding {
            Encoding::Angle => SearchSpace::uniform(3 * n, -FRAC_PI_2, FRAC_PI_2, FRAC_PI_2),
            Encoding::Spherical => {
                let d: f64 = (0..3)
                    .map(|c| (self.goal[c] - self.start[c]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let r_max = 2.0 * d / n.max(1) as f64;
                let phi0 = self.heading[0];
                let ranges = [
                    [0.0, r_max],
                    [-FRAC_PI_4, FRAC_PI_4],
                    [phi0 - FRAC_PI_4, phi0 + FRAC_PI_4],
                ];
                let mut space = SearchSpace {
                    lower: Vec::with_capacity(3 * n),
                    upper: Vec::with_capacity(3 * n),
                    max_step: Vec::with_capacity(3 * n),
                };
                for [lo, hi] in ranges {
                    for _ in 0..n {
                        space.lower.push(lo);
                        space.upper.push(hi);
                        space.max_step.push(0.5 * (hi - lo));
                    }
                }
                space
            }
        }
    }

    /// The particle's free nodes into `out` (3 n numbers: x…, y…, z…).
    pub fn decode(&self, position: &[f64], out: &mut [f64]) {
        let n = self.nodes;
        let [bx, by, bz] = self.bounds;
        match self.encoding {
            Encoding::Angle => {
                // Eq. 1, x = ½ [(max − min) sin θ + max + min], with a sine
                // that inlines and vectorises (θ stays in the box).
                for (c, b) in [bx, by, bz].iter().enumerate() {
                    let (angles, xs) =
                        (&position[c * n..(c + 1) * n], &mut out[c * n..(c + 1) * n]);
                    for (x, &theta) in xs.iter_mut().zip(angles) {
                        *x = 0.5 * ((b[1] - b[0]) * sin_within_quarter_turn(theta) + b[1] + b[0]);
                    }
                }
            }
            Encoding::Spherical => {
                // SphericalToCart.m: each node from the clamped one before,
                // x with sin φ and y with cos φ, clamped max first, then min.
                let clamp = |v: f64, b: [f64; 2]| {
                    let v = if v > b[1] { b[1] } else { v };
                    if v < b[0] { b[0] } else { v }
                };
                // φ as φ0 + δ, |δ| ≤ π/4 in the box: sin and cos of δ by
                // series, then the angle sum with φ0's. The
                // steps first (independent, so they vectorise), then the
                // chain of sums and clamps in place.
                let [phi0, sin_phi0, cos_phi0] = self.heading;
                let (r, rest) = position.split_at(n);
                let (psi, phi) = rest.split_at(n);
                let (sx, rest) = out.split_at_mut(n);
                let (sy, sz) = rest.split_at_mut(n);
                let in_series = psi.iter().all(|a| a.abs() <= SERIES_RANGE)
                    && phi.iter().all(|a| (a - phi0).abs() <= SERIES_RANGE);
                let trig = |a: f64| {
                    if in_series {
                        series_sin_cos(a)
                    } else {
                        a.sin_cos()
                    }
                };
                for i in 0..n {
                    let (sin_psi, cos_psi) = trig(psi[i]);
                    let (sin_delta, cos_delta) = trig(phi[i] - phi0);
                    let sin_phi = sin_phi0 * cos_delta + cos_phi0 * sin_delta;
                    let cos_phi = cos_phi0 * cos_delta - sin_phi0 * sin_delta;
                    sx[i] = r[i] * cos_psi * sin_phi;
                    sy[i] = r[i] * cos_psi * cos_phi;
                    sz[i] = r[i] * sin_psi;
                }
                let (mut x, mut y, mut z) = (self.start[0], self.start[1], self.start[2]);
                for i in 0..n {
                    x = clamp(x + sx[i], bx);
                    y = clamp(y + sy[i], by);
                    z = clamp(z + sz[i], bz);
                    (sx[i], sy[i], sz[i]) = (x, y, z);
                }
            }
        }
    }

    /// A particle that decodes to `nodes` (x…, y…, z…), as near as the box
    /// allows: the inverse of eq. 1 per coordinate, or each node's step from
    /// the one before as (r, ψ, φ) with x on sin φ and y on cos φ.
    pub fn encode(&self, nodes: &[f64]) -> Vec<f64> {
        let n = self.nodes;
        let mut out = vec![0.0; 3 * n];
        match self.encoding {
            Encoding::Angle => {
                for (c, b) in self.bounds.iter().enumerate() {
                    for i in 0..n {
                        out[c * n + i] =
                            crate::base::swarm::encode_angle(nodes[c * n + i], b[0], b[1]);
                    }
                }
            }
            Encoding::Spherical => {
                let mut from = self.start;
                for i in 0..n {
                    let to = [nodes[i], nodes[n + i], nodes[2 * n + i]];
                    let [dx, dy, dz] = [to[0] - from[0], to[1] - from[1], to[2] - from[2]];
                    out[i] = (dx * dx + dy * dy + dz * dz).sqrt();
                    out[n + i] = dz.atan2(dx.hypot(dy));
                    out[2 * n + i] = dx.atan2(dy);
                    from = to;
                }
            }
        }
        out
    }

    /// The encoding's published settings (the benchmark's README) for a
    /// swarm of `particles` × `iterations`: inertia 1 damped by 0.98 per
    /// iteration, the global best updated after each particle; c1 = c2 = 2
    /// for the angles, 1.5 for the spherical vectors.
    pub fn published(&self, particles: usize, iterations: usize) -> SequentialConfig {
        let gain = match self.encoding {
            Encoding::Angle => 2.0,
            Encoding::Spherical => 1.5,
        };
        SequentialConfig {
            particles,
            iterations,
            inertia: 1.0,
            damping: 0.98,
            cognitive: gain,
            social: gain,
            streams: 0,
            init_passes: 100,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn encoding_then_decoding_gives_the_nodes_back() {
        let decoder = |encoding| {
            Decoder::from_parts(
                encoding,
                3,
                [[0.0, 100.0], [0.0, 100.0], [10.0, 20.0]],
                [5.0, 5.0, 15.0],
                [95.0, 95.0, 15.0],
            )
        };
        let nodes = [20.0, 40.0, 70.0, 10.0, 35.0, 60.0, 15.0, 17.0, 12.0];
        for encoding in [Encoding::Angle, Encoding::Spherical] {
            let d = decoder(encoding);
            let mut back = [0.0; 9];
            d.decode(&d.encode(&nodes), &mut back);
            for (a, b) in back.iter().zip(nodes) {
                assert!((a - b).abs() < 1e-9, "{encoding:?}: {back:?}");
            }
        }
    }

    #[test]
    fn the_series_sine_and_cosine_match_libm_on_an_eighth_turn() {
        let mut worst = 0.0f64;
        for k in 0..=200_000 {
            let delta = SERIES_RANGE * (2.0 * k as f64 / 200_000.0 - 1.0);
            let (s, c) = series_sin_cos(delta);
            let (ws, wc) = delta.sin_cos();
            worst = worst.max((s - ws).abs()).max((c - wc).abs());
        }
        assert!(worst <= 4.5e-16, "worst error {worst:e}");
        assert_eq!(series_sin_cos(0.0), (0.0, 1.0));
    }

    #[test]
    fn spherical_decoding_agrees_with_libm_trigonometry() {
        // SphericalToCart.m with libm's sin and cos, on random particles:
        // the nodes agree to a few ulp of the map's size.
        let d = Decoder::from_parts(
            Encoding::Spherical,
            10,
            [[1.0, 1045.0], [1.0, 879.0], [100.0, 200.0]],
            [200.0, 100.0, 150.0],
            [800.0, 800.0, 150.0],
        );
        let space = d.space();
        let mut out = [0.0; 30];
        for k in 0..2000u64 {
            let position: Vec<f64> = (0..30)
                .map(|i| {
                    let t = ((k * 7919 + i as u64 * 104_729) % 1001) as f64 / 1000.0;
                    // Every tenth particle reaches outside the box (libm's
                    // trigonometry there).
                    let t = if k % 10 == 0 { 3.0 * t - 1.0 } else { t };
                    space.lower[i] + t * (space.upper[i] - space.lower[i])
                })
                .collect();
            d.decode(&position, &mut out);
            let (mut x, mut y, mut z) = (200.0f64, 100.0f64, 150.0f64);
            for i in 0..10 {
                let (r, psi, phi) = (position[i], position[10 + i], position[20 + i]);
                x = (x + r * psi.cos() * phi.sin()).clamp(1.0, 1045.0);
                y = (y + r * psi.cos() * phi.cos()).clamp(1.0, 879.0);
                z = (z + r * psi.sin()).clamp(100.0, 200.0);
                for (got, want) in [(out[i], x), (out[10 + i], y), (out[20 + i], z)] {
                    assert!((got - want).abs() <= 1e-11, "{got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn the_series_sine_matches_libm_on_the_box() {
        let mut worst = 0.0f64;
        for k in 0..=200_000 {
            let theta = -FRAC_PI_2 + FRAC_PI_2 * 2.0 * k as f64 / 200_000.0;
            worst = worst.max((sin_within_quarter_turn(theta) - theta.sin()).abs());
        }
        assert!(worst <= 4.5e-16, "worst error {worst:e}");
        assert_eq!(sin_within_quarter_turn(0.0), 0.0);
        assert_eq!(sin_within_quarter_turn(FRAC_PI_2), 1.0);
    }
}
