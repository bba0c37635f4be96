//! Waypoints from a timed track: Douglas–Peucker on the synchronous
//! Euclidean distance (SED; the "TD-TR" variant of Meratnia and de By,
//! *Spatiotemporal compression techniques for moving point objects*, EDBT 2004).
//!
//! Plain Douglas–Peucker bounds how far the track strays from the polyline
//! in space. A formation needs more: where each vehicle is *at each instant*.
//! So the error of a sample at time t is its distance to the point the
//! straight leg reaches at t, flown at the constant speed that arrives at the
//! leg's end on time. Every kept sample is a waypoint; between two of them
//! every sample of the track stays within `tolerance` of where the leg puts
//! the vehicle at that same time. Two vehicles thus keep their distance to
//! within 2 × tolerance, and their clearance to within tolerance.

use nalgebra::Point3;

use crate::outcome::tracks::TrackSample;

/// Where the straight leg a → b is at time t, flown at constant speed.
pub fn on_leg(a: &TrackSample, b: &TrackSample, t: f64) -> Point3<f64> {
    let span = b.t - a.t;
    if span <= 0.0 {
        return b.position;
    }
    let s = ((t - a.t) / span).clamp(0.0, 1.0);
    a.position + (b.position - a.position) * s
}

/// Indices of the samples kept as waypoints (the first and the last always),
/// such that every sample is within `tolerance` metres (SED) of its leg.
pub fn simplify(samples: &[TrackSample], tolerance: f64) -> Vec<usize> {
    let n = samples.len();
    if n <= 2 {
        return (0..n).collect();
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    // An explicit stack: tracks of thousands of samples, no deep recursion.
    let mut stack = vec![(0usize, n - 1)];
    while let Some((first, last)) = stack.pop() {
        if last <= first + 1 {
            continue;
        }
        let (a, b) = (&samples[first], &samples[last]);
        let mut worst = (first, -1.0f64);
        for (k, s) in samples.iter().enumerate().take(last).skip(first + 1) {
            let d = (s.position - on_leg(a, b, s.t)).norm();
            if d > worst.1 {
                worst = (k, d);
            }
        }
        if worst.1 > tolerance {
            keep[worst.0] = true;
            stack.push((worst.0, last));
            stack.push((first, worst.0));
        }
    }
    (0..n).filter(|&k| keep[k]).collect()
}

/// The largest SED of `samples` from the legs between the kept ones.
pub fn max_error(samples: &[TrackSample], kept: &[usize]) -> f64 {
    kept.windows(2)
        .flat_map(|w| {
            let (a, b) = (&samples[w[0]], &samples[w[1]]);
            samples[w[0]..=w[1]]
                .iter()
                .map(move |s| (s.position - on_leg(a, b, s.t)).norm())
        })
        .fold(0.0, f64::max)
}
