//! `QGC WPL 110` files (`.waypoints`), as MAVProxy, Mission Planner and
//! QGroundControl read them: a header line, then one line per item with 12
//! TAB-separated fields: index, current, frame, command, param1..param4,
//! latitude, longitude, altitude, autocontinue. Item 0 is the home position
//! (frame 0, its altitude in the export's convention); the others are the
//! `.plan`'s items, with altitudes relative to home (frame 3).
//!
//! Latitudes and longitudes are the `.plan`'s 1e-7° grid points, written
//! with 8 decimals a fifth of a step away from zero ([`grid_digits`]): a
//! reader that rounds to 1e-7° (QGroundControl, MAVSDK) and one that
//! truncates (MAVProxy and pymavlink's `int(x * 1e7)`) both store the
//! grid point, so every reader flies the `.plan`'s coordinates.

use std::fmt::Write;

use super::{Placement, Planned, VehiclePlan, items};

/// A number as the format writes it: NaN ("keep the current value") as 0.
fn num(v: f64) -> String {
    if v.is_finite() {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s.is_empty() || s == "-" {
            "0".to_owned()
        } else {
            s.to_owned()
        }
    } else {
        "0".to_owned()
    }
}

/// The 8-decimal text of a 1e-7° grid point `e7`: 0.2 of a step away from
/// zero, so rounding and truncating `× 1e7` both give `e7` back.
pub fn grid_digits(e7: i64) -> String {
    let tenths = e7 * 10 + 2 * e7.signum();
    let sign = if tenths < 0 { "-" } else { "" };
    let a = tenths.unsigned_abs();
    format!("{sign}{}.{:08}", a / 100_000_000, a % 100_000_000)
}

/// The `.waypoints` text of one vehicle, and its number of lines after the header.
pub fn render(
    planned: &Planned,
    plan: &VehiclePlan,
    placement: &Placement,
    tolerance: f64,
) -> (String, usize) {
    let (home, list) = items(planned, plan, placement, tolerance);
    let mut out = String::from("QGC WPL 110\n");
    let _ = writeln!(
        out,
        "0\t1\t0\t16\t0\t0\t0\t0\t{}\t{}\t{}\t1",
        grid_digits(home.latitude),
        grid_digits(home.longitude),
        home.altitude
    );
    for (i, item) in list.iter().enumerate() {
        let (lat, lon, alt) = item.at.map_or_else(
            || ("0".to_owned(), "0".to_owned(), 0.0),
            |s| {
                (
                    grid_digits(s.latitude),
                    grid_digits(s.longitude),
                    s.relative,
                )
            },
        );
        let [p1, p2, p3, p4] = item.params;
        let _ = writeln!(
            out,
            "{}\t0\t3\t{}\t{}\t{}\t{}\t{}\t{lat}\t{lon}\t{alt}\t1",
            i + 1,
            item.command,
            num(p1),
            num(p2),
            num(p3),
            num(p4),
        );
    }
    (out, list.len() + 1)
}
