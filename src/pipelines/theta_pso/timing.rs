//! When the formation is where along its path: the time law s(t) of the
//! centroid, fastest within every UAV's `[vehicle]` limits.
//!
//! The geometry fixes where each UAV is for each arc length s of the
//! centroid path (`motion`): p_n(s). All UAVs share one s(t), so the
//! formation stays in step and its pace is, at each moment, what its most
//! constrained UAV allows. With x = ṡ² and u = s̈, UAV n's velocity and
//! acceleration are
//!
//!   v_n = p_n'(s) ṡ,   a_n = p_n'(s) u + p_n''(s) x,
//!
//! so each limit is a constraint on (x, u) at each s: the horizontal speed
//! |p'_xy| √x ≤ v_max, the climb and descent rates on p'_z √x, the
//! horizontal acceleration |p'_xy u + p''_xy x| ≤ a_max (a convex cone in
//! (x, u)), the vertical acceleration p'_z u + p''_z x within [−a_down, a_up],
//! and the centroid's cruise ṡ ≤ the formation's ground speed. This is the
//! time-optimal path parameterisation problem; it is solved here by
//! reachability analysis on a grid of s (Pham & Pham, "A new approach to
//! time-optimal path parameterization based on reachability analysis", IEEE
//! T-RO 34(3), 2018: TOPP-RA): a backward pass finds, at each grid point, the
//! largest x from which the end is still reachable at rest; a forward pass
//! from rest takes the largest admissible u at each point. u is constant
//! over each grid step, so ṡ is continuous: no UAV's velocity jumps.
//!
//! A formation that would have to crawl slower than [`MIN_PACE`] to keep
//! its limits (absurdly low limits) is flown at that pace instead, and
//! verification names the limit it breaks, where.

use nalgebra::{Point3, Vector3};

use crate::mission::VehicleLimits;

/// The slowest pace the centroid is ever held to between start and goal,
/// m/s: the slowest leg speed an export commands (`export::MIN_SPEED`).
pub const MIN_PACE: f64 = 0.1;
/// Grid step of the time law away from the corners, metres of centroid path
/// (at most).
pub const GRID_STEP: f64 = 0.1;
/// Finest grid step near the corners, metres.
pub const FINE_STEP_MIN: f64 = 0.005;

/// Grid points along a path of `length` metres: every [`GRID_STEP`], every
/// window's step within each of `windows` (arc-length intervals and their
/// steps), and exactly at each of `stops`; with the index of each stop.
pub fn grid(length: f64, windows: &[(f64, f64, f64)], stops: &[f64]) -> (Vec<f64>, Vec<usize>) {
    if length.is_nan() || length <= 0.0 {
        return (vec![0.0, 0.0], Vec::new());
    }
    let coarse = ((length / GRID_STEP).ceil() as usize).max(8);
    let mut arcs: Vec<f64> = (0..=coarse)
        .map(|i| length * i as f64 / coarse as f64)
        .collect();
    let mut finest = GRID_STEP;
    for &(a, b, step) in windows {
        let (a, b) = (a.max(0.0), b.min(length));
        let step = step.max(FINE_STEP_MIN);
        if b <= a {
            continue;
        }
        finest = finest.min(step);
        let n = ((b - a) / step).ceil() as usize;
        arcs.extend((0..=n).map(|i| a + (b - a) * i as f64 / n as f64));
    }
    let stops: Vec<f64> = stops
        .iter()
        .copied()
        .filter(|s| *s > 0.0 && *s < length)
        .collect();
    // Points closer than a quarter of the finest step to a stop give way
    // to it, so the stop is a grid point of its own.
    arcs.retain(|a| stops.iter().all(|s| (a - s).abs() >= finest * 0.25));
    arcs.extend(&stops);
    arcs.sort_by(f64::total_cmp);
    arcs.dedup_by(|b, a| *b - *a < FINE_STEP_MIN * 0.1);
    if let Some(last) = arcs.last_mut() {
        *last = length;
    }
    let at = stops
        .iter()
        .filter_map(|s| arcs.iter().position(|a| a == s))
        .collect();
    (arcs, at)
}
/// The share of each limit the trajectories plan to: the rest covers what
/// the time law's grid does not see between its points (verification
/// holds the whole limit).
pub const PLANNED_SHARE: f64 = 0.9;
/// Bisection steps of each grid point's largest x.
const BISECTIONS: usize = 48;

/// The centroid's time law: ṡ² at each grid point and the time it is
/// reached.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeLaw {
    /// Arc length of each grid point, metres (increasing).
    arcs: Vec<f64>,
    /// x = ṡ² at each grid point, (m/s)².
    x: Vec<f64>,
    /// Seconds from the start at each grid point.
    t: Vec<f64>,
}

/// Where the formation is along its path at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Arc length of the centroid, metres.
    pub s: f64,
    /// Its rate, m/s.
    pub speed: f64,
}

/// The first and second derivatives of each UAV's position with respect
/// to s at one grid point.
#[derive(Debug, Clone, Copy)]
struct Shape {
    d1: Vector3<f64>,
    d2: Vector3<f64>,
}

/// What one grid point allows: each UAV's derivatives and limits.
struct Point<'a> {
    shapes: &'a [Shape],
    limits: &'a [VehicleLimits],
    /// Where the limits need a pace below the floor: the floor is flown,
    /// x ≤ `relaxed` with the centroid's own ramp (`ramp`) for u.
    relaxed: Option<f64>,
    ramp: f64,
}

impl Point<'_> {
    /// The interval of u admissible at `x` for every UAV; `None` when
    /// none is (x too fast for the curvature or the speeds).
    fn u_range(&self, x: f64) -> Option<(f64, f64)> {
        if let Some(cap) = self.relaxed {
            return (x <= cap).then_some((-self.ramp, self.ramp));
        }
        self.limited(x)
    }

    /// The largest x the horizontal acceleration allows each UAV on its
    /// own (|p' × p''| x ≤ |p'| a, where u can do nothing against the
    /// curvature), the least over the UAVs: where the bisection starts.
    fn curvature_cap(&self) -> f64 {
        self.shapes
            .iter()
            .zip(self.limits)
            .map(|(shape, limit)| {
                let (d1, d2) = (shape.d1.xy(), shape.d2.xy());
                let cross = (d1.x * d2.y - d1.y * d2.x).abs();
                if cross > 1e-12 {
                    d1.norm() * limit.acceleration / cross
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// [`Self::u_range`] by the UAVs' limits alone.
    fn limited(&self, x: f64) -> Option<(f64, f64)> {
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for (shape, limit) in self.shapes.iter().zip(self.limits) {
            let (d1, d2) = (shape.d1, shape.d2);
            // Horizontal: |d1 u + d2 x|² ≤ a² over x-y.
            let a = d1.x * d1.x + d1.y * d1.y;
            let b = x * (d1.x * d2.x + d1.y * d2.y);
            let c = x * x * (d2.x * d2.x + d2.y * d2.y) - limit.acceleration * limit.acceleration;
            if a < 1e-12 {
                if c > 0.0 {
                    return None;
                }
            } else {
                let disc = b * b - a * c;
                if disc < 0.0 {
                    return None;
                }
                let r = disc.sqrt();
                lo = lo.max((-b - r) / a);
                hi = hi.min((-b + r) / a);
            }
            // Vertical: −a_down ≤ d1z u + d2z x ≤ a_up.
            let (top, bottom) = (limit.up - d2.z * x, -limit.down - d2.z * x);
            if d1.z.abs() < 1e-9 {
                if top < 0.0 || bottom > 0.0 {
                    return None;
                }
            } else if d1.z > 0.0 {
                lo = lo.max(bottom / d1.z);
                hi = hi.min(top / d1.z);
            } else {
                lo = lo.max(top / d1.z);
                hi = hi.min(bottom / d1.z);
            }
        }
        (lo <= hi).then_some((lo, hi))
    }

    /// The largest x ≤ `cap` with an admissible u that reaches
    /// `[0, next]` at the grid point `step` further on (`None` for the
    /// next: any x there).
    fn largest(&self, cap: f64, step: f64, next: Option<f64>) -> f64 {
        if cap <= 0.0 {
            return 0.0;
        }
        let ok = |x: f64| {
            self.u_range(x).is_some_and(|(lo, hi)| match next {
                None => true,
                // x + 2 step u ∈ [0, next]
                Some(n) => lo <= (n - x) / (2.0 * step) && -x / (2.0 * step) <= hi,
            })
        };
        if ok(cap) {
            return cap;
        }
        let (mut good, mut bad) = (0.0, cap);
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (good + bad);
            if ok(mid) {
                good = mid;
            } else {
                bad = mid;
            }
            if bad - good <= 1e-9 * cap.max(1e-9) {
                break;
            }
        }
        good
    }
}

impl TimeLaw {
    /// The fastest time law through `positions` (every UAV's position at
    /// each grid point, the grid points at arc lengths `arcs`, increasing),
    /// from rest to rest, with UAV n held to `limits[n]` and the centroid
    /// to `cruise` (m/s), and at rest at the grid points
    /// `stops` (indices: where a UAV's path has a corner kept as planned,
    /// which no speed can cross without a velocity jump).
    pub fn plan(
        arcs: &[f64],
        positions: &[Vec<Point3<f64>>],
        limits: &[VehicleLimits],
        cruise: f64,
        stops: &[usize],
    ) -> Self {
        let nodes = positions.len().min(arcs.len());
        let flat = || TimeLaw {
            arcs: arcs[..nodes].to_vec(),
            x: vec![0.0; nodes],
            t: vec![0.0; nodes],
        };
        if nodes < 2 || positions[0].is_empty() {
            return flat();
        }
        let uavs = limits.len().min(positions[0].len());
        let planned = &limits[..uavs];
        let shapes = derivatives(&arcs[..nodes], positions, uavs, stops);
        let pace = MIN_PACE.min(cruise);
        let ramp = ramp(planned);
        let step = |i: usize| arcs[i + 1] - arcs[i];
        let mut points: Vec<Point> = (0..nodes)
            .map(|i| Point {
                shapes: &shapes[i * uavs..(i + 1) * uavs],
                limits: planned,
                relaxed: None,
                ramp,
            })
            .collect();
        // The fastest each point allows at all; where the limits need a
        // pace below the floor, the floor is flown (`relaxed`).
        let reach: Vec<f64> = points
            .iter_mut()
            .map(|p| {
                let speeds = speed_cap(p.shapes, planned, cruise);
                let fastest = p.largest(speeds.min(p.curvature_cap()), 1.0, None);
                let floor = (pace * pace).min(speeds);
                if fastest < floor {
                    p.relaxed = Some(floor);
                    floor
                } else {
                    fastest
                }
            })
            .collect();
        let mut reach = reach;
        for &i in stops {
            if let Some(r) = reach.get_mut(i) {
                *r = 0.0;
            }
        }
        // Backward: the largest x at each point from which the end is
        // reachable at rest.
        let mut hi = vec![0.0; nodes];
        for i in (0..nodes - 1).rev() {
            hi[i] = points[i].largest(reach[i], step(i), Some(hi[i + 1]));
        }
        // Forward from rest: the largest admissible u at each point.
        let mut x = vec![0.0; nodes];
        for i in 0..nodes - 1 {
            let ceiling = hi[i + 1];
            let room = (ceiling - x[i]) / (2.0 * step(i));
            let u = points[i]
                .u_range(x[i])
                .map_or(room, |(_, u_hi)| u_hi.min(room));
            x[i + 1] = (x[i] + 2.0 * step(i) * u).clamp(0.0, ceiling);
        }
        x[nodes - 1] = 0.0;
        let mut t = vec![0.0; nodes];
        for i in 0..nodes - 1 {
            let rates = x[i].sqrt() + x[i + 1].sqrt();
            let dt = if rates > 1e-12 {
                2.0 * step(i) / rates
            } else {
                (4.0 * step(i) / ramp).sqrt()
            };
            t[i + 1] = t[i] + dt;
        }
        TimeLaw {
            arcs: arcs[..nodes].to_vec(),
            x,
            t,
        }
    }

    /// Seconds from start to goal.
    pub fn duration(&self) -> f64 {
        self.t.last().copied().unwrap_or(0.0)
    }

    /// Metres of centroid path.
    pub fn length(&self) -> f64 {
        self.arcs.last().copied().unwrap_or(0.0)
    }

    /// Where the centroid is at `t` (clamped to the flight): u is constant
    /// over each grid step, so s and ṡ are exact between grid points.
    pub fn at(&self, t: f64) -> Progress {
        let n = self.t.len();
        if n < 2 {
            return Progress { s: 0.0, speed: 0.0 };
        }
        if t >= self.duration() {
            return Progress {
                s: self.length(),
                speed: 0.0,
            };
        }
        let t = t.max(0.0);
        let i = self.t.partition_point(|&ti| ti <= t).clamp(1, n - 1) - 1;
        let tau = t - self.t[i];
        let (a, b) = (self.arcs[i], self.arcs[i + 1]);
        let v0 = self.x[i].sqrt();
        let u = (self.x[i + 1] - self.x[i]) / (2.0 * (b - a));
        let s = (a + v0 * tau + 0.5 * u * tau * tau).clamp(a, b);
        Progress {
            s,
            speed: (v0 + u * tau).max(0.0),
        }
    }

    /// When the centroid is at arc length `s`, seconds.
    pub fn time_at(&self, s: f64) -> f64 {
        let n = self.t.len();
        if n < 2 {
            return 0.0;
        }
        let s = s.clamp(0.0, self.length());
        let i = self.arcs.partition_point(|&a| a <= s).clamp(1, n - 1) - 1;
        let ds = s - self.arcs[i];
        let v0 = self.x[i].sqrt();
        let u = (self.x[i + 1] - self.x[i]) / (2.0 * (self.arcs[i + 1] - self.arcs[i]));
        // s = v0 τ + u τ² / 2 solved for τ (the root that is reached first).
        let tau = if u.abs() < 1e-12 {
            if v0 > 1e-12 { ds / v0 } else { 0.0 }
        } else {
            let disc = (v0 * v0 + 2.0 * u * ds).max(0.0);
            (disc.sqrt() - v0) / u
        };
        (self.t[i] + tau.max(0.0)).min(self.t[i + 1])
    }

    /// The largest ṡ anywhere, m/s.
    pub fn top_speed(&self) -> f64 {
        self.x.iter().copied().fold(0.0, f64::max).sqrt()
    }
}

/// The centroid's own acceleration where the floor is flown: the
/// smallest of the UAVs' limits.
fn ramp(limits: &[VehicleLimits]) -> f64 {
    limits
        .iter()
        .map(|l| l.acceleration.min(l.up).min(l.down))
        .fold(f64::INFINITY, f64::min)
        .max(1e-6)
}

/// The largest x the speeds allow at one point: each UAV's horizontal
/// speed, climb and descent rate, and the centroid's cruise.
fn speed_cap(shapes: &[Shape], limits: &[VehicleLimits], cruise: f64) -> f64 {
    let mut x = cruise * cruise;
    for (shape, limit) in shapes.iter().zip(limits) {
        let d1 = shape.d1;
        let horizontal = d1.x * d1.x + d1.y * d1.y;
        if horizontal > 1e-12 {
            x = x.min(limit.speed * limit.speed / horizontal);
        }
        let vertical = if d1.z > 0.0 {
            limit.climb
        } else {
            limit.descent
        };
        if d1.z.abs() > 1e-9 {
            x = x.min(vertical * vertical / (d1.z * d1.z));
        }
    }
    x
}

/// p' and p'' of every UAV at every grid point (arc lengths `arcs`) by
/// the three-point differences of an uneven grid (one-sided first
/// derivative and no second at the ends), point-major. A grid point's
/// derivatives govern the step after it, so at a stop (a corner, where the
/// path's direction changes at once) they are the path's after the stop.
fn derivatives(
    arcs: &[f64],
    positions: &[Vec<Point3<f64>>],
    uavs: usize,
    stops: &[usize],
) -> Vec<Shape> {
    let nodes = arcs.len();
    let mut out = Vec::with_capacity(nodes * uavs);
    for i in 0..nodes {
        // At a stop, the three points after it.
        let centre = if stops.contains(&i) && i + 2 < nodes {
            i + 1
        } else {
            i
        };
        // n indexes the rows of several grid points at once.
        #[allow(clippy::needless_range_loop)]
        for n in 0..uavs {
            let shape = if centre == 0 || centre + 1 == nodes {
                let (a, b) = if i == 0 { (0, 1) } else { (i - 1, i) };
                Shape {
                    d1: (positions[b][n] - positions[a][n]) / (arcs[b] - arcs[a]),
                    d2: Vector3::zeros(),
                }
            } else if centre != i {
                // Forward from the stop: the slope leaving it, and the
                // curvature of the three points after it.
                let c = centre;
                let (h1, h2) = (arcs[c] - arcs[c - 1], arcs[c + 1] - arcs[c]);
                let (pa, pi, pb) = (
                    positions[c - 1][n].coords,
                    positions[c][n].coords,
                    positions[c + 1][n].coords,
                );
                Shape {
                    d1: (pi - pa) / h1,
                    d2: (pb * h1 - pi * (h1 + h2) + pa * h2) * (2.0 / (h1 * h2 * (h1 + h2))),
                }
            } else {
                let (h1, h2) = (arcs[i] - arcs[i - 1], arcs[i + 1] - arcs[i]);
                let (pa, pi, pb) = (
                    positions[i - 1][n].coords,
                    positions[i][n].coords,
                    positions[i + 1][n].coords,
                );
                let denominator = h1 * h2 * (h1 + h2);
                Shape {
                    d1: (pb * (h1 * h1) - pa * (h2 * h2) + pi * (h2 * h2 - h1 * h1)) / denominator,
                    d2: (pb * h1 - pi * (h1 + h2) + pa * h2) * (2.0 / denominator),
                }
            };
            out.push(shape);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> VehicleLimits {
        crate::mission::Vehicle::default().limits(0)
    }

    fn straight(length: f64) -> (Vec<f64>, Vec<Vec<Point3<f64>>>) {
        let n = (length / GRID_STEP).round() as usize;
        let step = length / n as f64;
        let arcs: Vec<f64> = (0..=n).map(|i| i as f64 * step).collect();
        let p = arcs
            .iter()
            .map(|&s| vec![Point3::new(s, 0.0, 10.0)])
            .collect();
        (arcs, p)
    }

    fn even(n: usize, step: f64) -> Vec<f64> {
        (0..=n).map(|i| i as f64 * step).collect()
    }

    /// A straight line from rest to rest: accelerate at the limit to the
    /// cruise, hold it, brake: the trapezoid, whose duration is L / v + v / a.
    #[test]
    fn a_straight_line_is_the_trapezoid_of_the_limits() {
        let (arcs, p) = straight(60.0);
        let law = TimeLaw::plan(&arcs, &p, &[limits()], 3.0, &[]);
        let a = limits().acceleration;
        let expected = 60.0 / 3.0 + 3.0 / a;
        assert!(
            (law.duration() - expected).abs() < 0.05,
            "{} vs {expected}",
            law.duration()
        );
        assert!((law.top_speed() - 3.0).abs() < 1e-9);
        assert_eq!(law.at(0.0).speed, 0.0);
        assert_eq!(law.at(law.duration()).speed, 0.0);
        // Half a second in, the formation is accelerating at a.
        let early = law.at(0.5);
        assert!((early.speed - 0.5 * a).abs() < 1e-6, "{early:?}");
        assert!((law.time_at(law.at(7.3).s) - 7.3).abs() < 1e-9);
    }

    /// Round a circle of radius R at cruise v: the centripetal acceleration
    /// v²/R must stay within the limit, so the pace is √(a R).
    #[test]
    fn a_tight_circle_is_flown_at_the_speed_its_acceleration_allows() {
        let radius = 1.0;
        let n = 400;
        let length = std::f64::consts::PI * radius;
        let step = length / n as f64;
        let p: Vec<Vec<Point3<f64>>> = (0..=n)
            .map(|i| {
                let a = i as f64 * step / radius;
                vec![Point3::new(
                    radius * a.sin(),
                    radius * (1.0 - a.cos()),
                    10.0,
                )]
            })
            .collect();
        let law = TimeLaw::plan(&even(n, step), &p, &[limits()], 12.0, &[]);
        let allowed = (limits().acceleration * radius).sqrt();
        let middle = law.at(law.duration() / 2.0).speed;
        assert!(
            (middle - allowed).abs() < 0.02 * allowed,
            "{middle} vs {allowed}"
        );
        assert!(law.top_speed() <= allowed * 1.001);
    }

    /// A UAV slower than the others sets the formation's pace.
    #[test]
    fn the_slowest_uav_sets_the_pace() {
        let (arcs, p) = straight(100.0);
        let two: Vec<Vec<Point3<f64>>> = p
            .iter()
            .map(|at| vec![at[0], at[0] + Vector3::new(0.0, 3.0, 0.0)])
            .collect();
        let mut slow = limits();
        slow.speed = 2.0;
        let law = TimeLaw::plan(&arcs, &two, &[limits(), slow], 5.0, &[]);
        assert!((law.top_speed() - 2.0).abs() < 1e-9);
    }

    /// A climb is held to the climb rate, a descent to the descent rate.
    #[test]
    fn climb_and_descent_rates_hold() {
        let n = 200;
        let step = 20.0 / n as f64;
        let up: Vec<Vec<Point3<f64>>> = (0..=n)
            .map(|i| vec![Point3::new(0.0, 0.0, 5.0 + i as f64 * step)])
            .collect();
        let law = TimeLaw::plan(&even(n, step), &up, &[limits()], 10.0, &[]);
        assert!((law.top_speed() - limits().climb).abs() < 1e-9);
        let down: Vec<Vec<Point3<f64>>> = up.iter().rev().cloned().collect();
        let law = TimeLaw::plan(&even(n, step), &down, &[limits()], 10.0, &[]);
        assert!((law.top_speed() - limits().descent).abs() < 1e-9);
    }
}
