//! Eq. 8 along the inspection passes a change of shape reaches into.
//!
//! A pass is laid out for the nominal shape (`inspection::PassGeometry`), so
//! where the formation holds it the facing UAV keeps the band by
//! construction. A squeeze or an IWP whose change (or hold) overlaps the pass
//! moves the UAVs, and the facing one may leave the band: verification would
//! then fail the inspection. The cost follows the formation along exactly
//! those passes. Not in the paper, whose passes and IWPs lie apart.

use super::*;

/// Step along a pass, metres: the facing UAV's distance changes smoothly
/// through a blend, and verification (every 0.1 s, 0.3 m at 3 m/s) judges.
const PASS_STEP: f64 = 0.5;

impl CostModel {
    /// Σ step × metres the UAV nearest the inspected obstacle is outside its
    /// stand-off band, over the stretches of pass inside a zone ([t1, t4]);
    /// outside every zone the nominal shape keeps the band by construction.
    pub(super) fn pass_deficit(
        &self,
        motion: &Motion<'_>,
        path: &CentroidPath,
        scratch: &mut Vec<Point3<f64>>,
    ) -> f64 {
        let mut deficit = 0.0;
        let mut reader = Reader::default();
        for pass in &path.passes {
            let (Some(cylinder), Some(band)) = (
                self.obstacles.get(pass.obstacle),
                self.bands.get(pass.obstacle),
            ) else {
                continue;
            };
            for zone in &path.zones {
                let [t1, _, _, t4] = zone.arcs();
                let (from, to) = (pass.arcs[0].max(t1), pass.arcs[1].min(t4));
                if to <= from {
                    continue;
                }
                each_sample(
                    motion,
                    [from, to],
                    PASS_STEP,
                    scratch,
                    &mut reader,
                    |at, step| {
                        let facing = at
                            .iter()
                            .map(|p| cylinder.clearance(p))
                            .fold(f64::INFINITY, f64::min);
                        deficit += (band[0] - facing).max(facing - band[1]).max(0.0) * step;
                    },
                );
            }
        }
        deficit
    }
}
