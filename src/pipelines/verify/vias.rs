//! The route's vias as flown (`[[route.via]]`): whether the formation's
//! centre crossed each gate between its two obstacles, below their tops,
//! and passed each point within its radius, in the file's order. A check of
//! the flight, as verification's other rows are: the path builder places
//! every via (`path`), this says whether the flight kept them.

use nalgebra::Point3;
use serde::Serialize;

use super::Trajectory;
use crate::mission::Mission;

/// Whether the flight kept one `[[route.via]]`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViaResult {
    /// Numbered from 1, as `route.via` is read.
    pub via: usize,
    /// `between 'pier 3' and 'pier 4'`, `by (40, 10, 12) within 1 m`.
    pub label: String,
    /// When the formation's centre crossed the gate (or came nearest the
    /// point), seconds; `None` when it never did.
    pub time: Option<f64>,
    /// For a point: how near the centre came, metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance: Option<f64>,
    pub ok: bool,
    /// Why not, in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub why: Option<String>,
}

/// Checks each `[[route.via]]` on the flight: the formation's centre (the
/// mean of its UAVs) crosses a gate's gap line (between its obstacles'
/// nearest points) at an altitude where both stand, or passes a point
/// within its radius, and the vias are kept in their order.
pub fn verify_vias(mission: &Mission, trajectories: &[Trajectory]) -> Vec<ViaResult> {
    let centres = super::centres(trajectories);
    let time = |k: usize| trajectories[0].samples[k].t;
    let ground = mission.ground_model();
    let above = |p: &Point3<f64>| p.z - ground.as_ref().map_or(0.0, |g| g.at(p.x, p.y));
    let mut last_time = f64::NEG_INFINITY;
    let mut out = Vec::new();
    for (i, via) in mission.route.via.iter().enumerate() {
        let mut result = ViaResult {
            via: i + 1,
            label: via.label(),
            time: None,
            distance: None,
            ok: false,
            why: None,
        };
        match (&via.between, via.point) {
            (Some([a, b]), _) => {
                let find = |name: &str| mission.obstacles.iter().find(|o| o.name == name);
                let (Some(oa), Some(ob)) = (find(a), find(b)) else {
                    result.why = Some("names an obstacle the mission does not have".into());
                    out.push(result);
                    continue;
                };
                let (pa, pb) = (mission.prism(oa), mission.prism(ob));
                let (ga, gb) = crate::base::shape::nearest_points(&*pa.outline, &*pb.outline);
                let (low, high) = (oa.base.max(ob.base), oa.top().min(ob.top()));
                let crossing = centres.windows(2).enumerate().find_map(|(k, w)| {
                    let (p, q) = (w[0], w[1]);
                    if !crate::base::geometry::segments_cross(&p.xy(), &q.xy(), &ga, &gb) {
                        return None;
                    }
                    let z = (above(&p) + above(&q)) / 2.0;
                    (low < z && z < high).then(|| time(k))
                });
                match crossing {
                    Some(t) => {
                        result.time = Some(t);
                        result.ok = true;
                    }
                    None => {
                        result.why = Some(format!(
                            "the formation's centre never crosses the gap between them below \
                             their tops ({:.1} m)",
                            high
                        ));
                    }
                }
            }
            (None, Some(point)) => {
                let nearest = centres
                    .iter()
                    .enumerate()
                    .map(|(k, p)| (k, (p - point).norm()))
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                if let Some((k, d)) = nearest {
                    result.time = Some(time(k));
                    result.distance = Some(d);
                    result.ok = d <= via.radius() + 1e-6;
                    if !result.ok {
                        result.why = Some(format!(
                            "the formation's centre comes {d:.2} m from it at the nearest, \
                             {} m required",
                            via.radius()
                        ));
                    }
                }
            }
            (None, None) => {}
        }
        if result.ok
            && let Some(t) = result.time
        {
            if t + 1e-9 < last_time {
                result.ok = false;
                result.why = Some(format!(
                    "kept at t = {t:.1} s, before route.via {} (out of order)",
                    i
                ));
            }
            last_time = last_time.max(t);
        }
        out.push(result);
    }
    out
}
