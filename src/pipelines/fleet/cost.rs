//! The cost each agent minimises (fleet paper, eqs. 3, 6, 9), over what that
//! agent can see: an [`Observation`]. Nothing here knows the rest of the
//! fleet: that boundary is what lets agents later run as separate processes.
//!
//! Readings (docs/fleet.md): Λ_i uses absolute deviations |‖·‖ − d| so that
//! Λ_i = 0 exactly at the desired configuration (DESIGN.md); a_ij is taken
//! at the candidate position x_i + h, so it steers the choice of h away from
//! d_ij < c; an obstacle's distance in Obs_ik is to its nearest point (the
//! surface of the cylinder), the "x_kobs" the agent's sensor measures; and
//! the safety distance is also a constraint (eq. 5), see [`CONSTRAINT`].

use nalgebra::{Point2, Vector2};
use serde::Serialize;

use crate::base::shape::Footprint;

/// Below this exponent exp() is under 1e-13 of the terms it is added to.
const NEGLIGIBLE: f64 = -30.0;

/// Eq. 3: a_ij = 1 + exp((c − d_ij)/σ). 2 at the safety distance, → 1 far away.
pub fn influence(distance: f64, safety: f64, sigma: f64) -> f64 {
    1.0 + obstacle_penalty(distance, safety, sigma)
}

/// Eq. 9: Obs_ik = exp((c − d_ik)/σ), d_ik the distance to the obstacle. 1 at c, → 0 far away.
pub fn obstacle_penalty(distance: f64, safety: f64, sigma: f64) -> f64 {
    let x = (safety - distance) / sigma;
    if x < NEGLIGIBLE { 0.0 } else { x.exp() }
}

/// Weight of a step's intrusion inside c (eq. 5 and objective 3 as
/// constraints): metres inside cost far more than anything else in Λ_i.
pub const CONSTRAINT: f64 = 1.0e3;

/// A neighbour as agent i sees it (eq. 2: within l).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Neighbour {
    pub position: Point2<f64>,
    /// d_ij^d.
    pub desired: f64,
}

/// Everything agent i's planner knows at a decision.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// x_i(t).
    pub position: Point2<f64>,
    /// P_d.
    pub target: Point2<f64>,
    /// d_ip^d.
    pub target_distance: f64,
    pub neighbours: Vec<Neighbour>,
    /// The obstacles within d_obs; eq. 9's d_ik is the distance to a
    /// footprint's nearest point (negative inside), as the other pipelines
    /// measure.
    pub obstacles: Vec<Footprint>,
    /// ρ, c, σ.
    pub rho: f64,
    pub safety: f64,
    pub sigma: f64,
    /// No reference closer than this to a neighbour's current position: c
    /// plus the neighbour's own step in the same round (c + h_max).
    pub keep_apart: f64,
    /// No reference closer than this to an obstacle: c plus a margin for the
    /// quadrotor's lag behind its reference (c + h_max/2).
    pub keep_clear: f64,
}

impl Observation {
    /// Eq. 6: Λ_i for the step h.
    pub fn cost(&self, h: &Vector2<f64>) -> f64 {
        let next = self.position + h;
        let mut cost = self.rho * ((self.target - next).norm() - self.target_distance).abs();
        for n in &self.neighbours {
            let distance = (n.position - next).norm();
            let weight = influence(distance, self.safety, self.sigma);
            cost += weight * (distance - n.desired).abs();
            cost += CONSTRAINT * (self.keep_apart - distance).max(0.0);
        }
        for o in &self.obstacles {
            let distance = o.signed_distance(&next);
            cost += obstacle_penalty(distance, self.safety, self.sigma);
            cost += CONSTRAINT * (self.keep_clear - distance).max(0.0);
        }
        cost
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 3 with Table 1's c = 0.8 m, σ = 0.4.
    #[test]
    fn influence_values() {
        assert_eq!(influence(0.8, 0.8, 0.4), 2.0);
        assert!((influence(0.4, 0.8, 0.4) - (1.0 + 1f64.exp())).abs() < 1e-12);
        assert!((influence(1.732, 0.8, 0.4) - (1.0 + (-2.33f64).exp())).abs() < 1e-12);
        assert!(influence(10.0, 0.8, 0.4) - 1.0 < 2e-10);
        assert_eq!(influence(100.0, 0.8, 0.4), 1.0);
    }

    /// Eq. 9's d_ik to a footprint is to its nearest point, not to the
    /// circle round it: beside the middle of a 10 m wall's face, 1 m out, an
    /// agent is 1 m from it (the bounding circle would put it inside).
    #[test]
    fn a_footprint_is_measured_to_its_nearest_point_eq9() {
        let wall: Vec<Point2<f64>> = [[0.0, 0.0], [10.0, 0.0], [10.0, 1.0], [0.0, 1.0]]
            .iter()
            .map(|&[x, y]| Point2::new(x, y))
            .collect();
        let o = Footprint::new(crate::base::shape::Polygon::new(wall));
        let (center, radius) = o.bounding_circle();
        let beside = Point2::new(5.0, 2.0);
        assert!((o.signed_distance(&beside) - 1.0).abs() < 1e-12);
        assert!((beside - center).norm() - radius < 0.0, "inside the circle");
        assert!((o.signed_distance(&Point2::new(12.0, 0.5)) - 2.0).abs() < 1e-12);
        assert!((o.signed_distance(&Point2::new(5.0, 0.5)) + 0.5).abs() < 1e-12);
        // The penalty follows: at c it is 1 (eq. 9).
        let at_c = Point2::new(5.0, 1.8);
        assert!((obstacle_penalty(o.signed_distance(&at_c), 0.8, 0.4) - 1.0).abs() < 1e-9);
    }

    /// Eq. 9 with Table 1's c = 0.8 m, σ = 0.4.
    #[test]
    fn obstacle_penalty_values() {
        assert_eq!(obstacle_penalty(0.8, 0.8, 0.4), 1.0);
        assert!((obstacle_penalty(0.0, 0.8, 0.4) - 2f64.exp()).abs() < 1e-12);
        assert!(obstacle_penalty(3.0, 0.8, 0.4) < 0.005);
    }

    /// Eq. 6: zero exactly at the desired configuration (a triangle 1 m
    /// around the target, 1.732 m apart), positive anywhere near it.
    #[test]
    fn lambda_is_zero_exactly_at_the_desired_configuration() {
        let target = Point2::new(2.0, 2.0);
        let corner = |k: f64| {
            let a = std::f64::consts::TAU * k / 3.0;
            target + Vector2::new(a.cos(), a.sin())
        };
        let side = 2.0 * (std::f64::consts::PI / 6.0).cos();
        let obs = Observation {
            position: corner(0.0),
            target,
            target_distance: 1.0,
            neighbours: [1.0, 2.0]
                .map(|k| Neighbour {
                    position: corner(k),
                    desired: side,
                })
                .to_vec(),
            obstacles: Vec::new(),
            rho: 5.0,
            safety: 0.8,
            sigma: 0.4,
            keep_apart: 1.2,
            keep_clear: 1.0,
        };
        assert!(
            obs.cost(&Vector2::zeros()).abs() < 1e-12,
            "{}",
            obs.cost(&Vector2::zeros())
        );
        for h in [
            Vector2::new(0.01, 0.0),
            Vector2::new(0.0, -0.01),
            Vector2::new(0.3, 0.3),
        ] {
            assert!(obs.cost(&h) > 1e-3, "h = {h}");
        }
    }
}
