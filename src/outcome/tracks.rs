//! Per-vehicle timed tracks: the common shape of every pipeline's result.
//!
//! A track is what one vehicle is planned to do: its position and velocity
//! (metres and m/s, ENU) at increasing times (seconds from the common start).
//! θ-PSO gives each UAV's trajectory (eqs. 12-15); FLATLO each aircraft's
//! reference (Algorithms 1-2 at its common-arrival airspeed: the plan, not the
//! one noisy simulated flight of it); the fleet each quadrotor's simulated
//! flight (its only plan: the references jump every τ). Exports, views and
//! recordings read tracks instead of each outcome's own fields.

/// One colour per vehicle (RGB), in vehicle order, cycling: the designer's
/// map and the Rerun recording draw UAV n in the same colour. Chosen to
/// stay apart on dark terminals and in the viewer (cyan first, as the map
/// always drew UAV 1).
pub const VEHICLE_COLORS: [[u8; 3]; 6] = [
    [23, 190, 207],
    [227, 119, 194],
    [44, 200, 44],
    [80, 140, 255],
    [255, 200, 60],
    [240, 80, 70],
];

/// Vehicle `i`'s colour (0-based).
pub fn vehicle_color(i: usize) -> [u8; 3] {
    VEHICLE_COLORS[i % VEHICLE_COLORS.len()]
}

/// One instant of a track (seconds, metres ENU, m/s): the same sample as a
/// θ-PSO trajectory's, so those tracks are the trajectories themselves.
pub use crate::pipelines::TrackSample;

/// One vehicle's timed track; each pipeline's face gives its own
/// (`PipelineOutcome::tracks`).
pub use crate::pipelines::Track;
