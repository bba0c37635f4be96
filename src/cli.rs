//! The command line: clap subcommands that call the library and print.
//!
//! Long (~920 lines) because it holds the clap tree of every subcommand with its help text,
//! `main`'s dispatch, and the plumbing the commands share (loading and reporting a mission,
//! recorders, Ctrl-C, the stderr progress, running a pipeline); the larger commands
//! already have files of their own.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::mission::{self, Checked, Report};
use crate::pipelines::{CancelToken, Completion, Event, Kind, Level, Observer, PlanOptions};
use crate::pipelines::{flatlo, fleet, theta_pso};
use crate::record::{self, Recorder, Sinks};
use crate::run::Run;

pub mod eval_cmd;
pub mod export_cmd;
pub mod fly_again;
pub mod fly_cmd;
pub mod import_cmd;
pub mod merge_cmd;
pub mod sweep_cmd;

/// Terminal mission designer for multi-UAV formations.
///
/// Without a command, opens the mission designer (TUI) on FILE, or on the
/// built-in bridge-inspection mission.
#[derive(Debug, Parser)]
#[command(name = "skyform", version, about, long_about = None, args_conflicts_with_subcommands = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Mission file to open in the designer (a new, minimal mission when it
    /// does not exist; written on the first save).
    pub file: Option<PathBuf>,
    /// Open the designer with live planning off (L turns it on): plans only
    /// when asked, with r.
    #[arg(long)]
    pub no_live: bool,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Open a mission file in the designer (TUI); same as `skyform FILE`.
    Edit {
        /// Mission TOML file (a new, minimal mission when it does not exist;
        /// written on the first save).
        file: PathBuf,
        /// Live planning off at the start (L turns it on).
        #[arg(long)]
        no_live: bool,
    },
    /// Start a new mission file and open it in the designer.
    ///
    /// Without --from the file is the minimal mission (a box, a start, a goal,
    /// the default formation; no origin, no obstacles); with --from it is a
    /// copy of that mission, comments and all. Refuses to replace a file.
    New {
        /// The mission file to create.
        file: PathBuf,
        /// Copy this mission instead: a file, or a shipped mission by name
        /// (bridge-inspection, narrow-passage, flatlo-squadron, fleet-triangle).
        #[arg(long, value_name = "MISSION")]
        from: Option<String>,
        /// Only write the file; do not open the designer.
        #[arg(long)]
        no_open: bool,
    },
    /// Validate mission files: print every error and warning with its line.
    ///
    /// Exits 0 when every file is valid, 1 when any has an error.
    Check {
        /// Mission TOML files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Treat warnings as errors.
        #[arg(long)]
        strict: bool,
        /// Print the diagnostics as JSON (one object per file) instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Run a planning pipeline on a mission.
    #[command(subcommand)]
    Run(RunCommand),
    /// Log a mission's scene (bounds, obstacles, route, IWPs) to Rerun without
    /// planning anything.
    Record {
        /// Mission TOML file.
        mission: PathBuf,
        #[command(flatten)]
        record: RecordArgs,
    },
    /// Plan a mission and write one autopilot mission file per vehicle
    /// (.plan, .waypoints, CSV), re-verified as it will be flown, and/or a
    /// KML of the whole plan.
    ///
    /// Files: `<mission-stem>-<pipeline>-uav<N>.<ext>` in DIR, and
    /// `<mission-stem>-<pipeline>.kml` (the mission, each vehicle's planned
    /// track in a folder of its own in its map colour, the verdict; altitudes
    /// relative to the ground). Each vehicle's
    /// track becomes waypoints within the tolerance of where the plan has it
    /// at each instant, with a commanded speed per leg so that it reaches
    /// each waypoint on time. The plans are flown as an autopilot flies them
    /// (straight legs at the commanded speeds, all vehicles starting
    /// together) and checked with the pipeline's own verification; a flown
    /// plan that breaks a constraint is refused unless --force. `plan`, `wpl`
    /// and `kml` need the mission's [origin]; `csv` works without it (ENU only).
    /// Prints the files, their waypoint counts, the largest deviation and
    /// timing error. Exit status: 0 written, 1 error, 2 refused, 130
    /// cancelled (Ctrl-C). See docs/export.md.
    Export(export_cmd::ExportArgs),
    /// Will the plan survive the air? Plan a mission, then fly its exported
    /// missions many times as the autopilots will (each leg at its written
    /// speed, each waypoint taken within the acceptance radius), in wind
    /// with Dryden gusts, on drifting GNSS fixes, taking off a little apart,
    /// and report what that does to the margins.
    ///
    /// The mission's [flight] section sets the air, the fixes and the
    /// autopilot (defaults: calm, GNSS σ 1 m horizontal and 1.5 m vertical,
    /// take-off skew σ 0.3 s). Prints the share of flights that break
    /// 2 r_Q and r_Q with 95 % intervals first, then the worst flight (replay
    /// it with --flight K), the tightest pairs and obstacles as percentiles
    /// over the flights beside the plan as written, and each vehicle's
    /// cross-track error. The same mission and seed give the same report on
    /// any number of threads. Exit status: 0 no flight broke a limit, 1
    /// error, 2 some flight did, 130 cancelled. See docs/flight-check.md.
    Fly(fly_cmd::FlyArgs),
    /// Merge the parts of a sharded flight check (`skyform fly … --shard
    /// I/N --json PART`, run anywhere: a Slurm array, a Kubernetes Indexed
    /// Job, a Ray cluster) into the report one process gives, bit for bit.
    /// Checks the parts are one check's and cover every flight once, plans
    /// the mission they carry again, and prints (and with --json writes)
    /// the report. The parts of a sharded rare-event estimate (`--rare
    /// --runs K --shard I/N`) merge the same way into its odds, no flight
    /// flown again. Exit status as `skyform fly`. See docs/flight-check.md.
    Merge(merge_cmd::MergeArgs),
    /// Bring a site survey's obstacles into a mission: GeoJSON (RFC 7946),
    /// KML or KMZ, as Google Earth, QGIS or OpenStreetMap draw them.
    ///
    /// Heights: a feature's `height` (or `top`) and `base` (or `min_height`)
    /// properties, metres above the ground (KML: ExtendedData), else the
    /// altitudes it is drawn with: KML's altitudeMode (relativeToGround;
    /// absolute, less [origin] altitude; clampToGround has none) and
    /// extrude; GeoJSON's third coordinate (above the WGS-84 ellipsoid, less
    /// [origin] altitude). A point is a post up to its altitude; an extruded
    /// polygon a footprint standing on the ground, one not extruded a deck
    /// at its altitude (resting on what the survey stands under it); a line
    /// not extruded, or marked as a power line or cable, a wire at its
    /// height (flown under or over, kept `radius`, 0.5 m, round it); another
    /// line a row of posts. Without any height, 1 m above the altitude band
    /// (a warning lists them); without a radius, 1 m. Everything is clipped
    /// to the bounds and written to the millimetre; the report says how
    /// each feature was read. Names from `name`, kinds from `kind` (KML: the
    /// folder). Obstacles are matched by name: importing the same file again
    /// changes nothing, a default never replaces a known height or radius.
    /// The mission is edited in place (comments and layout kept) and saved
    /// atomically; nothing is written on an error. Needs the mission's
    /// [origin]. Exit status: 0 imported (or nothing to change), 1 error, 2
    /// refused: the survey would lower, thin or remove an obstacle the
    /// mission has, or the mission would have validation errors it does not
    /// have now (--force writes it anyway).
    Import(import_cmd::ImportArgs),
    /// Print the cost of given paths under the mission's cost, one per line
    /// with 17 significant digits (`inf` where infinite): the parity hook
    /// with the SPSO benchmark's reference code (see docs/spso.md).
    ///
    /// Each CSV row holds 3 n numbers: the n free nodes' x, then y, then z
    /// above the ground. Exit status: 0 printed, 1 error.
    Eval(eval_cmd::EvalArgs),
    /// Run a pipeline over many seeds in parallel and print a table:
    /// how many gave a result (θ-PSO: J finite; FLATLO, fleet: finished),
    /// how many the verdict passed (θ-PSO: feasible; FLATLO, fleet: passed),
    /// the best cost (or headline figure) mean ± sd, median, min, max, wall
    /// and CPU time, cost evaluations per CPU-second.
    ///
    /// Exit status: 0 every run finished, 1 an error.
    Sweep(sweep_cmd::SweepArgs),
    /// Fly some of a fleet's agents in this process, talking to the others
    /// over Zenoh (`skyform run fleet --distributed` starts these itself).
    ///
    /// Connects to a coordinator's hub, says which agents it flies and which
    /// mission (a different mission or seed is refused), then flies them
    /// step by step until the coordinator ends the run. Exits when the
    /// coordinator goes away. Exit status: 0 the run ended, 1 an error
    /// (printed on stderr).
    #[cfg(feature = "zenoh")]
    Agent(AgentArgs),
}

/// `skyform agent`.
#[cfg(feature = "zenoh")]
#[derive(Debug, clap::Args)]
pub struct AgentArgs {
    /// Mission TOML file (the coordinator's mission: checked by fingerprint).
    pub mission: PathBuf,
    /// The agents to fly, numbered from 1: `2`, `1-3`, `1,4-6`.
    #[arg(long)]
    pub ids: String,
    /// The coordinator's hub, e.g. tcp/127.0.0.1:7447.
    #[arg(long, value_name = "ENDPOINT")]
    pub connect: String,
    /// The run's name (the coordinator gives it; keys are under
    /// skyform/<mission>/<run>).
    #[arg(long, default_value = "run")]
    pub run: String,
    /// Seed of the run (default: the mission's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Fly on this process's own clock instead of the coordinator's steps.
    #[arg(long)]
    pub realtime: bool,
    /// Longest wait for the coordinator, seconds.
    #[arg(long, default_value_t = 20.0)]
    pub timeout: f64,
}

#[derive(Debug, Subcommand)]
pub enum RunCommand {
    /// θ-PSO formation path planning with reconfiguration at intermediate waypoints.
    ///
    /// Before the swarm, a route stage searches for a corridor the formation
    /// can fly (through the IWPs, shrunk or in a column where the site is
    /// narrower than it); with none, the run stops there and names what
    /// closes the way. Progress goes to stderr, a summary to stdout (the
    /// verdict first). Exit status: 0 feasible plan, 1 error, 2 infeasible
    /// plan or no corridor, 130 cancelled (Ctrl-C).
    ThetaPso {
        /// Mission TOML file.
        mission: PathBuf,
        /// List every unusable IWP in the summary (default: counted by
        /// reason, the few nearest the path named).
        #[arg(long)]
        verbose: bool,
        /// Seed of the swarm (default: the mission's `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Write the whole outcome as JSON to FILE, or to stdout with `-`
        /// (the summary then goes to stderr).
        #[arg(long, value_name = "FILE|-")]
        json: Option<PathBuf>,
        /// Evaluate the swarm on one thread (same result, slower).
        #[arg(long)]
        sequential: bool,
        /// Search about the plan in FILE (a JSON object with `waypoints` and
        /// `pass_angles`: a run's outcome, or the `warm_start` record of a
        /// warm-started one, to repeat it) with a swarm of at most 25 (that
        /// plan, ten particles about it, the corridor's first seeds), and
        /// stop it once it settles, as the designer's live re-plans do.
        #[arg(long, value_name = "FILE")]
        warm_from: Option<PathBuf>,
        #[command(flatten)]
        record: RecordArgs,
    },
    /// The distributed fleet: one PSO per quadrotor, flown by quadrotor
    /// dynamics under quaternion control.
    ///
    /// Progress goes to stderr, a summary to stdout. Exit status: 0 formed at
    /// every target and kept the safety distance, 1 error, 2 did not, 130
    /// cancelled (Ctrl-C).
    Fleet(FleetArgs),
    /// FLATLO: the latitudinal-to-longitudinal squadron transition, simulated
    /// with the point-mass aircraft model and verified.
    ///
    /// Progress goes to stderr, a summary to stdout. Exit status: 0 the
    /// squadron kept its minimum separation, 1 error, 2 it did not, 130
    /// cancelled (Ctrl-C).
    Flatlo {
        /// Mission TOML file (its [flatlo] section).
        mission: PathBuf,
        /// Seed of the noise (default: the mission's `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Write the whole outcome as JSON to FILE, or to stdout with `-`.
        #[arg(long, value_name = "FILE|-")]
        json: Option<PathBuf>,
        #[command(flatten)]
        record: RecordArgs,
    },
    /// Any other registered pipeline, with the options every run has:
    /// `skyform run NAME MISSION [--seed S] [--json FILE|-] [--verbose]
    /// [recording options]`.
    #[command(external_subcommand)]
    Other(Vec<String>),
}

/// `skyform run NAME …` for a registered pipeline without a subcommand of
/// its own (`RunCommand::Other`).
#[derive(Debug, Parser)]
struct PlainRunArgs {
    /// Mission TOML file.
    mission: PathBuf,
    /// Seed of the run (default: the mission's `seed`).
    #[arg(long)]
    seed: Option<u64>,
    /// Write the whole outcome as JSON to FILE, or to stdout with `-`.
    #[arg(long, value_name = "FILE|-")]
    json: Option<PathBuf>,
    /// The summary lists everything it would count.
    #[arg(long)]
    verbose: bool,
    #[command(flatten)]
    record: RecordArgs,
}

/// A registered pipeline run through [`PlainRunArgs`]; an unknown name
/// is an error that lists the pipelines.
fn run_other(args: &[String]) -> u8 {
    let name = args.first().map_or("", String::as_str);
    let Some(kind) = Kind::ALL.into_iter().find(|k| k.words().slug == name) else {
        let known: Vec<&str> = Kind::ALL.iter().map(|k| k.words().slug).collect();
        eprintln!(
            "error: no pipeline '{name}' to run: {} (skyform run --help)",
            known.join(", ")
        );
        return exit::ERROR;
    };
    let plain = match PlainRunArgs::try_parse_from(args) {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() {
                exit::ERROR
            } else {
                exit::OK
            };
        }
    };
    run_pipeline(
        &plain.mission,
        plain.seed,
        plain.json.as_deref(),
        &plain.record.sinks(),
        plain.verbose,
        |seed| Run::new(kind, seed),
    )
}

/// The distributed fleet: one PSO per quadrotor every τ, flown by
/// quadrotor dynamics under quaternion control.
///
/// Progress goes to stderr, a summary to stdout. Exit status: 0 the fleet
/// formed at every target and kept the safety distance, 1 error, 2 it did
/// not, 130 cancelled (Ctrl-C).
#[derive(Debug, clap::Args)]
pub struct FleetArgs {
    /// Mission TOML file (its [fleet] section).
    pub mission: PathBuf,
    /// Seed of the random starts and of every agent's PSO (default: the mission's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Write the whole outcome as JSON to FILE, or to stdout with `-`.
    #[arg(long, value_name = "FILE|-")]
    pub json: Option<PathBuf>,
    /// Fly the agents in P processes of their own on this machine, talking
    /// over Zenoh (loopback TCP); this process coordinates. Lockstep, the
    /// result is the in-process run's, bit for bit.
    #[cfg(feature = "zenoh")]
    #[arg(long, value_name = "P")]
    pub distributed: Option<usize>,
    /// With --distributed: each process flies on its own wall clock, as
    /// onboard (not reproducible), instead of the coordinator's steps.
    #[cfg(feature = "zenoh")]
    #[arg(long, requires = "distributed")]
    pub realtime: bool,
    #[command(flatten)]
    pub record: RecordArgs,
}

/// Where to send a Rerun recording of the run.
#[derive(Debug, Clone, clap::Args)]
pub struct RecordArgs {
    /// Save a Rerun recording to FILE (open it with `rerun FILE`).
    #[arg(long, value_name = "FILE")]
    pub rrd: Option<PathBuf>,
    /// Stream to a running Rerun viewer [default URL: rerun+http://127.0.0.1:9876/proxy].
    #[arg(long, value_name = "URL", num_args = 0..=1, default_missing_value = record::DEFAULT_VIEWER_URL)]
    pub connect: Option<String>,
    /// Start a local Rerun viewer (the `rerun` binary on PATH) and stream to it.
    #[arg(long)]
    pub spawn: bool,
}

impl RecordArgs {
    fn sinks(&self) -> Sinks {
        Sinks {
            rrd: self.rrd.clone(),
            connect: self.connect.clone(),
            spawn: self.spawn,
        }
    }
}

/// Exit status of a run, as the shell sees it.
pub mod exit {
    /// Success; for `run`, a feasible plan.
    pub const OK: u8 = 0;
    /// Invalid input or a failure.
    pub const ERROR: u8 = 1;
    /// The plan breaks a hard constraint.
    pub const INFEASIBLE: u8 = 2;
    /// Stopped by Ctrl-C (128 + SIGINT).
    pub const CANCELLED: u8 = 130;
}

/// Entry point of the binary.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let Some(command) = cli.command else {
        return ExitCode::from(edit(cli.file, !cli.no_live));
    };
    match command {
        Command::Edit { file, no_live } => ExitCode::from(edit(Some(file), !no_live)),
        Command::New {
            file,
            from,
            no_open,
        } => ExitCode::from(new_mission(&file, from.as_deref(), no_open)),
        Command::Check {
            files,
            strict,
            json,
        } => ExitCode::from(check(&files, strict, json)),
        Command::Run(RunCommand::ThetaPso {
            mission,
            verbose,
            seed,
            json,
            sequential,
            warm_from,
            record,
        }) => {
            let options = PlanOptions {
                parallel: !sequential,
            };
            let warm = match warm_from.as_deref().map(read_warm_start).transpose() {
                Ok(w) => w.map(std::sync::Arc::new),
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(exit::ERROR);
                }
            };
            ExitCode::from(run_pipeline(
                &mission,
                seed,
                json.as_deref(),
                &record.sinks(),
                verbose,
                |seed| Run {
                    options,
                    ..Run::asking(theta_pso::Request { warm: warm.clone() }, seed)
                },
            ))
        }
        Command::Run(RunCommand::Fleet(a)) => {
            #[cfg(feature = "zenoh")]
            let processes = a.distributed.map(|count| crate::pipelines::Processes {
                count,
                realtime: a.realtime,
            });
            #[cfg(not(feature = "zenoh"))]
            let processes = None;
            ExitCode::from(run_pipeline(
                &a.mission,
                a.seed,
                a.json.as_deref(),
                &a.record.sinks(),
                false,
                |seed| Run::asking(fleet::Request { processes }, seed),
            ))
        }
        Command::Run(RunCommand::Flatlo {
            mission,
            seed,
            json,
            record,
        }) => ExitCode::from(run_pipeline(
            &mission,
            seed,
            json.as_deref(),
            &record.sinks(),
            false,
            |seed| Run::asking(flatlo::Request, seed),
        )),
        Command::Run(RunCommand::Other(args)) => ExitCode::from(run_other(&args)),
        Command::Record { mission, record } => {
            ExitCode::from(record_mission(&mission, &record.sinks()))
        }
        Command::Export(args) => ExitCode::from(export_cmd::export_command(&args)),
        Command::Fly(args) => ExitCode::from(fly_cmd::fly_command(&args)),
        Command::Merge(args) => ExitCode::from(merge_cmd::merge_command(&args)),
        Command::Import(args) => ExitCode::from(import_cmd::import_command(&args)),
        Command::Eval(args) => ExitCode::from(eval_cmd::eval_command(&args)),
        Command::Sweep(args) => ExitCode::from(sweep_cmd::sweep_command(&args)),
        #[cfg(feature = "zenoh")]
        Command::Agent(args) => ExitCode::from(agent(&args)),
    }
}

/// `skyform agent`: errors go to stderr (the coordinator relays them).
#[cfg(feature = "zenoh")]
fn agent(args: &AgentArgs) -> u8 {
    let Some(mission) = load_reporting(&args.mission) else {
        return exit::ERROR;
    };
    let ids = match crate::distributed::wire::parse_ids(&args.ids, mission.fleet.agents) {
        Ok(ids) => ids,
        Err(e) => {
            eprintln!("error: --ids: {e}");
            return exit::ERROR;
        }
    };
    if !(args.timeout.is_finite() && args.timeout > 0.0) {
        eprintln!("error: --timeout: must be a positive number of seconds");
        return exit::ERROR;
    }
    let options = crate::distributed::AgentOptions {
        connect: args.connect.clone(),
        run: args.run.clone(),
        seed: args.seed.unwrap_or(mission.seed),
        timeout: std::time::Duration::from_secs_f64(args.timeout.min(86_400.0)),
        realtime: args.realtime,
        spawned_by: std::env::var(crate::distributed::agent::SPAWNED_BY)
            .ok()
            .and_then(|pid| pid.parse().ok()),
    };
    match crate::distributed::fly(&mission, ids, &options) {
        Ok(()) => exit::OK,
        Err(e) => {
            eprintln!("error: {e}");
            exit::ERROR
        }
    }
}

/// The TUI; errors (not a terminal, a file that is not a mission) go to stderr.
fn edit(file: Option<PathBuf>, live: bool) -> u8 {
    match crate::tui::run(file, live) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            exit::ERROR
        }
    }
}

/// `skyform new`: writes the template or a copy of `from` at `file`, then
/// opens the designer on it (unless `no_open`).
fn new_mission(file: &std::path::Path, from: Option<&str>, no_open: bool) -> u8 {
    if file.exists() {
        eprintln!(
            "error: {} exists; open it with `skyform {}` or choose another name",
            file.display(),
            file.display()
        );
        return exit::ERROR;
    }
    let (text, source) = match from {
        None => (
            mission::template_text(&mission::name_for(file)),
            "the minimal mission".to_owned(),
        ),
        Some(from) => match copied_mission(from) {
            Ok(found) => found,
            Err(e) => {
                eprintln!("error: {e}");
                return exit::ERROR;
            }
        },
    };
    if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty())
        && let Err(e) = std::fs::create_dir_all(dir)
    {
        eprintln!("error: cannot create {}: {e}", dir.display());
        return exit::ERROR;
    }
    if let Err(e) = crate::base::atomic::write(file, text.as_bytes()) {
        eprintln!("error: cannot write {}: {e}", file.display());
        return exit::ERROR;
    }
    eprintln!("created {} from {source}", file.display());
    if no_open {
        exit::OK
    } else {
        edit(Some(file.to_path_buf()), true)
    }
}

/// The text of the mission `from` names (a file, else a shipped mission by
/// file name or stem) and what to call it; it must be a mission.
fn copied_mission(from: &str) -> Result<(String, String), String> {
    let path = std::path::Path::new(from);
    let (text, source) = if path.is_file() {
        let text = mission::read(path).map_err(|e| e.to_string())?;
        (text, path.display().to_string())
    } else {
        let wanted = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let wanted = wanted.unwrap_or_else(|| from.to_owned());
        let builtin = mission::BUILTIN
            .iter()
            .find(|b| b.file_name == wanted || b.file_name.strip_suffix(".toml") == Some(&wanted));
        let Some(b) = builtin else {
            let names: Vec<&str> = mission::BUILTIN.iter().map(|b| b.file_name).collect();
            return Err(format!(
                "no mission {from}: give a mission file or a shipped one ({})",
                names.join(", ")
            ));
        };
        (b.text.to_owned(), format!("the shipped {}", b.file_name))
    };
    if crate::outcome::diagnose::check_text(&text, Some(&source))
        .mission
        .is_none()
    {
        return Err(format!(
            "{source} is not a mission (`skyform check {source}` says why)"
        ));
    }
    Ok((text, source))
}

/// `skyform record`.
fn record_mission(path: &std::path::Path, sinks: &Sinks) -> u8 {
    if sinks.is_empty() {
        eprintln!("error: say where the recording goes: --rrd FILE, --connect [URL] or --spawn");
        return exit::ERROR;
    }
    let Some(mission) = load_reporting(path) else {
        return exit::ERROR;
    };
    match record::record_scene(&mission, sinks) {
        Ok((finished, warnings)) => {
            for w in warnings {
                eprintln!("warning: {w}");
            }
            report_recording(finished.as_ref());
            exit::OK
        }
        Err(e) => {
            eprintln!("error: {e}");
            exit::ERROR
        }
    }
}

/// Loads a mission for a command: its warnings and errors go to stderr.
fn load_reporting(path: &std::path::Path) -> Option<mission::Mission> {
    match crate::outcome::diagnose::load(path) {
        Ok(loaded) => {
            eprint!("{}", loaded.warnings);
            Some(loaded.mission)
        }
        Err(e) => {
            eprintln!("error: {e}");
            None
        }
    }
}

/// Opens `sinks` for a recording of a `kind` run on `mission`, each viewer
/// that cannot be reached a warning on stderr; `None` when nothing records.
/// A sink that cannot start is said, and its exit status returned.
fn start_recorder(
    mission: &mission::Mission,
    kind: Kind,
    sinks: &Sinks,
) -> Result<Option<Recorder>, u8> {
    let mut warnings = Vec::new();
    let started = Recorder::start(&mission.name, Some(kind), sinks, &mut warnings);
    for w in warnings {
        eprintln!("warning: {w}");
    }
    started.map_err(|e| {
        eprintln!("error: {e}");
        exit::ERROR
    })
}

/// One line about the file a recording left.
fn report_recording(finished: Option<&record::Finished>) {
    let Some(f) = finished else { return };
    if let Some((path, size)) = &f.file {
        eprintln!("recording: wrote {} ({size} bytes)", path.display());
    }
    if let Some(e) = &f.error {
        eprintln!("error: recording: {e}");
    }
    if f.dropped > 0 {
        eprintln!(
            "warning: the viewer fell behind; {} recording messages were dropped",
            f.dropped
        );
    }
}

/// Ctrl-C sets the token (the pipeline stops at the next iteration and keeps
/// its best); a second Ctrl-C exits at once.
fn cancel_on_ctrl_c() -> CancelToken {
    // One handler per process: a command that plans, then flies (`fly`),
    // asks twice and gets the same token.
    static TOKEN: std::sync::OnceLock<CancelToken> = std::sync::OnceLock::new();
    if let Some(token) = TOKEN.get() {
        return token.clone();
    }
    let token = TOKEN.get_or_init(CancelToken::new).clone();
    let handler = token.clone();
    let installed = ctrlc::set_handler(move || {
        if handler.is_cancelled() {
            std::process::exit(i32::from(exit::CANCELLED));
        }
        eprintln!("\ncancelling… (Ctrl-C again to quit at once)");
        handler.cancel();
    });
    if let Err(e) = installed {
        eprintln!("warning: Ctrl-C will not cancel cleanly: {e}");
    }
    token
}

/// Progress on stderr: a bar redrawn in place on a terminal, a line every
/// 10 % otherwise (CI logs, pipes).
struct StderrProgress {
    terminal: bool,
    last_decile: i32,
    best: f64,
    stage: String,
}

impl StderrProgress {
    fn new() -> Self {
        use std::io::IsTerminal;
        StderrProgress {
            terminal: std::io::stderr().is_terminal(),
            last_decile: -1,
            best: f64::NAN,
            stage: String::new(),
        }
    }
}

impl StderrProgress {
    /// "  best J = …" once an optimiser reported a cost.
    fn best_text(&self) -> String {
        if self.best.is_finite() {
            format!("  best J = {:.3}", self.best)
        } else {
            String::new()
        }
    }
}

impl Observer for StderrProgress {
    fn on_event(&mut self, event: Event<'_>) {
        match event {
            Event::Stage(stage) => {
                if self.terminal && !self.stage.is_empty() {
                    eprintln!();
                }
                self.stage = stage.to_owned();
                if !self.terminal {
                    eprintln!("stage: {stage}");
                }
            }
            Event::Iteration { cost, .. } => self.best = cost,
            Event::Progress(fraction) => {
                let percent = (fraction * 100.0).round() as i32;
                if self.terminal {
                    let filled = (fraction * 30.0).round() as usize;
                    eprint!(
                        "\r{:<14} [{:<30}] {percent:>3}%{}",
                        self.stage,
                        "#".repeat(filled.min(30)),
                        self.best_text()
                    );
                } else if percent / 10 > self.last_decile {
                    self.last_decile = percent / 10;
                    eprintln!("progress: {percent}%{}", self.best_text());
                }
            }
            Event::Log(level, message) => {
                if self.terminal {
                    eprint!("\r\x1b[K");
                }
                let tag = match level {
                    Level::Info => "info",
                    Level::Warn => "warning",
                };
                eprintln!("{tag}: {message}");
            }
            // The log says who was lost, and when.
            Event::Vehicles { .. } => {}
        }
    }
}

/// The plan in `path` to warm-start from: a JSON object with `waypoints`
/// (and `pass_angles`), as a θ-PSO outcome and its `warm_start` record have.
fn read_warm_start(
    path: &std::path::Path,
) -> Result<crate::pipelines::theta_pso::WarmStart, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("--warm-from {}: {e}", path.display()))?;
    let mut warm: crate::pipelines::theta_pso::WarmStart = serde_json::from_str(&text)
        .map_err(|e| {
            format!(
                "--warm-from {}: not a plan (a JSON object with `waypoints` and `pass_angles`): {e}",
                path.display()
            )
        })?;
    if warm.waypoints.is_empty() {
        return Err(format!(
            "--warm-from {}: the plan has no waypoints",
            path.display()
        ));
    }
    if warm.from.is_empty() {
        warm.from = format!("the plan in {}", path.display());
    }
    Ok(warm)
}

/// `skyform run PIPELINE`: load, record, run (`run` of the seed: the given
/// one, else the mission's) with progress and Ctrl-C, summarise, write JSON,
/// choose the exit status.
fn run_pipeline(
    path: &std::path::Path,
    seed: Option<u64>,
    json: Option<&std::path::Path>,
    sinks: &Sinks,
    verbose: bool,
    run: impl FnOnce(u64) -> Run,
) -> u8 {
    let Some(mission) = load_reporting(path) else {
        return exit::ERROR;
    };
    let run = run(seed.unwrap_or(mission.seed));
    let kind = run.kind();
    let recorder = match start_recorder(&mission, kind, sinks) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let cancel = cancel_on_ctrl_c();
    let mut progress = StderrProgress::new();
    let ran = run.carry_out(&mission, recorder, &mut progress, &cancel);
    let finished = ran.recorded;
    let outcome = match ran.result {
        Ok(o) => o,
        // No plan exists within the planner's model: not an error of the
        // program or the file, the answer (with the place that closes the way).
        Err(crate::pipelines::PipelineError::NoRoute(no_plan)) => {
            if progress.terminal {
                eprintln!();
            }
            report_recording(finished.as_ref());
            println!("result       NO PLAN: {no_plan}");
            // Scripts and the designer read why, and what closes the way.
            if let Some(target) = json {
                let record = serde_json::json!({
                    "pipeline": kind,
                    "mission": mission.name,
                    "seed": seed.unwrap_or(mission.seed),
                    "result": "no plan",
                    "reason": no_plan.reason,
                    "obstacles": no_plan.obstacles,
                    "passages": no_plan.passages,
                    "route": no_plan.route,
                });
                let text = serde_json::to_string_pretty(&record).unwrap_or_default();
                if target.as_os_str() == "-" {
                    println!("{text}");
                } else if let Err(e) = crate::base::atomic::write(target, text.as_bytes()) {
                    eprintln!("error: cannot write {}: {e}", target.display());
                    return exit::ERROR;
                }
            }
            return exit::INFEASIBLE;
        }
        Err(e) => {
            eprintln!("\nerror: {e}");
            return exit::ERROR;
        }
    };
    if progress.terminal {
        eprintln!();
    }
    report_recording(finished.as_ref());
    let json_to_stdout = json.is_some_and(|p| p.as_os_str() == "-");
    let summary = outcome.summary_with(verbose);
    if json_to_stdout {
        eprint!("{summary}");
    } else {
        print!("{summary}");
    }
    if let Some(target) = json {
        let text = match outcome.to_json() {
            Ok(t) => t,
            Err(e) => {
                eprintln!("error: cannot write the outcome as JSON: {e}");
                return exit::ERROR;
            }
        };
        if json_to_stdout {
            println!("{text}");
        } else if let Err(e) = crate::base::atomic::write(target, text.as_bytes()) {
            eprintln!("error: cannot write {}: {e}", target.display());
            return exit::ERROR;
        }
    }
    if outcome.completion() == Completion::Cancelled {
        exit::CANCELLED
    } else if outcome.ok() {
        exit::OK
    } else {
        exit::INFEASIBLE
    }
}

/// `skyform check`: one report per file, then a one-line verdict.
fn check(files: &[PathBuf], strict: bool, json: bool) -> u8 {
    let mut failed = false;
    let mut json_reports = Vec::new();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for path in files {
        let name = path.display().to_string();
        let report = match mission::read(path) {
            Ok(text) => {
                let Checked { report, .. } =
                    crate::outcome::diagnose::check_text(&text, Some(&name));
                report
            }
            Err(e) => Report::new(vec![
                mission::Diagnostic::error(mission::FieldPath::root(), e.to_string())
                    .locate(Some(&name), &mission::SourceMap::new("")),
            ]),
        };
        let bad = report.has_errors() || (strict && report.warning_count() > 0);
        failed |= bad;
        if json {
            json_reports.push(serde_json::json!({
                "file": name,
                "valid": !bad,
                "diagnostics": report.diagnostics,
            }));
            continue;
        }
        let _ = write!(out, "{report}");
        let verdict = if bad { "FAILED" } else { "ok" };
        let _ = writeln!(
            out,
            "{name}: {verdict} ({} error(s), {} warning(s))",
            report.error_count(),
            report.warning_count()
        );
    }
    if json {
        let text = serde_json::to_string_pretty(&json_reports).unwrap_or_default();
        let _ = writeln!(out, "{text}");
    }
    if failed { exit::ERROR } else { exit::OK }
}
