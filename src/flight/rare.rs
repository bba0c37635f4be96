//! Rare-event odds of the flight check (`skyform fly --rare`): the
//! probability that a flight breaks a limit, down to 10⁻⁶ and below, from a
//! few thousand flights instead of millions.
//!
//! **Method: subset simulation** (S.-K. Au and J. L. Beck, "Estimation of
//! small failure probabilities in high dimensions by subset simulation",
//! Probabilistic Engineering Mechanics 16(4), 2001), with the conditional
//! samples drawn by **preconditioned Crank-Nicolson** moves (S. L. Cotter,
//! G. O. Roberts, A. M. Stuart, D. White, "MCMC methods for functions",
//! Statistical Science 28(3), 2013), which keep the standard normal prior
//! exactly however many dimensions a flight has (about 10⁵ for the bridge).
//!
//! A flight is a deterministic function of its inputs u: every random
//! number it draws is a standard normal ([`Normals`]: the skews, the gust
//! noise, the fix noise, in order). Its **room** g(u) is the least distance
//! to the limit over the flight (a pair's closest approach less 2 r_Q, or a
//! vehicle's least clearance less r_Q); it breaks the limit when g < 0.
//! Level 0 flies N flights on fresh inputs; each level keeps the p₀ N
//! flights of least room (p₀ = 0.1) and moves each by pCN
//! (u' = ρ u + √(1 − ρ²) ξ, accepted when g(u') stays below the level's
//! threshold) into 1/p₀ flights of the next level, until at least p₀ N
//! flights break the limit. P = p₀^m · (breaks / N). Its coefficient of
//! variation is Au & Beck's eq. 28-29 (the chains' correlation included);
//! the interval is P·e^{±1.96 δ}. The step √(1 − ρ²) adapts from level to
//! level towards an acceptance of about 0.4 (Papaioannou et al. 2015).
//!
//! Every flight of the estimate is a function of (seed, level, chain, move),
//! so the same seed gives the same estimate on any number of threads, and
//! the most likely failing flight (the failing inputs of highest prior
//! density, least |u|) is flown again for its tracks.

use std::sync::atomic::{AtomicUsize, Ordering};

use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::air::Normals;
use super::{FlightError, Flown, Setup, fly_on, on_threads, vehicle_pairs};
use crate::pipelines::CancelToken;

/// The share of each level's flights that seeds the next (p₀).
pub const LEVEL_SHARE: f64 = 0.1;

/// Levels at most: p₀¹² = 10⁻¹²; below that the estimate is a bound.
pub const MAX_LEVELS: usize = 12;

/// The method, as the report names it.
pub const METHOD: &str = "subset simulation (Au & Beck 2001), pCN moves (Cotter et al. 2013)";

/// A limit a flight may break.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Limit {
    /// Two vehicles closer than 2 r_Q.
    Separation,
    /// A vehicle closer than r_Q to an obstacle.
    Clearance,
}

impl Limit {
    pub fn words(self) -> &'static str {
        match self {
            Limit::Separation => "2 r_Q between vehicles",
            Limit::Clearance => "r_Q from obstacles",
        }
    }
}

/// How an estimate is run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RareOptions {
    /// Flights per level (N); at least 1/p₀.
    pub per_level: usize,
    pub seed: u64,
    /// Worker threads (`None`: one per CPU). The estimate does not depend on it.
    pub threads: Option<usize>,
}

/// One level of the estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Level {
    /// The room below which a flight counts for this level's share
    /// (metres; the last level's is 0: the limit itself).
    pub threshold: f64,
    /// The share of this level's flights below it.
    pub share: f64,
    /// The pCN step √(1 − ρ²) of the moves that made this level's flights
    /// (0 for level 0: fresh flights), and the share of moves accepted.
    pub step: f64,
    pub acceptance: f64,
}

/// The most likely failing flight found: where it broke the limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// Its room, metres (negative: past the limit).
    pub room: f64,
    /// What came too close, in words.
    pub what: String,
    /// When, seconds on the plan's clock.
    pub t: f64,
    /// |u| / √D: how far its inputs lie from the mean flight's, in σ per
    /// input (about 1 for a typical flight).
    pub spread: f64,
    /// Where it is in the estimate: (level, chain, move).
    pub at: (usize, usize, usize),
    /// The independent run it is in (`odds.rs`; 0 for a single estimate).
    #[serde(default)]
    pub run: usize,
    /// Its inputs (the standard normals it drew, in order): flown again by
    /// [`fly_failure`]. Not in the report's JSON (about 10⁵ numbers); a
    /// failing-flight file (`odds::FailingFile`) carries them.
    #[serde(skip)]
    pub inputs: Vec<f32>,
}

/// The probability that a flight breaks one limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    pub limit: Limit,
    pub method: String,
    pub estimate: f64,
    /// The 95 % interval, P·e^{±1.96 δ}.
    pub low: f64,
    pub high: f64,
    /// Coefficient of variation δ (Au & Beck eq. 28-29).
    pub cov: f64,
    /// Flights flown.
    pub flights: usize,
    /// No flight broke the limit within [`MAX_LEVELS`]: `estimate` is 0 and
    /// `high` a bound (p₀^levels · 3/N).
    pub bound: bool,
    pub levels: Vec<Level>,
    pub most_likely: Option<Failure>,
}

/// A flight's inputs as a vector: the n-th draw is `u[n]` (the mean, 0,
/// past its end: only a flight whose earliest take-off is more than 6 σ
/// early reads that far).
struct Reading<'a> {
    u: &'a [f32],
    at: usize,
}

impl Normals for Reading<'_> {
    fn normal(&mut self) -> f64 {
        let x = self.u.get(self.at).map_or(0.0, |x| f64::from(*x));
        self.at += 1;
        x
    }
}

/// The draws a flight of `setup` takes at most: the skews, the air's and
/// the fixes' first draws, then per step the gusts (5 draws in turbulence)
/// and the common and own fixes (3 each), over the longest flight.
pub fn dimension(setup: &Setup) -> usize {
    let n = setup.plans.len();
    let p = &setup.mission.flight;
    let gusts = if p.turbulence == crate::mission::Turbulence::None || p.wind_speed < 0.0 {
        0
    } else {
        5
    };
    let early = (6.0 * p.takeoff_skew / p.step).ceil() as usize;
    let steps = setup.steps() + early + 1;
    n + 5 + 3 + 3 * n + steps * (gusts + 3 + 3 * n)
}

/// Fresh inputs: `d` standard normals from stream `stream` of `seed`.
fn fresh(seed: u64, stream: u64, d: usize) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    (0..d).map(|_| rng.normal() as f32).collect()
}

/// The stream of level `level`'s flight or chain `k`.
fn stream(level: usize, k: usize) -> u64 {
    ((level as u64) << 32) | k as u64
}

/// The room of a flight to `limit`, and what and when it was least.
fn room(setup: &Setup, flown: &Flown, limit: Limit) -> (f64, String, f64) {
    let mut best = (f64::INFINITY, String::new(), 0.0);
    match limit {
        Limit::Separation => {
            for ((i, j), c) in vehicle_pairs(setup.plans.len()).zip(&flown.pairs) {
                let r = c.distance - setup.closest;
                if r < best.0 {
                    best = (
                        r,
                        format!(
                            "UAV {} and UAV {} {:.2} m apart",
                            setup.plans[i].vehicle + 1,
                            setup.plans[j].vehicle + 1,
                            c.distance
                        ),
                        c.t,
                    );
                }
            }
        }
        Limit::Clearance => {
            for (v, near) in setup.near.iter().enumerate() {
                for (slot, &o) in near.iter().enumerate() {
                    let c = flown.obstacles[v][slot];
                    let r = c.distance - setup.clearance;
                    if r < best.0 {
                        best = (
                            r,
                            format!(
                                "UAV {} {:.2} m from '{}'",
                                setup.plans[v].vehicle + 1,
                                c.distance,
                                setup.mission.obstacles[o].name
                            ),
                            c.t,
                        );
                    }
                }
            }
        }
    }
    best
}

/// Flies the inputs `u`: its room to `limit` (the number alone: this is
/// every flight of every level, so nothing is put in words).
fn fly_inputs(setup: &Setup, u: &[f32], limit: Limit) -> f64 {
    let flown = fly_on(setup, &mut Reading { u, at: 0 }, 0, false, false);
    match limit {
        Limit::Separation => flown.separation_room(setup),
        Limit::Clearance => flown.clearance_room(setup),
    }
}

/// Flies a failing flight's inputs again, keeping every vehicle's track.
pub fn fly_failure(setup: &Setup, inputs: &[f32]) -> Flown {
    fly_on(setup, &mut Reading { u: inputs, at: 0 }, 0, true, false)
}

/// One sample of a level: its room and |u|².
#[derive(Debug, Clone, Copy)]
struct Sample {
    room: f64,
    norm2: f64,
}

fn norm2(u: &[f32]) -> f64 {
    u.iter().map(|x| f64::from(*x).powi(2)).sum()
}

/// One chain of a level: from `seed` (its first sample), `moves` pCN moves
/// of step `step`, each accepted when its room stays below `threshold`.
/// Returns each sample and whether the move that made it was accepted;
/// with `keep = Some(m)`, stops after move m and returns its inputs.
struct Chain<'a> {
    setup: &'a Setup<'a>,
    limit: Limit,
    seed: u64,
    level: usize,
    index: usize,
    step: f64,
    threshold: f64,
}

impl Chain<'_> {
    fn run(
        &self,
        start: &[f32],
        start_sample: Sample,
        moves: usize,
        keep: Option<usize>,
        accepted: Option<&[bool]>,
        cancel: &CancelToken,
    ) -> (Vec<(Sample, bool)>, Option<Vec<f32>>) {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(stream(self.level, self.index));
        let rho = (1.0 - self.step * self.step).max(0.0).sqrt();
        let mut u = start.to_vec();
        let mut current = start_sample;
        let mut out = vec![(current, true)];
        let mut proposal = vec![0f32; u.len()];
        for m in 1..=moves {
            if keep.is_some_and(|k| m > k) || cancel.is_cancelled() {
                break;
            }
            for (p, x) in proposal.iter_mut().zip(&u) {
                *p = (rho * f64::from(*x) + self.step * rng.normal()) as f32;
            }
            // Replaying a chain for its inputs: the moves' fates are known.
            let take = match accepted {
                Some(fates) => fates.get(m).copied().unwrap_or(false),
                None => {
                    let r = fly_inputs(self.setup, &proposal, self.limit);
                    let take = r < self.threshold;
                    if take {
                        current = Sample {
                            room: r,
                            norm2: norm2(&proposal),
                        };
                    }
                    take
                }
            };
            if take {
                std::mem::swap(&mut u, &mut proposal);
            }
            out.push((current, take));
        }
        (out, keep.map(|_| u))
    }
}

/// Au & Beck's eq. 29: the correlation factor γ of a level's indicator
/// `hit[c][s]` (chain c, sample s) with mean `p`.
fn correlation_factor(hit: &[Vec<bool>], p: f64) -> f64 {
    let chains = hit.len();
    let length = hit.iter().map(Vec::len).min().unwrap_or(0);
    let n = (chains * length) as f64;
    let r = |k: usize| -> f64 {
        let mut sum = 0.0;
        for h in hit {
            for s in 0..length - k {
                sum += f64::from(u8::from(h[s] && h[s + k]));
            }
        }
        sum / (n - (k * chains) as f64) - p * p
    };
    let r0 = p * (1.0 - p);
    if r0 <= 0.0 || length < 2 {
        return 0.0;
    }
    (1..length)
        .map(|k| 2.0 * (1.0 - k as f64 / length as f64) * r(k) / r0)
        .sum::<f64>()
        .max(0.0)
}

/// Estimates the probability that a flight of `setup` breaks `limit`;
/// `progress(flights flown, level)` as flights finish.
///
/// Long (~215 lines) because it is the algorithm's loop in one place, as
/// Au & Beck's Figure 1 gives it: level 0, then each level's seeds,
/// chains, threshold and coefficient of variation, then the estimate.
pub fn estimate(
    setup: &Setup,
    limit: Limit,
    options: RareOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &CancelToken,
) -> Result<Estimate, FlightError> {
    let n = options.per_level.max((1.0 / LEVEL_SHARE) as usize);
    let seeds = ((n as f64) * LEVEL_SHARE).round() as usize;
    let moves = n / seeds - 1;
    let d = dimension(setup);
    setup.within_budget(n)?;
    let flown = AtomicUsize::new(0);
    let tick = |level: usize| progress(flown.fetch_add(1, Ordering::Relaxed) + 1, level);

    // Level 0: fresh flights.
    let level0: Vec<Option<Sample>> = on_threads(options.threads, || {
        (0..n)
            .into_par_iter()
            .map(|k| {
                if cancel.is_cancelled() {
                    return None;
                }
                let u = fresh(options.seed, stream(0, k), d);
                let room = fly_inputs(setup, &u, limit);
                tick(0);
                Some(Sample {
                    room,
                    norm2: norm2(&u),
                })
            })
            .collect()
    });
    let level0: Vec<Sample> = level0
        .into_iter()
        .collect::<Option<_>>()
        .ok_or(FlightError::Cancelled)?;
    // Every sample of the current level: (sample, how to make its inputs
    // again: level 0's k, or (chain, move) of the level's chains).
    let mut samples: Vec<(Sample, (usize, usize))> = level0
        .into_iter()
        .enumerate()
        .map(|(k, s)| (s, (k, 0)))
        .collect();
    let mut hits: Vec<Vec<bool>> = Vec::new();
    let mut chains_fates: Vec<Vec<bool>> = Vec::new();
    let mut chain_starts: Vec<(Vec<f32>, Sample)> = Vec::new();
    let mut levels = Vec::new();
    let mut product = 1.0;
    let mut delta2 = 0.0;
    let mut step = 0.5;
    let mut level = 0;
    let mut last_acceptance = 0.0;
    loop {
        let mut order: Vec<usize> = (0..samples.len()).collect();
        order.sort_by(|&a, &b| {
            samples[a]
                .0
                .room
                .total_cmp(&samples[b].0.room)
                .then(a.cmp(&b))
        });
        let breaks = samples.iter().filter(|s| s.0.room < 0.0).count();
        let next = 0.5 * (samples[order[seeds - 1]].0.room + samples[order[seeds]].0.room);
        // Nothing near (no pair, no obstacle within reach): no level helps.
        let last = breaks >= seeds || level + 1 >= MAX_LEVELS || !next.is_finite();
        let threshold = if last { 0.0 } else { next };
        let share = if last {
            breaks as f64 / n as f64
        } else {
            seeds as f64 / n as f64
        };
        // This level's coefficient of variation (eq. 28; level 0 plain
        // Monte Carlo, the later ones with their chains' correlation).
        let gamma = if level == 0 {
            0.0
        } else {
            for (c, fates) in hits.iter_mut().enumerate() {
                for (s, h) in fates.iter_mut().enumerate() {
                    *h = samples[c * (moves + 1) + s].0.room < threshold;
                }
            }
            correlation_factor(&hits, share)
        };
        if share > 0.0 {
            delta2 += (1.0 - share) / (n as f64 * share) * (1.0 + gamma);
        }
        levels.push(Level {
            threshold,
            share,
            step: if level == 0 { 0.0 } else { step },
            acceptance: last_acceptance,
        });
        // What makes this level's samples' inputs again.
        let replay = Replay {
            starts: &chain_starts,
            fates: &chains_fates,
            step,
            moves,
            d,
        };
        if last {
            product *= share;
            let failing = order
                .iter()
                .copied()
                .filter(|&i| samples[i].0.room < 0.0)
                .min_by(|&a, &b| samples[a].0.norm2.total_cmp(&samples[b].0.norm2));
            let most_likely = failing.map(|i| {
                let (sample, at) = samples[i];
                let u = inputs_of(setup, limit, options, level, at, &replay, cancel);
                let flown = fly_on(setup, &mut Reading { u: &u, at: 0 }, 0, false, false);
                let (r, what, t) = room(setup, &flown, limit);
                Failure {
                    room: r,
                    what,
                    t,
                    spread: (sample.norm2 / d as f64).sqrt(),
                    at: (level, at.0, at.1),
                    run: 0,
                    inputs: u,
                }
            });
            let bound = breaks == 0;
            let delta = delta2.sqrt();
            let (estimate, low, high) = if bound {
                (
                    0.0,
                    0.0,
                    product.max(LEVEL_SHARE.powi(level as i32) * 3.0 / n as f64),
                )
            } else {
                let spread = (1.96 * delta).exp();
                (product, product / spread, product * spread)
            };
            return Ok(Estimate {
                limit,
                method: METHOD.to_owned(),
                estimate,
                low,
                high,
                cov: delta,
                flights: flown.load(Ordering::Relaxed),
                bound,
                levels,
                most_likely,
            });
        }
        product *= share;
        // The next level's seeds: this level's `seeds` flights of least room.
        let starts: Vec<(Vec<f32>, Sample)> = order[..seeds]
            .iter()
            .map(|&i| {
                let (sample, at) = samples[i];
                let u = inputs_of(setup, limit, options, level, at, &replay, cancel);
                (u, sample)
            })
            .collect();
        if level > 0 {
            step = adapt(step, last_acceptance);
        }
        level += 1;
        let runs: Vec<Vec<(Sample, bool)>> = on_threads(options.threads, || {
            starts
                .par_iter()
                .enumerate()
                .map(|(c, (u, s))| {
                    let chain = Chain {
                        setup,
                        limit,
                        seed: options.seed,
                        level,
                        index: c,
                        step,
                        threshold,
                    };
                    let (out, _) = chain.run(u, *s, moves, None, None, cancel);
                    for _ in 0..moves {
                        tick(level);
                    }
                    out
                })
                .collect()
        });
        if cancel.is_cancelled() {
            return Err(FlightError::Cancelled);
        }
        let accepted = runs
            .iter()
            .flat_map(|r| r.iter().skip(1))
            .filter(|(_, a)| *a)
            .count();
        last_acceptance = accepted as f64 / (seeds * moves).max(1) as f64;
        chains_fates = runs
            .iter()
            .map(|r| r.iter().map(|(_, a)| *a).collect())
            .collect();
        hits = runs.iter().map(|r| vec![false; r.len()]).collect();
        samples = runs
            .iter()
            .enumerate()
            .flat_map(|(c, r)| r.iter().enumerate().map(move |(m, (s, _))| (*s, (c, m))))
            .collect();
        chain_starts = starts;
    }
}

/// The pCN step for the next level: towards an acceptance of 0.3-0.5.
fn adapt(step: f64, acceptance: f64) -> f64 {
    if acceptance < 0.3 {
        (step * 0.7).max(0.05)
    } else if acceptance > 0.5 {
        (step * 1.3).min(1.0)
    } else {
        step
    }
}

/// What replays a level's chains: their starts, each move's fate, the
/// step, the moves per chain, the inputs' dimension.
#[derive(Clone, Copy)]
struct Replay<'a> {
    starts: &'a [(Vec<f32>, Sample)],
    fates: &'a [Vec<bool>],
    step: f64,
    moves: usize,
    d: usize,
}

/// The inputs of a sample of level `level` at `at`: level 0's flight k
/// drawn again, or a chain's move replayed from its start with the fates
/// it had (no flight flown).
fn inputs_of(
    setup: &Setup,
    limit: Limit,
    options: RareOptions,
    level: usize,
    at: (usize, usize),
    chains: &Replay,
    cancel: &CancelToken,
) -> Vec<f32> {
    let Replay {
        starts,
        fates,
        step,
        moves,
        d,
    } = *chains;
    if level == 0 {
        return fresh(options.seed, stream(0, at.0), d);
    }
    let (c, m) = at;
    let chain = Chain {
        setup,
        limit,
        seed: options.seed,
        level,
        index: c,
        step,
        threshold: f64::INFINITY,
    };
    let (start, sample) = &starts[c];
    chain
        .run(start, *sample, moves, Some(m), Some(&fates[c]), cancel)
        .1
        .unwrap_or_default()
}
