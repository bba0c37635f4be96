//! The search's steps made a corridor: runs of cells pulled tight, the
//! jumps (crossings, passes, gaps) kept exact, climbs as ramps, and the
//! corridor carried through the IWP crossings it passes.

use std::collections::HashMap;

use nalgebra::Point2;

use super::field::Field;
use super::search::{self, Step, bit};
use super::{Corridor, Leg, Site};
use crate::base::geometry::segments_cross;
use crate::pipelines::theta_pso::path::PathBuilder;

/// The search's steps as a corridor: runs of cells pulled tight within their
/// mode, the jumps kept exact, each climb a short ramp round its cell.
///
/// Long (~235 lines): one walk over the steps (runs, layer changes, climbs, jumps with their
/// landings), then the
/// ramps laid out; over a quarter of it is rustfmt spreading the seven calls of its `flush`
/// closure (which borrows the walk's vectors) over eight lines each.
#[allow(clippy::too_many_arguments)]
pub(super) fn assemble(
    site: &Site,
    steps: &[Step],
    [start, goal]: [Point2<f64>; 2],
    crossings: &[[Point2<f64>; 2]],
    landed: &HashMap<(usize, usize), [Point2<f64>; 2]>,
    candidates: &[(usize, f64, bool, [Point2<f64>; 2])],
    via_points: &[Point2<f64>],
    gaps: &[[Point2<f64>; 2]],
    inspections: usize,
) -> Corridor {
    let field = site.field();
    let levels = &site.levels;
    let height = |level: usize| levels.altitude(level);
    let first = levels.start;
    let mut points = vec![start];
    let mut heights = vec![height(first)];
    let mut legs = Vec::new();
    let mut passes = vec![(0.0, true); inspections];
    // Climbs: the index of the leg that climbs, and its ramp's half run.
    let mut climbs: Vec<(usize, f64)> = Vec::new();
    // The current run: its points and mode.
    let mut run: Vec<Point2<f64>> = vec![start];
    let (mut layer, mut level) = (0, first);
    let flush = |run: &mut Vec<Point2<f64>>,
                 (layer, level): (usize, usize),
                 points: &mut Vec<Point2<f64>>,
                 heights: &mut Vec<f64>,
                 legs: &mut Vec<Leg>,
                 end: Point2<f64>| {
        run.push(end);
        let pulled = pull_tight(field, &site.open, bit(level, layer), run);
        for p in pulled.into_iter().skip(1) {
            if (p - points[points.len() - 1]).norm() > 1e-9 {
                points.push(p);
                heights.push(height(level));
                legs.push(Leg::Free { layer });
            }
        }
        run.clear();
    };
    for (k, step) in steps.iter().enumerate().skip(1) {
        let last = k + 1 == steps.len();
        match *step {
            Step::Cell {
                cell,
                layer: l,
                level: v,
            } => {
                let here = field.center(cell);
                if v != level {
                    // A climb: up (or down) at this cell, from the run so far.
                    flush(
                        &mut run,
                        (layer, level),
                        &mut points,
                        &mut heights,
                        &mut legs,
                        here,
                    );
                    let pair = v.min(level);
                    let run_half = site.ramp(pair);
                    // Climbs through several levels at one cell are one ramp.
                    match climbs.last_mut() {
                        Some((leg, half)) if *leg + 1 == legs.len() && points[*leg] == here => {
                            *half = half.min(run_half);
                            *heights.last_mut().unwrap_or(&mut 0.0) = height(v);
                        }
                        _ => {
                            climbs.push((legs.len(), run_half));
                            points.push(here);
                            heights.push(height(v));
                            legs.push(Leg::Free { layer: l });
                        }
                    }
                    run.push(here);
                    (layer, level) = (l, v);
                    if last {
                        flush(
                            &mut run,
                            (layer, level),
                            &mut points,
                            &mut heights,
                            &mut legs,
                            goal,
                        );
                    }
                } else if l != layer {
                    // A change of layer: a vertex where the transition is.
                    flush(
                        &mut run,
                        (layer, level),
                        &mut points,
                        &mut heights,
                        &mut legs,
                        here,
                    );
                    run.push(here);
                    layer = l;
                } else if last {
                    flush(
                        &mut run,
                        (layer, level),
                        &mut points,
                        &mut heights,
                        &mut legs,
                        goal,
                    );
                } else {
                    run.push(here);
                }
            }
            Step::Jump {
                tag,
                layer: l,
                level: v,
                ..
            } => {
                let (ends, leg) = if tag < 2 * crossings.len() {
                    let [a, z] = crossings[tag / 2];
                    let ends = if tag % 2 == 0 { [a, z] } else { [z, a] };
                    (ends, Some(Leg::Crossing(tag / 2)))
                } else if tag < 2 * crossings.len() + candidates.len() {
                    let (i, phi, on_left, ends) = candidates[tag - 2 * crossings.len()];
                    passes[i] = (phi, on_left);
                    (ends, Some(Leg::Pass(i)))
                } else if tag < 2 * crossings.len() + candidates.len() + via_points.len() {
                    // A via point: a corner of the route, no leg of its own.
                    let p = via_points[tag - 2 * crossings.len() - candidates.len()];
                    ([p, p], None)
                } else {
                    // A gap's straight, flown in the layer it is taken in.
                    let g = tag - 2 * crossings.len() - candidates.len() - via_points.len();
                    let [a, z] = gaps[g / 2];
                    let ends = if g.is_multiple_of(2) { [a, z] } else { [z, a] };
                    (ends, Some(Leg::Free { layer: l }))
                };
                // A crossing carried out to meet the grid: the straights
                // from and to the cells the search stood at.
                let lands = match leg {
                    Some(Leg::Crossing(_)) => landed.get(&(tag, v)).copied(),
                    _ => None,
                }
                .unwrap_or(ends);
                flush(
                    &mut run,
                    (layer, level),
                    &mut points,
                    &mut heights,
                    &mut legs,
                    lands[0],
                );
                if lands[0] != ends[0] {
                    points.push(ends[0]);
                    heights.push(height(v));
                    legs.push(Leg::Free { layer });
                }
                if let Some(leg) = leg {
                    points.push(ends[1]);
                    heights.push(height(v));
                    legs.push(leg);
                } else if points.last() != Some(&ends[0]) {
                    // The run was already at the point (pulled tight onto it).
                    points.push(ends[0]);
                    heights.push(height(v));
                    legs.push(Leg::Free { layer });
                }
                if lands[1] != ends[1] {
                    points.push(lands[1]);
                    heights.push(height(v));
                    legs.push(Leg::Free { layer: l });
                }
                run.push(lands[1]);
                (layer, level) = (l, v);
                if last {
                    flush(
                        &mut run,
                        (layer, level),
                        &mut points,
                        &mut heights,
                        &mut legs,
                        goal,
                    );
                }
            }
        }
    }
    if points.last() != Some(&goal) {
        flush(
            &mut run,
            (layer, level),
            &mut points,
            &mut heights,
            &mut legs,
            goal,
        );
    }
    // Each climb, a vertical leg at its cell, becomes a ramp: its foot back
    // along the leg before, its top on along the leg after, each within the
    // ramp's half run of the cell (clear at every altitude between).
    for &(leg, half) in &climbs {
        let c = points[leg];
        if leg > 0 {
            let before = points[leg - 1];
            let back = (before - c).norm();
            if back > 1e-9 {
                points[leg] = c + (before - c) * (half.min(0.45 * back) / back);
            }
        }
        if leg + 2 < points.len() {
            let after = points[leg + 2];
            let on = (after - c).norm();
            if on > 1e-9 {
                points[leg + 1] = c + (after - c) * (half.min(0.45 * on) / on);
            }
        }
    }
    let mut corridor = Corridor {
        points,
        legs,
        passes,
        length: 0.0,
        heights: if levels.is_flat() {
            Vec::new()
        } else {
            heights
        },
        coarse_cell: None,
        squeeze: None,
    };
    corridor.length = polyline_length(&corridor);
    corridor
}

/// The corridor's free legs in the nominal shape across an IWP's gate,
/// taken through its crossing as the path builder will fly them
/// (`PathBuilder::crossing_leg` puts a crossing into every leg across its
/// gate, at the altitudes where the gap stands in the way, unless a squeeze
/// already carries the formation through in a shape that fits): the
/// crossing's straight put in, and the
/// corridor's points standing on that straight (a run pulled tight through a
/// gap in single file bends at its ends) left out, so the path does not
/// double back over the straight. A crossing whose approach or exit the
/// site closes is left as it was.
pub(super) fn through_crossings(site: &Site, builder: &PathBuilder, corridor: &mut Corridor) {
    let crossings = builder.crossings();
    let gates = builder.crossing_gates();
    let windows = builder.crossing_windows();
    let field = site.field();
    let height = |corridor: &Corridor, i: usize| corridor.heights.get(i).copied();
    let level_of = |z: Option<f64>| z.and_then(|z| site.levels.level_of(z)).unwrap_or(0);
    let mut placed: Vec<usize> = corridor
        .legs
        .iter()
        .filter_map(|l| match l {
            Leg::Crossing(c) => Some(*c),
            _ => None,
        })
        .collect();
    let mut k = 0;
    while k < corridor.legs.len() {
        // Only in the nominal shape: a leg flown squeezed (shrunk, in a
        // column) passes the gaps its shape fits as the squeeze carries it.
        let Leg::Free { layer: 0 } = corridor.legs[k] else {
            k += 1;
            continue;
        };
        let layer = 0;
        let (a, b) = (corridor.points[k], corridor.points[k + 1]);
        let level = level_of(height(corridor, k));
        let span = site.levels.span(level);
        // The first gate the leg crosses, from its start.
        let hit = (0..crossings.len())
            .filter(|&c| windows[c][0] <= span[1] + 1e-9 && span[0] <= windows[c][1] + 1e-9)
            .filter(|&c| {
                // As the path builder: once each, none within another's straight.
                !placed.iter().any(|&p| {
                    p == c || builder.crossings_overlap(p, c) || builder.crossings_overlap(c, p)
                })
            })
            .filter(|&c| segments_cross(&a, &b, &gates[c][0], &gates[c][1]))
            .min_by(|&c, &d| {
                let at = |g: &[Point2<f64>; 2]| (nalgebra::center(&g[0], &g[1]) - a).norm();
                at(&gates[c]).total_cmp(&at(&gates[d]))
            });
        let Some(c) = hit else {
            k += 1;
            continue;
        };
        let [p, q] = crossings[c];
        let (enter, leave) = if (q - p).dot(&(b - a)) >= 0.0 {
            (p, q)
        } else {
            (q, p)
        };
        let centre = nalgebra::center(&p, &q);
        let n = (leave - enter) / (leave - enter).norm().max(1e-12);
        let reach = (leave - enter).norm() / 2.0;
        let half_gate = (gates[c][1] - gates[c][0]).norm() / 2.0;
        let on_straight = |x: Point2<f64>| {
            let d = x - centre;
            d.dot(&n).abs() <= reach && (d.x * n.y - d.y * n.x).abs() <= half_gate
        };
        // Points on the straight before the leg's end, and after its start.
        let mut first = k;
        while first > 0
            && matches!(corridor.legs[first - 1], Leg::Free { .. })
            && on_straight(corridor.points[first])
        {
            first -= 1;
        }
        let mut last = k + 1;
        while last + 1 < corridor.points.len()
            && matches!(corridor.legs[last], Leg::Free { .. })
            && on_straight(corridor.points[last])
        {
            last += 1;
        }
        let open = |x: Point2<f64>, y: Point2<f64>| {
            search::visible(field, &site.open, bit(level, layer), x, y)
        };
        let (from, to) = (corridor.points[first], corridor.points[last]);
        if !(open(from, enter) && open(leave, to)) {
            k += 1;
            continue;
        }
        let z = height(corridor, k);
        placed.push(c);
        corridor.points.splice(first + 1..last, [enter, leave]);
        corridor.legs.splice(
            first..last,
            [Leg::Free { layer }, Leg::Crossing(c), Leg::Free { layer }],
        );
        if let Some(z) = z {
            corridor.heights.splice(first + 1..last, [z, z]);
        }
        k = first + 2;
    }
    corridor.length = polyline_length(corridor);
}

/// The corridor's length, metres (its heights' climbs included).
pub(super) fn polyline_length(corridor: &Corridor) -> f64 {
    let z = |i: usize| corridor.heights.get(i).copied().unwrap_or(0.0);
    corridor
        .points
        .windows(2)
        .enumerate()
        .map(|(i, w)| (w[1] - w[0]).norm().hypot(z(i + 1) - z(i)))
        .sum()
}

/// The run's points with every corner removed that a straight line on open
/// cells can skip: from each kept point, the farthest one in sight.
fn pull_tight(field: &Field, open: &[u64], bit: u64, run: &[Point2<f64>]) -> Vec<Point2<f64>> {
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
