//! Where along the centroid path the formation changes shape (eq. 9, Fig. 2):
//! the zones round each IWP crossing and squeezed stretch, and how zones
//! that follow closely are scheduled into one another.

use nalgebra::Vector3;

use crate::pipelines::theta_pso::iwp::{Shape, lateral_half_width};

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
