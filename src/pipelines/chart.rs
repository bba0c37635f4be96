//! What a pipeline's outcome shows on the designer's map, in a few plain
//! words (lines, rings, marks in an ink that says what they are) that the
//! map (`tui/view/map/`) draws in its colours. A pipeline charts itself in
//! its own `chart.rs`, without knowing the terminal; as with a recording's
//! [`super::sketch`], the front end interprets the words once for every
//! pipeline.

use crate::mission::Mission;

/// What a thing on the map is, which the map turns into a colour. Marks are
/// bold, but in [`Ink::Plain`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ink {
    /// Vehicle `i`'s own colour (`sketch::vehicle_color`, 0-based).
    Vehicle(usize),
    /// Context that stays behind the result: a reference, a sensing range,
    /// a stale vehicle's track.
    Faded,
    /// A stale result's own lines.
    Grey,
    /// The formation's path, a reference point.
    Plain,
    /// Where the formation changes shape.
    Zone,
    /// Where it inspects.
    Pass,
    /// Where a hard constraint breaks.
    Fault,
}

/// What the map asks an outcome to chart.
#[derive(Debug, Clone, Copy)]
pub struct ChartView<'a> {
    /// The mission as it stands in the designer (it may have been edited
    /// since the run).
    pub mission: &'a Mission,
    /// The mission was edited since the run.
    pub stale: bool,
    /// The result is the designer's live plan, which says at once where it
    /// fails.
    pub live: bool,
    /// The replay's instant, seconds (`None`: the end of the flight).
    pub at: Option<f64>,
}

/// Where an outcome is charted: the top-down map (x, y in metres) or the
/// side view (distance along the outcome's path, altitude).
pub trait Chart {
    /// A polyline.
    fn line(&mut self, points: Vec<[f64; 2]>, ink: Ink);
    /// A circle of `radius` metres around `centre`.
    fn ring(&mut self, centre: [f64; 2], radius: f64, ink: Ink);
    /// Text at a point.
    fn mark(&mut self, at: [f64; 2], text: String, ink: Ink);
    /// What follows is drawn over what came before.
    fn layer(&mut self);
}
