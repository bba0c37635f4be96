//! The route stage: before the swarm, a deterministic search for a corridor
//! the formation can fly from start to goal, or the place that closes the way.
//!
//! Not in the paper, which starts its swarm at random (Fig. 3, line 9) and
//! has no answer when no plan exists. The search runs on a grid over the site
//! (`field`), in three layers:
//! - *nominal*: the centroid keeps the nominal shape's reach r + r_Q + margin
//!   from every obstacle and r from the bounds (r: the farthest UAV from the
//!   centroid in the plane), so every UAV is clear whatever the heading;
//! - *shrunk*: the same for the shape shrunk to the smallest scale eq. 7
//!   allows (the closest two UAVs 2 r_Q + 5 cm apart), for the stretches
//!   where the site is narrower than the formation but no IWP says so (a
//!   street between two walls);
//! - *column*: the centroid keeps r_Q + margin, the UAVs in single file
//!   along the path (the alignment of Fig. 2 flown as a real column flies),
//!   where even the shrink does not fit.
//!
//! A change of layer costs the transition distance. Each usable IWP crossing
//! (eq. 9, Fig. 2) is an edge of its own, straight through its gap, in
//! either direction; each inspection pass (eq. 8) is one too, at 16 angles
//! and both sides, flown in order (the search has a stage per pass). The
//! cheapest route is pulled tight within each layer and handed to the swarm
//! as seeded particles and kept as a plan of its own (`plan`).
//!
//! When no route exists the stage names what closes the way (`blocked`): the
//! chain of obstacles between the reached and the unreached part of the site,
//! which bounds it runs between, and why its widest gap does not let the
//! formation through. The grid guides the search but never closes a
//! passage between two obstacles, or an obstacle and the bounds: each IWP's
//! crossing and each gap the grid may not resolve is a straight of its own,
//! decided on exact geometry and joined to the grid (`gaps`,
//! `Site::landing`), at any cell size (issue 51). The disc model makes it
//! conservative (a plan the route stage finds keeps every UAV clear; a
//! formation turned to just the right heading might squeeze through where
//! the disc model says it cannot).
//!
//! Long (~1060 lines) because it holds the stage's driver and the site it searches: the
//! shape, layers and levels, the cells' open bits, the landings that join exact passages to
//! the grid, the stops and the jumps, the second look over a window (`focus`); the search,
//! the field, the gaps, the guide, the corridor's assembly, the squeeze map and the refusal's
//! words are submodules.

mod blocked;
mod corridor;
pub mod field;
mod gaps;
mod guide;
pub mod levels;
mod reuse;
mod search;
mod squeeze;

use std::collections::HashMap;
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use nalgebra::Point2;
use serde::{Deserialize, Serialize};

pub use reuse::reuse;

use self::corridor::{assemble, through_crossings};
use self::field::Field;
use self::guide::Guide;
use self::levels::Levels;
use self::search::{Graph, Jump, LAYERS, bit, climb_bit};
use self::squeeze::squeeze_map;
use super::iwp::{Iwp, Shape as FormationShape, column_spacing, min_pair_distance};
use super::path::{PathBuilder, SqueezeMap};
use crate::base::shape::Footprint;
use crate::mission::Mission;

/// Angles tried round each inspected obstacle.
const PASS_ANGLES: usize = 16;
/// Cells the grid has at most (per layer and stage).
const MAX_CELLS: f64 = 160_000.0;
/// The finest grid, metres: the search is complete up to this cell size.
pub(crate) const FINEST_CELL: f64 = 0.2;
/// Search states (cell × layer × stage) at most: about 16 bytes each.
const MAX_STATES: f64 = 2_000_000.0;
/// The same for a search over several levels (cell × layer × level ×
/// stage): about 100 MB at most, once per run, when the flat search failed.
const MAX_STACKED_STATES: f64 = 6_000_000.0;
/// Cells a crossing's end may be carried out to meet the grid (`Site::landing`).
const LANDING_CELLS: usize = 6;
/// Metres a passage's straight may run out to meet the grid: through the
/// depth of what stands either side of it (an aisle between bays 8 m deep).
const LANDING_METRES: f64 = 12.0;
/// Extra spacing the squeezed shape keeps beyond 2 r_Q between two UAVs.
const SQUEEZE_SPACING_MARGIN: f64 = 0.05;

/// A leg of the corridor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Leg {
    /// Flown in layer 0 (nominal), 1 (shrunk) or 2 (column).
    Free { layer: usize },
    /// Crossing `i` of the path builder (a usable IWP), straight.
    Crossing(usize),
    /// The pass of inspection `i` of the path builder.
    Pass(usize),
}

/// The route found: start, corners, crossings and passes, goal.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Corridor {
    pub points: Vec<Point2<f64>>,
    /// `legs[i]` joins `points[i]` and `points[i + 1]`.
    pub legs: Vec<Leg>,
    /// Per inspection (builder order): the angle round the axis and the side.
    pub passes: Vec<(f64, bool)>,
    pub length: f64,
    /// The centroid's altitude at each point, metres, when the search had
    /// to climb (or descend) off the start's and goal's altitudes to pass
    /// over (under) what closes the way there; empty: between them, as the
    /// seeding spreads it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub heights: Vec<f64>,
    /// The search's cell, metres, when coarser than the finest (a large
    /// site: a way that fits by less than about a cell may not be seen);
    /// `None` at the finest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coarse_cell: Option<f64>,
    /// Where the formation flies squeezed, for every path the swarm tries
    /// (worked out from the site for each run, never written).
    #[serde(skip)]
    pub squeeze: Option<Arc<SqueezeMap>>,
}

/// Two corridors are the same route (the squeeze map is the site's reading
/// of it, not part of it).
impl PartialEq for Corridor {
    fn eq(&self, other: &Self) -> bool {
        self.points == other.points
            && self.legs == other.legs
            && self.passes == other.passes
            && self.length == other.length
            && self.heights == other.heights
    }
}

/// Why no corridor exists.
#[derive(Debug, Clone, PartialEq)]
pub struct Blocked {
    /// In words, naming the obstacles and the widths involved.
    pub reason: String,
    /// The obstacles that close the way (indices into `mission.obstacles`).
    pub obstacles: Vec<usize>,
    /// The gaps between them too narrow to pass, widest first: the two
    /// obstacles (indices), the width, the width needed, the gap's ends.
    pub passages: Vec<BlockedPassage>,
    /// The route that was tried: from the start as far as the formation
    /// reached, to its point nearest the goal (ENU metres; empty when it
    /// could not move at all).
    pub tried: Vec<Point2<f64>>,
}

/// A gap that closes the way: the two obstacles (indices into
/// `mission.obstacles`), its width, the width needed, its ends.
pub type BlockedPassage = ([usize; 2], f64, f64, [Point2<f64>; 2]);

/// What the route stage needs of the formation.
struct Shape {
    /// Farthest UAV from the centroid in the plane, nominal shape, metres.
    reach: f64,
    /// The smallest shrink scale.
    smallest: f64,
    r_q: f64,
    margin: f64,
    /// The column, when eq. 7 allows one (its ends within d_com).
    column: Option<FormationShape>,
}

impl Shape {
    fn new(mission: &Mission, margin: f64) -> Self {
        let f = &mission.formation;
        let reach = f.slots.iter().map(|o| o.xy().norm()).fold(0.0, f64::max);
        let closest = min_pair_distance(&f.slots);
        let smallest = if closest.is_finite() && closest > 0.0 {
            ((f.closest_pair() + SQUEEZE_SPACING_MARGIN) / closest).min(1.0)
        } else {
            0.0
        };
        let spacing = column_spacing(f);
        let gaps = f.slots.len().saturating_sub(1) as f64;
        let column = (f.slots.len() > 1 && gaps * spacing <= f.comm_range)
            .then_some(FormationShape::Alignment { spacing });
        Shape {
            reach,
            smallest,
            r_q: f.least_clearance(),
            margin,
            column,
        }
    }

    /// Clearance the centroid needs in each layer (∞: the layer is closed).
    fn need(&self) -> [f64; LAYERS] {
        [
            self.reach + self.r_q + self.margin,
            self.smallest * self.reach + self.r_q + self.margin,
            if self.column.is_some() {
                self.r_q + self.margin
            } else {
                f64::INFINITY
            },
        ]
    }

    /// Whether the smallest shrink keeps every UAV clear at a centroid
    /// `clearance` from the nearest obstacle and `inside` from the bounds.
    fn shrink_fits(&self, clearance: f64, inside: f64) -> bool {
        let reach = self.smallest * self.reach;
        clearance >= reach + self.r_q + self.margin - 1e-9 && inside >= reach - 1e-9
    }

    /// The scale that keeps every UAV clear at a centroid `clearance` from
    /// the nearest obstacle and `inside` from the nearest side of the bounds.
    fn scale_for(&self, clearance: f64, inside: f64) -> f64 {
        if self.reach <= 0.0 {
            return 1.0;
        }
        ((clearance - self.r_q - self.margin) / self.reach)
            .min(inside / self.reach)
            .clamp(self.smallest, 1.0)
    }
}

/// The obstacles in the way of a formation flying anywhere in `span`, as
/// discs (see [`levels::blocks`]).
fn blocking(mission: &Mission, span: [f64; 2]) -> Vec<(usize, Footprint)> {
    mission
        .obstacles
        .iter()
        .enumerate()
        .filter(|(_, o)| levels::blocks(mission, o, span))
        .map(|(k, o)| (k, o.outline()))
        .collect()
}

/// Cost of a metre climbed or descended between levels, in metres of
/// route: a climb is slower than level flight (PX4's climb and descent
/// rates are below its horizontal speed) and the paper's paths keep their
/// altitude where they can.
const CLIMB_COST: f64 = 2.0;

/// Half the horizontal run of a climb between two levels `dz` apart: the
/// ramp is flown within this of the cell the search climbed at, so that
/// cell keeps this much more clearance over every altitude between. At
/// most 2.5 m, but never under a cell and a half: on a large site's coarse
/// cells (over 1.67 m) the cell wins (a `clamp` with its bounds crossed
/// aborted the run there).
fn ramp(dz: f64, cell: f64) -> f64 {
    (0.5 * dz.abs()).min(2.5).max(1.5 * cell)
}

/// One level of the search: what stands in the way there.
pub(crate) struct Level {
    /// The obstacles in the way (mission index, disc) and their discs alone.
    obstacles: Vec<(usize, Footprint)>,
    discs: Vec<Footprint>,
    /// The clearance field to them.
    field: Field,
}

/// The grid the route stage searches and what it knows of every cell: the
/// clearance field at every level, and in which modes (a layer at a level)
/// each cell may be entered and where the formation may climb.
pub(crate) struct Site {
    shape: Shape,
    /// The clearance the centroid needs in each layer.
    need: [f64; LAYERS],
    levels: Levels,
    at: Vec<Level>,
    /// Per cell, the search's bits (`search::bit`, `search::climb_bit`).
    open: Vec<u64>,
    /// The rectangle searched: the bounds, or `focus`'s window. Every grid
    /// of the site covers it, so their cells are the search's.
    area: Area,
}

impl Site {
    /// The grid's geometry (every level's field shares it).
    fn field(&self) -> &Field {
        &self.at[0].field
    }

    /// The squeezed regions `corridor` passes, as the paths the swarm tries
    /// read them (`None` when it never squeezes).
    fn squeeze_of(&self, corridor: &Corridor, mission: &Mission) -> Option<Arc<SqueezeMap>> {
        squeeze_map(self, corridor, mission)
    }

    /// The site searched at `levels` for a route with `stops` stops (the
    /// passes and the crossings asked for by name).
    fn new(
        mission: &Mission,
        builder: &PathBuilder,
        margin: f64,
        levels: Levels,
        stops: usize,
        searched: Area,
    ) -> Self {
        let shape = Shape::new(mission, margin);
        let need = shape.need();
        let b = &mission.bounds;
        let area = (searched[0][1] - searched[0][0]) * (searched[1][1] - searched[1][0]);
        // The search holds a state per cell, layer, level and stage: the grid
        // shares its states among the stages (one more than the stops) and
        // the levels, never finer than 0.2 m. A large site gets
        // coarse cells rather than gigabytes (the refusal then speaks for
        // that resolution).

        let budget = if levels.is_flat() {
            MAX_STATES
        } else {
            MAX_STACKED_STATES
        };
        let cells = (budget / (LAYERS * levels.len() * (stops + 1)) as f64).min(MAX_CELLS);
        let cell = (area / cells).sqrt().max(FINEST_CELL);
        let ramps: Vec<f64> = (0..levels.len().saturating_sub(1))
            .map(|pair| {
                let [lo, hi] = levels.hull(pair);
                ramp(hi - lo, cell)
            })
            .collect();
        let cap = need[0] + 2.0 * cell;
        let at: Vec<Level> = (0..levels.len())
            .map(|l| {
                let obstacles = blocking(mission, levels.span(l));
                let discs: Vec<Footprint> = obstacles.iter().map(|(_, d)| d.clone()).collect();
                let field = Field::new(searched, &discs, cell, cap);
                Level {
                    obstacles,
                    discs,
                    field,
                }
            })
            .collect();
        let boxes = [
            [dx_dy(builder)[0], dx_dy(builder)[1]],
            [
                shrink(b.x, shape.smallest * shape.reach),
                shrink(b.y, shape.smallest * shape.reach),
            ],
            [b.x, b.y],
        ];
        let inside = |p: Point2<f64>, [x, y]: [[f64; 2]; 2]| {
            x[0] <= p.x && p.x <= x[1] && y[0] <= p.y && p.y <= y[1]
        };
        // Half a cell's diagonal of slack: a straight between two open cell
        // centres stays clear in between.
        let slack = cell * std::f64::consts::FRAC_1_SQRT_2;
        let geometry = &at[0].field;
        let mut open: Vec<u64> = (0..geometry.len())
            .map(|i| {
                let p = geometry.center(i);
                let mut bits = 0;
                for (l, level) in at.iter().enumerate() {
                    let c = level.field.clearance(i);
                    for layer in 0..LAYERS {
                        if c >= need[layer] + slack && inside(p, boxes[layer]) {
                            bits |= bit(l, layer);
                        }
                    }
                }
                bits
            })
            .collect();
        // Where the formation may climb between two levels: every altitude
        // between them clear by the layer's need and the ramp's run.
        for (pair, run) in ramps.iter().enumerate() {
            let discs: Vec<Footprint> = blocking(mission, levels.hull(pair))
                .into_iter()
                .map(|(_, d)| d)
                .collect();
            let hull = Field::new(searched, &discs, cell, cap + run);
            for (i, bits) in open.iter_mut().enumerate() {
                let (c, p) = (hull.clearance(i), hull.center(i));
                for layer in 0..LAYERS {
                    if c >= need[layer] + slack + run && inside(p, boxes[layer]) {
                        *bits |= climb_bit(pair, layer);
                    }
                }
            }
        }
        // Round the start and the goal the disc model is too strict: validation
        // has checked the formation fits there; let the centroid leave them
        // wherever it is itself clear, at the level it is at there.
        let (start, goal) = (mission.route.start.xy(), mission.route.goal.xy());
        for (end, l) in [(start, levels.start), (goal, levels.goal)] {
            let around = shape.reach + cell;
            let field = &at[l].field;
            for i in field.cells_within(end, around) {
                let p = field.center(i);
                if (p - end).norm() <= around
                    && field.clearance(i) >= shape.r_q + margin
                    && b.contains_xy(&p)
                {
                    open[i] |= bit(l, 0) | bit(l, 1) | bit(l, 2);
                }
            }
        }
        Site {
            shape,
            need,
            levels,
            at,
            area: searched,
            open,
        }
    }

    /// Cost of each climb between neighbouring levels, metres of route.
    fn climb_costs(&self) -> Vec<f64> {
        (0..self.levels.len().saturating_sub(1))
            .map(|pair| {
                let [lo, hi] = self.levels.hull(pair);
                CLIMB_COST * (hi - lo) + self.field().cell()
            })
            .collect()
    }

    /// Where a straight leaving `p` (a point the formation may stand at,
    /// clear by exact geometry: a crossing's end) along `out` meets the
    /// grid at `level`: `p`'s own cell when it is open (layer 0: the jump
    /// as before), else [`Site::landing_from`]. At coarse cells a
    /// crossing's end may lie in a cell whose centre is near the posts it
    /// passes: without the landing the grid would decide the passage
    /// closed (issue 51).
    fn landing(
        &self,
        level: usize,
        p: Point2<f64>,
        out: nalgebra::Vector2<f64>,
    ) -> Option<(usize, Point2<f64>, usize)> {
        if !self.field().contains(p) {
            return None;
        }
        let here = self.field().index_of(p);
        if (0..LAYERS).any(|l| self.open[here] & bit(level, l) != 0) {
            return Some((here, p, 0));
        }
        self.landing_from(level, p, out, 0)
    }

    /// The first point q on the straight from `p` along `out` (at a third
    /// of a cell's steps, out to [`LANDING_CELLS`] cells or
    /// [`LANDING_METRES`], whichever is farther) whose cell is open in a
    /// layer no wider than `widest` whose need the straight p → q keeps
    /// from every obstacle in the way (exact): its cell, q and that layer.
    fn landing_from(
        &self,
        level: usize,
        p: Point2<f64>,
        out: nalgebra::Vector2<f64>,
        widest: usize,
    ) -> Option<(usize, Point2<f64>, usize)> {
        let field = self.field();
        let discs = &self.at[level].discs;
        let step = field.cell() / 3.0;
        let steps = (3 * LANDING_CELLS).max((LANDING_METRES / step).ceil() as usize);
        let out = out / out.norm().max(1e-12);
        // Only the obstacles the straight could come near.
        let reach = step * steps as f64 + self.need[0];
        let near: Vec<&Footprint> = discs
            .iter()
            .filter(|d| (d.center() - p).norm() - d.radius() < reach)
            .collect();
        for k in 1..=steps {
            let q = p + out * (step * k as f64);
            let cell = field.index_of(q);
            if !field.contains(q) {
                return None;
            }
            let layer = (widest..LAYERS).find(|&l| {
                self.open[cell] & bit(level, l) != 0
                    && near
                        .iter()
                        .all(|d| d.segment_distance(&p, &q) >= self.need[l] - 1e-9)
            });
            if let Some(layer) = layer {
                return Some((cell, q, layer));
            }
            // The straight itself closed: no landing on it.
            if near
                .iter()
                .any(|d| d.segment_distance(&p, &q) < self.need[LAYERS - 1] - 1e-9)
            {
                return None;
            }
        }
        None
    }

    /// The half run of the ramp of a climb between level `pair` and the one above.
    fn ramp(&self, pair: usize) -> f64 {
        let [lo, hi] = self.levels.hull(pair);
        ramp(hi - lo, self.field().cell())
    }
}

/// Whether a pass along the straight `ends` round obstacle `k` (mission
/// index) is open at `level`: every cell on it open in the nominal layer, or
/// nearest to `k` itself and clear of it by r_Q (the pass flies close to its
/// obstacle on purpose), and both ends open.
fn pass_clear(site: &Site, level: usize, k: usize, ends: [Point2<f64>; 2]) -> bool {
    let Level {
        field, obstacles, ..
    } = &site.at[level];
    let open = &site.open;
    let obstacle = obstacles.iter().position(|(o, _)| *o == k);
    let nominal = bit(level, 0);
    if !ends.iter().all(|p| field.contains(*p)) {
        return false;
    }
    field.cells_along(ends[0], ends[1]).all(|c| {
        open[c] & nominal != 0
            || (field.nearest_disc(c) == obstacle && field.clearance(c) > site.shape.r_q)
    }) && ends.iter().all(|p| open[field.index_of(*p)] & nominal != 0)
}

/// The route stage for `mission`: the cheapest corridor, or why none exists.
///
/// First at the altitudes between the start's and the goal's (flat); when
/// that finds no corridor, again with the formation free to climb over (or
/// descend under) what closes the way, level by level (`levels`).
pub fn find(
    mission: &Mission,
    builder: &PathBuilder,
    iwps: &[Iwp],
    margin: f64,
) -> Result<Corridor, Blocked> {
    let b = &mission.bounds;
    let whole = find_in(mission, builder, iwps, margin, [b.x, b.y]);
    if whole.is_ok() {
        return whole;
    }
    let Some(window) = focus(mission, builder, iwps) else {
        return whole;
    };
    find_in(mission, builder, iwps, margin, window).or_else(|_| {
        whole.map_err(|mut blocked| {
            let [x, y] = window;
            blocked.reason.push_str(&format!(
                "; searched again at finer cells over x {:.0} to {:.0} m, y {:.0} to {:.0} m (round \
                 the start, the goal and every gap narrower than the formation): no corridor there \
                 either",
                x[0], x[1], y[0], y[1]
            ));
            blocked
        })
    })
}

/// A rectangle of the x-y plane: [x range, y range], metres.
type Area = [[f64; 2]; 2];

/// Metres the focused window reaches beyond what it must hold.
const FOCUS_PAD: f64 = 20.0;

/// Where to look again, at finer cells, when a large site's coarse grid
/// found no corridor: the box round the start, the goal, the user's via
/// points, the inspected obstacles and every gap eq. 9 places an IWP at
/// (the passages narrower than the formation, where a coarse cell may close
/// a way that bends between three obstacles), `FOCUS_PAD` beyond and
/// within the bounds. `None` when the site is already fine or the window
/// would not be much smaller than the site (issue 51: two rows in series
/// on a 1 km site, the way bending along 3.5 m between them, closed at
/// 2.5 m cells and open at 0.75 m).
fn focus(mission: &Mission, builder: &PathBuilder, iwps: &[Iwp]) -> Option<Area> {
    let b = &mission.bounds;
    let size = |a: &Area| (a[0][1] - a[0][0]) * (a[1][1] - a[1][0]);
    let whole = [b.x, b.y];
    if (size(&whole) / MAX_CELLS).sqrt() <= 1.5 * FINEST_CELL {
        return None;
    }
    let f = &mission.formation;
    let pad = FOCUS_PAD + f.radius();
    let mut held: Vec<(Point2<f64>, f64)> = vec![
        (mission.route.start.xy(), pad),
        (mission.route.goal.xy(), pad),
    ];
    held.extend(builder.via_points().iter().map(|(_, p)| (p.xy(), pad)));
    held.extend(iwps.iter().map(|i| (i.position, pad)));
    let around = f.surface_distance[1] + pad;
    held.extend(
        mission
            .obstacles
            .iter()
            .filter(|o| o.inspect)
            .map(|o| (o.center, o.radius + around)),
    );
    let mut window = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
    for (p, reach) in held {
        for (axis, range) in window.iter_mut().enumerate() {
            range[0] = range[0].min(p[axis] - reach).max(whole[axis][0]);
            range[1] = range[1].max(p[axis] + reach).min(whole[axis][1]);
        }
    }
    (size(&window) <= size(&whole) / 4.0).then_some(window)
}

/// The route search over `area` (the whole site, or [`focus`]'s window):
/// flat, then over levels.
fn find_in(
    mission: &Mission,
    builder: &PathBuilder,
    iwps: &[Iwp],
    margin: f64,
    area: Area,
) -> Result<Corridor, Blocked> {
    let flat = find_at(mission, builder, iwps, margin, Levels::flat(mission), area);
    let Err(blocked) = flat else {
        return flat;
    };
    let z_box = builder.decoding_box()[2];
    let levels = Levels::stacked(
        mission,
        z_box,
        &builder.pass_altitudes(),
        &blocked.obstacles,
    );
    if levels.len() < 2 {
        return Err(with_altitudes(mission, blocked, z_box));
    }
    find_at(mission, builder, iwps, margin, levels, area).map_err(|stacked| {
        // The stacked search names what closes the way at every altitude it
        // tried; when nothing does (the way closes only in combination), the
        // flat search's chain is the one to name.
        let named = if stacked.obstacles.is_empty() {
            blocked
        } else {
            stacked
        };
        with_altitudes(mission, named, z_box)
    })
}

/// `blocked`'s reason with what the band leaves over and under the
/// obstacles it names: the altitude the formation would need to pass over
/// (under) them, and why it cannot.
fn with_altitudes(mission: &Mission, blocked: Blocked, z_box: [f64; 2]) -> Blocked {
    let members = &blocked.obstacles;
    if members.is_empty() {
        return blocked;
    }
    let obstacles = &mission.obstacles;
    let top = members
        .iter()
        .map(|&k| obstacles[k].height)
        .fold(f64::NEG_INFINITY, f64::max);
    let base = members
        .iter()
        .map(|&k| obstacles[k].base)
        .fold(f64::INFINITY, f64::min);
    let reach = if base > 0.0 {
        format!(" from {base:.1} m to {top:.1} m")
    } else {
        format!(" from the ground to {top:.1} m")
    };
    let over = match members.iter().find(|&&k| !obstacles[k].overfly) {
        Some(&k) => format!("'{}' may not be flown over", obstacles[k].name),
        None => {
            let z = members
                .iter()
                .map(|&k| mission.passing_altitudes(&obstacles[k])[0])
                .fold(f64::NEG_INFINITY, f64::max);
            if z > z_box[1] {
                format!(
                    "over them the formation's centroid would fly at {z:.1} m, above the {:.1} m the band's ceiling leaves it",
                    z_box[1]
                )
            } else {
                format!("climbing over them (at {z:.1} m) does not open the way")
            }
        }
    };
    let under = if base <= 0.0 {
        String::new()
    } else {
        let z = members
            .iter()
            .map(|&k| mission.passing_altitudes(&obstacles[k])[1])
            .fold(f64::INFINITY, f64::min);
        if z < z_box[0] {
            format!(
                "; under them it would fly at {z:.1} m, below the {:.1} m the band's floor leaves it",
                z_box[0]
            )
        } else {
            format!("; descending under them (at {z:.1} m) does not open the way")
        }
    };
    Blocked {
        reason: format!("{}; they stand{reach}: {over}{under}", blocked.reason),
        obstacles: blocked.obstacles,
        passages: blocked.passages,
        tried: blocked.tried,
    }
}

/// The route search at `levels` (see [`find`]).
///
/// Long (~150 lines): the stage in order (stops, the site, crossing, pass and via jumps, the guided
/// search, the corridor and its squeeze map), each step reading the one before.
fn find_at(
    mission: &Mission,
    builder: &PathBuilder,
    iwps: &[Iwp],
    margin: f64,
    levels: Levels,
    area: Area,
) -> Result<Corridor, Blocked> {
    let (start, goal) = (mission.route.start.xy(), mission.route.goal.xy());
    let overlaps = |a: [f64; 2], b: [f64; 2]| a[0] <= b[1] + 1e-9 && b[0] <= a[1] + 1e-9;

    // The stops, in order along start → goal: every inspection pass, and
    // every crossing the user asked for by name (a `[[reconfiguration.
    // waypoints]]` entry): the route must take those; the others it may.
    let crossings = builder.crossings();
    let windows = builder.crossing_windows();
    let requested = requested_crossings(mission, builder, iwps);
    let order = stop_order(builder, &crossings, &requested, start, goal);
    let site = Site::new(mission, builder, margin, levels, order.len(), area);
    let field = site.field();
    let levels = &site.levels;
    let stage_of_crossing = |c: usize| order.iter().position(|s| *s == Stop::Crossing(c));
    let (mut jumps, landed) = crossing_jumps(&site, &crossings, &windows, &stage_of_crossing);
    // The user's via points: a stop of no length at the point's cell, at
    // the level of its altitude (any, flat), in whatever layer it is reached.
    let via_points = builder.via_points();
    let mut via_jumps = Vec::new();
    for (stage, stop) in order.iter().enumerate() {
        let Stop::Via(k) = *stop else { continue };
        let p = via_points[k].1;
        let at: Vec<usize> = (0..levels.len())
            .filter(|&l| {
                levels.is_flat() || {
                    let [lo, hi] = levels.span(l);
                    lo - 1e-9 <= p.z && p.z <= hi + 1e-9
                }
            })
            .collect();
        let at = if at.is_empty() {
            (0..levels.len()).collect()
        } else {
            at
        };
        for level in at {
            via_jumps.push((stage, level, p.xy(), k));
        }
    }
    let pass_altitudes = builder.pass_altitudes();
    let mut candidates: Vec<(usize, f64, bool, [Point2<f64>; 2])> = Vec::new();
    for (stage, stop) in order.iter().enumerate() {
        let Stop::Pass(i) = *stop else { continue };
        let (k, _) = builder.inspections()[i];
        // At the levels the pass may be flown at (the flat one: any).
        let at = (0..levels.len())
            .filter(|&l| levels.is_flat() || overlaps(pass_altitudes[i], levels.span(l)));
        for level in at {
            for j in 0..PASS_ANGLES {
                let phi = TAU * j as f64 / PASS_ANGLES as f64 - PI;
                for on_left in [true, false] {
                    let ends = builder.pass_ends(i, phi, on_left);
                    if pass_clear(&site, level, k, ends) {
                        jumps.push(Jump {
                            from: field.index_of(ends[0]),
                            to: field.index_of(ends[1]),
                            length: (ends[1] - ends[0]).norm(),
                            pass_at: Some(stage),
                            crossing: false,
                            tag: 2 * crossings.len() + candidates.len(),
                            level,
                            widest: 0,
                        });
                        candidates.push((i, phi, on_left, ends));
                    }
                }
            }
        }
    }

    let via_tag = 2 * crossings.len() + candidates.len();
    for &(stage, level, p, k) in via_jumps.iter().filter(|j| field.contains(j.2)) {
        let cell = field.index_of(p);
        jumps.push(Jump {
            from: cell,
            to: cell,
            length: 0.0,
            pass_at: Some(stage),
            crossing: true,
            tag: via_tag + k,
            level,
            widest: 0,
        });
    }
    // The gaps the grid may not resolve, each a straight of its own.
    let gap_tag = via_tag + via_points.len();
    let gap_ends = gaps::jumps(&site, mission, iwps, gap_tag, &mut jumps);
    let climb_cost = site.climb_costs();
    let graph = Graph {
        field,
        open: &site.open,
        jumps: &jumps,
        stages: order.len(),
        switch_cost: mission
            .reconfiguration
            .transition_distance
            .max(field.cell()),
        climb_cost: &climb_cost,
        start_level: levels.start,
        goal_level: levels.goal,
    };
    let (s, g) = (field.index_of(start), field.index_of(goal));
    let guide = Guide::new(&graph, g);
    let first_mode = levels.start * LAYERS;
    // A start the relaxation cannot leave needs no search.
    let guided = guide
        .bound(s, first_mode, 0)
        .and_then(|_| search::search(&graph, s, g, |c, m, st| guide.bound(c, m, st)).ok());
    let found = match guided {
        Some(steps) => Ok(steps),
        // No route. What the formation reaches, to say what closes the way:
        // a plain flood when not even the relaxation reaches the goal, else
        // the whole search without the guide's pruning.
        None => match search::unreachable(&graph, s, g) {
            Some(reached) => Err(reached),
            None => search::search(&graph, s, g, |_, _, _| Some(0.0)),
        },
    };
    let steps = match found {
        Ok(steps) => steps,
        Err(reached) => {
            let tried = search::tried(&graph, s, g, &reached);
            let blocked = explain(mission, iwps, builder, &site, &reached, &order);
            return Err(Blocked { tried, ..blocked });
        }
    };

    let points: Vec<Point2<f64>> = via_points.iter().map(|(_, p)| p.xy()).collect();
    let mut corridor = assemble(
        &site,
        &steps,
        [start, goal],
        &crossings,
        &landed,
        &candidates,
        &points,
        &gap_ends,
        builder.inspections().len(),
    );
    through_crossings(&site, builder, &mut corridor);
    corridor.squeeze = site.squeeze_of(&corridor, mission);
    corridor.coarse_cell = (field.cell() > 1.5 * FINEST_CELL).then_some(field.cell());
    Ok(corridor)
}

/// Each crossing's jumps, either way, at the levels where both sides of
/// its gap stand in the way, its ends carried out to meet the grid where
/// their own cells are shut (`Site::landing`); and where they were, by
/// (tag, level): the points the search's cells stand for.
#[allow(clippy::type_complexity)]
fn crossing_jumps(
    site: &Site,
    crossings: &[[Point2<f64>; 2]],
    windows: &[[f64; 2]],
    stage_of_crossing: &dyn Fn(usize) -> Option<usize>,
) -> (Vec<Jump>, HashMap<(usize, usize), [Point2<f64>; 2]>) {
    let overlaps = |a: [f64; 2], b: [f64; 2]| a[0] <= b[1] + 1e-9 && b[0] <= a[1] + 1e-9;
    let levels = &site.levels;
    let mut jumps = Vec::new();
    let mut landed = HashMap::new();
    for (c, [a, z]) in crossings.iter().enumerate() {
        for level in (0..levels.len()).filter(|&l| overlaps(windows[c], levels.span(l))) {
            let ends = [*a, *z];
            let (Some(la), Some(lz)) = (
                site.landing(level, *a, a - z),
                site.landing(level, *z, z - a),
            ) else {
                continue;
            };
            let lands = [la, lz];
            for direction in 0..2 {
                let (from, to) = (lands[direction], lands[1 - direction]);
                let tag = 2 * c + direction;
                let off = (from.1 - ends[direction]).norm() + (to.1 - ends[1 - direction]).norm();
                if off > 0.0 {
                    landed.insert((tag, level), [from.1, to.1]);
                }
                jumps.push(Jump {
                    from: from.0,
                    to: to.0,
                    length: (a - z).norm() + off,
                    pass_at: stage_of_crossing(c),
                    crossing: true,
                    tag,
                    level,
                    widest: from.2.max(to.2),
                });
            }
        }
    }
    (jumps, landed)
}

/// Why the search at `site`'s levels reached no corridor: the chain of
/// obstacles round what it reached (`blocked::explain`), among those in
/// the way at every level (for the flat search, its one level's).
fn explain(
    mission: &Mission,
    iwps: &[Iwp],
    builder: &PathBuilder,
    site: &Site,
    reached: &search::Reached,
    order: &[Stop],
) -> Blocked {
    let shape = &site.shape;
    // The narrowest layer's need: what nothing at all fits through.
    let (need, squeezed) = if shape.column.is_some() {
        (site.need[2], 0.0)
    } else {
        (site.need[1], shape.smallest * shape.reach)
    };
    let everywhere;
    let (field, obstacles) = if site.levels.len() == 1 {
        (&site.at[0].field, &site.at[0].obstacles)
    } else {
        // In the way at every level: nothing the search tried passes them.
        let kept: Vec<(usize, Footprint)> = site.at[0]
            .obstacles
            .iter()
            .filter(|(k, _)| {
                site.at
                    .iter()
                    .all(|l| l.obstacles.iter().any(|(o, _)| o == k))
            })
            .cloned()
            .collect();
        let discs: Vec<Footprint> = kept.iter().map(|(_, d)| d.clone()).collect();
        let geometry = site.field();
        everywhere = (
            Field::new(
                site.area,
                &discs,
                geometry.cell(),
                site.need[0] + 2.0 * geometry.cell(),
            ),
            kept,
        );
        (&everywhere.0, &everywhere.1)
    };
    blocked::explain(
        mission, iwps, field, obstacles, reached, order, builder, need, squeezed,
    )
}

/// The x and y ranges of the builder's decoding box (the nominal layer's).
fn dx_dy(builder: &PathBuilder) -> [[f64; 2]; 2] {
    let [x, y, _] = builder.decoding_box();
    [x, y]
}

/// Per crossing of the path builder: whether the user asked for it by name
/// (a `[[reconfiguration.waypoints]]` entry, or a gate of `[[route.via]]`),
/// which makes it a stop.
pub(super) fn requested_crossings(
    mission: &Mission,
    builder: &PathBuilder,
    iwps: &[Iwp],
) -> Vec<bool> {
    builder
        .crossing_iwps()
        .iter()
        .map(|&i| {
            let [a, b] = &iwps[i].between;
            iwps[i].gate.is_some() || mission.reconfiguration.choice(a, b).is_some()
        })
        .collect()
}

/// A stop the route must make, in order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// Inspection `i` of the path builder.
    Pass(usize),
    /// Crossing `c` of the path builder (a requested IWP, or a gate).
    Crossing(usize),
    /// The user's via point `k` (`PathBuilder::via_points`).
    Via(usize),
}

/// The inspections, the requested crossings (builder indices) and the via
/// points in the order they lie along start → goal, except that the user's
/// own vias (gates and points) keep the order of `[[route.via]]` among the
/// places they take.
fn stop_order(
    builder: &PathBuilder,
    crossings: &[[Point2<f64>; 2]],
    requested: &[bool],
    start: Point2<f64>,
    goal: Point2<f64>,
) -> Vec<Stop> {
    let axis = goal - start;
    let along = |p: Point2<f64>| (p - start).dot(&axis);
    let mut order: Vec<(Stop, f64)> = builder
        .inspections()
        .iter()
        .enumerate()
        .map(|(i, (_, c))| (Stop::Pass(i), along(*c)))
        .chain(
            crossings
                .iter()
                .enumerate()
                .filter(|(c, _)| requested[*c])
                .map(|(c, [a, z])| (Stop::Crossing(c), along(nalgebra::center(a, z)))),
        )
        .chain(
            builder
                .via_points()
                .iter()
                .enumerate()
                .map(|(k, (_, p))| (Stop::Via(k), along(p.xy()))),
        )
        .collect();
    order.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut order: Vec<Stop> = order.into_iter().map(|(s, _)| s).collect();
    // The user's vias in the file's order, in the places they took.
    let mut user: Vec<(usize, Stop)> = builder
        .via_gates()
        .into_iter()
        .map(|(k, c)| (k, Stop::Crossing(c)))
        .chain(
            builder
                .via_points()
                .iter()
                .enumerate()
                .map(|(j, (k, _))| (*k, Stop::Via(j))),
        )
        .collect();
    user.sort_by_key(|(k, _)| *k);
    let is_user = |s: &Stop| user.iter().any(|(_, u)| u == s);
    let places: Vec<usize> = (0..order.len()).filter(|&i| is_user(&order[i])).collect();
    for (place, (_, stop)) in places.into_iter().zip(user) {
        order[place] = stop;
    }
    order
}

fn shrink([lo, hi]: [f64; 2], by: f64) -> [f64; 2] {
    if hi - lo > 2.0 * by {
        [lo + by, hi - by]
    } else {
        let mid = (lo + hi) / 2.0;
        [mid, mid]
    }
}

#[cfg(test)]
mod tests;
