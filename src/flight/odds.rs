//! The odds `skyform fly --rare` reports: K independent runs of the
//! rare-event estimate (`rare.rs`), their mean with its interval, and a
//! share of the runs written as a part that `skyform merge` combines into
//! the report one process gives, bit for bit.
//!
//! Subset simulation is sequential level by level, so one estimate is one
//! process's work. What splits is the runs: run r is seeded
//! [`run_seed`]`(seed, r)` (run 0 with the seed itself, so `--runs 1` is
//! the single estimate), runs are independent, and the mean of K of them
//! has a variance K times smaller: the c.o.v. of a 10⁻⁶ estimate, about 0.3
//! for one run on the bridge, is about 0.1 for ten. The mean's variance is
//! the sum of the runs' own (δ_r P_r)² over K²; a run that saw no break
//! counts as 0 with no variance, and when none did the mean is a bound:
//! the rule of three over the K runs' last levels pooled.
//!
//! Shard I of N runs the runs [`Shard::range`] gives it (`skyform fly
//! --rare --runs K --shard I/N --json PART`); the merge checks the parts
//! are one estimate's and cover every run once, and combines them in run
//! order, as one process does: no flight is flown again.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use super::rare::{self, Estimate, Failure, Limit, RareOptions};
use super::shard::{MergeError, PartWords, Shard, Sharded, merge_parts};
use super::{FlightError, Setup};
use crate::pipelines::{CancelToken, Kind};

/// What a rare-event part file says it is.
pub const PART_FORMAT: &str = "skyform rare-event part 1";

/// The most runs one estimate may have (each is a full subset simulation).
pub const MAX_RUNS: usize = 1000;

/// The seed of independent run `run` of an estimate seeded `seed`: run 0
/// is the seed itself; the others are spread by SplitMix64 so that
/// neighbouring seeds' runs do not share streams.
pub fn run_seed(seed: u64, run: usize) -> u64 {
    if run == 0 {
        return seed;
    }
    let mut z = seed ^ (run as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// One run's estimates of both limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Run {
    pub run: usize,
    pub separation: Estimate,
    pub clearance: Estimate,
}

/// The odds of breaking one limit: the mean of the runs' estimates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Odds {
    pub limit: Limit,
    pub method: String,
    pub estimate: f64,
    /// The 95 % interval, P̄·e^{±1.96 δ}.
    pub low: f64,
    pub high: f64,
    /// The mean's coefficient of variation δ.
    pub cov: f64,
    /// Flights flown by every run.
    pub flights: usize,
    /// No run saw a break: `estimate` is 0 and `high` a bound.
    pub bound: bool,
    /// The most likely failing flight over every run (least spread; the
    /// lowest run on a tie), with its run.
    pub most_likely: Option<Failure>,
    /// Each run's own estimate, levels and all.
    pub runs: Vec<Estimate>,
}

impl Odds {
    /// The mean of `runs` (one limit's estimates, in run order).
    pub fn of(limit: Limit, runs: Vec<Estimate>) -> Odds {
        let k = runs.len().max(1) as f64;
        let bound = runs.iter().all(|e| e.bound);
        let estimate = runs.iter().map(|e| e.estimate).sum::<f64>() / k;
        let variance = runs
            .iter()
            .map(|e| (e.cov * e.estimate).powi(2))
            .sum::<f64>()
            / (k * k);
        let (cov, low, high) = if bound {
            // The rule of three on the runs' last levels pooled: 3/(K N)
            // where each run's own bound is 3/N.
            let high = runs.iter().map(|e| e.high).sum::<f64>() / (k * k);
            (0.0, 0.0, high)
        } else {
            let cov = variance.sqrt() / estimate;
            let spread = (1.96 * cov).exp();
            (cov, estimate / spread, estimate * spread)
        };
        let method = if runs.len() == 1 {
            rare::METHOD.to_owned()
        } else {
            format!(
                "{}; the mean of {} independent runs",
                rare::METHOD,
                runs.len()
            )
        };
        let most_likely = runs
            .iter()
            .filter_map(|e| e.most_likely.as_ref())
            .min_by(|a, b| a.spread.total_cmp(&b.spread).then(a.run.cmp(&b.run)))
            .cloned();
        Odds {
            limit,
            method,
            estimate,
            low,
            high,
            cov,
            flights: runs.iter().map(|e| e.flights).sum(),
            bound,
            most_likely,
            runs,
        }
    }
}

/// What `skyform fly --rare --json` writes, and `skyform merge` of its
/// parts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OddsReport {
    pub mission: String,
    pub seed: u64,
    pub per_level: usize,
    pub runs: usize,
    pub separation: Odds,
    pub clearance: Odds,
}

impl OddsReport {
    /// The report of every run of an estimate, in run order.
    pub fn new(mission: &str, seed: u64, per_level: usize, runs: Vec<Run>) -> OddsReport {
        let count = runs.len();
        let (separation, clearance): (Vec<Estimate>, Vec<Estimate>) = runs
            .into_iter()
            .map(|r| (r.separation, r.clearance))
            .unzip();
        OddsReport {
            mission: mission.to_owned(),
            seed,
            per_level,
            runs: count,
            separation: Odds::of(Limit::Separation, separation),
            clearance: Odds::of(Limit::Clearance, clearance),
        }
    }
}

/// Runs `runs` of the estimate of both limits seeded `options.seed`;
/// `progress(run, limit, flights, level)` as flights finish.
pub fn fly_runs(
    setup: &Setup,
    options: RareOptions,
    runs: Range<usize>,
    progress: &(dyn Fn(usize, Limit, usize, usize) + Sync),
    cancel: &CancelToken,
) -> Result<Vec<Run>, FlightError> {
    runs.map(|run| {
        let options = RareOptions {
            seed: run_seed(options.seed, run),
            ..options
        };
        let one = |limit: Limit| {
            let tick = |done: usize, level: usize| progress(run, limit, done, level);
            rare::estimate(setup, limit, options, &tick, cancel).map(|mut e| {
                if let Some(f) = &mut e.most_likely {
                    f.run = run;
                }
                e
            })
        };
        Ok(Run {
            run,
            separation: one(Limit::Separation)?,
            clearance: one(Limit::Clearance)?,
        })
    })
    .collect()
}

/// What a failing-flight file says it is.
pub const FAILING_FORMAT: &str = "skyform failing flights 1";

/// The most likely failing flights of an estimate, with everything needed
/// to fly them again anywhere (`skyform fly MISSION --inputs FILE`): the
/// mission and the plan's seed, and each flight's inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailingFile {
    pub format: String,
    /// The mission flown, as TOML (a replay refuses another).
    pub mission: String,
    pub pipeline: Kind,
    /// The seed of the plan (and of the estimate).
    pub seed: u64,
    /// Each limit's most likely failing flight, where one was seen.
    pub flights: Vec<FailingFlight>,
}

/// One limit's most likely failing flight.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailingFlight {
    pub limit: Limit,
    /// What it broke, where and when, as the report said.
    pub failure: Failure,
    /// Its standard normal inputs, in the order the flight draws them.
    pub inputs: Vec<f32>,
}

impl FailingFile {
    /// The failing flights of `odds` (each limit's most likely, with its
    /// inputs: only a report made in this process has them).
    pub fn new(mission_toml: String, pipeline: Kind, seed: u64, odds: &[&Odds]) -> FailingFile {
        let flights = odds
            .iter()
            .filter_map(|o| {
                let f = o.most_likely.as_ref()?;
                (!f.inputs.is_empty()).then(|| FailingFlight {
                    limit: o.limit,
                    failure: f.clone(),
                    inputs: f.inputs.clone(),
                })
            })
            .collect();
        FailingFile {
            format: FAILING_FORMAT.to_owned(),
            mission: mission_toml,
            pipeline,
            seed,
            flights,
        }
    }
}

/// One shard's runs and what they belong to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Part {
    pub format: String,
    /// The mission flown, as TOML (the merge only compares it).
    pub mission: String,
    /// Its name, as the report gives it.
    pub name: String,
    pub pipeline: Kind,
    pub seed: u64,
    pub per_level: usize,
    /// Runs of the whole estimate.
    pub runs: usize,
    pub shard: Shard,
    /// This shard's runs, in run order.
    pub done: Vec<Run>,
}

/// A rare-event estimate's parts: its runs.
static ESTIMATE_PARTS: PartWords = PartWords {
    kind: "rare-event",
    whole: "estimate",
    piece: "run",
    count: "number of runs",
    command: "skyform fly --rare --shard",
    most: MAX_RUNS,
};

impl Sharded for Part {
    type Piece = Run;
    const WORDS: &'static PartWords = &ESTIMATE_PARTS;
    const FORMAT: &'static str = PART_FORMAT;

    fn format(&self) -> &str {
        &self.format
    }

    fn count(&self) -> usize {
        self.runs
    }

    fn differs(&self, first: &Self) -> Option<&'static str> {
        [
            ("mission", self.mission != first.mission),
            ("pipeline", self.pipeline != first.pipeline),
            ("seed", self.seed != first.seed),
            ("flights per level", self.per_level != first.per_level),
            ("number of runs", self.runs != first.runs),
        ]
        .into_iter()
        .find_map(|(what, differs)| differs.then_some(what))
    }

    fn take(&mut self) -> Vec<(usize, Run)> {
        std::mem::take(&mut self.done)
            .into_iter()
            .map(|r| (r.run, r))
            .collect()
    }
}

/// The report of `parts`, checked to be one estimate's and to hold every
/// run once. Parts are numbered from 1 in errors, in the order given.
pub fn merge(parts: Vec<Part>) -> Result<OddsReport, MergeError> {
    let (first, runs) = merge_parts(parts)?;
    Ok(OddsReport::new(
        &first.name,
        first.seed,
        first.per_level,
        runs,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(p: f64, cov: f64, bound: bool, high: f64) -> Estimate {
        let spread = (1.96 * cov).exp();
        Estimate {
            limit: Limit::Clearance,
            method: rare::METHOD.to_owned(),
            estimate: p,
            low: p / spread,
            high: if bound { high } else { p * spread },
            cov,
            flights: 1000,
            bound,
            levels: Vec::new(),
            most_likely: None,
        }
    }

    #[test]
    fn one_run_is_its_own_estimate() {
        let e = estimate(6.15e-6, 0.33, false, 0.0);
        let odds = Odds::of(Limit::Clearance, vec![e.clone()]);
        assert!((odds.estimate - e.estimate).abs() < 1e-20);
        assert!((odds.cov - e.cov).abs() < 1e-12);
        assert!((odds.low - e.low).abs() < 1e-18 && (odds.high - e.high).abs() < 1e-18);
        assert_eq!(odds.method, rare::METHOD);
    }

    /// Four runs of equal estimate and δ: the mean's δ is half each run's
    /// (the variance of a mean of K independent runs is K times smaller).
    #[test]
    fn the_mean_of_k_runs_has_a_cov_sqrt_k_times_smaller() {
        let runs = vec![estimate(1e-6, 0.4, false, 0.0); 4];
        let odds = Odds::of(Limit::Clearance, runs);
        assert!((odds.estimate - 1e-6).abs() < 1e-18);
        assert!((odds.cov - 0.2).abs() < 1e-12, "{}", odds.cov);
        assert_eq!(odds.flights, 4000);
        assert!(
            odds.method.contains("4 independent runs"),
            "{}",
            odds.method
        );
    }

    /// No run saw a break: a bound K times below each run's (the rule of
    /// three over the pooled last levels).
    #[test]
    fn runs_without_a_break_pool_into_a_lower_bound() {
        let runs = vec![estimate(0.0, 0.0, true, 3e-12); 3];
        let odds = Odds::of(Limit::Clearance, runs);
        assert!(odds.bound);
        assert_eq!(odds.estimate, 0.0);
        assert!((odds.high - 1e-12).abs() < 1e-24, "{}", odds.high);
    }

    #[test]
    fn run_zero_keeps_the_seed_and_the_others_differ() {
        assert_eq!(run_seed(7, 0), 7);
        let seeds: Vec<u64> = (0..50).map(|r| run_seed(7, r)).collect();
        let mut distinct = seeds.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert_eq!(distinct.len(), seeds.len());
        assert_ne!(run_seed(7, 1), run_seed(8, 1));
    }
}
