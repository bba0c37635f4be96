//! The fleet's synchronous rounds as a simulation with named stages on state
//! it owns: every step it takes a [`Snapshot`] of the fleet, `record`s it on
//! the sample grid, applies the `disturb`ances, lets each agent due to decide
//! `observe` (an [`Observation`]: everything its planner may know, a plain
//! value a transport could carry) and `decide` from that alone, and `fly`s
//! one step. `finish` turns what was recorded into the outcome.

use nalgebra::{Point2, Point3, Vector2};
use rayon::prelude::*;

use super::agent::Planner;
use super::cost::{Detected, Neighbour, Observation};
use super::network::{Message, Network};
use super::quadrotor::{self, Body, State};
use super::{
    AgentOutcome, AgentSample, Closest, DistanceSeries, FleetOutcome, MAX_SERIES_AGENTS, Other,
    SAMPLE_RATE, Scenario, TargetOutcome, neighbourhoods, scenario,
};
use crate::base::ode::rk4_step;
use crate::mission::{FleetParams, FleetPush, Mission};
use crate::pipelines::{CancelToken, Completion, Event, Level, Observer};

/// One quadrotor in flight.
struct Flight {
    planner: Planner,
    state: State,
    reference: Point3<f64>,
}

/// The step counts of the run, from the mission's periods.
struct Clock {
    dt: f64,
    steps: usize,
    replan_every: usize,
    record_every: usize,
    report_every: usize,
}

/// The fleet as every agent sees it at the start of a step.
pub struct Snapshot {
    step: usize,
    t: f64,
    /// The target in force (index into the scenario's targets) and where it is.
    active: usize,
    target: Point2<f64>,
    positions: Vec<Point2<f64>>,
    /// A scheduled round (every τ): everyone decides, neighbour lists rebuilt.
    scheduled: bool,
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
}

/// The fleet in flight, with everything the round loop needs.
pub struct Simulation<'m> {
    mission: &'m Mission,
    p: &'m FleetParams,
    seed: u64,
    scenario: Scenario,
    /// The obstacles in the flight plane (the fleet flies over the others).
    obstacles: Vec<Detected>,
    body: Body,
    flights: Vec<Flight>,
    clock: Clock,
    pushes: Vec<&'m FleetPush>,
    next_push: usize,
    round: u64,
    /// Each agent's neighbours within `watch_radius`, rebuilt every round.
    near: Vec<Vec<usize>>,
    watch_radius: f64,
    /// What each agent has heard of the others (`network`).
    network: Network,
    log: Log,
}

impl<'m> Simulation<'m> {
    /// The fleet at its starts (drawn with `seed`), hovering.
    pub fn new(mission: &'m Mission, seed: u64) -> Self {
        let p = &mission.fleet;
        let n = p.agents;
        let sc = scenario(mission, seed);
        let obstacles = mission
            .obstacles
            .iter()
            .filter(|o| o.height > p.altitude)
            .map(|o| Detected {
                center: o.center,
                radius: o.radius,
            })
            .collect();
        let flights = sc
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
        let dt = p.sim_step;
        let clock = Clock {
            dt,
            steps: (p.duration / dt).round() as usize,
            replan_every: ((p.replan_period / dt).round() as usize).max(1),
            record_every: ((1.0 / (SAMPLE_RATE * dt)).round() as usize).max(1),
            report_every: ((1.0 / dt).round() as usize).max(1),
        };
        let kept = clock.steps / clock.record_every + 1;
        let mut distances = Vec::new();
        if n <= MAX_SERIES_AGENTS {
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
        let log = Log {
            times: Vec::with_capacity(kept),
            samples: vec![Vec::with_capacity(kept); n],
            distances,
            closest_agents: None,
            closest_obstacle: None,
            outside: vec![None; sc.targets.len()],
            inside_at_end: vec![false; sc.targets.len()],
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
            clock,
            pushes,
            next_push: 0,
            round: 0,
            near: vec![Vec::new(); n],
            // Each reference is at most √2·h_max from its agent, so two agents
            // close in on each other by well under 2·√2·h_max + 1 m in one τ.
            watch_radius: p
                .neighbourhood
                .max(p.safety_distance + 2.0 * std::f64::consts::SQRT_2 * p.step_max + 1.0),
            network: Network::new(&p.network, p.neighbourhood, n, seed, dt),
            log,
        }
    }

    /// Runs every step to the mission's duration, or until `cancel`.
    pub fn run(&mut self, observer: &mut dyn Observer, cancel: &CancelToken) -> Completion {
        let steps = self.clock.steps;
        for k in 0..=steps {
            let now = self.snapshot(k);
            if k.is_multiple_of(self.clock.record_every) {
                self.record(&now);
            }
            self.disturb(now.t);
            self.broadcast(&now);
            let due = self.due(&now);
            // Before the first target appears the agents hold their starts.
            let started = now.t >= self.scenario.targets[0].0;
            if started && due.iter().any(|&d| d) {
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
                        now.t, self.p.duration
                    );
                    observer.on_event(Event::Log(Level::Warn, &text));
                    return Completion::Cancelled;
                }
            }
        }
        Completion::Finished
    }

    /// The fleet at step `k`; at a scheduled round the neighbour lists are
    /// rebuilt, reaching beyond c by what two agents can close within τ: in
    /// between, the same lists serve the "closer than c" check and the
    /// closest-approach record. Eq. 2's Ξ_i (within l) is taken from them in
    /// `observe`.
    fn snapshot(&mut self, k: usize) -> Snapshot {
        let t = k as f64 * self.clock.dt;
        let targets = &self.scenario.targets;
        let active = targets
            .iter()
            .rposition(|(time, _)| *time <= t)
            .unwrap_or(0);
        let positions: Vec<Point2<f64>> = self
            .flights
            .iter()
            .map(|f| quadrotor::position(&f.state).xy())
            .collect();
        let scheduled = k.is_multiple_of(self.clock.replan_every);
        if scheduled {
            self.near = neighbourhoods(&positions, self.watch_radius);
        }
        Snapshot {
            step: k,
            t,
            active,
            target: targets[active].1,
            positions,
            scheduled,
        }
    }

    /// Records (and checks) the snapshot: samples, closest approaches, the
    /// distance series, whether the formation stands.
    fn record(&mut self, now: &Snapshot) {
        let (p, log, positions, t) = (self.p, &mut self.log, &now.positions, now.t);
        log.times.push(t);
        for (i, f) in self.flights.iter().enumerate() {
            log.samples[i].push(AgentSample {
                t,
                position: quadrotor::position(&f.state),
                reference: f.reference,
            });
            for &j in self.near[i].iter().filter(|&&j| j > i) {
                let d = (positions[j] - positions[i]).norm();
                if log.closest_agents.as_ref().is_none_or(|c| d < c.distance) {
                    log.closest_agents = Some(Closest {
                        a: i,
                        b: Other::Agent(j),
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
                .filter(|o| o.height > p.altitude)
            {
                let d = (o.center - positions[i]).norm() - o.radius;
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
        let within =
            |d: f64, want: f64| (d - want).abs() <= p.tolerance * want.max(p.safety_distance);
        let desired = &self.scenario.desired;
        let formed = positions
            .iter()
            .all(|q| within((q - now.target).norm(), p.target_distance))
            && (0..positions.len()).all(|i| {
                self.near[i]
                    .iter()
                    .all(|&j| within((positions[j] - positions[i]).norm(), desired[i][j]))
            });
        log.inside_at_end[now.active] = formed;
        if !formed {
            log.outside[now.active] = Some(t);
        }
    }

    /// Disturbances (4.2): an impulse due by `t` changes the velocity at once.
    fn disturb(&mut self, t: f64) {
        while let Some(push) = self.pushes.get(self.next_push).filter(|p| p.time <= t) {
            if let Some(f) = self.flights.get_mut(push.agent) {
                f.state[3] += push.impulse.x / self.p.mass;
                f.state[4] += push.impulse.y / self.p.mass;
            }
            self.next_push += 1;
        }
    }

    /// Who decides now: everyone at a scheduled round; an agent with a
    /// neighbour closer than c at once.
    fn due(&self, now: &Snapshot) -> Vec<bool> {
        let positions = &now.positions;
        (0..positions.len())
            .map(|i| {
                now.scheduled
                    || self
                        .heard_neighbours(i)
                        .any(|m| (m.position - positions[i]).norm() < self.p.safety_distance)
            })
            .collect()
    }

    /// Every agent broadcasts its state of this step; what arrives now is
    /// heard (`network`).
    fn broadcast(&mut self, now: &Snapshot) {
        let out = self
            .flights
            .iter()
            .enumerate()
            .map(|(i, f)| Message {
                sender: i,
                step: now.step,
                position: now.positions[i],
                velocity: Vector2::new(f.state[3], f.state[4]),
                reference: f.reference.xy(),
            })
            .collect();
        self.network.exchange(now.step, out, &self.near);
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

    /// What each agent due to decide observes: the neighbours it heard
    /// within l (their last messages) and the obstacles within d_obs,
    /// nothing else.
    fn observe(&self, now: &Snapshot, due: &[bool]) -> Vec<Option<Observation>> {
        (0..due.len())
            .into_par_iter()
            .with_min_len(8)
            .map(|i| due[i].then(|| self.observation(i, now)))
            .collect()
    }

    fn observation(&self, i: usize, now: &Snapshot) -> Observation {
        let (p, positions) = (self.p, &now.positions);
        let me = positions[i];
        Observation {
            position: me,
            target: now.target,
            target_distance: p.target_distance,
            // Eq. 2: Ξ_i, the agents within l (the round's lists reach a little
            // further, for the safety check).
            // What it heard of them, not where they are.
            neighbours: self
                .in_reach(i, me)
                .map(|m| Neighbour {
                    position: m.position,
                    desired: self.scenario.desired[i][m.sender],
                })
                .collect(),
            obstacles: self
                .obstacles
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

    /// Every agent with an observation runs its PSO on it (each on its own
    /// random stream, in parallel) and moves its reference by the step found.
    fn decide(&mut self, now: &Snapshot, observations: &[Option<Observation>]) {
        let (round, altitude, positions) = (self.round, self.p.altitude, &now.positions);
        self.flights
            .par_iter_mut()
            .enumerate()
            .with_min_len(8)
            .for_each(|(i, f)| {
                if let Some(view) = &observations[i] {
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

    /// The outcome of what was flown; logs each target's result.
    pub fn finish(self, completion: Completion, observer: &mut dyn Observer) -> FleetOutcome {
        let Simulation {
            mission,
            p,
            seed,
            scenario: sc,
            flights,
            clock,
            log,
            network,
            ..
        } = self;
        let end = log.times.last().copied().unwrap_or(0.0);
        let targets = sc
            .targets
            .iter()
            .enumerate()
            .map(|(k, &(time, position))| {
                let converged_after = (log.inside_at_end[k] && time <= end).then(|| {
                    let since = log.outside[k]
                        .map_or(time, |last| last + clock.record_every as f64 * clock.dt);
                    (since - time).max(0.0)
                });
                TargetOutcome {
                    time,
                    position,
                    converged_after,
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
                t.1.x,
                t.1.y
            );
            observer.on_event(Event::Log(Level::Info, &text));
        }
        // A cancelled run stays at the share it got through.
        if completion == Completion::Finished {
            observer.on_event(Event::Progress(1.0));
        }
        let agents = flights
            .into_iter()
            .zip(log.samples)
            .enumerate()
            .map(|(i, (f, samples))| AgentOutcome {
                index: i,
                start: sc.starts[i],
                samples,
                decisions: f.planner.decisions,
                evaluations: f.planner.evaluations,
                network: network.stats()[i],
            })
            .collect();
        FleetOutcome {
            pipeline: crate::pipelines::Kind::Fleet,
            mission: mission.name.clone(),
            seed,
            completion,
            duration: end,
            times: log.times,
            agents,
            targets,
            distances: log.distances,
            safety_distance: p.safety_distance,
            closest_agents: log.closest_agents,
            closest_obstacle: log.closest_obstacle,
        }
    }
}
