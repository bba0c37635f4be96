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
        .map(|&(time, p)| FleetTarget {
            time,
            position: Point2::new(p[0], p[1]),
        })
        .collect();
    f.duration = duration;
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
    m.obstacles = vec![Obstacle {
        name: "barrier".into(),
        center: Point2::new(0.0, 0.0),
        radius: 0.3,
        height: 2.5,
        kind: None,
        inspect: false,
        stand_off: None,
    }];
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
    m.fleet.duration = 10.0;
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
    m.fleet.duration = 3.0;
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
