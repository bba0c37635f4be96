//! ENU ↔ WGS-84 about the mission's `[origin]`: the exports use the
//! mission's own conversion (`mission::geodesy`), the one that also reads
//! latitude/longitude positions in mission files, so a position written
//! either way is the same point.

pub use crate::mission::geodesy::{Frame, Geodetic};
