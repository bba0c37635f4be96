//! Flight check speed (issue 39): 1,000 flights of the bridge in its shipped
//! weather (5 m/s, light Dryden turbulence, GNSS σ 1 m, skew σ 0.3 s) in at
//! most 10 s on two cores. Measured here: 100 flights on one thread and on
//! two (the same report either way), so flights per second and the scaling
//! from one thread to two are read off one run.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use skyform::export::Planned;
use skyform::flight::{self, Options, Setup};
use skyform::mission::{self, Mission};
use skyform::outcome;
use skyform::pipelines::theta_pso::PlanOptions;
use skyform::pipelines::{CancelToken, Kind, Silent};

/// The θ-PSO plan of `m` on seed 1, as its files fly it.
fn planned(m: &Mission) -> Planned {
    let o = outcome::run(
        Kind::ThetaPso,
        m,
        1,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    Planned::from_outcome(m, &o)
}

fn benches(c: &mut Criterion) {
    let m = mission::default_mission().mission;
    let planned = planned(&m);
    let setup = Setup::new(&m, &planned).unwrap_or_else(|e| panic!("{e}"));
    let mut group = c.benchmark_group("flight");
    group.sample_size(10);
    for threads in [1, 2] {
        group.bench_function(format!("bridge_100_flights/{threads}_threads"), |b| {
            b.iter(|| {
                let options = Options {
                    flights: 100,
                    seed: 1,
                    threads: Some(threads),
                };
                flight::check(black_box(&setup), options, &|_, _| {}, &CancelToken::new())
                    .map(|r| r.break_any.count)
            })
        });
    }
    group.finish();
}

/// Issue 52: a rare-event estimate at the 10⁻⁶ level in at most 60 s on
/// two cores. The bridge 1.2 m from its obstacles on σ 0.3 m fixes (no
/// flight of 2,000 breaks r_Q): r_Q's probability by subset simulation,
/// 1,000 flights a level (about 6 × 10⁻⁶, c.o.v. about 0.3). Each run has
/// a seed of its own (1, 2, …; the plan is the same), so the runs are
/// independent estimates: at the end the bench prints their mean, their
/// spread as a coefficient of variation beside the mean δ each stated, and
/// how many of the runs' 95 % intervals hold the mean. Select it with
/// `cargo bench --bench flight rare`; ten runs take several minutes.
fn rare(c: &mut Criterion) {
    let mut m = mission::default_mission().mission;
    m.flight.gnss_sigma_horizontal = 0.3;
    m.formation.obstacle_margin = 1.2;
    let planned = planned(&m);
    let setup = Setup::new(&m, &planned).unwrap_or_else(|e| panic!("{e}"));
    let mut runs: Vec<flight::rare::Estimate> = Vec::new();
    let mut group = c.benchmark_group("rare");
    group.sample_size(10);
    group.bench_function("bridge_clearance_1e-6/1000_a_level", |b| {
        b.iter(|| {
            let options = flight::rare::RareOptions {
                per_level: 1000,
                seed: runs.len() as u64 + 1,
                threads: Some(2),
            };
            let estimate = flight::rare::estimate(
                black_box(&setup),
                flight::rare::Limit::Clearance,
                options,
                &|_, _| {},
                &CancelToken::new(),
            )
            .unwrap_or_else(|e| panic!("{e}"));
            runs.push(estimate);
        })
    });
    group.finish();
    if runs.len() >= 2 {
        let n = runs.len() as f64;
        let mean = runs.iter().map(|e| e.estimate).sum::<f64>() / n;
        let var = runs
            .iter()
            .map(|e| (e.estimate - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        let stated = runs.iter().map(|e| e.cov).sum::<f64>() / n;
        let holding = runs
            .iter()
            .filter(|e| e.low <= mean && mean <= e.high)
            .count();
        eprintln!(
            "rare/bridge_clearance_1e-6: {} independent runs, mean {mean:.3e}, c.o.v. over the \
             runs {:.2} (stated δ, mean {stated:.2}); {holding} of {} intervals hold the mean; \
             estimates {:?}",
            runs.len(),
            var.sqrt() / mean,
            runs.len(),
            runs.iter()
                .map(|e| format!("{:.2e}", e.estimate))
                .collect::<Vec<_>>()
        );
    }
}

criterion_group!(flight_benches, benches, rare);
criterion_main!(flight_benches);
