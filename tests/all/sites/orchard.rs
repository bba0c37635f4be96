//! An orchard: the large site live planning is held to (issue 51).
//!
//! Ten rows of twenty trees across a 240 m × 160 m site (38,400 m²), the
//! route crossing every row, and twelve UAVs in a 4 × 3 grid 3 m apart. The
//! trees stand 7.8 m apart along a row, jittered by up to 1.5 m, with radii
//! of 0.6-1.6 m and heights of 6-18 m: the grid (10.8 m across with r_Q)
//! passes few gaps whole and shrinks or files through the rest. Written as
//! TOML and read by the mission parser, so it is a file a user could bring.

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use skyform::mission::{self, Mission};

/// Trees per row, and rows: 200 obstacles.
pub const TREES_PER_ROW: usize = 20;
pub const ROWS: usize = 10;

/// The orchard of `seed`, as TOML.
pub fn orchard_toml(seed: u64) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let slots: Vec<String> = (0..4)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| {
            format!(
                "[{:.1}, {:.1}, 0.0]",
                (i as f64 - 1.5) * 3.0,
                (j as f64 - 1.0) * 3.0
            )
        })
        .collect();
    let mut text = format!(
        r#"name = "Orchard of {trees} trees"
description = "Twelve UAVs in a 4 x 3 grid cross an orchard of {trees} trees."
seed = 3

[bounds]
x = [0.0, 240.0]
y = [0.0, 160.0]
z = [5.0, 25.0]

[route]
start = [10.0, 80.0, 12.0]
goal = [230.0, 82.0, 12.0]

[formation]
uav_radius = 0.4
comm_range = 30.0
ground_speed = 4.0
surface_distance = [1.0, 5.0]
slots = [{slots}]

[reconfiguration]
default_shape = "auto"
shrink_scale = 0.5
transition_distance = 15.0
hold_distance = 1.0

[theta_pso]
swarm_size = 100
waypoints = 7
iterations = 150
"#,
        trees = ROWS * TREES_PER_ROW,
        slots = slots.join(", ")
    );
    for row in 0..ROWS {
        let x = 30.0 + 20.0 * row as f64;
        for k in 0..TREES_PER_ROW {
            text.push_str(&format!(
                "\n[[obstacles]]\nname = \"tree {}.{}\"\nkind = \"tree\"\n\
                 center = [{:.2}, {:.2}]\nradius = {:.2}\nheight = {:.1}\n",
                row + 1,
                k + 1,
                x + rng.random_range(-1.5..1.5),
                5.0 + 7.8 * k as f64 + rng.random_range(-1.5..1.5),
                rng.random_range(0.6..1.6),
                rng.random_range(6.0..18.0),
            ));
        }
    }
    text
}

/// The orchard of `seed`, parsed.
pub fn orchard(seed: u64) -> Mission {
    mission::parse_str(&orchard_toml(seed), "orchard.toml")
        .map(|l| l.mission)
        .unwrap_or_else(|e| panic!("the orchard parses: {e}"))
}
