//! From plan to flight: one mission file per vehicle that autopilots load,
//! re-verified as they will be flown.
//!
//! Each vehicle's timed track ([`crate::outcome::tracks`]) is reduced to waypoints
//! ([`simplify`]: every sample within the tolerance of where the straight leg
//! puts the vehicle at the same instant) at the coordinates the files store
//! ([`geodesy`]: 1e-7°, float32; one altitude convention for every file)
//! with a commanded speed per leg ([`legs`]: ground speed for multicopters,
//! airspeed for fixed wing), so that each vehicle reaches each waypoint
//! when the plan says. The files are then flown as an autopilot flies them
//! and checked with the shared verification every pipeline's plan passes
//! ([`crate::pipelines::verify`]) against the hard limits, every written
//! speed against the vehicle's ([`reverify`]). Only
//! then are they written: QGroundControl `.plan` ([`plan`]), `QGC WPL 110`
//! ([`wpl`]) or CSV ([`csv`]), atomically. A KML of the whole plan ([`kml`]:
//! the mission, every vehicle's home and track, the verdict) is one more
//! file, to look at over imagery. `docs/export.md` describes the formats.

pub mod csv;
pub mod geodesy;
pub mod kml;
pub mod legs;
pub mod plan;
pub mod reverify;
pub mod simplify;
pub mod wpl;

use std::path::{Path, PathBuf};

use nalgebra::Point3;
use serde::Serialize;

use crate::mission::Mission;
use crate::outcome::tracks::Track;
use crate::pipelines::{Airframe, Kind, Limits};

pub use geodesy::{Frame, Geodetic, Home, Placement, Stored};
pub use legs::{HOLD_STEP, LegLimits, MIN_SPEED, SPEED_STEP};
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

    /// A waypoint file (`.plan`, `.waypoints`): the reduced plans.
    pub fn waypoints(self) -> bool {
        matches!(self, Format::Plan | Format::Wpl)
    }
}

/// Smallest tolerance, metres: the stored coordinates alone may put a
/// waypoint [`geodesy::RESOLUTION`] (8.5 mm) from its sample, and 1 cm
/// leaves the reduction 1.5 mm beyond that.
pub const MIN_TOLERANCE: f64 = 0.01;

/// How each pipeline names its vehicles: θ-PSO's UAVs, FLATLO's
/// aircraft, the fleet's agents.
pub fn noun(pipeline: Kind) -> &'static str {
    pipeline.face().words().noun
}

/// What a pipeline's outcome gives the export: each vehicle's track, the
/// limits its verification holds, and the deviation it allows.
#[derive(Debug, Clone, PartialEq)]
pub struct Planned {
    pub pipeline: Kind,
    pub seed: u64,
    pub tracks: Vec<Track>,
    /// The hard limits the files are re-verified against.
    pub limits: Limits,
    /// What each vehicle's autopilot lets a leg fly, in track order.
    pub legs: Vec<LegLimits>,
    /// The most the pipeline lets a vehicle stray from its track, metres,
    /// before the plan's own slack is considered (see [`Planned::default_tolerance`]).
    pub margin: f64,
    /// Where `margin` comes from, in words.
    pub margin_source: String,
    /// Fixed-wing loiter radius at the end, metres.
    pub loiter_radius: f64,
    /// The run's verdict in one line (`Outcome::headline`), for the KML.
    pub verdict: String,
    /// Why the files' limits are not the run's (`ExportRules::limits_note`).
    pub limits_note: Option<String>,
    /// The acceptance radius every `NAV_WAYPOINT` writes (param2), metres:
    /// for a multicopter the one the flight check flies
    /// (`flight.acceptance_radius`), so the file and the check take a
    /// waypoint alike (issue 52); `None` (fixed wing, not flown by the
    /// check): the tolerance, at least 0.1 m.
    pub acceptance: Option<f64>,
}

impl Planned {
    /// What the export needs of any pipeline's outcome: the tracks its
    /// vehicles fly (`Outcome::reference_tracks`) and the rules its face
    /// holds them to (`PipelineOutcome::export_rules`).
    pub fn from_outcome(mission: &Mission, outcome: &crate::outcome::Outcome) -> Self {
        let rules = outcome.face().export_rules(mission);
        let tracks = outcome.reference_tracks();
        let acceptance = matches!(rules.airframe, Airframe::Multicopter)
            .then_some(mission.flight.acceptance_radius);
        let legs = tracks
            .iter()
            .map(|t| match rules.airframe {
                Airframe::Multicopter => LegLimits::multicopter(mission.vehicle.limits(t.vehicle)),
                Airframe::FixedWing { airspeed } => LegLimits::fixed_wing(Some(airspeed)),
            })
            .collect();
        Planned {
            pipeline: outcome.kind(),
            seed: outcome.seed(),
            legs,
            tracks,
            limits: rules.limits,
            margin: rules.margin,
            margin_source: rules.margin_source.into(),
            loiter_radius: rules.loiter_radius,
            verdict: outcome.headline(),
            limits_note: rules.limits_note,
            acceptance,
        }
    }

    /// How the pipeline names its vehicles ([`noun`]).
    pub fn noun(&self) -> &'static str {
        noun(self.pipeline)
    }

    /// The legs of the vehicle of track `i`.
    pub fn legs_of(&self, i: usize) -> LegLimits {
        self.legs
            .get(i)
            .copied()
            .unwrap_or_else(|| LegLimits::fixed_wing(None))
    }

    /// The default tolerance: the pipeline's margin, or less when the plan
    /// itself has less slack against a hard limit (a clearance's excess over
    /// its limit; half a distance's excess between two vehicles, since both
    /// may stray). Never below [`MIN_TOLERANCE`].
    pub fn default_tolerance(&self, mission: &Mission) -> (f64, String) {
        let slack = reverify::slack(mission, &self.limits, &self.tracks);
        let (tolerance, source) = match slack {
            Some((s, what)) if s < self.margin => {
                let what = reverify::worded(&what, self.noun());
                (s, format!("the plan's slack on {what}"))
            }
            _ => (self.margin, self.margin_source.clone()),
        };
        if tolerance < MIN_TOLERANCE {
            return (
                MIN_TOLERANCE,
                format!(
                    "{source} is {tolerance:.4} m, below the stored coordinates' resolution: \
                     raised to {MIN_TOLERANCE} m"
                ),
            );
        }
        (tolerance, source)
    }
}

/// One waypoint of a vehicle's reduced plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Waypoint {
    /// When the plan has the vehicle here, seconds from the common start.
    pub t: f64,
    /// Metres ENU: where the file's stored coordinates put the vehicle
    /// (1e-7° and float32; the track's sample itself without `[origin]`).
    pub position: Point3<f64>,
    /// Commanded speed of the leg that ends here, m/s (0 for the first):
    /// ground speed for multicopters, airspeed for fixed wing.
    pub speed: f64,
    /// Seconds the vehicle waits here before the next leg.
    pub hold: f64,
}

/// One vehicle's reduced plan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VehiclePlan {
    /// 0-based (file names say `<noun><vehicle + 1>`).
    pub vehicle: usize,
    /// Where it is armed: the ground under its first waypoint (`None`
    /// without `[origin]`).
    #[serde(skip)]
    pub home: Option<Home>,
    /// How its autopilot flies the legs.
    pub legs: LegLimits,
    pub waypoints: Vec<Waypoint>,
}

/// Reduces every track to waypoints (see [`reduce_track`]).
pub fn reduce(
    planned: &Planned,
    placement: Option<&Placement>,
    tolerance: f64,
) -> Vec<VehiclePlan> {
    planned
        .tracks
        .iter()
        .enumerate()
        .map(|(i, track)| reduce_track(track, planned.legs_of(i), placement, tolerance))
        .collect()
}

/// One track's waypoints, each at the position its file stores (with
/// `placement`), and each leg the speed that arrives on time, rounded to
/// [`SPEED_STEP`]; a rounding early on is made up on the next leg, so
/// timing errors do not add up. Every sample of the track stays within
/// `tolerance` of where the plan *as flown* (stored coordinates, rounded
/// speeds, holds) puts the vehicle at the same instant: the SED tolerance of
/// the reduction is tightened until the flight is within it, down to
/// keeping every sample.
pub fn reduce_track(
    track: &Track,
    legs: LegLimits,
    placement: Option<&Placement>,
    tolerance: f64,
) -> VehiclePlan {
    /// Tightenings tried before every sample is kept.
    const TRIES: usize = 12;
    let home = placement
        .zip(track.samples.first())
        .map(|(p, s)| p.home(&s.position.xy()));
    let store = |p: &Point3<f64>| match (placement, &home) {
        (Some(placement), Some(home)) => placement.round_trip(p, home),
        _ => *p,
    };
    let mut sed = tolerance;
    for _ in 0..TRIES {
        let kept = simplify::simplify(&track.samples, sed);
        let plan = plan_through(track, &kept, legs, home, &store);
        let deviation = reverify::deviation(&plan, track);
        if deviation <= tolerance {
            return plan;
        }
        // Stored coordinates, rounding and holds add what the reduction
        // did not see: ask the reduction for less, in proportion.
        sed *= 0.9 * tolerance / deviation;
    }
    let every: Vec<usize> = (0..track.samples.len()).collect();
    plan_through(track, &every, legs, home, &store)
}

/// The plan whose waypoints are `track`'s samples `kept` (where `store`
/// puts them), each leg at the speed (or hold, then the slowest speed)
/// that reaches it on time.
fn plan_through(
    track: &Track,
    kept: &[usize],
    legs: LegLimits,
    home: Option<Home>,
    store: &dyn Fn(&Point3<f64>) -> Point3<f64>,
) -> VehiclePlan {
    let mut waypoints: Vec<Waypoint> = Vec::with_capacity(kept.len());
    // When the vehicle flown as planned reaches the last waypoint.
    let mut flown = 0.0;
    for &k in kept {
        let s = &track.samples[k];
        let position = store(&s.position);
        let Some(prev) = waypoints.last_mut() else {
            flown = s.t;
            waypoints.push(Waypoint {
                t: s.t,
                position,
                speed: 0.0,
                hold: 0.0,
            });
            continue;
        };
        let (hold, speed) = legs.command(&prev.position, &position, s.t - prev.t, s.t - flown);
        prev.hold = hold;
        flown += hold + legs.duration(&prev.position, &position, speed);
        waypoints.push(Waypoint {
            t: s.t,
            position,
            speed,
            hold: 0.0,
        });
    }
    VehiclePlan {
        vehicle: track.vehicle,
        home,
        legs,
        waypoints,
    }
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
    /// Why the files' limits are not the run's, when they are not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limits_note: Option<String>,
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
    #[error(
        "the tolerance must be a number of metres of at least {MIN_TOLERANCE} (the stored \
         coordinates alone may move a waypoint by up to 8.5 mm: 1e-7° of latitude and longitude), got {0}"
    )]
    BadTolerance(f64),
    #[error(
        "the files cannot hold --tolerance {tolerance} m: keeping every sample of the track, \
         a flown {noun} still strays {held:.3} m (speeds to 0.01 m/s, coordinates to 1e-7°); \
         ask for at least that"
    )]
    Unreachable {
        tolerance: f64,
        held: f64,
        noun: &'static str,
    },
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

/// File name of one vehicle's export: `<mission-stem>-<pipeline>-<noun><N>.<ext>`
/// (`uav`, `aircraft` or `agent`, as the pipeline names its vehicles).
pub fn file_name(stem: &str, pipeline: Kind, vehicle: usize, format: Format) -> String {
    format!(
        "{stem}-{}-{}{}.{}",
        pipeline.words().slug,
        noun(pipeline).to_lowercase(),
        vehicle + 1,
        format.extension()
    )
}

/// File name of the KML of the whole plan: `<mission-stem>-<pipeline>.kml`.
pub fn kml_file_name(stem: &str, pipeline: Kind) -> String {
    format!("{stem}-{}.kml", pipeline.words().slug)
}

/// Reduces, re-verifies and (unless refused) writes one file per vehicle and
/// format into `options.out_dir`, named after `stem` (the mission file's stem).
///
/// Long (~125 lines) because it is the export's one gate in order: the checks, the tolerance
/// (raised to what the files hold), the reduction, the re-verification that may refuse, then
/// each format written; every refusal must come before the first file is written.
pub fn export(
    mission: &Mission,
    stem: &str,
    planned: &Planned,
    options: &Options,
) -> Result<Exported, ExportError> {
    let placement = Placement::new(mission);
    if placement.is_none()
        && let Some(f) = options.formats.iter().find(|f| f.geodetic())
    {
        return Err(ExportError::NoOrigin(f.name()));
    }
    if planned.tracks.iter().all(|t| t.samples.is_empty()) {
        return Err(ExportError::Empty(planned.pipeline.words().slug));
    }
    let (mut tolerance, mut tolerance_source) = match options.tolerance {
        Some(t) if t.is_finite() && t >= MIN_TOLERANCE => (t, "--tolerance".to_owned()),
        Some(t) => return Err(ExportError::BadTolerance(t)),
        None => planned.default_tolerance(mission),
    };
    let plans = reduce(planned, placement.as_ref(), tolerance);
    // Keeping every sample may still leave a flight off by more (timing
    // roundings on many short legs): announce what the files hold, or say
    // that the tolerance asked for cannot be held.
    let held = plans
        .iter()
        .zip(&planned.tracks)
        .map(|(p, t)| reverify::deviation(p, t))
        .fold(0.0, f64::max);
    if held > tolerance {
        if options.tolerance.is_some() {
            return Err(ExportError::Unreachable {
                tolerance,
                held,
                noun: planned.noun(),
            });
        }
        tolerance_source = format!(
            "{tolerance_source}: {tolerance:.3} m, raised to what the files hold keeping every sample"
        );
        tolerance = held;
    }
    let waypoint_files = options.formats.iter().any(|f| f.waypoints());
    let csv_texts: Vec<String> = if options.formats.contains(&Format::Csv) {
        planned
            .tracks
            .iter()
            .zip(&plans)
            .map(|(t, p)| csv::render(t, placement.as_ref(), p.home.as_ref()).0)
            .collect()
    } else {
        Vec::new()
    };
    let reverification = reverify::reverify(
        mission,
        planned,
        &plans,
        tolerance,
        waypoint_files,
        (!csv_texts.is_empty()).then_some(csv_texts.as_slice()),
        placement.as_ref(),
    );
    // The KML shows the plan itself: only the files to fly are refused.
    let forced = !reverification.passed();
    if forced && !options.force {
        return Err(ExportError::Refused(Box::new(reverification)));
    }

    std::fs::create_dir_all(&options.out_dir).map_err(|source| ExportError::Io {
        path: options.out_dir.clone(),
        source,
    })?;
    let mut files = Vec::new();
    for format in &options.formats {
        if let (Format::Kml, Some(placement)) = (format, &placement) {
            let path = options.out_dir.join(kml_file_name(stem, planned.pipeline));
            let (text, items) = kml::render(mission, planned, &plans, placement);
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
        for (i, (plan, track)) in plans.iter().zip(&planned.tracks).enumerate() {
            let name = file_name(stem, planned.pipeline, plan.vehicle, *format);
            let path = options.out_dir.join(name);
            let (text, items) = match (format, &placement) {
                (Format::Csv, _) => (
                    csv_texts.get(i).cloned().unwrap_or_default(),
                    track.samples.len(),
                ),
                (Format::Plan, Some(placement)) => {
                    plan::render(mission, planned, plan, placement, tolerance)
                }
                (Format::Wpl, Some(placement)) => wpl::render(planned, plan, placement, tolerance),
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
        limits_note: planned.limits_note.clone(),
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
    /// Latitude and longitude (whole 1e-7°) and altitude relative to home
    /// (metres, float32) as the files store them; `None` for commands
    /// without a position.
    pub at: Option<Stored>,
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

/// The home position and the mission items of one vehicle: take-off to the
/// first waypoint's height, a speed change wherever the commanded speed
/// changes, the waypoints, then land (multicopters) or loiter without limit
/// at the last waypoint (fixed wing: ArduPlane would otherwise return to
/// launch when the mission ends, across the other aircraft's plans).
pub fn items(
    planned: &Planned,
    plan: &VehiclePlan,
    placement: &Placement,
    tolerance: f64,
) -> (Home, Vec<Item>) {
    let home = plan.home.unwrap_or_else(|| {
        let first = plan
            .waypoints
            .first()
            .map_or_else(Point3::origin, |w| w.position);
        placement.home(&first.xy())
    });
    let stored = |p: &Point3<f64>| placement.stored(p, &home);
    let fixed_wing = planned.pipeline.words().fixed_wing;
    // Ground speed for multicopters, airspeed for fixed wing (still air).
    let speed_type = if fixed_wing { 0.0 } else { 1.0 };
    let accept = planned.acceptance.unwrap_or(tolerance.max(0.1));
    let mut out = Vec::with_capacity(plan.waypoints.len() + 4);
    let Some(first) = plan.waypoints.first() else {
        return (home, out);
    };
    let takeoff_pitch = if fixed_wing { 15.0 } else { 0.0 };
    out.push(Item {
        command: cmd::NAV_TAKEOFF,
        frame: 3,
        params: [takeoff_pitch, 0.0, 0.0, f64::NAN],
        at: Some(Stored {
            latitude: home.latitude,
            longitude: home.longitude,
            relative: stored(&first.position).relative,
        }),
        waypoint: None,
    });
    let mut speed = f64::NAN;
    for (i, w) in plan.waypoints.iter().enumerate() {
        // The speed of the leg that leaves this waypoint is set on arrival.
        out.push(Item {
            command: cmd::NAV_WAYPOINT,
            frame: 3,
            params: [w.hold, accept, 0.0, f64::NAN],
            at: Some(stored(&w.position)),
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
    let l = stored(&last.position);
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
            at: Some(Stored { relative: 0.0, ..l }),
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
