//! Everything skyform can say about a mission before running it.
//!
//! `mission::validate` holds the rules of the file itself; the pipelines know
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

/// What the pipelines say of a mission that follows the rules: their budgets
/// first (a run too large to start), then θ-PSO's IWPs and inspections,
/// then FLATLO's airspeeds and bounds predicted from its references
/// (`Pipeline::findings`).
fn pipeline_findings(mission: &Mission) -> Vec<Diagnostic> {
    use crate::pipelines::Kind;
    // Every registered pipeline's predicted size, then its findings, each
    // in the order of `Kind`.
    let budgets = Kind::ALL
        .into_iter()
        .flat_map(|kind| kind.face().budget(mission));
    let findings = Kind::ALL
        .into_iter()
        .flat_map(|kind| kind.face().findings(mission, None));
    budgets.chain(findings).collect()
}

/// `mission::check_str` with the pipelines' findings, located in `text`.
pub fn check_text(text: &str, file: Option<&str>) -> Checked {
    let mut checked = mission::check_str(text, file);
    if let Some(m) = &checked.mission
        && !checked.report.has_errors()
    {
        let source = SourceMap::new(text);
        // The pipelines' own sections' rules; their findings only on a
        // mission that follows every rule, as in `diagnose`.
        let sections: Vec<Diagnostic> = crate::pipelines::Kind::ALL
            .into_iter()
            .flat_map(|kind| kind.face().validate(m))
            .collect();
        let findings = if sections.iter().any(Diagnostic::is_error) {
            Vec::new()
        } else {
            pipeline_findings(m)
        };
        let extra: Vec<Diagnostic> = sections
            .into_iter()
            .chain(findings)
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
