//! The squeezed stretches of a path: where its centroid enters a region of
//! the route stage's squeeze map, the formation flies the region's shape.

use nalgebra::{Point2, Point3};

use super::{CentroidPath, PathBuilder, Zone, ZoneCause};
use crate::pipelines::theta_pso::iwp::Shape;
use crate::pipelines::theta_pso::iwp::Shape as FormationShape;
use crate::pipelines::theta_pso::path::ArcWalker;
use crate::pipelines::theta_pso::route::field::Field;

/// The squeezed stretches of the site the corridor uses: a path whose
/// centroid enters one flies it in the region's shape (a shrink, or the
/// column).
#[derive(Debug, Clone)]
pub struct SqueezeMap {
    pub(crate) field: Field,
    /// Per cell, the region (1-based) or 0.
    pub(crate) region: Vec<u16>,
    /// Per region, the shape flown there.
    pub(crate) shapes: Vec<FormationShape>,
    /// The mission's index and the centre of each of the field's discs.
    pub(crate) obstacle_of: Vec<(usize, Point2<f64>)>,
    /// Per cell, how many cells away the nearest region cell is (Chebyshev,
    /// capped at 255): a sample this far out lets the next few be skipped.
    pub(crate) free: Vec<u8>,
    /// The box every point of a region lies in (lower and upper corner): a
    /// leg that misses it needs no sample.
    pub(crate) extent: [Point2<f64>; 2],
}

impl SqueezeMap {
    /// The region at `p` and its shape, if `p` is in one.
    pub fn at(&self, p: Point2<f64>) -> Option<(u16, FormationShape)> {
        let r = self.region[self.field.index_of(p)];
        (r > 0).then(|| (r, self.shapes[r as usize - 1]))
    }

    /// The region at `p` as [`Self::at`], and outside them the distance
    /// within which no point is in one (0 inside).
    pub fn at_with_room(&self, p: Point2<f64>) -> (Option<(u16, FormationShape)>, f64) {
        let i = self.field.index_of(p);
        let r = self.region[i];
        if r > 0 {
            (Some((r, self.shapes[r as usize - 1])), 0.0)
        } else {
            // Within d − 1 cells (in x and in y) of this cell's point every
            // cell is d − 1 or fewer steps away, so none is a region's.
            let d = f64::from(self.free[i]);
            (None, (d - 1.0).max(0.0) * self.field.cell())
        }
    }

    /// The box holding every point that is in a region.
    pub fn extent(&self) -> [Point2<f64>; 2] {
        self.extent
    }

    /// Side of the grid's cells, metres: the resolution to sample paths at.
    pub fn resolution(&self) -> f64 {
        self.field.cell()
    }

    /// The obstacles nearest `p` on the left and on the right of the
    /// direction `along` (mission indices; one twice when the other side is
    /// open or a bound: the stretch is squeezed beside it; with neither
    /// side's, the obstacle nearest `p` twice).
    pub fn sides(&self, p: Point2<f64>, along: nalgebra::Vector2<f64>) -> [usize; 2] {
        let left = nalgebra::Vector2::new(-along.y, along.x).normalize();
        let probe = |sign: f64| {
            let mut d = 0.0;
            while d <= 50.0 {
                let i = self.field.index_of(p + left * sign * d);
                if let Some(&(k, center)) = self
                    .field
                    .nearest_disc(i)
                    .and_then(|k| self.obstacle_of.get(k))
                    && (center - p).dot(&left) * sign > 0.0
                {
                    return Some(k);
                }
                d += self.field.cell();
            }
            None
        };
        match (probe(1.0), probe(-1.0)) {
            (Some(a), Some(b)) => [a, b],
            (Some(a), None) | (None, Some(a)) => [a, a],
            (None, None) => {
                let nearest = self
                    .field
                    .nearest_disc(self.field.index_of(p))
                    .and_then(|k| self.obstacle_of.get(k))
                    .map_or(0, |&(k, _)| k);
                [nearest, nearest]
            }
        }
    }
}

impl PathBuilder {
    /// Names the obstacles each squeezed stretch of `path` passes between
    /// (where it is narrowest: in its middle), for the plan as reported.
    pub fn name_squeezes(&self, path: &mut CentroidPath) {
        let Some(map) = &self.squeeze else { return };
        let walker = ArcWalker::new(&path.points);
        for zone in &mut path.zones {
            let middle = (zone.hold[0] + zone.hold[1]) / 2.0;
            for cause in &mut zone.causes {
                if let ZoneCause::Squeeze { pair, .. } = cause {
                    *pair = map.sides(walker.at(middle).xy(), walker.heading(middle, 1.0).xy());
                }
            }
        }
    }

    /// A zone for each stretch of the path inside a squeezed region of the
    /// route stage: the shrink at the region's scale, held from
    /// `hold_distance` before the region to `hold_distance` after it.
    ///
    /// A stretch within an IWP's zone ([t1, t4]) is that IWP's: its shape
    /// was chosen (by the operator or as the least change) and checked for
    /// that gap, so the squeeze does not override it.
    pub(super) fn squeeze_zones(
        &self,
        map: &SqueezeMap,
        points: &[Point3<f64>],
        arcs: &[f64],
        crossings: &[Zone],
    ) -> Vec<Zone> {
        let total = arcs.last().copied().unwrap_or(0.0);
        let step = map.resolution();
        // (region, shape, first s, last s)
        let mut runs: Vec<(u16, Shape, f64, f64)> = Vec::new();
        let mut current: Option<(u16, Shape, f64, f64)> = None;
        // The last sample looked up outside the regions, and how far along
        // the path from it none can be (a straight or a polyline from it
        // is at least as long as the distance it covers).
        let mut clear_until = f64::NEG_INFINITY;
        let extent = map.extent();
        for (i, w) in points.windows(2).enumerate() {
            let (a, b) = (w[0].xy(), w[1].xy());
            let length = arcs[i + 1] - arcs[i];
            let n = ((length / step).ceil() as usize).max(1);
            // Only the samples within the regions' box can be in one; those
            // outside it end a run as any sample outside would.
            let Some([u0, u1]) = clip(a, b, extent) else {
                runs.extend(current.take());
                continue;
            };
            let first = ((u0 * n as f64).floor() as usize).min(n);
            let last = ((u1 * n as f64).ceil() as usize).min(n);
            if first > 0 {
                runs.extend(current.take());
            }
            for k in first..=last {
                let u = k as f64 / n as f64;
                let s = arcs[i] + length * u;
                if s < clear_until {
                    continue; // outside every region, as the last sample
                }
                let (hit, room) = map.at_with_room(a + (b - a) * u);
                if hit.is_none() && room > 0.0 {
                    clear_until = s + room;
                }
                match (hit, current.as_mut()) {
                    (Some((r, _)), Some(run)) if run.0 == r => run.3 = s,
                    (hit, _) => {
                        if let Some(run) = current.take() {
                            runs.push(run);
                        }
                        current = hit.map(|(r, shape)| (r, shape, s, s));
                    }
                }
            }
            if last < n {
                runs.extend(current.take());
            }
        }
        runs.extend(current);
        let within_a_crossing = |first: f64, last: f64| {
            crossings.iter().any(|z| {
                let [t1, _, _, t4] = z.arcs();
                t1 <= first && last <= t4
            })
        };
        runs.into_iter()
            .filter(|&(_, _, first, last)| !within_a_crossing(first, last))
            .map(|(region, shape, first, last)| {
                // A column is complete before its first UAV enters and held
                // until its last has left.
                let half = match shape {
                    Shape::Alignment { spacing } => (0..self.slots.len())
                        .map(|n| {
                            crate::pipelines::theta_pso::iwp::column_place(&self.slots, n, spacing)
                                .abs()
                        })
                        .fold(0.0, f64::max),
                    _ => 0.0,
                };
                let hold = [
                    (first - self.hold_distance - half).max(0.0),
                    (last + self.hold_distance + half).min(total),
                ];
                let middle = (first + last) / 2.0;
                Zone {
                    // Named only for the plan kept (`name_squeezes`): the
                    // swarm does not need the names.
                    causes: vec![ZoneCause::Squeeze {
                        region,
                        pair: [usize::MAX; 2],
                    }],
                    shape,
                    arc: middle,
                    hold,
                    transition_in: self.transition.min(hold[0]),
                    transition_out: self.transition.min(total - hold[1]),
                    from: None,
                    into: None,
                }
            })
            .collect()
    }
}

/// The share [u0, u1] of the segment a → b inside the box `[lower, upper]`
/// (Liang-Barsky), or `None` when it misses the box.
pub(super) fn clip(
    a: Point2<f64>,
    b: Point2<f64>,
    [lower, upper]: [Point2<f64>; 2],
) -> Option<[f64; 2]> {
    let d = b - a;
    let (mut u0, mut u1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - lower.x),
        (d.x, upper.x - a.x),
        (-d.y, a.y - lower.y),
        (d.y, upper.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None; // parallel to this side and outside it
            }
        } else {
            let u = q / p;
            if p < 0.0 {
                u0 = u0.max(u);
            } else {
                u1 = u1.min(u);
            }
        }
    }
    (u0 <= u1).then_some([u0, u1])
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::*;
    use crate::base::shape::Footprint;
    use crate::pipelines::theta_pso::trajectory::Reconfiguration;

    /// A squeeze map over 40 m × 40 m with these discs (mission indices 10,
    /// 11, …), no region marked: only `sides` is asked.
    fn map(centres: &[(f64, f64)]) -> SqueezeMap {
        let discs: Vec<Footprint> = centres
            .iter()
            .map(|&(x, y)| Footprint::circle(Point2::new(x, y), 3.0))
            .collect();
        let field = Field::new([[0.0, 40.0], [0.0, 40.0]], &discs, 0.5, 20.0);
        let cells = field.len();
        SqueezeMap {
            field,
            region: vec![0; cells],
            shapes: Vec::new(),
            obstacle_of: discs
                .iter()
                .enumerate()
                .map(|(k, d)| (10 + k, d.center()))
                .collect(),
            free: vec![0; cells],
            extent: [Point2::new(0.0, 0.0), Point2::new(40.0, 40.0)],
        }
    }

    /// Issue 36: a stretch squeezed by one obstacle, the other side open,
    /// is named by that obstacle once ("beside 'oak'", not "between 'oak'
    /// and 'oak'"); with none on either side, by the nearest, never by the
    /// mission's first obstacle.
    #[test]
    fn a_squeeze_is_named_by_an_obstacle_on_each_side_or_beside_one() {
        let (p, east) = (Point2::new(20.0, 20.0), Vector2::new(1.0, 0.0));
        assert_eq!(map(&[(20.0, 26.0), (20.0, 14.0)]).sides(p, east), [10, 11]);
        assert_eq!(map(&[(20.0, 26.0)]).sides(p, east), [10, 10]);
        // Straight ahead, on neither side: the nearest obstacle (it was
        // [0, 0], whatever the mission's first obstacle is).
        assert_eq!(map(&[(26.0, 20.0)]).sides(p, east), [10, 10]);

        let mut r = Reconfiguration {
            iwp: None,
            between: ["oak 7".into(), "oak 7".into()],
            shape: Shape::Shrink { scale: 0.5 },
            position: Point3::origin(),
            t1: 0.0,
            t2: 1.0,
            t3: 2.0,
            t4: 3.0,
        };
        assert_eq!(r.obstacles(), "beside 'oak 7'");
        r.between[1] = "oak 8".into();
        assert_eq!(r.obstacles(), "between 'oak 7' and 'oak 8'");
    }
}
