//! An obstacle's shape: a footprint in the plane ([`Outline`], one type
//! per shape: [`Circle`], [`Polygon`]) stood up between two heights as a
//! [`Prism`]. Every planner, check, drawing and export asks its questions
//! through [`Outline`] (how far, which point is nearest, what bounds it,
//! where it faces, how it is drawn), so a new shape is one module here and
//! one line where the mission reads it (`mission::Obstacle::outline`).
//!
//! The pair queries ([`nearest_points`], [`gap_between`]) are exact for
//! discs and for straight-sided outlines, and found by alternating
//! projections for any other (exact in the limit for convex shapes).
//!
//! This module is a leaf: it knows nothing of missions or pipelines.

mod circle;
mod polygon;
mod prism;

use std::fmt;
use std::sync::Arc;

use nalgebra::{Point2, Vector2};

pub use self::circle::Circle;
pub use self::polygon::Polygon;
pub use self::prism::Prism;

/// A shape's footprint in the plane (metres ENU): what a vertical prism is
/// the extrusion of. Distances are signed: positive outside, negative
/// inside.
pub trait Outline: fmt::Debug + Send + Sync {
    /// What it is, in a word: "cylinder", "footprint".
    fn kind(&self) -> &'static str;

    /// The circle round it that the broad phases read (nothing of the
    /// outline is outside it).
    fn bounding_circle(&self) -> (Point2<f64>, f64);

    /// Signed distance from `q` to the outline.
    fn signed_distance(&self, q: &Point2<f64>) -> f64;

    /// The point of the outline nearest `q`.
    fn nearest(&self, q: &Point2<f64>) -> Point2<f64>;

    /// Distance from the segment `a` → `b` to the outline: 0 where it
    /// crosses it, negative (as deep as its deeper end) when an end is
    /// inside.
    fn segment_distance(&self, a: &Point2<f64>, b: &Point2<f64>) -> f64;

    /// The outward normal (not of unit length) at the outline's point
    /// nearest `q`: the face a UAV at `q` looks at.
    fn normal(&self, q: &Point2<f64>) -> Vector2<f64>;

    /// Of the outline, the point farthest out along the unit vector `n`,
    /// and how far behind the line through `on` with normal `n` it lies
    /// (negative past it): the support point, as a line sees it.
    fn nearest_to_line(&self, on: &Point2<f64>, n: &Vector2<f64>) -> (Point2<f64>, f64);

    /// Points along the outline, in order, no farther from it between two
    /// of them than `tolerance`: how it is drawn and exported. A polygon's
    /// are its own vertices.
    fn ring(&self, tolerance: f64) -> Vec<Point2<f64>>;

    /// Its size in words, for a description: "radius 2 m", "footprint of
    /// 6 vertices".
    fn words(&self) -> String;

    /// A disc's centre and radius (its queries then reduce to the centre's);
    /// `None` for any other shape.
    fn disc(&self) -> Option<(Point2<f64>, f64)> {
        None
    }

    /// The vertices of a straight-sided outline, as written (either
    /// winding); empty for a curved one.
    fn corners(&self) -> &[Point2<f64>] {
        &[]
    }
}

/// A shared shape, cheap to clone: what a prism, the route's field and the
/// fleet's detections hold.
#[derive(Debug, Clone)]
pub struct Footprint(Arc<dyn Outline>);

impl Footprint {
    pub fn new(outline: impl Outline + 'static) -> Self {
        Footprint(Arc::new(outline))
    }

    /// A disc.
    pub fn circle(center: Point2<f64>, radius: f64) -> Self {
        Footprint::new(Circle { center, radius })
    }

    /// Its bounding circle's centre.
    pub fn center(&self) -> Point2<f64> {
        self.0.bounding_circle().0
    }

    /// Its bounding circle's radius.
    pub fn radius(&self) -> f64 {
        self.0.bounding_circle().1
    }
}

impl std::ops::Deref for Footprint {
    type Target = dyn Outline;
    fn deref(&self) -> &Self::Target {
        &*self.0
    }
}

/// Two footprints are the same when they are the same kind with the same
/// bounding circle and the same outline drawn at a centimetre.
impl PartialEq for Footprint {
    fn eq(&self, other: &Self) -> bool {
        self.kind() == other.kind()
            && self.bounding_circle() == other.bounding_circle()
            && self.ring(0.01) == other.ring(0.01)
    }
}

/// The closest points of two outlines, `a`'s then `b`'s (for two apart).
/// A disc's is towards the other's point nearest its centre; between
/// straight-sided outlines the distance is attained at a vertex of one of
/// them; other shapes alternate projections from their centres.
pub fn nearest_points(a: &dyn Outline, b: &dyn Outline) -> (Point2<f64>, Point2<f64>) {
    match (a.disc(), b.disc()) {
        (Some((ca, _)), Some((cb, _))) => (a.nearest(&cb), b.nearest(&ca)),
        (Some((ca, _)), None) => {
            let on_b = b.nearest(&ca);
            (a.nearest(&on_b), on_b)
        }
        (None, Some(_)) => {
            let (on_b, on_a) = nearest_points(b, a);
            (on_a, on_b)
        }
        (None, None) if !a.corners().is_empty() && !b.corners().is_empty() => {
            let from = |x: &dyn Outline, y: &dyn Outline| {
                x.corners()
                    .iter()
                    .map(|v| (*v, y.nearest(v)))
                    .min_by(|p, q| (p.0 - p.1).norm().total_cmp(&(q.0 - q.1).norm()))
            };
            let ab = from(a, b);
            let ba = from(b, a).map(|(on_b, on_a)| (on_a, on_b));
            match (ab, ba) {
                (Some(p), Some(q)) if (q.0 - q.1).norm() < (p.0 - p.1).norm() => q,
                (Some(p), _) => p,
                _ => (a.bounding_circle().0, b.bounding_circle().0),
            }
        }
        (None, None) => alternating(a, b),
    }
}

/// The distance between two outlines' edges, negative where they overlap
/// (as deep as a disc's reach into the other, or a vertex's): what a
/// passage between them leaves.
pub fn gap_between(a: &dyn Outline, b: &dyn Outline) -> f64 {
    match (a.disc(), b.disc()) {
        (Some((c, r)), _) => b.signed_distance(&c) - r,
        (None, Some((c, r))) => a.signed_distance(&c) - r,
        (None, None) if !a.corners().is_empty() && !b.corners().is_empty() => {
            let of = |from: &dyn Outline, to: &dyn Outline| {
                from.corners()
                    .iter()
                    .map(|v| to.signed_distance(v))
                    .fold(f64::INFINITY, f64::min)
            };
            of(a, b).min(of(b, a))
        }
        (None, None) => {
            let (p, q) = alternating(a, b);
            let apart = a.signed_distance(&q) > 0.0 && b.signed_distance(&p) > 0.0;
            let d = (q - p).norm();
            if apart { d } else { -d }
        }
    }
}

/// Closest points by alternating projections from the bounding centres:
/// each step projects onto one outline the other's last point.
fn alternating(a: &dyn Outline, b: &dyn Outline) -> (Point2<f64>, Point2<f64>) {
    let mut on_a = a.nearest(&b.bounding_circle().0);
    let mut on_b = b.nearest(&on_a);
    for _ in 0..64 {
        let next_a = a.nearest(&on_b);
        let next_b = b.nearest(&next_a);
        let moved = (next_a - on_a).norm() + (next_b - on_b).norm();
        (on_a, on_b) = (next_a, next_b);
        if moved < 1e-9 {
            break;
        }
    }
    (on_a, on_b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ellipse, the shape no planner was written for: its queries by
    /// a fine polygon, enough to check the pair queries' fallback.
    #[derive(Debug)]
    struct Ring(Polygon);

    impl Outline for Ring {
        fn kind(&self) -> &'static str {
            "ring"
        }
        fn bounding_circle(&self) -> (Point2<f64>, f64) {
            self.0.bounding_circle()
        }
        fn signed_distance(&self, q: &Point2<f64>) -> f64 {
            self.0.signed_distance(q)
        }
        fn nearest(&self, q: &Point2<f64>) -> Point2<f64> {
            self.0.nearest(q)
        }
        fn segment_distance(&self, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
            self.0.segment_distance(a, b)
        }
        fn normal(&self, q: &Point2<f64>) -> Vector2<f64> {
            self.0.normal(q)
        }
        fn nearest_to_line(&self, on: &Point2<f64>, n: &Vector2<f64>) -> (Point2<f64>, f64) {
            self.0.nearest_to_line(on, n)
        }
        fn ring(&self, tolerance: f64) -> Vec<Point2<f64>> {
            self.0.ring(tolerance)
        }
        fn words(&self) -> String {
            "a test ring".into()
        }
    }

    fn square(at: [f64; 2], half: f64) -> Polygon {
        let [x, y] = at;
        Polygon::new(
            [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
                .iter()
                .map(|[u, v]| Point2::new(x + u * half, y + v * half))
                .collect(),
        )
    }

    #[test]
    fn the_pair_queries_agree_whichever_way_the_shapes_are_known() {
        // Two squares 3 m apart, known by their corners and (hidden) only
        // through their distances: the same gap and the same points.
        let (a, b) = (square([0.0, 0.0], 1.0), square([5.0, 0.5], 1.0));
        let exact = gap_between(&a, &b);
        assert!((exact - 3.0).abs() < 1e-12, "{exact}");
        let (ra, rb) = (Ring(square([0.0, 0.0], 1.0)), Ring(square([5.0, 0.5], 1.0)));
        let found = gap_between(&ra, &rb);
        assert!((found - exact).abs() < 1e-9, "{found} vs {exact}");
        let (p, q) = nearest_points(&ra, &rb);
        assert!(((q - p).norm() - 3.0).abs() < 1e-9);
        assert!((p.x - 1.0).abs() < 1e-9 && (q.x - 4.0).abs() < 1e-9);
        // Overlapping: negative.
        let over = gap_between(
            &Ring(square([0.0, 0.0], 1.0)),
            &Ring(square([1.5, 0.0], 1.0)),
        );
        assert!(over < 0.0, "{over}");
    }

    #[test]
    fn a_disc_meets_a_polygon_at_the_polygon_point_nearest_its_centre() {
        let disc = Circle {
            center: Point2::new(0.0, 0.0),
            radius: 1.0,
        };
        let wall = square([4.0, 0.0], 1.0);
        assert_eq!(gap_between(&disc, &wall), 2.0);
        assert_eq!(gap_between(&wall, &disc), 2.0);
        let (p, q) = nearest_points(&disc, &wall);
        assert_eq!((p, q), (Point2::new(1.0, 0.0), Point2::new(3.0, 0.0)));
        let (q2, p2) = nearest_points(&wall, &disc);
        assert_eq!((p2, q2), (p, q));
    }
}
