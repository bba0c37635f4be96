//! One particle-swarm engine for every planner.
//!
//! The engine moves particles in a box of plain coordinates. Encodings live in
//! the objective: θ-PSO searches angles θ ∈ [-π/2, π/2] and its cost decodes
//! them with eq. 1; the fleet's PSO searches steps h directly. The update is
//! eq. 1 of the θ-PSO paper (the standard inertia-weight PSO):
//!
//! Δθ ← w Δθ + c1 r1 (λ_i − θ) + c2 r2 (λ_g − θ),  θ ← θ + Δθ,
//!
//! with Δθ and θ clamped to the box, r1, r2 ~ U(0, 1) drawn once per particle
//! and iteration (the paper's scalars r_{1i}^k, r_{2i}^k).
//!
//! Determinism: each particle draws from its own ChaCha8 stream (`set_stream`)
//! and costs are evaluated before any best is updated, so the result depends on
//! the seed only, not on how many threads evaluate the costs.

use std::ops::ControlFlow;

use rand::rngs::ChaCha8Rng;
use rand::{Rng, RngExt, SeedableRng};
use rayon::prelude::*;

/// The swarm's hyper-parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct SwarmConfig {
    /// N, particles.
    pub particles: usize,
    /// Iterations after the initial evaluation.
    pub iterations: usize,
    /// w, inertia weight.
    pub inertia: f64,
    /// c1, pull toward the particle's own best.
    pub cognitive: f64,
    /// c2, pull toward the swarm's best.
    pub social: f64,
    /// Evaluate the particles' costs on the rayon pool. Same result either way.
    pub parallel: bool,
    /// Which set of random streams the particles draw from: 0 for a first
    /// run, 1, 2, … for restarts of the same seed (new streams, same seed).
    pub streams: u64,
}

/// The box the particles move in and the largest step per iteration, per dimension.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchSpace {
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub max_step: Vec<f64>,
}

impl SearchSpace {
    /// `dims` dimensions, each in [lower, upper] with steps up to `max_step`.
    pub fn uniform(dims: usize, lower: f64, upper: f64, max_step: f64) -> Self {
        SearchSpace {
            lower: vec![lower; dims],
            upper: vec![upper; dims],
            max_step: vec![max_step; dims],
        }
    }

    pub fn dims(&self) -> usize {
        self.lower.len()
    }
}

/// A position and its cost.
#[derive(Debug, Clone, PartialEq)]
pub struct Best {
    pub position: Vec<f64>,
    pub cost: f64,
}

/// What the engine tells its caller after each iteration.
#[derive(Debug)]
pub struct IterationReport<'a> {
    /// 1-based; iteration 0 is the initial evaluation.
    pub iteration: usize,
    pub best: &'a Best,
    /// The global best changed in this iteration.
    pub improved: bool,
}

/// The outcome of a minimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct SwarmResult {
    pub best: Best,
    /// Iterations completed (≤ the configured count when stopped early).
    pub iterations: usize,
    /// Cost evaluations made.
    pub evaluations: usize,
    /// The caller stopped the run (cancellation).
    pub stopped: bool,
}

/// Minimises `cost` over `space`. `on_iteration` is called after the initial
/// evaluation (iteration 0) and after each iteration; returning
/// `ControlFlow::Break` stops the run, keeping the best found so far.
/// A NaN cost counts as +∞, so it never becomes a best.
///
/// Particle i starts at `starts[i]` (clamped into the box) when given, at a
/// uniform random position otherwise: a caller can seed the swarm with
/// guesses it already has.
///
/// `cost(position, bound)` is called with the particle's personal best as
/// `bound`: once it knows the cost reaches the bound it may return any value
/// ≥ it (a partial sum), since such a candidate updates no best. The search
/// is then exactly the one full evaluations would make.
pub fn minimize<F, C>(
    space: &SearchSpace,
    config: &SwarmConfig,
    seed: u64,
    starts: &[Vec<f64>],
    cost: F,
    mut on_iteration: C,
) -> SwarmResult
where
    F: Fn(&[f64], f64) -> f64 + Sync,
    C: FnMut(&IterationReport<'_>) -> ControlFlow<()>,
{
    let dims = space.dims();
    let n = config.particles.max(1);
    let mut rngs = particle_streams(seed, config.streams, n);
    let mut positions: Vec<Vec<f64>> = rngs
        .iter_mut()
        .enumerate()
        .map(|(i, rng)| start_position(rng, space, starts.get(i)))
        .collect();
    let mut velocities = vec![vec![0.0; dims]; n];

    let unbounded = vec![f64::INFINITY; n];
    let mut costs = evaluate(&positions, &unbounded, &cost, config.parallel);
    let mut evaluations = n;
    let mut personal: Vec<Best> = positions
        .iter()
        .zip(&costs)
        .map(|(p, &c)| Best {
            position: p.clone(),
            cost: c,
        })
        .collect();
    let mut global = best_of(&personal);

    if let Some(stopped) = report_or_stop(&mut on_iteration, &global, 0, true, evaluations) {
        return stopped;
    }

    for iteration in 1..=config.iterations {
        for (i, rng) in rngs.iter_mut().enumerate() {
            let r1: f64 = rng.random();
            let r2: f64 = rng.random();
            let (x, v) = (&mut positions[i], &mut velocities[i]);
            for d in 0..dims {
                let step = config.inertia * v[d]
                    + config.cognitive * r1 * (personal[i].position[d] - x[d])
                    + config.social * r2 * (global.position[d] - x[d]);
                v[d] = step.clamp(-space.max_step[d], space.max_step[d]);
                x[d] = (x[d] + v[d]).clamp(space.lower[d], space.upper[d]);
            }
        }
        let bounds: Vec<f64> = personal.iter().map(|p| p.cost).collect();
        costs = evaluate(&positions, &bounds, &cost, config.parallel);
        evaluations += n;
        for (i, &c) in costs.iter().enumerate() {
            if c < personal[i].cost {
                personal[i] = Best {
                    position: positions[i].clone(),
                    cost: c,
                };
            }
        }
        let candidate = best_of(&personal);
        let improved = candidate.cost < global.cost;
        if improved {
            global = candidate;
        }
        if let Some(stopped) =
            report_or_stop(&mut on_iteration, &global, iteration, improved, evaluations)
        {
            return stopped;
        }
    }
    SwarmResult {
        best: global,
        iterations: config.iterations,
        evaluations,
        stopped: false,
    }
}

/// The loop of the SPSO reference code (`SPSO_MAIN.m`), used by the SPSO
/// benchmark for both of its encodings.
#[derive(Debug, Clone, PartialEq)]
pub struct SequentialConfig {
    pub particles: usize,
    pub iterations: usize,
    /// w at the first iteration.
    pub inertia: f64,
    /// w is multiplied by this after each iteration (wdamp, 0.98).
    pub damping: f64,
    pub cognitive: f64,
    pub social: f64,
    /// As `SwarmConfig::streams`.
    pub streams: u64,
    /// The initial pass is repeated while no particle has a finite cost, at
    /// most this many times (the reference repeats it without limit).
    pub init_passes: usize,
}

/// Minimises `cost` the way the SPSO reference code does, with one seeded
/// stream per particle (particle i starts at `starts[i]`, clamped, when
/// given, as in [`minimize`]):
///
/// - start uniformly in the box, velocities 0; repeat the initial pass while
///   no particle has a finite cost;
/// - per particle and dimension: v ← w v + c1 r1 (p − x) + c2 r2 (g − x), with
///   r1, r2 drawn per dimension; v clamped to ±`max_step`; x ← x + v; v ← −v
///   where x left the box; x clamped into the box;
/// - the particle is evaluated at once; its personal best is replaced only
///   when strictly better, and then the global best too when strictly better,
///   so later particles of the same iteration already follow it;
/// - w ← w · damping after each iteration.
///
/// The global best changes between particles, so the particles are updated
/// in order on one thread: the result depends on the seed only. Parallelism
/// is over runs (`skyform sweep`). `cost(position, bound)` may stop at a
/// partial sum ≥ `bound`, the particle's personal best, as for `minimize`.
pub fn minimize_sequential<F, C>(
    space: &SearchSpace,
    config: &SequentialConfig,
    seed: u64,
    starts: &[Vec<f64>],
    mut cost: F,
    mut on_iteration: C,
) -> SwarmResult
where
    F: FnMut(&[f64], f64) -> f64,
    C: FnMut(&IterationReport<'_>) -> ControlFlow<()>,
{
    let dims = space.dims();
    let n = config.particles.max(1);
    let mut rngs = particle_streams(seed, config.streams, n);
    let mut guarded = |x: &[f64], bound: f64| {
        let c = cost(x, bound);
        if c.is_nan() { f64::INFINITY } else { c }
    };
    let mut positions = vec![vec![0.0; dims]; n];
    let mut velocities = vec![vec![0.0; dims]; n];
    let mut personal: Vec<Best> = Vec::with_capacity(n);
    let mut global = Best {
        position: vec![0.0; dims],
        cost: f64::INFINITY,
    };
    let mut evaluations = 0usize;
    for pass in 0..config.init_passes.max(1) {
        personal.clear();
        for (i, rng) in rngs.iter_mut().enumerate() {
            // A given start stands in the first pass only.
            positions[i] = start_position(rng, space, starts.get(i).filter(|_| pass == 0));
            let c = guarded(&positions[i], f64::INFINITY);
            evaluations += 1;
            personal.push(Best {
                position: positions[i].clone(),
                cost: c,
            });
            if c < global.cost {
                global = personal[i].clone();
            }
        }
        if global.cost.is_finite() {
            break;
        }
    }
    if global.cost.is_infinite() {
        // No finite cost anywhere: the first particle stands for the swarm.
        global = personal[0].clone();
    }
    if let Some(stopped) = report_or_stop(&mut on_iteration, &global, 0, true, evaluations) {
        return stopped;
    }
    let mut w = config.inertia;
    let mut draws = vec![0u64; 2 * dims];
    for iteration in 1..=config.iterations {
        let mut improved = false;
        let gains = Gains {
            inertia: w,
            cognitive: config.cognitive,
            social: config.social,
        };
        for (i, rng) in rngs.iter_mut().enumerate() {
            let (x, v) = (&mut positions[i], &mut velocities[i]);
            // r1, r2 of each dimension in turn: the draws `rng.random::<f64>()`
            // makes, taken first so the update below has no calls or
            // branches and vectorises.
            for u in draws.iter_mut() {
                *u = rng.next_u64();
            }
            move_particle(
                space,
                gains,
                &draws,
                &personal[i].position,
                &global.position,
                x,
                v,
            );
            let c = guarded(x, personal[i].cost);
            evaluations += 1;
            if c < personal[i].cost {
                personal[i].position.copy_from_slice(x);
                personal[i].cost = c;
                if c < global.cost {
                    global.position.copy_from_slice(x);
                    global.cost = c;
                    improved = true;
                }
            }
        }
        w *= config.damping;
        if let Some(stopped) =
            report_or_stop(&mut on_iteration, &global, iteration, improved, evaluations)
        {
            return stopped;
        }
    }
    SwarmResult {
        best: global,
        iterations: config.iterations,
        evaluations,
        stopped: false,
    }
}

/// w, c1, c2 of one iteration.
#[derive(Clone, Copy)]
struct Gains {
    inertia: f64,
    cognitive: f64,
    social: f64,
}

/// One particle's move in the reference loop (see [`minimize_sequential`]),
/// dimension d with r1 = `draws[2d]`, r2 = `draws[2d + 1]` as uniform
/// [0, 1) numbers. Written with selects in place of `clamp` and `if`, so it
/// vectorises; the arithmetic and its order are the reference's.
fn move_particle(
    space: &SearchSpace,
    gains: Gains,
    draws: &[u64],
    personal: &[f64],
    global: &[f64],
    x: &mut [f64],
    v: &mut [f64],
) {
    let lanes = x
        .iter_mut()
        .zip(v.iter_mut())
        .zip(draws.chunks_exact(2))
        .zip(personal.iter().zip(global))
        .zip(space.lower.iter().zip(&space.upper).zip(&space.max_step));
    for ((((x, v), r), (&p, &g)), ((&lo, &hi), &limit)) in lanes {
        let (r1, r2) = (unit_interval(r[0]), unit_interval(r[1]));
        let step =
            gains.inertia * *v + gains.cognitive * r1 * (p - *x) + gains.social * r2 * (g - *x);
        let step = if step < -limit { -limit } else { step };
        let step = if step > limit { limit } else { step };
        let moved = *x + step;
        let outside = moved < lo || moved > hi;
        *v = if outside { -step } else { step };
        let moved = if moved < lo { lo } else { moved };
        *x = if moved > hi { hi } else { moved };
    }
}

/// `rand`'s uniform f64 in [0, 1) from one 64-bit draw: the top 53 bits
/// times 2⁻⁵³, what `rng.random::<f64>()` returns for the same draw.
#[inline(always)]
fn unit_interval(draw: u64) -> f64 {
    (draw >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Eq. 1 of the θ-PSO paper, third line (the angle encoding every θ-PSO
/// objective decodes, here so the planner and the SPSO benchmark share it): x = ½ [(x_max − x_min) sin θ + x_max + x_min].
pub fn decode_angle(theta: f64, min: f64, max: f64) -> f64 {
    0.5 * ((max - min) * theta.sin() + max + min)
}

/// The inverse of eq. 1 on [min, max]: the angle that decodes to `x` (clamped).
pub fn encode_angle(x: f64, min: f64, max: f64) -> f64 {
    if max > min {
        ((2.0 * x - max - min) / (max - min))
            .clamp(-1.0, 1.0)
            .asin()
    } else {
        0.0
    }
}

/// One seeded stream per particle; 2^32 streams per run, so restarts
/// (`streams` = 1, 2, …) never share a stream with a first run.
fn particle_streams(seed: u64, streams: u64, n: usize) -> Vec<ChaCha8Rng> {
    (0..n)
        .map(|i| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream((streams << 32) | i as u64);
            rng
        })
        .collect()
}

/// A particle's first position: uniform in the box, or `start` clamped into
/// it when given. The random draw is made either way, so seeding one
/// particle does not shift any other particle's stream.
fn start_position(rng: &mut ChaCha8Rng, space: &SearchSpace, start: Option<&Vec<f64>>) -> Vec<f64> {
    let dims = space.dims();
    let random: Vec<f64> = (0..dims)
        .map(|d| sample(rng, space.lower[d], space.upper[d]))
        .collect();
    match start {
        Some(start) if start.len() == dims => (0..dims)
            .map(|d| start[d].clamp(space.lower[d], space.upper[d]))
            .collect(),
        _ => random,
    }
}

/// Reports an iteration; the result to return when `on_iteration` stops the
/// run there (the best so far kept).
fn report_or_stop<C>(
    on_iteration: &mut C,
    global: &Best,
    iteration: usize,
    improved: bool,
    evaluations: usize,
) -> Option<SwarmResult>
where
    C: FnMut(&IterationReport<'_>) -> ControlFlow<()>,
{
    let report = IterationReport {
        iteration,
        best: global,
        improved,
    };
    on_iteration(&report).is_break().then(|| SwarmResult {
        best: global.clone(),
        iterations: iteration,
        evaluations,
        stopped: true,
    })
}

fn sample(rng: &mut ChaCha8Rng, lower: f64, upper: f64) -> f64 {
    if upper > lower {
        rng.random_range(lower..=upper)
    } else {
        lower
    }
}

fn evaluate<F>(positions: &[Vec<f64>], bounds: &[f64], cost: &F, parallel: bool) -> Vec<f64>
where
    F: Fn(&[f64], f64) -> f64 + Sync,
{
    let guarded = |(p, bound): (&Vec<f64>, &f64)| {
        let c = cost(p, *bound);
        if c.is_nan() { f64::INFINITY } else { c }
    };
    if parallel {
        positions.par_iter().zip(bounds).map(guarded).collect()
    } else {
        positions.iter().zip(bounds).map(guarded).collect()
    }
}

/// The lowest cost; the first particle wins ties, so the choice is stable.
fn best_of(personal: &[Best]) -> Best {
    let mut best = &personal[0];
    for b in &personal[1..] {
        if b.cost < best.cost {
            best = b;
        }
    }
    best.clone()
}

#[cfg(test)]
mod tests;
