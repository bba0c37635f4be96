//! Helpers shared by the tests that run the real binary.

use std::process::{Command, Output};

pub mod toml_leaves;

/// Runs `skyform ARGS` from the crate's root and collects its output.
pub fn skyform(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_skyform"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap_or_else(|e| panic!("cannot start skyform: {e}"))
}
pub mod oracle;

/// `mission` with θ-PSO's swarm cut to `iterations` (a designer's test
/// needs a plan on the map, not the best one).
pub fn quick(
    mut mission: skyform::mission::Mission,
    iterations: usize,
) -> skyform::mission::Mission {
    mission.theta_pso.iterations = iterations;
    mission
}

/// The Python of the venv that `variable` names (one `.ci/run` creates
/// with `requirements`): `None`, and the test skipped, without it, except
/// under CI (`CI` set), where it fails: CI must run what needs it.
pub fn venv_python(variable: &str, requirements: &str) -> Option<std::path::PathBuf> {
    match std::env::var_os(variable) {
        Some(venv) => {
            let python = std::path::PathBuf::from(venv).join("bin").join("python");
            assert!(python.exists(), "{variable} has no {}", python.display());
            Some(python)
        }
        None => {
            assert!(
                std::env::var_os("CI").is_none(),
                "CI is set but {variable} is not: .ci/run must create the venv of {requirements}"
            );
            eprintln!("skipped: set {variable} to a venv with {requirements}");
            None
        }
    }
}
