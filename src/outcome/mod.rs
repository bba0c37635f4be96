//! One pipeline interface from run to view.
//!
//! [`run`] runs any [`Kind`] of pipeline on a mission and a seed; every
//! caller (the CLI's `run` and `export`, the designer's jobs, the recorder,
//! the tests) gets one [`Outcome`] back and reads it through the same
//! methods: its verdict, a one-line headline, its summary, its convergence
//! series and its vehicles' tracks. Each answer comes from the pipeline's
//! own face (`pipelines::face`, implemented in the pipeline's `face.rs`);
//! the enum is registered in `pipelines/mod.rs` and read here. What only one
//! pipeline has (θ-PSO's cost terms, FLATLO's pair table, the fleet's
//! distance series) is reached through `theta_pso()`, `flatlo()`, `fleet()`.
//!
//! Adding a pipeline: see "Adding a pipeline" in `docs/architecture.md`.

pub mod diagnose;
pub mod tracks;

use serde::Serialize;

use crate::mission::Mission;
use crate::pipelines::{
    Ask, CancelToken, Completion, Kind, Observer, PipelineError, PlanOptions, Request,
};
pub use crate::pipelines::{Outcome, Verdict};
use tracks::Track;

/// What [`Outcome::figure`] is for `kind`, as a sweep's table heads it.
pub fn figure_name(kind: Kind) -> &'static str {
    kind.face().words().figure_name
}

/// Whether a run of `kind` on `mission` is small enough to plan live, after
/// every edit, in the designer: none of [`over_live_limits`].
pub fn interactive(kind: Kind, mission: &Mission) -> bool {
    over_live_limits(kind, mission).is_empty()
}

/// The sizes that keep a run of `kind` on `mission` from being planned live
/// (each with its figure and the limit), none when it is small enough (each
/// pipeline's `Pipeline::over_live_limits`). The designer says these when
/// it opens with live planning off.
pub fn over_live_limits(kind: Kind, mission: &Mission) -> Vec<String> {
    kind.face().over_live_limits(mission)
}

/// What `kind` predicts of a run on `mission` against the documented
/// limits (`pipelines::limits`), before one starts.
pub fn budget(kind: Kind, mission: &Mission) -> Vec<crate::mission::Diagnostic> {
    kind.face().budget(mission)
}

/// Runs `kind` on `mission` with `seed`, asking nothing more of it (θ-PSO
/// cold, the fleet in this process).
pub fn run(
    kind: Kind,
    mission: &Mission,
    seed: u64,
    options: PlanOptions,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<Outcome, PipelineError> {
    run_request(
        &kind.request(),
        mission,
        seed,
        options,
        None,
        observer,
        cancel,
    )
}

/// [`run`], the pipeline asked `request` (its own request type: θ-PSO's
/// warm start, say), reading what was found of the mission's `revision`
/// already, if anything. The one place a run is handed to its pipeline.
pub fn run_request(
    request: &Request,
    mission: &Mission,
    seed: u64,
    options: PlanOptions,
    revision: Option<&crate::pipelines::Revision>,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<Outcome, PipelineError> {
    let ask = Ask {
        seed,
        options,
        request,
        revision,
    };
    request.kind().face().run(mission, ask, observer, cancel)
}

/// What every front end reads of an outcome, each answer its pipeline's
/// (`Outcome::face`).
impl Outcome {
    pub fn kind(&self) -> Kind {
        self.face().kind()
    }

    pub fn seed(&self) -> u64 {
        self.face().seed()
    }

    pub fn completion(&self) -> Completion {
        self.face().completion()
    }

    /// Pass, or fail with the first broken constraint. A cancelled θ-PSO run
    /// still has a verdict on its best plan so far (it is a whole plan); a
    /// cancelled FLATLO or fleet run has flown only part of the way.
    pub fn verdict(&self) -> Verdict {
        self.face().verdict()
    }

    /// Meets its hard constraints (a cancelled run never does).
    pub fn ok(&self) -> bool {
        self.verdict() == Verdict::Passed
    }

    /// One line for the status bar and the job list.
    pub fn headline(&self) -> String {
        let verdict = match self.verdict() {
            Verdict::Passed => self.kind().face().words().passed.to_owned(),
            Verdict::Failed(reason) => format!("FAILED: {reason}"),
            Verdict::Cancelled => "no verdict on a partial run".to_owned(),
        };
        self.face().headline(&verdict)
    }

    /// The multi-line summary `skyform run` prints.
    pub fn summary(&self) -> String {
        self.summary_with(false)
    }

    /// The summary; `verbose` lists every unusable IWP instead of counting
    /// them by reason.
    pub fn summary_with(&self, verbose: bool) -> String {
        self.face().summary(verbose)
    }

    /// The best cost after each iteration (θ-PSO); empty for the others.
    pub fn convergence(&self) -> &[f64] {
        self.face().convergence()
    }

    /// The run gave a result to judge: θ-PSO a finite J, FLATLO a verified
    /// flight, the fleet a finished one.
    pub fn judged(&self) -> bool {
        self.face().judged()
    }

    /// The one figure a sweep tabulates (named by [`figure_name`]): θ-PSO's
    /// best J, FLATLO's closest pair, the fleet's closest two agents (m);
    /// NaN when there is none.
    pub fn figure(&self) -> f64 {
        self.face().figure()
    }

    /// Cost evaluations: θ-PSO's swarm, every agent's PSO; 0 for FLATLO.
    pub fn evaluations(&self) -> usize {
        self.face().evaluations()
    }

    /// The verdict in one word for the job list: a θ-PSO plan is feasible or
    /// not, a flown run passes or fails; `None` for a partial run.
    pub fn verdict_word(&self) -> Option<&'static str> {
        let (passed, failed) = self.kind().face().words().verdicts;
        match self.verdict() {
            Verdict::Passed => Some(passed),
            Verdict::Failed(_) => Some(failed),
            Verdict::Cancelled => None,
        }
    }

    /// The cost the run minimised (θ-PSO's best J); `None` for the
    /// pipelines without one.
    pub fn best_cost(&self) -> Option<f64> {
        self.face().best_cost()
    }

    /// Every vehicle's timed track as planned and flown: θ-PSO's UAV
    /// trajectories, FLATLO's simulated aircraft (their references are
    /// `reference_tracks`), the fleet's simulated quadrotors.
    pub fn tracks(&self) -> Vec<Track> {
        self.face().tracks()
    }

    /// The references the vehicles tracked, where they differ from the
    /// flight (FLATLO); the tracks themselves otherwise.
    pub fn reference_tracks(&self) -> Vec<Track> {
        self.face()
            .reference_tracks()
            .unwrap_or_else(|| self.tracks())
    }

    /// The outcome as JSON: the pipeline's own fields, `tracks`, and
    /// `reference_tracks` where they differ.
    pub fn to_json(&self) -> serde_json::Result<String> {
        #[derive(Serialize)]
        struct WithTracks<'a> {
            #[serde(flatten)]
            outcome: &'a Outcome,
            tracks: Vec<Track>,
            #[serde(skip_serializing_if = "Option::is_none")]
            reference_tracks: Option<Vec<Track>>,
        }
        serde_json::to_string_pretty(&WithTracks {
            outcome: self,
            tracks: self.tracks(),
            reference_tracks: self.face().reference_tracks(),
        })
    }
}
