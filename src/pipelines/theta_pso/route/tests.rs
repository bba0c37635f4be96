use super::*;
use crate::pipelines::theta_pso::route::guide::Guide;
use crate::pipelines::theta_pso::route::search::{self, Graph, Jump, LEVEL_BITS, Step};
use crate::pipelines::theta_pso::route::squeeze::{chebyshev_distance, region_extent};

/// The room `at_with_room` reports is never wrong: within it of the
/// sampled point no point is in a region, so the path builder may skip
/// those samples and find the same squeezed stretches; nor is the extent:
/// every point in a region lies inside it, so a leg that misses it needs no
/// sample at all.
#[test]
fn the_room_round_a_sample_holds_no_squeezed_region() {
    let field = Field::new([[0.0, 40.0], [0.0, 30.0]], &[], 0.25, 5.0);
    let mut region = vec![0u16; field.len()];
    // Two regions: a block and a single cell.
    for (i, r) in region.iter_mut().enumerate() {
        let c = field.center(i);
        if (10.0..12.0).contains(&c.x) && (5.0..20.0).contains(&c.y) {
            *r = 1;
        }
    }
    let lone = field.index_of(Point2::new(30.0, 25.0));
    region[lone] = 2;
    let free = chebyshev_distance(&field, &region);
    let extent = region_extent(&field, &region);
    let map = SqueezeMap {
        field,
        region,
        shapes: vec![FormationShape::Shrink { scale: 0.5 }; 2],
        obstacle_of: Vec::new(),
        free,
        extent,
    };
    let [lower, upper] = map.extent();
    let mut inside = 0;
    for ix in 0..=400 {
        for iy in 0..=300 {
            let p = Point2::new(ix as f64 * 0.1, iy as f64 * 0.1);
            if map.at(p).is_some() {
                assert!(
                    lower.x <= p.x && p.x <= upper.x && lower.y <= p.y && p.y <= upper.y,
                    "{p:?} is in a region but outside the extent {lower:?}-{upper:?}"
                );
                inside += 1;
            }
        }
    }
    assert!(
        inside > 100,
        "the regions hold {inside} of the points sampled"
    );
    // The box is tight: from the block's lower corner to the lone cell's upper.
    assert!(
        (lower.x - 9.875).abs() < 0.3 && (upper.y - 25.125).abs() < 0.3,
        "{lower:?} {upper:?}"
    );
    let mut checked = 0;
    for ix in 0..80 {
        for iy in 0..60 {
            let p = Point2::new(ix as f64 * 0.5 + 0.13, iy as f64 * 0.5 + 0.07);
            let (hit, room) = map.at_with_room(p);
            assert_eq!(hit.is_some(), map.at(p).is_some());
            if room <= 0.0 {
                continue;
            }
            for k in 0..16 {
                let a = k as f64 * std::f64::consts::TAU / 16.0;
                let q = p + nalgebra::Vector2::new(a.cos(), a.sin()) * (room * 0.999);
                assert!(map.at(q).is_none(), "{q:?} within {room} m of {p:?}");
                checked += 1;
            }
        }
    }
    assert!(checked > 10_000, "{checked}");
    // Next to the block the room is small; far from both, large.
    assert!(map.at_with_room(Point2::new(12.6, 10.0)).1 < 1.0);
    assert!(map.at_with_room(Point2::new(25.0, 5.0)).1 > 5.0);
}

/// The length of a found route: its steps between cell centres, its layer
/// changes at `switch` each, its jumps at their length.
fn route_cost(field: &Field, jumps: &[Jump], steps: &[Step], switch: f64) -> f64 {
    let at = |s: &Step| match *s {
        Step::Cell {
            cell, layer, level, ..
        }
        | Step::Jump {
            cell, layer, level, ..
        } => (cell, level * LAYERS + layer),
    };
    steps
        .windows(2)
        .map(|w| match w[1] {
            Step::Jump { tag, .. } => jumps
                .iter()
                .find(|j| j.tag == tag)
                .map_or(0.0, |j| j.length),
            _ => {
                let ((a, la), (b, lb)) = (at(&w[0]), at(&w[1]));
                if a == b && la != lb {
                    switch
                } else {
                    (field.center(a) - field.center(b)).norm()
                }
            }
        })
        .sum()
}

/// The coarse guide only ranks and prunes the search's states: on a site
/// with two walls whose gaps only the narrower layers pass, and a crossing
/// edge through the second, the guided search finds a route as short as
/// Dijkstra's (within the guide's slack) and expands a fraction of it.
#[test]
fn the_guided_search_finds_a_route_as_short_as_dijkstras() {
    let mut discs = Vec::new();
    for k in 0..30 {
        let y = k as f64;
        if !(14.0..17.0).contains(&y) {
            discs.push(Footprint::circle(Point2::new(15.0, y), 0.5));
        }
        if !(5.0..7.0).contains(&y) {
            discs.push(Footprint::circle(Point2::new(30.0, y), 0.5));
        }
    }
    let field = Field::new([[0.0, 45.0], [0.0, 30.0]], &discs, 0.25, 6.0);
    // Nominal needs 2.5 m of clearance, the shrink 1.2 m, the column 0.6 m.
    let need = [2.5, 1.2, 0.6];
    let open: Vec<u64> = (0..field.len())
        .map(|i| {
            (0..LAYERS)
                .filter(|&l| field.clearance(i) >= need[l])
                .fold(0, |bits, l| bits | bit(0, l))
        })
        .collect();
    // The second wall's gap is also a crossing edge of its own.
    let jumps = vec![Jump {
        from: field.index_of(Point2::new(27.0, 6.0)),
        to: field.index_of(Point2::new(33.0, 6.0)),
        length: 6.0,
        pass_at: None,
        crossing: true,
        tag: 0,
        level: 0,
        widest: 0,
    }];
    let graph = Graph {
        field: &field,
        open: &open,
        jumps: &jumps,
        stages: 0,
        switch_cost: 5.0,
        climb_cost: &[],
        start_level: 0,
        goal_level: 0,
    };
    let (s, g) = (
        field.index_of(Point2::new(3.0, 25.0)),
        field.index_of(Point2::new(42.0, 25.0)),
    );
    let guide = Guide::new(&graph, g);
    let guided = search::search(&graph, s, g, |c, l, st| guide.bound(c, l, st));
    let plain = search::search(&graph, s, g, |_, _, _| Some(0.0));
    let (Ok(guided), Ok(plain)) = (guided, plain) else {
        panic!("both searches find the way through the two gaps");
    };
    let (a, b) = (
        route_cost(&field, &jumps, &guided, 5.0),
        route_cost(&field, &jumps, &plain, 5.0),
    );
    assert!(
        a >= b - 1e-9,
        "Dijkstra's {b} is the shortest; the guided found {a}"
    );
    assert!(
        a <= b * 1.02,
        "the guided route {a} m is more than 2 % over Dijkstra's {b} m"
    );
    // The route changes layer to pass the gaps: the guide charged for it.
    assert!(
        guided
            .iter()
            .any(|s| matches!(s, Step::Cell { layer: 1 | 2, .. }))
    );
    // The bound is a lower bound, and more than the straight line (39 m):
    // it knows the walls are there. (Not tight here: a coarse cell at the
    // top of the first wall holds open cells on both sides of it.)
    let bound = guide.bound(s, 0, 0).unwrap_or(f64::INFINITY);
    let straight = (field.center(g) - field.center(s)).norm();
    assert!(
        bound <= b && bound > straight + 5.0,
        "bound {bound}, straight {straight}, route {b}"
    );
    // A start walled in by the relaxation has no bound at all.
    let boxed = field.index_of(Point2::new(15.0, 3.0));
    assert_eq!(guide.bound(boxed, 0, 0), None);
}

/// The search in levels: a wall across the site closes level 0 (the
/// altitude the route starts and ends at) and stands below level 1, where a
/// deck closes the way further on. The route climbs to level 1 where the
/// climb bits allow (clear of both), passes the wall, comes back down
/// before the deck and ends at level 0; the guided search finds it as short
/// as Dijkstra's, and the climbs cost what the graph says.
#[test]
fn the_search_climbs_between_levels_where_every_altitude_between_is_clear() {
    use crate::pipelines::theta_pso::route::search::climb_bit;
    let (x_wall, x_deck) = (12.0, 28.0);
    let field = Field::new([[0.0, 40.0], [0.0, 20.0]], &[], 0.5, 5.0);
    let open: Vec<u64> = (0..field.len())
        .map(|i| {
            let x = field.center(i).x;
            let wall = (x - x_wall).abs() < 1.0;
            let deck = (x - x_deck).abs() < 2.0;
            // Level 0 is closed by the wall, level 1 by the deck; a climb
            // is clear away from both (and the deck stands between the
            // levels, so not under it either).
            let mut bits = 0;
            for layer in 0..LAYERS {
                if !wall {
                    bits |= bit(0, layer);
                }
                if !deck {
                    bits |= bit(1, layer);
                }
                if (x - x_wall).abs() > 2.0 && (x - x_deck).abs() > 3.0 {
                    bits |= climb_bit(0, layer);
                }
            }
            bits
        })
        .collect();
    let climb = [4.0];
    let graph = Graph {
        field: &field,
        open: &open,
        jumps: &[],
        stages: 0,
        switch_cost: 5.0,
        climb_cost: &climb,
        start_level: 0,
        goal_level: 0,
    };
    let (s, g) = (
        field.index_of(Point2::new(2.0, 10.0)),
        field.index_of(Point2::new(38.0, 10.0)),
    );
    let guide = Guide::new(&graph, g);
    let guided = search::search(&graph, s, g, |c, m, st| guide.bound(c, m, st));
    let plain = search::search(&graph, s, g, |_, _, _| Some(0.0));
    let (Ok(guided), Ok(plain)) = (guided, plain) else {
        panic!("both searches climb over the wall and come down before the deck");
    };
    let level_at = |steps: &[Step], x: f64| {
        steps
            .iter()
            .find_map(|st| match *st {
                Step::Cell { cell, level, .. } if (field.center(cell).x - x).abs() < 0.3 => {
                    Some(level)
                }
                _ => None,
            })
            .unwrap_or(usize::MAX)
    };
    for steps in [&guided, &plain] {
        assert_eq!(level_at(steps, x_wall), 1, "over the wall at level 1");
        assert_eq!(level_at(steps, x_deck), 0, "under the deck at level 0");
    }
    // Two climbs (up, down) at 4 each on a 36 m route.
    let cost = |steps: &[Step]| -> f64 {
        steps
            .windows(2)
            .map(|w| match (w[0], w[1]) {
                (
                    Step::Cell {
                        cell: a, level: la, ..
                    },
                    Step::Cell {
                        cell: b, level: lb, ..
                    },
                ) if a == b && la != lb => climb[0],
                (a, b) => {
                    let at = |s: Step| match s {
                        Step::Cell { cell, .. } | Step::Jump { cell, .. } => cell,
                    };
                    (field.center(at(a)) - field.center(at(b))).norm()
                }
            })
            .sum()
    };
    let (a, b) = (cost(&guided), cost(&plain));
    assert!(a >= b - 1e-9 && a <= b * 1.02, "guided {a}, Dijkstra {b}");
    assert!(b >= 36.0 + 8.0 - 1e-9, "{b}: the climbs were charged");
    // Without climb bits there is no way at all.
    let flat: Vec<u64> = open.iter().map(|b| b & LEVEL_BITS).collect();
    let closed = Graph {
        open: &flat,
        ..graph
    };
    assert!(search::search(&closed, s, g, |_, _, _| Some(0.0)).is_err());
}
