//! The two basic 3D manoeuvres of FLATLO (Section 2.1, Figs. 4-5): go
//! forward (FW) and turn (C), kept as exact geometry and sampled on demand.
//!
//! Readings (docs/flatlo.md): the direction of travel is
//! t(φ, β) = (cos β cos φ, cos β sin φ, sin β). C turns in the plane of t and
//! n, where n is the horizontal left normal n₀ = (−sin φ, cos φ, 0) rotated
//! about t by θ: θ = 0 turns left, θ = π turns right, θ = π/2 pulls up. A turn
//! of angle α at radius r follows p(σ) = P + r(1 − cos σ) n + r sin σ t for
//! σ ∈ [0, α] and leaves in the direction t cos α + n sin α.

use nalgebra::{Point3, Unit, UnitQuaternion, Vector3};
use serde::Serialize;

/// t(φ, β): unit direction of heading φ and climb β (radians).
pub fn direction(phi: f64, beta: f64) -> Vector3<f64> {
    Vector3::new(beta.cos() * phi.cos(), beta.cos() * phi.sin(), beta.sin())
}

/// Heading φ and climb β of a direction (the inverse of [`direction`]).
///
/// Algorithm 1 (lines 19-20) prints φ₂ = sin⁻¹(Δy/D); that loses the quadrant
/// for headings beyond ±90°, so the heading is taken with atan2 of the
/// horizontal components, which agrees with it wherever it is defined.
pub fn angles(dir: &Vector3<f64>) -> (f64, f64) {
    let d = dir.normalize();
    (d.y.atan2(d.x), d.z.clamp(-1.0, 1.0).asin())
}

/// One manoeuvre: a straight segment (FW) or a circular arc (C).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Primitive {
    /// FW(P, φ, β, vel, d, T): from `start` along the unit `dir` for `length` metres.
    Forward {
        start: Point3<f64>,
        dir: Vector3<f64>,
        length: f64,
    },
    /// C(P, φ, β, θ, α, vel, r, T): from `start`, initial unit direction `dir`,
    /// towards the unit normal `normal`, radius `radius`, turning `angle` radians.
    Turn {
        start: Point3<f64>,
        dir: Vector3<f64>,
        normal: Vector3<f64>,
        radius: f64,
        angle: f64,
    },
}

/// Position, unit tangent and curvature vector (d²p/ds²) at an arc length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    pub position: Point3<f64>,
    pub tangent: Vector3<f64>,
    pub curvature: Vector3<f64>,
}

impl Primitive {
    /// FW of the paper: go forward `d` metres from `p` with heading φ and climb β.
    pub fn forward(p: Point3<f64>, phi: f64, beta: f64, d: f64) -> Self {
        Primitive::Forward {
            start: p,
            dir: direction(phi, beta),
            length: d,
        }
    }

    /// C of the paper: from `p` with heading φ and climb β, turn by α on a
    /// circle of radius r, in the plane selected by θ.
    pub fn turn(p: Point3<f64>, phi: f64, beta: f64, theta: f64, alpha: f64, r: f64) -> Self {
        let t = direction(phi, beta);
        let n0 = Vector3::new(-phi.sin(), phi.cos(), 0.0);
        let rotation = UnitQuaternion::from_axis_angle(&Unit::new_normalize(t), theta);
        Primitive::Turn {
            start: p,
            dir: t,
            normal: rotation * n0,
            radius: r,
            angle: alpha,
        }
    }

    /// A turn from the unit direction `dir` onto the unit direction `onto`
    /// (at an angle in (0, π)) on a circle of radius `r`, in the plane the two
    /// directions span.
    pub fn turn_onto(p: Point3<f64>, dir: Vector3<f64>, onto: Vector3<f64>, r: f64) -> Self {
        let cos = dir.dot(&onto).clamp(-1.0, 1.0);
        Primitive::Turn {
            start: p,
            dir,
            normal: (onto - dir * cos).normalize(),
            radius: r,
            angle: cos.acos(),
        }
    }

    /// Arc length, metres.
    pub fn length(&self) -> f64 {
        match *self {
            Primitive::Forward { length, .. } => length,
            Primitive::Turn { radius, angle, .. } => radius * angle,
        }
    }

    /// The point `s` metres along (clamped to the primitive).
    pub fn at(&self, s: f64) -> PathPoint {
        let s = s.clamp(0.0, self.length());
        match *self {
            Primitive::Forward { start, dir, .. } => PathPoint {
                position: start + dir * s,
                tangent: dir,
                curvature: Vector3::zeros(),
            },
            Primitive::Turn {
                start,
                dir,
                normal,
                radius,
                ..
            } => {
                let sigma = s / radius;
                let (sin, cos) = sigma.sin_cos();
                PathPoint {
                    position: start + normal * (radius * (1.0 - cos)) + dir * (radius * sin),
                    tangent: dir * cos + normal * sin,
                    curvature: (normal * cos - dir * sin) / radius,
                }
            }
        }
    }

    pub fn end(&self) -> PathPoint {
        self.at(self.length())
    }
}

/// A reference path: primitives joined end to end.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Path {
    pub primitives: Vec<Primitive>,
    /// Arc length at the start of each primitive, and the total at the end.
    pub starts: Vec<f64>,
}

impl Path {
    pub fn new(primitives: Vec<Primitive>) -> Self {
        let mut starts = Vec::with_capacity(primitives.len() + 1);
        let mut s = 0.0;
        starts.push(0.0);
        for p in &primitives {
            s += p.length();
            starts.push(s);
        }
        Path { primitives, starts }
    }

    pub fn length(&self) -> f64 {
        self.starts.last().copied().unwrap_or(0.0)
    }

    /// The point at arc length `s` (past the end: continues straight along the
    /// last direction, as an aircraft would). `hint` is the primitive to try
    /// first; sampling in order makes a whole sweep O(m).
    pub fn at(&self, s: f64, hint: &mut usize) -> PathPoint {
        let n = self.primitives.len();
        if n == 0 {
            return PathPoint {
                position: Point3::origin(),
                tangent: Vector3::x(),
                curvature: Vector3::zeros(),
            };
        }
        let mut k = (*hint).min(n - 1);
        while k > 0 && s < self.starts[k] {
            k -= 1;
        }
        while k + 1 < n && s >= self.starts[k + 1] {
            k += 1;
        }
        *hint = k;
        let local = s - self.starts[k];
        let primitive = &self.primitives[k];
        if local > primitive.length() {
            let end = primitive.end();
            return PathPoint {
                position: end.position + end.tangent * (local - primitive.length()),
                tangent: end.tangent,
                curvature: Vector3::zeros(),
            };
        }
        primitive.at(local)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    fn close(a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
        (a - b).norm() < 1e-9
    }

    #[test]
    fn go_forward_covers_its_distance_in_its_direction() {
        let fw = Primitive::forward(Point3::new(1.0, 2.0, 3.0), FRAC_PI_2, 0.1, 100.0);
        assert_eq!(fw.length(), 100.0);
        let end = fw.end();
        assert!((end.position - Point3::new(1.0, 2.0, 3.0)).norm() - 100.0 < 1e-9);
        assert!(close(&end.tangent, &direction(FRAC_PI_2, 0.1)));
        assert!(
            end.tangent.x.abs() < 1e-12 && end.tangent.z > 0.0,
            "north and climbing"
        );
    }

    #[test]
    fn theta_zero_turns_left_and_pi_turns_right() {
        // Heading east, level: left is north (+y).
        let left = Primitive::turn(Point3::origin(), 0.0, 0.0, 0.0, FRAC_PI_2, 1000.0);
        let end = left.end();
        assert!(
            close(&end.position.coords, &Vector3::new(1000.0, 1000.0, 0.0)),
            "{}",
            end.position
        );
        assert!(close(&end.tangent, &Vector3::y()));
        let right = Primitive::turn(Point3::origin(), 0.0, 0.0, PI, FRAC_PI_2, 1000.0);
        let end = right.end();
        assert!(close(
            &end.position.coords,
            &Vector3::new(1000.0, -1000.0, 0.0)
        ));
        assert!(close(&end.tangent, &-Vector3::y()));
        // π/2 pulls up.
        let up = Primitive::turn(Point3::origin(), 0.0, 0.0, FRAC_PI_2, FRAC_PI_2, 10.0);
        assert!(close(&up.end().tangent, &Vector3::z()));
    }

    #[test]
    fn a_turn_keeps_its_radius_and_arc_length() {
        let r = 4575.0;
        let c = Primitive::turn(Point3::new(5.0, -3.0, 3050.0), 0.7, 0.0, PI, FRAC_PI_4, r);
        assert!((c.length() - r * FRAC_PI_4).abs() < 1e-9);
        let Primitive::Turn { start, normal, .. } = c else {
            unreachable!()
        };
        let centre = start + normal * r;
        for k in 0..=20 {
            let p = c.at(c.length() * k as f64 / 20.0);
            assert!(((p.position - centre).norm() - r).abs() < 1e-6);
            assert!((p.curvature.norm() - 1.0 / r).abs() < 1e-15);
            assert!(p.tangent.dot(&p.curvature).abs() < 1e-15);
        }
        // End direction: heading turned right by 45°.
        let (phi, beta) = angles(&c.end().tangent);
        assert!((phi - (0.7 - FRAC_PI_4)).abs() < 1e-12);
        assert!(beta.abs() < 1e-12);
        // The chord of a 45° arc.
        let chord = (c.end().position - start).norm();
        assert!((chord - 2.0 * r * (FRAC_PI_4 / 2.0).sin()).abs() < 1e-6);
    }

    #[test]
    fn a_path_is_continuous_and_walks_past_its_end_straight() {
        let a = Primitive::forward(Point3::origin(), 0.0, 0.0, 50.0);
        let b = Primitive::turn(a.end().position, 0.0, 0.0, 0.0, FRAC_PI_2, 20.0);
        let path = Path::new(vec![a, b]);
        assert!((path.length() - (50.0 + 20.0 * FRAC_PI_2)).abs() < 1e-12);
        let mut hint = 0;
        let before = path.at(50.0 - 1e-9, &mut hint);
        let after = path.at(50.0 + 1e-9, &mut hint);
        assert!((before.position - after.position).norm() < 1e-6);
        let beyond = path.at(path.length() + 10.0, &mut hint);
        assert!(close(
            &beyond.position.coords,
            &(path.at(path.length(), &mut hint).position.coords + Vector3::y() * 10.0)
        ));
    }
}
