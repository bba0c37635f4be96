//! A survey's features as cylinders in the mission's ENU frame.
//!
//! A point is one cylinder; a line a row of them (`cover::cover_line`); a
//! polygon a footprint, as surveyed (holes filled: a courtyard is no way
//! through for a formation). Lines and polygons are clipped to the bounds
//! first (obstacle centres must lie
//! in them), points outside are left out; both are said. Radius and height
//! come from the feature's `radius` and `height` properties (metres),
//! else from the defaults here, with a warning; the name from its name
//! (else `<file stem> <number>`), the kind from its `kind` property (else
//! its KML folder). A feature far from the bounds is an error: the file is
//! of another site, or its latitudes and longitudes are swapped.

use std::collections::HashSet;
use std::fmt;

use geo::{Area, BooleanOps, Coord, LineString, MultiLineString, MultiPolygon, Polygon};
use nalgebra::Point2;
use serde_json::Value;

use super::cover::{self, Disc};
use super::{Feature, Shape, Survey};
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
    pub skipped: Vec<String>,
    pub warnings: Vec<String>,
}

/// The obstacles of every feature of `survey`, or every problem found.
///
/// Long (~180 lines): one match over the survey's feature kinds (point, line, polygon), each
/// placing and clipping in a few lines; around it, each feature's properties read and its
/// obstacles named.
pub fn make(
    mission: &Mission,
    origin: &GeoOrigin,
    survey: &Survey,
    stem: &str,
) -> Result<Made, Vec<String>> {
    let frame = Frame::new(origin);
    let bounds = &mission.bounds;
    let box_polygon = rectangle(bounds);
    let default_height = bounds.z[1] + HEIGHT_ABOVE_BAND;
    let mut made = Made::default();
    let mut problems = Vec::new();
    let mut names: HashSet<String> = HashSet::new();
    let (mut no_radius, mut no_height) = (Vec::new(), Vec::new());
    for f in &survey.features {
        if let Some(why) = &f.unusable {
            made.skipped.push(format!("{}: {why}", f.label()));
            continue;
        }
        let enu = |p: &[f64; 2]| frame.ground_to_enu(p[1], p[0]);
        if let Some(far) = far_from_site(f, &frame, bounds) {
            problems.push(far);
            continue;
        }
        let radius = property(f, "radius", &mut problems);
        // Its top (`height`, or `top`) and its underside (`base`, or OSM's
        // `min_height`): a deck, a gantry beam.
        let height =
            property(f, "height", &mut problems).or_else(|| property(f, "top", &mut problems));
        let base = ground_property(f, "base", &mut problems)
            .or_else(|| ground_property(f, "min_height", &mut problems));
        let overfly = flag(f, "overfly", &mut problems);
        if let (Some(b), Some(h)) = (base, height)
            && b >= h
        {
            problems.push(format!(
                "{}: its base {b} m is at or above its top {h} m",
                f.label()
            ));
        }
        let mut discs: Vec<Disc> = Vec::new();
        let mut footprints: Vec<Vec<Point2<f64>>> = Vec::new();
        let mut outside_points = 0;
        let mut no_area = false;
        for shape in &f.shapes {
            match shape {
                Shape::Point(p) => {
                    let center = enu(p);
                    if bounds.contains_xy(&center) {
                        let r = radius.unwrap_or(DEFAULT_POINT_RADIUS);
                        discs.push(tidy(Disc { center, radius: r }));
                    } else {
                        outside_points += 1;
                    }
                }
                Shape::Line(points) => {
                    let line: Vec<Point2<f64>> = points.iter().map(enu).collect();
                    let r = radius.unwrap_or(DEFAULT_LINE_RADIUS);
                    let (pieces, length, outside) = clip_line(&line, &box_polygon);
                    let before = discs.len();
                    for piece in pieces {
                        let row = cover::cover_line(&piece, r);
                        discs.extend(row.into_iter().map(tidy));
                    }
                    if discs.len() > before {
                        made.notes.push(Note::Line {
                            label: f.label(),
                            cylinders: discs.len() - before,
                            radius: r,
                            length,
                            outside,
                        });
                    }
                }
                Shape::Polygon(rings) => {
                    let Some(polygon) = enu_polygon(rings, &enu) else {
                        continue;
                    };
                    let whole = polygon.unsigned_area();
                    if whole <= 1e-6 {
                        no_area = true;
                        continue;
                    }
                    let inside = box_polygon.intersection(&polygon);
                    let area = inside.unsigned_area();
                    if area <= 1e-6 {
                        continue;
                    }
                    let before = footprints.len();
                    let mut holes = 0;
                    for part in &inside {
                        holes += part.interiors().len();
                        if let Some(outline) = footprint_of(part.exterior()) {
                            footprints.push(outline);
                        }
                    }
                    made.notes.push(Note::Polygon {
                        label: f.label(),
                        footprints: footprints.len() - before,
                        vertices: footprints[before..].iter().map(Vec::len).sum(),
                        area,
                        holes,
                        outside: (whole - area).max(0.0),
                    });
                }
            }
        }
        if discs.is_empty() && footprints.is_empty() {
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
        if radius.is_none() && f.shapes.iter().any(|s| !matches!(s, Shape::Polygon(_))) {
            no_radius.push(f.label());
        }
        if height.is_none() {
            no_height.push(f.label());
        }
        let name = unique_name(f, stem, &mut names);
        let kind = f
            .property("kind")
            .and_then(text)
            .or_else(|| f.folder.clone());
        let several = discs.len() + footprints.len() > 1;
        let shapes = discs
            .into_iter()
            .map(|d| (d.center, d.radius, Vec::new()))
            .chain(footprints.into_iter().map(|v| {
                let (center, radius) = crate::base::geometry::bounding_circle(&v);
                (center, radius, v)
            }));
        let obstacles = shapes
            .enumerate()
            .map(|(k, (center, radius, footprint))| Obstacle {
                name: if several {
                    format!("{name} #{}", k + 1)
                } else {
                    name.clone()
                },
                center,
                radius,
                height: height.unwrap_or(default_height),
                footprint,
                base: base.unwrap_or(0.0),
                overfly: overfly.unwrap_or(true),
                clearance_above: 0.0,
                kind: kind.clone(),
                inspect: false,
                stand_off: None,
            })
            .collect();
        made.features.push(FeatureObstacles { name, obstacles });
    }
    if !problems.is_empty() {
        return Err(problems);
    }
    if !no_radius.is_empty() {
        made.warnings.push(format!(
            "no radius in {}: {DEFAULT_POINT_RADIUS} m assumed (set a `radius` property, metres)",
            listing(&no_radius)
        ));
    }
    if !no_height.is_empty() {
        made.warnings.push(format!(
            "no height in {}: {default_height} m assumed, {HEIGHT_ABOVE_BAND} m above the \
             altitude band so the plan goes round (set a `height` property, metres)",
            listing(&no_height)
        ));
    }
    Ok(made)
}

/// As the mission file writes it: the centre to 0.1 mm (a survey's points
/// are not known better; the file stays readable), the radius as given.
fn tidy(d: Disc) -> Disc {
    // Through the decimal text, so the file shows the short form.
    let short = |v: f64| format!("{v:.4}").parse().unwrap_or(v);
    Disc {
        center: Point2::new(short(d.center.x), short(d.center.y)),
        radius: d.radius,
    }
}

/// A few labels and how many more.
fn listing(labels: &[String]) -> String {
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

/// A positive number of metres from the feature's property `key` (a JSON
/// number, or text as KML's extended data holds it); a problem when it is
/// there but not one.
fn property(f: &Feature, key: &str, problems: &mut Vec<String>) -> Option<f64> {
    metres(f, key, |v| v > 0.0, "a positive number of metres", problems)
}

/// A height above the ground (0 allowed), metres.
fn ground_property(f: &Feature, key: &str, problems: &mut Vec<String>) -> Option<f64> {
    metres(
        f,
        key,
        |v| v >= 0.0,
        "a number of metres, 0 or more",
        problems,
    )
}

/// The finite number of property `key` that `fits`; a problem saying it
/// must be `what` when it is there but not one.
fn metres(
    f: &Feature,
    key: &str,
    fits: impl Fn(f64) -> bool,
    what: &str,
    problems: &mut Vec<String>,
) -> Option<f64> {
    let value = f.property(key)?;
    let number = match value {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => s.trim().parse::<f64>().ok(),
        Value::Null => return None,
        _ => None,
    };
    match number {
        Some(v) if v.is_finite() && fits(v) => Some(v),
        _ => {
            problems.push(format!(
                "{}: its `{key}` must be {what}, got {value}",
                f.label()
            ));
            None
        }
    }
}

/// A yes/no property (`true`, `false`, or their words).
fn flag(f: &Feature, key: &str, problems: &mut Vec<String>) -> Option<bool> {
    let value = f.property(key)?;
    let read = match value {
        Value::Bool(b) => Some(*b),
        Value::String(s) => match s.trim().to_ascii_lowercase().as_str() {
            "true" | "yes" | "1" => Some(true),
            "false" | "no" | "0" => Some(false),
            _ => None,
        },
        Value::Null => return None,
        _ => None,
    };
    if read.is_none() {
        problems.push(format!(
            "{}: its `{key}` must be true or false, got {value}",
            f.label()
        ));
    }
    read
}

/// The x-y box of the bounds as a polygon.
fn rectangle(b: &Bounds) -> Polygon<f64> {
    let ring = vec![
        Coord {
            x: b.x[0],
            y: b.y[0],
        },
        Coord {
            x: b.x[1],
            y: b.y[0],
        },
        Coord {
            x: b.x[1],
            y: b.y[1],
        },
        Coord {
            x: b.x[0],
            y: b.y[1],
        },
        Coord {
            x: b.x[0],
            y: b.y[0],
        },
    ];
    Polygon::new(LineString::new(ring), Vec::new())
}

/// A polygon's rings in ENU metres; `None` without an outer ring.
fn enu_polygon(
    rings: &[Vec<[f64; 2]>],
    enu: &dyn Fn(&[f64; 2]) -> Point2<f64>,
) -> Option<MultiPolygon<f64>> {
    let ring = |r: &Vec<[f64; 2]>| {
        LineString::new(
            r.iter()
                .map(|p| {
                    let q = enu(p);
                    Coord { x: q.x, y: q.y }
                })
                .collect(),
        )
    };
    let (outer, holes) = rings.split_first()?;
    let polygon = Polygon::new(ring(outer), holes.iter().map(ring).collect());
    Some(MultiPolygon::new(vec![polygon]))
}

/// A ring as a footprint: its vertices to 0.1 mm (the file shows the short
/// form), without the closing repeat or repeated vertices; `None` when
/// fewer than three remain.
fn footprint_of(ring: &LineString<f64>) -> Option<Vec<Point2<f64>>> {
    let short = |v: f64| format!("{v:.4}").parse().unwrap_or(v);
    let mut out: Vec<Point2<f64>> = Vec::new();
    for c in ring.coords() {
        let p = Point2::new(short(c.x), short(c.y));
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    if out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    (out.len() >= 3).then_some(out)
}

/// The parts of `line` inside `bounds`, their length and the length left
/// outside, metres.
fn clip_line(line: &[Point2<f64>], bounds: &Polygon<f64>) -> (Vec<Vec<Point2<f64>>>, f64, f64) {
    let length = |l: &[Point2<f64>]| l.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>();
    let whole = length(line);
    if line.len() < 2 {
        return (vec![line.to_vec()], 0.0, 0.0);
    }
    let input = MultiLineString::new(vec![LineString::new(
        line.iter().map(|p| Coord { x: p.x, y: p.y }).collect(),
    )]);
    let pieces: Vec<Vec<Point2<f64>>> = bounds
        .clip(&input, false)
        .0
        .into_iter()
        .map(|l| l.coords().map(|c| Point2::new(c.x, c.y)).collect())
        .filter(|l: &Vec<Point2<f64>>| !l.is_empty())
        .collect();
    let inside: f64 = pieces.iter().map(|p| length(p)).sum();
    (pieces, inside, (whole - inside).max(0.0))
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
        .flat_map(|s| match s {
            Shape::Point(p) => vec![*p],
            Shape::Line(l) => l.clone(),
            Shape::Polygon(r) => r.iter().flatten().copied().collect(),
        })
        .map(|[lon, lat]| (lon, lat, away(lon, lat)))
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
