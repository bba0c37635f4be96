//! Intermediate waypoints (θ-PSO eq. 9) and the shape the formation takes there.
//!
//! Reading of eq. 9: for two obstacles p, q the gap d_pq is the distance
//! between their circles along the line C_p C_q (centre distance minus both
//! radii). An IWP sits at the midpoint of that gap when the gap is at least
//! one UAV wide (2 r_Q) but narrower than the formation (2 (r_F + r_Q)):
//! one UAV fits, the nominal formation does not. Two refinements a flight
//! engineer needs and the paper leaves implicit:
//! - a gap blocked by a third obstacle (the segment P_p P_q passes within
//!   r_Q of it) is not a passage and gets no IWP;
//! - both obstacles must reach into the altitude band; over a lower one the
//!   formation can simply fly.

use nalgebra::{Point2, Vector2, Vector3};
use serde::Serialize;

use crate::geometry::segment_point_distance;
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
    /// The shape used, resolved from the choice.
    pub shape: Shape,
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
        let mut out = Vec::with_capacity(nominal.len());
        self.offsets_into(nominal, blend, &mut out);
        out
    }

    /// As `offsets`, into a reused buffer.
    pub fn offsets_into(&self, nominal: &[Vector3<f64>], blend: f64, out: &mut Vec<Vector3<f64>>) {
        out.clear();
        match *self {
            Shape::Alignment { spacing } => {
                let order = column_order(nominal);
                let n = nominal.len();
                out.extend(nominal.iter().copied());
                for (rank, &slot) in order.iter().enumerate() {
                    let x = (rank as f64 - (n as f64 - 1.0) / 2.0) * spacing;
                    let target = Vector3::new(x, 0.0, 0.0);
                    out[slot] = nominal[slot].lerp(&target, blend);
                }
            }
            Shape::Rotation => {
                let angle = blend * std::f64::consts::FRAC_PI_2;
                let (s, c) = angle.sin_cos();
                // R_y(angle): x' = c x + s z, z' = -s x + c z.
                out.extend(
                    nominal
                        .iter()
                        .map(|o| Vector3::new(c * o.x + s * o.z, o.y, -s * o.x + c * o.z)),
                );
            }
            Shape::Shrink { scale } => {
                let k = 1.0 - blend * (1.0 - scale);
                out.extend(nominal.iter().map(|o| o * k));
            }
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

/// Slots sorted front to back by their forward offset, so that forming the
/// column never makes two UAVs swap places along the path.
fn column_order(nominal: &[Vector3<f64>]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..nominal.len()).collect();
    order.sort_by(|&a, &b| nominal[a].x.total_cmp(&nominal[b].x).then(a.cmp(&b)));
    order
}

/// Half the width the offsets occupy across the path, UAV radius included.
pub fn lateral_half_width(offsets: &[Vector3<f64>], uav_radius: f64) -> f64 {
    offsets.iter().map(|o| o.y.abs()).fold(0.0, f64::max) + uav_radius
}

/// Largest vertical distance of a slot from the centroid.
pub fn vertical_half_height(offsets: &[Vector3<f64>]) -> f64 {
    offsets.iter().map(|o| o.z.abs()).fold(0.0, f64::max)
}

/// Smallest distance between two slots (∞ for fewer than two).
pub fn min_pair_distance(offsets: &[Vector3<f64>]) -> f64 {
    let mut best = f64::INFINITY;
    for i in 0..offsets.len() {
        for j in (i + 1)..offsets.len() {
            best = best.min((offsets[i] - offsets[j]).norm());
        }
    }
    best
}

/// The spacing of the alignment column: the closest nominal pair, at least 2 r_Q.
pub fn column_spacing(formation: &Formation) -> f64 {
    let nominal = min_pair_distance(&formation.slots);
    let floor = 2.0 * formation.uav_radius;
    if nominal.is_finite() {
        nominal.max(floor)
    } else {
        floor
    }
}

/// Resolves a choice into a shape for a gap of width `gap`.
///
/// `Auto` is the least change that fits: among the shapes whose lateral
/// width fits the gap, the one that moves the UAVs least (largest slot
/// displacement). Shrink is tried at the largest scale that fits (never below
/// the spacing 2 r_Q allows), which often beats a full alignment. When nothing
/// fits, alignment is the narrowest there is; verification will say whether
/// it was enough.
pub fn resolve_shape(choice: ShapeChoice, gap: f64, formation: &Formation, shrink: f64) -> Shape {
    let alignment = Shape::Alignment {
        spacing: column_spacing(formation),
    };
    match choice {
        ShapeChoice::Alignment => alignment,
        ShapeChoice::Rotation => Shape::Rotation,
        ShapeChoice::Shrink => Shape::Shrink { scale: shrink },
        ShapeChoice::Auto => {
            let slots = &formation.slots;
            let r_q = formation.uav_radius;
            let mut candidates = vec![alignment, Shape::Rotation];
            let widest = slots.iter().map(|o| o.y.abs()).fold(0.0, f64::max);
            if widest > 0.0 {
                let fit = ((gap / 2.0 - r_q) / widest).min(1.0);
                let closest = min_pair_distance(slots);
                let floor = if closest.is_finite() {
                    2.0 * r_q / closest
                } else {
                    0.0
                };
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
            candidates
                .into_iter()
                .filter(|s| lateral_half_width(&s.offsets(slots, 1.0), r_q) <= gap / 2.0 + 1e-9)
                .min_by(|a, b| displacement(a).total_cmp(&displacement(b)))
                .unwrap_or(alignment)
        }
    }
}

/// Every IWP of the mission by eq. 9, with the operator's choices applied.
pub fn find_iwps(mission: &Mission) -> Vec<Iwp> {
    let f = &mission.formation;
    let r_q = f.uav_radius;
    let too_narrow = 2.0 * r_q;
    let fits_formation = 2.0 * (f.radius() + r_q);
    let obstacles = &mission.obstacles;
    let mut found = Vec::new();
    for p in 0..obstacles.len() {
        for q in (p + 1)..obstacles.len() {
            let (a, b) = (&obstacles[p], &obstacles[q]);
            if a.height <= mission.bounds.z[0] || b.height <= mission.bounds.z[0] {
                continue;
            }
            let axis = b.center - a.center;
            let distance = axis.norm();
            if distance == 0.0 {
                continue;
            }
            let gap = distance - a.radius - b.radius;
            if !(too_narrow <= gap && gap < fits_formation) {
                continue;
            }
            let u = axis / distance;
            let p_p = a.center + u * a.radius;
            let p_q = b.center - u * b.radius;
            let blocked = obstacles.iter().enumerate().any(|(k, o)| {
                k != p
                    && k != q
                    && o.height > mission.bounds.z[0]
                    && segment_point_distance(&p_p, &p_q, &o.center) < o.radius + r_q
            });
            if blocked {
                continue;
            }
            let choice = mission.reconfiguration.waypoints.iter().find(|w| {
                (w.between[0] == a.name && w.between[1] == b.name)
                    || (w.between[0] == b.name && w.between[1] == a.name)
            });
            let (enabled, shape_choice, scale) = match choice {
                Some(w) => (
                    w.enabled,
                    w.shape,
                    w.scale.unwrap_or(mission.reconfiguration.shrink_scale),
                ),
                None => (
                    true,
                    mission.reconfiguration.default_shape,
                    mission.reconfiguration.shrink_scale,
                ),
            };
            found.push(Iwp {
                between: [a.name.clone(), b.name.clone()],
                obstacles: [p, q],
                position: Point2::from((p_p.coords + p_q.coords) / 2.0),
                gap,
                normal: Vector2::new(-u.y, u.x),
                enabled,
                choice: shape_choice,
                shape: resolve_shape(shape_choice, gap, f, scale),
            });
        }
    }
    found
}
