//! Checks the flown result against the hard constraints, sample by sample.
//!
//! The cost only penalises; this decides. For every UAV and every sample:
//! clearance to every obstacle ≥ r_Q, every pair within [2 r_Q, d_com]
//! (eq. 7), altitude inside the band (eq. 5), position inside the bounds;
//! and for every inspected obstacle, eq. 8 over its pass (`verify_inspections`, with the pass geometry of `inspection`).
//! A plan that fails any of them is infeasible.

use nalgebra::Point3;
use serde::Serialize;

use super::trajectory::Trajectory;
use crate::mission::Mission;
use crate::pipelines::Limits;

/// Where a worst value happens.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Location {
    pub time: f64,
    /// 0-based slot index (UAV n + 1 in messages, as in the paper).
    pub uav: usize,
    /// The other UAV or the obstacle, when the check involves one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub other: Option<String>,
    pub position: Point3<f64>,
}

/// One row of the verification table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    pub name: &'static str,
    /// "≥" or "≤": how `worst` must compare with `limit`.
    pub relation: &'static str,
    pub limit: f64,
    /// The worst value over all UAVs and samples; `None` when nothing was
    /// measured (no obstacles, a single UAV).
    pub worst: Option<f64>,
    pub ok: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at: Option<Location>,
}

/// A sample that breaks a constraint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Violation {
    pub check: &'static str,
    pub value: f64,
    pub location: Location,
}

/// The verification table and the verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verification {
    pub feasible: bool,
    pub checks: Vec<Check>,
    /// The first violations found (at most `MAX_VIOLATIONS`), for display.
    pub violations: Vec<Violation>,
    /// How many samples broke a constraint in all.
    pub violation_count: usize,
    /// Eq. 8, one row per inspected obstacle.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub inspections: Vec<InspectionResult>,
}

impl Verification {
    /// The first broken constraint in words: the check, the UAV, the obstacle
    /// or other UAV, and the time; or the first inspection that failed.
    pub fn first_failure(&self) -> Option<String> {
        if let Some(c) = self.checks.iter().find(|c| !c.ok) {
            let worst = c
                .worst
                .map_or_else(|| "n/a".to_owned(), |w| format!("{w:.3}"));
            let at = c.at.as_ref().map_or_else(String::new, |a| {
                let other = a
                    .other
                    .as_deref()
                    .map_or_else(String::new, |o| format!(" vs {o}"));
                format!(" (UAV {} at t = {:.1} s{other})", a.uav + 1, a.time)
            });
            return Some(format!(
                "{} worst {worst} {} {}{at}",
                c.name, c.relation, c.limit
            ));
        }
        self.inspections.iter().find(|i| !i.ok).map(|i| {
            format!(
                "inspection of '{}': {:.1} m within [{}, {}] m of its surface, {} m required (eq. 8)",
                i.obstacle, i.achieved, i.band[0], i.band[1], i.required
            )
        })
    }
}

/// Violations kept in the outcome.
pub const MAX_VIOLATIONS: usize = 200;

/// Tracks the worst value of one check.
struct Tracker {
    check: Check,
    at_least: bool,
}

impl Tracker {
    fn new(name: &'static str, at_least: bool, limit: f64) -> Self {
        Tracker {
            check: Check {
                name,
                relation: if at_least { "≥" } else { "≤" },
                limit,
                worst: None,
                ok: true,
                at: None,
            },
            at_least,
        }
    }

    /// Records a value; returns whether it breaks the limit.
    fn observe(&mut self, value: f64, at: impl FnOnce() -> Location) -> bool {
        let worse = match self.check.worst {
            None => true,
            Some(w) => {
                if self.at_least {
                    value < w
                } else {
                    value > w
                }
            }
        };
        if worse {
            self.check.worst = Some(value);
            self.check.at = Some(at());
        }
        let bad = if self.at_least {
            value < self.check.limit
        } else {
            value > self.check.limit
        };
        if bad {
            self.check.ok = false;
        }
        bad
    }
}

/// θ-PSO's own thresholds, in the shared vocabulary of the checks.
impl Limits {
    /// θ-PSO's hard constraints: r_Q, [2 r_Q, d_com] (eq. 7), eq. 8.
    pub fn theta_pso(mission: &Mission) -> Self {
        let f = &mission.formation;
        Limits {
            clearance: f.uav_radius,
            closest: 2.0 * f.uav_radius,
            farthest: Some(f.comm_range),
            inspections: true,
        }
    }
}

/// Verifies trajectories sampled at common times.
pub fn verify(mission: &Mission, trajectories: &[Trajectory]) -> Verification {
    verify_within(mission, &Limits::theta_pso(mission), trajectories)
}

/// Verifies trajectories sampled at common times against `limits`, the
/// altitude band and the x-y bounds of `mission`.
pub fn verify_within(
    mission: &Mission,
    limits: &Limits,
    trajectories: &[Trajectory],
) -> Verification {
    let b = &mission.bounds;
    let mut clearance = Tracker::new("obstacle clearance", true, limits.clearance);
    let mut closest = Tracker::new("inter-UAV distance (closest)", true, limits.closest);
    let mut farthest = Tracker::new(
        "inter-UAV distance (farthest)",
        false,
        limits.farthest.unwrap_or(f64::INFINITY),
    );
    let mut low = Tracker::new("altitude (lowest)", true, b.z[0]);
    let mut high = Tracker::new("altitude (highest)", false, b.z[1]);
    let mut inside = Tracker::new("distance inside the x-y bounds", true, 0.0);
    let mut violations = Vec::new();
    let mut count = 0usize;
    let mut note = |check: &'static str, value: f64, location: Location| {
        count += 1;
        if violations.len() < MAX_VIOLATIONS {
            violations.push(Violation {
                check,
                value,
                location,
            });
        }
    };
    let cylinders: Vec<_> = mission
        .obstacles
        .iter()
        .map(|o| mission.cylinder(o))
        .collect();
    let ground = mission.ground_model();
    let samples = trajectories
        .iter()
        .map(|t| t.samples.len())
        .min()
        .unwrap_or(0);

    for k in 0..samples {
        for (n, traj) in trajectories.iter().enumerate() {
            let s = &traj.samples[k];
            let p = s.position;
            let here = |other: Option<String>| Location {
                time: s.t,
                uav: n,
                other,
                position: p,
            };
            for (o, c) in mission.obstacles.iter().zip(&cylinders) {
                let d = c.clearance(&p);
                if clearance.observe(d, || here(Some(o.name.clone()))) {
                    note(clearance.check.name, d, here(Some(o.name.clone())));
                }
            }
            // The band is above the ground under the UAV (z = 0 without terrain).
            let h = p.z - ground.as_ref().map_or(0.0, |g| g.at(p.x, p.y));
            if low.observe(h, || here(None)) {
                note(low.check.name, h, here(None));
            }
            if high.observe(h, || here(None)) {
                note(high.check.name, h, here(None));
            }
            let margin = b.horizontal_margin(&p);
            if inside.observe(margin, || here(None)) {
                note(inside.check.name, margin, here(None));
            }
            for (m, other) in trajectories.iter().enumerate().skip(n + 1) {
                let d = (other.samples[k].position - p).norm();
                let name = || Some(format!("UAV {}", m + 1));
                if closest.observe(d, || here(name())) {
                    note(closest.check.name, d, here(name()));
                }
                if farthest.observe(d, || here(name())) {
                    note(farthest.check.name, d, here(name()));
                }
            }
        }
    }
    let checks: Vec<Check> = [clearance, closest, farthest, low, high, inside]
        .into_iter()
        .map(|t| t.check)
        .filter(|c| c.limit.is_finite())
        .collect();
    let inspections = if limits.inspections {
        verify_inspections(mission, trajectories)
    } else {
        Vec::new()
    };
    Verification {
        feasible: checks.iter().all(|c| c.ok) && inspections.iter().all(|i| i.ok),
        checks,
        violations,
        violation_count: count,
        inspections,
    }
}

/// Eq. 8 as flown, for one inspected obstacle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InspectionResult {
    pub obstacle: String,
    /// [d_min^s, d_max^s], metres.
    pub band: [f64; 2],
    /// Pass length required, metres of centroid path.
    pub required: f64,
    /// Longest stretch over which the facing UAV stayed in the band, metres.
    pub achieved: f64,
    /// The facing UAV's distance range over that stretch, metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance: Option<[f64; 2]>,
    /// When that stretch starts and ends, seconds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<[f64; 2]>,
    /// 0-based UAV facing the surface in the middle of the stretch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uav: Option<usize>,
    pub ok: bool,
}

/// Checks eq. 8 on the flown trajectories for every inspected obstacle:
/// the longest run of samples where the nearest UAV is within the band must
/// cover the pass (less one sample's travel, the resolution of the check).
pub fn verify_inspections(mission: &Mission, trajectories: &[Trajectory]) -> Vec<InspectionResult> {
    let f = &mission.formation;
    let samples = trajectories
        .iter()
        .map(|t| t.samples.len())
        .min()
        .unwrap_or(0);
    let step = trajectories
        .first()
        .and_then(|t| t.samples.get(1).map(|s| s.t - t.samples[0].t))
        .unwrap_or(0.0);
    let resolution = step * f.ground_speed;
    mission
        .obstacles
        .iter()
        .filter(|o| o.inspect)
        .map(|o| {
            let band = o.stand_off_band(f);
            let cylinder = o.cylinder();
            // (start, end) sample indices of the current and the best run.
            let mut run: Option<usize> = None;
            let mut best: Option<(usize, usize)> = None;
            let facing = |k: usize| {
                trajectories
                    .iter()
                    .enumerate()
                    .map(|(n, t)| (n, cylinder.clearance(&t.samples[k].position)))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
            };
            for k in 0..=samples {
                let inside =
                    k < samples && facing(k).is_some_and(|(_, d)| band[0] <= d && d <= band[1]);
                match (inside, run) {
                    (true, None) => run = Some(k),
                    (false, Some(first)) => {
                        let last = k - 1;
                        if best.is_none_or(|(a, b)| last - first > b - a) {
                            best = Some((first, last));
                        }
                        run = None;
                    }
                    _ => {}
                }
            }
            let time = |k: usize| trajectories[0].samples[k].t;
            let achieved = best.map_or(0.0, |(a, b)| (time(b) - time(a)) * f.ground_speed);
            let distance = best.map(|(a, b)| {
                (a..=b).fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], k| {
                    let d = facing(k).map_or(f64::NAN, |(_, d)| d);
                    [lo.min(d), hi.max(d)]
                })
            });
            InspectionResult {
                obstacle: o.name.clone(),
                band,
                required: f.inspection_pass,
                achieved,
                distance,
                time: best.map(|(a, b)| [time(a), time(b)]),
                uav: best.and_then(|(a, b)| facing((a + b) / 2).map(|(n, _)| n)),
                ok: achieved + resolution + 1e-9 >= f.inspection_pass,
            }
        })
        .collect()
}
