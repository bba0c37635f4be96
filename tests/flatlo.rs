//! FLATLO against its paper: the theorem of Section 4.2 on the exact
//! references, and the simulated squadron of Section 3.

use nalgebra::Point3;
use skyform::mission::{self, FlatloParams, Mission};
use skyform::pipelines::flatlo::{self, algorithm, line_spacing};
use skyform::pipelines::{CancelToken, Completion, Silent};

fn paper_mission() -> Mission {
    mission::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/missions/flatlo-squadron.toml"
    )))
    .unwrap()
    .mission
}

/// Theorem 1 (Section 4.2): whatever N, the noise-free references end in one
/// line along the original direction, neighbours Δ_d apart, and every
/// aircraft reaches it at the same instant.
#[test]
fn theorem_1_references_end_in_a_line_spaced_by_delta_d_for_n_2_to_12() {
    for n in 2..=12 {
        for (heading, spacing, climb) in [
            (0.0, 18_300.0, 0.0),
            (37.0, 9_000.0, 0.0),
            (-120.0, 25_000.0, 0.0),
            (15.0, 18_300.0, 10.0),
        ] {
            let p = FlatloParams {
                aircraft: n,
                spacing,
                heading_deg: heading,
                climb_deg: climb,
                start: nalgebra::Point2::new(1_000.0, -2_000.0),
                ..FlatloParams::default()
            };
            let plan = flatlo::references(&p);
            let line =
                algorithm::line_direction(p.heading_deg.to_radians(), p.climb_deg.to_radians());
            // At the common arrival time each aircraft is exactly at the end of
            // its transition: they arrive together.
            let mut at_arrival = Vec::new();
            for r in &plan.references {
                assert!(
                    (r.distance(plan.arrival) - r.transition_length).abs()
                        <= 1e-9 * r.transition_length
                );
                assert!(r.airspeed <= p.airspeed * (1.0 + 1e-12));
                at_arrival.push(r.at(plan.arrival, &mut 0).position);
            }
            for points in [
                at_arrival,
                plan.references
                    .iter()
                    .map(|r| r.at(plan.duration, &mut 0).position)
                    .collect::<Vec<Point3<f64>>>(),
            ] {
                let (spacing_list, spread) = line_spacing(&points, &line);
                assert_eq!(spacing_list.len(), n - 1);
                for s in &spacing_list {
                    let error = (s.spacing - spacing).abs() / spacing;
                    assert!(
                        error < 1e-9,
                        "N={n} heading {heading}: {} → {} spaced {} (error {error:e})",
                        s.front,
                        s.back,
                        s.spacing
                    );
                }
                assert!(spread / spacing < 1e-9, "N={n}: lateral spread {spread} m");
                // One straight line along t(φ, β), climbing or not.
                for q in &points {
                    let d = q - points[0];
                    let off = (d - line * d.dot(&line)).norm();
                    assert!(
                        off / spacing < 1e-9,
                        "N={n} climb {climb}: {off} m off the line"
                    );
                }
                // Aircraft 0 leads and the order is by index (Algorithm 2).
                let order: Vec<usize> = std::iter::once(spacing_list[0].front)
                    .chain(spacing_list.iter().map(|s| s.back))
                    .collect();
                assert_eq!(order, (0..n).collect::<Vec<_>>());
            }
        }
    }
}

/// Section 4.1: the references are O(m) in the samples: sampling twice as
/// finely gives twice the samples, and each sample lies on the reference.
#[test]
fn sampling_is_linear_in_the_number_of_samples() {
    let p = FlatloParams::default();
    let plan = flatlo::references(&p);
    let coarse = flatlo::sample(&plan.references[0], 2.0, plan.duration);
    let fine = flatlo::sample(&plan.references[0], 1.0, plan.duration);
    assert_eq!(coarse.len(), (plan.duration / 2.0).ceil() as usize + 1);
    assert_eq!(fine.len(), (plan.duration / 1.0).ceil() as usize + 1);
    // Consecutive samples are one period of flight apart (straight or nearly).
    for w in fine.windows(2).take(100) {
        let step = (w[1].position - w[0].position).norm();
        assert!((step - plan.references[0].airspeed).abs() < 1e-6, "{step}");
    }
}

/// Section 3: the paper's case (N = 4, Δ_d = 18,300 m, r = 4,575 m,
/// 30.5 m/s, 0.25 % noise) simulated with RK4 keeps its spacing within 1 % and
/// never comes closer than 15 km (the paper reports 14.5 km for its closest pair).
#[test]
fn the_paper_case_flies_into_line_without_coming_close() {
    let m = paper_mission();
    assert_eq!(m.flatlo.noise, 0.0025);
    let out = flatlo::plan(&m, m.seed, &mut Silent, &CancelToken::new()).unwrap();
    assert_eq!(out.completion, Completion::Finished);
    let v = out.verification.as_ref().unwrap();
    assert!(v.passed);
    assert!(
        v.max_spacing_error < 0.01,
        "spacing error {}",
        v.max_spacing_error
    );
    for s in &v.final_spacing {
        assert!((s.spacing - 18_300.0).abs() < 183.0, "{s:?}");
    }
    assert!(
        v.lateral_spread < 100.0,
        "lateral spread {} m",
        v.lateral_spread
    );
    let closest = out.closest.unwrap();
    assert!(closest.min_distance > 15_000.0, "{closest:?}");
    assert_eq!(out.pairs.len(), 6);
    // The closest pair overall is the closest of the pair table.
    let table_min = out
        .pairs
        .iter()
        .map(|p| p.min_distance)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(closest.min_distance, table_min);
    // The aircraft do follow their references.
    for a in &out.aircraft {
        assert!(
            a.tracking_rms < 20.0,
            "aircraft {}: RMS {}",
            a.index,
            a.tracking_rms
        );
        assert!(
            a.tracking_max < 250.0,
            "aircraft {}: max {}",
            a.index,
            a.tracking_max
        );
    }
    // The slowest aircraft flies its transition at 14.4 m/s.
    let slowest = out
        .aircraft
        .iter()
        .map(|a| a.airspeed)
        .fold(f64::MAX, f64::min);
    assert!((slowest - 14.381).abs() < 1e-3, "{slowest}");
}

/// Issue 24, item 17: the summary numbers the aircraft of the final line
/// from 1, as it numbers them everywhere else (aircraft 1-4, not 0→1).
#[test]
fn the_summary_numbers_the_final_line_from_one() {
    let m = paper_mission();
    let out = flatlo::plan(&m, m.seed, &mut Silent, &CancelToken::new()).unwrap();
    let summary = skyform::outcome::summary::flatlo(&out);
    let line = summary
        .lines()
        .find(|l| l.contains("final line"))
        .unwrap_or_else(|| panic!("no final line in\n{summary}"));
    let mut named: Vec<usize> = line
        .split(", ")
        .flat_map(|pair| {
            let pair = pair.trim_start_matches("  final line").trim();
            let ends = pair.split(' ').next().unwrap_or_default();
            ends.split('→')
                .map(|n| n.parse::<usize>().unwrap_or_else(|_| panic!("{line}")))
                .collect::<Vec<_>>()
        })
        .collect();
    named.sort_unstable();
    named.dedup();
    assert_eq!(named, [1, 2, 3, 4], "{line}");
}

#[test]
fn the_same_seed_gives_the_same_flight_and_another_seed_another() {
    let mut m = paper_mission();
    m.flatlo.final_leg = 2_000.0;
    let a = flatlo::plan(&m, 11, &mut Silent, &CancelToken::new()).unwrap();
    let b = flatlo::plan(&m, 11, &mut Silent, &CancelToken::new()).unwrap();
    assert_eq!(a, b);
    let c = flatlo::plan(&m, 12, &mut Silent, &CancelToken::new()).unwrap();
    assert_ne!(a.aircraft[0].flown, c.aircraft[0].flown);
    // Without noise the seed does not matter.
    m.flatlo.noise = 0.0;
    let d = flatlo::plan(&m, 1, &mut Silent, &CancelToken::new()).unwrap();
    let e = flatlo::plan(&m, 2, &mut Silent, &CancelToken::new()).unwrap();
    assert_eq!(d.aircraft, e.aircraft);
}

#[test]
fn an_odd_squadron_puts_its_middle_aircraft_in_front() {
    let mut m = paper_mission();
    m.flatlo.aircraft = 5;
    m.flatlo.noise = 0.0;
    let out = flatlo::plan(&m, 0, &mut Silent, &CancelToken::new()).unwrap();
    let v = out.verification.as_ref().unwrap();
    assert_eq!(v.final_spacing[0].front, 0);
    assert!(v.max_spacing_error < 0.01, "{v:?}");
    assert!(v.passed);
}

#[test]
fn a_too_small_separation_threshold_is_a_failed_verification_not_an_error() {
    let mut m = paper_mission();
    m.flatlo.min_separation = 20_000.0;
    m.flatlo.final_leg = 1_000.0;
    let out = flatlo::plan(&m, 1, &mut Silent, &CancelToken::new()).unwrap();
    assert!(!out.passed());
    assert!(out.closest.unwrap().min_distance < 20_000.0);
}

#[test]
fn cancel_stops_the_simulation_early() {
    let m = paper_mission();
    let cancel = CancelToken::new();
    cancel.cancel();
    let out = flatlo::plan(&m, 1, &mut Silent, &cancel).unwrap();
    assert_eq!(out.completion, Completion::Cancelled);
    let flown = out.aircraft[0].flown.last().unwrap().t;
    assert!(flown < 120.0, "stopped after the first chunk, at {flown} s");
    // A partial flight gets no verdict, pass or fail.
    assert!(out.verification.is_none());
    assert!(!out.passed());
}

/// What is kept per aircraft is bounded however long the flight: the paper
/// case flies ~5,800 s sampled every second; with a 0.1 s sample period
/// that is 58,000 samples, decimated to at most `KEPT_SAMPLES` (+ the last).
#[test]
fn kept_samples_are_bounded_and_include_the_end() {
    let mut m = paper_mission();
    m.flatlo.sample_period = 0.1;
    let out = flatlo::plan(&m, 1, &mut Silent, &CancelToken::new()).unwrap();
    assert!(out.sample_stride > 1, "stride {}", out.sample_stride);
    for a in &out.aircraft {
        assert!(
            a.flown.len() <= flatlo::KEPT_SAMPLES + 1,
            "{}",
            a.flown.len()
        );
        assert!(
            a.reference.len() <= flatlo::KEPT_SAMPLES + 2,
            "{}",
            a.reference.len()
        );
        let end = a.flown.last().unwrap().t;
        assert!(
            (end - out.duration).abs() <= m.flatlo.sim_step,
            "{end} vs {}",
            out.duration
        );
    }
}

/// Large squadrons keep no pair table; the swept closest pair must be the
/// brute-force minimum over every pair at every sample instant. With the
/// stride at 1 (short flight) the kept samples are all the samples.
#[test]
fn a_large_squadron_finds_the_same_closest_pair_as_brute_force() {
    let mut m = paper_mission();
    m.flatlo.aircraft = 16;
    m.flatlo.spacing = 500.0;
    m.flatlo.turn_radius = 150.0;
    m.flatlo.final_leg = 500.0;
    let out = flatlo::plan(&m, 2, &mut Silent, &CancelToken::new()).unwrap();
    assert!(out.pairs.is_empty());
    assert_eq!(out.sample_stride, 1);
    let mut best = (f64::INFINITY, 0, 0, 0.0);
    for a in 0..out.aircraft.len() {
        for b in a + 1..out.aircraft.len() {
            for (sa, sb) in out.aircraft[a].flown.iter().zip(&out.aircraft[b].flown) {
                let d = (sa.position - sb.position).norm();
                if d < best.0 {
                    best = (d, a, b, sa.t);
                }
            }
        }
    }
    let c = out.closest.unwrap();
    assert_eq!((c.min_distance, c.a, c.b, c.time), best);
}
