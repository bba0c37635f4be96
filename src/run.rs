//! One run, the same for every front end: the CLI's `run`, `export` and
//! `sweep` and the designer's jobs all carry out a [`Run`] here. It logs the
//! mission to the recorder (if any), hands the pipeline's events to the
//! caller's observer and the recorder, plans through `outcome::run_request`, logs
//! the outcome and finishes the recording; what the caller does with the
//! [`Ran`] (print, export, count, show) is its own.

use crate::mission::Mission;
use crate::outcome::{self, Outcome};
use crate::pipelines::{
    CancelToken, Kind, Observer, PipelineError, PlanOptions, Processes, Request, Tee,
};

#[cfg(feature = "rerun")]
pub use crate::record::{Finished, Recorder};

/// What to run: a seed, how the run may use the machine, and the
/// pipeline's own request (which pipeline, and what only it reads: θ-PSO's
/// warm start, the fleet's agent processes).
#[derive(Debug, Clone)]
pub struct Run {
    pub seed: u64,
    pub options: PlanOptions,
    pub request: Request,
    /// What was found of the mission's revision already (the designer's),
    /// for the run to read instead of finding it again.
    pub revision: Option<std::sync::Arc<crate::pipelines::Revision>>,
}

/// What a run left: the outcome (or why there is none) and the recording.
#[derive(Debug)]
pub struct Ran {
    pub result: Result<Outcome, PipelineError>,
    /// The recording, finished: its `.rrd` is complete.
    pub recorded: Option<Finished>,
}

impl Run {
    /// A plain run of `kind`: nothing asked beyond the mission and the seed.
    pub fn new(kind: Kind, seed: u64) -> Self {
        Run::asking(kind.request(), seed)
    }

    /// A run of the pipeline `request` is for, asking it that.
    pub fn asking(request: impl Into<Request>, seed: u64) -> Self {
        Run {
            seed,
            options: PlanOptions::default(),
            request: request.into(),
            revision: None,
        }
    }

    /// The pipeline it runs.
    pub fn kind(&self) -> Kind {
        self.request.kind()
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
        if let Some(processes) = self.request.processes() {
            return distributed(mission, self.seed, processes, observer, cancel);
        }
        outcome::run_request(
            &self.request,
            mission,
            self.seed,
            self.options,
            self.revision.as_deref(),
            observer,
            cancel,
        )
    }
}

/// A run whose vehicles fly as agent processes (the coordinator in this
/// process; the fleet's, the one pipeline that does).
#[cfg(feature = "zenoh")]
fn distributed(
    mission: &Mission,
    seed: u64,
    processes: Processes,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<Outcome, PipelineError> {
    let mut options = crate::distributed::Options::new(processes.count);
    options.realtime = processes.realtime;
    crate::distributed::coordinate(mission, seed, &options, observer, cancel).map(Outcome::from)
}

/// A build without Zenoh flies every fleet in process.
#[cfg(not(feature = "zenoh"))]
fn distributed(
    _: &Mission,
    _: u64,
    _: Processes,
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
