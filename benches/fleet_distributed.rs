//! The distributed fleet over Zenoh (issue 26), against the in-process run:
//! 3, 10 and 30 agents in 1, 2 and 3 agent processes on this machine, lockstep
//! on loopback. Each measured run flies 2 s (400 steps of 5 ms); the time
//! reported is the flight alone (the start-up, sessions and hellos are
//! measured apart, in `fleet_distributed/startup`). Per communication round
//! = time / 401; the overhead of a round is that less the in-process run's
//! time per step. Targets: 3 agents in 3 processes ≤ 1 ms per round beyond
//! the in-process step, start-up ≤ 2 s; 30 agents in 3 processes faster than
//! real time (a step in under 5 ms).
//!
//! Needs the `skyform` binary (default features): `cargo bench --bench
//! fleet_distributed`.

#[path = "common/fleets.rs"]
mod fleets;

use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use skyform::distributed::{self, Options};
use skyform::mission::Mission;
use skyform::pipelines::fleet;
use skyform::pipelines::{CancelToken, Silent};

/// Seconds each measured run flies.
const FLIGHT: f64 = 2.0;

fn fleet_of(n: usize) -> Mission {
    fleets::fleet_of(n, FLIGHT)
}

fn options(processes: usize) -> Options {
    Options {
        processes,
        realtime: false,
        program: PathBuf::from(env!("CARGO_BIN_EXE_skyform")),
        timeout: Duration::from_secs(30),
    }
}

/// One distributed run: the flight's time (start-up excluded) and the start-up.
fn distributed_run(m: &Mission, processes: usize) -> (Duration, Duration) {
    let began = Instant::now();
    let o = distributed::coordinate(m, 1, &options(processes), &mut Silent, &CancelToken::new())
        .unwrap_or_else(|e| panic!("{e}"));
    let total = began.elapsed();
    let startup = Duration::from_secs_f64(o.distributed.map_or(0.0, |d| d.startup));
    (total.saturating_sub(startup), startup)
}

fn lockstep(c: &mut Criterion) {
    let mut group = c.benchmark_group("fleet_distributed");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    for n in [3, 10, 30] {
        let m = fleet_of(n);
        group.bench_function(format!("{n}_agents/in_process"), |b| {
            b.iter(|| fleet::plan(black_box(&m), 1, &mut Silent, &CancelToken::new()))
        });
        for p in [1, 2, 3] {
            group.bench_function(format!("{n}_agents/{p}_processes"), |b| {
                b.iter_custom(|iterations| (0..iterations).map(|_| distributed_run(&m, p).0).sum())
            });
        }
    }
    let m = fleet_of(3);
    group.bench_function("startup/3_processes", |b| {
        b.iter_custom(|iterations| (0..iterations).map(|_| distributed_run(&m, 3).1).sum())
    });
    group.finish();
}

criterion_group!(benches, lockstep);
criterion_main!(benches);
