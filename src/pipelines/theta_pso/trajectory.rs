//! Per-UAV timed trajectories from the centroid path (θ-PSO eqs. 12-15),
//! flyable within the vehicle's limits.
//!
//! The path is flown with its corners rounded (`path::rounding`, each within
//! the tolerance given) and at the fastest pace every UAV's `[vehicle]`
//! limits allow (`timing`): from rest at the start to rest at the goal,
//! slower through turns and changes of shape where an outer UAV would
//! otherwise be too fast or turn too hard. At each sample every UAV is where
//! `motion` puts it (the slot offsets of the current shape turned into the
//! inertial frame, eq. 13, and added to the centroid, eq. 14), the same
//! function the cost judged; its velocity (eq. 15) is the derivative of that
//! position along the path times the centroid's rate.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::iwp::Iwp;
use super::motion::Motion;
use super::path::rounding::{self, Rounded};
use super::path::{CentroidPath, Zone, ZoneCause};
use super::timing::{self, TimeLaw};
use crate::mission::Mission;
use crate::pipelines::PipelineError;

/// One sample of a UAV's trajectory: the shared timed sample.
pub use crate::pipelines::TrackSample as Sample;

/// The timed trajectory T_n of one UAV (eq. 15): the shared timed track
/// that verification judges.
pub use crate::pipelines::verify::Trajectory;

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

/// A centroid path as flown: the trajectories, the timetable of its
/// reconfigurations, and how it was rounded and timed.
#[derive(Debug, Clone)]
pub struct Flight {
    pub trajectories: Vec<Trajectory>,
    pub reconfigurations: Vec<Reconfiguration>,
    /// The path as flown: simplified and its corners rounded.
    pub rounded: Rounded,
    /// The centroid's time law along the flown path.
    pub law: TimeLaw,
    /// Where the centroid is along the flown path at each sample, metres.
    pub progress: Vec<f64>,
}

impl Flight {
    /// Seconds from start to goal.
    pub fn duration(&self) -> f64 {
        self.law.duration()
    }

    /// When the centroid passes the planned path's arc length `s`, seconds.
    pub fn time_at_planned(&self, s: f64) -> f64 {
        self.law.time_at(self.rounded.map.rounded(s))
    }
}

/// The per-UAV trajectories and the reconfiguration timetable of `path`,
/// its corners rounded within `tolerance(i)` for the i-th corner
/// (`rounding::corners`), timed within `share` of `mission`'s `[vehicle]`
/// limits (`timing::PLANNED_SHARE` unless the samples showed that too
/// close) at the formation's ground speed at most. `names`: the mission's obstacle
/// names (for squeezed stretches). `OverBudget`, before a sample is taken,
/// when the timed flight needs more trajectory samples than
/// `limits::TRAJECTORY_SAMPLES` (a vehicle allowed 1e-9 m/s² flies for
/// years).
pub fn generate(
    path: &CentroidPath,
    iwps: &[Iwp],
    names: &[String],
    mission: &Mission,
    span: f64,
    share: f64,
    tolerance: impl Fn(usize) -> f64,
) -> Result<Flight, PipelineError> {
    let formation = &mission.formation;
    let rounded = rounding::round(path, tolerance);
    let motion = Motion::new(&rounded.path, &formation.slots, span);
    let n = formation.slots.len();
    let length = motion.length();
    let limits: Vec<_> = (0..n)
        .map(|uav| mission.vehicle.limits(uav).scaled(share))
        .collect();
    // A finer grid round every rounded corner, where each UAV turns when
    // the centroid does (a column's UAVs a column's half length before and
    // after it): eight steps along its arc, but never shorter than two and
    // a half of its chords, so the time law reads the arc's curvature and
    // not its chords' corners.
    let column = n as f64 * super::iwp::column_spacing(formation) / 2.0;
    let reach = formation.radius() + span + column + 0.5;
    let windows: Vec<(f64, f64, f64)> = rounded
        .flown
        .iter()
        .filter(|c| c.tangent > 0.0)
        .map(|c| {
            let step = (c.radius * c.turn / 8.0).max(2.5 * c.chord);
            (c.at - c.tangent - reach, c.at + c.tangent + reach, step)
        })
        .collect();
    let stops = stops(&rounded, &motion);
    let (arcs, stops) = timing::grid(length, &windows, &stops);
    let mut reader = super::motion::Reader::default();
    let mut here = Vec::with_capacity(n);
    let grid: Vec<Vec<Point3<f64>>> = arcs
        .iter()
        .map(|&s| {
            motion.read_into(s, &mut here, &mut reader);
            here.clone()
        })
        .collect();
    let law = TimeLaw::plan(&arcs, &grid, &limits, formation.ground_speed, &stops);
    let duration = law.duration();
    let needed = (duration / SAMPLE_PERIOD + 1.0) * n as f64;
    if crate::pipelines::exceeds(needed, crate::pipelines::limits::TRAJECTORY_SAMPLES) {
        return Err(PipelineError::OverBudget(format!(
            "vehicle: the planned flight ({length:.1} m in {} s within the [vehicle] limits) \
             needs {} trajectory samples (limit {})",
            crate::pipelines::figure(duration),
            crate::pipelines::figure(needed),
            crate::pipelines::figure(crate::pipelines::limits::TRAJECTORY_SAMPLES)
        )));
    }
    let steps = (duration / SAMPLE_PERIOD).ceil().max(1.0) as usize;
    let mut samples = vec![Vec::with_capacity(steps + 1); n];
    let (mut behind, mut ahead) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut behind_reader, mut ahead_reader) = (reader.clone(), reader);
    let mut centre_reader = super::motion::Reader::default();
    let mut arcs = Vec::with_capacity(steps + 1);
    for k in 0..=steps {
        let t = (k as f64 * SAMPLE_PERIOD).min(duration);
        let progress = law.at(t);
        arcs.push(progress.s);
        // The derivative along the path over a millimetre either side.
        let (a, b) = (
            (progress.s - DERIVATIVE_STEP).max(0.0),
            (progress.s + DERIVATIVE_STEP).min(length),
        );
        motion.read_into(progress.s, &mut here, &mut centre_reader);
        motion.read_into(a, &mut behind, &mut behind_reader);
        motion.read_into(b, &mut ahead, &mut ahead_reader);
        for uav in 0..n {
            let velocity = if b > a {
                (ahead[uav] - behind[uav]) / (b - a) * progress.speed
            } else {
                Vector3::zeros()
            };
            samples[uav].push(Sample {
                t,
                position: here[uav],
                velocity,
            });
        }
    }
    let trajectories = samples
        .into_iter()
        .enumerate()
        .map(|(uav, samples)| Trajectory { uav, samples })
        .collect();
    let reconfigurations = timetable(&rounded.path, &motion, iwps, names, &law);
    Ok(Flight {
        trajectories,
        reconfigurations,
        rounded,
        law,
        progress: arcs,
    })
}

/// Where the formation must stop along the flown path: at each corner kept
/// as planned (a kink: no room to round it, or a hairpin), and, for a
/// column, wherever one of its UAVs reaches such a corner (its place in
/// the column ahead of or behind the centroid).
fn stops(rounded: &Rounded, motion: &Motion) -> Vec<f64> {
    let kinks: Vec<f64> = rounded
        .flown
        .iter()
        .filter(|c| c.tangent == 0.0)
        .map(|c| c.at)
        .collect();
    let mut out = kinks.clone();
    for zone in &rounded.path.zones {
        let [a1, _, _, a4] = zone.arcs();
        let spacings = [
            zone.shape,
            zone.from.unwrap_or(zone.shape),
            zone.into.unwrap_or(zone.shape),
        ]
        .into_iter()
        .filter_map(|shape| match shape {
            super::iwp::Shape::Alignment { spacing } => Some(spacing),
            _ => None,
        });
        for spacing in spacings {
            for n in 0..motion.uavs() {
                let place = motion.column_place(n, spacing);
                out.extend(
                    kinks
                        .iter()
                        .map(|k| k - place)
                        .filter(|s| (a1..=a4).contains(s)),
                );
            }
        }
    }
    out.sort_by(f64::total_cmp);
    out.dedup_by(|b, a| (*b - *a).abs() < 1e-9);
    out
}

/// Metres along the path either side of a sample for its velocity.
const DERIVATIVE_STEP: f64 = 1e-3;

/// One reconfiguration per IWP a zone of the flown path crosses, timed.
fn timetable(
    path: &CentroidPath,
    motion: &Motion,
    iwps: &[Iwp],
    names: &[String],
    law: &TimeLaw,
) -> Vec<Reconfiguration> {
    let duration = law.duration();
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
    path.zones
        .iter()
        .flat_map(|z| reported(z).into_iter().map(move |cause| (z, cause)))
        .map(|(z, cause)| {
            let [a1, a2, a3, a4] = z.arcs();
            let at = |s: f64| law.time_at(s).clamp(0.0, duration);
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
        .collect()
}
