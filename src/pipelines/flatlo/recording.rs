//! FLATLO in a recording (`pipelines::sketch`): references and flown paths
//! per aircraft, the aircraft on `sim_time`, their airspeed, γ, χ and
//! controls as series, the closest approaches as events.

use super::{FlatloOutcome, FlownSample};
use crate::pipelines::sketch::{Note, Plot, Sketch, Style};

/// FLATLO's entity paths, per aircraft (0-based, as `aircraft_0`).
pub mod paths {
    /// The run's property and the root of its entities.
    pub const ROOT: &str = "flatlo";
    /// Events on `sim_time` (the arrival, closest approaches, the first limit broken).
    pub const EVENTS: &str = "flatlo/events";
    pub const AIRSPEED: &str = "flatlo/airspeed";
    pub const LOAD_FACTOR: &str = "flatlo/load_factor";

    /// `part` is `reference`, `flown`, `aircraft` or a series (`airspeed`, …).
    pub fn aircraft(part: &str, index: usize) -> String {
        format!("flatlo/{part}/aircraft_{index}")
    }
}

/// The plots beside the scene.
pub const PLOTS: &[&[Plot]] = &[
    &[Plot {
        title: "airspeed, m/s",
        path: paths::AIRSPEED,
    }],
    &[Plot {
        title: "load factor",
        path: paths::LOAD_FACTOR,
    }],
];

/// A FLATLO outcome.
pub fn sketch(o: &FlatloOutcome, out: &mut dyn Sketch) {
    let min_separation = o.verification.as_ref().map_or(0.0, |v| v.min_separation);
    out.property(
        paths::ROOT,
        format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\naircraft: {}\n\
             arrival: {:.1} s\nduration: {:.1} s\nclosest: {}\nspacing error: {}\n\
             passed: {}\nskyform: {}",
            o.header.mission,
            o.header.pipeline.words().slug,
            o.header.seed,
            o.header.completion,
            o.aircraft.len(),
            o.arrival_time,
            o.duration,
            o.closest.map_or("-".to_owned(), |c| format!(
                "{} and {} at {:.0} m",
                c.a + 1,
                c.b + 1,
                c.min_distance
            )),
            o.verification
                .as_ref()
                .map_or("-".to_owned(), |v| format!("{:.3e}", v.max_spacing_error)),
            o.verification
                .as_ref()
                .map_or("no verdict (cancelled)".to_owned(), |v| v
                    .passed
                    .to_string()),
            env!("CARGO_PKG_VERSION")
        ),
    );
    for a in &o.aircraft {
        let name = format!("aircraft {}", a.index + 1);
        out.strips(
            &paths::aircraft("reference", a.index),
            vec![a.reference.iter().map(|s| s.position).collect()],
            Style::rgb([170, 170, 170]).label(format!("reference {}", a.index)),
        );
        let flown: Vec<_> = a.flown.iter().map(|s| s.position).collect();
        out.strips(
            &paths::aircraft("flown", a.index),
            vec![flown.clone()],
            Style::vehicle(a.index).label(name.clone()),
        );
        let times: Vec<f64> = a.flown.iter().map(|s| s.t).collect();
        out.moving_point(
            &paths::aircraft("aircraft", a.index),
            &times,
            &flown,
            Style::vehicle(a.index).radius(150.0).label(name),
        );
        type Series = fn(&FlownSample) -> f64;
        let series: [(&str, Series); 6] = [
            ("airspeed", |s| s.airspeed),
            ("gamma_deg", |s| s.gamma.to_degrees()),
            ("chi_deg", |s| s.chi.to_degrees()),
            ("thrust", |s| s.controls.thrust),
            ("load_factor", |s| s.controls.load_factor),
            ("bank_deg", |s| s.controls.bank.to_degrees()),
        ];
        for (quantity, value) in series {
            out.series(
                &paths::aircraft(quantity, a.index),
                &times,
                a.flown.iter().map(value).collect(),
                None,
            );
        }
    }
    out.event(
        paths::EVENTS,
        o.arrival_time,
        format!(
            "every aircraft on the longitudinal line at t = {:.1} s",
            o.arrival_time
        ),
        Note::Info,
    );
    let closest_only: Vec<_> = o.closest.into_iter().collect();
    let pairs = if o.pairs.is_empty() {
        &closest_only
    } else {
        &o.pairs
    };
    for p in pairs {
        out.event(
            paths::EVENTS,
            p.time,
            format!(
                "closest approach of aircraft {} and {}: {:.0} m",
                p.a + 1,
                p.b + 1,
                p.min_distance
            ),
            Note::closest(p.min_distance < min_separation),
        );
    }
    // The first limit of the flight broken, at its time.
    if let Some(v) = o.verification.as_ref().and_then(|v| v.violation) {
        out.event(
            paths::EVENTS,
            v.time,
            format!("not flyable: {}", v.describe()),
            Note::Warn,
        );
    }
}
