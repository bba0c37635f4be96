//! A disc: a pole, a pier, a tree, a tank.

use nalgebra::{Point2, Vector2};

use super::Outline;
use crate::base::geometry::segment_point_distance;

/// A disc of `radius` about `center`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    pub center: Point2<f64>,
    pub radius: f64,
}

impl Outline for Circle {
    fn kind(&self) -> &'static str {
        "cylinder"
    }

    fn bounding_circle(&self) -> (Point2<f64>, f64) {
        (self.center, self.radius)
    }

    fn signed_distance(&self, q: &Point2<f64>) -> f64 {
        (q - self.center).norm() - self.radius
    }

    fn nearest(&self, q: &Point2<f64>) -> Point2<f64> {
        let away = q - self.center;
        let n = away.norm();
        if n > 0.0 {
            self.center + away * (self.radius / n)
        } else {
            self.center + Vector2::new(self.radius, 0.0)
        }
    }

    fn segment_distance(&self, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
        segment_point_distance(a, b, &self.center) - self.radius
    }

    fn normal(&self, q: &Point2<f64>) -> Vector2<f64> {
        self.nearest(q) - self.center
    }

    fn nearest_to_line(&self, on: &Point2<f64>, n: &Vector2<f64>) -> (Point2<f64>, f64) {
        (
            self.center + n * self.radius,
            (on - self.center).dot(n) - self.radius,
        )
    }

    /// Anticlockwise from east, as many points as keep every chord within
    /// `tolerance` of the circle (at least 8).
    fn ring(&self, tolerance: f64) -> Vec<Point2<f64>> {
        let n = chords(self.radius, tolerance);
        (0..n)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / n as f64;
                Point2::new(
                    self.center.x + self.radius * a.cos(),
                    self.center.y + self.radius * a.sin(),
                )
            })
            .collect()
    }

    fn words(&self) -> String {
        format!("radius {} m", self.radius)
    }

    fn disc(&self) -> Option<(Point2<f64>, f64)> {
        Some((self.center, self.radius))
    }
}

/// How many equal chords keep within `tolerance` of a circle of `radius`:
/// a chord of half-angle θ strays r (1 − cos θ) from its arc.
pub(super) fn chords(radius: f64, tolerance: f64) -> usize {
    if !(radius > tolerance && tolerance > 0.0) {
        return 8;
    }
    let half = (1.0 - tolerance / radius).acos();
    ((std::f64::consts::PI / half).ceil() as usize).clamp(8, 720)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_keeps_within_its_tolerance_of_the_circle() {
        let c = Circle {
            center: Point2::new(3.0, -2.0),
            radius: 10.0,
        };
        for tolerance in [0.5, 0.05, 0.01] {
            let ring = c.ring(tolerance);
            for (i, p) in ring.iter().enumerate() {
                assert!(c.signed_distance(p).abs() < 1e-9);
                let q = ring[(i + 1) % ring.len()];
                let middle = nalgebra::center(p, &q);
                let stray = -c.signed_distance(&middle);
                assert!(stray <= tolerance + 1e-12, "{stray} > {tolerance}");
            }
        }
        assert_eq!(c.ring(0.5).len(), chords(10.0, 0.5));
        assert!(c.ring(0.01).len() > c.ring(0.5).len());
    }
}
