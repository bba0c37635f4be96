//! Passages the grid may not resolve, decided on exact geometry (issue 51).
//!
//! The route's grid opens a cell only where its centre has the layer's
//! clearance plus half a cell's diagonal, so a passage narrower than the
//! need plus about a cell and a half (2.5 m cells on a 1 km² site) may show
//! no open cell and look closed. An IWP's gap is a crossing of its own
//! (`Site::landing` joins it to the grid); this module does the same for
//! the gaps eq. 9 places no IWP in:
//! - between two obstacles wider than the formation (no reconfiguration,
//!   so no IWP): flown in the nominal shape, or the widest that fits;
//! - between an obstacle and a side of the bounds, where the column may
//!   pass (its UAVs follow the path, so the centroid may run up to the
//!   bound; `verify` holds each UAV inside the bounds, not r_Q inside).
//!
//! Each passage is a straight through the middle of the gap, perpendicular
//! to it, with every point of it clear by the layer's need (checked at its
//! midpoint and on the way out to the grid): the grid may guide, never
//! close, such a passage. Only the gaps the grid might miss are added (at
//! the finest cells, those within about 0.7 m of the need).

use nalgebra::{Point2, Vector2};

use super::Site;
use super::search::{Jump, LAYERS};
use crate::base::shape::nearest_points;
use crate::mission::Bounds;

/// A straight through a gap: its ends (where it meets the grid) and the
/// widest layer it may be flown in.
#[derive(Debug, Clone, Copy)]
pub struct Gap {
    pub ends: [Point2<f64>; 2],
    pub cells: [usize; 2],
    pub layer: usize,
}

impl Gap {
    /// The two jumps (either way) at `level`, tagged `tag` and `tag + 1`.
    pub fn jumps(&self, level: usize, tag: usize) -> [Jump; 2] {
        let length = (self.ends[1] - self.ends[0]).norm();
        let jump = |k: usize| Jump {
            from: self.cells[k],
            to: self.cells[1 - k],
            length,
            pass_at: None,
            crossing: true,
            tag: tag + k,
            level,
            widest: self.layer,
        };
        [jump(0), jump(1)]
    }
}

/// The passages at `level` the grid may miss, each joined to the grid, for
/// the obstacle pairs with no IWP (`has_iwp`) and between each obstacle and
/// the bounds.
pub fn find(
    site: &Site,
    level: usize,
    bounds: &Bounds,
    has_iwp: impl Fn(usize, usize) -> bool,
) -> Vec<Gap> {
    let field = site.field();
    let slack = field.cell() * (std::f64::consts::FRAC_1_SQRT_2 + 2.0);
    let need = site.need;
    let obstacles = &site.at[level].obstacles;
    let discs = &site.at[level].discs;
    let clear = |p: Point2<f64>, layer: usize| {
        discs
            .iter()
            .all(|d| d.signed_distance(&p) >= need[layer] - 1e-9)
    };
    let mut found = Vec::new();
    let mut through = |middle: Point2<f64>, across: Vector2<f64>, widest: usize| {
        let Some(layer) = (widest..LAYERS).find(|&l| clear(middle, l)) else {
            return;
        };
        let along = Vector2::new(-across.y, across.x);
        let (Some(a), Some(b)) = (
            site.landing_from(level, middle, along, layer),
            site.landing_from(level, middle, -along, layer),
        ) else {
            return;
        };
        found.push(Gap {
            ends: [a.1, b.1],
            cells: [a.0, b.0],
            layer: layer.max(a.2).max(b.2),
        });
    };
    for (i, (p, dp)) in obstacles.iter().enumerate() {
        for (q, dq) in &obstacles[i + 1..] {
            // A quick reject on the bounding circles, then the exact gap.
            let apart = (dp.center() - dq.center()).norm() - dp.radius() - dq.radius();
            if apart >= 2.0 * need[0] + slack || has_iwp(*p, *q) {
                continue;
            }
            let (a, b) = nearest_points(&**dp, &**dq);
            let gap = (b - a).norm();
            let widest = (0..LAYERS).find(|&l| gap >= 2.0 * need[l]);
            let Some(widest) = widest else { continue };
            if gap >= 2.0 * need[widest] + slack || gap < 1e-9 {
                continue;
            }
            through(nalgebra::center(&a, &b), (b - a) / gap, widest);
        }
    }
    // Against the bounds: the column only (the other layers keep their
    // reach inside the bounds, where the grid's own box sees them).
    let sides = [
        (Point2::new(bounds.x[0], 0.0), Vector2::new(-1.0, 0.0)),
        (Point2::new(bounds.x[1], 0.0), Vector2::new(1.0, 0.0)),
        (Point2::new(0.0, bounds.y[0]), Vector2::new(0.0, -1.0)),
        (Point2::new(0.0, bounds.y[1]), Vector2::new(0.0, 1.0)),
    ];
    let column = LAYERS - 1;
    for (_, d) in obstacles {
        for &(on, n) in &sides {
            if (on - d.center()).dot(&n) - d.radius() >= need[column] + slack {
                continue;
            }
            let (a, gap) = d.nearest_to_line(&on, &n);
            if gap < need[column] || gap >= need[column] + slack {
                continue;
            }
            // Midway between the least the column keeps from the
            // obstacle and the bound.
            let middle = a + n * ((need[column] + gap) / 2.0);
            through(middle, n, column);
        }
    }
    found
}

/// Every level's gaps as jumps (appended to `jumps`), tagged from `tag` on
/// (two per gap, either way), for the obstacle pairs with no IWP in
/// `iwps`; each gap's ends, in tag order.
pub fn jumps(
    site: &Site,
    mission: &crate::mission::Mission,
    iwps: &[crate::pipelines::theta_pso::iwp::Iwp],
    tag: usize,
    jumps: &mut Vec<Jump>,
) -> Vec<[Point2<f64>; 2]> {
    let has_iwp = |p: usize, q: usize| {
        iwps.iter()
            .any(|i| i.obstacles == [p, q] || i.obstacles == [q, p])
    };
    let mut ends: Vec<[Point2<f64>; 2]> = Vec::new();
    for level in 0..site.levels.len() {
        for gap in find(site, level, &mission.bounds, has_iwp) {
            jumps.extend(gap.jumps(level, tag + 2 * ends.len()));
            ends.push(gap.ends);
        }
    }
    ends
}
