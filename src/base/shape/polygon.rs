//! A straight-sided footprint: a building, a transformer bay, a deck, a
//! wire's box.

use std::sync::Arc;

use nalgebra::{Point2, Vector2};

use super::Outline;
use crate::base::geometry::{
    bounding_circle, polygon_nearest, polygon_signed_distance, segment_point_distance,
    segments_cross,
};

/// A simple polygon: its vertices, either winding, not closed (the last
/// joins the first), with its bounding circle.
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    vertices: Arc<[Point2<f64>]>,
    center: Point2<f64>,
    radius: f64,
}

impl Polygon {
    /// The polygon through `vertices`, its bounding circle found.
    pub fn new(vertices: Vec<Point2<f64>>) -> Self {
        let (center, radius) = bounding_circle(&vertices);
        Polygon {
            vertices: vertices.into(),
            center,
            radius,
        }
    }

    /// The polygon through `vertices` with a bounding circle already found
    /// (a mission's obstacle keeps it settled; `center` and `radius` must
    /// hold every vertex).
    pub fn bounded(vertices: &[Point2<f64>], center: Point2<f64>, radius: f64) -> Self {
        Polygon {
            vertices: vertices.into(),
            center,
            radius,
        }
    }
}

impl Outline for Polygon {
    fn kind(&self) -> &'static str {
        "footprint"
    }

    fn bounding_circle(&self) -> (Point2<f64>, f64) {
        (self.center, self.radius)
    }

    fn signed_distance(&self, q: &Point2<f64>) -> f64 {
        polygon_signed_distance(&self.vertices, q)
    }

    fn nearest(&self, q: &Point2<f64>) -> Point2<f64> {
        polygon_nearest(&self.vertices, q)
    }

    /// Between two polylines the least distance is at a vertex of one of
    /// them, so this is exact.
    fn segment_distance(&self, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
        let ends = self.signed_distance(a).min(self.signed_distance(b));
        if ends <= 0.0 {
            return ends;
        }
        let v = &self.vertices;
        let n = v.len();
        let mut best = ends;
        for i in 0..n {
            let (p, q) = (v[i], v[(i + 1) % n]);
            if segments_cross(a, b, &p, &q) {
                return 0.0;
            }
            best = best.min(segment_point_distance(a, b, &p));
        }
        best
    }

    /// The nearest edge's outward normal (either winding).
    fn normal(&self, q: &Point2<f64>) -> Vector2<f64> {
        let on = self.nearest(q);
        let v = &self.vertices;
        let n = v.len();
        let edge = (0..n)
            .min_by(|&a, &b| {
                let d = |i: usize| segment_point_distance(&v[i], &v[(i + 1) % n], &on);
                d(a).total_cmp(&d(b))
            })
            .unwrap_or(0);
        let d = v[(edge + 1) % n] - v[edge];
        let out = Vector2::new(d.y, -d.x);
        if self.signed_distance(&(on + out.normalize() * 1e-3))
            > self.signed_distance(&(on - out.normalize() * 1e-3))
        {
            out
        } else {
            -out
        }
    }

    fn nearest_to_line(&self, on: &Point2<f64>, n: &Vector2<f64>) -> (Point2<f64>, f64) {
        self.vertices
            .iter()
            .map(|p| (*p, (on - p).dot(n)))
            .min_by(|s, t| s.1.total_cmp(&t.1))
            .unwrap_or((self.center, f64::INFINITY))
    }

    fn ring(&self, _tolerance: f64) -> Vec<Point2<f64>> {
        self.vertices.to_vec()
    }

    fn words(&self) -> String {
        format!("footprint of {} vertices", self.vertices.len())
    }

    fn corners(&self) -> &[Point2<f64>] {
        &self.vertices
    }
}
