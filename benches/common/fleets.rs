//! The fleets the fleet benchmarks fly: `n` agents in a square room sized
//! for them, one target at the origin, a regular polygon whose sides are the
//! paper's 1.732 m, flying `duration` seconds.

use nalgebra::Point2;
use skyform::mission::{self, Mission};

pub fn fleet_of(n: usize, duration: f64) -> Mission {
    let text = include_str!("../../missions/fleet-triangle.toml");
    let mut m = mission::parse_str(text, "fleet-triangle.toml")
        .map(|l| l.mission)
        .unwrap_or_else(|e| panic!("{e}"));
    let radius = if n > 3 {
        1.732 / (2.0 * (std::f64::consts::PI / n as f64).sin())
    } else {
        1.0
    };
    let half = (radius * 1.5).max(5.0);
    m.bounds.x = [-half, half];
    m.bounds.y = [-half, half];
    m.route.start = nalgebra::Point3::new(-half + 0.5, -half + 0.5, 1.0);
    m.route.goal = nalgebra::Point3::new(half - 0.5, half - 0.5, 1.0);
    m.obstacles.clear();
    m.fleet.agents = n;
    m.fleet.target_distance = radius;
    m.fleet.duration = Some(duration);
    m.fleet.targets.truncate(1);
    m.fleet.targets[0].position = Point2::origin();
    m
}
