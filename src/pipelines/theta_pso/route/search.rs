//! A* over the clearance field's cells, in three layers (the nominal shape,
//! the smallest shrink, the column), at one or more levels (altitudes, see
//! `levels`) and in stages (the inspection passes flown so far), with the
//! IWP crossings and the passes as edges of their own.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::Point2;

use super::field::{CellLists, Field};

/// The layers, widest first: the nominal shape, the smallest shrink, the
/// column (single file along the path).
pub const LAYERS: usize = 3;

/// The bit of `layer` at `level` in a cell's open bits.
pub const fn bit(level: usize, layer: usize) -> u64 {
    1 << (level * LAYERS + layer)
}

/// The bit saying the formation in `layer` may climb at a cell between
/// level `pair` and the one above (every altitude between them clear).
pub const fn climb_bit(pair: usize, layer: usize) -> u64 {
    1 << (CLIMBS + pair * LAYERS + layer)
}

/// Where the climb bits begin: the levels' bits fill the ones below.
const CLIMBS: usize = 32;

/// The bits of every level and layer (no climbs).
pub const LEVEL_BITS: u64 = (1 << CLIMBS) - 1;

/// A straight edge of its own: an IWP crossing (any layer, stage kept) or an
/// inspection pass (nominal layer, to the next stage).
#[derive(Debug, Clone, Copy)]
pub struct Jump {
    pub from: usize,
    pub to: usize,
    pub length: f64,
    /// `Some(stage)`: a stop of the route (a pass, or a crossing the user
    /// asked for) taken at that stage, to the next one.
    pub pass_at: Option<usize>,
    /// A crossing: flown in the layer it is entered in (a pass: nominal).
    pub crossing: bool,
    /// Index of the crossing or of the pass candidate, for the caller.
    pub tag: usize,
    /// The level it is flown at (it lands there too).
    pub level: usize,
    /// The widest layer it may be entered in (0: any): a jump joined to
    /// the grid by straights clear only for a narrower shape
    /// (`route::Site::landing`) is entered in that shape or narrower.
    pub widest: usize,
}

/// What the search works on.
pub struct Graph<'a> {
    pub field: &'a Field,
    /// Per cell, one bit per level and layer it may be entered in, and one
    /// per pair of levels and layer it may be climbed between in.
    pub open: &'a [u64],
    pub jumps: &'a [Jump],
    /// Stops to make, in order (passes, requested crossings): the stages
    /// are 0..=stops.
    pub stages: usize,
    /// Cost of changing layer, metres (a transition flown).
    pub switch_cost: f64,
    /// Cost of climbing between level `i` and `i + 1`, metres; one entry
    /// fewer than there are levels.
    pub climb_cost: &'a [f64],
    /// The levels the route starts and ends at.
    pub start_level: usize,
    pub goal_level: usize,
}

impl Graph<'_> {
    /// How many levels the graph has.
    pub fn levels(&self) -> usize {
        self.climb_cost.len() + 1
    }

    /// Its modes: a layer at a level, `level * LAYERS + layer`.
    pub fn modes(&self) -> usize {
        self.levels() * LAYERS
    }
}

/// One step of the found route.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// Moved to a neighbouring cell (or started there), changed layer or
    /// climbed to another level there.
    Cell {
        cell: usize,
        layer: usize,
        level: usize,
    },
    /// Took jump `tag` (a crossing or a pass) ending at `cell`.
    Jump {
        cell: usize,
        tag: usize,
        layer: usize,
        level: usize,
    },
}

/// `link` of the start state (no parent).
const ROOT: u32 = u32::MAX;

/// The cells reached by the search, for explaining a failure.
pub struct Reached {
    /// Per cell, the highest stage reached there (`None`: never reached).
    pub stage: Vec<Option<usize>>,
}

/// The jumps (indices) leaving each cell.
fn jumps_from(graph: &Graph<'_>) -> CellLists<usize> {
    let pairs = graph
        .jumps
        .iter()
        .enumerate()
        .map(|(j, jump)| (jump.from, j))
        .collect();
    CellLists::new(graph.field.len(), pairs)
}

/// The cells reached from `start` when `goal` is not among them, in a
/// relaxation of the search's graph: a cell open in any layer at any level
/// is open to all, every jump may be taken at any stage and level. No plain flood (a few
/// milliseconds) reaching the goal means no route at all, and the refusal
/// needs no search; when it does reach, the search decides.
pub fn unreachable(graph: &Graph<'_>, start: usize, goal: usize) -> Option<Reached> {
    let field = graph.field;
    let mut seen = vec![false; field.len()];
    let mut queue = std::collections::VecDeque::from([start]);
    seen[start] = true;
    let jumps = jumps_from(graph);
    while let Some(cell) = queue.pop_front() {
        if cell == goal {
            return None;
        }
        let next = field
            .neighbourhood(cell)
            .filter(|&j| graph.open[j] & LEVEL_BITS != 0 || j == goal)
            .chain(jumps.at(cell).iter().map(|&j| graph.jumps[j].to));
        for j in next {
            if !seen[j] {
                seen[j] = true;
                queue.push_back(j);
            }
        }
    }
    // Past every stop: the goal itself is what cannot be reached.
    let stage = seen.iter().map(|&s| s.then_some(graph.stages)).collect();
    Some(Reached { stage })
}

/// The route that was tried, for a refusal to draw: the shortest way from
/// `start` through the cells `reached` (by the steps and jumps of the
/// graph, at their lengths) to the reached cell of the furthest stage
/// nearest `goal`, as the cells' centres where the way turns (its ends
/// kept).
pub fn tried(graph: &Graph<'_>, start: usize, goal: usize, reached: &Reached) -> Vec<Point2<f64>> {
    let field = graph.field;
    let top = reached.stage.iter().flatten().copied().max();
    let target = (0..field.len())
        .filter(|&c| top.is_some() && reached.stage[c] == top)
        .min_by(|&a, &b| {
            let d = |c: usize| (field.center(c) - field.center(goal)).norm();
            d(a).total_cmp(&d(b))
        });
    let Some(target) = target else {
        return Vec::new();
    };
    let jumps = jumps_from(graph);
    let mut parent = vec![usize::MAX; field.len()];
    let mut distance = vec![f64::INFINITY; field.len()];
    parent[start] = start;
    distance[start] = 0.0;
    let mut open = BinaryHeap::from([Entry {
        estimate: 0.0,
        reached: 0.0,
        state: start,
    }]);
    while let Some(Entry {
        reached: d,
        state: cell,
        ..
    }) = open.pop()
    {
        if cell == target {
            break;
        }
        if d > distance[cell] {
            continue;
        }
        let next = field.steps(cell).chain(
            jumps
                .at(cell)
                .iter()
                .map(|&j| (graph.jumps[j].to, graph.jumps[j].length)),
        );
        for (j, length) in next {
            if reached.stage[j].is_some() && d + length < distance[j] {
                distance[j] = d + length;
                parent[j] = cell;
                open.push(Entry {
                    estimate: d + length,
                    reached: d + length,
                    state: j,
                });
            }
        }
    }
    if parent[target] == usize::MAX {
        return Vec::new();
    }
    let mut cells = vec![target];
    while let Some(&c) = cells.last().filter(|&&c| c != start) {
        cells.push(parent[c]);
    }
    cells.reverse();
    let points: Vec<Point2<f64>> = cells.iter().map(|&c| field.center(c)).collect();
    // Only where the way turns: a straight run of cells is its two ends.
    let mut kept = vec![points[0]];
    for w in points.windows(3) {
        if (w[1] - w[0]).perp(&(w[2] - w[1])).abs() > 1e-9 {
            kept.push(w[1]);
        }
    }
    if points.len() > 1 {
        kept.push(points[points.len() - 1]);
    }
    kept
}

/// The cheapest route from `start` to `goal` through every stage, ranked by
/// `heuristic` (cell, mode, stage → a bound of what is left, or `None`
/// where the goal is out of reach: the state is never entered), or the
/// cells reached when there is none: all of them when the heuristic prunes
/// nothing. It starts at the graph's start level and ends at its goal
/// level.
///
/// Long (~175 lines): one A* loop whose moves (steps, layer changes, climbs, crossings, passes)
/// share its state arrays, then the route (or the cells reached) read back from them.
pub fn search(
    graph: &Graph<'_>,
    start: usize,
    goal: usize,
    heuristic: impl Fn(usize, usize, usize) -> Option<f64>,
) -> Result<Vec<Step>, Reached> {
    let field = graph.field;
    let cells = field.len();
    let modes = graph.modes();
    let levels = graph.levels();
    let states = cells * modes * (graph.stages + 1);
    let state = |cell: usize, mode: usize, stage: usize| (stage * modes + mode) * cells + cell;
    // Zeroed arrays: the system hands them out untouched, so a search that
    // reaches a corner of a large site pays only for that corner's pages.
    // `link[s]` is 0 for a state never reached, `ROOT` for the start, else
    // its parent + 1; `cost[s]` holds only where `link[s]` is not 0; `via[s]`
    // is the jump taken there + 1, or 0.
    let mut cost = vec![0.0f64; states];
    let mut link = vec![0u32; states];
    let mut via = vec![0u32; states];
    let known = |link: &[u32], cost: &[f64], s: usize| {
        if link[s] == 0 { f64::INFINITY } else { cost[s] }
    };
    let index = jumps_from(graph);

    let mut open = BinaryHeap::new();
    let first_mode = graph.start_level * LAYERS;
    let first = state(start, first_mode, 0);
    cost[first] = 0.0;
    link[first] = ROOT;
    if let Some(estimate) = heuristic(start, first_mode, 0) {
        open.push(Entry {
            estimate,
            reached: 0.0,
            state: first,
        });
    }
    let mut done = None;
    while let Some(Entry {
        state: s, reached, ..
    }) = open.pop()
    {
        let cell = s % cells;
        let mode = (s / cells) % modes;
        let (level, layer) = (mode / LAYERS, mode % LAYERS);
        let stage = s / (cells * modes);
        let g = known(&link, &cost, s);
        if reached > g {
            continue; // stale entry: a cheaper way here was found since
        }
        if cell == goal && stage == graph.stages && level == graph.goal_level {
            done = Some(s);
            break;
        }
        let mut relax = |to: usize, g_to: f64, through: u32, open: &mut BinaryHeap<Entry>| {
            if g_to < known(&link, &cost, to) {
                let Some(left) = heuristic(to % cells, (to / cells) % modes, to / (cells * modes))
                else {
                    return; // no way on from there, even relaxed
                };
                cost[to] = g_to;
                link[to] = s as u32 + 1;
                via[to] = through;
                open.push(Entry {
                    estimate: g_to + left,
                    reached: g_to,
                    state: to,
                });
            }
        };
        let here = bit(level, layer);
        for (next, length) in field.steps(cell) {
            if graph.open[next] & here != 0 || next == goal {
                relax(state(next, mode, stage), g + length, 0, &mut open);
            }
        }
        // A transition to another layer, flown where the wider shape fits.
        for other in (0..LAYERS).filter(|&l| l != layer) {
            if graph.open[cell] & bit(level, other.min(layer)) != 0 {
                relax(
                    state(cell, level * LAYERS + other, stage),
                    g + graph.switch_cost,
                    0,
                    &mut open,
                );
            }
        }
        // A climb to the level above or below, where every altitude between
        // is clear.
        if level + 1 < levels && graph.open[cell] & climb_bit(level, layer) != 0 {
            relax(
                state(cell, mode + LAYERS, stage),
                g + graph.climb_cost[level],
                0,
                &mut open,
            );
        }
        if level > 0 && graph.open[cell] & climb_bit(level - 1, layer) != 0 {
            relax(
                state(cell, mode - LAYERS, stage),
                g + graph.climb_cost[level - 1],
                0,
                &mut open,
            );
        }
        for &j in index.at(cell) {
            let jump = &graph.jumps[j];
            if jump.level != level || layer < jump.widest {
                continue;
            }
            let next_stage = match jump.pass_at {
                None => stage,
                Some(at) if at == stage => stage + 1,
                Some(_) => continue,
            };
            if !jump.crossing {
                if layer == 0 {
                    relax(
                        state(jump.to, level * LAYERS, next_stage),
                        g + jump.length,
                        j as u32 + 1,
                        &mut open,
                    );
                }
                continue;
            }
            // Out of a crossing in the widest layer the far side allows, no
            // wider than the one it came in.
            let Some(arrive) = (layer..LAYERS).find(|&l| graph.open[jump.to] & bit(level, l) != 0)
            else {
                continue;
            };
            relax(
                state(jump.to, level * LAYERS + arrive, next_stage),
                g + jump.length,
                j as u32 + 1,
                &mut open,
            );
        }
    }
    let Some(end) = done else {
        let mut stage = vec![None; cells];
        for (s, l) in link.iter().enumerate() {
            if *l != 0 {
                let (cell, st) = (s % cells, s / (cells * modes));
                if stage[cell].is_none_or(|old| st > old) {
                    stage[cell] = Some(st);
                }
            }
        }
        return Err(Reached { stage });
    };
    let mut steps = Vec::new();
    let mut s = end;
    loop {
        let cell = s % cells;
        let mode = (s / cells) % modes;
        let (level, layer) = (mode / LAYERS, mode % LAYERS);
        let step = if via[s] != 0 {
            Step::Jump {
                cell,
                tag: graph.jumps[via[s] as usize - 1].tag,
                layer,
                level,
            }
        } else {
            Step::Cell { cell, layer, level }
        };
        steps.push(step);
        if link[s] == ROOT {
            break;
        }
        s = link[s] as usize - 1;
    }
    steps.reverse();
    Ok(steps)
}

/// A state on the open list: its estimate of the whole route through it,
/// and the cost it was reached at.
#[derive(Debug, PartialEq)]
struct Entry {
    estimate: f64,
    reached: f64,
    state: usize,
}

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        // The smallest estimate first; among equal ones the deepest (on a
        // grid many routes tie, and finishing one beats widening all).
        other
            .estimate
            .total_cmp(&self.estimate)
            .then(self.reached.total_cmp(&other.reached))
            .then(other.state.cmp(&self.state))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Whether the straight from `a` to `b` stays on cells open in `bit`.
pub fn visible(field: &Field, open: &[u64], bit: u64, a: Point2<f64>, b: Point2<f64>) -> bool {
    field.cells_along(a, b).all(|i| open[i] & bit != 0)
}
