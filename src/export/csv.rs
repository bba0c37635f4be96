//! CSV of each track's timed samples: `t,x,y,z,vx,vy,vz` (seconds, metres
//! and m/s ENU), then, when the mission has an `[origin]`,
//! `lat,lon,alt,rel_alt`: degrees, degrees, metres in the export's one
//! altitude convention (`geodesy`: `[origin].altitude + z`) and metres
//! above the vehicle's home (what the `.plan` and `.waypoints` files hold
//! as frame-3 altitudes). One header row.

use std::fmt::Write;

use nalgebra::{Point3, Vector3};

use super::{Home, Placement};
use crate::outcome::tracks::{Track, TrackSample};

/// The CSV text of one track, and its number of samples.
pub fn render(
    track: &Track,
    placement: Option<&Placement>,
    home: Option<&Home>,
) -> (String, usize) {
    let geodetic = placement.zip(home);
    let mut out = String::from("t,x,y,z,vx,vy,vz");
    if geodetic.is_some() {
        out.push_str(",lat,lon,alt,rel_alt");
    }
    out.push('\n');
    for s in &track.samples {
        let (p, v) = (&s.position, &s.velocity);
        let _ = write!(
            out,
            "{:.3},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
            s.t, p.x, p.y, p.z, v.x, v.y, v.z
        );
        if let Some((placement, home)) = geodetic {
            let g = placement.absolute(p);
            let _ = write!(
                out,
                ",{:.9},{:.9},{:.4},{:.4}",
                g.latitude,
                g.longitude,
                g.altitude,
                p.z - home.enu.z
            );
        }
        out.push('\n');
    }
    (out, track.samples.len())
}

/// The samples of a CSV text as a reader takes them: each at its
/// latitude, longitude and altitude (through `placement`) when the file
/// has them, else at its x, y, z. Rows that do not parse are skipped (the
/// caller compares the count).
pub fn read(text: &str, placement: Option<&Placement>) -> Vec<TrackSample> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name);
    let geodetic = placement.zip(column("lat").zip(column("lon")).zip(column("alt")));
    lines
        .filter_map(|line| {
            let f: Vec<f64> = line
                .split(',')
                .map(str::parse)
                .collect::<Result<_, _>>()
                .ok()?;
            let get = |i: usize| f.get(i).copied();
            let t = get(0)?;
            let position = match geodetic {
                Some((placement, ((lat, lon), alt))) => {
                    placement.enu(get(lat)?, get(lon)?, get(alt)? - placement.datum())
                }
                None => Point3::new(get(1)?, get(2)?, get(3)?),
            };
            Some(TrackSample {
                t,
                position,
                velocity: Vector3::new(get(4)?, get(5)?, get(6)?),
            })
        })
        .collect()
}
