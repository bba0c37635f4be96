//! Plain 3D geometry shared by validation, planners and verification.
//!
//! Metres, ENU (z up), ground at z = 0. This module is a leaf: it knows nothing
//! of missions or pipelines.

use std::sync::Arc;

use nalgebra::{Point2, Point3, Vector3};

/// A vertical prism: a footprint in the plane, from z = `base` (0 for what
/// stands on the ground, higher for a deck) up to z = `height`. The
/// footprint is the circle (`center`, `radius`), a cylinder, unless
/// `polygon` holds vertices; then the circle is the polygon's bounding
/// circle, which the broad phases read (nothing of the polygon is outside
/// it).
#[derive(Debug, Clone, PartialEq)]
pub struct Prism {
    pub center: Point2<f64>,
    pub radius: f64,
    /// A simple polygon's vertices, either winding, not closed (the last
    /// joins the first); empty for a cylinder.
    pub polygon: Arc<[Point2<f64>]>,
    pub base: f64,
    pub height: f64,
}

impl Prism {
    /// A cylinder from `base` to `height`.
    pub fn cylinder(center: Point2<f64>, radius: f64, base: f64, height: f64) -> Self {
        Prism {
            center,
            radius,
            polygon: Arc::from([]),
            base,
            height,
        }
    }

    /// Horizontal distance from `p` to the axis (the bounding circle's
    /// centre for a polygon).
    pub fn horizontal_distance(&self, p: &Point3<f64>) -> f64 {
        (p.xy() - self.center).norm()
    }

    /// Signed distance in the plane from `q` to the footprint's outline:
    /// positive outside, negative inside.
    pub fn outward(&self, q: &Point2<f64>) -> f64 {
        if self.polygon.is_empty() {
            (q - self.center).norm() - self.radius
        } else {
            polygon_signed_distance(&self.polygon, q)
        }
    }

    /// Distance in the plane from the segment `a` → `b` to the footprint:
    /// 0 where it crosses the outline, negative (as deep as its deeper
    /// end) when an end is inside. Between two polylines the least distance
    /// is at a vertex of one of them, so this is exact.
    pub fn segment_distance(&self, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
        let ends = self.outward(a).min(self.outward(b));
        if ends <= 0.0 || self.polygon.is_empty() {
            return if self.polygon.is_empty() {
                segment_point_distance(a, b, &self.center) - self.radius
            } else {
                ends
            };
        }
        let n = self.polygon.len();
        let mut best = ends;
        for i in 0..n {
            let (p, q) = (self.polygon[i], self.polygon[(i + 1) % n]);
            if segments_cross(a, b, &p, &q) {
                return 0.0;
            }
            best = best.min(segment_point_distance(a, b, &p));
        }
        best
    }

    /// The point of the footprint's outline nearest `q`.
    pub fn nearest_on_outline(&self, q: &Point2<f64>) -> Point2<f64> {
        if self.polygon.is_empty() {
            let away = q - self.center;
            let n = away.norm();
            if n > 0.0 {
                self.center + away * (self.radius / n)
            } else {
                self.center + nalgebra::Vector2::new(self.radius, 0.0)
            }
        } else {
            polygon_nearest(&self.polygon, q)
        }
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
        let outward = self.outward(&p.xy());
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

/// The closest points of two footprints' outlines, `a`'s then `b`'s (for
/// two apart). Between polygons the distance is attained at a vertex of
/// one of them; a circle's point is towards the other's nearest point.
pub fn nearest_points(a: &Prism, b: &Prism) -> (Point2<f64>, Point2<f64>) {
    match (a.polygon.is_empty(), b.polygon.is_empty()) {
        (true, true) => (
            a.nearest_on_outline(&b.center),
            b.nearest_on_outline(&a.center),
        ),
        (true, false) => {
            let on_b = b.nearest_on_outline(&a.center);
            (a.nearest_on_outline(&on_b), on_b)
        }
        (false, true) => {
            let (on_b, on_a) = nearest_points(b, a);
            (on_a, on_b)
        }
        (false, false) => {
            let from = |x: &Prism, y: &Prism| {
                x.polygon
                    .iter()
                    .map(|v| (*v, y.nearest_on_outline(v)))
                    .min_by(|p, q| (p.0 - p.1).norm().total_cmp(&(q.0 - q.1).norm()))
            };
            let ab = from(a, b);
            let ba = from(b, a).map(|(on_b, on_a)| (on_a, on_b));
            match (ab, ba) {
                (Some(p), Some(q)) if (q.0 - q.1).norm() < (p.0 - p.1).norm() => q,
                (Some(p), _) => p,
                _ => (a.center, b.center),
            }
        }
    }
}

/// Signed distance from `q` to the simple polygon `vertices`: the distance
/// to its nearest edge, negative inside (even-odd rule).
pub fn polygon_signed_distance(vertices: &[Point2<f64>], q: &Point2<f64>) -> f64 {
    let mut nearest = f64::INFINITY;
    let mut inside = false;
    let n = vertices.len();
    for i in 0..n {
        let (a, b) = (&vertices[i], &vertices[(i + 1) % n]);
        nearest = nearest.min(segment_point_distance(a, b, q));
        if (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    if inside { -nearest } else { nearest }
}

/// The point of the polygon's boundary nearest `q`.
pub fn polygon_nearest(vertices: &[Point2<f64>], q: &Point2<f64>) -> Point2<f64> {
    let n = vertices.len();
    let mut best = (f64::INFINITY, *q);
    for i in 0..n {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        let ab = b - a;
        let p = a + ab * clamped_fraction(&ab, &(q - a));
        let d = (p - q).norm();
        if d < best.0 {
            best = (d, p);
        }
    }
    best.1
}

/// The circle round `vertices` that the broad phases read: centred on the
/// middle of their bounding box, through the farthest vertex.
pub fn bounding_circle(vertices: &[Point2<f64>]) -> (Point2<f64>, f64) {
    let (mut lo, mut hi) = (
        Point2::new(f64::INFINITY, f64::INFINITY),
        Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for v in vertices {
        lo = Point2::new(lo.x.min(v.x), lo.y.min(v.y));
        hi = Point2::new(hi.x.max(v.x), hi.y.max(v.y));
    }
    let center = nalgebra::center(&lo, &hi);
    let radius = vertices
        .iter()
        .map(|v| (v - center).norm())
        .fold(0.0, f64::max);
    (center, radius)
}

/// Whether the plane segments a-b and c-d intersect (touching counts).
pub fn segments_cross(a: &Point2<f64>, b: &Point2<f64>, c: &Point2<f64>, d: &Point2<f64>) -> bool {
    let orient = |p: &Point2<f64>, q: &Point2<f64>, r: &Point2<f64>| (q - p).perp(&(r - p));
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    d1 * d2 <= 0.0 && d3 * d4 <= 0.0 && !(d1 == 0.0 && d2 == 0.0 && d3 == 0.0 && d4 == 0.0)
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

    fn pole() -> Prism {
        Prism::cylinder(Point2::new(0.0, 0.0), 1.0, 0.0, 10.0)
    }

    /// An L-shaped building, 10 × 10 with the 5 × 5 north-east quarter cut
    /// out, 6 m high.
    fn ell() -> Prism {
        let polygon: Vec<_> = [
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 5.0],
            [5.0, 5.0],
            [5.0, 10.0],
            [0.0, 10.0],
        ]
        .iter()
        .map(|&[x, y]| Point2::new(x, y))
        .collect();
        let (center, radius) = bounding_circle(&polygon);
        Prism {
            center,
            radius,
            polygon: polygon.into(),
            base: 0.0,
            height: 6.0,
        }
    }

    #[test]
    fn clearance_to_a_footprint_is_to_its_nearest_edge_and_negative_inside() {
        let l = ell();
        // In the cut-out corner: 1 m from the inner edge x = 5 (the
        // bounding circle holds it, the footprint does not).
        let notch = l.clearance(&Point3::new(6.0, 8.0, 3.0));
        assert!((notch - 1.0).abs() < 1e-12, "{notch}");
        let corner = l.clearance(&Point3::new(7.0, 7.0, 3.0));
        assert!((corner - 2.0).abs() < 1e-12, "{corner}");
        // Beside the south face, and inside the west wing.
        assert_eq!(l.clearance(&Point3::new(3.0, -2.0, 3.0)), 2.0);
        assert_eq!(l.clearance(&Point3::new(2.0, 8.0, 3.0)), -2.0);
        // Over the roof: straight up to it, and diagonally past its edge.
        assert_eq!(l.clearance(&Point3::new(2.0, 2.0, 9.0)), 3.0);
        let past = l.clearance(&Point3::new(13.0, 2.0, 10.0));
        assert!(
            (past - 5.0).abs() < 1e-12,
            "3-4-5 over the east edge, got {past}"
        );
        // The bounding circle holds every vertex; the notch is outside the
        // footprint although inside that circle.
        assert!((l.radius - 50f64.sqrt()).abs() < 1e-12);
        assert_eq!(
            l.nearest_on_outline(&Point2::new(6.0, 8.0)),
            Point2::new(5.0, 8.0)
        );
    }

    #[test]
    fn a_deck_is_cleared_under_its_base() {
        let deck = Prism::cylinder(Point2::new(0.0, 0.0), 3.0, 8.0, 10.0);
        assert_eq!(deck.clearance(&Point3::new(0.0, 0.0, 5.0)), 3.0);
        assert_eq!(deck.clearance(&Point3::new(0.0, 0.0, 9.0)), -3.0);
        let corner = deck.clearance(&Point3::new(7.0, 0.0, 5.0));
        assert!((corner - 5.0).abs() < 1e-12, "{corner}");
    }

    #[test]
    fn clearance_beside_the_wall_is_horizontal() {
        assert_eq!(pole().clearance(&Point3::new(3.0, 0.0, 5.0)), 2.0);
        assert_eq!(pole().clearance(&Point3::new(0.5, 0.0, 5.0)), -0.5);
    }

    #[test]
    fn clearance_above_the_top_is_to_the_top_disc() {
        assert_eq!(pole().clearance(&Point3::new(0.0, 0.0, 13.0)), 3.0);
        let corner = pole().clearance(&Point3::new(4.0, 0.0, 14.0));
        assert!((corner - 5.0).abs() < 1e-12, "3-4-5 triangle, got {corner}");
    }

    #[test]
    fn axis_distance_is_continuous_over_the_top() {
        let below = pole().axis_distance(&Point3::new(2.5, 0.0, 10.0));
        let above = pole().axis_distance(&Point3::new(2.5, 0.0, 10.0 + 1e-9));
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
