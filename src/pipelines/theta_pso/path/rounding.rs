//! The centroid path's corners rounded for flight.
//!
//! The swarm plans a polyline: at each vertex the direction of travel turns
//! at once, and a UAV that flew it exactly would have to stop there (any
//! speed through a corner is a velocity jump). The path flown is the
//! planned one with its corners rounded, as a multicopter's trajectory
//! generator rounds a waypoint it does not stop at, each corner within its
//! `tolerance` (metres: the most the flown path may stray from the planned
//! one there), in two steps that share it:
//!
//! 1. **Simplified**, within half the tolerance: vertices the path can
//!    leave out without straying more than that (Douglas–Peucker with a
//!    tolerance per vertex) are left out. The swarm's paths have kinks a
//!    few centimetres long where a via (an IWP's crossing, an inspection
//!    pass) joins a free waypoint; flown one by one, each would be a tight
//!    corner of its own.
//! 2. **Rounded**, within the other half: each corner left, turning by φ,
//!    becomes a circular arc tangent to both legs with tangent length T on
//!    each, radius ρ = T / tan(φ/2), passing T tan(φ/4) inside the vertex.
//!    T is at most half of either leg, so two arcs never overlap.
//!
//! A larger tolerance is a wider arc, flown faster; the trajectory gives
//! each corner the room the cost keeps (`flight`), less where that breaks a
//! constraint, and verification judges the flight. An arc is written as
//! short chords (at most [`ARC_STEP_ANGLE`] of turn and [`ARC_STEP_LENGTH`]
//! each), so the flown path is still a polyline that every reader of a
//! path (`ArcWalker`, `Motion`) reads as before. [`ArcMap`] carries every
//! arc length of the planned path (zones, passes) onto the flown one.

use nalgebra::{Point3, Vector3};

use super::{CentroidPath, Pass, Zone, cumulative_lengths};

/// Largest turn of one chord of a rounded corner, radians (2°).
pub const ARC_STEP_ANGLE: f64 = std::f64::consts::PI / 90.0;
/// Longest chord of a rounded corner, metres.
pub const ARC_STEP_LENGTH: f64 = 0.04;
/// Most chords one corner is written with.
const MAX_CHORDS: usize = 400;
/// A turn below this is no corner, radians.
const NO_TURN: f64 = 1e-6;
/// A sharper turn is a hairpin, kept as planned (its arc would have no
/// radius): 179°.
const MAX_TURN: f64 = std::f64::consts::PI * 179.0 / 180.0;
/// An arc tighter than this is no rounding (a near-hairpin in a
/// centimetre): the corner is kept and flown by stopping at it, metres.
pub const MIN_RADIUS: f64 = 0.05;

/// The planned path's arc lengths carried onto the flown path: monotone
/// piecewise-linear maps through (before, after) pairs, one per step.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ArcMap {
    steps: Vec<Vec<(f64, f64)>>,
}

impl ArcMap {
    /// The flown path's arc length where the planned path's is `s`.
    pub fn rounded(&self, s: f64) -> f64 {
        self.steps.iter().fold(s, |s, knots| through(knots, s))
    }
}

/// `s` through the knots of one step.
fn through(k: &[(f64, f64)], s: f64) -> f64 {
    match k.len() {
        0 => s,
        1 => s - k[0].0 + k[0].1,
        _ => {
            let i = k.partition_point(|&(a, _)| a <= s).clamp(1, k.len() - 1);
            let (a0, b0) = k[i - 1];
            let (a1, b1) = k[i];
            if a1 - a0 <= 1e-12 {
                b1
            } else {
                b0 + (b1 - b0) * ((s - a0) / (a1 - a0))
            }
        }
    }
}

/// One corner of the planned path: where it is, how sharp, and how far
/// along the path its simplification or rounding reaches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// Arc length of the vertex along the planned path.
    pub arc: f64,
    /// Turn, radians.
    pub turn: f64,
    /// Metres of path either side of the vertex the flown path differs
    /// over (0: flown as planned).
    pub extent: f64,
}

/// One corner as flown: where on the flown path, its arc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arc {
    /// Arc length of the arc's middle along the flown path.
    pub at: f64,
    /// Tangent length on each leg, metres (0: a kink, not rounded).
    pub tangent: f64,
    /// Radius, metres.
    pub radius: f64,
    /// Turn, radians.
    pub turn: f64,
    /// Length of each chord it is written with, metres.
    pub chord: f64,
}

/// The planned path as flown.
#[derive(Debug, Clone)]
pub struct Rounded {
    /// The flown path, its zones and passes on its own arc lengths.
    pub path: CentroidPath,
    /// Every corner of the planned path ([`corners`]), in order.
    pub planned: Vec<Corner>,
    /// Every corner of the simplified path, as rounded.
    pub flown: Vec<Arc>,
    /// The planned path's arc lengths on the flown path.
    pub map: ArcMap,
}

/// The planned path's corners: one per inner vertex that turns (repeated
/// points count once). [`round`]'s tolerances are in this order.
pub fn corners(points: &[Point3<f64>]) -> Vec<Corner> {
    let p = deduped(points);
    let arcs = cumulative_lengths(&p);
    corner_vertices(&p)
        .into_iter()
        .map(|(i, turn)| Corner {
            arc: arcs[i],
            turn,
            extent: 0.0,
        })
        .collect()
}

/// The polyline without its repeated points (a via on a waypoint), which
/// would hide the corner they stand at.
fn deduped(points: &[Point3<f64>]) -> Vec<Point3<f64>> {
    let mut out = points.to_vec();
    out.dedup_by(|b, a| (*b - *a).norm() < 1e-9);
    out
}

/// (vertex, turn) of every inner vertex that turns.
fn corner_vertices(points: &[Point3<f64>]) -> Vec<(usize, f64)> {
    (1..points.len().saturating_sub(1))
        .filter_map(|i| {
            let turn = turn_between(&(points[i] - points[i - 1]), &(points[i + 1] - points[i]))?;
            Some((i, turn))
        })
        .collect()
}

/// The turn from `a` to `b`, radians; `None` for a leg of no length or no turn.
fn turn_between(a: &Vector3<f64>, b: &Vector3<f64>) -> Option<f64> {
    let (la, lb) = (a.norm(), b.norm());
    if la < 1e-9 || lb < 1e-9 {
        return None;
    }
    let turn = (a.dot(b) / (la * lb)).clamp(-1.0, 1.0).acos();
    (turn > NO_TURN).then_some(turn)
}

/// `path` as flown: simplified and rounded (see the module's doc), the
/// i-th corner of [`corners`] within `tolerance(i)` metres (0 flies it as
/// planned), its zones and passes carried onto the new arc lengths.
pub fn round(path: &CentroidPath, tolerance: impl Fn(usize) -> f64) -> Rounded {
    let p = deduped(&path.points);
    let arcs = cumulative_lengths(&p);
    let vertices = corner_vertices(&p);
    // Each vertex's budget: a corner its own tolerance, a vertex on a
    // straight the smaller of the corners either side.
    let mut budget = vec![f64::INFINITY; p.len()];
    for (c, &(i, _)) in vertices.iter().enumerate() {
        budget[i] = tolerance(c).max(0.0);
    }
    let mut left = f64::INFINITY;
    for b in budget.iter_mut() {
        if b.is_finite() {
            left = *b;
        } else {
            *b = left;
        }
    }
    let mut right = f64::INFINITY;
    for (i, b) in budget.iter_mut().enumerate().rev() {
        let own = vertices.iter().any(|&(v, _)| v == i);
        if own {
            right = *b;
        } else {
            *b = b.min(right);
        }
    }
    let budget: Vec<f64> = budget
        .into_iter()
        .map(|b| if b.is_finite() { b } else { 0.0 })
        .collect();
    // 1. Simplified within half of each vertex's budget.
    let kept = simplify(&p, &budget);
    let simple: Vec<Point3<f64>> = kept.iter().map(|&i| p[i]).collect();
    let simple_arcs = cumulative_lengths(&simple);
    let first_step: Vec<(f64, f64)> = kept
        .iter()
        .zip(&simple_arcs)
        .map(|(&i, &s)| (arcs[i], s))
        .collect();
    // 2. Rounded within the other half.
    let simple_budget: Vec<f64> = kept.iter().map(|&i| budget[i] / 2.0).collect();
    let (points, flown, second_step) = round_corners(&simple, &simple_arcs, &simple_budget);
    let map = ArcMap {
        steps: vec![first_step, second_step],
    };
    // How far each planned corner's change reaches along the path.
    let planned = vertices
        .iter()
        .map(|&(i, turn)| {
            let k = kept.partition_point(|&v| v < i);
            let extent = if kept.get(k) == Some(&i) {
                let s = map.rounded(arcs[i]);
                flown
                    .iter()
                    .find(|a| (a.at - s).abs() < 1e-6 + a.tangent)
                    .map_or(0.0, |a| a.tangent)
            } else {
                // Left out: the chord between the kept vertices either side.
                let before = k.checked_sub(1).map_or(0.0, |b| arcs[i] - arcs[kept[b]]);
                let after = kept.get(k).map_or(0.0, |&a| arcs[a] - arcs[i]);
                before.max(after)
            };
            Corner {
                arc: arcs[i],
                turn,
                extent,
            }
        })
        .collect();
    let zones = path.zones.iter().map(|z| carried(z, &map)).collect();
    let passes = path
        .passes
        .iter()
        .map(|pass| Pass {
            arcs: [map.rounded(pass.arcs[0]), map.rounded(pass.arcs[1])],
            ..pass.clone()
        })
        .collect();
    Rounded {
        path: CentroidPath {
            points,
            zones,
            passes,
            crossed: path.crossed.clone(),
        },
        planned,
        flown,
        map,
    }
}

/// Douglas–Peucker with a tolerance per vertex: the indices of the
/// vertices kept (the ends always), every vertex left out within half its
/// `budget` of the chord that replaces it.
fn simplify(p: &[Point3<f64>], budget: &[f64]) -> Vec<usize> {
    if p.len() < 3 {
        return (0..p.len()).collect();
    }
    let mut keep = vec![false; p.len()];
    keep[0] = true;
    keep[p.len() - 1] = true;
    let mut stack = vec![(0usize, p.len() - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        // The vertex farthest beyond what it allows.
        let worst = (a + 1..b)
            .map(|k| {
                let d = crate::base::geometry::segment_point_distance_3d(&p[a], &p[b], &p[k]);
                (k, d - budget[k] / 2.0)
            })
            .max_by(|x, y| x.1.total_cmp(&y.1));
        if let Some((k, over)) = worst
            && over > 0.0
        {
            keep[k] = true;
            stack.push((a, k));
            stack.push((k, b));
        }
    }
    (0..p.len()).filter(|&i| keep[i]).collect()
}

/// (planned arc length, flown arc length) pairs, in order: what [`ArcMap`]
/// interpolates.
type ArcPairs = Vec<(f64, f64)>;

/// Each corner of `p` (arc lengths `arcs`) rounded within `budget` (per
/// vertex): the flown points, the arcs, and the map of arc lengths.
fn round_corners(
    p: &[Point3<f64>],
    arcs: &[f64],
    budget: &[f64],
) -> (Vec<Point3<f64>>, Vec<Arc>, ArcPairs) {
    let mut points = Vec::with_capacity(p.len() * 8);
    let mut flown = Vec::new();
    let mut knots = vec![(0.0, 0.0)];
    let Some(&first) = p.first() else {
        return (points, flown, knots);
    };
    let mut out = Polyline {
        points: &mut points,
        length: 0.0,
    };
    out.push(first);
    for i in 1..p.len() {
        if i + 1 == p.len() {
            out.push(p[i]);
            break;
        }
        let (d_in, d_out) = (p[i] - p[i - 1], p[i + 1] - p[i]);
        let Some(phi) = turn_between(&d_in, &d_out) else {
            out.push(p[i]);
            continue;
        };
        let (l_in, l_out) = (d_in.norm(), d_out.norm());
        let (u_in, u_out) = (d_in / l_in, d_out / l_out);
        let quarter = (phi / 4.0).tan();
        let tangent = (budget[i] / quarter).min(0.5 * l_in.min(l_out));
        // A hairpin (φ → π) has no finite arc: keep the corner (flown by
        // stopping at it), as any corner with no room for an arc.
        let half_tan = (phi / 2.0).tan();
        if tangent <= 1e-9
            || !half_tan.is_finite()
            || phi > MAX_TURN
            || tangent / half_tan < MIN_RADIUS
        {
            out.push(p[i]);
            flown.push(Arc {
                at: out.length,
                tangent: 0.0,
                radius: 0.0,
                turn: phi,
                chord: 0.0,
            });
            continue;
        }
        let radius = tangent / half_tan;
        // The arc in the plane of the two legs, from A on the incoming leg.
        let normal = (u_out - u_in * u_out.dot(&u_in)).normalize();
        let a = p[i] - u_in * tangent;
        let chords = ((phi / ARC_STEP_ANGLE).ceil() as usize)
            .max((radius * phi / ARC_STEP_LENGTH).ceil() as usize)
            .clamp(1, MAX_CHORDS);
        out.push(a);
        let start = out.length;
        knots.push((arcs[i] - tangent, start));
        for k in 1..chords {
            let sigma = phi * k as f64 / chords as f64;
            out.push(a + normal * (radius * (1.0 - sigma.cos())) + u_in * (radius * sigma.sin()));
        }
        out.push(p[i] + u_out * tangent);
        knots.push((arcs[i] + tangent, out.length));
        flown.push(Arc {
            at: 0.5 * (start + out.length),
            tangent,
            radius,
            turn: phi,
            chord: 2.0 * radius * (phi / chords as f64 / 2.0).sin(),
        });
    }
    let total = out.length;
    knots.push((arcs.last().copied().unwrap_or(0.0), total));
    knots.dedup_by(|b, a| b.0 <= a.0);
    (points, flown, knots)
}

/// The flown path as it is written, with its length so far.
struct Polyline<'a> {
    points: &'a mut Vec<Point3<f64>>,
    length: f64,
}

impl Polyline<'_> {
    fn push(&mut self, q: Point3<f64>) {
        if let Some(last) = self.points.last() {
            self.length += (q - last).norm();
        }
        self.points.push(q);
    }
}

/// A zone with its arc lengths carried onto the flown path.
fn carried(zone: &Zone, map: &ArcMap) -> Zone {
    let [t1, t2, t3, t4] = zone.arcs();
    let [r1, r2, r3, r4] = [t1, t2, t3, t4].map(|s| map.rounded(s));
    Zone {
        arc: map.rounded(zone.arc),
        hold: [r2, r3],
        transition_in: (r2 - r1).max(0.0),
        transition_out: (r4 - r3).max(0.0),
        ..zone.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn length(points: &[Point3<f64>]) -> f64 {
        points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
    }

    fn square_corner() -> CentroidPath {
        CentroidPath::bare(vec![
            Point3::new(0.0, 0.0, 10.0),
            Point3::new(10.0, 0.0, 10.0),
            Point3::new(10.0, 10.0, 10.0),
        ])
    }

    /// A right-angle corner with a 0.2 m tolerance: rounded within half of
    /// it (the other half is the simplification's), so the arc passes
    /// T tan(φ/4) = 0.1 m inside the vertex, with radius T / tan(φ/2), and
    /// the path is shorter by 2T − ρφ.
    #[test]
    fn a_corner_is_rounded_within_its_tolerance() {
        let r = round(&square_corner(), |_| 0.2);
        let arc = r.flown[0];
        let quarter = (std::f64::consts::FRAC_PI_8).tan();
        assert!((arc.tangent - 0.1 / quarter).abs() < 1e-12);
        assert!((arc.radius - arc.tangent).abs() < 1e-12, "tan(45°) = 1");
        let vertex = Point3::new(10.0, 0.0, 10.0);
        let nearest = r
            .path
            .points
            .iter()
            .map(|q| (q - vertex).norm())
            .fold(f64::INFINITY, f64::min);
        // The middle chord's vertex lies on the arc, at the tolerance.
        assert!((nearest - 0.1).abs() < 1e-3, "{nearest}");
        let flown = length(&r.path.points);
        let expected = 20.0 - 2.0 * arc.tangent + arc.radius * std::f64::consts::FRAC_PI_2;
        assert!((flown - expected).abs() < 1e-3, "{flown} vs {expected}");
        assert!((r.map.rounded(20.0) - flown).abs() < 1e-9);
        assert!(
            (r.map.rounded(5.0) - 5.0).abs() < 1e-12,
            "before the corner"
        );
        assert_eq!(r.planned[0].extent, arc.tangent);
    }

    /// A corner no tolerance allows is kept as planned, and so is a hairpin.
    #[test]
    fn a_corner_without_room_or_a_hairpin_is_kept() {
        let r = round(&square_corner(), |_| 0.0);
        assert_eq!(r.path.points, square_corner().points);
        assert_eq!(r.planned[0].extent, 0.0);
        let hairpin = CentroidPath::bare(vec![
            Point3::new(0.0, 0.0, 10.0),
            Point3::new(10.0, 0.0, 10.0),
            Point3::new(0.0, 0.0, 10.0),
        ]);
        let r = round(&hairpin, |_| 0.5);
        assert_eq!(r.path.points, hairpin.points);
    }

    /// Tangents never take more than half a leg, so two corners close
    /// together never overlap.
    #[test]
    fn tangents_take_at_most_half_a_leg() {
        let path = CentroidPath::bare(vec![
            Point3::new(0.0, 0.0, 10.0),
            Point3::new(10.0, 0.0, 10.0),
            Point3::new(10.0, 1.0, 10.0),
            Point3::new(20.0, 1.0, 10.0),
        ]);
        let r = round(&path, |_| 5.0);
        assert!(r.flown.iter().all(|c| c.tangent <= 0.5 + 1e-12));
        let arcs = cumulative_lengths(&r.path.points);
        assert!(arcs.windows(2).all(|w| w[1] >= w[0]));
    }

    /// A kink a few centimetres long (a via joining a waypoint) is left
    /// out: the flown path has one corner where the planned one has three,
    /// and no flown point strays from the planned path more than the
    /// tolerance.
    #[test]
    fn a_short_kink_is_simplified_away_within_the_tolerance() {
        let planned = vec![
            Point3::new(0.0, 0.0, 10.0),
            Point3::new(10.0, 0.0, 10.0),
            Point3::new(10.03, 0.02, 10.0),
            Point3::new(10.05, 0.0, 10.0),
            Point3::new(20.0, 5.0, 10.0),
        ];
        let path = CentroidPath::bare(planned.clone());
        assert_eq!(corners(&planned).len(), 3);
        let r = round(&path, |_| 0.1);
        assert_eq!(r.flown.len(), 1, "{:?}", r.flown);
        let stray = r
            .path
            .points
            .iter()
            .map(|q| {
                planned
                    .windows(2)
                    .map(|w| crate::base::geometry::segment_point_distance_3d(&w[0], &w[1], q))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        assert!(stray <= 0.1 + 1e-9, "{stray}");
        assert!(r.planned.iter().all(|c| c.extent > 0.0));
    }
}
