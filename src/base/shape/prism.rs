//! A footprint stood up between two heights: the solid a UAV keeps clear of.

use nalgebra::{Point2, Point3};

use super::Footprint;

/// A vertical prism: a footprint in the plane, from z = `base` (0 for what
/// stands on the ground, higher for a deck) up to z = `height`. `center`
/// and `radius` are the footprint's bounding circle, which the broad phases
/// read (nothing of the footprint is outside it).
#[derive(Debug, Clone, PartialEq)]
pub struct Prism {
    pub center: Point2<f64>,
    pub radius: f64,
    pub outline: Footprint,
    pub base: f64,
    pub height: f64,
}

impl Prism {
    /// `outline` from `base` to `height`.
    pub fn new(outline: Footprint, base: f64, height: f64) -> Self {
        let (center, radius) = outline.bounding_circle();
        Prism {
            center,
            radius,
            outline,
            base,
            height,
        }
    }

    /// A cylinder from `base` to `height`.
    pub fn cylinder(center: Point2<f64>, radius: f64, base: f64, height: f64) -> Self {
        Prism::new(Footprint::circle(center, radius), base, height)
    }

    /// Horizontal distance from `p` to the axis (the bounding circle's
    /// centre for any other shape).
    pub fn horizontal_distance(&self, p: &Point3<f64>) -> f64 {
        (p.xy() - self.center).norm()
    }

    /// Signed distance in the plane from `q` to the footprint's outline:
    /// positive outside, negative inside.
    pub fn outward(&self, q: &Point2<f64>) -> f64 {
        self.outline.signed_distance(q)
    }

    /// Distance in the plane from the segment `a` → `b` to the footprint
    /// ([`Outline::segment_distance`]).
    pub fn segment_distance(&self, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
        self.outline.segment_distance(a, b)
    }

    /// The point of the footprint's outline nearest `q`.
    pub fn nearest_on_outline(&self, q: &Point2<f64>) -> Point2<f64> {
        self.outline.nearest(q)
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

    /// Signed distance from `p` to the solid: positive outside, negative
    /// inside (as deep as the nearest side wall).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::shape::Polygon;

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
        Prism::new(Footprint::new(Polygon::new(polygon)), 0.0, 6.0)
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
}
