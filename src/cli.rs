//! The command line: clap subcommands that call the library and print.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::flatlo::{self, FlatloOutcome};
use crate::fleet::{self, FleetOutcome};
use crate::mission::{self, Checked, Report};
use crate::pipeline::{CancelToken, Completion, Event, Level, Observer, PipelineError, Tee};
use crate::planner::{self, PlanOptions, ThetaPsoOutcome};
use crate::record::{self, Recorder, Sinks};

pub mod eval_cmd;
pub mod export_cmd;
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
    /// Mission file to open in the designer (created on first save if missing).
    pub file: Option<PathBuf>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Open a mission file in the designer (TUI); same as `skyform FILE`.
    Edit {
        /// Mission TOML file (created on first save if missing).
        file: PathBuf,
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
    /// (.plan, .waypoints, CSV), re-verified as it will be flown.
    ///
    /// Files: `<mission-stem>-<pipeline>-uav<N>.<ext>` in DIR. Each vehicle's
    /// track becomes waypoints within the tolerance of where the plan has it
    /// at each instant, with a commanded speed per leg so that it reaches
    /// each waypoint on time. The plans are flown as an autopilot flies them
    /// (straight legs at the commanded speeds, all vehicles starting
    /// together) and checked with the pipeline's own verification; a flown
    /// plan that breaks a constraint is refused unless --force. `plan` and
    /// `wpl` need the mission's [origin]; `csv` works without it (ENU only).
    /// Prints the files, their waypoint counts, the largest deviation and
    /// timing error. Exit status: 0 written, 1 error, 2 refused, 130
    /// cancelled (Ctrl-C). See docs/export.md.
    Export(export_cmd::ExportArgs),
    /// Print the cost of given paths under the mission's cost, one per line
    /// with 17 significant digits (`inf` where infinite): the parity hook
    /// with the SPSO benchmark's reference code (see docs/spso.md).
    ///
    /// Each CSV row holds 3 n numbers: the n free nodes' x, then y, then z
    /// above the ground. Exit status: 0 printed, 1 error.
    Eval(eval_cmd::EvalArgs),
    /// Run a pipeline over many seeds in parallel and print a table:
    /// feasible/passed counts, the best cost (or headline figure) mean ± sd,
    /// median, min, max, wall and CPU time, cost evaluations per CPU-second.
    ///
    /// Exit status: 0 every run finished, 1 an error.
    Sweep(sweep_cmd::SweepArgs),
}

#[derive(Debug, Subcommand)]
pub enum RunCommand {
    /// θ-PSO formation path planning with reconfiguration at intermediate waypoints.
    ///
    /// Progress goes to stderr, a summary to stdout. Exit status: 0 feasible
    /// plan, 1 error, 2 infeasible plan, 130 cancelled (Ctrl-C).
    ThetaPso {
        /// Mission TOML file.
        mission: PathBuf,
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
        return ExitCode::from(edit(cli.file));
    };
    match command {
        Command::Edit { file } => ExitCode::from(edit(Some(file))),
        Command::Check {
            files,
            strict,
            json,
        } => ExitCode::from(check(&files, strict, json)),
        Command::Run(RunCommand::ThetaPso {
            mission,
            seed,
            json,
            sequential,
            record,
        }) => {
            let options = PlanOptions {
                parallel: !sequential,
            };
            ExitCode::from(run_pipeline(
                &mission,
                seed,
                json.as_deref(),
                &record.sinks(),
                |m, seed, observer, cancel| planner::plan(m, seed, options, observer, cancel),
            ))
        }
        Command::Run(RunCommand::Fleet(a)) => ExitCode::from(run_pipeline(
            &a.mission,
            a.seed,
            a.json.as_deref(),
            &a.record.sinks(),
            fleet::plan,
        )),
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
            flatlo::plan,
        )),
        Command::Record { mission, record } => {
            ExitCode::from(record_mission(&mission, &record.sinks()))
        }
        Command::Export(args) => ExitCode::from(export_cmd::export_command(&args)),
        Command::Eval(args) => ExitCode::from(eval_cmd::eval_command(&args)),
        Command::Sweep(args) => ExitCode::from(sweep_cmd::sweep_command(&args)),
    }
}

/// The TUI; errors (not a terminal, a file that is not a mission) go to stderr.
fn edit(file: Option<PathBuf>) -> u8 {
    match crate::tui::run(file) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            exit::ERROR
        }
    }
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
    match crate::diagnose::load(path) {
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

/// One line about the file a recording left.
fn report_recording(finished: Option<&record::Finished>) {
    let Some(f) = finished else { return };
    if let Some((path, size)) = &f.file {
        eprintln!("recording: wrote {} ({size} bytes)", path.display());
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
    let token = CancelToken::new();
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
            Event::PathIteration { cost, .. } => self.best = cost.total,
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
        }
    }
}

/// What `skyform run` needs of any pipeline's outcome.
trait RunOutcome: serde::Serialize {
    fn summary(&self) -> String;
    fn completion(&self) -> Completion;
    /// The result meets its hard constraints (exit 0 rather than 2).
    fn ok(&self) -> bool;
    fn record(&self, recorder: &mut Recorder);
}

impl RunOutcome for ThetaPsoOutcome {
    fn summary(&self) -> String {
        theta_pso_summary(self)
    }
    fn completion(&self) -> Completion {
        self.completion
    }
    fn ok(&self) -> bool {
        self.feasible()
    }
    fn record(&self, recorder: &mut Recorder) {
        recorder.log_theta_pso(self);
    }
}

impl RunOutcome for FlatloOutcome {
    fn summary(&self) -> String {
        flatlo_summary(self)
    }
    fn completion(&self) -> Completion {
        self.completion
    }
    fn ok(&self) -> bool {
        self.passed()
    }
    fn record(&self, recorder: &mut Recorder) {
        recorder.log_flatlo(self);
    }
}

impl RunOutcome for FleetOutcome {
    fn summary(&self) -> String {
        fleet_summary(self)
    }
    fn completion(&self) -> Completion {
        self.completion
    }
    fn ok(&self) -> bool {
        self.kept_apart() && self.obstacles_clear() && self.converged()
    }
    fn record(&self, recorder: &mut Recorder) {
        recorder.log_fleet(self);
    }
}

/// `skyform run PIPELINE`: load, record, run with progress and Ctrl-C,
/// summarise, write JSON, choose the exit status.
fn run_pipeline<O: RunOutcome>(
    path: &std::path::Path,
    seed: Option<u64>,
    json: Option<&std::path::Path>,
    sinks: &Sinks,
    plan: impl FnOnce(
        &mission::Mission,
        u64,
        &mut dyn Observer,
        &CancelToken,
    ) -> Result<O, PipelineError>,
) -> u8 {
    let Some(mission) = load_reporting(path) else {
        return exit::ERROR;
    };
    let seed = seed.unwrap_or(mission.seed);
    let mut warnings = Vec::new();
    let mut recorder = match Recorder::start(&mission.name, sinks, &mut warnings) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return exit::ERROR;
        }
    };
    for w in warnings {
        eprintln!("warning: {w}");
    }
    let cancel = cancel_on_ctrl_c();
    let mut progress = StderrProgress::new();
    let result = match recorder.as_mut() {
        Some(r) => {
            r.log_mission(&mission);
            plan(&mission, seed, &mut Tee(&mut progress, r), &cancel)
        }
        None => plan(&mission, seed, &mut progress, &cancel),
    };
    let outcome = match result {
        Ok(o) => o,
        Err(e) => {
            eprintln!("\nerror: {e}");
            return exit::ERROR;
        }
    };
    if let Some(r) = recorder.as_mut() {
        outcome.record(r);
    }
    // Every clone of the stream is dropped here, so the file is complete
    // (with its footer) before anything else is printed or the process ends.
    let finished = recorder.map(Recorder::finish);
    if progress.terminal {
        eprintln!();
    }
    report_recording(finished.as_ref());
    let json_to_stdout = json.is_some_and(|p| p.as_os_str() == "-");
    let summary = outcome.summary();
    if json_to_stdout {
        eprint!("{summary}");
    } else {
        print!("{summary}");
    }
    if let Some(target) = json {
        let text = match serde_json::to_string_pretty(&outcome) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("error: cannot write the outcome as JSON: {e}");
                return exit::ERROR;
            }
        };
        if json_to_stdout {
            println!("{text}");
        } else if let Err(e) = mission::write_atomically(target, text.as_bytes()) {
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

/// The human summary of a θ-PSO outcome.
pub fn theta_pso_summary(o: &ThetaPsoOutcome) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(s, "θ-PSO plan for \"{}\" (seed {})", o.mission, o.seed);
    let restarts = match o.restarts {
        0 => String::new(),
        n => format!(" ({n} restart(s): the best plan failed verification)"),
    };
    let _ = writeln!(
        s,
        "  run          {:?} after {} iterations, {} cost evaluations{restarts}",
        o.completion, o.iterations, o.evaluations
    );
    let c = &o.cost;
    let _ = writeln!(
        s,
        "  cost         J = {:.3}  (J1 length {:.2} m, J2 obstacles {:.5}, J3 altitude {:.3}, J_R waypoints {:.2} m, J_B bounds {:.3}, J_T turning {:.3})",
        c.total, c.length, c.obstacle, c.altitude, c.waypoints, c.bounds, c.turning
    );
    let reference = match (o.reference_length, o.length_ratio) {
        (Some(r), Some(ratio)) => format!("; J1 / reference {ratio:.3} (shortest route {r:.1} m)"),
        _ => "; no reference route reaches the goal".to_owned(),
    };
    let _ = writeln!(
        s,
        "  path         {:.1} m in {:.1} s, {} free waypoints{reference}",
        o.path_length,
        o.duration,
        o.waypoints.len()
    );
    let enabled = o.iwps.iter().filter(|i| i.enabled).count();
    let _ = writeln!(
        s,
        "  IWPs         {} found, {enabled} enabled",
        o.iwps.len()
    );
    for i in o.iwps.iter().filter(|i| i.enabled && i.unusable.is_some()) {
        let _ = writeln!(
            s,
            "  IWP          '{}' | '{}' unusable: {}",
            i.between[0],
            i.between[1],
            i.unusable.as_deref().unwrap_or_default()
        );
    }
    for r in &o.reconfigurations {
        let _ = writeln!(
            s,
            "  reconfig     {} between '{}' and '{}': t1 {:.1} s, t2 {:.1} s, t3 {:.1} s, t4 {:.1} s",
            r.shape.name(),
            r.between[0],
            r.between[1],
            r.t1,
            r.t2,
            r.t3,
            r.t4
        );
    }
    let _ = writeln!(s, "  verification");
    for check in &o.verification.checks {
        let worst = check
            .worst
            .map_or_else(|| "n/a".to_owned(), |w| format!("{w:.3}"));
        let at = check.at.as_ref().map_or_else(String::new, |a| {
            let other = a
                .other
                .as_deref()
                .map_or_else(String::new, |o| format!(" vs {o}"));
            format!("  (UAV {} at t = {:.1} s{other})", a.uav + 1, a.time)
        });
        let verdict = if check.ok { "ok  " } else { "FAIL" };
        let _ = writeln!(
            s,
            "    {verdict} {:<32} worst {worst:>9} {} {}{at}",
            check.name, check.relation, check.limit
        );
    }
    for i in &o.verification.inspections {
        let verdict = if i.ok { "ok  " } else { "FAIL" };
        let band = i.distance.map_or_else(
            || "never within the band".to_owned(),
            |[lo, hi]| format!("facing UAV at {lo:.2}-{hi:.2} m"),
        );
        let _ = writeln!(
            s,
            "    {verdict} inspection of {:<19} {:>5.1} m ≥ {} m within [{}, {}] m, {band}",
            format!("'{}'", i.obstacle),
            i.achieved,
            i.required,
            i.band[0],
            i.band[1]
        );
    }
    let verdict = if o.feasible() {
        "FEASIBLE"
    } else {
        "INFEASIBLE"
    };
    let _ = writeln!(s, "  result       {verdict}");
    s
}

/// The human summary of a FLATLO outcome.
pub fn flatlo_summary(o: &FlatloOutcome) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "FLATLO transition for \"{}\" (seed {})",
        o.mission, o.seed
    );
    let _ = writeln!(
        s,
        "  run          {:?}, {:.1} s simulated; every aircraft on the line at t = {:.1} s",
        o.completion, o.duration, o.arrival_time
    );
    for a in &o.aircraft {
        let _ = writeln!(
            s,
            "  aircraft {:<3} {:<6} Δm {:>8.0} m  Δ {:>7.0} m  transition {:>8.0} m at {:>6.2} m/s  tracking max {:>7.1} m, RMS {:>6.1} m",
            a.index,
            format!("{:?}", a.side).to_lowercase(),
            a.advance,
            a.lateral_distance,
            a.transition_length,
            a.airspeed,
            a.tracking_max,
            a.tracking_rms
        );
    }
    for p in &o.pairs {
        let _ = writeln!(
            s,
            "  pair {:>2}-{:<2}    closest {:>9.1} m at t = {:.0} s",
            p.a, p.b, p.min_distance, p.time
        );
    }
    let closest = o.closest.map_or("-".to_owned(), |c| {
        format!(
            "aircraft {} and {} at {:.1} m (t = {:.0} s)",
            c.a, c.b, c.min_distance, c.time
        )
    });
    let Some(v) = &o.verification else {
        let _ = writeln!(
            s,
            "  result       CANCELLED: no verdict on a partial flight; closest so far {closest}"
        );
        return s;
    };
    let spacing: Vec<String> = v
        .final_spacing
        .iter()
        .map(|x| format!("{}→{} {:.1} m", x.front, x.back, x.spacing))
        .collect();
    let _ = writeln!(s, "  final line   {}", spacing.join(", "));
    let _ = writeln!(
        s,
        "               spacing error {:.3} % of Δd, lateral spread {:.1} m",
        v.max_spacing_error * 100.0,
        v.lateral_spread
    );
    let verdict = if v.passed { "PASS" } else { "FAIL" };
    let _ = writeln!(
        s,
        "  result       {verdict}: closest {closest}, minimum separation {:.0} m",
        v.min_separation
    );
    s
}

/// The human summary of a fleet outcome.
pub fn fleet_summary(o: &FleetOutcome) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(s, "Fleet for \"{}\" (seed {})", o.mission, o.seed);
    let _ = writeln!(
        s,
        "  run          {:?}, {:.1} s simulated, {} agents",
        o.completion,
        o.duration,
        o.agents.len()
    );
    for (k, t) in o.targets.iter().enumerate() {
        let reached = t.converged_after.map_or("NOT REACHED".to_owned(), |a| {
            format!("formed {a:.2} s after it appeared")
        });
        let _ = writeln!(
            s,
            "  target {:<5} ({:.2}, {:.2}) at t = {:.1} s: {reached}",
            k + 1,
            t.position.x,
            t.position.y,
            t.time
        );
    }
    for d in &o.distances {
        let last = d.values.last().copied().unwrap_or(f64::NAN);
        let min = d.values.iter().copied().fold(f64::INFINITY, f64::min);
        let _ = writeln!(
            s,
            "  pair {:>2}-{:<3}   final {last:.3} m (desired {:.3}), min {min:.3} m",
            d.a, d.b, d.desired
        );
    }
    let agents = o.closest_agents.as_ref().map_or("-".to_owned(), |c| {
        format!(
            "agents {} and {} at {:.3} m (t = {:.2} s)",
            c.a, c.b, c.distance, c.time
        )
    });
    let obstacle = o.closest_obstacle.as_ref().map_or("-".to_owned(), |c| {
        format!(
            "agent {} to '{}' at {:.3} m (t = {:.2} s)",
            c.a, c.b, c.distance, c.time
        )
    });
    let _ = writeln!(
        s,
        "  closest      {agents}; safety distance c = {} m",
        o.safety_distance
    );
    let _ = writeln!(s, "  obstacles    {obstacle}");
    let decisions: usize = o.agents.iter().map(|a| a.decisions).sum();
    let evaluations: usize = o.agents.iter().map(|a| a.evaluations).sum();
    let _ = writeln!(
        s,
        "  PSO effort   {decisions} decisions, {evaluations} cost evaluations ({:.0} per agent per second)",
        evaluations as f64 / (o.agents.len().max(1) as f64 * o.duration.max(1e-9))
    );
    let verdict = if o.kept_apart() && o.obstacles_clear() && o.converged() {
        "PASS"
    } else {
        "FAIL"
    };
    let _ = writeln!(s, "  result       {verdict}");
    s
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
                let Checked { report, .. } = crate::diagnose::check_text(&text, Some(&name));
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
