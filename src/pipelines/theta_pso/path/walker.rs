//! A point moving along a polyline by arc length: what the cost, the
//! trajectories and the verification read a centroid path with.

use nalgebra::{Point3, Vector3};

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
        self.at_from(s, &mut Hint::default())
    }

    /// [`Self::at`], starting the search for the leg at `hint` (the leg of
    /// the last read through it) and leaving it at this read's leg: a
    /// caller reading along the path finds each leg by a step or two.
    pub fn at_from(&self, s: f64, hint: &mut Hint) -> Point3<f64> {
        let n = self.points.len();
        if n == 0 {
            return Point3::origin();
        }
        if n == 1 {
            return self.points[0];
        }
        let s = s.clamp(0.0, self.length());
        // The leg holding s: i = 1 + the inner vertices at or before it (the
        // first vertex is at 0 ≤ s), whichever leg the search starts from.
        let mut i = hint.0.clamp(1, n - 1);
        while i < n - 1 && self.arcs[i] <= s {
            i += 1;
        }
        while i > 1 && self.arcs[i - 1] > s {
            i -= 1;
        }
        hint.0 = i;
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
        self.at_extended_from(s, &mut Hint::default())
    }

    /// [`Self::at_extended`] through a [`Hint`], as [`Self::at_from`].
    pub fn at_extended_from(&self, s: f64, hint: &mut Hint) -> Point3<f64> {
        let length = self.length();
        let n = self.points.len();
        if n < 2 || (0.0..=length).contains(&s) {
            return self.at_from(s, hint);
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
        self.heading_from(s, span, &mut [Hint::default(); 2])
    }

    /// [`Self::heading`] through two [`Hint`]s: behind and ahead.
    pub fn heading_from(&self, s: f64, span: f64, hints: &mut [Hint; 2]) -> Vector3<f64> {
        let [behind_hint, ahead_hint] = hints;
        let ahead = self.at_from(s + span, ahead_hint);
        let behind = self.at_from(s - span, behind_hint);
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

/// Where a reader of an [`ArcWalker`] last was: the leg of its last read.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Hint(usize);
