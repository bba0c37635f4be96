//! The SPSO benchmark (Phung & Ha, *Safety-enhanced UAV path planning with
//! spherical vector-based particle swarm optimization*, Applied Soft
//! Computing 107, 2021): its exact cost (`cost`) and the two encodings of one
//! swarm that plan against it (`encoding`), the θ-PSO angles of eq. 1 and
//! SPSO's spherical vectors. Readings in `docs/spso.md`.

pub mod cost;
pub mod encoding;
pub mod seeding;

pub use cost::{Model, Terms, Threat};

use std::ops::ControlFlow;

use nalgebra::Point3;

use crate::base::swarm::{self, SwarmResult};
use crate::mission::{Encoding, Mission};
pub use encoding::Decoder;

/// The benchmark's model of `mission`: start, goal, the free nodes, the
/// obstacles as threats (centre and radius; their height is not used), the
/// altitude band and the loaded height map.
pub fn model(mission: &Mission) -> Result<Model, String> {
    let map = mission
        .height_map()
        .ok_or("the SPSO cost needs the mission's [terrain] height map")?
        .clone();
    let (s, g) = (mission.route.start, mission.route.goal);
    let threats = mission
        .obstacles
        .iter()
        .map(|o| Threat {
            x: o.center.x,
            y: o.center.y,
            radius: o.radius,
        })
        .collect();
    Ok(Model::new(
        [s.x, s.y, s.z],
        [g.x, g.y, g.z],
        mission.theta_pso.waypoints,
        threats,
        mission.bounds.z,
        map,
    ))
}

/// One run of the swarm against the benchmark cost.
#[derive(Debug, Clone)]
pub struct Run {
    /// The best path's free nodes, x…, y…, z… (z above the ground).
    pub nodes: Vec<f64>,
    pub terms: Terms,
    /// The best J after the initial pass and after each iteration.
    pub convergence: Vec<f64>,
    pub swarm: SwarmResult,
}

/// Minimises the benchmark cost with `encoding` and its published settings
/// for `particles` × `iterations`, particle i starting at `starts[i]` when
/// given (`seeding::particles`). `on_iteration(iteration, best J, best
/// nodes)` may stop the run (the best so far is kept).
pub fn optimise(
    model: &Model,
    decoder: &Decoder,
    particles: usize,
    iterations: usize,
    seed: u64,
    starts: &[Vec<f64>],
    mut on_iteration: impl FnMut(usize, f64, &[f64]) -> ControlFlow<()>,
) -> Run {
    let space = decoder.space();
    let config = decoder.published(particles, iterations);
    let mut buffer = vec![0.0; 3 * decoder.nodes()];
    let mut shown = vec![0.0; 3 * decoder.nodes()];
    let mut convergence = Vec::with_capacity(iterations + 1);
    let result = swarm::minimize_sequential(
        &space,
        &config,
        seed,
        starts,
        |position, bound| {
            decoder.decode(position, &mut buffer);
            model.cost_below(&buffer, bound)
        },
        |report| {
            convergence.push(report.best.cost);
            decoder.decode(&report.best.position, &mut shown);
            on_iteration(report.iteration, report.best.cost, &shown)
        },
    );
    let mut nodes = vec![0.0; 3 * decoder.nodes()];
    decoder.decode(&result.best.position, &mut nodes);
    let terms = model.terms(&nodes);
    Run {
        nodes,
        terms,
        convergence,
        swarm: result,
    }
}

/// The path's points in the ENU frame: start, nodes, goal, each at its
/// absolute altitude z + H as the cost computes it.
pub fn points(model: &Model, nodes: &[f64]) -> Vec<Point3<f64>> {
    let n = model.nodes;
    let mut out = Vec::with_capacity(n + 2);
    let mut push = |x: f64, y: f64, z: f64| {
        let h = model.ground(x, y).unwrap_or(0.0);
        out.push(Point3::new(x, y, f64::from(z as f32 + h)));
    };
    push(model.start[0], model.start[1], model.start[2]);
    for i in 0..n.min(nodes.len() / 3) {
        push(nodes[i], nodes[n + i], nodes[2 * n + i]);
    }
    push(model.goal[0], model.goal[1], model.goal[2]);
    out
}

/// The mission's encoding, or `over` when given.
pub fn encoding_of(mission: &Mission, over: Option<Encoding>) -> Encoding {
    over.unwrap_or(mission.theta_pso.encoding)
}

/// `x` as C's `%.17g` (what the reference's costs are printed with):
/// 17 significant digits, trailing zeros dropped, `inf`, `-inf`, `nan`.
pub fn g17(x: f64) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf".into() } else { "-inf".into() };
    }
    if x == 0.0 {
        return if x.is_sign_negative() {
            "-0".into()
        } else {
            "0".into()
        };
    }
    let sci = format!("{x:.16e}");
    let (mantissa, exponent) = sci.split_once('e').unwrap_or((sci.as_str(), "0"));
    let exponent: i32 = exponent.parse().unwrap_or(0);
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_owned()
        } else {
            s
        }
    };
    if (-4..17).contains(&exponent) {
        let decimals = (16 - exponent).max(0) as usize;
        trim(format!("{x:.decimals$}"))
    } else {
        let sign = if exponent < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", trim(mantissa.to_owned()), exponent.abs())
    }
}

#[cfg(test)]
#[allow(clippy::excessive_precision)]
mod tests {
    use super::g17;

    #[test]
    fn g17_prints_like_printf() {
        assert_eq!(g17(750.0), "750");
        assert_eq!(g17(5925.8548228312056), "5925.8548228312056");
        assert_eq!(g17(643.13010235415595), "643.13010235415595");
        assert_eq!(g17(77.319616508180175), "77.319616508180175");
        assert_eq!(g17(f64::INFINITY), "inf");
        assert_eq!(g17(0.1), "0.10000000000000001");
        assert_eq!(g17(1e20), "1e+20");
        assert_eq!(g17(1.5e-7), "1.4999999999999999e-07");
    }
}
