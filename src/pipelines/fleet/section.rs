//! `[fleet]` as a unit of the mission: its rules (`rules.rs`), registered
//! with the file's (`mission::SECTION_RULES`); its inspector rows and its
//! targets' (`Pipeline::rows`, `PointKind::rows`); and its targets and
//! initial positions,
//! which a file may write as latitude/longitude
//! (`mission::geodetic::SECTION_POSITIONS`). The mission's floor runs and
//! converts them whenever a mission is read, naming no pipeline.

use crate::mission::FleetTarget;
use crate::mission::geodetic::{Position, SECTION_POSITIONS, SectionPositions, Slot, Step};
use crate::mission::{FieldPath, Mission, SECTION_RULES, SectionRules};
use crate::pipelines::rows::{
    PointRow, Row, auto_or_number, count, fmt_num, geo_moved, geo_text, in_the_file, listed, num,
    number, put, text,
};
use nalgebra::Point2;

#[linkme::distributed_slice(SECTION_RULES)]
static RULES: SectionRules = SectionRules {
    key: "fleet",
    check: |c, path, mission| c.fleet(path, &mission.fleet, mission),
};

#[linkme::distributed_slice(SECTION_POSITIONS)]
static POSITIONS: SectionPositions = SectionPositions {
    slots: &[
        Slot {
            steps: &[
                Step::Key("fleet"),
                Step::Key("targets"),
                Step::Each,
                Step::Key("position"),
            ],
            air: false,
        },
        Slot {
            steps: &[
                Step::Key("fleet"),
                Step::Key("initial_positions"),
                Step::Each,
            ],
            air: false,
        },
    ],
    positions: |m| {
        let fleet = FieldPath::root().key("fleet");
        let targets = m.fleet.targets.iter().enumerate().map(|(i, t)| {
            let path = fleet.key("targets").index(i).key("position");
            (path, Position::Ground(t.position))
        });
        let starts = m.fleet.initial_positions.iter().enumerate().map(|(i, p)| {
            let path = fleet.key("initial_positions").index(i);
            (path, Position::Ground(*p))
        });
        targets.chain(starts).collect()
    },
};

/// The inspector's rows of `[fleet]` (Table 1, the scenario, the quadrotor);
/// its matrices and lists are shown, edited in the file (`Pipeline::rows`).
#[rustfmt::skip]
pub(super) static ROWS: &[Row] = &[
    Row { name: "agents n", unit: "", keys: &["agents"], get: |m| text(m.fleet.agents), set: |m, t| put(&mut m.fleet.agents, count(t)) },
    Row { name: "ρ target weight", unit: "", keys: &["rho"], get: |m| num(m.fleet.rho), set: |m, t| put(&mut m.fleet.rho, number(t)) },
    Row { name: "σ steepness", unit: "", keys: &["sigma"], get: |m| num(m.fleet.sigma), set: |m, t| put(&mut m.fleet.sigma, number(t)) },
    Row { name: "c safety", unit: "m", keys: &["safety_distance"], get: |m| num(m.fleet.safety_distance), set: |m, t| put(&mut m.fleet.safety_distance, number(t)) },
    Row { name: "l neighbourhood", unit: "m", keys: &["neighbourhood"], get: |m| num(m.fleet.neighbourhood), set: |m, t| put(&mut m.fleet.neighbourhood, number(t)) },
    Row { name: "d_obs detection", unit: "m", keys: &["detection_range"], get: |m| num(m.fleet.detection_range), set: |m, t| put(&mut m.fleet.detection_range, number(t)) },
    Row { name: "h_max step", unit: "m", keys: &["step_max"], get: |m| num(m.fleet.step_max), set: |m, t| put(&mut m.fleet.step_max, number(t)) },
    Row { name: "τ replan", unit: "s", keys: &["replan_period"], get: |m| num(m.fleet.replan_period), set: |m, t| put(&mut m.fleet.replan_period, number(t)) },
    Row { name: "d_ip to target", unit: "m", keys: &["target_distance"], get: |m| num(m.fleet.target_distance), set: |m, t| put(&mut m.fleet.target_distance, number(t)) },
    Row { name: "altitude", unit: "m", keys: &["altitude"], get: |m| num(m.fleet.altitude), set: |m, t| put(&mut m.fleet.altitude, number(t)) },
    Row { name: "duration", unit: "s", keys: &["duration"], get: |m| text(m.fleet.duration.map_or_else(|| "auto".to_owned(), fmt_num)), set: |m, t| put(&mut m.fleet.duration, auto_or_number(t)) },
    Row { name: "tolerance", unit: "", keys: &["tolerance"], get: |m| num(m.fleet.tolerance), set: |m, t| put(&mut m.fleet.tolerance, number(t)) },
    Row { name: "PSO particles", unit: "", keys: &["swarm_size"], get: |m| text(m.fleet.swarm_size), set: |m, t| put(&mut m.fleet.swarm_size, count(t)) },
    Row { name: "PSO iterations", unit: "", keys: &["iterations"], get: |m| text(m.fleet.iterations), set: |m, t| put(&mut m.fleet.iterations, count(t)) },
    Row { name: "PSO inertia w", unit: "", keys: &["inertia"], get: |m| num(m.fleet.inertia), set: |m, t| put(&mut m.fleet.inertia, number(t)) },
    Row { name: "PSO cognitive c1", unit: "", keys: &["cognitive"], get: |m| num(m.fleet.cognitive), set: |m, t| put(&mut m.fleet.cognitive, number(t)) },
    Row { name: "PSO social c2", unit: "", keys: &["social"], get: |m| num(m.fleet.social), set: |m, t| put(&mut m.fleet.social, number(t)) },
    Row { name: "dynamics step", unit: "s", keys: &["sim_step"], get: |m| num(m.fleet.sim_step), set: |m, t| put(&mut m.fleet.sim_step, number(t)) },
    Row { name: "mass", unit: "kg", keys: &["mass"], get: |m| num(m.fleet.mass), set: |m, t| put(&mut m.fleet.mass, number(t)) },
    Row { name: "inertia J x", unit: "kg·m²", keys: &["inertia_diag"], get: |m| num(m.fleet.inertia_diag.x), set: |m, t| put(&mut m.fleet.inertia_diag.x, number(t)) },
    Row { name: "inertia J y", unit: "kg·m²", keys: &["inertia_diag"], get: |m| num(m.fleet.inertia_diag.y), set: |m, t| put(&mut m.fleet.inertia_diag.y, number(t)) },
    Row { name: "inertia J z", unit: "kg·m²", keys: &["inertia_diag"], get: |m| num(m.fleet.inertia_diag.z), set: |m, t| put(&mut m.fleet.inertia_diag.z, number(t)) },
    Row { name: "K_pos position", unit: "", keys: &["position_gains"], get: |m| num(m.fleet.position_gains[0]), set: |m, t| put(&mut m.fleet.position_gains[0], number(t)) },
    Row { name: "K_pos velocity", unit: "", keys: &["position_gains"], get: |m| num(m.fleet.position_gains[1]), set: |m, t| put(&mut m.fleet.position_gains[1], number(t)) },
    Row { name: "K_att attitude", unit: "", keys: &["attitude_gains"], get: |m| num(m.fleet.attitude_gains[0]), set: |m, t| put(&mut m.fleet.attitude_gains[0], number(t)) },
    Row { name: "K_att rate", unit: "", keys: &["attitude_gains"], get: |m| num(m.fleet.attitude_gains[1]), set: |m, t| put(&mut m.fleet.attitude_gains[1], number(t)) },
    Row { name: "max thrust", unit: "N", keys: &["max_thrust"], get: |m| num(m.fleet.max_thrust), set: |m, t| put(&mut m.fleet.max_thrust, number(t)) },
    Row { name: "max tilt", unit: "°", keys: &["max_tilt_deg"], get: |m| num(m.fleet.max_tilt_deg), set: |m, t| put(&mut m.fleet.max_tilt_deg, number(t)) },
    Row { name: "distances d^d", unit: "", keys: &["distances"], get: |m| text(listed(m.fleet.distances.len(), "rows", "a uniform polygon")), set: in_the_file },
    Row { name: "initial positions", unit: "", keys: &["initial_positions"], get: |m| text(listed(m.fleet.initial_positions.len(), "positions", "seeded random")), set: in_the_file },
    Row { name: "pushes", unit: "", keys: &["pushes"], get: |m| text(listed(m.fleet.pushes.len(), "pushes", "none")), set: in_the_file },
];

/// The inspector's rows of one of `[fleet]`'s targets (`PointKind::rows`):
/// its time; a point to form around, where it is (in metres and, with an
/// `[origin]`, in degrees); a target of one point per agent, its centre and
/// how many points it has.
#[rustfmt::skip]
pub(super) static TARGET_ROWS: &[PointRow] = &[
    PointRow { name: "time", unit: "s", keys: &["time"], get: |m, i| num(target_at(m, i)?.time), set: |m, i, t| put(&mut target(m, i)?.time, number(t)) },
    PointRow { name: "x", unit: "m", keys: &["position"], get: |m, i| num(around_at(m, i)?.position.x), set: |m, i, t| put(&mut target(m, i)?.position.x, number(t)) },
    PointRow { name: "y", unit: "m", keys: &["position"], get: |m, i| num(around_at(m, i)?.position.y), set: |m, i, t| put(&mut target(m, i)?.position.y, number(t)) },
    PointRow { name: "lat", unit: "°", keys: &["position", "latitude"], get: |m, i| Some(geo_text(m, around_at(m, i)?.position, true)), set: |m, i, t| set_geo(m, i, t, true) },
    PointRow { name: "lon", unit: "°", keys: &["position", "longitude"], get: |m, i| Some(geo_text(m, around_at(m, i)?.position, false)), set: |m, i, t| set_geo(m, i, t, false) },
    PointRow { name: "centre x", unit: "m", keys: &["positions"], get: |m, i| num(each_at(m, i)?.centre().x), set: |m, i, t| { let x = number(t)?; let tg = target(m, i)?; let c = tg.centre(); tg.move_to(Point2::new(x, c.y)); Ok(()) } },
    PointRow { name: "centre y", unit: "m", keys: &["positions"], get: |m, i| num(each_at(m, i)?.centre().y), set: |m, i, t| { let y = number(t)?; let tg = target(m, i)?; let c = tg.centre(); tg.move_to(Point2::new(c.x, y)); Ok(()) } },
    PointRow { name: "points", unit: "", keys: &["positions"], get: |m, i| text(each_at(m, i)?.positions.len()), set: |_, _, _| Err("one point per agent: edit `positions` in the file (the planner assigns them)".into()) },
];

fn target_at(m: &Mission, i: usize) -> Option<&FleetTarget> {
    m.fleet.targets.get(i)
}

/// A target of one point to form around.
fn around_at(m: &Mission, i: usize) -> Option<&FleetTarget> {
    target_at(m, i).filter(|t| t.positions.is_empty())
}

/// A target of one point per agent.
fn each_at(m: &Mission, i: usize) -> Option<&FleetTarget> {
    target_at(m, i).filter(|t| !t.positions.is_empty())
}

fn target(m: &mut Mission, i: usize) -> Result<&mut FleetTarget, String> {
    m.fleet.targets.get_mut(i).ok_or("no such target".into())
}

/// Moves target `i` to a typed latitude or longitude (the other kept).
fn set_geo(m: &mut Mission, i: usize, text: &str, latitude: bool) -> Result<(), String> {
    let here = target_at(m, i).ok_or("no such target")?.position;
    let p = geo_moved(m, here, text, latitude)?;
    target(m, i)?.position = p;
    Ok(())
}
