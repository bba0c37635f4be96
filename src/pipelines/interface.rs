//! What every planning pipeline shares: progress reporting and cancellation.
//!
//! A pipeline is a plain function of a validated mission and a seed. It tells
//! an [`Observer`] what it is doing and checks a [`CancelToken`] between
//! iterations. It never touches a terminal, a file or Rerun: the CLI, the TUI,
//! the recorder, the tests and the benchmarks are all observers.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::Point3;
use serde::Serialize;

/// One timed sample of a vehicle's track, planned or flown: seconds,
/// metres ENU, m/s. θ-PSO's trajectories are made of them, and every
/// pipeline's tracks (`outcome::tracks`) and the exports read them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrackSample {
    pub t: f64,
    pub position: Point3<f64>,
    pub velocity: nalgebra::Vector3<f64>,
}

/// The thresholds a verification holds tracks to, whichever pipeline flew
/// them: θ-PSO's are `Limits::theta_pso` (`pipelines::verify`); the exports
/// re-verify FLATLO and fleet plans with their own pipeline's thresholds
/// through the same checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Least clearance to every obstacle's surface, metres (θ-PSO: r_Q).
    pub clearance: f64,
    /// Least distance between two vehicles at the same instant, metres (eq. 7: 2 r_Q).
    pub closest: f64,
    /// Largest distance between two vehicles, metres (eq. 7: d_com); `None`: no such limit.
    pub farthest: Option<f64>,
    /// Check eq. 8 over each inspected obstacle's pass.
    pub inspections: bool,
    /// Hold every vehicle's speeds and accelerations, sample to sample, to
    /// the mission's `[vehicle]` limits (θ-PSO's timed trajectories; not
    /// an export's straight legs, whose autopilot shapes its own).
    pub dynamics: bool,
}

/// Severity of a log event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    Info,
    Warn,
}

/// Something a pipeline reports while it runs.
#[derive(Debug, Clone, Copy)]
pub enum Event<'a> {
    /// A new stage started ("planning", "trajectories", "verification", ...).
    Stage(&'a str),
    /// Overall progress in [0, 1].
    Progress(f64),
    /// A search's best after an iteration: its cost, the cost's named
    /// terms (the total first: what a recording plots on the `iteration`
    /// timeline) and its path (θ-PSO's best centroid path).
    Iteration {
        iteration: usize,
        cost: f64,
        terms: &'a [(&'static str, f64)],
        path: &'a [Point3<f64>],
    },
    /// A message for the log.
    Log(Level, &'a str),
    /// Vehicles flown by processes of their own (a distributed fleet's
    /// agents): how many still answer, of how many.
    Vehicles { alive: usize, total: usize },
}

/// Receives a pipeline's events on the pipeline's thread. Keep it cheap: it
/// runs between iterations of the hot loop.
pub trait Observer {
    fn on_event(&mut self, event: Event<'_>);
}

/// An observer that ignores everything.
#[derive(Debug, Default)]
pub struct Silent;

impl Observer for Silent {
    fn on_event(&mut self, _: Event<'_>) {}
}

impl<F: FnMut(Event<'_>)> Observer for F {
    fn on_event(&mut self, event: Event<'_>) {
        self(event)
    }
}

/// Forwards every event to two observers (progress bar and recorder, say).
pub struct Tee<'a, 'b>(pub &'a mut dyn Observer, pub &'b mut dyn Observer);

impl Observer for Tee<'_, '_> {
    fn on_event(&mut self, event: Event<'_>) {
        self.0.on_event(event);
        self.1.on_event(event);
    }
}

/// A shared flag to ask a running pipeline to stop. Cloning shares the flag.
#[derive(Debug, Clone, Default)]
pub struct CancelToken(Arc<AtomicBool>);

impl CancelToken {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Completion {
    /// Every iteration ran.
    #[default]
    Finished,
    /// Stopped by the cancel token; the outcome holds the best found so far.
    Cancelled,
}

/// Why a pipeline could not produce an outcome at all.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PipelineError {
    #[error("the mission is not valid:\n{0}")]
    InvalidMission(String),
    #[error("{0}")]
    Unsupported(String),
    /// The run would exceed a documented limit (`limits`).
    #[error("the run is too large to start:\n{0}")]
    OverBudget(String),
    /// θ-PSO's route stage found no way from start to goal within its model;
    /// the text names what closes it.
    #[error("{0}")]
    NoRoute(NoPlan),
    /// The transport between a distributed fleet's processes failed (a
    /// process that never answered, a mission that differs): in words,
    /// naming the step and the agents.
    #[error("distributed run: {0}")]
    Transport(String),
}

/// Every pipeline's first step: a mission with errors is refused, naming
/// them; then a run whose predicted size (`budget`, read only of a valid
/// mission) is over its documented limit.
pub fn require_admissible(
    mission: &crate::mission::Mission,
    budget: fn(&crate::mission::Mission) -> Vec<crate::mission::Diagnostic>,
) -> Result<(), PipelineError> {
    refuse_errors(
        &crate::mission::validate(mission),
        PipelineError::InvalidMission,
    )?;
    refuse_errors(&budget(mission), PipelineError::OverBudget)
}

/// The errors among `findings`, one per line, as the refusal `error` makes.
pub(crate) fn refuse_errors(
    findings: &[crate::mission::Diagnostic],
    error: fn(String) -> PipelineError,
) -> Result<(), PipelineError> {
    let errors: Vec<String> = findings
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.to_string())
        .collect();
    if errors.is_empty() {
        Ok(())
    } else {
        Err(error(errors.join("\n")))
    }
}

/// The documented limits on what one run may cost (README, "Limits").
///
/// Every pipeline predicts its work and memory from the mission alone
/// (`theta_pso::budget`, `flatlo::budget`, `fleet::budget`) and refuses a
/// mission over these figures before it starts. They sit far above every
/// realistic mission (the shipped ones use under 1 % of each) and keep the
/// largest allowed run within a few minutes and a few GiB on a 2-core,
/// 24 GiB machine: an allocation failure or an OOM kill cannot be caught,
/// so the only safe large run is one never started.
pub mod limits {
    /// θ-PSO particles (memory: particles × dimensions × 4 vectors).
    pub const THETA_PSO_PARTICLES: usize = 100_000;
    /// θ-PSO free waypoints (decision dimensions grow with them).
    pub const THETA_PSO_WAYPOINTS: usize = 1_000;
    /// θ-PSO path segments L (each cost evaluation walks them).
    pub const THETA_PSO_SEGMENTS: usize = 100_000;
    /// θ-PSO cost evaluations: particles × iterations × (1 + restarts)
    /// (about 10 µs each on one core: 2e7 is a few minutes on two).
    pub const THETA_PSO_EVALUATIONS: f64 = 2e7;
    /// θ-PSO broad-phase obstacle checks: cost evaluations × legs of a
    /// path (free waypoints + 1) × obstacles (a few nanoseconds each: 1e10
    /// is a few minutes on two cores, as the evaluations' limit).
    pub const THETA_PSO_OBSTACLE_CHECKS: f64 = 1e10;
    /// Trajectory samples kept for every UAV together (duration / 0.1 s × UAVs).
    pub const TRAJECTORY_SAMPLES: f64 = 1e7;
    /// FLATLO aircraft.
    pub const FLATLO_AIRCRAFT: usize = 4_096;
    /// FLATLO integration steps: aircraft × simulated duration / sim_step
    /// (about 7e6 per second on this machine's two cores).
    pub const FLATLO_STEPS: f64 = 1e9;
    /// FLATLO sample instants scanned by verification: aircraft × duration /
    /// sample_period.
    pub const FLATLO_SAMPLES: f64 = 1e9;
    /// Fleet agents.
    pub const FLEET_AGENTS: usize = 256;
    /// Fleet cost evaluations: agents × re-plans × particles × iterations.
    pub const FLEET_EVALUATIONS: f64 = 2e8;
    /// Fleet dynamics steps: agents × duration / sim_step.
    pub const FLEET_STEPS: f64 = 1e9;
    /// Fleet samples kept: agents × duration × 20 Hz.
    pub const FLEET_SAMPLES: f64 = 1e7;
}

/// A figure for budget messages: `1.2e8` beyond 10⁵, `1e-6` below 10⁻⁴,
/// plain between.
pub fn figure(x: f64) -> String {
    if !x.is_finite() {
        "∞".to_owned()
    } else if x.abs() >= 1e5 {
        format!("{x:.1e}").replace(".0e", "e")
    } else if x != 0.0 && x.abs() < 1e-4 {
        format!("{x:e}")
    } else if x == x.trunc() {
        format!("{x:.0}")
    } else {
        format!("{}", (x * 1e3).round() / 1e3)
    }
}

/// A predicted figure over its limit; NaN or infinite figures are over.
pub fn exceeds(figure: f64, limit: f64) -> bool {
    !figure.is_finite() || figure > limit
}

/// The field a budget over its limit names: its largest factor, which is
/// the one the user most likely mistyped (the first of equals).
pub fn largest_factor<'a>(factors: &[(&'a str, f64)]) -> &'a str {
    let mut best: Option<(&str, f64)> = None;
    for &(field, value) in factors {
        if best.is_none_or(|(_, b)| value > b) {
            best = Some((field, value));
        }
    }
    best.map_or("", |(field, _)| field)
}

/// The sizes over the live limits among `checks` (each a figure, its limit
/// and what it is, `#` standing for the figure), in words:
/// "221 obstacles (live up to 200)".
pub fn live_limits(checks: &[(f64, f64, &str)]) -> Vec<String> {
    checks
        .iter()
        .filter(|(value, limit, _)| exceeds(*value, *limit))
        .map(|&(value, limit, what)| {
            format!(
                "{} (live up to {})",
                what.replace('#', &figure(value)),
                figure(limit)
            )
        })
        .collect()
}

/// Why no plan exists, as a run says it (`NO PLAN: …`) and writes it
/// (`--json`): the reason in words, and the obstacles that close the way
/// (or the gate that cannot be kept), by name.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NoPlan {
    pub reason: String,
    pub obstacles: Vec<String>,
    /// The passages that close the way, widest first (empty when the
    /// refusal is not about a passage).
    pub passages: Vec<Passage>,
    /// The route that was tried: from the start as far as the formation
    /// reached, to its point nearest the goal, where it turns (ENU metres;
    /// empty when the refusal is not the route search's).
    pub route: Vec<[f64; 2]>,
}

/// A passage between two obstacles too narrow for the formation, as a
/// refusal names it and `--json` writes it (so scripts and the designer
/// can draw it): the two obstacles, the gap's width, the width the
/// narrowest shape needs there, and the gap's two ends (ENU metres).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Passage {
    pub between: [String; 2],
    pub width: f64,
    pub needs: f64,
    pub ends: [[f64; 2]; 2],
}

impl std::fmt::Display for NoPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.reason)
    }
}
