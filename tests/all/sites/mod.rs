//! Generated sites for θ-PSO: what a user brings, not what we wrote.
//!
//! A site is a box with one to three walls of cylinders across the route,
//! each closed but for one gap (narrower than the formation but at least
//! 2 r_Q + 0.6 m, or wider than it), walls as close as 15 m apart and
//! slanted up to ±20° without meeting inside the box, clutter between and
//! around them, start and goal a few metres inside the west and east bounds,
//! and a formation of 3 to 12 UAVs in one of nine shapes. Half the sites
//! inspect one or two free-standing obstacles (eq. 8). The swarm is the
//! paper's (100 particles, 150 iterations, 7 waypoints).
//!
//! The wide variant (`generated_wide`) reaches past the family the planner
//! was built against: six more shapes (an echelon of 5, a column of 4, a
//! ring of 8, a V of 5 stacked in two altitudes, a 2 × 2 × 2 box, a 2 × 2
//! grid 1.6 m apart), r_Q from 0.3 to 0.7 m, and the site mirrored and/or
//! transposed, so the route runs east to west or south to north. A tower
//! whose pass cannot hold eq. 8 for the shape (an echelon's facing UAV
//! changes along a pass; `check` refuses it, naming the band) is not
//! inspected.
//!
//! A plan exists by construction: the clutter keeps off the corridor
//! start → gap 1 → … → gap n → goal by the formation's safe radius, and off
//! each gap's crossing, so every site is one a correct planner must plan.
//! Shared by `tests/all/theta_pso_sites.rs` (the CI's share) and
//! `examples/theta_pso_sites.rs` (the measurement over hundreds of runs).

#![allow(dead_code)]

pub mod orchard;
pub mod three_d;

use nalgebra::{Point2, Point3, Vector2, Vector3};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use skyform::base::geometry::segment_point_distance;
use skyform::mission::{self, Mission, Obstacle};
use skyform::pipelines::theta_pso::PassGeometry;

/// The formation shapes of the family: name and slots (x forward, y left).
pub const SHAPES: [&str; 9] = [
    "triangle 3",
    "line 4",
    "diamond 4",
    "V 5",
    "grid 3x2",
    "V 7",
    "grid 3x3",
    "line 6",
    "grid 4x3",
];

/// The wide variant's further shapes, after [`SHAPES`] (index 9 on).
pub const WIDE_SHAPES: [&str; 6] = [
    "echelon 5",
    "column 4",
    "ring 8",
    "V 5 in two altitudes",
    "box 2x2x2",
    "grid 2x2 tight",
];

/// Slots of shape `index` of [`SHAPES`].
pub fn slots(index: usize) -> Vec<Vector3<f64>> {
    let grid = |across: usize, deep: usize, spacing: f64| -> Vec<Vector3<f64>> {
        let mut s = Vec::new();
        for row in 0..deep {
            for col in 0..across {
                s.push(Vector3::new(
                    (deep as f64 - 1.0) / 2.0 * spacing - row as f64 * spacing,
                    (across as f64 - 1.0) / 2.0 * spacing - col as f64 * spacing,
                    0.0,
                ));
            }
        }
        s
    };
    let line = |n: usize, spacing: f64| -> Vec<Vector3<f64>> {
        (0..n)
            .map(|i| {
                Vector3::new(
                    0.0,
                    (n as f64 - 1.0) / 2.0 * spacing - i as f64 * spacing,
                    0.0,
                )
            })
            .collect()
    };
    let vee = |n: usize, spacing: f64| -> Vec<Vector3<f64>> {
        let mut s = vec![Vector3::zeros()];
        for i in 1..n {
            let k = i.div_ceil(2) as f64;
            let side = if i % 2 == 1 { 1.0 } else { -1.0 };
            s.push(Vector3::new(
                -k * spacing * 0.8,
                side * k * spacing * 0.6,
                0.0,
            ));
        }
        centred(s)
    };
    match index % (SHAPES.len() + WIDE_SHAPES.len()) {
        0 => vec![
            Vector3::new(0.0, 2.0, 0.0),
            Vector3::new(-2.0, -1.0, 0.0),
            Vector3::new(2.0, -1.0, 0.0),
        ],
        1 => line(4, 2.5),
        2 => vec![
            Vector3::new(2.5, 0.0, 0.0),
            Vector3::new(0.0, 2.0, 0.0),
            Vector3::new(-2.5, 0.0, 0.0),
            Vector3::new(0.0, -2.0, 0.0),
        ],
        3 => vee(5, 3.0),
        4 => grid(3, 2, 3.0),
        5 => vee(7, 2.5),
        6 => grid(3, 3, 3.0),
        7 => line(6, 2.5),
        8 => grid(4, 3, 3.0),
        9 => centred(
            (0..5)
                .map(|k| Vector3::new(-2.0 * k as f64, 2.0 * k as f64, 0.0))
                .collect(),
        ),
        10 => centred(
            (0..4)
                .map(|k| Vector3::new(-2.5 * k as f64, 0.0, 0.0))
                .collect(),
        ),
        11 => (0..8)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 8.0;
                Vector3::new(4.0 * a.cos(), 4.0 * a.sin(), 0.0)
            })
            .collect(),
        12 => {
            let mut s = vee(5, 3.0);
            for (i, o) in s.iter_mut().enumerate() {
                o.z = if i % 2 == 0 { 1.0 } else { -1.0 };
            }
            centred(s)
        }
        13 => {
            let mut s = Vec::new();
            for z in [-1.5, 1.5] {
                for (x, y) in [(1.5, 1.5), (1.5, -1.5), (-1.5, 1.5), (-1.5, -1.5)] {
                    s.push(Vector3::new(x, y, z));
                }
            }
            s
        }
        _ => grid(2, 2, 1.6),
    }
}

fn centred(mut s: Vec<Vector3<f64>>) -> Vec<Vector3<f64>> {
    let c = s.iter().sum::<Vector3<f64>>() / s.len() as f64;
    for o in &mut s {
        *o -= c;
    }
    s
}

/// A generated site and the dimensions it is reported by.
pub struct Site {
    pub mission: Mission,
    pub walls: usize,
    /// Walls whose gap is narrower than the formation (a reconfiguration).
    pub narrow: usize,
    pub shape: &'static str,
    pub uavs: usize,
    pub inspected: usize,
    /// The closest two walls' distance along the route, metres (∞ for one).
    pub closest_walls: f64,
}

/// Site `index` of the family.
pub fn generated(index: u64) -> Site {
    generate(index, false)
}

/// Site `index` of the wide variant (the module's doc).
pub fn generated_wide(index: u64) -> Site {
    generate(index, true)
}

fn generate(index: u64, wide: bool) -> Site {
    let salt = if wide { 0x3a1d_e000 } else { 0 };
    let mut rng =
        ChaCha8Rng::seed_from_u64(0x51_7e5 ^ salt ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let shapes = SHAPES.len() + if wide { WIDE_SHAPES.len() } else { 0 };
    let shape_index = rng.random_range(0..shapes);
    let shape = SHAPES
        .get(shape_index)
        .or_else(|| WIDE_SHAPES.get(shape_index - SHAPES.len()))
        .copied()
        .unwrap_or("?");
    let formation_slots = slots(shape_index);
    let walls = rng.random_range(1..=3usize);
    let width: f64 = rng.random_range(60.0..100.0);
    // Distances between consecutive walls along x, and the approach legs.
    let spacing: Vec<f64> = (1..walls)
        .map(|_| {
            if rng.random_bool(0.4) {
                rng.random_range(15.0..22.0)
            } else {
                rng.random_range(22.0..45.0)
            }
        })
        .collect();
    // Half the sites inspect one or two towers; they stand in a longer
    // approach field, beside the way in or out.
    let inspected = if rng.random_bool(0.5) {
        rng.random_range(1..=2usize)
    } else {
        0
    };
    let approach: f64 = rng.random_range(30.0..45.0) + if inspected > 0 { 25.0 } else { 0.0 };
    let length = 2.0 * approach + spacing.iter().sum::<f64>();

    let text = format!(
        "name = \"site {index} ({shape}, {walls} wall(s))\"\nseed = {index}\n\
         [bounds]\nx = [0.0, {length}]\ny = [0.0, {width}]\nz = [5.0, 20.0]\n\
         [route]\nstart = [5.0, 30.0, 10.0]\ngoal = [{}, 30.0, 10.0]\n",
        length - 5.0
    );
    let mut m = mission::parse_str(&text, "site.toml")
        .map(|l| l.mission)
        .unwrap_or_else(|e| panic!("{e}"));
    m.formation.slots = formation_slots;
    if wide && shape != "grid 2x2 tight" {
        // The tight grid keeps r_Q = 0.5 m (1.6 m ≥ 2 r_Q + 0.6 m of room).
        m.formation.uav_radius = rng.random_range(0.3..0.7);
    }
    let r_q = m.formation.uav_radius;
    let r_f = m.formation.radius();
    let safe = r_f + r_q;
    let lateral = m
        .formation
        .slots
        .iter()
        .map(|o| o.y.abs())
        .fold(0.0, f64::max)
        + r_q;
    let z_max = m.bounds.z[1];
    // Start and goal a few metres inside the west and east bounds.
    let inset = |rng: &mut ChaCha8Rng| safe + rng.random_range(0.5..4.0);
    m.route.start = Point3::new(
        inset(&mut rng),
        rng.random_range(safe + 5.0..width - safe - 5.0),
        rng.random_range(8.0..17.0),
    );
    m.route.goal = Point3::new(
        length - inset(&mut rng),
        rng.random_range(safe + 5.0..width - safe - 5.0),
        rng.random_range(8.0..17.0),
    );

    // The walls: lines x = x_w + (y − y_w) tan(slant), closed but for one gap.
    let mut x_w = approach;
    let mut previous: Option<(f64, f64)> = None; // (x at y = 0, x at y = width)
    let mut gaps: Vec<(Point2<f64>, Vector2<f64>)> = Vec::new();
    let mut narrow = 0;
    let mut wall_obstacles: Vec<(Point2<f64>, f64, usize)> = Vec::new();
    for w in 0..walls {
        if w > 0 {
            x_w += spacing[w - 1];
        }
        let y_w = width / 2.0;
        // A slant that keeps the wall at least 12 m from the one before.
        let mut slant = 0.0f64;
        for _ in 0..20 {
            slant = rng.random_range(-20.0f64..20.0).to_radians();
            let ends = (x_w - y_w * slant.tan(), x_w + (width - y_w) * slant.tan());
            if previous.is_none_or(|(a, b)| ends.0 - a >= 12.0 && ends.1 - b >= 12.0) {
                break;
            }
            slant = 0.0;
        }
        let ends = (x_w - y_w * slant.tan(), x_w + (width - y_w) * slant.tan());
        previous = Some(ends);
        let along = Vector2::new(slant.sin(), slant.cos());
        let origin = Point2::new(x_w, y_w);
        let half = width / 2.0 / slant.cos();
        let gap_at = rng.random_range(-(half - 2.0 * safe - 4.0)..(half - 2.0 * safe - 4.0));
        let is_narrow = rng.random_bool(0.6);
        let gap = if is_narrow {
            narrow += 1;
            rng.random_range((2.0 * r_q + 0.6)..(2.0 * lateral - 0.05).max(2.0 * r_q + 0.7))
        } else {
            rng.random_range((2.0 * safe + 0.3)..(2.0 * safe + 3.0))
        };
        gaps.push((origin + along * gap_at, Vector2::new(along.y, -along.x)));
        let inside =
            |p: &Point2<f64>| (0.0..=length).contains(&p.x) && (0.0..=width).contains(&p.y);
        for side in [1.0, -1.0] {
            let mut edge = gap_at + side * gap / 2.0;
            loop {
                let r: f64 = rng.random_range(0.5..2.0);
                let center = origin + along * (edge + side * r);
                if !inside(&center) {
                    let t = if side * along.y > 0.0 {
                        (width - origin.y) / along.y
                    } else {
                        -origin.y / along.y
                    };
                    let r_end = ((t - edge) * side).abs().max(0.5) + 0.3;
                    let mut end = origin + along * t;
                    end.y = end.y.clamp(0.0, width);
                    wall_obstacles.push((end, r_end, w));
                    break;
                }
                wall_obstacles.push((center, r, w));
                edge += side * (2.0 * r - rng.random_range(0.1..0.5));
            }
        }
    }
    for (i, (center, r, w)) in wall_obstacles.iter().enumerate() {
        m.obstacles.push(Obstacle {
            name: format!("wall {} post {}", w + 1, i + 1),
            center: *center,
            radius: *r,
            height: z_max + rng.random_range(2.0..10.0),
            footprint: Vec::new(),
            base: 0.0,
            overfly: true,
            clearance_above: 0.0,
            kind: Some("wall".into()),
            inspect: false,
            stand_off: None,
            description: None,
            wire: None,
            inspect_side: None,
        });
    }

    // The corridor a plan can fly: start → each gap's crossing → goal.
    let mut corridor: Vec<Point2<f64>> = vec![m.route.start.xy()];
    for (c, n) in &gaps {
        corridor.push(c - n * (safe + 4.0));
        corridor.push(c + n * (safe + 4.0));
    }
    corridor.push(m.route.goal.xy());
    let off_corridor = |p: &Point2<f64>, keep: f64| {
        corridor
            .windows(2)
            .all(|w| segment_point_distance(&w[0], &w[1], p) > keep)
    };

    // Clutter between and around the walls, and the inspected obstacles.
    let clutter = rng.random_range(2..=8usize);
    let band = m.formation.surface_distance;
    let mut placed = 0;
    let mut inspect_placed = 0;
    let mut tries = 0;
    while (placed < clutter || inspect_placed < inspected) && tries < 20_000 {
        tries += 1;
        let inspect = inspect_placed < inspected && (placed >= clutter || rng.random_bool(0.5));
        let r = if inspect {
            rng.random_range(0.8..2.5)
        } else {
            rng.random_range(0.3..3.0)
        };
        // An inspected obstacle stands beside the corridor (a crew inspects
        // what is on its way); clutter anywhere.
        let c = if inspect {
            // The legs between the crossings (even indices), not across a gap.
            let leg = 2 * rng.random_range(0..corridor.len() / 2);
            let (a, b) = (corridor[leg], corridor[leg + 1]);
            let along = b - a;
            let across = Vector2::new(-along.y, along.x) / along.norm().max(1e-9);
            let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let room = r + band[1] + 2.0 * lateral + 1.0;
            a + along * rng.random_range(0.1..0.9)
                + across * side * (room + rng.random_range(0.5..15.0))
        } else {
            Point2::new(
                rng.random_range(3.0..length - 3.0),
                rng.random_range(3.0..width - 3.0),
            )
        };
        // An inspected obstacle needs room all round for its pass; clutter
        // keeps off the corridor and the walls' gaps.
        let room = if inspect {
            r + band[1] + 2.0 * lateral + 1.0
        } else {
            r + safe + 0.5
        };
        let clear_of_others = m.obstacles.iter().all(|o| {
            let need = if inspect {
                room + o.radius
            } else if o.inspect {
                o.radius + band[1] + 2.0 * lateral + 1.0 + r
            } else {
                r + o.radius + 1.0
            };
            (o.center - c).norm() > need
        });
        let inside =
            c.x - room > 0.0 && c.x + room < length && c.y - room > 0.0 && c.y + room < width;
        let ok = clear_of_others
            && off_corridor(&c, room)
            && (!inspect || inside)
            && (c - m.route.start.xy()).norm() > r + safe + 3.0
            && (c - m.route.goal.xy()).norm() > r + safe + 3.0;
        if !ok {
            continue;
        }
        let name = if inspect {
            inspect_placed += 1;
            format!("tower {inspect_placed}")
        } else {
            placed += 1;
            format!("clutter {placed}")
        };
        m.obstacles.push(Obstacle {
            name,
            center: c,
            radius: r,
            height: if inspect {
                z_max + 5.0
            } else {
                rng.random_range(6.0..30.0)
            },
            footprint: Vec::new(),
            base: 0.0,
            overfly: true,
            clearance_above: 0.0,
            kind: None,
            inspect,
            stand_off: None,
            description: None,
            wire: None,
            inspect_side: None,
        });
    }
    let mut towers = inspect_placed;
    if wide {
        let f = &m.formation;
        for o in m.obstacles.iter_mut().filter(|o| o.inspect) {
            let band = o.stand_off_band(f);
            if PassGeometry::new(&f.slots, o.radius, band, f.inspection_pass).is_err() {
                o.inspect = false;
                towers -= 1;
            }
        }
        transform(&mut m, rng.random_range(0..4u32));
    }
    let uavs = m.formation.slots.len();
    Site {
        walls,
        narrow,
        shape,
        uavs,
        inspected: towers,
        closest_walls: spacing.iter().copied().fold(f64::INFINITY, f64::min),
        mission: m,
    }
}

/// The site mirrored east to west (`turn` bit 0) and/or transposed, x and y
/// swapped (bit 1): the same site, flown in another direction.
fn transform(m: &mut Mission, turn: u32) {
    let (length, width) = (m.bounds.x[1], m.bounds.y[1]);
    let map = |p: Point2<f64>| {
        let p = if turn & 1 == 1 {
            Point2::new(length - p.x, p.y)
        } else {
            p
        };
        if turn & 2 == 2 {
            Point2::new(p.y, p.x)
        } else {
            p
        }
    };
    for o in &mut m.obstacles {
        o.center = map(o.center);
    }
    for q in [&mut m.route.start, &mut m.route.goal] {
        let xy = map(q.xy());
        (q.x, q.y) = (xy.x, xy.y);
    }
    if turn & 2 == 2 {
        m.bounds.x = [0.0, width];
        m.bounds.y = [0.0, length];
    }
}
