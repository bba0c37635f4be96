//! Per-vehicle timed tracks: the common shape of every pipeline's result.
//!
//! A track is what one vehicle is planned to do: its position and velocity
//! (metres and m/s, ENU) at increasing times (seconds from the common start).
//! θ-PSO gives each UAV's trajectory (eqs. 12-15); FLATLO each aircraft's
//! flown track (the point-mass model tracking its reference under the
//! controller, RK4: what verification judged); the fleet each quadrotor's
//! simulated flight (its only plan: the references jump every τ). Exports, views and
//! recordings read tracks instead of each outcome's own fields.

/// One colour per vehicle, the same on the designer's map and in the
/// recording (`pipelines::sketch`).
pub use crate::pipelines::sketch::{VEHICLE_COLORS, vehicle_color};

/// One instant of a track (seconds, metres ENU, m/s): the same sample as a
/// θ-PSO trajectory's, so those tracks are the trajectories themselves.
pub use crate::pipelines::TrackSample;

/// One vehicle's timed track; each pipeline's face gives its own
/// (`PipelineOutcome::tracks`).
pub use crate::pipelines::Track;
