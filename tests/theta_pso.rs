//! θ-PSO pipeline: each piece against hand-computed values from the paper's
//! equations, then whole runs on the shipped missions.

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Point2, Point3, Vector2, Vector3};
use skyform::mission::{self, Mission, Obstacle, ShapeChoice};
use skyform::pipeline::{CancelToken, Completion, Event, Silent};
use skyform::planner::iwp::{lateral_half_width, resolve_shape};
use skyform::planner::path::{ArcWalker, decode_angle};
use skyform::planner::{
    CentroidPath, CostModel, Iwp, PlanOptions, Shape, ThetaPsoOutcome, find_iwps, plan,
};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
}

/// A 100 × 100 m box, band 5-15 m, the default triangle, no obstacles.
fn open_field() -> Mission {
    let text = "name = \"field\"\n[bounds]\nx = [0.0, 100.0]\ny = [0.0, 100.0]\nz = [5.0, 15.0]\n\
                [route]\nstart = [10.0, 50.0, 10.0]\ngoal = [90.0, 50.0, 10.0]\n";
    mission::parse_str(text, "field.toml")
        .map(|l| l.mission)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn pole(name: &str, x: f64, y: f64, radius: f64) -> Obstacle {
    Obstacle {
        name: name.into(),
        center: Point2::new(x, y),
        radius,
        height: 30.0,
        kind: None,
    }
}

fn bare(points: Vec<Point3<f64>>) -> CentroidPath {
    CentroidPath {
        points,
        zones: Vec::new(),
    }
}

fn run(mission: &Mission, seed: u64) -> ThetaPsoOutcome {
    plan(
        mission,
        seed,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

// ---- eq. 1 ------------------------------------------------------------------

#[test]
fn eq1_decodes_the_angle_range_onto_the_bounds() {
    assert!(close(decode_angle(-FRAC_PI_2, 7.0, 15.0), 7.0));
    assert!(close(decode_angle(FRAC_PI_2, 7.0, 15.0), 15.0));
    assert!(close(decode_angle(0.0, 7.0, 15.0), 11.0));
    assert!(
        close(decode_angle(FRAC_PI_2 / 3.0, 0.0, 2.0), 1.5),
        "sin 30° = ½"
    );
}

// ---- cost terms, eqs. 3, 4, 5, 11 --------------------------------------------

#[test]
fn j1_is_the_polyline_length_eq3() {
    let m = open_field();
    let model = CostModel::new(&m, &[]);
    let path = bare(vec![
        Point3::new(0.0, 0.0, 10.0),
        Point3::new(3.0, 4.0, 10.0),
        Point3::new(3.0, 4.0, 12.0),
    ]);
    let t = model.terms(&path);
    assert!(close(t.length, 7.0));
    assert_eq!((t.obstacle, t.altitude, t.waypoints), (0.0, 0.0, 0.0));
    assert!(close(t.total, 7.0), "β1 = 1 and nothing else");
}

#[test]
fn j2_is_the_mean_safe_radius_violation_eq4() {
    let mut m = open_field();
    m.theta_pso.segments = 1;
    m.obstacles = vec![pole("p", 50.0, 50.0, 1.0), pole("far", 10.0, 10.0, 1.0)];
    let model = CostModel::new(&m, &[]);
    // One segment whose midpoint is 2 m from the pole's axis, below its top.
    let path = bare(vec![
        Point3::new(48.0, 48.0, 10.0),
        Point3::new(52.0, 48.0, 10.0),
    ]);
    let safe = 1.0 + 5f64.sqrt() + 0.5; // r_k + r_F + r_Q
    let expected = (1.0 - 2.0 / safe) / (1.0 * 2.0); // L = 1, K = 2
    let t = model.terms(&path);
    assert!(close(t.obstacle, expected), "{} vs {expected}", t.obstacle);
    let weighted = 4.0 + m.theta_pso.weight_obstacle * expected;
    assert!(close(t.total, weighted));
}

#[test]
fn j2_above_a_cylinder_measures_to_its_top_disc() {
    let mut m = open_field();
    m.theta_pso.segments = 1;
    let mut low = pole("stump", 50.0, 50.0, 1.0);
    low.height = 9.0;
    m.obstacles = vec![low];
    let model = CostModel::new(&m, &[]);
    // Midpoint right above the axis, 1 m over the top: d = r + 1 = 2 m.
    let path = bare(vec![
        Point3::new(49.0, 50.0, 10.0),
        Point3::new(51.0, 50.0, 10.0),
    ]);
    let safe = 1.0 + 5f64.sqrt() + 0.5;
    assert!(close(model.terms(&path).obstacle, 1.0 - 2.0 / safe));
}

#[test]
fn j3_sums_the_altitude_band_violations_eq5() {
    let mut m = open_field();
    m.theta_pso.segments = 3;
    let model = CostModel::new(&m, &[]);
    // Legs of 10, 17 and 10 m get one segment each; midpoints at z = 20 (5 m
    // over), 11.5 (inside) and 3 (2 m under).
    let path = bare(vec![
        Point3::new(0.0, 0.0, 20.0),
        Point3::new(10.0, 0.0, 20.0),
        Point3::new(10.0, 0.0, 3.0),
        Point3::new(20.0, 0.0, 3.0),
    ]);
    let t = model.terms(&path);
    assert!(close(t.altitude, 5.0 + 0.0 + 2.0), "{}", t.altitude);
    // At or below the ground: the finite stand-in for ∞.
    let under = bare(vec![
        Point3::new(0.0, 0.0, -1.0),
        Point3::new(1.0, 0.0, -1.0),
    ]);
    m.theta_pso.segments = 1;
    let t = CostModel::new(&m, &[]).terms(&under);
    assert_eq!(t.altitude, m.theta_pso.ground_penalty);
    assert!(t.total.is_finite());
}

#[test]
fn jr_is_the_mean_horizontal_distance_to_enabled_iwps_eq11() {
    let mut m = open_field();
    m.theta_pso.segments = 2;
    let iwp = |x: f64, y: f64, enabled: bool| Iwp {
        between: ["a".into(), "b".into()],
        obstacles: [0, 1],
        position: Point2::new(x, y),
        gap: 2.0,
        normal: Vector2::new(1.0, 0.0),
        enabled,
        choice: ShapeChoice::Auto,
        shape: Shape::Rotation,
    };
    let iwps = [iwp(0.0, 4.0, true), iwp(100.0, 100.0, false)];
    let model = CostModel::new(&m, &iwps);
    // Two segments, midpoints (3, 0) and (9, 0): distances 5 and √97 to (0, 4).
    let path = bare(vec![
        Point3::new(0.0, 0.0, 10.0),
        Point3::new(12.0, 0.0, 10.0),
    ]);
    let expected = (5.0 + 97f64.sqrt()) / 2.0;
    assert!(close(model.terms(&path).waypoints, expected));
}

// ---- eq. 9 --------------------------------------------------------------------

#[test]
fn eq9_places_an_iwp_only_in_gaps_one_uav_but_not_the_formation_fits() {
    // r_Q = 0.5, r_F = √5: the window is 1.0 ≤ gap < 2 (√5 + 0.5) ≈ 5.47 m.
    let with_gap = |gap: f64| {
        let mut m = open_field();
        m.obstacles = vec![
            pole("a", 50.0, 30.0, 2.0),
            pole("b", 50.0, 30.0 + 4.0 + gap, 2.0),
        ];
        find_iwps(&m)
    };
    let inside = with_gap(1.5);
    assert_eq!(inside.len(), 1);
    assert!(close(inside[0].gap, 1.5));
    assert!(close(inside[0].position.x, 50.0) && close(inside[0].position.y, 32.75));
    assert!(close(inside[0].normal.norm(), 1.0) && close(inside[0].normal.y, 0.0));
    assert_eq!(with_gap(1.0).len(), 1, "exactly one UAV wide is in (≤)");
    assert!(with_gap(0.99).is_empty(), "too narrow for one UAV");
    assert!(with_gap(5.5).is_empty(), "the formation fits");
    assert_eq!(with_gap(5.4).len(), 1);
}

#[test]
fn eq9_ignores_a_gap_blocked_by_a_third_obstacle() {
    let mut m = open_field();
    m.obstacles = vec![
        pole("a", 50.0, 30.0, 2.0),
        pole("b", 50.0, 37.0, 2.0),
        pole("plug", 50.0, 33.5, 0.4),
    ];
    let names: Vec<_> = find_iwps(&m).iter().map(|i| i.between.clone()).collect();
    assert!(
        !names.contains(&["a".to_string(), "b".to_string()]),
        "{names:?}"
    );
}

#[test]
fn the_operator_can_disable_an_iwp_and_choose_its_shape() {
    let m = mission::default_mission().mission;
    let iwps = find_iwps(&m);
    assert_eq!(iwps.len(), 1, "{iwps:?}");
    assert_eq!(
        iwps[0].between,
        ["light pole 4".to_string(), "pier 5".to_string()]
    );
    assert!(matches!(iwps[0].shape, Shape::Alignment { .. }));
    let mut m2 = m.clone();
    m2.reconfiguration.waypoints[0].enabled = false;
    assert!(!find_iwps(&m2)[0].enabled);
    m2.reconfiguration.waypoints[0].shape = ShapeChoice::Rotation;
    assert_eq!(find_iwps(&m2)[0].shape, Shape::Rotation);
}

// ---- reconfiguration geometry (Section III, Fig. 2) ------------------------------

#[test]
fn alignment_is_a_column_that_fits_the_gap() {
    let f = open_field().formation;
    let shape = resolve_shape(ShapeChoice::Alignment, 1.5, &f, 0.5);
    let column = shape.offsets(&f.slots, 1.0);
    assert!(column.iter().all(|o| o.y == 0.0 && o.z == 0.0));
    assert!(lateral_half_width(&column, f.uav_radius) <= 1.5 / 2.0);
    // Spacing keeps the closest nominal pair's distance (√13 m), centroid at 0.
    let mut xs: Vec<f64> = column.iter().map(|o| o.x).collect();
    xs.sort_by(f64::total_cmp);
    assert!(close(xs[1] - xs[0], 13f64.sqrt()) && close(xs[2] - xs[1], 13f64.sqrt()));
    assert!(close(xs.iter().sum::<f64>(), 0.0));
}

#[test]
fn rotation_keeps_uav1_level_and_moves_the_others_vertically() {
    let f = open_field().formation;
    let turned = Shape::Rotation.offsets(&f.slots, 1.0);
    // UAV 1 (ΔT1 = [0, 2, 0]) stays; ΔT2, ΔT3 go to ±2 m in height (Fig. 7).
    assert_eq!(turned[0], Vector3::new(0.0, 2.0, 0.0));
    assert!(close(turned[1].z.abs(), 2.0) && close(turned[2].z.abs(), 2.0));
    assert!(close(turned[1].z, -turned[2].z));
    assert!(
        turned.iter().all(|o| close(o.x, 0.0)),
        "in the vertical plane across the path"
    );
    // Rigid: the distances between UAVs never change.
    for b in [0.25, 0.5, 0.75] {
        let mid = Shape::Rotation.offsets(&f.slots, b);
        assert!(close(
            (mid[1] - mid[2]).norm(),
            (f.slots[1] - f.slots[2]).norm()
        ));
    }
}

#[test]
fn shrink_scales_the_offsets_toward_the_centroid() {
    let f = open_field().formation;
    let shrunk = Shape::Shrink { scale: 0.6 }.offsets(&f.slots, 1.0);
    for (a, b) in f.slots.iter().zip(&shrunk) {
        assert!(close(b.x, 0.6 * a.x) && close(b.y, 0.6 * a.y) && close(b.z, 0.6 * a.z));
    }
    let half = Shape::Shrink { scale: 0.6 }.offsets(&f.slots, 0.5);
    assert!(close(half[0].y, 0.8 * 2.0), "half-way: scale 0.8");
}

#[test]
fn auto_picks_the_least_change_that_fits() {
    let f = open_field().formation;
    // 3 m gap: shrinking to (1.5 - 0.5) / 2 = 0.5 fits and moves UAVs ≤ 1.1 m,
    // less than the column (≥ 2 m) or the rotation (which does not fit).
    let shape = resolve_shape(ShapeChoice::Auto, 3.0, &f, 0.5);
    assert!(
        matches!(shape, Shape::Shrink { scale } if close(scale, 0.5)),
        "{shape:?}"
    );
    // 1.2 m gap: shrink would need scale 0.05 < 2 r_Q / √13: only the column fits.
    let shape = resolve_shape(ShapeChoice::Auto, 1.2, &f, 0.5);
    assert!(matches!(shape, Shape::Alignment { .. }), "{shape:?}");
}

// ---- trajectories, eqs. 6, 12-15 ------------------------------------------------

#[test]
fn the_uavs_centroid_follows_the_planned_path_eq6() {
    let m = mission::default_mission().mission;
    let o = run(&m, 1);
    let walker = ArcWalker::new(&o.centroid_path);
    let speed = m.formation.ground_speed;
    let n = o.trajectories.len() as f64;
    for k in 0..o.trajectories[0].samples.len() {
        let t = o.trajectories[0].samples[k].t;
        let mean = o
            .trajectories
            .iter()
            .map(|tr| tr.samples[k].position.coords)
            .sum::<Vector3<f64>>()
            / n;
        let planned = walker.at(t * speed);
        assert!(
            (mean - planned.coords).norm() < 1e-9,
            "t = {t}: centroid {mean:?} vs path {planned:?}"
        );
    }
}

#[test]
fn rotation_keeps_uav1_on_the_centroid_height_profile() {
    let mut m = mission::default_mission().mission;
    m.reconfiguration.waypoints[0].shape = ShapeChoice::Rotation;
    let o = run(&m, 2);
    let r = &o.reconfigurations[0];
    let walker = ArcWalker::new(&o.centroid_path);
    let mut others_moved = 0.0f64;
    for (k, s) in o.trajectories[0].samples.iter().enumerate() {
        let centroid_z = walker.at(s.t * m.formation.ground_speed).z;
        assert!(
            (s.position.z - centroid_z).abs() < 1e-9,
            "UAV 1 off at t = {}",
            s.t
        );
        if (r.t2..=r.t3).contains(&s.t) {
            let dz = o.trajectories[1].samples[k].position.z - centroid_z;
            others_moved = others_moved.max(dz.abs());
        }
    }
    assert!(
        close(others_moved, 2.0),
        "UAV 2 is 2 m off level in the hold: {others_moved}"
    );
}

#[test]
fn the_speed_is_the_formations_ground_speed_away_from_reconfigurations() {
    let m = mission::default_mission().mission;
    let o = run(&m, 3);
    let r = &o.reconfigurations[0];
    // Mid-hold, on the straight crossing of the gap, every UAV flies at 3 m/s.
    let mid = (r.t2 + r.t3) / 2.0;
    for tr in &o.trajectories {
        let s = tr
            .samples
            .iter()
            .min_by(|a, b| (a.t - mid).abs().total_cmp(&(b.t - mid).abs()));
        let v = s.map(|s| s.velocity.norm()).unwrap_or_default();
        assert!((v - 3.0).abs() < 1e-6, "UAV {} at {v} m/s", tr.uav);
    }
    assert!(r.t1 < r.t2 && r.t2 < r.t3 && r.t3 < r.t4);
    assert!(close(o.duration, o.path_length / 3.0));
}

// ---- whole runs ------------------------------------------------------------------

#[test]
fn the_bridge_is_planned_feasibly_through_the_narrow_passage_for_20_seeds() {
    let m = mission::default_mission().mission;
    let mut costs = Vec::new();
    for seed in 0..20 {
        let o = run(&m, seed);
        let failed: Vec<_> = o.verification.checks.iter().filter(|c| !c.ok).collect();
        assert!(o.feasible(), "seed {seed}: {failed:#?}");
        assert_eq!(o.reconfigurations.len(), 1, "seed {seed}");
        assert_eq!(o.reconfigurations[0].shape.name(), "alignment");
        // The centroid path goes through the IWP between light pole 4 and pier 5.
        let iwp = o.iwps[0].position;
        let through = o.centroid_path.iter().any(|p| (p.xy() - iwp).norm() < 1e-9);
        assert!(through, "seed {seed}");
        costs.push(o.cost.total);
    }
    let mean = costs.iter().sum::<f64>() / costs.len() as f64;
    let sd = (costs.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / costs.len() as f64).sqrt();
    eprintln!("bridge, 20 seeds: best J mean {mean:.3}, sd {sd:.3}");
}

#[test]
fn the_same_seed_gives_bit_identical_json_on_one_or_many_threads() {
    let m = mission::default_mission().mission;
    let seq = plan(
        &m,
        9,
        PlanOptions { parallel: false },
        &mut Silent,
        &CancelToken::new(),
    );
    let par = plan(
        &m,
        9,
        PlanOptions { parallel: true },
        &mut Silent,
        &CancelToken::new(),
    );
    let seq = seq.map(|o| serde_json::to_string(&o).unwrap_or_default());
    let par = par.map(|o| serde_json::to_string(&o).unwrap_or_default());
    assert!(seq.as_ref().is_ok_and(|s| s.len() > 1000));
    assert_eq!(seq, par);
    let other = run(&m, 10);
    assert_ne!(seq.ok(), serde_json::to_string(&other).ok());
}

#[test]
fn a_walled_in_start_is_reported_infeasible() {
    let mut m = open_field();
    // A ring of poles around the start, 6 m out, gaps far narrower than a UAV.
    m.obstacles = (0..24)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 24.0;
            pole(
                &format!("ring {i}"),
                10.0 + 6.0 * a.cos() + 10.0,
                50.0 + 6.0 * a.sin(),
                0.7,
            )
        })
        .collect();
    m.route.start = Point3::new(20.0, 50.0, 10.0);
    let o = run(&m, 1);
    assert!(!o.feasible());
    let clearance = &o.verification.checks[0];
    assert!(!clearance.ok && clearance.worst.is_some_and(|w| w < m.formation.uav_radius));
    assert!(o.verification.violation_count > 0 && !o.verification.violations.is_empty());
}

#[test]
fn cancelling_returns_promptly_with_the_best_so_far() {
    let m = mission::default_mission().mission;
    let cancel = CancelToken::new();
    let mut iterations_seen = 0;
    let trigger = cancel.clone();
    let mut observer = |e: Event<'_>| {
        if let Event::PathIteration { iteration, .. } = e {
            iterations_seen = iteration;
            if iteration == 5 {
                trigger.cancel();
            }
        }
    };
    let o = plan(&m, 4, PlanOptions::default(), &mut observer, &cancel);
    let o = o.unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(o.completion, Completion::Cancelled);
    assert_eq!(o.iterations, 5);
    assert_eq!(iterations_seen, 5);
    assert_eq!(o.convergence.len(), 6);
    assert!(
        !o.trajectories.is_empty(),
        "a cancelled run still returns its best path"
    );
}

#[test]
fn an_invalid_mission_is_an_error_not_a_panic() {
    let mut m = open_field();
    m.theta_pso.swarm_size = 0;
    let r = plan(
        &m,
        1,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    );
    assert!(r.is_err_and(|e| e.to_string().contains("theta_pso.swarm_size")));
}

#[test]
fn the_observer_sees_every_iteration_with_a_non_increasing_best() {
    let mut m = open_field();
    m.theta_pso.iterations = 20;
    m.theta_pso.swarm_size = 20;
    let mut totals = Vec::new();
    let mut stages = Vec::new();
    let mut observer = |e: Event<'_>| match e {
        Event::PathIteration { cost, path, .. } => {
            assert!(path.len() >= 2);
            totals.push(cost.total);
        }
        Event::Stage(s) => stages.push(s.to_owned()),
        _ => {}
    };
    let o = plan(
        &m,
        1,
        PlanOptions::default(),
        &mut observer,
        &CancelToken::new(),
    );
    assert!(o.is_ok());
    assert_eq!(totals.len(), 21);
    assert!(totals.windows(2).all(|w| w[1] <= w[0]));
    assert_eq!(
        stages,
        [
            "intermediate waypoints",
            "planning",
            "trajectories",
            "verification"
        ]
    );
}
