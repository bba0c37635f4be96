//! Generated sites in three dimensions: what a survey crew brings, past the
//! walls of posts the planner was first built against (issue 37).
//!
//! A site is a box crossed by one to three *barriers* between a start near
//! the west bound and a goal near the east bound, then mirrored and/or
//! transposed. Each barrier closes the way but for what a plan may use:
//! - a **wall of posts** (cylinders, radius 0.3-1.5 m) or of **wall
//!   segments** (thin rectangles), slanted up to ±35°, with one real gap
//!   (narrower than the formation but a column's width and 0.6 m more, or
//!   wider than it), sometimes a wide **decoy** gap that opens into a closed
//!   pocket (walled off between this wall and the next, or a U behind the
//!   last); its posts as tall as the sky, **low** under the flight (flown
//!   over, gapless or not) or above the flight with room under the ceiling
//!   (**climbed**);
//! - a **row of footprints** (rectangles and L-shapes, transformer bays and
//!   buildings) with one or two aisles narrower than the formation (a
//!   column's width and more) or wider, live (`overfly = false`), tall, or
//!   low enough to fly over;
//! - a **deck** across the whole width (a rectangle from a base to a top)
//!   with room under it, over it, or both, sometimes on piers;
//! - a **low fence** (a thin wall polygon) whose top is inside the band,
//!   under or over the flight, gapless or with a gap.
//!
//! Consecutive barriers stand 10-14 m apart (four in ten) or 14-35 m.
//! Half the sites inspect one obstacle (eq. 8): a tree or a tower, tall or
//! short (its top inside the band), in open ground, three in ten of them 2-3
//! m from a bound. Clutter stands off the way. The formation is one of 30
//! shapes of 3-12 UAVs (the family's fifteen, the eight, seven
//! more), r_Q 0.3-0.6 m; the band's floor 2-8 m and its ceiling 10-20 m above.
//!
//! A plan exists by construction: every barrier leaves a way the formation
//! (in some shape, at some altitude of the band) can fly, the clutter keeps
//! off the way, and the inspected obstacle has room round it. The site is
//! written as a mission file's TOML (`Site3d::toml`), so it can be run from
//! the command line as a user would (`skyform run theta-pso FILE`).

use std::f64::consts::PI;
use std::fmt::Write as _;

use nalgebra::{Point2, Vector2, Vector3};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use skyform::base::geometry::segment_point_distance;
use skyform::mission::{self, Mission};

/// Shapes beyond [`super::SHAPES`] and [`super::WIDE_SHAPES`]: the issue's
/// eight, then seven more.
pub const MORE_SHAPES: [&str; 15] = [
    "wedge 6",
    "hexagon 7",
    "staggered rows 7",
    "arrow 7",
    "line 5",
    "grid 4x2",
    "cross 5",
    "deep grid 4x3",
    "ring 10",
    "double column 6",
    "diamond 9",
    "V 11",
    "wide grid 4x3",
    "trapezoid 5",
    "stacked line 6",
];

/// Every shape of the family: name and slots (x forward, y left, z up).
pub fn shape(index: usize) -> (&'static str, Vec<Vector3<f64>>) {
    let base = super::SHAPES.len() + super::WIDE_SHAPES.len();
    let index = index % (base + MORE_SHAPES.len());
    if index < super::SHAPES.len() {
        return (super::SHAPES[index], super::slots(index));
    }
    if index < base {
        return (
            super::WIDE_SHAPES[index - super::SHAPES.len()],
            super::slots(index),
        );
    }
    let v = |x: f64, y: f64| Vector3::new(x, y, 0.0);
    let grid = |across: usize, deep: usize, dx: f64, dy: f64| -> Vec<Vector3<f64>> {
        let mut s = Vec::new();
        for row in 0..deep {
            for col in 0..across {
                s.push(v(-(row as f64) * dx, col as f64 * dy));
            }
        }
        s
    };
    let k = index - base;
    let slots = match k {
        // Rows of 1, 2, 3 behind one another.
        0 => vec![
            v(2.5, 0.0),
            v(0.0, 1.4),
            v(0.0, -1.4),
            v(-2.5, 2.8),
            v(-2.5, 0.0),
            v(-2.5, -2.8),
        ],
        1 => std::iter::once(v(0.0, 0.0))
            .chain((0..6).map(|i| {
                let a = i as f64 * PI / 3.0;
                v(2.6 * a.cos(), 2.6 * a.sin())
            }))
            .collect(),
        2 => (0..4)
            .map(|i| v(1.3, -4.5 + 3.0 * i as f64))
            .chain((0..3).map(|i| v(-1.3, -3.0 + 3.0 * i as f64)))
            .collect(),
        3 => vec![
            v(3.0, 0.0),
            v(1.2, 1.6),
            v(1.2, -1.6),
            v(-0.6, 3.2),
            v(-0.6, -3.2),
            v(-1.2, 0.0),
            v(-3.4, 0.0),
        ],
        4 => (0..5).map(|i| v(0.0, -5.0 + 2.5 * i as f64)).collect(),
        5 => grid(4, 2, 3.0, 3.0),
        6 => vec![
            v(0.0, 0.0),
            v(2.5, 0.0),
            v(-2.5, 0.0),
            v(0.0, 2.5),
            v(0.0, -2.5),
        ],
        7 => grid(3, 4, 3.0, 3.0),
        8 => (0..10)
            .map(|i| {
                let a = i as f64 * PI / 5.0;
                v(4.6 * a.cos(), 4.6 * a.sin())
            })
            .collect(),
        9 => grid(2, 3, 2.5, 2.2),
        10 => {
            let mut s = Vec::new();
            for i in -1..=1 {
                for j in -1..=1 {
                    // A 3 × 3 grid turned 45°: a diamond.
                    let (x, y) = (i as f64 * 2.4, j as f64 * 2.4);
                    let c = std::f64::consts::FRAC_1_SQRT_2;
                    s.push(v(c * (x - y), c * (x + y)));
                }
            }
            s
        }
        11 => {
            let mut s = vec![v(0.0, 0.0)];
            for i in 1..=5 {
                let f = i as f64;
                s.push(v(-1.4 * f, 1.7 * f));
                s.push(v(-1.4 * f, -1.7 * f));
            }
            s
        }
        12 => grid(4, 3, 2.4, 3.2),
        13 => vec![
            v(1.5, 1.6),
            v(1.5, -1.6),
            v(-1.5, 3.6),
            v(-1.5, 0.0),
            v(-1.5, -3.6),
        ],
        _ => (0..6)
            .map(|i| {
                Vector3::new(
                    0.0,
                    -3.0 + 2.0 * (i / 2) as f64 + if i % 2 == 0 { 0.6 } else { -0.6 },
                    if i % 2 == 0 { 1.0 } else { -1.0 },
                )
            })
            .collect(),
    };
    (MORE_SHAPES[k], centred(slots))
}

fn centred(mut s: Vec<Vector3<f64>>) -> Vec<Vector3<f64>> {
    let c = s.iter().sum::<Vector3<f64>>() / s.len() as f64;
    for o in &mut s {
        *o -= c;
    }
    s
}

/// How many shapes [`shape`] knows.
pub fn shapes() -> usize {
    super::SHAPES.len() + super::WIDE_SHAPES.len() + MORE_SHAPES.len()
}

/// A generated site, its mission file and the dimensions it is reported by.
pub struct Site3d {
    pub mission: Mission,
    pub toml: String,
    /// (dimension, value) pairs: the barriers, the shape, the inspection…
    pub dims: Vec<(&'static str, String)>,
}

/// An obstacle as the generator places it.
#[derive(Clone)]
struct Body {
    name: String,
    kind: &'static str,
    outline: Outline,
    base: f64,
    height: f64,
    overfly: bool,
    inspect: bool,
}

#[derive(Clone)]
enum Outline {
    Circle(Point2<f64>, f64),
    Polygon(Vec<Point2<f64>>),
}

impl Outline {
    /// Distance in the plane from `p` to the outline (0 inside).
    fn distance(&self, p: &Point2<f64>) -> f64 {
        match self {
            Outline::Circle(c, r) => ((p - c).norm() - r).max(0.0),
            Outline::Polygon(v) => skyform::base::geometry::polygon_signed_distance(v, p).max(0.0),
        }
    }

    fn map(&mut self, f: &dyn Fn(Point2<f64>) -> Point2<f64>) {
        match self {
            Outline::Circle(c, _) => *c = f(*c),
            Outline::Polygon(v) => v.iter_mut().for_each(|p| *p = f(*p)),
        }
    }
}

/// The formation's figures the generator sizes the site by.
struct Fig {
    r_q: f64,
    /// Farthest UAV from the centroid, 3-D (r_F) and in the plane.
    r_f: f64,
    /// Half the formation's lateral width, r_Q included.
    lateral: f64,
    /// Half its height (the largest |z| of a slot).
    half_height: f64,
    /// What the lowest (highest) UAV keeps above (below) an obstacle it
    /// passes over (under): r_Q + the safety margin + the cost's margin.
    clear: f64,
}

/// Which barrier, and how it is passed.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Barrier {
    Posts,
    Segments,
    Bays,
    Deck,
    Fence,
}

impl Barrier {
    fn name(self) -> &'static str {
        match self {
            Barrier::Posts => "posts",
            Barrier::Segments => "wall segments",
            Barrier::Bays => "footprint row",
            Barrier::Deck => "deck",
            Barrier::Fence => "low fence",
        }
    }
}

/// Site `index` of the family (see the module's doc). Sites whose mission
/// `check` would refuse (a rare collision of the generator's choices) are
/// drawn again from the next sub-seed, so every index is a valid site.
pub fn generated_3d(index: u64) -> Site3d {
    generate(index, false)
}

/// Site `index` of the hard variant: two to four barriers, most 10-14 m
/// apart, narrower sites, a band 8-12 m deep, r_Q up to 0.7 m, decoys and
/// inspections more often (half of them near a bound), posts of uneven
/// heights (±0.5 m), more clutter.
pub fn generated_3d_hard(index: u64) -> Site3d {
    generate(index, true)
}

fn generate(index: u64, hard: bool) -> Site3d {
    for attempt in 0..80u64 {
        if let Some(site) = attempt_site(index, attempt, hard) {
            return site;
        }
    }
    panic!("site {index}: no valid site in 80 draws")
}

/// Heights of a barrier: a top above the sky (`Full`), a top the formation
/// flies over at the start's and goal's altitudes (`Under`), a top it must
/// climb over (`Climb`).
#[derive(Clone, Copy, PartialEq, Debug)]
enum Height {
    Full,
    Under,
    Climb,
}

fn attempt_site(index: u64, attempt: u64, hard: bool) -> Option<Site3d> {
    let salt = if hard { 0x4a2d_0000 } else { 0 };
    let mut rng = ChaCha8Rng::seed_from_u64(
        0x3d_5172
            ^ salt
            ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ attempt.wrapping_mul(0xabcd_ef01),
    );
    // The hard variant's odds and ranges.
    let (close_odds, decoy_odds, inspect_odds, bound_odds) = if hard {
        (0.7, 0.75, 0.8, 0.5)
    } else {
        (0.4, 0.45, 0.5, 0.3)
    };
    let shape_index = rng.random_range(0..shapes());
    let (shape_name, slots) = shape(shape_index);
    let r_q: f64 = if shape_name == "grid 2x2 tight" {
        0.5
    } else {
        rng.random_range(0.3..if hard { 0.7 } else { 0.6 })
    };
    let r_f = slots.iter().map(|o| o.norm()).fold(0.0, f64::max);
    let lateral = slots.iter().map(|o| o.y.abs()).fold(0.0, f64::max) + r_q;
    let half_height = slots.iter().map(|o| o.z.abs()).fold(0.0, f64::max);
    let fig = Fig {
        r_q,
        r_f,
        lateral,
        half_height,
        clear: r_q + 0.1 + 0.1,
    };
    let safe = r_f + r_q;
    let column = 2.0 * (r_q + 0.2);

    // The band: its floor, its ceiling, the flight's altitude.
    let floor: f64 = rng.random_range(2.0..8.0);
    let ceiling = floor
        + if hard {
            rng.random_range(8.0..12.0)
        } else {
            rng.random_range(10.0..20.0)
        };
    let usable = [floor + half_height + 0.5, ceiling - half_height - 0.5];
    let barriers = if hard {
        rng.random_range(2..=4usize)
    } else {
        rng.random_range(1..=3usize)
    };
    let width: f64 = if hard {
        rng.random_range(40.0..70.0)
    } else {
        rng.random_range(50.0..90.0)
    };
    let spacing: Vec<f64> = (1..barriers)
        .map(|_| {
            if rng.random_bool(close_odds) {
                rng.random_range(10.0..14.0)
            } else {
                rng.random_range(14.0..35.0)
            }
        })
        .collect();
    let inspected = rng.random_bool(inspect_odds);
    // Open ground before the first barrier and after the last: at least
    // room for the formation at the start and the goal, more for a pass.
    let approach: f64 =
        rng.random_range(25.0..40.0f64).max(4.0 * safe + 14.0) + if inspected { 22.0 } else { 0.0 };
    // No barrier's line comes nearer the west or east bound than this.
    let open_ground = approach * 0.5;
    let length = 2.0 * approach + spacing.iter().sum::<f64>();
    let inset = |rng: &mut ChaCha8Rng| safe + rng.random_range(0.5..4.0);
    let start = Point2::new(
        inset(&mut rng),
        rng.random_range(safe + 4.0..width - safe - 4.0),
    );
    let goal = Point2::new(
        length - inset(&mut rng),
        rng.random_range(safe + 4.0..width - safe - 4.0),
    );
    // The flight's altitude at the start and the goal: the middle third of
    // the band mostly, anywhere in it at times.
    let flight = |rng: &mut ChaCha8Rng| {
        let third = (usable[1] - usable[0]) / 3.0;
        if rng.random_bool(0.7) {
            rng.random_range(usable[0] + third..usable[1] - third)
        } else {
            rng.random_range(usable[0]..usable[1])
        }
    };
    let (start_z, goal_z) = (flight(&mut rng), flight(&mut rng));
    let low_flight = start_z.min(goal_z);
    let high_flight = start_z.max(goal_z);

    let mut bodies: Vec<Body> = Vec::new();
    let mut dims: Vec<(&'static str, String)> = Vec::new();
    // The way a plan can fly: points it passes, in order.
    let mut way: Vec<Point2<f64>> = vec![start];
    let mut kinds: Vec<String> = Vec::new();
    let mut x_w = approach;
    let mut previous_ends: Option<(f64, f64)> = None;
    let mut previous_slant = 0.0f64;
    let mut decoys = 0;
    let mut narrowest = f64::INFINITY;
    let mut max_slant = 0.0f64;
    // Where the gap of the wall before lay along its line (to put the
    // next gap 20-40 m away, as the maze has them).
    let mut last_gap_y: Option<f64> = None;
    // After a decoy whose pocket reaches the next wall: the side of the
    // last gap (−1, +1 along the line) the next gap must not lie on.
    let mut pocket_side: Option<f64> = None;
    // Each barrier's kind and heights, drawn first (a decoy's pocket looks
    // at the barrier after it).
    let plan_of: Vec<(Barrier, Height)> = (0..barriers)
        .map(|_| {
            let kind = match rng.random_range(0..100) {
                0..35 => Barrier::Posts,
                35..50 => Barrier::Segments,
                50..70 => Barrier::Bays,
                70..85 => Barrier::Deck,
                _ => Barrier::Fence,
            };
            let height = match kind {
                Barrier::Posts | Barrier::Segments => match rng.random_range(0..10) {
                    0..6 => Height::Full,
                    6..8 => Height::Under,
                    _ => Height::Climb,
                },
                Barrier::Fence => {
                    if rng.random_bool(0.6) {
                        Height::Under
                    } else {
                        Height::Climb
                    }
                }
                _ => Height::Full,
            };
            (kind, height)
        })
        .collect();
    for b in 0..barriers {
        if b > 0 {
            x_w += spacing[b - 1];
        }
        let close_next = spacing.get(b).is_some_and(|s| *s < 14.0);
        let (kind, height) = plan_of[b];
        // The next barrier is a full wall: a pocket may be closed against it.
        let wall_next = plan_of.get(b + 1).is_some_and(|(k, h)| {
            matches!(k, Barrier::Posts | Barrier::Segments) && *h == Height::Full
        });
        let avoid = pocket_side.take();
        // Walls slant; decks and rows of bays less.
        let widest = match kind {
            Barrier::Posts | Barrier::Segments | Barrier::Fence => 35.0,
            _ => 15.0,
        };
        let y_w = width / 2.0;
        let mut slant = 0.0f64;
        for _ in 0..30 {
            let s: f64 = rng.random_range(-widest..widest);
            let s = s.to_radians();
            let ends = (x_w - y_w * s.tan(), x_w + (width - y_w) * s.tan());
            let apart = previous_ends.is_none_or(|(a, c)| ends.0 - a >= 8.0 && ends.1 - c >= 8.0);
            let inside = [ends.0, ends.1]
                .iter()
                .all(|x| (open_ground..=length - open_ground).contains(x));
            if apart && inside {
                slant = s;
                break;
            }
            slant = previous_slant;
        }
        let ends = (x_w - y_w * slant.tan(), x_w + (width - y_w) * slant.tan());
        if previous_ends.is_some_and(|(a, c)| ends.0 - a < 7.0 || ends.1 - c < 7.0)
            || [ends.0, ends.1]
                .iter()
                .any(|x| !(open_ground..=length - open_ground).contains(x))
        {
            return None;
        }
        previous_ends = Some(ends);
        previous_slant = slant;
        max_slant = max_slant.max(slant.abs().to_degrees());
        let line = Line {
            origin: Point2::new(x_w, y_w),
            along: Vector2::new(slant.sin(), slant.cos()),
            half: width / 2.0 / slant.cos(),
        };
        // A top for a barrier flown over: under the lower flight, or above
        // the higher one with room under the ceiling; `None` when the band
        // leaves no room for it.
        let top_for = |rng: &mut ChaCha8Rng, h: Height| -> Option<f64> {
            match h {
                Height::Full => Some(ceiling + rng.random_range(2.0..10.0)),
                Height::Under => {
                    let hi = low_flight - half_height - fig.clear - 0.4;
                    (hi > 1.0).then(|| rng.random_range(hi.min(1.0 + 0.5 * hi)..hi))
                }
                Height::Climb => {
                    let lo = high_flight - half_height - fig.clear + 0.5;
                    let hi = usable[1] - half_height - fig.clear - 0.8;
                    (hi > lo.max(1.0)).then(|| rng.random_range(lo.max(1.0)..hi))
                }
            }
        };
        let mut label = String::from(kind.name());
        match kind {
            Barrier::Posts | Barrier::Segments | Barrier::Fence => {
                let top = top_for(&mut rng, height)?;
                // Gapless when flown over (half of them), else one gap.
                let gapless = height != Height::Full && rng.random_bool(0.5);
                let mut gaps: Vec<(f64, f64)> = Vec::new();
                let lane = line.half - safe - 4.0;
                if lane < 4.0 {
                    return None;
                }
                if !gapless {
                    let narrow = rng.random_bool(0.6);
                    let w = if narrow {
                        let hi = (2.0 * lateral - 0.05).max(column + 0.9);
                        rng.random_range((column + 0.6).max(2.0 * r_q + 0.6)..hi)
                    } else {
                        rng.random_range(2.0 * safe + 0.3..2.0 * safe + 3.0)
                    };
                    narrowest = narrowest.min(w);
                    let mut at = rng.random_range(-lane..lane);
                    if let Some(y) = last_gap_y {
                        // 20-40 m along from the gap before, when the wall
                        // allows, never towards the pocket before it.
                        let mut found = avoid.is_none();
                        for _ in 0..40 {
                            let t = rng.random_range(-lane..lane);
                            let away = avoid.is_none_or(|s| (t - y) * s < 0.0);
                            if (20.0..=40.0).contains(&(t - y).abs()) && away {
                                at = t;
                                found = true;
                                break;
                            }
                        }
                        if !found {
                            return None;
                        }
                    }
                    gaps.push((at, w));
                    last_gap_y = Some(at);
                    label.push_str(if narrow { ", narrow gap" } else { ", wide gap" });
                } else {
                    label.push_str(", gapless");
                }
                // A wide decoy into a closed pocket: on a wall of full height
                // with a gap, away from the way on to the next gap.
                let decoy = height == Height::Full
                    && !gaps.is_empty()
                    && kind != Barrier::Fence
                    && rng.random_bool(decoy_odds)
                    && ((close_next && wall_next) || b + 1 == barriers);
                let mut pocket: Option<(f64, f64)> = None;
                if decoy {
                    let (at, w) = gaps[0];
                    let dw = rng.random_range(2.0 * safe + 0.5..2.0 * safe + 3.0);
                    // The side of the real gap away from the start-goal line's
                    // crossing is where the way goes on; put the decoy nearer
                    // the line, on the other side.
                    let cross = line.param_of(Point2::new(x_w, (start.y + goal.y) / 2.0));
                    let side = if cross < at { -1.0 } else { 1.0 };
                    let center = at + side * (w / 2.0 + rng.random_range(6.0..12.0) + dw / 2.0);
                    if center.abs() + dw / 2.0 + 5.0 < line.half {
                        gaps.push((center, dw));
                        pocket = Some((center, dw));
                        pocket_side = (b + 1 < barriers).then_some(side);
                        decoys += 1;
                        label.push_str(", decoy");
                    }
                }
                let flat = kind == Barrier::Fence || kind == Barrier::Segments;
                let prefix = if kind == Barrier::Fence {
                    format!("fence {}", b + 1)
                } else {
                    format!("wall {}", b + 1)
                };
                build_wall(
                    &mut rng,
                    &mut bodies,
                    &line,
                    &gaps,
                    flat,
                    (
                        top,
                        if hard && height != Height::Full {
                            0.5
                        } else {
                            0.0
                        },
                    ),
                    &prefix,
                    kind,
                );
                if let Some((center, dw)) = pocket {
                    let depth = if b + 1 < barriers {
                        spacing[b]
                    } else {
                        rng.random_range(6.0..9.0)
                    };
                    build_pocket(
                        &mut rng,
                        &mut bodies,
                        &line,
                        center,
                        dw,
                        depth,
                        b + 1 < barriers,
                        top,
                        &format!("pocket {}", b + 1),
                    );
                }
                let normal = line.normal();
                for (at, w) in gaps.iter().take(1) {
                    let c = line.at(*at);
                    let lead = safe + 3.0 + w * 0.0;
                    way.push(c - normal * lead);
                    way.push(c + normal * lead);
                }
                label.push_str(match height {
                    Height::Full => "",
                    Height::Under => ", under the flight",
                    Height::Climb => ", climbed",
                });
            }
            Barrier::Bays => {
                let live = rng.random_bool(0.5);
                let low = !live && rng.random_bool(0.4);
                let top = if live {
                    rng.random_range(usable[0].max(4.0)..ceiling + 5.0)
                } else if low {
                    top_for(&mut rng, Height::Under)?
                } else {
                    ceiling + rng.random_range(2.0..8.0)
                };
                let aisles = if rng.random_bool(0.3) { 2 } else { 1 };
                let lane = line.half - safe - 4.0;
                if lane < 6.0 {
                    return None;
                }
                let mut openings = Vec::new();
                for _ in 0..aisles {
                    let narrow = rng.random_bool(0.7);
                    let w = if narrow {
                        let hi = (2.0 * lateral - 0.05).max(column + 0.9);
                        rng.random_range((column + 0.6).max(2.0 * r_q + 0.6)..hi)
                    } else {
                        rng.random_range(2.0 * safe + 0.3..2.0 * safe + 3.0)
                    };
                    narrowest = narrowest.min(w);
                    let at = rng.random_range(-lane..lane);
                    if openings
                        .iter()
                        .all(|(a, ow): &(f64, f64)| (a - at).abs() > (w + ow) / 2.0 + 6.0)
                    {
                        openings.push((at, w));
                    }
                }
                openings.sort_by(|a, b| a.0.total_cmp(&b.0));
                let depth = rng.random_range(3.0..7.0);
                build_bays(
                    &mut rng,
                    &mut bodies,
                    &line,
                    &openings,
                    depth,
                    top,
                    !live,
                    &format!("bay {}", b + 1),
                );
                let normal = line.normal();
                let (at, _) = openings[rng.random_range(0..openings.len())];
                let c = line.at(at);
                way.push(c - normal * (safe + depth / 2.0 + 3.0));
                way.push(c + normal * (safe + depth / 2.0 + 3.0));
                label.push_str(if live {
                    ", live"
                } else if low {
                    ", low"
                } else {
                    ", tall"
                });
                label.push_str(&format!(", {} aisle(s)", openings.len()));
            }
            Barrier::Deck => {
                // Room under, over, or both.
                let under_need = floor + 2.0 * half_height + 2.0 * fig.clear + 0.8;
                let over_need = ceiling - 2.0 * half_height - 2.0 * fig.clear - 0.8;
                let choice = rng.random_range(0..3);
                let (base, top) = match choice {
                    // Under only: a thick deck up to the sky.
                    0 => {
                        let base = rng.random_range(
                            under_need..(under_need + 4.0).min(ceiling - 1.0).max(under_need + 0.1),
                        );
                        (base, ceiling + rng.random_range(1.0..6.0))
                    }
                    // Over only: its base under the floor's room.
                    1 => {
                        let top = rng.random_range(
                            (over_need - 4.0).max(floor + 1.5)..over_need.max(floor + 1.6),
                        );
                        let base =
                            rng.random_range(0.5..(top - 0.5).min(under_need - 0.5).max(0.6));
                        (base, top)
                    }
                    // Both: a thin deck with room under and over.
                    _ => {
                        let base = rng.random_range(under_need..under_need + 1.5);
                        let top = base + rng.random_range(0.5..2.0);
                        (base, top)
                    }
                };
                if base >= top || top <= floor || (choice == 0 && base + 0.5 > ceiling) {
                    return None;
                }
                let thick = rng.random_range(4.0..10.0);
                let piers = choice != 1 && rng.random_bool(0.4);
                let o = line.origin;
                let (a, n) = (line.along, line.normal());
                let h = line.half + 3.0;
                let corners = vec![
                    o - a * h - n * thick / 2.0,
                    o + a * h - n * thick / 2.0,
                    o + a * h + n * thick / 2.0,
                    o - a * h + n * thick / 2.0,
                ];
                bodies.push(Body {
                    name: format!("deck {}", b + 1),
                    kind: "deck",
                    outline: Outline::Polygon(corners),
                    base,
                    height: top,
                    overfly: true,
                    inspect: false,
                });
                let mut lane_at =
                    rng.random_range(-(line.half - safe - 4.0)..(line.half - safe - 4.0));
                if piers {
                    // Piers from the ground to the deck, 2 r_F + 3-8 m apart
                    // (centre to centre), under its middle.
                    let step = 2.0 * safe + rng.random_range(3.0..8.0);
                    let r = rng.random_range(0.4..1.0);
                    let mut t = -line.half + rng.random_range(0.0..step);
                    let mut k = 0;
                    let mut best = (f64::INFINITY, lane_at);
                    while t < line.half {
                        k += 1;
                        bodies.push(Body {
                            name: format!("pier {}.{}", b + 1, k),
                            kind: "pier",
                            outline: Outline::Circle(line.at(t), r),
                            base: 0.0,
                            height: base,
                            overfly: true,
                            inspect: false,
                        });
                        let mid = t + step / 2.0;
                        if mid.abs() < line.half - safe - 4.0 && (mid - lane_at).abs() < best.0 {
                            best = ((mid - lane_at).abs(), mid);
                        }
                        t += step;
                    }
                    lane_at = best.1;
                    label.push_str(", on piers");
                }
                let c = line.at(lane_at);
                let nn = line.normal();
                way.push(c - nn * (thick / 2.0 + safe + 3.0));
                way.push(c + nn * (thick / 2.0 + safe + 3.0));
                label.push_str(match choice {
                    0 => ", under",
                    1 => ", over",
                    _ => ", under or over",
                });
            }
        }
        kinds.push(label);
    }
    way.push(goal);
    let off_way = |p: &Point2<f64>, keep: f64| {
        way.windows(2)
            .all(|w| segment_point_distance(&w[0], &w[1], p) > keep)
    };

    // The inspected obstacle: a tree or a tower in open ground, before the
    // first barrier or after the last, tall or short, sometimes near a bound.
    let band = [1.0, 5.0];
    let mut inspect_dim = String::from("none");
    if inspected {
        let short = rng.random_bool(0.5);
        let near_bound = rng.random_bool(bound_odds);
        let r = rng.random_range(0.4..2.0);
        let room = r + band[1] + 2.0 * lateral + 1.0;
        let top = if short {
            // Its top inside the band, with a side the formation can be
            // level with (`check` refuses one it cannot).
            let lo = floor + 2.0 * half_height + 1.5;
            let hi = ceiling - 2.0;
            if lo >= hi {
                return None;
            }
            rng.random_range(lo..hi)
        } else {
            ceiling + rng.random_range(2.0..8.0)
        };
        let mut placed = None;
        let sides = [
            [start.x + safe + 4.0, open_ground - 2.0],
            [length - open_ground + 2.0, goal.x - safe - 4.0],
        ];
        for _ in 0..4000 {
            let [lo, hi] = sides[rng.random_range(0..2usize)];
            if lo >= hi {
                continue;
            }
            let x = rng.random_range(lo..hi);
            let y = if near_bound {
                let inset = r + rng.random_range(2.0..3.0);
                if rng.random_bool(0.5) {
                    inset
                } else {
                    width - inset
                }
            } else {
                rng.random_range(room..width - room)
            };
            let c = Point2::new(x, y);
            let clear = bodies.iter().all(|b| b.outline.distance(&c) > room + r)
                && (c - start).norm() > r + safe + 4.0
                && (c - goal).norm() > r + safe + 4.0;
            if clear {
                placed = Some(c);
                break;
            }
        }
        let c = placed?;
        bodies.push(Body {
            name: if short {
                "tower 1".into()
            } else {
                "tree 1".into()
            },
            kind: if short { "tower" } else { "tree" },
            outline: Outline::Circle(c, r),
            base: 0.0,
            height: top,
            overfly: true,
            inspect: true,
        });
        inspect_dim = format!(
            "{}{}",
            if short { "short" } else { "tall" },
            if near_bound { ", near a bound" } else { "" }
        );
    }

    // Clutter off the way, the inspected obstacle and the start and goal.
    let clutter = rng.random_range(0..=if hard { 12usize } else { 6 });
    let mut placed = 0;
    for _ in 0..3000 {
        if placed >= clutter {
            break;
        }
        let r = rng.random_range(0.3..2.5);
        let c = Point2::new(
            rng.random_range(3.0..length - 3.0),
            rng.random_range(3.0..width - 3.0),
        );
        let keep = r + safe + 1.0;
        let clear = bodies.iter().all(|b| {
            let need = if b.inspect {
                r + band[1] + 2.0 * lateral + 2.0
            } else {
                r + 1.0
            };
            b.outline.distance(&c) > need
        }) && off_way(&c, keep)
            && (c - start).norm() > keep + 3.0
            && (c - goal).norm() > keep + 3.0;
        if !clear {
            continue;
        }
        placed += 1;
        bodies.push(Body {
            name: format!("clutter {placed}"),
            kind: "clutter",
            outline: Outline::Circle(c, r),
            base: 0.0,
            height: rng.random_range(2.0..ceiling + 10.0),
            overfly: true,
            inspect: false,
        });
    }

    // Mirrored and/or transposed: the route east to west, south to north…
    let turn = rng.random_range(0..4u32);
    let map = move |p: Point2<f64>| {
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
    for b in &mut bodies {
        b.outline.map(&map);
    }
    let (start, goal) = (map(start), map(goal));
    let (bx, by) = if turn & 2 == 2 {
        (width, length)
    } else {
        (length, width)
    };

    let mut toml = String::new();
    let _ = writeln!(
        toml,
        "name = \"3-D site {index} ({shape_name}, {})\"\nseed = {index}\n",
        kinds.join("; ")
    );
    let _ = writeln!(
        toml,
        "[bounds]\nx = [0.0, {bx:.3}]\ny = [0.0, {by:.3}]\nz = [{floor:.3}, {ceiling:.3}]\n"
    );
    let _ = writeln!(
        toml,
        "[route]\nstart = [{:.3}, {:.3}, {start_z:.3}]\ngoal = [{:.3}, {:.3}, {goal_z:.3}]\n",
        start.x, start.y, goal.x, goal.y
    );
    let slot_text: Vec<String> = slots
        .iter()
        .map(|s| format!("[{:.4}, {:.4}, {:.4}]", s.x, s.y, s.z))
        .collect();
    let _ = writeln!(
        toml,
        "[formation]\nuav_radius = {r_q:.3}\nslots = [{}]\n",
        slot_text.join(", ")
    );
    for b in &bodies {
        let _ = writeln!(
            toml,
            "[[obstacles]]\nname = \"{}\"\nkind = \"{}\"",
            b.name, b.kind
        );
        match &b.outline {
            Outline::Circle(c, r) => {
                let _ = writeln!(toml, "center = [{:.3}, {:.3}]\nradius = {r:.3}", c.x, c.y);
            }
            Outline::Polygon(v) => {
                let vs: Vec<String> = v
                    .iter()
                    .map(|p| format!("[{:.3}, {:.3}]", p.x, p.y))
                    .collect();
                let _ = writeln!(toml, "footprint = [{}]", vs.join(", "));
            }
        }
        let _ = writeln!(toml, "height = {:.3}", b.height);
        if b.base > 0.0 {
            let _ = writeln!(toml, "base = {:.3}", b.base);
        }
        if !b.overfly {
            let _ = writeln!(toml, "overfly = false");
        }
        if b.inspect {
            let _ = writeln!(toml, "inspect = true");
        }
        let _ = writeln!(toml);
    }
    let loaded = match mission::parse_str(&toml, "site3d.toml") {
        Ok(l) => l,
        Err(e) => {
            if std::env::var_os("SKYFORM_SITE_DEBUG").is_some() {
                let errors = match &e {
                    mission::MissionError::Invalid { report, .. } => report
                        .errors()
                        .map(|d| d.to_string())
                        .collect::<Vec<_>>()
                        .join("\n  "),
                    other => other.to_string(),
                };
                eprintln!("site {index} draw {attempt} refused: {errors}");
            }
            return None;
        }
    };
    let refused = skyform::pipelines::theta_pso::diagnostics(&loaded.mission)
        .iter()
        .any(|d| d.is_error());
    if refused {
        return None;
    }
    let uavs = slots.len();
    dims.push(("barriers", barriers.to_string()));
    for k in &kinds {
        dims.push(("barrier", k.clone()));
    }
    dims.push((
        "closest barriers",
        match spacing.iter().copied().fold(f64::INFINITY, f64::min) {
            s if s < 14.0 => "10-14 m".into(),
            s if s.is_finite() => "14-35 m".into(),
            _ => "one".into(),
        },
    ));
    dims.push((
        "slant",
        if max_slant >= 20.0 {
            "20-35°".into()
        } else {
            "0-20°".to_string()
        },
    ));
    dims.push(("decoy", (decoys > 0).to_string()));
    dims.push(("shape", shape_name.to_string()));
    dims.push(("uavs", format!("{uavs:>2}")));
    dims.push((
        "r_Q",
        if r_q < 0.45 {
            "0.30-0.45".into()
        } else {
            "0.45-0.60".to_string()
        },
    ));
    dims.push(("inspection", inspect_dim));
    dims.push((
        "narrowest opening",
        if narrowest < 2.0 * lateral {
            "narrower than the formation".into()
        } else {
            "wider".to_string()
        },
    ));
    dims.push((
        "direction",
        ["eastward", "westward", "northward", "southward"][turn as usize].into(),
    ));
    Some(Site3d {
        mission: loaded.mission,
        toml,
        dims,
    })
}

/// A barrier's line across the site: `origin + along · t`, t ∈ [-half, half]
/// reaching the south and north bounds.
struct Line {
    origin: Point2<f64>,
    along: Vector2<f64>,
    half: f64,
}

impl Line {
    fn at(&self, t: f64) -> Point2<f64> {
        self.origin + self.along * t
    }

    /// Across the line, towards the east (the way on).
    fn normal(&self) -> Vector2<f64> {
        Vector2::new(self.along.y, -self.along.x)
    }

    fn param_of(&self, p: Point2<f64>) -> f64 {
        (p - self.origin).dot(&self.along)
    }
}

/// A wall along `line` closed but for `gaps` (centre, width along the line):
/// posts (radius 0.3-1.5 m, touching, their tops `top` ± `jitter`) or flat
/// segments (thin rectangles 3-8 m long), its ends past the bounds.
#[allow(clippy::too_many_arguments)]
fn build_wall(
    rng: &mut ChaCha8Rng,
    bodies: &mut Vec<Body>,
    line: &Line,
    gaps: &[(f64, f64)],
    flat: bool,
    (top, jitter): (f64, f64),
    prefix: &str,
    kind: Barrier,
) {
    // The wall's pieces between the gaps, as intervals of t.
    let mut edges: Vec<(f64, f64)> = gaps
        .iter()
        .map(|(c, w)| (c - w / 2.0, c + w / 2.0))
        .collect();
    edges.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut pieces = Vec::new();
    let mut from = -line.half;
    for (a, b) in &edges {
        pieces.push((from, *a));
        from = *b;
    }
    pieces.push((from, line.half));
    let thick = rng.random_range(0.3..0.9);
    let n = line.normal();
    let mut k = 0;
    for (a, b) in pieces {
        if b - a <= 0.0 {
            continue;
        }
        if flat {
            // Rectangles 3-8 m long, overlapping by 0.1 m, the last clipped.
            let mut t = a;
            while t < b - 1e-6 {
                let len = rng.random_range(3.0..8.0f64).min(b - t);
                let (p, q) = (line.at(t), line.at(t + len));
                k += 1;
                bodies.push(Body {
                    name: format!("{prefix} seg {k}"),
                    kind: if kind == Barrier::Fence {
                        "fence"
                    } else {
                        "wall"
                    },
                    outline: Outline::Polygon(vec![
                        p - n * thick / 2.0,
                        q - n * thick / 2.0,
                        q + n * thick / 2.0,
                        p + n * thick / 2.0,
                    ]),
                    base: 0.0,
                    height: top,
                    overfly: true,
                    inspect: false,
                });
                t += len - if t + len < b { 0.1 } else { 0.0 };
                if len < 0.05 {
                    break;
                }
            }
        } else {
            // Posts from the piece's upper end (a gap's lower edge, exact)
            // down to its lower end (a gap's upper edge, exact), touching.
            let mut posts = Vec::new();
            let lo = a.max(-line.half);
            let mut t = b.min(line.half);
            loop {
                let rest = t - lo;
                if rest <= 3.0 {
                    // The last post spans what is left, its lower edge exact.
                    let r = (rest / 2.0 + 0.1).max(0.3);
                    posts.push((lo + r, r));
                    break;
                }
                let r: f64 = rng.random_range(0.3..1.5);
                posts.push((t - r, r));
                t -= 2.0 * r - rng.random_range(0.1..0.3);
            }
            for (c, r) in posts {
                k += 1;
                let uneven = if jitter > 0.0 {
                    rng.random_range(-jitter..jitter)
                } else {
                    0.0
                };
                bodies.push(Body {
                    name: format!("{prefix} post {k}"),
                    kind: "post",
                    outline: Outline::Circle(line.at(c), r),
                    base: 0.0,
                    height: top + uneven,
                    overfly: true,
                    inspect: false,
                });
            }
        }
    }
}

/// A closed pocket behind the decoy gap (centre `at`, width `w` along the
/// line): two side walls of posts `depth` metres on (to the next wall when
/// `to_next`), and a back wall when not.
#[allow(clippy::too_many_arguments)]
fn build_pocket(
    rng: &mut ChaCha8Rng,
    bodies: &mut Vec<Body>,
    line: &Line,
    at: f64,
    w: f64,
    depth: f64,
    to_next: bool,
    top: f64,
    prefix: &str,
) {
    let n = line.normal();
    let half = w / 2.0 + rng.random_range(1.0..2.5);
    let mut k = 0;
    let mut post = |c: Point2<f64>, r: f64, bodies: &mut Vec<Body>| {
        k += 1;
        bodies.push(Body {
            name: format!("{prefix} post {k}"),
            kind: "post",
            outline: Outline::Circle(c, r),
            base: 0.0,
            height: top,
            overfly: true,
            inspect: false,
        });
    };
    let r = 0.6;
    let step = 2.0 * r - 0.2;
    // Side walls from the wall to `depth` on (a little past the next wall's
    // line, so they meet it whatever its slant).
    let reach = if to_next { depth + 2.0 } else { depth };
    for side in [-1.0, 1.0] {
        let foot = line.at(at + side * half);
        let mut s = 0.0;
        while s <= reach {
            post(foot + n * s, r, bodies);
            s += step;
        }
    }
    if !to_next {
        let mut t = -half;
        while t <= half {
            post(line.at(at + t) + n * depth, r, bodies);
            t += step;
        }
    }
}

/// A row of footprints along `line`: rectangles (some L-shaped) `depth`
/// deep, with `openings` (centre, width) between them as aisles.
#[allow(clippy::too_many_arguments)]
fn build_bays(
    rng: &mut ChaCha8Rng,
    bodies: &mut Vec<Body>,
    line: &Line,
    openings: &[(f64, f64)],
    depth: f64,
    top: f64,
    overfly: bool,
    prefix: &str,
) {
    let n = line.normal();
    let a = line.along;
    let mut pieces = Vec::new();
    let mut from = -line.half - 1.0;
    for (c, w) in openings {
        pieces.push((from, c - w / 2.0));
        from = c + w / 2.0;
    }
    pieces.push((from, line.half + 1.0));
    let mut k = 0;
    for (lo, hi) in pieces {
        // Split into bays 5-12 m long that touch (no aisle between them).
        let mut t = lo;
        while t < hi - 1e-6 {
            let len = rng.random_range(5.0..12.0f64).min(hi - t);
            let (p, q) = (line.at(t), line.at(t + len));
            let (d0, d1) = (-depth / 2.0, depth / 2.0);
            k += 1;
            // An L-shape: a notch out of one back corner, when it is long enough.
            let outline = if len > 6.0 && rng.random_bool(0.35) {
                let cut = len * rng.random_range(0.3..0.5);
                let back = depth * rng.random_range(0.3..0.5);
                vec![
                    p + n * d0,
                    q + n * d0,
                    q + n * (d1 - back),
                    q - a * cut + n * (d1 - back),
                    q - a * cut + n * d1,
                    p + n * d1,
                ]
            } else {
                vec![p + n * d0, q + n * d0, q + n * d1, p + n * d1]
            };
            bodies.push(Body {
                name: format!("{prefix}.{k}"),
                kind: "bay",
                outline: Outline::Polygon(outline),
                base: 0.0,
                height: top,
                overfly,
                inspect: false,
            });
            // Touching bays overlap by a hair so no sliver gap opens.
            t += len - if t + len < hi { 0.05 } else { 0.0 };
            if len < 0.1 {
                break;
            }
        }
    }
}
