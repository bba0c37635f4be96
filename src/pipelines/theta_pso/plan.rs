//! θ-PSO's Fig. 3 as named stages, each a short function of what the one
//! before gave, as `fleet::Simulation::run` reads: [`admit`] the mission,
//! [`intermediate_waypoints`] (eq. 9), [`route_stage`] (the corridor),
//! [`seed_swarm`] (line 9), the search ([`Search::swarm`]: the swarm, then
//! verification, the repair step and restarts; [`Search::fly_the_corridor`]
//! when every run fails), [`report_broken`], and the [`outcome`] with its
//! trajectories (eqs. 12-15).
//!
//! Long (~710 lines) because it is Fig. 3 whole: each stage a short function, the search's
//! attempts and restarts, the repair and the corridor, in the order they run.

use std::ops::ControlFlow;

use serde::Serialize;

use super::{
    CentroidPath, CostTerms, Iwp, PlanOptions, PlannedPass, Problem, ThetaPsoOutcome, Trajectory,
    USABLE_LOGGED, Verification, WARM_STALL, WARM_SWARM, WARM_TOLERANCE, WarmStart, benchmark,
    budget, cost, flight, reference, repair, route, seeding, trajectory, trajectory_samples,
    unusable,
};
use crate::base::swarm::{self, SwarmConfig};
use crate::mission::Mission;
use crate::pipelines::verify;
use crate::pipelines::{
    CancelToken, Completion, Event, Kind, Level, Observer, PipelineError, Revision,
};

/// Plans `mission` with `seed`. Reports to `observer`, stops early (keeping
/// the best so far) when `cancel` is set. Fails on an invalid mission and
/// when the route stage finds no corridor (naming what closes the way);
/// a plan that fails verification is an infeasible outcome, not an error.
///
/// The swarm starts partly on the route stage's corridor. When its best
/// fails verification, the repair step moves it locally; when that fails
/// too, the swarm runs again with new random streams of the same seed, up to
/// `theta_pso.restarts` times; when every run fails, the corridor itself is
/// tried. The first feasible plan is kept, else the one of lowest cost.
pub fn plan(
    mission: &Mission,
    seed: u64,
    options: PlanOptions,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<ThetaPsoOutcome, PipelineError> {
    plan_warm(mission, seed, options, None, observer, cancel)
}

/// [`plan`], part of the swarm started from `warm`'s plan (and the swarm
/// stopped once it stalls, see [`WarmStart`]); `None` is [`plan`] exactly.
///
/// Fig. 3 as named stages, each reading what the one before gave.
pub fn plan_warm(
    mission: &Mission,
    seed: u64,
    options: PlanOptions,
    warm: Option<&WarmStart>,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<ThetaPsoOutcome, PipelineError> {
    plan_given(mission, seed, options, warm, None, observer, cancel)
}

/// [`plan_warm`] on a mission whose `revision` was already looked at (the
/// designer's, on each edit): its IWPs and its findings are read, not found
/// again. `None`: found here, once.
pub fn plan_given(
    mission: &Mission,
    seed: u64,
    options: PlanOptions,
    warm: Option<&WarmStart>,
    revision: Option<&Revision>,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<ThetaPsoOutcome, PipelineError> {
    if mission.theta_pso.cost == crate::mission::CostKind::Spso {
        return benchmark::plan(mission, seed, observer, cancel);
    }
    // Found once: the admission and the search read the same IWPs.
    let given = revision.and_then(super::face::prepared_iwps);
    let iwps = match given {
        Some(iwps) => iwps.clone(),
        None => super::find_iwps(mission),
    };
    admit(mission, &iwps, revision)?;
    let mut problem = intermediate_waypoints(mission, iwps, observer)?;
    let corridor = route_stage(mission, &mut problem, warm, observer)?;
    let starts = seed_swarm(mission, &problem, &corridor, seed, warm, observer);
    let mut search = Search::default();
    search.swarm(
        mission, &problem, &starts, options, seed, warm, observer, cancel,
    )?;
    search.fly_the_corridor(mission, &problem, &starts, observer)?;
    let best = search.best()?;
    report_broken(&best, search.completion, observer);
    Ok(outcome(
        mission, seed, warm, problem, corridor, &search, best,
    ))
}

/// Before Fig. 3's first line: a valid mission within the run's budget,
/// with no IWP or inspection already known to be impossible.
fn admit(
    mission: &Mission,
    iwps: &[Iwp],
    revision: Option<&Revision>,
) -> Result<(), PipelineError> {
    match revision {
        Some(r) => r.admit_rules(Kind::ThetaPso)?,
        None => crate::pipelines::require_admissible(mission, budget)?,
    }
    // A gate the user asked for that no formation can take: no plan keeps
    // the route as written.
    if mission.route.via.iter().any(|v| v.between.is_some())
        && let Some((g, iwp)) = iwps
            .iter()
            .find_map(|i| Some((i.gate?, i)).filter(|(_, i)| i.unusable.is_some()))
    {
        return Err(PipelineError::NoRoute(crate::pipelines::NoPlan {
            reason: format!(
                "route.via {} (between '{}' and '{}') cannot be kept: {}",
                g + 1,
                iwp.between[0],
                iwp.between[1],
                iwp.unusable.clone().unwrap_or_default()
            ),
            obstacles: iwp.between.to_vec(),
            passages: Vec::new(),
            route: Vec::new(),
        }));
    }
    if let Some(r) = revision {
        return r.admit_findings(Kind::ThetaPso);
    }
    let errors: Vec<String> = super::diagnostics_given(mission, iwps)
        .into_iter()
        .filter(|d| d.is_error())
        .map(|d| d.to_string())
        .collect();
    if !errors.is_empty() {
        return Err(PipelineError::InvalidMission(errors.join("\n")));
    }
    Ok(())
}

/// The IWPs (eq. 9, Fig. 2) and the problem the swarm solves over them.
fn intermediate_waypoints(
    mission: &Mission,
    iwps: Vec<Iwp>,
    observer: &mut dyn Observer,
) -> Result<Problem, PipelineError> {
    observer.on_event(Event::Stage("intermediate waypoints"));
    let problem =
        Problem::given(mission, iwps).map_err(|(_, e)| PipelineError::InvalidMission(e))?;
    log_iwps(observer, &problem.iwps);
    Ok(problem)
}

/// The route stage: a corridor the formation can fly (the warm start's,
/// when it still holds), which the problem then follows; none is a
/// refusal naming what closes the way.
fn route_stage(
    mission: &Mission,
    problem: &mut Problem,
    warm: Option<&WarmStart>,
    observer: &mut dyn Observer,
) -> Result<route::Corridor, PipelineError> {
    observer.on_event(Event::Stage("route"));
    let reused = warm.and_then(|w| w.corridor.as_ref()).and_then(|previous| {
        route::reuse(
            mission,
            &problem.builder,
            &problem.iwps,
            problem.cost.margin(),
            previous,
        )
    });
    if reused.is_some() {
        observer.on_event(Event::Log(
            Level::Info,
            "route: the warm start's corridor still holds; no search",
        ));
    }
    let corridor = match reused {
        Some(c) => c,
        None => route::find(
            mission,
            &problem.builder,
            &problem.iwps,
            problem.cost.margin(),
        )
        .map_err(|blocked| {
            PipelineError::NoRoute(crate::pipelines::NoPlan {
                obstacles: blocked
                    .obstacles
                    .iter()
                    .filter_map(|&k| mission.obstacles.get(k).map(|o| o.name.clone()))
                    .collect(),
                route: blocked.tried.iter().map(|p| [p.x, p.y]).collect(),
                passages: blocked
                    .passages
                    .iter()
                    .map(
                        |&([p, q], width, needs, [a, b])| crate::pipelines::Passage {
                            between: [
                                mission.obstacles[p].name.clone(),
                                mission.obstacles[q].name.clone(),
                            ],
                            width,
                            needs,
                            ends: [[a.x, a.y], [b.x, b.y]],
                        },
                    )
                    .collect(),
                reason: blocked.reason,
            })
        })?,
    };
    problem.follow(mission, &corridor);
    observer.on_event(Event::Log(
        Level::Info,
        &format!(
            "route: a corridor of {:.1} m, {} free waypoints{}",
            corridor.length,
            problem.builder.free_waypoints(),
            if corridor.squeeze.is_some() {
                ", squeezed where the site is narrower than the formation"
            } else {
                ""
            }
        ),
    ));
    Ok(corridor)
}

/// Fig. 3, line 9: the swarm's first positions, partly on the corridor,
/// the warm start's plan first.
fn seed_swarm(
    mission: &Mission,
    problem: &Problem,
    corridor: &route::Corridor,
    seed: u64,
    warm: Option<&WarmStart>,
    observer: &mut dyn Observer,
) -> Vec<Vec<f64>> {
    let starts = seeding::particles(mission, problem, corridor, seed);
    let Some(w) = warm else {
        return starts;
    };
    // The earlier plan first: it stands where this one most likely is.
    let mut warmed = seeding::warm(problem, w, seed);
    warmed.extend(starts);
    warmed.truncate(mission.theta_pso.swarm_size.clamp(1, WARM_SWARM));
    observer.on_event(Event::Log(
        Level::Info,
        &format!(
            "warm start from {}",
            if w.from.is_empty() {
                "a plan given"
            } else {
                &w.from
            }
        ),
    ));
    warmed
}

/// What the search has found so far: the plan kept (feasible first, then
/// the lower J), the budget refusal of a plan too long to sample, and the
/// swarm's effort.
#[derive(Default)]
struct Search {
    kept: Option<Attempt>,
    over_budget: Option<PipelineError>,
    iterations: usize,
    evaluations: usize,
    restarts: usize,
    completion: Completion,
}

impl Search {
    /// Fig. 3's loop, then verification, the repair step and restarts: the
    /// swarm runs, its best is verified and, when it fails, repaired; when
    /// that fails too, the swarm runs again with new random streams of the
    /// same seed, up to `theta_pso.restarts` times.
    #[allow(clippy::too_many_arguments)]
    fn swarm(
        &mut self,
        mission: &Mission,
        problem: &Problem,
        starts: &[Vec<f64>],
        options: PlanOptions,
        seed: u64,
        warm: Option<&WarmStart>,
        observer: &mut dyn Observer,
        cancel: &CancelToken,
    ) -> Result<(), PipelineError> {
        let stall = warm.map(|_| (WARM_STALL, WARM_TOLERANCE));
        let p = &mission.theta_pso;
        for attempt in 0..=p.restarts {
            if attempt > 0 {
                self.restarts = attempt;
                let message = format!(
                    "the best plan fails verification ({}); restart {attempt} of {} with new random streams",
                    self.kept
                        .as_ref()
                        .and_then(|k| k.verification.first_failure())
                        .unwrap_or_default(),
                    p.restarts
                );
                observer.on_event(Event::Log(Level::Warn, &message));
            }
            observer.on_event(Event::Stage("planning"));
            let (result, convergence, converged) = run_swarm(
                problem,
                p,
                options,
                seed,
                attempt,
                self.iterations,
                starts,
                stall,
                observer,
                cancel,
            );
            self.iterations += result.iterations;
            self.evaluations += result.evaluations;
            if converged {
                observer.on_event(Event::Log(
                    Level::Info,
                    &format!(
                        "warm-started swarm settled after {} iterations",
                        result.iterations
                    ),
                ));
            } else if result.stopped {
                observer.on_event(Event::Log(
                    Level::Warn,
                    &format!(
                        "cancelled after {} iterations; keeping the best so far",
                        result.iterations
                    ),
                ));
                self.completion = Completion::Cancelled;
            }
            observer.on_event(Event::Stage("verification"));
            // A plan whose flight would be too long to sample is no plan: the
            // next run of the swarm may find another (the budget error stands
            // when none does).
            let tried = match Attempt::new(
                mission,
                problem,
                result.best.position,
                convergence,
                PlanSource::Swarm,
            ) {
                Ok(tried) => tried,
                Err(e @ PipelineError::OverBudget(_))
                    if self.completion == Completion::Finished =>
                {
                    observer.on_event(Event::Log(Level::Warn, &e.to_string()));
                    self.over_budget = Some(e);
                    continue;
                }
                Err(e) => return Err(e),
            };
            let tried = if self.completion == Completion::Finished {
                repaired(mission, problem, tried, observer)?
            } else {
                tried
            };
            let done = tried.verification.feasible || self.completion == Completion::Cancelled;
            if self.kept.as_ref().is_none_or(|k| tried.better_than(k)) {
                self.kept = Some(tried);
            }
            if done {
                break;
            }
        }
        Ok(())
    }

    /// Every run of the swarm failed: fly the corridor itself, if it verifies.
    fn fly_the_corridor(
        &mut self,
        mission: &Mission,
        problem: &Problem,
        starts: &[Vec<f64>],
        observer: &mut dyn Observer,
    ) -> Result<(), PipelineError> {
        let Some(start) = starts.first() else {
            return Ok(());
        };
        if self.kept.as_ref().is_some_and(|k| k.verification.feasible)
            || self.completion != Completion::Finished
        {
            return Ok(());
        }
        let position = repair::repair(mission, problem, start).unwrap_or_else(|| start.clone());
        let convergence = self
            .kept
            .as_ref()
            .map(|k| k.convergence.clone())
            .unwrap_or_default();
        match Attempt::new(
            mission,
            problem,
            position,
            convergence,
            PlanSource::Corridor,
        ) {
            Ok(fallback) if fallback.verification.feasible || self.kept.is_none() => {
                if fallback.verification.feasible {
                    observer.on_event(Event::Log(
                        Level::Warn,
                        "every run of the swarm failed verification; the route stage's corridor is flown",
                    ));
                }
                self.kept = Some(fallback);
            }
            Ok(_) => {}
            Err(e @ PipelineError::OverBudget(_)) => self.over_budget = Some(e),
            Err(e) => return Err(e),
        }
        Ok(())
    }

    /// The plan kept, or why there is none.
    fn best(&mut self) -> Result<Attempt, PipelineError> {
        self.kept.take().ok_or_else(|| {
            self.over_budget.take().unwrap_or_else(|| {
                PipelineError::Unsupported("the swarm never ran (no attempt)".into())
            })
        })
    }
}

/// The repair step: a plan that fails verification moved clear of its
/// violations locally, when it can be; else the plan as it was.
fn repaired(
    mission: &Mission,
    problem: &Problem,
    mut tried: Attempt,
    observer: &mut dyn Observer,
) -> Result<Attempt, PipelineError> {
    if tried.verification.feasible {
        return Ok(tried);
    }
    let Some(fixed) = repair::repair(mission, problem, &tried.position) else {
        return Ok(tried);
    };
    observer.on_event(Event::Log(
        Level::Info,
        &format!(
            "the best plan failed verification ({}); the repair step moved it clear",
            tried.verification.first_failure().unwrap_or_default()
        ),
    ));
    let convergence = std::mem::take(&mut tried.convergence);
    match Attempt::new(mission, problem, fixed, convergence, PlanSource::Repaired) {
        Ok(repaired) => Ok(repaired),
        Err(e @ PipelineError::OverBudget(_)) => {
            observer.on_event(Event::Log(Level::Warn, &e.to_string()));
            Ok(tried)
        }
        Err(e) => Err(e),
    }
}

/// Every constraint and inspection the kept plan breaks, as warnings; a
/// finished run at 100 % (a cancelled one stays at the share it got
/// through).
fn report_broken(best: &Attempt, completion: Completion, observer: &mut dyn Observer) {
    for check in best.verification.checks.iter().filter(|c| !c.ok) {
        let message = format!(
            "constraint broken: {} {} {} (worst {})",
            check.name,
            check.relation,
            check.limit,
            verify::figure(check.worst.unwrap_or(f64::NAN))
        );
        observer.on_event(Event::Log(Level::Warn, &message));
    }
    for i in best.verification.inspections.iter().filter(|i| !i.ok) {
        let message = format!(
            "inspection of '{}' broken: {:.1} m of {} m within [{}, {}] m (eq. 8)",
            i.obstacle, i.achieved, i.required, i.band[0], i.band[1]
        );
        observer.on_event(Event::Log(Level::Warn, &message));
    }
    if completion == Completion::Finished {
        observer.on_event(Event::Progress(1.0));
    }
}

/// The outcome: the kept plan's trajectories (eqs. 12-15), its passes and
/// reconfigurations, what it flew over and under, against the reference
/// length.
fn outcome(
    mission: &Mission,
    seed: u64,
    warm: Option<&WarmStart>,
    problem: Problem,
    corridor: route::Corridor,
    search: &Search,
    best: Attempt,
) -> ThetaPsoOutcome {
    let resolution = mission.formation.ground_speed * trajectory::SAMPLE_PERIOD;
    let reference = reference::lower_bound(mission, &problem.iwps, resolution);
    let waypoints = problem.builder.decode(&best.position);
    let pass_angles = problem.builder.pass_angles(&best.position);
    let bypassed = problem
        .iwps
        .iter()
        .enumerate()
        .filter(|(i, iwp)| iwp.is_via() && !best.path.crossed.contains(i))
        .map(|(i, _)| i)
        .collect();
    let passes = best
        .path
        .passes
        .iter()
        .map(|pass| PlannedPass {
            obstacle: mission.obstacles[pass.obstacle].name.clone(),
            time: [
                best.flight.time_at_planned(pass.arcs[0]),
                best.flight.time_at_planned(pass.arcs[1]),
            ],
            on_left: pass.on_left,
        })
        .collect();
    let reference_length = reference.map(|r| r.length);
    let [passed_over, passed_under] = passed_by_altitude(mission, &best.flight.trajectories);
    let unused_choices = super::unused_choices(mission, &problem.iwps)
        .into_iter()
        .map(|d| d.message)
        .collect();
    ThetaPsoOutcome {
        header: crate::pipelines::Header {
            pipeline: crate::pipelines::Kind::ThetaPso,
            mission: mission.name.clone(),
            seed,
            completion: search.completion,
        },
        iterations: search.iterations,
        evaluations: search.evaluations,
        restarts: search.restarts,
        cost: best.cost,
        convergence: best.convergence,
        iwps: problem.iwps,
        waypoints,
        pass_angles,
        warm_start: warm.cloned(),
        path_length: best.cost.length,
        duration: best.flight.duration(),
        reference_length,
        length_ratio: reference_length
            .filter(|r| *r > 0.0)
            .map(|r| best.cost.length / r),
        passes,
        centroid_path: best.path.points,
        flown_path: best.flight.rounded.path.points,
        flown_arcs: best.flight.progress,
        reconfigurations: best.flight.reconfigurations,
        bypassed,
        unused_choices,
        passed_over,
        passed_under,
        source: best.source,
        route_length: corridor.length,
        corridor,
        trajectories: best.flight.trajectories,
        verification: best.verification,
    }
}

/// A particle built into a plan and verified.
struct Attempt {
    position: Vec<f64>,
    convergence: Vec<f64>,
    path: CentroidPath,
    cost: CostTerms,
    flight: trajectory::Flight,
    verification: Verification,
    source: PlanSource,
}

/// Where the plan kept comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanSource {
    /// The swarm's best, as it came out.
    Swarm,
    /// The swarm's best, moved out of its violations by the repair step.
    Repaired,
    /// The route stage's corridor (the swarm's plans all failed).
    Corridor,
}

impl Attempt {
    /// `position` built, sampled and verified (`OverBudget` when the path is
    /// too long to sample).
    fn new(
        mission: &Mission,
        problem: &Problem,
        position: Vec<f64>,
        convergence: Vec<f64>,
        source: PlanSource,
    ) -> Result<Self, PipelineError> {
        let speed = mission.formation.ground_speed;
        let mut path = problem.path(&position);
        problem.builder.name_squeezes(&mut path);
        let cost = problem.cost.terms(&path);
        // The budget checked the straight distance; the planned path is longer.
        let samples = trajectory_samples(cost.length / speed, mission.formation.slots.len());
        if crate::pipelines::exceeds(samples, crate::pipelines::limits::TRAJECTORY_SAMPLES) {
            return Err(PipelineError::OverBudget(format!(
                "formation.ground_speed: the planned path ({:.1} m at {} m/s) needs {} \
                 trajectory samples (limit {})",
                cost.length,
                crate::pipelines::figure(speed),
                crate::pipelines::figure(samples),
                crate::pipelines::figure(crate::pipelines::limits::TRAJECTORY_SAMPLES)
            )));
        }
        let names: Vec<String> = mission.obstacles.iter().map(|o| o.name.clone()).collect();
        // Slowing through the turns makes the flight longer than the path
        // over the ground speed: the flight checks its own samples.
        let (flight, verification) = flight::fly(mission, &path, &problem.iwps, &names)?;
        Ok(Attempt {
            position,
            convergence,
            path,
            cost,
            flight,
            verification,
            source,
        })
    }

    /// Feasible first, then the lower J.
    fn better_than(&self, other: &Attempt) -> bool {
        (self.verification.feasible, -self.cost.total)
            > (other.verification.feasible, -other.cost.total)
    }
}

/// The IWPs in a few log lines: the first [`USABLE_LOGGED`] usable ones
/// (and how many there are), the unusable ones counted by reason (a forest
/// has hundreds).
fn log_iwps(observer: &mut dyn Observer, iwps: &[Iwp]) {
    let usable: Vec<&Iwp> = iwps.iter().filter(|i| i.unusable.is_none()).collect();
    if usable.len() > USABLE_LOGGED {
        let message = format!("{} usable IWPs; the {USABLE_LOGGED} first:", usable.len());
        observer.on_event(Event::Log(Level::Info, &message));
    }
    for iwp in usable.into_iter().take(USABLE_LOGGED) {
        let state = if iwp.enabled { "enabled" } else { "disabled" };
        let message = format!(
            "IWP between '{}' and '{}': gap {:.2} m, {} ({state})",
            iwp.between[0],
            iwp.between[1],
            iwp.gap,
            iwp.shape_name()
        );
        observer.on_event(Event::Log(Level::Info, &message));
    }
    for group in unusable::unusable_groups(iwps, &[], 0) {
        let message = format!("{} IWP(s) unusable: {}", group.count, group.reason);
        observer.on_event(Event::Log(Level::Info, &message));
    }
}

/// One run of the swarm from `starts` (the rest at random) on the `attempt`-th
/// set of random streams, reporting each iteration's best path and J; the
/// result, the convergence of J (iteration 0 = the initial swarm), and
/// whether it stopped because it stalled: `stall` (iterations, share of J)
/// stops it once its best J has improved by no more than that share over
/// that many iterations.
#[allow(clippy::too_many_arguments)]
fn run_swarm(
    problem: &Problem,
    p: &crate::mission::ThetaPsoParams,
    options: PlanOptions,
    seed: u64,
    attempt: usize,
    iterations_before: usize,
    starts: &[Vec<f64>],
    stall: Option<(usize, f64)>,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> (swarm::SwarmResult, Vec<f64>, bool) {
    let config = SwarmConfig {
        // A warm start searches about the earlier plan: a smaller swarm.
        particles: if stall.is_some() {
            p.swarm_size.min(WARM_SWARM)
        } else {
            p.swarm_size
        },
        iterations: p.iterations,
        inertia: p.inertia,
        cognitive: p.cognitive,
        social: p.social,
        parallel: options.parallel,
        streams: attempt as u64,
    };
    let mut convergence = Vec::with_capacity(p.iterations + 1);
    let mut shown: Option<(CentroidPath, CostTerms)> = None;
    let offset = iterations_before + attempt;
    let mut stalled = false;
    let result = swarm::minimize(
        &problem.space,
        &config,
        seed,
        starts,
        |angles, bound| problem.objective_below(angles, bound),
        |report| {
            // The best only changes on improvement; rebuild its path only then.
            if report.improved || shown.is_none() {
                let path = problem.path(&report.best.position);
                let cost = problem.cost.terms(&path);
                shown = Some((path, cost));
            }
            if let Some((path, cost)) = &shown {
                // J of the best, not the objective (which adds the
                // infeasibility step while the best still breaks a constraint).
                convergence.push(cost.total);
                observer.on_event(Event::Iteration {
                    iteration: offset + report.iteration,
                    cost: cost.total,
                    terms: &cost.named(),
                    path: &path.points,
                });
            }
            observer.on_event(Event::Progress(
                0.95 * report.iteration as f64 / p.iterations.max(1) as f64,
            ));
            if let Some((window, share)) = stall
                && convergence.len() > window
                && report.best.cost < cost::INFEASIBLE_STEP
            {
                let now = convergence[convergence.len() - 1];
                let before = convergence[convergence.len() - 1 - window];
                if before - now <= share * now.abs() {
                    stalled = true;
                    return ControlFlow::Break(());
                }
            }
            if cancel.is_cancelled() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    (result, convergence, stalled && !cancel.is_cancelled())
}

/// The obstacles some UAV's track passes over and under (see
/// [`ThetaPsoOutcome::passed_over`]).
pub fn passed_by_altitude(mission: &Mission, tracks: &[Trajectory]) -> [Vec<String>; 2] {
    let mut found = [Vec::new(), Vec::new()];
    for o in &mission.obstacles {
        let prism = mission.prism(o);
        let (mut over, mut under) = (false, false);
        for s in tracks.iter().flat_map(|t| &t.samples) {
            let p = s.position;
            if prism.outward(&p.xy()) <= 0.0 {
                over |= p.z > prism.height;
                under |= p.z < prism.base;
            }
            if over && under {
                break;
            }
        }
        for (list, passed) in found.iter_mut().zip([over, under]) {
            if passed {
                list.push(o.name.clone());
            }
        }
    }
    found
}
