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
//! formation through. The grid resolution makes the search complete up to
//! the cell size; the disc model makes it conservative (a plan the route
//! stage finds keeps every UAV clear; a formation turned to just the right
//! heading might squeeze through where the disc model says it cannot).

mod blocked;
pub mod field;
mod guide;
mod reuse;
mod search;

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use nalgebra::Point2;
use serde::{Deserialize, Serialize};

pub use reuse::reuse;

use self::field::{Disc, Field};
use self::guide::Guide;
use self::search::{Graph, Jump, LAYERS, Step, bit};
use super::iwp::{Iwp, Shape as FormationShape, column_spacing, min_pair_distance};
use super::path::{PathBuilder, SqueezeMap};
use crate::mission::{Mission, Obstacle};

/// Angles tried round each inspected obstacle.
const PASS_ANGLES: usize = 16;
/// Cells the grid has at most (per layer and stage).
const MAX_CELLS: f64 = 160_000.0;
/// The finest grid, metres: the search is complete up to this cell size.
pub(crate) const FINEST_CELL: f64 = 0.2;
/// Search states (cell × layer × stage) at most: about 16 bytes each.
const MAX_STATES: f64 = 2_000_000.0;
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
    /// The centroid altitude the corridor is flown at, when the search had
    /// to climb (or descend) off the start's and goal's altitudes to pass
    /// over (under) what closes the way there; `None`: between them.
    #[serde(default)]
    pub cruise: Option<f64>,
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
            && self.cruise == other.cruise
    }
}

/// Why no corridor exists.
#[derive(Debug, Clone, PartialEq)]
pub struct Blocked {
    /// In words, naming the obstacles and the widths involved.
    pub reason: String,
    /// The obstacles that close the way (indices into `mission.obstacles`).
    pub obstacles: Vec<usize>,
}

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

/// Whether the formation, at the altitudes the seeded corridor flies
/// (between the start's and the goal's, in the band), passes over
/// obstacle `o` or under it: its lowest UAV clears the top, or its highest
/// the base, by r_Q + the safety margin + the cost's clearance margin.
///
/// The θ-PSO paper's obstacles are cylinders of height z_k and its paths
/// 3-D; the cost (eq. 4 above and below a cylinder) and verification
/// measure to the top and bottom discs. The route stage is 2-D: an
/// obstacle the formation passes over or under as it flies is left out of
/// its search, so a gapless wall of 9 m posts is no wall to a formation at
/// 10 m, nor a deck 14 m up. One it would have to climb over is still kept
/// out, as is one marked `overfly = false`.
///
/// With a `cruise` altitude the corridor is flown at that altitude instead.
pub fn passed_by_altitude(mission: &Mission, o: &Obstacle, cruise: Option<f64>) -> bool {
    let [over, under] = pass_altitudes(mission, o);
    let (low, high) = cruise.map_or_else(|| seeded_altitudes(mission), |z| (z, z));
    over <= low || high <= under
}

/// The lower and the higher of the start's and the goal's altitudes, in
/// the band: the altitudes a corridor between them flies.
fn seeded_altitudes(mission: &Mission) -> (f64, f64) {
    let z = mission.bounds.z;
    let band = |v: f64| v.clamp(z[0], z[1].max(z[0]));
    let (start, goal) = (mission.route.start.z, mission.route.goal.z);
    (band(start.min(goal)), band(start.max(goal)))
}

/// The lowest centroid altitude that passes over `o` (its lowest UAV r_Q +
/// margins above the top) and the highest that passes under it.
fn pass_altitudes(mission: &Mission, o: &Obstacle) -> [f64; 2] {
    let f = &mission.formation;
    let below = f.slots.iter().map(|s| -s.z).fold(0.0, f64::max);
    let above = f.slots.iter().map(|s| s.z).fold(0.0, f64::max);
    let clearance = f.least_clearance() + mission.theta_pso.clearance_margin.max(0.0);
    [o.top() + clearance + below, o.base - clearance - above]
}

/// Altitudes to search at when no corridor exists between the start's and
/// the goal's: those that pass over (then under) more of what is in the
/// way there, inside the band the centroid may take (`z_box`), from the
/// nearest; at most [`MAX_CRUISE_TRIES`], the one passing over (under) all
/// of them among them.
fn cruise_altitudes(mission: &Mission, z_box: [f64; 2]) -> Vec<f64> {
    let (low, high) = seeded_altitudes(mission);
    let in_way: Vec<[f64; 2]> = mission
        .obstacles
        .iter()
        .filter(|o| o.within(mission.bounds.z) && !passed_by_altitude(mission, o, None))
        .map(|o| pass_altitudes(mission, o))
        .collect();
    // Up to half the tries among `v`, nearest first, at its thirds, the last
    // being the largest (for `under`, negated: the lowest, under all).
    let pick = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() < 0.05);
        let n = v.len();
        let per = MAX_CRUISE_TRIES / 2;
        let mut chosen: Vec<f64> = (1..=per)
            .filter_map(|i| v.get((n * i).div_ceil(per).max(1) - 1).copied())
            .collect();
        chosen.dedup();
        chosen
    };
    let over = pick(
        in_way
            .iter()
            .map(|[o, _]| *o)
            .filter(|z| *z > high && *z <= z_box[1])
            .collect(),
    );
    let under = pick(
        in_way
            .iter()
            .map(|[_, u]| -*u)
            .filter(|z| -*z < low && -*z >= z_box[0])
            .collect(),
    );
    over.into_iter()
        .chain(under.into_iter().map(|z| -z))
        .collect()
}

/// Most altitudes the route stage tries off the start's and goal's.
const MAX_CRUISE_TRIES: usize = 6;

/// The obstacles a formation in the band cannot fly over or under, as
/// discs (see [`passed_by_altitude`]).
fn blocking(mission: &Mission, cruise: Option<f64>) -> Vec<(usize, Disc)> {
    let z = mission.bounds.z;
    mission
        .obstacles
        .iter()
        .enumerate()
        .filter(|(_, o)| o.within(z) && !passed_by_altitude(mission, o, cruise))
        .map(|(k, o)| {
            (
                k,
                Disc {
                    center: o.center,
                    radius: o.radius,
                    polygon: (!o.footprint.is_empty()).then(|| o.footprint.as_slice().into()),
                },
            )
        })
        .collect()
}

/// The grid the route stage searches and what it knows of every cell: the
/// clearance field, and in which layers each cell may be entered.
pub(crate) struct Site {
    shape: Shape,
    /// The clearance the centroid needs in each layer.
    need: [f64; LAYERS],
    /// The obstacles in the way (mission index, disc) and their discs alone.
    obstacles: Vec<(usize, Disc)>,
    discs: Vec<Disc>,
    field: Field,
    /// Per cell, one bit per layer it may be entered in.
    open: Vec<u8>,
}

impl Site {
    /// The squeezed regions `corridor` passes, as the paths the swarm tries
    /// read them (`None` when it never squeezes).
    fn squeeze_of(&self, corridor: &Corridor, mission: &Mission) -> Option<Arc<SqueezeMap>> {
        squeeze_map(
            &self.field,
            &self.open,
            corridor,
            &self.shape,
            mission,
            &self.discs,
        )
        .map(|mut map| {
            map.obstacle_of = self.obstacles.iter().map(|(k, d)| (*k, d.center)).collect();
            Arc::new(map)
        })
    }

    fn new(mission: &Mission, builder: &PathBuilder, margin: f64, cruise: Option<f64>) -> Self {
        let shape = Shape::new(mission, margin);
        let need = shape.need();
        let b = &mission.bounds;
        let area = (b.x[1] - b.x[0]) * (b.y[1] - b.y[0]);
        // The search holds a state per cell, layer and stage: the grid shares
        // MAX_STATES among the stages (a stop per pass and requested crossing),
        // never finer than 0.2 m. A large site gets coarse cells rather than
        // gigabytes (the refusal then speaks for that resolution).
        let stops = builder.inspections().len() + builder.crossing_iwps().len();
        let cells = (MAX_STATES / (LAYERS * (stops + 1)) as f64).min(MAX_CELLS);
        let cell = (area / cells).sqrt().max(FINEST_CELL);
        let obstacles = blocking(mission, cruise);
        let discs: Vec<Disc> = obstacles.iter().map(|(_, d)| d.clone()).collect();
        let field = Field::new([b.x, b.y], &discs, cell, need[0] + 2.0 * cell);
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
        let (start, goal) = (mission.route.start.xy(), mission.route.goal.xy());
        let mut open: Vec<u8> = (0..field.len())
            .map(|i| {
                let (c, p) = (field.clearance(i), field.center(i));
                // Half a cell's diagonal of slack: a straight between two open
                // cell centres stays clear in between.
                let slack = cell * std::f64::consts::FRAC_1_SQRT_2;
                (0..LAYERS)
                    .filter(|&l| c >= need[l] + slack && inside(p, boxes[l]))
                    .fold(0, |bits, l| bits | bit(l))
            })
            .collect();
        // Round the start and the goal the disc model is too strict: validation
        // has checked the formation fits there; let the centroid leave them
        // wherever it is itself clear.
        for end in [start, goal] {
            let around = shape.reach + cell;
            for i in field.cells_within(end, around) {
                let p = field.center(i);
                if (p - end).norm() <= around
                    && field.clearance(i) >= shape.r_q + margin
                    && b.contains_xy(&p)
                {
                    open[i] |= bit(0) | bit(1) | bit(2);
                }
            }
        }
        Site {
            shape,
            need,
            obstacles,
            discs,
            field,
            open,
        }
    }
}

/// Whether a pass along the straight `ends` round obstacle `k` (mission
/// index) is open: every cell on it open in the nominal layer, or nearest to
/// `k` itself and clear of it by r_Q (the pass flies close to its obstacle
/// on purpose), and both ends open.
fn pass_clear(
    field: &Field,
    open: &[u8],
    obstacles: &[(usize, Disc)],
    r_q: f64,
    k: usize,
    ends: [Point2<f64>; 2],
) -> bool {
    let obstacle = obstacles.iter().position(|(o, _)| *o == k);
    field.cells_along(ends[0], ends[1]).all(|c| {
        open[c] & bit(0) != 0 || (field.nearest_disc(c) == obstacle && field.clearance(c) > r_q)
    }) && ends.iter().all(|p| open[field.index_of(*p)] & bit(0) != 0)
}

/// The route stage for `mission`: the cheapest corridor, or why none exists.
///
/// Long (~170 lines): the stage in order (grid, open layers, stops, jumps, search, corridor, squeeze map), each step reading the one before.
pub fn find(
    mission: &Mission,
    builder: &PathBuilder,
    iwps: &[Iwp],
    margin: f64,
) -> Result<Corridor, Blocked> {
    let flat = find_at(mission, builder, iwps, margin, None);
    let Err(blocked) = flat else {
        return flat;
    };
    // Closed between the start's and the goal's altitudes: climb over (or
    // descend under) what closes it, when the band leaves room.
    for z in cruise_altitudes(mission, builder.decoding_box()[2]) {
        if let Ok(corridor) = find_at(mission, builder, iwps, margin, Some(z)) {
            return Ok(corridor);
        }
    }
    Err(blocked)
}

/// The route search with the corridor flown at `cruise` (see [`find`]).
fn find_at(
    mission: &Mission,
    builder: &PathBuilder,
    iwps: &[Iwp],
    margin: f64,
    cruise: Option<f64>,
) -> Result<Corridor, Blocked> {
    let site = Site::new(mission, builder, margin, cruise);
    let Site {
        shape,
        need,
        obstacles,
        field,
        open,
        ..
    } = &site;
    let (start, goal) = (mission.route.start.xy(), mission.route.goal.xy());

    // The stops, in order along start → goal: every inspection pass, and
    // every crossing the user asked for by name (a `[[reconfiguration.
    // waypoints]]` entry): the route must take those; the others it may.
    let crossings = builder.crossings();
    let requested: Vec<bool> = builder
        .crossing_iwps()
        .iter()
        .map(|&i| {
            let [a, b] = &iwps[i].between;
            mission.reconfiguration.choice(a, b).is_some()
        })
        .collect();
    let order = stop_order(builder, &crossings, &requested, start, goal);
    let stage_of_crossing = |c: usize| order.iter().position(|s| *s == Stop::Crossing(c));
    let mut jumps = Vec::new();
    for (c, [a, z]) in crossings.iter().enumerate() {
        for (direction, (from, to)) in [(*a, *z), (*z, *a)].into_iter().enumerate() {
            jumps.push(Jump {
                from: field.index_of(from),
                to: field.index_of(to),
                length: (to - from).norm(),
                pass_at: stage_of_crossing(c),
                crossing: true,
                tag: 2 * c + direction,
            });
        }
    }
    let mut candidates: Vec<(usize, f64, bool, [Point2<f64>; 2])> = Vec::new();
    for (stage, stop) in order.iter().enumerate() {
        let Stop::Pass(i) = *stop else { continue };
        let (k, _) = builder.inspections()[i];
        for j in 0..PASS_ANGLES {
            let phi = TAU * j as f64 / PASS_ANGLES as f64 - PI;
            for on_left in [true, false] {
                let ends = builder.pass_ends(i, phi, on_left);
                if pass_clear(field, open, obstacles, shape.r_q, k, ends) {
                    jumps.push(Jump {
                        from: field.index_of(ends[0]),
                        to: field.index_of(ends[1]),
                        length: (ends[1] - ends[0]).norm(),
                        pass_at: Some(stage),
                        crossing: false,
                        tag: 2 * crossings.len() + candidates.len(),
                    });
                    candidates.push((i, phi, on_left, ends));
                }
            }
        }
    }

    let graph = Graph {
        field,
        open,
        jumps: &jumps,
        stages: order.len(),
        switch_cost: mission
            .reconfiguration
            .transition_distance
            .max(field.cell()),
    };
    let (s, g) = (field.index_of(start), field.index_of(goal));
    let guide = Guide::new(&graph, g);
    // A start the relaxation cannot leave needs no search.
    let guided = guide
        .bound(s, 0, 0)
        .and_then(|_| search::search(&graph, s, g, |c, l, st| guide.bound(c, l, st)).ok());
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
            return Err(blocked::explain(
                mission,
                iwps,
                field,
                obstacles,
                &reached,
                &order,
                builder,
                // The narrowest layer's: what nothing at all fits through.
                if shape.column.is_some() {
                    need[2]
                } else {
                    need[1]
                },
                if shape.column.is_some() {
                    0.0
                } else {
                    shape.smallest * shape.reach
                },
            ));
        }
    };

    let mut corridor = assemble(
        field,
        open,
        &steps,
        start,
        goal,
        &crossings,
        &candidates,
        builder.inspections().len(),
    );
    corridor.squeeze = site.squeeze_of(&corridor, mission);
    corridor.cruise = cruise;
    Ok(corridor)
}

/// The x and y ranges of the builder's decoding box (the nominal layer's).
fn dx_dy(builder: &PathBuilder) -> [[f64; 2]; 2] {
    let [x, y, _] = builder.decoding_box();
    [x, y]
}

/// A stop the route must make, in order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// Inspection `i` of the path builder.
    Pass(usize),
    /// Crossing `c` of the path builder (a requested IWP).
    Crossing(usize),
}

/// The inspections and the requested crossings (builder indices) in the
/// order they lie along start → goal.
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
        .collect();
    order.sort_by(|a, b| a.1.total_cmp(&b.1));
    order.into_iter().map(|(s, _)| s).collect()
}

fn shrink([lo, hi]: [f64; 2], by: f64) -> [f64; 2] {
    if hi - lo > 2.0 * by {
        [lo + by, hi - by]
    } else {
        let mid = (lo + hi) / 2.0;
        [mid, mid]
    }
}

/// The search's steps as a corridor: runs of cells pulled tight within their
/// layer, the jumps kept exact.
#[allow(clippy::too_many_arguments)]
fn assemble(
    field: &Field,
    open: &[u8],
    steps: &[Step],
    start: Point2<f64>,
    goal: Point2<f64>,
    crossings: &[[Point2<f64>; 2]],
    candidates: &[(usize, f64, bool, [Point2<f64>; 2])],
    inspections: usize,
) -> Corridor {
    let mut points = vec![start];
    let mut legs = Vec::new();
    let mut passes = vec![(0.0, true); inspections];
    // The current run: its points and layer.
    let mut run: Vec<Point2<f64>> = vec![start];
    let mut layer = 0;
    let flush = |run: &mut Vec<Point2<f64>>,
                 layer: usize,
                 points: &mut Vec<Point2<f64>>,
                 legs: &mut Vec<Leg>,
                 end: Point2<f64>| {
        run.push(end);
        let pulled = pull_tight(field, open, bit(layer), run);
        for p in pulled.into_iter().skip(1) {
            if (p - points[points.len() - 1]).norm() > 1e-9 {
                points.push(p);
                legs.push(Leg::Free { layer });
            }
        }
        run.clear();
    };
    for (k, step) in steps.iter().enumerate().skip(1) {
        match *step {
            Step::Cell { cell, layer: l } => {
                if l != layer {
                    // A change of layer: a vertex where the transition is.
                    flush(&mut run, layer, &mut points, &mut legs, field.center(cell));
                    run.push(field.center(cell));
                    layer = l;
                } else if k + 1 == steps.len() {
                    flush(&mut run, layer, &mut points, &mut legs, goal);
                } else {
                    run.push(field.center(cell));
                }
            }
            Step::Jump { tag, layer: l, .. } => {
                let (ends, leg) = if tag < 2 * crossings.len() {
                    let [a, z] = crossings[tag / 2];
                    let ends = if tag % 2 == 0 { [a, z] } else { [z, a] };
                    (ends, Leg::Crossing(tag / 2))
                } else {
                    let (i, phi, on_left, ends) = candidates[tag - 2 * crossings.len()];
                    passes[i] = (phi, on_left);
                    (ends, Leg::Pass(i))
                };
                flush(&mut run, layer, &mut points, &mut legs, ends[0]);
                points.push(ends[1]);
                legs.push(leg);
                run.push(ends[1]);
                layer = l;
                if k + 1 == steps.len() {
                    flush(&mut run, layer, &mut points, &mut legs, goal);
                }
            }
        }
    }
    if points.last() != Some(&goal) {
        flush(&mut run, layer, &mut points, &mut legs, goal);
    }
    let length = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    Corridor {
        points,
        legs,
        passes,
        length,
        cruise: None,
        squeeze: None,
    }
}

/// The run's points with every corner removed that a straight line on open
/// cells can skip: from each kept point, the farthest one in sight.
fn pull_tight(field: &Field, open: &[u8], bit: u8, run: &[Point2<f64>]) -> Vec<Point2<f64>> {
    if run.len() <= 2 {
        return run.to_vec();
    }
    let mut kept = vec![run[0]];
    let mut anchor = 0;
    while anchor + 1 < run.len() {
        // The farthest point of the run in sight (from the far end back).
        let next = ((anchor + 2)..run.len())
            .rev()
            .find(|&j| search::visible(field, open, bit, run[anchor], run[j]))
            .unwrap_or(anchor + 1);
        kept.push(run[next]);
        anchor = next;
    }
    kept
}

/// The squeezed regions the corridor passes: the connected cells where only
/// the shrink fits (flown at the scale the corridor needs through it) or
/// only the column does; `None` when the corridor never squeezes.
fn squeeze_map(
    field: &Field,
    open: &[u8],
    corridor: &Corridor,
    shape: &Shape,
    mission: &Mission,
    discs: &[Disc],
) -> Option<SqueezeMap> {
    // The narrowest layer a cell is open in, when it is not open in the nominal.
    let narrow = |i: usize| -> Option<usize> {
        (open[i] & bit(0) == 0)
            .then(|| (1..LAYERS).find(|&l| open[i] & bit(l) != 0))
            .flatten()
    };
    let mut region = vec![0u16; field.len()];
    let mut shapes: Vec<FormationShape> = Vec::new();
    for (leg, w) in corridor.legs.iter().zip(corridor.points.windows(2)) {
        if matches!(leg, Leg::Free { layer: 0 } | Leg::Pass(_)) {
            continue;
        }
        let (a, b) = (w[0], w[1]);
        let steps = (((b - a).norm() / (field.cell() / 3.0)).ceil() as usize).max(1);
        for k in 0..=steps {
            let p = a + (b - a) * (k as f64 / steps as f64);
            let i = field.index_of(p);
            let Some(layer) = narrow(i) else { continue };
            if region[i] == 0 {
                if shapes.len() >= u16::MAX as usize - 1 {
                    break;
                }
                shapes.push(match (layer, shape.column) {
                    (2, Some(column)) => column,
                    _ => FormationShape::Shrink { scale: 1.0 },
                });
                let label = shapes.len() as u16;
                flood(field, &mut region, i, label, &|j| narrow(j) == Some(layer));
            }
            let r = region[i] as usize - 1;
            if let FormationShape::Shrink { scale } = &mut shapes[r] {
                let fits = shape.scale_for(
                    field.clearance_at(p, discs),
                    mission
                        .bounds
                        .horizontal_margin(&nalgebra::Point3::new(p.x, p.y, 0.0)),
                );
                *scale = scale.min(fits);
            }
        }
    }
    if shapes.is_empty() {
        return None;
    }
    let free = chebyshev_distance(field, &region);
    let extent = region_extent(field, &region);
    Some(SqueezeMap {
        field: field.clone(),
        region,
        shapes,
        obstacle_of: Vec::new(),
        free,
        extent,
    })
}

/// The box holding every point whose cell is in a region.
fn region_extent(field: &Field, region: &[u16]) -> [Point2<f64>; 2] {
    // A point belongs to the cell whose centre is nearest: half a cell (and
    // a hair) beyond the region cells' centres.
    let pad = field.cell() * 0.5 + 1e-9;
    let mut extent = [
        Point2::new(f64::INFINITY, f64::INFINITY),
        Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    ];
    for (i, _) in region.iter().enumerate().filter(|(_, r)| **r > 0) {
        let c = field.center(i);
        extent[0] = extent[0].inf(&Point2::new(c.x - pad, c.y - pad));
        extent[1] = extent[1].sup(&Point2::new(c.x + pad, c.y + pad));
    }
    extent
}

/// Per cell, the Chebyshev distance in cells to the nearest cell with a
/// region (0 on one), capped at 255: the two passes of the 8-neighbour
/// chamfer (each from the neighbours already passed), exact for this metric.
fn chebyshev_distance(field: &Field, region: &[u16]) -> Vec<u8> {
    let (nx, ny) = field.size();
    let mut d: Vec<u8> = region
        .iter()
        .map(|&r| if r > 0 { 0 } else { 255 })
        .collect();
    let at = |d: &[u8], x: usize, y: usize| d[y * nx + x].saturating_add(1);
    for y in 0..ny {
        for x in 0..nx {
            let mut v = d[y * nx + x];
            if x > 0 {
                v = v.min(at(&d, x - 1, y));
            }
            if y > 0 {
                v = v.min(at(&d, x, y - 1));
                if x > 0 {
                    v = v.min(at(&d, x - 1, y - 1));
                }
                if x + 1 < nx {
                    v = v.min(at(&d, x + 1, y - 1));
                }
            }
            d[y * nx + x] = v;
        }
    }
    for y in (0..ny).rev() {
        for x in (0..nx).rev() {
            let mut v = d[y * nx + x];
            if x + 1 < nx {
                v = v.min(at(&d, x + 1, y));
            }
            if y + 1 < ny {
                v = v.min(at(&d, x, y + 1));
                if x + 1 < nx {
                    v = v.min(at(&d, x + 1, y + 1));
                }
                if x > 0 {
                    v = v.min(at(&d, x - 1, y + 1));
                }
            }
            d[y * nx + x] = v;
        }
    }
    d
}

/// Labels the connected narrow cells round `seed` with `label`.
fn flood(
    field: &Field,
    region: &mut [u16],
    seed: usize,
    label: u16,
    narrow: &dyn Fn(usize) -> bool,
) {
    let mut stack = vec![seed];
    region[seed] = label;
    while let Some(i) = stack.pop() {
        for j in field.neighbourhood(i) {
            if region[j] == 0 && narrow(j) {
                region[j] = label;
                stack.push(j);
            }
        }
    }
}

#[cfg(test)]
mod tests;
