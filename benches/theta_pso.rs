//! θ-PSO speed: one cost evaluation, and one full run of the paper's
//! configuration (100 particles, 7 waypoints, 150 iterations) on the bridge.
//! Targets: a full run no slower than 1.2× the centroid-only cost of the
//! earlier release (issue 11), under 10 ms on one core (issue 15); runs are
//! measured with sequential evaluation (one core).
//!
//! `paper_run_one_core` plans the shipped bridge (with its two inspection
//! passes); `paper_run_no_inspection` the same bridge without them, the
//! mission the earlier releases measured.

use std::f64::consts::FRAC_PI_4;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use skyform::mission::{self, Mission};
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

criterion_group!(benches, cost_evaluation, full_run, budget_check);
criterion_main!(benches);
