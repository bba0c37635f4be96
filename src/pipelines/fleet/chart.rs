//! The fleet on the designer's map (`pipelines::chart`): at the replay's
//! instant, each agent's trail so far, its detection range, its reference
//! and where it is.

use super::FleetOutcome;
use crate::pipelines::chart::{Chart, ChartView, Ink};

pub fn chart(o: &FleetOutcome, view: &ChartView, out: &mut dyn Chart) {
    let t = view.at.unwrap_or(o.duration);
    let detection = view.mission.fleet.detection_range;
    for a in &o.agents {
        let ink = if view.stale {
            Ink::Grey
        } else {
            Ink::Vehicle(a.index)
        };
        let upto = a.samples.partition_point(|s| s.t <= t);
        let trail = a.samples[..upto]
            .iter()
            .map(|s| [s.position.x, s.position.y])
            .collect();
        out.line(trail, ink);
        if let Some(s) = a.samples[..upto].last() {
            out.ring([s.position.x, s.position.y], detection, Ink::Faded);
            out.mark([s.reference.x, s.reference.y], "·".into(), Ink::Plain);
            let at = [s.position.x, s.position.y];
            out.mark(at, format!("●{}", a.index + 1), ink);
        }
    }
}
