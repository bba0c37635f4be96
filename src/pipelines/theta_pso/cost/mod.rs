//! The θ-PSO cost J = β1 J1 + β2 J2 + β3 J3 + β_R J_R + β_B J_B (eqs. 2-5,
//! 10-11), judged on every UAV's path, not only the centroid's.
//!
//! What verification checks is what each UAV flies: its slot offset turned
//! with the heading, through the reconfigurations and holds (`motion`). So
//! the cost evaluates the same function:
//!
//! - J1 (eq. 3): the centroid path's exact polyline length.
//! - J2 (eq. 4), per UAV and along whole pieces of path: for each UAV n and
//!   obstacle k, max(1 − d / r^S, 0) with r^S = r_k + r_Q + margin is
//!   *integrated* along the UAV's path (closed form on each straight piece,
//!   `violation_along`), not sampled at midpoints, so a thin pole between
//!   two samples is seen. Normalised by N K J1, so a path violating by v
//!   everywhere scores v, as the paper's mean over L segments does. Zero
//!   exactly when every UAV keeps r_Q + margin from every obstacle.
//! - J3 (eq. 5), per UAV: the altitude-band violation of each UAV (the ±
//!   height of a rotated shape included), summed over L equal shares of the
//!   path as the paper sums over its L segments; below the ground the finite
//!   `ground_penalty`.
//! - J_B, per UAV: how far it leaves the x-y bounds, summed the same way
//!   (the paper keeps the centroid inside by decoding; its UAVs can still
//!   leave, at an IWP's straight crossing).
//! - J_R (eq. 11), as printed: mean horizontal distance of the L segment
//!   midpoints to the enabled IWPs.
//! - J_T (not in the paper): the centroid path's horizontal turns beyond 90°,
//!   radians, so the swarm prefers no hairpins where a gentler route exists.
//!
//! Speed: a leg far from every obstacle, well inside the band and the bounds
//! cannot put a UAV in violation (every UAV stays within the formation's
//! reach of the centroid), so only the legs that come close are followed UAV
//! by UAV. Along them the path of each UAV is straight between knots (the
//! path's vertices ± the heading's span, the zones' t1..t4) except where the
//! heading turns or the shape blends; those stretches are split finely.
//!
//! Long (~925 lines) because it is J's terms and the one evaluation that sums them on every
//! UAV's path: the broad phase over the legs, the narrow phase along them, the scratch both
//! reuse, the turning term and the closed-form violation integral; the pairs' and the
//! passes' deficits are already submodules.

use nalgebra::{Point2, Point3, SVector, Vector3};

use super::iwp::{Iwp, Shape};
use super::motion::{Motion, Reader};
use super::path::Hint;
use super::path::{CentroidPath, heading_span};
use crate::base::shape::Prism;
use crate::mission::{Bounds, Mission, ThetaPsoParams};
use serde::Serialize;

mod pairs;
mod passes;

/// How far a UAV's path may stray from the chord of a piece where the heading
/// turns, metres: a fifth of the default clearance margin.
const CHORD_TOLERANCE: f64 = 0.02;
/// Longest piece where the shape blends, metres.
const BLEND_STEP: f64 = 2.0;
/// Room the cost asks between two UAVs beyond 2 r_Q + the safety margin,
/// metres (eq. 7 as verified is ≥ 2 r_Q + the margin); below the room the
/// smallest shrink and the column leave (`route::SQUEEZE_SPACING_MARGIN`).
pub const PAIR_FLOOR: f64 = 0.02;
/// Step of the pair check along the changes of shape, metres.
const PAIR_STEP: f64 = 0.5;
/// Halvings of one knot interval at most (2^8 pieces).
const MAX_DEPTH: u32 = 8;

/// Everything the cost needs, prepared once per run.
#[derive(Debug, Clone)]
pub struct CostModel {
    params: ThetaPsoParams,
    obstacles: Vec<Prism>,
    slots: Vec<Vector3<f64>>,
    /// r_Q + the safety margin: what every UAV keeps from an obstacle and
    /// a bound before the cost's own margin.
    uav_radius: f64,
    /// 2 r_Q + the safety margin + [`PAIR_FLOOR`]: the closest two UAVs
    /// may come before the pairs' term counts (eq. 7).
    pair_floor: f64,
    /// The clearance margin in use (the mission's, reduced where a gap is tight).
    margin: f64,
    span: f64,
    /// Farthest any UAV can be from the centroid horizontally, any shape.
    reach: f64,
    /// Farthest any UAV can be above or below the centroid, any shape.
    rise: f64,
    /// The same in the nominal shape, outside the reconfiguration zones.
    nominal_reach: f64,
    nominal_rise: f64,
    /// Eq. 8's stand-off band of each obstacle (used for the inspected).
    bands: Vec<[f64; 2]>,
    /// C_j of the enabled IWPs.
    iwp_points: Vec<Point2<f64>>,
    band: [f64; 2],
    bounds: Bounds,
    /// With terrain, the band is above the ground under each UAV.
    ground: Option<crate::base::terrain::Ground>,
    /// Cosine of the largest heading turn over one piece: the turn at which a
    /// UAV `reach` from the centroid strays `CHORD_TOLERANCE` from the chord.
    max_turn_cos: f64,
}

/// Cost terms of a θ-PSO path (eqs. 2-5, 10-11), unweighted, plus the weighted total.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct CostTerms {
    /// J1, path length, metres (eq. 3).
    pub length: f64,
    /// J2, mean violation of the obstacles' safe radii (eq. 4).
    pub obstacle: f64,
    /// J3, summed altitude-band violation, metres (eq. 5).
    pub altitude: f64,
    /// J_R, mean horizontal distance of the path to the enabled IWPs, metres (eq. 11).
    pub waypoints: f64,
    /// J_B, how far the UAVs leave the x-y bounds, summed over L shares of the path, metres.
    pub bounds: f64,
    /// J_T, the path's horizontal turns beyond 90°, summed, radians.
    pub turning: f64,
    /// J = β1 J1 + β2 J2 + β3 J3 + β_R J_R + β_B J_B + β_T J_T (eqs. 2, 10).
    pub total: f64,
}

impl CostTerms {
    /// The terms by name, the total first: what the run's progress reports
    /// (`Event::Iteration`) and a recording plots under `theta_pso/cost/`.
    pub fn named(&self) -> [(&'static str, f64); 5] {
        [
            ("J_total", self.total),
            ("J1_length", self.length),
            ("J2_obstacle", self.obstacle),
            ("J3_altitude", self.altitude),
            ("JR_waypoints", self.waypoints),
        ]
    }
}

/// What the swarm adds to J for a path that breaks a constraint anywhere
/// (Deb's feasibility rule, IEEE TEC 2000, as a penalty step): any path that
/// keeps every UAV clear ranks before any that does not, whatever their
/// lengths. Larger than any feasible J (J1 of a path within the trajectory
/// budget is far below 10⁶ m).
pub const INFEASIBLE_STEP: f64 = 1.0e6;

/// A path's J, its terms, and the objective the swarm minimises.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evaluation {
    pub terms: CostTerms,
    /// J for a path the cost finds clear; else J + [`INFEASIBLE_STEP`] +
    /// β2 Σ violation / J1 (J2 not averaged over the UAVs and obstacles, so
    /// one UAV clipping one post of a 200-post wall is not 1/200 as bad).
    pub objective: f64,
}

/// The terms a centroid path's points alone give (`CostModel::lead`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lead {
    /// J1, metres.
    pub length: f64,
    /// J_R, metres.
    pub waypoints: f64,
    /// J_T, radians.
    pub turning: f64,
    /// The L segments J_R was taken over (J3 and J_B are summed over them).
    segments: usize,
    /// β1 J1 + β_R J_R + β_T J_T.
    pub total: f64,
}

/// Running sums of the per-UAV terms.
#[derive(Default)]
struct Sums {
    /// Σ arc length × (1 − d / r^S)⁺ over UAVs, obstacles, pieces.
    obstacle: f64,
    /// Σ arc length × δ over UAVs, pieces.
    altitude: f64,
    /// Σ arc length × metres outside the bounds over UAVs, pieces.
    bounds: f64,
    /// Σ arc length × metres closer than 2 r_Q + the margin + `PAIR_FLOOR`, over the
    /// pairs of UAVs where they can change (eq. 7).
    spacing: f64,
    /// Σ step × metres the facing UAV is outside eq. 8's band, along the
    /// inspection passes a change of shape reaches into.
    passes: f64,
}

impl Sums {
    fn violated(&self) -> bool {
        self.obstacle > 0.0
            || self.altitude > 0.0
            || self.bounds > 0.0
            || self.spacing > 0.0
            || self.passes > 0.0
    }

    /// The violations measured in metres of path, undiluted (the swarm's
    /// penalty beyond the step).
    fn undiluted(&self) -> f64 {
        self.obstacle + self.spacing + self.passes
    }
}

impl CostModel {
    pub fn new(mission: &Mission, iwps: &[Iwp]) -> Self {
        let f = &mission.formation;
        let shapes: Vec<Shape> = iwps
            .iter()
            .filter(|i| i.is_via())
            .filter_map(|i| i.shape)
            .collect();
        let nominal_reach = f.slots.iter().map(|o| o.xy().norm()).fold(0.0, f64::max);
        let nominal_rise = f.slots.iter().map(|o| o.z.abs()).fold(0.0, f64::max);
        let (mut reach, mut rise) = (nominal_reach, nominal_rise);
        for shape in &shapes {
            for (n, o) in f.slots.iter().enumerate() {
                let full = shape.offset(&f.slots, n, 1.0);
                reach = reach.max(full.xy().norm()).max(o.norm());
                rise = rise.max(match shape {
                    // Turning about y sweeps x into z: the whole arc.
                    Shape::Rotation => (o.x * o.x + o.z * o.z).sqrt(),
                    _ => full.z.abs(),
                });
            }
        }
        // Room an IWP gap leaves beside the shape that crosses it.
        let spare = iwps
            .iter()
            .filter(|i| i.is_via())
            .map(|i| {
                let offsets = i
                    .shape
                    .map_or_else(|| f.slots.clone(), |s| s.offsets(&f.slots, 1.0));
                i.gap / 2.0 - super::iwp::lateral_half_width(&offsets, f.least_clearance())
            })
            .fold(f64::INFINITY, f64::min);
        let margin = mission
            .theta_pso
            .clearance_margin
            .min((spare / 2.0).max(0.0));
        CostModel {
            params: mission.theta_pso.clone(),
            obstacles: mission.obstacles.iter().map(|o| mission.prism(o)).collect(),
            bands: mission
                .obstacles
                .iter()
                .map(|o| o.stand_off_band(f))
                .collect(),
            slots: f.slots.clone(),
            uav_radius: f.least_clearance(),
            pair_floor: f.closest_pair() + PAIR_FLOOR,
            margin,
            span: heading_span(mission),
            reach,
            rise,
            nominal_reach,
            nominal_rise,
            iwp_points: iwps
                .iter()
                .filter(|i| i.enabled)
                .map(|i| i.position)
                .collect(),
            band: mission.bounds.z,
            bounds: mission.bounds.clone(),
            ground: mission.ground_model(),
            max_turn_cos: {
                let half = (1.0 - CHORD_TOLERANCE / reach.max(CHORD_TOLERANCE)).max(0.0);
                2.0 * half * half - 1.0
            },
        }
    }

    /// The clearance beyond r_Q the cost asks of every UAV, metres.
    pub fn margin(&self) -> f64 {
        self.margin
    }

    /// J and its terms for a centroid path.
    pub fn terms(&self, path: &CentroidPath) -> CostTerms {
        self.evaluate_below(path, f64::INFINITY).terms
    }

    /// J, its terms and the swarm's objective, or, as soon as the objective
    /// is known to reach `bound`, partial sums that already do (every term is
    /// ≥ 0, so a partial sum is a lower bound). The swarm passes a particle's
    /// personal best: a candidate that cannot beat it changes nothing,
    /// whatever its exact cost, so the search is the same as with full
    /// evaluations, only faster.
    pub fn evaluate_below(&self, path: &CentroidPath, bound: f64) -> Evaluation {
        self.evaluate_rest(path, self.lead(&path.points), bound)
    }

    /// J1, J_R and J_T with their weighted sum: what the path's points alone
    /// give, before any UAV is followed. Every other term is ≥ 0, so the
    /// sum is a lower bound of the objective: a particle whose lead reaches
    /// its bound needs no zones and no UAV followed.
    pub fn lead(&self, points: &[Point3<f64>]) -> Lead {
        let p = &self.params;
        let length = super::path::cumulative_lengths(points)
            .last()
            .copied()
            .unwrap_or(0.0);
        let turning = turning_excess(points, TURN_WINDOW);
        let (segments, waypoints) = self.waypoint_term(points, length);
        Lead {
            length,
            waypoints,
            turning,
            segments,
            total: p.weight_length * length
                + p.weight_waypoints * waypoints
                + p.weight_turning * turning,
        }
    }

    /// [`Self::evaluate_below`] given the path's [`Lead`].
    pub fn evaluate_rest(&self, path: &CentroidPath, lead: Lead, bound: f64) -> Evaluation {
        let (terms, violation) = self.terms_below(path, lead, bound);
        let objective = if violation > 0.0 {
            terms.total + INFEASIBLE_STEP + self.params.weight_obstacle * violation
        } else {
            terms.total
        };
        Evaluation { terms, objective }
    }

    /// J's terms (partial once the objective reaches `bound`) and the
    /// undiluted obstacle violation: Σ over UAVs and obstacles of the
    /// violation integral, over J1 (J2 before the paper's mean over N and K).
    /// Any band or bounds violation counts as a violation too.
    ///
    /// Long (~140 lines) because it is the evaluation's hot path in order (the broad phase
    /// over the legs, the legs deepest first, each followed until the bound is reached, then
    /// the pairs' and passes' deficits), its early exits sharing one `Scratch` and `Sums`.
    fn terms_below(&self, path: &CentroidPath, lead: Lead, bound: f64) -> (CostTerms, f64) {
        let points = &path.points;
        let p = &self.params;
        let total = lead.length;
        let segments = lead.segments;
        let mut terms = CostTerms {
            length: total,
            waypoints: lead.waypoints,
            turning: lead.turning,
            total: lead.total,
            ..CostTerms::default()
        };
        // Until a violation shows, the objective is at least J's sum so far
        // (an infeasible path's is larger still, by the step).
        if terms.total >= bound {
            return (terms, 0.0);
        }
        let motion = Motion::new(path, &self.slots, self.span);
        let arcs = motion.walker().arcs();
        let mut sums = Sums::default();
        let mut scratch = Scratch::default();
        let n = self.slots.len().max(1) as f64;
        let k = self.obstacles.len();
        let l = segments.max(1) as f64;
        let obstacle_scale = if k > 0 && total > 0.0 {
            1.0 / (n * k as f64 * total)
        } else {
            0.0
        };
        let share = if total > 0.0 { l / (n * total) } else { 0.0 };
        let undiluted = if total > 0.0 { 1.0 / total } else { 0.0 };
        let base = terms.total;
        // Which legs a UAV may break a constraint on, and with which obstacles.
        for (i, leg) in points.windows(2).enumerate() {
            let (a, b) = (leg[0], leg[1]);
            // Outside the zones the formation keeps its nominal extent.
            let (s0, s1) = (arcs[i], arcs[i + 1]);
            let (reach, rise) = if path.zones.iter().any(|z| {
                let [z0, _, _, z3] = z.arcs();
                z0 < s1 && s0 < z3
            }) {
                (self.reach, self.rise)
            } else {
                (self.nominal_reach, self.nominal_rise)
            };
            let first = scratch.all_near.len();
            let mut depth = f64::NEG_INFINITY;
            for (k, c) in self.obstacles.iter().enumerate() {
                if let Some(window) = self.touch_window(&a, &b, c, reach, rise) {
                    scratch.all_near.push((k, window));
                    if bound.is_finite() {
                        let (_, closest) =
                            crate::base::geometry::segment_projection(&a.xy(), &b.xy(), &c.center);
                        let room = c.radius + self.uav_radius + self.margin + reach;
                        depth = depth.max(room - closest);
                    }
                }
            }
            let low = a.z.min(b.z) - rise;
            let high = a.z.max(b.z) + rise;
            // Over terrain the band moves with the ground: follow every leg.
            let band = self.ground.is_some() || low < self.band[0] || high > self.band[1];
            let inside = self
                .bounds
                .horizontal_margin(&a)
                .min(self.bounds.horizontal_margin(&b));
            let edge = inside < reach;
            if scratch.all_near.len() == first && !band && !edge {
                continue;
            }
            if edge {
                depth = depth.max(reach - inside);
            }
            scratch.legs.push(LegWork {
                leg: i,
                whole: band || edge,
                near: first..scratch.all_near.len(),
                depth,
            });
        }
        // Against a bound, the legs that reach deepest into an obstacle (or
        // out of the bounds) first: a path that breaks a constraint usually
        // shows it there, and the evaluation stops at the first violation.
        if bound.is_finite() {
            scratch.legs.sort_by(|a, b| b.depth.total_cmp(&a.depth));
        }
        // The pairs' deficit (eq. 7) last: the most costly term, and not
        // needed when the legs alone reach the bound.
        let mut reached_bound = false;
        let legs = std::mem::take(&mut scratch.legs);
        // Any violation adds the step: against a bound it reaches, the first
        // one found ends the evaluation.
        let stop_at_violation = bound <= base + INFEASIBLE_STEP;
        for work in &legs {
            scratch.near.clear();
            scratch
                .near
                .extend_from_slice(&scratch.all_near[work.near.clone()]);
            let i = work.leg;
            self.follow_leg(
                &motion,
                path,
                arcs[i],
                arcs[i + 1],
                work.whole,
                stop_at_violation,
                &mut scratch,
                &mut sums,
            );
            let mut so_far = base
                + p.weight_obstacle * sums.obstacle * obstacle_scale
                + (p.weight_altitude * sums.altitude + p.weight_bounds * sums.bounds) * share;
            if sums.violated() {
                so_far += INFEASIBLE_STEP + p.weight_obstacle * sums.undiluted() * undiluted;
            }
            if so_far >= bound {
                reached_bound = true;
                break;
            }
        }
        if !reached_bound {
            sums.spacing = self.pair_deficit(&motion, path, &mut scratch.current);
            sums.passes = self.pass_deficit(&motion, path, &mut scratch.current);
        }
        terms.obstacle = sums.obstacle * obstacle_scale;
        terms.altitude = sums.altitude * share;
        terms.bounds = sums.bounds * share;
        terms.total = base
            + p.weight_obstacle * terms.obstacle
            + p.weight_altitude * terms.altitude
            + p.weight_bounds * terms.bounds;
        let violation = if sums.violated() {
            // Positive even for a band or bounds violation alone.
            (sums.undiluted() * undiluted).max(f64::MIN_POSITIVE)
        } else {
            0.0
        };
        (terms, violation)
    }

    /// J_R (eq. 11) over about L segments (each leg a share proportional to
    /// its length, at least one); returns the segment count and J_R.
    fn waypoint_term(&self, points: &[Point3<f64>], total: f64) -> (usize, f64) {
        let target = self.params.segments.max(1) as f64;
        let mut segments = 0usize;
        let mut sum = 0.0;
        for leg in points.windows(2) {
            let (a, b) = (leg[0], leg[1]);
            let len = (b - a).norm();
            let pieces = if total > 0.0 {
                ((target * len / total).round() as usize).max(1)
            } else {
                1
            };
            if !self.iwp_points.is_empty() {
                for k in 0..pieces {
                    let u = (k as f64 + 0.5) / pieces as f64;
                    let mid = a + (b - a) * u;
                    sum += self
                        .iwp_points
                        .iter()
                        .map(|c| (mid.xy() - c).norm())
                        .sum::<f64>();
                }
            }
            segments += pieces;
        }
        let m = self.iwp_points.len();
        let jr = if m > 0 {
            sum / (segments.max(1) as f64 * m as f64)
        } else {
            0.0
        };
        (segments, jr)
    }

    /// Where along the centroid leg a-b (fractions t0 ≤ t ≤ t1) a UAV of
    /// the formation can come within r_Q + margin of cylinder `c`, or `None`
    /// when nowhere (broad phase: every UAV is within `reach` of the centroid
    /// horizontally and `rise` vertically on this leg).
    fn touch_window(
        &self,
        a: &Point3<f64>,
        b: &Point3<f64>,
        c: &Prism,
        reach: f64,
        rise: f64,
    ) -> Option<(f64, f64)> {
        let safe = c.radius + self.uav_radius + self.margin + reach;
        let keep = self.uav_radius + self.margin;
        if a.z.min(b.z) - rise >= c.height + keep || a.z.max(b.z) + rise <= c.base - keep {
            // Entirely above the top, or under the base, by more than the
            // safe distance.
            return None;
        }
        // |a + t (b − a) − c| < safe in the plane.
        closer_than(&(a.xy() - c.center), &(b.xy() - a.xy()), safe)
    }

    /// Follows every UAV along the leg [s0, s1] of the centroid path: the
    /// whole leg when `whole` (the band or the bounds are in reach), else only
    /// the windows where a UAV can touch one of `scratch.near`'s obstacles;
    /// when `stop`, only up to the first violation.
    ///
    /// Long (~150 lines) because it is one leg's narrow phase in order (the windows merged,
    /// the knots where the motion changes, the pieces split where the heading turns, the UAVs
    /// read and their violations summed), on the borrowed scratch so it allocates nothing.
    #[allow(clippy::too_many_arguments)]
    fn follow_leg(
        &self,
        motion: &Motion<'_>,
        path: &CentroidPath,
        s0: f64,
        s1: f64,
        whole: bool,
        stop: bool,
        scratch: &mut Scratch,
        sums: &mut Sums,
    ) {
        if s1 <= s0 {
            return;
        }
        let Scratch {
            near,
            windows,
            knots,
            samples,
            previous,
            current,
            ..
        } = scratch;
        let len = s1 - s0;
        // Obstacle windows as arc lengths, merged.
        for (_, (t0, t1)) in near.iter_mut() {
            (*t0, *t1) = (s0 + *t0 * len, s0 + *t1 * len);
        }
        windows.clear();
        if whole {
            windows.push((s0, s1));
        } else {
            windows.extend(near.iter().map(|(_, w)| *w));
            windows.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut merged = 0;
            for i in 1..windows.len() {
                if windows[i].0 <= windows[merged].1 {
                    windows[merged].1 = windows[merged].1.max(windows[i].1);
                } else {
                    merged += 1;
                    windows[merged] = windows[i];
                }
            }
            windows.truncate(merged + 1);
        }
        let span = motion.span();
        for &(w0, w1) in windows.iter() {
            knots.clear();
            knots.push(w0);
            knots.push(w1);
            for &a in motion.walker().arcs() {
                for s in [a - span, a + span] {
                    if w0 < s && s < w1 {
                        knots.push(s);
                    }
                }
            }
            for zone in &path.zones {
                for s in zone.arcs() {
                    if w0 < s && s < w1 {
                        knots.push(s);
                    }
                }
                // In file along the path, UAV n passes a vertex when the
                // centroid is its place in the column short of it.
                let [z0, _, _, z3] = zone.arcs();
                let column = [Some(zone.shape), zone.from, zone.into]
                    .into_iter()
                    .flatten()
                    .find(|s| matches!(s, Shape::Alignment { .. }));
                if let Some(Shape::Alignment { spacing }) = column {
                    for &a in motion.walker().arcs() {
                        for n in 0..self.slots.len() {
                            let s = a - motion.column_place(n, spacing);
                            if w0 < s && s < w1 && z0 <= s && s <= z3 {
                                knots.push(s);
                            }
                        }
                    }
                }
            }
            // Over terrain, sample the band at the map's resolution (at most
            // 4096 samples a window): the ground changes between vertices.
            if let Some(g) = &self.ground {
                let pixel = g.map.pixel[0].abs().min(g.map.pixel[1].abs());
                let step = pixel.max((w1 - w0) / 4096.0);
                let mut s = w0 + step;
                while s < w1 {
                    knots.push(s);
                    s += step;
                }
            }
            knots.sort_by(f64::total_cmp);
            knots.dedup_by(|a, b| (*a - *b).abs() < 1e-9);

            // Split the intervals where the heading turns (until each piece's
            // chord stays within CHORD_TOLERANCE of the UAVs' arcs) or the
            // shape blends.
            samples.clear();
            samples.push(w0);
            let mut chord = [Hint::default(); 2];
            let mut heading_before = motion.walker().heading_from(w0, span, &mut chord);
            for w in knots.windows(2) {
                let (k0, k1) = (w[0], w[1]);
                let heading_after = motion.walker().heading_from(k1, span, &mut chord);
                let blend_step = if motion.state_at((k0 + k1) / 2.0).is_changing() {
                    BLEND_STEP
                } else {
                    f64::INFINITY
                };
                let piece = Piece {
                    motion,
                    max_turn_cos: self.max_turn_cos,
                    step: blend_step,
                };
                piece.split(
                    k0,
                    k1,
                    heading_before,
                    heading_after,
                    MAX_DEPTH,
                    samples,
                    &mut chord,
                );
                heading_before = heading_after;
            }

            let mut reader = Reader::default();
            motion.read_into(samples[0], previous, &mut reader);
            for w in samples.windows(2) {
                let (a, b) = (w[0], w[1]);
                motion.read_into(b, current, &mut reader);
                // A circle round every UAV's piece of this interval: an
                // obstacle whose axis stands `safe` beyond it adds nothing
                // (each piece lies in the circle, so each UAV's distance to
                // the axis is at least that), and is passed over whole.
                // The same for each UAV: a piece whose start stands `safe`
                // plus the longest piece from the axis.
                let (middle, spread) = enclosing(previous, current);
                let longest = previous
                    .iter()
                    .zip(current.iter())
                    .map(|(p, q)| (q.xy() - p.xy()).norm_squared())
                    .fold(0.0, f64::max)
                    .sqrt();
                for &(k, (n0, n1)) in near.iter() {
                    if b < n0 || a > n1 {
                        continue;
                    }
                    let c = &self.obstacles[k];
                    let safe = c.radius + self.uav_radius + self.margin;
                    if (middle - c.center).norm() - spread >= safe {
                        continue;
                    }
                    let far = (safe + longest) * (safe + longest);
                    for (p, q) in previous.iter().zip(current.iter()) {
                        if (p.xy() - c.center).norm_squared() >= far {
                            continue;
                        }
                        sums.obstacle += violation_along(p, q, c, safe);
                    }
                }
                if whole {
                    self.observe_points(current, b - a, sums);
                }
                std::mem::swap(previous, current);
                if stop && sums.violated() {
                    return;
                }
            }
        }
    }

    /// Band and bounds violations of the UAVs at one sample, weighted by the
    /// arc length the sample stands for.
    fn observe_points(&self, points: &[Point3<f64>], len: f64, sums: &mut Sums) {
        if len <= 0.0 {
            return;
        }
        for p in points {
            let ground = self.ground.as_ref().map_or(0.0, |g| g.at(p.x, p.y));
            sums.altitude += len * self.altitude_violation(p.z - ground);
            let out = -self.bounds.horizontal_margin(p);
            if out > 0.0 {
                sums.bounds += len * out;
            }
        }
    }

    /// δ of eq. 5 for a UAV at height z above the ground.
    fn altitude_violation(&self, z: f64) -> f64 {
        let [z_min, z_max] = self.band;
        if z <= 0.0 {
            self.params.ground_penalty
        } else if z > z_max {
            z - z_max
        } else if z < z_min {
            z_min - z
        } else {
            0.0
        }
    }
}

/// How finely to split the pieces of a UAV's path.
struct Piece<'a, 'm> {
    motion: &'a Motion<'m>,
    max_turn_cos: f64,
    /// Longest piece, metres (where the shape blends).
    step: f64,
}

impl Piece<'_, '_> {
    /// Pushes the ends of the pieces of (a, b] into `samples`, halving while
    /// a piece turns the heading by more than allowed or is longer than the
    /// step (the heading read through `chord`).
    #[allow(clippy::too_many_arguments)]
    fn split(
        &self,
        a: f64,
        b: f64,
        heading_a: Vector3<f64>,
        heading_b: Vector3<f64>,
        depth: u32,
        samples: &mut Vec<f64>,
        chord: &mut [Hint; 2],
    ) {
        if depth == 0 || (heading_a.dot(&heading_b) >= self.max_turn_cos && b - a <= self.step) {
            samples.push(b);
            return;
        }
        let mid = (a + b) / 2.0;
        let heading_mid = self
            .motion
            .walker()
            .heading_from(mid, self.motion.span(), chord);
        self.split(a, mid, heading_a, heading_mid, depth - 1, samples, chord);
        self.split(mid, b, heading_mid, heading_b, depth - 1, samples, chord);
    }
}

/// Where along f + t d, t ∈ [0, 1], the point is closer than `radius` to
/// the origin: between the roots of |f + t d|² = radius², a quadratic in t;
/// all of [0, 1] when d is nil and f is inside. The broad phase's windows
/// (`touch_window`) and the column's chords (`pairs::linear_deficit`).
fn closer_than<const D: usize>(
    f: &SVector<f64, D>,
    d: &SVector<f64, D>,
    radius: f64,
) -> Option<(f64, f64)> {
    let qa = d.norm_squared();
    let qb = 2.0 * f.dot(d);
    let qc = f.norm_squared() - radius * radius;
    if qa < 1e-18 {
        return (qc < 0.0).then_some((0.0, 1.0));
    }
    let disc = qb * qb - 4.0 * qa * qc;
    if disc <= 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let t0 = ((-qb - root) / (2.0 * qa)).max(0.0);
    let t1 = ((-qb + root) / (2.0 * qa)).min(1.0);
    (t0 < t1).then_some((t0, t1))
}

/// Every UAV's position at evenly spaced arc lengths from `from` to `to`,
/// both included, at most `most` apart: `at(positions, spacing)` at each.
/// The changes of shape' pairs and the passes' facing UAV are sampled so.
fn each_sample(
    motion: &Motion<'_>,
    [from, to]: [f64; 2],
    most: f64,
    scratch: &mut Vec<Point3<f64>>,
    reader: &mut Reader,
    mut at: impl FnMut(&[Point3<f64>], f64),
) {
    let samples = (((to - from) / most).ceil() as usize).max(1);
    let step = (to - from) / samples as f64;
    for k in 0..=samples {
        motion.read_into(from + k as f64 * step, scratch, reader);
        at(scratch, step);
    }
}

/// Half the stretch of path over which J_T sums the corners' turns into
/// one, metres: corners within a metre turn as one (issue 36's 200° turn
/// "within 1 m of path").
pub const TURN_WINDOW: f64 = 0.5;

/// J_T: the path's horizontal turns beyond 90°, radians. A sharper turn
/// whips the formation round (its outer UAVs speed up with the turn rate
/// times their offset) and doubles back on the route.
///
/// A turn is what the path turns within `window` either side of a point
/// ([`TURN_WINDOW`]: the formation turns through close corners as through
/// one): the sum of the signed turns of the corners there. J_T is
/// the mean over the path's points of that turn's excess beyond 90°, each
/// point's window 2 `window` long, so an isolated corner of θ costs
/// θ − 90° (as a corner did before issue 36), a 200° turn made of three
/// corners 30 cm apart costs 110° instead of nothing, corners far apart
/// cost what each does alone, and a zigzag's corners cancel. The mean is
/// continuous in the corners' positions (no step where a leg grows past
/// the window), which the swarm needs.
pub fn turning_excess(points: &[Point3<f64>], window: f64) -> f64 {
    // (arc length, signed turn) of every corner.
    let mut corners: Vec<(f64, f64)> = Vec::new();
    let mut incoming: Option<nalgebra::Vector2<f64>> = None;
    let mut s = 0.0;
    for w in points.windows(2) {
        let d = w[1].xy() - w[0].xy();
        let length = (w[1] - w[0]).norm();
        if d.norm() > 1e-9 {
            if let Some(a) = incoming {
                let signed = a.perp(&d).atan2(a.dot(&d));
                if signed.abs() > 1e-12 {
                    corners.push((s, signed));
                }
            }
            incoming = Some(d);
        }
        s += length;
    }
    let right_angle = std::f64::consts::FRAC_PI_2;
    if window <= 0.0 {
        return corners
            .iter()
            .map(|c| (c.1.abs() - right_angle).max(0.0))
            .sum();
    }
    // Sweep the window's centre along the path: the sum of the turns in it
    // changes only where a corner enters (centre at its arc − window) or
    // leaves (+ window).
    let mut events: Vec<(f64, f64)> = corners
        .iter()
        .flat_map(|&(at, turn)| [(at - window, turn), (at + window, -turn)])
        .collect();
    events.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut sum, mut excess) = (0.0f64, 0.0);
    for pair in events.windows(2) {
        sum += pair[0].1;
        let span = pair[1].0 - pair[0].0;
        if span > 0.0 {
            excess += span * (sum.abs() - right_angle).max(0.0);
        }
    }
    excess / (2.0 * window)
}

/// A leg a UAV may break a constraint on: its index, whether it is followed
/// whole (the band or the bounds are in reach), its obstacles (a range of
/// `Scratch::all_near`), and how deep the formation's reach goes into one
/// of them or out of the bounds, metres.
struct LegWork {
    leg: usize,
    whole: bool,
    near: std::ops::Range<usize>,
    depth: f64,
}

/// Buffers reused across the legs of one evaluation.
#[derive(Default)]
struct Scratch {
    /// Every leg's obstacles with their windows, leg after leg.
    all_near: Vec<(usize, (f64, f64))>,
    legs: Vec<LegWork>,
    /// Obstacles a UAV may touch on this leg, with their window along it.
    near: Vec<(usize, (f64, f64))>,
    windows: Vec<(f64, f64)>,
    knots: Vec<f64>,
    samples: Vec<f64>,
    previous: Vec<Point3<f64>>,
    current: Vec<Point3<f64>>,
}

/// The middle of the points' bounding box (in the plane) and the farthest
/// point's distance from it: a circle holding every point, so every
/// segment between them.
fn enclosing(a: &[Point3<f64>], b: &[Point3<f64>]) -> (nalgebra::Point2<f64>, f64) {
    let (mut lo, mut hi) = (
        nalgebra::Point2::new(f64::INFINITY, f64::INFINITY),
        nalgebra::Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for p in a.iter().chain(b) {
        lo = nalgebra::Point2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = nalgebra::Point2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    let middle = nalgebra::center(&lo, &hi);
    let spread = a
        .iter()
        .chain(b)
        .map(|p| (p.xy() - middle).norm_squared())
        .fold(0.0, f64::max)
        .sqrt();
    (middle, spread)
}

/// ∫ max(1 − d / R, 0) dℓ along the straight piece p-q of a UAV's path
/// (eq. 4's violation, integrated instead of sampled), with d the distance to
/// the cylinder's axis (over the top disc above it) and R = r^S.
///
/// Along a straight line passing h from the axis, d = √(h² + u²) with u the
/// distance along it from the closest point, so the integral has a closed
/// form: F(u) = u − (u √(u² + h²) + h² asinh(u / h)) / 2R, taken over the
/// part of the piece within √(R² − h²) of the closest point. Exact for a
/// level piece below the top; above it, h is the axis distance at the closest
/// point (which counts the height over the top disc).
///
/// Any other footprint (a polygon, any shape not a disc) has no axis: d is
/// R + its clearance (R its bounding circle's radius, so r^S − d is the
/// clearance short of r_Q + margin, as for a cylinder), integrated by the
/// midpoint rule at 0.2 m or finer.
pub fn violation_along(p: &Point3<f64>, q: &Point3<f64>, c: &Prism, safe: f64) -> f64 {
    /// Samples judged at once by their middle's clearance.
    const SKIP_BLOCK: usize = 8;
    if c.outline.disc().is_none() {
        let length = (q - p).norm();
        let n = ((length / 0.2).ceil() as usize).clamp(2, 64);
        let step = length / n as f64;
        // The integrand is 0 wherever the clearance reaches safe − R, and
        // the clearance changes by no more than the distance moved: a
        // block of samples whose middle is that far plus half the block
        // clear adds nothing, and is skipped (the same sum, bit for bit:
        // only zeros are left out). A long wall's bounding circle takes in
        // every piece of the path, so most pieces are skipped whole.
        let free = safe - c.radius;
        let at = |i: f64| p + (q - p) * (i / n as f64);
        let mut total = 0.0;
        let mut block = 0;
        while block < n {
            let end = (block + SKIP_BLOCK).min(n);
            let middle = at((block + end) as f64 / 2.0);
            if c.clearance(&middle) - step * (end - block) as f64 / 2.0 >= free {
                block = end;
                continue;
            }
            for i in block..end {
                total += (1.0 - (c.radius + c.clearance(&at(i as f64 + 0.5))) / safe).max(0.0);
            }
            block = end;
        }
        return total * step;
    }
    let (a, b) = (p.xy(), q.xy());
    let ab = b - a;
    let length = ab.norm();
    let (t, _) = crate::base::geometry::segment_projection(&a, &b, &c.center);
    let h = c.axis_distance(&(p + (q - p) * t));
    if h >= safe {
        return 0.0;
    }
    let reach = (safe * safe - h * h).sqrt();
    if length < 1e-12 {
        return 0.0;
    }
    // Signed distances of the piece's ends from the line's closest point.
    let along = ab / length;
    let s_closest = (c.center - a).dot(&along);
    let u0 = (-s_closest).max(-reach);
    let u1 = (length - s_closest).min(reach);
    if u1 <= u0 {
        return 0.0;
    }
    let antiderivative = |u: f64| {
        let tail = if h > 1e-12 {
            u * (u * u + h * h).sqrt() + h * h * (u / h).asinh()
        } else {
            u * u.abs()
        };
        u - tail / (2.0 * safe)
    };
    antiderivative(u1) - antiderivative(u0)
}

#[cfg(test)]
mod tests;
