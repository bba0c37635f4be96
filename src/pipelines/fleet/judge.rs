//! How a fleet's formation is judged at an instant (eq. 4 with
//! `fleet.tolerance`): the ± metres each distance may be off, and how far
//! the agents still flying stand from their desired distances.

use nalgebra::Point2;

use super::{Deviation, FormationError, Goal};
use crate::mission::FleetParams;

/// The ± metres a distance of the formation at `goal` may be off: a share
/// (`fleet.tolerance`) of it, but no less than that share of c; an agent's
/// own point (desired 0) that share of the closest two points' distance.
pub fn tolerance_of(p: &FleetParams, goal: &Goal) -> impl Fn(f64) -> f64 + use<> {
    let share = p.tolerance;
    let floor = match &goal.assigned {
        Some((points, _)) => {
            let mut closest = f64::INFINITY;
            for i in 0..points.len() {
                for j in i + 1..points.len() {
                    closest = closest.min((points[i] - points[j]).norm());
                }
            }
            if closest.is_finite() {
                closest.max(p.safety_distance)
            } else {
                p.safety_distance
            }
        }
        None => p.safety_distance,
    };
    move |want: f64| share * want.max(floor)
}

/// How far the fleet at `positions` (the agents still flying: `alive`) is
/// from its formation at `goal` at `t`: the pair distance and the distance
/// to the target (its own point, for an agent given one) furthest from
/// their desired values (in tolerances), and the centre's offset.
pub fn formation_error(
    positions: &[Point2<f64>],
    alive: &[bool],
    goal: &Goal,
    target_distance: f64,
    tolerance: &dyn Fn(f64) -> f64,
    t: f64,
) -> FormationError {
    let deviation = |a: usize, b: Option<usize>, distance: f64, want: f64| Deviation {
        a,
        b,
        distance,
        desired: want,
        tolerance: tolerance(want),
    };
    let worse = |best: Option<Deviation>, d: Deviation| match best {
        Some(b) if b.tolerances() >= d.tolerances() => Some(b),
        _ => Some(d),
    };
    let flying: Vec<usize> = (0..positions.len()).filter(|&i| alive[i]).collect();
    let mut pair = None;
    for (k, &i) in flying.iter().enumerate() {
        for &j in &flying[k + 1..] {
            let d = (positions[j] - positions[i]).norm();
            pair = worse(pair, deviation(i, Some(j), d, goal.desired[i][j]));
        }
    }
    let mut to_target = None;
    for &i in &flying {
        let (point, want) = goal.of(i, target_distance);
        let d = (positions[i] - point).norm();
        to_target = worse(to_target, deviation(i, None, d, want));
    }
    let centre = flying
        .iter()
        .fold(nalgebra::Vector2::zeros(), |s, &i| s + positions[i].coords)
        / flying.len().max(1) as f64;
    FormationError {
        time: t,
        pair,
        to_target,
        centre_offset: (Point2::from(centre) - goal.centre).norm(),
    }
}
