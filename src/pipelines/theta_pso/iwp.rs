//! Intermediate waypoints (θ-PSO eq. 9) and the shape the formation takes there.
//!
//! Reading of eq. 9: for two obstacles p, q the gap d_pq is the distance
//! between their circles along the line C_p C_q (centre distance minus both
//! radii). An IWP sits at the midpoint of that gap when the gap is at least
//! one UAV wide (2 r_Q, with the safety margin each side) but narrower than
//! the formation (2 (r_F + r_Q), the same): one UAV fits, the nominal
//! formation does not. Every "r_Q" of the planner is r_Q plus
//! `formation.safety_margin` (r_Q + m from an obstacle, 2 r_Q + m between two
//! UAVs): the room verification holds every flight to. Two refinements a
//! flight engineer needs and the paper leaves implicit:
//! - a gap blocked by a third obstacle (the segment P_p P_q passes within
//!   r_Q of it) is not a passage and gets no IWP;
//! - both obstacles must stand in the formation's way at a common altitude
//!   of the band (`Iwp::window`): over a lower one, or under a deck, the
//!   formation can simply fly, and a gap between a deck and a post that
//!   stands below it is no passage; a third obstacle or the wall's depth
//!   counts only where it stands at those altitudes too.
//!
//! The formation crosses an IWP straight along the gap's normal, so what must
//! fit is its *lateral* width (UAV radius included), not r_F. Hence:
//! - a gap at least as wide as the nominal shape's lateral width needs no
//!   reconfiguration: the IWP is flown straight through in the nominal shape;
//! - `auto` picks, among the shapes that narrow the formation enough, the one
//!   that moves the UAVs least; rotation (about the lateral axis) never
//!   narrows it, so `auto` never offers it for a gap;
//! - a shape that does not fit (the operator's choice) makes the IWP unusable,
//!   with the reason, instead of a plan that fails later.
//!
//! A gate the user names (`[[route.via]] between = [p, q]`) is an IWP
//! whatever its width: one wider than the formation is flown straight
//! through in the nominal shape. It is a via the path must take (the route
//! stage and the path builder place it in order); one that cannot be taken
//! (narrower than one UAV, blocked, never in the way at a common altitude)
//! is unusable with the reason, which refuses the plan (`NO PLAN`).
//!
//! Long (~1110 lines) because it is eq. 9 and Fig. 2 together: the shapes, the widths they
//! need, the crossing's hold against each obstacle as the crossing sees it (a disc, a
//! footprint's edges), each pair's IWP (or gate) with why none, read as one reading.

use nalgebra::{Point2, Vector2, Vector3};
use serde::Serialize;

use crate::base::geometry::segment_point_distance;
use crate::base::shape::nearest_points;
use crate::mission::{Formation, Mission, ShapeChoice};

/// An intermediate waypoint between two obstacles.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Iwp {
    /// Names of the two obstacles, in file order.
    pub between: [String; 2],
    /// Their indices in `mission.obstacles`.
    pub obstacles: [usize; 2],
    /// C_j, the gap's midpoint, metres ENU.
    pub position: Point2<f64>,
    /// d_pq, free width of the gap, metres.
    pub gap: f64,
    /// Unit vector across the gap line (perpendicular to C_p C_q): the
    /// direction the formation flies through.
    pub normal: Vector2<f64>,
    /// Disabled IWPs take no part in J_R and cause no reconfiguration.
    pub enabled: bool,
    /// The operator's choice (or the mission's default).
    pub choice: ShapeChoice,
    /// The shape flown through the gap; `None` when the nominal formation
    /// already fits (or when the IWP is unusable).
    pub shape: Option<Shape>,
    /// Why no shape can pass this gap, when none can.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unusable: Option<String>,
    /// h: the new shape is held this far each side of the gap line, metres
    /// of centroid path (`hold_distance` plus the depth of the wall; for a
    /// column, plus its length, so that every UAV passes in file).
    pub hold: f64,
    /// The crossing is straight this far each side of the gap line, metres:
    /// h plus the heading's span for a rigid shape, only through the posts
    /// for a column (whose UAVs follow the path).
    pub straight: f64,
    /// The centroid altitudes at which both obstacles stand in the
    /// formation's way (`Mission::passing_altitudes`), metres: outside them
    /// the formation passes over or under one of them, and the gap is none.
    #[serde(skip)]
    pub window: [f64; 2],
    /// The `[[route.via]]` entry (0-based) that names this gap: the route
    /// must pass through it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gate: Option<usize>,
}

impl Iwp {
    /// The ends of the straight crossing: `straight` either way from the
    /// gap along its normal.
    pub fn straight_ends(&self) -> [Point2<f64>; 2] {
        let reach = self.normal * self.straight;
        [self.position - reach, self.position + reach]
    }

    /// The planned path goes through this IWP.
    pub fn is_via(&self) -> bool {
        self.enabled && self.unusable.is_none()
    }

    /// "alignment", "shrink", …, or "nominal" when the formation passes as it is.
    pub fn shape_name(&self) -> &'static str {
        match (&self.shape, &self.unusable) {
            (_, Some(_)) => "unusable",
            (Some(shape), None) => shape.name(),
            (None, None) => "nominal",
        }
    }
}

/// A formation shape at an IWP (θ-PSO paper, Fig. 2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Shape {
    /// Single file along the direction of travel, spaced as the closest
    /// nominal pair (never closer than 2 r_Q).
    Alignment { spacing: f64 },
    /// The shape turned 90° about the formation's lateral (y) axis, into the
    /// vertical plane across the path. A slot on the y axis (UAV 1 of the
    /// paper's triangle) keeps its path; the others change height (Fig. 7).
    Rotation,
    /// The shape scaled toward the centroid.
    Shrink { scale: f64 },
}

impl Shape {
    /// Slot offsets (formation frame) part-way into the shape: `blend` 0 is
    /// the nominal formation, 1 the full shape. Rotation turns rigidly; the
    /// others move each UAV along a straight line.
    pub fn offsets(&self, nominal: &[Vector3<f64>], blend: f64) -> Vec<Vector3<f64>> {
        (0..nominal.len())
            .map(|n| self.offset(nominal, n, blend))
            .collect()
    }

    /// The offset of slot `n` alone (no allocation: the cost calls this for
    /// every UAV at every knot).
    pub fn offset(&self, nominal: &[Vector3<f64>], n: usize, blend: f64) -> Vector3<f64> {
        let o = nominal[n];
        match *self {
            Shape::Alignment { spacing } => {
                let x = column_place(nominal, n, spacing);
                o.lerp(&Vector3::new(x, 0.0, 0.0), blend)
            }
            Shape::Rotation => {
                let (s, c) = (blend * std::f64::consts::FRAC_PI_2).sin_cos();
                // R_y(angle): x' = c x + s z, z' = -s x + c z.
                Vector3::new(c * o.x + s * o.z, o.y, -s * o.x + c * o.z)
            }
            Shape::Shrink { scale } => o * (1.0 - blend * (1.0 - scale)),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Shape::Alignment { .. } => "alignment",
            Shape::Rotation => "rotation",
            Shape::Shrink { .. } => "shrink",
        }
    }
}

/// How far ahead of the centroid (negative: behind) slot `n` flies in the
/// column, metres along the path.
pub fn column_place(nominal: &[Vector3<f64>], n: usize, spacing: f64) -> f64 {
    column_rank_from_middle(nominal, n) * spacing
}

/// Slot `n`'s place in the column counted in spacings from its middle:
/// [`column_place`] is this times the spacing.
pub fn column_rank_from_middle(nominal: &[Vector3<f64>], n: usize) -> f64 {
    let count = nominal.len() as f64;
    column_rank(nominal, n) as f64 - (count - 1.0) / 2.0
}

/// Place of slot `n` in the column, front to back by forward offset (ties by
/// index), so that forming the column never makes two UAVs swap places.
fn column_rank(nominal: &[Vector3<f64>], n: usize) -> usize {
    let key = |m: usize| (nominal[m].x, m);
    let (x, _) = key(n);
    (0..nominal.len())
        .filter(|&m| {
            let (xm, _) = key(m);
            xm < x || (xm == x && m < n)
        })
        .count()
}

/// Half the width the offsets occupy across the path, UAV radius included.
pub fn lateral_half_width(offsets: &[Vector3<f64>], uav_radius: f64) -> f64 {
    offsets.iter().map(|o| o.y.abs()).fold(0.0, f64::max) + uav_radius
}

/// Largest vertical distance of a slot from the centroid.
pub fn vertical_half_height(offsets: &[Vector3<f64>]) -> f64 {
    offsets.iter().map(|o| o.z.abs()).fold(0.0, f64::max)
}

/// Smallest distance between two slots (∞ for fewer than two): the
/// mission's, which the presets read too.
pub use crate::mission::min_pair_distance;

/// The spacing of the alignment column: the closest nominal pair, at
/// least 2 r_Q + the safety margin.
pub fn column_spacing(formation: &Formation) -> f64 {
    let nominal = min_pair_distance(&formation.slots);
    let floor = formation.closest_pair() + COLUMN_SPARE;
    let spacing = if nominal.is_finite() {
        nominal.max(floor)
    } else {
        floor
    };
    // Eq. 7: the column's first and last UAVs stay within d_com of each
    // other, with room to spare for the sampling.
    let gaps = formation.slots.len().saturating_sub(1) as f64;
    if gaps > 0.0 {
        spacing
            .min((formation.comm_range - COLUMN_SPARE) / gaps)
            .max(floor)
    } else {
        spacing
    }
}

/// A curved outline that is not a disc (no shape today) is seen through
/// its ring: chords no more than this inside the curve.
const RING_TOLERANCE: f64 = 0.01;

/// What a column leaves of d_com at its ends, and beyond 2 r_Q between two
/// UAVs, metres (room for the sampling).
const COLUMN_SPARE: f64 = 0.05;

/// Whether a column of the formation keeps eq. 7: 2 r_Q apart and its ends
/// within d_com.
fn column_keeps_eq7(formation: &Formation) -> bool {
    let gaps = formation.slots.len().saturating_sub(1) as f64;
    gaps * column_spacing(formation) <= formation.comm_range + FIT_EPS
}

/// Half length of the chord the formation frame's heading is taken from
/// (see `path::ArcWalker::heading`).
pub fn heading_span(mission: &Mission) -> f64 {
    mission.formation.radius().max(1.0)
}

/// Tolerance of the width comparisons, metres.
const FIT_EPS: f64 = 1e-9;

/// How the formation passes a gap of width `gap`: `Ok(Some(shape))` to
/// reconfigure, `Ok(None)` when the nominal shape already fits, `Err(reason)`
/// when the chosen shape cannot pass.
///
/// `Auto` is the least change that fits: among the shapes that make the
/// lateral width fit, the one that moves the UAVs least (largest slot
/// displacement). Shrink is tried at the largest scale that leaves `margin`
/// beside the outermost UAVs (never below the spacing 2 r_Q + the safety
/// margin allows), which often beats a full alignment.
pub fn resolve_shape(
    choice: ShapeChoice,
    gap: f64,
    formation: &Formation,
    shrink: f64,
    margin: f64,
) -> Result<Option<Shape>, String> {
    let slots = &formation.slots;
    let r_q = formation.least_clearance();
    let fits =
        |shape: &Shape| lateral_half_width(&shape.offsets(slots, 1.0), r_q) <= gap / 2.0 + FIT_EPS;
    let width = |shape: &Shape| 2.0 * lateral_half_width(&shape.offsets(slots, 1.0), r_q);
    let alignment = Shape::Alignment {
        spacing: column_spacing(formation),
    };
    let column_ok = column_keeps_eq7(formation);
    let explicit = |shape: Shape| {
        if matches!(shape, Shape::Alignment { .. }) && !column_ok {
            Err(format!(
                "a column of {} UAVs at least 2 r_Q + the safety margin = {:.2} m apart is longer \
                 than d_com = {} m (eq. 7)",
                slots.len(),
                formation.closest_pair(),
                formation.comm_range
            ))
        } else if fits(&shape) {
            Ok(Some(shape))
        } else {
            Err(format!(
                "{} leaves the formation {:.2} m wide (UAV radius included) and the gap is {gap:.2} m{}",
                shape.name(),
                width(&shape),
                match shape {
                    Shape::Rotation => ": rotation keeps the width; choose alignment or shrink",
                    _ => "",
                }
            ))
        }
    };
    match choice {
        ShapeChoice::Alignment => explicit(alignment),
        ShapeChoice::Rotation => explicit(Shape::Rotation),
        ShapeChoice::Shrink => explicit(Shape::Shrink { scale: shrink }),
        ShapeChoice::Auto => {
            auto_shapes(gap, formation, margin).map(|shapes| shapes.first().copied())
        }
    }
}

/// `Auto`'s shapes for a gap of width `gap`, the least change first: none
/// (`Ok(vec![])`) when the nominal shape already fits, else the shapes that
/// narrow the formation enough, by their largest slot displacement (the
/// column, a shrink at the largest scale that leaves `margin` beside the
/// outer UAVs and 2 r_Q + the safety margin between two), or why none fits.
/// `find_iwps` takes the first whose crossing the site leaves room for.
pub fn auto_shapes(gap: f64, formation: &Formation, margin: f64) -> Result<Vec<Shape>, String> {
    let slots = &formation.slots;
    let r_q = formation.least_clearance();
    let fits =
        |shape: &Shape| lateral_half_width(&shape.offsets(slots, 1.0), r_q) <= gap / 2.0 + FIT_EPS;
    let nominal_width = 2.0 * lateral_half_width(slots, r_q);
    if nominal_width <= gap + 2.0 * FIT_EPS {
        return Ok(Vec::new());
    }
    let alignment = Shape::Alignment {
        spacing: column_spacing(formation),
    };
    let mut candidates = if column_keeps_eq7(formation) {
        vec![alignment]
    } else {
        Vec::new()
    };
    let widest = slots.iter().map(|o| o.y.abs()).fold(0.0, f64::max);
    if widest > 0.0 {
        let fit = (gap / 2.0 - r_q - margin.max(0.0)) / widest;
        let closest = min_pair_distance(slots);
        let floor = if closest.is_finite() {
            formation.closest_pair() / closest
        } else {
            0.0
        };
        // fit < 1 here (the nominal shape does not fit), so a shrink at
        // `fit` always narrows the formation.
        if fit > 0.0 && fit >= floor {
            candidates.push(Shape::Shrink { scale: fit });
        }
    }
    let displacement = |shape: &Shape| {
        let target = shape.offsets(slots, 1.0);
        slots
            .iter()
            .zip(&target)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    };
    candidates.retain(|s| fits(s));
    candidates.sort_by(|a, b| displacement(a).total_cmp(&displacement(b)));
    if candidates.is_empty() {
        let width = 2.0 * lateral_half_width(&alignment.offsets(slots, 1.0), r_q);
        return Err(format!(
            "no shape fits: the narrowest, a column, is {width:.2} m wide and the gap is {gap:.2} m"
        ));
    }
    Ok(candidates)
}

/// Where a UAV at offset `o` (crossing frame: forward, lateral) would be
/// within `reach` of an obstacle at (x_k, y_k): the open interval of the
/// centroid's forward position x' with |x' + o.x − x_k| < √(reach² − (o.y − y_k)²).
fn conflict(o: &Vector3<f64>, x_k: f64, y_k: f64, reach: f64) -> Option<(f64, f64)> {
    let dy = o.y - y_k;
    // Exactly `reach` away is clear (verification asks ≥ r_Q).
    (dy.abs() < reach - 1e-9).then(|| {
        let q = (reach * reach - dy * dy).sqrt();
        (x_k - o.x - q, x_k - o.x + q)
    })
}

/// An obstacle as the crossing sees it: in the crossing's frame (x
/// forward along the crossing, y to its left, from the gap's midpoint), a
/// disc (a cylinder) or its footprint's outline (its own edges, not its
/// bounding circle: a bay's circle reaches across the aisle beside it).
enum Seen {
    Disc { x: f64, y: f64, radius: f64 },
    Outline(Vec<Vector2<f64>>),
}

impl Seen {
    fn of(o: &crate::mission::Obstacle, center: Point2<f64>, forward: Vector2<f64>) -> Self {
        let left = Vector2::new(-forward.y, forward.x);
        let frame = |p: &Point2<f64>| {
            let d = p - center;
            Vector2::new(d.dot(&forward), d.dot(&left))
        };
        let outline = o.outline();
        if let Some((c, radius)) = outline.disc() {
            let c = frame(&c);
            Seen::Disc {
                x: c.x,
                y: c.y,
                radius,
            }
        } else {
            Seen::Outline(outline.ring(RING_TOLERANCE).iter().map(frame).collect())
        }
    }

    /// How deep it reaches along the crossing either side of the gap line
    /// (a disc of the gap's pair stands on the line through the gap, so its
    /// radius; taken so, a hair's breadth off the line changes nothing).
    fn depth(&self) -> f64 {
        match self {
            Seen::Disc { radius, .. } => *radius,
            Seen::Outline(v) => v.iter().map(|p| p.x.abs()).fold(0.0, f64::max),
        }
    }

    /// Where a UAV at offset `o` would come within `clearance` of it: the
    /// interval of the centroid's forward position (a footprint's: the
    /// hull of its edges' intervals, exact for a convex one).
    fn conflict(&self, o: &Vector3<f64>, clearance: f64) -> Option<(f64, f64)> {
        match self {
            Seen::Disc { x, y, radius } => conflict(o, *x, *y, radius + clearance),
            Seen::Outline(v) => {
                let n = v.len();
                let mut hull: Option<(f64, f64)> = None;
                for i in 0..n {
                    if let Some((lo, hi)) = capsule_on_line(v[i], v[(i + 1) % n], o.y, clearance) {
                        hull = Some(hull.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
                    }
                }
                hull.map(|(lo, hi)| (lo - o.x, hi - o.x))
            }
        }
    }
}

/// The x interval where the line y = `y0` comes closer than `r` to the
/// segment a-b (their capsule cut by the line), if it does. The capsule is
/// convex, so its cut is one interval: the hull of the cuts of its two end
/// discs and of its middle strip (points whose projection falls on the
/// segment within `r` of it), each solved exactly.
fn capsule_on_line(a: Vector2<f64>, b: Vector2<f64>, y0: f64, r: f64) -> Option<(f64, f64)> {
    let mut hull: Option<(f64, f64)> = None;
    let mut join = |lo: f64, hi: f64| {
        if lo < hi {
            hull = Some(hull.map_or((lo, hi), |(x0, x1)| (x0.min(lo), x1.max(hi))));
        }
    };
    for end in [a, b] {
        let dy = y0 - end.y;
        if dy.abs() < r {
            let half = (r * r - dy * dy).sqrt();
            join(end.x - half, end.x + half);
        }
    }
    let along = b - a;
    let length = along.norm();
    if length > 1e-12 {
        let u = along / length;
        let n = Vector2::new(-u.y, u.x);
        // Each constraint on p = (x, y0) is linear in x: lo ≤ k x + c ≤ hi.
        let mut interval = (f64::NEG_INFINITY, f64::INFINITY);
        for (k, c, lo, hi) in [
            (u.x, (y0 - a.y) * u.y - a.x * u.x, 0.0, length),
            (n.x, (y0 - a.y) * n.y - a.x * n.x, -r, r),
        ] {
            if k.abs() < 1e-15 {
                if !(lo <= c && c <= hi) {
                    interval = (1.0, 0.0);
                }
            } else {
                let (x0, x1) = ((lo - c) / k, (hi - c) / k);
                interval = (interval.0.max(x0.min(x1)), interval.1.min(x0.max(x1)));
            }
        }
        join(interval.0, interval.1);
    }
    hull
}

/// The hold of the crossing of a gap, or why its shape cannot cross.
///
/// Crossing straight along the gap's normal, the formation must be in its
/// new shape wherever the nominal shape (or one part-way into the new one)
/// would come within r_Q + margin of an obstacle of the wall it pierces: the
/// hold is `hold_distance` beyond the deepest such point, so the shape is
/// complete that far before any UAV reaches the obstacles (the paper's "1 m
/// before"). And the new shape itself must keep r_Q from every obstacle while
/// it is held; when it cannot, the IWP is unusable.
fn crossing_hold(
    mission: &Mission,
    circles: &[Circle],
    pair: [usize; 2],
    center: Point2<f64>,
    normal: Vector2<f64>,
    shape: Option<Shape>,
    window: [f64; 2],
) -> Result<(f64, f64), String> {
    let f = &mission.formation;
    let r_q = f.least_clearance();
    let margin = mission.theta_pso.clearance_margin.max(0.0);
    let obstacles = &mission.obstacles;
    // How deep the wall the gap pierces is along the crossing: as far
    // either side of the gap line as both its obstacles flank it (the
    // shallower one's reach). Beyond it one side is open: a post beside a
    // wall that runs along the crossing narrows the way for the post's
    // depth, not for the wall's kilometre (issue 51: a crossing 2 km each
    // side led the route out of the site).
    let deepest = pair
        .iter()
        .map(|&k| Seen::of(&obstacles[k], center, normal).depth())
        .fold(f64::INFINITY, f64::min);
    let wall_zone = deepest + f.safe_radius() + margin;
    let mut approaching = vec![f.slots.clone()];
    if let Some(shape) = shape {
        for blend in [0.25, 0.5, 0.75] {
            approaching.push(shape.offsets(&f.slots, blend));
        }
    }
    let held = shape.map_or_else(|| f.slots.clone(), |s| s.offsets(&f.slots, 1.0));
    let in_band = |k: &usize| stands_in(mission, &obstacles[*k], window);
    // Broad phase: a conflict within `zone` of the gap along the crossing
    // is a UAV (at most `reach` from the centroid) within `clearance` of
    // the obstacle, so one whose bounding circle keeps farther than that
    // from the gap's middle has none. On a forest of 200 this is most of
    // them, for every IWP.
    let reach = approaching
        .iter()
        .chain([&held])
        .flatten()
        .map(|o| o.xy().norm())
        .fold(0.0, f64::max);
    let near = |zone: f64, clearance: f64| -> Vec<usize> {
        (0..circles.len())
            .filter(|&k| {
                let (c, r) = circles[k];
                (c - center).norm() - r < zone + reach + clearance
            })
            .filter(in_band)
            .collect()
    };
    let mut depth: f64 = 0.0;
    let at_the_wall = near(wall_zone, r_q + margin);
    for sign in [1.0, -1.0] {
        let forward = normal * sign;
        for &k in &at_the_wall {
            let seen = Seen::of(&obstacles[k], center, forward);
            for o in approaching.iter().flatten() {
                if let Some((lo, hi)) = seen.conflict(o, r_q + margin) {
                    // Only conflicts at the wall: the path may turn before
                    // an obstacle farther along the crossing line.
                    if lo < wall_zone && hi > -wall_zone {
                        depth = depth.max(lo.abs()).max(hi.abs());
                    }
                }
            }
        }
    }
    let hold = mission.reconfiguration.hold_distance + depth;
    // A column flies along the path: it is held from before its first UAV
    // reaches the wall until its last has left it (and at least as long as a
    // rigid shape would be), but the path need only be straight through the
    // posts themselves. A rigid shape is straight for the whole hold, and
    // for the heading's span beyond it so the heading points along the
    // crossing throughout.
    let through_posts = deepest + r_q + margin + mission.reconfiguration.hold_distance;
    let (hold, line) = match shape {
        Some(Shape::Alignment { spacing }) => {
            let half = (0..f.slots.len())
                .map(|n| column_place(&f.slots, n, spacing).abs())
                .fold(0.0, f64::max);
            (hold.max(half + through_posts), through_posts)
        }
        _ => (hold, hold + heading_span(mission)),
    };
    let along = hold.max(line);
    let on_the_hold = near(along, r_q);
    for sign in [1.0, -1.0] {
        let forward = normal * sign;
        for &k in &on_the_hold {
            let seen = Seen::of(&obstacles[k], center, forward);
            // Only where the UAV is on the straight: a column's UAVs beyond
            // it are on the path's other legs, which the cost judges.
            let on_line = |o: &Vector3<f64>, (lo, hi): (f64, f64)| {
                let (lo, hi) = (lo.max(-line - o.x), hi.min(line - o.x));
                (lo < hi).then_some((lo, hi))
            };
            // Held over the hold, and (a rigid shape) on along its straight
            // as it turns back (`along`): nothing may stand in its way there
            // either.
            if held
                .iter()
                .filter_map(|o| seen.conflict(o, r_q).and_then(|c| on_line(o, c)))
                .any(|(lo, hi)| lo < along && hi > -along)
            {
                return Err(format!(
                    "held through the gap, the {} would pass within r_Q of '{}'",
                    shape.map_or("nominal formation", |s| s.name()),
                    obstacles[k].name
                ));
            }
        }
    }
    Ok((hold, line))
}

/// Whether obstacle `o` reaches into the band and stands in the way of a
/// centroid somewhere in `window` (metres).
fn stands_in(mission: &Mission, o: &crate::mission::Obstacle, window: [f64; 2]) -> bool {
    let [over, under] = mission.passing_altitudes(o);
    o.within(mission.bounds.z) && under < window[1] && over > window[0]
}

/// An obstacle's bounding circle (centre, radius): the broad phase of the
/// pairs and of the crossings, read once per search rather than from each
/// obstacle at every turn.
type Circle = (Point2<f64>, f64);

fn bounding_circles(mission: &Mission) -> Vec<Circle> {
    mission
        .obstacles
        .iter()
        .map(|o| (o.center, o.radius))
        .collect()
}

/// Every IWP of the mission by eq. 9, with the operator's choices applied.
///
/// Long (~120 lines) because it is eq. 9 over each pair of obstacles in order (the altitudes
/// both block, the gap and its ends, what else stands in it, the operator's choice, the shape
/// and its hold), each test reading the figures of the one before.
pub fn find_iwps(mission: &Mission) -> Vec<Iwp> {
    searches::count(&mission.name);
    let f = &mission.formation;
    let r_q = f.least_clearance();
    let too_narrow = 2.0 * r_q;
    let fits_formation = 2.0 * (f.radius() + r_q);
    let obstacles = &mission.obstacles;
    let circles = bounding_circles(mission);
    let gates = mission.route.via.iter().any(|v| v.between.is_some());
    let mut found = Vec::new();
    for p in 0..obstacles.len() {
        for q in (p + 1)..obstacles.len() {
            // Eq. 9 places no IWP between two obstacles the whole formation
            // passes between (a gate the user names has one all the same):
            // their bounding circles say so, on a forest for most pairs.
            let ((cp, rp), (cq, rq)) = (circles[p], circles[q]);
            if !gates && (cp - cq).norm() - rp - rq >= fits_formation {
                continue;
            }
            let (a, b) = (&obstacles[p], &obstacles[q]);
            let gate = gate_of(mission, &a.name, &b.name);
            let iwp = pair_iwp(mission, &circles, p, q, gate, too_narrow, fits_formation);
            found.extend(iwp);
        }
    }
    prefer_columns_in_sequence(mission, &circles, &mut found);
    found
}

/// Why eq. 9 places no IWP between obstacles `p` and `q` (`p < q`), in
/// words, with what would make the route pass between them.
pub fn why_no_iwp(mission: &Mission, p: usize, q: usize) -> String {
    let f = &mission.formation;
    let r_q = f.least_clearance();
    let (too_narrow, fits_formation) = (2.0 * r_q, 2.0 * (f.radius() + r_q));
    let (a, b) = (&mission.obstacles[p].name, &mission.obstacles[q].name);
    let route = format!(
        "to make the route pass between them, add [[route.via]] between = [\"{a}\", \"{b}\"]"
    );
    let circles = bounding_circles(mission);
    match pair_iwp(
        mission,
        &circles,
        p,
        q,
        Some(usize::MAX),
        too_narrow,
        fits_formation,
    ) {
        Some(iwp) => match iwp.unusable {
            Some(reason) => reason,
            None if iwp.gap >= fits_formation => format!(
                "their gap, {:.2} m, is wider than the formation ({:.2} m with r_Q and the \
                 margins): it passes without reconfiguring, so no reconfiguration is chosen \
                 there; {route}",
                iwp.gap, fits_formation
            ),
            None => format!("eq. 9 does not place one there; {route}"),
        },
        None => format!("they are no gap the formation could pass; {route}"),
    }
}

/// The `[[route.via]]` entry that names the pair `a`, `b` as a gate.
fn gate_of(mission: &Mission, a: &str, b: &str) -> Option<usize> {
    mission.route.via.iter().position(|v| {
        v.point.is_none()
            && v.between
                .as_ref()
                .is_some_and(|pair| crate::mission::same_pair(pair, a, b))
    })
}

/// Eq. 9 on the pair `p`, `q`: its IWP, or `None` when it has none. A gate
/// (`gate`: the user's `[[route.via]]`) always has one: unusable, with the
/// reason, when no formation can pass it.
///
/// Long (~150 lines) because it is eq. 9 on one pair in order (the altitudes both block,
/// the gap and its ends, what else stands in it, the operator's choice, the shape and its
/// hold), each test reading the figures of the one before, and each saying why a gate
/// the user named cannot be kept.
fn pair_iwp(
    mission: &Mission,
    circles: &[Circle],
    p: usize,
    q: usize,
    gate: Option<usize>,
    too_narrow: f64,
    fits_formation: f64,
) -> Option<Iwp> {
    let f = &mission.formation;
    let r_q = f.least_clearance();
    let obstacles = &mission.obstacles;
    let (a, b) = (&obstacles[p], &obstacles[q]);
    let mut refusal: Option<String> = None;
    if !a.within(mission.bounds.z) || !b.within(mission.bounds.z) {
        gate?;
        let low = if a.within(mission.bounds.z) { b } else { a };
        refusal = Some(format!(
            "'{}' stands outside the altitude band z {:?} m: the formation passes over or \
             under it, not between",
            low.name, mission.bounds.z
        ));
    }
    // The altitudes at which both stand in the way, within those the
    // centroid may take (the band less the shape's half height).
    let ([over_a, under_a], [over_b, under_b]) =
        (mission.passing_altitudes(a), mission.passing_altitudes(b));
    let window = [under_a.max(under_b), over_a.min(over_b)];
    let half = vertical_half_height(&f.slots);
    let z = mission.bounds.z;
    if window[0] >= window[1] || window[0] >= z[1] - half || window[1] <= z[0] + half {
        gate?;
        refusal.get_or_insert_with(|| {
            format!(
                "'{}' and '{}' do not stand in the formation's way at a common altitude of \
                 the band: it passes over or under one of them",
                a.name, b.name
            )
        });
    }
    let (pa, pb) = (a.prism(), b.prism());
    let (p_p, p_q, gap, u) = if pa.outline.disc().is_some() && pb.outline.disc().is_some() {
        let axis = b.center - a.center;
        let distance = axis.norm();
        if distance == 0.0 {
            gate?;
            return None;
        }
        let u = axis / distance;
        let gap = distance - a.radius - b.radius;
        (a.center + u * a.radius, b.center - u * b.radius, gap, u)
    } else {
        // Footprints: the IWP is at the middle of their nearest
        // points (eq. 9's P_p, P_q on the outlines).
        if gate.is_none() && (a.center - b.center).norm() - a.radius - b.radius >= fits_formation {
            return None;
        }
        let (p_p, p_q) = nearest_points(&*pa.outline, &*pb.outline);
        let apart = pa.outward(&p_q) > 0.0 && pb.outward(&p_p) > 0.0;
        let gap = if apart { (p_q - p_p).norm() } else { -1.0 };
        (p_p, p_q, gap, (p_q - p_p) / gap.abs().max(1e-12))
    };
    if gap < too_narrow {
        gate?;
        refusal.get_or_insert_with(|| {
            if gap < 0.0 {
                format!("'{}' and '{}' touch: there is no gap", a.name, b.name)
            } else {
                format!(
                    "the gap is {gap:.2} m, narrower than one UAV (2 × (r_Q + the margins) = \
                     {too_narrow:.2} m)"
                )
            }
        });
    } else if gap >= fits_formation {
        gate?;
    }
    let blocker = circles.iter().enumerate().find_map(|(k, (c, r))| {
        let o = &obstacles[k];
        (k != p
            && k != q
            && segment_point_distance(&p_p, &p_q, c) < r + r_q
            && stands_in(mission, o, window)
            && (o.outline().disc().is_some() || o.prism().segment_distance(&p_p, &p_q) < r_q))
            .then_some(o)
    });
    if let Some(o) = blocker {
        gate?;
        refusal.get_or_insert_with(|| format!("'{}' stands in the gap", o.name));
    }
    let choice = mission.reconfiguration.choice(&a.name, &b.name);
    let (enabled, shape_choice, scale) = match choice {
        Some(w) => (
            w.enabled || gate.is_some(),
            w.shape,
            w.scale.unwrap_or(mission.reconfiguration.shrink_scale),
        ),
        None => (
            true,
            mission.reconfiguration.default_shape,
            mission.reconfiguration.shrink_scale,
        ),
    };
    let position = Point2::from((p_p.coords + p_q.coords) / 2.0);
    // Two walls that run on past the site may be nearest outside it: that
    // gap is not flown, and what lies between them inside is left to the
    // route's grid and its exact gaps (issue 51: a crossing 2 km out of a
    // 1 km site).
    if !mission.bounds.contains_xy(&position) {
        gate?;
        refusal.get_or_insert_with(|| {
            format!(
                "the gap is narrowest at ({:.1}, {:.1}) m, outside the x-y bounds",
                position.x, position.y
            )
        });
    }
    let normal = Vector2::new(-u.y, u.x);
    let margin = mission.theta_pso.clearance_margin.max(0.0);
    let hold_for = |shape: Option<Shape>| {
        crossing_hold(mission, circles, [p, q], position, normal, shape, window)
    };
    let resolved = if let Some(reason) = refusal {
        Err(reason)
    } else if shape_choice == ShapeChoice::Auto {
        // The least change whose crossing the site leaves room for
        // (a shrink's straight may run into the next wall where a
        // column's, through the posts only, does not).
        auto_shapes(gap, f, margin).and_then(|shapes| {
            if shapes.is_empty() {
                return hold_for(None).map(|hold| (None, hold));
            }
            let mut first_reason = None;
            for shape in &shapes {
                match hold_for(Some(*shape)) {
                    Ok(hold) => return Ok((Some(*shape), hold)),
                    Err(reason) => {
                        first_reason.get_or_insert(reason);
                    }
                }
            }
            Err(first_reason.unwrap_or_default())
        })
    } else {
        resolve_shape(shape_choice, gap, f, scale, margin)
            .and_then(|shape| hold_for(shape).map(|hold| (shape, hold)))
    };
    let (shape, (hold, straight), unusable) = match resolved {
        Ok((shape, hold)) => (shape, hold, None),
        Err(reason) => (None, (0.0, 0.0), Some(reason)),
    };
    // The straight is flown inside the site: no farther either way than the
    // bounds.
    let straight = straight.min(room_along(&mission.bounds, position, normal));
    Some(Iwp {
        between: [a.name.clone(), b.name.clone()],
        obstacles: [p, q],
        position,
        gap: gap.max(0.0),
        normal,
        enabled,
        choice: shape_choice,
        shape,
        unusable,
        hold,
        straight,
        window,
        gate,
    })
}

/// How far from `p` (inside `bounds`) along `±direction` the x-y bounds
/// leave room, the nearer of the two ways.
fn room_along(bounds: &crate::mission::Bounds, p: Point2<f64>, direction: Vector2<f64>) -> f64 {
    let d = direction / direction.norm().max(1e-12);
    let mut room = f64::INFINITY;
    for (axis, range) in [bounds.x, bounds.y].into_iter().enumerate() {
        let (at, step) = (p[axis], d[axis].abs());
        if step > 1e-12 {
            room = room.min((at - range[0]).min(range[1] - at).max(0.0) / step);
        }
    }
    room
}

/// Two crossings in sequence whose straights overlap along the way (walls
/// closer than the straights are long, the gaps not far apart across it)
/// could only be flown one after the other by doubling back between them.
/// Where `auto` chose a rigid shape for either, its column is taken
/// instead when the site leaves room for it: a column's straight runs
/// through the posts only.
fn prefer_columns_in_sequence(mission: &Mission, circles: &[Circle], iwps: &mut [Iwp]) {
    let auto = |iwp: &Iwp| {
        iwp.is_via()
            && iwp.choice == ShapeChoice::Auto
            && iwp
                .shape
                .is_some_and(|s| !matches!(s, Shape::Alignment { .. }))
    };
    let mut switch = vec![false; iwps.len()];
    for i in 0..iwps.len() {
        for j in (i + 1)..iwps.len() {
            let (a, b) = (&iwps[i], &iwps[j]);
            if !(auto(a) || auto(b)) || !a.is_via() || !b.is_via() {
                continue;
            }
            let d = b.position - a.position;
            let along = d.dot(&a.normal).abs();
            let across = d.dot(&Vector2::new(-a.normal.y, a.normal.x)).abs();
            let overlap = a.straight + b.straight - along;
            let f = &mission.formation;
            if overlap > 0.0 && across < 2.0 * overlap + 2.0 * f.radius() && along > 1e-6 {
                switch[i] |= auto(a);
                switch[j] |= auto(b);
            }
        }
    }
    let f = &mission.formation;
    for (iwp, _) in iwps.iter_mut().zip(&switch).filter(|(_, s)| **s) {
        let column = Shape::Alignment {
            spacing: column_spacing(f),
        };
        if !column_keeps_eq7(f)
            || lateral_half_width(&column.offsets(&f.slots, 1.0), f.least_clearance())
                > iwp.gap / 2.0 + FIT_EPS
        {
            continue;
        }
        if let Ok((hold, straight)) = crossing_hold(
            mission,
            circles,
            iwp.obstacles,
            iwp.position,
            iwp.normal,
            Some(column),
            iwp.window,
        ) {
            iwp.shape = Some(column);
            iwp.hold = hold;
            iwp.straight = straight;
        }
    }
}

/// How many times the IWPs of a mission, by name, were searched for in
/// this process: what shows that an edit finds them once (a test reads
/// it; a mission name per test keeps tests apart).
pub mod searches {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};

    fn table() -> &'static Mutex<HashMap<String, usize>> {
        static TABLE: OnceLock<Mutex<HashMap<String, usize>>> = OnceLock::new();
        TABLE.get_or_init(Mutex::default)
    }

    pub(super) fn count(name: &str) {
        if let Ok(mut t) = table().lock() {
            *t.entry(name.to_owned()).or_default() += 1;
        }
    }

    /// The searches for the mission named `name` so far.
    pub fn of(name: &str) -> usize {
        table()
            .lock()
            .map_or(0, |t| t.get(name).copied().unwrap_or(0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission::Obstacle;

    /// A 100 m site on x with obstacles of the given footprints standing
    /// from the ground to 30 m.
    fn site_with(outlines: &[(&str, &[[f64; 2]])]) -> Mission {
        let text = "name = \"slabs\"\n[bounds]\nx = [0.0, 100.0]\ny = [-30.0, 30.0]\n\
                    z = [3.0, 12.0]\n[route]\nstart = [5.0, 0.0, 8.0]\ngoal = [95.0, 0.0, 8.0]\n";
        let mut m = crate::mission::parse_str(text, "slabs.toml")
            .unwrap_or_else(|e| panic!("{e}"))
            .mission;
        for (name, outline) in outlines {
            let mut o = Obstacle::standing(name.to_string(), Point2::origin(), 0.0, 30.0);
            o.footprint = outline.iter().map(|&[x, y]| Point2::new(x, y)).collect();
            o.overfly = false;
            o.settle();
            m.obstacles.push(o);
        }
        m
    }

    /// `x0..x1` × `y0..y1`.
    fn slab(x0: f64, x1: f64, y0: f64, y1: f64) -> [[f64; 2]; 4] {
        [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    }

    /// A crossing is straight for as far as both its obstacles flank the
    /// gap: a 2 m post beside a wall that runs 2 km along the crossing
    /// narrows the way for the post's 2 m, not the wall's 2 km (issue 51,
    /// series #6: the route ran its crossing out of the site).
    #[test]
    fn a_crossing_is_as_deep_as_the_shallower_of_its_two_obstacles() {
        let m = site_with(&[
            ("post", &slab(49.0, 51.0, -1.0, 1.0)),
            ("wall", &slab(-950.0, 1050.0, 2.5, 3.5)),
        ]);
        let iwps = find_iwps(&m);
        let iwp = iwps
            .iter()
            .find(|i| i.between == ["post", "wall"])
            .unwrap_or_else(|| panic!("no IWP: {iwps:?}"));
        assert!(iwp.is_via(), "{iwp:?}");
        assert!((iwp.gap - 1.5).abs() < 1e-9, "{iwp:?}");
        // Along x through the gap; 1 m of post each side, r_Q, the margins
        // and the hold are a few metres, the wall's 1 km is not.
        assert!(iwp.normal.x.abs() > 0.999, "{iwp:?}");
        assert!(iwp.straight < 15.0 && iwp.straight > 1.0, "{iwp:?}");
    }

    fn iwps_between(m: &Mission, a: &str, b: &str) -> Vec<Iwp> {
        let found: Vec<Iwp> = find_iwps(m)
            .into_iter()
            .filter(|i| i.between == [a, b])
            .collect();
        assert_eq!(found.len(), 1, "{a} | {b}: {found:?}");
        found
    }

    /// Two walls nearest each other outside the site leave no IWP there, and
    /// no crossing's straight runs past the bounds.
    #[test]
    fn no_crossing_lies_or_runs_outside_the_bounds() {
        // Converging walls, nearest (1.4 m apart) at x = 600, where the site
        // ends at x = 100; a post 1.5 m south of the wall, 1 m from the
        // site's east end.
        let m = site_with(&[
            ("south", &slab(0.0, 600.0, -1.0, 0.0)),
            (
                "north",
                &[[0.0, 8.0], [600.0, 1.4], [600.0, 2.4], [0.0, 9.0]],
            ),
            ("post", &slab(98.0, 99.0, -3.5, -2.5)),
        ]);
        assert!(
            iwps_between(&m, "south", "post").iter().all(|i| i.is_via()),
            "the post's gap is a crossing"
        );
        let iwps = find_iwps(&m);
        assert!(
            !iwps.iter().any(|i| i.between == ["south", "north"]),
            "the walls' gap lies outside the site: {iwps:?}"
        );
        for iwp in iwps.iter().filter(|i| i.is_via()) {
            for p in iwp.straight_ends() {
                assert!(m.bounds.contains_xy(&p), "{iwp:?} ends at {p}");
            }
        }
    }

    /// The capsule's cut by a line, solved exactly, against the distance to
    /// the segment sampled every millimetre along the line, for segments
    /// of every slant and lines above, through and beside them.
    #[test]
    fn a_capsules_cut_by_a_line_is_where_the_segment_is_nearer_than_r() {
        let segments = [
            (Vector2::new(0.0, 0.0), Vector2::new(4.0, 0.0)),
            (Vector2::new(-1.0, -2.0), Vector2::new(2.0, 3.0)),
            (Vector2::new(1.0, -3.0), Vector2::new(1.0, 3.0)),
            (Vector2::new(2.0, 2.0), Vector2::new(2.0, 2.0)),
        ];
        for (a, b) in segments {
            for y0 in [-3.9, -2.5, -0.3, 0.0, 0.7, 2.2, 3.4] {
                let r = 0.8;
                let near = |x: f64| {
                    let p = Vector2::new(x, y0);
                    let ab = b - a;
                    let t = if ab.norm_squared() > 0.0 {
                        ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    (a + ab * t - p).norm() < r
                };
                let xs: Vec<f64> = (-6000..6000)
                    .map(|k| k as f64 * 1e-3)
                    .filter(|&x| near(x))
                    .collect();
                match (capsule_on_line(a, b, y0, r), xs.first(), xs.last()) {
                    (Some((lo, hi)), Some(first), Some(last)) => {
                        assert!(
                            (lo - first).abs() < 2e-3 && (hi - last).abs() < 2e-3,
                            "{a} {b} {y0}: {lo} {hi} vs {first} {last}"
                        );
                    }
                    (None, None, None) => {}
                    (got, first, last) => panic!("{a} {b} {y0}: {got:?} vs {first:?}..{last:?}"),
                }
            }
        }
    }
}
