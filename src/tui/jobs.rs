//! Pipelines running in the background while the UI stays live.
//!
//! A job is a worker thread that runs a pipeline on a snapshot of the mission
//! and reports through a channel; the UI thread owns the [`Job`] records and
//! updates them from those messages ([`Job::apply`]). A panic in the pipeline
//! is caught and reported as a failed job. Cancelling sets the job's
//! [`CancelToken`]; the pipeline returns its best so far.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::thread;
use std::time::{Duration, Instant};

use crossbeam_channel::Sender;
use nalgebra::Point3;

use crate::mission::Mission;
pub use crate::outcome::Outcome;
pub use crate::pipelines::Kind;
use crate::pipelines::Processes;
use crate::pipelines::{CancelToken, Completion, Event, Level, Observer};
use crate::run::{Recorder, Run};

pub type JobId = usize;

/// Where a job's Rerun recording goes.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RecordSettings {
    /// Save an `.rrd` here.
    pub rrd: Option<PathBuf>,
    pub viewer: Viewer,
}

/// Streaming to a Rerun viewer.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Viewer {
    #[default]
    Off,
    /// A viewer already running at the default URL.
    Connect,
    /// Start `rerun` and stream to it.
    Spawn,
}

impl Viewer {
    pub fn next(self) -> Viewer {
        match self {
            Viewer::Off => Viewer::Connect,
            Viewer::Connect => Viewer::Spawn,
            Viewer::Spawn => Viewer::Off,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Viewer::Off => "off",
            Viewer::Connect => "connect",
            Viewer::Spawn => "spawn",
        }
    }
}

/// What a worker tells the UI.
#[derive(Debug)]
pub enum JobMsg {
    Stage(JobId, String),
    Progress(JobId, f64),
    /// A search's best cost after an iteration; its path only when it changed.
    Iteration {
        id: JobId,
        cost: f64,
        path: Option<Vec<Point3<f64>>>,
    },
    Log(JobId, Level, String),
    /// Vehicles flown by processes of their own still answering, of how many.
    Vehicles {
        id: JobId,
        alive: usize,
        total: usize,
    },
    /// The run's recording was written.
    Recorded {
        id: JobId,
        path: PathBuf,
        bytes: u64,
    },
    /// The run ended with an outcome, or an error (or a caught panic).
    Done(JobId, Result<Outcome, JobError>),
    /// The flight check of the job's plan moved on, or ended.
    Flight(JobId, FlightUpdate),
}

/// A flight check's news (`G`).
#[derive(Debug)]
pub enum FlightUpdate {
    /// Flights flown, of how many.
    Progress(usize, usize),
    Done(Result<Box<FlightResult>, String>),
}

/// A job's flight check as the designer shows it.
#[derive(Debug, Clone, PartialEq)]
pub enum FlightCheck {
    Running { done: usize, total: usize },
    Done(Box<FlightResult>),
    Failed(String),
}

/// What the designer keeps of a flight check: the verdict in words, the
/// worst place, and each UAV's p99 envelope along its plan.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightResult {
    /// "4.5 % break 2 r_Q, 99.0 % break r_Q (of 1000 flights)".
    pub verdict: String,
    /// The worst flight in words, and where its UAV was then.
    pub worst: Option<(String, Point3<f64>)>,
    /// Per UAV (0-based): points along its plan as written with the p99
    /// cross-track error there, metres.
    pub envelope: Vec<Vec<(Point3<f64>, f64)>>,
}

/// Why a job produced no outcome.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JobError {
    /// The pipeline refused the mission (invalid, over its budget).
    #[error("{0}")]
    Pipeline(#[from] crate::pipelines::PipelineError),
    /// The pipeline panicked; the designer lives on.
    #[error("the pipeline panicked: {0}")]
    Panicked(String),
    #[error("cannot start a thread: {0}")]
    Thread(String),
}

/// How a job stands.
#[derive(Debug, Clone, PartialEq)]
pub enum JobState {
    Running,
    /// Cancelled; an outcome (the best so far) may still be there.
    Cancelled,
    Failed(JobError),
    /// Finished; the job's outcome holds the verdict.
    Done,
}

/// One launched pipeline, as the UI knows it.
#[derive(Debug)]
pub struct Job {
    pub id: JobId,
    pub pipeline: Kind,
    pub seed: u64,
    /// The mission as it was at launch: the result is stale when the
    /// document no longer equals it.
    pub mission: Mission,
    pub state: JobState,
    pub stage: String,
    pub progress: f64,
    /// Best total cost after each iteration so far.
    pub convergence: Vec<f64>,
    /// The best centroid path so far (while running).
    pub live_path: Vec<Point3<f64>>,
    pub outcome: Option<Outcome>,
    /// The last warning the pipeline logged.
    pub last_warning: Option<String>,
    pub started: Instant,
    pub ended: Option<Instant>,
    pub cancel: CancelToken,
    /// The `.rrd` the run records to, if it does.
    pub rrd: Option<PathBuf>,
    /// The recording written, and its size in bytes.
    pub recorded: Option<(PathBuf, u64)>,
    /// A fleet flown by agent processes (`None`: in this process).
    pub distributed: Option<Processes>,
    /// Its agents still flying, of how many (once the processes are ready).
    pub agents: Option<(usize, usize)>,
    /// Its plan's flight check (`G`), when one was asked for.
    pub flight: Option<FlightCheck>,
}

impl Job {
    pub fn new(id: JobId, pipeline: Kind, seed: u64, mission: Mission, started: Instant) -> Self {
        Job {
            id,
            pipeline,
            seed,
            mission,
            state: JobState::Running,
            stage: "starting".into(),
            progress: 0.0,
            convergence: Vec::new(),
            live_path: Vec::new(),
            outcome: None,
            last_warning: None,
            started,
            ended: None,
            cancel: CancelToken::new(),
            rrd: None,
            recorded: None,
            distributed: None,
            agents: None,
            flight: None,
        }
    }

    pub fn is_running(&self) -> bool {
        self.state == JobState::Running
    }

    pub fn elapsed(&self, now: Instant) -> Duration {
        self.ended
            .unwrap_or(now)
            .saturating_duration_since(self.started)
    }

    /// θ-PSO's best J (FLATLO has no cost).
    pub fn best_cost(&self) -> Option<f64> {
        self.outcome
            .as_ref()
            .and_then(Outcome::best_cost)
            .or(self.convergence.last().copied())
    }

    /// Updates the record from a worker's message (`now` stamps the end).
    pub fn apply(&mut self, msg: JobMsg, now: Instant) {
        match msg {
            JobMsg::Stage(_, stage) => self.stage = stage,
            JobMsg::Progress(_, p) => self.progress = p.clamp(0.0, 1.0),
            JobMsg::Iteration { cost, path, .. } => {
                self.convergence.push(cost);
                if let Some(path) = path {
                    self.live_path = path;
                }
            }
            JobMsg::Log(_, Level::Warn, text) => self.last_warning = Some(text),
            JobMsg::Recorded { path, bytes, .. } => self.recorded = Some((path, bytes)),
            JobMsg::Log(_, Level::Info, _) => {}
            JobMsg::Vehicles { alive, total, .. } => self.agents = Some((alive, total)),
            JobMsg::Flight(_, FlightUpdate::Progress(done, total)) => {
                self.flight = Some(FlightCheck::Running { done, total });
            }
            JobMsg::Flight(_, FlightUpdate::Done(result)) => {
                self.flight = Some(match result {
                    Ok(r) => FlightCheck::Done(r),
                    Err(e) => FlightCheck::Failed(e),
                });
            }
            JobMsg::Done(_, result) => {
                self.ended = Some(now);
                match result {
                    Ok(outcome) => {
                        // A cancelled run keeps the share it got through.
                        if outcome.completion() == Completion::Finished {
                            self.progress = 1.0;
                        }
                        self.state = match outcome.completion() {
                            Completion::Cancelled => JobState::Cancelled,
                            Completion::Finished => JobState::Done,
                        };
                        if !outcome.convergence().is_empty() {
                            self.convergence = outcome.convergence().to_vec();
                        }
                        self.live_path.clear();
                        self.outcome = Some(outcome);
                    }
                    Err(e) => self.state = JobState::Failed(e),
                }
            }
        }
    }
}

impl JobMsg {
    pub fn job(&self) -> JobId {
        match self {
            JobMsg::Stage(id, _)
            | JobMsg::Progress(id, _)
            | JobMsg::Log(id, _, _)
            | JobMsg::Done(id, _)
            | JobMsg::Flight(id, _) => *id,
            JobMsg::Iteration { id, .. }
            | JobMsg::Recorded { id, .. }
            | JobMsg::Vehicles { id, .. } => *id,
        }
    }
}

/// Forwards pipeline events to the UI, sending the path only when it changed.
struct Forward {
    id: JobId,
    tx: Sender<JobMsg>,
    last_cost: Option<f64>,
}

impl Observer for Forward {
    fn on_event(&mut self, event: Event<'_>) {
        let msg = match event {
            Event::Stage(s) => JobMsg::Stage(self.id, s.to_owned()),
            Event::Progress(p) => JobMsg::Progress(self.id, p),
            Event::Iteration { cost, path, .. } => {
                let changed = self.last_cost != Some(cost);
                self.last_cost = Some(cost);
                JobMsg::Iteration {
                    id: self.id,
                    cost,
                    path: changed.then(|| path.to_vec()),
                }
            }
            Event::Log(level, text) => JobMsg::Log(self.id, level, text.to_owned()),
            Event::Vehicles { alive, total } => JobMsg::Vehicles {
                id: self.id,
                alive,
                total,
            },
        };
        // The UI may be gone (quitting): nothing left to tell.
        let _ = self.tx.send(msg);
    }
}

/// Starts a run on `mission` on a worker thread (a fleet's agents flown
/// where its request's `processes` say).
pub fn spawn_pipeline(
    id: JobId,
    run: Run,
    mission: Mission,
    cancel: CancelToken,
    record: RecordSettings,
    tx: Sender<JobMsg>,
) {
    spawn(id, tx, move |tx| {
        carry_out(id, run, &mission, &cancel, &record, tx)
    });
}

/// Runs `work` on a worker thread and always ends with one `Done` message:
/// its result, or its panic as an error.
pub fn spawn<F>(id: JobId, tx: Sender<JobMsg>, work: F)
where
    F: FnOnce(&Sender<JobMsg>) -> Result<Outcome, JobError> + Send + 'static,
{
    let worker_tx = tx.clone();
    let spawned = thread::Builder::new()
        .name(format!("skyform-job-{id}"))
        .spawn(move || {
            let run = catch_unwind(AssertUnwindSafe(|| work(&worker_tx)));
            let result = run.unwrap_or_else(|panic| Err(panic_message(&*panic)));
            let _ = worker_tx.send(JobMsg::Done(id, result));
        });
    if let Err(e) = spawned {
        let _ = tx.send(JobMsg::Done(id, Err(JobError::Thread(e.to_string()))));
    }
}

/// The run itself, on the worker thread: the one run path (`run::Run`),
/// with the recorder the settings ask for.
fn carry_out(
    id: JobId,
    run: Run,
    mission: &Mission,
    cancel: &CancelToken,
    record: &RecordSettings,
    tx: &Sender<JobMsg>,
) -> Result<Outcome, JobError> {
    let mut forward = Forward {
        id,
        tx: tx.clone(),
        last_cost: None,
    };
    let recorder = start_recording(id, run.kind(), mission, record, tx);
    let ran = run.carry_out(mission, recorder, &mut forward, cancel);
    let outcome = ran.result?;
    #[cfg(feature = "rerun")]
    if let Some(finished) = ran.recorded {
        if let Some((path, bytes)) = finished.file {
            let _ = tx.send(JobMsg::Recorded { id, path, bytes });
        }
        if let Some(e) = finished.error {
            let _ = tx.send(JobMsg::Log(id, Level::Warn, format!("not recorded: {e}")));
        }
    }
    Ok(outcome)
}

/// Opens the recording sinks; every failure is a warning of the job, never fatal.
#[cfg(feature = "rerun")]
fn start_recording(
    id: JobId,
    pipeline: Kind,
    mission: &Mission,
    record: &RecordSettings,
    tx: &Sender<JobMsg>,
) -> Option<Recorder> {
    use crate::record::{DEFAULT_VIEWER_URL, Sinks};
    let sinks = Sinks {
        rrd: record.rrd.clone(),
        connect: (record.viewer == Viewer::Connect).then(|| DEFAULT_VIEWER_URL.to_owned()),
        spawn: record.viewer == Viewer::Spawn,
    };
    if sinks.is_empty() {
        return None;
    }
    let mut warnings = Vec::new();
    let started = Recorder::start(&mission.name, Some(pipeline), &sinks, &mut warnings);
    for w in warnings {
        let _ = tx.send(JobMsg::Log(id, Level::Warn, w));
    }
    started.unwrap_or_else(|e| {
        let _ = tx.send(JobMsg::Log(id, Level::Warn, format!("not recorded: {e}")));
        None
    })
}

/// A build without Rerun records nothing, and says so when asked to.
#[cfg(not(feature = "rerun"))]
fn start_recording(
    id: JobId,
    _: Kind,
    _: &Mission,
    record: &RecordSettings,
    tx: &Sender<JobMsg>,
) -> Option<Recorder> {
    if record.rrd.is_some() || record.viewer != Viewer::Off {
        let text = "this build has no Rerun support (feature `rerun`)".to_owned();
        let _ = tx.send(JobMsg::Log(id, Level::Warn, text));
    }
    None
}

/// Flies the plan of `outcome` in `mission`'s `[flight]` air on a worker
/// thread: progress every 5 % of the flights, then the verdict, the worst
/// place and the p99 envelope (`flight::check_recorded`). A
/// panic is reported as a failed check.
pub fn spawn_flight_check(
    id: JobId,
    mission: Mission,
    outcome: Outcome,
    cancel: CancelToken,
    tx: Sender<JobMsg>,
) {
    let worker_tx = tx.clone();
    let spawned = thread::Builder::new()
        .name(format!("skyform-flight-{id}"))
        .spawn(move || {
            let work = || flight_check(id, &mission, &outcome, &cancel, &worker_tx);
            let result = catch_unwind(AssertUnwindSafe(work))
                .unwrap_or_else(|panic| Err(panic_message(&*panic).to_string()));
            let _ = worker_tx.send(JobMsg::Flight(id, FlightUpdate::Done(result)));
        });
    if let Err(e) = spawned {
        let _ = tx.send(JobMsg::Flight(id, FlightUpdate::Done(Err(e.to_string()))));
    }
}

fn flight_check(
    id: JobId,
    mission: &Mission,
    outcome: &Outcome,
    cancel: &CancelToken,
    tx: &Sender<JobMsg>,
) -> Result<Box<FlightResult>, String> {
    use crate::flight::{self, Options, Setup};
    let planned = crate::export::Planned::from_outcome(mission, outcome);
    let setup = Setup::new(mission, &planned).map_err(|e| e.to_string())?;
    let options = Options {
        flights: mission.flight.flights,
        seed: outcome.seed(),
        threads: None,
    };
    let step = (options.flights / 20).max(1);
    let progress = |done: usize, total: usize| {
        if done.is_multiple_of(step) || done == total {
            let _ = tx.send(JobMsg::Flight(id, FlightUpdate::Progress(done, total)));
        }
    };
    let (report, recording) =
        flight::check_recorded(&setup, options, &progress, cancel).map_err(|e| e.to_string())?;
    let pct = |s: &flight::Share| format!("{:.1} %", 100.0 * s.share);
    let verdict = format!(
        "{} break 2 r_Q, {} break r_Q (of {} flights)",
        pct(&report.break_separation),
        pct(&report.break_clearance),
        report.flights
    );
    let worst = report.worst.as_ref().map(|w| {
        let k = recording
            .times
            .partition_point(|&t| t < w.t)
            .min(recording.times.len().saturating_sub(1));
        let at = recording
            .written
            .iter()
            .find(|(v, _)| *v == w.vehicle)
            .and_then(|(_, p)| p.get(k).copied())
            .unwrap_or_else(Point3::origin);
        (
            format!("flight {}: {} at t = {:.1} s", w.flight, w.what, w.t),
            at,
        )
    });
    let envelope = recording
        .written
        .iter()
        .zip(&recording.envelope)
        .map(|((_, points), radii)| points.iter().copied().zip(radii.iter().copied()).collect())
        .collect();
    Ok(Box::new(FlightResult {
        verdict,
        worst,
        envelope,
    }))
}

fn panic_message(panic: &(dyn std::any::Any + Send)) -> JobError {
    let text = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    JobError::Panicked(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panicking_job_ends_as_a_failed_job() {
        let (tx, rx) = crossbeam_channel::unbounded();
        spawn(4, tx, |_| panic!("boom"));
        let msg = rx.recv_timeout(Duration::from_secs(10)).unwrap();
        let mut job = Job::new(
            4,
            Kind::default(),
            0,
            crate::mission::default_mission().mission,
            Instant::now(),
        );
        job.apply(msg, Instant::now());
        assert_eq!(
            job.state,
            JobState::Failed(JobError::Panicked("boom".into()))
        );
        assert!(job.ended.is_some());
    }

    #[test]
    fn a_panic_payload_becomes_a_readable_error() {
        let caught = catch_unwind(|| panic!("index out of bounds")).unwrap_err();
        assert_eq!(
            panic_message(&*caught).to_string(),
            "the pipeline panicked: index out of bounds"
        );
    }
}
