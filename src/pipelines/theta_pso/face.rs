//! θ-PSO's face: what every front end reads of it (`pipelines::face`).

use super::{ThetaPsoOutcome, chart, recording, summary};
use crate::mission::{Diagnostic, Mission};
use crate::pipelines::chart::{Chart, ChartView};
use crate::pipelines::face::Words;
use crate::pipelines::sketch::{Plot, Sketch};
use crate::pipelines::{Airframe, ExportRules, Limits};
use crate::pipelines::{
    Ask, CancelToken, Observer, Outcome, Pipeline, PipelineError, PipelineOutcome, Track, Verdict,
};

/// θ-PSO (`Kind::ThetaPso`).
pub struct ThetaPso;

/// The IWPs θ-PSO found of `revision` (its `Pipeline::prepare`), if it
/// was looked at.
pub fn prepared_iwps(revision: &crate::pipelines::Revision) -> Option<&Vec<super::Iwp>> {
    revision
        .prepared(crate::pipelines::Kind::ThetaPso)?
        .downcast_ref::<Vec<super::Iwp>>()
}

/// θ-PSO's words: a run is complete when its J is finite, good when
/// feasible; a live run is short and deterministic.
static WORDS: Words = Words {
    name: "θ-PSO",
    slug: "theta-pso",
    noun: "UAV",
    nouns: "UAVs",
    fixed_wing: false,
    figure_name: "best J",
    tallies: ("J finite", "feasible"),
    verdicts: ("feasible", "INFEASIBLE"),
    passed: "feasible",
    live: true,
    run_key: ('r', "run θ-PSO with the mission's seed"),
    processes_key: None,
    speed_field: None,
    bounds_advice: None,
    section: ("theta_pso", "θ-PSO parameters"),
    dwarfs_the_site: false,
    spacing_field: Some("formation.slots"),
};

impl Pipeline for ThetaPso {
    fn words(&self) -> &'static Words {
        &WORDS
    }

    fn vehicles(&self, mission: &Mission) -> usize {
        mission.formation.slots.len()
    }

    fn scene(&self, mission: &Mission, out: &mut dyn Sketch) {
        recording::iwps(mission, out);
    }

    /// The SPSO benchmark names its cost, encoding and swarm.
    fn describe(&self, mission: &Mission) -> String {
        let p = &mission.theta_pso;
        if p.cost == crate::mission::CostKind::Spso {
            format!(
                "θ-PSO, SPSO cost, {:?} encoding, {} × {}",
                p.encoding, p.swarm_size, p.iterations
            )
        } else {
            self.words().name.to_owned()
        }
    }

    /// The obstacle margin, kept beyond r_Q and the safety margin from every
    /// obstacle; verification holds it as a hard limit (eq. 7), so a plan
    /// that passes keeps it everywhere, in a named IWP's gap too. It leaves
    /// the pairs to the slots ([`Pipeline::widen_spacing`]): a margin between
    /// the UAVs could not pass the slots' own spacing.
    /// (`theta_pso.clearance_margin`, the room the cost asks for, is capped
    /// site-wide by the narrowest IWP gap.)
    fn margin_field(&self, mission: &Mission) -> Option<(&'static str, f64)> {
        Some((
            "formation.obstacle_margin",
            mission.formation.obstacle_margin,
        ))
    }

    fn add_margin(&self, mission: &mut Mission, m: f64) {
        mission.formation.obstacle_margin += m;
    }

    fn widen_spacing(&self, mission: &mut Mission, scale: f64) {
        for slot in &mut mission.formation.slots {
            *slot *= scale;
        }
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
        prepared: Option<&crate::pipelines::Prepared>,
    ) -> Vec<Diagnostic> {
        match prepared.and_then(|p| p.downcast_ref::<Vec<super::Iwp>>()) {
            Some(iwps) => super::diagnostics_given(mission, iwps),
            None => super::diagnostics(mission),
        }
    }

    /// The IWPs (eq. 9), found once per revision: the findings, the map
    /// and the run read them ([`prepared_iwps`]).
    fn prepare(&self, mission: &Mission) -> Option<crate::pipelines::Prepared> {
        Some(std::sync::Arc::new(super::find_iwps(mission)))
    }

    fn budget(&self, mission: &Mission) -> Vec<Diagnostic> {
        super::budget(mission)
    }

    /// Up to 20,000 cost evaluations per run (the paper's 100 × 150 is
    /// 15,000), 12 UAVs, 200 obstacles and a site of 40,000 m² (the bridge
    /// plans in about 0.2 s cold on two cores; a 1 m nudge of a tree of the
    /// 200-tree orchard re-plans in about 90 ms, `cargo bench --bench live`).
    fn over_live_limits(&self, mission: &Mission) -> Vec<String> {
        let p = &mission.theta_pso;
        let b = &mission.bounds;
        let evaluations = p.swarm_size.saturating_mul(p.iterations) as f64;
        let area = (b.x[1] - b.x[0]) * (b.y[1] - b.y[0]);
        crate::pipelines::live_limits(&[
            (evaluations, 20_000.0, "# cost evaluations per run"),
            (mission.formation.slots.len() as f64, 12.0, "# UAVs"),
            (mission.obstacles.len() as f64, 200.0, "# obstacles"),
            (area, 40_000.0, "a site of # m²"),
        ])
    }

    fn run(
        &self,
        mission: &Mission,
        ask: Ask<'_>,
        observer: &mut dyn Observer,
        cancel: &CancelToken,
    ) -> Result<Outcome, PipelineError> {
        let warm = match ask.request {
            crate::pipelines::Request::ThetaPso(own) => own.warm.as_deref(),
            _ => None,
        };
        super::plan::plan_given(
            mission,
            ask.seed,
            ask.options,
            warm,
            ask.revision,
            observer,
            cancel,
        )
        .map(Outcome::from)
    }
}

impl PipelineOutcome for ThetaPsoOutcome {
    fn chart(&self, view: &ChartView, out: &mut dyn Chart) {
        chart::chart(self, view, out);
    }

    fn flown_path(&self) -> Option<&[nalgebra::Point3<f64>]> {
        Some(&self.flown_path)
    }

    fn chart_side(&self, view: &ChartView, out: &mut dyn Chart) {
        chart::chart_side(self, view, out);
    }

    fn header(&self) -> &crate::pipelines::Header {
        &self.header
    }

    /// A cancelled run still has a verdict on its best plan so far: it is a
    /// whole plan.
    fn verdict(&self) -> Verdict {
        match self.verification.first_failure() {
            None if self.feasible() => Verdict::Passed,
            None => Verdict::Failed("a constraint is broken".into()),
            Some(reason) => Verdict::Failed(reason),
        }
    }

    fn headline(&self, verdict: &str) -> String {
        format!(
            "J = {:.2}, {:.1} m, {verdict}",
            self.cost.total, self.path_length
        )
    }

    fn summary(&self, verbose: bool) -> String {
        summary::theta_pso(self, verbose)
    }

    fn convergence(&self) -> &[f64] {
        &self.convergence
    }

    /// A finite J.
    fn judged(&self) -> bool {
        self.cost.total.is_finite()
    }

    /// The best J.
    fn figure(&self) -> f64 {
        self.cost.total
    }

    fn evaluations(&self) -> usize {
        self.evaluations
    }

    /// Every UAV's trajectory (eqs. 12-15).
    fn tracks(&self) -> Vec<Track> {
        self.trajectories
            .iter()
            .map(|t| Track {
                vehicle: t.uav,
                samples: t.samples.clone(),
            })
            .collect()
    }

    /// The hard limits r_Q, [2 r_Q, d_com], the band, the bounds and eq. 8:
    /// the `formation.safety_margin` the plan keeps beyond r_Q and 2 r_Q is
    /// room the reduction may use. The written legs are flown by the
    /// autopilot's own trajectory generator: their speeds are checked, not
    /// their accelerations. The margin is `theta_pso.clearance_margin`, the
    /// room the cost keeps for a real autopilot.
    fn table(&self) -> Vec<crate::pipelines::table::Row> {
        summary::table(self)
    }

    fn export_rules(&self, mission: &Mission) -> ExportRules {
        let f = &mission.formation;
        ExportRules {
            limits: Limits {
                clearance: f.uav_radius,
                closest: 2.0 * f.uav_radius,
                farthest: Some(f.comm_range),
                dynamics: false,
                ..Limits::theta_pso(mission)
            },
            airframe: Airframe::Multicopter,
            margin: mission.theta_pso.clearance_margin,
            margin_source: "theta_pso.clearance_margin",
            loiter_radius: 0.0,
            limits_note: Some(format!(
                "the files are held to r_Q = {} m from the obstacles and 2 r_Q = {} m apart; \
                 the plan was verified at r_Q + the safety margin ({} m and {} m), and that \
                 margin is the room the files may stray from it",
                crate::mission::compact(f.uav_radius),
                crate::mission::compact(2.0 * f.uav_radius),
                crate::mission::compact(f.least_clearance()),
                crate::mission::compact(f.closest_pair())
            )),
        }
    }

    fn sketch(&self, scene: Option<&Mission>, out: &mut dyn Sketch) {
        recording::sketch(self, scene, out);
    }

    fn sketch_live(&self, root: &str, out: &mut dyn Sketch) {
        recording::centroid(self, &format!("{root}/centroid"), out);
    }

    fn best_cost(&self) -> Option<f64> {
        Some(self.cost.total)
    }

    fn warm_request(&self, from: &str) -> Option<crate::pipelines::Request> {
        let warm = super::WarmStart {
            from: format!("the plan of run {from} (J {:.2})", self.cost.total),
            waypoints: self.waypoints.clone(),
            pass_angles: self.pass_angles.clone(),
            corridor: Some(self.corridor.clone()),
        };
        let warm = Some(std::sync::Arc::new(warm));
        (!self.waypoints.is_empty()).then(|| super::Request { warm }.into())
    }

    fn warm_from(&self) -> Option<String> {
        self.warm_start
            .as_ref()
            .map(|w| format!("warm from {}", w.from))
    }
}
