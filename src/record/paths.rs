//! Every entity path of a recording, in one place: the layout `docs/rerun.md`
//! documents and the viewer layout (`layout.rs`) shows. The scene is under
//! `world/`, the mission file at `mission`, each pipeline under its own root.

use crate::pipelines::Kind;

pub const WORLD: &str = "world";
pub const BOUNDS: &str = "world/bounds";
pub const OBSTACLES: &str = "world/obstacles";
/// Obstacles with a polygon footprint, one mesh each (`world/footprints/<k>`,
/// k the obstacle's index in the mission).
pub const FOOTPRINTS: &str = "world/footprints";
pub const INSPECTION: &str = "world/inspection";
pub const ROUTE: &str = "world/route";
pub const TERRAIN: &str = "world/terrain";
pub const IWPS: &str = "world/iwps";
/// The mission file as a text document.
pub const MISSION: &str = "mission";

/// The root of a pipeline's entities (and the name of its recording
/// property): its slug as an entity name, `theta_pso`, `flatlo`, `fleet`.
pub fn root(kind: Kind) -> String {
    kind.slug().replace('-', "_")
}

/// Where a pipeline's log lines (its `Event::Log`s) go: under its own root,
/// so its layout's event panel shows them.
pub fn log(kind: Kind) -> String {
    format!("{}/log", root(kind))
}

/// Where a pipeline's events on `sim_time` go (reconfigurations, closest approaches).
pub fn events(kind: Kind) -> String {
    format!("{}/events", root(kind))
}

/// An entity path as the viewer layout names it (rooted).
pub fn origin(path: &str) -> String {
    format!("/{path}")
}

/// θ-PSO's entities.
/// The designer's live plans, one per `revision`.
pub const LIVE_CENTROID: &str = "live/plan/centroid";
pub const LIVE_EVENTS: &str = "live/events";

/// Vehicle `k` (0-based) of a live plan, named from 1.
pub fn live_track(k: usize) -> String {
    format!("live/plan/vehicle_{}", k + 1)
}

pub mod theta_pso {
    /// The cost terms on the `iteration` timeline.
    pub const COST: &str = "theta_pso/cost";
    pub const COST_TOTAL: &str = "theta_pso/cost/J_total";
    pub const COST_LENGTH: &str = "theta_pso/cost/J1_length";
    pub const COST_OBSTACLE: &str = "theta_pso/cost/J2_obstacle";
    pub const COST_ALTITUDE: &str = "theta_pso/cost/J3_altitude";
    pub const COST_WAYPOINTS: &str = "theta_pso/cost/JR_waypoints";
    /// The swarm's best centroid path of each iteration.
    pub const BEST_PATH: &str = "theta_pso/best_path";
    pub const CLEARANCE: &str = "theta_pso/clearance";
    pub const CENTROID: &str = "theta_pso/plan/centroid";
    pub const VIOLATIONS: &str = "theta_pso/violations";

    /// UAV `uav` (0-based) is named from 1.
    pub fn clearance(uav: usize) -> String {
        format!("{CLEARANCE}/uav_{}", uav + 1)
    }

    pub fn plan(uav: usize) -> String {
        format!("theta_pso/plan/uav_{}", uav + 1)
    }

    pub fn uav(uav: usize) -> String {
        format!("theta_pso/uavs/uav_{}", uav + 1)
    }

    /// The stretch of the centroid path inspecting `obstacle`.
    pub fn pass(obstacle: &str) -> String {
        format!("theta_pso/plan/pass_{}", obstacle.replace([' ', '/'], "_"))
    }
}

/// FLATLO's entities, per aircraft (0-based, as `aircraft_0`).
pub mod flatlo {
    pub const AIRSPEED: &str = "flatlo/airspeed";
    pub const LOAD_FACTOR: &str = "flatlo/load_factor";

    /// `part` is `reference`, `flown`, `aircraft` or a series (`airspeed`, …).
    pub fn aircraft(part: &str, index: usize) -> String {
        format!("flatlo/{part}/aircraft_{index}")
    }
}

/// A flight check's entities (`skyform fly --rrd`), per vehicle named from 1.
pub mod flight {
    /// The report, as text.
    pub const REPORT: &str = "flight/report";

    pub fn written(vehicle: usize) -> String {
        format!("flight/written/uav_{vehicle}")
    }

    /// The p99 cross-track envelope along the plan.
    pub fn envelope(vehicle: usize) -> String {
        format!("flight/envelope/uav_{vehicle}")
    }

    pub fn worst(flight: usize, vehicle: usize) -> String {
        format!("flight/worst/flight_{flight}/uav_{vehicle}")
    }
}

/// The fleet's entities, per agent (0-based, as `agent_0`).
pub mod fleet {
    pub const DISTANCES: &str = "fleet/distances";
    pub const SAFETY_C: &str = "fleet/distances/safety_c";
    pub const TARGET: &str = "fleet/target";
    /// At each sample, the agents that heard each other.
    pub const LINKS: &str = "fleet/links";

    /// `part` is `trails`, `agents` or `references`.
    pub fn agent(part: &str, index: usize) -> String {
        format!("fleet/{part}/agent_{index}")
    }

    /// The distance of agents `a` and `b` (0-based), named from 1.
    pub fn distance(a: usize, b: usize) -> String {
        format!("{DISTANCES}/{}_{}", a + 1, b + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pipeline_logs_under_its_own_root() {
        for kind in [Kind::ThetaPso, Kind::Flatlo, Kind::Fleet] {
            assert!(log(kind).starts_with(&format!("{}/", root(kind))));
            assert!(events(kind).starts_with(&format!("{}/", root(kind))));
        }
        assert_eq!(log(Kind::Flatlo), "flatlo/log");
        assert_eq!(root(Kind::ThetaPso), "theta_pso");
        assert_eq!(theta_pso::pass("pier 1/a"), "theta_pso/plan/pass_pier_1_a");
        assert_eq!(fleet::distance(0, 2), "fleet/distances/1_3");
    }
}
