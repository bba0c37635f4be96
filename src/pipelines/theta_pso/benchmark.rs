//! θ-PSO against the SPSO benchmark's cost (`theta_pso.cost = "spso"`): the
//! swarm searches the benchmark's n free nodes with the mission's encoding
//! (`crate::pipelines::theta_pso::spso`), and the best path is flown, sampled and verified like
//! any θ-PSO plan (trajectories, the band above the ground, clearances), so
//! the CLI, the designer and the recording show it as they show any plan.
//!
//! The outcome's cost terms carry the benchmark's: `length` = J1,
//! `obstacle` = J2, `altitude` = J3, `turning` = J4 in radians (as every
//! `CostTerms::turning`; the benchmark's own `spso::Terms::smoothness` is in
//! degrees, its unit), `total` = J (the benchmark's, J4 in degrees in it).

use std::ops::ControlFlow;

use super::CostTerms;
use super::{ThetaPsoOutcome, path, trajectory};
use crate::mission::Mission;
use crate::pipelines::theta_pso::spso::{self, Decoder};
use crate::pipelines::{CancelToken, Completion, Event, Level, Observer, PipelineError};

/// The benchmark's terms as `CostTerms`.
pub fn cost_terms(t: &spso::Terms) -> CostTerms {
    CostTerms {
        length: t.length,
        obstacle: t.threat,
        altitude: t.altitude,
        waypoints: 0.0,
        bounds: 0.0,
        turning: t.smoothness.to_radians(),
        total: t.total,
    }
}

/// Plans `mission` (cost = "spso") with `seed`.
///
/// Long (~130 lines) because it is the benchmark run's stages in order (the swarm with its
/// progress and cancel callback, the path against the sample budget, the flight and its
/// verification), and a third of it fills the outcome, most of its fields empty here.
pub fn plan(
    mission: &Mission,
    seed: u64,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<ThetaPsoOutcome, PipelineError> {
    crate::pipelines::require_admissible(mission, super::budget)?;
    let model = spso::model(mission).map_err(PipelineError::InvalidMission)?;
    let decoder = Decoder::new(mission, mission.theta_pso.encoding);
    let p = &mission.theta_pso;
    observer.on_event(Event::Stage("planning"));
    let mut last_cost = f64::NAN;
    // Only a swarm's worth can start anywhere: more is the swarm, seeded.
    let seeded = p.seeded_particles.min(p.swarm_size);
    let starts = spso::seeding::particles(&model, &decoder, seeded, seed);
    let run = spso::optimise(
        &model,
        &decoder,
        p.swarm_size,
        p.iterations,
        seed,
        &starts,
        |iteration, best, nodes| {
            if best != last_cost {
                last_cost = best;
                let terms = cost_terms(&model.terms(nodes));
                let points = spso::points(&model, nodes);
                observer.on_event(Event::Iteration {
                    iteration,
                    cost: terms.total,
                    terms: &terms.named(),
                    path: &points,
                });
            }
            observer.on_event(Event::Progress(
                0.95 * iteration as f64 / p.iterations.max(1) as f64,
            ));
            if cancel.is_cancelled() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    let completion = if run.swarm.stopped {
        observer.on_event(Event::Log(
            Level::Warn,
            &format!(
                "cancelled after {} iterations; keeping the best so far",
                run.swarm.iterations
            ),
        ));
        Completion::Cancelled
    } else {
        Completion::Finished
    };
    if run.terms.total.is_infinite() {
        observer.on_event(Event::Log(
            Level::Warn,
            "no path of finite benchmark cost was found (every particle collides or leaves the map)",
        ));
    }
    observer.on_event(Event::Stage("trajectories"));
    let points = spso::points(&model, &run.nodes);
    let centroid = path::CentroidPath::bare(points);
    let speed = mission.formation.ground_speed;
    let length: f64 = centroid
        .points
        .windows(2)
        .map(|w| (w[1] - w[0]).norm())
        .sum();
    let samples =
        (length / speed / trajectory::SAMPLE_PERIOD + 1.0) * mission.formation.slots.len() as f64;
    if crate::pipelines::exceeds(samples, crate::pipelines::limits::TRAJECTORY_SAMPLES) {
        return Err(PipelineError::OverBudget(format!(
            "formation.ground_speed: the planned path ({length:.1} m at {} m/s) needs {} \
             trajectory samples (limit {})",
            crate::pipelines::figure(speed),
            crate::pipelines::figure(samples),
            crate::pipelines::figure(crate::pipelines::limits::TRAJECTORY_SAMPLES)
        )));
    }
    observer.on_event(Event::Stage("verification"));
    let (flight, verification) = super::flight::fly(mission, &centroid, &[], &[])?;
    observer.on_event(Event::Progress(1.0));
    let n = model.nodes;
    let waypoints = (0..n)
        .map(|i| nalgebra::Point3::new(run.nodes[i], run.nodes[n + i], run.nodes[2 * n + i]))
        .collect();
    Ok(ThetaPsoOutcome {
        header: crate::pipelines::Header {
            pipeline: crate::pipelines::Kind::ThetaPso,
            mission: mission.name.clone(),
            seed,
            completion,
        },
        iterations: run.swarm.iterations,
        evaluations: run.swarm.evaluations,
        restarts: 0,
        cost: cost_terms(&run.terms),
        convergence: run.convergence,
        iwps: Vec::new(),
        waypoints,
        pass_angles: Vec::new(),
        warm_start: None,
        path_length: length,
        duration: flight.duration(),
        reference_length: None,
        length_ratio: None,
        passed_over: Vec::new(),
        passed_under: Vec::new(),
        passes: Vec::new(),
        centroid_path: centroid.points,
        flown_path: flight.rounded.path.points,
        flown_arcs: flight.progress,
        reconfigurations: flight.reconfigurations,
        bypassed: Vec::new(),
        unused_choices: Vec::new(),
        source: super::PlanSource::Swarm,
        route_length: length,
        corridor: super::route::Corridor {
            points: Vec::new(),
            legs: Vec::new(),
            passes: Vec::new(),
            length: 0.0,
            heights: Vec::new(),
            coarse_cell: None,
            squeeze: None,
        },
        trajectories: flight.trajectories,
        verification,
    })
}
