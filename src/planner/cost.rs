//! The θ-PSO cost J = β1 J1 + β2 J2 + β3 J3 + β_R J_R (eqs. 2-5, 10-11).
//!
//! The centroid path is split into about L straight segments: each leg of the
//! polyline gets a share of L proportional to its length (at least one), so
//! J1 is the exact polyline length and the segment midpoints are evenly
//! spread. J2, J3 and J_R are evaluated at the midpoints.
//!
//! Safe radius of eq. 4: r^S = r_k + r_F + r_Q for the nominal formation. In a
//! reconfiguration zone the formation is narrower: there r^S = r_k + ρ with ρ
//! blended linearly (with the zone's blend b) from r_F + r_Q to the lateral
//! half-width of the new shape (UAV radius included). Across the IWP the path
//! is straight along the gap's normal, so the lateral width is what must clear
//! the obstacles.

use nalgebra::{Point2, Point3};

use super::iwp::{Iwp, lateral_half_width};
use super::path::CentroidPath;
use crate::geometry::{Cylinder, polyline_length};
use crate::mission::{Mission, ThetaPsoParams};
use crate::pipeline::CostTerms;

/// Everything the cost needs, prepared once per run.
#[derive(Debug, Clone)]
pub struct CostModel {
    params: ThetaPsoParams,
    obstacles: Vec<Cylinder>,
    /// r_F + r_Q of the nominal formation.
    nominal_safe: f64,
    /// Per IWP (same indexing as the IWP list): lateral half-width of its shape.
    shape_half_width: Vec<f64>,
    /// C_j of the enabled IWPs.
    iwp_points: Vec<Point2<f64>>,
    band: [f64; 2],
}

impl CostModel {
    pub fn new(mission: &Mission, iwps: &[Iwp]) -> Self {
        let f = &mission.formation;
        CostModel {
            params: mission.theta_pso.clone(),
            obstacles: mission.obstacles.iter().map(|o| o.cylinder()).collect(),
            nominal_safe: f.safe_radius(),
            shape_half_width: iwps
                .iter()
                .map(|i| lateral_half_width(&i.shape.offsets(&f.slots, 1.0), f.uav_radius))
                .collect(),
            iwp_points: iwps
                .iter()
                .filter(|i| i.enabled)
                .map(|i| i.position)
                .collect(),
            band: mission.bounds.z,
        }
    }

    /// J and its terms for a centroid path.
    pub fn terms(&self, path: &CentroidPath) -> CostTerms {
        let points = &path.points;
        let total = polyline_length(points);
        let target = self.params.segments.max(1) as f64;
        let mut segments = 0usize;
        let (mut j2, mut j3, mut jr) = (0.0, 0.0, 0.0);
        let mut arc = 0.0;
        for leg in points.windows(2) {
            let (a, b) = (leg[0], leg[1]);
            let len = (b - a).norm();
            let pieces = if total > 0.0 {
                ((target * len / total).round() as usize).max(1)
            } else {
                1
            };
            for k in 0..pieces {
                let u = (k as f64 + 0.5) / pieces as f64;
                let mid = a + (b - a) * u;
                let s = arc + len * u;
                j2 += self.obstacle_violation(&mid, self.safe_margin(path, s));
                j3 += self.altitude_violation(mid.z);
                jr += self
                    .iwp_points
                    .iter()
                    .map(|c| (mid.xy() - c).norm())
                    .sum::<f64>();
            }
            segments += pieces;
            arc += len;
        }
        let l = segments.max(1) as f64;
        let k = self.obstacles.len();
        let m = self.iwp_points.len();
        let obstacle = if k > 0 { j2 / (l * k as f64) } else { 0.0 };
        let waypoints = if m > 0 { jr / (l * m as f64) } else { 0.0 };
        let p = &self.params;
        CostTerms {
            length: total,
            obstacle,
            altitude: j3,
            waypoints,
            total: p.weight_length * total
                + p.weight_obstacle * obstacle
                + p.weight_altitude * j3
                + p.weight_waypoints * waypoints,
        }
    }

    /// ρ at arc length s: r_F + r_Q, narrowed inside reconfiguration zones.
    fn safe_margin(&self, path: &CentroidPath, s: f64) -> f64 {
        let mut margin = self.nominal_safe;
        for zone in &path.zones {
            let b = zone.blend(s);
            if b > 0.0 {
                let narrow = self.shape_half_width[zone.iwp];
                margin = margin.min((1.0 - b) * self.nominal_safe + b * narrow);
            }
        }
        margin
    }

    /// Σ_k max(1 − d_k / r^S_k, 0) at one midpoint (the inner sum of eq. 4).
    fn obstacle_violation(&self, p: &Point3<f64>, margin: f64) -> f64 {
        let mut sum = 0.0;
        for c in &self.obstacles {
            let safe = c.radius + margin;
            // Cheap rejection: far away horizontally means no violation at any height.
            let dx = p.x - c.center.x;
            let dy = p.y - c.center.y;
            if dx * dx + dy * dy >= safe * safe {
                continue;
            }
            let d = c.axis_distance(p);
            if d < safe {
                sum += 1.0 - d / safe;
            }
        }
        sum
    }

    /// δ_l of eq. 5 for a segment at height z.
    fn altitude_violation(&self, z: f64) -> f64 {
        let [z_min, z_max] = self.band;
        if z <= 0.0 {
            self.params.ground_penalty
        } else if z > z_max {
            z - z_max
        } else if z < z_min {
            z_min - z
        } else {
            0.0
        }
    }
}
