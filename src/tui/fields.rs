//! What can be selected and the inspector's editable fields for each.
//!
//! A field is read and written as text, so typing a value, pasting one and a
//! test all go through the same `set`. Each field names the mission path its
//! diagnostics are reported on (`obstacles[3].radius`), which is how a
//! validation message finds its way next to the field it concerns.
//!
//! Long (one closure per field of every item): declaring the fields as data
//! with typed paths is the open part of issue 13.

use nalgebra::{Point2, Vector3};

use crate::mission::{Mission, Obstacle, ShapeChoice, WaypointChoice};
use crate::planner::Iwp;
use crate::planner::iwp::same_pair;

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
                (named(a) && named(b))
                    || mission
                        .reconfiguration
                        .waypoints
                        .iter()
                        .any(|w| same_pair(&w.between, a, b))
            }
            _ => true,
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
            .any(|w| same_pair(&w.between, &choice.between[0], &choice.between[1]));
        if !listed {
            items.push(Item::Waypoint(choice.between.clone()));
        }
    }
    items
}

/// Whether a diagnostic at `path` belongs to the field at `field`.
pub fn concerns(path: &str, field: &str) -> bool {
    path == field
        || path
            .strip_prefix(field)
            .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}

/// An obstacle renamed from `old` to `new`: the IWP choices that named it
/// follow, unless another obstacle still carries the old name.
fn rename_references(m: &mut Mission, old: &str, new: &str) {
    if old == new || m.obstacles.iter().any(|o| o.name == old) {
        return;
    }
    for choice in &mut m.reconfiguration.waypoints {
        for name in &mut choice.between {
            if name == old {
                *name = new.to_owned();
            }
        }
    }
}

type Setter = fn(&mut Mission, &Item, &str) -> Result<(), String>;

/// One editable line of the inspector.
#[derive(Clone)]
pub struct Field {
    pub label: &'static str,
    /// Mission path whose diagnostics belong to this field.
    pub path: String,
    /// Current value, as it would be typed.
    pub value: String,
    set: Setter,
}

impl std::fmt::Debug for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} = {} ({})", self.label, self.value, self.path)
    }
}

impl Field {
    /// Parses `text` and writes it into `mission`; the error says what is expected.
    pub fn set(&self, mission: &mut Mission, item: &Item, text: &str) -> Result<(), String> {
        (self.set)(mission, item, text.trim())
    }
}

fn field(label: &'static str, path: impl Into<String>, value: impl ToString, set: Setter) -> Field {
    Field {
        label,
        path: path.into(),
        value: value.to_string(),
        set,
    }
}

/// Metres, degrees, gains: any finite number.
pub fn number(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("'{text}' is not a number")),
    }
}

fn count(text: &str) -> Result<usize, String> {
    text.parse::<usize>()
        .map_err(|_| format!("'{text}' is not a whole number ≥ 0"))
}

fn shape(text: &str) -> Result<ShapeChoice, String> {
    match text.to_ascii_lowercase().as_str() {
        "auto" | "automatic" => Ok(ShapeChoice::Auto),
        "alignment" | "align" => Ok(ShapeChoice::Alignment),
        "rotation" | "rotate" => Ok(ShapeChoice::Rotation),
        "shrink" => Ok(ShapeChoice::Shrink),
        _ => Err(format!(
            "'{text}' is not a shape: auto, alignment, rotation or shrink"
        )),
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

fn yes_no(text: &str) -> Result<bool, String> {
    match text.to_ascii_lowercase().as_str() {
        "yes" | "y" | "true" | "on" | "1" => Ok(true),
        "no" | "n" | "false" | "off" | "0" => Ok(false),
        _ => Err(format!("'{text}' is not yes or no")),
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

fn obstacle<'m>(m: &'m mut Mission, item: &Item) -> Result<&'m mut Obstacle, String> {
    match item {
        Item::Obstacle(i) => m.obstacles.get_mut(*i).ok_or("no such obstacle".into()),
        _ => Err("not an obstacle".into()),
    }
}

/// One end of an obstacle's stand-off band; an empty entry goes back to the
/// formation's `surface_distance` for both ends.
fn set_stand_off(m: &mut Mission, item: &Item, end: usize, t: &str) -> Result<(), String> {
    let default = m.formation.surface_distance;
    let o = obstacle(m, item)?;
    if t.trim().is_empty() {
        o.stand_off = None;
        return Ok(());
    }
    let mut band = o.stand_off.unwrap_or(default);
    band[end] = number(t)?;
    o.stand_off = Some(band);
    Ok(())
}

fn slot<'m>(m: &'m mut Mission, item: &Item) -> Result<&'m mut Vector3<f64>, String> {
    match item {
        Item::Slot(i) => m.formation.slots.get_mut(*i).ok_or("no such slot".into()),
        _ => Err("not a slot".into()),
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
    let same = |w: &WaypointChoice| same_pair(&w.between, &between[0], &between[1]);
    let list = &mut m.reconfiguration.waypoints;
    let index = match list.iter().position(same) {
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

fn find_choice<'m>(m: &'m Mission, between: &[String; 2]) -> Option<&'m WaypointChoice> {
    m.reconfiguration
        .waypoints
        .iter()
        .find(|w| same_pair(&w.between, &between[0], &between[1]))
}

/// The `[terrain]` keys; the map is read again when they change
/// (`Document::edit`), and a file that does not load is an error on
/// `terrain.file`.
fn terrain_fields(m: &Mission) -> Vec<Field> {
    let Some(t) = &m.terrain else {
        return Vec::new();
    };
    fn terrain(m: &mut Mission) -> Result<&mut crate::mission::Terrain, String> {
        m.terrain
            .as_mut()
            .ok_or_else(|| "the mission has no [terrain]".to_owned())
    }
    let lookup = match t.lookup {
        crate::terrain::Lookup::Nearest => "nearest",
        crate::terrain::Lookup::Bilinear => "bilinear",
    };
    vec![
        field("file", "terrain.file", &t.file, |m, _, text| {
            if text.trim().is_empty() {
                return Err("the terrain needs a GeoTIFF file".into());
            }
            terrain(m)?.file = text.trim().to_owned();
            Ok(())
        }),
        field(
            "origin x (m)",
            "terrain.origin",
            fmt_num(t.origin[0]),
            |m, _, text| {
                terrain(m)?.origin[0] = number(text)?;
                Ok(())
            },
        ),
        field(
            "origin y (m)",
            "terrain.origin",
            fmt_num(t.origin[1]),
            |m, _, text| {
                terrain(m)?.origin[1] = number(text)?;
                Ok(())
            },
        ),
        field(
            "pixel x (m)",
            "terrain.pixel_size",
            fmt_num(t.pixel_size[0]),
            |m, _, text| {
                terrain(m)?.pixel_size[0] = number(text)?;
                Ok(())
            },
        ),
        field(
            "pixel y (m)",
            "terrain.pixel_size",
            fmt_num(t.pixel_size[1]),
            |m, _, text| {
                terrain(m)?.pixel_size[1] = number(text)?;
                Ok(())
            },
        ),
        field("lookup", "terrain.lookup", lookup, |m, _, text| {
            terrain(m)?.lookup = match text.trim() {
                "nearest" => crate::terrain::Lookup::Nearest,
                "bilinear" => crate::terrain::Lookup::Bilinear,
                other => return Err(format!("'{other}' is not a lookup: nearest or bilinear")),
            };
            Ok(())
        }),
    ]
}

/// The inspector's fields for `item`, with the values they have in `mission`.
pub fn fields(item: &Item, mission: &Mission) -> Vec<Field> {
    let m = mission;
    match item {
        Item::Mission => vec![
            field("name", "name", &m.name, |m, _, t| {
                m.name = t.to_owned();
                Ok(())
            }),
            field("description", "description", &m.description, |m, _, t| {
                m.description = t.to_owned();
                Ok(())
            }),
            field("seed", "seed", m.seed, |m, _, t| {
                m.seed = t
                    .parse()
                    .map_err(|_| format!("'{t}' is not a seed (0 … 2⁶⁴-1)"))?;
                Ok(())
            }),
            field(
                "origin lat (°)",
                "origin.latitude",
                origin_value(m, |o| o.latitude),
                |m, _, t| set_origin(m, t, |o, v| o.latitude = v),
            ),
            field(
                "origin lon (°)",
                "origin.longitude",
                origin_value(m, |o| o.longitude),
                |m, _, t| set_origin(m, t, |o, v| o.longitude = v),
            ),
            field(
                "origin alt (m)",
                "origin.altitude",
                origin_value(m, |o| o.altitude),
                |m, _, t| set_origin(m, t, |o, v| o.altitude = v),
            ),
        ],
        Item::Bounds => {
            let b = &m.bounds;
            vec![
                field("x min (m)", "bounds.x", fmt_num(b.x[0]), |m, _, t| {
                    m.bounds.x[0] = number(t)?;
                    Ok(())
                }),
                field("x max (m)", "bounds.x", fmt_num(b.x[1]), |m, _, t| {
                    m.bounds.x[1] = number(t)?;
                    Ok(())
                }),
                field("y min (m)", "bounds.y", fmt_num(b.y[0]), |m, _, t| {
                    m.bounds.y[0] = number(t)?;
                    Ok(())
                }),
                field("y max (m)", "bounds.y", fmt_num(b.y[1]), |m, _, t| {
                    m.bounds.y[1] = number(t)?;
                    Ok(())
                }),
                field("z min (m)", "bounds.z", fmt_num(b.z[0]), |m, _, t| {
                    m.bounds.z[0] = number(t)?;
                    Ok(())
                }),
                field("z max (m)", "bounds.z", fmt_num(b.z[1]), |m, _, t| {
                    m.bounds.z[1] = number(t)?;
                    Ok(())
                }),
            ]
        }
        Item::Start => {
            let p = &m.route.start;
            vec![
                field("x (m)", "route.start", fmt_num(p.x), |m, _, t| {
                    m.route.start.x = number(t)?;
                    Ok(())
                }),
                field("y (m)", "route.start", fmt_num(p.y), |m, _, t| {
                    m.route.start.y = number(t)?;
                    Ok(())
                }),
                field("z (m)", "route.start", fmt_num(p.z), |m, _, t| {
                    m.route.start.z = number(t)?;
                    Ok(())
                }),
            ]
        }
        Item::Goal => {
            let p = &m.route.goal;
            vec![
                field("x (m)", "route.goal", fmt_num(p.x), |m, _, t| {
                    m.route.goal.x = number(t)?;
                    Ok(())
                }),
                field("y (m)", "route.goal", fmt_num(p.y), |m, _, t| {
                    m.route.goal.y = number(t)?;
                    Ok(())
                }),
                field("z (m)", "route.goal", fmt_num(p.z), |m, _, t| {
                    m.route.goal.z = number(t)?;
                    Ok(())
                }),
            ]
        }
        Item::Obstacle(i) => {
            let Some(o) = m.obstacles.get(*i) else {
                return Vec::new();
            };
            let at = |key: &str| format!("obstacles[{i}].{key}");
            vec![
                field("name", at("name"), &o.name, |m, item, t| {
                    let old = std::mem::replace(&mut obstacle(m, item)?.name, t.to_owned());
                    rename_references(m, &old, t);
                    Ok(())
                }),
                field(
                    "kind",
                    at("kind"),
                    o.kind.as_deref().unwrap_or(""),
                    |m, item, t| {
                        obstacle(m, item)?.kind = (!t.is_empty()).then(|| t.to_owned());
                        Ok(())
                    },
                ),
                field(
                    "centre x (m)",
                    at("center"),
                    fmt_num(o.center.x),
                    |m, item, t| {
                        obstacle(m, item)?.center.x = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "centre y (m)",
                    at("center"),
                    fmt_num(o.center.y),
                    |m, item, t| {
                        obstacle(m, item)?.center.y = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "radius (m)",
                    at("radius"),
                    fmt_num(o.radius),
                    |m, item, t| {
                        obstacle(m, item)?.radius = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "height (m)",
                    at("height"),
                    fmt_num(o.height),
                    |m, item, t| {
                        obstacle(m, item)?.height = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "inspect (eq. 8)",
                    at("inspect"),
                    if o.inspect { "yes" } else { "no" },
                    |m, item, t| {
                        obstacle(m, item)?.inspect = yes_no(t)?;
                        Ok(())
                    },
                ),
                field(
                    "stand-off min (m)",
                    at("stand_off"),
                    fmt_num(o.stand_off_band(&m.formation)[0]),
                    |m, item, t| set_stand_off(m, item, 0, t),
                ),
                field(
                    "stand-off max (m)",
                    at("stand_off"),
                    fmt_num(o.stand_off_band(&m.formation)[1]),
                    |m, item, t| set_stand_off(m, item, 1, t),
                ),
            ]
        }
        Item::Formation => {
            let f = &m.formation;
            let r = &m.reconfiguration;
            vec![
                field(
                    "UAV radius r_Q (m)",
                    "formation.uav_radius",
                    fmt_num(f.uav_radius),
                    |m, _, t| {
                        m.formation.uav_radius = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "ground speed (m/s)",
                    "formation.ground_speed",
                    fmt_num(f.ground_speed),
                    |m, _, t| {
                        m.formation.ground_speed = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "comm range (m)",
                    "formation.comm_range",
                    fmt_num(f.comm_range),
                    |m, _, t| {
                        m.formation.comm_range = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "surface d min (m)",
                    "formation.surface_distance",
                    fmt_num(f.surface_distance[0]),
                    |m, _, t| {
                        m.formation.surface_distance[0] = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "surface d max (m)",
                    "formation.surface_distance",
                    fmt_num(f.surface_distance[1]),
                    |m, _, t| {
                        m.formation.surface_distance[1] = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "inspection pass (m)",
                    "formation.inspection_pass",
                    fmt_num(f.inspection_pass),
                    |m, _, t| {
                        m.formation.inspection_pass = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "default shape",
                    "reconfiguration.default_shape",
                    shape_name(r.default_shape),
                    |m, _, t| {
                        m.reconfiguration.default_shape = shape(t)?;
                        Ok(())
                    },
                ),
                field(
                    "shrink scale",
                    "reconfiguration.shrink_scale",
                    fmt_num(r.shrink_scale),
                    |m, _, t| {
                        m.reconfiguration.shrink_scale = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "transition (m)",
                    "reconfiguration.transition_distance",
                    fmt_num(r.transition_distance),
                    |m, _, t| {
                        m.reconfiguration.transition_distance = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "hold (m)",
                    "reconfiguration.hold_distance",
                    fmt_num(r.hold_distance),
                    |m, _, t| {
                        m.reconfiguration.hold_distance = number(t)?;
                        Ok(())
                    },
                ),
            ]
        }
        Item::Slot(i) => {
            let Some(s) = m.formation.slots.get(*i) else {
                return Vec::new();
            };
            let at = format!("formation.slots[{i}]");
            vec![
                field("forward x (m)", at.clone(), fmt_num(s.x), |m, item, t| {
                    slot(m, item)?.x = number(t)?;
                    Ok(())
                }),
                field("left y (m)", at.clone(), fmt_num(s.y), |m, item, t| {
                    slot(m, item)?.y = number(t)?;
                    Ok(())
                }),
                field("up z (m)", at, fmt_num(s.z), |m, item, t| {
                    slot(m, item)?.z = number(t)?;
                    Ok(())
                }),
            ]
        }
        Item::Waypoint(between) => {
            let choice = find_choice(m, between);
            let index = m
                .reconfiguration
                .waypoints
                .iter()
                .position(|w| Some(w) == choice);
            let at = |key: &str| match index {
                Some(i) => format!("reconfiguration.waypoints[{i}].{key}"),
                None => "reconfiguration.waypoints".into(),
            };
            let enabled = choice.is_none_or(|c| c.enabled);
            let chosen = choice.map_or(ShapeChoice::Auto, |c| c.shape);
            let scale = choice
                .and_then(|c| c.scale)
                .map(fmt_num)
                .unwrap_or_default();
            vec![
                field(
                    "enabled",
                    at("enabled"),
                    if enabled { "yes" } else { "no" },
                    |m, item, t| {
                        waypoint_choice(m, item)?.enabled = yes_no(t)?;
                        Ok(())
                    },
                ),
                field("shape", at("shape"), shape_name(chosen), |m, item, t| {
                    waypoint_choice(m, item)?.shape = shape(t)?;
                    Ok(())
                }),
                field(
                    "scale (blank: default)",
                    at("scale"),
                    scale,
                    |m, item, t| {
                        waypoint_choice(m, item)?.scale =
                            if t.is_empty() { None } else { Some(number(t)?) };
                        Ok(())
                    },
                ),
            ]
        }
        Item::Squadron => squadron_fields(m),
        Item::Fleet => fleet_fields(m),
        Item::Terrain => terrain_fields(m),
        Item::FleetTarget(i) => {
            let Some(t) = m.fleet.targets.get(*i) else {
                return Vec::new();
            };
            let at = |key: &str| format!("fleet.targets[{i}].{key}");
            vec![
                field("time (s)", at("time"), fmt_num(t.time), |m, item, t| {
                    target(m, item)?.time = number(t)?;
                    Ok(())
                }),
                field(
                    "x (m)",
                    at("position"),
                    fmt_num(t.position.x),
                    |m, item, t| {
                        target(m, item)?.position.x = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "y (m)",
                    at("position"),
                    fmt_num(t.position.y),
                    |m, item, t| {
                        target(m, item)?.position.y = number(t)?;
                        Ok(())
                    },
                ),
            ]
        }
        Item::ThetaPso => {
            let p = &m.theta_pso;
            vec![
                field(
                    "swarm size",
                    "theta_pso.swarm_size",
                    p.swarm_size,
                    |m, _, t| {
                        m.theta_pso.swarm_size = count(t)?;
                        Ok(())
                    },
                ),
                field(
                    "waypoints",
                    "theta_pso.waypoints",
                    p.waypoints,
                    |m, _, t| {
                        m.theta_pso.waypoints = count(t)?;
                        Ok(())
                    },
                ),
                field(
                    "iterations",
                    "theta_pso.iterations",
                    p.iterations,
                    |m, _, t| {
                        m.theta_pso.iterations = count(t)?;
                        Ok(())
                    },
                ),
                field(
                    "inertia w",
                    "theta_pso.inertia",
                    fmt_num(p.inertia),
                    |m, _, t| {
                        m.theta_pso.inertia = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "cognitive c1",
                    "theta_pso.cognitive",
                    fmt_num(p.cognitive),
                    |m, _, t| {
                        m.theta_pso.cognitive = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "social c2",
                    "theta_pso.social",
                    fmt_num(p.social),
                    |m, _, t| {
                        m.theta_pso.social = number(t)?;
                        Ok(())
                    },
                ),
                field("segments L", "theta_pso.segments", p.segments, |m, _, t| {
                    m.theta_pso.segments = count(t)?;
                    Ok(())
                }),
                field(
                    "β1 length",
                    "theta_pso.weight_length",
                    fmt_num(p.weight_length),
                    |m, _, t| {
                        m.theta_pso.weight_length = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "β2 obstacle",
                    "theta_pso.weight_obstacle",
                    fmt_num(p.weight_obstacle),
                    |m, _, t| {
                        m.theta_pso.weight_obstacle = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "β3 altitude",
                    "theta_pso.weight_altitude",
                    fmt_num(p.weight_altitude),
                    |m, _, t| {
                        m.theta_pso.weight_altitude = number(t)?;
                        Ok(())
                    },
                ),
                field(
                    "βR waypoints",
                    "theta_pso.weight_waypoints",
                    fmt_num(p.weight_waypoints),
                    |m, _, t| {
                        m.theta_pso.weight_waypoints = number(t)?;
                        Ok(())
                    },
                ),
            ]
        }
    }
}

fn target<'m>(
    m: &'m mut Mission,
    item: &Item,
) -> Result<&'m mut crate::mission::FleetTarget, String> {
    match item {
        Item::FleetTarget(i) => m.fleet.targets.get_mut(*i).ok_or("no such target".into()),
        _ => Err("not a fleet target".into()),
    }
}

/// The fleet's parameters (Table 1 and the scenario); gains and the
/// airframe stay in the file.
fn fleet_fields(m: &Mission) -> Vec<Field> {
    let p = &m.fleet;
    vec![
        field("agents n", "fleet.agents", p.agents, |m, _, t| {
            m.fleet.agents = count(t)?;
            Ok(())
        }),
        field(
            "ρ target weight",
            "fleet.rho",
            fmt_num(p.rho),
            |m, _, t| {
                m.fleet.rho = number(t)?;
                Ok(())
            },
        ),
        field(
            "σ steepness",
            "fleet.sigma",
            fmt_num(p.sigma),
            |m, _, t| {
                m.fleet.sigma = number(t)?;
                Ok(())
            },
        ),
        field(
            "c safety (m)",
            "fleet.safety_distance",
            fmt_num(p.safety_distance),
            |m, _, t| {
                m.fleet.safety_distance = number(t)?;
                Ok(())
            },
        ),
        field(
            "l neighbourhood (m)",
            "fleet.neighbourhood",
            fmt_num(p.neighbourhood),
            |m, _, t| {
                m.fleet.neighbourhood = number(t)?;
                Ok(())
            },
        ),
        field(
            "d_obs detection (m)",
            "fleet.detection_range",
            fmt_num(p.detection_range),
            |m, _, t| {
                m.fleet.detection_range = number(t)?;
                Ok(())
            },
        ),
        field(
            "h_max step (m)",
            "fleet.step_max",
            fmt_num(p.step_max),
            |m, _, t| {
                m.fleet.step_max = number(t)?;
                Ok(())
            },
        ),
        field(
            "τ replan (s)",
            "fleet.replan_period",
            fmt_num(p.replan_period),
            |m, _, t| {
                m.fleet.replan_period = number(t)?;
                Ok(())
            },
        ),
        field(
            "d_ip to target (m)",
            "fleet.target_distance",
            fmt_num(p.target_distance),
            |m, _, t| {
                m.fleet.target_distance = number(t)?;
                Ok(())
            },
        ),
        field(
            "altitude (m)",
            "fleet.altitude",
            fmt_num(p.altitude),
            |m, _, t| {
                m.fleet.altitude = number(t)?;
                Ok(())
            },
        ),
        field(
            "duration (s)",
            "fleet.duration",
            fmt_num(p.duration),
            |m, _, t| {
                m.fleet.duration = number(t)?;
                Ok(())
            },
        ),
        field(
            "tolerance",
            "fleet.tolerance",
            fmt_num(p.tolerance),
            |m, _, t| {
                m.fleet.tolerance = number(t)?;
                Ok(())
            },
        ),
    ]
}

/// FLATLO's squadron: what the operator sets per mission; the airframe
/// constants stay in the file.
fn squadron_fields(m: &Mission) -> Vec<Field> {
    let p = &m.flatlo;
    vec![
        field("aircraft N", "flatlo.aircraft", p.aircraft, |m, _, t| {
            m.flatlo.aircraft = count(t)?;
            Ok(())
        }),
        field(
            "spacing Δd (m)",
            "flatlo.spacing",
            fmt_num(p.spacing),
            |m, _, t| {
                m.flatlo.spacing = number(t)?;
                Ok(())
            },
        ),
        field(
            "airspeed (m/s)",
            "flatlo.airspeed",
            fmt_num(p.airspeed),
            |m, _, t| {
                m.flatlo.airspeed = number(t)?;
                Ok(())
            },
        ),
        field(
            "turn radius r (m)",
            "flatlo.turn_radius",
            fmt_num(p.turn_radius),
            |m, _, t| {
                m.flatlo.turn_radius = number(t)?;
                Ok(())
            },
        ),
        field(
            "heading φ (°)",
            "flatlo.heading_deg",
            fmt_num(p.heading_deg),
            |m, _, t| {
                m.flatlo.heading_deg = number(t)?;
                Ok(())
            },
        ),
        field(
            "climb β (°)",
            "flatlo.climb_deg",
            fmt_num(p.climb_deg),
            |m, _, t| {
                m.flatlo.climb_deg = number(t)?;
                Ok(())
            },
        ),
        field(
            "altitude (m)",
            "flatlo.altitude",
            fmt_num(p.altitude),
            |m, _, t| {
                m.flatlo.altitude = number(t)?;
                Ok(())
            },
        ),
        field(
            "start x (m)",
            "flatlo.start",
            fmt_num(p.start.x),
            |m, _, t| {
                m.flatlo.start.x = number(t)?;
                Ok(())
            },
        ),
        field(
            "start y (m)",
            "flatlo.start",
            fmt_num(p.start.y),
            |m, _, t| {
                m.flatlo.start.y = number(t)?;
                Ok(())
            },
        ),
        field(
            "final leg K2 (m)",
            "flatlo.final_leg",
            fmt_num(p.final_leg),
            |m, _, t| {
                m.flatlo.final_leg = number(t)?;
                Ok(())
            },
        ),
        field("noise σ", "flatlo.noise", fmt_num(p.noise), |m, _, t| {
            m.flatlo.noise = number(t)?;
            Ok(())
        }),
        field(
            "min separation (m)",
            "flatlo.min_separation",
            fmt_num(p.min_separation),
            |m, _, t| {
                m.flatlo.min_separation = number(t)?;
                Ok(())
            },
        ),
    ]
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

/// An `[origin]` value for the inspector: empty when the mission has none.
fn origin_value(m: &Mission, get: fn(&crate::mission::GeoOrigin) -> f64) -> String {
    m.origin
        .as_ref()
        .map_or_else(String::new, |o| fmt_num(get(o)))
}

/// Sets one `[origin]` value (creating the section at 0°, 0°, 0 m); an empty
/// text removes the section (exports then offer CSV in ENU only).
fn set_origin(
    m: &mut Mission,
    text: &str,
    set: fn(&mut crate::mission::GeoOrigin, f64),
) -> Result<(), String> {
    if text.trim().is_empty() {
        m.origin = None;
        return Ok(());
    }
    let v = number(text)?;
    let origin = m.origin.get_or_insert(crate::mission::GeoOrigin {
        latitude: 0.0,
        longitude: 0.0,
        altitude: 0.0,
    });
    set(origin, v);
    Ok(())
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
                let value = if f.label.contains("shape") {
                    "shrink".to_string()
                } else if f.value == "yes" || f.value == "no" {
                    "yes".to_string()
                } else {
                    "7".to_string()
                };
                f.set(&mut m, &item, &value).unwrap();
                assert_eq!(fields(&item, &m)[k].value, value, "{item:?} {}", f.label);
            }
        }
    }

    #[test]
    fn bad_text_is_refused_with_what_was_expected() {
        let mut m = default_mission().mission;
        let radius = &fields(&Item::Obstacle(0), &m)[4];
        assert_eq!(radius.label, "radius (m)");
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
        let shape = &fields(&item, &m)[1];
        shape.set(&mut m, &item, "rotation").unwrap();
        assert_eq!(m.reconfiguration.waypoints.len(), 1);
        assert_eq!(m.reconfiguration.waypoints[0].shape, ShapeChoice::Rotation);
        // Named the other way round, it is the same IWP.
        let item = Item::Waypoint(["light pole 4".into(), "pier 5".into()]);
        fields(&item, &m)[0].set(&mut m, &item, "no").unwrap();
        assert_eq!(m.reconfiguration.waypoints.len(), 1);
        assert!(!m.reconfiguration.waypoints[0].enabled);
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
