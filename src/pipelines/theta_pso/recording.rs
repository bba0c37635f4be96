//! θ-PSO in a recording (`pipelines::sketch`): the planned paths, the UAVs
//! on `sim_time`, their clearances, reconfigurations, inspection passes and
//! violations. The swarm's progress on the `iteration` timeline (cost terms,
//! best path) is logged by the recorder from the run's events.

use nalgebra::Point3;

use super::ThetaPsoOutcome;
use crate::mission::Mission;
use crate::pipelines::sketch::{Note, Plot, Sketch, Style};

/// θ-PSO's entity paths.
pub mod paths {
    /// The run's property and the root of its entities.
    pub const ROOT: &str = "theta_pso";
    /// Events on `sim_time` (reconfigurations, passes, violations).
    pub const EVENTS: &str = "theta_pso/events";
    /// The cost terms on the `iteration` timeline, one series per term
    /// (`CostTerms::named`: `theta_pso/cost/J_total`, …), and the swarm's
    /// best centroid path of each iteration at `theta_pso/best_path`,
    /// logged by the recorder from the run's events.
    pub const COST: &str = "theta_pso/cost";
    pub const CLEARANCE: &str = "theta_pso/clearance";
    pub const CENTROID: &str = "theta_pso/plan/centroid";
    pub const VIOLATIONS: &str = "theta_pso/violations";
    /// The mission's IWPs, in the static scene beside the obstacles.
    pub const IWPS: &str = "world/iwps";

    /// UAV `uav` (0-based) is named from 1.
    pub fn clearance(uav: usize) -> String {
        format!("{CLEARANCE}/uav_{}", uav + 1)
    }

    pub fn plan(uav: usize) -> String {
        format!("theta_pso/plan/uav_{}", uav + 1)
    }

    pub fn uav(uav: usize) -> String {
        format!("theta_pso/uavs/uav_{}", uav + 1)
    }

    /// The stretch of the centroid path inspecting `obstacle`.
    pub fn pass(obstacle: &str) -> String {
        format!("theta_pso/plan/pass_{}", obstacle.replace([' ', '/'], "_"))
    }
}

/// The plots beside the scene: the clearance plays with the flight on
/// `sim_time`, the timeline the viewer opens on; the cost is on
/// `iteration`, in the tab behind.
pub const PLOTS: &[&[Plot]] = &[&[
    Plot {
        title: "clearance to obstacles, m",
        path: paths::CLEARANCE,
    },
    Plot {
        title: "θ-PSO cost (timeline: iteration)",
        path: paths::COST,
    },
]];

/// The mission's IWPs (eq. 9) at mid-band, each labelled with its pair,
/// yellow when enabled, grey when not: what the crossings will be.
pub fn iwps(m: &Mission, out: &mut dyn Sketch) {
    let iwps = super::find_iwps(m);
    if iwps.is_empty() {
        return;
    }
    let z = (m.bounds.z[0] + m.bounds.z[1]) / 2.0;
    let marks = iwps
        .iter()
        .map(|i| {
            let state = if i.enabled { "" } else { " (disabled)" };
            let color = if i.enabled {
                [250, 200, 0]
            } else {
                [120, 120, 120]
            };
            (
                Point3::new(i.position.x, i.position.y, z),
                Style::rgb(color)
                    .radius(0.4)
                    .label(format!("IWP {} | {}{state}", i.between[0], i.between[1])),
            )
        })
        .collect();
    out.marks(paths::IWPS, marks);
}

/// The plan's centroid path, white and labelled: the outcome's and each
/// live revision's.
pub fn centroid(o: &ThetaPsoOutcome, path: &str, out: &mut dyn Sketch) {
    out.strips(
        path,
        vec![o.centroid_path.clone()],
        Style::rgb([255, 255, 255]).label("centroid"),
    );
}

/// A θ-PSO outcome: planned paths, UAVs moving on `sim_time`, events,
/// violations; each UAV's clearance when the mission is known.
pub fn sketch(o: &ThetaPsoOutcome, scene: Option<&Mission>, out: &mut dyn Sketch) {
    if let Some(m) = scene {
        clearances(o, m, out);
    }
    out.property(
        paths::ROOT,
        format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\niterations: {}\n\
             feasible: {}\ncost J: {:.4}\nlength: {:.2} m\nduration: {:.2} s\nskyform: {}",
            o.header.mission,
            o.header.pipeline.words().slug,
            o.header.seed,
            o.header.completion,
            o.iterations,
            o.feasible(),
            o.cost.total,
            o.path_length,
            o.duration,
            env!("CARGO_PKG_VERSION")
        ),
    );
    centroid(o, paths::CENTROID, out);
    trajectories(o, out);
    reconfigurations(o, out);
    passes(o, out);
    violations(o, out);
}

/// Each UAV's clearance over `sim_time`: the distance from its sphere of
/// radius r_Q + the safety margin to the nearest obstacle (terrain-raised),
/// 0 = the least verification accepts. The plot beside the scene on the
/// timeline the flight plays on.
fn clearances(o: &ThetaPsoOutcome, m: &Mission, out: &mut dyn Sketch) {
    let prisms: Vec<_> = m.obstacles.iter().map(|ob| m.prism(ob)).collect();
    if prisms.is_empty() {
        return;
    }
    for t in &o.trajectories {
        let times: Vec<f64> = t.samples.iter().map(|s| s.t).collect();
        let values = t
            .samples
            .iter()
            .map(|s| {
                prisms
                    .iter()
                    .map(|c| c.clearance(&s.position))
                    .fold(f64::INFINITY, f64::min)
                    - m.formation.least_clearance()
            })
            .collect();
        out.series(
            &paths::clearance(t.uav),
            &times,
            values,
            Some(Style::vehicle(t.uav).label(format!("UAV {}", t.uav + 1))),
        );
    }
}

/// Each UAV's planned path (static), and the UAV with its velocity on `sim_time`.
fn trajectories(o: &ThetaPsoOutcome, out: &mut dyn Sketch) {
    for t in &o.trajectories {
        let name = format!("UAV {}", t.uav + 1);
        let positions: Vec<Point3<f64>> = t.samples.iter().map(|s| s.position).collect();
        out.strips(
            &paths::plan(t.uav),
            vec![positions.clone()],
            Style::vehicle(t.uav).label(name.clone()),
        );
        let times: Vec<f64> = t.samples.iter().map(|s| s.t).collect();
        let uav = paths::uav(t.uav);
        out.moving_point(
            &uav,
            &times,
            &positions,
            Style::vehicle(t.uav).radius(0.5).label(name),
        );
        let velocities: Vec<_> = t.samples.iter().map(|s| s.velocity).collect();
        out.moving_arrows(
            &format!("{uav}/velocity"),
            &times,
            &positions,
            &velocities,
            Style::vehicle(t.uav),
        );
    }
}

/// t1..t4 of each reconfiguration, as events on `sim_time`.
fn reconfigurations(o: &ThetaPsoOutcome, out: &mut dyn Sketch) {
    for r in &o.reconfigurations {
        for (label, t) in [
            ("t1: transformation starts", r.t1),
            ("t2: shape complete", r.t2),
            ("t3: return starts", r.t3),
            ("t4: back to nominal", r.t4),
        ] {
            out.event(
                paths::EVENTS,
                t,
                format!("{} {}: {label}", r.shape.name(), r.obstacles()),
                Note::Info,
            );
        }
    }
}

/// Inspection passes (eq. 8): the centroid's stretch, and when each begins and ends.
fn passes(o: &ThetaPsoOutcome, out: &mut dyn Sketch) {
    for (pass, result) in o.passes.iter().zip(&o.verification.inspections) {
        let [t0, t1] = pass.time;
        let steps = 20;
        let stretch: Vec<Point3<f64>> = (0..=steps)
            .map(|k| o.centroid_at(t0 + (t1 - t0) * k as f64 / steps as f64))
            .collect();
        out.strips(
            &paths::pass(&pass.obstacle),
            vec![stretch],
            Style::rgb([230, 110, 230])
                .radius(0.25)
                .label(format!("inspection of {}", pass.obstacle)),
        );
        for (label, t) in [("inspection pass starts", t0), ("inspection pass ends", t1)] {
            let achieved = result.distance.map_or_else(
                || "no stretch within the band".to_owned(),
                |[lo, hi]| {
                    format!(
                        "{:.1} m within the band, at {lo:.2}-{hi:.2} m",
                        result.achieved
                    )
                },
            );
            out.event(
                paths::EVENTS,
                t,
                format!("{label}: '{}' ({achieved})", pass.obstacle),
                if result.ok { Note::Info } else { Note::Warn },
            );
        }
    }
}

/// Each violation found by verification: a red point and a warning event.
fn violations(o: &ThetaPsoOutcome, out: &mut dyn Sketch) {
    for v in &o.verification.violations {
        let other = v.location.other.as_deref().unwrap_or("");
        out.points_at(
            paths::VIOLATIONS,
            v.location.time,
            vec![v.location.position],
            Style::rgb([255, 0, 0])
                .radius(0.8)
                .label(format!("{} {:.2} {other}", v.check, v.value)),
        );
        out.event(
            paths::EVENTS,
            v.location.time,
            format!(
                "violation: UAV {} {} = {:.3} {other}",
                v.location.uav + 1,
                v.check,
                v.value
            ),
            Note::Warn,
        );
    }
}
