//! A site survey into a mission: obstacles from GeoJSON (RFC 7946) and
//! KML/KMZ files, with the heights the tools draw them with.
//!
//! A file is read into a [`Survey`] of features in WGS-84 (`geojson.rs`,
//! `kml.rs`: the georust readers, then the checks a survey must pass:
//! closed rings, coordinates in range, near the mission's origin). Each
//! position keeps its altitude and each shape the way its altitudes are
//! meant ([`Vertical`]: KML's `altitudeMode` / `gx:altitudeMode` and
//! `extrude`; GeoJSON's third coordinate, RFC 7946 §3.1.1). Each feature
//! becomes obstacles in the mission's ENU frame (`obstacles.rs`, its
//! heights read in `heights.rs`): a point a post, a polygon a footprint as
//! surveyed (a block standing on the ground, or a deck or a slab at its
//! height), a line not extruded (or marked as a power line) a wire at its
//! height, another line a row of posts (`cover.rs`); all clipped to the
//! bounds. The report says which reading each feature got and names the
//! narrowest aisle between the footprints imported. They join the mission by
//! name (`merge.rs`): importing the same file again changes nothing, an
//! updated survey updates its obstacles, and one that would lower or thin a
//! known obstacle says so (the CLI then asks for `--force`).
//! Reading the file is the only I/O; the CLI and the designer write.

pub mod cover;
mod geojson;
mod heights;
mod kml;
mod merge;
mod obstacles;
mod pieces;

use std::path::Path;

use serde_json::{Map, Value};

use crate::mission::Mission;

pub use heights::{DEFAULT_DECK_THICKNESS, DEFAULT_WIRE_RADIUS, Reading};
pub use merge::{Change, Changes};
pub use obstacles::{DEFAULT_LINE_RADIUS, DEFAULT_POINT_RADIUS, HEIGHT_ABOVE_BAND, Note};

/// One position of a feature: degrees of longitude and latitude (the order
/// both GeoJSON and KML write) and the altitude written with it, metres,
/// when there is one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Position {
    pub lon: f64,
    pub lat: f64,
    pub alt: Option<f64>,
}

impl Position {
    /// A position without an altitude.
    pub fn flat(lon: f64, lat: f64) -> Self {
        Position {
            lon,
            lat,
            alt: None,
        }
    }
}

/// A shape of a feature.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    Point(Position),
    Line(Vec<Position>),
    /// The outer ring, then the holes; each ring closed as written.
    Polygon(Vec<Vec<Position>>),
}

impl Shape {
    /// Every position of the shape.
    pub fn positions(&self) -> Vec<Position> {
        match self {
            Shape::Point(p) => vec![*p],
            Shape::Line(l) => l.clone(),
            Shape::Polygon(rings) => rings.iter().flatten().copied().collect(),
        }
    }
}

/// What the altitudes written with a shape measure from (KML's
/// `altitudeMode` and `gx:altitudeMode`; GeoJSON's third coordinate).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AltitudeMode {
    /// KML's default: the shape lies on the ground, its altitudes unused
    /// (also `gx:altitudeMode` `clampToSeaFloor`).
    #[default]
    ClampToGround,
    /// Metres above the ground under each position (also
    /// `relativeToSeaFloor`: skyform's ground is the ground).
    RelativeToGround,
    /// KML's `absolute`: metres above mean sea level.
    AboveSeaLevel,
    /// GeoJSON's third coordinate: metres above the WGS-84 ellipsoid
    /// (RFC 7946 §3.1.1).
    AboveEllipsoid,
}

impl AltitudeMode {
    /// As the tool that wrote it names it.
    pub fn name(self) -> &'static str {
        match self {
            AltitudeMode::ClampToGround => "clampToGround",
            AltitudeMode::RelativeToGround => "relativeToGround",
            AltitudeMode::AboveSeaLevel => "absolute",
            AltitudeMode::AboveEllipsoid => "above the WGS-84 ellipsoid, RFC 7946",
        }
    }
}

/// How a shape's altitudes are meant: from what they measure, and whether
/// the shape is extruded down to the ground (KML's `extrude`; `None` where
/// the format has no such flag, GeoJSON without an `extrude` property).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Vertical {
    pub mode: AltitudeMode,
    pub extrude: Option<bool>,
}

/// A shape as drawn: its positions and how their altitudes are meant.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawn {
    pub shape: Shape,
    pub vertical: Vertical,
}

impl Drawn {
    /// A shape with no altitudes (clamped to the ground).
    pub fn flat(shape: Shape) -> Self {
        Drawn {
            shape,
            vertical: Vertical::default(),
        }
    }

    /// Whether the shape's altitudes mean anything: a mode other than
    /// clamped to the ground, and at least one position with an altitude.
    pub fn has_altitudes(&self) -> bool {
        self.vertical.mode != AltitudeMode::ClampToGround
            && self.shape.positions().iter().any(|p| p.alt.is_some())
    }
}

/// One feature of a survey: a GeoJSON Feature, a KML Placemark.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Feature {
    /// 1-based, in the order of the file.
    pub number: usize,
    pub name: Option<String>,
    /// Its properties (GeoJSON) or extended data (KML, as text).
    pub properties: Map<String, Value>,
    /// The KML folder it is in, the kind when it gives none.
    pub folder: Option<String>,
    /// Its free text (KML's `description`, a `description` property).
    pub description: Option<String>,
    pub shapes: Vec<Drawn>,
    /// Why it has no usable geometry, when it has none.
    pub unusable: Option<String>,
}

impl Feature {
    /// `feature 4 'pier 5'`, as messages name it.
    pub fn label(&self) -> String {
        match &self.name {
            Some(name) => format!("feature {} '{name}'", self.number),
            None => format!("feature {}", self.number),
        }
    }

    /// A property by name, any case.
    pub fn property(&self, key: &str) -> Option<&Value> {
        self.properties
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(key))
            .map(|(_, v)| v)
    }
}

/// The features of one file.
#[derive(Debug, Clone, PartialEq)]
pub struct Survey {
    /// "GeoJSON", "KML" or "KMZ".
    pub format: &'static str,
    pub features: Vec<Feature>,
}

/// Why nothing was imported (and nothing written).
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    #[error("cannot read {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Format { path: String, message: String },
    #[error("{path}: {} problem(s), nothing imported:\n  {}", problems.len(), problems.join("\n  "))]
    Features { path: String, problems: Vec<String> },
    #[error(
        "the mission has no [origin]: a survey's latitudes and longitudes are placed through \
         it; add the WGS-84 latitude, longitude and altitude of the ENU origin"
    )]
    NoOrigin,
}

/// What an import gives: the mission with the survey in it, and what
/// changed and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Imported {
    pub mission: Mission,
    pub format: &'static str,
    pub features: usize,
    pub changes: Changes,
    /// Per polygon and line: the cylinders made and what they add.
    pub notes: Vec<Note>,
    /// How each feature's heights were read.
    pub readings: Vec<Reading>,
    /// Features listed, not imported: outside the bounds, no usable geometry.
    pub skipped: Vec<String>,
    /// Defaults assumed (no radius, no height), grouped.
    pub warnings: Vec<String>,
    /// The narrowest aisle between two imported footprints that stand at a
    /// common altitude: their names and the width, metres.
    pub aisle: Option<(String, String, f64)>,
}

/// Reads a survey file: GeoJSON (`.geojson`, `.json`), KML (`.kml`) or KMZ
/// (`.kmz`, or any zip), by its name and, failing that, its first bytes.
pub fn read_survey(path: &Path) -> Result<Survey, ImportError> {
    let bytes = std::fs::read(path).map_err(|source| ImportError::Read {
        path: path.display().to_string(),
        source,
    })?;
    parse_survey(&bytes, &path.display().to_string())
}

/// [`read_survey`] on bytes already read; `name` names the file.
pub fn parse_survey(bytes: &[u8], name: &str) -> Result<Survey, ImportError> {
    let format_error = |message: String| ImportError::Format {
        path: name.to_owned(),
        message,
    };
    let lower = name.to_ascii_lowercase();
    let survey = if bytes.starts_with(b"PK\x03\x04") || lower.ends_with(".kmz") {
        kml::read_kmz(bytes).map_err(format_error)?
    } else if lower.ends_with(".kml") || looks_like_xml(bytes) {
        let text =
            std::str::from_utf8(bytes).map_err(|e| format_error(format!("not UTF-8 text: {e}")))?;
        kml::read_kml(text, "KML").map_err(format_error)?
    } else {
        let text =
            std::str::from_utf8(bytes).map_err(|e| format_error(format!("not UTF-8 text: {e}")))?;
        geojson::read(text).map_err(|e| match e {
            geojson::Problem::Format(message) => format_error(message),
            geojson::Problem::Features(problems) => ImportError::Features {
                path: name.to_owned(),
                problems,
            },
        })?
    };
    let problems: Vec<String> = survey.features.iter().flat_map(check_feature).collect();
    if !problems.is_empty() {
        return Err(ImportError::Features {
            path: name.to_owned(),
            problems,
        });
    }
    Ok(survey)
}

fn looks_like_xml(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(0);
    bytes[start..].starts_with(b"<") || bytes.starts_with(b"\xEF\xBB\xBF<")
}

/// What a feature's geometry must be, whatever the format: coordinates in
/// range, rings closed and long enough (RFC 7946 3.1.6; KML's LinearRing).
fn check_feature(f: &Feature) -> Vec<String> {
    let mut problems = Vec::new();
    let check_position = |p: &Position, problems: &mut Vec<String>| {
        let (lon, lat) = (p.lon, p.lat);
        if p.alt.is_some_and(|a| !a.is_finite()) {
            problems.push(format!(
                "{}: the altitude at ({lon}, {lat}) is not a number",
                f.label()
            ));
        }
        if !(lon.is_finite() && lat.is_finite()) {
            problems.push(format!(
                "{}: coordinate ({lon}, {lat}) is not a number",
                f.label()
            ));
        } else if lat.abs() > 90.0 || lon.abs() > 180.0 {
            let swapped = if lat.abs() > 90.0 && lon.abs() <= 90.0 && lat.abs() <= 180.0 {
                " (latitude and longitude swapped? longitude comes first)"
            } else {
                ""
            };
            problems.push(format!(
                "{}: coordinate ({lon}, {lat}) is out of range: longitude must be within ±180°, \
                 latitude within ±90°{swapped}",
                f.label()
            ));
        }
    };
    for drawn in &f.shapes {
        match &drawn.shape {
            Shape::Point(p) => check_position(p, &mut problems),
            Shape::Line(points) => points.iter().for_each(|p| check_position(p, &mut problems)),
            Shape::Polygon(rings) => {
                for (k, ring) in rings.iter().enumerate() {
                    ring.iter().for_each(|p| check_position(p, &mut problems));
                    let which = if k == 0 {
                        "its outer ring".to_owned()
                    } else {
                        format!("hole {k}")
                    };
                    match (ring.first(), ring.last()) {
                        _ if ring.len() < 4 => problems.push(format!(
                            "{}: {which} has {} positions; a closed ring needs at least 4 \
                             (the first repeated at the end)",
                            f.label(),
                            ring.len()
                        )),
                        (Some(a), Some(b)) if (a.lon, a.lat) != (b.lon, b.lat) => {
                            problems.push(format!(
                                "{}: {which} does not close: it starts at ({}, {}) and ends at \
                             ({}, {}); the last position must repeat the first",
                                f.label(),
                                a.lon,
                                a.lat,
                                b.lon,
                                b.lat
                            ))
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    problems
}

/// Puts the survey's features into `mission` as obstacles (see the module
/// comment); `stem` names the unnamed ones (`<stem> <number>`). Fails,
/// listing every feature concerned, when a feature lies far from the
/// mission's site (latitude and longitude swapped, another site) or its
/// properties are not numbers.
pub fn import(mission: &Mission, survey: &Survey, stem: &str) -> Result<Imported, ImportError> {
    let origin = mission.origin.as_ref().ok_or(ImportError::NoOrigin)?;
    let made = obstacles::make(mission, origin, survey, stem).map_err(|problems| {
        ImportError::Features {
            path: stem.to_owned(),
            problems,
        }
    })?;
    let (merged, changes) = merge::merge(mission, &made.features);
    let aisle = narrowest_aisle(made.features.iter().flat_map(|f| f.obstacles.iter()));
    Ok(Imported {
        mission: merged,
        format: survey.format,
        features: survey.features.len(),
        changes,
        notes: made.notes,
        readings: made.readings,
        skipped: made.skipped,
        warnings: made.warnings,
        aisle,
    })
}

/// The narrowest gap between two of `obstacles`' footprints that stand at
/// a common altitude (their outlines' nearest points: the aisle a
/// formation would fly), with their names; none when fewer than two
/// footprints, or none apart.
fn narrowest_aisle<'a>(
    obstacles: impl Iterator<Item = &'a crate::mission::Obstacle>,
) -> Option<(String, String, f64)> {
    let footprints: Vec<&crate::mission::Obstacle> =
        obstacles.filter(|o| !o.footprint.is_empty()).collect();
    let mut best: Option<(String, String, f64)> = None;
    for (i, a) in footprints.iter().enumerate() {
        for b in &footprints[i + 1..] {
            let apart = (a.center - b.center).norm() - a.radius - b.radius;
            if best.as_ref().is_some_and(|(_, _, w)| apart >= *w)
                || a.base >= b.height
                || b.base >= a.height
            {
                continue;
            }
            let (pa, pb) = (a.prism(), b.prism());
            let (p, q) = crate::base::shape::nearest_points(&*pa.outline, &*pb.outline);
            if pa.outward(&q) <= 0.0 || pb.outward(&p) <= 0.0 {
                continue; // touching or overlapping: one building
            }
            let width = (q - p).norm();
            if best.as_ref().is_none_or(|(_, _, w)| width < *w) {
                best = Some((a.name.clone(), b.name.clone(), width));
            }
        }
    }
    best
}

/// The stem of a survey file's name, for unnamed features.
pub fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "survey".to_owned())
}

impl Imported {
    /// What the import did, in lines for a person: the changes, each
    /// polygon's and line's cylinders, what was skipped, then warnings.
    pub fn report(&self) -> String {
        let mut out = String::new();
        let c = &self.changes;
        out.push_str(&format!(
            "{} {} feature(s): {} obstacle(s) added, {} updated, {} removed, {} unchanged\n",
            self.format,
            self.features,
            c.added().count(),
            c.updated().count(),
            c.removed().count(),
            c.unchanged
        ));
        let added: Vec<&str> = c
            .added()
            .filter_map(|a| match a {
                Change::Added(name) => Some(name.as_str()),
                _ => None,
            })
            .collect();
        if !added.is_empty() {
            out.push_str(&format!("  added {}\n", merge::runs(&added)));
        }
        for change in c.list.iter().filter(|c| !matches!(c, Change::Added(_))) {
            out.push_str(&format!("  {change}\n"));
        }
        for note in &self.notes {
            out.push_str(&format!("  {note}\n"));
        }
        for reading in &self.readings {
            out.push_str(&format!("  read {reading}\n"));
        }
        for loss in &c.losses {
            out.push_str(&format!("  loss: {loss}\n"));
        }
        for s in &self.skipped {
            out.push_str(&format!("  skipped {s}\n"));
        }
        if let Some((a, b, width)) = &self.aisle {
            let f = &self.mission.formation;
            let r_q = f.least_clearance();
            let nominal = 2.0 * (f.slots.iter().map(|s| s.y.abs()).fold(0.0, f64::max) + r_q);
            let fits = if *width >= nominal {
                "the formation passes it as it is"
            } else if *width >= 2.0 * r_q {
                "narrower than the formation: it passes in a narrower shape (a shrink or a column)"
            } else {
                "narrower than one UAV: no way through"
            };
            out.push_str(&format!(
                "  narrowest aisle between footprints: '{a}' | '{b}', {width:.2} m (the formation \
                 is {nominal:.2} m wide, one UAV {:.2} m): {fits}\n",
                2.0 * r_q
            ));
        }
        for w in &self.warnings {
            out.push_str(&format!("warning: {w}\n"));
        }
        out
    }
}
