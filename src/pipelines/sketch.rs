//! What a pipeline's outcome shows in a 3-D recording, in a few plain
//! words (polylines, moving points, series, events on the `sim_time`
//! timeline) that the recorder (`record/`) says to Rerun. A pipeline draws
//! itself here, in its own `recording.rs`, without knowing the viewer; the
//! recorder interprets the words once for every pipeline.

use nalgebra::{Point3, Vector3};

/// One colour per vehicle (RGB), in vehicle order, cycling: the designer's
/// map and the Rerun recording draw UAV n in the same colour. Chosen to
/// stay apart on dark terminals and in the viewer (cyan first, as the map
/// always drew UAV 1).
pub const VEHICLE_COLORS: [[u8; 3]; 6] = [
    [23, 190, 207],
    [227, 119, 194],
    [44, 200, 44],
    [80, 140, 255],
    [255, 200, 60],
    [240, 80, 70],
];

/// Vehicle `i`'s colour (0-based).
pub fn vehicle_color(i: usize) -> [u8; 3] {
    VEHICLE_COLORS[i % VEHICLE_COLORS.len()]
}

/// How a thing is drawn: each part left out is the viewer's default.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Style {
    /// RGBA.
    pub color: Option<[u8; 4]>,
    /// Metres (a line's or a point's radius).
    pub radius: Option<f32>,
    pub label: Option<String>,
}

impl Style {
    /// Just a colour, opaque.
    pub fn rgb([r, g, b]: [u8; 3]) -> Style {
        Style {
            color: Some([r, g, b, 255]),
            ..Style::default()
        }
    }

    /// Vehicle `i`'s colour ([`vehicle_color`]).
    pub fn vehicle(i: usize) -> Style {
        Style::rgb(vehicle_color(i))
    }

    pub fn radius(self, radius: f32) -> Style {
        Style {
            radius: Some(radius),
            ..self
        }
    }

    pub fn label(self, label: impl Into<String>) -> Style {
        Style {
            label: Some(label.into()),
            ..self
        }
    }
}

/// How an event reads in the log: plain, information or a warning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Note {
    Plain,
    Info,
    Warn,
}

impl Note {
    /// A closest approach: a warning under its limit, information otherwise.
    pub fn closest(below_limit: bool) -> Note {
        if below_limit { Note::Warn } else { Note::Info }
    }
}

/// A plot beside the 3-D scene in the viewer layout: its title and the
/// entity path whose series it shows. A pipeline's plots are a column of
/// panels (`&[&[Plot]]`), a panel of more than one plot a set of tabs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Plot {
    pub title: &'static str,
    pub path: &'static str,
}

/// Where a pipeline's outcome is drawn. Paths are entity paths under the
/// pipeline's root (its slug, `theta_pso`); times are seconds on
/// `sim_time`.
pub trait Sketch {
    /// A text document (markdown) attached to the recording as `name`.
    fn property(&mut self, name: &str, markdown: String);
    /// Polylines shown for the whole recording.
    fn strips(&mut self, path: &str, strips: Vec<Vec<Point3<f64>>>, style: Style);
    /// Polylines from time `t` on (until the next at `path`).
    fn strips_at(&mut self, path: &str, t: f64, strips: Vec<Vec<Point3<f64>>>, style: Style);
    /// Points shown for the whole recording, each in its own style (a
    /// scene's marks: θ-PSO's IWPs, enabled or not).
    fn marks(&mut self, path: &str, marks: Vec<(Point3<f64>, Style)>);
    /// Points from time `t` on.
    fn points_at(&mut self, path: &str, t: f64, points: Vec<Point3<f64>>, style: Style);
    /// A point that moves: at `positions[k]` from `times[k]`.
    fn moving_point(&mut self, path: &str, times: &[f64], positions: &[Point3<f64>], style: Style);
    /// Arrows that move: from `origins[k]` along `vectors[k]` at `times[k]`.
    fn moving_arrows(
        &mut self,
        path: &str,
        times: &[f64],
        origins: &[Point3<f64>],
        vectors: &[Vector3<f64>],
        style: Style,
    );
    /// A series of values at `times`; `style` names and colours its line
    /// (`None`: the viewer's).
    fn series(&mut self, path: &str, times: &[f64], values: Vec<f64>, style: Option<Style>);
    /// An event in the log at `path` at time `t`.
    fn event(&mut self, path: &str, t: f64, text: String, note: Note);
}
