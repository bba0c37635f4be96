//! Per-UAV timed trajectories from the centroid path (θ-PSO eqs. 12-15).
//!
//! The centroid moves along its path at the formation's ground speed. At each
//! sample every UAV is where `motion` puts it (the slot offsets of the
//! current shape turned into the inertial frame, eq. 13, and added to the
//! centroid, eq. 14), the same function the cost judged. Velocities are the
//! time derivative of the sampled positions (eq. 15).

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::iwp::Iwp;
use super::motion::Motion;
use super::path::{CentroidPath, Zone, ZoneCause};
use crate::mission::Formation;

/// One sample of a UAV's trajectory: the shared timed sample.
pub use crate::pipelines::TrackSample as Sample;

/// The timed trajectory T_n of one UAV (eq. 15).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trajectory {
    /// 0-based slot index.
    pub uav: usize,
    pub samples: Vec<Sample>,
}

/// A reconfiguration as flown: which IWP (or squeezed stretch), which
/// shape, and when.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reconfiguration {
    /// The IWP crossed; `None` for a squeezed stretch of the route stage,
    /// where the site is narrower than the formation but no IWP says so.
    pub iwp: Option<usize>,
    /// The obstacles of the IWP, or the nearest on either side of the
    /// squeezed stretch where it is narrowest; one name twice for a stretch
    /// squeezed beside one obstacle, the other side open (names are unique).
    pub between: [String; 2],
    pub shape: super::iwp::Shape,
    /// Centroid position at the IWP.
    pub position: Point3<f64>,
    /// t1 (start of transformation), t2 (shape complete), t3 (start of
    /// return), t4 (back to nominal), seconds from the start.
    pub t1: f64,
    pub t2: f64,
    pub t3: f64,
    pub t4: f64,
}

impl Reconfiguration {
    /// Where it is, as a reader is told: "between 'a' and 'b'", or "beside
    /// 'a'" for a stretch squeezed by one obstacle (not "between 'oak' and
    /// 'oak'").
    pub fn obstacles(&self) -> String {
        let [a, b] = &self.between;
        if a == b {
            format!("beside '{a}'")
        } else {
            format!("between '{a}' and '{b}'")
        }
    }
}

/// Samples per second of the trajectories.
pub const SAMPLE_PERIOD: f64 = 0.1;

/// The per-UAV trajectories and the reconfiguration timetable.
/// `names`: the mission's obstacle names (for squeezed stretches).
pub fn generate(
    path: &CentroidPath,
    iwps: &[Iwp],
    names: &[String],
    formation: &Formation,
    span: f64,
) -> (Vec<Trajectory>, Vec<Reconfiguration>) {
    let motion = Motion::new(path, &formation.slots, span);
    let speed = formation.ground_speed;
    let duration = motion.length() / speed;
    let steps = (duration / SAMPLE_PERIOD).ceil().max(1.0) as usize;
    let times: Vec<f64> = (0..=steps)
        .map(|k| (k as f64 * SAMPLE_PERIOD).min(duration))
        .collect();

    let n = formation.slots.len();
    let mut positions = vec![Vec::with_capacity(times.len()); n];
    let mut here = Vec::with_capacity(n);
    let mut reader = super::motion::Reader::default();
    for &t in &times {
        motion.read_into(t * speed, &mut here, &mut reader);
        for (uav, p) in here.iter().enumerate() {
            positions[uav].push(*p);
        }
    }

    let trajectories = positions
        .into_iter()
        .enumerate()
        .map(|(uav, p)| Trajectory {
            uav,
            samples: with_velocities(&times, &p),
        })
        .collect();

    let name = |k: usize| names.get(k).cloned().unwrap_or_default();
    // One reconfiguration per IWP a zone crosses; a zone that crosses none
    // is one squeezed stretch (the first of its causes names it).
    let reported = |z: &'_ Zone| -> Vec<ZoneCause> {
        let crossings: Vec<ZoneCause> = z
            .causes
            .iter()
            .filter(|c| matches!(c, ZoneCause::Iwp { .. }))
            .copied()
            .collect();
        if crossings.is_empty() {
            z.causes.first().copied().into_iter().collect()
        } else {
            crossings
        }
    };
    let reconfigurations = path
        .zones
        .iter()
        .flat_map(|z| reported(z).into_iter().map(move |cause| (z, cause)))
        .map(|(z, cause)| {
            let [a1, a2, a3, a4] = z.arcs();
            let at = |s: f64| (s / speed).clamp(0.0, duration);
            let (iwp, between) = match cause {
                ZoneCause::Iwp { iwp, pair } => (
                    Some(iwp),
                    iwps.get(iwp)
                        .map(|i| i.between.clone())
                        .unwrap_or_else(|| [name(pair[0]), name(pair[1])]),
                ),
                ZoneCause::Squeeze { pair, .. } => (None, [name(pair[0]), name(pair[1])]),
            };
            let arc = match cause {
                ZoneCause::Iwp { .. } => z.arc,
                ZoneCause::Squeeze { .. } => (a2 + a3) / 2.0,
            };
            Reconfiguration {
                iwp,
                between,
                shape: z.shape,
                position: motion.walker().at(arc),
                t1: at(a1),
                t2: at(a2),
                t3: at(a3),
                t4: at(a4),
            }
        })
        .collect();
    (trajectories, reconfigurations)
}

/// Velocities by central differences (one-sided at the ends).
fn with_velocities(times: &[f64], positions: &[Point3<f64>]) -> Vec<Sample> {
    let n = positions.len();
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            let dt = times[b] - times[a];
            let velocity = if dt > 0.0 {
                (positions[b] - positions[a]) / dt
            } else {
                Vector3::zeros()
            };
            Sample {
                t: times[k],
                position: positions[k],
                velocity,
            }
        })
        .collect()
}
