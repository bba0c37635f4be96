//! `skyform import`: a site survey's obstacles into a mission file, edited
//! in place and saved atomically, or nothing written.

use std::collections::HashSet;
use std::path::PathBuf;

use super::exit;
use crate::import::{self, Imported};
use crate::mission::{self, Diagnostic};

/// The arguments of `skyform import` (its help is on `Command::Import`).
#[derive(Debug, clap::Args)]
pub struct ImportArgs {
    /// Survey file: GeoJSON (.geojson, .json), KML (.kml) or KMZ (.kmz).
    pub file: PathBuf,
    /// Mission TOML file the obstacles go into (edited in place).
    #[arg(long, value_name = "MISSION")]
    pub into: PathBuf,
    /// Say what would change; write nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// Write even when the mission then has validation errors it does not
    /// have now, or when the survey lowers, thins or removes an obstacle
    /// the mission already has.
    #[arg(long)]
    pub force: bool,
}

/// `skyform import`.
pub fn import_command(args: &ImportArgs) -> u8 {
    let name = args.into.display().to_string();
    let text = match mission::read(&args.into) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return exit::ERROR;
        }
    };
    let checked = crate::outcome::diagnose::check_text(&text, Some(&name));
    let Some(before) = checked.mission else {
        eprint!("{}", checked.report);
        eprintln!("error: {name} is not a mission file skyform can read: nothing imported");
        return exit::ERROR;
    };
    let imported = match import::read_survey(&args.file)
        .and_then(|survey| import::import(&before, &survey, &import::stem(&args.file)))
    {
        Ok(i) => i,
        Err(e) => {
            eprintln!("error: {e}");
            eprintln!("nothing written to {name}");
            return exit::ERROR;
        }
    };
    print!(
        "import {} into {name}: {}",
        args.file.display(),
        imported.report()
    );
    if imported.changes.is_empty() {
        println!("nothing to write: {name} already holds every feature as it is");
        return exit::OK;
    }
    let new_text = match mission::edit_in_place(&imported.mission, &text) {
        Some(t) => t,
        None => match mission::to_toml_string(&imported.mission) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("error: {e}");
                return exit::ERROR;
            }
        },
    };
    let losses = &imported.changes.losses;
    if !losses.is_empty() && !args.force {
        eprintln!(
            "error: the survey would lower, thin or remove {} obstacle(s) {name} already has \
             (listed above as `loss:`); nothing written (--force writes it)",
            losses.len()
        );
        return exit::INFEASIBLE;
    }
    if !losses.is_empty() {
        eprintln!(
            "warning: --force: {} obstacle(s) lowered, thinned or removed as the survey has them",
            losses.len()
        );
    }
    let new_errors = errors_added(&checked.report.diagnostics, &new_text, &name);
    if !new_errors.is_empty() {
        let label = if args.force { "warning" } else { "error" };
        eprintln!(
            "{label}: with the survey in it, {name} would have {} error(s) it does not have now:",
            new_errors.len()
        );
        for d in &new_errors {
            eprintln!("  {d}");
        }
        if !args.force {
            eprintln!("nothing written (--force writes it anyway; the designer shows each error)");
            return exit::INFEASIBLE;
        }
    }
    if args.dry_run {
        println!("dry run: nothing written");
        return exit::OK;
    }
    if let Err(e) = crate::base::atomic::write(&args.into, new_text.as_bytes()) {
        eprintln!("error: cannot save {name}: {e}; it is unchanged");
        return exit::ERROR;
    }
    println!("wrote {name}: {}", counts(&imported));
    exit::OK
}

/// The errors of the mission `text` (located in it) that the mission did
/// not have before (`before`, by field and message).
fn errors_added(before: &[Diagnostic], text: &str, name: &str) -> Vec<Diagnostic> {
    let known: HashSet<(String, String)> = before
        .iter()
        .filter(|d| d.is_error())
        .map(|d| (d.path.to_string(), d.message.clone()))
        .collect();
    crate::outcome::diagnose::check_text(text, Some(name))
        .report
        .errors()
        .filter(|d| !known.contains(&(d.path.to_string(), d.message.clone())))
        .cloned()
        .collect()
}

fn counts(imported: &Imported) -> String {
    let c = &imported.changes;
    format!(
        "{} obstacle(s) added, {} updated, {} removed",
        c.added().count(),
        c.updated().count(),
        c.removed().count()
    )
}
