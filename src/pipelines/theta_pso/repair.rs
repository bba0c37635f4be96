//! The repair step: after the swarm, a plan that fails verification is
//! pushed out of its violations locally before the swarm runs again.
//!
//! Not in the paper. A swarm's best often fails by a little in one place (a
//! UAV 0.2 m inside r_Q next to a post, a corner cut too tight); another
//! run of the swarm from new random streams may not find what a nudge of
//! one waypoint would. So: verify; at the first violation, take the free
//! waypoints nearest it and try moving each a little in eight directions
//! (0.5, 1, 2 and 4 m); keep the move that lowers the swarm's objective most
//! (the objective ranks any clear path before any that is not, so a move
//! that removes the violation wins); verify again; up to [`ROUNDS`] times.
//! Deterministic: the same plan in gives the same plan out.

use nalgebra::{Point3, Vector3};

use super::Problem;
use super::cost::INFEASIBLE_STEP;
use super::path::ArcWalker;
use crate::mission::Mission;

/// Rounds of verify-and-move at most.
pub const ROUNDS: usize = 16;
/// Waypoints tried per round, the nearest to the violation first.
const NEAREST: usize = 3;
/// Step lengths tried, metres.
const STEPS: [f64; 4] = [0.5, 1.0, 2.0, 4.0];

/// A particle whose plan verifies, made from `position` by local moves, or
/// `None` when the moves do not get there.
pub fn repair(mission: &Mission, problem: &Problem, position: &[f64]) -> Option<Vec<f64>> {
    let builder = &problem.builder;
    let free = builder.free_waypoints();
    let mut waypoints = builder.decode(position);
    let passes: Vec<f64> = position[(3 * free).min(position.len())..].to_vec();
    // The pass angles travel in the particle as encoded angles; keep them.
    let encode = |w: &[Point3<f64>]| {
        let mut p = builder.encode(w, &[]);
        p.truncate(3 * free);
        p.extend_from_slice(&passes);
        p
    };
    let objective = |w: &[Point3<f64>]| problem.objective_below(&encode(w), f64::INFINITY);
    let names: Vec<String> = mission.obstacles.iter().map(|o| o.name.clone()).collect();
    let mut current = objective(&waypoints);
    for _ in 0..ROUNDS {
        let particle = encode(&waypoints);
        let path = problem.path(&particle);
        // A flight too long to sample cannot be repaired here; the attempt
        // built from the particle says why.
        let (_, verification) = super::flight::fly(mission, &path, &problem.iwps, &names).ok()?;
        if verification.feasible {
            return Some(particle);
        }
        // Where it fails: the first violation, or where the objective says.
        let at = verification
            .violations
            .first()
            .map(|v| v.location.position)
            .or_else(|| {
                verification
                    .checks
                    .iter()
                    .find(|c| !c.ok)
                    .and_then(|c| c.at.as_ref().map(|a| a.position))
            })?;
        // The free waypoints nearest the violation, nearest first.
        let mut order: Vec<usize> = (0..waypoints.len()).collect();
        order.sort_by(|&a, &b| {
            (waypoints[a].xy() - at.xy())
                .norm()
                .total_cmp(&(waypoints[b].xy() - at.xy()).norm())
        });
        let mut best: Option<(f64, Vec<Point3<f64>>)> = None;
        for &k in order.iter().take(NEAREST) {
            for step in STEPS {
                for d in 0..8 {
                    let angle = std::f64::consts::TAU * d as f64 / 8.0;
                    let mut trial = waypoints.clone();
                    trial[k] += Vector3::new(angle.cos(), angle.sin(), 0.0) * step;
                    let value = objective(&trial);
                    if value < current && best.as_ref().is_none_or(|(b, _)| value < *b) {
                        best = Some((value, trial));
                    }
                }
            }
        }
        // A waypoint far from the violation moves little of it: also try one
        // moved onto the path where it fails, pushed away from the obstacle.
        if best.as_ref().is_none_or(|(b, _)| *b >= INFEASIBLE_STEP) {
            let walker = ArcWalker::new(&path.points);
            let nearest = order.first().copied();
            if let Some(k) = nearest {
                for step in STEPS {
                    for d in 0..8 {
                        let angle = std::f64::consts::TAU * d as f64 / 8.0;
                        let mut trial = waypoints.clone();
                        let on_path = closest_on(&walker, at);
                        trial[k] = Point3::new(
                            on_path.x + angle.cos() * step,
                            on_path.y + angle.sin() * step,
                            trial[k].z,
                        );
                        let value = objective(&trial);
                        if value < current && best.as_ref().is_none_or(|(b, _)| value < *b) {
                            best = Some((value, trial));
                        }
                    }
                }
            }
        }
        let (value, moved) = best?;
        current = value;
        waypoints = moved;
    }
    None
}

/// The point of the path nearest `p` (sampled every metre).
fn closest_on(walker: &ArcWalker<'_>, p: Point3<f64>) -> Point3<f64> {
    let length = walker.length();
    let steps = (length.ceil() as usize).max(1);
    (0..=steps)
        .map(|k| walker.at(length * k as f64 / steps as f64))
        .min_by(|a, b| {
            (a.xy() - p.xy())
                .norm()
                .total_cmp(&(b.xy() - p.xy()).norm())
        })
        .unwrap_or(p)
}
