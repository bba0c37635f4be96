//! The distributed fleet (Belkadi et al., Algorithm 1): every quadrotor runs
//! its own PSO over the next step h (eqs. 6, 8) from what it observes, and
//! flies the result with the quaternion laws (eqs. 10-13).
//!
//! Rounds are synchronous: every τ (or at once for an agent with a neighbour
//! closer than c) the agents due to decide all read the same snapshot of the
//! fleet, decide in parallel, each with its own random stream, and only then
//! move. So the result does not depend on the number of threads.
//!
//! Here: the scenario, the run's predicted size (`budget`) and the outcome
//! types; the round loop with its named stages (observe, decide, fly,
//! record) is `simulation.rs`, the per-agent pieces `agent.rs` and
//! `cost.rs`; the quadrotor they fly is shared (`pipelines::quadrotor`), as
//! the flight check flies it too.

pub mod agent;
pub mod chart;
pub mod cost;
pub mod face;
pub mod judge;
pub mod network;
pub mod numbering;
pub mod recording;
mod rules;
pub mod scenario;
mod section;
pub mod simulation;
pub mod summary;

use std::collections::HashMap;

use nalgebra::{Point2, Point3};
use serde::Serialize;

use crate::mission::{Diagnostic, FieldPath, Mission};
use crate::pipelines::{CancelToken, Event, Observer, PipelineError};

pub use scenario::{
    Goal, Scenario, assign, default_target, duration_finding, polygon_distances, scenario,
};
use simulation::Simulation;

/// Samples kept per simulated second (positions, distances).
const SAMPLE_RATE: f64 = 20.0;

/// One recorded instant of an agent.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AgentSample {
    pub t: f64,
    pub position: Point3<f64>,
    /// Y_id: the reference the agent flies to (eq. 8).
    pub reference: Point3<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AgentOutcome {
    /// 0-based here; numbered from 1 in the JSON (`agent`), as everywhere a
    /// person reads it.
    #[serde(rename = "agent", serialize_with = "numbering::one")]
    pub index: usize,
    pub start: Point2<f64>,
    pub samples: Vec<AgentSample>,
    /// PSO runs (decisions) and cost evaluations: the agent's planning effort.
    pub decisions: usize,
    pub evaluations: usize,
    /// Messages it sent, heard and lost, and the age of what it decided on.
    pub network: network::LinkStats,
}

/// The desired formation around one target, and when the fleet reached it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetOutcome {
    pub time: f64,
    /// The target, or the middle of its points (one per agent).
    pub position: Point2<f64>,
    /// For a target of one point per agent: the point each agent was given
    /// (by agent), and which of the file's points that is (numbered from
    /// 1, as the file lists them).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub assigned: Vec<Point2<f64>>,
    #[serde(
        skip_serializing_if = "Vec::is_empty",
        serialize_with = "numbering::ones"
    )]
    pub assignment: Vec<usize>,
    /// Seconds after the target appeared when every distance (to the target
    /// and between every two agents, lost ones where they were last heard)
    /// entered its tolerance for good; None if never.
    pub converged_after: Option<f64>,
    /// How far the formation was at the last sample while this target was in
    /// force; None when no sample fell in its time.
    pub end: Option<FormationError>,
}

/// How far a fleet stands from its desired formation at one instant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FormationError {
    pub time: f64,
    /// The inter-agent distance furthest from its d_ij^d (None: one agent).
    pub pair: Option<Deviation>,
    /// The agent whose distance to the target is furthest from d_ip^d.
    pub to_target: Option<Deviation>,
    /// Distance from the agents' centroid to the target, metres.
    pub centre_offset: f64,
}

/// One distance of the formation against its desired value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Deviation {
    /// 0-based agents (numbered from 1 in the JSON); `b` is None for the
    /// distance from `a` to the target.
    #[serde(serialize_with = "numbering::one")]
    pub a: usize,
    #[serde(serialize_with = "numbering::maybe")]
    pub b: Option<usize>,
    pub distance: f64,
    pub desired: f64,
    /// The ± metres `fleet.tolerance` allows it.
    pub tolerance: f64,
}

impl Deviation {
    /// How many tolerances off it is (within tolerance: at most 1).
    pub fn tolerances(&self) -> f64 {
        (self.distance - self.desired).abs() / self.tolerance.max(f64::MIN_POSITIVE)
    }

    pub fn within(&self) -> bool {
        (self.distance - self.desired).abs() <= self.tolerance
    }
}

/// A closest approach of agent `a` (0-based; from 1 in the JSON) to
/// another agent or an obstacle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Closest {
    #[serde(serialize_with = "numbering::one")]
    pub a: usize,
    pub b: Other,
    pub distance: f64,
    pub time: f64,
}

/// What an agent came close to.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Other {
    /// Another agent, 0-based (from 1 in the JSON).
    Agent(#[serde(serialize_with = "numbering::one")] usize),
    /// An obstacle, by name.
    Obstacle(String),
}

impl std::fmt::Display for Other {
    /// As people read it: agents from 1, obstacles by name in quotes.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Other::Agent(j) => write!(f, "{}", j + 1),
            Other::Obstacle(name) => write!(f, "'{name}'"),
        }
    }
}

/// The inter-agent distances over time (fleet paper, Fig. 13), for fleets
/// small enough to list every pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DistanceSeries {
    /// 0-based agents (from 1 in the JSON).
    #[serde(serialize_with = "numbering::one")]
    pub a: usize,
    #[serde(serialize_with = "numbering::one")]
    pub b: usize,
    pub desired: f64,
    pub values: Vec<f64>,
}

/// Fleets larger than this get no per-pair distance series (n² of them).
pub const MAX_SERIES_AGENTS: usize = 12;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FleetOutcome {
    /// The pipeline, the mission, the seed and how the run ended.
    #[serde(flatten)]
    pub header: crate::pipelines::Header,
    pub duration: f64,
    /// Times of the samples (and of the distance series).
    pub times: Vec<f64>,
    pub agents: Vec<AgentOutcome>,
    pub targets: Vec<TargetOutcome>,
    pub distances: Vec<DistanceSeries>,
    /// c.
    pub safety_distance: f64,
    /// Closest two agents ever came (on the sample grid).
    pub closest_agents: Option<Closest>,
    /// Closest any agent came to an obstacle's surface.
    pub closest_obstacle: Option<Closest>,
    /// Per sample (fleets up to `MAX_SERIES_AGENTS`), the pairs of agents
    /// (i < j) that each heard the other within l: the links the network
    /// kept up (agents from 1 in the JSON).
    #[serde(
        skip_serializing_if = "Vec::is_empty",
        serialize_with = "numbering::links"
    )]
    pub links: Vec<Vec<(usize, usize)>>,
    /// Agents whose process went away during the run (distributed runs).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub lost: Vec<simulation::LostAgent>,
    /// How the run was carried out over processes, when it was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distributed: Option<Distributed>,
    /// For each target not reached: what held each agent back that stood
    /// short of its place at the end of the target's time.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub short: Vec<Shortfall>,
}

/// An agent that stood short of its place in a formation not reached, and
/// why: the obstacle it is stalled behind, or the time it still needed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Shortfall {
    /// The target, numbered from 1.
    pub target: usize,
    /// 0-based (from 1 in the JSON).
    #[serde(serialize_with = "numbering::one")]
    pub agent: usize,
    /// Metres from its place (its target point, or d_ip from the target).
    pub short_by: f64,
    /// In words: `stalled behind 'pier 2'`, `on its way at 0.52 m/s: about
    /// 80 s more`.
    pub why: String,
}

/// What a fleet run asks beyond the mission and the seed: agent processes
/// to fly in (`skyform run fleet --distributed`, the designer's `Z`);
/// `None`, in this process.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Request {
    pub processes: Option<crate::pipelines::Processes>,
}

/// A fleet flown by agents in processes of their own (`skyform run fleet
/// --distributed`): how, and what the transport cost.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Distributed {
    /// Agent processes.
    pub processes: usize,
    /// "lockstep" (the coordinator's clock, reproducible) or "realtime"
    /// (each agent on its own timer).
    pub clock: String,
    /// Seconds from the first process started to every agent ready.
    pub startup: f64,
    /// Per communication round (a step's states in, the round announced),
    /// seconds: mean and worst, as the coordinator timed them.
    pub round_mean: f64,
    pub round_worst: f64,
    /// Messages the coordinator received over the transport (agents' states).
    pub messages: usize,
}

impl FleetOutcome {
    /// No two agents and no agent and obstacle came closer than c.
    pub fn kept_apart(&self) -> bool {
        self.closest_agents
            .as_ref()
            .is_none_or(|c| c.distance >= self.safety_distance)
    }

    /// No agent came closer than c to an obstacle's surface.
    pub fn obstacles_clear(&self) -> bool {
        self.closest_obstacle
            .as_ref()
            .is_none_or(|c| c.distance >= self.safety_distance)
    }

    /// Every target's formation was reached.
    pub fn converged(&self) -> bool {
        self.targets.iter().all(|t| t.converged_after.is_some())
    }
}

/// Agents within `radius` of each agent (eq. 2), by a uniform grid of that
/// cell size: O(n) for a spread-out fleet, not all pairs.
pub fn neighbourhoods(positions: &[Point2<f64>], radius: f64) -> Vec<Vec<usize>> {
    let cell = radius.max(1e-6);
    let key = |p: &Point2<f64>| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, p) in positions.iter().enumerate() {
        grid.entry(key(p)).or_default().push(i);
    }
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (cx, cy) = key(p);
            let mut found = Vec::new();
            for dx in -1..=1 {
                for dy in -1..=1 {
                    if let Some(cell) = grid.get(&(cx + dx, cy + dy)) {
                        for &j in cell {
                            if j != i && (positions[j] - p).norm() <= radius {
                                found.push(j);
                            }
                        }
                    }
                }
            }
            found.sort_unstable();
            found
        })
        .collect()
}

/// The fleet's predicted size against `pipeline::limits`: agents, cost
/// evaluations (agents × re-plans × particles × iterations), dynamics steps
/// (agents × duration / sim_step) and kept samples (agents × duration × 20 Hz).
pub fn budget(mission: &Mission) -> Vec<Diagnostic> {
    use crate::pipelines::{figure, limits};
    let p = &mission.fleet;
    // Left out, a run lasts at most the automatic cap: the budget holds that.
    let duration = p.duration.unwrap_or(crate::mission::AUTO_DURATION_MAX);
    let at = |key: &str| FieldPath::root().key("fleet").key(key);
    let mut out = Vec::new();
    let n = p.agents as f64;
    if p.agents > limits::FLEET_AGENTS {
        out.push(Diagnostic::error(
            at("agents"),
            format!(
                "{} agents is over the limit of {}",
                figure(n),
                limits::FLEET_AGENTS
            ),
        ));
        return out;
    }
    let replans = (duration / p.replan_period).ceil();
    let evaluations = n * replans * p.swarm_size as f64 * p.iterations as f64;
    if crate::pipelines::exceeds(evaluations, limits::FLEET_EVALUATIONS) {
        let key = if p.replan_period < 1e-3 {
            "replan_period"
        } else {
            crate::pipelines::largest_factor(&[
                ("swarm_size", p.swarm_size as f64),
                ("iterations", p.iterations as f64),
            ])
        };
        out.push(Diagnostic::error(
            at(key),
            format!(
                "{} agents × {} re-plans × {} particles × {} iterations make {} cost \
                 evaluations (limit {})",
                p.agents,
                figure(replans),
                figure(p.swarm_size as f64),
                figure(p.iterations as f64),
                figure(evaluations),
                figure(limits::FLEET_EVALUATIONS)
            ),
        ));
    }
    let steps = n * (duration / p.sim_step).ceil();
    if crate::pipelines::exceeds(steps, limits::FLEET_STEPS) {
        let key = if p.sim_step < 1e-4 {
            "sim_step"
        } else {
            "duration"
        };
        out.push(Diagnostic::error(
            at(key),
            format!(
                "{} agents over {} s in steps of {} s: {} dynamics steps (limit {})",
                p.agents,
                figure(duration),
                figure(p.sim_step),
                figure(steps),
                figure(limits::FLEET_STEPS)
            ),
        ));
    }
    let samples = n * duration * SAMPLE_RATE;
    if crate::pipelines::exceeds(samples, limits::FLEET_SAMPLES) {
        out.push(Diagnostic::error(
            at("duration"),
            format!(
                "{} agents over {} s at {SAMPLE_RATE} Hz: {} samples kept (limit {})",
                p.agents,
                figure(duration),
                figure(samples),
                figure(limits::FLEET_SAMPLES)
            ),
        ));
    }
    out
}

/// Simulates the mission's fleet with `seed` (starts, PSO streams). Fails
/// only on an invalid mission.
pub fn plan(
    mission: &Mission,
    seed: u64,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<FleetOutcome, PipelineError> {
    crate::pipelines::require_admissible(mission, budget)?;
    observer.on_event(Event::Stage("scenario"));
    let mut simulation = Simulation::new(mission, seed);
    observer.on_event(Event::Stage("flight"));
    let mut link = simulation::Loopback::new(mission.fleet.agents);
    let completion = simulation
        .run(&mut link, observer, cancel)
        .map_err(|e| PipelineError::Transport(e.to_string()))?;
    Ok(simulation.finish(completion, &[], observer))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::ChaCha8Rng;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn three_agents_one_metre_out_are_1_732_apart() {
        let d = polygon_distances(3, 1.0);
        assert!((d[0][1] - 3f64.sqrt()).abs() < 1e-12);
        assert!((d[1][2] - 2.0 * (std::f64::consts::PI / 6.0).cos()).abs() < 1e-12);
        assert_eq!(d[2][2], 0.0);
    }

    #[test]
    fn the_grid_finds_exactly_the_neighbours_within_l() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let positions: Vec<Point2<f64>> = (0..300)
            .map(|_| Point2::new(rng.random_range(-40.0..40.0), rng.random_range(-40.0..40.0)))
            .collect();
        let found = neighbourhoods(&positions, 5.0);
        for (i, list) in found.iter().enumerate() {
            let brute: Vec<usize> = (0..positions.len())
                .filter(|&j| j != i && (positions[j] - positions[i]).norm() <= 5.0)
                .collect();
            assert_eq!(list, &brute, "agent {i}");
        }
    }
}
