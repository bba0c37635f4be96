//! How the map and the formation editor are looked at: zoom, the map's
//! panned centre and the nudge step. Its own state, changed only through
//! these methods; the extent the map fits at zoom 1 comes from the caller
//! (it grows with a shown FLATLO flight).

use nalgebra::Point2;

/// Nudge steps offered, metres.
pub const STEPS: [f64; 10] = [0.01, 0.1, 0.5, 1.0, 5.0, 10.0, 50.0, 100.0, 500.0, 1000.0];

/// An x-y box: [x min, x max], [y min, y max].
pub type Extent = ([f64; 2], [f64; 2]);

#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Map zoom (1 = the extent fits the view) and centre (None = the
    /// extent's middle).
    zoom: f64,
    center: Option<Point2<f64>>,
    formation_zoom: f64,
    /// Index into [`STEPS`].
    step: usize,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            zoom: 1.0,
            center: None,
            formation_zoom: 1.0,
            step: 3,
        }
    }
}

impl Camera {
    pub fn zoom(&self) -> f64 {
        self.zoom
    }

    pub fn formation_zoom(&self) -> f64 {
        self.formation_zoom
    }

    /// The panned centre, if the map was panned or zoomed about a point.
    pub fn panned_center(&self) -> Option<Point2<f64>> {
        self.center
    }

    /// Where the map looks within `extent`.
    pub fn map_center(&self, (x, y): Extent) -> Point2<f64> {
        self.center
            .unwrap_or(Point2::new((x[0] + x[1]) / 2.0, (y[0] + y[1]) / 2.0))
    }

    /// The nudge step, metres.
    pub fn step_size(&self) -> f64 {
        STEPS[self.step.min(STEPS.len() - 1)]
    }

    /// A larger (+1) or smaller (−1) nudge step, within [`STEPS`].
    pub fn change_step(&mut self, by: i32) {
        self.step = (self.step as i32 + by).clamp(0, STEPS.len() as i32 - 1) as usize;
    }

    /// Zooms the map by `factor` (within 0.1…10,000), keeping the point `at`
    /// under the pointer when given.
    pub fn zoom_map(&mut self, factor: f64, at: Option<Point2<f64>>, extent: Extent) {
        let zoom = (self.zoom * factor).clamp(0.1, 10_000.0);
        let applied = zoom / self.zoom;
        if let Some(p) = at {
            let c = self.map_center(extent);
            self.center = Some(p + (c - p) / applied);
        }
        self.zoom = zoom;
    }

    /// Zooms the formation editor by `factor` (within 0.1…100).
    pub fn zoom_formation(&mut self, factor: f64) {
        self.formation_zoom = (self.formation_zoom * factor).clamp(0.1, 100.0);
    }

    /// Pans the map by fractions (`fx`, `fy`) of the view.
    pub fn pan(&mut self, fx: f64, fy: f64, extent: Extent) {
        let (x, y) = extent;
        let (w, h) = (x[1] - x[0], y[1] - y[0]);
        let c = self.map_center(extent);
        self.center = Some(Point2::new(
            c.x + fx * w / self.zoom,
            c.y + fy * h / self.zoom,
        ));
    }

    /// Looks at `center` (None: the extent's middle), at the same zoom.
    pub fn look_at(&mut self, center: Option<Point2<f64>>) {
        self.center = center;
    }

    /// Whether the whole extent is surely in view (zoom 1 or less, not panned).
    pub fn shows_everything(&self) -> bool {
        self.zoom <= 1.0 && self.center.is_none()
    }

    /// The whole extent in view again.
    pub fn fit_map(&mut self) {
        self.zoom = 1.0;
        self.center = None;
    }

    pub fn fit_formation(&mut self) {
        self.formation_zoom = 1.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXTENT: Extent = ([0.0, 100.0], [0.0, 50.0]);

    #[test]
    fn zooming_about_a_point_keeps_it_in_place() {
        let mut c = Camera::default();
        let p = Point2::new(80.0, 10.0);
        let before = c.map_center(EXTENT);
        c.zoom_map(2.0, Some(p), EXTENT);
        // The point keeps its offset from the centre, halved.
        let after = c.map_center(EXTENT);
        assert!(((p - after) * 2.0 - (p - before)).norm() < 1e-12);
        assert_eq!(c.zoom(), 2.0);
        c.fit_map();
        assert_eq!((c.zoom(), c.panned_center()), (1.0, None));
    }

    #[test]
    fn zoom_and_step_stay_in_their_ranges() {
        let mut c = Camera::default();
        c.zoom_map(1e9, None, EXTENT);
        assert_eq!(c.zoom(), 10_000.0);
        c.zoom_formation(1e-9);
        assert_eq!(c.formation_zoom(), 0.1);
        for _ in 0..20 {
            c.change_step(1);
        }
        assert_eq!(c.step_size(), 1000.0);
        c.change_step(-100);
        assert_eq!(c.step_size(), 0.01);
    }

    #[test]
    fn a_pan_moves_by_a_fraction_of_the_view() {
        let mut c = Camera::default();
        c.zoom_map(2.0, None, EXTENT);
        c.pan(0.1, -0.2, EXTENT);
        assert_eq!(c.map_center(EXTENT), Point2::new(55.0, 20.0));
    }
}
