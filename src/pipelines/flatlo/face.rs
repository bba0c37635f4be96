//! FLATLO's face: what every front end reads of it (`pipelines::face`).

use nalgebra::{Point3, Vector3};

use super::{FlatloOutcome, chart, recording, summary};
use crate::mission::{Diagnostic, Mission};
use crate::pipelines::chart::{Chart, ChartView};
use crate::pipelines::face::Words;
use crate::pipelines::sketch::{Plot, Sketch};
use crate::pipelines::{Airframe, ExportRules, Limits};
use crate::pipelines::{
    Ask, CancelToken, Observer, Outcome, Pipeline, PipelineError, PipelineOutcome, Track,
    TrackSample, Verdict,
};

/// FLATLO (`Kind::Flatlo`).
pub struct Flatlo;

/// FLATLO's words: a flown run finishes, and passes or fails; the paper's
/// case takes about 30 ms, so it plans live.
static WORDS: Words = Words {
    name: "FLATLO",
    slug: "flatlo",
    noun: "aircraft",
    nouns: "aircraft",
    fixed_wing: true,
    figure_name: "closest pair (m)",
    tallies: ("finished", "passed"),
    verdicts: ("pass", "FAIL"),
    passed: "flyable, separation kept",
    live: true,
    run_key: (
        'F',
        "run FLATLO, the squadron transition (select Squadron with n/p to edit it)",
    ),
    processes_key: None,
    speed_field: Some("flatlo.airspeed_range"),
    bounds_advice: Some(
        "widen bounds.x and bounds.y to hold the squadron's manoeuvre (flatlo.spacing, \
         flatlo.turn_radius and flatlo.start set its extent)",
    ),
    section: ("flatlo", "Squadron (FLATLO)"),
    dwarfs_the_site: true,
    spacing_field: None,
};

impl Pipeline for Flatlo {
    fn words(&self) -> &'static Words {
        &WORDS
    }

    fn vehicles(&self, mission: &Mission) -> usize {
        mission.flatlo.aircraft
    }

    fn rows(&self) -> &'static [crate::pipelines::rows::Row] {
        super::section::ROWS
    }

    fn plots(&self) -> &'static [&'static [Plot]] {
        recording::PLOTS
    }

    fn findings(
        &self,
        mission: &Mission,
        _prepared: Option<&crate::pipelines::Prepared>,
    ) -> Vec<Diagnostic> {
        super::diagnostics(mission)
    }

    fn budget(&self, mission: &Mission) -> Vec<Diagnostic> {
        super::budget(mission)
    }

    /// Up to 8 aircraft and 200,000 integration steps.
    fn over_live_limits(&self, mission: &Mission) -> Vec<String> {
        let p = &mission.flatlo;
        let mut limits = vec![(p.aircraft as f64, 8.0, "# aircraft")];
        if p.aircraft <= 8 {
            let steps = p.aircraft as f64 * super::references(p).duration / p.sim_step;
            limits.push((steps, 200_000.0, "# integration steps"));
        }
        crate::pipelines::live_limits(&limits)
    }

    fn run(
        &self,
        mission: &Mission,
        ask: Ask<'_>,
        observer: &mut dyn Observer,
        cancel: &CancelToken,
    ) -> Result<Outcome, PipelineError> {
        super::plan(mission, ask.seed, observer, cancel).map(Outcome::from)
    }
}

impl PipelineOutcome for FlatloOutcome {
    fn chart(&self, view: &ChartView, out: &mut dyn Chart) {
        chart::chart(self, view, out);
    }

    fn header(&self) -> &crate::pipelines::Header {
        &self.header
    }

    /// A cancelled run has flown only part of the way: no verdict. Else the
    /// first limit of the flight broken, then the separation.
    fn verdict(&self) -> Verdict {
        let Some(v) = &self.verification else {
            return Verdict::Cancelled;
        };
        if v.passed {
            return Verdict::Passed;
        }
        let separation = self
            .closest
            .filter(|_| !v.separated(self.closest))
            .map(|c| {
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

    fn headline(&self, verdict: &str) -> String {
        let closest = self
            .closest
            .map_or("-".into(), |c| format!("{:.0} m", c.min_distance));
        match &self.verification {
            Some(v) => format!(
                "closest {closest}, spacing error {:.2} %, {verdict}",
                v.max_spacing_error * 100.0
            ),
            None => format!("closest so far {closest}, {verdict}"),
        }
    }

    fn summary(&self, _verbose: bool) -> String {
        summary::flatlo(self)
    }

    /// A verified flight.
    fn judged(&self) -> bool {
        self.verification.is_some()
    }

    /// The closest pair, metres.
    fn figure(&self) -> f64 {
        self.closest.as_ref().map_or(f64::NAN, |c| c.min_distance)
    }

    fn evaluations(&self) -> usize {
        0
    }

    /// Every aircraft's simulated flight (the samples it kept:
    /// `FlatloOutcome::sample_stride`), velocity from V, γ, χ (eqs. 4-6).
    fn tracks(&self) -> Vec<Track> {
        self.aircraft
            .iter()
            .map(|a| Track {
                vehicle: a.index,
                samples: a
                    .flown
                    .iter()
                    .map(|s| {
                        let (sg, cg) = s.gamma.sin_cos();
                        let (sc, cc) = s.chi.sin_cos();
                        TrackSample {
                            t: s.t,
                            position: s.position,
                            velocity: Vector3::new(cg * cc, cg * sc, sg) * s.airspeed,
                        }
                    })
                    .collect(),
            })
            .collect()
    }

    /// Every aircraft's reference (Algorithms 1-2 at its common-arrival
    /// airspeed: the plan, not the one noisy simulated flight of it), on
    /// the sample grid, velocities by central differences.
    fn reference_tracks(&self) -> Option<Vec<Track>> {
        Some(
            self.aircraft
                .iter()
                .map(|a| {
                    let times: Vec<f64> = a.reference.iter().map(|s| s.t).collect();
                    let positions: Vec<Point3<f64>> =
                        a.reference.iter().map(|s| s.position).collect();
                    Track::from_positions(a.index, &times, &positions)
                })
                .collect(),
        )
    }

    /// The references, held to `min_separation` (and the band and bounds,
    /// which the geofence enforces); the margin is the largest tracking
    /// error of the simulated autopilot with which the squadron was
    /// verified; the airspeeds within `flatlo.airspeed_range`.
    fn table(&self) -> Vec<crate::pipelines::table::Row> {
        summary::table(self)
    }

    fn export_rules(&self, mission: &Mission) -> ExportRules {
        let p = &mission.flatlo;
        ExportRules {
            limits: Limits {
                clearance: 0.0,
                closest: p.min_separation,
                farthest: None,
                inspections: false,
                dynamics: false,
            },
            airframe: Airframe::FixedWing {
                airspeed: p.airspeed_range,
            },
            margin: self
                .aircraft
                .iter()
                .map(|a| a.tracking_max)
                .fold(0.0, f64::max),
            margin_source: "the simulated squadron's largest tracking error",
            limits_note: None,
            loiter_radius: p.turn_radius,
        }
    }

    fn sketch(&self, _scene: Option<&Mission>, out: &mut dyn Sketch) {
        recording::sketch(self, out);
    }
}
