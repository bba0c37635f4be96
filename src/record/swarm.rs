//! The swarm's progress on the `iteration` timeline: the cost terms and the
//! best centroid path of each iteration, from the run's `PathIteration`
//! events (θ-PSO's; its outcome draws itself: `theta_pso::recording`).

use rerun::RecordingStream;

use super::log_series;
use crate::pipelines::theta_pso::CostTerms;
use crate::pipelines::theta_pso::recording::paths as at;

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
