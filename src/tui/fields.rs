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
    /// The `[terrain]` height map (listed when the mission has one).
    Terrain,
    Obstacle(usize),
    Formation,
    Slot(usize),
    /// The IWP between these two obstacles (eq. 9): its reconfiguration choice.
    Waypoint([String; 2]),
    ThetaPso,
    /// The FLATLO squadron and its aircraft model.
    Squadron,
    /// The distributed fleet's parameters.
    Fleet,
    /// One target of the fleet's timed sequence.
    FleetTarget(usize),
}

impl Item {
    pub fn title(&self, mission: &Mission) -> String {
        match self {
            Item::Mission => "Mission".into(),
            Item::Bounds => "Bounds".into(),
            Item::Start => "Start".into(),
            Item::Goal => "Goal".into(),
            Item::Terrain => "Terrain".into(),
            Item::Obstacle(i) => match mission.obstacles.get(*i) {
                Some(o) => format!("Obstacle {} '{}'", i + 1, o.name),
                None => format!("Obstacle {}", i + 1),
            },
            Item::Formation => "Formation".into(),
            Item::Slot(i) => format!("Slot {} (UAV {})", i + 1, i + 1),
            Item::Waypoint([a, b]) => format!("IWP {a} ↔ {b}"),
            Item::ThetaPso => "θ-PSO parameters".into(),
            Item::Squadron => "Squadron (FLATLO)".into(),
            Item::Fleet => "Fleet".into(),
            Item::FleetTarget(i) => format!("Fleet target {}", i + 1),
        }
    }

    /// Whether the item still exists in `mission` (after an undo, say).
    pub fn exists(&self, mission: &Mission) -> bool {
        match self {
            Item::Obstacle(i) => *i < mission.obstacles.len(),
            Item::Slot(i) => *i < mission.formation.slots.len(),
            Item::FleetTarget(i) => *i < mission.fleet.targets.len(),
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
            Item::Bounds => root.key("bounds"),
            Item::Start => root.key("route").key("start"),
            Item::Goal => root.key("route").key("goal"),
            Item::Terrain => root.key("terrain"),
            Item::Formation => root.key("formation"),
            Item::Slot(i) => root.key("formation").key("slots").index(*i),
            Item::ThetaPso => root.key("theta_pso"),
            Item::Squadron => root.key("flatlo"),
            Item::Fleet => root.key("fleet"),
            Item::FleetTarget(i) => root.key("fleet").key("targets").index(*i),
            Item::Mission => return None,
        })
    }

    /// The item's index in its list of the mission (an IWP's: its entry in
    /// `reconfiguration.waypoints`, if it has one yet).
    fn index(&self, m: &Mission) -> Option<usize> {
        match self {
            Item::Obstacle(i) | Item::Slot(i) | Item::FleetTarget(i) => Some(*i),
            Item::Waypoint([a, b]) => m.reconfiguration.position(a, b),
            _ => None,
        }
    }
}

/// The items the map's next/previous keys cycle through, in order.
pub fn map_items(mission: &Mission) -> Vec<Item> {
    let mut items = vec![Item::Mission, Item::Bounds, Item::Start, Item::Goal];
    if mission.terrain.is_some() {
        items.push(Item::Terrain);
    }
    items.extend((0..mission.obstacles.len()).map(Item::Obstacle));
    items.push(Item::ThetaPso);
    items.push(Item::Squadron);
    items.push(Item::Fleet);
    items.extend((0..mission.fleet.targets.len()).map(Item::FleetTarget));
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
#[derive(Debug, Clone, Copy)]
enum Step {
    Key(&'static str),
    Index,
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
            };
        }
        let path = spec.keys.iter().fold(path, |p, key| p.key(key));
        if self.derived.iter().any(|s| std::ptr::eq(s, spec)) {
            return path;
        }
        let mut siblings = self.fields.iter().filter(|s| s.keys == spec.keys);
        let element = siblings.clone().position(|s| std::ptr::eq(s, spec));
        match (siblings.nth(1), element) {
            (Some(_), Some(i)) => path.index(i),
            _ => path,
        }
    }
}

/// One editable line of the inspector: a field of the table, with the path
/// and value it has for the selected item.
#[derive(Clone)]
pub struct Field {
    spec: &'static Spec,
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
        self.spec.unit
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
        (self.spec.set)(mission, item, text.trim())
    }
}

/// The inspector's fields for `item`, with the values they have in
/// `mission` (none for an item that is not in it).
pub fn fields(item: &Item, mission: &Mission) -> Vec<Field> {
    let table = table::of(item);
    table
        .derived
        .iter()
        .chain(table.fields)
        .filter_map(|spec| {
            let value = (spec.get)(mission, item)?;
            let label = if spec.unit.is_empty() {
                spec.name.to_owned()
            } else {
                format!("{} ({})", spec.name, spec.unit)
            };
            Some(Field {
                spec,
                label,
                path: table.path(spec, item, mission),
                value,
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

/// Metres, degrees, gains: any finite number.
pub fn number(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        // `1e400` is a number, one too large for any field (Rust reads it
        // as infinity); `inf` and `nan` are not numbers a field takes.
        Ok(v) if v.is_infinite() && text.chars().any(|c| c.is_ascii_digit()) => Err(format!(
            "'{text}' is too large: the largest number a field holds is about 1.8e308"
        )),
        _ => Err(format!("'{text}' is not a number")),
    }
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

/// Formats a number the way it would be typed: exactly when that is short
/// (so opening a field and applying it changes nothing), else to 4 decimals.
pub fn fmt_num(v: f64) -> String {
    // Huge and tiny values in scientific notation: `1e300`, not 301 digits
    // (it reads back as typed).
    if v.is_finite() && v != 0.0 && !(1e-4..1e9).contains(&v.abs()) {
        return format!("{v:e}");
    }
    let exact = format!("{v}");
    let s = if exact.len() <= 12 {
        exact
    } else {
        let rounded = format!("{v:.4}");
        rounded
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_owned()
    };
    if s == "-0" { "0".into() } else { s }
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
    Obstacle {
        name: format!("obstacle {n}"),
        center,
        radius: 1.0,
        height: (mission.bounds.z[1] + 1.0).max(1.0),
        kind: None,
        inspect: false,
        stand_off: None,
    }
}

/// A copy of `original` next to it, with a fresh name.
pub fn duplicate_obstacle(mission: &Mission, original: &Obstacle) -> Obstacle {
    let offset = 2.0 * original.radius + 1.0;
    let mut copy = original.clone();
    copy.center.x += offset;
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
mod tests {
    use super::*;
    use crate::mission::default_mission;

    #[test]
    fn every_field_reads_back_what_it_writes() {
        let mut m = default_mission().mission;
        let items = [
            Item::Bounds,
            Item::Start,
            Item::Obstacle(0),
            Item::Formation,
            Item::Slot(1),
            Item::ThetaPso,
        ];
        for item in items {
            for (k, f) in fields(&item, &m).into_iter().enumerate() {
                let value = match f.label() {
                    l if l.contains("shape") => "shrink".to_string(),
                    "preset" => "diamond".to_string(),
                    "cost" => "paper".to_string(),
                    "encoding" => "angle".to_string(),
                    _ if f.value() == "yes" || f.value() == "no" => "yes".to_string(),
                    l if l.ends_with("lat (°)") || l.ends_with("lon (°)") => {
                        // A position nearby: 7° would be thousands of km off the site.
                        let now: f64 = f.value().parse().unwrap();
                        let typed = format!("{:.8}", now + 1e-4);
                        typed.trim_end_matches('0').trim_end_matches('.').to_owned()
                    }
                    _ => "7".to_string(),
                };
                f.set(&mut m, &item, &value).unwrap();
                assert_eq!(
                    fields(&item, &m)[k].value(),
                    value,
                    "{item:?} {}",
                    f.label()
                );
            }
        }
    }

    #[test]
    fn bad_text_is_refused_with_what_was_expected() {
        let mut m = default_mission().mission;
        let all = fields(&Item::Obstacle(0), &m);
        let radius = all.iter().find(|f| f.label() == "radius (m)").unwrap();
        let before = m.clone();
        let err = radius.set(&mut m, &Item::Obstacle(0), "wide").unwrap_err();
        assert_eq!(err, "'wide' is not a number");
        assert_eq!(m, before);
        assert!(radius.set(&mut m, &Item::Obstacle(0), "NaN").is_err());
    }

    #[test]
    fn an_iwp_choice_is_created_on_first_edit() {
        let mut m = default_mission().mission;
        m.reconfiguration.waypoints.clear();
        let item = Item::Waypoint(["pier 5".into(), "light pole 4".into()]);
        let shape = &fields(&item, &m)[2];
        assert_eq!(shape.label(), "shape");
        assert!(shape.set(&mut m, &item, "round").is_err());
        assert!(
            m.reconfiguration.waypoints.is_empty(),
            "not on a refused text"
        );
        shape.set(&mut m, &item, "rotation").unwrap();
        assert_eq!(m.reconfiguration.waypoints.len(), 1);
        assert_eq!(m.reconfiguration.waypoints[0].shape, ShapeChoice::Rotation);
        // Named the other way round, it is the same IWP.
        let item = Item::Waypoint(["light pole 4".into(), "pier 5".into()]);
        fields(&item, &m)[1].set(&mut m, &item, "no").unwrap();
        assert_eq!(m.reconfiguration.waypoints.len(), 1);
        assert!(!m.reconfiguration.waypoints[0].enabled);
    }

    /// The label of the field (or of the last field of the group) a
    /// message holding `message` is drawn under for `item`; "item" when it
    /// is drawn with the item.
    fn shown_under(item: &Item, m: &Mission, message: &str) -> Option<String> {
        let fields = fields(item, m);
        let d = crate::outcome::diagnose::diagnose(m)
            .into_iter()
            .find(|d| d.message.contains(message))?;
        let (place, _) = place(item, m, &fields, &d.path)?;
        Some(match place.after() {
            Some(k) => fields[k].label().to_owned(),
            None => "item".to_owned(),
        })
    }

    /// A message on one element of an array is under that element's field;
    /// one on the whole array after the group of its elements; an IWP's own
    /// entry's messages are under the IWP, and an IWP without an entry
    /// claims none.
    #[test]
    fn each_message_is_under_the_field_it_names() {
        let mut m = default_mission().mission;
        m.obstacles[3].stand_off = Some([1.0, f64::NAN]);
        assert_eq!(
            shown_under(&Item::Obstacle(3), &m, "finite").as_deref(),
            Some("stand-off max (m)")
        );
        m.obstacles[3].stand_off = Some([1.0, 5.0]);
        m.route.start.z = f64::INFINITY;
        assert_eq!(
            shown_under(&Item::Start, &m, "finite").as_deref(),
            Some("z (m)")
        );
        // Issue 24, item 6: the start's altitude out of the band is under z.
        m.route.start.z = 50.0;
        assert_eq!(
            shown_under(&Item::Start, &m, "altitude band").as_deref(),
            Some("z (m)")
        );
        m.route.start.z = 10.0;
        // An inverted range is about both ends: after the pair.
        m.bounds.x = [150.0, 100.0];
        let bounds = fields(&Item::Bounds, &m);
        let d = crate::outcome::diagnose::diagnose(&m);
        let whole = d
            .iter()
            .find(|d| d.path.to_string() == "bounds.x")
            .expect("a message on bounds.x");
        assert_eq!(
            place(&Item::Bounds, &m, &bounds, &whole.path),
            Some((Place::Group(0, 1), true))
        );
        // Issue 24, item 6: 1e9 typed into x max is a message under x max.
        m.bounds.x = [0.0, 1e9];
        assert_eq!(
            shown_under(&Item::Bounds, &m, "local plane").as_deref(),
            Some("x max (m)")
        );
        m.bounds.x = [0.0, 138.0];

        // An IWP entry naming a missing obstacle: its message is under the
        // IWP's obstacles field, and the IWP without an entry claims none.
        let iwp = Item::Waypoint(["pier 5".into(), "light pole 4".into()]);
        m.reconfiguration.waypoints.clear();
        m.reconfiguration.waypoints.push(WaypointChoice {
            between: ["pier 5".into(), "nowhere".into()],
            enabled: true,
            shape: ShapeChoice::Auto,
            scale: None,
        });
        let broken = Item::Waypoint(["pier 5".into(), "nowhere".into()]);
        let d = crate::outcome::diagnose::diagnose(&m);
        let between = d
            .iter()
            .find(|d| d.path.to_string() == "reconfiguration.waypoints[0].between")
            .expect("a message on the missing name");
        assert!(place(&iwp, &m, &fields(&iwp, &m), &between.path).is_none());
        let broken_fields = fields(&broken, &m);
        let (at, exact) = place(&broken, &m, &broken_fields, &between.path).unwrap();
        assert!(exact);
        assert_eq!(broken_fields[at.after().unwrap()].label(), "obstacles");
        assert!(iwp.path(&m).is_none());
    }

    /// Issue 24, item 6: a number too large for a double is not "not a number".
    #[test]
    fn a_number_too_large_says_so() {
        assert!(number("1e400").unwrap_err().contains("too large"));
        assert!(number("-1e400").unwrap_err().contains("too large"));
        assert_eq!(number("inf").unwrap_err(), "'inf' is not a number");
        assert_eq!(number("1e9"), Ok(1e9));
    }

    /// Issue 13: a field's path is the typed path the validator reports on.
    #[test]
    fn each_field_is_at_the_typed_path_its_diagnostics_name() {
        let mut m = default_mission().mission;
        let at = |item: &Item, m: &Mission, label: &str| {
            let f = fields(item, m).into_iter().find(|f| f.label() == label);
            f.map(|f| f.path().to_string())
        };
        let obstacle = Item::Obstacle(3);
        assert_eq!(
            at(&obstacle, &m, "radius (m)").as_deref(),
            Some("obstacles[3].radius")
        );
        assert_eq!(
            at(&obstacle, &m, "stand-off max (m)").as_deref(),
            Some("obstacles[3].stand_off[1]")
        );
        assert_eq!(
            at(&Item::Start, &m, "z (m)").as_deref(),
            Some("route.start[2]")
        );
        assert_eq!(
            at(&Item::Formation, &m, "default shape").as_deref(),
            Some("reconfiguration.default_shape")
        );
        assert_eq!(
            at(&Item::Slot(2), &m, "up z (m)").as_deref(),
            Some("formation.slots[2][2]")
        );
        // An IWP without an entry yet: where its entry will go.
        m.reconfiguration.waypoints.clear();
        let iwp = Item::Waypoint(["pier 5".into(), "light pole 4".into()]);
        assert_eq!(
            at(&iwp, &m, "shape").as_deref(),
            Some("reconfiguration.waypoints[0].shape")
        );
        fields(&iwp, &m)[2].set(&mut m, &iwp, "shrink").unwrap();
        assert_eq!(
            at(&iwp, &m, "shape").as_deref(),
            Some("reconfiguration.waypoints[0].shape")
        );

        // The validator's message on the radius is the radius field's.
        m.obstacles[3].radius = -1.0;
        let all = fields(&obstacle, &m);
        let radius = all.iter().find(|f| f.label() == "radius (m)").unwrap();
        let found: Vec<_> = crate::outcome::diagnose::diagnose(&m)
            .into_iter()
            .filter(|d| d.path.starts_with(radius.path()))
            .collect();
        assert!(
            found.iter().any(|d| d.message.contains("must be positive")),
            "{found:?}"
        );
        assert_eq!(radius.unit(), "m");
        // A missing item has no fields.
        assert!(fields(&Item::Obstacle(99), &m).is_empty());
    }

    #[test]
    fn numbers_are_shown_as_typed() {
        assert_eq!(fmt_num(3.0), "3");
        assert_eq!(fmt_num(-0.0), "0");
        assert_eq!(fmt_num(0.7298), "0.7298");
        assert_eq!(fmt_num(1e5), "100000");
        assert_eq!(fmt_num(2.71), "2.71", "short values exactly");
        assert_eq!(fmt_num(12.345678), "12.345678");
        assert_eq!(fmt_num(0.1 + 0.2), "0.3", "long ones rounded");
    }
}
