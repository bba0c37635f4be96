//! The reduced plans flown as an autopilot flies them, and checked.
//!
//! Every vehicle starts at its first waypoint at t = 0, together with the
//! others, waits out each waypoint's hold, and flies each leg in a straight
//! line at the leg's commanded speed (as written: rounded). The flights are
//! sampled at the planned tracks' instants and handed to the pipeline's own
//! verification ([`crate::pipelines::theta_pso::verify::verify_within`]) with the
//! pipeline's limits. Also measured: the largest distance between where a
//! vehicle flies and where its track has it at the same instant (the
//! deviation), and the largest difference between when a vehicle reaches a
//! waypoint and when the plan says (the timing error).
//!
//! Take-off, landing and loitering are outside the check: they happen before
//! the first and after the last waypoint.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::VehiclePlan;
use crate::mission::Mission;
use crate::outcome::tracks::{Track, TrackSample};
use crate::pipelines::Limits;
use crate::pipelines::theta_pso::verify::{Verification, verify_within};
use crate::pipelines::theta_pso::{Sample, Trajectory};

/// A broken constraint of the flown plans, located.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Failure {
    /// The verification row ("obstacle clearance", …) or the inspection.
    pub constraint: String,
    /// 0-based vehicle.
    pub vehicle: usize,
    /// The other vehicle or the obstacle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub other: Option<String>,
    /// 1-based waypoint the vehicle is flying to (or holding at).
    pub waypoint: usize,
    /// Seconds from the common start.
    pub time: f64,
    /// The worst value and the limit it breaks (metres).
    pub value: f64,
    pub relation: &'static str,
    pub limit: f64,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let other = self
            .other
            .as_deref()
            .map_or_else(String::new, |o| format!(" vs {o}"));
        write!(
            f,
            "{}: UAV {}{other}, leg to waypoint {}, t = {:.1} s: {:.3} m, must be {} {} m",
            self.constraint,
            self.vehicle + 1,
            self.waypoint,
            self.time,
            self.value,
            self.relation,
            self.limit
        )
    }
}

/// Where a largest error happened.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct At {
    /// 0-based vehicle.
    pub vehicle: usize,
    /// 1-based waypoint.
    pub waypoint: usize,
    pub time: f64,
}

/// The verdict on the flown plans.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reverification {
    /// The pipeline's verification table, on the flown plans.
    pub verification: Verification,
    pub failures: Vec<Failure>,
    /// Largest |flown(t) − track(t)|, metres.
    pub max_deviation: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deviation_at: Option<At>,
    /// Largest |arrival − planned time| at a waypoint, seconds.
    pub max_timing_error: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing_at: Option<At>,
}

impl Reverification {
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }

    /// One line per broken constraint.
    pub fn failure_text(&self) -> String {
        self.failures
            .iter()
            .map(|f| format!("  {f}"))
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// A vehicle's plan as flown: arrival and departure at each waypoint.
#[derive(Debug, Clone)]
pub struct Flight<'a> {
    plan: &'a VehiclePlan,
    arrive: Vec<f64>,
    depart: Vec<f64>,
}

impl<'a> Flight<'a> {
    pub fn new(plan: &'a VehiclePlan) -> Self {
        let w = &plan.waypoints;
        let mut arrive = Vec::with_capacity(w.len());
        let mut depart = Vec::with_capacity(w.len());
        let mut t = w.first().map_or(0.0, |w| w.t);
        for (i, wp) in w.iter().enumerate() {
            if i > 0 {
                let length = (wp.position - w[i - 1].position).norm();
                if wp.speed > 0.0 {
                    t += length / wp.speed;
                }
            }
            arrive.push(t);
            t += wp.hold;
            depart.push(t);
        }
        Flight {
            plan,
            arrive,
            depart,
        }
    }

    /// When the vehicle reaches each waypoint, seconds.
    pub fn arrivals(&self) -> &[f64] {
        &self.arrive
    }

    /// 0-based index of the waypoint the vehicle flies to (or holds at) at t.
    pub fn leg(&self, t: f64) -> usize {
        let last = self.arrive.len().saturating_sub(1);
        (0..self.depart.len())
            .find(|&i| t <= self.depart[i])
            .unwrap_or(last)
    }

    /// Position and velocity at t (holding at the ends).
    pub fn at(&self, t: f64) -> (Point3<f64>, Vector3<f64>) {
        let w = &self.plan.waypoints;
        if w.is_empty() {
            return (Point3::origin(), Vector3::zeros());
        }
        let i = self.leg(t);
        if i == 0 || t >= self.arrive[i] {
            return (w[i].position, Vector3::zeros());
        }
        let (a, b) = (&w[i - 1], &w[i]);
        let span = self.arrive[i] - self.depart[i - 1];
        if span <= 0.0 {
            return (b.position, Vector3::zeros());
        }
        let s = ((t - self.depart[i - 1]) / span).clamp(0.0, 1.0);
        (
            a.position + (b.position - a.position) * s,
            (b.position - a.position) / span,
        )
    }
}

/// Where a track has its vehicle at t (linear between samples).
fn track_at(samples: &[TrackSample], t: f64) -> Option<Point3<f64>> {
    let k = samples.partition_point(|s| s.t < t);
    match (
        k.checked_sub(1).and_then(|i| samples.get(i)),
        samples.get(k),
    ) {
        (_, Some(b)) if b.t <= t => Some(b.position),
        (Some(a), Some(b)) => Some(super::simplify::on_leg(a, b, t)),
        (Some(a), None) => Some(a.position),
        (None, Some(b)) => Some(b.position),
        (None, None) => None,
    }
}

/// The largest distance between where `plan`, flown, puts its vehicle and
/// where `track` has it, at the track's instants and at the flight's end.
pub fn deviation(plan: &VehiclePlan, track: &Track) -> f64 {
    let flight = Flight::new(plan);
    let end = flight.arrivals().last().copied();
    track
        .samples
        .iter()
        .map(|s| s.t)
        .chain(end)
        .filter_map(|t| Some((flight.at(t).0 - track_at(&track.samples, t)?).norm()))
        .fold(0.0, f64::max)
}

/// Flies `plans` and checks them against `limits` and the mission's band and
/// bounds; measures deviation from `tracks` and timing errors.
///
/// Long (~125 lines): the checks of the flown plans one after another, each a short block, in the order the report lists them.
pub fn reverify(
    mission: &Mission,
    limits: &Limits,
    tracks: &[Track],
    plans: &[VehiclePlan],
) -> Reverification {
    let flights: Vec<Flight> = plans.iter().map(Flight::new).collect();
    // The instants: the longest track's samples (the pipelines sample every
    // vehicle on one grid), and each flight's end.
    let mut times: Vec<f64> = tracks
        .iter()
        .max_by_key(|t| t.samples.len())
        .map(|t| t.samples.iter().map(|s| s.t).collect())
        .unwrap_or_default();
    let end = flights
        .iter()
        .filter_map(|f| f.arrivals().last().copied())
        .fold(f64::NEG_INFINITY, f64::max);
    if times.last().is_some_and(|&t| end > t) {
        times.push(end);
    }

    let mut max_deviation = 0.0;
    let mut deviation_at = None;
    let trajectories: Vec<Trajectory> = flights
        .iter()
        .zip(tracks)
        .map(|(flight, track)| {
            let samples = times
                .iter()
                .map(|&t| {
                    let (position, velocity) = flight.at(t);
                    if let Some(p) = track_at(&track.samples, t) {
                        let d = (position - p).norm();
                        if d > max_deviation {
                            max_deviation = d;
                            deviation_at = Some(At {
                                vehicle: track.vehicle,
                                waypoint: flight.leg(t) + 1,
                                time: t,
                            });
                        }
                    }
                    Sample {
                        t,
                        position,
                        velocity,
                    }
                })
                .collect();
            Trajectory {
                uav: track.vehicle,
                samples,
            }
        })
        .collect();

    let mut max_timing_error = 0.0;
    let mut timing_at = None;
    for (flight, plan) in flights.iter().zip(plans) {
        for (i, (w, a)) in plan.waypoints.iter().zip(flight.arrivals()).enumerate() {
            let e = (a - w.t).abs();
            if e > max_timing_error {
                max_timing_error = e;
                timing_at = Some(At {
                    vehicle: plan.vehicle,
                    waypoint: i + 1,
                    time: w.t,
                });
            }
        }
    }

    let verification = verify_within(mission, limits, &trajectories);
    let flight_of = |vehicle: usize| {
        plans
            .iter()
            .position(|p| p.vehicle == vehicle)
            .and_then(|i| flights.get(i))
    };
    let mut failures: Vec<Failure> = verification
        .checks
        .iter()
        .filter(|c| !c.ok)
        .map(|c| {
            let (vehicle, other, time) =
                c.at.as_ref()
                    .map_or((0, None, 0.0), |a| (a.uav, a.other.clone(), a.time));
            Failure {
                constraint: c.name.to_owned(),
                vehicle,
                other,
                waypoint: flight_of(vehicle).map_or(0, |f| f.leg(time) + 1),
                time,
                value: c.worst.unwrap_or(f64::NAN),
                relation: c.relation,
                limit: c.limit,
            }
        })
        .collect();
    for i in verification.inspections.iter().filter(|i| !i.ok) {
        let vehicle = i.uav.unwrap_or(0);
        let time = i.time.map_or(0.0, |t| t[0]);
        failures.push(Failure {
            constraint: format!(
                "inspection pass of eq. 8 (metres in [{}, {}] m of the surface)",
                i.band[0], i.band[1]
            ),
            vehicle,
            other: Some(format!("'{}'", i.obstacle)),
            waypoint: flight_of(vehicle).map_or(0, |f| f.leg(time) + 1),
            time,
            value: i.achieved,
            relation: "≥",
            limit: i.required,
        });
    }
    Reverification {
        verification,
        failures,
        max_deviation,
        deviation_at,
        max_timing_error,
        timing_at,
    }
}

/// The plan's own slack against `limits`: the smallest excess of a
/// clearance, altitude or bounds margin over its limit, or half the excess
/// of a distance between two vehicles. `None` when nothing was measured.
pub fn slack(mission: &Mission, limits: &Limits, tracks: &[Track]) -> Option<(f64, String)> {
    let trajectories: Vec<Trajectory> = tracks
        .iter()
        .map(|t| Trajectory {
            uav: t.vehicle,
            samples: t
                .samples
                .iter()
                .map(|s| Sample {
                    t: s.t,
                    position: s.position,
                    velocity: s.velocity,
                })
                .collect(),
        })
        .collect();
    let limits = Limits {
        inspections: false,
        ..*limits
    };
    let v = verify_within(mission, &limits, &trajectories);
    v.checks
        .iter()
        .filter_map(|c| {
            let worst = c.worst?;
            let excess = if c.relation == "≥" {
                worst - c.limit
            } else {
                c.limit - worst
            };
            let share = if c.name.starts_with("inter-UAV") {
                excess / 2.0
            } else {
                excess
            };
            Some((share, c.name.to_owned()))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}
