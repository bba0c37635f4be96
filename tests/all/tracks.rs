//! Per-vehicle tracks, one shape for every pipeline (issue 13): each
//! pipeline's tracks match what it computed, and they are in the JSON.

use nalgebra::Point3;
use skyform::mission::{self, BUILTIN, Mission};
use skyform::outcome::{self, Outcome, Verdict};
use skyform::pipelines::theta_pso::PlanOptions;
use skyform::pipelines::{CancelToken, Kind, Silent};

fn shipped(name: &str) -> Mission {
    let b = BUILTIN.iter().find(|b| b.file_name == name).unwrap();
    mission::parse_str(b.text, b.file_name).unwrap().mission
}

fn run(kind: Kind, m: &Mission) -> Outcome {
    outcome::run(
        kind,
        m,
        m.seed,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap()
}

fn distance_to_polyline(points: &[Point3<f64>], p: &Point3<f64>) -> f64 {
    points
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let ab = b - a;
            let t = if ab.norm_squared() > 0.0 {
                ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (a + ab * t - p).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// θ-PSO: one track per UAV; away from the reconfigurations the UAVs'
/// centroid is on the planned centroid path (eq. 6: the slots' centroid is
/// the formation's reference point).
#[test]
fn theta_pso_tracks_centre_on_the_planned_path() {
    let m = shipped("bridge-inspection.toml");
    let out = run(Kind::ThetaPso, &m);
    let o = out.theta_pso().unwrap();
    let tracks = out.tracks();
    assert_eq!(tracks.len(), m.formation.slots.len());
    let n = tracks[0].samples.len();
    assert!(n > 100);
    let mut checked = 0;
    for k in 0..n {
        let t = tracks[0].samples[k].t;
        let reconfiguring = o
            .reconfigurations
            .iter()
            .any(|r| t >= r.t1 - 1e-9 && t <= r.t4 + 1e-9);
        if reconfiguring {
            continue;
        }
        let sum = tracks.iter().fold(nalgebra::Vector3::zeros(), |acc, tr| {
            acc + tr.samples[k].position.coords
        });
        let centroid = Point3::from(sum / tracks.len() as f64);
        // The path as flown: the planned one with its corners rounded.
        let d = distance_to_polyline(&o.flown_path, &centroid);
        assert!(d < 1e-6, "t = {t}: centroid {d} m off the path");
        checked += 1;
    }
    assert!(
        checked > n / 2,
        "{checked} of {n} samples away from reconfigurations"
    );
}

/// FLATLO: the tracks are the flown aircraft; their last samples lie on the
/// longitudinal line, Δ_d apart (Section 4.2), as verification found.
#[test]
fn flatlo_tracks_end_on_the_longitudinal_line() {
    let m = shipped("flatlo-squadron.toml");
    let out = run(Kind::Flatlo, &m);
    let tracks = out.tracks();
    assert_eq!(tracks.len(), m.flatlo.aircraft);
    let ends: Vec<Point3<f64>> = tracks
        .iter()
        .map(|t| t.samples.last().unwrap().position)
        .collect();
    let line = skyform::pipelines::flatlo::algorithm::line_direction(
        m.flatlo.heading_deg.to_radians(),
        m.flatlo.climb_deg.to_radians(),
    );
    let (spacing, spread) = skyform::pipelines::flatlo::line_spacing(&ends, &line);
    for s in &spacing {
        assert!(
            (s.spacing - m.flatlo.spacing).abs() < 0.01 * m.flatlo.spacing,
            "{s:?}"
        );
    }
    assert!(spread < 100.0, "lateral spread {spread} m");
    // The flown track's velocity is the aircraft's: V along (γ, χ).
    let a = &out.flatlo().unwrap().aircraft[0];
    let v = tracks[0].samples[0].velocity.norm();
    assert!((v - a.flown[0].airspeed).abs() < 1e-9);
    // The references are there too, ending on the exact line.
    assert_eq!(out.reference_tracks().len(), m.flatlo.aircraft);
}

/// Fleet: the tracks are the simulated quadrotors; their last samples are
/// the formed triangle around the last target (eq. 6's desired distances).
#[test]
fn fleet_tracks_end_in_the_formed_triangle() {
    let m = shipped("fleet-triangle.toml");
    let out = run(Kind::Fleet, &m);
    assert_eq!(out.verdict(), Verdict::Passed, "{}", out.headline());
    let o = out.fleet().unwrap();
    let tracks = out.tracks();
    assert_eq!(tracks.len(), m.fleet.agents);
    for d in &o.distances {
        let a = tracks[d.a].samples.last().unwrap().position;
        let b = tracks[d.b].samples.last().unwrap().position;
        let got = (a - b).norm();
        assert!(
            (got - d.desired).abs() <= m.fleet.tolerance * d.desired + 1e-9,
            "agents {} and {}: {got} m, desired {}",
            d.a,
            d.b,
            d.desired
        );
    }
}

#[test]
fn the_json_outcome_carries_every_vehicle_track() {
    let mut m = shipped("flatlo-squadron.toml");
    m.flatlo.final_leg = 500.0;
    let out = run(Kind::Flatlo, &m);
    let json: serde_json::Value = serde_json::from_str(&out.to_json().unwrap()).unwrap();
    assert_eq!(json["pipeline"], "flatlo");
    let tracks = json["tracks"].as_array().unwrap();
    assert_eq!(tracks.len(), m.flatlo.aircraft);
    let samples = tracks[1]["samples"].as_array().unwrap();
    assert_eq!(samples.len(), out.flatlo().unwrap().aircraft[1].flown.len());
    assert!(samples[0]["velocity"].as_array().is_some());
    assert_eq!(
        json["reference_tracks"].as_array().unwrap().len(),
        m.flatlo.aircraft
    );
}
