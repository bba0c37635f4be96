//! A mission at one revision and what was found of it, once: the rules'
//! diagnostics, every pipeline's predicted size and findings, and what each
//! pipeline prepared for a run (θ-PSO: its IWPs). The designer finds them on
//! each edit and passes them on: the map, the inspector, the status line
//! and the live run read the same, and nothing is found twice for one edit
//! (issue 53). A run without one (the CLI, a sweep) finds its own.

use std::any::Any;
use std::sync::Arc;

use super::interface::refuse_errors;
use super::{Kind, PipelineError};
use crate::mission::{Diagnostic, Mission};

/// What a pipeline prepared of a mission for its findings and its run;
/// only that pipeline knows its type (`Pipeline::prepare`).
pub type Prepared = Arc<dyn Any + Send + Sync>;

/// What was found of one revision of a mission.
#[derive(Default)]
pub struct Revision {
    /// The rules of the file and of every registered section
    /// (`mission::validate`), which the reading of the file reports too.
    rules: Vec<Diagnostic>,
    /// Per pipeline, in `Kind::ALL`'s order: its predicted size against the
    /// limits, its findings, what it prepared. Empty when a rule is broken
    /// (a pipeline's findings mean nothing then).
    own: Vec<Own>,
}

impl std::fmt::Debug for Revision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Revision")
            .field("diagnostics", &self.diagnostics().len())
            .finish_non_exhaustive()
    }
}

struct Own {
    kind: Kind,
    budget: Vec<Diagnostic>,
    findings: Vec<Diagnostic>,
    prepared: Option<Prepared>,
}

impl Revision {
    /// Everything skyform says of `mission` before a run, found once.
    pub fn of(mission: &Mission) -> Self {
        let rules = crate::mission::validate(mission);
        if rules.iter().any(Diagnostic::is_error) {
            return Revision {
                rules,
                own: Vec::new(),
            };
        }
        let own = Kind::ALL
            .into_iter()
            .map(|kind| {
                let face = kind.face();
                let prepared = face.prepare(mission);
                Own {
                    kind,
                    budget: face.budget(mission),
                    findings: face.findings(mission, prepared.as_ref()),
                    prepared,
                }
            })
            .collect();
        Revision { rules, own }
    }

    /// Every diagnostic, as `check` and the designer list them: the rules,
    /// then every pipeline's predicted size, then every pipeline's findings.
    pub fn diagnostics(&self) -> Vec<Diagnostic> {
        let mut all = self.rules.clone();
        all.extend(self.beyond_the_file());
        all
    }

    /// What the pipelines say beyond the rules: their predicted sizes, then
    /// their findings (`check` locates these in the text after the rules,
    /// which the reading of the file reports itself).
    pub fn beyond_the_file(&self) -> Vec<Diagnostic> {
        let budgets = self.own.iter().flat_map(|o| o.budget.iter());
        let findings = self.own.iter().flat_map(|o| o.findings.iter());
        budgets.chain(findings).cloned().collect()
    }

    /// What `kind` prepared (for its own run to read back).
    pub fn prepared(&self, kind: Kind) -> Option<&Prepared> {
        self.own.iter().find(|o| o.kind == kind)?.prepared.as_ref()
    }

    /// A run of `kind` may start as far as the rules and its limits go:
    /// the same refusals, in the same words, as a run that finds them.
    pub fn admit_rules(&self, kind: Kind) -> Result<(), PipelineError> {
        refuse_errors(&self.rules, PipelineError::InvalidMission)?;
        refuse_errors(&self.own_of(kind)?.budget, PipelineError::OverBudget)
    }

    /// Its findings hold no error (an inspection eq. 8 cannot hold).
    pub fn admit_findings(&self, kind: Kind) -> Result<(), PipelineError> {
        refuse_errors(&self.own_of(kind)?.findings, PipelineError::InvalidMission)
    }

    fn own_of(&self, kind: Kind) -> Result<&Own, PipelineError> {
        self.own.iter().find(|o| o.kind == kind).ok_or_else(|| {
            PipelineError::InvalidMission("the mission was not looked at for this run".into())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::theta_pso::plan::{plan_given, plan_warm};
    use crate::pipelines::{CancelToken, PlanOptions, Silent};

    /// A θ-PSO run handed the designer's revision refuses with the same
    /// error, in the same words, as one that looks at the mission itself
    /// (a broken rule, a run over its limits), and plans the same plan
    /// from the same IWPs when it may.
    #[test]
    fn a_run_on_a_revision_refuses_and_plans_as_one_that_looks_itself() {
        let bridge = crate::mission::default_mission().mission;
        let mut broken = bridge.clone();
        broken.formation.uav_radius = -1.0;
        let mut too_big = bridge.clone();
        too_big.theta_pso.swarm_size = 1_000_000;
        for (what, m) in [
            ("valid", &bridge),
            ("broken", &broken),
            ("too big", &too_big),
        ] {
            let revision = Revision::of(m);
            let cancel = CancelToken::new();
            let options = PlanOptions::default();
            let given = plan_given(m, 3, options, None, Some(&revision), &mut Silent, &cancel);
            let alone = plan_warm(m, 3, options, None, &mut Silent, &cancel);
            match (given, alone) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(what, "valid");
                    assert_eq!(a.cost.total.to_bits(), b.cost.total.to_bits(), "the same J");
                    assert_eq!(a.iwps.len(), b.iwps.len());
                }
                (Err(a), Err(b)) => {
                    assert_ne!(what, "valid");
                    assert_eq!(a.to_string(), b.to_string(), "{what}");
                    assert_eq!(
                        std::mem::discriminant(&a),
                        std::mem::discriminant(&b),
                        "{what}"
                    );
                }
                (a, b) => panic!("{what}: {:?} vs {:?}", a.err(), b.err()),
            }
        }
    }

    /// What `check` adds after the file's rules is the revision's
    /// diagnostics less those rules, in the same order: on a valid mission
    /// the budgets and findings, on a broken one nothing (no findings), and
    /// never the rules twice. A pipeline's section's rules are the file's:
    /// θ-PSO's registered rule on its swarm is among `mission::validate`'s.
    #[test]
    fn beyond_the_file_is_the_revision_less_the_files_rules() {
        let bridge = crate::mission::default_mission().mission;
        let mut section_broken = bridge.clone();
        section_broken.theta_pso.swarm_size = 0;
        let mut too_big = bridge.clone();
        too_big.theta_pso.swarm_size = 1_000_000;
        for m in [&bridge, &section_broken, &too_big] {
            let revision = Revision::of(m);
            let file = crate::mission::validate(m);
            let all = revision.diagnostics();
            assert_eq!(all[..file.len()], file[..]);
            assert_eq!(revision.beyond_the_file(), all[file.len()..]);
        }
        let file = crate::mission::validate(&section_broken);
        assert!(
            file.iter()
                .any(|d| d.is_error() && d.path.to_string() == "theta_pso.swarm_size"),
            "{file:?}"
        );
        assert!(Revision::of(&section_broken).beyond_the_file().is_empty());
        let big = Revision::of(&too_big).beyond_the_file();
        assert!(big.iter().any(Diagnostic::is_error), "{big:?}");
        assert!(
            crate::mission::validate(&too_big)
                .iter()
                .all(|d| !d.is_error())
        );
    }
}
