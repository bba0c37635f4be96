//! What a recording of a flight check shows (`record::flight` draws it):
//! each vehicle's plan as written, the p99 envelope of its cross-track
//! error, the worst flights as flown, and flights flown again from their
//! inputs (a rare-event estimate's most likely failures).

use nalgebra::Point3;

use super::report::{self, Report};
use super::{Flown, Options, SAMPLE_EVERY, Setup, Track, fly};
use crate::export::reverify::Flight;

/// What a recording of a check shows (`record::flight`): each vehicle's
/// plan as written, the p99 of its cross-track error along it (the
/// envelope: a tube of that radius), and the worst flights as flown.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    pub mission: String,
    /// The instants of the samples, seconds on the plan's clock.
    pub times: Vec<f64>,
    /// Per vehicle (1-based number, its as-written positions at `times`).
    pub written: Vec<(usize, Vec<Point3<f64>>)>,
    /// Per vehicle, the p99 cross-track error at each of `times`, metres.
    pub envelope: Vec<Vec<f64>>,
    /// The worst flights: (flight, its vehicles' tracks).
    pub worst: Vec<(usize, Vec<Track>)>,
    /// Flights flown again from their inputs (a rare-event estimate's most
    /// likely failures): (its name, its vehicles' tracks).
    pub failing: Vec<(String, Vec<Track>)>,
}

impl Recording {
    /// A recording of flights flown again from their inputs: the plan as
    /// written over their time, no envelope, the flights as flown.
    pub fn of_failing(setup: &Setup, failing: Vec<(String, Vec<Track>)>) -> Recording {
        let dt = setup.mission.flight.step * SAMPLE_EVERY as f64;
        let end = failing
            .iter()
            .flat_map(|(_, tracks)| tracks.iter().filter_map(|t| t.last().map(|s| s.0)))
            .fold(setup.planned_end, f64::max);
        let start = setup.start();
        let samples = ((end - start) / dt).ceil().max(0.0) as usize + 1;
        let times: Vec<f64> = (0..samples).map(|k| start + k as f64 * dt).collect();
        Recording {
            mission: setup.mission.name.clone(),
            written: written(setup, &times),
            envelope: vec![Vec::new(); setup.plans.len()],
            times,
            worst: Vec::new(),
            failing,
        }
    }
}

/// Each vehicle's position as written at `times`: (its 1-based number,
/// the positions).
fn written(setup: &Setup, times: &[f64]) -> Vec<(usize, Vec<Point3<f64>>)> {
    setup
        .plans
        .iter()
        .map(|p| {
            let schedule = Flight::new(p);
            (
                p.vehicle + 1,
                times.iter().map(|&t| schedule.at(t).0).collect(),
            )
        })
        .collect()
}

/// The flights recorded as the worst: this many.
pub const RECORDED_WORST: usize = 3;

/// What a recording shows, from the flights of a check flown with their
/// cross-track samples kept ([`check_recorded`]): the envelope, and the
/// [`RECORDED_WORST`] worst flights' tracks (the report's worst, then the
/// flights where the tightest pairs and obstacles were worst), flown again.
pub(super) fn recording(
    setup: &Setup,
    options: Options,
    report: &Report,
    flown: &[Flown],
) -> Recording {
    let spreads: Vec<&Vec<Vec<f32>>> = flown.iter().filter_map(|f| f.spread.as_ref()).collect();
    let dt = setup.mission.flight.step * SAMPLE_EVERY as f64;
    let samples = spreads
        .iter()
        .copied()
        .flatten()
        .map(Vec::len)
        .max()
        .unwrap_or(0);
    let start = setup.start();
    let times: Vec<f64> = (0..samples).map(|k| start + k as f64 * dt).collect();
    let envelope = (0..setup.plans.len())
        .map(|v| {
            (0..samples)
                .map(|k| {
                    // A flight that finished early holds its last sample.
                    let mut at: Vec<f64> = spreads
                        .iter()
                        .filter_map(|f| f[v].get(k).or(f[v].last()).map(|x| f64::from(*x)))
                        .collect();
                    at.sort_by(f64::total_cmp);
                    report::quantile(&at, 0.99)
                })
                .collect()
        })
        .collect();
    let written = written(setup, &times);
    let mut chosen: Vec<usize> = Vec::new();
    let candidates = report.worst.iter().map(|w| w.flight).chain(
        report
            .pairs
            .iter()
            .map(|p| p.closest.worst_flight)
            .chain(report.obstacles.iter().map(|o| o.clearance.worst_flight)),
    );
    for k in candidates {
        if chosen.len() < RECORDED_WORST && !chosen.contains(&k) {
            chosen.push(k);
        }
    }
    let worst = chosen
        .into_iter()
        .map(|k| {
            (
                k,
                fly(setup, options.seed, k, true).tracks.unwrap_or_default(),
            )
        })
        .collect();
    Recording {
        mission: setup.mission.name.clone(),
        times,
        written,
        envelope,
        worst,
        failing: Vec::new(),
    }
}
