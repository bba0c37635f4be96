//! θ-PSO on the designer's map (`pipelines::chart`): each UAV's trajectory,
//! the centroid's path, the reconfiguration zones [t1, t4] and the
//! inspection passes (eq. 8) along it, and where verification failed; in
//! the side view, each UAV's altitude along the flown path.

use super::ThetaPsoOutcome;
use crate::pipelines::chart::{Chart, ChartView, Ink};

/// Top down.
pub fn chart(o: &ThetaPsoOutcome, view: &ChartView, out: &mut dyn Chart) {
    for (k, t) in o.trajectories.iter().enumerate() {
        let ink = if view.stale {
            Ink::Faded
        } else {
            Ink::Vehicle(k)
        };
        out.line(
            t.samples
                .iter()
                .map(|s| [s.position.x, s.position.y])
                .collect(),
            ink,
        );
    }
    let ink = if view.stale { Ink::Grey } else { Ink::Plain };
    out.line(o.centroid_path.iter().map(|p| [p.x, p.y]).collect(), ink);
    out.layer();
    if !view.stale {
        for r in &o.reconfigurations {
            out.line(centroid_between(o, r.t1, r.t4), Ink::Zone);
        }
        for pass in &o.passes {
            out.line(centroid_between(o, pass.time[0], pass.time[1]), Ink::Pass);
        }
    }
    let at =
        |v: &crate::pipelines::verify::Violation| [v.location.position.x, v.location.position.y];
    for v in o.verification.violations.iter().take(50) {
        out.mark(at(v), "✗".into(), Ink::Fault);
    }
    // A live plan says at once where it fails: the first violation named.
    if let (false, true, Some(v)) = (view.stale, view.live, o.verification.violations.first()) {
        let with = v
            .location
            .other
            .as_ref()
            .map_or_else(String::new, |other| format!(" vs {other}"));
        let text = format!(
            "✗ UAV {} {} {:.2}{with}",
            v.location.uav + 1,
            v.check,
            v.value
        );
        out.mark(at(v), text, Ink::Fault);
    }
}

/// Along the flown path (`ThetaPsoOutcome::flown_path`): each UAV's
/// altitude where the centroid is.
pub fn chart_side(o: &ThetaPsoOutcome, view: &ChartView, out: &mut dyn Chart) {
    for (k, t) in o.trajectories.iter().enumerate() {
        let ink = if view.stale {
            Ink::Faded
        } else {
            Ink::Vehicle(k)
        };
        let pts = t
            .samples
            .iter()
            .zip(&o.flown_arcs)
            .map(|(s, along)| [*along, s.position.z])
            .collect();
        out.line(pts, ink);
    }
}

/// The formation centroid (mean of the UAVs) from time `t0` to `t1`, x-y.
fn centroid_between(o: &ThetaPsoOutcome, t0: f64, t1: f64) -> Vec<[f64; 2]> {
    let Some(first) = o.trajectories.first() else {
        return Vec::new();
    };
    let n = o.trajectories.len() as f64;
    (0..first.samples.len())
        .filter(|&k| (t0..=t1).contains(&first.samples[k].t))
        .map(|k| {
            let (mut x, mut y) = (0.0, 0.0);
            for t in &o.trajectories {
                if let Some(s) = t.samples.get(k) {
                    x += s.position.x;
                    y += s.position.y;
                }
            }
            [x / n, y / n]
        })
        .collect()
}
