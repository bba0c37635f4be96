//! A rectangle of the screen and the piece of the plane it shows: the one
//! conversion between cells and metres that drawing, terrain shading and
//! hit-testing share.
//!
//! Terminal cells are about twice as tall as wide, so a row spans twice the
//! metres of a column: circles stay round at any zoom.

use nalgebra::Point2;
use ratatui::layout::{Margin, Rect};

use crate::base::geometry::farthest_offset;
use crate::mission::Mission;
use crate::tui::app::App;

/// A rectangle of the screen and the piece of the plane it shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewport {
    /// The cells drawn into (inside the pane's border).
    pub inner: Rect,
    pub x: [f64; 2],
    pub y: [f64; 2],
}

impl Viewport {
    /// A view of `inner` centred on `center`, `metres_per_column` wide per cell.
    fn centred(inner: Rect, center: Point2<f64>, metres_per_column: f64) -> Self {
        let half_w = inner.width.max(1) as f64 * metres_per_column / 2.0;
        let half_h = inner.height.max(1) as f64 * 2.0 * metres_per_column / 2.0;
        Viewport {
            inner,
            x: [center.x - half_w, center.x + half_w],
            y: [center.y - half_h, center.y + half_h],
        }
    }

    /// The top-down map of `app` drawn in the pane `area` (border included).
    pub fn map(app: &App, area: Rect) -> Self {
        let inner = area.inner(Margin::new(1, 1));
        let (bx, by) = app.map_extent();
        let (w, h) = (
            (bx[1] - bx[0]).abs().max(1.0),
            (by[1] - by[0]).abs().max(1.0),
        );
        let fit =
            (w / inner.width.max(1) as f64).max(h / (2.0 * inner.height.max(1) as f64)) * 1.08;
        Viewport::centred(inner, app.map_center(), fit / app.camera().zoom())
    }

    /// The formation editor: canvas x is to the right of travel (−y of the
    /// formation frame), canvas y is forward (x).
    pub fn formation(app: &App, area: Rect) -> Self {
        let inner = area.inner(Margin::new(1, 1));
        let r = formation_extent(app.mission()) + app.mission().formation.uav_radius + 1.0;
        let fit = (2.0 * r / inner.width.max(1) as f64)
            .max(2.0 * r / (2.0 * inner.height.max(1) as f64))
            * 1.15;
        Viewport::centred(inner, Point2::origin(), fit / app.camera().formation_zoom())
    }

    pub fn metres_per_column(&self) -> f64 {
        (self.x[1] - self.x[0]) / self.inner.width.max(1) as f64
    }

    /// The cell a point falls in, or None outside the view.
    pub fn to_cell(&self, p: Point2<f64>) -> Option<(u16, u16)> {
        let r = self.inner;
        let fx = (p.x - self.x[0]) / (self.x[1] - self.x[0]) * r.width as f64;
        let fy = (self.y[1] - p.y) / (self.y[1] - self.y[0]) * r.height as f64;
        let inside = (0.0..r.width as f64).contains(&fx) && (0.0..r.height as f64).contains(&fy);
        inside.then(|| (r.x + fx as u16, r.y + fy as u16))
    }

    /// The point under a cell, or None outside the view.
    pub fn to_world(&self, column: u16, row: u16) -> Option<Point2<f64>> {
        let r = self.inner;
        if column < r.x || row < r.y || column >= r.x + r.width || row >= r.y + r.height {
            return None;
        }
        let fx = (column - r.x) as f64 + 0.5;
        let fy = (row - r.y) as f64 + 0.5;
        Some(Point2::new(
            self.x[0] + fx * (self.x[1] - self.x[0]) / r.width as f64,
            self.y[1] - fy * (self.y[1] - self.y[0]) / r.height as f64,
        ))
    }
}

/// The formation's radius (for drawing and hit-testing slots).
pub fn formation_extent(m: &Mission) -> f64 {
    farthest_offset(&m.formation.slots).max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_spans_twice_the_metres_of_a_column() {
        let vp = Viewport::centred(Rect::new(1, 1, 100, 40), Point2::new(0.0, 0.0), 0.5);
        assert!((vp.x[1] - vp.x[0] - 50.0).abs() < 1e-12);
        assert!((vp.y[1] - vp.y[0] - 40.0).abs() < 1e-12);
    }

    #[test]
    fn a_cell_maps_back_to_the_metres_under_it() {
        let vp = Viewport::centred(Rect::new(1, 1, 100, 40), Point2::new(10.0, 20.0), 0.5);
        // The cell right of the centre line, below it.
        let p = vp.to_world(51, 21).unwrap();
        assert!((p.x - 10.25).abs() < 1e-9, "{p}");
        assert!((p.y - 19.5).abs() < 1e-9, "{p}");
        assert_eq!(vp.to_world(0, 5), None, "the border is not the map");
    }
}
