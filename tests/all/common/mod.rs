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
