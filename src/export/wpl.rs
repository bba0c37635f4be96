//! `QGC WPL 110` files (`.waypoints`), as MAVProxy, Mission Planner and
//! QGroundControl read them: a header line, then one line per item with 12
//! TAB-separated fields: index, current, frame, command, param1..param4,
//! latitude, longitude, altitude, autocontinue. Item 0 is the home position
//! (frame 0, absolute altitude); the others are the `.plan`'s items, with
//! altitudes relative to home (frame 3).

use std::fmt::Write;

use super::{Frame, Planned, VehiclePlan, items};

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

/// The `.waypoints` text of one vehicle, and its number of lines after the header.
pub fn render(
    planned: &Planned,
    plan: &VehiclePlan,
    frame: &Frame,
    tolerance: f64,
) -> (String, usize) {
    let (home, list) = items(planned, plan, frame, tolerance);
    let mut out = String::from("QGC WPL 110\n");
    let _ = writeln!(
        out,
        "0\t1\t0\t16\t0\t0\t0\t0\t{:.8}\t{:.8}\t{:.6}\t1",
        home.latitude, home.longitude, home.altitude
    );
    for (i, item) in list.iter().enumerate() {
        let [lat, lon, alt] = item.at.unwrap_or([0.0; 3]);
        let [p1, p2, p3, p4] = item.params;
        let _ = writeln!(
            out,
            "{}\t0\t3\t{}\t{}\t{}\t{}\t{}\t{lat:.8}\t{lon:.8}\t{alt:.6}\t1",
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
