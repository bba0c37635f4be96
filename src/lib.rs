//! skyform: a terminal mission designer for multi-UAV formations.
//!
//! Data flows one way: a mission file becomes a validated [`mission::Mission`],
//! pipelines turn it into outcomes, and views (CLI, TUI, Rerun) show them.
//! See `docs/architecture.md`.

pub mod atomic;
#[cfg(feature = "rerun")]
pub mod cli;
pub mod detour;
pub mod diagnose;
pub mod export;
pub mod flatlo;
pub mod fleet;
pub mod geometry;
pub mod import;
pub mod mission;
pub mod ode;
pub mod outcome;
pub mod pipeline;
pub mod planner;
#[cfg(feature = "rerun")]
pub mod record;
pub mod run;
pub mod spso;
pub mod swarm;
pub mod terrain;
pub mod tracks;
pub mod tui;
