//! A centroid path as it will be flown, and verified: rounded, timed, and
//! rounded less where the rounding itself breaks a constraint.
//!
//! Every corner is rounded within the room the plan leaves there: half the
//! least slack of any UAV near it (its clearance beyond r_Q and the safety
//! margin, its distance inside the bounds and the band, a pair's beyond
//! 2 r_Q and the margin) in the planned, untimed geometry, at least the room
//! the cost keeps (`theta_pso.clearance_margin`) and at most
//! [`MAX_TOLERANCE`]: a corner in open air is flown on a wide arc, fast, and
//! a corner against a wall on a tight one, slowly. The rounded arc passes
//! inside the corner and a UAV's offset turns with the heading, so the
//! rounding can still take a UAV closer to something than the planned path
//! did. When verification fails near a rounded corner, that corner is
//! rounded again within a quarter of its tolerance, and at the third time
//! not at all: a corner kept as planned is flown by stopping at it, exactly
//! where the cost judged it.
//!
//! The time law plans a little inside the vehicle's limits
//! (`timing::PLANNED_SHARE`); where the samples still show a UAV over a
//! limit (the grid misses a peak), the flight is timed again that much
//! further inside them (not when the samples are a hundred times over: that is a
//! kink no pace smooths).

use super::iwp::Iwp;
use super::path::CentroidPath;
use super::path::rounding::corners;
use super::trajectory::{self, Flight};
use crate::mission::Mission;
use crate::pipelines::PipelineError;
use crate::pipelines::verify::{self, Verification};
use nalgebra::{Point2, Point3};

/// Times a corner's tolerance is cut (to a quarter, then to nothing).
const RETRIES: usize = 2;
/// The widest a corner is rounded, metres.
pub const MAX_TOLERANCE: f64 = 1.0;
/// Times the flight is timed again further inside the vehicle's limits.
const RETIMES: usize = 3;
/// How far over a limit the samples may be for a slower timing to help:
/// the grid misses a peak by a few tens of percent (more where the pace
/// is held at its floor, `timing::MIN_PACE`), a kink by thousands.
const KINK: f64 = 100.0;

/// `path` flown and verified (see the module's doc). `names`: the mission's
/// obstacle names. `OverBudget` when a timing of it needs more samples
/// than the run-size limit (`trajectory::generate`).
pub fn fly(
    mission: &Mission,
    path: &CentroidPath,
    iwps: &[Iwp],
    names: &[String],
) -> Result<(Flight, Verification), PipelineError> {
    let span = super::path::heading_span(mission);
    let planned = corners(&path.points);
    let floor = mission.theta_pso.clearance_margin.max(0.0);
    let widest = MAX_TOLERANCE.max(floor);
    let mut tolerances: Vec<f64> = slack_near(mission, path, &planned, 2.0 * widest)
        .into_iter()
        .map(|slack| (0.5 * slack).clamp(floor, widest))
        .collect();
    let mut share = super::timing::PLANNED_SHARE;
    let generate = |tolerances: &[f64], share: f64| {
        trajectory::generate(path, iwps, names, mission, span, share, |i| tolerances[i])
    };
    let mut flight = generate(&tolerances, share)?;
    let mut verification = verify::verify(mission, &flight.trajectories);
    for retry in 0..=RETRIES {
        if verification.feasible {
            break;
        }
        let blamed = blamed_corners(mission, &flight, &verification);
        if blamed.is_empty() {
            break;
        }
        for i in blamed {
            tolerances[i] = if retry == RETRIES {
                0.0
            } else {
                tolerances[i] / 4.0
            };
        }
        flight = generate(&tolerances, share)?;
        verification = verify::verify(mission, &flight.trajectories);
    }
    for _ in 0..RETIMES {
        let over = verification
            .checks
            .iter()
            .filter(|c| verify::is_dynamics(c.name) && !c.ok)
            .filter_map(|c| c.worst.map(|w| w / c.limit))
            .fold(1.0, f64::max);
        // A peak far over a limit is a kink in a UAV's path, which a slower
        // flight does not smooth: timed that much slower the whole flight
        // would crawl (hours for a few hundred metres) and still break it.
        if over <= 1.0 || over > KINK {
            break;
        }
        share *= 0.98 / over;
        flight = generate(&tolerances, share)?;
        verification = verify::verify(mission, &flight.trajectories);
    }
    Ok((flight, verification))
}

/// For each corner of the planned path, the least slack of any UAV within
/// its reach in the planned geometry (untimed, every 0.25 m of the centroid
/// path): clearance to every obstacle beyond r_Q + the safety margin, the
/// distance inside the x-y bounds and the altitude band, and each pair's
/// distance beyond 2 r_Q + the margin. Metres, at most `enough` (any slack
/// that large gives the corner its widest arc), so only the obstacles within
/// `enough` of where the UAVs fly near the corner are read.
fn slack_near(
    mission: &Mission,
    path: &CentroidPath,
    planned: &[super::path::rounding::Corner],
    enough: f64,
) -> Vec<f64> {
    let f = &mission.formation;
    let span = super::path::heading_span(mission);
    let motion = super::motion::Motion::new(path, &f.slots, span);
    let column = f.slots.len() as f64 * super::iwp::column_spacing(f) / 2.0;
    let reach = f.radius() + span + column + MAX_TOLERANCE;
    let cylinders: Vec<_> = mission.obstacles.iter().map(|o| mission.prism(o)).collect();
    let ground = mission.ground_model();
    let b = &mission.bounds;
    let lc = f.least_clearance();
    let mut here = Vec::new();
    let mut flown: Vec<Point3<f64>> = Vec::new();
    let mut near = Vec::new();
    let mut reader = super::motion::Reader::default();
    planned
        .iter()
        .map(|c| {
            let (from, to) = (
                (c.arc - reach).max(0.0),
                (c.arc + reach).min(motion.length()),
            );
            let steps = ((to - from) / 0.25).ceil().max(1.0) as usize;
            flown.clear();
            for k in 0..=steps {
                motion.read_into(
                    from + (to - from) * k as f64 / steps as f64,
                    &mut here,
                    &mut reader,
                );
                flown.extend_from_slice(&here);
            }
            // The obstacles within `enough` of the box the UAVs fly in.
            let (low, high) = flown.iter().fold(
                (
                    Point2::new(f64::INFINITY, f64::INFINITY),
                    Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
                ),
                |(lo, hi), p| (lo.inf(&p.xy()), hi.sup(&p.xy())),
            );
            near.clear();
            near.extend(cylinders.iter().filter(|c| {
                let outside = (c.center - c.center.sup(&low).inf(&high)).norm();
                outside - c.radius - lc < enough
            }));
            let mut slack = enough;
            let uavs = here.len().max(1);
            for sample in flown.chunks(uavs) {
                for (n, p) in sample.iter().enumerate() {
                    for cylinder in &near {
                        // Only what can be near: the bound on the slack.
                        let far = cylinder.horizontal_distance(p) - cylinder.radius;
                        if far - lc < slack {
                            slack = slack.min(cylinder.clearance(p) - lc);
                        }
                    }
                    let height = p.z - ground.as_ref().map_or(0.0, |g| g.at(p.x, p.y));
                    slack = slack
                        .min(b.horizontal_margin(p))
                        .min(height - b.z[0])
                        .min(b.z[1] - height);
                    for q in &sample[n + 1..] {
                        slack = slack.min((q - p).norm() - f.closest_pair());
                    }
                }
            }
            slack
        })
        .collect()
}

/// The rounded corners near where `verification` fails: within the
/// formation's reach (its radius, the heading's chord and a column's
/// length) of the centroid at a failing sample or inspection.
fn blamed_corners(mission: &Mission, flight: &Flight, verification: &Verification) -> Vec<usize> {
    let f = &mission.formation;
    let column = f.slots.len() as f64 * crate::pipelines::theta_pso::iwp::column_spacing(f);
    let reach = f.radius() + super::path::heading_span(mission) + column + 1.0;
    // Only where the UAVs are: the vehicle's limits are the time law's.
    let mut times: Vec<f64> = verification
        .violations
        .iter()
        .filter(|v| !verify::is_dynamics(v.check))
        .map(|v| v.location.time)
        .chain(
            verification
                .checks
                .iter()
                .filter(|c| !c.ok && !verify::is_dynamics(c.name))
                .filter_map(|c| c.at.as_ref().map(|a| a.time)),
        )
        .collect();
    for inspection in verification.inspections.iter().filter(|i| !i.ok) {
        match inspection.time {
            Some([a, b]) => times.extend([a, b]),
            None => times.extend(
                flight
                    .rounded
                    .path
                    .passes
                    .iter()
                    .map(|p| flight.law.time_at(0.5 * (p.arcs[0] + p.arcs[1]))),
            ),
        }
    }
    let arcs: Vec<f64> = times.iter().map(|&t| flight.law.at(t).s).collect();
    flight
        .rounded
        .planned
        .iter()
        .enumerate()
        .filter(|(_, c)| c.extent > 0.0)
        .filter(|(_, c)| {
            let at = flight.rounded.map.rounded(c.arc);
            arcs.iter().any(|s| (s - at).abs() <= reach + c.extent)
        })
        .map(|(i, _)| i)
        .collect()
}
