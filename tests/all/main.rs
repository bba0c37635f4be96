//! The integration tests, one binary (each module a file of its own, as
//! they were when each was a binary): one link of the Rerun SDK instead of
//! thirty. `cargo test --test all MODULE::` runs one file's tests
//! (`cargo test --test all export::`).

#![allow(clippy::too_many_lines)]

mod common;
mod sites;

mod architecture;
mod campaign;
mod chart;
mod cli;
mod export;
mod extreme_values;
mod flatlo;
mod fleet;
mod fleet_distributed;
mod fleet_lost;
mod fleet_network;
mod flight_check;
mod fuzz_loader;
mod geodetic;
mod import;
mod inspector_places;
mod mission_files;
mod mission_save;
mod mission_validation;
mod passages;
mod rare;
mod recording;
mod shapes;
mod spso;
mod terrain;
mod terrain_view;
mod theta_pso;
mod theta_pso_family;
mod theta_pso_sites;
mod tracks;
mod tui_pty;
mod tui_snapshots;
mod tui_state;
