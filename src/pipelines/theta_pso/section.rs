//! `[theta_pso]` as a unit of the mission: its rules (the swarm's sizes and
//! weights, and what `cost = "spso"` and the spherical encoding need of the
//! rest of the mission), registered with the file's (`mission::SECTION_RULES`),
//! which run them whenever a mission is read or checked, naming no pipeline.

use crate::mission::{Checker, FieldPath, SECTION_RULES, SectionRules, ThetaPsoParams};
use crate::mission::{CostKind, Encoding};
use crate::pipelines::rows::{Row, count, num, number, put, text};

#[linkme::distributed_slice(SECTION_RULES)]
static RULES: SectionRules = SectionRules {
    key: "theta_pso",
    check: |c, path, mission| c.theta_pso(path, &mission.theta_pso, mission.terrain.is_some()),
};

/// The inspector's rows of `[theta_pso]`: every key (`Pipeline::rows`).
#[rustfmt::skip]
pub(super) static ROWS: &[Row] = &[
    Row { name: "swarm size", unit: "", keys: &["swarm_size"], get: |m| text(m.theta_pso.swarm_size), set: |m, t| put(&mut m.theta_pso.swarm_size, count(t)) },
    Row { name: "waypoints", unit: "", keys: &["waypoints"], get: |m| text(m.theta_pso.waypoints), set: |m, t| put(&mut m.theta_pso.waypoints, count(t)) },
    Row { name: "iterations", unit: "", keys: &["iterations"], get: |m| text(m.theta_pso.iterations), set: |m, t| put(&mut m.theta_pso.iterations, count(t)) },
    Row { name: "restarts", unit: "", keys: &["restarts"], get: |m| text(m.theta_pso.restarts), set: |m, t| put(&mut m.theta_pso.restarts, count(t)) },
    Row { name: "seeded particles", unit: "", keys: &["seeded_particles"], get: |m| text(m.theta_pso.seeded_particles), set: |m, t| put(&mut m.theta_pso.seeded_particles, count(t)) },
    Row { name: "clearance margin", unit: "m", keys: &["clearance_margin"], get: |m| num(m.theta_pso.clearance_margin), set: |m, t| put(&mut m.theta_pso.clearance_margin, number(t)) },
    Row { name: "inertia w", unit: "", keys: &["inertia"], get: |m| num(m.theta_pso.inertia), set: |m, t| put(&mut m.theta_pso.inertia, number(t)) },
    Row { name: "cognitive c1", unit: "", keys: &["cognitive"], get: |m| num(m.theta_pso.cognitive), set: |m, t| put(&mut m.theta_pso.cognitive, number(t)) },
    Row { name: "social c2", unit: "", keys: &["social"], get: |m| num(m.theta_pso.social), set: |m, t| put(&mut m.theta_pso.social, number(t)) },
    Row { name: "segments L", unit: "", keys: &["segments"], get: |m| text(m.theta_pso.segments), set: |m, t| put(&mut m.theta_pso.segments, count(t)) },
    Row { name: "β1 length", unit: "", keys: &["weight_length"], get: |m| num(m.theta_pso.weight_length), set: |m, t| put(&mut m.theta_pso.weight_length, number(t)) },
    Row { name: "β2 obstacle", unit: "", keys: &["weight_obstacle"], get: |m| num(m.theta_pso.weight_obstacle), set: |m, t| put(&mut m.theta_pso.weight_obstacle, number(t)) },
    Row { name: "β3 altitude", unit: "", keys: &["weight_altitude"], get: |m| num(m.theta_pso.weight_altitude), set: |m, t| put(&mut m.theta_pso.weight_altitude, number(t)) },
    Row { name: "βR waypoints", unit: "", keys: &["weight_waypoints"], get: |m| num(m.theta_pso.weight_waypoints), set: |m, t| put(&mut m.theta_pso.weight_waypoints, number(t)) },
    Row { name: "J_B bounds weight", unit: "", keys: &["weight_bounds"], get: |m| num(m.theta_pso.weight_bounds), set: |m, t| put(&mut m.theta_pso.weight_bounds, number(t)) },
    Row { name: "J_T turning weight", unit: "", keys: &["weight_turning"], get: |m| num(m.theta_pso.weight_turning), set: |m, t| put(&mut m.theta_pso.weight_turning, number(t)) },
    Row { name: "ground penalty", unit: "", keys: &["ground_penalty"], get: |m| num(m.theta_pso.ground_penalty), set: |m, t| put(&mut m.theta_pso.ground_penalty, number(t)) },
    Row { name: "cost", unit: "", keys: &["cost"], get: |m| text(cost_name(m.theta_pso.cost)), set: |m, t| put(&mut m.theta_pso.cost, cost(t)) },
    Row { name: "encoding", unit: "", keys: &["encoding"], get: |m| text(encoding_name(m.theta_pso.encoding)), set: |m, t| put(&mut m.theta_pso.encoding, encoding(t)) },
];

fn cost(text: &str) -> Result<CostKind, String> {
    match text.trim().to_ascii_lowercase().as_str() {
        "paper" => Ok(CostKind::Paper),
        "spso" => Ok(CostKind::Spso),
        other => Err(format!("'{other}' is not a cost: paper or spso")),
    }
}

fn cost_name(cost: CostKind) -> &'static str {
    match cost {
        CostKind::Paper => "paper",
        CostKind::Spso => "spso",
    }
}

fn encoding(text: &str) -> Result<Encoding, String> {
    match text.trim().to_ascii_lowercase().as_str() {
        "angle" => Ok(Encoding::Angle),
        "spherical" => Ok(Encoding::Spherical),
        other => Err(format!("'{other}' is not an encoding: angle or spherical")),
    }
}

fn encoding_name(encoding: Encoding) -> &'static str {
    match encoding {
        Encoding::Angle => "angle",
        Encoding::Spherical => "spherical",
    }
}

impl Checker {
    /// `[theta_pso]`, and what `cost = "spso"` and the spherical encoding
    /// need of the rest of the mission (a `[terrain]`: `has_terrain`).
    fn theta_pso(&mut self, path: &FieldPath, p: &ThetaPsoParams, has_terrain: bool) {
        if p.cost == CostKind::Spso {
            if !has_terrain {
                self.error(
                    path.key("cost"),
                    "\"spso\" needs a [terrain] height map (its J3 and J4 read the ground)",
                );
            }
            let most = crate::mission::SPSO_MAX_NODES;
            if p.waypoints > most {
                self.error(
                    path.key("waypoints"),
                    format!("the SPSO cost takes at most {most} free nodes"),
                );
            }
        } else if p.encoding == Encoding::Spherical {
            self.error(
                path.key("encoding"),
                "\"spherical\" encodes the SPSO benchmark's paths: it needs cost = \"spso\"",
            );
        }
        self.at_least_one(path.key("swarm_size"), p.swarm_size, "particle");
        self.at_least_one(path.key("waypoints"), p.waypoints, "waypoint");
        self.at_least_one(path.key("iterations"), p.iterations, "iteration");
        if p.segments < p.waypoints + 1 {
            self.error(
                path.key("segments"),
                format!(
                    "{} segments cannot split a path through {} waypoints; \
                     needs at least {}",
                    p.segments,
                    p.waypoints,
                    p.waypoints + 1
                ),
            );
        }
        for (key, value) in [
            ("inertia", p.inertia),
            ("cognitive", p.cognitive),
            ("social", p.social),
            ("weight_length", p.weight_length),
            ("weight_obstacle", p.weight_obstacle),
            ("weight_altitude", p.weight_altitude),
            ("weight_waypoints", p.weight_waypoints),
            ("weight_bounds", p.weight_bounds),
            ("weight_turning", p.weight_turning),
            ("clearance_margin", p.clearance_margin),
        ] {
            self.non_negative(path.key(key), value, "");
        }
        self.positive(path.key("ground_penalty"), p.ground_penalty, "");
        if p.inertia >= 1.0 {
            self.warning(
                path.key("inertia"),
                format!(
                    "w = {} ≥ 1 lets the swarm's velocities grow without bound",
                    p.inertia
                ),
            );
        }
        if p.weight_obstacle == 0.0 {
            self.warning(
                path.key("weight_obstacle"),
                "is 0: the planner will ignore obstacles (the result is still verified)",
            );
        }
    }
}
