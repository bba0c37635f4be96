//! The windows on top of the screen that take the keys: help, the open
//! dialog, save as, and the questions (unsaved changes, save an invalid
//! mission, replace a file, restore a recovery copy).
//!
//! [`Overlays`] owns the window shown and the text typed into it; what a
//! "yes" does (save, open, quit) touches the document and the jobs, so the
//! app carries it out. The open dialog's list (which files it offers, how
//! typing filters them) and the reading of a chosen file are here too.

use std::path::{Path, PathBuf};

use super::action::Action;
use super::recovery;
use crate::mission::{self, Mission};

/// A file the open dialog offers.
#[derive(Debug, Clone, PartialEq)]
pub enum Entry {
    File(PathBuf),
    Builtin(&'static str),
    /// A `.toml` path typed that does not exist: a new mission there.
    New(PathBuf),
}

impl Entry {
    pub fn label(&self) -> String {
        match self {
            Entry::File(p) => p.display().to_string(),
            Entry::Builtin(name) => format!("(built-in) {name}"),
            Entry::New(p) => format!("{} (new)", p.display()),
        }
    }
}

/// What to do once a save went through (nothing happens if it did not).
#[derive(Debug, Clone, PartialEq)]
pub enum AfterSave {
    Stay,
    Quit,
    /// "Save first" in the open dialog's unsaved-changes prompt.
    Open(Entry),
}

/// A window on top of the screen that takes the keys.
#[derive(Debug, Clone, PartialEq)]
pub enum Overlay {
    Help,
    /// Unsaved changes: save, discard or stay.
    Quit,
    /// Jobs are running and would be cancelled: quit or stay.
    QuitRunning,
    SaveAs {
        input: String,
        then: AfterSave,
    },
    /// The mission has errors: save anyway?
    SaveInvalid {
        path: Option<PathBuf>,
        errors: Vec<String>,
        then: AfterSave,
    },
    /// The open dialog: the missions found, the text typed (a filter, or
    /// a path to open that is not listed), what it leaves (`matches`) and
    /// the cursor in those.
    Open {
        entries: Vec<Entry>,
        input: String,
        matches: Vec<Entry>,
        cursor: usize,
    },
    /// Unsaved changes would be lost by opening `entry`: save first,
    /// discard them, or stay.
    Discard(Entry),
    /// "Save as" onto a file that exists: replace it?
    Overwrite {
        path: PathBuf,
        then: AfterSave,
    },
    /// An earlier session left unsaved changes: restore them?
    Recover(Box<recovery::Copy>),
    /// The survey file to import obstacles from (typed path).
    Import {
        input: String,
    },
}

/// The window shown, if any, and where the help overlay is scrolled to.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overlays {
    shown: Option<Overlay>,
    /// First line of the help overlay shown (it scrolls on small screens).
    help_scroll: u16,
}

impl Overlays {
    /// The window on top, if any.
    pub fn current(&self) -> Option<&Overlay> {
        self.shown.as_ref()
    }

    pub fn help_scroll(&self) -> u16 {
        self.help_scroll
    }

    pub fn show(&mut self, overlay: Overlay) {
        self.shown = Some(overlay);
    }

    /// Closes the window on top; false if there was none.
    pub fn close(&mut self) -> bool {
        self.shown.take().is_some()
    }

    /// The open dialog, listing the missions found from `cwd`.
    pub fn open_dialog(&mut self, cwd: &Path) {
        let entries = open_entries(cwd);
        self.shown = Some(Overlay::Open {
            matches: entries.clone(),
            entries,
            input: String::new(),
            cursor: 0,
        });
    }

    /// Scrolls, types or moves in the window on top for one action (the
    /// others are not the overlays'). Relative paths typed start at `cwd`.
    pub fn update(&mut self, action: Action, cwd: &Path) {
        match action {
            Action::ToggleHelp => {
                self.help_scroll = 0;
                self.shown = match self.shown {
                    Some(Overlay::Help) => None,
                    _ => Some(Overlay::Help),
                }
            }
            Action::ScrollHelp(by) => {
                self.help_scroll =
                    (i64::from(self.help_scroll) + i64::from(by)).clamp(0, 500) as u16;
            }
            Action::PromptInput(c) => self.edit_prompt(cwd, |input| input.push(c)),
            Action::PromptClear => self.edit_prompt(cwd, String::clear),
            Action::PromptBackspace => self.edit_prompt(cwd, |input| {
                input.pop();
            }),
            Action::PickerMove(d) => {
                if let Some(Overlay::Open {
                    matches, cursor, ..
                }) = &mut self.shown
                {
                    let n = matches.len() as i32;
                    if n > 0 {
                        *cursor = (*cursor as i32 + d).clamp(0, n - 1) as usize;
                    }
                }
            }
            _ => {}
        }
    }

    /// Changes the text of the prompt on screen (save as, open); the open
    /// dialog filters its list by it.
    fn edit_prompt(&mut self, cwd: &Path, change: impl FnOnce(&mut String)) {
        match &mut self.shown {
            Some(Overlay::SaveAs { input, .. }) | Some(Overlay::Import { input }) => change(input),
            Some(Overlay::Open {
                entries,
                input,
                matches,
                cursor,
            }) => {
                change(input);
                *matches = open_matches(entries, input, cwd);
                *cursor = 0;
            }
            _ => {}
        }
    }
}

/// The missions the open dialog offers: `*.toml` in `missions/` and the
/// current directory, then the built-in ones.
pub fn open_entries(cwd: &Path) -> Vec<Entry> {
    let mut files = Vec::new();
    for dir in [cwd.join("missions"), cwd.to_path_buf()] {
        if let Ok(read) = std::fs::read_dir(&dir) {
            for entry in read.flatten() {
                let p = entry.path();
                if p.extension().is_some_and(|e| e == "toml") && p.is_file() {
                    let shown = p.strip_prefix(cwd).map(Path::to_path_buf).unwrap_or(p);
                    files.push(shown);
                }
            }
        }
    }
    files.sort();
    files.dedup();
    let mut entries: Vec<Entry> = files
        .into_iter()
        .filter(|p| p.file_name().is_some_and(|n| n != "Cargo.toml"))
        .map(|p| Entry::File(if p.is_relative() { cwd.join(p) } else { p }))
        .collect();
    entries.extend(mission::BUILTIN.iter().map(|b| Entry::Builtin(b.file_name)));
    entries
}

/// A typed path, relative to `cwd` unless absolute (`~/` is the home folder).
pub fn typed_path(cwd: &Path, input: &str) -> PathBuf {
    let input = input.trim();
    if let Some(rest) = input.strip_prefix("~/")
        && let Some(home) = std::env::var_os("HOME")
    {
        return PathBuf::from(home).join(rest);
    }
    cwd.join(input)
}

/// What the open dialog lists for the text typed: the entries whose label
/// holds it (exact, then starting with it, then the rest), after the typed
/// path itself when it is a file not listed; just the typed path when
/// nothing matches (Enter then opens it, or says why not).
pub fn open_matches(entries: &[Entry], input: &str, cwd: &Path) -> Vec<Entry> {
    let wanted = input.trim().to_lowercase();
    if wanted.is_empty() {
        return entries.to_vec();
    }
    let typed = typed_path(cwd, input);
    let mut ranked: Vec<(u8, &Entry)> = entries
        .iter()
        .filter_map(|e| {
            let label = entry_label(e, cwd).to_lowercase();
            let file = match e {
                Entry::File(p) | Entry::New(p) => {
                    p.file_name().map(|n| n.to_string_lossy().to_lowercase())
                }
                Entry::Builtin(n) => Some(n.to_lowercase()),
            };
            let rank = if label == wanted || matches!(e, Entry::File(p) if *p == typed) {
                0
            } else if label.starts_with(&wanted)
                || file.as_ref().is_some_and(|f| f.starts_with(&wanted))
            {
                1
            } else if label.contains(&wanted) {
                2
            } else {
                return None;
            };
            Some((rank, e))
        })
        .collect();
    ranked.sort_by_key(|(rank, _)| *rank);
    let mut matches: Vec<Entry> = ranked.into_iter().map(|(_, e)| e.clone()).collect();
    let listed = matches
        .iter()
        .any(|e| matches!(e, Entry::File(p) if *p == typed));
    let new = !typed.exists() && typed.extension().is_some_and(|e| e == "toml");
    if new {
        // A mission file that does not exist yet: Enter starts it there.
        matches.insert(0, Entry::New(typed));
    } else if matches.is_empty() || (!listed && typed.is_file()) {
        matches.insert(0, Entry::File(typed));
    }
    matches
}

/// An entry as the open dialog shows it: files relative to `cwd`.
pub fn entry_label(entry: &Entry, cwd: &Path) -> String {
    match entry {
        Entry::File(p) => p.strip_prefix(cwd).unwrap_or(p).display().to_string(),
        Entry::New(p) => format!(
            "{}  (new: Enter starts a new mission there)",
            p.strip_prefix(cwd).unwrap_or(p).display()
        ),
        other => other.label(),
    }
}

/// A mission read for opening, not yet in the designer.
pub struct Loaded {
    pub mission: Mission,
    pub text: String,
    pub name: String,
    pub path: Option<PathBuf>,
    /// Validation errors (it opens; the inspector shows them).
    pub errors: usize,
    /// Not on disk yet: a new mission to be written at `path`.
    pub new: bool,
}

/// Reads and checks `entry`; the message names the file when it cannot be
/// opened (missing, a folder, not a mission).
pub fn load(entry: &Entry) -> Result<Loaded, String> {
    let (text, name, path) = match entry {
        Entry::New(p) => {
            if p.exists() {
                return Err(format!("{} exists: open it instead", p.display()));
            }
            let name = mission::name_for(p);
            let mission = mission::template(&name).map_err(|e| e.to_string())?;
            return Ok(Loaded {
                mission,
                text: mission::template_text(&name),
                name: p.display().to_string(),
                path: Some(p.clone()),
                errors: 0,
                new: true,
            });
        }
        Entry::File(p) => {
            if p.is_dir() {
                return Err(format!("cannot open {}: it is a folder", p.display()));
            }
            if !p.exists() {
                return Err(format!(
                    "cannot open {}: no such file (a name ending in .toml starts a new mission)",
                    p.display()
                ));
            }
            match mission::read(p) {
                Ok(text) => (text, p.display().to_string(), Some(p.clone())),
                Err(e) => return Err(e.to_string()),
            }
        }
        Entry::Builtin(name) => match mission::BUILTIN.iter().find(|b| b.file_name == *name) {
            Some(b) => (b.text.to_owned(), b.file_name.to_owned(), None),
            None => return Err(format!("no built-in mission {name}")),
        },
    };
    let checked = crate::outcome::diagnose::check_text(&text, Some(&name));
    match checked.mission {
        Some(mission) => Ok(Loaded {
            mission,
            errors: checked.report.error_count(),
            text,
            name,
            path,
            new: false,
        }),
        None => {
            let first = checked
                .report
                .errors()
                .next()
                .map(|d| d.to_string())
                .unwrap_or_default();
            Err(format!("cannot open {name}: {first}"))
        }
    }
}
