//! The mission being edited: where it lives on disk, what was last saved,
//! and the undo history.
//!
//! Every change goes through [`Document::edit`] (one undo step) or a drag
//! ([`Document::begin_gesture`] … [`Document::end_gesture`], one undo step
//! however many moves it makes). "Modified" compares with the saved mission
//! rather than counting edits, so undoing back to the saved state clears it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::mission::{self, Diagnostic, Mission, MissionError};
use crate::pipelines::Revision;

/// Undo steps kept; the oldest are forgotten first.
const HISTORY_LIMIT: usize = 500;

#[derive(Debug, Clone)]
pub struct Document {
    mission: Mission,
    /// The file it is saved to; `None` for the built-in default until "save as".
    path: Option<PathBuf>,
    saved: Mission,
    /// The file does not exist yet: modified until the first save.
    never_saved: bool,
    undo: Vec<Mission>,
    redo: Vec<Mission>,
    /// The mission before the gesture (drag) in progress, if any.
    gesture: Option<Mission>,
    /// What was found of the mission as it is (its diagnostics, each
    /// pipeline's preparation: θ-PSO's IWPs), once after every change; the
    /// map, the inspector and the live run read it.
    revision: Arc<Revision>,
    /// `revision`'s diagnostics.
    diagnostics: Vec<Diagnostic>,
    /// The text the mission was read from (or last saved as): saves edit it
    /// in place, so the user's comments and layout stay.
    source: Option<String>,
    /// Changes (edits, gestures, undos, redos) since the last save.
    changes: usize,
    /// What to call a document without a file ("(built-in) NAME").
    label: Option<String>,
    /// The shipped mission it is a copy of, by file name, until it is saved.
    builtin: Option<&'static str>,
}

impl Document {
    pub fn new(mission: Mission, path: Option<PathBuf>) -> Self {
        let revision = Arc::new(Revision::of(&mission));
        let diagnostics = revision.diagnostics();
        Document {
            saved: mission.clone(),
            never_saved: false,
            mission,
            path,
            undo: Vec::new(),
            redo: Vec::new(),
            gesture: None,
            revision,
            diagnostics,
            source: None,
            changes: 0,
            label: None,
            builtin: None,
        }
    }

    /// A copy of the shipped mission `file_name` (no file of its own yet):
    /// named after it in the status bar, recordings and exports.
    pub fn with_builtin(mut self, file_name: &'static str) -> Self {
        self.builtin = Some(file_name);
        self.label = Some(format!("(built-in) {file_name}"));
        self
    }

    /// What files made from this mission are named after: its file's stem,
    /// else the shipped mission's (`bridge-inspection`), else its name's slug.
    pub fn stem(&self) -> String {
        let builtin = self.builtin.map(Path::new);
        stem(self.path.as_deref().or(builtin), &self.mission.name)
    }

    /// Names a document that has no file yet (a built-in mission).
    pub fn with_label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    /// The text the mission was read from: saves keep its comments and layout.
    pub fn with_source(mut self, text: impl Into<String>) -> Self {
        self.source = Some(text.into());
        self
    }

    pub fn source(&self) -> Option<&str> {
        self.source.as_deref()
    }

    /// Changes since the last save (what a recovery copy holds).
    pub fn changes(&self) -> usize {
        self.changes
    }

    /// A document for a file that does not exist yet: the content of
    /// `mission`, unsaved, to be written to `path`.
    pub fn new_file(mission: Mission, path: PathBuf) -> Self {
        Document {
            never_saved: true,
            ..Document::new(mission, Some(path))
        }
    }

    pub fn mission(&self) -> &Mission {
        &self.mission
    }

    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// The name shown in the status bar.
    pub fn title(&self) -> String {
        match &self.path {
            Some(p) => p.display().to_string(),
            None => self
                .label
                .clone()
                .unwrap_or_else(|| format!("(built-in) {}", mission::BUILTIN[0].file_name)),
        }
    }

    pub fn is_modified(&self) -> bool {
        self.never_saved || self.mission != self.saved
    }

    pub fn diagnostics(&self) -> &[Diagnostic] {
        &self.diagnostics
    }

    /// What was found of the mission as it is, once (see `revision`).
    pub fn revision(&self) -> Arc<Revision> {
        Arc::clone(&self.revision)
    }

    /// Finds the revision's diagnostics and preparations, after a change.
    fn look(&mut self) {
        self.revision = Arc::new(Revision::of(&self.mission));
        self.diagnostics = self.revision.diagnostics();
    }

    pub fn error_count(&self) -> usize {
        self.diagnostics.iter().filter(|d| d.is_error()).count()
    }

    /// The errors as `field.path: message` lines (for the run refusal and the
    /// save confirmation).
    pub fn error_lines(&self) -> Vec<String> {
        self.diagnostics
            .iter()
            .filter(|d| d.is_error())
            .map(|d| format!("{}: {}", d.path, d.message))
            .collect()
    }

    /// Applies `change` as one undo step. A change that leaves the mission as
    /// it was records nothing.
    pub fn edit(&mut self, change: impl FnOnce(&mut Mission)) {
        let before = self.mission.clone();
        change(&mut self.mission);
        self.reload_terrain_if_moved(&before);
        if self.mission != before {
            self.push_undo(before);
            self.changed();
        }
    }

    /// Starts a gesture (a mouse drag): its moves are one undo step.
    pub fn begin_gesture(&mut self) {
        if self.gesture.is_none() {
            self.gesture = Some(self.mission.clone());
        }
    }

    /// A move inside the gesture (or a plain edit when none is in progress).
    pub fn gesture_edit(&mut self, change: impl FnOnce(&mut Mission)) {
        if self.gesture.is_none() {
            return self.edit(change);
        }
        change(&mut self.mission);
        self.look();
    }

    pub fn end_gesture(&mut self) {
        if let Some(before) = self.gesture.take()
            && before != self.mission
        {
            self.push_undo(before);
            self.changed();
        }
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Returns false when there is nothing to undo.
    pub fn undo(&mut self) -> bool {
        self.end_gesture();
        match self.undo.pop() {
            Some(previous) => {
                self.redo
                    .push(std::mem::replace(&mut self.mission, previous));
                self.look();
                true
            }
            None => false,
        }
    }

    /// Returns false when there is nothing to redo.
    pub fn redo(&mut self) -> bool {
        self.end_gesture();
        match self.redo.pop() {
            Some(next) => {
                self.undo.push(std::mem::replace(&mut self.mission, next));
                self.look();
                true
            }
            None => false,
        }
    }

    /// Saves atomically to the document's file (or `path`, which becomes the
    /// document's file: "save as").
    pub fn save(&mut self, path: Option<PathBuf>) -> Result<PathBuf, MissionError> {
        let target = match path.or_else(|| self.path.clone()) {
            Some(p) => p,
            None => {
                return Err(MissionError::Write {
                    path: "(built-in mission)".into(),
                    source: std::io::Error::other("it has no file yet: use save as"),
                });
            }
        };
        let text = mission::save_edited(&self.mission, self.source.as_deref(), &target)?;
        self.source = Some(text);
        self.changes = 0;
        self.saved = self.mission.clone();
        self.never_saved = false;
        self.path = Some(target.clone());
        Ok(target)
    }

    /// Reads the height map again when the edit changed which file it is or
    /// where it lies (the loaded map compares equal whatever it holds), from
    /// the mission's folder as loading does.
    fn reload_terrain_if_moved(&mut self, before: &Mission) {
        let key = |m: &Mission| {
            m.terrain
                .as_ref()
                .map(|t| (t.file.clone(), t.origin, t.pixel_size))
        };
        if key(&self.mission) != key(before) {
            let base = self
                .path
                .as_deref()
                .and_then(Path::parent)
                .map(Path::to_path_buf)
                .unwrap_or_default();
            self.mission.load_terrain(&base);
        }
    }

    fn push_undo(&mut self, before: Mission) {
        self.undo.push(before);
        if self.undo.len() > HISTORY_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
    }

    fn changed(&mut self) {
        self.changes += 1;
        self.look();
    }
}

/// A file-name-friendly version of a mission name.
pub fn slug(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    let s = s.trim_matches('-').to_owned();
    if s.is_empty() { "mission".into() } else { s }
}

/// What files made from a mission are named after: its file's stem, or the
/// slug of its name when it has no file yet (recordings, exports).
pub fn stem(path: Option<&Path>, name: &str) -> String {
    path.and_then(Path::file_stem)
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| slug(name))
}
