//! `skyform fly`: plan, then fly the plan's exported missions many times in
//! wind, on GNSS fixes, with take-off skew, and report what that does to
//! its margins (docs/flight-check.md).

use std::io::IsTerminal;
use std::path::PathBuf;

use super::{cancel_on_ctrl_c, exit, load_reporting};
use crate::base::atomic;
use crate::flight::{self, FlightError, Options, Setup};
use crate::mission::Mission;
use crate::pipelines::{CancelToken, Kind};

/// The arguments of `skyform fly` (its help is on `Command::Fly`).
/// The pipelines `--pipeline` offers: those whose vehicles the check flies
/// (multicopters; a fixed-wing squadron flies on its own model).
fn flown_pipelines() -> impl clap::builder::TypedValueParser<Value = Kind> {
    use clap::ValueEnum;
    use clap::builder::TypedValueParser;
    let names: Vec<clap::builder::PossibleValue> = Kind::value_variants()
        .iter()
        .filter(|k| !k.words().fixed_wing)
        .filter_map(|k| k.to_possible_value())
        .collect();
    clap::builder::PossibleValuesParser::new(names)
        .map(|name: String| Kind::from_str(&name, true).unwrap_or_default())
}

#[derive(Debug, clap::Args)]
pub struct FlyArgs {
    /// Mission TOML file (its `[flight]` section sets the air; defaults:
    /// calm, GNSS σ 1 m / 1.5 m, take-off skew σ 0.3 s).
    pub mission: PathBuf,
    /// The pipeline that plans the mission: one whose vehicles are
    /// multicopters, which the check flies.
    #[arg(long, value_parser = flown_pipelines(), default_value = "theta-pso")]
    pub pipeline: Kind,
    /// Flights (default: flight.flights, 1000).
    #[arg(long)]
    pub flights: Option<usize>,
    /// Seed of the plan and of the flights (default: the mission's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Fly only flight K again and print it (the report names its worst).
    #[arg(long, value_name = "K")]
    pub flight: Option<usize>,
    /// Write the report as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Worker threads (default: one per CPU); the report does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// List every pair and every obstacle, not the five tightest.
    #[arg(long)]
    pub verbose: bool,
    /// Find the smallest extra clearance m from the obstacles (θ-PSO:
    /// formation.obstacle_margin + m; fleet: fleet.safety_distance + m)
    /// whose plan breaks r_Q in at most this share of the flights (0.001:
    /// one flight in a thousand), then, if the pairs still break 2 r_Q more
    /// often, the smallest widening of the slots that brings them within it,
    /// re-planning as needed, and report that plan and the fields to set.
    #[arg(long, value_name = "SHARE")]
    pub target: Option<f64>,
    /// Estimate the odds of breaking 2 r_Q and r_Q down to 10⁻⁶ and below
    /// by subset simulation (a few thousand flights where brute force
    /// would need millions): each limit's probability, its 95 % interval
    /// and coefficient of variation, and the most likely failing flight.
    #[arg(long, conflicts_with_all = ["target", "flight"])]
    pub rare: bool,
    /// Flights per level of `--rare` (at least 10; more: a tighter interval).
    #[arg(long, value_name = "N", default_value_t = 1000, requires = "rare")]
    pub per_level: usize,
    /// Independent runs of `--rare`, each seeded apart (run 0 with the
    /// seed itself), reported as their mean: K runs give an interval about
    /// √K times narrower, and `--shard I/N` splits them between machines.
    #[arg(long, value_name = "K", default_value_t = 1, requires = "rare")]
    pub runs: usize,
    /// With `--rare`: write each limit's most likely failing flight (its
    /// inputs, the mission and the seed) to FILE, for `--inputs` to fly
    /// again anywhere.
    #[arg(long, value_name = "FILE", requires = "rare")]
    pub failure: Option<PathBuf>,
    /// Fly again the failing flights FILE holds (written by `--rare
    /// --failure`) on this mission's plan: each printed as `--flight K`
    /// prints a flight, and recorded with `--rrd`, `--connect` or `--spawn`.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["rare", "target", "shard", "flight"])]
    pub inputs: Option<PathBuf>,
    /// Fly only shard I of N of the check (I from 0: a contiguous share of
    /// the flight numbers; with `--rare`, of the `--runs`) and write them
    /// to the --json file, a part for `skyform merge`: the merged parts
    /// give the report one process gives, bit for bit, whichever machines
    /// ran them.
    #[arg(long, value_name = "I/N", requires = "json", conflicts_with_all = ["target", "flight"])]
    pub shard: Option<String>,
    /// A Rerun recording of the check: the plan as written, the p99
    /// envelope of each UAV as a tube, the worst flights as flown.
    #[command(flatten)]
    pub record: super::RecordArgs,
}

/// `skyform fly`. Exit status: 0 no flight broke a limit, 1 error, 2 some
/// flight broke 2 r_Q or r_Q, 130 cancelled.
pub fn fly_command(args: &FlyArgs) -> u8 {
    let Some(mut mission) = load_reporting(&args.mission) else {
        return exit::ERROR;
    };
    if args.pipeline.words().fixed_wing {
        eprintln!(
            "error: {}'s aircraft fly on their own model; the flight check flies multicopters \
             (--pipeline theta-pso or fleet)",
            args.pipeline.words().name
        );
        return exit::ERROR;
    }
    if let Some(n) = args.flights {
        mission.flight.flights = n;
        let problems: Vec<_> = crate::mission::validate(&mission)
            .into_iter()
            .filter(|d| d.is_error() && d.path.to_string().starts_with("flight"))
            .collect();
        if let Some(d) = problems.first() {
            eprintln!("error: --flights {n}: {}", d.message);
            return exit::ERROR;
        }
    }
    let seed = args.seed.unwrap_or(mission.seed);
    // A file of failing flights is read and checked before the plan is
    // made: one of another mission or seed is refused at once.
    let failing = match &args.inputs {
        Some(path) => match super::fly_again::read(path, &mission, args.pipeline, seed) {
            Ok(file) => Some((path, file)),
            Err(code) => return code,
        },
        None => None,
    };
    let cancel = cancel_on_ctrl_c();
    // The margin search plans for itself, from no margin up.
    if let Some(target) = args.target {
        return margin(args, &mission, seed, target, &cancel);
    }
    let planned = match super::export_cmd::planned(&mission, args.pipeline, seed) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let setup = match Setup::new(&mission, &planned) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return exit::ERROR;
        }
    };
    if let Some(k) = args.flight {
        return super::fly_again::flight(&setup, seed, k);
    }
    if let Some((path, file)) = failing {
        return super::fly_again::inputs(&setup, &mission, args, seed, path, &file);
    }
    if args.rare {
        return rare(&setup, &mission, args, seed, &cancel);
    }
    if let Some(shard) = &args.shard {
        return super::merge_cmd::fly_shard(&setup, &mission, args, seed, shard, &cancel);
    }
    let terminal = std::io::stderr().is_terminal();
    let progress = |done: usize, total: usize| {
        if terminal && (done.is_multiple_of(50) || done == total) {
            eprint!("\rflights: {done} / {total}");
        }
    };
    let options = Options {
        flights: mission.flight.flights,
        seed,
        threads: args.threads,
    };
    // A recording needs each flight's cross-track samples: kept as they fly.
    let checked = if args.record.sinks().is_empty() {
        flight::check(&setup, options, &progress, &cancel).map(|r| (r, None))
    } else {
        flight::check_recorded(&setup, options, &progress, &cancel).map(|(r, rec)| (r, Some(rec)))
    };
    if terminal {
        eprintln!();
    }
    let (report, recording) = match checked {
        Ok(r) => r,
        Err(e) => return said(&e),
    };
    print!("{}", report.text(args.verbose));
    if let Some(recording) = recording {
        let code = record(&setup, recording, &report, args);
        if code != exit::OK {
            return code;
        }
    }
    report_written(&report, args.json.as_deref())
}

/// A check's report written as JSON to `json` (atomically), and the exit
/// status it gives: 2 when some flight broke a limit, 0 when none did.
pub(super) fn report_written(report: &flight::Report, json: Option<&std::path::Path>) -> u8 {
    if let Some(path) = json
        && let Err(status) = json_written(report, "the report", path, true)
    {
        return status;
    }
    if report.break_separation.count > 0 || report.break_clearance.count > 0 {
        exit::INFEASIBLE
    } else {
        exit::OK
    }
}

/// `value` written as JSON to `path` (atomically; `pretty` for a person to
/// read), or, saying why and naming `what`, the exit status of the failure.
pub(super) fn json_written(
    value: &impl serde::Serialize,
    what: &str,
    path: &std::path::Path,
    pretty: bool,
) -> Result<(), u8> {
    let text = if pretty {
        serde_json::to_string_pretty(value)
    } else {
        serde_json::to_string(value)
    };
    let text = text.map_err(|e| {
        eprintln!("error: {what} as JSON: {e}");
        exit::ERROR
    })?;
    atomic::write(path, text.as_bytes()).map_err(|e| {
        eprintln!("error: {}: {e}", path.display());
        exit::ERROR
    })
}

/// The recording of a check (`--rrd`, `--connect`, `--spawn`): the scene,
/// the plan as written, the envelope, the worst flights, the report.
fn record(
    setup: &Setup,
    recording: flight::Recording,
    report: &flight::Report,
    args: &FlyArgs,
) -> u8 {
    let mut recorder =
        match super::start_recorder(setup.mission, args.pipeline, &args.record.sinks()) {
            Ok(Some(r)) => r,
            Ok(None) => return exit::OK,
            Err(code) => return code,
        };
    recorder.log_mission(setup.mission);
    recorder.log_flights(recording, report.text(true));
    super::report_recording(Some(&recorder.finish()));
    exit::OK
}

/// `--target`: the margin search, then the report of the plan it found.
///
/// Long (~135 lines) because it is the search's whole output in reading order: the
/// progress, then one verdict per outcome (met, met with wider slots, not met, no plan), the
/// fields to set, the tries, the report and the JSON.
fn margin(args: &FlyArgs, mission: &Mission, seed: u64, target: f64, cancel: &CancelToken) -> u8 {
    if !(target.is_finite() && (0.0..1.0).contains(&target)) {
        eprintln!("error: --target {target}: a share of flights in [0, 1)");
        return exit::ERROR;
    }
    let options = Options {
        flights: mission.flight.flights,
        seed,
        threads: args.threads,
    };
    let pipeline = args.pipeline;
    let Some((field, now)) = flight::margin_field(mission, pipeline) else {
        eprintln!(
            "error: --target: {} has no margin to widen",
            pipeline.words().name
        );
        return exit::ERROR;
    };
    let mut tries = 0;
    let mut plan = |m: &Mission| {
        tries += 1;
        if let Some((field, value)) = flight::margin_field(m, pipeline) {
            eprintln!("try {tries}: {field} = {value:.2}");
        }
        flight::passing_plan(pipeline, m, seed, cancel)
    };
    eprintln!(
        "searching the margin from the obstacles, then the spacing if the pairs need it: {} flights \
         per try, the same flights each try (0, then as far as the flights fell short, then \
         between the last that failed and the first that met, to {} m)",
        options.flights,
        flight::MARGIN_RESOLUTION
    );
    let search = match flight::find_margin(pipeline, mission, target, options, &mut plan, cancel) {
        Ok(s) => s,
        Err(e) => return said(&e),
    };
    let tried: Vec<String> = search
        .tried
        .iter()
        .map(|t| {
            if t.spacing == 1.0 {
                format!("{:.2} m: {}", t.margin, t.note)
            } else {
                format!("{:.2} m, spacing ×{:.2}: {}", t.margin, t.spacing, t.note)
            }
        })
        .collect();
    let spacing_field = pipeline
        .face()
        .words()
        .spacing_field
        .unwrap_or("the spacing");
    let highest_margin = search
        .limit
        .as_ref()
        .map_or(flight::MAX_MARGIN, |l| l.margin);
    let code = match (search.margin, &search.report, search.spacing) {
        (Some(m), Some(report), spacing) => {
            let widened = spacing
                .map(|s| format!(" and the spacing ×{s:.2}"))
                .unwrap_or_default();
            println!(
                "margin       {m:.2} m from the obstacles{widened} keeps {} of flights within \
                 2 r_Q and r_Q (target {:.2} %)",
                format_share(report.break_any.share),
                100.0 * target,
            );
            println!("set          {field} = {:.2}   # now {now:.2}", now + m);
            if let Some(s) = spacing {
                let mut wider = mission.clone();
                flight::with_spacing(&mut wider, pipeline, s);
                println!(
                    "             {spacing_field} = {}   # ×{s:.2}: at the mission's spacing the \
                     pairs broke 2 r_Q in more than {:.2} % of flights whatever the margin",
                    slots_text(&wider),
                    100.0 * target
                );
            }
            exit::OK
        }
        (Some(_), None, Some(s)) => {
            println!(
                "margin       the spacing ×{s:.2} keeps 2 r_Q in all but {:.2} % of flights, but no \
                 margin up to {highest_margin:.2} m from the obstacles then keeps r_Q too",
                100.0 * target
            );
            print_limit("margin", search.limit.as_ref(), |m| format!("{m:.2} m"));
            exit::INFEASIBLE
        }
        (Some(m), None, None) => {
            println!(
                "margin       {m:.2} m from the obstacles keeps r_Q in all but {:.2} % of flights, \
                 but the pairs break 2 r_Q more often than that",
                100.0 * target
            );
            let widest = search.spacing_limit.as_ref().map_or(
                if pipeline.face().words().spacing_field.is_some() {
                    flight::MAX_SPACING
                } else {
                    1.0
                },
                |l| l.margin,
            );
            if widest > 1.0 {
                println!(
                    "spacing      none up to ×{widest:.2} ({spacing_field}) meets {:.2} %",
                    100.0 * target
                );
            } else {
                println!("spacing      {spacing_field} cannot be widened here");
            }
            print_limit("spacing", search.spacing_limit.as_ref(), |s| {
                format!("×{s:.2}")
            });
            exit::INFEASIBLE
        }
        (None, ..) => {
            println!(
                "margin       none up to {highest_margin:.2} m from the obstacles keeps r_Q in all \
                 but {:.2} % of flights",
                100.0 * target
            );
            print_limit("margin", search.limit.as_ref(), |m| format!("{m:.2} m"));
            exit::INFEASIBLE
        }
    };
    print_fixes(&search);
    println!("tried        {}", tried.join("; "));
    if let Some(report) = &search.report {
        print!("{}", report.text(args.verbose));
    }
    if let (Some(path), Ok(text)) = (&args.json, serde_json::to_string_pretty(&search))
        && let Err(e) = atomic::write(path, text.as_bytes())
    {
        eprintln!("error: {}: {e}", path.display());
        return exit::ERROR;
    }
    code
}

/// A check that did not end, said on stderr: its exit status.
pub(super) fn said(e: &FlightError) -> u8 {
    if *e == FlightError::Cancelled {
        eprintln!("cancelled");
        exit::CANCELLED
    } else {
        eprintln!("error: {e}");
        exit::ERROR
    }
}

/// The `fixes` line: what finer GNSS fixes do at the nearest try.
fn print_fixes(search: &flight::MarginSearch) {
    if let (Some(near), Some(b)) = (&search.nearest, &search.better_fixes) {
        let at = if near.spacing == 1.0 {
            format!("{:.2} m", near.margin)
        } else {
            format!("{:.2} m, spacing ×{:.2}", near.margin, near.spacing)
        };
        println!(
            "fixes        at the nearest try ({at}), {} fixes (GNSS σ {} m horizontal, {} m vertical: \
             flight.gnss_sigma_horizontal, gnss_sigma_vertical) {}: {} of {} flights break a limit \
             ({:.2} %, 95 % CI {:.2}-{:.2} %)",
            b.grade,
            b.sigma_horizontal,
            b.sigma_vertical,
            if b.meets {
                "meet the target"
            } else {
                "still miss it"
            },
            b.share.count,
            b.share.of,
            100.0 * b.share.share,
            100.0 * b.share.low,
            100.0 * b.share.high
        );
    }
}

/// The `limit` line: the largest `what` the mission stays valid with, as
/// `shown`, and the validator's words above it.
fn print_limit(what: &str, limit: Option<&flight::MarginLimit>, shown: fn(f64) -> String) {
    if let Some(limit) = limit {
        println!(
            "limit        no {what} above {} is valid: {}",
            shown(limit.margin),
            limit.why
        );
    }
}

/// The θ-PSO slots as a TOML array, to the millimetre.
fn slots_text(mission: &Mission) -> String {
    let slots: Vec<String> = mission
        .formation
        .slots
        .iter()
        .map(|s| format!("[{:.3}, {:.3}, {:.3}]", s.x, s.y, s.z))
        .collect();
    format!("[{}]", slots.join(", "))
}

/// 1 − share as a percentage of flights kept ("99.9 %").
fn format_share(share: f64) -> String {
    format!("{:.1} %", 100.0 * (1.0 - share))
}

/// `--rare`: each limit's probability by subset simulation (the mean of
/// `--runs` independent runs), printed and (`--json`) written as
/// `{"separation": {estimate, low, high, method, flights, …, runs: […]},
/// "clearance": {…}}`; with `--shard I/N`, this shard's runs written as a
/// part for `skyform merge`. Exit 2 when either estimate is at least one in
/// a million.
fn rare(setup: &Setup, mission: &Mission, args: &FlyArgs, seed: u64, cancel: &CancelToken) -> u8 {
    use flight::odds::{self, OddsReport};
    use flight::rare::{self, RareOptions};
    let terminal = std::io::stderr().is_terminal();
    let options = RareOptions {
        per_level: args.per_level.max(10),
        seed,
        threads: args.threads,
    };
    if !(1..=odds::MAX_RUNS).contains(&args.runs) {
        eprintln!("error: --runs {}: from 1 to {}", args.runs, odds::MAX_RUNS);
        return exit::ERROR;
    }
    let progress = |run: usize, limit: rare::Limit, done: usize, level: usize| {
        if terminal && done.is_multiple_of(50) {
            eprint!(
                "\rrun {run}: {}: level {level}, {done} flights",
                limit.words()
            );
        }
    };
    if let Some(shard) = &args.shard {
        return super::merge_cmd::rare_shard(
            setup, mission, args, options, shard, &progress, cancel,
        );
    }
    println!(
        "rare-event odds of {} ({}, {} flights a level, {} run(s), seed {seed})",
        setup.mission.name,
        rare::METHOD,
        options.per_level,
        args.runs
    );
    let runs = odds::fly_runs(setup, options, 0..args.runs, &progress, cancel);
    if terminal {
        eprintln!();
    }
    let runs = match runs {
        Ok(r) => r,
        Err(e) => return said(&e),
    };
    let report = OddsReport::new(&setup.mission.name, seed, options.per_level, runs);
    let status = odds_written(&report, args.json.as_deref());
    if let Some(path) = &args.failure {
        let odds = [&report.separation, &report.clearance];
        if let Err(code) =
            super::fly_again::write_failing(path, mission, args.pipeline, seed, &odds)
        {
            return code;
        }
    }
    status
}

/// A rare-event report printed and written as JSON to `json`
/// (atomically), and the exit status it gives: 2 when either estimate is at
/// least 10⁻⁶, 0 when both are below.
pub(super) fn odds_written(
    report: &flight::odds::OddsReport,
    json: Option<&std::path::Path>,
) -> u8 {
    print!("{}", odds_text(&report.separation));
    print!("{}", odds_text(&report.clearance));
    if let Some(path) = json
        && let Err(status) = json_written(report, "the estimate", path, true)
    {
        return status;
    }
    if report.separation.estimate >= 1e-6 || report.clearance.estimate >= 1e-6 {
        exit::INFEASIBLE
    } else {
        exit::OK
    }
}

/// One limit's odds in words.
pub fn odds_text(o: &flight::odds::Odds) -> String {
    let runs = o.runs.len();
    let how = if runs == 1 {
        format!("{} level(s)", o.runs.first().map_or(0, |e| e.levels.len()))
    } else {
        format!("{runs} runs")
    };
    let mut out = if o.bound {
        format!(
            "  {:<24} below {:.1e}: no flight broke it in {how} ({} flights)\n",
            o.limit.words(),
            o.high,
            o.flights
        )
    } else {
        format!(
            "  {:<24} P = {:.2e} (95 % {:.2e} to {:.2e}, c.o.v. {:.2}), {} flights, {how}\n",
            o.limit.words(),
            o.estimate,
            o.low,
            o.high,
            o.cov,
            o.flights,
        )
    };
    if let Some(f) = &o.most_likely {
        let run = if runs > 1 {
            format!("run {}, ", f.run)
        } else {
            String::new()
        };
        out += &format!(
            "    most likely failure: {} at t = {:.1} s, {:.2} m past the limit ({run}{})\n",
            f.what,
            f.t,
            -f.room,
            if f.at.0 == 0 {
                format!("level 0, flight {}", f.at.1)
            } else {
                format!("level {}, chain {}, move {}", f.at.0, f.at.1, f.at.2)
            }
        );
    }
    out
}
