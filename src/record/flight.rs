//! A flight check in a recording (`skyform fly --rrd`): each vehicle's plan
//! as written, the p99 envelope of its cross-track error as a tube (a ball
//! of that radius every fifth of a second along the plan), the worst flights
//! as flown (and flights flown again from their inputs), and the report.

use rerun::RecordingStream;

use super::paths::flight as at;
use super::{f32x3, uav_color};
use crate::flight::Recording;

/// Samples between the envelope's balls (at 20 Hz: five a second).
const ENVELOPE_EVERY: usize = 4;

pub fn log_flights(
    stream: &RecordingStream,
    rec: &Recording,
    report: &str,
) -> rerun::RecordingStreamResult<()> {
    stream.log_static(at::REPORT, &rerun::TextDocument::new(report))?;
    for (v, (vehicle, written)) in rec.written.iter().enumerate() {
        let color = uav_color(vehicle - 1);
        let line: Vec<[f32; 3]> = written.iter().map(f32x3).collect();
        stream.log_static(
            at::written(*vehicle),
            &rerun::LineStrips3D::new([line])
                .with_colors([color])
                .with_labels([format!("UAV {vehicle} as written")]),
        )?;
        let envelope = rec.envelope.get(v).map_or(&[][..], Vec::as_slice);
        let (centres, radii): (Vec<[f32; 3]>, Vec<f32>) = written
            .iter()
            .zip(envelope)
            .step_by(ENVELOPE_EVERY)
            .map(|(p, r)| (f32x3(p), *r as f32))
            .unzip();
        let [r, g, b, _] = color.to_array();
        stream.log_static(
            at::envelope(*vehicle),
            &rerun::Points3D::new(centres)
                .with_radii(radii)
                .with_colors([rerun::Color::from_unmultiplied_rgba(r, g, b, 48)]),
        )?;
    }
    for (flight, tracks) in &rec.worst {
        for (v, track) in tracks.iter().enumerate() {
            let vehicle = rec.written.get(v).map_or(v + 1, |w| w.0);
            let line: Vec<[f32; 3]> = track.iter().map(|(_, p)| f32x3(p)).collect();
            stream.log_static(
                at::worst(*flight, vehicle),
                &rerun::LineStrips3D::new([line])
                    .with_colors([rerun::Color::from_rgb(230, 60, 60)])
                    .with_labels([format!("flight {flight}, UAV {vehicle}")]),
            )?;
        }
    }
    for (name, tracks) in &rec.failing {
        for (v, track) in tracks.iter().enumerate() {
            let vehicle = rec.written.get(v).map_or(v + 1, |w| w.0);
            let line: Vec<[f32; 3]> = track.iter().map(|(_, p)| f32x3(p)).collect();
            stream.log_static(
                at::failing(name, vehicle),
                &rerun::LineStrips3D::new([line])
                    .with_colors([rerun::Color::from_rgb(240, 150, 30)])
                    .with_labels([format!("{name}, UAV {vehicle}")]),
            )?;
        }
    }
    Ok(())
}
