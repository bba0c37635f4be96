//! Per-vehicle timed tracks: the common shape of every pipeline's result.
//!
//! A track is what one vehicle is planned to do: its position and velocity
//! (metres and m/s, ENU) at increasing times (seconds from the common start).
//! θ-PSO gives each UAV's trajectory (eqs. 12-15); FLATLO each aircraft's
//! reference (Algorithms 1-2 at its common-arrival airspeed: the plan, not the
//! one noisy simulated flight of it); the fleet each quadrotor's simulated
//! flight (its only plan: the references jump every τ). Exports, views and
//! recordings read tracks instead of each outcome's own fields.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use crate::pipelines::flatlo::FlatloOutcome;
use crate::pipelines::fleet::FleetOutcome;
use crate::pipelines::theta_pso::ThetaPsoOutcome;

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

/// One vehicle's timed track.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Track {
    /// 0-based vehicle index (UAV n + 1 in messages and file names).
    pub vehicle: usize,
    pub samples: Vec<TrackSample>,
}

impl Track {
    /// The track from positions at `times`, velocities by central differences.
    pub fn from_positions(vehicle: usize, times: &[f64], positions: &[Point3<f64>]) -> Self {
        let n = times.len().min(positions.len());
        let samples = (0..n)
            .map(|k| {
                let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
                let dt = times[b] - times[a];
                let velocity = if dt > 0.0 {
                    (positions[b] - positions[a]) / dt
                } else {
                    Vector3::zeros()
                };
                TrackSample {
                    t: times[k],
                    position: positions[k],
                    velocity,
                }
            })
            .collect();
        Track { vehicle, samples }
    }

    /// Seconds from the first to the last sample.
    pub fn duration(&self) -> f64 {
        match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => b.t - a.t,
            _ => 0.0,
        }
    }
}

/// Every UAV's trajectory of a θ-PSO plan.
pub fn theta_pso(outcome: &ThetaPsoOutcome) -> Vec<Track> {
    outcome
        .trajectories
        .iter()
        .map(|t| Track {
            vehicle: t.uav,
            samples: t.samples.clone(),
        })
        .collect()
}

/// Every aircraft's reference of a FLATLO run, on the sample grid.
pub fn flatlo(outcome: &FlatloOutcome) -> Vec<Track> {
    outcome
        .aircraft
        .iter()
        .map(|a| {
            let times: Vec<f64> = a.reference.iter().map(|s| s.t).collect();
            let positions: Vec<Point3<f64>> = a.reference.iter().map(|s| s.position).collect();
            Track::from_positions(a.index, &times, &positions)
        })
        .collect()
}

/// Every aircraft's simulated flight of a FLATLO run (the samples it kept:
/// `FlatloOutcome::sample_stride`), velocity from V, γ, χ (eqs. 4-6).
pub fn flatlo_flown(outcome: &FlatloOutcome) -> Vec<Track> {
    outcome
        .aircraft
        .iter()
        .map(|a| Track {
            vehicle: a.index,
            samples: a
                .flown
                .iter()
                .map(|s| {
                    let (sg, cg) = s.gamma.sin_cos();
                    let (sc, cc) = s.chi.sin_cos();
                    TrackSample {
                        t: s.t,
                        position: s.position,
                        velocity: nalgebra::Vector3::new(cg * cc, cg * sc, sg) * s.airspeed,
                    }
                })
                .collect(),
        })
        .collect()
}

/// Every quadrotor's flight of a fleet run.
pub fn fleet(outcome: &FleetOutcome) -> Vec<Track> {
    outcome
        .agents
        .iter()
        .map(|a| {
            let times: Vec<f64> = a.samples.iter().map(|s| s.t).collect();
            let positions: Vec<Point3<f64>> = a.samples.iter().map(|s| s.position).collect();
            Track::from_positions(a.index, &times, &positions)
        })
        .collect()
}
