//! The distributed fleet against its paper's experiments (Section 4).

use nalgebra::{Point2, Vector2};
use skyform::mission::{self, FleetPush, FleetTarget, Mission, Obstacle};
use skyform::pipelines::fleet::{self, FleetOutcome};
use skyform::pipelines::{CancelToken, Silent};

fn triangle_mission() -> Mission {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/missions/fleet-triangle.toml");
    mission::load(std::path::Path::new(path)).unwrap().mission
}

/// One agent (Section 4.1: d_d = 0 in Table 1), starting at `start`.
fn one_agent(start: Point2<f64>, targets: &[(f64, [f64; 2])], duration: f64) -> Mission {
    let mut m = triangle_mission();
    m.obstacles.clear();
    let f = &mut m.fleet;
    f.agents = 1;
    f.target_distance = 0.0;
    f.initial_positions = vec![start];
    f.targets = targets
        .iter()
        .map(|&(time, p)| FleetTarget::around(time, Point2::new(p[0], p[1])))
        .collect();
    f.duration = Some(duration);
    m
}

fn run(m: &Mission, seed: u64) -> FleetOutcome {
    let report = mission::validate(m);
    assert!(report.iter().all(|d| !d.is_error()), "{report:?}");
    fleet::plan(m, seed, &mut Silent, &CancelToken::new()).unwrap()
}

fn last_xy(o: &FleetOutcome, agent: usize) -> Point2<f64> {
    o.agents[agent].samples.last().unwrap().position.xy()
}

/// Section 4.1: one agent reaches three consecutive targets.
#[test]
fn one_agent_alone_reaches_each_target() {
    let targets = [(0.0, [2.0, 1.0]), (15.0, [-1.0, 2.0]), (30.0, [0.0, -2.0])];
    let o = run(&one_agent(Point2::new(-3.0, -3.0), &targets, 45.0), 1);
    for (k, t) in o.targets.iter().enumerate() {
        let after = t
            .converged_after
            .unwrap_or_else(|| panic!("target {k} never reached"));
        assert!(after < 14.0, "target {k} took {after} s");
    }
    assert!((last_xy(&o, 0) - Point2::new(0.0, -2.0)).norm() < 0.05);
    // At 0.4 m per τ = 0.1 s at most: the reference never jumps further.
    for w in o.agents[0].samples.windows(2) {
        let jump = (w[1].reference - w[0].reference).xy().norm();
        assert!(jump <= 0.4 * 2.0 + 1e-9, "{jump}");
    }
}

/// Section 4.2: a push while hovering over the target; the planner brings
/// the agent back.
#[test]
fn one_agent_recovers_from_a_push() {
    let mut m = one_agent(Point2::new(1.0, 1.0), &[(0.0, [1.0, 1.0])], 20.0);
    m.fleet.pushes = vec![FleetPush {
        agent: 0,
        time: 5.0,
        impulse: Vector2::new(0.6, 0.3),
    }];
    let o = run(&m, 2);
    let displaced = o.agents[0]
        .samples
        .iter()
        .map(|s| (s.position.xy() - Point2::new(1.0, 1.0)).norm())
        .fold(0.0, f64::max);
    assert!(displaced > 0.3, "the push moved it {displaced} m");
    let before: f64 = o.agents[0]
        .samples
        .iter()
        .filter(|s| s.t < 5.0)
        .map(|s| (s.position.xy() - Point2::new(1.0, 1.0)).norm())
        .fold(0.0, f64::max);
    assert!(before < 0.01, "hovering before the push: {before}");
    assert!(
        (last_xy(&o, 0) - Point2::new(1.0, 1.0)).norm() < 0.05,
        "{}",
        last_xy(&o, 0)
    );
}

/// Section 4.3: an obstacle on the way; the agent goes around it and never
/// comes within the safety distance c of its surface.
#[test]
fn one_agent_goes_around_an_obstacle_outside_the_safety_distance() {
    let mut m = one_agent(Point2::new(-3.5, 0.2), &[(0.0, [3.5, 0.0])], 25.0);
    m.bounds.x = [-5.0, 5.0];
    m.obstacles = vec![Obstacle::standing(
        "barrier",
        Point2::new(0.0, 0.0),
        0.3,
        2.5,
    )];
    let o = run(&m, 3);
    assert!(
        (last_xy(&o, 0) - Point2::new(3.5, 0.0)).norm() < 0.05,
        "{}",
        last_xy(&o, 0)
    );
    let closest = o.closest_obstacle.clone().unwrap();
    assert!(closest.distance >= m.fleet.safety_distance, "{closest:?}");
    // It did have to deviate: somewhere it was well off the straight line.
    let deviation = o.agents[0]
        .samples
        .iter()
        .map(|s| s.position.y.abs())
        .fold(0.0, f64::max);
    assert!(deviation > 0.8, "{deviation}");
}

/// Section 4.4, Fig. 13: three agents from random starts form the triangle
/// (1.732 m apart, 1 m from each target) at every one of four targets, and
/// never come closer than c, for ten seeds.
#[test]
fn three_agents_form_the_triangle_and_keep_apart_for_ten_seeds() {
    let m = triangle_mission();
    for seed in 0..10 {
        let o = run(&m, seed);
        assert!(o.converged(), "seed {seed}: {:?}", o.targets);
        assert!(o.kept_apart(), "seed {seed}: {:?}", o.closest_agents);
        let obstacle = o.closest_obstacle.clone().unwrap();
        assert!(
            obstacle.distance >= m.fleet.safety_distance,
            "seed {seed}: {obstacle:?}"
        );
        assert_eq!(o.distances.len(), 3);
        for d in &o.distances {
            let last = *d.values.last().unwrap();
            assert!(
                (last - 1.732).abs() / 1.732 < 0.05,
                "seed {seed}: {}-{} ends {last}",
                d.a,
                d.b
            );
            assert!((d.desired - 3f64.sqrt()).abs() < 1e-12);
        }
    }
}

#[test]
fn results_do_not_depend_on_the_number_of_threads() {
    let mut m = triangle_mission();
    m.fleet.duration = Some(10.0);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| run(&m, 4))
    };
    assert_eq!(on(1), on(2));
}

#[test]
fn thirty_agents_run_with_their_neighbourhoods() {
    let mut m = triangle_mission();
    m.bounds.x = [-20.0, 20.0];
    m.bounds.y = [-20.0, 20.0];
    m.obstacles.clear();
    m.fleet.agents = 30;
    m.fleet.target_distance = 9.0;
    m.fleet.duration = Some(3.0);
    m.fleet.targets.truncate(1);
    let o = run(&m, 5);
    assert_eq!(o.agents.len(), 30);
    assert!(o.distances.is_empty(), "no n² series for 30 agents");
    for a in &o.agents {
        // Every τ = 0.1 s, 30 rounds at least; 20 particles × (1 + 20 iterations) each.
        assert!(a.decisions >= 30, "{}", a.decisions);
        assert_eq!(a.evaluations, a.decisions * 20 * 21);
    }
}

/// The errors validation gives `m`, as `path: message`.
fn errors(m: &Mission) -> Vec<String> {
    mission::validate(m)
        .into_iter()
        .filter(|d| d.is_error())
        .map(|d| format!("{}: {}", d.path, d.message))
        .collect()
}

fn with_distances(agents: usize, target_distance: f64, distances: Vec<Vec<f64>>) -> Mission {
    let mut m = triangle_mission();
    m.fleet.agents = agents;
    m.fleet.target_distance = target_distance;
    m.fleet.distances = distances;
    m
}

/// The distances of a square of side 2 m (diagonal 2√2), agents in order
/// round it.
fn square_of_side_2() -> Vec<Vec<f64>> {
    let (a, d) = (2.0, 2.0 * 2f64.sqrt());
    vec![
        vec![0.0, a, d, a],
        vec![a, 0.0, a, d],
        vec![d, a, 0.0, a],
        vec![a, d, a, 0.0],
    ]
}

/// Eq. 4's ∂_d must be a formation: the paper's triangle as written (1.732
/// for √3), a square round its circle, and the default regular polygons of
/// 2 to 12 agents written out pass.
#[test]
fn a_formation_the_fleet_can_stand_in_passes() {
    let s = 1.732;
    let triangle = vec![vec![0.0, s, s], vec![s, 0.0, s], vec![s, s, 0.0]];
    assert!(errors(&with_distances(3, 1.0, triangle)).is_empty());
    let square = square_of_side_2();
    assert!(errors(&with_distances(4, 2f64.sqrt(), square)).is_empty());
    for n in 2..=12 {
        let polygon = fleet::polygon_distances(n, 3.0);
        let found = errors(&with_distances(n, 3.0, polygon));
        assert!(found.is_empty(), "{n} agents: {found:?}");
    }
}

/// A triangle that does not close is refused at its longest entry, naming
/// the three agents and the sum (the triangle inequality); so is a square
/// whose diagonal does not fit the circle d_ip^d gives it, naming the target.
#[test]
fn distances_no_triangle_can_have_are_refused_naming_the_triangle() {
    let found = errors(&with_distances(
        3,
        3.0,
        vec![
            vec![0.0, 1.0, 5.0],
            vec![1.0, 0.0, 2.0],
            vec![5.0, 2.0, 0.0],
        ],
    ));
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0]
            .starts_with("fleet.distances[0][2]: no formation in the plane has these distances:")
            && found[0].contains("agent 1, agent 2 and agent 3 cannot form a triangle")
            && found[0].contains("distances[0][2] = 5 m is longer than")
            && found[0].contains("= 3 m"),
        "{found:?}"
    );
    let square = square_of_side_2();
    // 1 m from the target, two corners 2.83 m apart cannot be.
    let found = errors(&with_distances(4, 1.0, square));
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].starts_with("fleet.distances[0][2]")
            && found[0].contains("with the target: agent 1, agent 3 and the target cannot form")
            && found[0].contains("must lie on a circle of that radius"),
        "{found:?}"
    );
}

/// Four agents all 2 m apart are a tetrahedron's corners: every triangle
/// closes, but no plane holds them (their Cayley–Menger determinant is not
/// 0); refused at the entry that misses, naming the agents it was placed
/// from and the tolerance.
#[test]
fn distances_that_need_a_third_dimension_are_refused_naming_the_entry() {
    let r = 2.0 * (3.0f64 / 8.0).sqrt(); // the tetrahedron's circumradius
    let all = vec![vec![2.0; 4]; 4];
    let mut tetrahedron = all.clone();
    for (i, row) in tetrahedron.iter_mut().enumerate() {
        row[i] = 0.0;
    }
    let found = errors(&with_distances(4, r, tetrahedron));
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].starts_with(
            "fleet.distances[2][3]: no formation in the plane has these distances: placed from"
        ) && found[0].contains("come 3.464 m apart, but distances[2][3] = 2 m")
            && found[0].contains("fleet.tolerance allows ± 0.100 m"),
        "{found:?}"
    );
}

/// `skyform check` refuses the impossible matrix with the file, the line
/// and the field, and exits non-zero.
#[test]
fn check_refuses_an_impossible_matrix_with_its_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("fleet.toml");
    let m = with_distances(
        3,
        3.0,
        vec![
            vec![0.0, 1.0, 5.0],
            vec![1.0, 0.0, 2.0],
            vec![5.0, 2.0, 0.0],
        ],
    );
    std::fs::write(&file, mission::to_toml_string(&m).unwrap()).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_skyform"))
        .arg("check")
        .arg(&file)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!out.status.success(), "{text}");
    assert!(
        text.contains("fleet.toml:") && text.contains("fleet.distances[0][2]"),
        "{text}"
    );
    assert!(text.contains("cannot form a triangle"), "{text}");
}
