//! Plain 3D geometry shared by validation, planners and verification.
//!
//! Metres, ENU (z up), ground at z = 0. This module is a leaf: it knows nothing
//! of missions or pipelines.

use nalgebra::{Point2, Point3, Vector2, Vector3};

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

/// `corners` in anticlockwise order (reversed when written clockwise): the
/// winding [`facing_edge`] and the passes along a face read.
pub fn anticlockwise(corners: &[Point2<f64>]) -> Vec<Point2<f64>> {
    let n = corners.len();
    let area: f64 = (0..n)
        .map(|i| corners[i].coords.perp(&corners[(i + 1) % n].coords))
        .sum();
    let mut ring = corners.to_vec();
    if area < 0.0 {
        ring.reverse();
    }
    ring
}

/// The edge of the anticlockwise `outline` whose outward normal is nearest
/// `normal` (the face an `inspect_side` names); the longer of two as near.
pub fn facing_edge(outline: &[Point2<f64>], normal: Vector2<f64>) -> usize {
    let n = outline.len();
    (0..n)
        .map(|i| {
            let d = outline[(i + 1) % n] - outline[i];
            let length = d.norm().max(1e-12);
            let outward = Vector2::new(d.y, -d.x) / length;
            (i, outward.dot(&normal), length)
        })
        .max_by(|a, b| {
            (a.1, a.2)
                .partial_cmp(&(b.1, b.2))
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .map_or(0, |(i, _, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

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
