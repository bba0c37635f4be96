//! Latitude/longitude positions in mission files.
//!
//! The start and goal, obstacle centres and the positions a pipeline's
//! section registers (`SECTION_POSITIONS`: the fleet's targets and initial
//! positions, FLATLO's start) may be written as WGS-84 latitude/longitude instead of
//! ENU metres:
//!
//! ```toml
//! start = { latitude = -33.875648, longitude = 151.191290, height = 10.0 }
//! center = { latitude = -33.875740, longitude = 151.191937 }
//! ```
//!
//! A point in the air gives `height` (metres above the ground: the mission's
//! z) or `altitude` (metres above the WGS-84 ellipsoid, as `[origin]` and the
//! exports' CSV); a point on the ground gives neither. Loading converts them
//! to ENU through `[origin]` ([`super::geodesy::Frame`]) in the spanned tree,
//! before the typed model is read: the rest of skyform sees metres only, and
//! every error still points at its line. [`Forms`] remembers which positions
//! the file wrote this way, so a save writes them back the same way.

use std::ops::Range;

use nalgebra::{Point2, Point3};
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::diagnostic::Diagnostic;
use super::geodesy::{Frame, Geodetic};
use super::model::{GeoOrigin, Mission};
use super::source::{FieldPath, PathSegment};

/// How a file wrote one position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// `{ latitude, longitude }`: a point of the ground plane.
    Ground,
    /// `{ latitude, longitude, altitude }`: metres above the ellipsoid.
    Altitude,
    /// `{ latitude, longitude, height }`: metres above the ground (z).
    Height,
}

/// A step of a position's place in the file.
#[derive(Debug, Clone, Copy)]
pub enum Step {
    Key(&'static str),
    /// Every element of an array.
    Each,
}

/// Where positions are, and whether they are in the air (x, y, z) or on
/// the ground (x, y).
pub struct Slot {
    pub steps: &'static [Step],
    pub air: bool,
}

/// The positions of a pipeline's own section that a file may write as
/// latitude/longitude (FLATLO's start, the fleet's targets), registered by
/// the pipeline's module (`#[linkme::distributed_slice(SECTION_POSITIONS)]`):
/// loading converts them and saving writes them back as every other
/// position, and this floor names no pipeline.
pub struct SectionPositions {
    /// Where they are in the file.
    pub slots: &'static [Slot],
    /// Each one of a mission in memory, at its path.
    pub positions: fn(&Mission) -> Vec<(FieldPath, Position)>,
}

/// Every registered section's positions.
#[linkme::distributed_slice]
pub static SECTION_POSITIONS: [SectionPositions];

/// The file's own slots, then every registered section's, in the order of
/// their sections' keys (the registry's order is the linker's).
fn slots() -> impl Iterator<Item = &'static Slot> {
    SLOTS.iter().chain(sections().flat_map(|s| s.slots.iter()))
}

/// The registered sections, in the order of their first slot's key.
fn sections() -> impl Iterator<Item = &'static SectionPositions> {
    let mut all: Vec<&SectionPositions> = SECTION_POSITIONS.iter().collect();
    all.sort_by_key(
        |s| match s.slots.first().and_then(|slot| slot.steps.first()) {
            Some(Step::Key(key)) => *key,
            _ => "",
        },
    );
    all.into_iter()
}

const SLOTS: [Slot; 3] = [
    Slot {
        steps: &[Step::Key("route"), Step::Key("start")],
        air: true,
    },
    Slot {
        steps: &[Step::Key("route"), Step::Key("goal")],
        air: true,
    },
    Slot {
        steps: &[Step::Key("obstacles"), Step::Each, Step::Key("center")],
        air: false,
    },
];

/// Metres from the origin beyond which a converted position is refused: the
/// ENU frame is a local plane (validation's limit on the bounds' span).
const REGION: f64 = 1e6;

/// Which positions a file wrote as latitude/longitude, and how many
/// elements its arrays of positions had (an element added later takes the
/// form of the file's last one).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Forms {
    written: Vec<(FieldPath, Form)>,
    lengths: Vec<(FieldPath, usize)>,
}

impl Forms {
    /// Whether the file wrote any position as latitude/longitude.
    pub fn any(&self) -> bool {
        !self.written.is_empty()
    }

    /// How the position at `path` is to be saved; `None`: ENU metres.
    pub fn form_of(&self, path: &FieldPath) -> Option<Form> {
        if let Some((_, form)) = self.written.iter().find(|(p, _)| p == path) {
            return Some(*form);
        }
        // An element the file did not have: like the file's last one.
        let at = path
            .0
            .iter()
            .position(|s| matches!(s, PathSegment::Index(_)))?;
        let PathSegment::Index(index) = path.0[at] else {
            return None;
        };
        let array = FieldPath(path.0[..at].to_vec());
        let (_, length) = self.lengths.iter().find(|(p, _)| *p == array)?;
        if index < *length || *length == 0 {
            return None;
        }
        let mut last = path.clone();
        last.0[at] = PathSegment::Index(length - 1);
        self.written
            .iter()
            .find(|(p, _)| *p == last)
            .map(|(_, form)| *form)
    }
}

/// One position found in the file as latitude/longitude.
struct Found {
    path: FieldPath,
    span: Range<usize>,
    form: Form,
    latitude: f64,
    longitude: f64,
    /// Altitude or height, by the form.
    up: f64,
}

/// What loading does to a file's latitude/longitude positions: each one's
/// place and the text of its ENU numbers ([`apply`] puts them in), and the
/// forms the file used.
#[derive(Debug, Default)]
pub struct Conversions {
    replacements: Vec<(FieldPath, Range<usize>, Vec<String>)>,
    pub forms: Forms,
}

/// Finds every latitude/longitude position of `root` (a mission file's
/// spanned tree) and converts it to ENU metres; [`apply`] writes them into
/// the tree. Fails with every problem found, each on its field: no
/// `[origin]`, a key missing or unknown, a number out of range, a point far
/// from the origin.
pub fn convert(root: &Spanned<DeTable<'_>>) -> Result<Conversions, Vec<Diagnostic>> {
    let mut found = Vec::new();
    let mut problems = Vec::new();
    let mut out = Conversions::default();
    for slot in slots() {
        visit(
            root.get_ref(),
            slot.steps,
            FieldPath::root(),
            &mut |path, value| {
                if let DeValue::Table(table) = value.get_ref() {
                    match read(table, slot.air, &path) {
                        Ok((form, latitude, longitude, up)) => found.push(Found {
                            path,
                            span: value.span(),
                            form,
                            latitude,
                            longitude,
                            up,
                        }),
                        Err(mut p) => problems.append(&mut p),
                    }
                }
            },
            &mut out.forms.lengths,
        );
    }
    if found.is_empty() {
        return if problems.is_empty() {
            Ok(out)
        } else {
            Err(problems)
        };
    }
    let frame = match origin(root.get_ref()) {
        Ok(origin) => Frame::new(&origin),
        Err(why) => {
            for f in &found {
                problems.push(Diagnostic::error(f.path.clone(), why.clone()));
            }
            return Err(problems);
        }
    };
    let terrain = root.get_ref().get("terrain").is_some();
    for f in &found {
        if f.form == Form::Altitude && terrain {
            problems.push(Diagnostic::error(
                f.path.key("altitude"),
                "with [terrain] every z is above the ground under it: give `height` \
                 (metres above the ground) instead of an ellipsoidal altitude",
            ));
            continue;
        }
        let values = enu(&frame, f);
        let distance = values[0].hypot(values[1]);
        if distance.is_nan() || distance > REGION {
            problems.push(Diagnostic::error(
                f.path.clone(),
                format!(
                    "latitude {}, longitude {} is {:.0} km from [origin]; positions are \
                     converted into its local ENU frame, which reaches 1,000 km (latitude \
                     and longitude swapped?)",
                    f.latitude,
                    f.longitude,
                    distance / 1e3
                ),
            ));
            continue;
        }
        // Rust's shortest round-trip text of a finite f64 is a TOML float.
        let texts = values.iter().map(|v| format!("{v:?}")).collect();
        out.replacements
            .push((f.path.clone(), f.span.clone(), texts));
        out.forms.written.push((f.path.clone(), f.form));
    }
    if problems.is_empty() {
        Ok(out)
    } else {
        Err(problems)
    }
}

/// `root` with every converted position in ENU metres: an array spanning
/// the table it replaces, so a later error on it points at the same place.
/// (The numbers borrow their text from `conversions`.)
pub fn apply<'a>(
    mut root: Spanned<DeTable<'a>>,
    conversions: &'a Conversions,
) -> Spanned<DeTable<'a>> {
    for (path, span, texts) in &conversions.replacements {
        let items = texts
            .iter()
            .filter_map(|t| DeValue::parse(t).ok())
            .map(|v| Spanned::new(span.clone(), v.into_inner()))
            .collect();
        if let Some(place) = value_at_mut(root.get_mut(), &path.0) {
            *place = Spanned::new(span.clone(), DeValue::Array(items));
        }
    }
    root
}

/// ENU metres of a found position: x, y on the ground, and z in the air.
fn enu(frame: &Frame, f: &Found) -> Vec<f64> {
    match f.form {
        Form::Ground => {
            let p = frame.ground_to_enu(f.latitude, f.longitude);
            vec![p.x, p.y]
        }
        Form::Height => {
            let p = frame.ground_to_enu(f.latitude, f.longitude);
            vec![p.x, p.y, f.up]
        }
        Form::Altitude => {
            let p = frame.to_enu(&Geodetic {
                latitude: f.latitude,
                longitude: f.longitude,
                altitude: f.up,
            });
            vec![p.x, p.y, p.z]
        }
    }
}

/// Calls `each` on every value at `steps` below `table`; records the length
/// of the arrays it steps through.
fn visit<'a, 'i>(
    table: &'a DeTable<'i>,
    steps: &[Step],
    path: FieldPath,
    each: &mut dyn FnMut(FieldPath, &'a Spanned<DeValue<'i>>),
    lengths: &mut Vec<(FieldPath, usize)>,
) {
    let Some((Step::Key(key), rest)) = steps.split_first() else {
        return;
    };
    let Some(value) = table.get(*key) else { return };
    let path = path.key(key);
    visit_value(value, rest, path, each, lengths);
}

fn visit_value<'a, 'i>(
    value: &'a Spanned<DeValue<'i>>,
    steps: &[Step],
    path: FieldPath,
    each: &mut dyn FnMut(FieldPath, &'a Spanned<DeValue<'i>>),
    lengths: &mut Vec<(FieldPath, usize)>,
) {
    match (steps.first(), value.get_ref()) {
        (None, _) => each(path, value),
        (Some(Step::Key(_)), DeValue::Table(t)) => visit(t, steps, path, each, lengths),
        (Some(Step::Each), DeValue::Array(items)) => {
            if !lengths.iter().any(|(p, _)| *p == path) {
                lengths.push((path.clone(), items.len()));
            }
            for (i, item) in items.iter().enumerate() {
                visit_value(item, &steps[1..], path.index(i), each, lengths);
            }
        }
        _ => {}
    }
}

/// The numbers of a `{ latitude, longitude[, altitude | height] }` table.
fn read(
    table: &DeTable<'_>,
    air: bool,
    path: &FieldPath,
) -> Result<(Form, f64, f64, f64), Vec<Diagnostic>> {
    let mut problems = Vec::new();
    let allowed: &[&str] = if air {
        &["latitude", "longitude", "altitude", "height"]
    } else {
        &["latitude", "longitude"]
    };
    for (key, _) in table.iter() {
        let key = key.get_ref().as_ref();
        if !allowed.contains(&key) {
            let what = if air {
                "a position in the air has latitude, longitude and height (above the ground) \
                 or altitude (above the WGS-84 ellipsoid)"
            } else {
                "a position on the ground has latitude and longitude only"
            };
            problems.push(Diagnostic::error(
                path.key(key),
                format!("unknown key `{key}`: {what}"),
            ));
        }
    }
    let mut number = |key: &str, required: bool| -> Option<f64> {
        let Some(value) = table.get(key) else {
            if required {
                problems.push(Diagnostic::error(
                    path.clone(),
                    format!("a latitude/longitude position needs `{key}`"),
                ));
            }
            return None;
        };
        let v = match value.get_ref() {
            DeValue::Float(f) => f.as_str().parse::<f64>().ok(),
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|i| i as f64),
            _ => None,
        };
        match v {
            Some(v) if v.is_finite() => Some(v),
            _ => {
                problems.push(Diagnostic::error(
                    path.key(key),
                    format!(
                        "must be a finite number, got {}",
                        value.get_ref().type_str()
                    ),
                ));
                None
            }
        }
    };
    let latitude = number("latitude", true);
    let longitude = number("longitude", true);
    let (altitude, height) = (number("altitude", false), number("height", false));
    let form = match (air, altitude, height) {
        (false, _, _) => Some((Form::Ground, 0.0)),
        (true, Some(a), None) => Some((Form::Altitude, a)),
        (true, None, Some(h)) => Some((Form::Height, h)),
        (true, Some(_), Some(_)) => {
            problems.push(Diagnostic::error(
                path.clone(),
                "gives both `altitude` and `height`: one says where the point is",
            ));
            None
        }
        (true, None, None) => {
            if table.get("altitude").is_none() && table.get("height").is_none() {
                problems.push(Diagnostic::error(
                    path.clone(),
                    "needs `height` (metres above the ground, the mission's z) or `altitude` \
                     (metres above the WGS-84 ellipsoid, as [origin])",
                ));
            }
            None
        }
    };
    if let Some(lat) = latitude
        && lat.abs() > 90.0
    {
        let hint = if longitude.is_some_and(|lon| lon.abs() <= 90.0) {
            " (latitude and longitude swapped?)"
        } else {
            ""
        };
        problems.push(Diagnostic::error(
            path.key("latitude"),
            format!("must be within ±90°, got {lat}{hint}"),
        ));
    }
    if let Some(lon) = longitude
        && lon.abs() > 180.0
    {
        problems.push(Diagnostic::error(
            path.key("longitude"),
            format!("must be within ±180°, got {lon}"),
        ));
    }
    match (problems.is_empty(), form, latitude, longitude) {
        (true, Some((form, up)), Some(lat), Some(lon)) => Ok((form, lat, lon, up)),
        _ => Err(problems),
    }
}

/// The file's `[origin]`, or why a latitude/longitude position cannot be
/// converted.
fn origin(root: &DeTable<'_>) -> Result<GeoOrigin, String> {
    let Some(value) = root.get("origin") else {
        return Err(
            "a latitude/longitude position needs the mission's [origin] (the WGS-84 \
                    latitude, longitude and altitude of the ENU origin): add it, or give \
                    the position in ENU metres"
                .into(),
        );
    };
    let number = |key: &str| -> Option<f64> {
        let DeValue::Table(t) = value.get_ref() else {
            return None;
        };
        match t.get(key)?.get_ref() {
            DeValue::Float(f) => f.as_str().parse().ok(),
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|i| i as f64),
            _ => None,
        }
    };
    match (number("latitude"), number("longitude")) {
        (Some(latitude), Some(longitude)) if latitude.abs() <= 90.0 && longitude.abs() <= 180.0 => {
            Ok(GeoOrigin {
                latitude,
                longitude,
                altitude: number("altitude").unwrap_or(0.0),
            })
        }
        _ => Err("a latitude/longitude position needs a valid [origin] \
                  (latitude within ±90°, longitude within ±180°)"
            .into()),
    }
}

/// The value at `segments` below `table`.
fn value_at_mut<'t, 'i>(
    table: &'t mut DeTable<'i>,
    segments: &[PathSegment],
) -> Option<&'t mut Spanned<DeValue<'i>>> {
    let (PathSegment::Key(key), rest) = segments.split_first()? else {
        return None;
    };
    let mut value = table.get_mut(key.as_str())?;
    for segment in rest {
        value = match (segment, value.get_mut()) {
            (PathSegment::Key(k), DeValue::Table(t)) => t.get_mut(k.as_str())?,
            (PathSegment::Index(i), DeValue::Array(items)) => items.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(value)
}

/// A position of the mission in memory (ENU metres), at its path.
pub enum Position {
    Ground(Point2<f64>),
    Air(Point3<f64>),
}

/// Every position of `m` that a file may write as latitude/longitude.
fn positions(m: &Mission) -> Vec<(FieldPath, Position)> {
    let root = FieldPath::root();
    let mut out = vec![
        (root.key("route").key("start"), Position::Air(m.route.start)),
        (root.key("route").key("goal"), Position::Air(m.route.goal)),
    ];
    for (i, o) in m.obstacles.iter().enumerate() {
        let path = root.key("obstacles").index(i).key("center");
        out.push((path, Position::Ground(o.center)));
    }
    for section in sections() {
        out.extend((section.positions)(m));
    }
    out
}

/// Writes into `tree` (the mission `m` as a TOML tree, ENU) every position
/// that `forms` says the file wrote as latitude/longitude, in that form,
/// through `m`'s origin. Without an origin the tree stays in metres.
pub fn write_forms(tree: &mut toml::Table, m: &Mission, forms: &Forms) {
    let Some(origin) = &m.origin else { return };
    if !forms.any() {
        return;
    }
    let frame = Frame::new(origin);
    for (path, position) in positions(m) {
        let Some(form) = forms.form_of(&path) else {
            continue;
        };
        let mut table = toml::Table::new();
        let mut put = |key: &str, v: f64| {
            table.insert(key.to_owned(), toml::Value::Float(v));
        };
        match (form, position) {
            (Form::Ground, Position::Ground(p)) => {
                let g = frame.ground_to_geodetic(&p);
                put("latitude", g.latitude);
                put("longitude", g.longitude);
            }
            (Form::Altitude, Position::Air(p)) => {
                let g = frame.to_geodetic(&p);
                put("latitude", g.latitude);
                put("longitude", g.longitude);
                put("altitude", g.altitude);
            }
            (Form::Height, Position::Air(p)) => {
                let g = frame.ground_to_geodetic(&p.xy());
                put("latitude", g.latitude);
                put("longitude", g.longitude);
                put("height", p.z);
            }
            _ => continue,
        }
        if let Some(place) = tree_value_mut(tree, &path.0) {
            *place = toml::Value::Table(table);
        }
    }
}

/// The value at `segments` in a TOML tree.
fn tree_value_mut<'t>(
    table: &'t mut toml::Table,
    segments: &[PathSegment],
) -> Option<&'t mut toml::Value> {
    let (PathSegment::Key(key), rest) = segments.split_first()? else {
        return None;
    };
    let mut value = table.get_mut(key)?;
    for segment in rest {
        value = match (segment, value) {
            (PathSegment::Key(k), toml::Value::Table(t)) => t.get_mut(k)?,
            (PathSegment::Index(i), toml::Value::Array(items)) => items.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(value)
}

/// Whether a TOML table is a latitude/longitude position.
pub fn is_position(table: &toml::Table) -> bool {
    table.contains_key("latitude") && table.contains_key("longitude")
}
