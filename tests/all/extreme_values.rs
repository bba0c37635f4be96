//! Every numeric field, every extreme value (issue 12).
//!
//! For each shipped mission, every numeric leaf of its TOML tree (the file
//! with its defaults filled in) gets each of `0, -1, 1e-9, 1e9, 1e300,
//! -1e300, nan, inf` (integers: `0, -1, 2^31, 2^63-1`). `check` must answer
//! without panicking; where the mission is still valid, every pipeline must
//! return without panic or abort, in bounded time: a watchdog cancels it
//! after `RUN_SECONDS` and it must be back soon after.
//!
//! CI runs every `SKYFORM_SWEEP_STRIDE`-th case (default 37). The whole
//! sweep, once by hand:
//!
//! ```text
//! SKYFORM_SWEEP_STRIDE=1 cargo test --release --test all extreme_values:: -- --nocapture
//! ```

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use skyform::mission::BUILTIN;
use skyform::pipelines::theta_pso::PlanOptions;
use skyform::pipelines::{CancelToken, Silent};

/// A run is cancelled after this long (the largest runs the budget allows
/// take minutes; the test needs bounded time, not their result).
const RUN_SECONDS: f64 = 1.0;
/// How long a cancelled run may take to come back.
const CANCEL_GRACE: Duration = Duration::from_secs(30);

const FLOATS: [f64; 8] = [0.0, -1.0, 1e-9, 1e9, 1e300, -1e300, f64::NAN, f64::INFINITY];
const INTEGERS: [i64; 4] = [0, -1, 1 << 31, i64::MAX];

use crate::common::toml_leaves;
use toml_leaves::{Step, leaf_mut, leaves};

fn name(at: &[Step]) -> String {
    let mut s = String::new();
    for step in at {
        match step {
            Step::Key(k) if s.is_empty() => s.push_str(k),
            Step::Key(k) => {
                s.push('.');
                s.push_str(k);
            }
            Step::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

#[derive(Debug, Default)]
struct Tally {
    cases: usize,
    refused_by_rules: usize,
    refused_by_budget: usize,
    valid: usize,
    runs: usize,
    runs_finished: usize,
    runs_cancelled_by_watchdog: usize,
    runs_refused: usize,
    panics: Vec<String>,
    slow: Vec<String>,
}

/// Runs `run` with a watchdog that cancels it after `RUN_SECONDS`; returns
/// whether the watchdog had to cancel it, or the panic message.
fn watched<T>(run: impl FnOnce(&CancelToken) -> T) -> (Result<T, String>, bool, Duration) {
    let cancel = CancelToken::new();
    let (done_tx, done_rx) = mpsc::channel::<()>();
    let watchdog = {
        let cancel = cancel.clone();
        thread::spawn(move || {
            let fired = done_rx
                .recv_timeout(Duration::from_secs_f64(RUN_SECONDS))
                .is_err();
            if fired {
                cancel.cancel();
            }
            fired
        })
    };
    let started = Instant::now();
    let result = catch_unwind(AssertUnwindSafe(|| run(&cancel))).map_err(|e| {
        e.downcast_ref::<String>()
            .cloned()
            .or_else(|| e.downcast_ref::<&str>().map(|s| (*s).to_owned()))
            .unwrap_or_else(|| "panic".into())
    });
    let took = started.elapsed();
    let _ = done_tx.send(());
    let fired = watchdog.join().unwrap_or(false);
    (result, fired, took)
}

fn sweep(stride: usize) -> Tally {
    let mut tally = Tally::default();
    let mut index = 0usize;
    for b in BUILTIN {
        let mission: skyform::mission::Mission = toml::from_str(b.text).unwrap();
        let tree = toml::Value::try_from(&mission).unwrap();
        let mut found = Vec::new();
        leaves(&tree, &mut Vec::new(), &mut found);
        for (at, integer) in found {
            let values: Vec<toml::Value> = if integer {
                INTEGERS.iter().map(|&i| toml::Value::Integer(i)).collect()
            } else {
                FLOATS.iter().map(|&x| toml::Value::Float(x)).collect()
            };
            for value in values {
                index += 1;
                if !index.is_multiple_of(stride) {
                    continue;
                }
                tally.cases += 1;
                let case = format!("{} {} = {value}", b.file_name, name(&at));
                let mut changed = tree.clone();
                *leaf_mut(&mut changed, &at) = value;
                let Ok(text) = toml::to_string(&changed) else {
                    continue;
                };
                let checked =
                    catch_unwind(|| skyform::outcome::diagnose::check_text(&text, Some("x.toml")));
                let checked = match checked {
                    Ok(c) => c,
                    Err(_) => {
                        tally.panics.push(format!("check: {case}"));
                        continue;
                    }
                };
                let Some(m) = checked.mission.filter(|_| !checked.report.has_errors()) else {
                    if checked.report.errors().any(|d| d.message.contains("limit")) {
                        tally.refused_by_budget += 1;
                    } else {
                        tally.refused_by_rules += 1;
                    }
                    continue;
                };
                tally.valid += 1;
                type Run<'a> = Box<dyn Fn(&CancelToken) -> Result<(), String> + 'a>;
                let runs: [(&str, Run); 3] = [
                    (
                        "theta-pso",
                        Box::new(|c| {
                            skyform::pipelines::theta_pso::plan(
                                &m,
                                1,
                                PlanOptions::default(),
                                &mut Silent,
                                c,
                            )
                            .map(drop)
                            .map_err(|e| e.to_string())
                        }),
                    ),
                    (
                        "flatlo",
                        Box::new(|c| {
                            skyform::pipelines::flatlo::plan(&m, 1, &mut Silent, c)
                                .map(drop)
                                .map_err(|e| e.to_string())
                        }),
                    ),
                    (
                        "fleet",
                        Box::new(|c| {
                            skyform::pipelines::fleet::plan(&m, 1, &mut Silent, c)
                                .map(drop)
                                .map_err(|e| e.to_string())
                        }),
                    ),
                ];
                for (pipeline, run) in runs {
                    tally.runs += 1;
                    let (result, fired, took) = watched(|c| run(c));
                    match result {
                        Err(panic) => tally.panics.push(format!("{pipeline}: {case}: {panic}")),
                        Ok(Err(_)) => tally.runs_refused += 1,
                        Ok(Ok(())) if fired => tally.runs_cancelled_by_watchdog += 1,
                        Ok(Ok(())) => tally.runs_finished += 1,
                    }
                    if took > Duration::from_secs_f64(RUN_SECONDS) + CANCEL_GRACE {
                        tally.slow.push(format!("{pipeline}: {case}: {took:?}"));
                    }
                }
            }
        }
    }
    tally
}

#[test]
fn every_numeric_field_takes_every_extreme_value_without_panic_or_abort() {
    let stride = std::env::var("SKYFORM_SWEEP_STRIDE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(37usize)
        .max(1);
    let started = Instant::now();
    let tally = sweep(stride);
    println!(
        "extreme-value sweep (every {stride}th case) in {:.0} s: {tally:#?}",
        started.elapsed().as_secs_f64()
    );
    assert!(tally.cases > 0);
    assert!(tally.panics.is_empty(), "panics: {:#?}", tally.panics);
    assert!(tally.slow.is_empty(), "slow to cancel: {:#?}", tally.slow);
    // The sweep reaches both sides: refused cases and runs.
    assert!(tally.refused_by_rules > 0 && tally.valid > 0, "{tally:#?}");
}
