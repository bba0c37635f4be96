//! θ-PSO speed: one cost evaluation, and one full run of the paper's
//! configuration (100 particles, 7 waypoints, 150 iterations) on the bridge.
//! Target (issue 3): a full run under 50 ms on one core, so the run is
//! measured with sequential evaluation.

use std::f64::consts::FRAC_PI_4;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use skyform::mission;
use skyform::pipeline::{CancelToken, Silent};
use skyform::planner::{PlanOptions, Problem, plan};

fn cost_evaluation(c: &mut Criterion) {
    let m = mission::default_mission().mission;
    let problem = Problem::new(&m);
    let angles: Vec<f64> = (0..problem.space.dims())
        .map(|i| FRAC_PI_4 * ((i as f64) * 0.7).sin())
        .collect();
    c.bench_function("theta_pso/cost_evaluation", |b| {
        b.iter(|| problem.evaluate(black_box(&angles)).total)
    });
}

fn full_run(c: &mut Criterion) {
    let m = mission::default_mission().mission;
    let mut group = c.benchmark_group("theta_pso");
    group.sample_size(20);
    group.bench_function("paper_run_one_core", |b| {
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
    group.finish();
}

criterion_group!(benches, cost_evaluation, full_run);
criterion_main!(benches);
