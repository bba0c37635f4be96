//! Shortest 2-D routes around discs: the reference length every plan is
//! measured against, and the route some particles start from.
//!
//! **Reference (a lower bound on J1).** A feasible plan keeps every UAV at
//! least r_Q from every obstacle. For an obstacle no UAV can fly over
//! (height + r_Q > z_max), that bounds how close the formation's *centroid*
//! can come to its axis: ρ_k, the distance from the centroid to the nearest
//! point that is at least r_k + r_Q from every UAV, whatever the heading,
//! for the nominal shape and every shape the plan may take (so a usable IWP
//! gap stays passable). ρ_k = 0 when the obstacle fits between the UAVs
//! (the formation can straddle a thin pole); such obstacles do not bound the
//! route. Inflating every obstacle by the formation's safe radius r_F + r_Q,
//! as a first reading would, is *not* a lower bound: a triangle passes a pier
//! on its narrow side about a metre closer than r_F allows. The route around
//! the discs of radius ρ_k (less the verification's sampling resolution),
//! each replaced by its inscribed polygon, is then no longer than any
//! feasible plan's centroid path, whose 3-D length J1 is longer still.
//!
//! **Seeding route.** The same search around the obstacles inflated by
//! r_F + r_Q + margin, with each usable IWP crossing as a free portal and the
//! centroid kept in its decoding box: a route the nominal formation flies
//! clear of everything, which the swarm can start from.

use nalgebra::{Point2, Vector2, Vector3};

use super::iwp::Iwp;
use crate::base::detour::{Disc, Route, shortest_route};
use crate::mission::Mission;

/// ρ: how close the centroid of a formation with UAVs at `offsets`
/// (horizontal, formation frame) can come to a point that must stay `reach`
/// from every UAV, in any direction: 0 when the point fits among the UAVs,
/// else the distance from the centroid to the nearest point of the boundary
/// of the union of the discs of radius `reach` round the UAVs (on one circle
/// nearest the centroid, or where two circles cross).
pub fn closest_centroid(offsets: &[Vector2<f64>], reach: f64) -> f64 {
    let covered = |p: &Vector2<f64>, skip: [usize; 2]| {
        offsets
            .iter()
            .enumerate()
            .any(|(n, o)| !skip.contains(&n) && (p - o).norm() < reach - 1e-9)
    };
    if !covered(&Vector2::zeros(), [usize::MAX; 2]) {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for (i, a) in offsets.iter().enumerate() {
        // The point of circle i nearest the centroid.
        let toward = if a.norm() > 1e-12 {
            -a / a.norm()
        } else {
            Vector2::x()
        };
        let p = a + toward * reach;
        if !covered(&p, [i, usize::MAX]) {
            best = best.min(p.norm());
        }
        for (j, b) in offsets.iter().enumerate().skip(i + 1) {
            let d = (b - a).norm();
            if d <= 1e-12 || d >= 2.0 * reach {
                continue;
            }
            let mid = (a + b) / 2.0;
            let h = (reach * reach - d * d / 4.0).sqrt();
            let across = Vector2::new(-(b - a).y, (b - a).x) / d;
            for p in [mid + across * h, mid - across * h] {
                if !covered(&p, [i, j]) {
                    best = best.min(p.norm());
                }
            }
        }
    }
    if best.is_finite() { best } else { 0.0 }
}

/// Every shape the formation may take (nominal, each usable IWP's shape and
/// the states on the way to it at quarter steps), as horizontal offsets.
fn possible_shapes(mission: &Mission, iwps: &[Iwp]) -> Vec<Vec<Vector2<f64>>> {
    let slots = &mission.formation.slots;
    let flat = |offsets: &[Vector3<f64>]| offsets.iter().map(|o| o.xy()).collect::<Vec<_>>();
    let mut shapes = vec![flat(slots)];
    for shape in iwps.iter().filter(|i| i.is_via()).filter_map(|i| i.shape) {
        for blend in [0.25, 0.5, 0.75, 1.0] {
            shapes.push(flat(&shape.offsets(slots, blend)));
        }
    }
    shapes
}

/// The reference of the module doc: the lower bound on J1 for `mission`, or
/// `None` when no route reaches the goal.
pub fn lower_bound(mission: &Mission, iwps: &[Iwp], resolution: f64) -> Option<Route> {
    let f = &mission.formation;
    let shapes = possible_shapes(mission, iwps);
    let discs: Vec<Disc> = mission
        .obstacles
        .iter()
        .filter(|o| o.closes(mission.bounds.z, f.least_clearance()))
        .map(|o| {
            // A footprint's inscribed circle about its bounding centre (none
            // when that centre is outside it): the bound stays a lower bound.
            let inner = (-o.outline().signed_distance(&o.center)).max(0.0);
            let reach = inner + f.least_clearance();
            let rho = shapes
                .iter()
                .map(|s| closest_centroid(s, reach))
                .fold(f64::INFINITY, f64::min);
            Disc {
                center: o.center,
                radius: (rho - resolution).max(0.0),
            }
        })
        .filter(|d| d.radius > 0.0)
        .collect();
    shortest_route(
        mission.route.start.xy(),
        mission.route.goal.xy(),
        &discs,
        &[],
        None,
    )
}

/// The seeding route of the module doc from `from` to `to`, through the IWP
/// crossings `portals`, inside `region`.
pub fn seeding_route(
    mission: &Mission,
    margin: f64,
    portals: &[[Point2<f64>; 2]],
    region: [[f64; 2]; 2],
    from: Point2<f64>,
    to: Point2<f64>,
) -> Option<Route> {
    let f = &mission.formation;
    let discs: Vec<Disc> = mission
        .obstacles
        .iter()
        .filter(|o| o.within(mission.bounds.z))
        .map(|o| Disc {
            center: o.center,
            radius: o.radius + f.safe_radius() + margin,
        })
        .collect();
    shortest_route(from, to, &discs, portals, Some(region))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_can_straddle_a_thin_pole_but_not_a_pier() {
        let triangle = [
            Vector2::new(0.0, 2.0),
            Vector2::new(-2.0, -1.0),
            Vector2::new(2.0, -1.0),
        ];
        assert_eq!(
            closest_centroid(&triangle, 0.8),
            0.0,
            "a 0.3 m pole plus r_Q"
        );
        // A pier (2.5 + 0.5): on the narrow side, between UAVs 2 and 3, the
        // centroid can come to 1 + √(3² − 2²) = 3.236 m of the axis.
        let rho = closest_centroid(&triangle, 3.0);
        assert!((rho - (1.0 + 5f64.sqrt())).abs() < 1e-9, "{rho}");
        let column = [
            Vector2::new(-3.6, 0.0),
            Vector2::zeros(),
            Vector2::new(3.6, 0.0),
        ];
        assert!((closest_centroid(&column, 0.75) - 0.75).abs() < 1e-9);
    }
}
