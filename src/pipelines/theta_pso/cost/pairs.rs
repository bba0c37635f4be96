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
        let floor = 2.0 * self.uav_radius + PAIR_FLOOR;
        let mut deficit = 0.0;
        let mut follow = |from: f64, to: f64, deficit: &mut f64| {
            let samples = (((to - from) / PAIR_STEP).ceil() as usize).max(1);
            let step = (to - from) / samples as f64;
            let mut reader = crate::pipelines::theta_pso::motion::Reader::default();
            for k in 0..=samples {
                motion.read_into(from + k as f64 * step, scratch, &mut reader);
                for i in 0..n {
                    for j in (i + 1)..n {
                        let gap = floor - (scratch[i] - scratch[j]).norm();
                        if gap > 0.0 {
                            *deficit += gap * step;
                        }
                    }
                }
            }
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
    /// at the path's point its place ahead of the centroid, so two UAVs are
    /// the chord between two points of the path a whole number of spacings
    /// apart. The path is sampled at a quarter spacing, so every such pair
    /// falls on two samples.
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
        let step = spacing / 4.0;
        let half = (n - 1) as f64 * spacing / 2.0;
        let (from, to) = (t2 - half, t3 + half);
        let samples = (((to - from) / step).ceil() as usize).max(1);
        let mut hint = crate::pipelines::theta_pso::path::Hint::default();
        let points: Vec<Point3<f64>> = (0..=samples)
            .map(|k| walker.at_extended_from(from + k as f64 * step, &mut hint))
            .collect();
        let mut deficit = 0.0;
        for i in 0..points.len() {
            for places in 1..n {
                let j = i + 4 * places;
                if j >= points.len() {
                    break;
                }
                let gap = floor - (points[j] - points[i]).norm();
                if gap > 0.0 {
                    deficit += gap * step;
                }
            }
        }
        deficit
    }
}
