//! Terrain in the views: the ground profile under a path (side view).

use nalgebra::Point3;

use crate::mission::Mission;

/// (distance along the path, ground height) at about `samples` points of
/// the path's horizontal track; empty without terrain. `along[i]` is the
/// horizontal distance of `points[i]` from the start.
pub fn ground_profile(
    mission: &Mission,
    points: &[Point3<f64>],
    along: &[f64],
    samples: usize,
) -> Vec<(f64, f64)> {
    if mission.height_map().is_none() || points.len() < 2 {
        return Vec::new();
    }
    let length = along.last().copied().unwrap_or(0.0);
    let step = (length / samples.max(1) as f64).max(1e-9);
    let mut out = Vec::with_capacity(samples + points.len());
    for (i, leg) in points.windows(2).enumerate() {
        let (a, b) = (leg[0], leg[1]);
        let (s0, s1) = (along[i], along[i + 1]);
        let pieces = ((s1 - s0) / step).ceil().max(1.0) as usize;
        for k in 0..=pieces {
            let t = k as f64 / pieces as f64;
            let p = a + (b - a) * t;
            out.push((s0 + t * (s1 - s0), mission.ground(p.x, p.y)));
        }
    }
    out
}
