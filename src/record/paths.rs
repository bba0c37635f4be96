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
/// Wires (power lines, cables) as lines at their height, labelled.
pub const WIRES: &str = "world/wires";

/// A footprint's entity, named after its obstacle (`world/footprints/pier 3`,
/// the name escaped as Rerun needs it).
pub fn footprint(name: &str) -> rerun::EntityPath {
    let mut parts: Vec<rerun::EntityPathPart> = FOOTPRINTS
        .split('/')
        .map(rerun::EntityPathPart::from)
        .collect();
    parts.push(rerun::EntityPathPart::from(name));
    rerun::EntityPath::from(parts)
}
pub const INSPECTION: &str = "world/inspection";
pub const ROUTE: &str = "world/route";
pub const TERRAIN: &str = "world/terrain";
/// The mission file as a text document.
pub const MISSION: &str = "mission";

/// The root of a pipeline's entities (and the name of its recording
/// property): its slug as an entity name, `theta_pso`, `flatlo`, `fleet`.
pub fn root(kind: Kind) -> String {
    kind.words().slug.replace('-', "_")
}

/// Where a pipeline's log lines (its `Event::Log`s) go: under its own root,
/// so its layout's event panel shows them.
pub fn log(kind: Kind) -> String {
    format!("{}/log", root(kind))
}

/// An entity path as the viewer layout names it (rooted).
pub fn origin(path: &str) -> String {
    format!("/{path}")
}

/// The designer's live plans, one per `revision`: each vehicle's track,
/// and what its pipeline adds (`PipelineOutcome::sketch_live`: θ-PSO's
/// centroid at `live/plan/centroid`).
pub const LIVE_PLAN: &str = "live/plan";
pub const LIVE_EVENTS: &str = "live/events";

/// Vehicle `k` (0-based) of a live plan, named from 1.
pub fn live_track(k: usize) -> String {
    format!("live/plan/vehicle_{}", k + 1)
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

    /// A flight flown again from its inputs (`name`: a rare-event
    /// estimate's most likely failure of a limit).
    pub fn failing(name: &str, vehicle: usize) -> String {
        format!("flight/failing/{name}/uav_{vehicle}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pipeline_logs_and_plots_under_its_own_root() {
        for kind in Kind::ALL {
            let root = format!("{}/", root(kind));
            assert!(log(kind).starts_with(&root));
            for plot in kind.face().plots().iter().flat_map(|panel| panel.iter()) {
                assert!(plot.path.starts_with(&root), "{kind:?}: {plot:?}");
            }
        }
        // Each pipeline's own entities (its `recording.rs`) under its root.
        use crate::pipelines::{flatlo, fleet, theta_pso};
        for (kind, own_root, events) in [
            (
                Kind::ThetaPso,
                theta_pso::recording::paths::ROOT,
                theta_pso::recording::paths::EVENTS,
            ),
            (
                Kind::Flatlo,
                flatlo::recording::paths::ROOT,
                flatlo::recording::paths::EVENTS,
            ),
            (
                Kind::Fleet,
                fleet::recording::paths::ROOT,
                fleet::recording::paths::EVENTS,
            ),
        ] {
            assert_eq!(own_root, root(kind));
            assert_eq!(events, format!("{}/events", root(kind)));
        }
        assert_eq!(log(Kind::Flatlo), "flatlo/log");
        assert_eq!(root(Kind::ThetaPso), "theta_pso");
    }
}
