//! An earlier run's corridor, checked against the mission as it is now: the
//! designer's live re-plans skip the search when a small edit leaves their
//! last corridor passable (not in the paper; see docs/theta-pso.md).

use nalgebra::Point2;

use super::levels::Levels;
use super::search::{LAYERS, bit, visible};
use super::{Corridor, Leg, Site, pass_clear};
use crate::mission::Mission;
use crate::pipelines::theta_pso::iwp::Iwp;
use crate::pipelines::theta_pso::path::PathBuilder;

/// How close two corridor points must be to be the same, metres.
const SAME: f64 = 1e-6;

/// `previous` on `mission`, when it still holds there: it runs from the
/// start to the goal, every free leg on cells open in its layer, every
/// crossing where the builder puts an IWP's crossing now, every pass where
/// the builder puts it and clear, each inspection passed once and each
/// crossing the user asked for taken; its squeezed stretches are worked out
/// anew on this site. A corridor that climbs between levels is searched
/// again. `None`: the search must run.
pub fn reuse(
    mission: &Mission,
    builder: &PathBuilder,
    iwps: &[Iwp],
    margin: f64,
    previous: &Corridor,
) -> Option<Corridor> {
    let points = &previous.points;
    let (start, goal) = (mission.route.start.xy(), mission.route.goal.xy());
    let same = |a: Point2<f64>, b: Point2<f64>| (a - b).norm() <= SAME;
    if points.len() != previous.legs.len() + 1
        || !same(*points.first()?, start)
        || !same(*points.last()?, goal)
        || previous.passes.len() != builder.inspections().len()
        || !previous.heights.is_empty()
        || !mission.route.via.is_empty()
    {
        // A route with the user's vias is searched again: their order is
        // the search's to keep.
        return None;
    }
    let stops = builder.inspections().len()
        + super::requested_crossings(mission, builder, iwps)
            .iter()
            .filter(|r| **r)
            .count()
        + builder.via_points().len();
    let b = &mission.bounds;
    let site = Site::new(
        mission,
        builder,
        margin,
        Levels::flat(mission),
        stops,
        [b.x, b.y],
    );
    let field = site.field();
    let crossings = builder.crossings();
    let windows = builder.crossing_windows();
    let [low, high] = site.levels.span(0);
    let mut passed = vec![0usize; previous.passes.len()];
    let mut crossed = vec![false; crossings.len()];
    for (leg, w) in previous.legs.iter().zip(points.windows(2)) {
        let (a, b) = (w[0], w[1]);
        let holds = match *leg {
            Leg::Free { layer } => {
                layer < LAYERS && visible(field, &site.open, bit(0, layer), a, b)
            }
            Leg::Crossing(c) => crossings.get(c).is_some_and(|&[p, q]| {
                crossed[c] = true;
                let [w0, w1] = windows[c];
                let in_the_way = w0 <= high + 1e-9 && low <= w1 + 1e-9;
                in_the_way && ((same(a, p) && same(b, q)) || (same(a, q) && same(b, p)))
            }),
            Leg::Pass(i) => {
                let &(phi, on_left) = previous.passes.get(i)?;
                passed[i] += 1;
                let ends = builder.pass_ends(i, phi, on_left);
                let (k, _) = builder.inspections()[i];
                same(a, ends[0]) && same(b, ends[1]) && pass_clear(&site, 0, k, ends)
            }
        };
        if !holds {
            return None;
        }
    }
    let requested = super::requested_crossings(mission, builder, iwps);
    let requested_missing = (0..crossed.len()).any(|c| requested[c] && !crossed[c]);
    if passed.iter().any(|&n| n != 1) || requested_missing {
        return None;
    }
    let mut corridor = previous.clone();
    corridor.squeeze = site.squeeze_of(&corridor, mission);
    Some(corridor)
}
