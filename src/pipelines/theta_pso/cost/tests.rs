use super::*;
use crate::pipelines::theta_pso::path::CentroidPath;

/// A 60 m × 40 m box, the formation's default triangle, and one post of
/// radius 3 m in the middle of the straight line from start to goal.
fn one_post() -> Mission {
    let text = "name = \"one post\"\n\
         [bounds]\nx = [0.0, 60.0]\ny = [0.0, 40.0]\nz = [5.0, 15.0]\n\
         [route]\nstart = [5.0, 20.0, 10.0]\ngoal = [55.0, 20.0, 10.0]\n\
         [[obstacles]]\nname = \"post\"\ncenter = [30.0, 20.0]\nradius = 3.0\nheight = 30.0\n";
    match crate::mission::parse_str(text, "one-post.toml") {
        Ok(loaded) => loaded.mission,
        Err(e) => panic!("{e}"),
    }
}

/// Deb's rule (cost.rs, `INFEASIBLE_STEP`): a short path through the post
/// has the smaller J, yet ranks after a long path round it, whatever the
/// weights make of the lengths.
#[test]
fn a_feasible_path_ranks_before_a_shorter_infeasible_one() {
    let m = one_post();
    let model = CostModel::new(&m, &[]);
    let (s, g) = (m.route.start, m.route.goal);
    let through = CentroidPath::bare(vec![s, g]);
    let round = CentroidPath::bare(vec![
        s,
        Point3::new(20.0, 32.0, 10.0),
        Point3::new(40.0, 32.0, 10.0),
        g,
    ]);
    let a = model.evaluate_below(&through, f64::INFINITY);
    let b = model.evaluate_below(&round, f64::INFINITY);
    assert!(a.terms.length < b.terms.length);
    assert!(
        a.terms.obstacle > 0.0,
        "the straight path must clip the post"
    );
    assert_eq!(b.terms.obstacle, 0.0, "the detour must keep clear");
    assert_eq!(b.objective, b.terms.total, "a clear path's objective is J");
    assert!(a.objective >= a.terms.total + INFEASIBLE_STEP);
    assert!(a.objective > b.objective);
}

/// The step ranks infeasible paths among themselves by how badly they
/// break the constraints: a path that grazes the post ranks before one
/// through its centre.
#[test]
fn among_infeasible_paths_the_smaller_violation_ranks_first() {
    let m = one_post();
    let model = CostModel::new(&m, &[]);
    let (s, g) = (m.route.start, m.route.goal);
    let graze = |y: f64| {
        CentroidPath::bare(vec![
            s,
            Point3::new(25.0, y, 10.0),
            Point3::new(35.0, y, 10.0),
            g,
        ])
    };
    let centre = model.evaluate_below(&graze(20.0), f64::INFINITY);
    let edge = model.evaluate_below(&graze(24.5), f64::INFINITY);
    assert!(centre.objective >= INFEASIBLE_STEP && edge.objective >= INFEASIBLE_STEP);
    assert!(edge.terms.obstacle < centre.terms.obstacle);
    assert!(edge.objective < centre.objective);
}

/// The column's pair check (eq. 7 along a column's hold) is the integral of
/// (floor − chord)⁺ over where the column's places sit, exact between the
/// path's vertices: through a sharp corner, where two UAVs 2.5 m apart along
/// the path come within 1.2 m of each other, it matches a 400-times finer
/// sampling of the same integral to 0.1 %, and a straight path has none.
#[test]
fn a_columns_pairs_are_judged_exactly_through_a_sharp_corner() {
    let mut m = one_post();
    m.formation.slots = (0..5)
        .map(|k| Vector3::new(5.0 - 2.5 * k as f64, 0.0, 0.0))
        .collect();
    let model = CostModel::new(&m, &[]);
    let floor = m.formation.closest_pair() + PAIR_FLOOR;
    let spacing = 2.5;
    let sampled = |points: &[Point3<f64>], [t2, t3]: [f64; 2]| {
        let walker = crate::pipelines::theta_pso::path::ArcWalker::new(points);
        let half = 2.0 * spacing;
        let mut sum = 0.0;
        for places in 1..5 {
            let chord = places as f64 * spacing;
            let (from, to) = (t2 - half, t3 + half - chord);
            let steps = ((to - from) / (spacing / 400.0)).ceil() as usize;
            let h = (to - from) / steps as f64;
            for k in 0..steps {
                let u = from + (k as f64 + 0.5) * h;
                let d = (walker.at_extended(u + chord) - walker.at_extended(u)).norm();
                sum += (floor - d).max(0.0) * h;
            }
        }
        sum
    };
    // A 150° turn: the chord of 2.5 m of path round the corner is ~0.65 m.
    let turn = 150f64.to_radians();
    let corner = Point3::new(30.0, 20.0, 10.0);
    let points = vec![
        Point3::new(10.0, 20.0, 10.0),
        corner,
        corner + Vector3::new(turn.cos(), turn.sin(), 0.0) * 20.0,
    ];
    let walker = crate::pipelines::theta_pso::path::ArcWalker::new(&points);
    let hold = [12.0, 28.0];
    let exact = model.column_deficit(&walker, hold, spacing, floor);
    let reference = sampled(&points, hold);
    assert!(reference > 0.1, "the corner must bring places together");
    assert!(
        (exact - reference).abs() <= 1e-3 * reference,
        "exact {exact} against sampled {reference}"
    );
    let straight = vec![Point3::new(10.0, 20.0, 10.0), Point3::new(50.0, 20.0, 10.0)];
    let walker = crate::pipelines::theta_pso::path::ArcWalker::new(&straight);
    assert_eq!(model.column_deficit(&walker, hold, spacing, floor), 0.0);
}

/// Eq. 8 where a change of shape reaches into an inspection pass: the pass
/// is laid out for the nominal shape, so a column held over it moves the
/// facing UAV out to the centroid's line and out of a tight band. The cost
/// then finds the path infeasible (verification would fail the inspection);
/// the same column held clear of the pass, or the pass flown in the nominal
/// shape, costs nothing.
#[test]
fn an_inspection_pass_flown_in_a_changed_shape_is_judged_on_the_facing_uav() {
    use crate::pipelines::theta_pso::inspection::PassGeometry;
    use crate::pipelines::theta_pso::path::{Pass, Zone, ZoneCause};
    let mut m = one_post();
    // A line abreast, 3 m apart: its outer UAV faces the post.
    m.formation.slots = vec![
        Vector3::new(0.0, 3.0, 0.0),
        Vector3::zeros(),
        Vector3::new(0.0, -3.0, 0.0),
    ];
    let band = [2.0, 4.0];
    m.obstacles[0].inspect = true;
    m.obstacles[0].stand_off = Some(band);
    let model = CostModel::new(&m, &[]);
    let geometry = match PassGeometry::new(&m.formation.slots, 3.0, band, 6.0) {
        Ok(g) => g,
        Err(e) => panic!("{e}"),
    };
    // Eastward past the post with the post on the right, the pass centred
    // abeam it (x = 30, arc 25 from x = 5).
    let y = 20.0 + geometry.radius_right;
    let path = |zone: Option<[f64; 2]>| CentroidPath {
        points: vec![Point3::new(5.0, y, 10.0), Point3::new(55.0, y, 10.0)],
        zones: zone
            .map(|hold| Zone {
                causes: vec![ZoneCause::Squeeze {
                    region: 1,
                    pair: [0, 0],
                }],
                shape: Shape::Alignment { spacing: 2.5 },
                arc: (hold[0] + hold[1]) / 2.0,
                hold,
                transition_in: 6.0,
                transition_out: 6.0,
                from: None,
                into: None,
            })
            .into_iter()
            .collect(),
        passes: vec![Pass {
            obstacle: 0,
            arcs: [22.0, 28.0],
            on_left: false,
        }],
        crossed: Vec::new(),
    };
    // In the column every UAV is on the centroid's line: its surface
    // distance abeam is the line's, beyond the band's top.
    assert!(geometry.radius_right - 3.0 > band[1]);
    let over = model.evaluate_below(&path(Some([18.0, 32.0])), f64::INFINITY);
    assert!(over.objective >= INFEASIBLE_STEP, "{over:?}");
    for clear in [None, Some([36.0, 44.0])] {
        let e = model.evaluate_below(&path(clear), f64::INFINITY);
        assert_eq!(e.objective, e.terms.total, "{clear:?}: {e:?}");
    }
}

/// Issue 36: a 200° turn made of three corners within a metre of path
/// costs J_T as the turn it is, not as three of 67° that cost nothing: the
/// mean over the window's positions (1 m either side) of the excess beyond
/// 90°, here (44° × 0.4 + 110° × 1.2 + 43° × 0.4) / 2 = 83.4°; the same
/// corners 5 m apart are three gentle turns; a zigzag's corners cancel; an
/// isolated hairpin costs its 90° beyond 90°.
#[test]
fn a_sharp_turn_spread_over_close_corners_is_never_free() {
    let deg = std::f64::consts::PI / 180.0;
    let path = |leg: f64, turns: &[f64]| {
        let mut points = vec![Point3::new(0.0, 0.0, 10.0), Point3::new(20.0, 0.0, 10.0)];
        let mut heading: f64 = 0.0;
        for (k, t) in turns.iter().enumerate() {
            heading += t * deg;
            let length = if k + 1 == turns.len() { 20.0 } else { leg };
            let last = *points.last().unwrap();
            points.push(last + Vector3::new(heading.cos(), heading.sin(), 0.0) * length);
        }
        points
    };
    let tight = turning_excess(&path(0.4, &[67.0, 67.0, 66.0]), 1.0);
    assert!((tight - 83.4 * deg).abs() < 1e-9, "{}", tight / deg);
    let spread = turning_excess(&path(5.0, &[67.0, 67.0, 66.0]), 1.0);
    assert_eq!(spread, 0.0);
    let zigzag = turning_excess(&path(0.4, &[80.0, -80.0, 80.0, -80.0]), 1.0);
    assert_eq!(zigzag, 0.0);
    let hairpin = turning_excess(&path(0.4, &[180.0]), 1.0);
    assert!((hairpin - 90.0 * deg).abs() < 1e-9);
}

/// The circle the cost culls obstacles by holds every UAV's piece of an
/// interval (so an obstacle `safe` beyond it adds nothing), and is no
/// larger than the points need: the farthest one is on it.
#[test]
fn the_enclosing_circle_holds_every_piece() {
    use nalgebra::Point3;
    let a = [
        Point3::new(0.0, 0.0, 5.0),
        Point3::new(3.0, -1.0, 6.0),
        Point3::new(-2.0, 4.0, 5.0),
    ];
    let b = [
        Point3::new(0.5, 0.2, 5.0),
        Point3::new(3.6, -0.7, 6.0),
        Point3::new(-1.4, 4.5, 5.0),
    ];
    let (middle, spread) = super::enclosing(&a, &b);
    let mut farthest: f64 = 0.0;
    for (p, q) in a.iter().zip(&b) {
        for k in 0..=10 {
            let x = p + (q - p) * (k as f64 / 10.0);
            let d = (x.xy() - middle).norm();
            assert!(
                d <= spread + 1e-12,
                "{x} is {d} from the middle, spread {spread}"
            );
            farthest = farthest.max(d);
        }
    }
    assert!((farthest - spread).abs() < 1e-12, "{farthest} vs {spread}");
}
