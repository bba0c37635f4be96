//! A pipeline's sketch (`pipelines::sketch`) said to Rerun: the one place
//! its words become archetypes. Times are on `sim_time`; the first logging
//! error (a sink gone) ends the sketch, as the recording is best effort.

use nalgebra::{Point3, Vector3};
use rerun::RecordingStream;

use super::f32x3;
use crate::pipelines::sketch::{Note, Sketch, Style};

/// Draws into `stream`; keeps the first error.
pub struct RerunSketch<'a> {
    stream: &'a RecordingStream,
    /// What is shown for the whole recording is logged static; a live
    /// plan's, at the stream's current time (its `revision`).
    timeless: bool,
    pub result: rerun::RecordingStreamResult<()>,
}

impl<'a> RerunSketch<'a> {
    pub fn new(stream: &'a RecordingStream) -> Self {
        RerunSketch {
            stream,
            timeless: true,
            result: Ok(()),
        }
    }

    /// A sketch whose lasting parts are logged at the stream's current
    /// time (a live plan's revision), not static.
    pub fn at_current_time(stream: &'a RecordingStream) -> Self {
        RerunSketch {
            timeless: false,
            ..RerunSketch::new(stream)
        }
    }

    /// Runs `log` unless an earlier call failed.
    fn then(&mut self, log: impl FnOnce(&RecordingStream) -> rerun::RecordingStreamResult<()>) {
        if self.result.is_ok() {
            self.result = log(self.stream);
        }
    }
}

fn color([r, g, b, a]: [u8; 4]) -> rerun::Color {
    rerun::Color::from_unmultiplied_rgba(r, g, b, a)
}

fn strips3d(strips: Vec<Vec<Point3<f64>>>, style: &Style) -> rerun::LineStrips3D {
    let strips: Vec<Vec<[f32; 3]>> = strips
        .iter()
        .map(|s| s.iter().map(f32x3).collect())
        .collect();
    let mut archetype = rerun::LineStrips3D::new(strips);
    if let Some(c) = style.color {
        archetype = archetype.with_colors([color(c)]);
    }
    if let Some(r) = style.radius {
        archetype = archetype.with_radii([r]);
    }
    if let Some(l) = &style.label {
        archetype = archetype.with_labels([l.clone()]);
    }
    archetype
}

fn points3d(points: Vec<Point3<f64>>, style: &Style) -> rerun::Points3D {
    styled_points(rerun::Points3D::new(points.iter().map(f32x3)), style)
}

/// `archetype` with `style`'s colour, radius and label.
fn styled_points(mut archetype: rerun::Points3D, style: &Style) -> rerun::Points3D {
    if let Some(c) = style.color {
        archetype = archetype.with_colors([color(c)]);
    }
    if let Some(r) = style.radius {
        archetype = archetype.with_radii([r]);
    }
    if let Some(l) = &style.label {
        archetype = archetype.with_labels([l.clone()]);
    }
    archetype
}

fn times(times: &[f64]) -> rerun::TimeColumn {
    rerun::TimeColumn::new_duration_secs("sim_time", times.iter().copied())
}

impl Sketch for RerunSketch<'_> {
    fn property(&mut self, name: &str, markdown: String) {
        self.then(|s| s.send_property(name, &rerun::TextDocument::from_markdown(markdown)));
    }

    fn strips(&mut self, path: &str, strips: Vec<Vec<Point3<f64>>>, style: Style) {
        let timeless = self.timeless;
        self.then(|s| {
            let archetype = strips3d(strips, &style);
            if timeless {
                s.log_static(path, &archetype)
            } else {
                s.log(path, &archetype)
            }
        });
    }

    fn strips_at(&mut self, path: &str, t: f64, strips: Vec<Vec<Point3<f64>>>, style: Style) {
        self.then(|s| {
            s.set_duration_secs("sim_time", t);
            s.log(path, &strips3d(strips, &style))
        });
    }

    /// One archetype: the positions, and each part of the style per
    /// point (a part that not every mark gives is left out).
    fn marks(&mut self, path: &str, marks: Vec<(Point3<f64>, Style)>) {
        let timeless = self.timeless;
        self.then(|s| {
            let mut archetype = rerun::Points3D::new(marks.iter().map(|(p, _)| f32x3(p)));
            if marks.iter().all(|(_, m)| m.label.is_some()) {
                archetype = archetype.with_labels(
                    marks
                        .iter()
                        .map(|(_, m)| m.label.clone().unwrap_or_default()),
                );
            }
            if marks.iter().all(|(_, m)| m.radius.is_some()) {
                archetype =
                    archetype.with_radii(marks.iter().map(|(_, m)| m.radius.unwrap_or_default()));
            }
            if marks.iter().all(|(_, m)| m.color.is_some()) {
                archetype = archetype.with_colors(
                    marks
                        .iter()
                        .map(|(_, m)| color(m.color.unwrap_or_default())),
                );
            }
            if timeless {
                s.log_static(path, &archetype)
            } else {
                s.log(path, &archetype)
            }
        });
    }

    fn points_at(&mut self, path: &str, t: f64, points: Vec<Point3<f64>>, style: Style) {
        self.then(|s| {
            s.set_duration_secs("sim_time", t);
            s.log(path, &points3d(points, &style))
        });
    }

    /// Its style logged once, its positions as one `send_columns`.
    fn moving_point(&mut self, path: &str, at: &[f64], positions: &[Point3<f64>], style: Style) {
        self.then(|s| {
            s.log_static(
                path,
                &styled_points(rerun::Points3D::update_fields(), &style),
            )?;
            s.send_columns(
                path,
                [times(at)],
                rerun::Points3D::update_fields()
                    .with_positions(positions.iter().map(f32x3))
                    .columns_of_unit_batches()?,
            )
        });
    }

    fn moving_arrows(
        &mut self,
        path: &str,
        at: &[f64],
        origins: &[Point3<f64>],
        vectors: &[Vector3<f64>],
        style: Style,
    ) {
        self.then(|s| {
            let mut fields = rerun::Arrows3D::update_fields();
            if let Some(c) = style.color {
                fields = fields.with_colors([color(c)]);
            }
            s.log_static(path, &fields)?;
            s.send_columns(
                path,
                [times(at)],
                rerun::Arrows3D::update_fields()
                    .with_origins(origins.iter().map(f32x3))
                    .with_vectors(vectors.iter().map(|v| [v.x as f32, v.y as f32, v.z as f32]))
                    .columns_of_unit_batches()?,
            )
        });
    }

    /// Its style (when given) logged once, its values as one `send_columns`.
    fn series(&mut self, path: &str, at: &[f64], values: Vec<f64>, style: Option<Style>) {
        self.then(|s| {
            if let Some(style) = style {
                let mut lines = rerun::SeriesLines::new();
                if let Some(c) = style.color {
                    lines = lines.with_colors([color(c)]);
                }
                if let Some(l) = style.label {
                    lines = lines.with_names([l]);
                }
                s.log_static(path, &lines)?;
            }
            s.send_columns(
                path,
                [times(at)],
                rerun::Scalars::update_fields()
                    .with_scalars(values)
                    .columns_of_unit_batches()?,
            )
        });
    }

    fn event(&mut self, path: &str, t: f64, text: String, note: Note) {
        self.then(|s| {
            s.set_duration_secs("sim_time", t);
            let log = rerun::TextLog::new(text);
            s.log(
                path,
                &match note {
                    Note::Plain => log,
                    Note::Info => log.with_level(rerun::TextLogLevel::INFO),
                    Note::Warn => log.with_level(rerun::TextLogLevel::WARN),
                },
            )
        });
    }
}
