//! One agent's onboard planner: its own PSO over the next step h ∈
//! [−h_max, h_max]² minimising Λ_i (eq. 6) for what it observes.

use std::ops::ControlFlow;

use nalgebra::Vector2;

use super::cost::Observation;
use crate::base::swarm::{self, SearchSpace, SwarmConfig};
use crate::mission::FleetParams;

/// The planner of agent `index`: deterministic from (seed, index, round).
#[derive(Debug, Clone)]
pub struct Planner {
    pub index: usize,
    seed: u64,
    config: SwarmConfig,
    space: SearchSpace,
    /// PSO runs so far.
    pub decisions: usize,
    /// Cost evaluations so far.
    pub evaluations: usize,
}

/// A well-mixed 64-bit value from a few (SplitMix64's finaliser).
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Planner {
    pub fn new(index: usize, seed: u64, p: &FleetParams) -> Self {
        Planner {
            index,
            seed,
            config: SwarmConfig {
                particles: p.swarm_size,
                iterations: p.iterations,
                inertia: p.inertia,
                cognitive: p.cognitive,
                social: p.social,
                // Agents run in parallel; each agent's own swarm stays on its thread.
                parallel: false,
                streams: 0,
            },
            space: SearchSpace::uniform(2, -p.step_max, p.step_max, p.step_max),
            decisions: 0,
            evaluations: 0,
        }
    }

    /// Cost evaluations of one decision: the swarm's particles, evaluated
    /// at the start and after every iteration (it never stops early).
    pub fn evaluations_per_decision(p: &FleetParams) -> usize {
        p.swarm_size * (p.iterations + 1)
    }

    /// The step h that minimises Λ_i now. `round` numbers the fleet's
    /// decision rounds, so every (agent, round) has its own random stream.
    pub fn decide(&mut self, view: &Observation, round: u64) -> Vector2<f64> {
        let stream = mix(self.seed ^ mix((self.index as u64) << 32 ^ round));
        let result = swarm::minimize(
            &self.space,
            &self.config,
            stream,
            &[],
            |h, _| view.cost(&Vector2::new(h[0], h[1])),
            |_| ControlFlow::Continue(()),
        );
        self.decisions += 1;
        self.evaluations += result.evaluations;
        Vector2::new(result.best.position[0], result.best.position[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point2;

    fn alone(position: Point2<f64>) -> Observation {
        Observation {
            position,
            target: Point2::new(2.0, 2.0),
            target_distance: 0.0,
            neighbours: Vec::new(),
            obstacles: Vec::new(),
            rho: 5.0,
            safety: 0.8,
            sigma: 0.4,
            keep_apart: 1.2,
            keep_clear: 1.0,
        }
    }

    #[test]
    fn far_from_the_target_the_step_is_the_longest_toward_it() {
        let p = FleetParams::default();
        let mut planner = Planner::new(0, 1, &p);
        let h = planner.decide(&alone(Point2::new(0.0, 2.0)), 0);
        // Straight east, the full 0.4 m (the box allows a longer diagonal, but
        // along x only 0.4 brings it closer).
        assert!((h.x - 0.4).abs() < 1e-3 && h.y.abs() < 0.05, "{h}");
        assert_eq!(planner.decisions, 1);
        assert_eq!(planner.evaluations, p.swarm_size * (p.iterations + 1));
        assert_eq!(planner.evaluations, Planner::evaluations_per_decision(&p));
    }

    #[test]
    fn close_to_the_target_the_step_lands_on_it() {
        let mut planner = Planner::new(0, 1, &FleetParams::default());
        let h = planner.decide(&alone(Point2::new(1.9, 2.1)), 0);
        assert!((h - Vector2::new(0.1, -0.1)).norm() < 1e-3, "{h}");
    }

    #[test]
    fn the_same_round_gives_the_same_decision() {
        let p = FleetParams::default();
        let view = alone(Point2::new(0.3, 0.7));
        let a = Planner::new(2, 9, &p).decide(&view, 5);
        let b = Planner::new(2, 9, &p).decide(&view, 5);
        assert_eq!(a, b);
    }
}
