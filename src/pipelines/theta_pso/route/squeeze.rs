//! The squeeze map: where the corridor flies narrower than the nominal
//! shape (the shrink, or single file), region by region, as the paths the
//! swarm tries read it.

use std::sync::Arc;

use nalgebra::Point2;

use super::field::Field;
use super::search::{LAYERS, bit};
use super::{Corridor, Leg, Level, Site};
use crate::mission::Mission;
use crate::pipelines::theta_pso::iwp::Shape as FormationShape;
use crate::pipelines::theta_pso::path::SqueezeMap;

/// The squeezed regions the corridor passes: the connected cells where only
/// the shrink fits (flown at the scale the corridor needs through it) or
/// only the column does, at the level each leg is flown at; `None` when the
/// corridor never squeezes.
///
/// Long (~135 lines): one walk along the corridor's narrow legs, each point's cell joined to a
/// region (flooded over the cells open in the same layer, or run along a passage's straight
/// through shut cells) and the shrink's scale narrowed to what fits there.
pub(super) fn squeeze_map(
    site: &Site,
    corridor: &Corridor,
    mission: &Mission,
) -> Option<Arc<SqueezeMap>> {
    let field = site.field();
    let open = &site.open;
    let shape = &site.shape;
    // The narrowest layer a cell is open in at `level`, when it is not open
    // in the nominal one.
    let narrow = |i: usize, level: usize| -> Option<usize> {
        (open[i] & bit(level, 0) == 0)
            .then(|| (1..LAYERS).find(|&l| open[i] & bit(level, l) != 0))
            .flatten()
    };
    let level_of_leg = |leg: usize| {
        corridor
            .heights
            .get(leg)
            .and_then(|z| site.levels.level_of(*z))
            .unwrap_or(0)
    };
    let mut region = vec![0u16; field.len()];
    let mut shapes: Vec<FormationShape> = Vec::new();
    // The level whose obstacles name the squeezes' sides.
    let mut named: Option<usize> = None;
    for (k, (leg, w)) in corridor
        .legs
        .iter()
        .zip(corridor.points.windows(2))
        .enumerate()
    {
        if matches!(leg, Leg::Free { layer: 0 } | Leg::Pass(_)) {
            continue;
        }
        let level = level_of_leg(k);
        let Level {
            field: at, discs, ..
        } = &site.at[level];
        let (a, b) = (w[0], w[1]);
        let leg_layer = match leg {
            Leg::Free { layer } => *layer,
            _ => 0,
        };
        let steps = (((b - a).norm() / (field.cell() / 3.0)).ceil() as usize).max(1);
        // The region the previous point of this leg was in.
        let mut previous: Option<u16> = None;
        for j in 0..=steps {
            let p = a + (b - a) * (j as f64 / steps as f64);
            let i = field.index_of(p);
            let closed = (0..LAYERS).all(|l| open[i] & bit(level, l) == 0);
            if closed && leg_layer > 0 && region[i] == 0 {
                // A passage's straight through cells the grid shuts (its
                // clearance checked exactly, `gaps`, `Site::landing`):
                // flown in the leg's shape, one region along it.
                let wanted = match (leg_layer, shape.column) {
                    (2, Some(column)) => column,
                    _ => FormationShape::Shrink { scale: 1.0 },
                };
                match previous {
                    Some(r)
                        if std::mem::discriminant(&shapes[r as usize - 1])
                            == std::mem::discriminant(&wanted) =>
                    {
                        region[i] = r
                    }
                    _ => {
                        if shapes.len() >= u16::MAX as usize - 1 {
                            break;
                        }
                        shapes.push(wanted);
                        named.get_or_insert(level);
                        region[i] = shapes.len() as u16;
                    }
                }
            }
            let Some(layer) = narrow(i, level)
                .filter(|_| !nominal_fits(site, mission, p, level))
                .or(closed.then_some(leg_layer))
                .filter(|l| *l > 0)
            else {
                previous = None;
                continue;
            };
            if region[i] == 0 {
                if shapes.len() >= u16::MAX as usize - 1 {
                    break;
                }
                shapes.push(match (layer, shape.column) {
                    (2, Some(column)) => column,
                    _ => FormationShape::Shrink { scale: 1.0 },
                });
                named.get_or_insert(level);
                let label = shapes.len() as u16;
                flood(field, &mut region, i, label, &|c| {
                    narrow(c, level) == Some(layer)
                        && !nominal_fits(site, mission, field.center(c), level)
                });
            }
            previous = Some(region[i]);
            let r = region[i] as usize - 1;
            if let FormationShape::Shrink { scale } = &mut shapes[r] {
                let (clearance, inside) = (
                    at.clearance_at(p, discs),
                    mission
                        .bounds
                        .horizontal_margin(&nalgebra::Point3::new(p.x, p.y, 0.0)),
                );
                *scale = scale.min(shape.scale_for(clearance, inside));
                // Where not even the smallest shrink fits (a point of the
                // corridor nearer the bounds or an obstacle than its
                // cell's centre), the region is flown in single file.
                if let (true, Some(column)) = (!shape.shrink_fits(clearance, inside), shape.column)
                {
                    shapes[r] = column;
                }
            }
        }
    }
    let named = &site.at[named?];
    let free = chebyshev_distance(field, &region);
    let extent = region_extent(field, &region);
    Some(Arc::new(SqueezeMap {
        field: named.field.clone(),
        region,
        shapes,
        obstacle_of: named
            .obstacles
            .iter()
            .map(|(k, d)| (*k, d.center()))
            .collect(),
        free,
        extent,
    }))
}

/// Whether the nominal shape fits at `p` at `level` on exact geometry. The
/// grid shuts a cell whose centre is within half a diagonal of the need,
/// so a narrow cell may hold points where nothing needs to squeeze; a
/// region grown over those squeezed the formation where it fits, into an
/// inspection pass beside it (the viaduct at a 3.4 m obstacle margin).
fn nominal_fits(site: &Site, mission: &Mission, p: Point2<f64>, level: usize) -> bool {
    let Level {
        field: at, discs, ..
    } = &site.at[level];
    let inside = mission
        .bounds
        .horizontal_margin(&nalgebra::Point3::new(p.x, p.y, 0.0));
    at.clearance_at(p, discs) >= site.need[0] - 1e-9 && inside >= site.shape.reach - 1e-9
}

/// The box holding every point whose cell is in a region.
pub(super) fn region_extent(field: &Field, region: &[u16]) -> [Point2<f64>; 2] {
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
pub(super) fn chebyshev_distance(field: &Field, region: &[u16]) -> Vec<u8> {
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
