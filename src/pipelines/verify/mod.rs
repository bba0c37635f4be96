//! Checks the flown result against the hard constraints, sample by sample.
//!
//! The cost only penalises; this decides. For every UAV and every sample:
//! clearance to every obstacle ≥ r_Q + the safety margin, every pair within
//! [2 r_Q + the safety margin, d_com] (eq. 7 with the margin), altitude
//! inside the band (eq. 5), position inside the bounds; every UAV's
//! horizontal and vertical speed and acceleration within its `[vehicle]`
//! limits (accelerations from one sample's velocity to the next); and for
//! every inspected obstacle, eq. 8 over its pass (`verify_inspections`, with
//! the pass geometry of `inspection`). A plan that fails any of them is
//! infeasible, and the first failure is named: the check, the UAV, the time,
//! the figure and the limit.

use nalgebra::Point3;
use serde::Serialize;

use crate::mission::Mission;
use crate::pipelines::{Limits, TrackSample};

mod vias;

pub use vias::ViaResult;

/// One UAV's timed track as verification judges it (θ-PSO's T_n, eq.
/// 15; an export's flown schedule).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trajectory {
    /// 0-based slot index.
    pub uav: usize,
    pub samples: Vec<TrackSample>,
}

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

impl Location {
    /// `UAV 1 at t = 42.9 s vs 11 kV line #1`: where a check was worst, as
    /// the failure line and the summary's table say it.
    pub fn words(&self) -> String {
        let other = self
            .other
            .as_deref()
            .map_or_else(String::new, |o| format!(" vs {o}"));
        format!("UAV {} at t = {:.1} s{other}", self.uav + 1, self.time)
    }
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

/// A check's figure as the tables print it: three decimals, or three
/// significant digits where three decimals would print 0.000 (a
/// 0.00001 m/s² limit broken by 0.0000112).
pub fn figure(value: f64) -> String {
    if value != 0.0 && value.abs() < 0.01 && value.is_finite() {
        format!("{value:.2e}")
    } else {
        format!("{value:.3}")
    }
}

/// A limit as the tables print it: as written, without the float noise a
/// sum such as r_Q + margin leaves (0.44999999999999996 is 0.45).
pub fn limit_figure(value: f64) -> String {
    let rounded = (value * 1e9).round() / 1e9;
    if value.abs() >= 1e-3 && rounded.is_finite() {
        format!("{rounded}")
    } else {
        format!("{value}")
    }
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
    /// The route's vias (`[[route.via]]`), one row each, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vias: Vec<ViaResult>,
}

impl Verification {
    /// The first broken constraint in words: the check, the UAV, the obstacle
    /// or other UAV, and the time; or the first inspection that failed.
    /// The first failed check (in the table's order) with its worst figure,
    /// where and against what, else the first failed inspection.
    pub fn first_failure(&self) -> Option<String> {
        if let Some(c) = self.checks.iter().find(|c| !c.ok) {
            let worst = c.worst.map_or_else(|| "n/a".to_owned(), figure);
            let at =
                c.at.as_ref()
                    .map_or_else(String::new, |a| format!(" ({})", a.words()));
            return Some(format!(
                "{} worst {worst} {} {}{at}",
                c.name,
                c.relation,
                limit_figure(c.limit)
            ));
        }
        if let Some(i) = self.inspections.iter().find(|i| !i.ok) {
            let side = i
                .side
                .as_ref()
                .map_or_else(String::new, |s| format!(" on its {s} face"));
            return Some(format!(
                "inspection of '{}': {:.1} m within [{}, {}] m of its surface{side}, {} m required \
                 (eq. 8)",
                i.obstacle, i.achieved, i.band[0], i.band[1], i.required
            ));
        }
        self.vias.iter().find(|v| !v.ok).map(|v| {
            format!(
                "route.via {} ({}): {}",
                v.via,
                v.label,
                v.why.as_deref().unwrap_or("not kept")
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
    /// θ-PSO's hard constraints: r_Q and 2 r_Q with the safety margin,
    /// d_com (eq. 7), eq. 8, the vehicle's limits.
    pub fn theta_pso(mission: &Mission) -> Self {
        let f = &mission.formation;
        Limits {
            clearance: f.least_clearance(),
            closest: f.closest_pair(),
            farthest: Some(f.comm_range),
            inspections: true,
            dynamics: true,
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
    let cylinders: Vec<_> = mission.obstacles.iter().map(|o| mission.prism(o)).collect();
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
                // The distance to its bounding circle's axis, less the
                // radius, is never more than the clearance (inside too): an
                // obstacle at least that far past both the limit and the
                // worst so far changes neither, so it is passed over.
                if let Some(worst) = clearance.check.worst {
                    let below = c.horizontal_distance(&p) - c.radius;
                    if below >= worst && below >= clearance.check.limit {
                        continue;
                    }
                }
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
    let mut checks: Vec<Check> = [clearance, closest, farthest, low, high, inside]
        .into_iter()
        .map(|t| t.check)
        .filter(|c| c.limit.is_finite())
        .collect();
    if limits.dynamics {
        let dynamics = Dynamics::measure(mission, trajectories, samples);
        for v in &dynamics.violations {
            note(v.check, v.value, v.location.clone());
        }
        checks.extend(dynamics.checks);
    }
    let (inspections, vias) = if limits.inspections {
        (
            verify_inspections(mission, trajectories),
            vias::verify_vias(mission, trajectories),
        )
    } else {
        (Vec::new(), Vec::new())
    };
    Verification {
        feasible: checks.iter().all(|c| c.ok)
            && inspections.iter().all(|i| i.ok)
            && vias.iter().all(|v| v.ok),
        checks,
        violations,
        violation_count: count,
        inspections,
        vias,
    }
}

/// The vehicle's limits as flown: one row each for the horizontal speed,
/// the vertical speed (climb and descent), the horizontal and the vertical
/// acceleration. UAVs may have limits of their own, so each row keeps the
/// value nearest its limit (the largest share of it) with that UAV's limit.
struct Dynamics {
    checks: Vec<Check>,
    violations: Vec<Violation>,
}

/// The rows of [`Dynamics`], by name.
pub const DYNAMICS_ROWS: [&str; 4] = [
    "horizontal speed (m/s)",
    "vertical speed (m/s)",
    "horizontal acceleration (m/s²)",
    "vertical acceleration (m/s²)",
];

/// Whether a check (or a violation's check) is one of the vehicle's
/// limits, not a constraint on where the UAVs are.
pub fn is_dynamics(check: &str) -> bool {
    DYNAMICS_ROWS.contains(&check)
}

/// One row of [`Dynamics`]: the largest share of the limit seen.
struct Share {
    check: Check,
    share: f64,
}

impl Share {
    fn new(name: &'static str) -> Self {
        Share {
            check: Check {
                name,
                relation: "≤",
                limit: 0.0,
                worst: None,
                ok: true,
                at: None,
            },
            share: f64::NEG_INFINITY,
        }
    }

    /// Records `value` against `limit`; returns whether it breaks it (a
    /// part in a million over, for the rounding of the samples).
    fn observe(&mut self, value: f64, limit: f64, at: impl FnOnce() -> Location) -> bool {
        let share = value / limit;
        if share > self.share {
            self.share = share;
            self.check.worst = Some(value);
            self.check.limit = limit;
            self.check.at = Some(at());
        }
        let bad = share > 1.0 + 1e-6;
        if bad {
            self.check.ok = false;
        }
        bad
    }
}

impl Dynamics {
    fn measure(mission: &Mission, trajectories: &[Trajectory], samples: usize) -> Self {
        let [speed, vertical, acceleration, vertical_acceleration] = DYNAMICS_ROWS;
        let mut speed = Share::new(speed);
        let mut vertical = Share::new(vertical);
        let mut acceleration = Share::new(acceleration);
        let mut vertical_acceleration = Share::new(vertical_acceleration);
        let mut violations = Vec::new();
        for (n, traj) in trajectories.iter().enumerate() {
            let limit = mission.vehicle.limits(n);
            for k in 0..samples.min(traj.samples.len()) {
                let s = &traj.samples[k];
                let here = || Location {
                    time: s.t,
                    uav: n,
                    other: None,
                    position: s.position,
                };
                let mut note = |row: &Share, value: f64| {
                    if violations.len() < MAX_VIOLATIONS {
                        violations.push(Violation {
                            check: row.check.name,
                            value,
                            location: here(),
                        });
                    }
                };
                let v = s.velocity;
                let horizontal = v.xy().norm();
                if speed.observe(horizontal, limit.speed, here) {
                    note(&speed, horizontal);
                }
                let rate = if v.z >= 0.0 {
                    limit.climb
                } else {
                    limit.descent
                };
                if vertical.observe(v.z.abs(), rate, here) {
                    note(&vertical, v.z.abs());
                }
                if k == 0 {
                    continue;
                }
                let before = &traj.samples[k - 1];
                let dt = s.t - before.t;
                if dt <= 1e-9 {
                    continue;
                }
                // The acceleration as the samples' velocities give it, and as
                // their positions do (a second difference, what a reader of
                // the tracks computes): the larger of the two is judged.
                let mut a = (v - before.velocity) / dt;
                if let Some(after) = traj.samples.get(k + 1) {
                    let ahead = after.t - s.t;
                    if ahead > 1e-9 {
                        let second = ((after.position - s.position) / ahead
                            - (s.position - before.position) / dt)
                            * (2.0 / (ahead + dt));
                        if second.xy().norm() > a.xy().norm() {
                            a.x = second.x;
                            a.y = second.y;
                        }
                        if second.z.abs() > a.z.abs() {
                            a.z = second.z;
                        }
                    }
                }
                let across = a.xy().norm();
                if acceleration.observe(across, limit.acceleration, here) {
                    note(&acceleration, across);
                }
                let up_or_down = if a.z >= 0.0 { limit.up } else { limit.down };
                if vertical_acceleration.observe(a.z.abs(), up_or_down, here) {
                    note(&vertical_acceleration, a.z.abs());
                }
            }
        }
        Dynamics {
            checks: [speed, vertical, acceleration, vertical_acceleration]
                .into_iter()
                .filter(|r| r.check.worst.is_some())
                .map(|r| r.check)
                .collect(),
            violations,
        }
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
    /// The side the mission asks for (`inspect_side`), as it names it; the
    /// stretch counts only where the facing UAV's nearest point of the
    /// obstacle lies on that face.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub side: Option<String>,
    /// The face inspected: the bearing of its outward normal at the facing
    /// UAV's nearest point in the middle of the stretch, degrees clockwise
    /// from north.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub face: Option<f64>,
    pub ok: bool,
}

/// The bearing (degrees clockwise from north, [0, 360)) of the outward
/// normal of `o`'s side nearest `p`: a footprint's nearest edge's, a
/// cylinder's radius through `p`.
pub fn face_bearing(o: &crate::base::shape::Prism, p: &Point3<f64>) -> f64 {
    let normal = o.outline.normal(&p.xy());
    normal.x.atan2(normal.y).to_degrees().rem_euclid(360.0)
}

/// Whether the point of `o` nearest `p` lies on the face `side` (the
/// compass bearing of its outward normal) names: a footprint's face is the
/// edge whose outward normal is nearest that bearing (its corners are on
/// it), a cylinder's the quarter of its surface facing that way (within
/// 45°).
pub fn on_side(o: &crate::base::shape::Prism, p: &Point3<f64>, side: f64) -> bool {
    let q = o.nearest_on_outline(&p.xy());
    let b = side.to_radians();
    let normal = nalgebra::Vector2::new(b.sin(), b.cos());
    if o.outline.corners().len() < 3 {
        let face = face_bearing(o, p);
        let d = (face - side).rem_euclid(360.0);
        return d.min(360.0 - d) <= 45.0 + 1e-9;
    }
    let outline = crate::base::geometry::anticlockwise(o.outline.corners());
    let n = outline.len();
    let i = crate::base::geometry::facing_edge(&outline, normal);
    crate::base::geometry::segment_point_distance(&outline[i], &outline[(i + 1) % n], &q) < 1e-6
}

/// The formation's centre (the mean of its UAVs) at each sample all the
/// tracks have: what the inspections and the vias are judged on.
fn centres(trajectories: &[Trajectory]) -> Vec<Point3<f64>> {
    let samples = trajectories
        .iter()
        .map(|t| t.samples.len())
        .min()
        .unwrap_or(0);
    (0..samples)
        .map(|k| {
            let sum: nalgebra::Vector3<f64> = trajectories
                .iter()
                .map(|t| t.samples[k].position.coords)
                .sum();
            Point3::from(sum / trajectories.len().max(1) as f64)
        })
        .collect()
}

/// Checks eq. 8 on the flown trajectories for every inspected obstacle:
/// the longest run of samples where the nearest UAV is within the band must
/// cover the pass, measured as the distance the formation's centre (the
/// mean of its UAVs) travels over the run, less one sample's travel there
/// (the resolution of the check). The pace varies along a timed flight, so
/// the distance is travelled, not time times a speed.
pub fn verify_inspections(mission: &Mission, trajectories: &[Trajectory]) -> Vec<InspectionResult> {
    let f = &mission.formation;
    // Distance travelled by the formation's centre up to each sample.
    let centres = centres(trajectories);
    let samples = centres.len();
    let mut travelled = Vec::with_capacity(samples);
    for k in 0..samples {
        let step = if k == 0 {
            0.0
        } else {
            (centres[k] - centres[k - 1]).norm()
        };
        travelled.push(travelled.last().copied().unwrap_or(0.0) + step);
    }
    mission
        .obstacles
        .iter()
        .filter(|o| o.inspect)
        .map(|o| {
            let band = o.stand_off_band(f);
            let cylinder = o.prism();
            let side = o.inspect_side.as_ref().and_then(|s| s.bearing());
            let on_face = |p: &Point3<f64>| side.is_none_or(|b| on_side(&cylinder, p, b));
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
                let inside = k < samples
                    && facing(k).is_some_and(|(n, d)| {
                        band[0] <= d
                            && d <= band[1]
                            && on_face(&trajectories[n].samples[k].position)
                    });
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
            let achieved = best.map_or(0.0, |(a, b)| travelled[b] - travelled[a]);
            // One sample's travel at either end of the run: where the band
            // was entered and left between samples.
            let resolution = best.map_or(0.0, |(a, b)| {
                let before = if a > 0 {
                    travelled[a] - travelled[a - 1]
                } else {
                    0.0
                };
                let after = travelled.get(b + 1).map_or(0.0, |next| next - travelled[b]);
                before.max(after)
            });
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
                side: o.inspect_side.as_ref().map(|s| s.words()),
                // The side asked for, every sample counted being on it;
                // else the face the facing UAV looks at mid-stretch.
                face: side.filter(|_| best.is_some()).or_else(|| {
                    best.and_then(|(a, b)| {
                        let k = (a + b) / 2;
                        facing(k).map(|(n, _)| {
                            face_bearing(&cylinder, &trajectories[n].samples[k].position)
                        })
                    })
                }),
                ok: achieved + resolution + 1e-9 >= f.inspection_pass,
            }
        })
        .collect()
}
