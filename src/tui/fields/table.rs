//! The inspector's fields of every kind of item, declared as tables (see
//! `fields.rs` for what a field is), and the reading and writing of their
//! values as text. The tables keep one field a line (`rustfmt::skip`) so
//! they read as tables: name, unit, keys, read, write.
//!
//! A pipeline's own section's rows, and its points', are its face's
//! (`Pipeline::rows`, `PointKind::rows`, in the pipeline's `section.rs`).
//!
//! Long (~660 lines) because it is the field tables of every other item kind (one field a
//! line) with the parsers, names and setters their cells call, read together.

use nalgebra::{Point2, Vector3};

use super::Step::{Index, Key, Vertex};
use super::{Item, Spec, Table, shape_name, waypoint_choice};
use crate::base::terrain::Lookup;
use crate::mission::{
    GeoOrigin, Mission, Obstacle, Preset, ShapeChoice, Terrain, Turbulence, WaypointChoice,
    spacing_of,
};
use crate::pipelines::rows::{count, fmt_num, geo_moved, geo_text, num, number, put, text};

/// The table of `item`'s kind.
pub(super) fn of(item: &Item) -> &'static Table {
    match item {
        Item::Mission => &MISSION,
        Item::Bounds => &BOUNDS,
        Item::Start => &START,
        Item::Goal => &GOAL,
        Item::Via(_) => &VIA,
        Item::Terrain => &TERRAIN,
        Item::Obstacle(_) => &OBSTACLE,
        Item::Vertex(_, _) => &VERTEX,
        Item::Formation => &FORMATION,
        Item::Slot(_) => &SLOT,
        Item::Waypoint(_) => &WAYPOINT,
        // A section's rows are its pipeline's (`Pipeline::rows`), its
        // points' their kind's (`PointKind::rows`).
        Item::Section(_) | Item::Point(_) => &NO_FIELDS,
        Item::Flight => &FLIGHT,
    }
}

/// An item whose fields are not in these tables.
static NO_FIELDS: Table = Table {
    base: &[],
    derived: &[],
    fields: &[],
};

/// `[flight]`: the air, the fixes and the autopilot of `skyform fly`.
#[rustfmt::skip]
static FLIGHT: Table = Table { base: &[Key("flight")], derived: &[], fields: &[
    Spec { name: "flights", unit: "", keys: &["flights"], get: |m, _| text(m.flight.flights), set: |m, _, t| put(&mut m.flight.flights, count(t)) },
    Spec { name: "wind speed", unit: "m/s", keys: &["wind_speed"], get: |m, _| num(m.flight.wind_speed), set: |m, _, t| put(&mut m.flight.wind_speed, number(t)) },
    Spec { name: "wind from", unit: "°", keys: &["wind_from_deg"], get: |m, _| num(m.flight.wind_from_deg), set: |m, _, t| put(&mut m.flight.wind_from_deg, number(t)) },
    Spec { name: "turbulence", unit: "", keys: &["turbulence"], get: |m, _| text(turbulence_name(m.flight.turbulence)), set: |m, _, t| put(&mut m.flight.turbulence, turbulence(t)) },
    Spec { name: "GNSS σ horiz.", unit: "m", keys: &["gnss_sigma_horizontal"], get: |m, _| num(m.flight.gnss_sigma_horizontal), set: |m, _, t| put(&mut m.flight.gnss_sigma_horizontal, number(t)) },
    Spec { name: "GNSS σ vert.", unit: "m", keys: &["gnss_sigma_vertical"], get: |m, _| num(m.flight.gnss_sigma_vertical), set: |m, _, t| put(&mut m.flight.gnss_sigma_vertical, number(t)) },
    Spec { name: "GNSS τ", unit: "s", keys: &["gnss_correlation_time"], get: |m, _| num(m.flight.gnss_correlation_time), set: |m, _, t| put(&mut m.flight.gnss_correlation_time, number(t)) },
    Spec { name: "GNSS own share", unit: "", keys: &["gnss_own_share"], get: |m, _| num(m.flight.gnss_own_share), set: |m, _, t| put(&mut m.flight.gnss_own_share, number(t)) },
    Spec { name: "take-off skew σ", unit: "s", keys: &["takeoff_skew"], get: |m, _| num(m.flight.takeoff_skew), set: |m, _, t| put(&mut m.flight.takeoff_skew, number(t)) },
    Spec { name: "acceptance", unit: "m", keys: &["acceptance_radius"], get: |m, _| num(m.flight.acceptance_radius), set: |m, _, t| put(&mut m.flight.acceptance_radius, number(t)) },
    Spec { name: "drag", unit: "1/s", keys: &["drag"], get: |m, _| num(m.flight.drag), set: |m, _, t| put(&mut m.flight.drag, number(t)) },
    Spec { name: "step", unit: "s", keys: &["step"], get: |m, _| num(m.flight.step), set: |m, _, t| put(&mut m.flight.step, number(t)) },
]};

fn turbulence_name(t: Turbulence) -> &'static str {
    match t {
        Turbulence::None => "none",
        Turbulence::Light => "light",
        Turbulence::Moderate => "moderate",
        Turbulence::Severe => "severe",
    }
}

fn turbulence(text: &str) -> Result<Turbulence, String> {
    match text.to_ascii_lowercase().as_str() {
        "none" | "calm" => Ok(Turbulence::None),
        "light" => Ok(Turbulence::Light),
        "moderate" => Ok(Turbulence::Moderate),
        "severe" => Ok(Turbulence::Severe),
        _ => Err(format!(
            "'{text}' is not a turbulence: none, light, moderate or severe"
        )),
    }
}

#[rustfmt::skip]
static MISSION: Table = Table { base: &[], derived: &[], fields: &[
    Spec { name: "name", unit: "", keys: &["name"], get: |m, _| text(&m.name), set: |m, _, t| put(&mut m.name, Ok(t.to_owned())) },
    Spec { name: "description", unit: "", keys: &["description"], get: |m, _| text(&m.description), set: |m, _, t| put(&mut m.description, Ok(t.to_owned())) },
    Spec { name: "seed", unit: "", keys: &["seed"], get: |m, _| text(m.seed), set: |m, _, t| put(&mut m.seed, seed(t)) },
    Spec { name: "origin lat", unit: "°", keys: &["origin", "latitude"], get: |m, _| origin(m, |o| o.latitude), set: |m, _, t| set_origin(m, t, OriginPart::Latitude) },
    Spec { name: "origin lon", unit: "°", keys: &["origin", "longitude"], get: |m, _| origin(m, |o| o.longitude), set: |m, _, t| set_origin(m, t, OriginPart::Longitude) },
    Spec { name: "origin alt", unit: "m", keys: &["origin", "altitude"], get: |m, _| origin(m, |o| o.altitude), set: |m, _, t| set_origin(m, t, OriginPart::Altitude) },
]};

#[rustfmt::skip]
static BOUNDS: Table = Table { base: &[Key("bounds")], derived: &[], fields: &[
    Spec { name: "x min", unit: "m", keys: &["x"], get: |m, _| num(m.bounds.x[0]), set: |m, _, t| put(&mut m.bounds.x[0], number(t)) },
    Spec { name: "x max", unit: "m", keys: &["x"], get: |m, _| num(m.bounds.x[1]), set: |m, _, t| put(&mut m.bounds.x[1], number(t)) },
    Spec { name: "y min", unit: "m", keys: &["y"], get: |m, _| num(m.bounds.y[0]), set: |m, _, t| put(&mut m.bounds.y[0], number(t)) },
    Spec { name: "y max", unit: "m", keys: &["y"], get: |m, _| num(m.bounds.y[1]), set: |m, _, t| put(&mut m.bounds.y[1], number(t)) },
    Spec { name: "z min", unit: "m", keys: &["z"], get: |m, _| num(m.bounds.z[0]), set: |m, _, t| put(&mut m.bounds.z[0], number(t)) },
    Spec { name: "z max", unit: "m", keys: &["z"], get: |m, _| num(m.bounds.z[1]), set: |m, _, t| put(&mut m.bounds.z[1], number(t)) },
]};

#[rustfmt::skip]
static START: Table = Table { base: &[Key("route"), Key("start")], derived: &[], fields: &[
    Spec { name: "x", unit: "m", keys: &[], get: |m, _| num(m.route.start.x), set: |m, _, t| put(&mut m.route.start.x, number(t)) },
    Spec { name: "y", unit: "m", keys: &[], get: |m, _| num(m.route.start.y), set: |m, _, t| put(&mut m.route.start.y, number(t)) },
    Spec { name: "z", unit: "m", keys: &[], get: |m, _| num(m.route.start.z), set: |m, _, t| put(&mut m.route.start.z, number(t)) },
    Spec { name: "lat", unit: "°", keys: &["latitude"], get: |m, i| geo(m, i, LAT), set: |m, i, t| set_geo(m, i, t, LAT) },
    Spec { name: "lon", unit: "°", keys: &["longitude"], get: |m, i| geo(m, i, LON), set: |m, i, t| set_geo(m, i, t, LON) },
]};

#[rustfmt::skip]
static GOAL: Table = Table { base: &[Key("route"), Key("goal")], derived: &[], fields: &[
    Spec { name: "x", unit: "m", keys: &[], get: |m, _| num(m.route.goal.x), set: |m, _, t| put(&mut m.route.goal.x, number(t)) },
    Spec { name: "y", unit: "m", keys: &[], get: |m, _| num(m.route.goal.y), set: |m, _, t| put(&mut m.route.goal.y, number(t)) },
    Spec { name: "z", unit: "m", keys: &[], get: |m, _| num(m.route.goal.z), set: |m, _, t| put(&mut m.route.goal.z, number(t)) },
    Spec { name: "lat", unit: "°", keys: &["latitude"], get: |m, i| geo(m, i, LAT), set: |m, i, t| set_geo(m, i, t, LAT) },
    Spec { name: "lon", unit: "°", keys: &["longitude"], get: |m, i| geo(m, i, LON), set: |m, i, t| set_geo(m, i, t, LON) },
]};

/// The `[terrain]` keys; the map is read again when they change
/// (`Document::edit`), and a file that does not load is an error on
/// `terrain.file`.
#[rustfmt::skip]
static TERRAIN: Table = Table { base: &[Key("terrain")], derived: &[], fields: &[
    Spec { name: "file", unit: "", keys: &["file"], get: |m, _| text(&m.terrain.as_ref()?.file), set: |m, _, t| put(&mut terrain(m)?.file, geotiff(t)) },
    Spec { name: "origin x", unit: "m", keys: &["origin"], get: |m, _| num(m.terrain.as_ref()?.origin[0]), set: |m, _, t| put(&mut terrain(m)?.origin[0], number(t)) },
    Spec { name: "origin y", unit: "m", keys: &["origin"], get: |m, _| num(m.terrain.as_ref()?.origin[1]), set: |m, _, t| put(&mut terrain(m)?.origin[1], number(t)) },
    Spec { name: "pixel x", unit: "m", keys: &["pixel_size"], get: |m, _| num(m.terrain.as_ref()?.pixel_size[0]), set: |m, _, t| put(&mut terrain(m)?.pixel_size[0], number(t)) },
    Spec { name: "pixel y", unit: "m", keys: &["pixel_size"], get: |m, _| num(m.terrain.as_ref()?.pixel_size[1]), set: |m, _, t| put(&mut terrain(m)?.pixel_size[1], number(t)) },
    Spec { name: "lookup", unit: "", keys: &["lookup"], get: |m, _| text(lookup_name(m.terrain.as_ref()?.lookup)), set: |m, _, t| put(&mut terrain(m)?.lookup, lookup(t)) },
]};

/// A `[[route.via]]`: a gate's two obstacles, or a point and its radius.
#[rustfmt::skip]
static VIA: Table = Table { base: &[Key("route"), Key("via"), Index], derived: &[], fields: &[
    Spec { name: "between", unit: "", keys: &["between"], get: |m, i| text(&via_at(m, i)?.between.as_ref()?[0]), set: |m, i, t| set_between(m, i, 0, t) },
    Spec { name: "and", unit: "", keys: &["between"], get: |m, i| text(&via_at(m, i)?.between.as_ref()?[1]), set: |m, i, t| set_between(m, i, 1, t) },
    Spec { name: "x", unit: "m", keys: &["point"], get: |m, i| num(via_at(m, i)?.point?.x), set: |m, i, t| set_via_point(m, i, 0, t) },
    Spec { name: "y", unit: "m", keys: &["point"], get: |m, i| num(via_at(m, i)?.point?.y), set: |m, i, t| set_via_point(m, i, 1, t) },
    Spec { name: "z", unit: "m", keys: &["point"], get: |m, i| num(via_at(m, i)?.point?.z), set: |m, i, t| set_via_point(m, i, 2, t) },
    Spec { name: "radius", unit: "m", keys: &["radius"], get: |m, i| { let v = via_at(m, i)?; v.point?; num(v.radius()) }, set: |m, i, t| { let r = number(t)?; via(m, i)?.radius = Some(r); Ok(()) } },
]};

#[rustfmt::skip]
static OBSTACLE: Table = Table { base: &[Key("obstacles"), Index], derived: &[], fields: &[
    Spec { name: "name", unit: "", keys: &["name"], get: |m, i| text(&obstacle_at(m, i)?.name), set: rename_obstacle },
    Spec { name: "kind", unit: "", keys: &["kind"], get: |m, i| text(obstacle_at(m, i)?.kind.as_deref().unwrap_or("")), set: |m, i, t| put(&mut obstacle(m, i)?.kind, Ok((!t.is_empty()).then(|| t.to_owned()))) },
    Spec { name: "centre x", unit: "m", keys: &["center"], get: |m, i| num(solid_at(m, i)?.center.x), set: |m, i, t| { let o = obstacle(m, i)?; let x = number(t)?; o.move_to(Point2::new(x, o.center.y)); Ok(()) } },
    Spec { name: "centre y", unit: "m", keys: &["center"], get: |m, i| num(solid_at(m, i)?.center.y), set: |m, i, t| { let o = obstacle(m, i)?; let y = number(t)?; o.move_to(Point2::new(o.center.x, y)); Ok(()) } },
    Spec { name: "centre lat", unit: "°", keys: &["center", "latitude"], get: |m, i| { solid_at(m, i)?; geo(m, i, LAT) }, set: |m, i, t| set_geo(m, i, t, LAT) },
    Spec { name: "centre lon", unit: "°", keys: &["center", "longitude"], get: |m, i| { solid_at(m, i)?; geo(m, i, LON) }, set: |m, i, t| set_geo(m, i, t, LON) },
    Spec { name: "radius", unit: "m", keys: &["radius"], get: |m, i| num(solid_at(m, i)?.radius), set: |m, i, t| { let r = number(t)?; obstacle(m, i)?.set_radius(r); Ok(()) } },
    Spec { name: "height", unit: "m", keys: &["height"], get: |m, i| num(solid_at(m, i)?.height), set: |m, i, t| put(&mut obstacle(m, i)?.height, number(t)) },
    Spec { name: "wire from x", unit: "m", keys: &["wire", "from"], get: |m, i| num(wire_at(m, i)?.from.x), set: |m, i, t| set_wire(m, i, 0, 0, t) },
    Spec { name: "wire from y", unit: "m", keys: &["wire", "from"], get: |m, i| num(wire_at(m, i)?.from.y), set: |m, i, t| set_wire(m, i, 0, 1, t) },
    Spec { name: "wire from z", unit: "m", keys: &["wire", "from"], get: |m, i| num(wire_at(m, i)?.from.z), set: |m, i, t| set_wire(m, i, 0, 2, t) },
    Spec { name: "wire to x", unit: "m", keys: &["wire", "to"], get: |m, i| num(wire_at(m, i)?.to.x), set: |m, i, t| set_wire(m, i, 1, 0, t) },
    Spec { name: "wire to y", unit: "m", keys: &["wire", "to"], get: |m, i| num(wire_at(m, i)?.to.y), set: |m, i, t| set_wire(m, i, 1, 1, t) },
    Spec { name: "wire to z", unit: "m", keys: &["wire", "to"], get: |m, i| num(wire_at(m, i)?.to.z), set: |m, i, t| set_wire(m, i, 1, 2, t) },
    Spec { name: "wire radius", unit: "m", keys: &["wire", "radius"], get: |m, i| num(wire_at(m, i)?.radius), set: |m, i, t| { let r = number(t)?; obstacle(m, i)?.set_radius(r); Ok(()) } },
    Spec { name: "inspect (eq. 8)", unit: "", keys: &["inspect"], get: |m, i| yes(obstacle_at(m, i)?.inspect), set: |m, i, t| put(&mut obstacle(m, i)?.inspect, yes_no(t)) },
    Spec { name: "stand-off min", unit: "m", keys: &["stand_off"], get: |m, i| num(obstacle_at(m, i)?.stand_off_band(&m.formation)[0]), set: |m, i, t| set_stand_off(m, i, 0, t) },
    Spec { name: "stand-off max", unit: "m", keys: &["stand_off"], get: |m, i| num(obstacle_at(m, i)?.stand_off_band(&m.formation)[1]), set: |m, i, t| set_stand_off(m, i, 1, t) },
    Spec { name: "inspect side", unit: "", keys: &["inspect_side"], get: |m, i| text(obstacle_at(m, i)?.inspect_side.as_ref().map_or_else(|| "any".to_owned(), |s| s.label())), set: |m, i, t| put(&mut obstacle(m, i)?.inspect_side, side(t)) },
    Spec { name: "base", unit: "m", keys: &["base"], get: |m, i| num(solid_at(m, i)?.base), set: |m, i, t| put(&mut obstacle(m, i)?.base, number(t)) },
    Spec { name: "overfly", unit: "", keys: &["overfly"], get: |m, i| yes(obstacle_at(m, i)?.overfly), set: |m, i, t| put(&mut obstacle(m, i)?.overfly, yes_no(t)) },
    Spec { name: "clearance above", unit: "m", keys: &["clearance_above"], get: |m, i| num(obstacle_at(m, i)?.clearance_above), set: |m, i, t| put(&mut obstacle(m, i)?.clearance_above, number(t)) },
]};

/// A footprint's vertex: moving it reshapes the footprint, whose centre and
/// radius follow (its bounding circle, `Obstacle::settle`).
#[rustfmt::skip]
static VERTEX: Table = Table { base: &[Key("obstacles"), Index, Key("footprint"), Vertex], derived: &[], fields: &[
    Spec { name: "x", unit: "m", keys: &[], get: |m, i| num(vertex_at(m, i)?.x), set: |m, i, t| set_vertex(m, i, 0, t) },
    Spec { name: "y", unit: "m", keys: &[], get: |m, i| num(vertex_at(m, i)?.y), set: |m, i, t| set_vertex(m, i, 1, t) },
]};

#[rustfmt::skip]
static FORMATION: Table = Table { base: &[], derived: &[
    Spec { name: "UAVs", unit: "", keys: &["formation", "slots"], get: |m, _| text(m.formation.slots.len()), set: |m, _, t| set_uav_count(m, t) },
    Spec { name: "preset", unit: "", keys: &["formation", "slots"], get: |m, _| text(Preset::detect(&m.formation.slots).map_or("custom", |(p, _)| p.name())), set: |m, _, t| set_preset(m, t) },
    Spec { name: "spacing", unit: "m", keys: &["formation", "slots"], get: |m, _| num(spacing_of(m)), set: |m, _, t| set_spacing(m, t) },
], fields: &[
    Spec { name: "UAV radius r_Q", unit: "m", keys: &["formation", "uav_radius"], get: |m, _| num(m.formation.uav_radius), set: |m, _, t| put(&mut m.formation.uav_radius, number(t)) },
    Spec { name: "ground speed", unit: "m/s", keys: &["formation", "ground_speed"], get: |m, _| num(m.formation.ground_speed), set: |m, _, t| put(&mut m.formation.ground_speed, number(t)) },
    Spec { name: "comm range", unit: "m", keys: &["formation", "comm_range"], get: |m, _| num(m.formation.comm_range), set: |m, _, t| put(&mut m.formation.comm_range, number(t)) },
    Spec { name: "safety margin", unit: "m", keys: &["formation", "safety_margin"], get: |m, _| num(m.formation.safety_margin), set: |m, _, t| put(&mut m.formation.safety_margin, number(t)) },
    Spec { name: "obstacle margin", unit: "m", keys: &["formation", "obstacle_margin"], get: |m, _| num(m.formation.obstacle_margin), set: |m, _, t| put(&mut m.formation.obstacle_margin, number(t)) },
    Spec { name: "max speed", unit: "m/s", keys: &["vehicle", "max_speed"], get: |m, _| num(m.vehicle.max_speed), set: |m, _, t| put(&mut m.vehicle.max_speed, number(t)) },
    Spec { name: "max climb", unit: "m/s", keys: &["vehicle", "max_climb_rate"], get: |m, _| num(m.vehicle.max_climb_rate), set: |m, _, t| put(&mut m.vehicle.max_climb_rate, number(t)) },
    Spec { name: "max descent", unit: "m/s", keys: &["vehicle", "max_descent_rate"], get: |m, _| num(m.vehicle.max_descent_rate), set: |m, _, t| put(&mut m.vehicle.max_descent_rate, number(t)) },
    Spec { name: "max accel", unit: "m/s²", keys: &["vehicle", "max_acceleration"], get: |m, _| num(m.vehicle.max_acceleration), set: |m, _, t| put(&mut m.vehicle.max_acceleration, number(t)) },
    Spec { name: "accel up", unit: "m/s²", keys: &["vehicle", "max_acceleration_up"], get: |m, _| num(m.vehicle.max_acceleration_up), set: |m, _, t| put(&mut m.vehicle.max_acceleration_up, number(t)) },
    Spec { name: "accel down", unit: "m/s²", keys: &["vehicle", "max_acceleration_down"], get: |m, _| num(m.vehicle.max_acceleration_down), set: |m, _, t| put(&mut m.vehicle.max_acceleration_down, number(t)) },
    Spec { name: "position gain xy", unit: "/s", keys: &["vehicle", "position_gain_xy"], get: |m, _| num(m.vehicle.position_gain_xy), set: |m, _, t| put(&mut m.vehicle.position_gain_xy, number(t)) },
    Spec { name: "position gain z", unit: "/s", keys: &["vehicle", "position_gain_z"], get: |m, _| num(m.vehicle.position_gain_z), set: |m, _, t| put(&mut m.vehicle.position_gain_z, number(t)) },
    Spec { name: "velocity gain xy", unit: "/s", keys: &["vehicle", "velocity_gain_xy"], get: |m, _| num(m.vehicle.velocity_gain_xy), set: |m, _, t| put(&mut m.vehicle.velocity_gain_xy, number(t)) },
    Spec { name: "velocity gain z", unit: "/s", keys: &["vehicle", "velocity_gain_z"], get: |m, _| num(m.vehicle.velocity_gain_z), set: |m, _, t| put(&mut m.vehicle.velocity_gain_z, number(t)) },
    Spec { name: "velocity I xy", unit: "/s²", keys: &["vehicle", "velocity_integral_xy"], get: |m, _| num(m.vehicle.velocity_integral_xy), set: |m, _, t| put(&mut m.vehicle.velocity_integral_xy, number(t)) },
    Spec { name: "velocity I z", unit: "/s²", keys: &["vehicle", "velocity_integral_z"], get: |m, _| num(m.vehicle.velocity_integral_z), set: |m, _, t| put(&mut m.vehicle.velocity_integral_z, number(t)) },
    Spec { name: "surface d min", unit: "m", keys: &["formation", "surface_distance"], get: |m, _| num(m.formation.surface_distance[0]), set: |m, _, t| put(&mut m.formation.surface_distance[0], number(t)) },
    Spec { name: "surface d max", unit: "m", keys: &["formation", "surface_distance"], get: |m, _| num(m.formation.surface_distance[1]), set: |m, _, t| put(&mut m.formation.surface_distance[1], number(t)) },
    Spec { name: "inspection pass", unit: "m", keys: &["formation", "inspection_pass"], get: |m, _| num(m.formation.inspection_pass), set: |m, _, t| put(&mut m.formation.inspection_pass, number(t)) },
    Spec { name: "default shape", unit: "", keys: &["reconfiguration", "default_shape"], get: |m, _| text(shape_name(m.reconfiguration.default_shape)), set: |m, _, t| put(&mut m.reconfiguration.default_shape, shape(t)) },
    Spec { name: "shrink scale", unit: "", keys: &["reconfiguration", "shrink_scale"], get: |m, _| num(m.reconfiguration.shrink_scale), set: |m, _, t| put(&mut m.reconfiguration.shrink_scale, number(t)) },
    Spec { name: "transition", unit: "m", keys: &["reconfiguration", "transition_distance"], get: |m, _| num(m.reconfiguration.transition_distance), set: |m, _, t| put(&mut m.reconfiguration.transition_distance, number(t)) },
    Spec { name: "hold", unit: "m", keys: &["reconfiguration", "hold_distance"], get: |m, _| num(m.reconfiguration.hold_distance), set: |m, _, t| put(&mut m.reconfiguration.hold_distance, number(t)) },
]};

#[rustfmt::skip]
static SLOT: Table = Table { base: &[Key("formation"), Key("slots"), Index], derived: &[], fields: &[
    Spec { name: "forward x", unit: "m", keys: &[], get: |m, i| num(slot_at(m, i)?.x), set: |m, i, t| put(&mut slot(m, i)?.x, number(t)) },
    Spec { name: "left y", unit: "m", keys: &[], get: |m, i| num(slot_at(m, i)?.y), set: |m, i, t| put(&mut slot(m, i)?.y, number(t)) },
    Spec { name: "up z", unit: "m", keys: &[], get: |m, i| num(slot_at(m, i)?.z), set: |m, i, t| put(&mut slot(m, i)?.z, number(t)) },
]};

/// An IWP's reconfiguration choice: the defaults until the first edit
/// creates its entry.
#[rustfmt::skip]
static WAYPOINT: Table = Table { base: &[Key("reconfiguration"), Key("waypoints"), Index], derived: &[], fields: &[
    Spec { name: "obstacles", unit: "", keys: &["between"], get: |_, i| between(i), set: |_, _, _| Err("an IWP is named by its two obstacles: rename an obstacle, or Del deletes this choice".into()) },
    Spec { name: "enabled", unit: "", keys: &["enabled"], get: |m, i| yes(choice_at(m, i).is_none_or(|c| c.enabled)), set: |m, i, t| set_choice(m, i, yes_no(t), |c| &mut c.enabled) },
    Spec { name: "shape", unit: "", keys: &["shape"], get: |m, i| text(shape_name(choice_at(m, i).map_or(ShapeChoice::Auto, |c| c.shape))), set: |m, i, t| set_choice(m, i, shape(t), |c| &mut c.shape) },
    Spec { name: "scale (blank: default)", unit: "", keys: &["scale"], get: |m, i| text(choice_at(m, i).and_then(|c| c.scale).map(fmt_num).unwrap_or_default()), set: |m, i, t| set_choice(m, i, blank_or(number, t), |c| &mut c.scale) },
]};

// Reading and writing the values as text.

const LAT: bool = true;
const LON: bool = false;

/// Where a positioned item is on the ground plane (x, y), metres ENU.
fn ground_xy(m: &Mission, item: &Item) -> Option<Point2<f64>> {
    match item {
        Item::Start => Some(m.route.start.xy()),
        Item::Goal => Some(m.route.goal.xy()),
        Item::Obstacle(_) => obstacle_at(m, item).map(|o| o.center),
        _ => None,
    }
}

/// The item's latitude or longitude through `[origin]` (the geodesy of the
/// files and exports); empty for a mission without an origin.
fn geo(m: &Mission, item: &Item, lat: bool) -> Option<String> {
    Some(geo_text(m, ground_xy(m, item)?, lat))
}

/// Moves the item to a typed latitude or longitude (the other and its
/// height kept). The value shown, applied again, moves nothing.
fn set_geo(m: &mut Mission, item: &Item, text: &str, lat: bool) -> Result<(), String> {
    let here = ground_xy(m, item).ok_or("the item is gone")?;
    let p = geo_moved(m, here, text, lat)?;
    match item {
        Item::Start => (m.route.start.x, m.route.start.y) = (p.x, p.y),
        Item::Goal => (m.route.goal.x, m.route.goal.y) = (p.x, p.y),
        Item::Obstacle(_) => obstacle(m, item)?.move_to(p),
        _ => return Err("this item has no position".into()),
    }
    Ok(())
}

fn yes(value: bool) -> Option<String> {
    text(if value { "yes" } else { "no" })
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

fn yes_no(text: &str) -> Result<bool, String> {
    match text.to_ascii_lowercase().as_str() {
        "yes" | "y" | "true" | "on" | "1" => Ok(true),
        "no" | "n" | "false" | "off" | "0" => Ok(false),
        _ => Err(format!("'{text}' is not yes or no")),
    }
}

fn seed(text: &str) -> Result<u64, String> {
    text.parse()
        .map_err(|_| format!("'{text}' is not a seed (0 … 2⁶⁴-1)"))
}

/// None for an empty text, else what `parse` makes of it.
fn blank_or<T>(parse: fn(&str) -> Result<T, String>, text: &str) -> Result<Option<T>, String> {
    if text.is_empty() {
        Ok(None)
    } else {
        parse(text).map(Some)
    }
}

fn geotiff(text: &str) -> Result<String, String> {
    if text.trim().is_empty() {
        return Err("the terrain needs a GeoTIFF file".into());
    }
    Ok(text.trim().to_owned())
}

fn lookup(text: &str) -> Result<Lookup, String> {
    match text.trim() {
        "nearest" => Ok(Lookup::Nearest),
        "bilinear" => Ok(Lookup::Bilinear),
        other => Err(format!("'{other}' is not a lookup: nearest or bilinear")),
    }
}

fn lookup_name(lookup: Lookup) -> &'static str {
    match lookup {
        Lookup::Nearest => "nearest",
        Lookup::Bilinear => "bilinear",
    }
}

/// The two obstacles an IWP choice names.
fn between(item: &Item) -> Option<String> {
    match item {
        Item::Waypoint([a, b]) => Some(format!("{a} ↔ {b}")),
        _ => None,
    }
}

// The formation's shape, worked out from its slots.

/// Most UAVs the designer makes a formation of (eq. 7 checks every pair).
const MOST_UAVS: usize = 1000;

/// A new number of UAVs: a preset stays that preset (at a spacing valid for
/// the mission), a custom shape gains slots behind or loses its last ones.
fn set_uav_count(m: &mut Mission, t: &str) -> Result<(), String> {
    let n = count(t)?;
    if n == 0 {
        return Err("a formation needs at least one UAV".into());
    }
    if n > MOST_UAVS {
        return Err(format!("at most {MOST_UAVS} UAVs"));
    }
    match Preset::detect(&m.formation.slots) {
        Some((preset, _)) if m.formation.slots.len() > 1 => {
            crate::mission::reshape(m, preset, n, None).map(|_| ())
        }
        _ => {
            let spacing = spacing_of(m);
            m.formation.slots = crate::mission::resize_custom(&m.formation.slots, n, spacing);
            Ok(())
        }
    }
}

/// A preset by name, at a spacing valid for the mission.
fn set_preset(m: &mut Mission, t: &str) -> Result<(), String> {
    let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
    let Some(preset) = Preset::named(t) else {
        return Err(format!(
            "'{t}' is not a preset: {} (a custom shape: move the slots)",
            names.join(", ")
        ));
    };
    let n = m.formation.slots.len().max(1);
    crate::mission::reshape(m, preset, n, None).map(|_| ())
}

/// The distance between neighbours: a preset is made again at it, a custom
/// shape scaled so its closest pair is that far apart.
fn set_spacing(m: &mut Mission, t: &str) -> Result<(), String> {
    let spacing = number(t)?;
    if spacing <= 0.0 {
        return Err(format!("the spacing must be positive, got {spacing} m"));
    }
    let n = m.formation.slots.len();
    match Preset::detect(&m.formation.slots) {
        Some((preset, _)) if n > 1 => {
            crate::mission::reshape(m, preset, n, Some(spacing)).map(|_| ())
        }
        _ if n > 1 => {
            let now = crate::mission::min_pair_distance(&m.formation.slots);
            m.formation.slots = crate::mission::rescale(&m.formation.slots, spacing / now);
            Ok(())
        }
        _ => Err("one UAV has no spacing: add UAVs first".into()),
    }
}

// The selected item in the mission, to read (`…_at`) and to write.

fn via_at<'m>(m: &'m Mission, item: &Item) -> Option<&'m crate::mission::Via> {
    match item {
        Item::Via(i) => m.route.via.get(*i),
        _ => None,
    }
}

fn via<'m>(m: &'m mut Mission, item: &Item) -> Result<&'m mut crate::mission::Via, String> {
    match item {
        Item::Via(i) => m.route.via.get_mut(*i).ok_or("no such via".into()),
        _ => Err("not a via".into()),
    }
}

/// One of a gate's two obstacles, by name (an obstacle the mission has).
fn set_between(m: &mut Mission, item: &Item, k: usize, text: &str) -> Result<(), String> {
    if !m.obstacles.iter().any(|o| o.name == text) {
        let near = crate::mission::nearest_name(text, m.obstacles.iter().map(|o| o.name.as_str()));
        return Err(format!(
            "no obstacle is named '{text}'{}",
            near.map(|n| format!(" (did you mean '{n}'?)"))
                .unwrap_or_default()
        ));
    }
    let v = via(m, item)?;
    let pair = v
        .between
        .as_mut()
        .ok_or("a via point: it has no obstacles")?;
    pair[k] = text.to_owned();
    Ok(())
}

/// One coordinate (0-2) of a via point.
fn set_via_point(m: &mut Mission, item: &Item, axis: usize, text: &str) -> Result<(), String> {
    let value = number(text)?;
    let v = via(m, item)?;
    let p = v.point.as_mut().ok_or("a gate: it has no point")?;
    p[axis] = value;
    Ok(())
}

/// An obstacle that is not a wire (whose box the wire's own fields set).
fn solid_at<'m>(m: &'m Mission, item: &Item) -> Option<&'m Obstacle> {
    obstacle_at(m, item).filter(|o| !o.is_wire())
}

/// A wire obstacle's span.
fn wire_at<'m>(m: &'m Mission, item: &Item) -> Option<&'m crate::mission::Wire> {
    obstacle_at(m, item)?.wire.as_ref()
}

/// One coordinate (`axis` 0-2) of one end (`end` 0: from, 1: to) of a
/// wire; its box follows.
fn set_wire(
    m: &mut Mission,
    item: &Item,
    end: usize,
    axis: usize,
    text: &str,
) -> Result<(), String> {
    let v = number(text)?;
    let o = obstacle(m, item)?;
    let w = o.wire.as_mut().ok_or("not a wire")?;
    let p = if end == 0 { &mut w.from } else { &mut w.to };
    p[axis] = v;
    o.settle();
    Ok(())
}

/// An inspected side: `any` (or nothing) for none, a bearing in degrees,
/// or a compass point.
fn side(text: &str) -> Result<Option<crate::mission::Side>, String> {
    use crate::mission::Side;
    let t = text.trim();
    if t.is_empty() || t.eq_ignore_ascii_case("any") {
        return Ok(None);
    }
    let side = match t.trim_end_matches('°').trim().parse::<f64>() {
        Ok(d) => Side::Degrees(d),
        Err(_) => Side::Named(t.to_owned()),
    };
    match side.bearing() {
        Some(_) => Ok(Some(side)),
        None => Err(format!(
            "a bearing in degrees clockwise from north (90: east), a compass point ({}), or any",
            Side::NAMES
                .iter()
                .map(|(n, _, _)| *n)
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

fn obstacle_at<'m>(m: &'m Mission, item: &Item) -> Option<&'m Obstacle> {
    match item {
        Item::Obstacle(i) => m.obstacles.get(*i),
        _ => None,
    }
}

fn obstacle<'m>(m: &'m mut Mission, item: &Item) -> Result<&'m mut Obstacle, String> {
    match item {
        Item::Obstacle(i) => m.obstacles.get_mut(*i).ok_or("no such obstacle".into()),
        _ => Err("not an obstacle".into()),
    }
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

/// A new name for an obstacle; the IWP choices that named it follow.
fn rename_obstacle(m: &mut Mission, item: &Item, text: &str) -> Result<(), String> {
    let old = std::mem::replace(&mut obstacle(m, item)?.name, text.to_owned());
    rename_references(m, &old, text);
    Ok(())
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

fn vertex_at(m: &Mission, item: &Item) -> Option<Point2<f64>> {
    match item {
        Item::Vertex(i, v) => m.obstacles.get(*i)?.footprint.get(*v).copied(),
        _ => None,
    }
}

/// One coordinate (0: x, 1: y) of the selected vertex, the footprint's
/// bounding circle following.
fn set_vertex(m: &mut Mission, item: &Item, axis: usize, t: &str) -> Result<(), String> {
    let Item::Vertex(i, v) = item else {
        return Err("not a vertex".into());
    };
    let value = number(t)?;
    let o = m.obstacles.get_mut(*i).ok_or("no such obstacle")?;
    let p = o.footprint.get_mut(*v).ok_or("no such vertex")?;
    p[axis] = value;
    o.settle();
    Ok(())
}

fn slot_at<'m>(m: &'m Mission, item: &Item) -> Option<&'m Vector3<f64>> {
    match item {
        Item::Slot(i) => m.formation.slots.get(*i),
        _ => None,
    }
}

fn slot<'m>(m: &'m mut Mission, item: &Item) -> Result<&'m mut Vector3<f64>, String> {
    match item {
        Item::Slot(i) => m.formation.slots.get_mut(*i).ok_or("no such slot".into()),
        _ => Err("not a slot".into()),
    }
}

fn terrain(m: &mut Mission) -> Result<&mut Terrain, String> {
    m.terrain
        .as_mut()
        .ok_or_else(|| "the mission has no [terrain]".to_owned())
}

/// The reconfiguration entry of an IWP, if the file has one.
fn choice_at<'m>(m: &'m Mission, item: &Item) -> Option<&'m WaypointChoice> {
    let Item::Waypoint([a, b]) = item else {
        return None;
    };
    m.reconfiguration.choice(a, b)
}

/// Writes one value of an IWP's choice. The text is parsed before the entry
/// is created, so a refused text leaves the mission as it was.
fn set_choice<T>(
    m: &mut Mission,
    item: &Item,
    value: Result<T, String>,
    place: fn(&mut WaypointChoice) -> &mut T,
) -> Result<(), String> {
    let value = value?;
    *place(waypoint_choice(m, item)?) = value;
    Ok(())
}

/// An `[origin]` value for the inspector: empty when the mission has none.
fn origin(m: &Mission, get: fn(&GeoOrigin) -> f64) -> Option<String> {
    Some(
        m.origin
            .as_ref()
            .map_or_else(String::new, |o| fmt_num(get(o))),
    )
}

/// One value of `[origin]`.
#[derive(Clone, Copy, PartialEq)]
enum OriginPart {
    Latitude,
    Longitude,
    Altitude,
}

/// Sets one `[origin]` value (creating the section at 0°, 0°, 0 m). An
/// empty text clears that value alone: the altitude goes back to 0 m; an
/// origin cannot lack its latitude or longitude, so the message says how to
/// remove the whole section (`none`; exports then write CSV in ENU only).
fn set_origin(m: &mut Mission, text: &str, part: OriginPart) -> Result<(), String> {
    let text = text.trim();
    if text.eq_ignore_ascii_case("none") {
        m.origin = None;
        return Ok(());
    }
    let value = match (text.is_empty(), part) {
        (false, _) => number(text)?,
        (true, OriginPart::Altitude) => 0.0,
        (true, _) if m.origin.is_none() => return Ok(()),
        (true, _) => {
            return Err(
                "an [origin] needs a latitude and a longitude; type none to remove the origin"
                    .into(),
            );
        }
    };
    let origin = m.origin.get_or_insert(GeoOrigin {
        latitude: 0.0,
        longitude: 0.0,
        altitude: 0.0,
    });
    match part {
        OriginPart::Latitude => origin.latitude = value,
        OriginPart::Longitude => origin.longitude = value,
        OriginPart::Altitude => origin.altitude = value,
    }
    Ok(())
}
