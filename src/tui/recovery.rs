//! The recovery copy: unsaved edits survive a crash, a `kill -9` or a closed
//! terminal.
//!
//! While the document has unsaved changes, the designer keeps a copy of the
//! mission in the state directory (`$SKYFORM_STATE_DIR`, else
//! `$XDG_STATE_HOME/skyform`, else `~/.local/state/skyform`), written
//! atomically at most once a second and within about a second of the last
//! edit. A save, an undo back to the saved state or a clean quit removes it.
//! Opening the same file (or built-in mission) again with a copy present
//! offers to restore it, with its time and number of changes.

use std::fs;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use crate::mission::{self, Mission};

/// At most one write per this interval while editing.
pub const INTERVAL: Duration = Duration::from_secs(1);

/// The state directory recovery copies live in.
pub fn state_dir() -> Option<PathBuf> {
    let env = |key: &str| std::env::var_os(key).filter(|v| !v.is_empty());
    if let Some(dir) = env("SKYFORM_STATE_DIR") {
        return Some(PathBuf::from(dir));
    }
    if let Some(dir) = env("XDG_STATE_HOME") {
        return Some(PathBuf::from(dir).join("skyform"));
    }
    env("HOME").map(|home| PathBuf::from(home).join(".local/state/skyform"))
}

/// What a document is: a file, or a built-in mission (by file name).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    File(PathBuf),
    Builtin(String),
}

impl Origin {
    pub fn label(&self) -> String {
        match self {
            Origin::File(p) => p.display().to_string(),
            Origin::Builtin(name) => format!("(built-in) {name}"),
        }
    }

    /// The copy's file name: the origin spelled out, `/` as `%` (as vim's
    /// swap files), so a listing of the directory says what each copy is of.
    fn file_name(&self) -> String {
        let key = match self {
            Origin::File(p) => {
                let absolute = std::path::absolute(p).unwrap_or_else(|_| p.clone());
                absolute.display().to_string().replace(['/', '\\'], "%")
            }
            Origin::Builtin(name) => format!("builtin%{name}"),
        };
        format!("{key}.recovery.toml")
    }
}

/// A recovery copy read back.
#[derive(Debug, Clone, PartialEq)]
pub struct Copy {
    pub mission: Mission,
    /// When it was written.
    pub saved_at: SystemTime,
    /// Changes since the file was last saved.
    pub changes: usize,
}

impl Copy {
    /// "3 change(s), saved 2 min ago (2026-12-01 18:04)" for the prompt, in
    /// the local time zone.
    pub fn describe(&self, now: SystemTime) -> String {
        self.describe_in(now, &jiff::tz::TimeZone::system())
    }

    /// [`Copy::describe`] with the clock read in `zone`.
    pub fn describe_in(&self, now: SystemTime, zone: &jiff::tz::TimeZone) -> String {
        let age = now.duration_since(self.saved_at).unwrap_or_default();
        let ago = match age.as_secs() {
            s if s < 60 => format!("{s} s ago"),
            s if s < 3600 => format!("{} min ago", s / 60),
            s if s < 86_400 => format!("{} h ago", s / 3600),
            s => format!("{} days ago", s / 86_400),
        };
        let when = jiff::Timestamp::try_from(self.saved_at)
            .map(|t| format!(" ({})", t.to_zoned(zone.clone()).strftime("%Y-%m-%d %H:%M")))
            .unwrap_or_default();
        format!("{} change(s), saved {ago}{when}", self.changes)
    }
}

/// Keeps one document's recovery copy up to date.
#[derive(Debug)]
pub struct Recovery {
    /// Where the copy goes; `None` when there is no state directory.
    path: Option<PathBuf>,
    /// What was last written (`None`: no copy on disk from us).
    written: Option<Mission>,
    last_write: Option<Instant>,
    /// A write failed: said once in the status line, not on every edit.
    pub failed: Option<String>,
}

impl Recovery {
    /// The copy for `origin` in the state directory.
    pub fn new(origin: &Origin) -> Self {
        Self::in_dir(state_dir(), origin)
    }

    /// The copy for `origin` in `dir` (`None`: keep no copy).
    pub fn in_dir(dir: Option<PathBuf>, origin: &Origin) -> Self {
        Recovery {
            path: dir.map(|d| d.join(origin.file_name())),
            written: None,
            last_write: None,
            failed: None,
        }
    }

    /// The copy for another origin in the same directory ("save as").
    pub fn moved_to(&self, origin: &Origin) -> Self {
        let dir = self
            .path
            .as_deref()
            .and_then(Path::parent)
            .map(Path::to_path_buf);
        Self::in_dir(dir, origin)
    }

    /// Where the copy is kept.
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// The copy left by an earlier session, if any.
    pub fn existing(&self) -> Option<Copy> {
        read(self.path.as_deref()?)
    }

    /// A write is due but held back by the interval.
    pub fn pending(&self, mission: &Mission, modified: bool) -> bool {
        modified && self.written.as_ref() != Some(mission)
    }

    /// Brings the copy in line with the document: written when modified
    /// (at most once per `INTERVAL` unless `force`), removed when not.
    pub fn keep(
        &mut self,
        mission: &Mission,
        modified: bool,
        changes: usize,
        now: Instant,
        force: bool,
    ) {
        let Some(path) = self.path.clone() else {
            return;
        };
        if !modified {
            self.discard();
            return;
        }
        if self.written.as_ref() == Some(mission) {
            return;
        }
        let due = self
            .last_write
            .is_none_or(|t| now.duration_since(t) >= INTERVAL);
        if !(due || force) {
            return;
        }
        self.last_write = Some(now);
        match write(&path, mission, changes) {
            Ok(()) => {
                self.written = Some(mission.clone());
                self.failed = None;
            }
            Err(e) => self.failed = Some(format!("cannot keep a recovery copy: {e}")),
        }
    }

    /// Removes the copy (saved, discarded, or quit cleanly).
    pub fn discard(&mut self) {
        if let Some(path) = &self.path
            && (self.written.is_some() || path.exists())
        {
            let _ = fs::remove_file(path);
        }
        self.written = None;
    }
}

const HEADER: &str = "# skyform recovery copy: unsaved changes, kept until saved or discarded\n";

fn write(path: &Path, mission: &Mission, changes: usize) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        fs::create_dir_all(dir)?;
    }
    let body = mission::to_toml_string(mission).map_err(std::io::Error::other)?;
    let stamp = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let text = format!("{HEADER}# saved_at = {stamp}\n# changes = {changes}\n{body}");
    crate::base::atomic::write(path, text.as_bytes())
}

/// A copy on disk, or `None` when there is none or it cannot be read as a
/// mission (then it is not offered).
pub fn read(path: &Path) -> Option<Copy> {
    let text = fs::read_to_string(path).ok()?;
    let number = |key: &str| -> Option<u64> {
        text.lines()
            .take(4)
            .find_map(|l| l.strip_prefix(&format!("# {key} = ")))
            .and_then(|v| v.trim().parse().ok())
    };
    let mission: Mission = toml::from_str(&text).ok()?;
    Some(Copy {
        mission,
        saved_at: UNIX_EPOCH + Duration::from_secs(number("saved_at").unwrap_or(0)),
        changes: number("changes").unwrap_or(0) as usize,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 24, item 18: the prompt gives the copy's date and time as a
    /// clock shows it, not a count of seconds since 1970.
    #[test]
    fn the_prompt_says_when_the_copy_was_saved_as_a_clock_does() {
        let copy = Copy {
            mission: crate::mission::default_mission().mission,
            saved_at: UNIX_EPOCH + Duration::from_secs(1_796_148_257),
            changes: 3,
        };
        let now = copy.saved_at + Duration::from_secs(150);
        assert_eq!(
            copy.describe_in(now, &jiff::tz::TimeZone::UTC),
            "3 change(s), saved 2 min ago (2026-12-01 18:04)"
        );
        assert!(!copy.describe(now).contains("unix time"));
    }
}
