//! A flight check beyond one machine: `skyform fly --shard I/N` writes one
//! shard's flights as a part, `skyform merge` turns the parts into the
//! report one process gives (`flight::shard`, docs/flight-check.md).

use std::path::PathBuf;

use super::exit;
use super::fly_cmd::{FlyArgs, said};
use crate::flight::{self, Options, Setup};
use crate::mission::Mission;
use crate::pipelines::CancelToken;

/// What every shard starts from: its `I/N`, the `--json` file its part
/// goes to (`pieces`: what the part holds, for the error), and the mission
/// as TOML for the part; or the exit status, said.
fn shard_start<'a>(
    args: &'a FlyArgs,
    mission: &Mission,
    shard: &str,
    pieces: &str,
) -> Result<(flight::shard::Shard, &'a std::path::Path, String), u8> {
    let shard = flight::shard::Shard::parse(shard).map_err(|e| {
        eprintln!("error: --shard {e}");
        exit::ERROR
    })?;
    let Some(path) = &args.json else {
        eprintln!("error: --shard writes its {pieces} to --json FILE");
        return Err(exit::ERROR);
    };
    let toml = crate::mission::to_toml_string(mission).map_err(|e| {
        eprintln!("error: {e}");
        exit::ERROR
    })?;
    Ok((shard, path, toml))
}

/// `--shard I/N`: this shard's flights written as a part for `skyform merge`.
pub fn fly_shard(
    setup: &Setup,
    mission: &Mission,
    args: &FlyArgs,
    seed: u64,
    shard: &str,
    cancel: &CancelToken,
) -> u8 {
    let (shard, path, toml) = match shard_start(args, mission, shard, "flights") {
        Ok(start) => start,
        Err(code) => return code,
    };
    let options = Options {
        flights: mission.flight.flights,
        seed,
        threads: args.threads,
    };
    let range = shard.range(options.flights);
    let part = match flight::shard::fly_shard(
        setup,
        toml,
        args.pipeline,
        options,
        shard,
        &|_, _| {},
        cancel,
    ) {
        Ok(p) => p,
        Err(e) => return said(&e),
    };
    let breaks = part
        .flown
        .iter()
        .filter(|f| f.broke_separation(setup) || f.broke_clearance(setup))
        .count();
    if let Err(status) = super::fly_cmd::json_written(&part, "the part", path, false) {
        return status;
    }
    println!(
        "shard {}/{} of {} flights of \"{}\" (seed {seed}): flights {}-{}, {breaks} broke a limit; \
         written to {} (merge the parts with `skyform merge`)",
        shard.index,
        shard.count,
        options.flights,
        setup.mission.name,
        range.start,
        range.end.saturating_sub(1),
        path.display()
    );
    exit::OK
}

/// `--rare --shard I/N`: this shard's runs of the rare-event estimate
/// written as a part for `skyform merge`.
pub fn rare_shard(
    setup: &Setup,
    mission: &Mission,
    args: &FlyArgs,
    options: flight::rare::RareOptions,
    shard: &str,
    progress: &(dyn Fn(usize, flight::rare::Limit, usize, usize) + Sync),
    cancel: &CancelToken,
) -> u8 {
    use flight::odds;
    let (shard, path, toml) = match shard_start(args, mission, shard, "runs") {
        Ok(start) => start,
        Err(code) => return code,
    };
    let range = shard.range(args.runs);
    let done = match odds::fly_runs(setup, options, range.clone(), progress, cancel) {
        Ok(d) => d,
        Err(e) => return said(&e),
    };
    if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        eprintln!();
    }
    if let Some(path) = &args.failure {
        // This shard's runs as one report: its most likely failures.
        let own = odds::OddsReport::new(
            &setup.mission.name,
            options.seed,
            options.per_level,
            done.clone(),
        );
        let failing = [&own.separation, &own.clearance];
        let written =
            super::fly_again::write_failing(path, mission, args.pipeline, options.seed, &failing);
        if let Err(code) = written {
            return code;
        }
    }
    let flights: usize = done
        .iter()
        .map(|r| r.separation.flights + r.clearance.flights)
        .sum();
    let part = odds::Part {
        format: odds::PART_FORMAT.to_owned(),
        mission: toml,
        name: setup.mission.name.clone(),
        pipeline: args.pipeline,
        seed: options.seed,
        per_level: options.per_level,
        runs: args.runs,
        shard,
        done,
    };
    if let Err(status) = super::fly_cmd::json_written(&part, "the part", path, false) {
        return status;
    }
    let which = if range.is_empty() {
        "no run".to_owned()
    } else {
        format!("runs {}-{}", range.start, range.end - 1)
    };
    println!(
        "shard {}/{} of {} rare-event runs of \"{}\" (seed {}): {which}, {flights} flights; \
         written to {} (merge the parts with `skyform merge`)",
        shard.index,
        shard.count,
        args.runs,
        setup.mission.name,
        options.seed,
        path.display()
    );
    exit::OK
}

/// The arguments of `skyform merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// The parts written by `skyform fly … --shard I/N --json PART` (a
    /// check's, or with `--rare` an estimate's), one per shard, in any
    /// order.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Write the merged report as JSON to FILE (as `skyform fly --json`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// List every pair and every obstacle, not the five tightest.
    #[arg(long)]
    pub verbose: bool,
}

/// `skyform merge`: the parts of a sharded check, or of a sharded
/// rare-event estimate, into its report. Exit status as `skyform fly`: 0 no
/// flight broke a limit (no estimate at 10⁻⁶ or more), 2 some did, 1 error.
pub fn merge_command(args: &MergeArgs) -> u8 {
    let mut texts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        match std::fs::read_to_string(path) {
            Ok(t) => texts.push(t),
            Err(e) => {
                eprintln!("error: {}: {e}", path.display());
                return exit::ERROR;
            }
        }
    }
    // The first part's format says which kind of parts these are.
    let format = texts
        .first()
        .and_then(|t| serde_json::from_str::<Format>(t).ok());
    if format.is_some_and(|f| f.format == flight::odds::PART_FORMAT) {
        return merge_odds(args, &texts);
    }
    let mut parts = Vec::with_capacity(texts.len());
    for (path, text) in args.parts.iter().zip(&texts) {
        match serde_json::from_str::<flight::shard::Part>(text) {
            Ok(p) => parts.push(p),
            Err(e) => {
                eprintln!(
                    "error: {}: not a part of `skyform fly --shard` ({e})",
                    path.display()
                );
                return exit::ERROR;
            }
        }
    }
    let (first, flown) = match flight::shard::merge(parts) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            return exit::ERROR;
        }
    };
    let origin = args.parts[0].display().to_string();
    let mission = match crate::mission::parse_str(&first.mission, &origin) {
        Ok(loaded) => loaded.mission,
        Err(e) => {
            eprintln!("error: the mission in {origin}: {e}");
            return exit::ERROR;
        }
    };
    let planned = match super::export_cmd::planned(&mission, first.pipeline, first.seed) {
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
    let options = Options {
        flights: first.flights,
        seed: first.seed,
        threads: None,
    };
    let report = flight::Report::new(&setup, options, &flown, &flight::as_written(&setup));
    print!("{}", report.text(args.verbose));
    super::fly_cmd::report_written(&report, args.json.as_deref())
}

/// A part's `format`, read before the rest says which part it is.
#[derive(serde::Deserialize)]
struct Format {
    format: String,
}

/// The parts of a sharded rare-event estimate into its report.
fn merge_odds(args: &MergeArgs, texts: &[String]) -> u8 {
    let mut parts = Vec::with_capacity(texts.len());
    for (path, text) in args.parts.iter().zip(texts) {
        match serde_json::from_str::<flight::odds::Part>(text) {
            Ok(p) => parts.push(p),
            Err(e) => {
                eprintln!(
                    "error: {}: not a part of `skyform fly --rare --shard` ({e})",
                    path.display()
                );
                return exit::ERROR;
            }
        }
    }
    match flight::odds::merge(parts) {
        Ok(report) => super::fly_cmd::odds_written(&report, args.json.as_deref()),
        Err(e) => {
            eprintln!("error: {e}");
            exit::ERROR
        }
    }
}
