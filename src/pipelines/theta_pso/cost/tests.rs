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
