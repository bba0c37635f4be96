//! `[theta_pso]` as a unit of the mission: its rules (the swarm's sizes and
//! weights, and what `cost = "spso"` and the spherical encoding need of the
//! rest of the mission), registered with the file's (`mission::SECTION_RULES`),
//! which run them whenever a mission is read or checked, naming no pipeline.

use crate::mission::{Checker, FieldPath, SECTION_RULES, SectionRules, ThetaPsoParams};

#[linkme::distributed_slice(SECTION_RULES)]
static RULES: SectionRules = SectionRules {
    key: "theta_pso",
    check: |c, path, mission| c.theta_pso(path, &mission.theta_pso, mission.terrain.is_some()),
};

impl Checker {
    /// `[theta_pso]`, and what `cost = "spso"` and the spherical encoding
    /// need of the rest of the mission (a `[terrain]`: `has_terrain`).
    fn theta_pso(&mut self, path: &FieldPath, p: &ThetaPsoParams, has_terrain: bool) {
        use crate::mission::{CostKind, Encoding};
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
