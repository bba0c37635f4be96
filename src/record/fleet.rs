//! The fleet in a recording.

use rerun::RecordingStream;

use super::paths::{self, fleet as at};
use super::{f32x3, log_closest, log_moving_point, log_series, uav_color};
use crate::pipelines::Kind;
use crate::pipelines::fleet::FleetOutcome;

/// A fleet outcome: agents with trails and their references on `sim_time`,
/// detection ranges, targets, the inter-agent distances (Fig. 13) as series.
pub fn log_outcome(stream: &RecordingStream, o: &FleetOutcome) -> rerun::RecordingStreamResult<()> {
    let events = paths::events(Kind::Fleet);
    stream.send_property(
        paths::root(Kind::Fleet),
        &rerun::TextDocument::from_markdown(format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\nagents: {}\n\
             kept apart: {}\nconverged: {}\nskyform: {}",
            o.mission,
            o.pipeline.slug(),
            o.seed,
            o.completion,
            o.agents.len(),
            o.kept_apart(),
            o.converged(),
            env!("CARGO_PKG_VERSION")
        )),
    )?;
    let times = rerun::TimeColumn::new_duration_secs("sim_time", o.times.iter().copied());
    for a in &o.agents {
        // A lost agent's samples end where it was lost.
        let times = if a.samples.len() == o.times.len() {
            times.clone()
        } else {
            rerun::TimeColumn::new_duration_secs("sim_time", a.samples.iter().map(|s| s.t))
        };
        let color = uav_color(a.index);
        let positions: Vec<[f32; 3]> = a.samples.iter().map(|s| f32x3(&s.position)).collect();
        let references: Vec<[f32; 3]> = a.samples.iter().map(|s| f32x3(&s.reference)).collect();
        stream.log_static(
            at::agent("trails", a.index),
            &rerun::LineStrips3D::new([positions.clone()]).with_colors([color]),
        )?;
        let agent = at::agent("agents", a.index);
        let style = rerun::Points3D::update_fields()
            .with_colors([color])
            .with_radii([0.15f32])
            .with_labels([format!("agent {}", a.index + 1)]);
        log_moving_point(stream, &agent, &times, style, positions.clone())?;
        let style = rerun::Points3D::update_fields()
            .with_colors([rerun::Color::from_rgb(200, 200, 200)])
            .with_radii([0.05f32]);
        let reference = at::agent("references", a.index);
        log_moving_point(stream, &reference, &times, style, references)?;
    }
    // Named from 1, as the agents are everywhere a person reads.
    for d in &o.distances {
        let entity = at::distance(d.a, d.b);
        stream.log_static(
            entity.as_str(),
            &rerun::SeriesLines::new().with_names([format!("agents {}–{}", d.a + 1, d.b + 1)]),
        )?;
        log_series(stream, &entity, &times, d.values.clone())?;
    }
    if !o.distances.is_empty() {
        let c = vec![o.safety_distance; o.times.len()];
        stream.log_static(
            at::SAFETY_C,
            &rerun::SeriesLines::new().with_names(["c (safety distance)"]),
        )?;
        log_series(stream, at::SAFETY_C, &times, c)?;
    }
    let z = o
        .agents
        .first()
        .and_then(|a| a.samples.first())
        .map_or(0.0, |s| s.position.z as f32);
    for (k, t) in o.targets.iter().enumerate() {
        stream.set_duration_secs("sim_time", t.time);
        stream.log(
            at::TARGET,
            &rerun::Points3D::new([[t.position.x as f32, t.position.y as f32, z]])
                .with_colors([rerun::Color::from_rgb(255, 215, 0)])
                .with_radii([0.1f32])
                .with_labels([format!("target {}", k + 1)]),
        )?;
        let text = match t.converged_after {
            Some(after) => format!(
                "target {} appears; formation reached {after:.2} s later",
                k + 1
            ),
            None => format!("target {} appears; formation NOT reached", k + 1),
        };
        stream.log(events.as_str(), &rerun::TextLog::new(text))?;
    }
    for (label, closest) in [
        ("agents", &o.closest_agents),
        ("obstacle", &o.closest_obstacle),
    ] {
        if let Some(c) = closest {
            log_closest(
                stream,
                events.as_str(),
                c.time,
                c.distance < o.safety_distance,
                format!(
                    "closest approach ({label}): agent {} and {} at {:.3} m",
                    c.a + 1,
                    c.b,
                    c.distance
                ),
            )?;
        }
    }
    log_network(stream, o)?;
    stream.reset_time();
    Ok(())
}

/// The network: at each sample, a line between every two agents that heard
/// each other within l (`fleet/links`), and the agents lost on the way
/// (where and when, on the events log and as a marker).
fn log_network(stream: &RecordingStream, o: &FleetOutcome) -> rerun::RecordingStreamResult<()> {
    let position = |agent: usize, k: usize| {
        o.agents
            .get(agent)
            .and_then(|a| a.samples.get(k))
            .map(|s| f32x3(&s.position))
    };
    for (k, (t, pairs)) in o.times.iter().zip(&o.links).enumerate() {
        let strips: Vec<Vec<[f32; 3]>> = pairs
            .iter()
            .filter_map(|&(i, j)| Some(vec![position(i, k)?, position(j, k)?]))
            .collect();
        stream.set_duration_secs("sim_time", *t);
        stream.log(
            at::LINKS,
            &rerun::LineStrips3D::new(strips)
                .with_colors([rerun::Color::from_unmultiplied_rgba(120, 200, 255, 140)])
                .with_radii([0.01f32]),
        )?;
    }
    let events = paths::events(Kind::Fleet);
    for l in &o.lost {
        stream.set_duration_secs("sim_time", l.time);
        stream.log(
            events.as_str(),
            &rerun::TextLog::new(format!("agent {} lost: {}", l.agent + 1, l.reason))
                .with_level(rerun::TextLogLevel::WARN),
        )?;
        if let Some(last) = o.agents.get(l.agent).and_then(|a| a.samples.last()) {
            stream.log(
                at::agent("lost", l.agent),
                &rerun::Points3D::new([f32x3(&last.position)])
                    .with_colors([rerun::Color::from_rgb(255, 60, 60)])
                    .with_radii([0.2f32])
                    .with_labels([format!("agent {} lost", l.agent + 1)]),
            )?;
        }
    }
    Ok(())
}
