use super::*;
use crate::pipelines::theta_pso::route::guide::Guide;
use crate::pipelines::theta_pso::route::search::{self, Graph, Jump, Step};

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
        Step::Cell { cell, layer } | Step::Jump { cell, layer, .. } => (cell, layer),
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
            discs.push(Disc::round(Point2::new(15.0, y), 0.5));
        }
        if !(5.0..7.0).contains(&y) {
            discs.push(Disc::round(Point2::new(30.0, y), 0.5));
        }
    }
    let field = Field::new([[0.0, 45.0], [0.0, 30.0]], &discs, 0.25, 6.0);
    // Nominal needs 2.5 m of clearance, the shrink 1.2 m, the column 0.6 m.
    let need = [2.5, 1.2, 0.6];
    let open: Vec<u8> = (0..field.len())
        .map(|i| {
            (0..LAYERS)
                .filter(|&l| field.clearance(i) >= need[l])
                .fold(0, |bits, l| bits | bit(l))
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
    }];
    let graph = Graph {
        field: &field,
        open: &open,
        jumps: &jumps,
        stages: 0,
        switch_cost: 5.0,
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
