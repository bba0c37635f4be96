//! The ground floor: what every layer above may use and nothing of ours it
//! imports beyond this folder (geometry, height maps, the ODE step, the PSO
//! engine, routes round discs and the open list's entry they share, the atomic
//! writer).

pub mod atomic;
pub mod detour;
pub mod geometry;
pub mod nearest;
pub mod ode;
pub mod shape;
pub mod swarm;
pub mod terrain;
