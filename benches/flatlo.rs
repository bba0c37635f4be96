//! FLATLO speed: reference generation and the full simulation (RK4, noise,
//! verification) of the paper case (N = 4, Section 3), and of a 64-aircraft
//! squadron (Δ_d = 500 m, r = 150 m, so that the line stays tens of km long).
//! Target (issue 6): the paper case fully simulated with noise under 100 ms.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use skyform::mission::{self, Mission};
use skyform::pipelines::flatlo;
use skyform::pipelines::{CancelToken, Silent};

fn paper() -> Mission {
    let text = include_str!("../missions/flatlo-squadron.toml");
    mission::parse_str(text, "flatlo-squadron.toml")
        .map(|l| l.mission)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn squadron_of_64() -> Mission {
    let mut m = paper();
    m.flatlo.aircraft = 64;
    m.flatlo.spacing = 500.0;
    m.flatlo.turn_radius = 150.0;
    m.flatlo.final_leg = 2_000.0;
    m
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("flatlo");
    group.sample_size(20);
    for (name, m) in [("paper_n4", paper()), ("n64", squadron_of_64())] {
        group.bench_function(format!("{name}/references"), |b| {
            b.iter(|| {
                let plan = flatlo::references(black_box(&m.flatlo));
                plan.references
                    .iter()
                    .map(|r| flatlo::sample(r, m.flatlo.sample_period, plan.duration).len())
                    .sum::<usize>()
            })
        });
        group.bench_function(format!("{name}/full_simulation"), |b| {
            b.iter(|| {
                flatlo::plan(black_box(&m), 3, &mut Silent, &CancelToken::new())
                    .map(|o| o.verification.map(|v| v.max_spacing_error))
            })
        });
    }
    group.finish();
}

criterion_group!(flatlo_benches, benches);
criterion_main!(flatlo_benches);
