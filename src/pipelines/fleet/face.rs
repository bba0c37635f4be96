//! The fleet's face: what every front end reads of it (`pipelines::face`).

use nalgebra::{Point3, Vector2};

use super::{FleetOutcome, chart, recording, summary};
use crate::mission::{Diagnostic, FleetTarget, Mission};
use crate::pipelines::chart::{Chart, ChartView};
use crate::pipelines::face::Words;
use crate::pipelines::points::PointKind;
use crate::pipelines::sketch::{Plot, Sketch};
use crate::pipelines::{Airframe, ExportRules, Limits};
use crate::pipelines::{
    Ask, CancelToken, Completion, Observer, Outcome, Pipeline, PipelineError, PipelineOutcome,
    Track, Verdict,
};

/// The distributed fleet (`Kind::Fleet`).
pub struct Fleet;

/// The fleet's words: a flown run finishes, and passes or fails; its run
/// is a flight of seconds, re-run by hand.
static WORDS: Words = Words {
    name: "fleet",
    slug: "fleet",
    noun: "agent",
    nouns: "agents",
    fixed_wing: false,
    figure_name: "closest agents (m)",
    tallies: ("finished", "passed"),
    verdicts: ("pass", "FAIL"),
    passed: "formed, safety distance kept",
    live: false,
    run_key: (
        'T',
        "run the distributed fleet (select Fleet and its targets with n/p to edit them; d adds a target)",
    ),
    processes_key: Some((
        'Z',
        "run the fleet as agent processes over Zenoh (same as T)",
    )),
    speed_field: None,
    bounds_advice: None,
    section: ("fleet", "Fleet"),
    dwarfs_the_site: false,
    spacing_field: None,
};

/// The fleet's targets, on the designer's map.
static POINTS: [PointKind; 1] = [PointKind {
    noun: "Fleet target",
    glyph: "◎",
    path: ["fleet", "targets"],
    count: |m| m.fleet.targets.len(),
    centre: |m, i| m.fleet.targets.get(i).map(|t| t.centre()),
    spots: |m, i| {
        m.fleet
            .targets
            .get(i)
            .map_or(Vec::new(), |t| t.positions.clone())
    },
    move_to: |m, i, p| {
        if let Some(t) = m.fleet.targets.get_mut(i) {
            t.move_to(p);
        }
    },
    add: |m| {
        // 10 s after the last, 1 m east of it; the first where the fleet
        // has room to form.
        let next = match m.fleet.targets.last() {
            Some(t) => {
                let mut next = t.clone();
                next.time = t.time + 10.0;
                next.move_to(t.centre() + Vector2::new(1.0, 0.0));
                next
            }
            None => FleetTarget::around(0.0, super::default_target(m)),
        };
        m.fleet.targets.push(next);
    },
    remove: |m, i| {
        if i < m.fleet.targets.len() {
            m.fleet.targets.remove(i);
        }
    },
    rows: super::section::TARGET_ROWS,
}];

impl Pipeline for Fleet {
    fn words(&self) -> &'static Words {
        &WORDS
    }

    fn points(&self) -> &'static [PointKind] {
        &POINTS
    }

    fn vehicles(&self, mission: &Mission) -> usize {
        mission.fleet.agents
    }

    /// The safety distance c, which every agent keeps from the others and
    /// from the obstacles.
    fn margin_field(&self, mission: &Mission) -> Option<(&'static str, f64)> {
        Some(("fleet.safety_distance", mission.fleet.safety_distance))
    }

    fn add_margin(&self, mission: &mut Mission, m: f64) {
        mission.fleet.safety_distance += m;
    }

    fn rows(&self) -> &'static [crate::pipelines::rows::Row] {
        super::section::ROWS
    }

    fn plots(&self) -> &'static [&'static [Plot]] {
        recording::PLOTS
    }

    fn budget(&self, mission: &Mission) -> Vec<Diagnostic> {
        super::budget(mission)
    }

    /// A written `fleet.duration` shorter than the fleet needs to reach its
    /// last target at its cruise speed.
    fn findings(
        &self,
        mission: &Mission,
        _prepared: Option<&crate::pipelines::Prepared>,
    ) -> Vec<Diagnostic> {
        super::duration_finding(mission).into_iter().collect()
    }

    fn over_live_limits(&self, _: &Mission) -> Vec<String> {
        vec!["the fleet simulates for seconds: never live".to_owned()]
    }

    fn flies_as_processes(&self) -> bool {
        true
    }

    fn run(
        &self,
        mission: &Mission,
        ask: Ask<'_>,
        observer: &mut dyn Observer,
        cancel: &CancelToken,
    ) -> Result<Outcome, PipelineError> {
        if ask.request.processes().is_some() {
            return Err(PipelineError::Unsupported(
                "agent processes are flown by the run path (`run::Run`), not in process".into(),
            ));
        }
        super::plan(mission, ask.seed, observer, cancel).map(Outcome::from)
    }
}

impl PipelineOutcome for FleetOutcome {
    fn chart(&self, view: &ChartView, out: &mut dyn Chart) {
        chart::chart(self, view, out);
    }

    fn header(&self) -> &crate::pipelines::Header {
        &self.header
    }

    /// Every pair (a lost agent where it was last heard) and every obstacle
    /// kept at c, no agent lost, every target's formation reached (by the
    /// agents still flying: a lost one is left out of it). Fails on the
    /// first broken one, in words; an agent lost is named with how its
    /// survivors did. A cancelled run has flown only part of the way: no
    /// verdict.
    fn verdict(&self) -> Verdict {
        if self.header.completion == Completion::Cancelled {
            return Verdict::Cancelled;
        }
        let lost = summary::lost_agents(self);
        let first = if let Some(c) = self.closest_agents.as_ref().filter(|_| !self.kept_apart()) {
            summary::too_close(self, c)
        } else if let Some(c) = self
            .closest_obstacle
            .as_ref()
            .filter(|_| !self.obstacles_clear())
        {
            format!(
                "agent {} came {:.3} m from {} (t = {:.2} s), closer than c = {} m",
                c.a + 1,
                c.distance,
                c.b,
                c.time,
                self.safety_distance
            )
        } else if let Some(lost) = &lost
            && self.targets.iter().all(|t| t.converged_after.is_some())
        {
            // A contingency the run must report, with how the survivors did.
            return Verdict::Failed(format!(
                "{lost}; the {} survivors (it left out) reached every formation and kept c",
                self.agents.len() - self.lost.len()
            ));
        } else if let Some((k, t)) = self
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

    fn headline(&self, verdict: &str) -> String {
        format!(
            "{} of {} targets formed, closest {}, {verdict}",
            self.targets
                .iter()
                .filter(|t| t.converged_after.is_some())
                .count(),
            self.targets.len(),
            self.closest_agents
                .as_ref()
                .map_or("-".into(), |c| format!("{:.2} m", c.distance)),
        )
    }

    fn summary(&self, _verbose: bool) -> String {
        summary::fleet(self, &self.verdict())
    }

    /// A finished flight.
    fn judged(&self) -> bool {
        self.header.completion == Completion::Finished
    }

    /// The closest two agents, metres.
    fn figure(&self) -> f64 {
        self.closest_agents
            .as_ref()
            .map_or(f64::NAN, |c| c.distance)
    }

    /// Every agent's PSO.
    fn evaluations(&self) -> usize {
        self.agents.iter().map(|a| a.evaluations).sum()
    }

    /// Every quadrotor's flight (its only plan: the references jump every
    /// τ), velocities by central differences.
    fn tracks(&self) -> Vec<Track> {
        self.agents
            .iter()
            .map(|a| {
                let times: Vec<f64> = a.samples.iter().map(|s| s.t).collect();
                let positions: Vec<Point3<f64>> = a.samples.iter().map(|s| s.position).collect();
                Track::from_positions(a.index, &times, &positions)
            })
            .collect()
    }

    /// The quadrotors' flights, held to the safety distance c between
    /// agents and from obstacles (and the band and bounds); the margin is
    /// the convergence tolerance on c, shared by two agents. The files are
    /// flown by a real multicopter's autopilot, within `[vehicle]`, as
    /// θ-PSO's are (the fleet's own quadrotor parameters model the paper's
    /// AR.Drone in the simulation).
    fn table(&self) -> Vec<crate::pipelines::table::Row> {
        summary::table(self)
    }

    fn export_rules(&self, mission: &Mission) -> ExportRules {
        let p = &mission.fleet;
        ExportRules {
            limits: Limits {
                clearance: p.safety_distance,
                closest: p.safety_distance,
                farthest: None,
                inspections: false,
                dynamics: false,
            },
            airframe: Airframe::Multicopter,
            margin: p.tolerance * p.safety_distance / 2.0,
            margin_source: "fleet.tolerance × fleet.safety_distance / 2",
            limits_note: None,
            loiter_radius: 0.0,
        }
    }

    /// The flight, replayed on the map (`,` `.` `>`).
    fn replay(&self) -> Option<f64> {
        Some(self.duration)
    }

    fn sketch(&self, _scene: Option<&Mission>, out: &mut dyn Sketch) {
        recording::sketch(self, out);
    }
}
