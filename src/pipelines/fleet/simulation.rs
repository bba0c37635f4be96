//! The fleet's synchronous rounds as a simulation with named stages on state
//! it owns. Every step: `disturb` the agents flown here, `broadcast` their
//! states, `exchange` them over the [`Link`] for every agent's (the whole
//! fleet's [`Snapshot`]), `record` it on the sample grid, let the `network`
//! decide what each agent hears, let each agent due to decide `observe` (an
//! [`Observation`]: everything its planner may know) and `decide` from that
//! alone, and `fly` one step. `finish` turns what was recorded into the
//! outcome.
//!
//! One process flies the whole fleet ([`Loopback`]); with a transport between
//! processes each flies its own agents and every process runs the same
//! network model on the same messages, so each knows which agents decide in
//! a round and every agent's random stream is the one of the in-process run.
//!
//! Long (~980 lines) because its stages are methods on the one `Simulation` whose state they
//! share (disturb, broadcast, exchange, record, observe, decide, fly, finish), with the
//! `Link` it exchanges through and the clocks and logs it keeps.

use nalgebra::{Point2, Point3, Vector2};
use rayon::prelude::*;
use serde::Serialize;

use super::agent::Planner;
use super::cost::{Neighbour, Observation};
use super::judge::{formation_error, tolerance_of};
use super::network::{Message, Network};
use super::{
    AgentOutcome, AgentSample, Closest, DistanceSeries, FleetOutcome, FormationError,
    MAX_SERIES_AGENTS, Other, SAMPLE_RATE, Scenario, Shortfall, TargetOutcome, neighbourhoods,
    scenario,
};
use crate::base::ode::rk4_step;
use crate::base::shape::Footprint;
use crate::mission::{FleetParams, FleetPush, Mission};
use crate::pipelines::quadrotor::{self, Body, State};
use crate::pipelines::{CancelToken, Completion, Event, Level, Observer};

/// What carries each step's messages between the processes that fly the
/// fleet: a process hands over its own agents' messages of the step and
/// gets back every agent's, and the agents lost since the last step.
pub trait Link {
    /// Every agent's message of `step` (`local` among them), in agent order:
    /// `None` for an agent not heard from at this step (lost, or with
    /// nothing new on a wall clock).
    fn exchange(&mut self, step: usize, local: &[Message]) -> Result<Delivery, LinkError>;
}

/// One step's messages, as a [`Link`] delivers them.
#[derive(Debug, Clone, Default)]
pub struct Delivery {
    /// Per agent, its message of the step, if one came.
    pub messages: Vec<Option<Message>>,
    /// Agents lost at this step, and why (in words).
    pub lost: Vec<(usize, String)>,
}

/// A transport that failed: which step, and why (naming the agents waited for).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("step {step} (t = {time:.3} s): {reason}")]
pub struct LinkError {
    pub step: usize,
    pub time: f64,
    pub reason: String,
}

/// The whole fleet in one process: every message is local.
pub struct Loopback {
    agents: usize,
    /// Agents lost at a step, with why: a process that dies, in process.
    losses: Vec<(usize, usize, String)>,
}

impl Loopback {
    pub fn new(agents: usize) -> Self {
        Loopback {
            agents,
            losses: Vec::new(),
        }
    }

    /// The same link, losing agent `agent` (0-based) at step `step` as a
    /// transport does when the agent's process dies: from that step it is
    /// neither heard nor flown, and the others are told why.
    pub fn losing(mut self, agent: usize, step: usize, reason: impl Into<String>) -> Self {
        self.losses.push((agent, step, reason.into()));
        self
    }
}

impl Link for Loopback {
    fn exchange(&mut self, step: usize, local: &[Message]) -> Result<Delivery, LinkError> {
        let mut messages = vec![None; self.agents];
        for m in local {
            let gone = self
                .losses
                .iter()
                .any(|(agent, at, _)| *agent == m.sender && *at <= step);
            if !gone && let Some(slot) = messages.get_mut(m.sender) {
                *slot = Some(*m);
            }
        }
        let lost = self
            .losses
            .iter()
            .filter(|(_, at, _)| *at == step)
            .map(|(agent, _, reason)| (*agent, reason.clone()))
            .collect();
        Ok(Delivery { messages, lost })
    }
}

/// An agent whose process went away, and when.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LostAgent {
    /// 0-based (numbered from 1 in the JSON, as in the log).
    #[serde(serialize_with = "super::numbering::one")]
    pub agent: usize,
    pub step: usize,
    /// Seconds of flight.
    pub time: f64,
    pub reason: String,
}

/// What one agent did over a run: its planning effort and its traffic.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct Effort {
    /// 0-based.
    pub agent: usize,
    pub decisions: usize,
    pub evaluations: usize,
    pub network: super::network::LinkStats,
}

/// One quadrotor in flight.
struct Flight {
    planner: Planner,
    state: State,
    reference: Point3<f64>,
}

/// The step counts of the run, from the mission's periods.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    pub dt: f64,
    pub steps: usize,
    replan_every: usize,
    record_every: usize,
    report_every: usize,
}

impl Clock {
    /// The clock of a run of `duration` seconds.
    pub fn of(p: &FleetParams, duration: f64) -> Self {
        let dt = p.sim_step;
        Clock {
            dt,
            steps: (duration / dt).round() as usize,
            replan_every: ((p.replan_period / dt).round() as usize).max(1),
            record_every: ((1.0 / (SAMPLE_RATE * dt)).round() as usize).max(1),
            report_every: ((1.0 / dt).round() as usize).max(1),
        }
    }
}

/// The fleet as every agent sees it at a step, from the step's messages.
pub struct Snapshot {
    step: usize,
    t: f64,
    /// The target in force (index into the scenario's targets).
    active: usize,
    positions: Vec<Point2<f64>>,
    /// A scheduled round (every τ): everyone decides, neighbour lists rebuilt.
    scheduled: bool,
    /// Where each lost agent may be now ([`Simulation::lost_region`]).
    lost: Vec<(usize, Footprint)>,
}

/// What the run has recorded so far, on the sample grid.
struct Log {
    times: Vec<f64>,
    samples: Vec<Vec<AgentSample>>,
    distances: Vec<DistanceSeries>,
    closest_agents: Option<Closest>,
    closest_obstacle: Option<Closest>,
    /// Per target: the last sampled time the formation was outside tolerance.
    outside: Vec<Option<f64>>,
    inside_at_end: Vec<bool>,
    /// Per target: how far the formation was at its last sample, and
    /// where every agent was then.
    ends: Vec<Option<FormationError>>,
    last_positions: Vec<Option<(f64, Vec<Point2<f64>>)>>,
    /// Per sample, the pairs (i < j) where each heard the other within l at
    /// that step (fleets up to `MAX_SERIES_AGENTS`): the links of the recording.
    links: Vec<Vec<(usize, usize)>>,
}

/// Each agent's own update clock, (period, phase) in steps, from
/// `[fleet.network] updates` (agents from 1; validation keeps the period
/// positive and the agents real).
fn own_clocks(p: &FleetParams) -> Vec<Option<(usize, usize)>> {
    let mut clocks = vec![None; p.agents];
    for u in &p.network.updates {
        if let Some(slot) = u.agent.checked_sub(1).and_then(|i| clocks.get_mut(i)) {
            *slot = Some((u.period.max(1), u.phase));
        }
    }
    clocks
}

/// The fleet in flight, with everything the round loop needs.
pub struct Simulation<'m> {
    mission: &'m Mission,
    p: &'m FleetParams,
    seed: u64,
    scenario: Scenario,
    /// The obstacles in the flight plane (the fleet flies over the others).
    obstacles: Vec<Footprint>,
    body: Body,
    /// The agents flown here, and their indices in the fleet.
    flights: Vec<Flight>,
    local: Vec<usize>,
    clock: Clock,
    pushes: Vec<&'m FleetPush>,
    next_push: usize,
    round: u64,
    /// Each agent's last message (its state at the step being run).
    current: Vec<Message>,
    /// Agents whose process went away: no longer flown or heard; the
    /// others keep clear of where they were last heard.
    alive: Vec<bool>,
    lost: Vec<LostAgent>,
    /// Decisions of every agent, here or elsewhere, as the replicated rounds
    /// tell them: an agent's effort when its own report never comes.
    decided: Vec<usize>,
    /// Each agent's neighbours within `watch_radius`, rebuilt every round.
    near: Vec<Vec<usize>>,
    watch_radius: f64,
    /// What each agent has heard of the others (`network`).
    network: Network,
    /// Per agent, its own update clock (period, phase) in steps, if it has
    /// one (`[fleet.network] updates`); else it decides at the rounds.
    own_clock: Vec<Option<(usize, usize)>>,
    /// Records samples (off in a process that only flies its agents).
    recording: bool,
    log: Log,
}

impl<'m> Simulation<'m> {
    /// The whole fleet at its starts (drawn with `seed`), hovering.
    pub fn new(mission: &'m Mission, seed: u64) -> Self {
        let all = (0..mission.fleet.agents).collect();
        Self::flying(mission, seed, all, true)
    }

    /// The fleet, flying here only the agents `local` (0-based), recording
    /// the samples when `recording`.
    pub fn flying(mission: &'m Mission, seed: u64, local: Vec<usize>, recording: bool) -> Self {
        let p = &mission.fleet;
        let n = p.agents;
        let sc = scenario(mission, seed);
        let obstacles = mission
            .obstacles
            .iter()
            .filter(|o| o.spans(p.altitude))
            .map(|o| o.outline())
            .collect();
        let local: Vec<usize> = local.into_iter().filter(|&i| i < n).collect();
        let flights = local
            .iter()
            .map(|&i| {
                let s = sc.starts[i];
                let start = Point3::new(s.x, s.y, p.altitude);
                Flight {
                    planner: Planner::new(i, seed, p),
                    state: quadrotor::hover_at(start),
                    reference: start,
                }
            })
            .collect();
        // Before the first exchange every agent is where it starts.
        let current = sc
            .starts
            .iter()
            .enumerate()
            .map(|(i, s)| Message {
                sender: i,
                step: 0,
                position: *s,
                height: p.altitude,
                velocity: Vector2::zeros(),
                reference: *s,
            })
            .collect();
        let clock = Clock::of(p, sc.duration);
        let kept = if recording {
            clock.steps / clock.record_every + 1
        } else {
            0
        };
        let mut distances = Vec::new();
        if recording && n <= MAX_SERIES_AGENTS {
            for a in 0..n {
                for b in a + 1..n {
                    distances.push(DistanceSeries {
                        a,
                        b,
                        desired: sc.targets[0].desired[a][b],
                        values: Vec::new(),
                    });
                }
            }
        }
        let log = Log {
            times: Vec::with_capacity(kept),
            samples: vec![Vec::with_capacity(kept); n],
            distances,
            closest_agents: None,
            closest_obstacle: None,
            outside: vec![None; sc.targets.len()],
            inside_at_end: vec![false; sc.targets.len()],
            ends: vec![None; sc.targets.len()],
            last_positions: vec![None; sc.targets.len()],
            links: Vec::new(),
        };
        let mut pushes: Vec<&FleetPush> = p.pushes.iter().collect();
        pushes.sort_by(|a, b| a.time.total_cmp(&b.time));
        Simulation {
            mission,
            p,
            seed,
            scenario: sc,
            obstacles,
            body: Body::from_params(p),
            flights,
            local,
            clock,
            pushes,
            next_push: 0,
            round: 0,
            current,
            alive: vec![true; n],
            lost: Vec::new(),
            decided: vec![0; n],
            near: vec![Vec::new(); n],
            // Each reference is at most √2·h_max from its agent, so two agents
            // close in on each other by well under 2·√2·h_max + 1 m in one τ.
            watch_radius: p
                .neighbourhood
                .max(p.safety_distance + 2.0 * std::f64::consts::SQRT_2 * p.step_max + 1.0),
            network: Network::new(&p.network, p.neighbourhood, n, seed, clock.dt),
            own_clock: own_clocks(p),
            recording,
            log,
        }
    }

    /// The run's step counts.
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// Runs every step to the mission's duration, or until `cancel`, every
    /// step's messages carried by `link`.
    pub fn run(
        &mut self,
        link: &mut dyn Link,
        observer: &mut dyn Observer,
        cancel: &CancelToken,
    ) -> Result<Completion, LinkError> {
        let steps = self.clock.steps;
        for k in 0..=steps {
            let t = k as f64 * self.clock.dt;
            self.disturb(t);
            let out = self.broadcast(k);
            let delivery = link.exchange(k, &out)?;
            let fresh = self.receive(k, t, delivery, observer);
            let now = self.snapshot(k);
            if self.recording && k.is_multiple_of(self.clock.record_every) {
                self.record(&now);
            }
            self.network.exchange(k, fresh, &self.near);
            let due = self.due(&now);
            // Before the first target appears the agents hold their starts.
            let started = now.t >= self.scenario.targets[0].time;
            if started && due.iter().any(|&d| d) {
                for (count, _) in self.decided.iter_mut().zip(&due).filter(|(_, d)| **d) {
                    *count += 1;
                }
                let observations = self.observe(&now, &due);
                self.count_ages(&now, &due);
                self.decide(&now, &observations);
                self.round += 1;
            }
            if k == steps {
                break;
            }
            self.fly(now.t);
            if k.is_multiple_of(self.clock.report_every) {
                observer.on_event(Event::Progress(0.98 * k as f64 / steps.max(1) as f64));
                if cancel.is_cancelled() {
                    let text = format!(
                        "cancelled at t = {:.1} s of {:.1} s",
                        now.t, self.scenario.duration
                    );
                    observer.on_event(Event::Log(Level::Warn, &text));
                    return Ok(Completion::Cancelled);
                }
            }
        }
        Ok(Completion::Finished)
    }

    /// Takes in a step's messages: the agents lost, and each agent's state
    /// (an agent not heard from this step stays where it was last heard).
    /// Returns the step's fresh messages, per agent.
    fn receive(
        &mut self,
        k: usize,
        t: f64,
        delivery: Delivery,
        observer: &mut dyn Observer,
    ) -> Vec<Option<Message>> {
        for (agent, reason) in delivery.lost {
            if self.alive.get(agent).copied().unwrap_or(false) {
                self.alive[agent] = false;
                let text = format!("agent {} lost at t = {t:.2} s: {reason}", agent + 1);
                observer.on_event(Event::Log(Level::Warn, &text));
                self.lost.push(LostAgent {
                    agent,
                    step: k,
                    time: t,
                    reason,
                });
            }
        }
        if !self.lost.is_empty() && self.lost.last().is_some_and(|l| l.step == k) {
            observer.on_event(Event::Vehicles {
                alive: self.alive.iter().filter(|&&a| a).count(),
                total: self.alive.len(),
            });
        }
        let mut fresh = delivery.messages;
        fresh.resize(self.current.len(), None);
        for (i, m) in fresh.iter_mut().enumerate() {
            if !self.alive[i] {
                *m = None;
            } else if let Some(m) = m {
                self.current[i] = *m;
            }
        }
        fresh
    }

    /// The fleet at step `k`, from the step's messages; at a scheduled round
    /// the neighbour lists are rebuilt (among the agents still flying),
    /// reaching beyond c by what two agents can close within τ: in between,
    /// the same lists serve the "closer than c" check and the closest-approach
    /// record. Eq. 2's Ξ_i (within l) is taken from them in `observe`.
    fn snapshot(&mut self, k: usize) -> Snapshot {
        let t = k as f64 * self.clock.dt;
        let targets = &self.scenario.targets;
        let active = targets.iter().rposition(|g| g.time <= t).unwrap_or(0);
        let positions: Vec<Point2<f64>> = self.current.iter().map(|m| m.position).collect();
        let scheduled = k.is_multiple_of(self.clock.replan_every);
        if scheduled {
            self.near = neighbourhoods(&positions, self.watch_radius);
            if !self.lost.is_empty() {
                let alive = &self.alive;
                for (i, list) in self.near.iter_mut().enumerate() {
                    if alive[i] {
                        list.retain(|&j| alive[j]);
                    } else {
                        list.clear();
                    }
                }
            }
        }
        let lost = self
            .lost
            .iter()
            .map(|l| (l.agent, self.lost_region(l.agent, k)))
            .collect();
        Snapshot {
            step: k,
            t,
            active,
            positions,
            scheduled,
            lost,
        }
    }

    /// Where lost agent `j` may be at step `k`, as every agent treats it (an
    /// obstacle of eq. 9; docs/fleet.md, "A lost agent"): a disc about its
    /// last known position x_j, the last state the transport delivered. Its
    /// planner is gone, not its position law (eq. 11), which flies it on to
    /// its last reference Y_j and holds it there; so the disc grows with the
    /// news's age at its last speed ‖v_j‖, up to ‖Y_j − x_j‖ plus its
    /// stopping distance at the tilt limit, ‖v_j‖² / (2 g tan θ_max).
    pub fn lost_region(&self, j: usize, k: usize) -> Footprint {
        let m = &self.current[j];
        let speed = m.velocity.norm();
        let age = k.saturating_sub(m.step) as f64 * self.clock.dt;
        let braking = quadrotor::G * self.p.max_tilt_deg.to_radians().tan();
        let stop = if braking > 0.0 {
            speed * speed / (2.0 * braking)
        } else {
            f64::INFINITY
        };
        let reach = (m.reference - m.position).norm() + stop;
        Footprint::circle(m.position, (speed * age).min(reach))
    }

    /// Records (and checks) the snapshot: samples, closest approaches, the
    /// distance series, whether the formation stands.
    fn record(&mut self, now: &Snapshot) {
        let ends = self.last_sample_of_target(now);
        let (p, log, positions, t) = (self.p, &mut self.log, &now.positions, now.t);
        log.times.push(t);
        for (i, m) in self.current.iter().enumerate() {
            if !self.alive[i] {
                continue;
            }
            log.samples[i].push(AgentSample {
                t,
                position: Point3::new(m.position.x, m.position.y, m.height),
                reference: Point3::new(m.reference.x, m.reference.y, p.altitude),
            });
            // Every pair counts: a lost agent where it was last heard.
            let lost = now.lost.iter().map(|(j, _)| *j);
            for j in self.near[i].iter().copied().filter(|&j| j > i).chain(lost) {
                let d = (positions[j] - positions[i]).norm();
                if log.closest_agents.as_ref().is_none_or(|c| d < c.distance) {
                    log.closest_agents = Some(Closest {
                        a: i.min(j),
                        b: Other::Agent(i.max(j)),
                        distance: d,
                        time: t,
                    });
                }
            }
            // Obstacles the fleet flies over are not in its way (as in `observe`).
            for o in self
                .mission
                .obstacles
                .iter()
                .filter(|o| o.spans(p.altitude))
            {
                let d = o.prism().outward(&positions[i]);
                if log.closest_obstacle.as_ref().is_none_or(|c| d < c.distance) {
                    log.closest_obstacle = Some(Closest {
                        a: i,
                        b: Other::Obstacle(o.name.clone()),
                        distance: d,
                        time: t,
                    });
                }
            }
        }
        for s in &mut log.distances {
            s.values.push((positions[s.a] - positions[s.b]).norm());
        }
        if self.current.len() <= MAX_SERIES_AGENTS {
            let l = p.neighbourhood;
            let heard = |i: usize, j: usize| {
                self.network
                    .heard(i, j)
                    .is_some_and(|m| (m.position - positions[i]).norm() <= l)
            };
            let n = self.current.len();
            log.links.push(
                (0..n)
                    .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
                    .filter(|&(i, j)| self.alive[i] && self.alive[j] && heard(i, j) && heard(j, i))
                    .collect(),
            );
        }
        // Eq. 4: every distance, to the target and between every two agents
        // still flying, within its tolerance: a lost agent is left out of
        // the formation its survivors hold (its slot stays empty).
        let goal = &self.scenario.targets[now.active];
        let tolerance = tolerance_of(p, goal);
        let within = |d: f64, want: f64| (d - want).abs() <= tolerance(want);
        let alive = &self.alive;
        let n = positions.len();
        let formed = (0..n).filter(|&i| alive[i]).all(|i| {
            let (point, want) = goal.of(i, p.target_distance);
            within((positions[i] - point).norm(), want)
                && (i + 1..n)
                    .filter(|&j| alive[j])
                    .all(|j| within((positions[j] - positions[i]).norm(), goal.desired[i][j]))
        });
        log.inside_at_end[now.active] = formed;
        if !formed {
            log.outside[now.active] = Some(t);
        }
        if ends {
            log.ends[now.active] = Some(formation_error(
                positions,
                alive,
                goal,
                p.target_distance,
                &tolerance,
                t,
            ));
            log.last_positions[now.active] = Some((t, positions.clone()));
        }
    }

    /// Whether `now` is the last sample recorded while its target is in force.
    fn last_sample_of_target(&self, now: &Snapshot) -> bool {
        let next = now.step + self.clock.record_every;
        let t = next as f64 * self.clock.dt;
        next > self.clock.steps
            || self
                .scenario
                .targets
                .get(now.active + 1)
                .is_some_and(|g| g.time <= t)
    }

    /// Disturbances (4.2): an impulse due by `t` changes the velocity at once
    /// (of an agent flown here).
    fn disturb(&mut self, t: f64) {
        while let Some(push) = self.pushes.get(self.next_push).filter(|p| p.time <= t) {
            if let Some(k) = self.local.iter().position(|&i| i == push.agent)
                && let Some(f) = self.flights.get_mut(k)
            {
                f.state[3] += push.impulse.x / self.p.mass;
                f.state[4] += push.impulse.y / self.p.mass;
            }
            self.next_push += 1;
        }
    }

    /// The state of step `k` each agent flown here broadcasts.
    fn broadcast(&self, k: usize) -> Vec<Message> {
        self.flights
            .iter()
            .zip(&self.local)
            .filter(|(_, i)| self.alive[**i])
            .map(|(f, &i)| {
                let at = quadrotor::position(&f.state);
                Message {
                    sender: i,
                    step: k,
                    position: at.xy(),
                    height: at.z,
                    velocity: Vector2::new(f.state[3], f.state[4]),
                    reference: f.reference.xy(),
                }
            })
            .collect()
    }

    /// Who decides now: everyone at a scheduled round (an agent with a
    /// clock of its own at its own steps instead); an agent with a neighbour
    /// closer than c at once (every agent's, from the replicated network:
    /// the round's number depends on it).
    fn due(&self, now: &Snapshot) -> Vec<bool> {
        let positions = &now.positions;
        (0..positions.len())
            .map(|i| {
                let scheduled = match self.own_clock[i] {
                    Some((period, phase)) => {
                        now.step >= phase && (now.step - phase).is_multiple_of(period)
                    }
                    None => now.scheduled,
                };
                let c = self.p.safety_distance;
                self.alive[i]
                    && (scheduled
                        || self
                            .heard_neighbours(i)
                            .any(|m| (m.position - positions[i]).norm() < c)
                        || now
                            .lost
                            .iter()
                            .any(|(_, r)| (r.center() - positions[i]).norm() - r.radius() < c))
            })
            .collect()
    }

    /// The last message agent `i` heard from each agent on its list.
    fn heard_neighbours(&self, i: usize) -> impl Iterator<Item = &Message> + '_ {
        self.near[i]
            .iter()
            .filter_map(move |&j| self.network.heard(i, j))
    }

    /// The neighbours agent `i` decides on: those it heard within l of it.
    fn in_reach(&self, i: usize, me: Point2<f64>) -> impl Iterator<Item = &Message> + '_ {
        let l = self.p.neighbourhood;
        self.heard_neighbours(i)
            .filter(move |m| (m.position - me).norm() <= l)
    }

    /// The age of every neighbour state each deciding agent used.
    fn count_ages(&mut self, now: &Snapshot, due: &[bool]) {
        for i in (0..due.len()).filter(|&i| due[i]) {
            let used: Vec<Message> = self.in_reach(i, now.positions[i]).copied().collect();
            for m in &used {
                self.network.used(i, m, now.step);
            }
        }
    }

    /// What each agent flown here and due to decide observes: the neighbours
    /// it heard within l (their last messages) and the obstacles within
    /// d_obs, nothing else.
    fn observe(&self, now: &Snapshot, due: &[bool]) -> Vec<Option<Observation>> {
        self.local
            .par_iter()
            .with_min_len(8)
            .map(|&i| due[i].then(|| self.observation(i, now)))
            .collect()
    }

    fn observation(&self, i: usize, now: &Snapshot) -> Observation {
        let (p, positions) = (self.p, &now.positions);
        let me = positions[i];
        let goal = &self.scenario.targets[now.active];
        let (target, target_distance) = goal.of(i, p.target_distance);
        Observation {
            position: me,
            target,
            target_distance,
            // Eq. 2: Ξ_i, the agents within l (the round's lists reach a little
            // further, for the safety check).
            // What it heard of them, not where they are.
            neighbours: self
                .in_reach(i, me)
                .map(|m| Neighbour {
                    position: m.position,
                    desired: goal.desired[i][m.sender],
                })
                .collect(),
            // The obstacles within d_obs, and each lost agent's region as one
            // (eq. 9: it is no longer a neighbour that steers itself).
            obstacles: self
                .obstacles
                .iter()
                .chain(now.lost.iter().map(|(_, r)| r))
                .filter(|o| o.signed_distance(&me) <= p.detection_range)
                .cloned()
                .collect(),
            rho: p.rho,
            safety: p.safety_distance,
            sigma: p.sigma,
            keep_apart: p.safety_distance + p.step_max,
            keep_clear: p.safety_distance + p.step_max / 2.0,
        }
    }

    /// Every agent flown here with an observation runs its PSO on it (each on
    /// its own random stream, in parallel) and moves its reference by the
    /// step found.
    fn decide(&mut self, now: &Snapshot, observations: &[Option<Observation>]) {
        let (round, altitude, positions) = (self.round, self.p.altitude, &now.positions);
        let local = &self.local;
        self.flights
            .par_iter_mut()
            .enumerate()
            .with_min_len(8)
            .for_each(|(k, f)| {
                if let Some(view) = &observations[k] {
                    let i = local[k];
                    let h: Vector2<f64> = f.planner.decide(view, round);
                    // Eq. 8: Y_id(t + τ) = Y_i(t) + h, in the flight plane.
                    f.reference = Point3::new(positions[i].x + h.x, positions[i].y + h.y, altitude);
                }
            });
    }

    /// Flies one step from `t` (eq. 10 under eqs. 11-13), each agent on its own.
    fn fly(&mut self, t: f64) {
        let (body, dt) = (&self.body, self.clock.dt);
        self.flights.par_iter_mut().with_min_len(8).for_each(|f| {
            let u = body.control(&f.state, &f.reference);
            f.state = rk4_step(|_, x| body.derivative(x, &u), t, &f.state, dt);
            quadrotor::renormalize(&mut f.state);
        });
    }

    /// What the agents flown here did: their planning effort and their
    /// traffic.
    pub fn effort(&self) -> Vec<Effort> {
        self.flights
            .iter()
            .zip(&self.local)
            .map(|(f, &i)| Effort {
                agent: i,
                decisions: f.planner.decisions,
                evaluations: f.planner.evaluations,
                network: self.network.stats()[i],
            })
            .collect()
    }

    /// The agents lost so far.
    pub fn lost(&self) -> &[LostAgent] {
        &self.lost
    }

    /// The outcome of what was flown; logs each target's result. `remote`
    /// is what the agents flown elsewhere did, as their processes reported
    /// it (an agent with no report keeps no effort and the traffic this
    /// process's network model counted for it).
    pub fn finish(
        self,
        completion: Completion,
        remote: &[Effort],
        observer: &mut dyn Observer,
    ) -> FleetOutcome {
        // What the rounds say each agent did, until its own count replaces it.
        let per_decision = Planner::evaluations_per_decision(self.p);
        let mut effort: Vec<Effort> = (0..self.p.agents)
            .map(|i| Effort {
                agent: i,
                decisions: self.decided[i],
                evaluations: self.decided[i] * per_decision,
                network: self.network.stats()[i],
            })
            .collect();
        for e in self.effort().into_iter().chain(remote.iter().copied()) {
            if let Some(slot) = effort.get_mut(e.agent) {
                *slot = e;
            }
        }
        let short = self.shortfalls();
        let Simulation {
            mission,
            p,
            seed,
            scenario: sc,
            clock,
            log,
            lost,
            ..
        } = self;
        let end = log.times.last().copied().unwrap_or(0.0);
        let targets = sc
            .targets
            .iter()
            .enumerate()
            .map(|(k, goal)| {
                let time = goal.time;
                let converged_after = (log.inside_at_end[k] && time <= end).then(|| {
                    let since = log.outside[k]
                        .map_or(time, |last| last + clock.record_every as f64 * clock.dt);
                    (since - time).max(0.0)
                });
                let (assigned, assignment) = goal.assigned.clone().unwrap_or_default();
                TargetOutcome {
                    time,
                    position: goal.centre,
                    assigned,
                    assignment,
                    converged_after,
                    end: log.ends[k].clone(),
                }
            })
            .collect();
        for (k, t) in sc.targets.iter().enumerate() {
            let reached = if log.inside_at_end[k] {
                "formation reached"
            } else {
                "formation not reached"
            };
            let text = format!(
                "target {} at ({:.2}, {:.2}): {reached}",
                k + 1,
                t.centre.x,
                t.centre.y
            );
            observer.on_event(Event::Log(Level::Info, &text));
        }
        // A cancelled run stays at the share it got through.
        if completion == Completion::Finished {
            observer.on_event(Event::Progress(1.0));
        }
        let agents = log
            .samples
            .into_iter()
            .enumerate()
            .map(|(i, samples)| AgentOutcome {
                index: i,
                start: sc.starts[i],
                samples,
                decisions: effort[i].decisions,
                evaluations: effort[i].evaluations,
                network: effort[i].network,
            })
            .collect();
        FleetOutcome {
            header: crate::pipelines::Header {
                pipeline: crate::pipelines::Kind::Fleet,
                mission: mission.name.clone(),
                seed,
                completion,
            },
            duration: end,
            times: log.times,
            agents,
            targets,
            distances: log.distances,
            safety_distance: p.safety_distance,
            closest_agents: log.closest_agents,
            closest_obstacle: log.closest_obstacle,
            links: log.links,
            lost,
            distributed: None,
            short,
        }
    }

    /// For each target not reached, each surviving agent that stood short
    /// of its place at its last sample: by how much, and what held it
    /// back. An obstacle in the flight plane between it and its place,
    /// within d_obs of it, is what it is stalled behind; else it was on its
    /// way, and the time it still needed at the cruise speed is said.
    fn shortfalls(&self) -> Vec<Shortfall> {
        let p = self.p;
        let mut out = Vec::new();
        for (k, goal) in self.scenario.targets.iter().enumerate() {
            if self.log.inside_at_end[k] {
                continue;
            }
            let Some((t, positions)) = &self.log.last_positions[k] else {
                continue;
            };
            let tolerance = tolerance_of(p, goal);
            for (i, q) in positions.iter().enumerate().filter(|(i, _)| self.alive[*i]) {
                let (point, want) = goal.of(i, p.target_distance);
                let to = point - q;
                let distance = to.norm();
                let short_by = (distance - want).abs();
                if short_by <= tolerance(want) {
                    continue;
                }
                // Where it should be: its point, or d_ip short of the target.
                let place = if distance > 1e-9 {
                    q + to * ((distance - want).max(0.0) / distance)
                } else {
                    *q
                };
                let blocking = self
                    .mission
                    .obstacles
                    .iter()
                    .filter(|o| o.spans(p.altitude))
                    .map(|o| (o, o.prism()))
                    .filter(|(_, prism)| {
                        prism.outward(q) <= p.detection_range
                            && prism.segment_distance(q, &place) < p.safety_distance
                    })
                    .min_by(|a, b| a.1.outward(q).total_cmp(&b.1.outward(q)));
                let why = match blocking {
                    Some((o, prism)) => format!(
                        "stalled behind '{}' ({:.1} m from it at t = {t:.1} s): the way to its \
                         place passes within c of it",
                        o.name,
                        prism.outward(q).max(0.0)
                    ),
                    None => {
                        let speed = p.cruise_speed();
                        format!(
                            "still on its way at t = {t:.1} s: at about {speed:.2} m/s it needs \
                             about {:.0} s more (fleet.duration)",
                            short_by / speed.max(1e-6)
                        )
                    }
                };
                out.push(Shortfall {
                    target: k + 1,
                    agent: i,
                    short_by,
                    why,
                });
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::Silent;

    /// The rounds' count of every agent's decisions (what a coordinator
    /// reports for an agent whose own report never comes) is the agents'
    /// own count: near a neighbour, on its own clock, or lost midway.
    #[test]
    fn the_rounds_count_each_agents_decisions_as_it_makes_them() {
        let mut m = crate::mission::default_mission().mission;
        m.fleet.duration = Some(8.0);
        m.fleet.network.updates = vec![crate::mission::FleetUpdate {
            agent: 2,
            period: 30,
            phase: 7,
        }];
        let mut simulation = Simulation::new(&m, 4);
        let mut link = Loopback::new(3).losing(2, 900, "gone");
        let flown = simulation.run(&mut link, &mut Silent, &CancelToken::new());
        assert_eq!(flown, Ok(Completion::Finished));
        let own: Vec<usize> = simulation
            .flights
            .iter()
            .map(|f| f.planner.decisions)
            .collect();
        assert_eq!(simulation.decided, own);
        assert!(own[2] > 0 && own[2] < own[0], "{own:?}");
        assert_ne!(own[1], own[0], "agent 2 on a clock of its own");
    }
}
