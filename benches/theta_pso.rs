//! θ-PSO speed: one cost evaluation, and one full run of the paper's
//! configuration (100 particles, 7 waypoints, 150 iterations) on the bridge.
//! Targets: a full run no slower than 1.2× the centroid-only cost of the
//! earlier release (issue 11), under 10 ms on one core (issue 15); runs are
//! measured with sequential evaluation (one core).
//!
//! `paper_run_one_core` plans the shipped bridge (with its two inspection
//! passes); `paper_run_no_inspection` the same bridge without them, the
//! mission the earlier releases measured.
//!
//! Issue 23: `route_refusal/*` is the time to refuse a mission with no
//! corridor (target < 50 ms: the route stage says so before any swarm), and
//! `sites/twelve_uavs_two_passages` one full run (all cores, as `skyform run`)
//! of the first generated site of `tests/sites` with a 4 × 3 grid and two
//! walls whose gaps both need a reconfiguration; `sites/twelve_uavs_three_walls`
//! the same with three walls (issue 51: both ≤ 1 s median; 0.83 s for the
//! first after the cost's per-interval and per-UAV culls, from 1.55 s).

#[path = "../tests/all/sites/mod.rs"]
mod sites;

use std::f64::consts::FRAC_PI_4;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Point2, Point3};
use skyform::mission::{self, Mission, Obstacle};
use skyform::pipelines::theta_pso::{PlanOptions, Problem, plan};
use skyform::pipelines::{CancelToken, Silent};

fn bridge_without_inspections() -> Mission {
    let mut m = mission::default_mission().mission;
    for o in &mut m.obstacles {
        o.inspect = false;
    }
    m
}

fn cost_evaluation(c: &mut Criterion) {
    for (name, m) in [
        (
            "theta_pso/cost_evaluation",
            mission::default_mission().mission,
        ),
        (
            "theta_pso/cost_evaluation_no_inspection",
            bridge_without_inspections(),
        ),
    ] {
        let Ok(problem) = Problem::new(&m) else {
            panic!("the bridge mission has an inspection that cannot be flown");
        };
        let angles: Vec<f64> = (0..problem.space.dims())
            .map(|i| FRAC_PI_4 * ((i as f64) * 0.7).sin())
            .collect();
        c.bench_function(name, |b| {
            b.iter(|| problem.evaluate(black_box(&angles)).total)
        });
    }
}

fn full_run(c: &mut Criterion) {
    let mut group = c.benchmark_group("theta_pso");
    group.sample_size(20);
    for (name, m) in [
        ("paper_run_one_core", mission::default_mission().mission),
        ("paper_run_no_inspection", bridge_without_inspections()),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                plan(
                    black_box(&m),
                    7,
                    PlanOptions { parallel: false },
                    &mut Silent,
                    &CancelToken::new(),
                )
                .map(|o| o.cost.total)
            })
        });
    }
    group.finish();
}

/// Issue 12: what every pipeline's budget check (and the whole `diagnose`,
/// run on every edit in the designer) costs on the bridge and on a
/// 4,096-aircraft squadron (the largest FLATLO budget: its references are
/// computed to know the flight time).
fn budget_check(c: &mut Criterion) {
    let bridge = mission::default_mission().mission;
    let mut squadron = bridge.clone();
    squadron.flatlo.aircraft = 4_096;
    squadron.flatlo.spacing = 500.0;
    squadron.flatlo.turn_radius = 150.0;
    for (name, m) in [("bridge", &bridge), ("squadron_4096", &squadron)] {
        c.bench_function(&format!("budget_check/{name}"), |b| {
            b.iter(|| {
                let m = black_box(m);
                skyform::pipelines::theta_pso::budget(m).len()
                    + skyform::pipelines::flatlo::budget(m).len()
                    + skyform::pipelines::fleet::budget(m).len()
            })
        });
    }
    c.bench_function("diagnose/bridge", |b| {
        b.iter(|| skyform::outcome::diagnose::diagnose(black_box(&bridge)).len())
    });
}

fn post(name: String, x: f64, y: f64, radius: f64) -> Obstacle {
    Obstacle::standing(name, Point2::new(x, y), radius, 30.0)
}

/// The two missions of the route stage's refusal tests (`tests/all/theta_pso.rs`):
/// a wall across a 100 m field whose one gap (0.6 m) is narrower than one
/// UAV, and a start ringed by 24 poles.
fn no_corridor() -> [(&'static str, Mission); 2] {
    let text = "name = \"field\"\n[bounds]\nx = [0.0, 100.0]\ny = [0.0, 100.0]\nz = [5.0, 15.0]\n\
                [route]\nstart = [10.0, 50.0, 10.0]\ngoal = [90.0, 50.0, 10.0]\n";
    let field = match mission::parse_str(text, "field.toml") {
        Ok(l) => l.mission,
        Err(e) => panic!("{e}"),
    };
    let mut wall = field.clone();
    for side in [1.0, -1.0] {
        let mut y = 50.0 + side * 1.3;
        while (0.0..=100.0).contains(&y) {
            wall.obstacles
                .push(post(format!("post {side} {y:.1}"), 50.0, y, 1.0));
            y += side * 1.8;
        }
    }
    let mut ring = field;
    ring.route.start = Point3::new(20.0, 50.0, 10.0);
    ring.obstacles = (0..24)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 24.0;
            post(
                format!("ring {i}"),
                20.0 + 6.0 * a.cos(),
                50.0 + 6.0 * a.sin(),
                0.7,
            )
        })
        .collect();
    [("wall_without_gap", wall), ("walled_in_start", ring)]
}

fn route_refusal(c: &mut Criterion) {
    for (name, m) in no_corridor() {
        c.bench_function(&format!("route_refusal/{name}"), |b| {
            b.iter(|| {
                let refused = plan(
                    black_box(&m),
                    1,
                    PlanOptions::default(),
                    &mut Silent,
                    &CancelToken::new(),
                );
                assert!(refused.is_err(), "{name} must be refused");
            })
        });
    }
}

fn twelve_uavs_two_passages(c: &mut Criterion) {
    let Some(site) = (0..1_000)
        .map(sites::generated)
        .find(|s| s.uavs == 12 && s.walls == 2 && s.narrow == 2)
    else {
        panic!("no 12-UAV site with two narrow passages in the first 1,000");
    };
    // Issue 51: a maze of three walls, every gap narrower than the grid.
    let Some(maze) = (0..1_000)
        .map(sites::generated)
        .find(|s| s.uavs == 12 && s.walls == 3 && s.narrow == 3)
    else {
        panic!("no 12-UAV site with three narrow passages in the first 1,000");
    };
    let mut group = c.benchmark_group("sites");
    group.sample_size(10);
    for (name, site) in [
        ("twelve_uavs_two_passages", &site),
        ("twelve_uavs_three_walls", &maze),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                plan(
                    black_box(&site.mission),
                    0,
                    PlanOptions::default(),
                    &mut Silent,
                    &CancelToken::new(),
                )
                .map(|o| o.feasible())
            })
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    cost_evaluation,
    full_run,
    budget_check,
    route_refusal,
    twelve_uavs_two_passages
);
criterion_main!(benches);
