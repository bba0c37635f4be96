//! The pairs' deficit (eq. 7): where two UAVs of the formation come closer
//! than 2 r_Q while it changes shape, and along a column.

use super::*;

impl CostModel {
    /// How far two UAVs come closer than [`PAIR_FLOOR`] to each other
    /// (eq. 7), integrated over the stretches where the pairs can change: the
    /// changes of shape (a straight blend between two shapes can bring two
    /// UAVs closer than either shape does) and a column's hold (a UAV flies at
    /// the centroid path's point its place ahead, so a hairpin or a sharp
    /// corner brings two of them together). A rigid shape held keeps its
    /// pairs, which validation checked.
    pub(super) fn pair_deficit(
        &self,
        motion: &Motion<'_>,
        path: &CentroidPath,
        scratch: &mut Vec<Point3<f64>>,
    ) -> f64 {
        let n = self.slots.len();
        if n < 2 {
            return 0.0;
        }
        let floor = self.pair_floor;
        let mut deficit = 0.0;
        let mut follow = |from: f64, to: f64, deficit: &mut f64| {
            let mut reader = Reader::default();
            each_sample(
                motion,
                [from, to],
                PAIR_STEP,
                scratch,
                &mut reader,
                |at, step| {
                    for i in 0..n {
                        for j in (i + 1)..n {
                            let gap = floor - (at[i] - at[j]).norm();
                            if gap > 0.0 {
                                *deficit += gap * step;
                            }
                        }
                    }
                },
            );
        };
        for zone in &path.zones {
            let [t1, t2, t3, t4] = zone.arcs();
            if t2 > t1 {
                follow(t1, t2, &mut deficit);
            }
            if t4 > t3 {
                follow(t3, t4, &mut deficit);
            }
            if let Shape::Alignment { spacing } = zone.shape {
                deficit += self.column_deficit(motion.walker(), [t2, t3], spacing, floor);
            }
        }
        deficit
    }

    /// The same over a column's hold [t2, t3], from the path alone: UAV n is
    /// at the path's point its place ahead of the centroid, so two UAVs `p`
    /// places apart are the chord between the path's points at u and
    /// u + p × spacing. Between the path's vertices (and the vertices one
    /// chord behind them) both ends move straight, so the chord is linear in
    /// u: its closest approach on each piece is exact, not sampled, and a
    /// hairpin that brings two UAVs together between samples is seen.
    pub(super) fn column_deficit(
        &self,
        walker: &crate::pipelines::theta_pso::path::ArcWalker<'_>,
        [t2, t3]: [f64; 2],
        spacing: f64,
        floor: f64,
    ) -> f64 {
        let n = self.slots.len();
        if spacing <= 0.0 || t3 <= t2 {
            return 0.0;
        }
        let half = (n - 1) as f64 * spacing / 2.0;
        let (from, to) = (t2 - half, t3 + half);
        let arcs = walker.arcs();
        let inner = &arcs[1..arcs.len().saturating_sub(1)];
        let mut breaks: Vec<f64> = Vec::with_capacity(2 * inner.len() + 2);
        let mut deficit = 0.0;
        for places in 1..n {
            let chord = places as f64 * spacing;
            let end = to - chord;
            if end <= from {
                break;
            }
            breaks.clear();
            breaks.push(from);
            breaks.push(end);
            for &a in inner {
                for u in [a, a - chord] {
                    if from < u && u < end {
                        breaks.push(u);
                    }
                }
            }
            breaks.sort_by(f64::total_cmp);
            let (mut behind, mut ahead) = (Hint::default(), Hint::default());
            let mut chord_at = |u: f64| {
                walker.at_extended_from(u + chord, &mut ahead)
                    - walker.at_extended_from(u, &mut behind)
            };
            let mut d0 = chord_at(breaks[0]);
            for w in breaks.windows(2) {
                let d1 = chord_at(w[1]);
                deficit += linear_deficit(d0, d1, floor) * (w[1] - w[0]);
                d0 = d1;
            }
        }
        deficit
    }
}

/// ∫₀¹ (floor − |d0 + t (d1 − d0)|)⁺ dt, in closed form: the chord is
/// closer than `floor` between the roots of a quadratic in t, and there
/// |d0 + t e| = |e| √((t + b)² + k²) with ∫ √(x² + k²) dx =
/// ½ (x √(x² + k²) + k² asinh(x / k)).
fn linear_deficit(d0: Vector3<f64>, d1: Vector3<f64>, floor: f64) -> f64 {
    let e = d1 - d0;
    let Some((lo, hi)) = closer_than(&d0, &e, floor) else {
        return 0.0;
    };
    let qa = e.norm_squared();
    if qa < 1e-18 {
        return (floor - d0.norm()).max(0.0);
    }
    let b = d0.dot(&e) / qa;
    let k2 = (d0.norm_squared() / qa - b * b).max(0.0);
    let k = k2.sqrt();
    let antiderivative = |x: f64| {
        let r = (x * x + k2).sqrt();
        0.5 * (x * r + if k > 0.0 { k2 * (x / k).asinh() } else { 0.0 })
    };
    let under = qa.sqrt() * (antiderivative(hi + b) - antiderivative(lo + b));
    (floor * (hi - lo) - under).max(0.0)
}
