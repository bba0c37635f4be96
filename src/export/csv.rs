//! CSV of each track's timed samples: `t,x,y,z,vx,vy,vz` (seconds, metres
//! and m/s ENU), then `lat,lon,alt` (degrees, degrees, metres above the
//! WGS-84 ellipsoid) when the mission has an `[origin]`. One header row.

use std::fmt::Write;

use super::Frame;
use crate::outcome::tracks::Track;

/// The CSV text of one track, and its number of samples.
pub fn render(track: &Track, frame: Option<&Frame>) -> (String, usize) {
    let mut out = String::from("t,x,y,z,vx,vy,vz");
    if frame.is_some() {
        out.push_str(",lat,lon,alt");
    }
    out.push('\n');
    for s in &track.samples {
        let (p, v) = (&s.position, &s.velocity);
        let _ = write!(
            out,
            "{:.3},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
            s.t, p.x, p.y, p.z, v.x, v.y, v.z
        );
        if let Some(frame) = frame {
            let g = frame.to_geodetic(p);
            let _ = write!(
                out,
                ",{:.9},{:.9},{:.4}",
                g.latitude, g.longitude, g.altitude
            );
        }
        out.push('\n');
    }
    (out, track.samples.len())
}
