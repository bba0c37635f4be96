//! One flight flown again and shown: `skyform fly --flight K` (flight K of
//! a check, from the check's seed), and `--inputs FILE`, the most likely
//! failing flights of `--rare`, flown from the inputs `--failure FILE`
//! wrote (flight::odds::FailingFile), printed and recorded.

use std::path::Path;

use super::exit;
use super::fly_cmd::FlyArgs;
use crate::flight::odds::{FAILING_FORMAT, FailingFile, Odds};
use crate::flight::{self, Flown, Setup};
use crate::mission::Mission;
use crate::pipelines::Kind;

/// Flight `k` of the check seeded `seed`, printed.
pub fn flight(setup: &Setup, seed: u64, k: usize) -> u8 {
    let f = flight::fly(setup, seed, k, false);
    println!(
        "flight {k} of the {} plan for \"{}\" (seed {seed})",
        setup.pipeline, setup.mission.name
    );
    if printed(setup, &f) {
        exit::INFEASIBLE
    } else {
        exit::OK
    }
}

/// `--failure FILE`: the most likely failing flights of `odds`, with their
/// inputs and the mission, written for `--inputs` (atomically). Nothing is
/// written, and that is said, when no flight failed.
pub fn write_failing(
    path: &Path,
    mission: &Mission,
    pipeline: Kind,
    seed: u64,
    odds: &[&Odds],
) -> Result<(), u8> {
    let toml = crate::mission::to_toml_string(mission).map_err(|e| {
        eprintln!("error: {e}");
        exit::ERROR
    })?;
    let file = FailingFile::new(toml, pipeline, seed, odds);
    if file.flights.is_empty() {
        println!("no flight failed: nothing to write to {}", path.display());
        return Ok(());
    }
    super::fly_cmd::json_written(&file, "the failing flights", path, false)?;
    println!(
        "the most likely failing flight of {} written to {} (fly it again: skyform fly MISSION \
         --inputs {})",
        file.flights
            .iter()
            .map(|f| f.limit.words())
            .collect::<Vec<_>>()
            .join(" and of "),
        path.display(),
        path.display()
    );
    Ok(())
}

/// `--inputs FILE`: each failing flight of `file` (read from `path` by
/// [`read`]) flown again on `setup`'s plan, printed, and recorded when a
/// sink is asked.
pub fn inputs(
    setup: &Setup,
    mission: &Mission,
    args: &FlyArgs,
    seed: u64,
    path: &Path,
    file: &FailingFile,
) -> u8 {
    let mut broke = false;
    let mut failing = Vec::new();
    for f in &file.flights {
        let flown = flight::rare::fly_failure(setup, &f.inputs);
        println!(
            "the most likely flight to break {} (seed {seed}, run {}, level {}, chain {}, move {}): \
             it broke it by {:.2} m ({})",
            f.limit.words(),
            f.failure.run,
            f.failure.at.0,
            f.failure.at.1,
            f.failure.at.2,
            -f.failure.room,
            f.failure.what
        );
        broke |= printed(setup, &flown);
        let name = match f.limit {
            flight::rare::Limit::Separation => "most_likely_separation",
            flight::rare::Limit::Clearance => "most_likely_clearance",
        };
        failing.push((name.to_owned(), flown.tracks.unwrap_or_default()));
    }
    let sinks = args.record.sinks();
    if !sinks.is_empty() {
        let mut recorder = match super::start_recorder(mission, args.pipeline, &sinks) {
            Ok(Some(r)) => r,
            Ok(None) => return exit::OK,
            Err(code) => return code,
        };
        recorder.log_mission(mission);
        let text = format!(
            "the most likely failing flights of \"{}\", flown again from {}",
            mission.name,
            path.display()
        );
        recorder.log_flights(flight::Recording::of_failing(setup, failing), text);
        super::report_recording(Some(&recorder.finish()));
    }
    if broke { exit::INFEASIBLE } else { exit::OK }
}

/// `--inputs FILE` read and checked to be of `mission` (its flight count
/// aside), `pipeline` and `seed`; or the exit status, the refusal said.
pub fn read(path: &Path, mission: &Mission, pipeline: Kind, seed: u64) -> Result<FailingFile, u8> {
    checked(path, mission, pipeline, seed).map_err(|e| {
        eprintln!("error: {}: {e}", path.display());
        exit::ERROR
    })
}

/// [`read`], the refusal in words.
fn checked(
    path: &Path,
    mission: &Mission,
    pipeline: Kind,
    seed: u64,
) -> Result<FailingFile, String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let file: FailingFile = serde_json::from_str(&text).map_err(|e| {
        format!("not a failing-flight file of `skyform fly --rare --failure` ({e})")
    })?;
    if file.format != FAILING_FORMAT {
        return Err(format!(
            "not a failing-flight file (format '{}')",
            file.format
        ));
    }
    let origin = path.display().to_string();
    let mut theirs = crate::mission::parse_str(&file.mission, &origin)
        .map_err(|e| format!("its mission: {e}"))?
        .mission;
    theirs.flight.flights = mission.flight.flights;
    let same = |m: &Mission| crate::mission::to_toml_string(m).map_err(|e| e.to_string());
    if same(&theirs)? != same(mission)? {
        return Err(format!(
            "its flights are of another mission (\"{}\" as it was when they were flown): fly \
             them on that mission",
            theirs.name
        ));
    }
    if file.pipeline != pipeline {
        return Err(format!(
            "its flights are of {}'s plan: add --pipeline {}",
            file.pipeline.words().name,
            file.pipeline.words().name
        ));
    }
    if file.seed != seed {
        return Err(format!(
            "its flights are of the plan seeded {}: add --seed {}",
            file.seed, file.seed
        ));
    }
    Ok(file)
}

/// A flight's take-off times and, per vehicle, its closest approaches and
/// its tightest obstacle, printed; whether it broke a limit.
fn printed(setup: &Setup, f: &Flown) -> bool {
    let n = setup.plans.len();
    let vehicle = |v: usize| setup.plans[v].vehicle + 1;
    let mark = |breaks: bool| if breaks { "BREAKS" } else { "ok" };
    let mut broke = false;
    for ((i, j), c) in flight::vehicle_pairs(n).zip(&f.pairs) {
        let mark = mark(c.distance < setup.closest);
        broke |= c.distance < setup.closest;
        println!(
            "  {mark:<6} UAV {} - UAV {}: closest {:.2} m at t = {:.1} s (2 r_Q = {:.2} m)",
            vehicle(i),
            vehicle(j),
            c.distance,
            c.t,
            setup.closest
        );
    }
    for (v, near) in setup.near.iter().enumerate() {
        let tightest = near
            .iter()
            .zip(&f.obstacles[v])
            .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance));
        if let Some((&o, c)) = tightest {
            let mark = mark(c.distance < setup.clearance);
            broke |= c.distance < setup.clearance;
            println!(
                "  {mark:<6} UAV {} took off {:+.2} s late; nearest '{}' at {:.2} m, t = {:.1} s \
                 (r_Q = {:.2} m); cross-track at most {:.2} m",
                vehicle(v),
                f.takeoff[v],
                setup.mission.obstacles[o].name,
                c.distance,
                c.t,
                setup.clearance,
                f.cross_track[v]
            );
        }
    }
    if !f.finished {
        println!("  a vehicle had not reached its last waypoint at the horizon");
    }
    broke
}
