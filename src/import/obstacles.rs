//! A survey's features as obstacles in the mission's ENU frame.
//!
//! A point is a post (a cylinder); a polygon a footprint, as surveyed
//! (holes filled: a courtyard is no way through for a formation); a wire a
//! span of `wire` per stretch; another line a row of posts
//! (`cover::cover_line`). How high each stands is `heights.rs`'s reading of
//! its properties and its altitudes. Everything is clipped to the bounds
//! (posts and rows so that no cylinder reaches out of them, so what is
//! written passes `check --strict`), points outside are left out; both are
//! said. A radius without a `radius` property and a height without any
//! are the defaults here, with a warning; the name comes from its name
//! (else `<file stem> <number>`), the kind from its `kind` property (else
//! an OpenStreetMap `power` tag, else its KML folder), the description
//! from its description. Numbers are written to the millimetre. A feature
//! far from the bounds is an error: the file is of another site, or its
//! latitudes and longitudes are swapped.

use std::collections::HashSet;
use std::fmt;

use serde_json::Value;

use super::cover;
use super::heights::{self, Props, Reading, metres};
use super::pieces::{Pending, Piece, Shaped, Site, obstacle, rest_surfaces, shape_pieces};
use super::{Feature, Survey};
use crate::mission::geodesy::Frame;
use crate::mission::{Bounds, GeoOrigin, Mission, Obstacle};

/// Radius of a point's cylinder without a `radius` property, metres.
pub const DEFAULT_POINT_RADIUS: f64 = 1.0;

/// Radius of a line's cylinders without a `radius` property, metres.
pub const DEFAULT_LINE_RADIUS: f64 = 1.0;

/// Without a `height` property an obstacle is this much taller than the
/// altitude band's top, metres: the plan goes round it, never over.
pub const HEIGHT_ABOVE_BAND: f64 = 1.0;

/// Farthest a feature may lie from the bounds, metres.
const REGION: f64 = 100_000.0;

/// The obstacles one feature makes, under the name it owns (its pieces
/// are `name #1`, `name #2`, … when there are several).
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureObstacles {
    pub name: String,
    pub obstacles: Vec<Obstacle>,
    /// Its radius and height came from the survey, not from a default: a
    /// re-import keeps a known obstacle's own where they did not.
    pub radius_known: bool,
    pub height_known: bool,
}

/// What a polygon's footprints or a line's cylinders are, for the report.
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    Polygon {
        label: String,
        /// Footprints made (a polygon the bounds cut in two makes two).
        footprints: usize,
        vertices: usize,
        /// m² of the polygon inside the bounds, and outside (left out).
        area: f64,
        /// Holes filled in.
        holes: usize,
        outside: f64,
    },
    Line {
        label: String,
        cylinders: usize,
        radius: f64,
        /// Metres of the line inside the bounds, and outside (left out).
        length: f64,
        outside: f64,
    },
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Note::Polygon {
                label,
                footprints,
                vertices,
                area,
                holes,
                outside,
            } => {
                write!(
                    f,
                    "polygon {label}: kept as {footprints} footprint(s) of {vertices} vertices, \
                     {area:.1} m²"
                )?;
                if *holes > 0 {
                    write!(f, "; {holes} hole(s) filled in")?;
                }
                if *outside > 0.05 {
                    write!(f, "; {outside:.1} m² outside the bounds left out")?;
                }
                Ok(())
            }
            Note::Line {
                label,
                cylinders,
                radius,
                length,
                outside,
            } => {
                write!(
                    f,
                    "line {label}: {cylinders} cylinder(s) of radius {radius} m along its \
                     {length:.1} m, covering {:.2} m either side",
                    cover::line_half_width(*radius)
                )?;
                if *outside > 0.05 {
                    write!(f, "; {outside:.1} m outside the bounds left out")?;
                }
                Ok(())
            }
        }
    }
}

/// Everything the features make.
#[derive(Debug, Default)]
pub struct Made {
    pub features: Vec<FeatureObstacles>,
    pub notes: Vec<Note>,
    /// How each feature's heights were read.
    pub readings: Vec<Reading>,
    pub skipped: Vec<String>,
    pub warnings: Vec<String>,
}

/// The obstacles of every feature of `survey`, or every problem found.
///
/// Long (~150 lines): one pass over the features (their properties, whether a wire, each
/// shape's pieces through `shape_pieces`), the surfaces rested on what stands under them,
/// then each feature's pieces named and made obstacles.
pub fn make(
    mission: &Mission,
    origin: &GeoOrigin,
    survey: &Survey,
    stem: &str,
) -> Result<Made, Vec<String>> {
    let frame = Frame::new(origin);
    let bounds = &mission.bounds;
    let default_height = bounds.z[1] + HEIGHT_ABOVE_BAND;
    let mut made = Made::default();
    let mut problems = Vec::new();
    let mut names: HashSet<String> = HashSet::new();
    let (mut no_radius, mut no_height) = (Vec::new(), Vec::new());
    let mut pending: Vec<Pending> = Vec::new();
    for f in &survey.features {
        if let Some(why) = &f.unusable {
            made.skipped.push(format!("{}: {why}", f.label()));
            continue;
        }
        if let Some(far) = far_from_site(f, &frame, bounds) {
            problems.push(far);
            continue;
        }
        let props = Props::read(f, &mut problems);
        let marked = match heights::marked_wire(f) {
            Ok(marked) => marked,
            Err(why) => {
                made.skipped.push(format!("{}: {why}", f.label()));
                continue;
            }
        };
        let site = Site {
            mission,
            frame: &frame,
            origin: origin.altitude,
        };
        let mut p = Pending {
            label: f.label(),
            name: String::new(),
            kind: None,
            description: f.description.clone(),
            overfly: props.overfly,
            pieces: Vec::new(),
            readings: Vec::new(),
            radius_known: props.radius.is_some(),
            height_known: true,
        };
        let mut outside_points = 0;
        let mut no_area = false;
        for drawn in &f.shapes {
            match shape_pieces(&site, f, drawn, &props, marked, &mut made.notes) {
                Ok(Shaped::Pieces(pieces, reading)) => {
                    p.pieces.extend(pieces);
                    p.readings.push(reading);
                }
                Ok(Shaped::Outside) => outside_points += 1,
                Ok(Shaped::NoArea) => no_area = true,
                Ok(Shaped::Nothing) => {}
                Err(problem) => problems.push(problem),
            }
        }
        if p.pieces.is_empty() {
            let why = if no_area {
                "a polygon of no area".to_owned()
            } else {
                format!("outside the bounds x {:?}, y {:?}", bounds.x, bounds.y)
            };
            made.skipped.push(format!("{}: {why}", f.label()));
            continue;
        }
        if outside_points > 0 {
            made.skipped.push(format!(
                "{}: {outside_points} of its points outside the bounds",
                f.label()
            ));
        }
        let needs_radius = p
            .pieces
            .iter()
            .any(|piece| matches!(piece, Piece::Post { .. }));
        if props.radius.is_none() && needs_radius {
            no_radius.push(f.label());
        }
        p.height_known = !p.pieces.iter().any(|piece| {
            matches!(
                piece,
                Piece::Post { top: None, .. } | Piece::Block { top: None, .. }
            )
        });
        if !p.height_known {
            no_height.push(f.label());
        }
        p.name = unique_name(f, stem, &mut names);
        p.kind = f
            .property("kind")
            .and_then(text)
            .or_else(|| {
                f.property("power")
                    .and_then(text)
                    .map(|t| format!("power {}", t.replace('_', " ")))
            })
            .or_else(|| f.folder.clone());
        pending.push(p);
    }
    if !problems.is_empty() {
        return Err(problems);
    }
    made.warnings.extend(rest_surfaces(&mut pending));
    for p in pending {
        let several = p.pieces.len() > 1;
        let obstacles = p
            .pieces
            .iter()
            .enumerate()
            .map(|(k, piece)| {
                let name = if several {
                    format!("{} #{}", p.name, k + 1)
                } else {
                    p.name.clone()
                };
                let mut o = obstacle(name, piece, default_height);
                o.overfly = p.overfly.unwrap_or(true);
                o.kind = p.kind.clone();
                o.description = p.description.clone();
                o
            })
            .collect();
        made.readings.push(Reading {
            label: p.label.clone(),
            text: p.readings.join("; "),
        });
        made.features.push(FeatureObstacles {
            name: p.name,
            obstacles,
            radius_known: p.radius_known,
            height_known: p.height_known,
        });
    }
    if !no_radius.is_empty() {
        made.warnings.push(format!(
            "no radius in {}: {DEFAULT_POINT_RADIUS} m assumed (set a `radius` property, metres)",
            listing(&no_radius)
        ));
    }
    if !no_height.is_empty() {
        made.warnings.push(format!(
            "no height in {}: {} assumed, {HEIGHT_ABOVE_BAND} m above the altitude band so the \
             plan goes round (draw it with altitudes, relativeToGround, or set a `height` \
             property, metres)",
            listing(&no_height),
            metres(default_height)
        ));
    }
    Ok(made)
}

/// A few labels and how many more.
pub(super) fn listing(labels: &[String]) -> String {
    const SHOWN: usize = 6;
    let mut out = labels
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if labels.len() > SHOWN {
        out.push_str(&format!(" and {} more", labels.len() - SHOWN));
    }
    out
}

/// The feature's name, or `<stem> <number>`, made unique in this import.
fn unique_name(f: &Feature, stem: &str, names: &mut HashSet<String>) -> String {
    let base = f
        .name
        .clone()
        .unwrap_or_else(|| format!("{stem} {}", f.number));
    let mut name = base.clone();
    let mut k = 2;
    while names.contains(&name) {
        name = format!("{base} ({k})");
        k += 1;
    }
    names.insert(name.clone());
    name
}

/// A text property (a number is written as it reads).
fn text(value: &Value) -> Option<String> {
    match value {
        Value::String(s) if !s.trim().is_empty() => Some(s.trim().to_owned()),
        Value::Number(n) => Some(n.to_string()),
        _ => None,
    }
}

/// A problem when the feature lies farther than [`REGION`] from the
/// bounds: with a hint when swapping its latitudes and longitudes would
/// bring it to the site.
fn far_from_site(f: &Feature, frame: &Frame, bounds: &Bounds) -> Option<String> {
    let away = |lon: f64, lat: f64| {
        let p = frame.ground_to_enu(lat, lon);
        let dx = (bounds.x[0] - p.x).max(p.x - bounds.x[1]).max(0.0);
        let dy = (bounds.y[0] - p.y).max(p.y - bounds.y[1]).max(0.0);
        dx.hypot(dy)
    };
    let first_far = f
        .shapes
        .iter()
        .flat_map(|d| d.shape.positions())
        .map(|p| (p.lon, p.lat, away(p.lon, p.lat)))
        .find(|(_, _, d)| d.is_nan() || *d > REGION)?;
    let (lon, lat, d) = first_far;
    let swapped = lat.abs() <= 180.0 && lon.abs() <= 90.0 && away(lat, lon) <= REGION;
    let hint = if swapped {
        ": its latitude and longitude are swapped (GeoJSON and KML write longitude first)"
    } else {
        ": a survey of another site, or latitude and longitude swapped?"
    };
    Some(format!(
        "{} is {:.0} km from the mission's bounds (longitude {lon}, latitude {lat}){hint}",
        f.label(),
        d / 1e3
    ))
}
