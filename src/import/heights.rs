//! How high a surveyed feature stands: its properties and the altitudes it
//! was drawn with, read the way the tool that drew it meant them.
//!
//! Readings (each named in the import's report, per feature):
//! - properties first: `height` (or `top`) is the top and `base` (or
//!   OpenStreetMap's and Overture's `min_height`) the underside, metres above
//!   the ground; `thickness` is a surface's depth below its altitude. A
//!   property the file writes is what the surveyor meant, even where the
//!   drawing says otherwise (the report says so);
//! - else the altitudes: relative to the ground as written; absolute (KML,
//!   above mean sea level) and GeoJSON's third coordinate (above the WGS-84
//!   ellipsoid, RFC 7946 §3.1.1) less the origin's altitude and the terrain
//!   under the point: `[origin] altitude` must be the ground's in the
//!   survey's datum;
//! - a point stands on the ground up to its altitude (a mast, a tree),
//!   extruded or not: a point in the air is no obstacle of any size;
//! - a polygon extruded (KML `extrude`) stands on the ground up to its
//!   altitude; one not extruded is a surface at its altitude (a deck): a
//!   slab between its lowest and highest altitude when they differ, else
//!   resting on what the same survey stands under it (a deck on its piers,
//!   down to their highest top), else `DEFAULT_DECK_THICKNESS` deep, with a
//!   warning. GeoJSON has no `extrude`: a polygon there stands on the
//!   ground (a building's roof height) unless it rests on the survey's
//!   lower features;
//! - a line not extruded with altitudes, or one the survey marks as a power
//!   line or a cable (OpenStreetMap's `power=line`, `minor_line`, an
//!   overhead `cable`, an `aerialway`; a kind or folder that says "power
//!   line", "wire" or "cable"), is a wire at its height, never a fence;
//!   another line is a row of posts up to its altitude (a fence, a hedge).

use serde_json::Value;

use super::{AltitudeMode, Drawn, Feature};

/// A surface's depth below its altitude when nothing says how deep it is
/// and nothing of the survey stands under it, metres.
pub const DEFAULT_DECK_THICKNESS: f64 = 1.0;

/// A wire's radius without a `radius` property, metres: the room round its
/// conductor (their spread and sway), beyond r_Q and the margins.
pub const DEFAULT_WIRE_RADIUS: f64 = crate::mission::DEFAULT_WIRE_RADIUS;

/// A sloped span is cut into pieces that rise at most this much, metres,
/// so the box each piece is kept as is never much taller than the wire.
pub const WIRE_PIECE_RISE: f64 = 1.0;

/// The heights a feature's properties give, metres above the ground.
#[derive(Debug, Clone, Copy, Default)]
pub struct Props {
    pub radius: Option<f64>,
    pub top: Option<f64>,
    pub base: Option<f64>,
    pub thickness: Option<f64>,
    pub overfly: Option<bool>,
}

impl Props {
    /// Reads them, a problem for each that is there but not a number.
    pub fn read(f: &Feature, problems: &mut Vec<String>) -> Props {
        let top = positive(f, "height", problems).or_else(|| positive(f, "top", problems));
        let base = ground(f, "base", problems).or_else(|| ground(f, "min_height", problems));
        if let (Some(b), Some(h)) = (base, top)
            && b >= h
        {
            problems.push(format!(
                "{}: its base {b} m is at or above its top {h} m",
                f.label()
            ));
        }
        Props {
            radius: positive(f, "radius", problems),
            top,
            base,
            thickness: positive(f, "thickness", problems),
            overfly: flag(f, "overfly", problems),
        }
    }
}

/// How one feature's heights were read, for the report.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    /// `feature 4 'pier 3'`.
    pub label: String,
    /// What it became and from what: `a block from the ground to 22.000 m
    /// (its altitude, relativeToGround, extruded)`.
    pub text: String,
}

impl std::fmt::Display for Reading {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.label, self.text)
    }
}

/// Whether the survey marks the feature as a wire: a power line, an
/// overhead cable or an aerialway (OpenStreetMap's tags), or a kind or
/// folder that says so. `Err` for a cable that is not overhead (left out:
/// it is no obstacle in the air).
pub fn marked_wire(f: &Feature) -> Result<bool, String> {
    let tag = |key: &str| {
        f.property(key)
            .and_then(Value::as_str)
            .map(|s| s.trim().to_ascii_lowercase())
    };
    let location = tag("location");
    match tag("power").as_deref() {
        Some("line" | "minor_line") => return Ok(true),
        Some("cable") => {
            return match location.as_deref() {
                Some("overhead") => Ok(true),
                _ => Err(
                    "a power cable not tagged location=overhead (OpenStreetMap: underground \
                     unless said): no obstacle in the air"
                        .into(),
                ),
            };
        }
        _ => {}
    }
    if tag("aerialway").is_some_and(|a| !a.is_empty() && a != "no" && a != "station") {
        return Ok(true);
    }
    let words = [
        "power line",
        "powerline",
        "power-line",
        "overhead line",
        "wire",
        "cable",
    ];
    let says = |text: Option<String>| {
        text.is_some_and(|t| {
            let t = t.to_ascii_lowercase();
            words.iter().any(|w| t.contains(w))
        })
    };
    Ok(says(tag("kind")) || says(f.folder.clone()))
}

/// A position's altitude as metres above the ground under it, as `mode`
/// means it; `None` without one or clamped to the ground. `origin` is the
/// mission's origin altitude, `ground` the terrain's height there (ENU).
pub fn above_ground(alt: Option<f64>, mode: AltitudeMode, origin: f64, ground: f64) -> Option<f64> {
    let a = alt?;
    match mode {
        AltitudeMode::ClampToGround => None,
        AltitudeMode::RelativeToGround => Some(a),
        AltitudeMode::AboveSeaLevel | AltitudeMode::AboveEllipsoid => Some(a - origin - ground),
    }
}

/// Why the drawing's altitudes were read so, in words: `relativeToGround,
/// extruded`.
pub fn how_drawn(d: &Drawn, origin: f64) -> String {
    let mode = match d.vertical.mode {
        AltitudeMode::AboveSeaLevel | AltitudeMode::AboveEllipsoid => {
            format!(
                "{}, less the origin's {}",
                d.vertical.mode.name(),
                metres(origin)
            )
        }
        other => other.name().to_owned(),
    };
    match d.vertical.extrude {
        Some(true) => format!("{mode}, extruded"),
        Some(false) => format!("{mode}, not extruded"),
        None => mode,
    }
}

/// Metres as the report writes them: to the millimetre, trailing zeros off.
pub fn metres(v: f64) -> String {
    let text = format!("{:.3}", round_mm(v));
    let text = text.trim_end_matches('0').trim_end_matches('.');
    format!("{text} m")
}

/// To the millimetre, as the mission file is written (a survey is not
/// known better, and the file stays readable).
pub fn round_mm(v: f64) -> f64 {
    let r = (v * 1000.0).round() / 1000.0;
    if r == 0.0 { 0.0 } else { r }
}

/// A positive number of metres from property `key`.
fn positive(f: &Feature, key: &str, problems: &mut Vec<String>) -> Option<f64> {
    number(f, key, |v| v > 0.0, "a positive number of metres", problems)
}

/// A height above the ground (0 allowed), metres.
fn ground(f: &Feature, key: &str, problems: &mut Vec<String>) -> Option<f64> {
    number(
        f,
        key,
        |v| v >= 0.0,
        "a number of metres, 0 or more",
        problems,
    )
}

/// The finite number of property `key` that `fits` (a JSON number, or
/// text as KML's extended data holds it); a problem saying it must be
/// `what` when it is there but not one.
fn number(
    f: &Feature,
    key: &str,
    fits: impl Fn(f64) -> bool,
    what: &str,
    problems: &mut Vec<String>,
) -> Option<f64> {
    let value = f.property(key)?;
    let parsed = match value {
        Value::Number(n) => n.as_f64(),
        Value::String(s) if s.trim().is_empty() => return None,
        // OpenStreetMap writes `height = "12 m"` at times.
        Value::String(s) => s.trim().trim_end_matches('m').trim().parse::<f64>().ok(),
        Value::Null => return None,
        _ => None,
    };
    match parsed {
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

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn feature(properties: Value, folder: Option<&str>) -> Feature {
        Feature {
            number: 1,
            name: Some("x".into()),
            properties: properties.as_object().cloned().unwrap_or_default(),
            folder: folder.map(str::to_owned),
            ..Feature::default()
        }
    }

    #[test]
    fn power_lines_and_overhead_cables_are_wires_an_underground_cable_is_none() {
        let wire = |p: Value, folder: Option<&str>| marked_wire(&feature(p, folder));
        assert_eq!(wire(json!({"power": "line"}), None), Ok(true));
        assert_eq!(wire(json!({"power": "minor_line"}), None), Ok(true));
        assert_eq!(
            wire(json!({"power": "cable", "location": "overhead"}), None),
            Ok(true)
        );
        assert!(wire(json!({"power": "cable"}), None).is_err());
        assert_eq!(wire(json!({"aerialway": "chair_lift"}), None), Ok(true));
        assert_eq!(wire(json!({"kind": "11 kV Power Line"}), None), Ok(true));
        assert_eq!(wire(json!({}), Some("Overhead lines")), Ok(true));
        assert_eq!(wire(json!({"kind": "fence"}), Some("Walls")), Ok(false));
    }

    #[test]
    fn altitudes_are_above_the_ground_as_their_mode_means() {
        let (origin, ground) = (12.0, 1.5);
        assert_eq!(
            above_ground(Some(30.0), AltitudeMode::RelativeToGround, origin, ground),
            Some(30.0)
        );
        assert_eq!(
            above_ground(Some(30.0), AltitudeMode::AboveSeaLevel, origin, ground),
            Some(16.5)
        );
        assert_eq!(
            above_ground(Some(30.0), AltitudeMode::AboveEllipsoid, origin, ground),
            Some(16.5)
        );
        assert_eq!(
            above_ground(Some(30.0), AltitudeMode::ClampToGround, origin, ground),
            None
        );
        assert_eq!(
            above_ground(None, AltitudeMode::RelativeToGround, origin, ground),
            None
        );
    }

    #[test]
    fn heights_are_read_from_properties_in_metres_and_to_the_millimetre() {
        let mut problems = Vec::new();
        let f = feature(
            json!({"height": "12 m", "min_height": 3, "radius": "0.4"}),
            None,
        );
        let p = Props::read(&f, &mut problems);
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(
            (p.top, p.base, p.radius),
            (Some(12.0), Some(3.0), Some(0.4))
        );
        assert_eq!(round_mm(0.000_299_999_999_999_300_8), 0.0);
        assert_eq!(round_mm(12.345_67), 12.346);
        assert_eq!(metres(22.0), "22 m");
        assert_eq!(metres(0.5004), "0.5 m");
    }
}
