//! The files flown as an autopilot flies them, and checked.
//!
//! The waypoint files (`.plan`, `.waypoints`, which store the same
//! coordinates): every vehicle starts at its first waypoint at t = 0,
//! together with the others, waits out each waypoint's hold, and flies each
//! leg in a straight line as its autopilot reads the written speed
//! ([`super::legs`]), between the positions the file stores (1e-7°,
//! float32). The CSV: its samples as written, in straight lines between
//! them. The flights are sampled at the planned tracks' instants and handed
//! to the shared verification ([`crate::pipelines::verify::verify_within`],
//! the one θ-PSO's plans pass too, for every pipeline's files) with the hard
//! limits the plan was held to. Also measured: the largest distance between where a vehicle flies
//! and where its track has it at the same instant (the deviation), the
//! largest difference between when a vehicle reaches a waypoint and when
//! the plan says (the timing error), and every leg's commanded speed and
//! climb or descent rate against the vehicle's limits.
//!
//! Take-off, landing and loitering are outside the check: they happen before
//! the first and after the last waypoint.
//!
//! Long (~775 lines) because it is the one check of the written files: its findings and
//! their advice, the flight an autopilot makes of a file, and each measure taken on it
//! (deviation, timing, verification, leg rates, the CSV as written), all reading the same
//! flights and limits.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::{LegLimits, Placement, Planned, VehiclePlan, csv, noun};
use crate::mission::Mission;
use crate::outcome::tracks::{Track, TrackSample};
use crate::pipelines::TrackSample as Sample;
use crate::pipelines::verify::Trajectory;
use crate::pipelines::verify::{Verification, verify_within};
use crate::pipelines::{Kind, Limits};

/// Which files a check flew.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Files {
    /// The `.plan` and `.waypoints` files (the same stored waypoints).
    Waypoints,
    /// The CSV samples as written.
    Csv,
}

/// A broken constraint of the flown files, located.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Failure {
    /// The verification row ("obstacle clearance", …), the inspection, or
    /// the rate ("commanded ground speed", "climb rate", …).
    pub constraint: String,
    /// How the pipeline names its vehicles ("UAV", "aircraft", "agent").
    pub noun: &'static str,
    /// 0-based vehicle.
    pub vehicle: usize,
    /// The other vehicle or the obstacle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub other: Option<String>,
    /// 1-based waypoint the vehicle is flying to (or holding at); for the
    /// CSV, the 1-based sample.
    pub waypoint: usize,
    /// Seconds from the common start.
    pub time: f64,
    /// The worst value and the limit it breaks.
    pub value: f64,
    pub relation: &'static str,
    pub limit: f64,
    /// "m" or "m/s".
    pub unit: &'static str,
    pub files: Files,
    /// The planned tracks themselves break this check: no tolerance mends it.
    pub in_plan: bool,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let other = self
            .other
            .as_deref()
            .map_or_else(String::new, |o| format!(" vs {o}"));
        let (files, step) = match self.files {
            Files::Waypoints => ("", "leg to waypoint"),
            Files::Csv => ("CSV as written: ", "sample"),
        };
        write!(
            f,
            "{files}{}: {} {}{other}, {step} {}, t = {:.1} s: {:.3} {unit}, must be {} {} {unit}",
            self.constraint,
            self.noun,
            self.vehicle + 1,
            self.waypoint,
            self.time,
            self.value,
            self.relation,
            self.limit,
            unit = self.unit,
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

/// One rate of the written legs against the vehicles' limits: its worst leg.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rate {
    /// "commanded ground speed", "climb rate", "descent rate",
    /// "commanded airspeed" (largest), "commanded airspeed (smallest)".
    pub name: &'static str,
    /// The worst value, m/s (the one nearest its vehicle's limit, or
    /// furthest past it).
    pub worst: f64,
    pub relation: &'static str,
    /// That vehicle's limit; `None`: the mission sets none.
    pub limit: Option<f64>,
    pub ok: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at: Option<At>,
}

/// The CSV samples as written, flown.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CsvCheck {
    pub verification: Verification,
    /// Largest distance between a written sample (where its coordinates put
    /// it: latitude, longitude, altitude with `[origin]`, else x, y, z) and
    /// the planned one, metres.
    pub max_deviation: f64,
}

/// The verdict on the flown files.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reverification {
    /// The pipeline's verification table, on the flown waypoint files.
    pub verification: Verification,
    /// The written legs' speeds and vertical rates.
    pub rates: Vec<Rate>,
    /// The CSV as written, when one is exported.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub csv: Option<CsvCheck>,
    /// Every broken constraint of the files exported.
    pub failures: Vec<Failure>,
    /// Largest |flown(t) − track(t)| of the waypoint files, metres.
    pub max_deviation: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deviation_at: Option<At>,
    /// Largest |arrival − planned time| at a waypoint, seconds.
    pub max_timing_error: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing_at: Option<At>,
    /// The tolerance the reduction was held to, metres.
    pub tolerance: f64,
    pub pipeline: Kind,
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

    /// What to do about the failures, one line per kind of cause: each
    /// names the check it answers.
    pub fn advice(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for f in &self.failures {
            let line = advice(f, self.pipeline, self.tolerance, self.max_deviation);
            if !out.contains(&line) {
                out.push(line);
            }
        }
        out
    }
}

/// The advice for one failure.
fn advice(f: &Failure, pipeline: Kind, tolerance: f64, deviation: f64) -> String {
    let (name, slug) = (pipeline.words().name, pipeline.words().slug);
    let c = f.constraint.as_str();
    if f.unit == "m/s" {
        let field = match (pipeline.words().speed_field, c) {
            (Some(field), _) => field,
            (None, "climb rate") => "vehicle.max_climb_rate",
            (None, "descent rate") => "vehicle.max_descent_rate",
            (None, _) => "vehicle.max_speed",
        };
        return format!(
            "{c}: the {name} plan needs {:.2} m/s on that leg and its {} is limited to {} m/s: \
             raise {field} (or this {}'s entry in vehicle.uavs) if it flies that fast, or plan \
             it slower; no tolerance changes that",
            f.value, f.noun, f.limit, f.noun
        );
    }
    if !f.in_plan {
        return format!(
            "{c}: the plan keeps it, the flown files do not: a smaller --tolerance (now \
             {tolerance:.3} m; the files stray up to {deviation:.3} m) keeps them closer to the \
             tracks; --force writes anyway"
        );
    }
    let fix = if c.starts_with("distance inside the x-y bounds") {
        pipeline
            .words()
            .bounds_advice
            .unwrap_or("widen bounds.x and bounds.y, or move the route inside them")
    } else if c.starts_with("altitude") {
        "widen bounds.z, or plan the heights inside it"
    } else {
        "plan it again (another --seed, or more room in the mission)"
    };
    format!(
        "{c}: the {name} plan itself breaks it ({} {} at t = {:.1} s; `skyform run {slug}` \
         shows it), so no tolerance changes that: {fix}",
        f.noun,
        f.vehicle + 1,
        f.time
    )
}

/// A verification row's name in the pipeline's words ("inter-aircraft
/// distance (closest)" for FLATLO).
pub fn worded(name: &str, noun: &str) -> String {
    name.replace("inter-UAV", &format!("inter-{noun}"))
}

/// "UAV 2" of the verification's locations in the pipeline's words.
fn worded_other(other: Option<String>, noun: &str) -> Option<String> {
    other.map(|o| match o.strip_prefix("UAV ") {
        Some(n) => format!("{noun} {n}"),
        None => o,
    })
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
                t += plan
                    .legs
                    .duration(&w[i - 1].position, &wp.position, wp.speed);
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

    /// When the vehicle leaves each waypoint, seconds.
    pub fn departures(&self) -> &[f64] {
        &self.depart
    }

    /// 0-based index of the waypoint the vehicle flies to (or holds at) at t.
    pub fn leg(&self, t: f64) -> usize {
        let last = self.arrive.len().saturating_sub(1);
        // Departures never go back in time (each leg starts where the one
        // before ended), so the first not before t is a binary search: the
        // flight check asks this of every vehicle at every step.
        let i = self.depart.partition_point(|&d| d < t);
        if i < self.depart.len() { i } else { last }
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

/// Flies the exported files and checks them against the planned limits
/// and the mission's band and bounds: the waypoint plans (their failures
/// count when `waypoint_files` are written) and the CSV texts (when
/// given); measures deviation from the tracks, timing errors and the rates
/// of the written legs.
///
/// Long (~130 lines) because it takes each measure in turn on the one set of flights (the
/// instants, the deviation from the tracks, the timing errors, the verification, the leg
/// rates, the CSV as written), each filling its fields of the one `Reverification`.
pub fn reverify(
    mission: &Mission,
    planned: &Planned,
    plans: &[VehiclePlan],
    tolerance: f64,
    waypoint_files: bool,
    csv_texts: Option<&[String]>,
    placement: Option<&Placement>,
) -> Reverification {
    let noun = noun(planned.pipeline);
    let tracks = &planned.tracks;
    let limits = &planned.limits;
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

    let in_plan = planned_verdicts(mission, limits, tracks);
    let verification = verify_within(mission, limits, &trajectories);
    let leg_of = |vehicle: usize, time: f64| {
        plans
            .iter()
            .position(|p| p.vehicle == vehicle)
            .and_then(|i| flights.get(i))
            .map_or(0, |f| f.leg(time) + 1)
    };
    let mut failures = verification_failures(&verification, noun, &in_plan, Files::Waypoints)
        .into_iter()
        .map(|mut f| {
            f.waypoint = leg_of(f.vehicle, f.time);
            f
        })
        .collect::<Vec<_>>();
    let (rates, rate_failures) = rates(plans, noun);
    failures.extend(rate_failures);
    if !waypoint_files {
        failures.clear();
    }

    let csv = csv_texts.map(|texts| {
        let (check, csv_failures) = csv_as_written(mission, limits, tracks, texts, placement);
        failures.extend(
            csv_failures
                .into_iter()
                .chain(verification_failures(
                    &check.verification,
                    noun,
                    &in_plan,
                    Files::Csv,
                ))
                .collect::<Vec<_>>(),
        );
        check
    });

    Reverification {
        verification,
        rates,
        csv,
        failures,
        max_deviation,
        deviation_at,
        max_timing_error,
        timing_at,
        tolerance,
        pipeline: planned.pipeline,
    }
}

/// The names of the checks the planned tracks themselves break.
fn planned_verdicts(mission: &Mission, limits: &Limits, tracks: &[Track]) -> Vec<String> {
    let v = verify_within(mission, limits, &trajectories_of(tracks));
    v.checks
        .iter()
        .filter(|c| !c.ok)
        .map(|c| c.name.to_owned())
        .chain(
            v.inspections
                .iter()
                .filter(|i| !i.ok)
                .map(|i| inspection_name(&i.band)),
        )
        .collect()
}

fn inspection_name(band: &[f64; 2]) -> String {
    format!(
        "inspection pass of eq. 8 (metres in [{}, {}] m of the surface)",
        band[0], band[1]
    )
}

/// One failure per broken check of `v` at its worst instant (the
/// waypoint is the 1-based sample until the caller says which leg).
fn verification_failures(
    v: &Verification,
    noun: &'static str,
    in_plan: &[String],
    files: Files,
) -> Vec<Failure> {
    let mut out: Vec<Failure> = v
        .checks
        .iter()
        .filter(|c| !c.ok)
        .map(|c| {
            let (vehicle, other, time) =
                c.at.as_ref()
                    .map_or((0, None, 0.0), |a| (a.uav, a.other.clone(), a.time));
            Failure {
                constraint: worded(c.name, noun),
                noun,
                vehicle,
                other: worded_other(other, noun),
                waypoint: 0,
                time,
                value: c.worst.unwrap_or(f64::NAN),
                relation: c.relation,
                limit: c.limit,
                unit: "m",
                files,
                in_plan: in_plan.iter().any(|n| n == c.name),
            }
        })
        .collect();
    for i in v.inspections.iter().filter(|i| !i.ok) {
        let name = inspection_name(&i.band);
        out.push(Failure {
            in_plan: in_plan.contains(&name),
            constraint: name,
            noun,
            vehicle: i.uav.unwrap_or(0),
            other: Some(format!("'{}'", i.obstacle)),
            waypoint: 0,
            time: i.time.map_or(0.0, |t| t[0]),
            value: i.achieved,
            relation: "≥",
            limit: i.required,
            unit: "m",
            files,
        });
    }
    out
}

/// The rates of every written leg against its vehicle's limits: the
/// commanded speed (ground speed or airspeed) as written, and the vertical
/// rate the plan gives the leg (its height change over the planned time
/// between its ends). One row per rate (its worst leg) and one failure per
/// rate broken (its worst leg).
fn rates(plans: &[VehiclePlan], noun: &'static str) -> (Vec<Rate>, Vec<Failure>) {
    struct Seen {
        name: &'static str,
        relation: &'static str,
        value: f64,
        limit: Option<f64>,
        at: At,
    }
    impl Seen {
        /// How far past (positive) or short of its limit the value is.
        fn excess(&self) -> f64 {
            self.limit.map_or(f64::NEG_INFINITY, |l| {
                if self.relation == "≤" {
                    self.value - l
                } else {
                    l - self.value
                }
            })
        }
        /// Ordering for "worst": past or nearest the limit, else the
        /// largest (smallest, for a lower bound) value.
        fn badness(&self) -> f64 {
            match (self.limit, self.relation) {
                (Some(_), _) => self.excess(),
                (None, "≤") => self.value,
                (None, _) => -self.value,
            }
        }
    }
    let mut seen: Vec<Seen> = Vec::new();
    for plan in plans {
        let legs: &LegLimits = &plan.legs;
        for (i, pair) in plan.waypoints.windows(2).enumerate() {
            let (a, b) = (&pair[0], &pair[1]);
            let at = At {
                vehicle: plan.vehicle,
                waypoint: i + 2,
                time: b.t,
            };
            let mut push = |name, relation, value, limit| {
                seen.push(Seen {
                    name,
                    relation,
                    value,
                    limit,
                    at,
                })
            };
            if b.speed > 0.0 {
                push(legs.speed_name(), "≤", b.speed, legs.speed);
                if legs.fixed_wing {
                    push(
                        "commanded airspeed (smallest)",
                        "≥",
                        b.speed,
                        legs.min_speed,
                    );
                }
            }
            if !legs.fixed_wing {
                let vertical = LegLimits::vertical_rate(&a.position, &b.position, b.t - a.t);
                if vertical >= 0.0 {
                    push("climb rate", "≤", vertical, legs.climb);
                } else {
                    push("descent rate", "≤", -vertical, legs.descent);
                }
            }
        }
    }
    let mut names: Vec<&'static str> = Vec::new();
    for s in &seen {
        if !names.contains(&s.name) {
            names.push(s.name);
        }
    }
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    for name in names {
        let worst = seen
            .iter()
            .filter(|s| s.name == name)
            .max_by(|a, b| a.badness().total_cmp(&b.badness()));
        let Some(w) = worst else { continue };
        let ok = w.excess() <= 1e-9;
        rows.push(Rate {
            name,
            worst: w.value,
            relation: w.relation,
            limit: w.limit,
            ok,
            at: Some(w.at),
        });
        if let (false, Some(limit)) = (ok, w.limit) {
            failures.push(Failure {
                constraint: name.to_owned(),
                noun,
                vehicle: w.at.vehicle,
                other: None,
                waypoint: w.at.waypoint,
                time: w.at.time,
                value: w.value,
                relation: w.relation,
                limit,
                unit: "m/s",
                files: Files::Waypoints,
                in_plan: true,
            });
        }
    }
    (rows, failures)
}

/// The CSV texts read back (the coordinates as written), flown in straight
/// lines between their samples and checked; their deviation from the tracks.
fn csv_as_written(
    mission: &Mission,
    limits: &Limits,
    tracks: &[Track],
    texts: &[String],
    placement: Option<&Placement>,
) -> (CsvCheck, Vec<Failure>) {
    let mut max_deviation: f64 = 0.0;
    let written: Vec<Track> = tracks
        .iter()
        .zip(texts)
        .map(|(track, text)| {
            let samples = csv::read(text, placement);
            for (s, p) in samples.iter().zip(&track.samples) {
                max_deviation = max_deviation.max((s.position - p.position).norm());
            }
            Track {
                vehicle: track.vehicle,
                samples,
            }
        })
        .collect();
    let verification = verify_within(mission, limits, &trajectories_of(&written));
    let mut failures = Vec::new();
    let short = tracks
        .iter()
        .zip(&written)
        .find(|(t, w)| t.samples.len() != w.samples.len());
    if let Some((t, w)) = short {
        // Cannot happen with the writer's own text; said rather than hidden.
        failures.push(Failure {
            constraint: "samples read back".into(),
            noun: "vehicle",
            vehicle: t.vehicle,
            other: None,
            waypoint: w.samples.len() + 1,
            time: 0.0,
            value: w.samples.len() as f64,
            relation: "=",
            limit: t.samples.len() as f64,
            unit: "samples",
            files: Files::Csv,
            in_plan: false,
        });
    }
    (
        CsvCheck {
            verification,
            max_deviation,
        },
        failures,
    )
}

fn trajectories_of(tracks: &[Track]) -> Vec<Trajectory> {
    tracks
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
        .collect()
}

/// The plan's own slack against `limits`: the smallest excess of a
/// clearance, altitude or bounds margin over its limit, or half the excess
/// of a distance between two vehicles. A check the plan itself breaks has
/// no slack to share (the refusal names it): it is left out, so it does not
/// shrink the tolerance of the checks it keeps. `None` when nothing was
/// measured.
pub fn slack(mission: &Mission, limits: &Limits, tracks: &[Track]) -> Option<(f64, String)> {
    let limits = Limits {
        inspections: false,
        ..*limits
    };
    let v = verify_within(mission, &limits, &trajectories_of(tracks));
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
            (share >= 0.0).then(|| (share, c.name.to_owned()))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}
