//! The designer's import key: a site survey's obstacles into the mission
//! being edited, as one undo step (`skyform import` without writing: the
//! save writes it, into the user's file).

use std::path::Path;

use super::editor::Editor;
use super::overlay::typed_path;
use super::status::StatusLine;
use crate::import;

/// Imports the survey at `input` (a path typed relative to `cwd`) into the
/// editor's mission; the status line says what changed, or why nothing did.
pub fn import(editor: &mut Editor, cwd: &Path, input: &str, status: &mut StatusLine) {
    if input.trim().is_empty() {
        status.error("type the survey file's path (GeoJSON, KML or KMZ)");
        return;
    }
    let path = typed_path(cwd, input);
    let survey = import::read_survey(&path);
    let imported = survey.and_then(|s| import::import(editor.mission(), &s, &import::stem(&path)));
    let imported = match imported {
        Ok(i) => i,
        Err(e) => {
            // The first problem fits the status line; all are in `skyform import`.
            let text = e.to_string();
            let first = text.lines().take(2).collect::<Vec<_>>().join(" ");
            status.error(format!("not imported: {first}"));
            return;
        }
    };
    let name = path
        .file_name()
        .map_or_else(|| input.to_owned(), |n| n.to_string_lossy().into_owned());
    let c = &imported.changes;
    if c.is_empty() {
        status.say(format!(
            "{name}: nothing to import, the mission holds all {} feature(s) as they are",
            imported.features
        ));
        return;
    }
    let errors_before = editor.doc().error_count();
    editor.restore(imported.mission.clone());
    let mut text = format!(
        "imported {name}: {} added, {} updated, {} removed",
        c.added().count(),
        c.updated().count(),
        c.removed().count()
    );
    if !imported.skipped.is_empty() {
        text.push_str(&format!(", {} skipped", imported.skipped.len()));
    }
    if !imported.warnings.is_empty() {
        text.push_str(" (defaults assumed: see `skyform import`)");
    }
    let errors = editor.doc().error_count();
    if let Some(first) = c.losses.first() {
        // Undoable here, but never quiet: the first loss named, the count.
        let more = c.losses.len() - 1;
        let more = if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        };
        status.error(format!("{text}; {first}{more}: u undoes"));
    } else if errors > errors_before {
        status.error(format!(
            "{text}; {} new error(s), see the inspector; u undoes",
            errors - errors_before
        ));
    } else {
        status.say(format!("{text}; u undoes"));
    }
}
