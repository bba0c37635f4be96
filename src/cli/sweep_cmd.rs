//! `skyform sweep`: one pipeline over many seeds, in parallel, summed up.

use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::{exit, load_reporting};
use crate::mission::{CostKind, Encoding, Mission};
use crate::outcome::{self, Verdict};
use crate::pipelines::PlanOptions;
use crate::pipelines::{CancelToken, Kind, Silent};
use crate::run::Run;

/// An encoding on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EncodingArg {
    Angle,
    Spherical,
}

/// The arguments of `skyform sweep` (its help is on `Command::Sweep`).
#[derive(Debug, clap::Args)]
pub struct SweepArgs {
    /// Mission TOML file.
    pub mission: PathBuf,
    /// Seeds A..B, both included (`1..10` is ten runs).
    #[arg(long, value_name = "A..B", value_parser = parse_seeds)]
    pub seeds: (u64, u64),
    /// The pipeline.
    #[arg(long, value_enum, default_value = "theta-pso")]
    pub pipeline: Kind,
    /// Runs at once (default: one per CPU).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Write one row per seed to FILE.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// With `cost = "spso"`: use this encoding (and its published settings)
    /// instead of the mission's.
    #[arg(long, value_enum)]
    pub encoding: Option<EncodingArg>,
}

/// `A..B` (or `A..=B`, or one seed `A`) into (A, B), A ≤ B.
pub fn parse_seeds(s: &str) -> Result<(u64, u64), String> {
    let (a, b) = match s.split_once("..") {
        Some((a, b)) => (a, b.trim_start_matches('=')),
        None => (s, s),
    };
    let a: u64 = a
        .trim()
        .parse()
        .map_err(|_| format!("'{a}' is not a seed"))?;
    let b: u64 = b
        .trim()
        .parse()
        .map_err(|_| format!("'{b}' is not a seed"))?;
    if a > b {
        return Err(format!(
            "{a}..{b} is empty: the first seed must not exceed the last"
        ));
    }
    if b - a >= 1_000_000 {
        return Err("at most a million seeds".into());
    }
    Ok((a, b))
}

/// One seed's run.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedRow {
    pub seed: u64,
    /// The run gave a result to judge: θ-PSO a finite J, FLATLO and the
    /// fleet a finished flight.
    pub completed: bool,
    /// The pipeline's own verdict, the one its `run` prints: θ-PSO
    /// FEASIBLE (verification passed), FLATLO and the fleet PASS.
    pub passed: bool,
    /// θ-PSO: best J; FLATLO: the closest pair (m); fleet: the closest two agents (m).
    pub figure: f64,
    /// Cost evaluations (θ-PSO, fleet PSO), 0 for FLATLO.
    pub evaluations: usize,
    pub wall: Duration,
    /// CPU time of the thread that ran it (the run's own threads for the
    /// fleet's parallel agents are not counted here, see `Summary::cpu`).
    pub cpu: Duration,
    /// An error instead of an outcome.
    pub error: Option<String>,
}

/// This thread's CPU time so far (Linux: /proc/thread-self/schedstat, ns).
fn thread_cpu() -> Option<Duration> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = s.split_whitespace().next()?.parse().ok()?;
    Some(Duration::from_nanos(ns))
}

/// This process's CPU time so far, user + system (Linux: /proc/self/stat).
fn process_cpu() -> Option<Duration> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) in parentheses.
    let rest = s.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let utime: u64 = fields.get(11)?.parse().ok()?;
    let stime: u64 = fields.get(12)?.parse().ok()?;
    // USER_HZ is 100 on every Linux this runs on.
    Some(Duration::from_millis((utime + stime) * 10))
}

/// Runs `pipeline` on `mission` for `seed` (one thread).
pub fn run_seed(mission: &Mission, kind: Kind, seed: u64) -> SeedRow {
    let cancel = CancelToken::new();
    let start = Instant::now();
    let cpu0 = thread_cpu();
    let mut row = SeedRow {
        seed,
        completed: false,
        passed: false,
        figure: f64::NAN,
        evaluations: 0,
        wall: Duration::ZERO,
        cpu: Duration::ZERO,
        error: None,
    };
    let run = Run {
        options: PlanOptions { parallel: false },
        ..Run::new(kind, seed)
    };
    match run.carry_out(mission, None, &mut Silent, &cancel).result {
        Ok(o) => {
            row.completed = o.judged();
            row.passed = o.verdict() == Verdict::Passed;
            row.figure = o.figure();
            row.evaluations = o.evaluations();
        }
        Err(e) => row.error = Some(e.to_string()),
    }
    row.wall = start.elapsed();
    row.cpu = match (cpu0, thread_cpu()) {
        (Some(a), Some(b)) => b.saturating_sub(a),
        _ => row.wall,
    };
    row
}

/// The table's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    pub runs: usize,
    /// Runs with a result to judge ([`SeedRow::completed`]).
    pub completed: usize,
    /// Runs the verdict passed ([`SeedRow::passed`]).
    pub passed: usize,
    pub errors: usize,
    /// Over the finite figures: mean, sample sd, median, min, max.
    pub stats: Option<[f64; 5]>,
    pub finite: usize,
    pub wall: Duration,
    /// The process's CPU time over the sweep (every thread).
    pub cpu: Duration,
    pub evaluations: usize,
}

/// mean, sd (n − 1), median, min, max of `values` (finite ones).
pub fn stats(values: &[f64]) -> Option<[f64; 5]> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = if v.len() > 1 {
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    let mid = v.len() / 2;
    let median = if v.len().is_multiple_of(2) {
        (v[mid - 1] + v[mid]) / 2.0
    } else {
        v[mid]
    };
    Some([mean, sd, median, v[0], v[v.len() - 1]])
}

pub fn summarise(rows: &[SeedRow], wall: Duration, cpu: Duration) -> Summary {
    let figures: Vec<f64> = rows.iter().map(|r| r.figure).collect();
    Summary {
        runs: rows.len(),
        completed: rows.iter().filter(|r| r.completed).count(),
        passed: rows.iter().filter(|r| r.passed).count(),
        errors: rows.iter().filter(|r| r.error.is_some()).count(),
        stats: stats(&figures),
        finite: figures.iter().filter(|x| x.is_finite()).count(),
        wall,
        cpu,
        evaluations: rows.iter().map(|r| r.evaluations).sum(),
    }
}

/// What a sweep's counts are called: one word, one meaning. The verdict
/// has the word the pipeline's own `run` prints (θ-PSO "feasible",
/// FLATLO and the fleet "passed"); the count of runs that gave a result to
/// judge has another ("J finite", "finished").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Words {
    pub completed: &'static str,
    pub verdict: &'static str,
}

impl Words {
    pub fn of(pipeline: Kind) -> Words {
        let (completed, verdict) = pipeline.words().tallies;
        Words { completed, verdict }
    }

    /// The CSV column names: `j_finite`, `feasible`, …
    fn column(word: &str) -> String {
        word.to_lowercase().replace(' ', "_")
    }
}

/// The CSV: a header and one row per seed.
pub fn csv(rows: &[SeedRow], figure: &str, words: Words) -> String {
    let mut out = format!(
        "seed,{},{},{figure},evaluations,wall_s,cpu_s,error\n",
        Words::column(words.completed),
        Words::column(words.verdict)
    );
    for r in rows {
        out.push_str(&format!(
            "{},{},{},{},{},{:.6},{:.6},{}\n",
            r.seed,
            r.completed,
            r.passed,
            crate::pipelines::theta_pso::spso::g17(r.figure),
            r.evaluations,
            r.wall.as_secs_f64(),
            r.cpu.as_secs_f64(),
            r.error
                .as_deref()
                .map(|e| format!("\"{}\"", e.replace('"', "'").replace('\n', " ")))
                .unwrap_or_default()
        ));
    }
    out
}

/// The table printed after a sweep.
pub fn table(s: &Summary, figure: &str, words: Words) -> String {
    let mut out = String::new();
    let line = |out: &mut String, k: &str, v: String| out.push_str(&format!("{k:<22}{v}\n"));
    line(&mut out, "runs", format!("{}", s.runs));
    line(
        &mut out,
        words.completed,
        format!("{} of {}", s.completed, s.runs),
    );
    line(
        &mut out,
        words.verdict,
        format!("{} of {}", s.passed, s.runs),
    );
    if s.errors > 0 {
        line(&mut out, "errors", format!("{}", s.errors));
    }
    match s.stats {
        Some([mean, sd, median, min, max]) => {
            line(
                &mut out,
                figure,
                format!(
                    "mean {mean:.1} ± {sd:.1} (sd), median {median:.1}, min {min:.1}, max {max:.1} \
                     ({} finite)",
                    s.finite
                ),
            );
        }
        None => line(&mut out, figure, "no finite value".into()),
    }
    line(
        &mut out,
        "wall time",
        format!("{:.2} s", s.wall.as_secs_f64()),
    );
    line(
        &mut out,
        "CPU time",
        format!("{:.2} s", s.cpu.as_secs_f64()),
    );
    if s.evaluations > 0 {
        let per = s.evaluations as f64 / s.cpu.as_secs_f64().max(1e-9);
        line(
            &mut out,
            "cost evaluations",
            format!(
                "{} ({} per CPU-second)",
                thousands(s.evaluations as f64),
                thousands(per)
            ),
        );
    }
    out
}

/// A whole number with thousands separators: 1,234,567.
pub fn thousands(x: f64) -> String {
    let digits = format!("{:.0}", x.max(0.0));
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

pub fn sweep_command(args: &SweepArgs) -> u8 {
    let Some(mut mission) = load_reporting(&args.mission) else {
        return exit::ERROR;
    };
    if let Some(e) = args.encoding {
        if mission.theta_pso.cost != CostKind::Spso {
            eprintln!("error: --encoding needs a mission with theta_pso.cost = \"spso\"");
            return exit::ERROR;
        }
        mission.theta_pso.encoding = match e {
            EncodingArg::Angle => Encoding::Angle,
            EncodingArg::Spherical => Encoding::Spherical,
        };
    }
    let (a, b) = args.seeds;
    let seeds: Vec<u64> = (a..=b).collect();
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(jobs).build() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: cannot start {jobs} worker threads: {e}");
            return exit::ERROR;
        }
    };
    let what = args.pipeline.face().describe(&mission);
    eprintln!(
        "sweep: {} · {what} · seeds {a}..{b} ({} runs) · {jobs} jobs",
        mission.name,
        seeds.len()
    );
    let figure = outcome::figure_name(args.pipeline);
    let terminal = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let done = AtomicUsize::new(0);
    let total = seeds.len();
    let cpu0 = process_cpu();
    let start = Instant::now();
    let rows: Vec<SeedRow> = pool.install(|| {
        seeds
            .par_iter()
            .map(|&seed| {
                let row = run_seed(&mission, args.pipeline, seed);
                let k = done.fetch_add(1, Ordering::Relaxed) + 1;
                let width = 30;
                let filled = k * width / total.max(1);
                let bar = format!(
                    "[{}{}] {k}/{total} seeds  last: seed {seed} {} {:.1} s",
                    "█".repeat(filled),
                    "·".repeat(width - filled),
                    crate::pipelines::theta_pso::spso::g17(row.figure),
                    row.wall.as_secs_f64()
                );
                if terminal {
                    eprint!("\r{bar}\x1b[K");
                    if k == total {
                        eprintln!();
                    }
                } else {
                    eprintln!("{bar}");
                }
                row
            })
            .collect()
    });
    let wall = start.elapsed();
    let cpu = match (cpu0, process_cpu()) {
        (Some(a), Some(b)) => b.saturating_sub(a),
        _ => rows.iter().map(|r| r.cpu).sum(),
    };
    for r in &rows {
        if let Some(e) = &r.error {
            eprintln!("seed {}: error: {e}", r.seed);
        }
    }
    let summary = summarise(&rows, wall, cpu);
    let words = Words::of(args.pipeline);
    print!("{}", table(&summary, figure, words));
    let _ = std::io::stdout().flush();
    if let Some(path) = &args.csv
        && let Err(e) = crate::base::atomic::write(path, csv(&rows, figure, words).as_bytes())
    {
        eprintln!("error: cannot write {}: {e}", path.display());
        return exit::ERROR;
    }
    if summary.errors > 0 {
        exit::ERROR
    } else {
        exit::OK
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 24, item 8: "feasible" is the verdict and nothing else: a run
    /// with a finite J that failed verification is counted as "J finite",
    /// not as feasible (the run's own summary says INFEASIBLE).
    #[test]
    fn the_sweep_table_says_feasible_only_for_the_verdict() {
        let summary = Summary {
            runs: 10,
            completed: 10,
            passed: 9,
            errors: 0,
            stats: None,
            finite: 10,
            wall: Duration::from_secs(1),
            cpu: Duration::from_secs(1),
            evaluations: 0,
        };
        let text = table(&summary, "best J", Words::of(Kind::ThetaPso));
        let feasible: Vec<&str> = text.lines().filter(|l| l.contains("feasible")).collect();
        assert_eq!(feasible, ["feasible              9 of 10"], "{text}");
        assert!(text.contains("J finite              10 of 10"), "{text}");
        let text = table(&summary, "closest pair (m)", Words::of(Kind::Flatlo));
        assert!(text.contains("passed                9 of 10"), "{text}");
        assert!(!text.contains("feasible"), "{text}");
        let row = SeedRow {
            seed: 4,
            completed: true,
            passed: false,
            figure: 1.5,
            evaluations: 0,
            wall: Duration::ZERO,
            cpu: Duration::ZERO,
            error: None,
        };
        let csv = csv(&[row], "best J", Words::of(Kind::ThetaPso));
        assert!(csv.starts_with("seed,j_finite,feasible,best J,"), "{csv}");
        assert!(csv.contains("\n4,true,false,"), "{csv}");
    }

    #[test]
    fn thousands_are_separated() {
        assert_eq!(thousands(1_006_000.0), "1,006,000");
        assert_eq!(thousands(999.4), "999");
        assert_eq!(thousands(0.0), "0");
    }

    #[test]
    fn seeds_parse_as_an_inclusive_range() {
        assert_eq!(parse_seeds("1..10"), Ok((1, 10)));
        assert_eq!(parse_seeds("3..=4"), Ok((3, 4)));
        assert_eq!(parse_seeds("7"), Ok((7, 7)));
        assert!(parse_seeds("5..1").is_err());
        assert!(parse_seeds("a..2").is_err());
    }

    #[test]
    fn stats_are_mean_sd_median_min_max_of_the_finite_values() {
        let s = stats(&[1.0, 2.0, 3.0, 4.0, f64::INFINITY]).expect("finite values");
        assert_eq!(s[0], 2.5);
        assert!((s[1] - 1.2909944487358056).abs() < 1e-15);
        assert_eq!(&s[2..], &[2.5, 1.0, 4.0]);
        assert_eq!(stats(&[f64::INFINITY]), None);
    }
}
