//! Eq. 8 along the inspection passes a change of shape reaches into.
//!
//! A pass is laid out for the nominal shape (`inspection::PassGeometry`), so
//! where the formation holds it the facing UAV keeps the band by
//! construction. A squeeze or an IWP whose change (or hold) overlaps the pass
//! moves the UAVs, and the facing one may leave the band: verification would
//! then fail the inspection. The cost follows the formation along exactly
//! those passes. Not in the paper, whose passes and IWPs lie apart.

use super::*;

/// Step along a pass, metres (verification samples every 0.1 s, 0.3 m at
/// 3 m/s).
const PASS_STEP: f64 = 0.2;

impl CostModel {
    /// Σ step × metres the UAV nearest the inspected obstacle is outside its
    /// stand-off band, over the passes that overlap a zone ([t1, t4]).
    pub(super) fn pass_deficit(
        &self,
        motion: &Motion<'_>,
        path: &CentroidPath,
        scratch: &mut Vec<Point3<f64>>,
    ) -> f64 {
        let mut deficit = 0.0;
        for pass in &path.passes {
            let [p0, p1] = pass.arcs;
            let changes = path.zones.iter().any(|zone| {
                let [t1, _, _, t4] = zone.arcs();
                t1 < p1 && p0 < t4
            });
            let (Some(cylinder), Some(band)) = (
                self.obstacles.get(pass.obstacle),
                self.bands.get(pass.obstacle),
            ) else {
                continue;
            };
            if !changes || p1 <= p0 {
                continue;
            }
            let samples = (((p1 - p0) / PASS_STEP).ceil() as usize).max(1);
            let step = (p1 - p0) / samples as f64;
            let mut reader = Reader::default();
            for k in 0..=samples {
                motion.read_into(p0 + k as f64 * step, scratch, &mut reader);
                let facing = scratch
                    .iter()
                    .map(|p| cylinder.clearance(p))
                    .fold(f64::INFINITY, f64::min);
                deficit += (band[0] - facing).max(facing - band[1]).max(0.0) * step;
            }
        }
        deficit
    }
}
