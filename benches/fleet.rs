//! Distributed fleet speed: one agent's decision (a PSO of 30 particles × 30
//! iterations over Λ_i with two neighbours and an obstacle in view), and a
//! simulated minute of 3, 30 and 300 agents (200 Hz quadrotor dynamics,
//! decisions every τ = 0.1 s). Target (issue 7): 300 agents simulate a
//! minute at least 10× faster than real time, i.e. in under 6 s.

#[path = "common/fleets.rs"]
mod fleets;

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point2;
use skyform::mission::{FleetParams, Mission};
use skyform::pipelines::fleet::{self, agent::Planner, cost};
use skyform::pipelines::{CancelToken, Silent};

fn fleet_of(n: usize) -> Mission {
    fleets::fleet_of(n, 60.0)
}

fn decision(c: &mut Criterion) {
    let p = FleetParams::default();
    let view = cost::Observation {
        position: Point2::new(0.0, 0.0),
        target: Point2::new(2.0, 1.0),
        target_distance: 1.0,
        neighbours: [Point2::new(1.5, 0.2), Point2::new(-0.4, 1.7)]
            .map(|q| cost::Neighbour {
                position: q,
                desired: 1.732,
            })
            .to_vec(),
        obstacles: vec![skyform::base::shape::Footprint::circle(
            Point2::new(1.0, -1.0),
            0.1,
        )],
        rho: p.rho,
        safety: p.safety_distance,
        sigma: p.sigma,
        keep_apart: 1.2,
        keep_clear: 1.0,
    };
    let mut planner = Planner::new(0, 1, &p);
    let mut round = 0;
    c.bench_function("fleet/one_decision", |b| {
        b.iter(|| {
            round += 1;
            planner.decide(black_box(&view), round)
        })
    });
}

fn minute(c: &mut Criterion) {
    let mut group = c.benchmark_group("fleet/simulated_minute");
    group.sample_size(10);
    for n in [3, 30, 300] {
        let m = fleet_of(n);
        group.bench_function(format!("{n}_agents"), |b| {
            b.iter(|| {
                fleet::plan(black_box(&m), 1, &mut Silent, &CancelToken::new())
                    .map(|o| o.agents.len())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, decision, minute);
criterion_main!(benches);
