//! Why the route stage found no corridor, in words a crew can act on.
//!
//! The search has flooded every cell the formation can reach (`Reached`).
//! The obstacles bordering that region are what closes the way; they are
//! grouped into chains (two obstacles are linked when even the smallest
//! shrink cannot pass between them, an obstacle to a side of the bounds when
//! it cannot pass between them either), and the chain with most of the
//! border is named: its two end members, how many it has, which sides of the
//! bounds it joins (or that it rings the start or the goal), and its widest
//! gap with the reason the formation cannot take it.

use nalgebra::Point2;

use super::field::Field;
use super::search::Reached;
use super::{FINEST_CELL, Stop};
use crate::base::shape::{Footprint, gap_between, nearest_points};
use crate::mission::Mission;
use crate::pipelines::theta_pso::iwp::Iwp;
use crate::pipelines::theta_pso::path::PathBuilder;

/// Passages a refusal lists at most (a wall of a hundred posts has 99).
const MAX_PASSAGES: usize = 20;

/// The sides of the bounds, in the order `side_of` numbers them.
const SIDES: [&str; 4] = ["west", "east", "south", "north"];

/// The reason of the route stage's refusal.
///
/// Long (~200 lines): one case after another (a stop out of reach, a boxed-in start or goal, a wall between two bounds), each a sentence with its widths.
#[allow(clippy::too_many_arguments)]
pub fn explain(
    mission: &Mission,
    iwps: &[Iwp],
    field: &Field,
    obstacles: &[(usize, Footprint)],
    reached: &Reached,
    order: &[super::Stop],
    builder: &PathBuilder,
    need: f64,
    squeezed_reach: f64,
) -> super::Blocked {
    let top = reached.stage.iter().flatten().copied().max().unwrap_or(0);
    // Where the search got stuck: the inspection it could not fly, or the goal.
    let stuck = match order.get(top) {
        Some(Stop::Pass(i)) => {
            let (k, _) = builder.inspections()[*i];
            format!(" to the inspection of '{}'", mission.obstacles[k].name)
        }
        Some(Stop::Crossing(c)) => {
            let iwp = &iwps[builder.crossing_iwps()[*c]];
            match iwp.gate {
                Some(g) => format!(
                    " through route.via {} (between '{}' and '{}')",
                    g + 1,
                    iwp.between[0],
                    iwp.between[1]
                ),
                None => format!(
                    " through the IWP asked for between '{}' and '{}'",
                    iwp.between[0], iwp.between[1]
                ),
            }
        }
        Some(Stop::Via(k)) => {
            let points = builder.via_points();
            let at = points.get(*k).map(|(_, p)| *p).unwrap_or_default();
            let number = mission
                .route
                .via
                .iter()
                .position(|v| v.point.is_some_and(|q| (q - at).norm() < 1e-9))
                .map_or(0, |i| i + 1);
            format!(
                " by route.via {number} ({:.1}, {:.1}, {:.1})",
                at.x, at.y, at.z
            )
        }
        None => String::new(),
    };
    let region = |i: usize| reached.stage[i] == Some(top);
    // Obstacles (indices into `obstacles`) bordering the reached region.
    let mut border = vec![0usize; obstacles.len()];
    for i in (0..field.len()).filter(|&i| region(i)) {
        for j in field.neighbourhood(i) {
            if !region(j)
                && let Some(d) = field.nearest_disc(j)
            {
                border[d] += 1;
            }
        }
    }

    // Chains: union-find over the obstacles, and over the four sides.
    let n = obstacles.len();
    let mut parent: Vec<usize> = (0..n + 4).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let b = &mission.bounds;
    let gap_of = |a: &Footprint, c: &Footprint| gap_between(&**a, &**c);
    for i in 0..n {
        for j in (i + 1)..n {
            if gap_of(&obstacles[i].1, &obstacles[j].1) < 2.0 * need {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                parent[ri] = rj;
            }
        }
        let d = &obstacles[i].1;
        let to_side = [
            d.center().x - b.x[0],
            b.x[1] - d.center().x,
            d.center().y - b.y[0],
            b.y[1] - d.center().y,
        ];
        for (side, distance) in to_side.iter().enumerate() {
            if distance - d.radius() < need + squeezed_reach {
                let (ri, rs) = (root(&mut parent, i), root(&mut parent, n + side));
                parent[ri] = rs;
            }
        }
    }
    // The chain that holds most of the border.
    let mut weight = vec![0usize; n + 4];
    for (i, w) in border.iter().enumerate() {
        let r = root(&mut parent, i);
        weight[r] += w;
    }
    let Some(chain) = (0..n + 4)
        .filter(|&r| weight[r] > 0)
        .max_by_key(|&r| weight[r])
    else {
        return super::Blocked {
            reason: format!(
                "no corridor from start to goal{stuck}: the formation has no room to move \
                 (even shrunk it needs {need:.2} m from every obstacle and stays inside the bounds)"
            ),
            obstacles: Vec::new(),
            passages: Vec::new(),
            tried: Vec::new(),
        };
    };
    let members: Vec<usize> = (0..n).filter(|&i| root(&mut parent, i) == chain).collect();
    let sides: Vec<&str> = (0..4)
        .filter(|&s| root(&mut parent, n + s) == chain)
        .map(|s| SIDES[s])
        .collect();
    let name = |i: usize| format!("'{}'", mission.obstacles[obstacles[i].0].name);

    // Its two ends: the members farthest apart along its longest extent.
    let (first, last) = extremes(&members, obstacles);
    let span = if members.len() == 1 {
        name(first)
    } else if sides.is_empty() {
        // A ring has no ends: name its first few members instead.
        let few: Vec<String> = members.iter().take(3).map(|&i| name(i)).collect();
        let more = if members.len() > 3 { ", …" } else { "" };
        format!("{} obstacles ({}{more})", members.len(), few.join(", "))
    } else {
        format!(
            "{} obstacles from {} to {}",
            members.len(),
            name(first),
            name(last)
        )
    };
    let start_inside = region(field.index_of(mission.route.start.xy()));
    let place = match sides.as_slice() {
        [] if start_inside => "round the start".to_owned(),
        [] => "round the goal".to_owned(),
        [one] => format!("against the {one} bound"),
        many => format!(
            "between the {} bounds",
            many.join(" and ")
                .replacen(" and ", ", ", many.len().saturating_sub(2))
        ),
    };

    // Its widest gap, and why the formation cannot take it.
    let widest = members
        .iter()
        .flat_map(|&i| members.iter().map(move |&j| (i, j)))
        .filter(|(i, j)| i < j)
        .map(|(i, j)| (i, j, gap_of(&obstacles[i].1, &obstacles[j].1)))
        .filter(|(_, _, g)| *g < 2.0 * need)
        .max_by(|a, b| a.2.total_cmp(&b.2));
    let r_q = mission.formation.least_clearance();
    let gap_text = widest.map_or_else(String::new, |(i, j, gap)| {
        let (p, q) = (obstacles[i].0, obstacles[j].0);
        let why = if gap < 2.0 * r_q {
            format!(
                "{:.2} m too narrow for one UAV (2 (r_Q + the safety margin) = {:.2} m)",
                2.0 * r_q - gap,
                2.0 * r_q
            )
        } else if let Some(iwp) = iwps
            .iter()
            .find(|w| (w.obstacles == [p, q]) || (w.obstacles == [q, p]))
        {
            match (&iwp.unusable, iwp.enabled) {
                (_, false) => "its IWP is disabled".to_owned(),
                (Some(reason), _) => format!("its IWP is unusable: {reason}"),
                (None, true) => format!(
                    "its IWP's crossing ({}) leads nowhere the formation fits",
                    iwp.shape_name()
                ),
            }
        } else if gap < 2.0 * (mission.formation.radius() + r_q) {
            "a third obstacle stands in it (no IWP, eq. 9)".to_owned()
        } else {
            format!("the shrunk formation needs {:.2} m", 2.0 * need)
        };
        format!(
            "; the widest gap between them, {} | {}, is {gap:.2} m: {why}",
            name(i),
            name(j)
        )
    });
    let passages = narrow_passages(mission, obstacles, &members, need);
    super::Blocked {
        reason: format!(
            "no corridor from start to goal{stuck}: {span} close the way {place}{gap_text}{}",
            resolution_note(field.cell())
        ),
        obstacles: members.iter().map(|&i| obstacles[i].0).collect(),
        passages,
        tried: Vec::new(),
    }
}

/// Every gap between `members` too narrow to pass (under 2 `need`), widest
/// first (at most [`MAX_PASSAGES`]), with its ends, for scripts and the
/// designer to draw.
fn narrow_passages(
    mission: &Mission,
    obstacles: &[(usize, Footprint)],
    members: &[usize],
    need: f64,
) -> Vec<super::BlockedPassage> {
    let mut passages: Vec<super::BlockedPassage> = members
        .iter()
        .flat_map(|&i| members.iter().map(move |&j| (i, j)))
        .filter(|(i, j)| i < j)
        .filter_map(|(i, j)| {
            let gap = gap_between(&*obstacles[i].1, &*obstacles[j].1);
            (gap < 2.0 * need).then(|| {
                let (a, b) = nearest_points(&*obstacles[i].1, &*obstacles[j].1);
                // As the words say it: one UAV's width (what verification
                // holds) where not even one fits, else the route's need.
                let one = 2.0 * mission.formation.least_clearance();
                let needs = if gap < one { one } else { 2.0 * need };
                (
                    [obstacles[i].0, obstacles[j].0],
                    gap.max(0.0),
                    needs,
                    [a, b],
                )
            })
        })
        .collect();
    passages.sort_by(|a, b| b.1.total_cmp(&a.1));
    passages.truncate(MAX_PASSAGES);
    passages
}

/// What a coarse search cannot see. The grid is as fine as 0.2 m, but a
/// large site is searched at coarser cells (its states are capped; named
/// from 0.3 m on): a way
/// that fits by less than about one cell may then not be found, and the
/// crew should know the refusal is only that sure.
fn resolution_note(cell: f64) -> String {
    if cell > 1.5 * FINEST_CELL {
        format!(
            " (this large site was searched at {cell:.2} m cells, not the finest {FINEST_CELL:.2} m: \
             every gap between two obstacles, or an obstacle and the bounds, was judged on exact \
             geometry; a way bent between three or more that fits by less than about {cell:.2} m \
             may not be found)"
        )
    } else {
        String::new()
    }
}

/// The two members farthest apart (the same one twice for a single member).
fn extremes(members: &[usize], obstacles: &[(usize, Footprint)]) -> (usize, usize) {
    let at = |i: usize| -> Point2<f64> { obstacles[i].1.center() };
    let mut best = (members[0], members[0], -1.0);
    for &i in members {
        for &j in members {
            let d = (at(i) - at(j)).norm();
            if d > best.2 {
                best = (i.min(j), i.max(j), d);
            }
        }
    }
    (best.0, best.1)
}
