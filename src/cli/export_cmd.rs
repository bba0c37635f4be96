//! `skyform export`: plan, re-verify as flown, write one file per vehicle.

use std::path::{Path, PathBuf};

use super::{StderrProgress, cancel_on_ctrl_c, exit, load_reporting};
use crate::export::{self, ExportError, Exported, Format, Options, Planned};
use crate::mission::Mission;
use crate::pipelines::verify::figure;
use crate::pipelines::{Completion, Kind};
use crate::run::Run;

/// A format on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    /// QGroundControl .plan (JSON).
    Plan,
    /// QGC WPL 110 .waypoints (MAVProxy, Mission Planner).
    Wpl,
    /// Timed samples t,x,y,z,vx,vy,vz[,lat,lon,alt].
    Csv,
    /// One KML of the mission and every vehicle's track (Google Earth).
    Kml,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Self {
        match f {
            FormatArg::Plan => Format::Plan,
            FormatArg::Wpl => Format::Wpl,
            FormatArg::Csv => Format::Csv,
            FormatArg::Kml => Format::Kml,
        }
    }
}

/// The arguments of `skyform export` (its help is on `Command::Export`).
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Mission TOML file.
    pub mission: PathBuf,
    /// File format; repeat for several (plan, wpl, csv, kml).
    #[arg(long, value_enum, required = true)]
    pub format: Vec<FormatArg>,
    /// Folder for the files (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// The pipeline that plans the mission.
    #[arg(long, value_enum, default_value = "theta-pso")]
    pub pipeline: Kind,
    /// Seed of the pipeline (default: the mission's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Largest distance, metres, between where a waypoint plan puts a vehicle
    /// and where the plan has it at the same instant, at least 0.01 (default:
    /// the plan's clearance margin, or less when the plan has less slack).
    #[arg(long, value_name = "METRES")]
    pub tolerance: Option<f64>,
    /// Write the files even when the flown plans break a constraint (warns).
    #[arg(long)]
    pub force: bool,
}

/// Plans `mission` with `pipeline`; `None` (after saying why) on error or Ctrl-C.
pub fn planned(mission: &Mission, pipeline: Kind, seed: u64) -> Result<Planned, u8> {
    let cancel = cancel_on_ctrl_c();
    let mut progress = StderrProgress::new();
    let result = Run::new(pipeline, seed)
        .carry_out(mission, None, &mut progress, &cancel)
        .result;
    if progress.terminal {
        eprintln!();
    }
    let outcome = result.map_err(|e| {
        eprintln!("error: {e}");
        exit::ERROR
    })?;
    let planned = Planned::from_outcome(mission, &outcome);
    let (completion, ok) = (outcome.completion(), outcome.ok());
    if completion == Completion::Cancelled {
        eprintln!("cancelled: nothing written");
        return Err(exit::CANCELLED);
    }
    if !ok {
        eprintln!(
            "warning: the {} result itself fails its verification (see `skyform run {}`)",
            pipeline.words().slug,
            pipeline.words().slug
        );
    }
    Ok(planned)
}

/// `skyform export`.
pub fn export_command(args: &ExportArgs) -> u8 {
    let Some(mission) = load_reporting(&args.mission) else {
        return exit::ERROR;
    };
    let mut formats: Vec<Format> = Vec::new();
    for f in &args.format {
        let f = Format::from(*f);
        if !formats.contains(&f) {
            formats.push(f);
        }
    }
    // Refuse a geodetic format before planning, not after.
    if mission.origin.is_none()
        && let Some(f) = formats.iter().find(|f| f.geodetic())
    {
        eprintln!("error: {}", ExportError::NoOrigin(f.name()));
        return exit::ERROR;
    }
    let pipeline = args.pipeline;
    let seed = args.seed.unwrap_or(mission.seed);
    let planned = match planned(&mission, pipeline, seed) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let options = Options {
        formats,
        out_dir: args.out.clone(),
        tolerance: args.tolerance,
        force: args.force,
    };
    match export::export(&mission, &stem(&args.mission), &planned, &options) {
        Ok(done) => {
            print!("{}", summary(&done));
            if done.forced {
                eprintln!(
                    "warning: written with --force although the plans as flown break a constraint:\n{}",
                    done.reverification.failure_text()
                );
            }
            exit::OK
        }
        Err(ExportError::Refused(r)) => {
            eprintln!("error: {}", ExportError::Refused(r.clone()));
            for line in r.advice() {
                eprintln!("  advice: {line}");
            }
            exit::INFEASIBLE
        }
        Err(e) => {
            eprintln!("error: {e}");
            exit::ERROR
        }
    }
}

/// The mission file's stem, for file names.
pub fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "mission".to_owned())
}

/// What was written, the waypoint counts, the deviation and timing error,
/// the flown checks and the written rates.
pub fn summary(done: &Exported) -> String {
    let r = &done.reverification;
    let noun = export::noun(done.pipeline);
    let mut out = format!(
        "export {}: tolerance {:.3} m ({})\n",
        done.pipeline.words().slug,
        done.tolerance,
        done.tolerance_source
    );
    if let Some(note) = &done.limits_note {
        out.push_str(&format!("  limits: {note}\n"));
    }
    let waypoint_files = done.files.iter().any(|f| f.format.waypoints());
    if waypoint_files {
        for p in &done.plans {
            out.push_str(&format!(
                "  {noun} {}: {} waypoints\n",
                p.vehicle + 1,
                p.waypoints.len()
            ));
        }
        let at = |a: Option<export::reverify::At>| {
            a.map_or_else(String::new, |a| {
                format!(
                    " ({noun} {}, waypoint {}, t = {:.1} s)",
                    a.vehicle + 1,
                    a.waypoint,
                    a.time
                )
            })
        };
        out.push_str(&format!(
            "as flown (the stored coordinates): largest deviation {:.3} m{}, largest timing \
             error {:.3} s{}\n",
            r.max_deviation,
            at(r.deviation_at),
            r.max_timing_error,
            at(r.timing_at)
        ));
        out.push_str(&checks(&r.verification, noun));
        for rate in &r.rates {
            let limit = rate.limit.map_or_else(
                || "(no limit in the mission)".to_owned(),
                |l| format!("{} {l} m/s", rate.relation),
            );
            out.push_str(&format!(
                "  {} {:<32} worst {} {limit}\n",
                if rate.ok { "✓" } else { "✗" },
                rate.name,
                figure(rate.worst),
            ));
        }
    }
    if let Some(csv) = &r.csv {
        out.push_str(&format!(
            "CSV as written: largest deviation {:.4} m\n",
            csv.max_deviation
        ));
        if !waypoint_files {
            out.push_str(&checks(&csv.verification, noun));
        }
    }
    out + &files_written(done)
}

/// The verification table, in the pipeline's words.
fn checks(v: &crate::pipelines::verify::Verification, noun: &str) -> String {
    let mut out = String::new();
    for c in &v.checks {
        out.push_str(&format!(
            "  {} {:<32} worst {} {} {}\n",
            if c.ok { "✓" } else { "✗" },
            export::reverify::worded(c.name, noun),
            c.worst.map_or_else(|| "n/a".to_owned(), figure),
            c.relation,
            c.limit
        ));
    }
    for i in &v.inspections {
        out.push_str(&format!(
            "  {} inspection of '{}': {:.1} m of {} m in [{}, {}] m (eq. 8)\n",
            if i.ok { "✓" } else { "✗" },
            i.obstacle,
            i.achieved,
            i.required,
            i.band[0],
            i.band[1]
        ));
    }
    out
}

/// One line per file written.
fn files_written(done: &Exported) -> String {
    let mut out = String::new();
    for f in &done.files {
        let line = match f.format {
            Format::Kml => format!(
                "wrote {} ({} tracks, {} placemarks, absolute altitudes)\n",
                f.path.display(),
                f.waypoints,
                f.items
            ),
            Format::Csv => format!(
                "wrote {} ({} waypoints, {} samples)\n",
                f.path.display(),
                f.waypoints,
                f.items
            ),
            Format::Plan | Format::Wpl => format!(
                "wrote {} ({} waypoints, {} items)\n",
                f.path.display(),
                f.waypoints,
                f.items
            ),
        };
        out.push_str(&line);
    }
    out
}
