//! The scenario a fleet mission describes, resolved before the flight:
//! the starts (written, or drawn with the seed), each target of the timed
//! sequence with its desired distances (a point to form around, or one point
//! per agent, assigned by least total distance), and how long it is flown.

use nalgebra::Point2;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

use crate::mission::{Diagnostic, FieldPath, Mission};

/// The scenario a fleet mission describes, resolved: starts, targets (each
/// with its d^d, a target of one point per agent with its assignment), and
/// how long it is flown.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    pub starts: Vec<Point2<f64>>,
    pub targets: Vec<Goal>,
    /// Seconds simulated: `fleet.duration`, or as long as the fleet needs.
    pub duration: f64,
    /// The farthest any agent goes from one place to the next, metres.
    pub farthest: f64,
}

/// One target of the timed sequence, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Goal {
    pub time: f64,
    /// The target, or the middle of its points.
    pub centre: Point2<f64>,
    /// A target of one point per agent: agent i's point, and which of the
    /// file's points that is. `None`: the fleet forms around `centre`.
    pub assigned: Option<(Vec<Point2<f64>>, Vec<usize>)>,
    /// d_ij^d.
    pub desired: Vec<Vec<f64>>,
}

impl Goal {
    /// Agent `i`'s target point and its desired distance from it (d_ip^d
    /// round the target; 0 to its own point).
    pub fn of(&self, i: usize, target_distance: f64) -> (Point2<f64>, f64) {
        match &self.assigned {
            Some((points, _)) => (points.get(i).copied().unwrap_or(self.centre), 0.0),
            None => (self.centre, target_distance),
        }
    }
}

/// Which of `to` each of `from` takes (`assignment[i]`: the index in `to`
/// of agent i's point), the least total distance (Kuhn-Munkres, on
/// millimetres so ties break the same way on every machine).
pub fn assign(from: &[Point2<f64>], to: &[Point2<f64>]) -> Vec<usize> {
    let n = from.len().min(to.len());
    if n == 0 {
        return Vec::new();
    }
    let weights = pathfinding::matrix::Matrix::from_fn(n, n, |(i, j)| {
        ((from[i] - to[j]).norm() * 1000.0).round() as i64
    });
    let (_, assignment) = pathfinding::kuhn_munkres::kuhn_munkres_min(&weights);
    assignment
}

/// Default d_ij^d: a regular polygon of radius d_ip^d around the target, the
/// agents in index order (three agents 1 m out: 1.732 m apart).
pub fn polygon_distances(n: usize, radius: f64) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let k = i.abs_diff(j) as f64;
                    2.0 * radius * (std::f64::consts::PI * k / n as f64).sin()
                })
                .collect()
        })
        .collect()
}

/// Resolves the mission's fleet section. Random starts are drawn (seeded)
/// inside the bounds, at least c from each other and from obstacles.
pub fn scenario(m: &Mission, seed: u64) -> Scenario {
    let p = &m.fleet;
    let n = p.agents;
    let starts = if p.initial_positions.len() == n {
        p.initial_positions.clone()
    } else {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(u64::MAX);
        let b = &m.bounds;
        let mut starts: Vec<Point2<f64>> = Vec::with_capacity(n);
        let mut attempts = 0;
        while starts.len() < n {
            let q = Point2::new(
                rng.random_range(b.x[0]..=b.x[1]),
                rng.random_range(b.y[0]..=b.y[1]),
            );
            attempts += 1;
            let clear = starts
                .iter()
                .all(|s| (s - q).norm() >= 2.0 * p.safety_distance)
                && m.obstacles
                    .iter()
                    .all(|o| o.prism().outward(&q) >= 2.0 * p.safety_distance);
            // A crowded box still gets its agents (the check is a courtesy).
            if clear || attempts > 1000 * n {
                starts.push(q);
            }
        }
        starts
    };
    let around = if p.distances.len() == n {
        p.distances.clone()
    } else {
        polygon_distances(n, p.target_distance)
    };
    let written: Vec<crate::mission::FleetTarget> = if p.targets.is_empty() {
        vec![crate::mission::FleetTarget::around(0.0, default_target(m))]
    } else {
        p.targets.clone()
    };
    let mut targets: Vec<Goal> = Vec::with_capacity(written.len());
    let mut from = starts.clone();
    for t in &written {
        let goal = if t.positions.len() == n && n > 0 {
            let assignment = assign(&from, &t.positions);
            let points: Vec<Point2<f64>> = assignment.iter().map(|&j| t.positions[j]).collect();
            let desired = (0..n)
                .map(|i| (0..n).map(|j| (points[i] - points[j]).norm()).collect())
                .collect();
            Goal {
                time: t.time,
                centre: t.centre(),
                assigned: Some((points, assignment)),
                desired,
            }
        } else {
            Goal {
                time: t.time,
                centre: t.centre(),
                assigned: None,
                desired: around.clone(),
            }
        };
        from = (0..n).map(|i| goal.of(i, 0.0).0).collect();
        targets.push(goal);
    }
    // The farthest any agent has to go, leg by leg, for the run's length.
    let mut farthest: f64 = 0.0;
    let mut at = starts.clone();
    for goal in &targets {
        for (i, q) in at.iter_mut().enumerate() {
            let (point, _) = goal.of(i, p.target_distance);
            farthest = farthest.max((point - *q).norm());
            *q = point;
        }
    }
    let last = targets.last().map_or(0.0, |g| g.time);
    Scenario {
        starts,
        targets,
        duration: p.run_duration(last, farthest),
        farthest,
    }
}

/// Where the fleet forms when the mission names no target: the free spot
/// nearest the bounds' centre, where the formation (agents d_ip round it,
/// each keeping c) stays inside the bounds and keeps c from every obstacle
/// taller than the flight altitude. A grid of at most 200 × 200 candidates;
/// the centre itself when nothing is free.
pub fn default_target(m: &Mission) -> Point2<f64> {
    let p = &m.fleet;
    let b = &m.bounds;
    let centre = b.center_xy();
    let reach = p.target_distance + p.safety_distance;
    let free = |q: &Point2<f64>| {
        q.x - reach >= b.x[0]
            && q.x + reach <= b.x[1]
            && q.y - reach >= b.y[0]
            && q.y + reach <= b.y[1]
            && m.obstacles
                .iter()
                .filter(|o| o.spans(p.altitude))
                .all(|o| o.prism().outward(q) >= reach + p.safety_distance)
    };
    if free(&centre) {
        return centre;
    }
    let span = (b.x[1] - b.x[0]).max(b.y[1] - b.y[0]);
    let step = (reach / 2.0).max(span / 200.0).max(1e-3);
    let (nx, ny) = (
        ((b.x[1] - b.x[0]) / step).ceil().min(200.0) as usize,
        ((b.y[1] - b.y[0]) / step).ceil().min(200.0) as usize,
    );
    let mut best: Option<(f64, Point2<f64>)> = None;
    for i in 0..=nx {
        for j in 0..=ny {
            let q = Point2::new(
                b.x[0] + (b.x[1] - b.x[0]) * i as f64 / nx.max(1) as f64,
                b.y[0] + (b.y[1] - b.y[0]) * j as f64 / ny.max(1) as f64,
            );
            let d = (q - centre).norm();
            if best.is_none_or(|(bd, _)| d < bd) && free(&q) {
                best = Some((d, q));
            }
        }
    }
    best.map_or(centre, |(_, q)| q)
}

/// A written `fleet.duration` too short for the fleet to reach its last
/// target at its cruise speed ([`FleetParams::cruise_speed`]): a warning
/// saying how long it needs, and that leaving it out flies as long.
///
/// [`FleetParams::cruise_speed`]: crate::mission::FleetParams::cruise_speed
pub fn duration_finding(mission: &Mission) -> Option<Diagnostic> {
    use crate::mission::compact;
    let p = &mission.fleet;
    let Some(written) = p.duration else {
        // Left out: say when even the longest automatic run is too short,
        // for a mission that sets its fleet up at all.
        if *p == crate::mission::FleetParams::default() {
            return None;
        }
        let sc = scenario(mission, mission.seed);
        let last = sc.targets.last().map_or(0.0, |g| g.time);
        let needed = last + sc.farthest / p.cruise_speed().max(1e-6);
        return (needed > crate::mission::AUTO_DURATION_MAX).then(|| {
            Diagnostic::warning(
                FieldPath::root().key("fleet").key("duration"),
                format!(
                    "left out, a run lasts at most {} s, and at about {:.2} m/s the farthest \
                     agent needs {:.0} s to reach its place ({:.0} m): write a duration",
                    crate::mission::AUTO_DURATION_MAX,
                    p.cruise_speed(),
                    needed,
                    sc.farthest
                ),
            )
        });
    };
    let finite = [
        p.step_max,
        p.position_gains[0],
        p.position_gains[1],
        written,
    ]
    .iter()
    .all(|v| v.is_finite() && *v > 0.0);
    if !finite || p.agents == 0 || p.agents > crate::pipelines::limits::FLEET_AGENTS {
        return None;
    }
    let sc = scenario(mission, mission.seed);
    let last = sc.targets.last().map_or(0.0, |g| g.time);
    let travel = sc.farthest / p.cruise_speed().max(1e-6);
    // The least it takes: the last target's time and the longest leg at
    // the cruise speed; leaving `duration` out gives twice the travel and
    // 20 s to settle.
    let needed = last + travel;
    (written < needed).then(|| {
        Diagnostic::warning(
            FieldPath::root().key("fleet").key("duration"),
            format!(
                "{} s is too short: the agents cruise at about {:.2} m/s (K_pos {} / {} × h_max \
                 {} m); the farthest goes {:.1} m, {:.0} s, after the last target at {} s: at \
                 least {:.0} s (leave `duration` out to fly as long as the fleet needs, {} s)",
                compact(written),
                p.cruise_speed(),
                compact(p.position_gains[0]),
                compact(p.position_gains[1]),
                compact(p.step_max),
                sc.farthest,
                travel,
                compact(last),
                needed.ceil(),
                compact(
                    crate::mission::FleetParams {
                        duration: None,
                        ..p.clone()
                    }
                    .run_duration(last, sc.farthest)
                )
            ),
        )
    })
}
