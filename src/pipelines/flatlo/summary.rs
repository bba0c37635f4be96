//! The human summary of a FLATLO outcome (`skyform run flatlo`). Aircraft
//! are numbered from 1 here as everywhere a person reads them; the JSON
//! keeps the 0-based indices.

use super::FlatloOutcome;
use crate::pipelines::table::{Cell, Row, Tone, row};

/// The human summary of a FLATLO outcome.
pub fn flatlo(o: &FlatloOutcome) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "FLATLO transition for \"{}\" (seed {})",
        o.header.mission, o.header.seed
    );
    let _ = writeln!(
        s,
        "  run          {:?}, {:.1} s simulated; every aircraft on the line at t = {:.1} s",
        o.header.completion, o.duration, o.arrival_time
    );
    for a in &o.aircraft {
        let _ = writeln!(
            s,
            "  aircraft {:<3} {:<6} Δm {:>8.0} m  Δ {:>7.0} m  transition {:>8.0} m at {:>6.2} m/s  tracking max {:>7.1} m, RMS {:>6.1} m",
            a.index + 1,
            format!("{:?}", a.side).to_lowercase(),
            a.advance,
            a.lateral_distance,
            a.transition_length,
            a.airspeed,
            a.tracking_max,
            a.tracking_rms
        );
    }
    for p in &o.pairs {
        let _ = writeln!(
            s,
            "  pair {:>2}-{:<2}    closest {:>9.1} m at t = {:.0} s",
            p.a + 1,
            p.b + 1,
            p.min_distance,
            p.time
        );
    }
    let closest = o.closest.map_or("-".to_owned(), |c| {
        format!(
            "aircraft {} and {} at {:.1} m (t = {:.0} s)",
            c.a + 1,
            c.b + 1,
            c.min_distance,
            c.time
        )
    });
    let Some(v) = &o.verification else {
        let _ = writeln!(
            s,
            "  result       CANCELLED: no verdict on a partial flight; closest so far {closest}"
        );
        return s;
    };
    let spacing: Vec<String> = v
        .final_spacing
        .iter()
        .map(|x| format!("{}→{} {:.1} m", x.front + 1, x.back + 1, x.spacing))
        .collect();
    let _ = writeln!(s, "  final line   {}", spacing.join(", "));
    let _ = writeln!(
        s,
        "               spacing error {:.3} % of Δd, lateral spread {:.1} m",
        v.max_spacing_error * 100.0,
        v.lateral_spread
    );
    let [slowest, fastest] = v.airspeed_flown;
    let [lo, hi] = v.airspeed_range;
    let _ = writeln!(
        s,
        "  flight       airspeed {slowest:.2}-{fastest:.2} m/s flown (airspeed_range [{lo}, {hi}] m/s); \
         bank at most {:.1}° (max_bank_deg {}°)",
        v.bank_flown_deg, v.max_bank_deg
    );
    let bounds = if v.bounds_margin >= 0.0 {
        format!(
            "every aircraft and its reference inside the x-y bounds and the altitude band, {:.0} m from the nearest edge at least",
            v.bounds_margin
        )
    } else {
        format!(
            "an aircraft left them: {:.0} m outside at worst",
            -v.bounds_margin
        )
    };
    let _ = writeln!(s, "  bounds       {bounds}");
    let verdict = match (&v.violation, v.passed) {
        (_, true) => "PASS:".to_owned(),
        (Some(x), false) => format!("FAIL: not flyable, {};", x.describe()),
        (None, false) => "FAIL:".to_owned(),
    };
    let _ = writeln!(
        s,
        "  result       {verdict} closest {closest}, minimum separation {:.0} m",
        v.min_separation
    );
    s
}

/// FLATLO's verification in the designer's jobs panel: the verdict, every
/// pair's closest approach (the eight closest), the first limit broken,
/// the airspeeds and bank flown, the final line, the worst tracking.
pub fn table(o: &FlatloOutcome) -> Vec<Row> {
    let verdict = match &o.verification {
        Some(v) if v.passed => Cell::new("✓ separation kept", Tone::Good),
        Some(v) if v.violation.is_some() => Cell::new("✗ NOT FLYABLE", Tone::BadStrong),
        Some(_) => Cell::new("✗ SEPARATION LOST", Tone::BadStrong),
        None => Cell::new("cancelled: no verdict", Tone::Warn),
    };
    let mut lines = vec![vec![
        Cell::plain(format!(
            "{} aircraft · on the line at {:.0} s · ",
            o.aircraft.len(),
            o.arrival_time
        )),
        verdict,
    ]];
    let min_separation = o.verification.as_ref().map_or(0.0, |v| v.min_separation);
    lines.push(row(
        format!("{:<6} {:>11} {:>8}", "pair", "closest m", "at s"),
        Tone::Strong,
    ));
    // Large squadrons keep only the closest pair overall.
    let mut pairs = if o.pairs.is_empty() {
        o.closest.into_iter().collect()
    } else {
        o.pairs.clone()
    };
    pairs.sort_by(|a, b| a.min_distance.total_cmp(&b.min_distance));
    for p in pairs.iter().take(8) {
        let tone = if p.min_distance < min_separation {
            Tone::Bad
        } else {
            Tone::Plain
        };
        lines.push(row(
            format!(
                "{:<6} {:>11.0} {:>8.0}",
                format!("{}-{}", p.a + 1, p.b + 1),
                p.min_distance,
                p.time
            ),
            tone,
        ));
    }
    if pairs.len() > 8 {
        lines.push(row(
            format!("… {} more pairs", pairs.len() - 8),
            Tone::Plain,
        ));
    }
    if let Some(v) = &o.verification {
        if let Some(x) = &v.violation {
            lines.push(row(x.describe(), Tone::Bad));
        }
        lines.push(row(
            format!(
                "airspeed {:.1}-{:.1} m/s (range {}-{}) · bank ≤ {:.1}°",
                v.airspeed_flown[0],
                v.airspeed_flown[1],
                v.airspeed_range[0],
                v.airspeed_range[1],
                v.bank_flown_deg
            ),
            Tone::Plain,
        ));
        lines.push(row(
            format!(
                "final spacing error {:.3} % · lateral spread {:.1} m",
                v.max_spacing_error * 100.0,
                v.lateral_spread
            ),
            Tone::Plain,
        ));
    }
    let worst = o
        .aircraft
        .iter()
        .max_by(|a, b| a.tracking_max.total_cmp(&b.tracking_max));
    if let Some(a) = worst {
        lines.push(row(
            format!(
                "worst tracking: aircraft {} max {:.1} m, RMS {:.1} m",
                a.index + 1,
                a.tracking_max,
                a.tracking_rms
            ),
            Tone::Plain,
        ));
    }
    lines
}
