//! Where some particles start: on the route stage's corridor.
//!
//! The paper starts every particle at random (Fig. 3, line 9). On a site with
//! walls and gaps, or passes to inspect, a random swarm of 100 can miss the
//! only way through. So `theta_pso.seeded_particles` particles start on the
//! corridor the route stage found (`route`): its corners, crossing ends and
//! pass ends become the free waypoints (the builder puts the crossings and
//! passes back in where the legs meet them), at heights along start → goal;
//! its pass angles become the particle's pass angles.
//!
//! The first seeded particle sits exactly on the corridor; the others are
//! jittered about it, with a seeded stream of their own. The rest of the swarm
//! starts at random as in the paper, so the seeds only add a candidate.

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Point2, Point3};
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::Problem;
use super::route::{Corridor, Leg};
use crate::mission::Mission;

/// Most free waypoints a particle gets to follow a corridor with many corners.
pub const MAX_FREE_WAYPOINTS: usize = 60;

/// The free waypoints a particle needs to follow `corridor`: the mission's,
/// or the corridor's inner points when it has more (at most
/// [`MAX_FREE_WAYPOINTS`]).
pub fn free_waypoints(mission: &Mission, corridor: &Corridor) -> usize {
    let inner = corridor.points.len().saturating_sub(2);
    mission
        .theta_pso
        .waypoints
        .max(inner.min(MAX_FREE_WAYPOINTS))
}

/// The starting particles, or none when the mission asks for none.
pub fn particles(
    mission: &Mission,
    problem: &Problem,
    corridor: &Corridor,
    seed: u64,
) -> Vec<Vec<f64>> {
    let count = mission
        .theta_pso
        .seeded_particles
        .min(mission.theta_pso.swarm_size);
    if count == 0 {
        return Vec::new();
    }
    let (waypoints, pass_angles) = waypoints(problem, corridor);
    let exact = problem.builder.encode(&waypoints, &pass_angles);
    about(&exact, count, 0.1, seed, u64::MAX)
}

/// `exact`, then `count − 1` copies jittered by normal noise of a spread
/// growing to `widest` radians (each angle kept in [-π/2, π/2]), drawn from
/// stream `stream` of `seed`.
fn about(exact: &[f64], count: usize, widest: f64, seed: u64, stream: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    (0..count)
        .map(|j| {
            let spread = widest * j as f64 / count as f64;
            match Normal::new(0.0, spread) {
                Ok(noise) if j > 0 => exact
                    .iter()
                    .map(|theta| (theta + noise.sample(&mut rng)).clamp(-FRAC_PI_2, FRAC_PI_2))
                    .collect(),
                _ => exact.to_vec(),
            }
        })
        .collect()
}

/// Particles a warm-started swarm begins with: the earlier plan exactly
/// (its waypoints refitted to this run's count), and a few about it.
pub const WARM_PARTICLES: usize = 10;

/// The warm start's particles: the plan of `warm` encoded for `problem`
/// (its waypoints, as many as the builder decodes: the corners that turn it
/// most kept, the longest legs halved), then copies jittered by up to 0.02
/// rad (a few metres on a site the bridge's size), on a stream of their own.
pub fn warm(problem: &Problem, warm: &super::WarmStart, seed: u64) -> Vec<Vec<f64>> {
    let builder = &problem.builder;
    let count = builder.free_waypoints();
    let points = fit_waypoints(builder.start(), builder.goal(), &warm.waypoints, count);
    let exact = builder.encode(&points, &warm.pass_angles);
    about(&exact, WARM_PARTICLES, 0.02, seed, u64::MAX - 1)
}

/// Exactly `count` waypoints from `waypoints` (between `start` and `goal`):
/// in the plane as [`fit_corners`] chooses them, each kept point with its
/// height, an added one at its neighbours' mean.
fn fit_waypoints(
    start: Point3<f64>,
    goal: Point3<f64>,
    waypoints: &[Point3<f64>],
    count: usize,
) -> Vec<Point3<f64>> {
    if waypoints.len() == count {
        return waypoints.to_vec();
    }
    let flat: Vec<Point2<f64>> = waypoints.iter().map(|p| p.xy()).collect();
    let free = vec![true; flat.len() + 1];
    let chosen = fit_corners(start.xy(), goal.xy(), flat.clone(), free, count);
    let all: Vec<Point3<f64>> = std::iter::once(start)
        .chain(waypoints.iter().copied())
        .chain(std::iter::once(goal))
        .collect();
    chosen
        .iter()
        .map(|p| {
            if let Some(k) = flat.iter().position(|q| q == p) {
                return waypoints[k];
            }
            // A midpoint of two neighbours: the height of the nearest leg's ends.
            let nearest = all
                .windows(2)
                .min_by(|a, b| {
                    let d =
                        |w: &[Point3<f64>]| (nalgebra::center(&w[0].xy(), &w[1].xy()) - p).norm();
                    d(a).total_cmp(&d(b))
                })
                .map_or(start.z, |w| (w[0].z + w[1].z) / 2.0);
            Point3::new(p.x, p.y, nearest)
        })
        .collect()
}

/// The corridor's inner points as free waypoints (fitted to the builder's
/// count), at the corridor's heights when it climbs, else at heights along
/// start → goal, and its pass angles.
fn waypoints(problem: &Problem, corridor: &Corridor) -> (Vec<Point3<f64>>, Vec<f64>) {
    let builder = &problem.builder;
    let [_, _, z] = builder.decoding_box();
    let (start, goal) = (builder.start(), builder.goal());
    let inner: Vec<Point2<f64>> = corridor
        .points
        .iter()
        .skip(1)
        .take(corridor.points.len().saturating_sub(2))
        .copied()
        .collect();
    // Only free legs take extra points: the builder flies crossings and
    // passes straight, a point inside one would send the path back over it.
    let free: Vec<bool> = corridor
        .legs
        .iter()
        .map(|leg| matches!(leg, Leg::Free { .. }))
        .collect();
    let chosen = fit_corners(start.xy(), goal.xy(), inner, free, builder.free_waypoints());
    // Between the start's and the goal's altitudes in proportion to the
    // distance flown, so the crossings and passes the builder puts on a
    // leg (at the leg's altitude where they lie) stay on one slope.
    let mut flown = Vec::with_capacity(chosen.len());
    let mut last = start.xy();
    let mut total = 0.0;
    for p in &chosen {
        total += (p - last).norm();
        flown.push(total);
        last = *p;
    }
    total += (goal.xy() - last).norm();
    let waypoints = chosen
        .iter()
        .zip(&flown)
        .map(|(p, d)| {
            let u = if total > 0.0 { d / total } else { 0.0 };
            let along = start.z + (goal.z - start.z) * u;
            let height = corridor_height(corridor, *p)
                .unwrap_or(along)
                .clamp(z[0], z[1]);
            Point3::new(p.x, p.y, height)
        })
        .collect();
    let pass_angles = corridor.passes.iter().map(|(phi, _)| *phi).collect();
    (waypoints, pass_angles)
}

/// The corridor's height at `p`, one of its points or on one of its legs
/// (the nearest leg, its height in proportion); `None` for a corridor left
/// between the start's and the goal's altitudes.
fn corridor_height(corridor: &Corridor, p: Point2<f64>) -> Option<f64> {
    let h = &corridor.heights;
    if h.len() != corridor.points.len() {
        return None;
    }
    corridor
        .points
        .windows(2)
        .zip(h.windows(2))
        .map(|(w, z)| {
            let (t, d) = crate::base::geometry::segment_projection(&w[0], &w[1], &p);
            (d, z[0] + (z[1] - z[0]) * t)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, z)| z)
}

/// Exactly `count` points from the route's corners: the corners that turn
/// the route most when there are too many (each removal is the corner whose
/// triangle with its neighbours has the least area), extra points halving the
/// longest free legs when there are too few (`free[i]`: leg `i`, from corner
/// `i - 1` or the start to corner `i` or the goal, may be split).
fn fit_corners(
    start: Point2<f64>,
    goal: Point2<f64>,
    mut corners: Vec<Point2<f64>>,
    mut free: Vec<bool>,
    count: usize,
) -> Vec<Point2<f64>> {
    free.resize(corners.len() + 1, true);
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
        // The two legs round it become one, free when either was.
        let merged = free[weakest] || free[weakest + 1];
        free.remove(weakest + 1);
        free[weakest] = merged;
    }
    while corners.len() < count {
        let length = |i: usize| (at(&corners, i as isize) - at(&corners, i as isize - 1)).norm();
        let longest = (0..=corners.len())
            .filter(|&i| free[i])
            .max_by(|p, q| length(*p).total_cmp(&length(*q)))
            .or_else(|| (0..=corners.len()).max_by(|p, q| length(*p).total_cmp(&length(*q))))
            .unwrap_or(0);
        let mid = nalgebra::center(
            &at(&corners, longest as isize - 1),
            &at(&corners, longest as isize),
        );
        corners.insert(longest, mid);
        let was = free[longest];
        free.insert(longest, was);
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
        let all = vec![true; 4];
        assert_eq!(
            fit_corners(s, g, corners.clone(), all.clone(), 1),
            vec![Point2::new(5.0, 5.0)]
        );
        let four = fit_corners(s, g, vec![Point2::new(5.0, 5.0)], all.clone(), 3);
        assert_eq!(four.len(), 3);
        assert!(four.contains(&Point2::new(5.0, 5.0)));
        assert_eq!(fit_corners(s, g, corners.clone(), all, 3), corners);
    }

    /// A warm start's waypoints refitted to another count keep the points
    /// they can (with their heights) and add midpoints at their legs'
    /// heights.
    #[test]
    fn warm_waypoints_are_refitted_keeping_their_heights() {
        let (s, g) = (Point3::new(0.0, 0.0, 10.0), Point3::new(10.0, 0.0, 10.0));
        let w = vec![
            Point3::new(2.0, 0.1, 11.0),
            Point3::new(5.0, 5.0, 12.0),
            Point3::new(8.0, 0.1, 13.0),
        ];
        assert_eq!(fit_waypoints(s, g, &w, 3), w);
        let one = fit_waypoints(s, g, &w, 1);
        assert_eq!(one, vec![Point3::new(5.0, 5.0, 12.0)]);
        let five = fit_waypoints(s, g, &w, 5);
        assert_eq!(five.len(), 5);
        for p in &w {
            assert!(five.contains(p), "{p} kept");
        }
        assert!(
            five.iter().all(|p| (10.0..=13.0).contains(&p.z)),
            "{five:?}"
        );
    }

    #[test]
    fn a_crossing_leg_is_never_split() {
        // start → A, A → B a long crossing, B → goal: the extra points go on
        // the short free legs, never between A and B.
        let (s, g) = (Point2::new(0.0, 0.0), Point2::new(30.0, 0.0));
        let (a, b) = (Point2::new(5.0, 0.0), Point2::new(25.0, 0.0));
        let fitted = fit_corners(s, g, vec![a, b], vec![true, false, true], 4);
        assert_eq!(fitted.len(), 4);
        let between = fitted.iter().filter(|p| p.x > 5.0 && p.x < 25.0).count();
        assert_eq!(between, 0, "{fitted:?}");
    }
}
