//! The fleet in a recording (`pipelines::sketch`): agents with trails and
//! their references on `sim_time`, targets, the inter-agent distances
//! (Fig. 13) as series, the network's links and the agents lost.

use nalgebra::Point3;

use super::FleetOutcome;
use crate::pipelines::sketch::{Note, Plot, Sketch, Style};

/// The fleet's entity paths, per agent (0-based, as `agent_0`).
pub mod paths {
    /// The run's property and the root of its entities.
    pub const ROOT: &str = "fleet";
    /// Events on `sim_time` (targets, closest approaches, agents lost).
    pub const EVENTS: &str = "fleet/events";
    pub const DISTANCES: &str = "fleet/distances";
    pub const SAFETY_C: &str = "fleet/distances/safety_c";
    pub const TARGET: &str = "fleet/target";
    /// At each sample, the agents that heard each other.
    pub const LINKS: &str = "fleet/links";

    /// `part` is `trails`, `agents`, `references` or `lost`.
    pub fn agent(part: &str, index: usize) -> String {
        format!("fleet/{part}/agent_{index}")
    }

    /// The distance of agents `a` and `b` (0-based), named from 1.
    pub fn distance(a: usize, b: usize) -> String {
        format!("{DISTANCES}/{}_{}", a + 1, b + 1)
    }
}

/// The plots beside the scene.
pub const PLOTS: &[&[Plot]] = &[&[Plot {
    title: "inter-agent distances, m (Fig. 13)",
    path: paths::DISTANCES,
}]];

/// A fleet outcome.
pub fn sketch(o: &FleetOutcome, out: &mut dyn Sketch) {
    out.property(
        paths::ROOT,
        format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\nagents: {}\n\
             kept apart: {}\nconverged: {}\nskyform: {}",
            o.header.mission,
            o.header.pipeline.words().slug,
            o.header.seed,
            o.header.completion,
            o.agents.len(),
            o.kept_apart(),
            o.converged(),
            env!("CARGO_PKG_VERSION")
        ),
    );
    for a in &o.agents {
        // A lost agent's samples end where it was lost.
        let times: Vec<f64> = a.samples.iter().map(|s| s.t).collect();
        let positions: Vec<Point3<f64>> = a.samples.iter().map(|s| s.position).collect();
        let references: Vec<Point3<f64>> = a.samples.iter().map(|s| s.reference).collect();
        out.strips(
            &paths::agent("trails", a.index),
            vec![positions.clone()],
            Style::vehicle(a.index),
        );
        out.moving_point(
            &paths::agent("agents", a.index),
            &times,
            &positions,
            Style::vehicle(a.index)
                .radius(0.15)
                .label(format!("agent {}", a.index + 1)),
        );
        out.moving_point(
            &paths::agent("references", a.index),
            &times,
            &references,
            Style::rgb([200, 200, 200]).radius(0.05),
        );
    }
    // Named from 1, as the agents are everywhere a person reads.
    for d in &o.distances {
        out.series(
            &paths::distance(d.a, d.b),
            &o.times,
            d.values.clone(),
            Some(Style::default().label(format!("agents {}–{}", d.a + 1, d.b + 1))),
        );
    }
    if !o.distances.is_empty() {
        out.series(
            paths::SAFETY_C,
            &o.times,
            vec![o.safety_distance; o.times.len()],
            Some(Style::default().label("c (safety distance)")),
        );
    }
    let z = o
        .agents
        .first()
        .and_then(|a| a.samples.first())
        .map_or(0.0, |s| s.position.z);
    for (k, t) in o.targets.iter().enumerate() {
        // A target of one point per agent: its points; else the target.
        let points = if t.assigned.is_empty() {
            vec![Point3::new(t.position.x, t.position.y, z)]
        } else {
            t.assigned
                .iter()
                .map(|q| Point3::new(q.x, q.y, z))
                .collect()
        };
        out.points_at(
            paths::TARGET,
            t.time,
            points,
            Style::rgb([255, 215, 0])
                .radius(0.1)
                .label(format!("target {}", k + 1)),
        );
        let text = match t.converged_after {
            Some(after) => format!(
                "target {} appears; formation reached {after:.2} s later",
                k + 1
            ),
            None => format!("target {} appears; formation NOT reached", k + 1),
        };
        out.event(paths::EVENTS, t.time, text, Note::Plain);
    }
    for (label, closest) in [
        ("agents", &o.closest_agents),
        ("obstacle", &o.closest_obstacle),
    ] {
        if let Some(c) = closest {
            out.event(
                paths::EVENTS,
                c.time,
                format!(
                    "closest approach ({label}): agent {} and {} at {:.3} m",
                    c.a + 1,
                    c.b,
                    c.distance
                ),
                Note::closest(c.distance < o.safety_distance),
            );
        }
    }
    network(o, out);
}

/// The network: at each sample, a line between every two agents that heard
/// each other within l (`fleet/links`), and the agents lost on the way
/// (where and when, on the events log and as a marker).
fn network(o: &FleetOutcome, out: &mut dyn Sketch) {
    let position = |agent: usize, k: usize| {
        o.agents
            .get(agent)
            .and_then(|a| a.samples.get(k))
            .map(|s| s.position)
    };
    for (k, (t, pairs)) in o.times.iter().zip(&o.links).enumerate() {
        let strips: Vec<Vec<Point3<f64>>> = pairs
            .iter()
            .filter_map(|&(i, j)| Some(vec![position(i, k)?, position(j, k)?]))
            .collect();
        out.strips_at(
            paths::LINKS,
            *t,
            strips,
            Style {
                color: Some([120, 200, 255, 140]),
                radius: Some(0.01),
                label: None,
            },
        );
    }
    for l in &o.lost {
        out.event(
            paths::EVENTS,
            l.time,
            format!("agent {} lost: {}", l.agent + 1, l.reason),
            Note::Warn,
        );
        if let Some(last) = o.agents.get(l.agent).and_then(|a| a.samples.last()) {
            out.points_at(
                &paths::agent("lost", l.agent),
                l.time,
                vec![last.position],
                Style::rgb([255, 60, 60])
                    .radius(0.2)
                    .label(format!("agent {} lost", l.agent + 1)),
            );
        }
    }
}
