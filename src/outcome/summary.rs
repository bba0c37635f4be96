//! The human summary of each pipeline's outcome (`skyform run`). Vehicles
//! are numbered from 1 here as everywhere a person reads them (UAV 1,
//! aircraft 1, agent 1); the JSON keeps the 0-based indices.

use super::Verdict;
use crate::pipelines::flatlo::FlatloOutcome;
use crate::pipelines::fleet::{Closest, Deviation, FleetOutcome, FormationError, Other};
use crate::pipelines::theta_pso::{ThetaPsoOutcome, unusable};

/// How many unusable IWPs the summary names (the nearest the route).
const NAMED_UNUSABLE: usize = 3;

/// The human summary of a θ-PSO outcome: the verdict and the first failing
/// check first, then the run, the cost, the route and the IWPs (the unusable
/// ones counted by reason and the few nearest the path named; all of them
/// when `verbose`), the reconfigurations and the verification table.
pub fn theta_pso(o: &ThetaPsoOutcome, verbose: bool) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(s, "θ-PSO plan for \"{}\" (seed {})", o.mission, o.seed);
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
        o.completion, o.iterations, o.evaluations
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
        format!(
            " (a large site, searched at {cell:.2} m cells: a way narrower than that may be missed)"
        )
    });
    let _ = writeln!(
        s,
        "  route        corridor {:.1} m; the plan is {source}{coarse}",
        o.route_length
    );
    iwps(&mut s, o, verbose);
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
        let worst = check.worst.map_or_else(
            || "n/a".to_owned(),
            crate::pipelines::theta_pso::verify::figure,
        );
        let at = check.at.as_ref().map_or_else(String::new, |a| {
            let other = a
                .other
                .as_deref()
                .map_or_else(String::new, |o| format!(" vs {o}"));
            format!("  (UAV {} at t = {:.1} s{other})", a.uav + 1, a.time)
        });
        rows.push(VerificationRow {
            ok: check.ok,
            text: format!(
                "{:<32} worst {worst:>9} {} {}{at}",
                check.name,
                check.relation,
                crate::pipelines::theta_pso::verify::limit_figure(check.limit)
            ),
        });
    }
    for i in &o.verification.inspections {
        let band = i.distance.map_or_else(
            || "never within the band".to_owned(),
            |[lo, hi]| format!("facing UAV at {lo:.2}-{hi:.2} m"),
        );
        rows.push(VerificationRow {
            ok: i.ok,
            text: format!(
                "inspection of {:<19} {:>5.1} m ≥ {} m within [{}, {}] m, {band}",
                format!("'{}'", i.obstacle),
                i.achieved,
                i.required,
                i.band[0],
                i.band[1]
            ),
        });
    }
    rows
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

/// The human summary of a FLATLO outcome.
pub fn flatlo(o: &FlatloOutcome) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "FLATLO transition for \"{}\" (seed {})",
        o.mission, o.seed
    );
    let _ = writeln!(
        s,
        "  run          {:?}, {:.1} s simulated; every aircraft on the line at t = {:.1} s",
        o.completion, o.duration, o.arrival_time
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

/// The human summary of a fleet outcome.
pub fn fleet(o: &FleetOutcome, verdict: &Verdict) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(s, "Fleet for \"{}\" (seed {})", o.mission, o.seed);
    let _ = writeln!(
        s,
        "  run          {:?}, {:.1} s simulated, {} agents",
        o.completion,
        o.duration,
        o.agents.len()
    );
    for (k, t) in o.targets.iter().enumerate() {
        let reached = match (t.converged_after, &t.end) {
            (Some(a), _) => format!("formed {a:.2} s after it appeared"),
            (None, Some(e)) => format!("NOT REACHED: {}", shortfall(e)),
            (None, None) => "NOT REACHED (no sample while it was in force)".to_owned(),
        };
        let _ = writeln!(
            s,
            "  target {:<5} ({:.2}, {:.2}) at t = {:.1} s: {reached}",
            k + 1,
            t.position.x,
            t.position.y,
            t.time
        );
    }
    for d in &o.distances {
        let last = d.values.last().copied().unwrap_or(f64::NAN);
        let min = d.values.iter().copied().fold(f64::INFINITY, f64::min);
        let _ = writeln!(
            s,
            "  pair {:>2}-{:<3}   final {last:.3} m (desired {:.3}), min {min:.3} m",
            d.a + 1,
            d.b + 1,
            d.desired
        );
    }
    let agents = o.closest_agents.as_ref().map_or("-".to_owned(), |c| {
        let lost = o
            .lost
            .iter()
            .find(|l| l.time <= c.time && (l.agent == c.a || c.b == Other::Agent(l.agent)))
            .map_or_else(String::new, |l| {
                format!(", agent {} where it was last heard", l.agent + 1)
            });
        format!(
            "agents {} and {} at {:.3} m (t = {:.2} s{lost})",
            c.a + 1,
            c.b,
            c.distance,
            c.time
        )
    });
    let obstacle = o.closest_obstacle.as_ref().map_or("-".to_owned(), |c| {
        format!(
            "agent {} to {} at {:.3} m (t = {:.2} s)",
            c.a + 1,
            c.b,
            c.distance,
            c.time
        )
    });
    let _ = writeln!(
        s,
        "  closest      {agents}; safety distance c = {} m",
        o.safety_distance
    );
    let _ = writeln!(s, "  obstacles    {obstacle}");
    // The network's traffic, when it is not the ideal one.
    let (sent, received, lost) = o.agents.iter().fold((0, 0, 0), |t, a| {
        (
            t.0 + a.network.sent,
            t.1 + a.network.received,
            t.2 + a.network.lost,
        )
    });
    let worst = o
        .agents
        .iter()
        .map(|a| a.network.worst_age)
        .fold(0.0, f64::max);
    if lost > 0 || worst > 0.0 {
        let mean =
            o.agents.iter().map(|a| a.network.mean_age).sum::<f64>() / o.agents.len().max(1) as f64;
        let _ = writeln!(
            s,
            "  network      {sent} sent, {received} heard, {lost} lost ({:.1} %); \
             neighbour information {mean:.3} s old on average, {worst:.3} s at worst",
            100.0 * lost as f64 / (lost + received).max(1) as f64
        );
    }
    if let Some(d) = &o.distributed {
        let rounds = if d.round_mean > 0.0 {
            format!(
                "round {:.3} ms mean, {:.3} ms worst; ",
                1e3 * d.round_mean,
                1e3 * d.round_worst
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "  distributed  {} agent process(es) over Zenoh, {} clock; ready in {:.2} s; \
             {rounds}{} states received by the coordinator",
            d.processes, d.clock, d.startup, d.messages
        );
    }
    // Per agent, when its messages went over a transport or a model.
    if o.distributed.is_some() || lost > 0 || worst > 0.0 {
        for a in &o.agents {
            let n = &a.network;
            let _ = writeln!(
                s,
                "  agent {:<6} {} sent, {} heard, {} lost; neighbour information {:.3} s old on average, {:.3} s at worst",
                a.index + 1,
                n.sent,
                n.received,
                n.lost,
                n.mean_age,
                n.worst_age
            );
        }
    }
    for l in &o.lost {
        let _ = writeln!(
            s,
            "  LOST         agent {} at t = {:.2} s: {}; the others flew on (its samples end there)",
            l.agent + 1,
            l.time,
            l.reason
        );
    }
    let decisions: usize = o.agents.iter().map(|a| a.decisions).sum();
    let evaluations: usize = o.agents.iter().map(|a| a.evaluations).sum();
    let _ = writeln!(
        s,
        "  PSO effort   {decisions} decisions{}, {evaluations} cost evaluations ({:.0} per agent per second)",
        decisions_by_agent(o),
        evaluations as f64 / (o.agents.len().max(1) as f64 * o.duration.max(1e-9))
    );
    // The pass rule is `Outcome::verdict`'s, written once.
    let verdict = match verdict {
        Verdict::Passed => "PASS",
        Verdict::Failed(_) => "FAIL",
        Verdict::Cancelled => "CANCELLED",
    };
    let _ = writeln!(s, "  result       {verdict}");
    s
}

/// The decisions of each agent, when they differ (an agent on a clock of its
/// own, or deciding at once near a neighbour): ` (201 / 67 / 201 by agent)`,
/// the least and the most for a fleet of more than twelve.
fn decisions_by_agent(o: &FleetOutcome) -> String {
    let counts: Vec<usize> = o.agents.iter().map(|a| a.decisions).collect();
    let (Some(least), Some(most)) = (counts.iter().min(), counts.iter().max()) else {
        return String::new();
    };
    if least == most {
        String::new()
    } else if counts.len() <= 12 {
        let each: Vec<String> = counts.iter().map(|d| d.to_string()).collect();
        format!(" ({} by agent)", each.join(" / "))
    } else {
        format!(" ({least} to {most} by agent)")
    }
}

/// How far a formation stood from its target, for `NOT REACHED`: the
/// distance furthest from its desired value between two agents and to the
/// target (`d14 5.159 m, want 6.000 ± 0.300`), and the centre's offset.
pub fn shortfall(e: &FormationError) -> String {
    let mut parts: Vec<String> = Vec::new();
    for d in [e.pair, e.to_target].iter().flatten() {
        parts.push(deviation(d));
    }
    parts.push(format!("centre {:.3} m from the target", e.centre_offset));
    format!("at t = {:.1} s {}", e.time, parts.join("; "))
}

/// One distance against its desired value: `d14 5.159 m (want 6.000 ±
/// 0.300)` between agents, `agent 2 1.250 m from the target (want …)`.
pub fn deviation(d: &Deviation) -> String {
    let what = match d.b {
        Some(b) => format!("d{}{} {:.3} m", d.a + 1, b + 1, d.distance),
        None => format!("agent {} {:.3} m from the target", d.a + 1, d.distance),
    };
    format!("{what} (want {:.3} ± {:.3})", d.desired, d.tolerance)
}

/// Items as a list people read: `3`, `3 and 4`, `2, 3 and 5`.
fn and_list(items: &[String]) -> String {
    match items.split_last() {
        None => String::new(),
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
    }
}

/// Every lost agent, when and why, in one sentence; None when none was.
pub fn lost_agents(o: &FleetOutcome) -> Option<String> {
    let first = o.lost.first()?;
    let agents: Vec<String> = o.lost.iter().map(|l| (l.agent + 1).to_string()).collect();
    let together = o.lost.iter().all(|l| l.step == first.step);
    Some(if o.lost.len() == 1 {
        format!(
            "agent {} was lost at t = {:.2} s ({})",
            first.agent + 1,
            first.time,
            first.reason
        )
    } else if together {
        format!(
            "agents {} were lost at t = {:.2} s ({})",
            and_list(&agents),
            first.time,
            first.reason
        )
    } else {
        let each: Vec<String> = o
            .lost
            .iter()
            .map(|l| format!("{} at t = {:.2} s", l.agent + 1, l.time))
            .collect();
        format!("agents {} were lost ({})", and_list(&each), first.reason)
    })
}

/// The closest approach of two agents that broke c, in words: a lost
/// agent is named as where it was last heard.
pub fn too_close(o: &FleetOutcome, c: &Closest) -> String {
    let b = match c.b {
        Other::Agent(b) => b,
        Other::Obstacle(_) => return format!("agent {} came too close to {}", c.a + 1, c.b),
    };
    let lost_before = |agent: usize| o.lost.iter().any(|l| l.agent == agent && l.time <= c.time);
    let pair = match (lost_before(c.a), lost_before(b)) {
        (false, true) => format!(
            "agent {} came within {:.3} m of where lost agent {} was last heard",
            c.a + 1,
            c.distance,
            b + 1
        ),
        (true, false) => format!(
            "agent {} came within {:.3} m of where lost agent {} was last heard",
            b + 1,
            c.distance,
            c.a + 1
        ),
        _ => format!(
            "agents {} and {} came {:.3} m apart",
            c.a + 1,
            b + 1,
            c.distance
        ),
    };
    format!(
        "{pair} (t = {:.2} s), closer than the safety distance c = {} m",
        c.time, o.safety_distance
    )
}
