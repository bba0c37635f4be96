//! Where some particles start: a route the nominal formation can fly.
//!
//! The paper starts every particle at random (Fig. 3, line 9). On a site with
//! a wall and one gap, or a few passes to inspect, a random swarm of 100 can
//! miss the only way through. So `theta_pso.seeded_particles` particles start
//! on a route found by geometry instead:
//! - the inspection passes in the order they lie along start → goal, each at
//!   the angle round its obstacle and on the side that make the route
//!   shortest (a small dynamic programme over 16 angles × 2 sides);
//! - between them, the shortest 2-D route around the obstacles inflated by
//!   the formation's safe radius, through the usable IWP crossings
//!   (`reference::seeding_route`);
//! - the route's corners as the free waypoints (the most important ones when
//!   there are more corners than waypoints, extra points on the longest legs
//!   when fewer).
//!
//! The first seeded particle sits exactly on that route; the others are
//! jittered about it, with a seeded stream of their own. The rest of the swarm
//! starts at random as in the paper, so the seeds only add a candidate.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::{Point2, Point3};
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::Problem;
use super::reference;
use crate::mission::Mission;

/// Angles tried round each inspected obstacle.
const PASS_ANGLES: usize = 16;

/// The starting particles, or none when the mission asks for none or no
/// route reaches the goal.
pub fn particles(mission: &Mission, problem: &Problem, seed: u64) -> Vec<Vec<f64>> {
    let count = mission
        .theta_pso
        .seeded_particles
        .min(mission.theta_pso.swarm_size);
    if count == 0 {
        return Vec::new();
    }
    let Some((waypoints, pass_angles)) = route(mission, problem) else {
        return Vec::new();
    };
    let exact = problem.builder.encode(&waypoints, &pass_angles);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(u64::MAX);
    (0..count)
        .map(|j| {
            let spread = 0.1 * j as f64 / count as f64;
            match Normal::new(0.0, spread) {
                Ok(noise) if j > 0 => exact
                    .iter()
                    .map(|theta| (theta + noise.sample(&mut rng)).clamp(-FRAC_PI_2, FRAC_PI_2))
                    .collect(),
                _ => exact.clone(),
            }
        })
        .collect()
}

/// The free waypoints and pass angles of the seeding route.
fn route(mission: &Mission, problem: &Problem) -> Option<(Vec<Point3<f64>>, Vec<f64>)> {
    let builder = &problem.builder;
    let (start, goal) = (mission.route.start, mission.route.goal);
    let [x, y, z] = builder.decoding_box();
    let portals = builder.crossings();
    let margin = problem.cost.margin();

    // The passes, ordered along start → goal, each at its best angle and side.
    let axis = (goal - start).xy();
    let mut inspections: Vec<(usize, Point2<f64>)> = builder
        .inspections()
        .into_iter()
        .enumerate()
        .map(|(i, (_, c))| (i, c))
        .collect();
    inspections.sort_by(|a, b| {
        (a.1 - start.xy())
            .dot(&axis)
            .total_cmp(&(b.1 - start.xy()).dot(&axis))
    });
    // A pass the nominal formation cannot fly clear of the other obstacles,
    // or that leaves the decoding box, is no candidate.
    let safe = mission.formation.safe_radius() + margin;
    let clear = |[p, q]: [Point2<f64>; 2]| {
        let inside = |a: &Point2<f64>| x[0] <= a.x && a.x <= x[1] && y[0] <= a.y && a.y <= y[1];
        inside(&p)
            && inside(&q)
            && mission.obstacles.iter().filter(|o| !o.inspect).all(|o| {
                crate::geometry::segment_point_distance(&p, &q, &o.center) >= o.radius + safe
            })
    };
    let chosen = choose_passes(builder, &inspections, start.xy(), goal.xy(), clear);

    // Legs between the passes, each the shortest route around the obstacles.
    let mut corners: Vec<Point2<f64>> = Vec::new();
    let mut from = start.xy();
    let mut stops: Vec<[Point2<f64>; 2]> = chosen.iter().map(|c| c.ends).collect();
    stops.push([goal.xy(), goal.xy()]);
    for [entry, exit] in stops {
        let leg = reference::seeding_route(mission, margin, &portals, [x, y], from, entry)?;
        corners.extend(
            leg.points
                .iter()
                .skip(1)
                .take(leg.points.len().saturating_sub(2)),
        );
        from = exit;
    }

    let free = mission.theta_pso.waypoints;
    let chosen_corners = fit_corners(start.xy(), goal.xy(), corners, free);
    let total = chosen_corners.len() + 1;
    let waypoints = chosen_corners
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let u = (i + 1) as f64 / total as f64;
            let height = (start.z + (goal.z - start.z) * u).clamp(z[0], z[1]);
            Point3::new(p.x, p.y, height)
        })
        .collect();
    let mut pass_angles = vec![0.0; chosen.len()];
    for c in &chosen {
        pass_angles[c.inspection] = c.phi;
    }
    Some((waypoints, pass_angles))
}

/// A pass as placed on the seeding route.
struct Chosen {
    inspection: usize,
    phi: f64,
    ends: [Point2<f64>; 2],
}

/// The angle and side of each pass (in the given order) that make
/// start → passes → goal shortest in straight lines.
fn choose_passes(
    builder: &super::PathBuilder,
    order: &[(usize, Point2<f64>)],
    start: Point2<f64>,
    goal: Point2<f64>,
    clear: impl Fn([Point2<f64>; 2]) -> bool,
) -> Vec<Chosen> {
    // candidates[s][c] = (phi, ends); best[s][c] = (length so far, previous c).
    let candidates: Vec<Vec<(f64, [Point2<f64>; 2])>> = order
        .iter()
        .map(|&(i, _)| {
            let all: Vec<(f64, [Point2<f64>; 2])> = (0..PASS_ANGLES)
                .flat_map(|j| {
                    let phi = TAU * j as f64 / PASS_ANGLES as f64 - PI;
                    [true, false].map(|on_left| (phi, builder.pass_ends(i, phi, on_left)))
                })
                .collect();
            let free: Vec<_> = all
                .iter()
                .copied()
                .filter(|(_, ends)| clear(*ends))
                .collect();
            if free.is_empty() { all } else { free }
        })
        .collect();
    let mut best: Vec<Vec<(f64, usize)>> = Vec::with_capacity(order.len());
    for (s, options) in candidates.iter().enumerate() {
        let row = options
            .iter()
            .map(|(_, [entry, exit])| {
                let through = (exit - entry).norm();
                if s == 0 {
                    ((entry - start).norm() + through, 0)
                } else {
                    candidates[s - 1]
                        .iter()
                        .zip(&best[s - 1])
                        .enumerate()
                        .map(|(c, ((_, [_, before]), (sofar, _)))| {
                            (sofar + (entry - before).norm() + through, c)
                        })
                        .min_by(|a, b| a.0.total_cmp(&b.0))
                        .unwrap_or((f64::INFINITY, 0))
                }
            })
            .collect();
        best.push(row);
    }
    let Some(last) = best.last() else {
        return Vec::new();
    };
    let mut c = last
        .iter()
        .enumerate()
        .map(|(c, (sofar, _))| {
            (
                c,
                sofar + (goal - candidates[order.len() - 1][c].1[1]).norm(),
            )
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0, |(c, _)| c);
    let mut chosen = Vec::with_capacity(order.len());
    for s in (0..order.len()).rev() {
        let (phi, ends) = candidates[s][c];
        chosen.push(Chosen {
            inspection: order[s].0,
            phi,
            ends,
        });
        c = best[s][c].1;
    }
    chosen.reverse();
    chosen
}

/// Exactly `count` points from the route's corners: the corners that turn
/// the route most when there are too many (each removal is the corner whose
/// triangle with its neighbours has the least area), extra points halving the
/// longest legs when there are too few.
fn fit_corners(
    start: Point2<f64>,
    goal: Point2<f64>,
    mut corners: Vec<Point2<f64>>,
    count: usize,
) -> Vec<Point2<f64>> {
    let at = |corners: &[Point2<f64>], i: isize| -> Point2<f64> {
        if i < 0 {
            start
        } else if i as usize >= corners.len() {
            goal
        } else {
            corners[i as usize]
        }
    };
    while corners.len() > count {
        let weakest = (0..corners.len())
            .map(|i| {
                let (a, b, c) = (
                    at(&corners, i as isize - 1),
                    corners[i],
                    at(&corners, i as isize + 1),
                );
                (i, ((b - a).perp(&(c - a))).abs())
            })
            .min_by(|p, q| p.1.total_cmp(&q.1))
            .map_or(0, |(i, _)| i);
        corners.remove(weakest);
    }
    while corners.len() < count {
        let longest = (0..=corners.len())
            .map(|i| {
                (
                    i,
                    (at(&corners, i as isize) - at(&corners, i as isize - 1)).norm(),
                )
            })
            .max_by(|p, q| p.1.total_cmp(&q.1))
            .map_or(0, |(i, _)| i);
        let mid = nalgebra::center(
            &at(&corners, longest as isize - 1),
            &at(&corners, longest as isize),
        );
        corners.insert(longest, mid);
    }
    corners
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitting_keeps_the_sharpest_corners_and_fills_long_legs() {
        let (s, g) = (Point2::new(0.0, 0.0), Point2::new(10.0, 0.0));
        let corners = vec![
            Point2::new(2.0, 0.1),
            Point2::new(5.0, 5.0),
            Point2::new(8.0, 0.1),
        ];
        assert_eq!(
            fit_corners(s, g, corners.clone(), 1),
            vec![Point2::new(5.0, 5.0)]
        );
        let four = fit_corners(s, g, vec![Point2::new(5.0, 5.0)], 3);
        assert_eq!(four.len(), 3);
        assert!(four.contains(&Point2::new(5.0, 5.0)));
        assert_eq!(fit_corners(s, g, corners.clone(), 3), corners);
    }
}
