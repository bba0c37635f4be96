//! FLATLO in a recording.

use rerun::RecordingStream;

use super::paths::{self, flatlo::aircraft};
use super::{f32x3, log_closest, log_moving_point, log_series, uav_color};
use crate::pipelines::Kind;
use crate::pipelines::flatlo::FlatloOutcome;

/// A FLATLO outcome: references and flown paths per aircraft, the aircraft
/// on `sim_time`, their airspeed, γ, χ and controls as series, the closest
/// approaches as events.
pub fn log_outcome(
    stream: &RecordingStream,
    o: &FlatloOutcome,
) -> rerun::RecordingStreamResult<()> {
    let events = paths::events(Kind::Flatlo);
    let min_separation = o.verification.as_ref().map_or(0.0, |v| v.min_separation);
    stream.send_property(
        paths::root(Kind::Flatlo),
        &rerun::TextDocument::from_markdown(format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\naircraft: {}\n\
             arrival: {:.1} s\nduration: {:.1} s\nclosest: {}\nspacing error: {}\n\
             passed: {}\nskyform: {}",
            o.mission,
            o.pipeline.slug(),
            o.seed,
            o.completion,
            o.aircraft.len(),
            o.arrival_time,
            o.duration,
            o.closest.map_or("-".to_owned(), |c| format!(
                "{} and {} at {:.0} m",
                c.a + 1,
                c.b + 1,
                c.min_distance
            )),
            o.verification
                .as_ref()
                .map_or("-".to_owned(), |v| format!("{:.3e}", v.max_spacing_error)),
            o.verification
                .as_ref()
                .map_or("no verdict (cancelled)".to_owned(), |v| v
                    .passed
                    .to_string()),
            env!("CARGO_PKG_VERSION")
        )),
    )?;
    for a in &o.aircraft {
        let color = uav_color(a.index);
        stream.log_static(
            aircraft("reference", a.index),
            &rerun::LineStrips3D::new([a
                .reference
                .iter()
                .map(|s| f32x3(&s.position))
                .collect::<Vec<_>>()])
            .with_colors([rerun::Color::from_rgb(170, 170, 170)])
            .with_labels([format!("reference {}", a.index)]),
        )?;
        stream.log_static(
            aircraft("flown", a.index),
            &rerun::LineStrips3D::new([a
                .flown
                .iter()
                .map(|s| f32x3(&s.position))
                .collect::<Vec<_>>()])
            .with_colors([color])
            .with_labels([format!("aircraft {}", a.index + 1)]),
        )?;
        let times = rerun::TimeColumn::new_duration_secs("sim_time", a.flown.iter().map(|s| s.t));
        let entity = aircraft("aircraft", a.index);
        let style = rerun::Points3D::update_fields()
            .with_colors([color])
            .with_radii([150.0f32])
            .with_labels([format!("aircraft {}", a.index + 1)]);
        let positions = a.flown.iter().map(|s| f32x3(&s.position)).collect();
        log_moving_point(stream, &entity, &times, style, positions)?;
        type Series = fn(&crate::pipelines::flatlo::FlownSample) -> f64;
        let series: [(&str, Series); 6] = [
            ("airspeed", |s| s.airspeed),
            ("gamma_deg", |s| s.gamma.to_degrees()),
            ("chi_deg", |s| s.chi.to_degrees()),
            ("thrust", |s| s.controls.thrust),
            ("load_factor", |s| s.controls.load_factor),
            ("bank_deg", |s| s.controls.bank.to_degrees()),
        ];
        for (quantity, value) in series {
            let entity = aircraft(quantity, a.index);
            log_series(stream, &entity, &times, a.flown.iter().map(value).collect())?;
        }
    }
    stream.set_duration_secs("sim_time", o.arrival_time);
    stream.log(
        events.as_str(),
        &rerun::TextLog::new(format!(
            "every aircraft on the longitudinal line at t = {:.1} s",
            o.arrival_time
        ))
        .with_level(rerun::TextLogLevel::INFO),
    )?;
    let closest_only: Vec<_> = o.closest.into_iter().collect();
    let pairs = if o.pairs.is_empty() {
        &closest_only
    } else {
        &o.pairs
    };
    for p in pairs {
        log_closest(
            stream,
            events.as_str(),
            p.time,
            p.min_distance < min_separation,
            format!(
                "closest approach of aircraft {} and {}: {:.0} m",
                p.a + 1,
                p.b + 1,
                p.min_distance
            ),
        )?;
    }
    // The first limit of the flight broken, at its time.
    if let Some(v) = o.verification.as_ref().and_then(|v| v.violation) {
        stream.set_duration_secs("sim_time", v.time);
        stream.log(
            events.as_str(),
            &rerun::TextLog::new(format!("not flyable: {}", v.describe()))
                .with_level(rerun::TextLogLevel::WARN),
        )?;
    }
    stream.reset_time();
    Ok(())
}
