//! The distributed fleet (Belkadi et al., Algorithm 1): every quadrotor runs
//! its own PSO over the next step h (eqs. 6, 8) from what it observes, and
//! flies the result with the quaternion laws (eqs. 10-13).
//!
//! Rounds are synchronous: every τ (or at once for an agent with a neighbour
//! closer than c) the agents due to decide all read the same snapshot of the
//! fleet, decide in parallel, each with its own random stream, and only then
//! move. So the result does not depend on the number of threads.
//!
//! Just over 700 lines: the scenario, what each agent observes, the run's
//! predicted size (`budget`) and the round loop share this module's sample
//! and outcome types; the per-agent pieces already live in `agent.rs`,
//! `cost.rs` and `quadrotor.rs`.

pub mod agent;
pub mod cost;
pub mod quadrotor;

use std::collections::HashMap;

use nalgebra::{Point2, Point3, Vector2};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::Serialize;

use crate::mission::{Diagnostic, FieldPath, FleetParams, Mission};
use crate::ode::rk4_step;
use crate::pipeline::{CancelToken, Completion, Event, Level, Observer, PipelineError};

use agent::Planner;
use cost::{Detected, Neighbour, Observation};
use quadrotor::{Body, State};

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
    pub index: usize,
    pub start: Point2<f64>,
    pub samples: Vec<AgentSample>,
    /// PSO runs (decisions) and cost evaluations: the agent's planning effort.
    pub decisions: usize,
    pub evaluations: usize,
}

/// The desired formation around one target, and when the fleet reached it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetOutcome {
    pub time: f64,
    pub position: Point2<f64>,
    /// Seconds after the target appeared when every distance (to the target
    /// and between agents) entered its tolerance for good; None if never.
    pub converged_after: Option<f64>,
}

/// A closest approach of agent `a` (0-based) to another agent or an obstacle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Closest {
    pub a: usize,
    pub b: Other,
    pub distance: f64,
    pub time: f64,
}

/// What an agent came close to.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Other {
    /// Another agent, 0-based.
    Agent(usize),
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
    pub a: usize,
    pub b: usize,
    pub desired: f64,
    pub values: Vec<f64>,
}

/// Fleets larger than this get no per-pair distance series (n² of them).
pub const MAX_SERIES_AGENTS: usize = 12;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FleetOutcome {
    pub pipeline: &'static str,
    pub mission: String,
    pub seed: u64,
    pub completion: Completion,
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

/// The scenario a fleet mission describes, resolved: starts, targets, d^d.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    pub starts: Vec<Point2<f64>>,
    pub targets: Vec<(f64, Point2<f64>)>,
    /// d_ij^d.
    pub desired: Vec<Vec<f64>>,
}

/// Default d_ij^d: a regular polygon of radius d_ip^d around the target, the
/// agents in index order (three agents 1 m out: 1.732 m apart).
pub fn polygon_distances(n: usize, radius: f64) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let k = i.abs_diff(j) as f64;
                    2.0 * radius * (std::f64::consts::PI * k / n as f64).sin()
                })
                .collect()
        })
        .collect()
}

/// Resolves the mission's fleet section. Random starts are drawn (seeded)
/// inside the bounds, at least c from each other and from obstacles.
pub fn scenario(m: &Mission, seed: u64) -> Scenario {
    let p = &m.fleet;
    let n = p.agents;
    let starts = if p.initial_positions.len() == n {
        p.initial_positions.clone()
    } else {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(u64::MAX);
        let b = &m.bounds;
        let mut starts: Vec<Point2<f64>> = Vec::with_capacity(n);
        let mut attempts = 0;
        while starts.len() < n {
            let q = Point2::new(
                rng.random_range(b.x[0]..=b.x[1]),
                rng.random_range(b.y[0]..=b.y[1]),
            );
            attempts += 1;
            let clear = starts
                .iter()
                .all(|s| (s - q).norm() >= 2.0 * p.safety_distance)
                && m.obstacles
                    .iter()
                    .all(|o| (o.center - q).norm() - o.radius >= 2.0 * p.safety_distance);
            // A crowded box still gets its agents (the check is a courtesy).
            if clear || attempts > 1000 * n {
                starts.push(q);
            }
        }
        starts
    };
    let targets = if p.targets.is_empty() {
        vec![(0.0, default_target(m))]
    } else {
        p.targets.iter().map(|t| (t.time, t.position)).collect()
    };
    let desired = if p.distances.len() == n {
        p.distances.clone()
    } else {
        polygon_distances(n, p.target_distance)
    };
    Scenario {
        starts,
        targets,
        desired,
    }
}

/// Where the fleet forms when the mission names no target: the free spot
/// nearest the bounds' centre, where the formation (agents d_ip round it,
/// each keeping c) stays inside the bounds and keeps c from every obstacle
/// taller than the flight altitude. A grid of at most 200 × 200 candidates;
/// the centre itself when nothing is free.
pub fn default_target(m: &Mission) -> Point2<f64> {
    let p = &m.fleet;
    let b = &m.bounds;
    let centre = b.center_xy();
    let reach = p.target_distance + p.safety_distance;
    let free = |q: &Point2<f64>| {
        q.x - reach >= b.x[0]
            && q.x + reach <= b.x[1]
            && q.y - reach >= b.y[0]
            && q.y + reach <= b.y[1]
            && m.obstacles
                .iter()
                .filter(|o| o.height > p.altitude)
                .all(|o| (o.center - q).norm() - o.radius >= reach + p.safety_distance)
    };
    if free(&centre) {
        return centre;
    }
    let span = (b.x[1] - b.x[0]).max(b.y[1] - b.y[0]);
    let step = (reach / 2.0).max(span / 200.0).max(1e-3);
    let (nx, ny) = (
        ((b.x[1] - b.x[0]) / step).ceil().min(200.0) as usize,
        ((b.y[1] - b.y[0]) / step).ceil().min(200.0) as usize,
    );
    let mut best: Option<(f64, Point2<f64>)> = None;
    for i in 0..=nx {
        for j in 0..=ny {
            let q = Point2::new(
                b.x[0] + (b.x[1] - b.x[0]) * i as f64 / nx.max(1) as f64,
                b.y[0] + (b.y[1] - b.y[0]) * j as f64 / ny.max(1) as f64,
            );
            let d = (q - centre).norm();
            if best.is_none_or(|(bd, _)| d < bd) && free(&q) {
                best = Some((d, q));
            }
        }
    }
    best.map_or(centre, |(_, q)| q)
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

/// What agent i observes of the fleet snapshot: its neighbours within l and
/// the obstacles within d_obs, nothing else.
fn observe(
    i: usize,
    positions: &[Point2<f64>],
    near: &[usize],
    target: Point2<f64>,
    desired: &[Vec<f64>],
    obstacles: &[Detected],
    p: &FleetParams,
) -> Observation {
    let me = positions[i];
    Observation {
        position: me,
        target,
        target_distance: p.target_distance,
        // Eq. 2: Ξ_i, the agents within l (the round's lists reach a little
        // further, for the safety check).
        neighbours: near
            .iter()
            .filter(|&&j| (positions[j] - me).norm() <= p.neighbourhood)
            .map(|&j| Neighbour {
                position: positions[j],
                desired: desired[i][j],
            })
            .collect(),
        obstacles: obstacles
            .iter()
            .filter(|o| (o.center - me).norm() - o.radius <= p.detection_range)
            .copied()
            .collect(),
        rho: p.rho,
        safety: p.safety_distance,
        sigma: p.sigma,
        keep_apart: p.safety_distance + p.step_max,
        keep_clear: p.safety_distance + p.step_max / 2.0,
    }
}

/// One quadrotor in flight.
struct Flight {
    planner: Planner,
    state: State,
    reference: Point3<f64>,
}

/// The fleet's predicted size against `pipeline::limits`: agents, cost
/// evaluations (agents × re-plans × particles × iterations), dynamics steps
/// (agents × duration / sim_step) and kept samples (agents × duration × 20 Hz).
pub fn budget(mission: &Mission) -> Vec<Diagnostic> {
    use crate::pipeline::{figure, limits};
    let p = &mission.fleet;
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
    let replans = (p.duration / p.replan_period).ceil();
    let evaluations = n * replans * p.swarm_size as f64 * p.iterations as f64;
    if crate::pipeline::exceeds(evaluations, limits::FLEET_EVALUATIONS) {
        let key = if p.replan_period < 1e-3 {
            "replan_period"
        } else if p.swarm_size >= p.iterations {
            "swarm_size"
        } else {
            "iterations"
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
    let steps = n * (p.duration / p.sim_step).ceil();
    if crate::pipeline::exceeds(steps, limits::FLEET_STEPS) {
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
                figure(p.duration),
                figure(p.sim_step),
                figure(steps),
                figure(limits::FLEET_STEPS)
            ),
        ));
    }
    let samples = n * p.duration * SAMPLE_RATE;
    if crate::pipeline::exceeds(samples, limits::FLEET_SAMPLES) {
        out.push(Diagnostic::error(
            at("duration"),
            format!(
                "{} agents over {} s at {SAMPLE_RATE} Hz: {} samples kept (limit {})",
                p.agents,
                figure(p.duration),
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
    crate::pipeline::require_valid(mission)?;
    crate::pipeline::require_within_budget(budget(mission))?;
    let p = &mission.fleet;
    let n = p.agents;
    observer.on_event(Event::Stage("scenario"));
    let sc = scenario(mission, seed);
    let obstacles: Vec<Detected> = mission
        .obstacles
        .iter()
        .filter(|o| o.height > p.altitude)
        .map(|o| Detected {
            center: o.center,
            radius: o.radius,
        })
        .collect();
    let body = Body::from_params(p);
    let mut flights: Vec<Flight> = sc
        .starts
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let start = Point3::new(s.x, s.y, p.altitude);
            Flight {
                planner: Planner::new(i, seed, p),
                state: quadrotor::hover_at(start),
                reference: start,
            }
        })
        .collect();

    observer.on_event(Event::Stage("flight"));
    let dt = p.sim_step;
    let steps = (p.duration / dt).round() as usize;
    let replan_every = ((p.replan_period / dt).round() as usize).max(1);
    let record_every = ((1.0 / (SAMPLE_RATE * dt)).round() as usize).max(1);
    let report_every = ((1.0 / dt).round() as usize).max(1);
    let series = n <= MAX_SERIES_AGENTS;

    let mut times = Vec::with_capacity(steps / record_every + 1);
    let mut samples: Vec<Vec<AgentSample>> = vec![Vec::with_capacity(steps / record_every + 1); n];
    let mut distances: Vec<DistanceSeries> = Vec::new();
    if series {
        for a in 0..n {
            for b in a + 1..n {
                distances.push(DistanceSeries {
                    a,
                    b,
                    desired: sc.desired[a][b],
                    values: Vec::new(),
                });
            }
        }
    }
    let mut closest_agents: Option<Closest> = None;
    let mut closest_obstacle: Option<Closest> = None;
    // Per target: the last sampled time the formation was outside tolerance.
    let mut outside: Vec<Option<f64>> = vec![None; sc.targets.len()];
    let mut inside_at_end: Vec<bool> = vec![false; sc.targets.len()];
    let mut pushes: Vec<&crate::mission::FleetPush> = p.pushes.iter().collect();
    pushes.sort_by(|a, b| a.time.total_cmp(&b.time));
    let mut next_push = 0;
    let mut completion = Completion::Finished;
    let mut round: u64 = 0;
    let mut near: Vec<Vec<usize>> = vec![Vec::new(); n];
    // Each reference is at most √2·h_max from its agent, so two agents close
    // in on each other by well under 2·√2·h_max + 1 m in one τ.
    let watch_radius = p
        .neighbourhood
        .max(p.safety_distance + 2.0 * std::f64::consts::SQRT_2 * p.step_max + 1.0);

    for k in 0..=steps {
        let t = k as f64 * dt;
        let active = sc
            .targets
            .iter()
            .rposition(|(time, _)| *time <= t)
            .unwrap_or(0);
        let target = sc.targets[active].1;
        let positions: Vec<Point2<f64>> = flights
            .iter()
            .map(|f| quadrotor::position(&f.state).xy())
            .collect();
        // Neighbour lists are built at every scheduled round, reaching beyond
        // c by what two agents can close within τ: in between, the same lists
        // serve the "closer than c" check and the closest-approach record.
        // Eq. 2's Ξ_i (within l) is taken from them in `observe`.
        let scheduled = k % replan_every == 0;
        if scheduled {
            near = neighbourhoods(&positions, watch_radius);
        }

        // Record (and check) on the sample grid.
        if k % record_every == 0 {
            times.push(t);
            for (i, f) in flights.iter().enumerate() {
                samples[i].push(AgentSample {
                    t,
                    position: quadrotor::position(&f.state),
                    reference: f.reference,
                });
                for &j in near[i].iter().filter(|&&j| j > i) {
                    let d = (positions[j] - positions[i]).norm();
                    if closest_agents.as_ref().is_none_or(|c| d < c.distance) {
                        closest_agents = Some(Closest {
                            a: i,
                            b: Other::Agent(j),
                            distance: d,
                            time: t,
                        });
                    }
                }
                // Obstacles the fleet flies over are not in its way (as in `observe`).
                for o in mission.obstacles.iter().filter(|o| o.height > p.altitude) {
                    let d = (o.center - positions[i]).norm() - o.radius;
                    if closest_obstacle.as_ref().is_none_or(|c| d < c.distance) {
                        closest_obstacle = Some(Closest {
                            a: i,
                            b: Other::Obstacle(o.name.clone()),
                            distance: d,
                            time: t,
                        });
                    }
                }
            }
            if series {
                for s in &mut distances {
                    s.values.push((positions[s.a] - positions[s.b]).norm());
                }
            }
            let within =
                |d: f64, want: f64| (d - want).abs() <= p.tolerance * want.max(p.safety_distance);
            let formed = positions
                .iter()
                .all(|q| within((q - target).norm(), p.target_distance))
                && (0..n).all(|i| {
                    near[i]
                        .iter()
                        .all(|&j| within((positions[j] - positions[i]).norm(), sc.desired[i][j]))
                });
            if formed {
                inside_at_end[active] = true;
            } else {
                inside_at_end[active] = false;
                outside[active] = Some(t);
            }
        }

        // Disturbances (4.2): an impulse changes the velocity at once.
        while next_push < pushes.len() && pushes[next_push].time <= t {
            let push = pushes[next_push];
            if let Some(f) = flights.get_mut(push.agent) {
                f.state[3] += push.impulse.x / p.mass;
                f.state[4] += push.impulse.y / p.mass;
            }
            next_push += 1;
        }

        // Who decides now: everyone every τ; an agent with a neighbour closer than c at once.
        let due: Vec<bool> = (0..n)
            .map(|i| {
                scheduled
                    || near[i]
                        .iter()
                        .any(|&j| (positions[j] - positions[i]).norm() < p.safety_distance)
            })
            .collect();
        // Before the first target appears the agents hold their starts.
        let started = t >= sc.targets[0].0;
        if started && due.iter().any(|&d| d) {
            let snapshot = &positions;
            let desired = &sc.desired;
            let obstacles = &obstacles;
            let near = &near;
            flights
                .par_iter_mut()
                .enumerate()
                .with_min_len(8)
                .for_each(|(i, f)| {
                    if due[i] {
                        let view = observe(i, snapshot, &near[i], target, desired, obstacles, p);
                        let h: Vector2<f64> = f.planner.decide(&view, round);
                        // Eq. 8: Y_id(t + τ) = Y_i(t) + h, in the flight plane.
                        f.reference =
                            Point3::new(snapshot[i].x + h.x, snapshot[i].y + h.y, p.altitude);
                    }
                });
            round += 1;
        }

        if k == steps {
            break;
        }
        // Fly one step (eq. 10 under eqs. 11-13), each agent on its own.
        flights.par_iter_mut().with_min_len(8).for_each(|f| {
            let u = body.control(&f.state, &f.reference);
            f.state = rk4_step(|_, x| body.derivative(x, &u), t, &f.state, dt);
            quadrotor::renormalize(&mut f.state);
        });

        if k % report_every == 0 {
            observer.on_event(Event::Progress(0.98 * k as f64 / steps.max(1) as f64));
            if cancel.is_cancelled() {
                completion = Completion::Cancelled;
                let text = format!("cancelled at t = {t:.1} s of {:.1} s", p.duration);
                observer.on_event(Event::Log(Level::Warn, &text));
                break;
            }
        }
    }

    let end = times.last().copied().unwrap_or(0.0);
    let targets = sc
        .targets
        .iter()
        .enumerate()
        .map(|(k, &(time, position))| {
            let window_end = sc.targets.get(k + 1).map_or(end, |next| next.0);
            let converged_after = (inside_at_end[k] && time <= end).then(|| {
                let since = outside[k].map_or(time, |last| last + record_every as f64 * dt);
                (since - time).max(0.0)
            });
            let _ = window_end;
            TargetOutcome {
                time,
                position,
                converged_after,
            }
        })
        .collect();
    for (k, t) in sc.targets.iter().enumerate() {
        let text = match (inside_at_end.get(k), outside.get(k)) {
            (Some(true), _) => format!(
                "target {} at ({:.2}, {:.2}): formation reached",
                k + 1,
                t.1.x,
                t.1.y
            ),
            _ => format!(
                "target {} at ({:.2}, {:.2}): formation not reached",
                k + 1,
                t.1.x,
                t.1.y
            ),
        };
        observer.on_event(Event::Log(Level::Info, &text));
    }
    // A cancelled run stays at the share it got through.
    if completion == Completion::Finished {
        observer.on_event(Event::Progress(1.0));
    }
    let agents = flights
        .into_iter()
        .zip(samples)
        .enumerate()
        .map(|(i, (f, samples))| AgentOutcome {
            index: i,
            start: sc.starts[i],
            samples,
            decisions: f.planner.decisions,
            evaluations: f.planner.evaluations,
        })
        .collect();
    Ok(FleetOutcome {
        pipeline: "fleet",
        mission: mission.name.clone(),
        seed,
        completion,
        duration: end,
        times,
        agents,
        targets,
        distances,
        safety_distance: p.safety_distance,
        closest_agents,
        closest_obstacle,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
