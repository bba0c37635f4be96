//! What can be selected, and the inspector's editable fields for each,
//! declared once as data.
//!
//! Each kind of item has a table of fields: a name and a unit, where the
//! field is in the mission (keys below the table's base path: a typed
//! [`FieldPath`], the one the validator reports its diagnostics on), and
//! how it is read and written as text. Typing a value, pasting one and a
//! test all go through the same `set`; a validation message is drawn where
//! its path says ([`place`]: under the field at that path, after the group
//! of fields that are that array's elements, or with the item at that path).
//! The tables themselves are in `fields/table.rs`.

use nalgebra::Point2;

use crate::mission::{FieldPath, Mission, Obstacle, PathSegment, ShapeChoice, WaypointChoice};
use crate::pipelines::Kind;
use crate::pipelines::points::PointKind;
use crate::pipelines::points::{self, PointRef};
use crate::pipelines::rows::{PointRow, Row};
pub use crate::pipelines::rows::{fmt_num, number};
use crate::pipelines::theta_pso::Iwp;

mod table;

/// Something the operator can select on the map, in the formation editor or
/// in the item list.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    Mission,
    Bounds,
    Start,
    Goal,
    /// A place the route must take (`[[route.via]]`, its index): a gate
    /// between two obstacles, or a point.
    Via(usize),
    /// The `[terrain]` height map (listed when the mission has one).
    Terrain,
    Obstacle(usize),
    /// Vertex `1` of obstacle `0`'s footprint.
    Vertex(usize, usize),
    Formation,
    Slot(usize),
    /// The IWP between these two obstacles (eq. 9): its reconfiguration choice.
    Waypoint([String; 2]),
    /// A pipeline's own section (`[theta_pso]`, `[flatlo]`, `[fleet]`).
    Section(Kind),
    /// A point of a pipeline's section the map draws (a fleet target).
    Point(PointRef),
    /// The air and autopilots of the flight check (`[flight]`).
    Flight,
}

impl Item {
    pub fn title(&self, mission: &Mission) -> String {
        match self {
            Item::Mission => "Mission".into(),
            Item::Bounds => "Bounds".into(),
            Item::Start => "Start".into(),
            Item::Goal => "Goal".into(),
            Item::Via(i) => match mission.route.via.get(*i) {
                Some(v) => format!("Route via {} ({})", i + 1, v.label()),
                None => format!("Route via {}", i + 1),
            },
            Item::Terrain => "Terrain".into(),
            Item::Obstacle(i) => match mission.obstacles.get(*i) {
                Some(o) => format!("Obstacle {} '{}'", i + 1, o.name),
                None => format!("Obstacle {}", i + 1),
            },
            Item::Vertex(i, v) => match mission.obstacles.get(*i) {
                Some(o) => format!("Vertex {} of '{}'", v + 1, o.name),
                None => format!("Vertex {} of obstacle {}", v + 1, i + 1),
            },
            Item::Formation => "Formation".into(),
            Item::Slot(i) => format!("Slot {} (UAV {})", i + 1, i + 1),
            Item::Waypoint([a, b]) => format!("IWP {a} ↔ {b}"),
            Item::Section(k) => k.words().section.1.into(),
            Item::Point(p) => p.title(),
            Item::Flight => "Flight check (air, GNSS)".into(),
        }
    }

    /// Whether the item still exists in `mission` (after an undo, say).
    pub fn exists(&self, mission: &Mission) -> bool {
        match self {
            Item::Obstacle(i) => *i < mission.obstacles.len(),
            Item::Vertex(i, v) => mission
                .obstacles
                .get(*i)
                .is_some_and(|o| *v < o.footprint.len()),
            Item::Slot(i) => *i < mission.formation.slots.len(),
            Item::Point(p) => p.exists(mission),
            Item::Via(i) => *i < mission.route.via.len(),
            Item::Terrain => mission.terrain.is_some(),
            Item::Waypoint([a, b]) => {
                let named = |n: &String| mission.obstacles.iter().any(|o| &o.name == n);
                (named(a) && named(b)) || mission.reconfiguration.position(a, b).is_some()
            }
            _ => true,
        }
    }

    /// Where the item is in `m`: the messages under it that no field shows
    /// are listed below its fields. None for the mission (its fields span
    /// the file) and for an IWP without an entry yet.
    pub fn path(&self, m: &Mission) -> Option<FieldPath> {
        let root = FieldPath::root();
        Some(match self {
            Item::Waypoint(_) => root
                .key("reconfiguration")
                .key("waypoints")
                .index(self.index(m)?),
            Item::Obstacle(i) => root.key("obstacles").index(*i),
            Item::Vertex(i, v) => root.key("obstacles").index(*i).key("footprint").index(*v),
            Item::Bounds => root.key("bounds"),
            Item::Start => root.key("route").key("start"),
            Item::Goal => root.key("route").key("goal"),
            Item::Via(i) => root.key("route").key("via").index(*i),
            Item::Terrain => root.key("terrain"),
            Item::Formation => root.key("formation"),
            Item::Slot(i) => root.key("formation").key("slots").index(*i),
            Item::Section(k) => root.key(k.words().section.0),
            Item::Flight => root.key("flight"),
            Item::Point(p) => {
                let [section, list] = p.kind()?.path;
                root.key(section).key(list).index(p.index)
            }
            Item::Mission => return None,
        })
    }

    /// The item's index in its list of the mission (an IWP's: its entry in
    /// `reconfiguration.waypoints`, if it has one yet).
    fn index(&self, m: &Mission) -> Option<usize> {
        match self {
            Item::Obstacle(i) | Item::Slot(i) | Item::Via(i) | Item::Vertex(i, _) => Some(*i),
            Item::Point(p) => Some(p.index),
            Item::Waypoint([a, b]) => m.reconfiguration.position(a, b),
            _ => None,
        }
    }
}

/// The items the map's next/previous keys cycle through, in order.
pub fn map_items(mission: &Mission) -> Vec<Item> {
    let mut items = vec![Item::Mission, Item::Bounds, Item::Start, Item::Goal];
    items.extend((0..mission.route.via.len()).map(Item::Via));
    if mission.terrain.is_some() {
        items.push(Item::Terrain);
    }
    items.extend((0..mission.obstacles.len()).map(Item::Obstacle));
    for k in Kind::ALL {
        items.push(Item::Section(k));
        items.extend(points::points_of(mission, k).into_iter().map(Item::Point));
    }
    items.push(Item::Flight);
    items
}

/// The items of the formation editor: the formation, its slots, the IWPs,
/// and every IWP choice of the file that is not one of them (it names a
/// missing obstacle, or has an invalid value): listed so it can be fixed or
/// deleted rather than leave the mission invalid beyond repair.
pub fn formation_items(mission: &Mission, iwps: &[Iwp]) -> Vec<Item> {
    let mut items = vec![Item::Formation];
    items.extend((0..mission.formation.slots.len()).map(Item::Slot));
    items.extend(iwps.iter().map(|w| Item::Waypoint(w.between.clone())));
    for choice in &mission.reconfiguration.waypoints {
        let listed = iwps
            .iter()
            .any(|w| choice.is_between(&w.between[0], &w.between[1]));
        if !listed {
            items.push(Item::Waypoint(choice.between.clone()));
        }
    }
    items
}

/// A step of a table's base path: a key, or the selected item's index in
/// its list.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Step {
    Key(&'static str),
    Index,
    /// The selected vertex's index in its footprint.
    Vertex,
}

/// One field of the inspector, declared once.
struct Spec {
    name: &'static str,
    /// Shown after the name, in parentheses; empty for none.
    unit: &'static str,
    /// Keys below the table's base: where the field is in the mission.
    keys: &'static [&'static str],
    /// The value as it would be typed; None when the item is not in the
    /// mission (any more).
    get: fn(&Mission, &Item) -> Option<String>,
    /// Writes the (trimmed) text into the item, parsed; the error says what
    /// is expected, or that the item is gone.
    set: fn(&mut Mission, &Item, &str) -> Result<(), String>,
}

/// The fields of one kind of item, below one base path.
struct Table {
    base: &'static [Step],
    /// Fields worked out from others (the formation's preset, UAVs and
    /// spacing, all from its slots), shown first; each is at its keys'
    /// path (they share keys without being an array's elements).
    derived: &'static [Spec],
    fields: &'static [Spec],
}

impl Table {
    /// Where `spec` is in `m` for `item`. An IWP without an entry yet is
    /// where its entry will go (the end of the list), so it claims no other
    /// entry's messages. Fields of one table that share their keys are the
    /// elements of that array, in order (x min, x max; x, y, z), as the
    /// validator indexes them (`bounds.x[1]`).
    fn path(&self, spec: &Spec, item: &Item, m: &Mission) -> FieldPath {
        let mut path = FieldPath::root();
        for step in self.base {
            path = match step {
                Step::Key(key) => path.key(key),
                // Only an IWP can lack an index: its entry is not made yet.
                Step::Index => {
                    path.index(item.index(m).unwrap_or(m.reconfiguration.waypoints.len()))
                }
                Step::Vertex => match item {
                    Item::Vertex(_, v) => path.index(*v),
                    _ => path,
                },
            };
        }
        let path = spec.keys.iter().fold(path, |p, key| p.key(key));
        if self.derived.iter().any(|s| std::ptr::eq(s, spec)) {
            return path;
        }
        element(path, self.fields, spec, |s| s.keys)
    }
}

/// `path`, indexed as an array's element when other fields of `all` share
/// `this`'s keys: fields that share their keys are that array's elements,
/// in order (x min, x max; x, y, z), as the validator indexes them.
fn element<T>(
    path: FieldPath,
    all: &[T],
    this: &T,
    keys: fn(&T) -> &'static [&'static str],
) -> FieldPath {
    let mut siblings = all.iter().filter(|s| keys(s) == keys(this));
    let index = siblings.clone().position(|s| std::ptr::eq(s, this));
    match (siblings.nth(1), index) {
        (Some(_), Some(i)) => path.index(i),
        _ => path,
    }
}

/// Where a field is declared: a row of the inspector's own tables, or a
/// row of a pipeline's section (`Pipeline::rows`).
#[derive(Clone, Copy)]
enum Source {
    Spec(&'static Spec),
    Row(&'static Row),
    /// A row of the point at this index of its list.
    Point(&'static PointRow, usize),
}

/// One editable line of the inspector: a field of the table, with the path
/// and value it has for the selected item.
#[derive(Clone)]
pub struct Field {
    source: Source,
    label: String,
    path: FieldPath,
    value: String,
}

impl std::fmt::Debug for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} = {} ({})", self.label, self.value, self.path)
    }
}

impl Field {
    /// The name with its unit, as the inspector shows it: `radius (m)`.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The unit alone (`m`, `m/s`, `°`); empty for none.
    pub fn unit(&self) -> &'static str {
        match self.source {
            Source::Spec(spec) => spec.unit,
            Source::Row(row) => row.unit,
            Source::Point(row, _) => row.unit,
        }
    }

    /// Where the field is in the mission; [`place`] says which
    /// diagnostics are shown under it.
    pub fn path(&self) -> &FieldPath {
        &self.path
    }

    /// Current value, as it would be typed.
    pub fn value(&self) -> &str {
        &self.value
    }

    /// Parses `text` and writes it into `mission`; the error says what is expected.
    pub fn set(&self, mission: &mut Mission, item: &Item, text: &str) -> Result<(), String> {
        match self.source {
            Source::Spec(spec) => (spec.set)(mission, item, text.trim()),
            Source::Row(row) => (row.set)(mission, text.trim()),
            Source::Point(row, i) => (row.set)(mission, i, text.trim()),
        }
    }
}

/// The inspector's fields for `item`, with the values they have in
/// `mission` (none for an item that is not in it).
pub fn fields(item: &Item, mission: &Mission) -> Vec<Field> {
    if let Item::Section(kind) = item {
        return section_fields(kind.face().rows(), kind.words().section.0, mission);
    }
    if let Item::Point(point) = item {
        return point
            .kind()
            .map_or_else(Vec::new, |kind| point_fields(kind, point.index, mission));
    }
    let table = table::of(item);
    table
        .derived
        .iter()
        .chain(table.fields)
        .filter_map(|spec| {
            Some(Field {
                source: Source::Spec(spec),
                label: label(spec.name, spec.unit),
                path: table.path(spec, item, mission),
                value: (spec.get)(mission, item)?,
            })
        })
        .collect()
}

/// The name with its unit: `radius (m)`.
fn label(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_owned()
    } else {
        format!("{name} ({unit})")
    }
}

/// Point `i`'s fields, its kind's rows below its table in the list
/// (`fleet.targets[1].position[0]`).
fn point_fields(kind: &PointKind, i: usize, mission: &Mission) -> Vec<Field> {
    let table = FieldPath::root()
        .key(kind.path[0])
        .key(kind.path[1])
        .index(i);
    kind.rows
        .iter()
        .filter_map(|row| {
            let path = row.keys.iter().fold(table.clone(), |p, k| p.key(k));
            Some(Field {
                source: Source::Point(row, i),
                label: label(row.name, row.unit),
                path: element(path, kind.rows, row, |r| r.keys),
                value: (row.get)(mission, i)?,
            })
        })
        .collect()
}

/// A pipeline's section's fields: its `rows` below `[key]` (`flatlo.start[1]`).
fn section_fields(rows: &'static [Row], key: &str, mission: &Mission) -> Vec<Field> {
    rows.iter()
        .filter_map(|row| {
            let path = row
                .keys
                .iter()
                .fold(FieldPath::root().key(key), |p, k| p.key(k));
            Some(Field {
                source: Source::Row(row),
                label: label(row.name, row.unit),
                path: element(path, rows, row, |r| r.keys),
                value: (row.get)(mission)?,
            })
        })
        .collect()
}

/// Where the inspector draws a message among an item's fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// Under this field.
    Field(usize),
    /// Under the fields `first..=last`, the elements of one array (x min
    /// and x max of `bounds.x`): after the last of them.
    Group(usize, usize),
    /// Below the item's fields, with the item (`route.start` under Start).
    Item,
}

impl Place {
    /// Whether a message here concerns field `k` (while it is typed into).
    pub fn covers(self, k: usize) -> bool {
        match self {
            Place::Field(f) => f == k,
            Place::Group(a, b) => (a..=b).contains(&k),
            Place::Item => false,
        }
    }

    /// After which field the message is drawn (`None`: after them all).
    pub fn after(self) -> Option<usize> {
        match self {
            Place::Field(k) | Place::Group(_, k) => Some(k),
            Place::Item => None,
        }
    }
}

/// Where a message at `path` is drawn for `item` (its `fields`), and
/// whether that place is at the message's own path. The place whose path
/// is the message's: its field, the group of its array's elements, the item
/// itself. Failing those (a message deeper than any field), the field it is
/// inside (the longest start of its path), else the item it is inside,
/// where it is listed with its path. `None`: it is another item's.
pub fn place(
    item: &Item,
    m: &Mission,
    fields: &[Field],
    path: &FieldPath,
) -> Option<(Place, bool)> {
    if let Some(k) = fields.iter().position(|f| f.path() == path) {
        return Some((Place::Field(k), true));
    }
    let elements: Vec<usize> = fields
        .iter()
        .enumerate()
        .filter(|(_, f)| {
            let p = &f.path().0;
            p.len() == path.0.len() + 1
                && f.path().starts_with(path)
                && matches!(p.last(), Some(PathSegment::Index(_)))
        })
        .map(|(k, _)| k)
        .collect();
    if let (Some(&a), Some(&b)) = (elements.first(), elements.last()) {
        return Some((Place::Group(a, b), true));
    }
    let item_path = item.path(m);
    if item_path.as_ref() == Some(path) {
        return Some((Place::Item, true));
    }
    let inside = fields
        .iter()
        .enumerate()
        .filter(|(_, f)| path.starts_with(f.path()))
        .max_by_key(|(k, f)| (f.path().0.len(), std::cmp::Reverse(*k)));
    if let Some((k, _)) = inside {
        return Some((Place::Field(k), false));
    }
    item_path
        .filter(|p| path.starts_with(p))
        .map(|_| (Place::Item, false))
}

pub fn shape_name(choice: ShapeChoice) -> &'static str {
    match choice {
        ShapeChoice::Auto => "auto",
        ShapeChoice::Alignment => "alignment",
        ShapeChoice::Rotation => "rotation",
        ShapeChoice::Shrink => "shrink",
    }
}

/// The shape after `choice` when cycling with one key.
pub fn next_shape(choice: ShapeChoice) -> ShapeChoice {
    match choice {
        ShapeChoice::Auto => ShapeChoice::Alignment,
        ShapeChoice::Alignment => ShapeChoice::Rotation,
        ShapeChoice::Rotation => ShapeChoice::Shrink,
        ShapeChoice::Shrink => ShapeChoice::Auto,
    }
}

/// The reconfiguration entry for an IWP, created with the defaults when the
/// file has none yet.
pub fn waypoint_choice<'m>(
    m: &'m mut Mission,
    item: &Item,
) -> Result<&'m mut WaypointChoice, String> {
    let Item::Waypoint(between) = item else {
        return Err("not an IWP".into());
    };
    let index = m.reconfiguration.position(&between[0], &between[1]);
    let list = &mut m.reconfiguration.waypoints;
    let index = match index {
        Some(i) => i,
        None => {
            list.push(WaypointChoice {
                between: between.clone(),
                enabled: true,
                shape: ShapeChoice::Auto,
                scale: None,
            });
            list.len() - 1
        }
    };
    Ok(&mut list[index])
}

/// A new obstacle at `center` with a name not yet used.
pub fn new_obstacle(mission: &Mission, center: Point2<f64>) -> Obstacle {
    let mut n = mission.obstacles.len() + 1;
    let taken = |name: &str| mission.obstacles.iter().any(|o| o.name == name);
    while taken(&format!("obstacle {n}")) {
        n += 1;
    }
    Obstacle::standing(
        format!("obstacle {n}"),
        center,
        1.0,
        (mission.bounds.z[1] + 1.0).max(1.0),
    )
}

/// A copy of `original` next to it, with a fresh name.
pub fn duplicate_obstacle(mission: &Mission, original: &Obstacle) -> Obstacle {
    let offset = 2.0 * original.radius + 1.0;
    let mut copy = original.clone();
    copy.move_to(copy.center + nalgebra::Vector2::new(offset, 0.0));
    let mut k = 2;
    while mission
        .obstacles
        .iter()
        .any(|o| o.name == format!("{} ({k})", original.name))
    {
        k += 1;
    }
    copy.name = format!("{} ({k})", original.name);
    copy
}

#[cfg(test)]
mod tests;
