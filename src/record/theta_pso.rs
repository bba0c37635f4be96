//! θ-PSO in a recording: the swarm's progress on the `iteration` timeline
//! (cost terms, best path), and the outcome: planned paths, the UAVs on
//! `sim_time`, their clearances, reconfigurations, inspection passes and
//! violations.

use rerun::RecordingStream;

use super::paths::{self, theta_pso as at};
use super::{f32x3, log_moving_point, log_series, uav_color};
use crate::mission::Mission;
use crate::pipelines::Kind;
use crate::pipelines::theta_pso::CostTerms;
use crate::pipelines::theta_pso::ThetaPsoOutcome;

/// Picks one term out of the cost breakdown.
type CostTerm = fn(&CostTerms) -> f64;

/// One `send_columns` per series for all iterations gathered so far.
pub fn flush_iterations(
    stream: &RecordingStream,
    pending: &mut Vec<(usize, CostTerms, Vec<[f32; 3]>)>,
) {
    if pending.is_empty() {
        return;
    }
    let iterations =
        rerun::TimeColumn::new_sequence("iteration", pending.iter().map(|(i, _, _)| *i as i64));
    let series: [(&str, CostTerm); 5] = [
        (at::COST_TOTAL, |c| c.total),
        (at::COST_LENGTH, |c| c.length),
        (at::COST_OBSTACLE, |c| c.obstacle),
        (at::COST_ALTITUDE, |c| c.altitude),
        (at::COST_WAYPOINTS, |c| c.waypoints),
    ];
    for (path, term) in series {
        let values: Vec<f64> = pending.iter().map(|(_, c, _)| term(c)).collect();
        let _ = log_series(stream, path, &iterations, values);
    }
    let strips: Vec<Vec<[f32; 3]>> = pending.drain(..).map(|(_, _, p)| p).collect();
    if let Ok(columns) = rerun::LineStrips3D::update_fields()
        .with_strips(strips)
        .columns_of_unit_batches()
    {
        let _ = stream.send_columns(at::BEST_PATH, [iterations], columns);
    }
}

/// Each UAV's clearance over `sim_time`: the distance from its sphere of
/// radius r_Q + the safety margin to the nearest obstacle (terrain-raised),
/// 0 = the least verification accepts. The plot beside the scene on the
/// timeline the flight plays on.
fn log_clearances(
    stream: &RecordingStream,
    o: &ThetaPsoOutcome,
    m: &Mission,
) -> rerun::RecordingStreamResult<()> {
    let cylinders: Vec<_> = m.obstacles.iter().map(|ob| m.prism(ob)).collect();
    if cylinders.is_empty() {
        return Ok(());
    }
    for t in &o.trajectories {
        let entity = at::clearance(t.uav);
        stream.log_static(
            entity.as_str(),
            &rerun::SeriesLines::new()
                .with_colors([uav_color(t.uav)])
                .with_names([format!("UAV {}", t.uav + 1)]),
        )?;
        let times = rerun::TimeColumn::new_duration_secs("sim_time", t.samples.iter().map(|s| s.t));
        let values = t
            .samples
            .iter()
            .map(|s| {
                cylinders
                    .iter()
                    .map(|c| c.clearance(&s.position))
                    .fold(f64::INFINITY, f64::min)
                    - m.formation.least_clearance()
            })
            .collect();
        log_series(stream, &entity, &times, values)?;
    }
    Ok(())
}

/// The plan's centroid path, white and labelled: the outcome's and each
/// live revision's.
pub fn centroid_strip(o: &ThetaPsoOutcome) -> rerun::LineStrips3D {
    rerun::LineStrips3D::new([o.centroid_path.iter().map(f32x3).collect::<Vec<_>>()])
        .with_colors([rerun::Color::from_rgb(255, 255, 255)])
        .with_labels(["centroid"])
}

/// A θ-PSO outcome: planned paths, UAVs moving on `sim_time`, events, violations.
pub fn log_outcome(
    stream: &RecordingStream,
    o: &ThetaPsoOutcome,
    scene: Option<&Mission>,
) -> rerun::RecordingStreamResult<()> {
    if let Some(m) = scene {
        log_clearances(stream, o, m)?;
    }
    let events = paths::events(Kind::ThetaPso);
    stream.send_property(
        paths::root(Kind::ThetaPso),
        &rerun::TextDocument::from_markdown(format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\niterations: {}\n\
             feasible: {}\ncost J: {:.4}\nlength: {:.2} m\nduration: {:.2} s\nskyform: {}",
            o.mission,
            o.pipeline.slug(),
            o.seed,
            o.completion,
            o.iterations,
            o.feasible(),
            o.cost.total,
            o.path_length,
            o.duration,
            env!("CARGO_PKG_VERSION")
        )),
    )?;
    stream.log_static(at::CENTROID, &centroid_strip(o))?;
    log_trajectories(stream, o)?;
    log_reconfigurations(stream, o, &events)?;
    log_passes(stream, o, &events)?;
    log_violations(stream, o, &events)?;
    stream.reset_time();
    Ok(())
}

/// Each UAV's planned path (static), and the UAV with its velocity on `sim_time`.
fn log_trajectories(
    stream: &RecordingStream,
    o: &ThetaPsoOutcome,
) -> rerun::RecordingStreamResult<()> {
    for t in &o.trajectories {
        let color = uav_color(t.uav);
        let entity = at::plan(t.uav);
        stream.log_static(
            entity.as_str(),
            &rerun::LineStrips3D::new([t
                .samples
                .iter()
                .map(|s| f32x3(&s.position))
                .collect::<Vec<_>>()])
            .with_colors([color])
            .with_labels([format!("UAV {}", t.uav + 1)]),
        )?;
        let times = rerun::TimeColumn::new_duration_secs("sim_time", t.samples.iter().map(|s| s.t));
        let positions: Vec<[f32; 3]> = t.samples.iter().map(|s| f32x3(&s.position)).collect();
        let velocities: Vec<[f32; 3]> = t
            .samples
            .iter()
            .map(|s| {
                [
                    s.velocity.x as f32,
                    s.velocity.y as f32,
                    s.velocity.z as f32,
                ]
            })
            .collect();
        let uav = at::uav(t.uav);
        let style = rerun::Points3D::update_fields()
            .with_colors([color])
            .with_radii([0.5f32])
            .with_labels([format!("UAV {}", t.uav + 1)]);
        log_moving_point(stream, &uav, &times, style, positions.clone())?;
        let arrows = format!("{uav}/velocity");
        stream.log_static(
            arrows.as_str(),
            &rerun::Arrows3D::update_fields().with_colors([color]),
        )?;
        stream.send_columns(
            arrows.as_str(),
            [times],
            rerun::Arrows3D::update_fields()
                .with_origins(positions)
                .with_vectors(velocities)
                .columns_of_unit_batches()?,
        )?;
    }
    Ok(())
}

/// t1..t4 of each reconfiguration, as events on `sim_time`.
fn log_reconfigurations(
    stream: &RecordingStream,
    o: &ThetaPsoOutcome,
    events: &str,
) -> rerun::RecordingStreamResult<()> {
    for r in &o.reconfigurations {
        for (label, t) in [
            ("t1: transformation starts", r.t1),
            ("t2: shape complete", r.t2),
            ("t3: return starts", r.t3),
            ("t4: back to nominal", r.t4),
        ] {
            stream.set_duration_secs("sim_time", t);
            stream.log(
                events,
                &rerun::TextLog::new(format!("{} {}: {label}", r.shape.name(), r.obstacles()))
                    .with_level(rerun::TextLogLevel::INFO),
            )?;
        }
    }
    Ok(())
}

/// Inspection passes (eq. 8): the centroid's stretch, and when each begins and ends.
fn log_passes(
    stream: &RecordingStream,
    o: &ThetaPsoOutcome,
    events: &str,
) -> rerun::RecordingStreamResult<()> {
    for (pass, result) in o.passes.iter().zip(&o.verification.inspections) {
        let [t0, t1] = pass.time;
        let steps = 20;
        let stretch: Vec<[f32; 3]> = (0..=steps)
            .map(|k| f32x3(&o.centroid_at(t0 + (t1 - t0) * k as f64 / steps as f64)))
            .collect();
        stream.log_static(
            at::pass(&pass.obstacle).as_str(),
            &rerun::LineStrips3D::new([stretch])
                .with_colors([rerun::Color::from_rgb(230, 110, 230)])
                .with_radii([0.25f32])
                .with_labels([format!("inspection of {}", pass.obstacle)]),
        )?;
        for (label, t) in [("inspection pass starts", t0), ("inspection pass ends", t1)] {
            stream.set_duration_secs("sim_time", t);
            let achieved = result.distance.map_or_else(
                || "no stretch within the band".to_owned(),
                |[lo, hi]| {
                    format!(
                        "{:.1} m within the band, at {lo:.2}-{hi:.2} m",
                        result.achieved
                    )
                },
            );
            stream.log(
                events,
                &rerun::TextLog::new(format!("{label}: '{}' ({achieved})", pass.obstacle))
                    .with_level(if result.ok {
                        rerun::TextLogLevel::INFO
                    } else {
                        rerun::TextLogLevel::WARN
                    }),
            )?;
        }
    }
    Ok(())
}

/// Each violation found by verification: a red point and a warning event.
fn log_violations(
    stream: &RecordingStream,
    o: &ThetaPsoOutcome,
    events: &str,
) -> rerun::RecordingStreamResult<()> {
    for v in &o.verification.violations {
        stream.set_duration_secs("sim_time", v.location.time);
        let other = v.location.other.as_deref().unwrap_or("");
        stream.log(
            at::VIOLATIONS,
            &rerun::Points3D::new([f32x3(&v.location.position)])
                .with_colors([rerun::Color::from_rgb(255, 0, 0)])
                .with_radii([0.8f32])
                .with_labels([format!("{} {:.2} {other}", v.check, v.value)]),
        )?;
        stream.log(
            events,
            &rerun::TextLog::new(format!(
                "violation: UAV {} {} = {:.3} {other}",
                v.location.uav + 1,
                v.check,
                v.value
            ))
            .with_level(rerun::TextLogLevel::WARN),
        )?;
    }
    Ok(())
}
