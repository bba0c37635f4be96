//! Shortest 2-D routes round discs: A* over the visibility graph of the
//! polygons inscribed in the discs, with optional free portals and a region
//! the route's corners must stay in.
//!
//! Plain geometry, used by the θ-PSO planner (its reference length and its
//! seeding route, `theta_pso::reference`) and by the SPSO benchmark's seeded
//! particles (`spso::seeding`); it sits below both so neither imports the
//! other for it.

use std::collections::BinaryHeap;

use nalgebra::{Point2, Vector2};

use super::nearest::Nearest;

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
            crate::base::geometry::segment_point_distance(a, b, &d.center)
                >= d.radius * inner - 1e-9
        })
    };

    // A* over the visibility graph, edges checked when a node is expanded.
    let n = nodes.len();
    let mut best = vec![f64::INFINITY; n];
    let mut from = vec![usize::MAX; n];
    let mut done = vec![false; n];
    let mut open = BinaryHeap::new();
    best[0] = 0.0;
    open.push(Nearest {
        key: (goal - start).norm(),
        node: 0,
    });
    while let Some(Nearest { node: u, .. }) = open.pop() {
        if done[u] {
            continue;
        }
        done[u] = true;
        if u == 1 {
            break;
        }
        let mut relax = |v: usize, length: f64, open: &mut BinaryHeap<Nearest>| {
            let through = best[u] + length;
            if through < best[v] {
                best[v] = through;
                from[v] = u;
                open.push(Nearest {
                    key: through + (goal - nodes[v]).norm(),
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
}
