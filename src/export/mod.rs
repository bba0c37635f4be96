//! From plan to flight: one mission file per vehicle that autopilots load,
//! re-verified as they will be flown.
//!
//! Each vehicle's timed track ([`crate::outcome::tracks`]) is reduced to waypoints
//! ([`simplify`]: every sample within the tolerance of where the straight leg
//! puts the vehicle at the same instant) with a commanded speed per leg, so
//! that each vehicle reaches each waypoint when the plan says. The reduced
//! plans are then flown as an autopilot flies them (straight legs at the
//! commanded speeds, all vehicles starting together) and checked with the
//! pipeline's own verification ([`reverify`]). Only then are the files
//! written: QGroundControl `.plan` ([`plan`]), `QGC WPL 110` ([`wpl`]) or CSV
//! ([`csv`]), atomically. A KML of the whole plan ([`kml`]: the mission, every
//! vehicle's track, the verdict) is one more file, to look at over imagery.
//! `docs/export.md` describes the formats.

pub mod csv;
pub mod geodesy;
pub mod kml;
pub mod plan;
pub mod reverify;
pub mod simplify;
pub mod wpl;

use std::path::{Path, PathBuf};

use nalgebra::Point3;
use serde::Serialize;

use crate::mission::Mission;
use crate::outcome::tracks::{self, Track};
use crate::pipelines::Kind;
use crate::pipelines::Limits;
use crate::pipelines::flatlo::FlatloOutcome;
use crate::pipelines::fleet::FleetOutcome;
use crate::pipelines::theta_pso::ThetaPsoOutcome;

pub use geodesy::{Frame, Geodetic};
pub use reverify::Reverification;

/// A file format of the export.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// QGroundControl `.plan` JSON.
    Plan,
    /// `QGC WPL 110` text (`.waypoints`), as MAVProxy and Mission Planner read it.
    Wpl,
    /// Timed ENU (and WGS-84) samples of each track.
    Csv,
    /// One KML of the mission and every vehicle's track (Google Earth).
    Kml,
}

impl Format {
    pub const ALL: [Format; 4] = [Format::Plan, Format::Wpl, Format::Csv, Format::Kml];

    pub fn extension(self) -> &'static str {
        match self {
            Format::Plan => "plan",
            Format::Wpl => "waypoints",
            Format::Csv => "csv",
            Format::Kml => "kml",
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Format::Plan => "plan",
            Format::Wpl => "wpl",
            Format::Csv => "csv",
            Format::Kml => "kml",
        }
    }

    /// Needs the mission's `[origin]` (latitude and longitude).
    pub fn geodetic(self) -> bool {
        !matches!(self, Format::Csv)
    }

    /// One file per vehicle, from the re-verified waypoint plans (the KML
    /// is one file of the planned tracks, to look at, not to fly).
    pub fn per_vehicle(self) -> bool {
        !matches!(self, Format::Kml)
    }
}

/// Slowest commanded speed of a multicopter leg, m/s; a vehicle that must
/// go slower waits at the leg's start instead.
pub const MIN_SPEED: f64 = 0.1;

/// Holds are written to this step, seconds (PX4 reads param1 as a float;
/// ArduCopter keeps whole seconds).
pub const HOLD_STEP: f64 = 0.01;

/// Commanded speeds are written to this step, m/s.
pub const SPEED_STEP: f64 = 0.01;

/// Smallest tolerance used, metres (a plan with no slack at all still gets
/// finite waypoint lists).
pub const MIN_TOLERANCE: f64 = 1e-3;

/// What a pipeline's outcome gives the export: each vehicle's track, the
/// limits its verification holds, and the deviation it allows.
#[derive(Debug, Clone, PartialEq)]
pub struct Planned {
    pub pipeline: Kind,
    pub seed: u64,
    pub tracks: Vec<Track>,
    pub limits: Limits,
    /// The most the pipeline lets a vehicle stray from its track, metres,
    /// before the plan's own slack is considered (see [`Planned::default_tolerance`]).
    pub margin: f64,
    /// Where `margin` comes from, in words.
    pub margin_source: String,
    /// Fixed-wing loiter radius at the end, metres.
    pub loiter_radius: f64,
    /// The run's verdict in one line (`Outcome::headline`), for the KML.
    pub verdict: String,
}

impl Planned {
    /// What the export needs of any pipeline's outcome.
    pub fn from_outcome(mission: &Mission, outcome: &crate::outcome::Outcome) -> Self {
        use crate::outcome::Outcome;
        match outcome {
            Outcome::ThetaPso(o) => Planned::theta_pso(mission, o),
            Outcome::Flatlo(o) => Planned::flatlo(mission, o),
            Outcome::Fleet(o) => Planned::fleet(mission, o),
        }
    }

    /// The headline of an outcome (what the designer and `skyform run` say).
    fn headline(outcome: crate::outcome::Outcome) -> String {
        outcome.headline()
    }

    /// θ-PSO: the UAVs' trajectories, held to r_Q, [2 r_Q, d_com], the band,
    /// the bounds and eq. 8; the margin is `theta_pso.clearance_margin`, the
    /// room the cost keeps for a real autopilot.
    pub fn theta_pso(mission: &Mission, outcome: &ThetaPsoOutcome) -> Self {
        Planned {
            pipeline: Kind::ThetaPso,
            seed: outcome.seed,
            tracks: tracks::theta_pso(outcome),
            // The written legs are flown by the autopilot's own trajectory
            // generator: its speeds are checked, not its accelerations.
            limits: Limits {
                dynamics: false,
                ..Limits::theta_pso(mission)
            },
            margin: mission.theta_pso.clearance_margin,
            margin_source: "theta_pso.clearance_margin".into(),
            loiter_radius: 0.0,
            verdict: Planned::headline(crate::outcome::Outcome::ThetaPso(Box::new(
                outcome.clone(),
            ))),
        }
    }

    /// FLATLO: the aircraft's references, held to `min_separation` (and the
    /// band and bounds, which the geofence enforces); the margin is the
    /// largest tracking error of the simulated autopilot with which the
    /// squadron was verified.
    pub fn flatlo(mission: &Mission, outcome: &FlatloOutcome) -> Self {
        let p = &mission.flatlo;
        let tracking = outcome
            .aircraft
            .iter()
            .map(|a| a.tracking_max)
            .fold(0.0, f64::max);
        Planned {
            pipeline: Kind::Flatlo,
            seed: outcome.seed,
            tracks: tracks::flatlo(outcome),
            limits: Limits {
                clearance: 0.0,
                closest: p.min_separation,
                farthest: None,
                inspections: false,
                dynamics: false,
            },
            margin: tracking,
            margin_source: "the simulated squadron's largest tracking error".into(),
            loiter_radius: p.turn_radius,
            verdict: Planned::headline(crate::outcome::Outcome::Flatlo(Box::new(outcome.clone()))),
        }
    }

    /// The fleet: the quadrotors' flights, held to the safety distance c
    /// between agents and from obstacles (and the band and bounds); the
    /// margin is the convergence tolerance on c, shared by two agents.
    pub fn fleet(mission: &Mission, outcome: &FleetOutcome) -> Self {
        let p = &mission.fleet;
        Planned {
            pipeline: Kind::Fleet,
            seed: outcome.seed,
            tracks: tracks::fleet(outcome),
            limits: Limits {
                clearance: p.safety_distance,
                closest: p.safety_distance,
                farthest: None,
                inspections: false,
                dynamics: false,
            },
            margin: p.tolerance * p.safety_distance / 2.0,
            margin_source: "fleet.tolerance × fleet.safety_distance / 2".into(),
            loiter_radius: 0.0,
            verdict: Planned::headline(crate::outcome::Outcome::Fleet(Box::new(outcome.clone()))),
        }
    }

    /// The default tolerance: the pipeline's margin, or less when the plan
    /// itself has less slack against a constraint (a clearance's excess over
    /// its limit; half a distance's excess between two vehicles, since both
    /// may stray). Never below [`MIN_TOLERANCE`].
    pub fn default_tolerance(&self, mission: &Mission) -> (f64, String) {
        let slack = reverify::slack(mission, &self.limits, &self.tracks);
        match slack {
            Some((s, what)) if s < self.margin => {
                (s.max(MIN_TOLERANCE), format!("the plan's slack on {what}"))
            }
            _ => (self.margin.max(MIN_TOLERANCE), self.margin_source.clone()),
        }
    }
}

/// One waypoint of a vehicle's reduced plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Waypoint {
    /// When the plan has the vehicle here, seconds from the common start.
    pub t: f64,
    /// Metres ENU.
    pub position: Point3<f64>,
    /// Commanded speed of the leg that ends here, m/s (0 for the first).
    pub speed: f64,
    /// Seconds the vehicle waits here before the next leg.
    pub hold: f64,
}

/// One vehicle's reduced plan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VehiclePlan {
    /// 0-based (file names say `uav<vehicle + 1>`).
    pub vehicle: usize,
    pub waypoints: Vec<Waypoint>,
}

impl VehiclePlan {
    /// Where the vehicle stands before take-off: on the ground (z = 0) below
    /// its first waypoint.
    pub fn home(&self) -> Point3<f64> {
        self.waypoints.first().map_or_else(Point3::origin, |w| {
            Point3::new(w.position.x, w.position.y, 0.0)
        })
    }
}

/// Reduces every track to waypoints and gives each leg the speed that
/// arrives on time, rounded to [`SPEED_STEP`]; a rounding early on is made
/// up on the next leg, so timing errors do not add up. Every sample of a
/// track stays within `tolerance` of where the plan *as flown* (rounded
/// speeds, holds) puts the vehicle at the same instant: the SED tolerance
/// of the reduction is tightened until the flight is within it, down to
/// keeping every sample.
pub fn reduce(tracks: &[Track], tolerance: f64, fixed_wing: bool) -> Vec<VehiclePlan> {
    tracks
        .iter()
        .map(|track| reduce_track(track, tolerance, fixed_wing))
        .collect()
}

/// One track's plan within `tolerance` as flown (see [`reduce`]).
fn reduce_track(track: &Track, tolerance: f64, fixed_wing: bool) -> VehiclePlan {
    /// Tightenings tried before every sample is kept.
    const TRIES: usize = 12;
    let mut sed = tolerance;
    for _ in 0..TRIES {
        let kept = simplify::simplify(&track.samples, sed);
        let plan = plan_through(track, &kept, fixed_wing);
        let deviation = reverify::deviation(&plan, track);
        if deviation <= tolerance {
            return plan;
        }
        // Rounding and holds add what the reduction did not see: ask the
        // reduction for less, in proportion to the excess.
        sed *= 0.9 * tolerance / deviation;
    }
    let every: Vec<usize> = (0..track.samples.len()).collect();
    plan_through(track, &every, fixed_wing)
}

/// The plan whose waypoints are `track`'s samples `kept`, each leg at the
/// speed (or hold, then the slowest speed) that reaches it on time.
fn plan_through(track: &Track, kept: &[usize], fixed_wing: bool) -> VehiclePlan {
    let mut waypoints: Vec<Waypoint> = Vec::with_capacity(kept.len());
    // When the vehicle flown as planned reaches the last waypoint.
    let mut flown = 0.0;
    for &k in kept {
        let s = &track.samples[k];
        let Some(prev) = waypoints.last_mut() else {
            flown = s.t;
            waypoints.push(Waypoint {
                t: s.t,
                position: s.position,
                speed: 0.0,
                hold: 0.0,
            });
            continue;
        };
        let length = (s.position - prev.position).norm();
        let available = s.t - flown;
        let (hold, speed) = leg_speed(length, available, fixed_wing);
        prev.hold = hold;
        flown += hold + if speed > 0.0 { length / speed } else { 0.0 };
        waypoints.push(Waypoint {
            t: s.t,
            position: s.position,
            speed,
            hold: 0.0,
        });
    }
    VehiclePlan {
        vehicle: track.vehicle,
        waypoints,
    }
}

/// Hold (seconds, to [`HOLD_STEP`]) and commanded speed for a leg of
/// `length` metres that has `available` seconds.
fn leg_speed(length: f64, available: f64, fixed_wing: bool) -> (f64, f64) {
    let round = |v: f64, step: f64| (v / step).round() * step;
    let available = available.max(0.0);
    if length <= 1e-9 {
        // A vehicle that stays put: a multicopter holds; a fixed wing cannot.
        let hold = if fixed_wing {
            0.0
        } else {
            round(available, HOLD_STEP)
        };
        return (hold, 0.0);
    }
    let available = available.max(1e-3);
    let needed = length / available;
    if fixed_wing || needed >= MIN_SPEED {
        return (0.0, round(needed, SPEED_STEP).max(SPEED_STEP));
    }
    // Too slow to command: wait, then fly the leg at the slowest speed.
    let hold = round(available - length / MIN_SPEED, HOLD_STEP).max(0.0);
    (hold, MIN_SPEED)
}

/// How to export.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    pub formats: Vec<Format>,
    pub out_dir: PathBuf,
    /// Metres; `None`: [`Planned::default_tolerance`].
    pub tolerance: Option<f64>,
    /// Write even when the flown plans break a constraint.
    pub force: bool,
}

/// A file written.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Written {
    pub path: PathBuf,
    pub format: Format,
    /// 0-based vehicle (0 for the KML, which holds them all).
    pub vehicle: usize,
    /// Waypoints (NAV_WAYPOINT items) of the vehicle's plan (KML: tracks).
    pub waypoints: usize,
    /// Lines or mission items written (CSV: samples; KML: placemarks).
    pub items: usize,
}

/// What an export did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Exported {
    pub pipeline: Kind,
    pub tolerance: f64,
    pub tolerance_source: String,
    pub plans: Vec<VehiclePlan>,
    pub reverification: Reverification,
    /// Written although the flown plans break a constraint (`--force`).
    pub forced: bool,
    pub files: Vec<Written>,
}

/// Why nothing was written.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error(
        "the {0} format needs the mission's geodetic origin: add an [origin] section \
         (latitude, longitude, altitude of the ENU origin) to the mission, or export csv"
    )]
    NoOrigin(&'static str),
    #[error("the tolerance must be a positive number of metres, got {0}")]
    BadTolerance(f64),
    #[error("the {0} result has no vehicle to export")]
    Empty(&'static str),
    #[error("export refused: the plans as flown break a constraint:\n{}", .0.failure_text())]
    Refused(Box<Reverification>),
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// File name of one vehicle's export: `<mission-stem>-<pipeline>-uav<N>.<ext>`.
pub fn file_name(stem: &str, pipeline: Kind, vehicle: usize, format: Format) -> String {
    format!(
        "{stem}-{}-uav{}.{}",
        pipeline.slug(),
        vehicle + 1,
        format.extension()
    )
}

/// File name of the KML of the whole plan: `<mission-stem>-<pipeline>.kml`.
pub fn kml_file_name(stem: &str, pipeline: Kind) -> String {
    format!("{stem}-{}.kml", pipeline.slug())
}

/// Reduces, re-verifies and (unless refused) writes one file per vehicle and
/// format into `options.out_dir`, named after `stem` (the mission file's stem).
pub fn export(
    mission: &Mission,
    stem: &str,
    planned: &Planned,
    options: &Options,
) -> Result<Exported, ExportError> {
    let frame = mission.origin.as_ref().map(Frame::new);
    if frame.is_none()
        && let Some(f) = options.formats.iter().find(|f| f.geodetic())
    {
        return Err(ExportError::NoOrigin(f.name()));
    }
    if planned.tracks.iter().all(|t| t.samples.is_empty()) {
        return Err(ExportError::Empty(planned.pipeline.slug()));
    }
    let (tolerance, tolerance_source) = match options.tolerance {
        Some(t) if t.is_finite() && t > 0.0 => (t, "--tolerance".to_owned()),
        Some(t) => return Err(ExportError::BadTolerance(t)),
        None => planned.default_tolerance(mission),
    };
    let fixed_wing = planned.pipeline.fixed_wing();
    let plans = reduce(&planned.tracks, tolerance, fixed_wing);
    let reverification = reverify::reverify(mission, &planned.limits, &planned.tracks, &plans);
    // The KML shows the plan itself: only the files to fly are refused.
    let flown = options.formats.iter().any(|f| f.per_vehicle());
    let forced = flown && !reverification.passed();
    if forced && !options.force {
        return Err(ExportError::Refused(Box::new(reverification)));
    }

    std::fs::create_dir_all(&options.out_dir).map_err(|source| ExportError::Io {
        path: options.out_dir.clone(),
        source,
    })?;
    let mut files = Vec::new();
    for format in &options.formats {
        if let (Format::Kml, Some(frame)) = (format, &frame) {
            let path = options.out_dir.join(kml_file_name(stem, planned.pipeline));
            let (text, items) = kml::render(mission, planned, frame);
            write_atomic(&path, text.as_bytes())?;
            files.push(Written {
                path,
                format: *format,
                vehicle: 0,
                waypoints: planned.tracks.len(),
                items,
            });
            continue;
        }
        for (plan, track) in plans.iter().zip(&planned.tracks) {
            let name = file_name(stem, planned.pipeline, plan.vehicle, *format);
            let path = options.out_dir.join(name);
            let (text, items) = match (format, &frame) {
                (Format::Csv, _) => csv::render(track, frame.as_ref()),
                (Format::Plan, Some(frame)) => {
                    plan::render(mission, planned, plan, frame, tolerance)
                }
                (Format::Wpl, Some(frame)) => wpl::render(planned, plan, frame, tolerance),
                (f @ (Format::Plan | Format::Wpl | Format::Kml), _) => {
                    return Err(ExportError::NoOrigin(f.name()));
                }
            };
            write_atomic(&path, text.as_bytes())?;
            files.push(Written {
                path,
                format: *format,
                vehicle: plan.vehicle,
                waypoints: plan.waypoints.len(),
                items,
            });
        }
    }
    Ok(Exported {
        pipeline: planned.pipeline,
        tolerance,
        tolerance_source,
        plans,
        reverification,
        forced,
        files,
    })
}

/// Writes atomically (`atomic::write`: a synced temporary file
/// renamed over `path`, so a reader never sees half a file), with the
/// permissions of any file the user creates.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    crate::base::atomic::write(path, bytes).map_err(|source| ExportError::Io {
        path: path.to_owned(),
        source,
    })
}

/// One mission item, as `.plan` and `.waypoints` both write it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Item {
    /// MAV_CMD.
    pub command: u16,
    /// MAV_FRAME: 3 (global, altitude relative to home) or 2 (mission, for DO commands).
    pub frame: u8,
    /// param1..param4; NaN where the autopilot should keep its own value.
    pub params: [f64; 4],
    /// Latitude, longitude (degrees) and altitude relative to home (metres);
    /// `None` for commands without a position.
    pub at: Option<[f64; 3]>,
    /// Index of the waypoint (0-based) when the item is one.
    pub waypoint: Option<usize>,
}

/// MAV_CMD numbers used.
pub mod cmd {
    pub const NAV_WAYPOINT: u16 = 16;
    pub const NAV_LOITER_UNLIM: u16 = 17;
    pub const NAV_LAND: u16 = 21;
    pub const NAV_TAKEOFF: u16 = 22;
    pub const DO_CHANGE_SPEED: u16 = 178;
}

/// The home position (WGS-84) and the mission items of one vehicle: take-off
/// to the first waypoint's height, a speed change wherever the commanded
/// speed changes, the waypoints, then land (multicopters) or loiter without
/// limit at the last waypoint (fixed wing: ArduPlane would otherwise return
/// to launch when the mission ends, across the other aircraft's plans).
pub fn items(
    planned: &Planned,
    plan: &VehiclePlan,
    frame: &Frame,
    tolerance: f64,
) -> (Geodetic, Vec<Item>) {
    let home = frame.to_geodetic(&plan.home());
    let relative = |p: &Point3<f64>| {
        let g = frame.to_geodetic(p);
        [g.latitude, g.longitude, g.altitude - home.altitude]
    };
    let fixed_wing = planned.pipeline.fixed_wing();
    // Ground speed for multicopters, airspeed for fixed wing (still air).
    let speed_type = if fixed_wing { 0.0 } else { 1.0 };
    let accept = tolerance.max(0.1);
    let mut out = Vec::with_capacity(plan.waypoints.len() + 4);
    let Some(first) = plan.waypoints.first() else {
        return (home, out);
    };
    let takeoff_pitch = if fixed_wing { 15.0 } else { 0.0 };
    let f = relative(&first.position);
    out.push(Item {
        command: cmd::NAV_TAKEOFF,
        frame: 3,
        params: [takeoff_pitch, 0.0, 0.0, f64::NAN],
        at: Some([home.latitude, home.longitude, f[2]]),
        waypoint: None,
    });
    let mut speed = f64::NAN;
    for (i, w) in plan.waypoints.iter().enumerate() {
        // The speed of the leg that leaves this waypoint is set on arrival.
        out.push(Item {
            command: cmd::NAV_WAYPOINT,
            frame: 3,
            params: [w.hold, accept, 0.0, f64::NAN],
            at: Some(relative(&w.position)),
            waypoint: Some(i),
        });
        let next = plan.waypoints.get(i + 1).map(|n| n.speed);
        if let Some(v) =
            next.filter(|v| *v > 0.0 && (speed.is_nan() || (*v - speed).abs() >= SPEED_STEP / 2.0))
        {
            speed = v;
            out.push(change_speed(speed_type, v));
        }
    }
    let last = plan.waypoints.last().unwrap_or(first);
    let l = relative(&last.position);
    out.push(if fixed_wing {
        Item {
            command: cmd::NAV_LOITER_UNLIM,
            frame: 3,
            params: [0.0, 0.0, planned.loiter_radius, f64::NAN],
            at: Some(l),
            waypoint: None,
        }
    } else {
        Item {
            command: cmd::NAV_LAND,
            frame: 3,
            params: [0.0, 0.0, 0.0, f64::NAN],
            at: Some([l[0], l[1], 0.0]),
            waypoint: None,
        }
    });
    (home, out)
}

fn change_speed(speed_type: f64, v: f64) -> Item {
    Item {
        command: cmd::DO_CHANGE_SPEED,
        frame: 2,
        params: [speed_type, v, -1.0, 0.0],
        at: None,
        waypoint: None,
    }
}

/// The obstacles the geofence excludes: every one no track passes over (a
/// fence circle is a column from the ground up; an obstacle the plan
/// overflies would trip it).
pub fn fence_obstacles<'a>(
    mission: &'a Mission,
    planned: &'a Planned,
) -> impl Iterator<Item = &'a crate::mission::Obstacle> + 'a {
    mission.obstacles.iter().filter(move |o| {
        !planned.tracks.iter().any(|t| {
            t.samples
                .iter()
                .any(|s| (s.position.xy() - o.center).norm() <= o.radius)
        })
    })
}
