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
use crate::pipelines::{CancelToken, Completion, Event, Level, Observer};
use crate::run::{Distribution, Recorder, Run};

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
    /// The swarm's best after an iteration; the path only when it changed.
    Iteration {
        id: JobId,
        cost: f64,
        path: Option<Vec<Point3<f64>>>,
    },
    Log(JobId, Level, String),
    /// A distributed fleet's agents still flying, of how many.
    Agents {
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
    pub distributed: Option<Distribution>,
    /// Its agents still flying, of how many (once the processes are ready).
    pub agents: Option<(usize, usize)>,
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
            JobMsg::Agents { alive, total, .. } => self.agents = Some((alive, total)),
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
            | JobMsg::Done(id, _) => *id,
            JobMsg::Iteration { id, .. }
            | JobMsg::Recorded { id, .. }
            | JobMsg::Agents { id, .. } => *id,
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
            Event::PathIteration { cost, path, .. } => {
                let changed = self.last_cost != Some(cost.total);
                self.last_cost = Some(cost.total);
                JobMsg::Iteration {
                    id: self.id,
                    cost: cost.total,
                    path: changed.then(|| path.to_vec()),
                }
            }
            Event::Log(level, text) => JobMsg::Log(self.id, level, text.to_owned()),
            Event::Agents { alive, total } => JobMsg::Agents {
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
/// where `run.distributed` says).
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
    let recorder = start_recording(id, run.kind, mission, record, tx);
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
            Kind::ThetaPso,
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
