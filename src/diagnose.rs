//! Everything skyform can say about a mission before running it.
//!
//! `mission::validate` holds the rules of the file itself; the pipelines know
//! more (an IWP no shape can pass, an inspection pass eq. 8 cannot hold).
//! Every reader of a mission (`check`, `run`, the designer) asks here, so
//! all of them see the same findings.

use crate::mission::{self, Checked, Diagnostic, Mission, Report, SourceMap};

/// Validation and every pipeline's own findings, errors and warnings.
pub fn diagnose(mission: &Mission) -> Vec<Diagnostic> {
    let mut all = mission::validate(mission);
    // A pipeline's findings only mean something on a mission that follows the
    // rules; on one that does not, the rules' errors are the news.
    if !all.iter().any(Diagnostic::is_error) {
        all.extend(crate::planner::diagnostics(mission));
    }
    all
}

/// `mission::check_str` with the pipelines' findings, located in `text`.
pub fn check_text(text: &str, file: Option<&str>) -> Checked {
    let mut checked = mission::check_str(text, file);
    if let Some(m) = &checked.mission
        && !checked.report.has_errors()
    {
        let source = SourceMap::new(text);
        let extra: Vec<Diagnostic> = crate::planner::diagnostics(m)
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
