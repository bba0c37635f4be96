//! The human summary of a fleet outcome (`skyform run fleet`) and the
//! words its verdict and the designer's tables share. Agents are numbered
//! from 1 here as everywhere a person reads them, the JSON too.

use super::{Closest, Deviation, FleetOutcome, FormationError, Other};
use crate::pipelines::Verdict;
use crate::pipelines::table::{Cell, Row, Tone, row};

/// The human summary of a fleet outcome.
///
/// Long (~185 lines) because it writes the summary's lines top to bottom (run, targets and
/// their assignments and shortfalls, the survivors judged,
/// pairs, closest, network, distributed, per-agent traffic, lost agents, effort, result),
/// each a few lines of formatting in the order printed.
pub fn fleet(o: &FleetOutcome, verdict: &Verdict) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Fleet for \"{}\" (seed {})",
        o.header.mission, o.header.seed
    );
    let _ = writeln!(
        s,
        "  run          {:?}, {:.1} s simulated, {} agents",
        o.header.completion,
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
        if !t.assignment.is_empty() {
            let each: Vec<String> = t
                .assignment
                .iter()
                .zip(&t.assigned)
                .enumerate()
                .map(|(i, (j, p))| format!("{} → point {} ({:.1}, {:.1})", i + 1, j + 1, p.x, p.y))
                .collect();
            let _ = writeln!(s, "    assigned   agent {}", each.join(", "));
        }
        for short in o.short.iter().filter(|f| f.target == k + 1) {
            let _ = writeln!(
                s,
                "    agent {:<4} {:.2} m short: {}",
                short.agent + 1,
                short.short_by,
                short.why
            );
        }
    }
    if !o.lost.is_empty() {
        let names: Vec<String> = o.lost.iter().map(|l| (l.agent + 1).to_string()).collect();
        let _ = writeln!(
            s,
            "  judged       the {} surviving agent(s): agent {} lost, left out of the formation",
            o.agents.len() - o.lost.len(),
            names.join(", ")
        );
    }
    let lost_one = |i: usize| o.lost.iter().find(|l| l.agent == i);
    for d in &o.distances {
        let min = d.values.iter().copied().fold(f64::INFINITY, f64::min);
        // A pair with a lost agent has no final distance: it is no longer there.
        let end = match lost_one(d.a).or_else(|| lost_one(d.b)) {
            Some(l) => format!(
                "agent {} lost at t = {:.1} s (no final distance)",
                l.agent + 1,
                l.time
            ),
            None => format!(
                "final {:.3} m (desired {:.3})",
                d.values.last().copied().unwrap_or(f64::NAN),
                d.desired
            ),
        };
        let _ = writeln!(
            s,
            "  pair {:>2}-{:<3}   {end}, min {min:.3} m",
            d.a + 1,
            d.b + 1
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
        Verdict::Passed => "PASS".to_owned(),
        Verdict::Failed(why) => format!("FAIL: {why}"),
        Verdict::Cancelled => "CANCELLED".to_owned(),
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

/// The fleet's result in the designer's jobs panel: the verdict on the
/// safety distance, each target's formation time, the closest approaches,
/// the final inter-agent distances, the processes, the agents lost, the
/// PSO effort.
pub fn table(o: &FleetOutcome) -> Vec<Row> {
    let safe = o.kept_apart() && o.obstacles_clear();
    let mut lines = vec![vec![
        Cell::plain(format!(
            "{} agents · {:.0} s · ",
            o.agents.len(),
            o.duration
        )),
        if safe {
            Cell::new("✓ safety distance kept", Tone::Good)
        } else {
            Cell::new("✗ SAFETY DISTANCE LOST", Tone::BadStrong)
        },
    ]];
    for (k, t) in o.targets.iter().enumerate() {
        let text = match t.converged_after {
            Some(a) => format!(
                "target {} (t {:.0} s): formed after {a:.1} s",
                k + 1,
                t.time
            ),
            None => format!(
                "target {} (t {:.0} s): NOT formed{}",
                k + 1,
                t.time,
                t.end
                    .as_ref()
                    .and_then(|e| e.pair.filter(|d| !d.within()).or(e.to_target))
                    .map_or_else(String::new, |d| format!(": {}", deviation(&d)))
            ),
        };
        let tone = if t.converged_after.is_some() {
            Tone::Plain
        } else {
            Tone::Bad
        };
        lines.push(row(text, tone));
    }
    if let Some(c) = &o.closest_agents {
        lines.push(row(
            format!(
                "closest agents {}-{}: {:.3} m at {:.1} s (c {})",
                c.a + 1,
                c.b,
                c.distance,
                c.time,
                o.safety_distance
            ),
            Tone::Plain,
        ));
    }
    if let Some(c) = &o.closest_obstacle {
        lines.push(row(
            format!(
                "closest obstacle: agent {} to {} {:.3} m",
                c.a + 1,
                c.b,
                c.distance
            ),
            Tone::Plain,
        ));
    }
    for d in o.distances.iter().take(6) {
        lines.push(row(
            format!(
                "d{}{} final {:.3} m (want {:.3})",
                d.a + 1,
                d.b + 1,
                d.values.last().copied().unwrap_or(f64::NAN),
                d.desired
            ),
            Tone::Plain,
        ));
    }
    if let Some(d) = &o.distributed {
        lines.push(row(
            format!(
                "{} agent process(es) over Zenoh, {}{}",
                d.processes,
                d.clock,
                if d.round_mean > 0.0 {
                    format!(" · round {:.2} ms", 1e3 * d.round_mean)
                } else {
                    String::new()
                }
            ),
            Tone::Plain,
        ));
    }
    for l in &o.lost {
        lines.push(row(
            format!(
                "agent {} LOST at {:.1} s: {}",
                l.agent + 1,
                l.time,
                l.reason
            ),
            Tone::BadStrong,
        ));
    }
    let evaluations: usize = o.agents.iter().map(|a| a.evaluations).sum();
    lines.push(row(
        format!("PSO: {evaluations} cost evaluations · , . > replay"),
        Tone::Plain,
    ));
    lines
}
