//! The human summary of a θ-PSO outcome (`skyform run theta-pso`), and the
//! verification table the designer's jobs panel shows. UAVs are numbered
//! from 1 here as everywhere a person reads them; the JSON keeps the
//! 0-based indices.

use super::{ThetaPsoOutcome, unusable};
use crate::pipelines::table::{Cell, Row, Tone, row};

/// How many unusable IWPs the summary names (the nearest the route).
const NAMED_UNUSABLE: usize = 3;

/// The human summary of a θ-PSO outcome: the verdict and the first failing
/// check first, then the run, the cost, the route and the IWPs (the unusable
/// ones counted by reason and the few nearest the path named; all of them
/// when `verbose`), the reconfigurations and the verification table.
pub fn theta_pso(o: &ThetaPsoOutcome, verbose: bool) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "θ-PSO plan for \"{}\" (seed {})",
        o.header.mission, o.header.seed
    );
    let verdict = match o.verification.first_failure() {
        None => "FEASIBLE".to_owned(),
        Some(why) => format!("INFEASIBLE: {why}"),
    };
    let _ = writeln!(s, "  result       {verdict}");
    let restarts = match o.restarts {
        0 => String::new(),
        n => format!(" ({n} restart(s): the best plan failed verification)"),
    };
    let _ = writeln!(
        s,
        "  run          {:?} after {} iterations, {} cost evaluations{restarts}",
        o.header.completion, o.iterations, o.evaluations
    );
    let c = &o.cost;
    let _ = writeln!(
        s,
        "  cost         J = {:.3}  (J1 length {:.2} m, J2 obstacles {:.5}, J3 altitude {:.3}, J_R waypoints {:.2} m, J_B bounds {:.3}, J_T turning {:.3})",
        c.total, c.length, c.obstacle, c.altitude, c.waypoints, c.bounds, c.turning
    );
    let reference = match (o.reference_length, o.length_ratio) {
        (Some(r), Some(ratio)) => format!("; J1 / reference {ratio:.3} (shortest route {r:.1} m)"),
        _ => "; no reference route reaches the goal".to_owned(),
    };
    let _ = writeln!(
        s,
        "  path         {:.1} m in {:.1} s, {} free waypoints{reference}",
        o.path_length,
        o.duration,
        o.waypoints.len()
    );
    let source = match o.source {
        crate::pipelines::theta_pso::PlanSource::Swarm => "the swarm's best",
        crate::pipelines::theta_pso::PlanSource::Repaired => {
            "the swarm's best, moved clear by the repair step"
        }
        crate::pipelines::theta_pso::PlanSource::Corridor => {
            "the route stage's corridor (every run of the swarm failed)"
        }
    };
    let coarse = o.corridor.coarse_cell.map_or_else(String::new, |cell| {
        format!(" (a large site, searched at {cell:.2} m cells; gaps judged on exact geometry)")
    });
    let _ = writeln!(
        s,
        "  route        corridor {:.1} m; the plan is {source}{coarse}",
        o.route_length
    );
    iwps(&mut s, o, verbose);
    for why in &o.unused_choices {
        let _ = writeln!(s, "  IWP choice   {why}");
    }
    for (word, names) in [("over", &o.passed_over), ("under", &o.passed_under)] {
        if !names.is_empty() {
            let _ = writeln!(s, "  flies {word:<6} {}", few_names(names));
        }
    }
    for r in &o.reconfigurations {
        let why = if r.iwp.is_some() {
            "at the IWP"
        } else {
            "squeezed"
        };
        let _ = writeln!(
            s,
            "  reconfig     {} {why} {}: t1 {:.1} s, t2 {:.1} s, t3 {:.1} s, t4 {:.1} s",
            r.shape.name(),
            r.obstacles(),
            r.t1,
            r.t2,
            r.t3,
            r.t4
        );
    }
    let _ = writeln!(s, "  verification");
    for row in verification_rows(o) {
        let verdict = if row.ok { "ok  " } else { "FAIL" };
        let _ = writeln!(s, "    {verdict} {}", row.text);
    }
    let verdict = if o.feasible() {
        "FEASIBLE"
    } else {
        "INFEASIBLE"
    };
    let _ = writeln!(s, "  result       {verdict}");
    s
}

/// Up to three names in quotes, then how many more: a gapless wall of 59
/// posts flown over is one short line.
fn few_names(names: &[String]) -> String {
    let shown: Vec<String> = names.iter().take(3).map(|n| format!("'{n}'")).collect();
    match names.len() {
        n if n > 3 => format!("{} and {} more", shown.join(", "), n - 3),
        _ => shown.join(", "),
    }
}

/// One row of θ-PSO's verification table: a check or an inspection pass,
/// whether it holds, and the text the CLI prints after `ok`/`FAIL` (the
/// designer shows the same rows).
#[derive(Debug, Clone, PartialEq)]
pub struct VerificationRow {
    pub ok: bool,
    pub text: String,
}

/// The verification table of a θ-PSO outcome: each check with its worst
/// value and where, then each inspection with its stretch and band.
pub fn verification_rows(o: &ThetaPsoOutcome) -> Vec<VerificationRow> {
    let mut rows = Vec::new();
    for check in &o.verification.checks {
        let worst = check
            .worst
            .map_or_else(|| "n/a".to_owned(), crate::pipelines::verify::figure);
        let at = check
            .at
            .as_ref()
            .map_or_else(String::new, |a| format!("  ({})", a.words()));
        rows.push(VerificationRow {
            ok: check.ok,
            text: format!(
                "{:<32} worst {worst:>9} {} {}{at}",
                check.name,
                check.relation,
                crate::pipelines::verify::limit_figure(check.limit)
            ),
        });
    }
    for i in &o.verification.inspections {
        let band = i.distance.map_or_else(
            || "never within the band".to_owned(),
            |[lo, hi]| format!("facing UAV at {lo:.2}-{hi:.2} m"),
        );
        // The face looked at: the side asked for, and the bearing flown.
        let face = match (&i.side, i.face) {
            (Some(side), Some(b)) => format!(", its {side} face ({b:.0}°)"),
            (Some(side), None) => format!(", its {side} face"),
            (None, Some(b)) => format!(", the face toward {}", compass(b)),
            (None, None) => String::new(),
        };
        rows.push(VerificationRow {
            ok: i.ok,
            text: format!(
                "inspection of {:<19} {:>5.1} m ≥ {} m within [{}, {}] m, {band}{face}",
                format!("'{}'", i.obstacle),
                i.achieved,
                i.required,
                i.band[0],
                i.band[1]
            ),
        });
    }
    for v in &o.verification.vias {
        let when = match (v.time, v.distance) {
            (Some(t), Some(d)) => format!("at t = {t:.1} s, {d:.2} m from it"),
            (Some(t), None) => format!("at t = {t:.1} s"),
            _ => String::new(),
        };
        let text = match &v.why {
            Some(why) => format!("route.via {} {}: {why}", v.via, v.label),
            None => format!("route.via {} {} kept {when}", v.via, v.label),
        };
        rows.push(VerificationRow { ok: v.ok, text });
    }
    rows
}

/// A bearing (degrees clockwise from north) as the nearest of the eight
/// compass points, with the figure: `east (87°)`.
pub fn compass(bearing: f64) -> String {
    let names = crate::mission::Side::NAMES;
    let k = ((bearing.rem_euclid(360.0) + 22.5) / 45.0).floor() as usize % 8;
    format!("{} ({bearing:.0}°)", names[k].0)
}

/// Bypassed IWPs the summary names one per line; more are one line.
const BYPASSED_NAMED: usize = 3;

/// The IWP lines of the θ-PSO summary.
fn iwps(s: &mut String, o: &ThetaPsoOutcome, verbose: bool) {
    use std::fmt::Write as _;
    let enabled = o.iwps.iter().filter(|i| i.enabled).count();
    let unusable: Vec<&crate::pipelines::theta_pso::Iwp> = o
        .iwps
        .iter()
        .filter(|i| i.enabled && i.unusable.is_some())
        .collect();
    let _ = writeln!(
        s,
        "  IWPs         {} found, {enabled} enabled, {} usable, {} unusable, {} bypassed",
        o.iwps.len(),
        enabled - unusable.len(),
        unusable.len(),
        o.bypassed.len()
    );
    let bypassed: Vec<&crate::pipelines::theta_pso::Iwp> =
        o.bypassed.iter().filter_map(|&i| o.iwps.get(i)).collect();
    if verbose || bypassed.len() <= BYPASSED_NAMED {
        for iwp in &bypassed {
            let _ = writeln!(
                s,
                "  IWP          '{}' | '{}' not crossed: the plan goes round it",
                iwp.between[0], iwp.between[1]
            );
        }
    } else {
        // A forest has dozens the plan goes round: one line, the first few
        // named (--verbose lists every one).
        let named: Vec<String> = bypassed
            .iter()
            .take(BYPASSED_NAMED)
            .map(|i| format!("'{}' | '{}'", i.between[0], i.between[1]))
            .collect();
        let _ = writeln!(
            s,
            "  IWP          {} not crossed, the plan goes round them: {}, and {} more (--verbose lists them)",
            bypassed.len(),
            named.join(", "),
            bypassed.len() - BYPASSED_NAMED
        );
    }
    if verbose {
        for i in &unusable {
            let _ = writeln!(
                s,
                "  IWP          '{}' | '{}' unusable: {}",
                i.between[0],
                i.between[1],
                i.unusable.as_deref().unwrap_or_default()
            );
        }
        return;
    }
    for group in unusable::unusable_groups(&o.iwps, &[], 0) {
        let _ = writeln!(
            s,
            "  IWP          {} unusable: {}",
            group.count, group.reason
        );
    }
    if unusable.is_empty() {
        return;
    }
    // The few nearest the path: those a user most likely meant the plan to take.
    let distance =
        |i: &crate::pipelines::theta_pso::Iwp| unusable::distance_to(&o.centroid_path, &i.position);
    let mut nearest: Vec<(f64, &crate::pipelines::theta_pso::Iwp)> =
        unusable.iter().map(|i| (distance(i), *i)).collect();
    nearest.sort_by(|a, b| a.0.total_cmp(&b.0));
    // One line: a forest's hundreds of unusable gaps are the groups above.
    let named: Vec<String> = nearest
        .iter()
        .take(NAMED_UNUSABLE)
        .map(|(d, i)| format!("'{}' | '{}' ({d:.1} m)", i.between[0], i.between[1]))
        .collect();
    let _ = writeln!(
        s,
        "  IWP          unusable, nearest the path: {}{}",
        named.join(", "),
        if nearest.len() > NAMED_UNUSABLE {
            " (--verbose lists them all)"
        } else {
            ""
        }
    );
}

/// θ-PSO's result in the designer's jobs panel, as the CLI prints it: the
/// verdict and its first failing check on top, the figures on one row
/// (the reconfigurations' word shortens on a narrow panel), the unusable
/// IWPs grouped by reason, then the whole verification table
/// ([`verification_rows`]).
pub fn table(o: &ThetaPsoOutcome) -> Vec<Row> {
    let v = &o.verification;
    let rows = verification_rows(o);
    let mut lines = vec![
        if o.header.completion == crate::pipelines::Completion::Cancelled {
            row("cancelled: no verdict on the best path so far", Tone::Warn)
        } else if v.feasible {
            row(
                format!("✓ FEASIBLE · all {} checks pass", rows.len()),
                Tone::GoodStrong,
            )
        } else {
            row(
                format!(
                    "✗ INFEASIBLE · {}",
                    v.first_failure().unwrap_or_else(|| "a check failed".into())
                ),
                Tone::BadStrong,
            )
        },
    ];
    let n = o.reconfigurations.len();
    lines.push(vec![
        Cell::plain(format!(
            "J {:.2} · {:.1} m · {:.1} s",
            o.cost.total, o.path_length, o.duration
        )),
        Cell::shortened(
            format!(" · {n} reconfiguration(s)"),
            format!(" · {n} reconfig."),
        ),
    ]);
    let enabled = o.iwps.iter().filter(|i| i.enabled).count();
    let groups = unusable::unusable_groups(&o.iwps, &o.centroid_path, 2);
    let unusable: usize = groups.iter().map(|g| g.count).sum();
    let mut iwps = format!("IWPs {} found, {enabled} enabled", o.iwps.len());
    if unusable > 0 {
        iwps.push_str(&format!(", {unusable} unusable (all in the IWP table, 2):"));
    }
    lines.push(row(iwps, Tone::Plain));
    for g in &groups {
        let named: Vec<String> = g
            .nearest
            .iter()
            .map(|b| format!("{} ↔ {}", b[0], b[1]))
            .collect();
        let more = if g.count > g.nearest.len() {
            ", …"
        } else {
            ""
        };
        lines.push(row(
            format!("  {} {}: {}{more}", g.count, g.reason, named.join(", ")),
            Tone::Warn,
        ));
    }
    for r in rows {
        let (mark, tone) = if r.ok {
            ("✓", Tone::Good)
        } else {
            ("✗", Tone::Bad)
        };
        let text = r.text.split_whitespace().collect::<Vec<_>>().join(" ");
        lines.push(vec![Cell::new(format!("{mark} "), tone), Cell::plain(text)]);
    }
    lines
}
