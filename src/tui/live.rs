//! Live planning: the plan follows the edit.
//!
//! With live mode on, every change of the mission (typing applied, a nudge,
//! each step of a drag, undo, redo) cancels the live run under way and
//! starts a new one on the edited mission once no further edit came for a
//! short debounce. Live runs do not fill the jobs list: each replaces the
//! last, and the map shows the newest as soon as it is in. A θ-PSO re-plan
//! starts part of its swarm from the last plan (`theta_pso::WarmStart`) and
//! stops once it settles, so a small edit re-plans in a fraction of a cold
//! run. A mission with errors pauses live planning (the first error says
//! why) until it is valid again.
//!
//! Nothing runs and nothing wakes the loop while nothing changes: the loop
//! sleeps until [`Live::due`].

use std::time::{Duration, Instant};

use crossbeam_channel::Sender;

use super::document::Document;
use super::jobs::{self, Job, JobId, JobMsg, JobState, Kind, RecordSettings};
use crate::mission::Mission;
use crate::run::Run;

/// Live runs' ids start here, far above the listed runs'.
pub const FIRST_ID: JobId = 1 << 40;

/// An edit after a quiet moment (a typed value, a nudge) waits this long for
/// the next one before a run starts: not noticeably.
pub const DEBOUNCE: Duration = Duration::from_millis(5);

/// An edit that comes while the last one is still being planned (a drag's
/// steps, a held key) waits this long for the next: a run starts once the
/// hand pauses, not at every step only to be cancelled at the next.
pub const BURST_DEBOUNCE: Duration = Duration::from_millis(30);

/// The live planner of the designer.
#[derive(Debug)]
pub struct Live {
    on: bool,
    /// What is re-planned: θ-PSO or FLATLO.
    pipeline: Kind,
    /// The mission the newest run plans (or will, once due).
    target: Option<Mission>,
    /// When the next run starts (the last edit plus the debounce).
    due: Option<Instant>,
    /// Runs started and not yet ended: the newest, and those cancelled
    /// that are winding down (they stop within a swarm iteration).
    running: Vec<Job>,
    /// The newest live result.
    latest: Option<Job>,
    /// Why live planning waits, when the mission has errors.
    paused: Option<String>,
    /// Why live planning was left off when the designer opened (the
    /// mission's size, `--no-live`), until it is turned on.
    held_off: Option<String>,

    next_id: JobId,
    /// Live plans that came in.
    revision: u64,
    /// Most runs that were under way at once (the bench's check that a drag
    /// never piles runs up).
    most_running: usize,
}

impl Default for Live {
    fn default() -> Self {
        Live {
            on: false,
            pipeline: Kind::default(),
            target: None,
            due: None,
            running: Vec::new(),
            latest: None,
            paused: None,
            held_off: None,
            next_id: FIRST_ID,
            revision: 0,
            most_running: 0,
        }
    }
}

impl Live {
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// The pipeline re-planned.
    pub fn pipeline(&self) -> Kind {
        self.pipeline
    }

    /// The newest live result, if one came in.
    pub fn latest(&self) -> Option<&Job> {
        self.latest.as_ref()
    }

    /// Why live planning waits, if it does (the mission's first error).
    pub fn paused(&self) -> Option<&str> {
        self.paused.as_deref()
    }

    /// Why live planning was left off when the designer opened, while it
    /// still is.
    pub fn held_off(&self) -> Option<&str> {
        self.held_off.as_deref().filter(|_| !self.on)
    }

    /// Leaves live planning off for `why` (said until it is turned on).
    pub fn hold_off(&mut self, why: String) {
        self.stop();
        self.held_off = Some(why);
    }

    /// A run is under way or due: the plan shown is being replaced.
    pub fn replanning(&self) -> bool {
        self.on && (self.due.is_some() || self.running.iter().any(|j| !j.cancel.is_cancelled()))
    }

    /// When the loop must wake to start a run.
    pub fn due(&self) -> Option<Instant> {
        self.due.filter(|_| self.on)
    }

    /// Live plans received so far.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Most live runs that were under way at once.
    pub fn most_running(&self) -> usize {
        self.most_running
    }

    pub fn any_running(&self) -> bool {
        !self.running.is_empty()
    }

    /// Turns live planning on for `pipeline` (θ-PSO or FLATLO; the fleet,
    /// which simulates for seconds, is never live); a run is due at once.
    pub fn start(&mut self, pipeline: Kind, now: Instant) -> Result<(), String> {
        if !pipeline.words().live {
            let key = crate::tui::keys::keys_for(&crate::tui::action::Action::Run(pipeline))
                .map_or_else(String::new, |k| format!(" with {k}"));
            return Err(format!(
                "the {} is not planned live: run it{key}",
                pipeline.words().name
            ));
        }
        self.on = true;
        self.held_off = None;
        self.pipeline = pipeline;
        self.target = None;
        self.due = Some(now);
        Ok(())
    }

    /// Turns live planning off: the runs under way are cancelled; the last
    /// live result stays on the map (and turns stale as any result).
    pub fn stop(&mut self) {
        self.on = false;
        self.due = None;
        self.paused = None;
        for job in &self.running {
            job.cancel.cancel();
        }
    }

    /// The document may have changed: when it did, the run under way is
    /// cancelled and a new one is due after the debounce (or, with errors,
    /// live planning pauses with the first).
    pub fn follow(&mut self, doc: &Document, now: Instant) {
        if !self.on || self.target.as_ref() == Some(doc.mission()) {
            return;
        }
        // The last edit not planned yet: the hand is still moving.
        let burst = self.replanning();
        self.target = Some(doc.mission().clone());
        for job in &self.running {
            job.cancel.cancel();
        }
        match doc.error_lines().into_iter().next() {
            Some(first) => {
                self.paused = Some(first);
                self.due = None;
            }
            None => {
                self.paused = None;
                self.due = Some(now + if burst { BURST_DEBOUNCE } else { DEBOUNCE });
            }
        }
    }

    /// Starts the run that is due by `now`, if one is: on the mission as it
    /// is, warm from the newest θ-PSO plan (`warm_from`, else the live one).
    pub fn poll(
        &mut self,
        doc: &Document,
        now: Instant,
        warm_from: Option<&Job>,
        record: RecordSettings,
        tx: &Sender<JobMsg>,
    ) {
        let Some(due) = self.due.filter(|_| self.on) else {
            return;
        };
        if now < due {
            return;
        }
        self.due = None;
        if let Some(first) = doc.error_lines().into_iter().next() {
            self.paused = Some(first);
            return;
        }
        let mission = doc.mission().clone();
        self.target = Some(mission.clone());
        let id = self.next_id;
        self.next_id += 1;
        let mut run = Run::new(self.pipeline, mission.seed);
        // What the edit already found (θ-PSO's IWPs, the findings): read,
        // not found again.
        run.revision = Some(doc.revision());
        // A pipeline with warm starts (θ-PSO) starts from the last plan.
        if let Some(request) = self
            .latest
            .as_ref()
            .or(warm_from)
            .and_then(warm_request)
            .filter(|r| r.kind() == self.pipeline)
        {
            run.request = request;
        }
        let job = Job::new(id, self.pipeline, mission.seed, mission.clone(), now);
        jobs::spawn_pipeline(id, run, mission, job.cancel.clone(), record, tx.clone());
        self.running.push(job);
        self.most_running = self.most_running.max(self.running.len());
    }

    /// Whether `id` is a live run's.
    pub fn owns(id: JobId) -> bool {
        id >= FIRST_ID
    }

    /// Applies a live run's message; true when a new plan came in (the
    /// newest run, finished and not superseded).
    pub fn on_msg(&mut self, msg: JobMsg, now: Instant) -> bool {
        let id = msg.job();
        let Some(k) = self.running.iter().position(|j| j.id == id) else {
            return false;
        };
        let done = matches!(msg, JobMsg::Done(..));
        self.running[k].apply(msg, now);
        if !done {
            return false;
        }
        let job = self.running.remove(k);
        // A superseded run's result is of a mission no longer there.
        if job.cancel.is_cancelled() || job.outcome.is_none() && job.state == JobState::Cancelled {
            return false;
        }
        let came_in = matches!(job.state, JobState::Done | JobState::Failed(_));
        if came_in {
            self.revision += 1;
            self.latest = Some(job);
        }
        came_in
    }
}

/// The request that starts a run warm from a job's plan, where its
/// pipeline has warm starts (θ-PSO's).
fn warm_request(job: &Job) -> Option<crate::pipelines::Request> {
    job.outcome.as_ref()?.face().warm_request(&label(job.id))
}

/// A run as people read its id: `job 3`, or `live 12` for a live run.
pub fn label(id: JobId) -> String {
    if Live::owns(id) {
        format!("live {}", id - FIRST_ID + 1)
    } else {
        format!("job {id}")
    }
}
