//! From a particle to a centroid path: the eq. 1 decoding, the via-points the
//! path must include (IWP crossings, inspection passes), and where along the
//! path the formation changes shape.
//!
//! Reading: the paper plans "the optimized path P_F* … in which the
//! intermediate waypoints for reconfiguration have been included" (III.C),
//! and Fig. 3 line 7 places the IWPs "using eqs. (7), (8), (9)". So:
//! - every usable IWP is a via-point of the centroid path, crossed straight
//!   along the gap's normal through C_j − a n, C_j, C_j + a n (a: the hold
//!   plus room for the heading to settle);
//! - every inspected obstacle (eq. 8) is a straight pass tangent to it, at the
//!   stand-off that keeps the facing UAV in its band; where around the
//!   obstacle the pass lies is one more angle of the particle (decoded as eq. 1
//!   decodes the waypoints), and which way round it is flown is the insertion's
//!   choice.
//!
//! Each via is inserted into the leg where it lengthens the path least, so the
//! swarm still decides the route between them.

use nalgebra::{Point2, Point3, Vector2, Vector3};

use super::inspection::PassGeometry;
use super::iwp::{Iwp, Shape, lateral_half_width, vertical_half_height};
pub use crate::base::swarm::{decode_angle, encode_angle};
use crate::mission::Mission;

/// Why the formation changes shape over a zone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ZoneCause {
    /// The crossing of IWP `iwp` (index into the IWP list) between the
    /// obstacles `pair`.
    Iwp { iwp: usize, pair: [usize; 2] },
    /// A squeezed region of the route stage (1-based), passed between the
    /// obstacles `pair` (nearest on the left and the right where it is
    /// narrowest; the same twice against a bound).
    Squeeze { region: u16, pair: [usize; 2] },
}

/// Where along the path the formation changes shape, and into what.
///
/// Arc lengths s along the centroid path, metres: [t1, t2] the change into
/// the shape (from the nominal shape, or from the zone before when the two
/// follow each other too closely to return in between), [t2, t3] the hold,
/// [t3, t4] the change out of it (into the nominal shape or the next zone's).
/// For an IWP the hold is s_j ± h, with h the mission's hold distance plus
/// the depth at which the formation could touch the wall, so the new shape
/// is complete `hold_distance` before any UAV reaches the obstacles (the
/// paper's "1 m before"); for a squeeze it is the stretch inside the region
/// ± the hold distance.
#[derive(Debug, Clone, PartialEq)]
pub struct Zone {
    /// Why: one cause, or several when consecutive zones merged into one hold.
    pub causes: Vec<ZoneCause>,
    pub shape: Shape,
    /// s_j, arc length of the IWP (the middle of the hold for a squeeze).
    pub arc: f64,
    /// [t2, t3] as arc lengths.
    pub hold: [f64; 2],
    /// Length of the change into the shape before the hold.
    pub transition_in: f64,
    /// Length of the change out of it after the hold.
    pub transition_out: f64,
    /// The shape the change in starts from (`None`: the nominal shape).
    pub from: Option<Shape>,
    /// The shape the change out ends in (`None`: the nominal shape).
    pub into: Option<Shape>,
}

/// The formation's shape at one arc length: the change from `from` to `to`
/// (`None`: the nominal shape), `blend` of the way (0 = `from`, 1 = `to`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeState {
    pub from: Option<Shape>,
    pub to: Option<Shape>,
    pub blend: f64,
}

impl ShapeState {
    /// The nominal shape.
    pub const NOMINAL: ShapeState = ShapeState {
        from: None,
        to: None,
        blend: 0.0,
    };

    /// A shape held.
    pub fn held(shape: Shape) -> Self {
        ShapeState {
            from: Some(shape),
            to: Some(shape),
            blend: 1.0,
        }
    }

    /// `shape` held, or the nominal shape for `None`.
    pub fn held_or_nominal(shape: Option<Shape>) -> Self {
        shape.map_or(ShapeState::NOMINAL, ShapeState::held)
    }

    /// Part-way between two shapes (not at either end).
    pub fn is_changing(&self) -> bool {
        self.from != self.to && self.blend > 0.0 && self.blend < 1.0
    }

    /// Slot `n`'s offset (formation frame) in this state. From or to the
    /// nominal shape it is the shape's own change (rotation turns rigidly,
    /// the others move each UAV along a straight line); between two shapes,
    /// each UAV moves straight from one to the other.
    pub fn offset(&self, nominal: &[Vector3<f64>], n: usize) -> Vector3<f64> {
        match (self.from, self.to) {
            (None, None) => nominal[n],
            (None, Some(to)) => to.offset(nominal, n, self.blend),
            (Some(from), None) => from.offset(nominal, n, 1.0 - self.blend),
            (Some(from), Some(to)) if from == to => from.offset(nominal, n, 1.0),
            (Some(from), Some(to)) => from
                .offset(nominal, n, 1.0)
                .lerp(&to.offset(nominal, n, 1.0), self.blend),
        }
    }
}

/// The smoothstep of a linear progress in [0, 1]: each UAV's velocity stays
/// continuous through a change of shape.
fn smoothstep(u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

impl Zone {
    /// The shape state at `s`, or `None` outside the zone.
    pub fn state(&self, s: f64) -> Option<ShapeState> {
        let [t1, t2, t3, t4] = self.arcs();
        if s < t1 || s > t4 {
            None
        } else if s < t2 {
            (self.transition_in > 0.0).then(|| ShapeState {
                from: self.from,
                to: Some(self.shape),
                blend: smoothstep((s - t1) / self.transition_in),
            })
        } else if s <= t3 {
            Some(ShapeState::held(self.shape))
        } else {
            (self.transition_out > 0.0).then(|| ShapeState {
                from: Some(self.shape),
                to: self.into,
                blend: smoothstep((s - t3) / self.transition_out),
            })
        }
    }

    /// Arc lengths of t1, t2, t3, t4.
    pub fn arcs(&self) -> [f64; 4] {
        [
            self.hold[0] - self.transition_in,
            self.hold[0],
            self.hold[1],
            self.hold[1] + self.transition_out,
        ]
    }

    pub fn contains(&self, s: f64) -> bool {
        let [a1, _, _, a4] = self.arcs();
        a1 < s && s < a4
    }
}

/// Shorter than this, a change between two shapes is not flown: the holds
/// of two zones this close join into one, in the narrower shape.
pub const MIN_BLEND: f64 = 2.0;

/// The zones in path order, with the ones that follow each other too
/// closely for the formation to return to its nominal shape in between
/// joined up: between two rigid shapes (shrinks, rotation) the change out of
/// one blends straight into the next one's shape over the stretch between
/// their holds; when that stretch is shorter than [`MIN_BLEND`], the holds
/// overlap, or either shape is the column, the two holds become one in the
/// narrower of the two shapes (lateral width, UAV radius included), which
/// fits both gaps. The column takes over its neighbours because it flies
/// along the path, clear wherever one UAV is, and because a straight blend
/// between a column and a spread shape can bring two UAVs closer than
/// either shape does. Not in the paper, whose experiment has one IWP (Fig. 2
/// shows each reconfiguration on its own).
pub fn schedule(mut zones: Vec<Zone>, slots: &[Vector3<f64>], r_q: f64) -> Vec<Zone> {
    zones.sort_by(|a, b| a.hold[0].total_cmp(&b.hold[0]));
    let width = |s: &Shape| lateral_half_width(&s.offsets(slots, 1.0), r_q);
    let mut i = 0;
    while i + 1 < zones.len() {
        let gap = zones[i + 1].hold[0] - zones[i].hold[1];
        if gap >= zones[i].transition_out + zones[i + 1].transition_in {
            i += 1;
            continue;
        }
        let column = |s: &Shape| matches!(s, Shape::Alignment { .. });
        let rigid = !column(&zones[i].shape) && !column(&zones[i + 1].shape);
        if gap >= MIN_BLEND && rigid && zones[i].shape != zones[i + 1].shape {
            let (a, b) = (zones[i].shape, zones[i + 1].shape);
            zones[i].transition_out = gap;
            zones[i].into = Some(b);
            zones[i + 1].transition_in = gap;
            zones[i + 1].from = Some(a);
            i += 1;
            continue;
        }
        // One hold over both, in the narrower shape; then look again at the
        // zone before, whose change now leads into a different hold.
        let next = zones.remove(i + 1);
        let zone = &mut zones[i];
        if width(&next.shape) < width(&zone.shape) {
            zone.shape = next.shape;
        }
        zone.hold = [
            zone.hold[0].min(next.hold[0]),
            zone.hold[1].max(next.hold[1]),
        ];
        zone.transition_out = next.transition_out;
        zone.into = next.into;
        for cause in next.causes {
            // One squeezed region entered twice is one cause.
            let same = |c: &ZoneCause| match (c, &cause) {
                (ZoneCause::Squeeze { region: a, .. }, ZoneCause::Squeeze { region: b, .. }) => {
                    a == b
                }
                (a, b) => a == b,
            };
            if !zone.causes.iter().any(same) {
                zone.causes.push(cause);
            }
        }
        if i > 0 {
            let shape = zones[i].shape;
            if zones[i - 1].into.is_some() {
                zones[i - 1].into = Some(shape);
                zones[i].from = Some(zones[i - 1].shape);
            }
            i -= 1;
        }
    }
    zones
}

/// An inspection pass as placed on one path: which obstacle, and the arc
/// lengths along the centroid path where the pass begins and ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Pass {
    /// Index into `mission.obstacles`.
    pub obstacle: usize,
    pub arcs: [f64; 2],
    /// The obstacle is on the formation's left (flown anticlockwise round it).
    pub on_left: bool,
}

/// A centroid path, its reconfiguration zones and its inspection passes.
#[derive(Debug, Clone, PartialEq)]
pub struct CentroidPath {
    pub points: Vec<Point3<f64>>,
    pub zones: Vec<Zone>,
    pub passes: Vec<Pass>,
    /// The IWPs the path crosses (indices into the IWP list).
    pub crossed: Vec<usize>,
}

impl CentroidPath {
    /// A path with no zones or passes (tests, references).
    pub fn bare(points: Vec<Point3<f64>>) -> Self {
        CentroidPath {
            points,
            zones: Vec::new(),
            passes: Vec::new(),
            crossed: Vec::new(),
        }
    }
}

/// What is fixed for a mission while the swarm searches.
#[derive(Debug, Clone)]
pub struct PathBuilder {
    start: Point3<f64>,
    goal: Point3<f64>,
    /// Decoding box of the free waypoints: the bounds less r_F horizontally
    /// and the nominal half-height vertically.
    bounds: [[f64; 2]; 3],
    free: usize,
    crossings: Vec<Crossing>,
    inspections: Vec<Inspection>,
    /// With terrain, the path is planned above the ground and lifted onto it
    /// at its vertices.
    ground: Option<crate::base::terrain::Ground>,
    /// The nominal slots and r_Q (to choose the narrower of two shapes).
    slots: Vec<Vector3<f64>>,
    uav_radius: f64,
    /// The mission's hold and transition distances (squeezed stretches).
    hold_distance: f64,
    transition: f64,
    /// Where the route stage found the site narrower than the formation.
    squeeze: Option<std::sync::Arc<super::route::SqueezeMap>>,
}

/// A usable IWP as a via: its straight crossing.
#[derive(Debug, Clone)]
struct Crossing {
    iwp: usize,
    pair: [usize; 2],
    shape: Option<Shape>,
    center: Point2<f64>,
    /// Normal scaled by the half length of the straight crossing.
    reach: Vector2<f64>,
    /// Half width of the gate a leg must pass to be taken through the gap:
    /// half the gap plus the formation's safe radius.
    gate: f64,
    hold: f64,
    transition: f64,
    /// Altitudes the centroid may take at the IWP so every UAV of the shape
    /// stays in the band.
    z_range: [f64; 2],
}

/// An inspected obstacle as a via: a straight pass tangent to it.
#[derive(Debug, Clone)]
struct Inspection {
    obstacle: usize,
    axis: Point2<f64>,
    geometry: PassGeometry,
    /// Half the straight: half the pass plus the heading's chord, so the
    /// formation flies the whole pass on a constant heading.
    half: f64,
    z_range: [f64; 2],
}

/// Number of angles a particle has for a mission: three per free waypoint,
/// one per inspected obstacle.
pub fn dimensions(mission: &Mission) -> usize {
    3 * mission.theta_pso.waypoints + mission.obstacles.iter().filter(|o| o.inspect).count()
}

pub use super::iwp::heading_span;

impl PathBuilder {
    pub fn new(mission: &Mission, iwps: &[Iwp], passes: &[(usize, PassGeometry)]) -> Self {
        let b = &mission.bounds;
        let f = &mission.formation;
        let nominal = &f.slots;
        let r_f = f.radius();
        let span = heading_span(mission);
        let band_for = |half_height: f64| {
            let (lo, hi) = (b.z[0] + half_height, b.z[1] - half_height);
            if lo <= hi {
                [lo, hi]
            } else {
                let mid = (b.z[0] + b.z[1]) / 2.0;
                [mid, mid]
            }
        };
        let crossings = iwps
            .iter()
            .enumerate()
            .filter(|(_, iwp)| iwp.is_via())
            .map(|(i, iwp)| {
                let shaped = iwp
                    .shape
                    .map_or_else(|| nominal.clone(), |s| s.offsets(nominal, 1.0));
                let hold = iwp.hold;
                // Straight far enough that the heading, taken from a chord of
                // ± span, points along the crossing for the whole hold (a
                // column's UAVs follow the path, so not for its length). No
                // longer: the swarm may extend it, a fixed longer one could
                // run into a nearby obstacle.
                let straight = iwp.straight;
                let half_height = vertical_half_height(&shaped).max(vertical_half_height(nominal));
                Crossing {
                    iwp: i,
                    pair: iwp.obstacles,
                    shape: iwp.shape,
                    center: iwp.position,
                    reach: iwp.normal * straight,
                    gate: iwp.gap / 2.0 + f.safe_radius(),
                    hold,
                    transition: mission.reconfiguration.transition_distance,
                    z_range: band_for(half_height),
                }
            })
            .collect();
        let inspections = passes
            .iter()
            .map(|&(k, geometry)| Inspection {
                obstacle: k,
                axis: mission.obstacles[k].center,
                geometry,
                half: mission.formation.inspection_pass / 2.0 + span,
                z_range: band_for(vertical_half_height(nominal)),
            })
            .collect();
        // The centroid searches a box shrunk by r_F so every UAV stays inside
        // the bounds; a box too small for that collapses to its middle line.
        let shrink = |[lo, hi]: [f64; 2], by: f64| {
            if hi - lo > 2.0 * by {
                [lo + by, hi - by]
            } else {
                let mid = (lo + hi) / 2.0;
                [mid, mid]
            }
        };
        let half_height = vertical_half_height(nominal);
        PathBuilder {
            start: mission.route.start,
            goal: mission.route.goal,
            bounds: [shrink(b.x, r_f), shrink(b.y, r_f), shrink(b.z, half_height)],
            free: mission.theta_pso.waypoints,
            crossings,
            inspections,
            ground: mission.ground_model(),
            slots: f.slots.clone(),
            uav_radius: f.uav_radius,
            hold_distance: mission.reconfiguration.hold_distance,
            transition: mission.reconfiguration.transition_distance,
            squeeze: None,
        }
    }

    /// Paths of this builder fly squeezed through `map`'s regions.
    pub fn set_squeeze(&mut self, map: Option<std::sync::Arc<super::route::SqueezeMap>>) {
        self.squeeze = map;
    }

    /// The number of free waypoints a particle decodes.
    pub fn free_waypoints(&self) -> usize {
        self.free
    }

    /// Particles decode `free` waypoints (more than the mission's when the
    /// route stage's corridor has more corners).
    pub fn set_free_waypoints(&mut self, free: usize) {
        self.free = free;
    }

    /// The straight crossings of the usable IWPs, end to end (portals of
    /// the seeding route).
    pub fn crossings(&self) -> Vec<[Point2<f64>; 2]> {
        self.crossings
            .iter()
            .map(|c| [c.center - c.reach, c.center + c.reach])
            .collect()
    }

    /// The IWP (index into the problem's IWPs) of each crossing.
    pub fn crossing_iwps(&self) -> Vec<usize> {
        self.crossings.iter().map(|c| c.iwp).collect()
    }

    /// Inspected obstacles, in the order their pass angles follow the
    /// waypoints in a particle: (index in `mission.obstacles`, axis).
    pub fn inspections(&self) -> Vec<(usize, Point2<f64>)> {
        self.inspections
            .iter()
            .map(|i| (i.obstacle, i.axis))
            .collect()
    }

    /// The ends of inspection `i`'s straight (the pass with its lead-in and
    /// lead-out) at angle `phi` round the axis, in the direction of travel,
    /// with the obstacle on the formation's left or right.
    pub fn pass_ends(&self, i: usize, phi: f64, on_left: bool) -> [Point2<f64>; 2] {
        let ins = &self.inspections[i];
        let (sin, cos) = phi.sin_cos();
        let radial = Vector2::new(cos, sin);
        // Anticlockwise round the axis: the obstacle is on the left.
        let anticlockwise = Vector2::new(-sin, cos);
        let (radius, direction) = if on_left {
            (ins.geometry.radius_left, anticlockwise)
        } else {
            (ins.geometry.radius_right, -anticlockwise)
        };
        let center = ins.axis + radial * radius;
        [center - direction * ins.half, center + direction * ins.half]
    }

    /// Start and goal of every path, metres ENU.
    pub fn start(&self) -> Point3<f64> {
        self.start
    }

    pub fn goal(&self) -> Point3<f64> {
        self.goal
    }

    /// The decoding box of the free waypoints (x, y, z ranges).
    pub fn decoding_box(&self) -> [[f64; 2]; 3] {
        self.bounds
    }

    /// Waypoints decoded from a particle: 3 angles per waypoint (x, y, z), eq. 1,
    /// into the bounds less the formation's radius (horizontally) and its
    /// vertical half-height (in the altitude band).
    pub fn decode(&self, angles: &[f64]) -> Vec<Point3<f64>> {
        angles[..(3 * self.free).min(angles.len())]
            .chunks_exact(3)
            .map(|c| {
                Point3::new(
                    decode_angle(c[0], self.bounds[0][0], self.bounds[0][1]),
                    decode_angle(c[1], self.bounds[1][0], self.bounds[1][1]),
                    decode_angle(c[2], self.bounds[2][0], self.bounds[2][1]),
                )
            })
            .collect()
    }

    /// The particle that stands for these waypoints (the inverse of eq. 1),
    /// each inspection pass placed at `pass_angles` (radians round the axis).
    pub fn encode(&self, waypoints: &[Point3<f64>], pass_angles: &[f64]) -> Vec<f64> {
        let mut angles = Vec::with_capacity(3 * self.free + self.inspections.len());
        for p in waypoints.iter().take(self.free) {
            for (d, v) in [p.x, p.y, p.z].into_iter().enumerate() {
                angles.push(encode_angle(v, self.bounds[d][0], self.bounds[d][1]));
            }
        }
        for (i, _) in self.inspections.iter().enumerate() {
            let phi = pass_angles.get(i).copied().unwrap_or(0.0);
            let wrapped = (phi + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            angles.push(encode_angle(
                wrapped,
                -std::f64::consts::PI,
                std::f64::consts::PI,
            ));
        }
        angles
    }

    /// start → waypoints → goal with the vias inserted: each IWP crossing
    /// where the path goes through its gap, each inspection pass where it
    /// adds the least length.
    pub fn build(&self, angles: &[f64]) -> CentroidPath {
        let waypoints = self.decode(angles);
        let extra = 3 * self.crossings.len() + 2 * self.inspections.len();
        let mut points = Vec::with_capacity(waypoints.len() + 2 + extra);
        points.push(self.start);
        points.extend_from_slice(&waypoints);
        points.push(self.goal);
        // locked[i]: leg i (points[i] → points[i + 1]) is part of a via's
        // straight and must not be split by another via.
        let mut locked = Vec::with_capacity(points.len() - 1 + extra);
        locked.resize(points.len() - 1, false);
        // Vias placed: (crossing or inspection index, index of its first point).
        let mut crossings: Vec<(usize, usize)> = Vec::with_capacity(self.crossings.len());
        let mut passes: Vec<(usize, usize, bool)> = Vec::with_capacity(self.inspections.len());
        for (i, c) in self.crossings.iter().enumerate() {
            if let Some((leg, triple)) = self.crossing_leg(&points, &locked, c) {
                insert(&mut points, &mut locked, leg, &triple);
                shift(&mut crossings, &mut passes, leg, 3);
                crossings.push((i, leg + 1));
            }
        }
        let free_angles = &angles[(3 * self.free).min(angles.len())..];
        for i in 0..self.inspections.len() {
            let theta = free_angles.get(i).copied().unwrap_or(0.0);
            let phi = decode_angle(theta, -std::f64::consts::PI, std::f64::consts::PI);
            let (leg, pair, on_left) = self.best_pass(&points, &locked, i, phi);
            insert(&mut points, &mut locked, leg, &pair);
            shift(&mut crossings, &mut passes, leg, 2);
            passes.push((i, leg + 1, on_left));
        }

        self.finish(points, &crossings, &passes)
    }

    /// The path of a corridor found by the route stage, as a particle's path
    /// would be built: its points lifted to heights along start → goal (in
    /// each via's band), its crossings and passes as vias.
    pub fn from_corridor(&self, corridor: &super::route::Corridor) -> CentroidPath {
        use super::route::Leg;
        let plane = &corridor.points;
        let total = corridor.length.max(1e-9);
        let mut s = 0.0;
        let mut points = Vec::with_capacity(plane.len() + corridor.legs.len());
        let mut crossings = Vec::new();
        let mut passes = Vec::new();
        let height = |s: f64| {
            let u = s / total;
            (self.start.z + (self.goal.z - self.start.z) * u)
                .clamp(self.bounds[2][0], self.bounds[2][1])
        };
        points.push(self.start);
        for (k, leg) in corridor.legs.iter().enumerate() {
            let (a, b) = (plane[k], plane[k + 1]);
            match *leg {
                Leg::Crossing(c) => {
                    let via = &self.crossings[c];
                    let z = height(s).clamp(via.z_range[0], via.z_range[1]);
                    // The leg into the crossing ends at its first point.
                    if let Some(last) = points.last_mut() {
                        last.z = z;
                    }
                    crossings.push((c, points.len() - 1));
                    points.push(Point3::new(via.center.x, via.center.y, z));
                    points.push(Point3::new(b.x, b.y, z));
                }
                Leg::Pass(i) => {
                    let ins = &self.inspections[i];
                    let z = height(s).clamp(ins.z_range[0], ins.z_range[1]);
                    if let Some(last) = points.last_mut() {
                        last.z = z;
                    }
                    passes.push((i, points.len() - 1, corridor.passes[i].1));
                    points.push(Point3::new(b.x, b.y, z));
                }
                Leg::Free { .. } => {
                    let z = if k + 1 == corridor.legs.len() {
                        self.goal.z
                    } else {
                        height(s + (b - a).norm())
                    };
                    points.push(Point3::new(b.x, b.y, z));
                }
            }
            s += (b - a).norm();
        }
        if let Some(last) = points.last_mut() {
            *last = self.goal;
        }
        self.finish(points, &crossings, &passes)
    }

    /// The path's zones and passes once its points and vias are placed:
    /// `crossings` (crossing index, index of its first point), `passes`
    /// (inspection index, index of its first point, obstacle on the left).
    fn finish(
        &self,
        mut points: Vec<Point3<f64>>,
        crossings: &[(usize, usize)],
        passes: &[(usize, usize, bool)],
    ) -> CentroidPath {
        if let Some(g) = &self.ground {
            for p in &mut points {
                p.z += g.at(p.x, p.y);
            }
        }
        let arcs = cumulative_lengths(&points);
        let total = arcs.last().copied().unwrap_or(0.0);
        let mut zones: Vec<Zone> = crossings
            .iter()
            .filter_map(|&(i, first)| {
                let c = &self.crossings[i];
                let shape = c.shape?;
                let arc = arcs[first + 1];
                Some(Zone {
                    causes: vec![ZoneCause::Iwp {
                        iwp: c.iwp,
                        pair: c.pair,
                    }],
                    shape,
                    arc,
                    hold: [arc - c.hold, arc + c.hold],
                    transition_in: c.transition.min((arc - c.hold).max(0.0)),
                    transition_out: c.transition.min((total - arc - c.hold).max(0.0)),
                    from: None,
                    into: None,
                })
            })
            .collect();
        if let Some(map) = &self.squeeze {
            let squeezes = self.squeeze_zones(map, &points, &arcs, &zones);
            zones.extend(squeezes);
        }
        let zones = if zones.len() > 1 {
            schedule(zones, &self.slots, self.uav_radius)
        } else {
            zones
        };
        let passes = passes
            .iter()
            .map(|&(i, first, on_left)| {
                let ins = &self.inspections[i];
                let lead = ins.half - ins.geometry.pass_length / 2.0;
                Pass {
                    obstacle: ins.obstacle,
                    arcs: [arcs[first] + lead, arcs[first + 1] - lead],
                    on_left,
                }
            })
            .collect();
        CentroidPath {
            points,
            zones,
            passes,
            crossed: crossings
                .iter()
                .map(|&(i, _)| self.crossings[i].iwp)
                .collect(),
        }
    }

    /// Names the obstacles each squeezed stretch of `path` passes between
    /// (where it is narrowest: in its middle), for the plan as reported.
    pub fn name_squeezes(&self, path: &mut CentroidPath) {
        let Some(map) = &self.squeeze else { return };
        let walker = ArcWalker::new(&path.points);
        for zone in &mut path.zones {
            let middle = (zone.hold[0] + zone.hold[1]) / 2.0;
            for cause in &mut zone.causes {
                if let ZoneCause::Squeeze { pair, .. } = cause {
                    *pair = map.sides(walker.at(middle).xy(), walker.heading(middle, 1.0).xy());
                }
            }
        }
    }

    /// A zone for each stretch of the path inside a squeezed region of the
    /// route stage: the shrink at the region's scale, held from
    /// `hold_distance` before the region to `hold_distance` after it.
    ///
    /// A stretch within an IWP's zone ([t1, t4]) is that IWP's: its shape
    /// was chosen (by the operator or as the least change) and checked for
    /// that gap, so the squeeze does not override it.
    fn squeeze_zones(
        &self,
        map: &super::route::SqueezeMap,
        points: &[Point3<f64>],
        arcs: &[f64],
        crossings: &[Zone],
    ) -> Vec<Zone> {
        let total = arcs.last().copied().unwrap_or(0.0);
        let step = map.resolution();
        // (region, shape, first s, last s)
        let mut runs: Vec<(u16, Shape, f64, f64)> = Vec::new();
        let mut current: Option<(u16, Shape, f64, f64)> = None;
        // The last sample looked up outside the regions, and how far along
        // the path from it none can be (a straight or a polyline from it
        // is at least as long as the distance it covers).
        let mut clear_until = f64::NEG_INFINITY;
        for (i, w) in points.windows(2).enumerate() {
            let (a, b) = (w[0].xy(), w[1].xy());
            let length = arcs[i + 1] - arcs[i];
            let n = ((length / step).ceil() as usize).max(1);
            for k in 0..=n {
                let u = k as f64 / n as f64;
                let s = arcs[i] + length * u;
                if s < clear_until {
                    continue; // outside every region, as the last sample
                }
                let (hit, room) = map.at_with_room(a + (b - a) * u);
                if hit.is_none() && room > 0.0 {
                    clear_until = s + room;
                }
                match (hit, current.as_mut()) {
                    (Some((r, _)), Some(run)) if run.0 == r => run.3 = s,
                    (hit, _) => {
                        if let Some(run) = current.take() {
                            runs.push(run);
                        }
                        current = hit.map(|(r, shape)| (r, shape, s, s));
                    }
                }
            }
        }
        runs.extend(current);
        let within_a_crossing = |first: f64, last: f64| {
            crossings.iter().any(|z| {
                let [t1, _, _, t4] = z.arcs();
                t1 <= first && last <= t4
            })
        };
        runs.into_iter()
            .filter(|&(_, _, first, last)| !within_a_crossing(first, last))
            .map(|(region, shape, first, last)| {
                // A column is complete before its first UAV enters and held
                // until its last has left.
                let half = match shape {
                    Shape::Alignment { spacing } => (0..self.slots.len())
                        .map(|n| super::iwp::column_place(&self.slots, n, spacing).abs())
                        .fold(0.0, f64::max),
                    _ => 0.0,
                };
                let hold = [
                    (first - self.hold_distance - half).max(0.0),
                    (last + self.hold_distance + half).min(total),
                ];
                let middle = (first + last) / 2.0;
                Zone {
                    // Named only for the plan kept (`name_squeezes`): the
                    // swarm does not need the names.
                    causes: vec![ZoneCause::Squeeze {
                        region,
                        pair: [usize::MAX; 2],
                    }],
                    shape,
                    arc: middle,
                    hold,
                    transition_in: self.transition.min(hold[0]),
                    transition_out: self.transition.min(total - hold[1]),
                    from: None,
                    into: None,
                }
            })
            .collect()
    }

    /// The first free leg that goes through the IWP's gap (the gap line,
    /// widened by the formation's safe radius into the obstacles on either
    /// side, so a path that clips the gap's edge is taken through its middle),
    /// and the via triple in that leg's direction of travel.
    fn crossing_leg(
        &self,
        points: &[Point3<f64>],
        locked: &[bool],
        via: &Crossing,
    ) -> Option<(usize, [Point3<f64>; 3])> {
        let along = Vector2::new(via.reach.y, -via.reach.x);
        let across = along * (via.gate / along.norm().max(1e-12));
        let (g0, g1) = (via.center - across, via.center + across);
        points.windows(2).enumerate().find_map(|(i, leg)| {
            let (a, b) = (leg[0], leg[1]);
            if locked[i] || !segments_cross(&a.xy(), &b.xy(), &g0, &g1) {
                return None;
            }
            let z = ((a.z + b.z) / 2.0).clamp(via.z_range[0], via.z_range[1]);
            let sign = if (b.xy() - a.xy()).dot(&via.reach) >= 0.0 {
                1.0
            } else {
                -1.0
            };
            let reach = via.reach * sign;
            Some((
                i,
                [
                    Point3::new(via.center.x - reach.x, via.center.y - reach.y, z),
                    Point3::new(via.center.x, via.center.y, z),
                    Point3::new(via.center.x + reach.x, via.center.y + reach.y, z),
                ],
            ))
        })
    }

    /// The leg, the pass's two ends and its side (obstacle on the left) that
    /// add the least length for inspection `i`'s pass at angle `phi`.
    fn best_pass(
        &self,
        points: &[Point3<f64>],
        locked: &[bool],
        i: usize,
        phi: f64,
    ) -> (usize, [Point3<f64>; 2], bool) {
        let ins = &self.inspections[i];
        let sides = [true, false].map(|on_left| (on_left, self.pass_ends(i, phi, on_left)));
        let mut best = (0, [Point3::origin(); 2], true, f64::INFINITY);
        for (leg_index, leg) in points.windows(2).enumerate() {
            if locked[leg_index] {
                continue;
            }
            let (a, b) = (leg[0], leg[1]);
            let z = ((a.z + b.z) / 2.0).clamp(ins.z_range[0], ins.z_range[1]);
            for (on_left, [p, q]) in sides {
                let first = Point3::new(p.x, p.y, z);
                let last = Point3::new(q.x, q.y, z);
                let added =
                    (first - a).norm() + (last - first).norm() + (b - last).norm() - (b - a).norm();
                if added < best.3 {
                    best = (leg_index, [first, last], on_left, added);
                }
            }
        }
        (best.0, best.1, best.2)
    }
}

/// Puts `via` into leg `leg` (after its first point), locking the via's own legs.
fn insert(points: &mut Vec<Point3<f64>>, locked: &mut Vec<bool>, leg: usize, via: &[Point3<f64>]) {
    let k = via.len();
    // Cheaper than `splice`, which allocates.
    points.extend_from_slice(via);
    points[leg + 1..].rotate_right(k);
    // Leg `leg` becomes k + 1 legs: the approach, the via's own k − 1, the exit.
    locked.extend(std::iter::repeat_n(true, k));
    locked[leg + 1..].rotate_right(k);
    locked[leg] = false;
    locked[leg + k] = false;
}

/// Indices of vias placed after leg `leg` move by the `k` points inserted there.
fn shift(
    crossings: &mut [(usize, usize)],
    passes: &mut [(usize, usize, bool)],
    leg: usize,
    k: usize,
) {
    for (_, first) in crossings.iter_mut() {
        if *first > leg {
            *first += k;
        }
    }
    for (_, first, _) in passes.iter_mut() {
        if *first > leg {
            *first += k;
        }
    }
}

/// Whether the plane segments a-b and c-d intersect (touching counts).
fn segments_cross(a: &Point2<f64>, b: &Point2<f64>, c: &Point2<f64>, d: &Point2<f64>) -> bool {
    let orient = |p: &Point2<f64>, q: &Point2<f64>, r: &Point2<f64>| (q - p).perp(&(r - p));
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    d1 * d2 <= 0.0 && d3 * d4 <= 0.0 && !(d1 == 0.0 && d2 == 0.0 && d3 == 0.0 && d4 == 0.0)
}

/// s at each vertex: 0 at the first, the total length at the last.
pub fn cumulative_lengths(points: &[Point3<f64>]) -> Vec<f64> {
    let mut s = 0.0;
    let mut out = Vec::with_capacity(points.len());
    out.push(0.0);
    for w in points.windows(2) {
        s += (w[1] - w[0]).norm();
        out.push(s);
    }
    out
}

/// A point moving along a polyline by arc length.
pub struct ArcWalker<'a> {
    points: &'a [Point3<f64>],
    arcs: Vec<f64>,
}

impl<'a> ArcWalker<'a> {
    pub fn new(points: &'a [Point3<f64>]) -> Self {
        ArcWalker {
            arcs: cumulative_lengths(points),
            points,
        }
    }

    pub fn length(&self) -> f64 {
        self.arcs.last().copied().unwrap_or(0.0)
    }

    /// Arc length of every vertex.
    pub fn arcs(&self) -> &[f64] {
        &self.arcs
    }

    pub fn points(&self) -> &[Point3<f64>] {
        self.points
    }

    /// Position at arc length `s` (clamped to the path).
    pub fn at(&self, s: f64) -> Point3<f64> {
        let n = self.points.len();
        if n == 0 {
            return Point3::origin();
        }
        if n == 1 {
            return self.points[0];
        }
        let s = s.clamp(0.0, self.length());
        let i = self.arcs.partition_point(|&a| a <= s).clamp(1, n - 1);
        let (a, b) = (self.points[i - 1], self.points[i]);
        let len = self.arcs[i] - self.arcs[i - 1];
        if len <= 0.0 {
            return b;
        }
        a + (b - a) * ((s - self.arcs[i - 1]) / len)
    }

    /// Position at arc length `s`, continued straight beyond either end
    /// along the first or the last leg (where a column's first and last UAVs
    /// are while the centroid is near the start or the goal).
    pub fn at_extended(&self, s: f64) -> Point3<f64> {
        let length = self.length();
        let n = self.points.len();
        if n < 2 || (0.0..=length).contains(&s) {
            return self.at(s);
        }
        let (from, to, beyond) = if s < 0.0 {
            (self.points[1], self.points[0], -s)
        } else {
            (self.points[n - 2], self.points[n - 1], s - length)
        };
        // The nearest leg with a direction (legs of zero length are skipped).
        let direction = {
            let d = to - from;
            if d.norm() > 1e-9 {
                d / d.norm()
            } else {
                let whole = if s < 0.0 {
                    self.points[0] - self.at(length.min(1.0))
                } else {
                    self.points[n - 1] - self.at((length - 1.0).max(0.0))
                };
                if whole.norm() > 1e-9 {
                    whole / whole.norm()
                } else {
                    Vector3::x()
                }
            }
        };
        to + direction * beyond
    }

    /// Unit horizontal direction of travel around `s`, from the chord between
    /// s − span and s + span: continuous in s, so the formation frame turns
    /// smoothly through the path's corners instead of snapping.
    pub fn heading(&self, s: f64, span: f64) -> Vector3<f64> {
        let ahead = self.at(s + span);
        let behind = self.at(s - span);
        let d = Vector3::new(ahead.x - behind.x, ahead.y - behind.y, 0.0);
        if d.norm() > 1e-9 {
            d.normalize()
        } else {
            let whole = self.at(self.length()) - self.at(0.0);
            let flat = Vector3::new(whole.x, whole.y, 0.0);
            if flat.norm() > 1e-9 {
                flat.normalize()
            } else {
                Vector3::x()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's triangle (Fig. 2's formation), r_Q = 0.5 m.
    fn triangle() -> Vec<Vector3<f64>> {
        vec![
            Vector3::new(2.0, 0.0, 0.0),
            Vector3::new(-1.0, 2.0, 0.0),
            Vector3::new(-1.0, -2.0, 0.0),
        ]
    }

    fn zone(iwp: usize, shape: Shape, hold: [f64; 2], transition: f64) -> Zone {
        Zone {
            causes: vec![ZoneCause::Iwp {
                iwp,
                pair: [2 * iwp, 2 * iwp + 1],
            }],
            shape,
            arc: (hold[0] + hold[1]) / 2.0,
            hold,
            transition_in: transition,
            transition_out: transition,
            from: None,
            into: None,
        }
    }

    const HALF: Shape = Shape::Shrink { scale: 0.5 };
    const COLUMN: Shape = Shape::Alignment { spacing: 2.0 };

    /// Eq. 9 / Fig. 2 read for one IWP: room for both changes between two
    /// zones, and each returns to the nominal shape on its own.
    #[test]
    fn zones_with_room_between_them_each_return_to_the_nominal_shape() {
        let zones = vec![
            zone(1, Shape::Rotation, [60.0, 64.0], 5.0),
            zone(0, HALF, [20.0, 24.0], 5.0),
        ];
        let out = schedule(zones, &triangle(), 0.5);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].shape, HALF, "sorted along the path");
        assert!(out.iter().all(|z| z.from.is_none() && z.into.is_none()));
        assert_eq!(out[0].transition_out, 5.0);
    }

    /// Two rigid shapes closer than their changes need, but at least
    /// `MIN_BLEND` apart: the change out of the first ends in the second,
    /// over the whole stretch between the holds, and the shape is continuous
    /// there (no return to the nominal shape between them).
    #[test]
    fn close_zones_blend_straight_from_one_shape_into_the_next() {
        let slots = triangle();
        let zones = vec![
            zone(0, HALF, [20.0, 24.0], 5.0),
            zone(1, Shape::Rotation, [28.0, 32.0], 5.0),
        ];
        let out = schedule(zones, &slots, 0.5);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].into, Some(Shape::Rotation));
        assert_eq!(out[1].from, Some(HALF));
        assert_eq!(out[0].transition_out, 4.0);
        assert_eq!(out[1].transition_in, 4.0);
        // One change, seen from both zones: the first's change out is the
        // second's change in, [24, 28].
        assert_eq!(out[0].arcs()[2..], out[1].arcs()[..2]);
        // Halfway between the holds the formation is halfway from one
        // shape to the other.
        let (Some(a), Some(b)) = (out[0].state(26.0), out[1].state(26.0)) else {
            panic!("both zones cover the stretch between their holds");
        };
        for n in 0..slots.len() {
            let mid = HALF
                .offset(&slots, n, 1.0)
                .lerp(&Shape::Rotation.offset(&slots, n, 1.0), 0.5);
            assert!((a.offset(&slots, n) - mid).norm() < 1e-12);
            assert!((b.offset(&slots, n) - mid).norm() < 1e-12);
        }
        // Never the nominal shape in between.
        for s in [24.5, 25.0, 27.0, 27.5] {
            let state = out[0].state(s).or(out[1].state(s));
            assert!(state.is_some_and(|st| st.from.is_some() && st.to.is_some()));
        }
    }

    /// Closer than `MIN_BLEND` (here the holds overlap): one hold over both
    /// in the narrower shape, which fits both gaps, with both causes kept.
    #[test]
    fn overlapping_zones_become_one_hold_in_the_narrower_shape() {
        let zones = vec![
            zone(0, Shape::Shrink { scale: 0.8 }, [20.0, 24.0], 5.0),
            zone(1, HALF, [23.0, 27.0], 5.0),
        ];
        let out = schedule(zones, &triangle(), 0.5);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].shape, HALF);
        assert_eq!(out[0].hold, [20.0, 27.0]);
        assert_eq!(out[0].causes.len(), 2);
        assert!(out[0].from.is_none() && out[0].into.is_none());
    }

    /// The column never blends with a spread shape (a straight blend can
    /// bring two UAVs closer than either shape): even with room for a blend
    /// the two holds join, in the column.
    #[test]
    fn a_column_takes_over_a_close_neighbour() {
        let zones = vec![
            zone(0, HALF, [20.0, 24.0], 5.0),
            zone(1, COLUMN, [28.0, 32.0], 5.0),
        ];
        let out = schedule(zones, &triangle(), 0.5);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].shape, COLUMN);
        assert_eq!(out[0].hold, [20.0, 32.0]);
    }

    /// Three in a row: the second and third join, and the first, which
    /// blended into the second's shape, now blends into the joined hold's.
    #[test]
    fn a_join_updates_the_blend_of_the_zone_before() {
        let zones = vec![
            zone(0, Shape::Rotation, [10.0, 14.0], 5.0),
            zone(1, Shape::Shrink { scale: 0.8 }, [18.0, 22.0], 5.0),
            zone(2, HALF, [22.5, 26.0], 5.0),
        ];
        let out = schedule(zones, &triangle(), 0.5);
        assert_eq!(out.len(), 2);
        assert_eq!(out[1].shape, HALF);
        assert_eq!(out[1].hold, [18.0, 26.0]);
        assert_eq!(out[0].into, Some(HALF));
        assert_eq!(out[1].from, Some(Shape::Rotation));
    }
}
