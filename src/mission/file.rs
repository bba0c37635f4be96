//! Reading, checking and atomically saving mission files.

use std::fs;
use std::io;
use std::path::Path;

use toml::de::DeTable;

use super::diagnostic::{Diagnostic, Report};
use super::model::Mission;
use super::read::{locate_toml_error, read_model};
use super::source::SourceMap;
use super::validate::validate;

/// What can go wrong between a mission file and a `Mission`.
#[derive(Debug, thiserror::Error)]
pub enum MissionError {
    #[error("cannot read {path}: {source}")]
    Read { path: String, source: io::Error },
    #[error("{origin} is not a valid mission ({} error(s)):\n{report}", report.error_count())]
    Invalid { origin: String, report: Report },
    #[error("cannot save {path}: {source}")]
    Write { path: String, source: io::Error },
    #[error("cannot write the mission as TOML: {0}")]
    Serialize(#[from] toml::ser::Error),
}

/// The result of checking a mission text: the mission when it could be read at
/// all, and every problem found (syntax, unknown keys, validation rules).
#[derive(Debug, Clone)]
pub struct Checked {
    pub mission: Option<Mission>,
    pub report: Report,
}

/// Parses and validates `text`; `file` names it in the messages.
/// Never panics, whatever the bytes.
pub fn check_str(text: &str, file: Option<&str>) -> Checked {
    let source = SourceMap::new(text);
    let locate = |d: Diagnostic| d.locate(file, &source);

    // The spanned parser recovers after a syntax error, so every syntax error
    // of the file is reported at once, not only the first.
    let (_, syntax_errors) = DeTable::parse_recoverable(text);
    if !syntax_errors.is_empty() {
        let diagnostics = syntax_errors
            .iter()
            .map(|e| locate_toml_error(e, &source))
            .map(locate)
            .collect();
        return Checked {
            mission: None,
            report: Report::new(diagnostics),
        };
    }
    match read_model(text, &source) {
        Ok((mut mission, _)) => {
            // A terrain file is relative to the mission file (or to the
            // current directory for a mission without one).
            let base = file
                .map(Path::new)
                .and_then(Path::parent)
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or_else(|| Path::new("."));
            mission.load_terrain(base);
            let mut found: Vec<Diagnostic> = validate(&mission).into_iter().map(locate).collect();
            // In the order of the file: the sections' rules run in the
            // order of their keys, not of the user's text. What the file
            // does not write (a default) comes after what it does.
            found.sort_by_key(|d| d.location.map_or(usize::MAX, |at| at.line));
            let report = Report::new(found);
            Checked {
                mission: Some(mission),
                report,
            }
        }
        Err(diagnostics) => Checked {
            mission: None,
            report: Report::new(diagnostics.into_iter().map(locate).collect()),
        },
    }
}

/// A valid mission and the warnings it raised.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub mission: Mission,
    pub warnings: Report,
}

/// Parses `text` into a valid mission, or fails with every error found.
pub fn parse_str(text: &str, origin: &str) -> Result<Loaded, MissionError> {
    let Checked { mission, report } = check_str(text, Some(origin));
    match mission {
        Some(mission) if !report.has_errors() => Ok(Loaded {
            mission,
            warnings: report,
        }),
        _ => Err(MissionError::Invalid {
            origin: origin.to_owned(),
            report,
        }),
    }
}

/// Reads a mission file; it must be valid.
pub fn load(path: &Path) -> Result<Loaded, MissionError> {
    let text = read(path)?;
    parse_str(&text, &path.display().to_string())
}

/// Reads a file as UTF-8 text, naming it in the error.
pub fn read(path: &Path) -> Result<String, MissionError> {
    fs::read_to_string(path).map_err(|source| MissionError::Read {
        path: path.display().to_string(),
        source,
    })
}

/// The mission as TOML text, the same shape as the shipped files.
pub fn to_toml_string(mission: &Mission) -> Result<String, MissionError> {
    let body = toml::to_string_pretty(mission)?;
    Ok(format!(
        "# skyform mission (format of skyform {}); see README.md for every field.\n\n{body}",
        env!("CARGO_PKG_VERSION")
    ))
}

/// Saves atomically: the text goes to a temporary file in the same directory,
/// is flushed to disk, then renamed over `path`. A crash or a full disk leaves
/// either the old file or the new one, never half of one.
pub fn save(mission: &Mission, path: &Path) -> Result<(), MissionError> {
    let text = to_toml_string(mission)?;
    crate::base::atomic::write(path, text.as_bytes()).map_err(|source| MissionError::Write {
        path: path.display().to_string(),
        source,
    })
}

/// Saves atomically into the user's file: with `original` (the text the
/// mission was read from), only the values that changed are rewritten, and
/// comments, order and layout stay (`edit::edit_in_place`); without it, or
/// when it is not a mission, the whole mission is written. Returns the text
/// written, the next save's `original`.
pub fn save_edited(
    mission: &Mission,
    original: Option<&str>,
    path: &Path,
) -> Result<String, MissionError> {
    let text = match original.and_then(|o| super::edit::edit_in_place(mission, o)) {
        Some(text) => text,
        None => to_toml_string(mission)?,
    };
    crate::base::atomic::write(path, text.as_bytes()).map_err(|source| MissionError::Write {
        path: path.display().to_string(),
        source,
    })?;
    Ok(text)
}
