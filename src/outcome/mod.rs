//! One pipeline interface from run to view.
//!
//! [`run`] runs any [`Kind`] of pipeline on a mission and a seed; every
//! caller (the CLI's `run` and `export`, the designer's jobs, the recorder,
//! the tests) gets one [`Outcome`] back and reads it through the same
//! methods: its verdict, a one-line headline, its summary, its convergence
//! series and its vehicles' tracks. What only one pipeline has (θ-PSO's
//! cost terms, FLATLO's pair table, the fleet's distance series) is reached
//! through `theta_pso()`, `flatlo()`, `fleet()`.
//!
//! Adding a pipeline: see "Adding a pipeline" in `docs/architecture.md`.

pub mod diagnose;
pub mod summary;
pub mod tracks;

use serde::Serialize;

use crate::mission::Mission;
use crate::pipelines::flatlo::{self, FlatloOutcome};
use crate::pipelines::fleet::{self, FleetOutcome};
use crate::pipelines::theta_pso::{self, PlanOptions, ThetaPsoOutcome};
use crate::pipelines::{CancelToken, Completion, Kind, Observer, PipelineError};
use tracks::Track;

/// A finished (or cancelled) run's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Outcome {
    ThetaPso(Box<ThetaPsoOutcome>),
    Flatlo(Box<FlatloOutcome>),
    Fleet(Box<FleetOutcome>),
}

/// What a run says of its plan.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Verdict {
    /// Every hard constraint holds.
    Passed,
    /// The first broken constraint, in words.
    Failed(String),
    /// Cancelled: a partial result gets no verdict.
    Cancelled,
}

/// What [`Outcome::figure`] is for `kind`, as a sweep's table heads it.
pub fn figure_name(kind: Kind) -> &'static str {
    match kind {
        Kind::ThetaPso => "best J",
        Kind::Flatlo => "closest pair (m)",
        Kind::Fleet => "closest agents (m)",
    }
}

/// Whether a run of `kind` on `mission` is small enough to plan live, after
/// every edit, in the designer: none of [`over_live_limits`].
pub fn interactive(kind: Kind, mission: &Mission) -> bool {
    over_live_limits(kind, mission).is_empty()
}

/// The sizes that keep a run of `kind` on `mission` from being planned live
/// (each with its figure and the limit), none when it is small enough:
/// θ-PSO up to 20,000 cost evaluations per run (the paper's 100 × 150 is
/// 15,000), 6 UAVs, 60 obstacles and a site of 40,000 m² (the bridge plans
/// in about 0.2 s cold on two cores); FLATLO up to 8 aircraft and 200,000
/// integration steps (the paper's case takes about 30 ms); never the fleet,
/// which simulates for seconds. The designer says these when it opens with
/// live planning off.
pub fn over_live_limits(kind: Kind, mission: &Mission) -> Vec<String> {
    use crate::pipelines::{exceeds, figure};
    let mut over = Vec::new();
    // "126 obstacles (live up to 60)".
    let mut check = |value: f64, limit: f64, what: &str| {
        if exceeds(value, limit) {
            let (value, limit) = (figure(value), figure(limit));
            over.push(format!(
                "{} (live up to {limit})",
                what.replace('#', &value)
            ));
        }
    };
    match kind {
        Kind::ThetaPso => {
            let p = &mission.theta_pso;
            let b = &mission.bounds;
            let evaluations = p.swarm_size.saturating_mul(p.iterations) as f64;
            check(evaluations, 20_000.0, "# cost evaluations per run");
            check(mission.formation.slots.len() as f64, 6.0, "# UAVs");
            check(mission.obstacles.len() as f64, 60.0, "# obstacles");
            let area = (b.x[1] - b.x[0]) * (b.y[1] - b.y[0]);
            check(area, 40_000.0, "a site of # m²");
        }
        Kind::Flatlo => {
            let p = &mission.flatlo;
            check(p.aircraft as f64, 8.0, "# aircraft");
            if p.aircraft <= 8 {
                let steps = p.aircraft as f64 * flatlo::references(p).duration / p.sim_step;
                check(steps, 200_000.0, "# integration steps");
            }
        }
        Kind::Fleet => over.push("the fleet simulates for seconds: never live".to_owned()),
    }
    over
}

/// What `kind` predicts of a run on `mission` against the documented
/// limits (`pipelines::limits`), before one starts.
pub fn budget(kind: Kind, mission: &Mission) -> Vec<crate::mission::Diagnostic> {
    match kind {
        Kind::ThetaPso => theta_pso::budget(mission),
        Kind::Flatlo => flatlo::budget(mission),
        Kind::Fleet => fleet::budget(mission),
    }
}

/// Runs `kind` on `mission` with `seed`, cold. `options` only matters to θ-PSO.
pub fn run(
    kind: Kind,
    mission: &Mission,
    seed: u64,
    options: PlanOptions,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<Outcome, PipelineError> {
    run_warm(kind, mission, seed, options, None, observer, cancel)
}

/// [`run`], θ-PSO started in part from `warm`'s plan (the designer's live
/// re-plans); the other pipelines have no warm start and ignore it. The one
/// place a run is handed to its pipeline.
pub fn run_warm(
    kind: Kind,
    mission: &Mission,
    seed: u64,
    options: PlanOptions,
    warm: Option<&theta_pso::WarmStart>,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<Outcome, PipelineError> {
    Ok(match kind {
        Kind::ThetaPso => Outcome::ThetaPso(Box::new(theta_pso::plan_warm(
            mission, seed, options, warm, observer, cancel,
        )?)),
        Kind::Flatlo => Outcome::Flatlo(Box::new(flatlo::plan(mission, seed, observer, cancel)?)),
        Kind::Fleet => Outcome::Fleet(Box::new(fleet::plan(mission, seed, observer, cancel)?)),
    })
}

/// The fleet's pass rule: every pair (a lost agent where it was last heard)
/// and every obstacle kept at c, no agent lost, every target's formation
/// reached. Fails on the first broken one, in words; when agents were lost
/// and that is not the first, they are named after it.
fn fleet_verdict(o: &FleetOutcome) -> Verdict {
    if o.completion == Completion::Cancelled {
        return Verdict::Cancelled;
    }
    let lost = summary::lost_agents(o);
    let first = if let Some(c) = o.closest_agents.as_ref().filter(|_| !o.kept_apart()) {
        summary::too_close(o, c)
    } else if let Some(c) = o.closest_obstacle.as_ref().filter(|_| !o.obstacles_clear()) {
        format!(
            "agent {} came {:.3} m from {} (t = {:.2} s), closer than c = {} m",
            c.a + 1,
            c.distance,
            c.b,
            c.time,
            o.safety_distance
        )
    } else if let Some(lost) = &lost {
        return Verdict::Failed(lost.clone());
    } else if let Some((k, t)) = o
        .targets
        .iter()
        .enumerate()
        .find(|(_, t)| t.converged_after.is_none())
    {
        let how_far = t
            .end
            .as_ref()
            .map_or_else(String::new, |e| format!(": {}", summary::shortfall(e)));
        format!("target {}'s formation was never reached{how_far}", k + 1)
    } else {
        return Verdict::Passed;
    };
    Verdict::Failed(match lost {
        Some(lost) => format!("{first}; {lost}"),
        None => first,
    })
}

impl Outcome {
    pub fn kind(&self) -> Kind {
        match self {
            Outcome::ThetaPso(_) => Kind::ThetaPso,
            Outcome::Flatlo(_) => Kind::Flatlo,
            Outcome::Fleet(_) => Kind::Fleet,
        }
    }

    pub fn seed(&self) -> u64 {
        match self {
            Outcome::ThetaPso(o) => o.seed,
            Outcome::Flatlo(o) => o.seed,
            Outcome::Fleet(o) => o.seed,
        }
    }

    pub fn completion(&self) -> Completion {
        match self {
            Outcome::ThetaPso(o) => o.completion,
            Outcome::Flatlo(o) => o.completion,
            Outcome::Fleet(o) => o.completion,
        }
    }

    /// Pass, or fail with the first broken constraint. A cancelled θ-PSO run
    /// still has a verdict on its best plan so far (it is a whole plan); a
    /// cancelled FLATLO or fleet run has flown only part of the way.
    pub fn verdict(&self) -> Verdict {
        match self {
            Outcome::ThetaPso(o) => match o.verification.first_failure() {
                None if o.feasible() => Verdict::Passed,
                None => Verdict::Failed("a constraint is broken".into()),
                Some(reason) => Verdict::Failed(reason),
            },
            Outcome::Flatlo(o) => match &o.verification {
                None => Verdict::Cancelled,
                Some(v) if v.passed => Verdict::Passed,
                Some(v) => {
                    // The first limit of the flight broken, then the separation.
                    let separation = o.closest.filter(|_| !v.separated(o.closest)).map(|c| {
                        format!(
                            "aircraft {} and {} came {:.0} m apart (t = {:.0} s), closer than {:.0} m",
                            c.a + 1,
                            c.b + 1,
                            c.min_distance,
                            c.time,
                            v.min_separation
                        )
                    });
                    let flight = v.violation.map(|x| x.describe());
                    Verdict::Failed(match (flight, separation) {
                        (Some(f), Some(s)) => format!("{f}; {s}"),
                        (Some(text), None) | (None, Some(text)) => text,
                        (None, None) => "separation lost".into(),
                    })
                }
            },
            Outcome::Fleet(o) => fleet_verdict(o),
        }
    }

    /// Meets its hard constraints (a cancelled run never does).
    pub fn ok(&self) -> bool {
        self.verdict() == Verdict::Passed
    }

    /// One line for the status bar and the job list.
    pub fn headline(&self) -> String {
        let verdict = match self.verdict() {
            Verdict::Passed => match self.kind() {
                Kind::ThetaPso => "feasible",
                Kind::Flatlo => "flyable, separation kept",
                Kind::Fleet => "formed, safety distance kept",
            }
            .to_owned(),
            Verdict::Failed(reason) => format!("FAILED: {reason}"),
            Verdict::Cancelled => "no verdict on a partial run".to_owned(),
        };
        match self {
            Outcome::ThetaPso(o) => {
                format!("J = {:.2}, {:.1} m, {verdict}", o.cost.total, o.path_length)
            }
            Outcome::Flatlo(o) => {
                let closest = o
                    .closest
                    .map_or("-".into(), |c| format!("{:.0} m", c.min_distance));
                match &o.verification {
                    Some(v) => format!(
                        "closest {closest}, spacing error {:.2} %, {verdict}",
                        v.max_spacing_error * 100.0
                    ),
                    None => format!("closest so far {closest}, {verdict}"),
                }
            }
            Outcome::Fleet(o) => format!(
                "{} of {} targets formed, closest {}, {verdict}",
                o.targets
                    .iter()
                    .filter(|t| t.converged_after.is_some())
                    .count(),
                o.targets.len(),
                o.closest_agents
                    .as_ref()
                    .map_or("-".into(), |c| format!("{:.2} m", c.distance)),
            ),
        }
    }

    /// The multi-line summary `skyform run` prints.
    pub fn summary(&self) -> String {
        self.summary_with(false)
    }

    /// The summary; `verbose` lists every unusable IWP instead of counting
    /// them by reason.
    pub fn summary_with(&self, verbose: bool) -> String {
        match self {
            Outcome::ThetaPso(o) => summary::theta_pso(o, verbose),
            Outcome::Flatlo(o) => summary::flatlo(o),
            Outcome::Fleet(o) => summary::fleet(o, &self.verdict()),
        }
    }

    /// The best cost after each iteration (θ-PSO); empty for the others.
    pub fn convergence(&self) -> &[f64] {
        match self {
            Outcome::ThetaPso(o) => &o.convergence,
            Outcome::Flatlo(_) | Outcome::Fleet(_) => &[],
        }
    }

    /// The run gave a result to judge: θ-PSO a finite J, FLATLO a verified
    /// flight, the fleet a finished one.
    pub fn judged(&self) -> bool {
        match self {
            Outcome::ThetaPso(o) => o.cost.total.is_finite(),
            Outcome::Flatlo(o) => o.verification.is_some(),
            Outcome::Fleet(o) => o.completion == Completion::Finished,
        }
    }

    /// The one figure a sweep tabulates (named by [`figure_name`]): θ-PSO's
    /// best J, FLATLO's closest pair, the fleet's closest two agents (m);
    /// NaN when there is none.
    pub fn figure(&self) -> f64 {
        match self {
            Outcome::ThetaPso(o) => o.cost.total,
            Outcome::Flatlo(o) => o.closest.as_ref().map_or(f64::NAN, |c| c.min_distance),
            Outcome::Fleet(o) => o.closest_agents.as_ref().map_or(f64::NAN, |c| c.distance),
        }
    }

    /// Cost evaluations: θ-PSO's swarm, every agent's PSO; 0 for FLATLO.
    pub fn evaluations(&self) -> usize {
        match self {
            Outcome::ThetaPso(o) => o.evaluations,
            Outcome::Flatlo(_) => 0,
            Outcome::Fleet(o) => o.agents.iter().map(|a| a.evaluations).sum(),
        }
    }

    /// The verdict in one word for the job list: a θ-PSO plan is feasible or
    /// not, a flown run passes or fails; `None` for a partial run.
    pub fn verdict_word(&self) -> Option<&'static str> {
        let plan = self.kind() == Kind::ThetaPso;
        match self.verdict() {
            Verdict::Passed => Some(if plan { "feasible" } else { "pass" }),
            Verdict::Failed(_) => Some(if plan { "INFEASIBLE" } else { "FAIL" }),
            Verdict::Cancelled => None,
        }
    }

    /// θ-PSO's best J; `None` for the pipelines without one.
    pub fn best_cost(&self) -> Option<f64> {
        self.theta_pso().map(|o| o.cost.total)
    }

    /// Every vehicle's timed track as planned and flown (`tracks.rs`):
    /// θ-PSO's UAV trajectories, FLATLO's simulated aircraft (their
    /// references are `reference_tracks`), the fleet's simulated quadrotors.
    pub fn tracks(&self) -> Vec<Track> {
        match self {
            Outcome::ThetaPso(o) => tracks::theta_pso(o),
            Outcome::Flatlo(o) => tracks::flatlo_flown(o),
            Outcome::Fleet(o) => tracks::fleet(o),
        }
    }

    /// The references the vehicles tracked, where they differ from the
    /// flight (FLATLO); the tracks themselves otherwise.
    pub fn reference_tracks(&self) -> Vec<Track> {
        match self {
            Outcome::Flatlo(o) => tracks::flatlo(o),
            Outcome::ThetaPso(_) | Outcome::Fleet(_) => self.tracks(),
        }
    }

    /// The outcome as JSON: the pipeline's own fields and `tracks`.
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
            reference_tracks: (self.kind() == Kind::Flatlo).then(|| self.reference_tracks()),
        })
    }

    pub fn theta_pso(&self) -> Option<&ThetaPsoOutcome> {
        match self {
            Outcome::ThetaPso(o) => Some(o),
            _ => None,
        }
    }

    pub fn flatlo(&self) -> Option<&FlatloOutcome> {
        match self {
            Outcome::Flatlo(o) => Some(o),
            _ => None,
        }
    }

    pub fn fleet(&self) -> Option<&FleetOutcome> {
        match self {
            Outcome::Fleet(o) => Some(o),
            _ => None,
        }
    }
}
