//! Where each UAV is when the centroid is at arc length s (θ-PSO eqs. 12-14).
//!
//! One function of s for the cost, the trajectories and the verification, so
//! the optimiser judges exactly the geometry that is flown: the centroid on
//! its path, the formation frame turned to the heading (x forward along the
//! horizontal direction of travel, y left, z up; eq. 13), and the slot offsets
//! of the current shape added to the centroid (eq. 14).
//!
//! One exception to the rigid frame: in the alignment (Fig. 2) the UAVs fly
//! in single file *along the path*, each at the centroid path's point its
//! place in the column ahead of or behind the centroid, as a real column
//! follows its leader. A rigid column of nine 2.5 m apart is 20 m long; turned
//! with the heading between two walls, its ends would sweep into them. Into
//! and out of the column each UAV moves straight between its place in the
//! formation frame and its place on the path.

use nalgebra::{Point3, Vector3};

use super::iwp::{Shape, column_rank_from_middle};
use super::path::{ArcWalker, CentroidPath, Hint, ShapeState, Zone};

/// The formation frame at one arc length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub centroid: Point3<f64>,
    /// Unit horizontal direction of travel.
    pub forward: Vector3<f64>,
    /// Unit horizontal vector to the left of `forward`.
    pub left: Vector3<f64>,
}

impl Frame {
    /// Eqs. 13-14: the offset (formation frame) turned into ENU and added to
    /// the centroid.
    pub fn place(&self, offset: &Vector3<f64>) -> Point3<f64> {
        self.centroid + self.forward * offset.x + self.left * offset.y + Vector3::z() * offset.z
    }
}

/// The formation moving along a centroid path.
pub struct Motion<'a> {
    walker: ArcWalker<'a>,
    zones: &'a [Zone],
    slots: &'a [Vector3<f64>],
    span: f64,
    /// Each slot's place in a column, in spacings from its middle (worked
    /// out once: every read of a column needs it for every UAV).
    ranks: Vec<f64>,
}

impl<'a> Motion<'a> {
    /// `span`: half the chord the heading is taken from (`path::heading_span`).
    pub fn new(path: &'a CentroidPath, slots: &'a [Vector3<f64>], span: f64) -> Self {
        Motion {
            walker: ArcWalker::new(&path.points),
            zones: &path.zones,
            slots,
            span,
            ranks: (0..slots.len())
                .map(|n| column_rank_from_middle(slots, n))
                .collect(),
        }
    }

    /// How far ahead of the centroid slot `n` flies in a column of
    /// `spacing` (`iwp::column_place`), metres along the path.
    pub fn column_place(&self, n: usize, spacing: f64) -> f64 {
        self.ranks[n] * spacing
    }

    pub fn walker(&self) -> &ArcWalker<'a> {
        &self.walker
    }

    pub fn length(&self) -> f64 {
        self.walker.length()
    }

    pub fn uavs(&self) -> usize {
        self.slots.len()
    }

    pub fn span(&self) -> f64 {
        self.span
    }

    /// The formation frame at arc length `s`.
    pub fn frame(&self, s: f64) -> Frame {
        self.frame_from(s, &mut Reader::default())
    }

    fn frame_from(&self, s: f64, reader: &mut Reader) -> Frame {
        let forward = self.walker.heading_from(s, self.span, &mut reader.chord);
        Frame {
            centroid: self.walker.at_from(s, &mut reader.centre),
            forward,
            left: Vector3::new(-forward.y, forward.x, 0.0),
        }
    }

    /// The formation's shape at `s`: nominal outside every zone.
    pub fn state_at(&self, s: f64) -> ShapeState {
        // The zones are in path order and only touch at shared changes.
        self.zones
            .iter()
            .find_map(|zone| zone.state(s))
            .unwrap_or(ShapeState::NOMINAL)
    }

    /// Where UAV `n` is at `s` in the shape state `state`, the frame there
    /// being `frame`.
    pub fn place(&self, n: usize, s: f64, frame: &Frame, state: ShapeState) -> Point3<f64> {
        self.place_from(n, s, frame, state, &mut Hint::default())
    }

    /// [`Self::place`], reading a column's place on the path through `hint`.
    fn place_from(
        &self,
        n: usize,
        s: f64,
        frame: &Frame,
        state: ShapeState,
        hint: &mut Hint,
    ) -> Point3<f64> {
        let mut column = |shape: Option<Shape>| match shape {
            Some(Shape::Alignment { spacing }) => Some(
                self.walker
                    .at_extended_from(s + self.column_place(n, spacing), hint),
            ),
            _ => None,
        };
        // A shape held is read once: both ends are the same point.
        let from = column(state.from);
        let to = if state.to == state.from {
            from
        } else {
            column(state.to)
        };
        match (from, to) {
            (None, None) => frame.place(&state.offset(self.slots, n)),
            (from, to) => {
                let end = |shape: Option<Shape>, on_path: Option<Point3<f64>>| {
                    on_path.unwrap_or_else(|| {
                        frame.place(&ShapeState::held_or_nominal(shape).offset(self.slots, n))
                    })
                };
                let a = end(state.from, from);
                let b = end(state.to, to);
                a + (b - a) * state.blend
            }
        }
    }

    /// Every UAV's position at `s`, into `out` (cleared first).
    pub fn positions_into(&self, s: f64, out: &mut Vec<Point3<f64>>) {
        self.read_into(s, out, &mut Reader::default());
    }

    /// [`Self::positions_into`] through a [`Reader`]: reading at arc lengths
    /// in order (as the cost and the trajectories do) finds each point of
    /// the path without a search.
    pub fn read_into(&self, s: f64, out: &mut Vec<Point3<f64>>, reader: &mut Reader) {
        let frame = self.frame_from(s, reader);
        let state = self.state_at(s);
        out.clear();
        reader.column.resize(self.slots.len(), Hint::default());
        for n in 0..self.slots.len() {
            let p = self.place_from(n, s, &frame, state, &mut reader.column[n]);
            out.push(p);
        }
    }
}

/// Where a reader of a [`Motion`] last was on the path: the centroid, the
/// two ends of the heading's chord, and each UAV's place in a column.
#[derive(Debug, Clone, Default)]
pub struct Reader {
    centre: Hint,
    chord: [Hint; 2],
    column: Vec<Hint>,
}
