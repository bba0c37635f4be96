use super::*;

#[test]
fn a_draw_becomes_the_number_rand_would_give() {
    let (mut a, mut b) = (ChaCha8Rng::seed_from_u64(7), ChaCha8Rng::seed_from_u64(7));
    for _ in 0..1000 {
        let want: f64 = a.random();
        assert_eq!(unit_interval(b.next_u64()).to_bits(), want.to_bits());
    }
}

/// The reference's move, written plainly (`SPSO_MAIN.m`).
fn reference_move(
    space: &SearchSpace,
    g: Gains,
    r: &[f64],
    p: &[f64],
    b: &[f64],
    x: &mut [f64],
    v: &mut [f64],
) {
    for d in 0..x.len() {
        let step = g.inertia * v[d]
            + g.cognitive * r[2 * d] * (p[d] - x[d])
            + g.social * r[2 * d + 1] * (b[d] - x[d]);
        v[d] = step.clamp(-space.max_step[d], space.max_step[d]);
        x[d] += v[d];
        if x[d] < space.lower[d] || x[d] > space.upper[d] {
            v[d] = -v[d];
        }
        x[d] = x[d].clamp(space.lower[d], space.upper[d]);
    }
}

#[test]
fn the_vectorised_move_is_the_reference_move_bit_for_bit() {
    let space = SearchSpace {
        lower: vec![-1.0, 0.0, 2.0, -5.0],
        upper: vec![1.0, 10.0, 3.0, 5.0],
        max_step: vec![1.0, 5.0, 0.5, 2.5],
    };
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut hits = [0usize; 2];
    for _ in 0..5000 {
        let wide = |rng: &mut ChaCha8Rng, d: usize| {
            let span = space.upper[d] - space.lower[d];
            space.lower[d] + span * (3.0 * rng.random::<f64>() - 1.0)
        };
        let x0: Vec<f64> = (0..4)
            .map(|d| wide(&mut rng, d).clamp(space.lower[d], space.upper[d]))
            .collect();
        let v0: Vec<f64> = (0..4)
            .map(|d| space.max_step[d] * (2.0 * rng.random::<f64>() - 1.0))
            .collect();
        let p: Vec<f64> = (0..4).map(|d| wide(&mut rng, d)).collect();
        let b: Vec<f64> = (0..4).map(|d| wide(&mut rng, d)).collect();
        let draws: Vec<u64> = (0..8).map(|_| rng.next_u64()).collect();
        let r: Vec<f64> = draws.iter().map(|&u| unit_interval(u)).collect();
        let g = Gains {
            inertia: 0.9,
            cognitive: 1.5,
            social: 1.5,
        };
        let (mut x1, mut v1) = (x0.clone(), v0.clone());
        let (mut x2, mut v2) = (x0.clone(), v0.clone());
        move_particle(&space, g, &draws, &p, &b, &mut x1, &mut v1);
        reference_move(&space, g, &r, &p, &b, &mut x2, &mut v2);
        for d in 0..4 {
            assert_eq!(
                (x1[d].to_bits(), v1[d].to_bits()),
                (x2[d].to_bits(), v2[d].to_bits())
            );
            let bounced = v2[d] != 0.0 && (x2[d] == space.lower[d] || x2[d] == space.upper[d]);
            hits[usize::from(bounced)] += 1;
        }
    }
    // Both the free and the mirrored branch are exercised.
    assert!(hits[0] > 1000 && hits[1] > 1000, "{hits:?}");
}

fn config(parallel: bool) -> SwarmConfig {
    SwarmConfig {
        particles: 30,
        iterations: 200,
        inertia: 0.7298,
        cognitive: 1.49618,
        social: 1.49618,
        parallel,
        streams: 0,
    }
}

fn sphere(x: &[f64]) -> f64 {
    x.iter().map(|v| (v - 0.3) * (v - 0.3)).sum()
}

#[test]
fn finds_the_minimum_of_a_sphere() {
    let space = SearchSpace::uniform(4, -1.0, 1.0, 0.5);
    let result = minimize(
        &space,
        &config(false),
        1,
        &[],
        |x, _| sphere(x),
        |_| ControlFlow::Continue(()),
    );
    assert!(result.best.cost < 1e-8, "cost {}", result.best.cost);
    assert!(result.best.position.iter().all(|v| (v - 0.3).abs() < 1e-3));
    assert_eq!(result.evaluations, 30 * 201);
}

#[test]
fn parallel_and_sequential_runs_are_identical() {
    let space = SearchSpace::uniform(6, -1.0, 1.0, 0.5);
    let seq = minimize(
        &space,
        &config(false),
        42,
        &[],
        |x, _| sphere(x),
        |_| ControlFlow::Continue(()),
    );
    let par = minimize(
        &space,
        &config(true),
        42,
        &[],
        |x, _| sphere(x),
        |_| ControlFlow::Continue(()),
    );
    assert_eq!(seq, par);
    let other = minimize(
        &space,
        &config(false),
        43,
        &[],
        |x, _| sphere(x),
        |_| ControlFlow::Continue(()),
    );
    assert_ne!(seq.best.position, other.best.position, "the seed matters");
}

#[test]
fn positions_stay_in_the_box() {
    // The minimum lies outside the box: the best must sit on the wall.
    let space = SearchSpace::uniform(2, -1.0, 1.0, 2.0);
    let result = minimize(
        &space,
        &config(false),
        3,
        &[],
        |x, _| -x[0] - x[1],
        |_| ControlFlow::Continue(()),
    );
    assert_eq!(result.best.position, vec![1.0, 1.0]);
}

#[test]
fn the_global_best_never_gets_worse_and_breaking_stops_at_once() {
    let space = SearchSpace::uniform(3, -1.0, 1.0, 0.5);
    let mut history = Vec::new();
    let result = minimize(
        &space,
        &config(false),
        5,
        &[],
        |x, _| sphere(x),
        |r| {
            history.push(r.best.cost);
            if r.iteration == 10 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    assert!(result.stopped);
    assert_eq!(result.iterations, 10);
    assert_eq!(history.len(), 11);
    assert!(history.windows(2).all(|w| w[1] <= w[0]));
}

#[test]
fn a_seeded_particle_starts_where_told_and_restarts_draw_new_streams() {
    let space = SearchSpace::uniform(2, -1.0, 1.0, 0.5);
    let mut first = Vec::new();
    minimize(
        &space,
        &config(false),
        4,
        &[vec![0.3, 0.3]],
        |x, _| sphere(x),
        |r| {
            first.push(r.best.cost);
            ControlFlow::Break(())
        },
    );
    assert_eq!(first, vec![0.0], "the seeded particle sits on the minimum");
    let run = |streams| {
        let cfg = SwarmConfig {
            streams,
            ..config(false)
        };
        minimize(
            &space,
            &cfg,
            4,
            &[],
            |x, _| sphere(x),
            |_| ControlFlow::Break(()),
        )
    };
    assert_ne!(run(0).best.position, run(1).best.position);
    assert_eq!(run(1), run(1));
}

#[test]
fn the_sequential_loop_finds_a_minimum_and_repeats_with_its_seed() {
    let space = SearchSpace::uniform(4, -1.0, 1.0, 1.0);
    let cfg = SequentialConfig {
        particles: 30,
        iterations: 200,
        inertia: 1.0,
        damping: 0.98,
        cognitive: 1.5,
        social: 1.5,
        streams: 0,
        init_passes: 10,
    };
    let run = |seed| {
        minimize_sequential(
            &space,
            &cfg,
            seed,
            &[],
            |x, _| sphere(x),
            |_| ControlFlow::Continue(()),
        )
    };
    let a = run(1);
    assert!(a.best.cost < 1e-6, "cost {}", a.best.cost);
    assert_eq!(a.evaluations, 30 * 201);
    assert_eq!(a, run(1));
    let early = |seed| {
        minimize_sequential(
            &space,
            &cfg,
            seed,
            &[],
            |x, _| sphere(x),
            |r| {
                if r.iteration == 3 {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            },
        )
    };
    assert_ne!(
        early(1).best.position,
        early(2).best.position,
        "the seed matters"
    );
    // No finite cost at first: the initial pass is repeated.
    let mut calls = 0;
    let r = minimize_sequential(
        &space,
        &SequentialConfig {
            iterations: 0,
            ..cfg.clone()
        },
        1,
        &[],
        |x, _| {
            calls += 1;
            if calls <= 30 {
                f64::INFINITY
            } else {
                sphere(x)
            }
        },
        |_| ControlFlow::Continue(()),
    );
    assert_eq!(r.evaluations, 60);
    assert!(r.best.cost.is_finite());
    // A given start is where its particle begins (clamped into the box).
    let start = |s: Vec<f64>| {
        minimize_sequential(
            &space,
            &SequentialConfig {
                iterations: 0,
                ..cfg.clone()
            },
            1,
            &[s],
            |x, _| sphere(x),
            |_| ControlFlow::Continue(()),
        )
    };
    let on_minimum = start(vec![0.3; 4]);
    assert_eq!((on_minimum.best.cost, on_minimum.evaluations), (0.0, 30));
    assert_eq!(
        start(vec![-5.0, 0.0, 0.0, 0.0]),
        start(vec![-1.0, 0.0, 0.0, 0.0])
    );
}

#[test]
fn nan_costs_never_become_the_best() {
    let space = SearchSpace::uniform(1, -1.0, 1.0, 0.5);
    let result = minimize(
        &space,
        &config(false),
        9,
        &[],
        |x, _| if x[0] > 0.0 { f64::NAN } else { -x[0] },
        |_| ControlFlow::Continue(()),
    );
    assert!(result.best.cost.is_finite());
    assert!(result.best.position[0] <= 0.0);
}
