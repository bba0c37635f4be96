//! Plain 3D geometry shared by validation, planners and verification.
//!
//! Metres, ENU (z up), ground at z = 0. This module is a leaf: it knows nothing
//! of missions or pipelines.

use nalgebra::{Point2, Point3, Vector3};

/// A vertical cylinder: axis through `center`, from z = `base` (0 for what
/// stands on the ground, higher for a deck) up to z = `height`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    pub center: Point2<f64>,
    pub radius: f64,
    pub base: f64,
    pub height: f64,
}

impl Cylinder {
    /// Horizontal distance from `p` to the axis.
    pub fn horizontal_distance(&self, p: &Point3<f64>) -> f64 {
        (p.xy() - self.center).norm()
    }

    /// Distance from `p` to the cylinder's axis, extended over the top and
    /// under the base: between them it is the horizontal distance to the
    /// axis; above (below), the radius plus the distance to the top (bottom)
    /// disc. Continuous at the top, and equal to
    /// the radius exactly on the surface, so `1 - d / r_safe` measures how deep
    /// a point is inside a safety margin around the whole solid (θ-PSO eq. 4).
    pub fn axis_distance(&self, p: &Point3<f64>) -> f64 {
        self.radius + self.clearance(p)
    }

    /// Signed distance from `p` to the solid cylinder: positive outside,
    /// negative inside (as deep as the nearest side wall).
    pub fn clearance(&self, p: &Point3<f64>) -> f64 {
        let outward = self.horizontal_distance(p) - self.radius;
        let off = if p.z > self.height {
            p.z - self.height
        } else if p.z < self.base {
            self.base - p.z
        } else {
            return outward;
        };
        let sideways = outward.max(0.0);
        (sideways * sideways + off * off).sqrt()
    }
}

/// Distance from `p` to the segment a-b, in the plane.
pub fn segment_point_distance(a: &Point2<f64>, b: &Point2<f64>, p: &Point2<f64>) -> f64 {
    segment_projection(a, b, p).1
}

/// Distance from `p` to the segment a-b in three dimensions.
pub fn segment_point_distance_3d(a: &Point3<f64>, b: &Point3<f64>, p: &Point3<f64>) -> f64 {
    let ab = b - a;
    (a + ab * clamped_fraction(&ab, &(p - a)) - p).norm()
}

/// The fraction t ∈ [0, 1] along a segment `ab` (a vector, in any
/// dimension) of the point nearest to a point `ap` from its start; 0 for a
/// segment of no length.
fn clamped_fraction<const D: usize>(
    ab: &nalgebra::SVector<f64, D>,
    ap: &nalgebra::SVector<f64, D>,
) -> f64 {
    let len2 = ab.norm_squared();
    if len2 > 0.0 {
        (ap.dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Where `p` projects onto the segment a-b: the fraction t ∈ [0, 1] along
/// it, and the distance from `p` to that point.
pub fn segment_projection(a: &Point2<f64>, b: &Point2<f64>, p: &Point2<f64>) -> (f64, f64) {
    let ab = b - a;
    let t = clamped_fraction(&ab, &(p - a));
    (t, (a + ab * t - p).norm())
}

/// Distance of the farthest offset from the origin: a formation's radius r_F
/// when the offsets are its slots (θ-PSO eq. 6).
pub fn farthest_offset(offsets: &[Vector3<f64>]) -> f64 {
    offsets.iter().map(|o| o.norm()).fold(0.0, f64::max)
}

/// Length of the polyline through `points`.
pub fn polyline_length(points: &[Point3<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    const POLE: Cylinder = Cylinder {
        center: Point2::new(0.0, 0.0),
        radius: 1.0,
        base: 0.0,
        height: 10.0,
    };

    #[test]
    fn clearance_beside_the_wall_is_horizontal() {
        assert_eq!(POLE.clearance(&Point3::new(3.0, 0.0, 5.0)), 2.0);
        assert_eq!(POLE.clearance(&Point3::new(0.5, 0.0, 5.0)), -0.5);
    }

    #[test]
    fn clearance_above_the_top_is_to_the_top_disc() {
        assert_eq!(POLE.clearance(&Point3::new(0.0, 0.0, 13.0)), 3.0);
        let corner = POLE.clearance(&Point3::new(4.0, 0.0, 14.0));
        assert!((corner - 5.0).abs() < 1e-12, "3-4-5 triangle, got {corner}");
    }

    #[test]
    fn axis_distance_is_continuous_over_the_top() {
        let below = POLE.axis_distance(&Point3::new(2.5, 0.0, 10.0));
        let above = POLE.axis_distance(&Point3::new(2.5, 0.0, 10.0 + 1e-9));
        assert!((below - above).abs() < 1e-6);
        assert_eq!(below, 2.5);
    }

    #[test]
    fn segment_point_distance_clamps_to_the_ends() {
        let (a, b) = (Point2::new(0.0, 0.0), Point2::new(4.0, 0.0));
        assert_eq!(segment_point_distance(&a, &b, &Point2::new(2.0, 3.0)), 3.0);
        assert_eq!(segment_point_distance(&a, &b, &Point2::new(7.0, 4.0)), 5.0);
        assert_eq!(segment_point_distance(&a, &a, &Point2::new(3.0, 4.0)), 5.0);
    }

    #[test]
    fn polyline_length_adds_segments() {
        let pts = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(3.0, 4.0, 0.0),
            Point3::new(3.0, 4.0, 2.0),
        ];
        assert_eq!(polyline_length(&pts), 7.0);
    }
}
