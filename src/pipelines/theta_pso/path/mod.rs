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
//! swarm still decides the route between them. The user's own vias
//! (`[[route.via]]`: a gate between two obstacles, crossed straight as an
//! IWP is; a point) come first, in their order: each goes into the leg
//! after the one before where it adds the least length, so every path
//! keeps them all, in order.
//!
//! Long (~950 lines) because it is the one `PathBuilder`: the decoding of a particle
//! (eq. 1), the crossings, inspections and the user's vias it prepares once, and their
//! insertion as via-points into the legs they lengthen least (in order for the user's); the rounding, the squeeze, the walker and
//! the zones are already submodules.

use nalgebra::{Point2, Point3, Vector2, Vector3};

use super::inspection::PassGeometry;
use super::iwp::{Iwp, Shape, lateral_half_width, vertical_half_height};
pub use crate::base::swarm::{decode_angle, encode_angle};
use crate::mission::Mission;

pub mod rounding;
mod squeeze;
mod walker;
mod zone;

pub use squeeze::SqueezeMap;
pub use walker::{ArcWalker, Hint, cumulative_lengths};
pub use zone::{MIN_BLEND, ShapeState, Zone, ZoneCause, schedule};

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

/// A particle's points with its vias placed, before the zones are worked
/// out (`PathBuilder::place`, then `PathBuilder::finish`).
#[derive(Debug, Clone, PartialEq)]
pub struct Placed {
    pub points: Vec<Point3<f64>>,
    /// (crossing index, index of its first point).
    crossings: Vec<(usize, usize)>,
    /// (inspection index, index of its first point, obstacle on the left).
    passes: Vec<(usize, usize, bool)>,
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
    squeeze: Option<std::sync::Arc<SqueezeMap>>,
    /// The user's vias, in their order.
    vias: Vec<UserVia>,
}

/// One of the user's `[[route.via]]`, as the builder places it.
#[derive(Debug, Clone, Copy)]
enum UserVia {
    /// Crossing `c` (a gate the user named).
    Gate(usize),
    /// A point the centroid passes.
    Point(Point3<f64>),
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
    /// The gap's width, metres.
    gap: f64,
    /// Left to `auto` (no choice of the user's for it): a squeeze may carry
    /// the formation through instead.
    auto: bool,
    /// A gate the user named (`[[route.via]]`, its index): always placed.
    user_gate: Option<usize>,
    hold: f64,
    transition: f64,
    /// Altitudes the centroid may take at the IWP so every UAV of the shape
    /// stays in the band.
    z_range: [f64; 2],
    /// Altitudes at which both obstacles stand in the way (`Iwp::window`):
    /// a leg crossing the gate outside them flies over or under the gap.
    window: [f64; 2],
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
    /// A footprint's outline, anticlockwise: its pass runs along a face.
    face: Option<std::sync::Arc<[Point2<f64>]>>,
    /// The side to inspect (`inspect_side`): the outward normal of the face
    /// the pass must look at; any side when `None`.
    side: Option<Vector2<f64>>,
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
                    gap: iwp.gap,
                    auto: iwp.choice == crate::mission::ShapeChoice::Auto
                        && mission
                            .reconfiguration
                            .choice(&iwp.between[0], &iwp.between[1])
                            .is_none(),
                    user_gate: iwp.gate,
                    hold,
                    transition: mission.reconfiguration.transition_distance,
                    z_range: band_for(half_height),
                    window: iwp.window,
                }
            })
            .collect::<Vec<Crossing>>();
        let vias = mission
            .route
            .via
            .iter()
            .enumerate()
            .filter_map(|(i, v)| match v.point {
                Some(p) => Some(UserVia::Point(p)),
                None => crossings
                    .iter()
                    .position(|c| c.user_gate == Some(i))
                    .map(UserVia::Gate),
            })
            .collect();
        let inspections = passes
            .iter()
            .map(|&(k, geometry)| Inspection {
                obstacle: k,
                axis: mission.obstacles[k].center,
                geometry,
                half: mission.formation.inspection_pass / 2.0 + span,
                // Level with the side (`check` refuses an obstacle no
                // altitude of the band is level with).
                z_range: mission
                    .inspection_altitudes(&mission.obstacles[k])
                    .unwrap_or_else(|| band_for(vertical_half_height(nominal))),
                face: anticlockwise(mission.obstacles[k].outline().corners()),
                side: mission.obstacles[k]
                    .inspect_side
                    .as_ref()
                    .and_then(|s| s.normal()),
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
            uav_radius: f.least_clearance(),
            hold_distance: mission.reconfiguration.hold_distance,
            transition: mission.reconfiguration.transition_distance,
            squeeze: None,
            vias,
        }
    }

    /// The user's via points, in their order among the vias: (index among
    /// the vias, the point).
    pub fn via_points(&self) -> Vec<(usize, Point3<f64>)> {
        self.vias
            .iter()
            .enumerate()
            .filter_map(|(k, v)| match v {
                UserVia::Point(p) => Some((k, *p)),
                UserVia::Gate(_) => None,
            })
            .collect()
    }

    /// The crossing of each gate among the user's vias, in their order:
    /// (index among the vias, crossing index).
    pub fn via_gates(&self) -> Vec<(usize, usize)> {
        self.vias
            .iter()
            .enumerate()
            .filter_map(|(k, v)| match v {
                UserVia::Gate(c) => Some((k, *c)),
                UserVia::Point(_) => None,
            })
            .collect()
    }

    /// Widens the decoding box (within the bounds `b`) to hold every point
    /// of `route`: a corridor squeezed in single file between an obstacle
    /// and the bounds runs closer to them than r_F (the column's UAVs
    /// follow the path), where a box shrunk by r_F could never decode a
    /// waypoint (issue 51: an aisle against the bounds).
    pub fn widen_to(&mut self, b: &crate::mission::Bounds, route: &[Point2<f64>]) {
        for (d, range) in [b.x, b.y].into_iter().enumerate() {
            for p in route {
                let v = if d == 0 { p.x } else { p.y };
                self.bounds[d][0] = self.bounds[d][0].min(v).max(range[0]);
                self.bounds[d][1] = self.bounds[d][1].max(v).min(range[1]);
            }
        }
    }

    /// Paths of this builder fly squeezed through `map`'s regions.
    pub fn set_squeeze(&mut self, map: Option<std::sync::Arc<SqueezeMap>>) {
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

    /// Whether crossings `a` and `b` overlap: `b`'s gap is within `a`'s
    /// straight's reach along it and within `a`'s gate across it.
    pub fn crossings_overlap(&self, a: usize, b: usize) -> bool {
        let (x, y) = (&self.crossings[a], &self.crossings[b]);
        let reach = x.reach.norm();
        let n = x.reach / reach.max(1e-12);
        let d = y.center - x.center;
        let along = d.dot(&n).abs();
        let across = (d.x * n.y - d.y * n.x).abs();
        along < reach + y.reach.norm() && across < x.gate
    }

    /// Each crossing's gate: the gap line widened by the formation's safe
    /// radius into the obstacles on either side. A leg across it is taken
    /// through the crossing (`crossing_leg`).
    pub fn crossing_gates(&self) -> Vec<[Point2<f64>; 2]> {
        self.crossings
            .iter()
            .map(|via| {
                let along = Vector2::new(via.reach.y, -via.reach.x);
                let across = along * (via.gate / along.norm().max(1e-12));
                [via.center - across, via.center + across]
            })
            .collect()
    }

    /// The altitudes at which each crossing's gap stands in the way (the
    /// crossing is flown only there).
    pub fn crossing_windows(&self) -> Vec<[f64; 2]> {
        self.crossings.iter().map(|c| c.window).collect()
    }

    /// The centroid altitudes each inspection's pass may be flown at
    /// (level with the side, in the band).
    pub fn pass_altitudes(&self) -> Vec<[f64; 2]> {
        self.inspections.iter().map(|i| i.z_range).collect()
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
        let radius = if on_left {
            ins.geometry.radius_left
        } else {
            ins.geometry.radius_right
        };
        if let Some(outline) = &ins.face {
            let (edge, at) = match ins.side {
                // On the chosen face, `phi` places the pass along it.
                Some(normal) => {
                    let i = crate::base::geometry::facing_edge(outline, normal);
                    let n = outline.len();
                    let length = (outline[(i + 1) % n] - outline[i]).norm();
                    (
                        i,
                        (phi + std::f64::consts::PI) / std::f64::consts::TAU * length,
                    )
                }
                None => perimeter_place(outline, phi),
            };
            return face_pass(
                outline,
                edge,
                at,
                radius,
                ins.geometry.pass_length,
                ins.half,
                on_left,
            );
        }
        // A cylinder's chosen side fixes the pass's angle round the axis.
        let phi = ins.side.map_or(phi, |n| n.y.atan2(n.x));
        let (sin, cos) = phi.sin_cos();
        let radial = Vector2::new(cos, sin);
        // Anticlockwise round the axis: the obstacle is on the left.
        let anticlockwise = Vector2::new(-sin, cos);
        let direction = if on_left {
            anticlockwise
        } else {
            -anticlockwise
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

    /// The pass angles of a particle, decoded (radians round each
    /// inspected obstacle's axis, in [-π, π]).
    pub fn pass_angles(&self, angles: &[f64]) -> Vec<f64> {
        let free_angles = &angles[(3 * self.free).min(angles.len())..];
        (0..self.inspections.len())
            .map(|i| {
                let theta = free_angles.get(i).copied().unwrap_or(0.0);
                decode_angle(theta, -std::f64::consts::PI, std::f64::consts::PI)
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
        self.finish(self.place(angles))
    }

    /// A particle's points with its vias placed, lifted onto the terrain:
    /// all that J1, J_R and J_T read. The zones (`finish`) cost more to
    /// work out, so the swarm first checks these terms against its bound.
    pub fn place(&self, angles: &[f64]) -> Placed {
        let waypoints = self.decode(angles);
        let extra = 3 * self.crossings.len() + 2 * self.inspections.len() + self.vias.len();
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
        // The user's vias first, in order: each into a leg after the last.
        let mut floor = 0;
        for via in &self.vias {
            match *via {
                UserVia::Gate(i) => {
                    let c = &self.crossings[i];
                    let Some((leg, triple)) = self.gate_leg(&points, &locked, c, floor) else {
                        continue;
                    };
                    insert(&mut points, &mut locked, leg, &triple);
                    shift(&mut crossings, &mut passes, leg, 3);
                    crossings.push((i, leg + 1));
                    floor = leg + 3;
                }
                UserVia::Point(p) => {
                    let Some(leg) = cheapest_leg(&points, &locked, floor, |a, b| {
                        (p - a).norm() + (b - p).norm() - (b - a).norm()
                    }) else {
                        continue;
                    };
                    insert(&mut points, &mut locked, leg, &[p]);
                    shift(&mut crossings, &mut passes, leg, 1);
                    floor = leg + 1;
                }
            }
        }
        for (i, c) in self.crossings.iter().enumerate() {
            if c.user_gate.is_some() {
                continue;
            }
            // A gap whose crossing would overlap one already placed (the
            // next post pair along a lane, the gap beside it in the same
            // wall) is passed within that one's straight: flying both in
            // turn would double back.
            if crossings.iter().any(|&(j, _)| self.crossings_overlap(j, i)) {
                continue;
            }
            if let Some((leg, triple, [snap_a, snap_b])) = self.crossing_leg(&points, &locked, c) {
                // A free waypoint standing on the straight is taken to its
                // end, so the path does not double back over it.
                if snap_a {
                    points[leg] = triple[0];
                }
                if snap_b {
                    points[leg + 1] = triple[2];
                }
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
        if let Some(g) = &self.ground {
            for p in &mut points {
                p.z += g.at(p.x, p.y);
            }
        }
        Placed {
            points,
            crossings,
            passes,
        }
    }

    /// The path's zones and passes once its points and vias are placed.
    pub fn finish(&self, placed: Placed) -> CentroidPath {
        let Placed {
            points,
            crossings,
            passes,
        } = placed;
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

    /// The first free leg that goes through the IWP's gap (the gap line,
    /// widened by the formation's safe radius into the obstacles on either
    /// side, so a path that clips the gap's edge is taken through its middle),
    /// and the via triple in that leg's direction of travel.
    fn crossing_leg(
        &self,
        points: &[Point3<f64>],
        locked: &[bool],
        via: &Crossing,
    ) -> Option<(usize, [Point3<f64>; 3], [bool; 2])> {
        let along = Vector2::new(via.reach.y, -via.reach.x);
        let across = along * (via.gate / along.norm().max(1e-12));
        let (g0, g1) = (via.center - across, via.center + across);
        points.windows(2).enumerate().find_map(|(i, leg)| {
            let (a, b) = (leg[0], leg[1]);
            if locked[i] || !crate::base::geometry::segments_cross(&a.xy(), &b.xy(), &g0, &g1) {
                return None;
            }
            // Over (or under) the gap's obstacles the leg needs no crossing.
            let there = altitude_along(a, b, via.center);
            if !(via.window[0] < there && there < via.window[1]) {
                return None;
            }

            let sign = if (b.xy() - a.xy()).dot(&via.reach) >= 0.0 {
                1.0
            } else {
                -1.0
            };
            let reach = via.reach * sign;
            // A leg that starts (or ends) on the crossing's straight, more
            // than a metre past its end, would be flown doubling back over
            // it: a free waypoint there is taken to the straight's end; a
            // fixed point (the start, the goal, a via's end) leaves the gap
            // to be passed as the leg flies it (and the cost judges that).
            let half = reach.norm();
            let unit = reach / half.max(1e-12);
            let back_a = (a.xy() - via.center).dot(&unit) + half;
            let back_b = half - (b.xy() - via.center).dot(&unit);
            let movable = |j: usize| j > 0 && j + 1 < points.len() && !locked[j - 1] && !locked[j];
            let snap = [back_a > DOUBLING_BACK, back_b > DOUBLING_BACK];
            if (snap[0] && !movable(i)) || (snap[1] && !movable(i + 1)) {
                return None;
            }
            // Unless, on an IWP left to `auto`, the leg runs through a
            // squeezed stretch (a lane between walls, an aisle) in a shape
            // that already fits the gap: the squeeze carries it through, no
            // crossing needed.
            if (snap[0] || snap[1])
                && via.auto
                && let Some(map) = &self.squeeze
            {
                let at = crate::base::geometry::segment_projection(&a.xy(), &b.xy(), &via.center).0;
                let through = a.xy() + (b.xy() - a.xy()) * at;
                if let Some((_, shape)) = map.at(through)
                    && lateral_half_width(&shape.offsets(&self.slots, 1.0), self.uav_radius)
                        <= via.gap / 2.0
                {
                    return None;
                }
            }
            // Its ends at the leg's altitude where they lie (in the band the
            // shape allows there), so no step up or down joins the crossing
            // to the leg, and straight between them.
            let height =
                |p: Point2<f64>| altitude_along(a, b, p).clamp(via.z_range[0], via.z_range[1]);
            let (enter, leave) = (via.center - reach, via.center + reach);
            let (z0, z1) = (height(enter), height(leave));
            Some((
                i,
                [
                    Point3::new(enter.x, enter.y, z0),
                    Point3::new(via.center.x, via.center.y, (z0 + z1) / 2.0),
                    Point3::new(leave.x, leave.y, z1),
                ],
                snap,
            ))
        })
    }

    /// Where a gate's crossing goes: the first free leg from `floor` on
    /// that crosses it (as `crossing_leg` takes an IWP), else the free leg
    /// from `floor` on where its straight adds the least length, flown in
    /// that leg's direction.
    fn gate_leg(
        &self,
        points: &[Point3<f64>],
        locked: &[bool],
        via: &Crossing,
        floor: usize,
    ) -> Option<(usize, [Point3<f64>; 3])> {
        let mut free = locked.to_vec();
        for l in free.iter_mut().take(floor.min(locked.len())) {
            *l = true;
        }
        if let Some((leg, triple, _)) = self.crossing_leg(points, &free, via) {
            return Some((leg, triple));
        }
        let triple_for = |a: Point3<f64>, b: Point3<f64>| {
            let sign = if (b.xy() - a.xy()).dot(&via.reach) >= 0.0 {
                1.0
            } else {
                -1.0
            };
            let reach = via.reach * sign;
            let height =
                |p: Point2<f64>| altitude_along(a, b, p).clamp(via.z_range[0], via.z_range[1]);
            let (enter, leave) = (via.center - reach, via.center + reach);
            let (z0, z1) = (height(enter), height(leave));
            [
                Point3::new(enter.x, enter.y, z0),
                Point3::new(via.center.x, via.center.y, (z0 + z1) / 2.0),
                Point3::new(leave.x, leave.y, z1),
            ]
        };
        let leg = cheapest_leg(points, locked, floor, |a, b| {
            let [t0, _, t2] = triple_for(a, b);
            (t0 - a).norm() + (t2 - t0).norm() + (b - t2).norm() - (b - a).norm()
        })?;
        Some((leg, triple_for(points[leg], points[leg + 1])))
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
            for (on_left, [p, q]) in sides {
                // At the leg's altitude where each end lies, in the pass's band.
                let at = |p: Point2<f64>| {
                    let z = altitude_along(a, b, p).clamp(ins.z_range[0], ins.z_range[1]);
                    Point3::new(p.x, p.y, z)
                };
                let (first, last) = (at(p), at(q));
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

/// The free leg from `floor` on for which `added` (of its two ends) is
/// least; `None` when every such leg is locked.
fn cheapest_leg(
    points: &[Point3<f64>],
    locked: &[bool],
    floor: usize,
    added: impl Fn(Point3<f64>, Point3<f64>) -> f64,
) -> Option<usize> {
    points
        .windows(2)
        .enumerate()
        .skip(floor)
        .filter(|(i, _)| !locked[*i])
        .map(|(i, w)| (i, added(w[0], w[1])))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// How far (metres) a leg may start past a crossing's entry (or end short
/// of its exit) and still be flown through it.
const DOUBLING_BACK: f64 = 1.0;

/// The altitude of the leg `a` → `b` where `p` projects onto it in the plane.
fn altitude_along(a: Point3<f64>, b: Point3<f64>, p: Point2<f64>) -> f64 {
    let t = crate::base::geometry::segment_projection(&a.xy(), &b.xy(), &p).0;
    a.z + (b.z - a.z) * t
}

/// A footprint's vertices anticlockwise (`None` for a cylinder).
fn anticlockwise(outline: &[Point2<f64>]) -> Option<std::sync::Arc<[Point2<f64>]>> {
    (outline.len() >= 3).then(|| crate::base::geometry::anticlockwise(outline).into())
}

/// The ends of a pass along edge `i` of the anticlockwise `outline`,
/// centred `at` metres along it (kept on the face as far as the pass's
/// length allows), its line `radius` out from the face, `half` either way,
/// the footprint on the formation's left or right.
fn face_pass(
    outline: &[Point2<f64>],
    i: usize,
    at: f64,
    radius: f64,
    pass: f64,
    half: f64,
    on_left: bool,
) -> [Point2<f64>; 2] {
    let n = outline.len();
    let (a, b) = (outline[i], outline[(i + 1) % n]);
    let length = (b - a).norm().max(1e-12);
    let along = (b - a) / length;
    // Anticlockwise: the outside is on the edge's right.
    let outward = Vector2::new(along.y, -along.x);
    let room = (pass / 2.0).min(length / 2.0);
    let centre = a + along * at.clamp(room, length - room) + outward * radius;
    // Along the edge the footprint is on the left.
    let direction = if on_left { along } else { -along };
    [centre - direction * half, centre + direction * half]
}

/// Where `phi` (radians in [-π, π]) falls on the anticlockwise `outline`'s
/// perimeter: the edge and the distance along it.
fn perimeter_place(outline: &[Point2<f64>], phi: f64) -> (usize, f64) {
    let n = outline.len();
    let edge = |i: usize| (outline[i], outline[(i + 1) % n]);
    let perimeter: f64 = (0..n).map(|i| (edge(i).1 - edge(i).0).norm()).sum();
    let mut at = ((phi + std::f64::consts::PI) / std::f64::consts::TAU).clamp(0.0, 1.0) * perimeter;
    let mut i = 0;
    while i + 1 < n && at > (edge(i).1 - edge(i).0).norm() {
        at -= (edge(i).1 - edge(i).0).norm();
        i += 1;
    }
    (i, at)
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

#[cfg(test)]
mod tests;
