//! One run, the same for every front end: the CLI's `run`, `export` and
//! `sweep` and the designer's jobs all carry out a [`Run`] here. It logs the
//! mission to the recorder (if any), hands the pipeline's events to the
//! caller's observer and the recorder, plans through `outcome::run_warm`, logs
//! the outcome and finishes the recording; what the caller does with the
//! [`Ran`] (print, export, count, show) is its own.

use crate::mission::Mission;
use crate::outcome::{self, Outcome};
use crate::pipelines::theta_pso::PlanOptions;
use crate::pipelines::{CancelToken, Kind, Observer, PipelineError, Tee};

#[cfg(feature = "rerun")]
pub use crate::record::{Finished, Recorder};

/// What to run: a pipeline, a seed, θ-PSO's options (and the plan it starts
/// warm from) and where a fleet's agents fly.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    pub kind: Kind,
    pub seed: u64,
    /// Only θ-PSO reads them.
    pub options: PlanOptions,
    /// The fleet's agents in processes of their own, over Zenoh (`None`: in
    /// this process). Only the fleet reads it.
    pub distributed: Option<Distribution>,
    /// θ-PSO: start part of the swarm from this plan (the designer's live
    /// re-plans); `None`, a cold run. Only θ-PSO reads it.
    pub warm: Option<std::sync::Arc<crate::pipelines::theta_pso::WarmStart>>,
}

/// A fleet flown by agent processes on this machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Distribution {
    /// How many agent processes.
    pub processes: usize,
    /// Each on its own wall clock (not reproducible) instead of lockstep.
    pub realtime: bool,
}

/// What a run left: the outcome (or why there is none) and the recording.
#[derive(Debug)]
pub struct Ran {
    pub result: Result<Outcome, PipelineError>,
    /// The recording, finished: its `.rrd` is complete.
    pub recorded: Option<Finished>,
}

impl Run {
    pub fn new(kind: Kind, seed: u64) -> Self {
        Run {
            kind,
            seed,
            options: PlanOptions::default(),
            distributed: None,
            warm: None,
        }
    }

    /// Carries the run out on this thread; `recorder` (started by the
    /// caller, who reports its sinks' warnings) gets the mission, every
    /// event and the outcome, and is finished before this returns.
    pub fn carry_out(
        &self,
        mission: &Mission,
        mut recorder: Option<Recorder>,
        observer: &mut dyn Observer,
        cancel: &CancelToken,
    ) -> Ran {
        let result = match recorder.as_mut() {
            Some(r) => {
                r.log_mission(mission);
                self.plan(mission, &mut Tee(&mut *observer, r), cancel)
            }
            None => self.plan(mission, observer, cancel),
        };
        if let (Some(r), Ok(outcome)) = (recorder.as_mut(), &result) {
            r.log_outcome(outcome);
        }
        // Every clone of the stream is dropped here, so the file is complete
        // (with its footer) before the caller prints anything.
        Ran {
            result,
            recorded: recorder.map(Recorder::finish),
        }
    }

    fn plan(
        &self,
        mission: &Mission,
        observer: &mut dyn Observer,
        cancel: &CancelToken,
    ) -> Result<Outcome, PipelineError> {
        if let (Kind::Fleet, Some(d)) = (self.kind, self.distributed) {
            return distributed(mission, self.seed, d, observer, cancel);
        }
        outcome::run_warm(
            self.kind,
            mission,
            self.seed,
            self.options,
            self.warm.as_deref(),
            observer,
            cancel,
        )
    }
}

/// The fleet over agent processes (the coordinator in this process).
#[cfg(feature = "zenoh")]
fn distributed(
    mission: &Mission,
    seed: u64,
    d: Distribution,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<Outcome, PipelineError> {
    let mut options = crate::distributed::Options::new(d.processes);
    options.realtime = d.realtime;
    crate::distributed::coordinate(mission, seed, &options, observer, cancel)
        .map(|o| Outcome::Fleet(Box::new(o)))
}

/// A build without Zenoh flies every fleet in process.
#[cfg(not(feature = "zenoh"))]
fn distributed(
    _: &Mission,
    _: u64,
    _: Distribution,
    _: &mut dyn Observer,
    _: &CancelToken,
) -> Result<Outcome, PipelineError> {
    Err(PipelineError::Unsupported(
        "this build has no Zenoh (built without the `zenoh` feature): fly the fleet in process"
            .into(),
    ))
}

/// A build without Rerun (`--no-default-features`) records nothing: no
/// recorder can exist, so a run never has one.
#[cfg(not(feature = "rerun"))]
#[derive(Debug)]
pub enum Recorder {}

/// What a recording left, in a build without Rerun: never anything.
#[cfg(not(feature = "rerun"))]
#[derive(Debug)]
pub enum Finished {}

#[cfg(not(feature = "rerun"))]
impl Recorder {
    fn log_mission(&mut self, _: &Mission) {
        match *self {}
    }

    fn log_outcome(&mut self, _: &Outcome) {
        match *self {}
    }

    fn finish(self) -> Finished {
        match self {}
    }
}

#[cfg(not(feature = "rerun"))]
impl Observer for Recorder {
    fn on_event(&mut self, _: crate::pipelines::Event<'_>) {
        match *self {}
    }
}
