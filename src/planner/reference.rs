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

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::{Point2, Vector2, Vector3};

use super::iwp::Iwp;
use crate::mission::Mission;

/// Vertices of the polygon inscribed in each disc.
const POLYGON: usize = 24;

/// A disc the route must stay out of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disc {
    pub center: Point2<f64>,
    pub radius: f64,
}

/// A found route and its length.
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    pub points: Vec<Point2<f64>>,
    pub length: f64,
}

/// The shortest route from `start` to `goal` that keeps out of the polygons
/// inscribed in `discs`, may use each portal (a free straight passage between
/// two points) and, when `region` is given ([x range, y range]), keeps its
/// vertices inside it. `None` when the goal cannot be reached.
pub fn shortest_route(
    start: Point2<f64>,
    goal: Point2<f64>,
    discs: &[Disc],
    portals: &[[Point2<f64>; 2]],
    region: Option<[[f64; 2]; 2]>,
) -> Option<Route> {
    // A disc that holds the start or the goal would wall it in: shrink it.
    let discs: Vec<Disc> = discs
        .iter()
        .map(|d| {
            let nearest = (start - d.center).norm().min((goal - d.center).norm());
            Disc {
                center: d.center,
                radius: d.radius.min(nearest - 1e-6).max(0.0),
            }
        })
        .filter(|d| d.radius > 0.0)
        .collect();
    let inner = (std::f64::consts::PI / POLYGON as f64).cos();
    let inside_region = |p: &Point2<f64>| {
        region.is_none_or(|[x, y]| {
            x[0] - 1e-9 <= p.x && p.x <= x[1] + 1e-9 && y[0] - 1e-9 <= p.y && p.y <= y[1] + 1e-9
        })
    };
    let blocked_point = |p: &Point2<f64>| {
        discs
            .iter()
            .any(|d| (p - d.center).norm() < d.radius * inner - 1e-9)
    };

    let mut nodes = vec![start, goal];
    let mut portal_of: Vec<Option<usize>> = vec![None, None];
    for (i, [a, b]) in portals.iter().enumerate() {
        nodes.push(*a);
        portal_of.push(Some(2 * i + 1));
        nodes.push(*b);
        portal_of.push(Some(2 * i));
    }
    let portal_nodes = nodes.len();
    for d in &discs {
        for j in 0..POLYGON {
            let a = std::f64::consts::TAU * j as f64 / POLYGON as f64;
            let p = d.center + Vector2::new(a.cos(), a.sin()) * d.radius;
            if inside_region(&p) && !blocked_point(&p) {
                nodes.push(p);
                portal_of.push(None);
            }
        }
    }
    let visible = |a: &Point2<f64>, b: &Point2<f64>| {
        discs.iter().all(|d| {
            crate::geometry::segment_point_distance(a, b, &d.center) >= d.radius * inner - 1e-9
        })
    };

    // A* over the visibility graph, edges checked when a node is expanded.
    let n = nodes.len();
    let mut best = vec![f64::INFINITY; n];
    let mut from = vec![usize::MAX; n];
    let mut done = vec![false; n];
    let mut open = BinaryHeap::new();
    best[0] = 0.0;
    open.push(Entry {
        estimate: (goal - start).norm(),
        node: 0,
    });
    while let Some(Entry { node: u, .. }) = open.pop() {
        if done[u] {
            continue;
        }
        done[u] = true;
        if u == 1 {
            break;
        }
        let mut relax = |v: usize, length: f64, open: &mut BinaryHeap<Entry>| {
            let through = best[u] + length;
            if through < best[v] {
                best[v] = through;
                from[v] = u;
                open.push(Entry {
                    estimate: through + (goal - nodes[v]).norm(),
                    node: v,
                });
            }
        };
        if let Some(other) = portal_of[u] {
            let other = other + 2;
            if !done[other] {
                relax(other, (nodes[other] - nodes[u]).norm(), &mut open);
            }
        }
        for v in 0..n {
            if done[v] || v == u || (v >= 2 && v < portal_nodes && portal_of[u] == Some(v - 2)) {
                continue;
            }
            if visible(&nodes[u], &nodes[v]) {
                relax(v, (nodes[v] - nodes[u]).norm(), &mut open);
            }
        }
    }
    if !best[1].is_finite() {
        return None;
    }
    let mut points = vec![goal];
    let mut at = 1;
    while at != 0 {
        at = from[at];
        points.push(nodes[at]);
    }
    points.reverse();
    Some(Route {
        points,
        length: best[1],
    })
}

#[derive(Debug, PartialEq)]
struct Entry {
    estimate: f64,
    node: usize,
}

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        // Smallest estimate first.
        other
            .estimate
            .total_cmp(&self.estimate)
            .then(other.node.cmp(&self.node))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

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
        .filter(|o| o.height + f.uav_radius > mission.bounds.z[1])
        .map(|o| {
            let reach = o.radius + f.uav_radius;
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
        .filter(|o| o.height > mission.bounds.z[0])
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
    fn an_open_field_route_is_the_straight_line() {
        let r = shortest_route(
            Point2::new(0.0, 0.0),
            Point2::new(10.0, 0.0),
            &[],
            &[],
            None,
        );
        assert_eq!(r.map(|r| r.length), Some(10.0));
    }

    #[test]
    fn a_disc_in_the_way_costs_about_its_half_circumference_at_most() {
        let disc = Disc {
            center: Point2::new(5.0, 0.0),
            radius: 2.0,
        };
        let r = shortest_route(
            Point2::new(-5.0, 0.0),
            Point2::new(15.0, 0.0),
            &[disc],
            &[],
            None,
        )
        .map(|r| r.length)
        .unwrap_or(f64::NAN);
        // Exact around the circle: 2 tangents √(10² − 2²) and the arc 2 (π − 2 acos(0.2)).
        let exact = 2.0 * 96f64.sqrt() + 2.0 * (std::f64::consts::PI - 2.0 * 0.2f64.acos());
        assert!(
            r <= exact + 1e-9,
            "inscribed polygon: a lower bound, {r} vs {exact}"
        );
        assert!(r > exact - 0.01, "and a close one: {r} vs {exact}");
    }

    #[test]
    fn a_portal_crosses_a_wall() {
        let wall: Vec<Disc> = (0..21)
            .map(|i| Disc {
                center: Point2::new(0.0, -10.0 + i as f64),
                radius: 0.8,
            })
            .collect();
        let start = Point2::new(-5.0, 0.0);
        let goal = Point2::new(5.0, 0.0);
        let around = shortest_route(start, goal, &wall, &[], None).map(|r| r.length);
        let portal = [Point2::new(-1.0, 0.0), Point2::new(1.0, 0.0)];
        let through = shortest_route(start, goal, &wall, &[portal], None).map(|r| r.length);
        assert!(around.is_some_and(|a| a > 20.0), "{around:?}");
        assert_eq!(through, Some(10.0));
        let boxed = shortest_route(start, goal, &wall, &[], Some([[-6.0, 6.0], [-5.0, 5.0]]));
        assert_eq!(boxed, None, "the wall spans the region");
    }

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
