//! The SPSO benchmark (issue 15): one cost evaluation, one decode + cost per
//! encoding, and one full run (500 particles × 200 iterations, 100,500
//! evaluations) per encoding, on one core. Evaluations per CPU-second =
//! evaluations / the measured time (criterion runs on one thread).
//! Target: ≥ 3.3 million per CPU-second (20× the batched numpy port's
//! ≈ 164,000).

use std::hint::black_box;
use std::ops::ControlFlow;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use skyform::mission::{Encoding, Mission};
use skyform::pipelines::theta_pso::spso::{self, Decoder};

fn mission() -> Mission {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("missions/spso-benchmark.toml");
    match skyform::mission::load(&path) {
        Ok(l) => l.mission,
        Err(e) => panic!("{e}"),
    }
}

/// Path 3 of the parity set: the safe route, z = 150 everywhere.
fn safe_route() -> Vec<f64> {
    let x = [
        230.0, 250.0, 290.0, 380.0, 470.0, 560.0, 640.0, 760.0, 800.0, 810.0,
    ];
    let y = [
        250.0, 420.0, 600.0, 640.0, 650.0, 660.0, 640.0, 660.0, 720.0, 770.0,
    ];
    let mut v = Vec::with_capacity(30);
    v.extend_from_slice(&x);
    v.extend_from_slice(&y);
    v.extend_from_slice(&[150.0; 10]);
    v
}

fn cost_evaluation(c: &mut Criterion) {
    let m = mission();
    let Ok(model) = spso::model(&m) else {
        panic!("no terrain");
    };
    let route = safe_route();
    assert_eq!(spso::g17(model.cost(&route)), "5925.8548228312056");
    c.bench_function("spso/cost_evaluation", |b| {
        b.iter(|| model.cost(black_box(&route)))
    });
    // Random particles of each encoding, decoded and costed (what a run does).
    for encoding in [Encoding::Angle, Encoding::Spherical] {
        let decoder = Decoder::new(&m, encoding);
        let space = decoder.space();
        let particles: Vec<Vec<f64>> = (0..256)
            .map(|k| {
                (0..space.dims())
                    .map(|d| {
                        let t = ((k * 7919 + d * 104_729) % 1000) as f64 / 999.0;
                        space.lower[d] + t * (space.upper[d] - space.lower[d])
                    })
                    .collect()
            })
            .collect();
        let mut buffer = vec![0.0; 3 * decoder.nodes()];
        let mut k = 0;
        c.bench_function(&format!("spso/decode_and_cost_{encoding:?}"), |b| {
            b.iter(|| {
                k = (k + 1) % particles.len();
                decoder.decode(black_box(&particles[k]), &mut buffer);
                model.cost(&buffer)
            })
        });
    }
}

fn full_run(c: &mut Criterion) {
    let m = mission();
    let Ok(model) = spso::model(&m) else {
        panic!("no terrain");
    };
    let mut group = c.benchmark_group("spso");
    group.sample_size(10);
    for encoding in [Encoding::Angle, Encoding::Spherical] {
        let decoder = Decoder::new(&m, encoding);
        group.bench_function(format!("full_run_{encoding:?}_500x200"), |b| {
            b.iter(|| {
                let run =
                    spso::optimise(&model, &decoder, 500, 200, black_box(1), &[], |_, _, _| {
                        ControlFlow::Continue(())
                    });
                // 100,500, plus 500 per extra initial pass when the first
                // draws no finite cost (the reference re-draws too).
                assert!(run.swarm.evaluations >= 100_500 && run.swarm.evaluations % 500 == 0);
                run.terms.total
            })
        });
    }
    group.finish();
}

criterion_group!(benches, cost_evaluation, full_run);
criterion_main!(benches);
