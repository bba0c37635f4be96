//! An independent answer to "does a passage exist?": a breadth-first search
//! over a voxel grid for a point that keeps `clearance` from every obstacle
//! (3-D distance to its prism), stays inside the bounds and the band, and
//! goes from the start to the goal. It reads only the mission's own fields
//! (bounds, route, obstacles' footprints, radii and heights), none of the
//! planner's code: a passage it finds with room to spare is one the planner
//! must find too.

use nalgebra::{Point2, Point3};
use skyform::mission::{Mission, Obstacle};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The grid the oracle searches: `cell` metres in x and y, `layer` metres
/// in z (one layer when every obstacle spans the band).
pub struct Grid {
    pub cell: f64,
    pub layer: f64,
}

/// Distance from `p` to the segment `a`-`b`.
fn to_segment(p: Point2<f64>, a: Point2<f64>, b: Point2<f64>) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared().max(1e-300)).clamp(0.0, 1.0);
    (a + ab * t - p).norm()
}

/// Horizontal distance from `p` to the obstacle's footprint (0 inside).
fn horizontal(o: &Obstacle, p: Point2<f64>) -> f64 {
    if o.footprint.len() < 3 {
        return ((p - o.center).norm() - o.radius).max(0.0);
    }
    let poly = &o.footprint;
    let mut inside = false;
    let mut best = f64::INFINITY;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        best = best.min(to_segment(p, a, b));
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
            inside = !inside;
        }
    }
    if inside { 0.0 } else { best }
}

/// Does `p` keep `clearance` from `o`? An obstacle that may not be flown
/// over reaches up without end.
fn clear_of(o: &Obstacle, p: Point3<f64>, clearance: f64) -> bool {
    if (p.xy() - o.center).norm() - o.radius >= clearance {
        return true;
    }
    let top = if o.overfly { o.height } else { f64::INFINITY };
    let dz = (o.base - p.z).max(p.z - top).max(0.0);
    if dz >= clearance {
        return true;
    }
    let dh = horizontal(o, p.xy());
    dh * dh + dz * dz >= clearance * clearance
}

/// Is there a way from the start to the goal keeping `clearance`?
pub fn passage_exists(m: &Mission, clearance: f64, grid: &Grid) -> bool {
    let b = &m.bounds;
    let n = |lo: f64, hi: f64, step: f64| ((hi - lo) / step).floor() as usize + 1;
    let (nx, ny) = (n(b.x[0], b.x[1], grid.cell), n(b.y[0], b.y[1], grid.cell));
    let nz = n(b.z[0], b.z[1], grid.layer);
    let at = |i: usize, j: usize, k: usize| {
        Point3::new(
            b.x[0] + i as f64 * grid.cell,
            b.y[0] + j as f64 * grid.cell,
            if nz == 1 {
                (b.z[0] + b.z[1]) / 2.0
            } else {
                b.z[0] + k as f64 * grid.layer
            },
        )
    };
    let index = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
    let cell_of = |p: Point3<f64>| {
        let i = ((p.x - b.x[0]) / grid.cell)
            .round()
            .clamp(0.0, (nx - 1) as f64) as usize;
        let j = ((p.y - b.y[0]) / grid.cell)
            .round()
            .clamp(0.0, (ny - 1) as f64) as usize;
        let k = if nz == 1 {
            0
        } else {
            ((p.z - b.z[0]) / grid.layer)
                .round()
                .clamp(0.0, (nz - 1) as f64) as usize
        };
        (i, j, k)
    };
    // 0 unknown, 1 blocked, 2 reached.
    let mut state = vec![0u8; nx * ny * nz];
    let free = |state: &mut [u8], (i, j, k): (usize, usize, usize)| -> bool {
        let s = &mut state[index(i, j, k)];
        if *s != 0 {
            return false;
        }
        let p = at(i, j, k);
        if m.obstacles.iter().all(|o| clear_of(o, p, clearance)) {
            *s = 2;
            true
        } else {
            *s = 1;
            false
        }
    };
    let start = cell_of(m.route.start);
    let goal = cell_of(m.route.goal);
    // Best first toward the goal: the order changes how soon, not whether.
    let to_goal = |(i, j, k): (usize, usize, usize)| {
        let d = |a: usize, b: usize| a.abs_diff(b) as u64;
        Reverse(d(i, goal.0).max(d(j, goal.1)) + d(k, goal.2))
    };
    let mut queue = BinaryHeap::new();
    if free(&mut state, start) {
        queue.push((to_goal(start), start));
    }
    while let Some((_, (i, j, k))) = queue.pop() {
        if (i, j, k) == goal {
            return true;
        }
        for (di, dj, dk) in [
            (-1, 0, 0),
            (1, 0, 0),
            (0, -1, 0),
            (0, 1, 0),
            (-1, -1, 0),
            (1, 1, 0),
            (-1, 1, 0),
            (1, -1, 0),
            (0, 0, -1),
            (0, 0, 1),
        ] {
            let (ni, nj, nk) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
            if ni < 0 || nj < 0 || nk < 0 || ni >= nx as i64 || nj >= ny as i64 || nk >= nz as i64 {
                continue;
            }
            let next = (ni as usize, nj as usize, nk as usize);
            if free(&mut state, next) {
                queue.push((to_goal(next), next));
            }
        }
    }
    false
}
