//! What is left of the route from each cell, mode (a layer at a level) and
//! stage, bounded from below on a coarse grid: the A*'s heuristic.
//!
//! A straight-line bound knows nothing of the walls nor of the transitions,
//! so on a site whose route bends round piers and changes shape at a gap the
//! search expands every state closer than the route's length: most of the
//! site, in every layer and stage (178,000 states on the bridge). This guide
//! runs one Dijkstra per stage, backwards from the goal (or from the stage's
//! stop edges and what is left after them), over a grid `FACTOR` times
//! coarser, in a relaxation of the search's graph:
//! - a coarse cell is open in a mode when any of its cells is, and may be
//!   climbed in when any of its cells may;
//! - the layer changes and the climbs cost what they cost in the search;
//! - a crossing is left in a layer its near cell is open in and lands in
//!   that layer or any narrower one its far cell is open in.
//!
//! Every route of the search is a route of the relaxation, so a state from
//! which the relaxation cannot reach the goal is never entered (pruned), and
//! the relaxed distance left, taken from the coarse cells round a cell plus
//! the way to their centres, less half a coarse diagonal of slack, ranks the
//! states (19,000 expanded on the bridge). The bound can overestimate by the
//! difference between coarse and fine grid steps, which costs at most that
//! much of the corridor's optimality, never its existence: the search stays
//! complete, and the corridor is pulled tight afterwards anyway.

use super::field::CellLists;
use super::search::{Graph, LAYERS, bit, climb_bit};
use crate::base::nearest::Nearest;

/// Fine cells per coarse cell along each axis.
const FACTOR: usize = 4;

/// Per stage, mode and coarse cell, the relaxed distance left to the goal.
pub struct Guide {
    fine_nx: usize,
    nx: usize,
    ny: usize,
    cells: usize,
    modes: usize,
    left: Vec<f32>,
    slack: f64,
    /// The way from a fine cell to the centres of the 3 × 3 coarse cells
    /// round its own, metres, by its place in its coarse cell: `bound`
    /// reads it for every state the search enters.
    way: Vec<[f64; 9]>,
}

/// The relaxed graph on the coarse grid, for one backward Dijkstra.
struct Coarse {
    nx: usize,
    ny: usize,
    cells: usize,
    side: f64,
    /// Per coarse cell, the modes any of its cells is open in and the
    /// climbs any may make (the search's bits).
    open: Vec<u64>,
    switch_cost: f64,
    climb_cost: Vec<f64>,
    levels: usize,
    /// The free crossings backwards: from the coarse cell they land in, the
    /// one they leave and their ends' layers (`Ends`).
    back: CellLists<Ends>,
}

impl Guide {
    /// The guide for `graph` towards the fine cell `goal`.
    pub fn new(graph: &Graph<'_>, goal: usize) -> Self {
        let field = graph.field;
        let (fine_nx, fine_ny) = field.size();
        let (nx, ny) = (fine_nx.div_ceil(FACTOR), fine_ny.div_ceil(FACTOR));
        let cells = nx * ny;
        let coarse = |i: usize| (i / fine_nx / FACTOR) * nx + (i % fine_nx) / FACTOR;
        let levels = graph.levels();
        let modes = graph.modes();
        let goal_modes = (0..LAYERS).fold(0, |bits, l| bits | bit(graph.goal_level, l));
        let mut open = vec![0u64; cells];
        for (i, bits) in graph.open.iter().enumerate() {
            open[coarse(i)] |= *bits;
        }
        open[coarse(goal)] |= goal_modes;
        let ends = |jump: &super::search::Jump| Ends {
            from: coarse(jump.from),
            length: jump.length,
            level: jump.level,
            leave: graph.open[jump.from],
            lands_from: (0..LAYERS)
                .find(|&l| graph.open[jump.to] & bit(jump.level, l) != 0)
                .unwrap_or(LAYERS),
        };
        let back = CellLists::new(
            cells,
            graph
                .jumps
                .iter()
                .filter(|j| j.pass_at.is_none())
                .map(|jump| (coarse(jump.to), ends(jump)))
                .collect(),
        );
        let relaxed = Coarse {
            nx,
            ny,
            cells,
            side: FACTOR as f64 * field.cell(),
            open,
            switch_cost: graph.switch_cost,
            climb_cost: graph.climb_cost.to_vec(),
            levels,
            back,
        };
        let stages = graph.stages;
        let per_stage = cells * modes;
        let mut left = vec![f32::INFINITY; per_stage * (stages + 1)];
        for stage in (0..=stages).rev() {
            // Where the stage's routes end: the goal, or a stop edge and
            // what is left after it.
            let mut sources: Vec<(usize, f64)> = Vec::new();
            if stage == stages {
                let g = coarse(goal);
                let at = graph.goal_level * LAYERS;
                sources.extend((0..LAYERS).map(|l| ((at + l) * cells + g, 0.0)));
            } else {
                let after = &left[(stage + 1) * per_stage..(stage + 2) * per_stage];
                for jump in graph.jumps.iter().filter(|j| j.pass_at == Some(stage)) {
                    let (from, to) = (coarse(jump.from), coarse(jump.to));
                    let at = jump.level * LAYERS;
                    if !jump.crossing {
                        // A pass: in the nominal layer, to the nominal layer.
                        sources.push((
                            at * cells + from,
                            jump.length + f64::from(after[at * cells + to]),
                        ));
                        continue;
                    }
                    // A crossing lands in the layer it is entered in, or the
                    // widest narrower one its far end is open in.
                    let e = ends(jump);
                    for l in (0..LAYERS).filter(|&l| e.leave & bit(jump.level, l) != 0) {
                        let rest = (l.max(e.lands_from)..LAYERS)
                            .map(|a| after[(at + a) * cells + to])
                            .fold(f32::INFINITY, f32::min);
                        sources.push(((at + l) * cells + from, jump.length + f64::from(rest)));
                    }
                }
            }
            sources.retain(|(_, d)| d.is_finite());
            relaxed.dijkstra(
                &mut left[stage * per_stage..(stage + 1) * per_stage],
                &sources,
            );
        }
        // Fine cells from the coarse cell's centre, and the centre's offset.
        let centre = (FACTOR as f64 - 1.0) / 2.0;
        let way = (0..FACTOR * FACTOR)
            .map(|k| {
                let (ox, oy) = ((k % FACTOR) as f64, (k / FACTOR) as f64);
                std::array::from_fn(|n| {
                    let (du, dv) = ((n % 3) as f64 - 1.0, (n / 3) as f64 - 1.0);
                    let dx = ox - du * FACTOR as f64 - centre;
                    let dy = oy - dv * FACTOR as f64 - centre;
                    dx.hypot(dy) * field.cell()
                })
            })
            .collect();
        Guide {
            fine_nx,
            nx,
            ny,
            cells,
            modes,
            left,
            slack: relaxed.side * std::f64::consts::FRAC_1_SQRT_2,
            way,
        }
    }

    /// A bound of the route left from fine cell `cell` in `mode` (a layer
    /// at a level) at `stage`, or `None` when the relaxation has none (nor
    /// has the search): the least over the coarse cells round it of what is
    /// left from their centre plus the way there, less the slack.
    pub fn bound(&self, cell: usize, mode: usize, stage: usize) -> Option<f64> {
        let (fx, fy) = (cell % self.fine_nx, cell / self.fine_nx);
        let (cx, cy) = (fx / FACTOR, fy / FACTOR);
        let plane = &self.left[(stage * self.modes + mode) * self.cells..][..self.cells];
        let own = plane[cy * self.nx + cx];
        if !own.is_finite() {
            return None;
        }
        let way = &self.way[(fy % FACTOR) * FACTOR + fx % FACTOR];
        let mut best = f64::INFINITY;
        for v in cy.saturating_sub(1)..=(cy + 1).min(self.ny - 1) {
            for u in cx.saturating_sub(1)..=(cx + 1).min(self.nx - 1) {
                let left = f64::from(plane[v * self.nx + u]);
                if left.is_finite() {
                    // u = cx + du, v = cy + dv with du, dv in -1..=1.
                    let n = (v + 1 - cy) * 3 + (u + 1 - cx);
                    best = best.min(left + way[n]);
                }
            }
        }
        Some((best - self.slack).max(0.0))
    }
}

impl Coarse {
    /// Distances over the coarse states (mode × cell) to `sources`, into
    /// `dist`, following the search's moves backwards.
    fn dijkstra(&self, dist: &mut [f32], sources: &[(usize, f64)]) {
        let cells = self.cells;
        let mut heap = Buckets::new(self.side);
        for &(state, d) in sources {
            if (d as f32) < dist[state] {
                dist[state] = d as f32;
                heap.push(Nearest {
                    key: d,
                    node: state,
                });
            }
        }
        let diagonal = self.side * std::f64::consts::SQRT_2;
        while let Some(Nearest {
            key: d,
            node: state,
        }) = heap.pop()
        {
            if d as f32 > dist[state] {
                continue;
            }
            let (mode, c) = (state / cells, state % cells);
            let (level, layer) = (mode / LAYERS, mode % LAYERS);
            let mut relax = |to: usize, length: f64, heap: &mut Buckets| {
                let next = d + length;
                if (next as f32) < dist[to] {
                    dist[to] = next as f32;
                    heap.push(Nearest {
                        key: next,
                        node: to,
                    });
                }
            };
            let here = bit(level, layer);
            let (x, y) = ((c % self.nx) as isize, (c / self.nx) as isize);
            if self.open[c] & here != 0 {
                for dy in -1..=1isize {
                    for dx in -1..=1isize {
                        let (u, v) = (x + dx, y + dy);
                        if (dx, dy) == (0, 0)
                            || u < 0
                            || v < 0
                            || u as usize >= self.nx
                            || v as usize >= self.ny
                        {
                            continue;
                        }
                        let from = v as usize * self.nx + u as usize;
                        if self.open[from] & here != 0 {
                            let length = if dx != 0 && dy != 0 {
                                diagonal
                            } else {
                                self.side
                            };
                            relax(mode * cells + from, length, &mut heap);
                        }
                    }
                }
            }
            for other in (0..LAYERS).filter(|&l| l != layer) {
                if self.open[c] & bit(level, other.min(layer)) != 0 {
                    relax(
                        (level * LAYERS + other) * cells + c,
                        self.switch_cost,
                        &mut heap,
                    );
                }
            }
            // Climbs, backwards: from the level below or above, here.
            if level > 0 && self.open[c] & climb_bit(level - 1, layer) != 0 {
                let cost = self.climb_cost[level - 1];
                relax((mode - LAYERS) * cells + c, cost, &mut heap);
            }
            if level + 1 < self.levels && self.open[c] & climb_bit(level, layer) != 0 {
                let cost = self.climb_cost[level];
                relax((mode + LAYERS) * cells + c, cost, &mut heap);
            }
            // A crossing landing here in this layer was entered in it or in a
            // wider one its near end is open in.
            for e in self.back.at(c) {
                if layer < e.lands_from || e.level != level {
                    continue;
                }
                for l in (0..=layer).filter(|&l| e.leave & bit(level, l) != 0) {
                    relax((level * LAYERS + l) * cells + e.from, e.length, &mut heap);
                }
            }
        }
    }
}
/// A crossing as the relaxation flies it.
struct Ends {
    /// The coarse cell it leaves.
    from: usize,
    length: f64,
    /// The level it is flown at.
    level: usize,
    /// The bits of its near end's cell (it is entered in a layer open there).
    leave: u64,
    /// The widest layer its far end's cell is open in: it lands in that one
    /// or narrower.
    lands_from: usize,
}

/// The open list of the guide's Dijkstra: buckets of keys `width` apart,
/// taken in order (Dial's algorithm). Every move of the coarse grid is at
/// least a coarse side long, so when a bucket is reached every entry in it
/// is final: taking them in any order gives the distances a heap would,
/// without its ordering work. A shorter move (a crossing narrower than a
/// cell) can land in the bucket being emptied; an entry improved that way
/// is simply taken again, so the distances stay exact.
struct Buckets {
    width: f64,
    lists: Vec<Vec<Nearest>>,
    current: usize,
}

impl Buckets {
    fn new(width: f64) -> Self {
        Buckets {
            width: width.max(f64::MIN_POSITIVE),
            lists: Vec::new(),
            current: 0,
        }
    }

    fn push(&mut self, entry: Nearest) {
        let b = ((entry.key / self.width) as usize).max(self.current);
        if b >= self.lists.len() {
            self.lists.resize_with(b + 1, Vec::new);
        }
        self.lists[b].push(entry);
    }

    fn pop(&mut self) -> Option<Nearest> {
        while let Some(list) = self.lists.get_mut(self.current) {
            if let Some(entry) = list.pop() {
                return Some(entry);
            }
            self.current += 1;
        }
        None
    }
}
