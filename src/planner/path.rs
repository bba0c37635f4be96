//! From a particle to a centroid path: the eq. 1 decoding, the IWP via-points,
//! and the reconfiguration zones along the path.
//!
//! Reading: the paper plans "the optimized path P_F* … in which the
//! intermediate waypoints for reconfiguration have been included" (III.C).
//! So every enabled IWP is a via-point of the centroid path, crossed straight
//! along the gap's normal: the path goes through C_j − a n, C_j, C_j + a n,
//! where a is the hold length below. Each IWP is inserted where it lengthens
//! the path least, so the swarm still decides the route between IWPs.

use nalgebra::{Point3, Vector3};

use super::iwp::{Iwp, Shape, vertical_half_height};
use crate::geometry::farthest_offset;
use crate::mission::Mission;

/// Eq. 1, third line: x = ½ [(x_max − x_min) sin θ + x_max + x_min].
pub fn decode_angle(theta: f64, min: f64, max: f64) -> f64 {
    0.5 * ((max - min) * theta.sin() + max + min)
}

/// Where along the path the formation changes shape for one IWP.
///
/// Arc lengths s along the centroid path, metres:
/// [s_j − h − T, s_j − h] transform (t1..t2), [s_j − h, s_j + h] hold (t2..t3),
/// [s_j + h, s_j + h + T] return (t3..t4), with T the transition distance and
/// h the hold length: the mission's hold distance plus the larger obstacle
/// radius plus the larger of the nominal and reconfigured formation radii, so
/// the new shape is complete `hold_distance` before its leading UAV reaches
/// the obstacles' depth (the paper's "1 m before").
#[derive(Debug, Clone, PartialEq)]
pub struct Zone {
    /// Index into the IWP list.
    pub iwp: usize,
    /// Obstacles of the gap.
    pub pair: [usize; 2],
    pub shape: Shape,
    /// s_j, arc length of the IWP.
    pub arc: f64,
    /// h, half length of the hold.
    pub hold: f64,
    /// T, length of each transition.
    pub transition: f64,
}

impl Zone {
    /// 0 outside the zone, 1 in the hold, a smoothstep in between (so each
    /// UAV's velocity stays continuous through the transition).
    pub fn blend(&self, s: f64) -> f64 {
        let from_hold = (s - self.arc).abs() - self.hold;
        if from_hold <= 0.0 {
            1.0
        } else if from_hold >= self.transition {
            0.0
        } else {
            let u = 1.0 - from_hold / self.transition;
            u * u * (3.0 - 2.0 * u)
        }
    }

    /// Arc lengths of t1, t2, t3, t4.
    pub fn arcs(&self) -> [f64; 4] {
        [
            self.arc - self.hold - self.transition,
            self.arc - self.hold,
            self.arc + self.hold,
            self.arc + self.hold + self.transition,
        ]
    }

    pub fn contains(&self, s: f64) -> bool {
        (s - self.arc).abs() < self.hold + self.transition
    }
}

/// A centroid path and its reconfiguration zones.
#[derive(Debug, Clone, PartialEq)]
pub struct CentroidPath {
    pub points: Vec<Point3<f64>>,
    pub zones: Vec<Zone>,
}

/// What is fixed for a mission while the swarm searches.
#[derive(Debug, Clone)]
pub struct PathBuilder {
    start: Point3<f64>,
    goal: Point3<f64>,
    bounds: [[f64; 2]; 3],
    vias: Vec<Via>,
}

#[derive(Debug, Clone)]
struct Via {
    iwp: usize,
    pair: [usize; 2],
    shape: Shape,
    center: nalgebra::Point2<f64>,
    /// Normal scaled by the half length of the straight crossing.
    reach: nalgebra::Vector2<f64>,
    hold: f64,
    transition: f64,
    /// Altitudes the centroid may take at the IWP so every UAV of the shape
    /// stays in the band.
    z_range: [f64; 2],
}

impl PathBuilder {
    pub fn new(mission: &Mission, iwps: &[Iwp]) -> Self {
        let b = &mission.bounds;
        let nominal = &mission.formation.slots;
        let r_f = mission.formation.radius();
        let vias = iwps
            .iter()
            .enumerate()
            .filter(|(_, iwp)| iwp.enabled)
            .map(|(i, iwp)| {
                let [p, q] = iwp.obstacles;
                let deepest = mission.obstacles[p].radius.max(mission.obstacles[q].radius);
                let shaped = iwp.shape.offsets(nominal, 1.0);
                let reach = r_f.max(farthest_offset(&shaped));
                let hold = mission.reconfiguration.hold_distance + deepest + reach;
                // Straight far enough that the whole shape, and the chord the
                // heading is taken from, lie on the crossing line while held.
                let straight = hold + reach + r_f.max(1.0);
                let half_height = vertical_half_height(&shaped).max(vertical_half_height(nominal));
                let (lo, hi) = (b.z[0] + half_height, b.z[1] - half_height);
                let z_range = if lo <= hi {
                    [lo, hi]
                } else {
                    let mid = (b.z[0] + b.z[1]) / 2.0;
                    [mid, mid]
                };
                Via {
                    iwp: i,
                    pair: iwp.obstacles,
                    shape: iwp.shape,
                    center: iwp.position,
                    reach: iwp.normal * straight,
                    hold,
                    transition: mission.reconfiguration.transition_distance,
                    z_range,
                }
            })
            .collect();
        // The centroid searches a box shrunk by r_F so every UAV stays inside
        // the bounds; a box too small for that collapses to its middle line.
        let shrink = |[lo, hi]: [f64; 2], by: f64| {
            if hi - lo > 2.0 * by {
                [lo + by, hi - by]
            } else {
                let mid = (lo + hi) / 2.0;
                [mid, mid]
            }
        };
        let half_height = vertical_half_height(nominal);
        PathBuilder {
            start: mission.route.start,
            goal: mission.route.goal,
            bounds: [shrink(b.x, r_f), shrink(b.y, r_f), shrink(b.z, half_height)],
            vias,
        }
    }

    /// Waypoints decoded from a particle: 3 angles per waypoint (x, y, z), eq. 1,
    /// into the bounds less the formation's radius (horizontally) and its
    /// vertical half-height (in the altitude band).
    pub fn decode(&self, angles: &[f64]) -> Vec<Point3<f64>> {
        angles
            .chunks_exact(3)
            .map(|c| {
                Point3::new(
                    decode_angle(c[0], self.bounds[0][0], self.bounds[0][1]),
                    decode_angle(c[1], self.bounds[1][0], self.bounds[1][1]),
                    decode_angle(c[2], self.bounds[2][0], self.bounds[2][1]),
                )
            })
            .collect()
    }

    /// start → waypoints → goal with every enabled IWP inserted.
    pub fn build(&self, waypoints: &[Point3<f64>]) -> CentroidPath {
        let mut points = Vec::with_capacity(waypoints.len() + 2 + 3 * self.vias.len());
        points.push(self.start);
        points.extend_from_slice(waypoints);
        points.push(self.goal);
        let mut centers = Vec::with_capacity(self.vias.len());
        for via in &self.vias {
            let (index, triple) = self.best_insertion(&points, via);
            // Insert after `index` (cheaper than `splice`, which allocates).
            points.extend_from_slice(&triple);
            points[index + 1..].rotate_right(3);
            // Indices of earlier IWP centres after this insertion point shift by 3.
            for c in centers.iter_mut() {
                if *c > index {
                    *c += 3;
                }
            }
            centers.push(index + 2);
        }
        let mut zones = Vec::with_capacity(self.vias.len());
        if !self.vias.is_empty() {
            let arcs = cumulative_lengths(&points);
            for (via, &c) in self.vias.iter().zip(&centers) {
                zones.push(Zone {
                    iwp: via.iwp,
                    pair: via.pair,
                    shape: via.shape,
                    arc: arcs[c],
                    hold: via.hold,
                    transition: via.transition,
                });
            }
        }
        CentroidPath { points, zones }
    }

    /// The leg (index of its first point) and the via triple, in the direction
    /// of travel, that add the least length.
    fn best_insertion(&self, points: &[Point3<f64>], via: &Via) -> (usize, [Point3<f64>; 3]) {
        let mut best = (0, [Point3::origin(); 3], f64::INFINITY);
        for (i, leg) in points.windows(2).enumerate() {
            let (a, b) = (leg[0], leg[1]);
            let z = ((a.z + b.z) / 2.0).clamp(via.z_range[0], via.z_range[1]);
            for sign in [1.0, -1.0] {
                let reach = via.reach * sign;
                let before = Point3::new(via.center.x - reach.x, via.center.y - reach.y, z);
                let middle = Point3::new(via.center.x, via.center.y, z);
                let after = Point3::new(via.center.x + reach.x, via.center.y + reach.y, z);
                let added = (before - a).norm() + (after - before).norm() + (b - after).norm()
                    - (b - a).norm();
                if added < best.2 {
                    best = (i, [before, middle, after], added);
                }
            }
        }
        (best.0, best.1)
    }
}

/// s at each vertex: 0 at the first, the total length at the last.
pub fn cumulative_lengths(points: &[Point3<f64>]) -> Vec<f64> {
    let mut s = 0.0;
    let mut out = Vec::with_capacity(points.len());
    out.push(0.0);
    for w in points.windows(2) {
        s += (w[1] - w[0]).norm();
        out.push(s);
    }
    out
}

/// A point moving along a polyline by arc length, with a cursor so that
/// increasing queries cost O(1) each.
pub struct ArcWalker<'a> {
    points: &'a [Point3<f64>],
    arcs: Vec<f64>,
}

impl<'a> ArcWalker<'a> {
    pub fn new(points: &'a [Point3<f64>]) -> Self {
        ArcWalker {
            arcs: cumulative_lengths(points),
            points,
        }
    }

    pub fn length(&self) -> f64 {
        self.arcs.last().copied().unwrap_or(0.0)
    }

    /// Position at arc length `s` (clamped to the path).
    pub fn at(&self, s: f64) -> Point3<f64> {
        let n = self.points.len();
        if n == 0 {
            return Point3::origin();
        }
        let s = s.clamp(0.0, self.length());
        let i = self
            .arcs
            .partition_point(|&a| a <= s)
            .clamp(1, n.max(2) - 1);
        if n == 1 {
            return self.points[0];
        }
        let (a, b) = (self.points[i - 1], self.points[i]);
        let len = self.arcs[i] - self.arcs[i - 1];
        if len <= 0.0 {
            return b;
        }
        a + (b - a) * ((s - self.arcs[i - 1]) / len)
    }

    /// Unit horizontal direction of travel around `s`, from the chord between
    /// s − span and s + span: continuous in s, so the formation frame turns
    /// smoothly through the path's corners instead of snapping.
    pub fn heading(&self, s: f64, span: f64) -> Vector3<f64> {
        let ahead = self.at(s + span);
        let behind = self.at(s - span);
        let d = Vector3::new(ahead.x - behind.x, ahead.y - behind.y, 0.0);
        if d.norm() > 1e-9 {
            d.normalize()
        } else {
            let whole = self.at(self.length()) - self.at(0.0);
            let flat = Vector3::new(whole.x, whole.y, 0.0);
            if flat.norm() > 1e-9 {
                flat.normalize()
            } else {
                Vector3::x()
            }
        }
    }
}
