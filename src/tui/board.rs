//! The job board: the runs of this session (`jobs.rs` runs each on its own
//! thread), the cursor in their list, the one whose result the map shows,
//! and how runs are recorded (an `.rrd` beside the mission, a Rerun viewer).
//!
//! It owns the channel the workers report through; the main loop waits on
//! [`JobBoard::messages`] and hands each message back to [`JobBoard::on_msg`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use crossbeam_channel::{Receiver, Sender, unbounded};

use super::action::Action;
use super::document::Document;
use super::jobs::{self, Job, JobId, JobMsg, Kind, RecordSettings, Viewer};
use super::live::Live;
use super::status::StatusLine;
use crate::pipelines::Level;

/// Agent processes a distributed fleet job starts at most (the designer
/// shares the machine with them).
const DESIGNER_PROCESSES: usize = 3;

pub struct JobBoard {
    jobs: Vec<Job>,
    /// The selected row of the jobs panel.
    cursor: usize,
    /// The job whose result the map shows.
    shown: Option<JobId>,
    /// Record runs to an `.rrd` beside the mission.
    record_rrd: bool,
    viewer: Viewer,
    /// Live planning: the plan follows the edit.
    live: Live,
    /// With a viewer on, the live plans' recording: one for the session,
    /// each plan a `revision`.
    #[cfg(feature = "rerun")]
    live_recording: Option<crate::record::Recorder>,
    tx: Sender<JobMsg>,
    rx: Receiver<JobMsg>,
}

impl Default for JobBoard {
    fn default() -> Self {
        let (tx, rx) = unbounded();
        JobBoard {
            jobs: Vec::new(),
            cursor: 0,
            shown: None,
            record_rrd: false,
            viewer: Viewer::Off,
            live: Live::default(),
            #[cfg(feature = "rerun")]
            live_recording: None,
            tx,
            rx,
        }
    }
}

impl JobBoard {
    pub fn jobs(&self) -> &[Job] {
        &self.jobs
    }

    /// The selected row: an index into [`JobBoard::jobs`].
    pub fn cursor(&self) -> usize {
        self.cursor
    }

    /// The id of the job whose result the map shows.
    pub fn shown_id(&self) -> Option<JobId> {
        self.shown
    }

    /// The job whose result is on the map (a listed run or the newest live one).
    pub fn shown(&self) -> Option<&Job> {
        let id = self.shown?;
        if Live::owns(id) {
            return self.live.latest().filter(|j| j.id == id);
        }
        self.jobs.iter().find(|j| j.id == id)
    }

    /// Live planning.
    pub fn live(&self) -> &Live {
        &self.live
    }

    /// Turns live planning on for the pipeline shown when it can plan live
    /// (`Words::live`), otherwise for the default one (θ-PSO), or off.
    pub fn toggle_live(&mut self, now: Instant, status: &mut StatusLine) {
        if self.live.is_on() {
            self.live.stop();
            status.say("live planning off: press r to plan");
            return;
        }
        let pipeline = self
            .shown()
            .map(|j| j.pipeline)
            .filter(|k| k.words().live)
            .unwrap_or_default();
        match self.live.start(pipeline, now) {
            Ok(()) => status.say(format!(
                "live planning on: {} re-plans after every edit (L turns it off)",
                pipeline.words().name
            )),
            Err(e) => status.error(e),
        }
    }

    /// Leaves live planning off for `why` (the designer's start).
    pub fn hold_live_off(&mut self, why: String) {
        self.live.hold_off(why);
    }

    /// Turns live planning on for `pipeline` (the designer's start).
    pub fn start_live(&mut self, pipeline: Kind, now: Instant) -> Result<(), String> {
        self.live.start(pipeline, now)
    }

    /// The document may have changed: live planning follows it.
    pub fn follow(&mut self, doc: &Document, now: Instant) {
        self.live.follow(doc, now);
    }

    /// With a viewer on, the newest live plan goes to the session's live
    /// recording (started at the first), as the next revision.
    #[cfg(feature = "rerun")]
    fn record_live(&mut self, status: &mut StatusLine) {
        use crate::record::{DEFAULT_VIEWER_URL, Recorder, Sinks};
        if self.viewer == Viewer::Off {
            if let Some(r) = self.live_recording.take() {
                r.finish();
            }
            return;
        }
        let Some(job) = self.live.latest() else {
            return;
        };
        if self.live_recording.is_none() {
            let sinks = Sinks {
                rrd: None,
                connect: (self.viewer == Viewer::Connect).then(|| DEFAULT_VIEWER_URL.to_owned()),
                spawn: self.viewer == Viewer::Spawn,
            };
            let mut warnings = Vec::new();
            let name = format!("{} (live)", job.mission.name);
            match Recorder::start(&name, Some(job.pipeline), &sinks, &mut warnings) {
                Ok(Some(mut r)) => {
                    r.log_mission(&job.mission);
                    self.live_recording = Some(r);
                }
                Ok(None) => {}
                Err(e) => status.error(format!("live recording: {e}")),
            }
            if let Some(w) = warnings.first() {
                status.error(format!("warning: {w}"));
            }
        }
        if let (Some(r), Some(o)) = (self.live_recording.as_mut(), job.outcome.as_ref()) {
            r.log_live(self.live.revision(), o);
        }
    }

    #[cfg(not(feature = "rerun"))]
    fn record_live(&mut self, _: &mut StatusLine) {}

    /// Starts the live run due by `now`, if one is.
    pub fn poll_live(&mut self, doc: &Document, now: Instant) {
        let warm_from = self
            .shown
            .filter(|id| !Live::owns(*id))
            .and_then(|id| self.jobs.iter().find(|j| j.id == id));
        self.live
            .poll(doc, now, warm_from, RecordSettings::default(), &self.tx);
    }

    pub fn record_rrd(&self) -> bool {
        self.record_rrd
    }

    pub fn viewer(&self) -> Viewer {
        self.viewer
    }

    /// The channel the workers report through.
    pub fn messages(&self) -> &Receiver<JobMsg> {
        &self.rx
    }

    pub fn any_running(&self) -> bool {
        self.jobs
            .iter()
            .any(|j| j.is_running() || matches!(j.flight, Some(jobs::FlightCheck::Running { .. })))
    }

    /// Lists a job that runs elsewhere (a run planned synchronously for a
    /// test or the benchmark), selected as a started run is; its messages
    /// come through [`JobBoard::on_msg`].
    pub fn adopt(&mut self, job: Job) {
        self.jobs.push(job);
        self.cursor = self.jobs.len() - 1;
    }

    /// Shows the selected job's result; false when there is no job.
    pub fn show_selected(&mut self) -> bool {
        match self.jobs.get(self.cursor) {
            Some(job) => {
                self.shown = Some(job.id);
                true
            }
            None => false,
        }
    }

    /// Cancels the running jobs (they return their best at once).
    pub fn cancel_all(&self) {
        for job in self.jobs.iter().filter(|j| j.is_running()) {
            job.cancel.cancel();
        }
    }

    /// Another mission is open: its jobs are not "stale" but gone.
    pub fn clear(&mut self) {
        self.cancel_all();
        self.jobs.clear();
        self.cursor = 0;
        self.shown = None;
    }

    /// Starts, cancels, selects or configures runs for one action (the
    /// others are not the board's). `doc` is what a run plans; `cwd` where
    /// the recording of a mission without a file goes.
    pub fn update(&mut self, action: Action, doc: &Document, cwd: &Path, status: &mut StatusLine) {
        use Action::*;
        let seed = doc.mission().seed;
        match action {
            Run(kind) => self.run(crate::run::Run::new(kind, seed), doc, cwd, status),
            RunDistributed(kind) => {
                // One process a vehicle of the pipeline that flies them.
                let processes = crate::pipelines::Processes {
                    count: kind
                        .face()
                        .vehicles(doc.mission())
                        .clamp(1, DESIGNER_PROCESSES),
                    realtime: false,
                };
                match kind.request().in_processes(processes) {
                    Some(request) => {
                        self.run(crate::run::Run::asking(request, seed), doc, cwd, status);
                    }
                    None => status.error(format!(
                        "{} does not fly as agent processes",
                        kind.words().name
                    )),
                }
            }
            RunNewSeed => {
                let seed = self
                    .jobs
                    .iter()
                    .map(|j| j.seed)
                    .max()
                    .map_or(seed.wrapping_add(1), |s| s.wrapping_add(1));
                let last = self.jobs.last();
                let mut run =
                    crate::run::Run::new(last.map_or_else(Kind::default, |j| j.pipeline), seed);
                // Where the last one flew: in agent processes, again.
                if let Some(request) = last
                    .and_then(|j| j.distributed)
                    .and_then(|p| run.request.clone().in_processes(p))
                {
                    run.request = request;
                }
                self.run(run, doc, cwd, status);
            }
            FlightCheck => self.flight_check(status),
            Cancel => self.cancel(status),
            JobUp => self.cursor = self.cursor.saturating_sub(1),
            JobDown => self.cursor = (self.cursor + 1).min(self.jobs.len().saturating_sub(1)),
            ToggleRecording => {
                self.record_rrd = !self.record_rrd;
                status.say(if self.record_rrd {
                    "runs are recorded to an .rrd beside the mission"
                } else {
                    "runs are not recorded"
                });
            }
            CycleViewer => self.cycle_viewer(status),
            _ => {}
        }
    }

    /// `G`: flies the shown job's plan (θ-PSO or the fleet) in the
    /// mission's `[flight]` air on a worker thread. A live plan on the map
    /// is kept as a job of its own first (the next edit replaces the live
    /// one), and that job is flown.
    fn flight_check(&mut self, status: &mut StatusLine) {
        if let Some(live) = self.shown.filter(|id| Live::owns(*id)) {
            match self
                .live
                .latest()
                .filter(|j| j.id == live && j.outcome.is_some())
            {
                Some(plan) => {
                    let id = self.jobs.last().map_or(1, |j| j.id + 1);
                    let mut kept = Job::new(
                        id,
                        plan.pipeline,
                        plan.seed,
                        plan.mission.clone(),
                        plan.started,
                    );
                    kept.state = plan.state.clone();
                    kept.stage = plan.stage.clone();
                    kept.progress = plan.progress;
                    kept.convergence = plan.convergence.clone();
                    kept.outcome = plan.outcome.clone();
                    kept.ended = plan.ended;
                    self.jobs.push(kept);
                    self.cursor = self.jobs.len() - 1;
                    self.shown = Some(id);
                    status.say(format!("{} kept as job {id}", super::live::label(live)));
                }
                None => {
                    status.error("flight check: the live plan is still coming; G again once it is on the map");
                    return;
                }
            }
        }
        let Some(id) = self.shown.filter(|id| !Live::owns(*id)) else {
            status.error(
                "flight check: no plan on the map: run one first (r), or turn live planning on (L)",
            );
            return;
        };
        let Some(job) = self.jobs.iter_mut().find(|j| j.id == id) else {
            return;
        };
        let Some(outcome) = job.outcome.clone() else {
            status.error(format!("flight check: job {id} has no plan"));
            return;
        };
        if job.pipeline.words().fixed_wing {
            status.error("flight check: FLATLO's aircraft fly on their own model; G flies θ-PSO and fleet plans");
            return;
        }
        if matches!(job.flight, Some(jobs::FlightCheck::Running { .. })) {
            status.say(format!("flight check of job {id} is under way"));
            return;
        }
        let total = job.mission.flight.flights;
        job.flight = Some(jobs::FlightCheck::Running { done: 0, total });
        jobs::spawn_flight_check(
            id,
            job.mission.clone(),
            outcome,
            job.cancel.clone(),
            self.tx.clone(),
        );
        status.say(format!(
            "flight check of job {id}: {total} flights in the mission's [flight] air…"
        ));
    }

    fn cancel(&self, status: &mut StatusLine) {
        let target = self
            .jobs
            .get(self.cursor)
            .filter(|j| j.is_running())
            .or_else(|| self.jobs.iter().rev().find(|j| j.is_running()));
        match target {
            Some(job) => {
                job.cancel.cancel();
                status.say(format!("cancelling job {}…", job.id));
            }
            None => status.say("no job is running"),
        }
    }

    fn cycle_viewer(&mut self, status: &mut StatusLine) {
        self.viewer = self.viewer.next();
        status.say(match self.viewer {
            Viewer::Off => "no Rerun viewer",
            Viewer::Connect => "runs stream to a running Rerun viewer (rerun --port 9876)",
            Viewer::Spawn => "runs start a Rerun viewer (`rerun` on PATH)",
        });
        // Say now when the viewer cannot be reached, not at the run.
        #[cfg(feature = "rerun")]
        if self.viewer != Viewer::Off
            && let Some(problem) = crate::record::viewer_problem(self.viewer == Viewer::Spawn)
        {
            status.error(format!("warning: {problem}"));
        }
    }

    fn run(&mut self, run: crate::run::Run, doc: &Document, cwd: &Path, status: &mut StatusLine) {
        let (pipeline, seed) = (run.kind(), run.seed);
        let errors = doc.error_lines();
        if let Some(first) = errors.first() {
            status.error(format!(
                "cannot run: {} error(s) in the mission; first: {first}",
                errors.len()
            ));
            return;
        }
        let id = self.jobs.last().map_or(1, |j| j.id + 1);
        let mut job = Job::new(id, pipeline, seed, doc.mission().clone(), Instant::now());
        job.distributed = run.request.processes();
        // A new name rather than over an earlier recording (of this session
        // or a file already there).
        let taken: Vec<&Path> = self.jobs.iter().filter_map(|j| j.rrd.as_deref()).collect();
        job.rrd = self
            .record_rrd
            .then(|| rrd_path(doc, cwd, pipeline.words().slug, seed, &taken));
        let record = RecordSettings {
            rrd: job.rrd.clone(),
            viewer: self.viewer,
        };
        let how = run.request.processes().map_or_else(String::new, |d| {
            format!(" in {} agent process(es) over Zenoh", d.count)
        });
        jobs::spawn_pipeline(
            id,
            run,
            job.mission.clone(),
            job.cancel.clone(),
            record,
            self.tx.clone(),
        );
        let recording = job.rrd.as_ref().map_or_else(String::new, |p| {
            let name = p.file_name().unwrap_or(p.as_os_str());
            format!(", recording to {}", name.to_string_lossy())
        });
        self.jobs.push(job);
        self.cursor = self.jobs.len() - 1;
        status.say(format!(
            "job {id}: {}{how} started with seed {seed}{recording} (x cancels)",
            pipeline.words().name
        ));
    }

    /// Applies a worker's message (`now` stamps job ends). True when a run
    /// finished and its result is now the one shown.
    pub fn on_msg(&mut self, msg: JobMsg, now: Instant, status: &mut StatusLine) -> bool {
        let id = msg.job();
        if Live::owns(id) {
            let came_in = self.live.on_msg(msg, now);
            if came_in && let Some(job) = self.live.latest() {
                self.shown = Some(job.id);
                if let jobs::JobState::Failed(e) = &job.state {
                    status.error(format!("live plan failed: {e}"));
                }
            }
            if came_in {
                self.record_live(status);
            }
            return came_in;
        }
        let note = match &msg {
            JobMsg::Log(_, Level::Warn, text) => Some((true, format!("job {id}: {text}"))),
            JobMsg::Recorded { path, bytes, .. } => Some((
                false,
                format!(
                    "job {id}: recorded {} ({:.1} MB)",
                    path.display(),
                    *bytes as f64 / 1e6
                ),
            )),
            JobMsg::Done(_, Err(e)) => Some((true, format!("job {id} failed: {e}"))),
            JobMsg::Flight(_, jobs::FlightUpdate::Done(Ok(r))) => Some((
                false,
                format!(
                    "job {id} flight check: {}{}",
                    r.verdict,
                    r.worst
                        .as_ref()
                        .map_or(String::new(), |(w, _)| format!("; worst {w}"))
                ),
            )),
            JobMsg::Flight(_, jobs::FlightUpdate::Done(Err(e))) => {
                Some((true, format!("job {id} flight check failed: {e}")))
            }
            _ => None,
        };
        let done = matches!(msg, JobMsg::Done(_, Ok(_)));
        // A refusal of the route search is shown too: the map draws the
        // passage that closes the way and the route that was tried.
        let refused = matches!(
            msg,
            JobMsg::Done(
                _,
                Err(jobs::JobError::Pipeline(
                    crate::pipelines::PipelineError::NoRoute(_)
                ))
            )
        );
        let mut shown = false;
        if let Some(job) = self.jobs.iter_mut().find(|j| j.id == id) {
            job.apply(msg, now);
            if refused {
                self.shown = Some(id);
                shown = true;
            }
            if done {
                let verb = if job.state == jobs::JobState::Cancelled {
                    "cancelled"
                } else {
                    "done"
                };
                let mut text = match &job.outcome {
                    Some(o) => format!("job {id} {verb}: {}", o.headline()),
                    None => format!("job {id} {verb}"),
                };
                // The recording is written before the run reports its end:
                // the status names the file.
                if let Some((path, bytes)) = &job.recorded {
                    text.push_str(&format!(
                        " · recorded {} ({:.1} MB)",
                        path.display(),
                        *bytes as f64 / 1e6
                    ));
                }
                self.shown = Some(id);
                shown = true;
                status.say(text);
            }
        }
        if let Some((error, text)) = note {
            status.set(text, error);
        }
        shown
    }
}

/// `<mission stem>-<pipeline>-seed<N>.rrd` beside the mission file (in
/// `cwd` for a mission without one), the stem as [`Document::stem`] gives
/// it; `-2`, `-3`… before `.rrd` when that file exists or is `taken` by a
/// run of this session, so no recording replaces another.
pub fn rrd_path(doc: &Document, cwd: &Path, pipeline: &str, seed: u64, taken: &[&Path]) -> PathBuf {
    let dir = match doc.path() {
        Some(p) => p.parent().map(Path::to_path_buf).unwrap_or_default(),
        None => cwd.to_path_buf(),
    };
    let base = format!("{}-{pipeline}-seed{seed}", doc.stem());
    (1..)
        .map(|k| match k {
            1 => dir.join(format!("{base}.rrd")),
            k => dir.join(format!("{base}-{k}.rrd")),
        })
        .find(|p| !p.exists() && !taken.contains(&p.as_path()))
        .unwrap_or_else(|| dir.join(format!("{base}.rrd")))
}
