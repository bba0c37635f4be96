//! A search's progress on the `iteration` timeline: each named term of its
//! best cost as a series under `<root>/cost/` and its best path at
//! `<root>/best_path`, from the run's `Event::Iteration`s (θ-PSO's swarm:
//! `theta_pso/cost/J_total`, …).

use rerun::RecordingStream;

use super::log_series;

/// One iteration as queued: its index, its cost's named terms, its path.
pub type Iteration = (usize, Vec<(&'static str, f64)>, Vec<[f32; 3]>);

/// One `send_columns` per series for all iterations gathered so far, under
/// the pipeline's `root`.
pub fn flush_iterations(stream: &RecordingStream, root: &str, pending: &mut Vec<Iteration>) {
    let Some((_, first, _)) = pending.first() else {
        return;
    };
    let iterations =
        rerun::TimeColumn::new_sequence("iteration", pending.iter().map(|(i, _, _)| *i as i64));
    let names: Vec<&'static str> = first.iter().map(|(name, _)| *name).collect();
    for (k, name) in names.into_iter().enumerate() {
        let values: Vec<f64> = pending
            .iter()
            .map(|(_, terms, _)| terms.get(k).map_or(f64::NAN, |(_, v)| *v))
            .collect();
        let _ = log_series(stream, &format!("{root}/cost/{name}"), &iterations, values);
    }
    let strips: Vec<Vec<[f32; 3]>> = pending.drain(..).map(|(_, _, p)| p).collect();
    if let Ok(columns) = rerun::LineStrips3D::update_fields()
        .with_strips(strips)
        .columns_of_unit_batches()
    {
        let _ = stream.send_columns(format!("{root}/best_path"), [iterations], columns);
    }
}
