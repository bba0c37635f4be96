//! One face per pipeline: what a front end may ask of any pipeline
//! ([`Pipeline`]) and of any pipeline's outcome ([`PipelineOutcome`]).
//!
//! Each pipeline implements both in its own `face.rs`; the registration in
//! `pipelines/mod.rs` hands a [`super::Kind`] its face and an
//! [`super::Outcome`] its outcome's; its nine matches over the pipelines
//! (the faces, the requests, the outcome's accessors) are the
//! registration. The CLI, the designer, the sweep, the recorder and the exports
//! read a pipeline through these two traits, so a new pipeline's words,
//! verdict, summary, tracks and budget live with it, not in the front ends.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::chart::{Chart, ChartView};
use super::sketch::{Plot, Sketch};
use super::table::Row;
use super::{CancelToken, Completion, Kind, Limits, Observer, Outcome, PipelineError, TrackSample};
use crate::mission::{Diagnostic, Mission};

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

/// What every outcome starts with, the same in each pipeline's JSON:
/// which pipeline ran which mission with which seed, and how the run ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Header {
    pub pipeline: Kind,
    pub mission: String,
    pub seed: u64,
    pub completion: Completion,
}

/// One vehicle's timed track: the common shape of every pipeline's result
/// (`PipelineOutcome::tracks`), which exports, views and recordings read
/// instead of each outcome's own fields.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Track {
    /// 0-based vehicle index (UAV n + 1 in messages and file names).
    pub vehicle: usize,
    pub samples: Vec<TrackSample>,
}

impl Track {
    /// The track from positions at `times`, velocities by central differences.
    pub fn from_positions(vehicle: usize, times: &[f64], positions: &[Point3<f64>]) -> Self {
        let n = times.len().min(positions.len());
        let samples = (0..n)
            .map(|k| {
                let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
                let dt = times[b] - times[a];
                let velocity = if dt > 0.0 {
                    (positions[b] - positions[a]) / dt
                } else {
                    Vector3::zeros()
                };
                TrackSample {
                    t: times[k],
                    position: positions[k],
                    velocity,
                }
            })
            .collect();
        Track { vehicle, samples }
    }

    /// Seconds from the first to the last sample.
    pub fn duration(&self) -> f64 {
        match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => b.t - a.t,
            _ => 0.0,
        }
    }
}

/// What flies a pipeline's exported files.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Airframe {
    /// A multicopter within the mission's `[vehicle]` limits.
    Multicopter,
    /// A fixed-wing aircraft whose commanded airspeeds keep this range, m/s.
    FixedWing { airspeed: [f64; 2] },
}

/// What the exports hold a pipeline's files to (`export::Planned`): the
/// tracks they write are its `reference_tracks`.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportRules {
    /// The hard limits the files are re-verified against.
    pub limits: Limits,
    pub airframe: Airframe,
    /// The most the pipeline lets a vehicle stray from its track, metres,
    /// before the plan's own slack is considered.
    pub margin: f64,
    /// Where `margin` comes from, in words.
    pub margin_source: &'static str,
    /// Fixed-wing loiter radius at the end, metres.
    pub loiter_radius: f64,
    /// Why the files are held to other limits than the run's verification
    /// (said in the export's summary), when they are.
    pub limits_note: Option<String>,
}

/// How a run may use the machine (not what to plan: that is the mission,
/// nor what only its pipeline reads: that is its [`super::Request`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanOptions {
    /// Spread the run's work over the rayon pool (same result either way;
    /// θ-PSO evaluates its swarm there). A sweep runs seeds side by side
    /// instead.
    pub parallel: bool,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions { parallel: true }
    }
}

/// A pipeline's vehicles flown by agent processes on this machine, talking
/// over Zenoh (`distributed`), instead of in the planning process.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Processes {
    /// How many agent processes.
    pub count: usize,
    /// Each on its own wall clock (not reproducible) instead of lockstep.
    pub realtime: bool,
}

/// One run as its pipeline is asked it: the seed, how it may use the
/// machine, and the pipeline's own request (`super::Request`).
#[derive(Debug, Clone, Copy)]
pub struct Ask<'a> {
    pub seed: u64,
    pub options: PlanOptions,
    pub request: &'a super::Request,
    /// What was found of this revision of the mission already (the
    /// designer's, on every edit): the run reads it instead of finding it
    /// again. `None`: the run finds its own.
    pub revision: Option<&'a super::Revision>,
}

/// A pipeline's fixed words and flags: what its face says of it whatever
/// the mission (one `static` per pipeline, read through [`Pipeline`]'s
/// methods of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Words {
    /// For people: `θ-PSO`.
    pub name: &'static str,
    /// On the command line and in file names: `theta-pso`.
    pub slug: &'static str,
    /// What it calls a vehicle: `UAV`.
    pub noun: &'static str,
    /// And more than one: `UAVs`.
    pub nouns: &'static str,
    /// Its vehicles fly with fixed wings.
    pub fixed_wing: bool,
    /// The sweep's figure column.
    pub figure_name: &'static str,
    /// A sweep's two tallies: complete and good.
    pub tallies: (&'static str, &'static str),
    /// The verdict in one word: passed and failed.
    pub verdicts: (&'static str, &'static str),
    /// The headline's verdict when every hard constraint holds.
    pub passed: &'static str,
    /// The designer may re-plan it after every edit.
    pub live: bool,
    /// Its run key and the key table's words.
    pub run_key: (char, &'static str),
    /// Its agent-process key and words, if it flies as processes.
    pub processes_key: Option<(char, &'static str)>,
    /// The field that limits its speed, when not `[vehicle]`'s.
    pub speed_field: Option<&'static str>,
    /// What to change when its flight leaves the bounds.
    pub bounds_advice: Option<&'static str>,
    /// The field a flight check widens to space its vehicles apart.
    pub spacing_field: Option<&'static str>,
    /// Its mission section: the TOML key and the designer's title
    /// (`("theta_pso", "θ-PSO parameters")`).
    pub section: (&'static str, &'static str),
    /// Its flights span kilometres (FLATLO's): the designer leaves the
    /// site's labels and the formation's slots off the map under one, where
    /// they would be letters piled on a few cells.
    pub dwarfs_the_site: bool,
}

/// A pipeline: its words, its limits and its run. One unit value per
/// pipeline (`Kind::face`).
pub trait Pipeline: Sync {
    /// Its fixed words and flags, as data ([`Words`]).
    fn words(&self) -> &'static Words;
    /// How many vehicles a run of it flies in `mission`.
    fn vehicles(&self, mission: &Mission) -> usize;
    /// The run in a few words for a sweep's first line (`θ-PSO`).
    fn describe(&self, _mission: &Mission) -> String {
        self.words().name.to_owned()
    }
    /// The mission field a flight check's margin is added to (`skyform fly
    /// --target`: what its verification holds as the least clearance), and
    /// its value in `mission`; `None` when the check does not fly its
    /// vehicles.
    fn margin_field(&self, _mission: &Mission) -> Option<(&'static str, f64)> {
        None
    }
    /// `mission` asked to keep `m` more (the field of [`Pipeline::margin_field`]).
    fn add_margin(&self, _mission: &mut Mission, _m: f64) {}
    /// `mission` with its vehicles spaced `scale` times as far apart (the
    /// field of [`Words::spacing_field`]).
    fn widen_spacing(&self, _mission: &mut Mission, _scale: f64) {}
    /// Its own section's fields, as the designer's inspector shows and
    /// edits them (kept in the pipeline's `section.rs`).
    fn rows(&self) -> &'static [super::rows::Row] {
        &[]
    }
    /// The points of its own section the designer draws on the map and
    /// lets the operator move, add and delete (the fleet's targets).
    fn points(&self) -> &'static [super::points::PointKind] {
        &[]
    }
    /// The plots its viewer layout puts beside the scene, a column of
    /// panels (a panel of several plots is a set of tabs).
    fn plots(&self) -> &'static [&'static [Plot]];
    /// What it says of a mission that follows the rules, before a run
    /// (θ-PSO: IWPs no shape can pass, inspections eq. 8 cannot hold;
    /// FLATLO: airspeeds and bounds predicted from its references).
    fn findings(&self, _mission: &Mission, _prepared: Option<&super::Prepared>) -> Vec<Diagnostic> {
        Vec::new()
    }
    /// What it finds of a mission that follows the rules once per
    /// revision, for its findings and its run to read (θ-PSO: the IWPs);
    /// kept in the [`super::Revision`].
    fn prepare(&self, _mission: &Mission) -> Option<super::Prepared> {
        None
    }
    /// What it adds to the mission's static scene in a recording, before
    /// any run, at paths of its own under `world/` (θ-PSO: its IWPs at
    /// mid-band, `world/iwps`); nothing by default.
    fn scene(&self, _mission: &Mission, _out: &mut dyn super::sketch::Sketch) {}
    /// Its predicted size against the documented limits (`limits`).
    fn budget(&self, mission: &Mission) -> Vec<Diagnostic>;
    /// The sizes that keep a run on `mission` from being planned live
    /// (each with its figure and the limit); none when it may be.
    fn over_live_limits(&self, mission: &Mission) -> Vec<String>;
    /// Its vehicles can fly as agent processes ([`Processes`], the fleet's):
    /// its request may ask for them, and the run path hands such a run to
    /// the transport (`distributed`) instead of [`Pipeline::run`].
    fn flies_as_processes(&self) -> bool {
        false
    }
    /// Runs it on `mission`, in this process.
    fn run(
        &self,
        mission: &Mission,
        ask: Ask<'_>,
        observer: &mut dyn Observer,
        cancel: &CancelToken,
    ) -> Result<Outcome, PipelineError>;
}

/// A pipeline's outcome, as every front end reads it.
pub trait PipelineOutcome {
    /// The shared header: pipeline, mission, seed, completion.
    fn header(&self) -> &Header;
    fn kind(&self) -> Kind {
        self.header().pipeline
    }
    fn seed(&self) -> u64 {
        self.header().seed
    }
    fn completion(&self) -> Completion {
        self.header().completion
    }
    /// Pass, or fail with the first broken constraint.
    fn verdict(&self) -> Verdict;
    /// The headline's figures around `verdict` (the verdict in words).
    fn headline(&self, verdict: &str) -> String;
    /// The multi-line summary `skyform run` prints; `verbose` lists
    /// everything a summary would count.
    fn summary(&self, verbose: bool) -> String;
    /// The best cost after each iteration, where there is one.
    fn convergence(&self) -> &[f64] {
        &[]
    }
    /// The run gave a result to judge.
    fn judged(&self) -> bool;
    /// The one figure a sweep tabulates (`Words::figure_name`); NaN
    /// when there is none.
    fn figure(&self) -> f64;
    /// Cost evaluations made.
    fn evaluations(&self) -> usize;
    /// Every vehicle's timed track as planned and flown.
    fn tracks(&self) -> Vec<Track>;
    /// The references the vehicles tracked, where they differ from the
    /// tracks (what the exports fly); `None`: the tracks themselves.
    fn reference_tracks(&self) -> Option<Vec<Track>> {
        None
    }
    /// What its exported files are held to.
    fn export_rules(&self, mission: &Mission) -> ExportRules;
    /// Its result as the designer's jobs panel shows it, the verdict first
    /// (the panel adds the flight check under it and STALE).
    fn table(&self) -> Vec<Row>;
    /// Draws the outcome in a recording; `scene` is the mission when the
    /// recording has it.
    fn sketch(&self, scene: Option<&Mission>, out: &mut dyn Sketch);
    /// Charts the outcome on the designer's map, top down.
    fn chart(&self, view: &ChartView, out: &mut dyn Chart);
    /// The path the designer's side view unrolls (distance along it against
    /// altitude); `None`: the straight line from start to goal.
    fn flown_path(&self) -> Option<&[Point3<f64>]> {
        None
    }
    /// Charts the outcome in the side view, along [`PipelineOutcome::flown_path`].
    fn chart_side(&self, _view: &ChartView, _out: &mut dyn Chart) {}
    /// What a live plan adds to its vehicles' tracks in a recording, under
    /// `root` (θ-PSO: its centroid path).
    fn sketch_live(&self, _root: &str, _out: &mut dyn Sketch) {}
    /// The plan it was started from, in words, when not from scratch
    /// (θ-PSO's warm start: "warm from revision 3").
    fn warm_from(&self) -> Option<String> {
        None
    }
    /// The cost the run minimised, where it has one (θ-PSO's best J).
    fn best_cost(&self) -> Option<f64> {
        None
    }
    /// The request that starts the next run of its pipeline from this plan
    /// (θ-PSO's warm start), `from` saying where it came from; `None` for a
    /// pipeline without warm starts.
    fn warm_request(&self, _from: &str) -> Option<super::Request> {
        None
    }
    /// How long a flight the designer can replay on the map runs, seconds
    /// (the fleet's); `None`: nothing to replay.
    fn replay(&self) -> Option<f64> {
        None
    }
}

/// A kind's words, read from its face.
impl Kind {
    /// Its fixed words and flags ([`Words`]): `Kind::Flatlo.words().name`
    /// is `FLATLO`.
    pub fn words(self) -> &'static Words {
        self.face().words()
    }
}
