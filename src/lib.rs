//! skyform: a terminal mission designer for multi-UAV formations.
//!
//! Data flows one way: a mission file becomes a validated [`mission::Mission`],
//! pipelines turn it into outcomes, and views (CLI, TUI, Rerun) show them.
//! See `docs/architecture.md`.

// Layers, from the ground up (docs/architecture.md): what every layer may
// use, what a user writes, the pipelines, what a run gives, the front ends.
pub mod base;
#[cfg(feature = "rerun")]
pub mod cli;
#[cfg(feature = "zenoh")]
pub mod distributed;
pub mod export;
pub mod flight;
pub mod import;
pub mod mission;
pub mod outcome;
pub mod pipelines;
#[cfg(feature = "rerun")]
pub mod record;
pub mod run;
pub mod tui;
