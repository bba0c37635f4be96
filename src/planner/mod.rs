//! θ-PSO formation planning with reconfiguration (Hoang et al.; Fig. 3 is the
//! algorithm): find the IWPs (eq. 9), search the centroid path with the
//! angle-encoded swarm (eq. 1) against J (eqs. 2-5, 10-11), derive each UAV's
//! timed trajectory through the reconfigurations (eqs. 12-15), and verify the
//! result against the hard constraints.

pub mod cost;
pub mod iwp;
pub mod path;
pub mod trajectory;
pub mod verify;

use std::f64::consts::FRAC_PI_2;
use std::ops::ControlFlow;

use nalgebra::Point3;
use serde::Serialize;

use crate::mission::Mission;
use crate::pipeline::{CancelToken, Completion, CostTerms, Event, Level, Observer, PipelineError};
use crate::swarm::{self, SearchSpace, SwarmConfig};

pub use cost::CostModel;
pub use iwp::{Iwp, Shape, find_iwps};
pub use path::{CentroidPath, PathBuilder};
pub use trajectory::{Reconfiguration, Sample, Trajectory};
pub use verify::{Check, Verification};

/// How to run (not what to plan: that is the mission).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanOptions {
    /// Evaluate the swarm's costs on the rayon pool (same result either way).
    pub parallel: bool,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions { parallel: true }
    }
}

/// Everything a θ-PSO run produces.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThetaPsoOutcome {
    pub pipeline: &'static str,
    pub mission: String,
    pub seed: u64,
    pub completion: Completion,
    /// Swarm iterations completed.
    pub iterations: usize,
    /// Cost evaluations made.
    pub evaluations: usize,
    /// The best path's cost terms.
    pub cost: CostTerms,
    /// Best total cost after each iteration (iteration 0 = initial swarm).
    pub convergence: Vec<f64>,
    /// The intermediate waypoints of eq. 9, enabled or not.
    pub iwps: Vec<Iwp>,
    /// The free waypoints the swarm chose, decoded (eq. 1).
    pub waypoints: Vec<Point3<f64>>,
    /// P_F*: start, waypoints and IWP via-points, goal.
    pub centroid_path: Vec<Point3<f64>>,
    /// Metres.
    pub path_length: f64,
    /// Seconds at the formation's ground speed.
    pub duration: f64,
    pub reconfigurations: Vec<Reconfiguration>,
    pub trajectories: Vec<Trajectory>,
    pub verification: Verification,
}

impl ThetaPsoOutcome {
    pub fn feasible(&self) -> bool {
        self.verification.feasible
    }
}

/// The dimensions and cost of the swarm search for one mission.
#[derive(Debug, Clone)]
pub struct Problem {
    pub iwps: Vec<Iwp>,
    pub builder: PathBuilder,
    pub cost: CostModel,
    pub space: SearchSpace,
}

impl Problem {
    pub fn new(mission: &Mission) -> Self {
        let iwps = find_iwps(mission);
        let builder = PathBuilder::new(mission, &iwps);
        let cost = CostModel::new(mission, &iwps);
        // θ and Δθ both live in [-π/2, π/2] (Fig. 3, line 10).
        let space = SearchSpace::uniform(
            3 * mission.theta_pso.waypoints,
            -FRAC_PI_2,
            FRAC_PI_2,
            FRAC_PI_2,
        );
        Problem {
            iwps,
            builder,
            cost,
            space,
        }
    }

    /// The centroid path a particle stands for.
    pub fn path(&self, angles: &[f64]) -> CentroidPath {
        self.builder.build(&self.builder.decode(angles))
    }

    /// J and its terms for a particle.
    pub fn evaluate(&self, angles: &[f64]) -> CostTerms {
        self.cost.terms(&self.path(angles))
    }
}

/// Plans `mission` with `seed`. Reports to `observer`, stops early (keeping
/// the best so far) when `cancel` is set. Fails only on an invalid mission;
/// an unreachable goal is an infeasible outcome, not an error.
pub fn plan(
    mission: &Mission,
    seed: u64,
    options: PlanOptions,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<ThetaPsoOutcome, PipelineError> {
    crate::pipeline::require_valid(mission)?;

    observer.on_event(Event::Stage("intermediate waypoints"));
    let problem = Problem::new(mission);
    for iwp in &problem.iwps {
        let state = if iwp.enabled { "enabled" } else { "disabled" };
        let message = format!(
            "IWP between '{}' and '{}': gap {:.2} m, {} ({state})",
            iwp.between[0],
            iwp.between[1],
            iwp.gap,
            iwp.shape.name()
        );
        observer.on_event(Event::Log(Level::Info, &message));
    }

    observer.on_event(Event::Stage("planning"));
    let p = &mission.theta_pso;
    let config = SwarmConfig {
        particles: p.swarm_size,
        iterations: p.iterations,
        inertia: p.inertia,
        cognitive: p.cognitive,
        social: p.social,
        parallel: options.parallel,
    };
    let mut convergence = Vec::with_capacity(p.iterations + 1);
    let mut shown: Option<(CentroidPath, CostTerms)> = None;
    let result = swarm::minimize(
        &problem.space,
        &config,
        seed,
        |angles| problem.evaluate(angles).total,
        |report| {
            convergence.push(report.best.cost);
            // The best only changes on improvement; rebuild its path only then.
            if report.improved || shown.is_none() {
                let path = problem.path(&report.best.position);
                let cost = problem.cost.terms(&path);
                shown = Some((path, cost));
            }
            if let Some((path, cost)) = &shown {
                observer.on_event(Event::PathIteration {
                    iteration: report.iteration,
                    cost,
                    path: &path.points,
                });
            }
            observer.on_event(Event::Progress(
                0.95 * report.iteration as f64 / p.iterations.max(1) as f64,
            ));
            if cancel.is_cancelled() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    let completion = if result.stopped {
        observer.on_event(Event::Log(
            Level::Warn,
            &format!(
                "cancelled after {} iterations; keeping the best so far",
                result.iterations
            ),
        ));
        Completion::Cancelled
    } else {
        Completion::Finished
    };

    observer.on_event(Event::Stage("trajectories"));
    let waypoints = problem.builder.decode(&result.best.position);
    let path = problem.builder.build(&waypoints);
    let cost = problem.cost.terms(&path);
    let (trajectories, reconfigurations) =
        trajectory::generate(&path, &problem.iwps, &mission.formation);

    observer.on_event(Event::Stage("verification"));
    let verification = verify::verify(mission, &trajectories);
    for check in verification.checks.iter().filter(|c| !c.ok) {
        let message = format!(
            "constraint broken: {} {} {} (worst {:.3})",
            check.name,
            check.relation,
            check.limit,
            check.worst.unwrap_or(f64::NAN)
        );
        observer.on_event(Event::Log(Level::Warn, &message));
    }
    observer.on_event(Event::Progress(1.0));

    Ok(ThetaPsoOutcome {
        pipeline: "theta-pso",
        mission: mission.name.clone(),
        seed,
        completion,
        iterations: result.iterations,
        evaluations: result.evaluations,
        cost,
        convergence,
        iwps: problem.iwps,
        waypoints,
        path_length: cost.length,
        duration: cost.length / mission.formation.ground_speed,
        centroid_path: path.points,
        reconfigurations,
        trajectories,
        verification,
    })
}
