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
    assert_eq!(out.header.completion, Completion::Finished);
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
    // The aircraft do follow their references (the slowest, held at its
    // airspeed floor while it falls back onto its reference, by 40 m RMS).
    for a in &out.aircraft {
        assert!(
            a.tracking_rms < 40.0,
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
    let summary = skyform::pipelines::flatlo::summary::flatlo(&out);
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
    // Five 18.3 km apart reach 36.6 km either side of the line, and further.
    m.bounds.x = [-5_000.0, 150_000.0];
    m.bounds.y = [-45_000.0, 45_000.0];
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
    assert_eq!(out.header.completion, Completion::Cancelled);
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

/// The errors every reader of `m` sees (`check`, `run`, the designer):
/// validation and the pipelines' predictions, as `path: message`.
fn findings(m: &Mission) -> Vec<String> {
    skyform::outcome::diagnose::diagnose(m)
        .into_iter()
        .filter(|d| d.is_error())
        .map(|d| format!("{}: {}", d.path, d.message))
        .collect()
}

/// `airspeed_range`'s defaults from the airframe of `[flatlo]` (docs/flatlo.md):
/// the minimum 1.25 × the stall speed √(2W / (ρ S C_L,max)) at C_L,max = 1.8
/// (ArduPlane's AIRSPEED_MIN, "at least 25 % above the stall speed"); the
/// maximum the fastest level flight (n = 1) whose drag the full thrust meets.
#[test]
fn the_airspeed_range_defaults_follow_from_the_airframe() {
    let p = FlatloParams::default();
    let weight = p.mass * skyform::mission::GRAVITY;
    let stall = (2.0 * weight / (p.air_density * p.wing_area * 1.8)).sqrt();
    assert!((stall - 10.97).abs() < 0.005, "{stall}");
    assert_eq!(p.airspeed_range[0], (1.25 * stall * 10.0).round() / 10.0);
    let airframe = flatlo::aircraft::Airframe::from_params(&p);
    // Bisection on the drag curve's fast side (D grows with V beyond 20 m/s).
    let (mut slow, mut fast) = (20.0, 100.0);
    for _ in 0..60 {
        let v = 0.5 * (slow + fast);
        if airframe.drag(v, 1.0) < p.max_thrust {
            slow = v;
        } else {
            fast = v;
        }
    }
    assert!((slow - 54.03).abs() < 0.01, "{slow}");
    assert_eq!(p.airspeed_range[1], (slow * 10.0).floor() / 10.0);
    // The paper's slowest aircraft (14.38 m/s) and its cruise are inside.
    assert!(p.airspeed_range[0] < 14.38 && p.airspeed < p.airspeed_range[1]);
}

/// The paper's case (Section 3) stays valid and flyable: no finding, and on
/// seeds 0-9 every aircraft's flown airspeed within airspeed_range at every
/// step (the autopilot holds its envelope: before it, the slowest dipped to
/// 7.5-8.9 m/s, below the stall speed, while falling back onto its
/// reference), every bank within max_bank_deg, every aircraft and reference
/// inside the bounds: PASS, the summary says so.
#[test]
fn the_paper_case_flies_within_its_airspeeds_bank_and_bounds() {
    let m = paper_mission();
    assert_eq!(findings(&m), Vec::<String>::new());
    for seed in 0..10 {
        let out = flatlo::plan(&m, seed, &mut Silent, &CancelToken::new()).unwrap();
        let v = out.verification.as_ref().unwrap();
        assert_eq!(v.violation, None, "seed {seed}");
        let [lo, hi] = m.flatlo.airspeed_range;
        for a in &out.aircraft {
            for s in &a.flown {
                assert!(lo <= s.airspeed && s.airspeed <= hi, "seed {seed}: {s:?}");
                assert!(s.controls.bank.abs().to_degrees() <= m.flatlo.max_bank_deg);
            }
        }
        assert!(
            lo <= v.airspeed_flown[0] && v.airspeed_flown[1] <= hi,
            "{v:?}"
        );
        assert!(v.bank_flown_deg <= v.max_bank_deg);
        assert!(v.bounds_margin > 0.0, "{}", v.bounds_margin);
        let outcome = skyform::outcome::Outcome::Flatlo(Box::new(out));
        assert_eq!(outcome.verdict(), skyform::outcome::Verdict::Passed);
        let summary = outcome.summary();
        assert!(
            summary.contains("  flight       airspeed ") && summary.contains("result       PASS")
        );
    }
}

/// Issue 36's twelve: the squadron of `missions/flatlo-squadron.toml` with
/// `aircraft = 12` spans x to 325,740 m and y −109,800 to 91,504 m, far
/// outside the bounds. `check` refuses it from the references (the same
/// figure the export refused it with, 205,740 m beyond x[1]), naming the
/// aircraft, the time and the figure; so does `run` (before flying), and
/// the pipeline itself.
#[test]
fn twelve_aircraft_outside_their_bounds_are_refused_by_check_and_run() {
    let mut m = paper_mission();
    m.flatlo.aircraft = 12;
    let found = findings(&m);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].starts_with("flatlo.aircraft: 12 of the 12 aircraft leave the bounds the export judges: first, aircraft ")
            && found[0].contains("at t = 0.0 s")
            && found[0].contains("furthest, aircraft 1's reference is at x = 325740 m at t = ")
            && found[0].contains("205740 m outside bounds.x[1] = 120000 m"),
        "{found:?}"
    );
    match flatlo::plan(&m, 3, &mut Silent, &CancelToken::new()) {
        Err(skyform::pipelines::PipelineError::InvalidMission(text)) => {
            assert!(text.contains("leave the bounds"), "{text}")
        }
        other => panic!("{other:?}"),
    }
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("twelve.toml");
    std::fs::write(&file, mission::to_toml_string(&m).unwrap()).unwrap();
    for args in [vec!["check"], vec!["run", "flatlo"]] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_skyform"))
            .args(&args)
            .arg(&file)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stderr).to_string()
            + &String::from_utf8_lossy(&out.stdout);
        assert!(!out.status.success(), "{args:?}: {text}");
        assert!(
            text.contains("twelve.toml:")
                && text.contains("flatlo.aircraft")
                && text.contains("205740 m outside"),
            "{args:?}: {text}"
        );
    }
}

/// A mission for another pipeline keeps the paper's squadron as its
/// `[flatlo]` defaults, far outside its bounds: `check` leaves it be (the
/// bridge stays valid), and `run flatlo` on it fails, naming the aircraft,
/// the time and the figure, instead of passing.
#[test]
fn a_squadron_outside_another_missions_bounds_fails_its_run_naming_where() {
    let mut m = mission::default_mission().mission;
    assert_eq!(findings(&m), Vec::<String>::new());
    m.flatlo.final_leg = 1_000.0;
    let out = flatlo::plan(&m, 1, &mut Silent, &CancelToken::new()).unwrap();
    let v = out.verification.as_ref().unwrap();
    assert!(!v.passed && v.bounds_margin < 0.0, "{v:?}");
    let x = v.violation.unwrap();
    assert_eq!(x.time, 0.0, "{x:?}");
    let verdict = skyform::outcome::Outcome::Flatlo(Box::new(out)).verdict();
    let skyform::outcome::Verdict::Failed(text) = verdict else {
        panic!("{verdict:?}")
    };
    assert!(
        text.starts_with("aircraft 1")
            && text.contains("at t = 0.0 s")
            && text.contains(" bounds.z[1] = 15 m"),
        "{text}"
    );
}

/// `check` refuses a squadron whose common-arrival airspeeds (each
/// aircraft's transition length over the common duration) leave
/// `airspeed_range`, naming the aircraft and the speed; a nominal airspeed
/// outside it; turns that need more bank than `max_bank_deg`; and a range
/// that is not one, with its field path.
#[test]
fn check_refuses_airspeeds_and_banks_the_aircraft_cannot_fly() {
    let mut m = paper_mission();
    m.flatlo.airspeed_range = [15.0, 54.0];
    let found = findings(&m);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].starts_with(
            "flatlo.airspeed_range[0]: aircraft 4 would fly its transition at 14.38 m/s"
        ) && found[0].contains("below airspeed_range[0] = 15 m/s"),
        "{found:?}"
    );
    m.flatlo.airspeed_range = [10.0, 25.0];
    let found = findings(&m);
    assert!(
        found
            .iter()
            .any(|f| f.starts_with("flatlo.airspeed: the nominal airspeed 30.5 m/s is outside")),
        "{found:?}"
    );
    let mut m = paper_mission();
    m.flatlo.max_bank_deg = 1.0;
    let found = findings(&m);
    assert!(
        found.len() == 1
            && found[0].starts_with("flatlo.max_bank_deg: aircraft 1's turns of 4575 m radius at 30.50 m/s need a bank of 1.2°"),
        "{found:?}"
    );
    let mut m = paper_mission();
    m.flatlo.airspeed_range = [40.0, 20.0];
    assert!(
        findings(&m)
            .iter()
            .any(|f| f.starts_with("flatlo.airspeed_range: is inverted"))
    );
    m.flatlo.airspeed_range = [-1.0, 20.0];
    assert!(
        findings(&m)
            .iter()
            .any(|f| f.starts_with("flatlo.airspeed_range[0]: must be positive"))
    );
}

/// A squadron `check` passes but whose flight leaves the range: with a
/// minimum of 14.3 m/s the slowest aircraft's plan (14.38 m/s) leaves the
/// autopilot no guard, and the noise takes it below: `run` fails, naming
/// the aircraft, the time, the figure and the limit (the first violation).
#[test]
fn a_flight_that_leaves_its_airspeed_range_fails_naming_the_first_violation() {
    let mut m = paper_mission();
    m.flatlo.airspeed_range = [14.3, 54.0];
    assert_eq!(findings(&m), Vec::<String>::new());
    let out = flatlo::plan(&m, 3, &mut Silent, &CancelToken::new()).unwrap();
    let v = out.verification.as_ref().unwrap();
    let x = v
        .violation
        .unwrap_or_else(|| panic!("flew {:?}", v.airspeed_flown));
    assert_eq!((x.aircraft, x.reference), (3, false), "{x:?}");
    assert!(x.value < 14.3 && x.limit == 14.3 && x.time > 0.0, "{x:?}");
    // It is the first: no step of any aircraft before it was below.
    for a in &out.aircraft {
        for s in a.flown.iter().filter(|s| s.t < x.time) {
            assert!(s.airspeed >= 14.3, "{s:?} before {x:?}");
        }
    }
    assert!(!v.passed);
    let verdict = skyform::outcome::Outcome::Flatlo(Box::new(out)).verdict();
    let expected = format!(
        "aircraft 4 flew {:.2} m/s at t = {:.1} s, below airspeed_range[0] = 14.3 m/s",
        x.value, x.time
    );
    assert_eq!(verdict, skyform::outcome::Verdict::Failed(expected));
}
