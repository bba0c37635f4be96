//! FLATLO on the designer's map (`pipelines::chart`): each aircraft's
//! reference (faded) and flight (its colour), where it started and where it
//! ended.

use super::FlatloOutcome;
use crate::pipelines::chart::{Chart, ChartView, Ink};

pub fn chart(o: &FlatloOutcome, view: &ChartView, out: &mut dyn Chart) {
    let xy = |p: &nalgebra::Point3<f64>| [p.x, p.y];
    for a in &o.aircraft {
        out.line(
            a.reference.iter().map(|s| xy(&s.position)).collect(),
            Ink::Faded,
        );
    }
    for a in &o.aircraft {
        let ink = if view.stale {
            Ink::Grey
        } else {
            Ink::Vehicle(a.index)
        };
        out.line(a.flown.iter().map(|s| xy(&s.position)).collect(), ink);
    }
    for a in &o.aircraft {
        let ink = Ink::Vehicle(a.index);
        out.mark(xy(&a.start), format!("{}", a.index + 1), ink);
        if let Some(end) = a.flown.last() {
            out.mark(xy(&end.position), format!("✈{}", a.index + 1), ink);
        }
    }
}
