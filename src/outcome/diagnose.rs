//! Everything skyform can say about a mission before running it.
//!
//! `mission::validate` holds the rules of the file itself, each pipeline's
//! section's among them (registered by the pipeline); the pipelines know
//! more (an IWP no shape can pass, an inspection pass eq. 8 cannot hold).
//! Each pipeline also predicts the size of a run and refuses one over the
//! documented limits (`pipeline::limits`). Every reader of a mission
//! (`check`, `run`, the designer) asks here, so all of them see the same
//! findings.

use crate::mission::{self, Checked, Diagnostic, Mission, Report, SourceMap};

/// Validation and every pipeline's own findings, errors and warnings.
pub fn diagnose(mission: &Mission) -> Vec<Diagnostic> {
    // A pipeline's findings only mean something on a mission that follows the
    // rules; on one that does not, the rules' errors are the news.
    crate::pipelines::Revision::of(mission).diagnostics()
}

/// `mission::check_str` with the pipelines' findings, located in `text`.
pub fn check_text(text: &str, file: Option<&str>) -> Checked {
    let mut checked = mission::check_str(text, file);
    if let Some(m) = &checked.mission
        && !checked.report.has_errors()
    {
        let source = SourceMap::new(text);
        // On a mission that follows every rule (as in `diagnose`), the
        // pipelines' budgets and findings: the revision the designer finds,
        // less the rules (the file's and every registered section's), which
        // `check_str` has located already.
        let extra: Vec<Diagnostic> = crate::pipelines::Revision::of(m)
            .beyond_the_file()
            .into_iter()
            .map(|d| d.locate(file, &source))
            .collect();
        if !extra.is_empty() {
            let mut all = checked.report.diagnostics.clone();
            all.extend(extra);
            checked.report = Report::new(all);
        }
    }
    checked
}

/// `mission::load` with the pipelines' findings: a mission over a run's
/// budget, or with an inspection eq. 8 cannot hold, is refused here, before
/// any run starts.
pub fn load(path: &std::path::Path) -> Result<mission::Loaded, mission::MissionError> {
    let text = mission::read(path)?;
    let origin = path.display().to_string();
    let Checked { mission, report } = check_text(&text, Some(&origin));
    match mission {
        Some(mission) if !report.has_errors() => Ok(mission::Loaded {
            mission,
            warnings: report,
        }),
        _ => Err(mission::MissionError::Invalid { origin, report }),
    }
}
