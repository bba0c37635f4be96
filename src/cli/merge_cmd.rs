//! A flight check beyond one machine: `skyform fly --shard I/N` writes one
//! shard's flights as a part, `skyform merge` turns the parts into the
//! report one process gives (`flight::shard`, docs/flight-check.md).

use std::path::PathBuf;

use super::exit;
use super::fly_cmd::{FlyArgs, said};
use crate::flight::{self, Options, Setup};
use crate::mission::Mission;
use crate::pipelines::CancelToken;

/// `--shard I/N`: this shard's flights written as a part for `skyform merge`.
pub fn fly_shard(
    setup: &Setup,
    mission: &Mission,
    args: &FlyArgs,
    seed: u64,
    shard: &str,
    cancel: &CancelToken,
) -> u8 {
    let shard = match flight::shard::Shard::parse(shard) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: --shard {e}");
            return exit::ERROR;
        }
    };
    let Some(path) = &args.json else {
        eprintln!("error: --shard writes its flights to --json FILE");
        return exit::ERROR;
    };
    let toml = match crate::mission::to_toml_string(mission) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return exit::ERROR;
        }
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

/// The arguments of `skyform merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// The parts written by `skyform fly … --shard I/N --json PART`, one
    /// per shard, in any order.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Write the merged report as JSON to FILE (as `skyform fly --json`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// List every pair and every obstacle, not the five tightest.
    #[arg(long)]
    pub verbose: bool,
}

/// `skyform merge`: the parts of a sharded check into its report. Exit
/// status as `skyform fly`: 0 no flight broke a limit, 2 some did, 1 error.
pub fn merge_command(args: &MergeArgs) -> u8 {
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("error: {}: {e}", path.display());
                return exit::ERROR;
            }
        };
        match serde_json::from_str::<flight::shard::Part>(&text) {
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
