//! Where each UAV is when the centroid is at arc length s (θ-PSO eqs. 12-14).
//!
//! One function of s for the cost, the trajectories and the verification, so
//! the optimiser judges exactly the geometry that is flown: the centroid on
//! its path, the formation frame turned to the heading (x forward along the
//! horizontal direction of travel, y left, z up; eq. 13), and the slot offsets
//! of the current shape added to the centroid (eq. 14).

use nalgebra::{Point3, Vector3};

use super::iwp::Shape;
use super::path::{ArcWalker, CentroidPath, Zone};

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
}

impl<'a> Motion<'a> {
    /// `span`: half the chord the heading is taken from (`path::heading_span`).
    pub fn new(path: &'a CentroidPath, slots: &'a [Vector3<f64>], span: f64) -> Self {
        Motion {
            walker: ArcWalker::new(&path.points),
            zones: &path.zones,
            slots,
            span,
        }
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
        let forward = self.walker.heading(s, self.span);
        Frame {
            centroid: self.walker.at(s),
            forward,
            left: Vector3::new(-forward.y, forward.x, 0.0),
        }
    }

    /// The shape the formation is changing into at `s` and how far (the zone
    /// furthest into its reconfiguration), or `None` in the nominal shape.
    pub fn shape_at(&self, s: f64) -> Option<(Shape, f64)> {
        let mut best: Option<(Shape, f64)> = None;
        for zone in self.zones {
            let b = zone.blend(s);
            if b > 0.0 && best.is_none_or(|(_, old)| b > old) {
                best = Some((zone.shape, b));
            }
        }
        best
    }

    /// Slot `n`'s offset in the formation frame for the shape state `shape`.
    pub fn offset(&self, n: usize, shape: Option<(Shape, f64)>) -> Vector3<f64> {
        match shape {
            Some((shape, blend)) => shape.offset(self.slots, n, blend),
            None => self.slots[n],
        }
    }

    /// Every UAV's position at `s`, into `out` (cleared first).
    pub fn positions_into(&self, s: f64, out: &mut Vec<Point3<f64>>) {
        let frame = self.frame(s);
        let shape = self.shape_at(s);
        out.clear();
        out.extend((0..self.slots.len()).map(|n| frame.place(&self.offset(n, shape))));
    }
}
