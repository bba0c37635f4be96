//! The designer's export key: the shown job's result, in every format the
//! mission allows, into `<mission-stem>-export/` beside the mission file.

use std::path::{Path, PathBuf};

use super::document::Document;
use super::jobs::{Job, Outcome};
use crate::export::{self, ExportError, Format, Options, Planned};
use crate::mission::Mission;
use crate::pipelines::Completion;

/// What the export needs of a finished job's outcome.
pub fn planned(mission: &Mission, outcome: &Outcome) -> Planned {
    Planned::from_outcome(mission, outcome)
}

/// The folder beside the mission file (or in `cwd` for an unsaved mission).
pub fn folder(mission_path: Option<&Path>, cwd: &Path, stem: &str) -> PathBuf {
    let dir = mission_path
        .and_then(Path::parent)
        .map(Path::to_path_buf)
        .unwrap_or_else(|| cwd.to_path_buf());
    dir.join(format!("{stem}-export"))
}

/// Exports the result on the map (`shown`) beside the document's file (in
/// `cwd` without one), named after the document ([`Document::stem`]): the
/// status line on success, the reason on refusal or failure.
pub fn export_shown(shown: Option<&Job>, doc: &Document, cwd: &Path) -> Result<String, String> {
    let Some(job) = shown else {
        return Err("no result on the map to export: run a pipeline, or Enter on a job".into());
    };
    let stem = doc.stem();
    export_job(job, &folder(doc.path(), cwd, &stem), &stem)
}

/// Exports `job`'s result (not forced): the status line on success, the
/// reason on refusal or failure.
pub fn export_job(job: &Job, dir: &Path, stem: &str) -> Result<String, String> {
    let Some(outcome) = &job.outcome else {
        return Err(format!("job {} has no result to export yet", job.id));
    };
    if outcome.completion() == Completion::Cancelled {
        return Err(format!(
            "job {} was cancelled: export a run that finished",
            job.id
        ));
    }
    let mission = &job.mission;
    let formats: Vec<Format> = if mission.origin.is_some() {
        Format::ALL.to_vec()
    } else {
        vec![Format::Csv]
    };
    let planned = planned(mission, outcome);
    let options = Options {
        formats,
        out_dir: dir.to_path_buf(),
        tolerance: None,
        force: false,
    };
    match export::export(mission, stem, &planned, &options) {
        Ok(done) => {
            let counts: Vec<String> = done
                .plans
                .iter()
                .map(|p| p.waypoints.len().to_string())
                .collect();
            let note = if mission.origin.is_none() {
                " (CSV only: add [origin] for .plan and .waypoints)"
            } else {
                ""
            };
            Ok(format!(
                "exported {} files to {}{note}: waypoints {}, deviation {:.3} m, timing {:.3} s",
                done.files.len(),
                dir.display(),
                counts.join("/"),
                done.reverification.max_deviation,
                done.reverification.max_timing_error
            ))
        }
        Err(ExportError::Refused(r)) => Err(format!(
            "export refused: {}",
            r.failures
                .first()
                .map_or_else(String::new, ToString::to_string)
        )),
        Err(e) => Err(format!("export failed: {e}")),
    }
}
