//! The Monte Carlo flight check (`skyform fly`): a plan flown many times as
//! its autopilots will fly the exported files, in wind and gusts, on GNSS
//! fixes, taking off a little apart, and what that does to its margins.
//!
//! Each flight is a plain function of the plan, the mission's `[flight]`
//! and (seed, flight number): its random numbers are one ChaCha8 stream per
//! flight, so a flight is the same whichever thread flies it and whatever
//! the thread count, and `--flight K` flies flight K again. The report is
//! read from the flights in their order. Models, sources and limits:
//! docs/flight-check.md.
//!
//! Long (~790 lines) because it is the check's one run: the setup from the exported plan,
//! one flight flown and measured, the many flights on threads with their recording, and the
//! `--target` margin search that plans and flies them again; the air, the autopilot and the
//! report are already submodules.

pub mod air;
pub mod autopilot;
mod report;

use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Point3, Vector3};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;
use serde::Serialize;

use crate::base::geometry::{Prism, segment_point_distance_3d};
use crate::export::reverify::Flight;
use crate::export::{Placement, Planned, VehiclePlan, reduce};
use crate::mission::Mission;
use crate::pipelines::fleet::quadrotor::Body;
use crate::pipelines::{CancelToken, Kind};

pub use report::{Report, Share, Spread, wilson};

use autopilot::Autopilot;

/// Flights are sampled for distances every this many steps (20 Hz at the
/// default 0.01 s step): a vehicle at 3 m/s moves 15 cm between samples.
const SAMPLE_EVERY: usize = 5;

/// Obstacles farther than this from every waypoint line of a vehicle are
/// not followed for it, metres: no gust or fix error moves it that far.
const NEAR: f64 = 25.0;

/// The most vehicle-steps one check may simulate (flights × vehicles ×
/// steps): about 20 s on two cores (the bridge's 1,000 flights are 3.3e7).
pub const MAX_VEHICLE_STEPS: f64 = 2e8;

/// What goes wrong before a check flies.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FlightError {
    #[error("the plan has no vehicle with two waypoints to fly")]
    Empty,
    #[error(
        "{flights} flights × {vehicles} vehicles × {steps} steps of {step} s make {total:.3e} \
         vehicle-steps, over the limit of {limit:.0e}: fewer flights (--flights, flight.flights) \
         or a longer flight.step"
    )]
    OverBudget {
        flights: usize,
        vehicles: usize,
        steps: usize,
        step: f64,
        total: f64,
        limit: f64,
    },
    #[error("cancelled")]
    Cancelled,
}

/// A plan made ready to fly: each vehicle's waypoints as the export writes
/// them, the limits its verification holds, the obstacles near each vehicle.
#[derive(Debug, Clone)]
pub struct Setup<'m> {
    pub mission: &'m Mission,
    /// The pipeline that planned it (`Kind::name`).
    pub pipeline: &'static str,
    pub plans: Vec<VehiclePlan>,
    /// Least clearance to an obstacle's surface (r_Q) and between two
    /// vehicles (2 r_Q), metres.
    pub clearance: f64,
    pub closest: f64,
    /// Each vehicle's obstacles to follow (indices into the mission's).
    pub near: Vec<Vec<usize>>,
    pub prisms: Vec<Prism>,
    /// When the last vehicle, flown as written, reaches its last waypoint.
    pub planned_end: f64,
    /// Flights stop here even when a vehicle has not finished.
    pub horizon: f64,
    /// The inspected obstacles (eq. 8): index, stand-off band [d_min,
    /// d_max] from the surface, metres, and the pass length asked.
    pub inspected: Vec<(usize, [f64; 2], f64)>,
}

impl<'m> Setup<'m> {
    /// The files an export would write for `planned`, read back as the
    /// vehicles' missions (stored coordinates, written speeds and holds).
    pub fn new(mission: &'m Mission, planned: &Planned) -> Result<Self, FlightError> {
        let placement = Placement::new(mission);
        let (tolerance, _) = planned.default_tolerance(mission);
        let plans = reduce(planned, placement.as_ref(), tolerance);
        if plans.iter().all(|p| p.waypoints.len() < 2) {
            return Err(FlightError::Empty);
        }
        let prisms: Vec<Prism> = mission.obstacles.iter().map(|o| mission.prism(o)).collect();
        let near = plans
            .iter()
            .map(|p| {
                (0..prisms.len())
                    .filter(|&k| {
                        p.waypoints.windows(2).any(|w| {
                            let (a, b) = (w[0].position, w[1].position);
                            let mid = a + (b - a) * 0.5;
                            prisms[k].clearance(&mid) - 0.5 * (b - a).norm() < NEAR
                        }) || p.waypoints.len() == 1
                            && prisms[k].clearance(&p.waypoints[0].position) < NEAR
                    })
                    .collect()
            })
            .collect();
        let planned_end = plans
            .iter()
            .filter_map(|p| Flight::new(p).arrivals().last().copied())
            .fold(0.0, f64::max);
        let skew = mission.flight.takeoff_skew;
        let inspected = mission
            .obstacles
            .iter()
            .enumerate()
            .filter(|(_, o)| o.inspect)
            .map(|(k, o)| {
                (
                    k,
                    o.stand_off_band(&mission.formation),
                    mission.formation.inspection_pass,
                )
            })
            .collect();
        Ok(Setup {
            inspected,
            mission,
            pipeline: planned.pipeline.name(),
            clearance: planned.limits.clearance,
            closest: planned.limits.closest,
            plans,
            near,
            prisms,
            planned_end,
            horizon: planned_end * 1.5 + 6.0 * skew + 30.0,
        })
    }

    /// When the first vehicle's plan starts, seconds on the plan's clock.
    pub fn start(&self) -> f64 {
        let start = self
            .plans
            .iter()
            .filter_map(|p| p.waypoints.first().map(|w| w.t))
            .fold(f64::INFINITY, f64::min);
        if start.is_finite() { start } else { 0.0 }
    }

    /// A flight's closest approaches before it flies: every pair and every
    /// vehicle's near obstacles at infinity.
    fn no_approach_yet(&self) -> (Vec<Closest>, Vec<Vec<Closest>>) {
        let n = self.plans.len();
        let pairs = vec![Closest::FAR; n * n.saturating_sub(1) / 2];
        let obstacles = self
            .near
            .iter()
            .map(|near| vec![Closest::FAR; near.len()])
            .collect();
        (pairs, obstacles)
    }

    /// Steps of one flight.
    pub fn steps(&self) -> usize {
        (self.horizon / self.mission.flight.step).ceil() as usize
    }

    /// Refuses a check larger than [`MAX_VEHICLE_STEPS`].
    pub fn within_budget(&self, flights: usize) -> Result<(), FlightError> {
        let steps = self.steps();
        let total = flights as f64 * self.plans.len() as f64 * steps as f64;
        if crate::pipelines::exceeds(total, MAX_VEHICLE_STEPS) {
            return Err(FlightError::OverBudget {
                flights,
                vehicles: self.plans.len(),
                steps,
                step: self.mission.flight.step,
                total,
                limit: MAX_VEHICLE_STEPS,
            });
        }
        Ok(())
    }
}

/// The pairs (i, j), i < j, of `n` vehicles in the order a flight keeps
/// them (`Flown::pairs`): (0, 1), (0, 2), …, (1, 2), …
pub fn vehicle_pairs(n: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..n).flat_map(move |i| (i + 1..n).map(move |j| (i, j)))
}

/// One vehicle's sampled positions: (seconds on the plan's clock, ENU).
pub type Track = Vec<(f64, Point3<f64>)>;

/// The closest two things came in one flight.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Closest {
    /// Metres (vehicle to vehicle, or vehicle to the obstacle's surface).
    pub distance: f64,
    /// Seconds on the plan's clock.
    pub t: f64,
}

impl Closest {
    const FAR: Closest = Closest {
        distance: f64::INFINITY,
        t: 0.0,
    };

    fn keep(&mut self, distance: f64, t: f64) {
        if distance < self.distance {
            *self = Closest { distance, t };
        }
    }
}

/// One flight: each pair's closest approach, each vehicle's least
/// clearance to each obstacle near it, each vehicle's largest cross-track
/// error, and whether every vehicle finished.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Flown {
    pub flight: usize,
    /// Pairs (i, j), i < j, in order.
    pub pairs: Vec<Closest>,
    /// `obstacles[v][k]`: vehicle v and its `Setup::near[v][k]`.
    pub obstacles: Vec<Vec<Closest>>,
    /// Metres from the line its mission has it on, the largest.
    pub cross_track: Vec<f64>,
    /// Seconds each vehicle took off after the plan's start (the skew).
    pub takeoff: Vec<f64>,
    /// Per inspected obstacle (`Setup::inspected`), the longest stretch any
    /// vehicle flew within its eq. 8 band, metres.
    pub inspections: Vec<f64>,
    pub finished: bool,
    /// Every vehicle's sampled track (only when asked).
    #[serde(skip)]
    pub tracks: Option<Vec<Track>>,
    /// Every vehicle's cross-track error at each sample (only when asked:
    /// the envelope of a recording).
    #[serde(skip)]
    pub spread: Option<Vec<Vec<f32>>>,
}

/// Flies flight `k` of the check seeded `seed`.
pub fn fly(setup: &Setup, seed: u64, k: usize, keep_tracks: bool) -> Flown {
    fly_keeping(setup, seed, k, keep_tracks, false)
}

/// [`fly`], keeping each sample's cross-track error when `keep_spread`.
fn fly_keeping(setup: &Setup, seed: u64, k: usize, keep_tracks: bool, keep_spread: bool) -> Flown {
    let p = &setup.mission.flight;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(k as u64);
    let body = Body::from_params(&setup.mission.fleet);
    let n = setup.plans.len();
    let mut takeoff = Vec::with_capacity(n);
    let mut fixes = Vec::with_capacity(n);
    let mut pilots: Vec<Autopilot> = Vec::with_capacity(n);
    let mut air = air::Air::new(p, &mut rng);
    let mut common = air::Gnss::new(p, false, &mut rng);
    for plan in &setup.plans {
        let skew: f64 = rng.sample::<f64, _>(StandardNormal) * p.takeoff_skew;
        let start = plan.waypoints.first().map_or(0.0, |w| w.t) + skew;
        takeoff.push(skew);
        fixes.push(air::Gnss::new(p, true, &mut rng));
        pilots.push(Autopilot::new(
            plan,
            setup.mission.vehicle.limits(plan.vehicle),
            body,
            p.acceptance_radius,
            start,
        ));
    }
    let (mut pairs, mut obstacles) = setup.no_approach_yet();
    let mut cross_track = vec![0.0f64; n];
    let mut tracks = keep_tracks.then(|| vec![Vec::new(); n]);
    let mut spread: Option<Vec<Vec<f32>>> = keep_spread.then(|| vec![Vec::new(); n]);
    let dt = p.step;
    let steps = setup.steps();
    let start = setup.start();
    let mut positions = vec![Point3::origin(); n];
    let mut passes = Passes::new(setup, n);
    let mut finished = false;
    for step in 0..=steps {
        let t = start + step as f64 * dt;
        if step % SAMPLE_EVERY == 0 || step == steps {
            for (v, pilot) in pilots.iter().enumerate() {
                positions[v] = pilot.position();
            }
            measure(setup, t, &positions, &mut pairs, &mut obstacles);
            passes.sample(setup, &positions);
            for (v, pilot) in pilots.iter().enumerate() {
                let (a, b) = pilot.line();
                let off = segment_point_distance_3d(&a, &b, &positions[v]);
                cross_track[v] = cross_track[v].max(off);
                if let Some(spread) = spread.as_mut() {
                    spread[v].push(off as f32);
                }
                if let Some(tracks) = tracks.as_mut() {
                    tracks[v].push((t, positions[v]));
                }
            }
            if pilots.iter().all(Autopilot::done) {
                finished = true;
                break;
            }
        }
        // The formation's air, at its mean height and velocity.
        let (mut height, mut velocity) = (0.0, Vector3::zeros());
        for pilot in &pilots {
            let here = pilot.position();
            height += (here.z - setup.mission.ground(here.x, here.y)) / n as f64;
            velocity += pilot.velocity() / n as f64;
        }
        let wind = air.step(&mut rng, dt, height, &velocity);
        let shared = common.step(&mut rng, dt);
        for (pilot, own) in pilots.iter_mut().zip(&mut fixes) {
            let gnss = shared + own.step(&mut rng, dt);
            pilot.step(t, dt, &gnss, &wind, p.drag);
        }
    }
    Flown {
        flight: k,
        pairs,
        obstacles,
        cross_track,
        takeoff,
        inspections: passes.best,
        finished,
        tracks,
        spread,
    }
}

/// Eq. 8 along a flight: for each inspected obstacle and vehicle, the
/// stretch flown so far without leaving the band, and the longest.
struct Passes {
    run: Vec<Vec<f64>>,
    best: Vec<f64>,
    last: Vec<Point3<f64>>,
}

impl Passes {
    fn new(setup: &Setup, n: usize) -> Self {
        Passes {
            run: vec![vec![0.0; n]; setup.inspected.len()],
            best: vec![0.0; setup.inspected.len()],
            last: Vec::new(),
        }
    }

    /// One sample: a vehicle inside the band at this sample and the last
    /// adds the way between them to its stretch; outside, its stretch ends.
    fn sample(&mut self, setup: &Setup, positions: &[Point3<f64>]) {
        for (k, &(o, [lo, hi], _)) in setup.inspected.iter().enumerate() {
            for (v, p) in positions.iter().enumerate() {
                let d = setup.prisms[o].clearance(p);
                if (lo..=hi).contains(&d) {
                    if let Some(last) = self.last.get(v) {
                        self.run[k][v] += (p - last).norm();
                    }
                    self.best[k] = self.best[k].max(self.run[k][v]);
                } else {
                    self.run[k][v] = 0.0;
                }
            }
        }
        self.last = positions.to_vec();
    }
}

/// Each pair's distance and each vehicle's clearance to its near
/// obstacles at one instant, kept where closer than before.
fn measure(
    setup: &Setup,
    t: f64,
    positions: &[Point3<f64>],
    pairs: &mut [Closest],
    obstacles: &mut [Vec<Closest>],
) {
    for ((i, j), closest) in vehicle_pairs(positions.len()).zip(pairs.iter_mut()) {
        closest.keep((positions[i] - positions[j]).norm(), t);
    }
    for (v, near) in setup.near.iter().enumerate() {
        for (slot, &o) in near.iter().enumerate() {
            obstacles[v][slot].keep(setup.prisms[o].clearance(&positions[v]), t);
        }
    }
}

/// The plan as its files fly it with an ideal vehicle (the export's
/// re-verification: straight legs at the written speeds, on time), sampled
/// as the flights are: the figures a calm flight should reproduce.
pub fn as_written(setup: &Setup) -> Flown {
    let flights: Vec<Flight> = setup.plans.iter().map(Flight::new).collect();
    let n = flights.len();
    let (mut pairs, mut obstacles) = setup.no_approach_yet();
    let dt = setup.mission.flight.step * SAMPLE_EVERY as f64;
    let start = setup.start();
    let steps = ((setup.planned_end - start).max(0.0) / dt).ceil() as usize;
    let mut positions = vec![Point3::origin(); n];
    let mut passes = Passes::new(setup, n);
    for step in 0..=steps {
        let t = start + step as f64 * dt;
        for (v, f) in flights.iter().enumerate() {
            positions[v] = f.at(t).0;
        }
        measure(setup, t, &positions, &mut pairs, &mut obstacles);
        passes.sample(setup, &positions);
    }
    Flown {
        flight: 0,
        pairs,
        obstacles,
        cross_track: vec![0.0; n],
        takeoff: vec![0.0; n],
        inspections: passes.best,
        finished: true,
        tracks: None,
        spread: None,
    }
}

/// How a check is run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Options {
    pub flights: usize,
    pub seed: u64,
    /// Worker threads (`None`: one per CPU). The report does not depend on it.
    pub threads: Option<usize>,
}

/// What a recording of a check shows (`record::flight`): each vehicle's
/// plan as written, the p99 of its cross-track error along it (the
/// envelope: a tube of that radius), and the worst flights as flown.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    pub mission: String,
    /// The instants of the samples, seconds on the plan's clock.
    pub times: Vec<f64>,
    /// Per vehicle (1-based number, its as-written positions at `times`).
    pub written: Vec<(usize, Vec<Point3<f64>>)>,
    /// Per vehicle, the p99 cross-track error at each of `times`, metres.
    pub envelope: Vec<Vec<f64>>,
    /// The worst flights: (flight, its vehicles' tracks).
    pub worst: Vec<(usize, Vec<Track>)>,
}

/// The flights recorded as the worst: this many.
pub const RECORDED_WORST: usize = 3;

/// Runs `work` on `threads` worker threads (`None`: rayon's pool).
fn on_threads<T: Send>(threads: Option<usize>, work: impl FnOnce() -> T + Send) -> T {
    match threads.and_then(|n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build()
            .ok()
    }) {
        Some(pool) => pool.install(work),
        None => work(),
    }
}

/// What a recording shows, from the flights of a check flown with their
/// cross-track samples kept ([`check_recorded`]): the envelope, and the
/// [`RECORDED_WORST`] worst flights' tracks (the report's worst, then the
/// flights where the tightest pairs and obstacles were worst), flown again.
fn recording(setup: &Setup, options: Options, report: &Report, flown: &[Flown]) -> Recording {
    let spreads: Vec<&Vec<Vec<f32>>> = flown.iter().filter_map(|f| f.spread.as_ref()).collect();
    let dt = setup.mission.flight.step * SAMPLE_EVERY as f64;
    let samples = spreads
        .iter()
        .copied()
        .flatten()
        .map(Vec::len)
        .max()
        .unwrap_or(0);
    let start = setup.start();
    let times: Vec<f64> = (0..samples).map(|k| start + k as f64 * dt).collect();
    let envelope = (0..setup.plans.len())
        .map(|v| {
            (0..samples)
                .map(|k| {
                    // A flight that finished early holds its last sample.
                    let mut at: Vec<f64> = spreads
                        .iter()
                        .filter_map(|f| f[v].get(k).or(f[v].last()).map(|x| f64::from(*x)))
                        .collect();
                    at.sort_by(f64::total_cmp);
                    report::quantile(&at, 0.99)
                })
                .collect()
        })
        .collect();
    let written = setup
        .plans
        .iter()
        .map(|p| {
            let schedule = Flight::new(p);
            (
                p.vehicle + 1,
                times.iter().map(|&t| schedule.at(t).0).collect(),
            )
        })
        .collect();
    let mut chosen: Vec<usize> = Vec::new();
    let candidates = report.worst.iter().map(|w| w.flight).chain(
        report
            .pairs
            .iter()
            .map(|p| p.closest.worst_flight)
            .chain(report.obstacles.iter().map(|o| o.clearance.worst_flight)),
    );
    for k in candidates {
        if chosen.len() < RECORDED_WORST && !chosen.contains(&k) {
            chosen.push(k);
        }
    }
    let worst = chosen
        .into_iter()
        .map(|k| {
            (
                k,
                fly(setup, options.seed, k, true).tracks.unwrap_or_default(),
            )
        })
        .collect();
    Recording {
        mission: setup.mission.name.clone(),
        times,
        written,
        envelope,
        worst,
    }
}

/// Flies `options.flights` flights of `setup` and reports them;
/// `progress(done, total)` is called as flights finish (from any thread).
pub fn check(
    setup: &Setup,
    options: Options,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &CancelToken,
) -> Result<Report, FlightError> {
    let flown = fly_all(setup, options, false, progress, cancel)?;
    Ok(Report::new(setup, options, &flown, &as_written(setup)))
}

/// [`check`], and what a recording of it shows, from the same flights
/// (their cross-track samples kept: about 5 kB a vehicle-minute).
pub fn check_recorded(
    setup: &Setup,
    options: Options,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &CancelToken,
) -> Result<(Report, Recording), FlightError> {
    let flown = fly_all(setup, options, true, progress, cancel)?;
    let report = Report::new(setup, options, &flown, &as_written(setup));
    let recording = recording(setup, options, &report, &flown);
    Ok((report, recording))
}

/// Every flight of a check, in flight order, on `options.threads`.
fn fly_all(
    setup: &Setup,
    options: Options,
    keep_spread: bool,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &CancelToken,
) -> Result<Vec<Flown>, FlightError> {
    setup.within_budget(options.flights)?;
    let done = AtomicUsize::new(0);
    let flown: Vec<Option<Flown>> = on_threads(options.threads, || {
        (0..options.flights)
            .into_par_iter()
            .map(|k| {
                if cancel.is_cancelled() {
                    return None;
                }
                let flown = fly_keeping(setup, options.seed, k, false, keep_spread);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, options.flights);
                Some(flown)
            })
            .collect()
    });
    flown
        .into_iter()
        .collect::<Option<Vec<Flown>>>()
        .ok_or(FlightError::Cancelled)
}

/// One margin tried by [`find_margin`]: the extra clearance, the spacing
/// scale, and the share of flights that broke a limit (`None`: no plan
/// with them).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tried {
    pub margin: f64,
    /// The vehicles' spacing as a multiple of the mission's (1: as drawn).
    pub spacing: f64,
    pub share: Option<f64>,
    pub note: String,
}

/// What [`find_margin`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MarginSearch {
    /// The target share of flights that may break 2 r_Q or r_Q.
    pub target: f64,
    /// The smallest extra clearance from the obstacles found that keeps
    /// r_Q in all but the target share (to [`MARGIN_RESOLUTION`]), metres;
    /// `None`: none up to [`MAX_MARGIN`] or the mission's limit.
    pub margin: Option<f64>,
    /// The spacing scale (> 1) the pairs needed beyond that margin, when
    /// they broke 2 r_Q too often at the mission's own spacing; `None`:
    /// not widened.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spacing: Option<f64>,
    /// The check of the plan made with them, when it meets the target.
    pub report: Option<Report>,
    pub tried: Vec<Tried>,
    /// The largest margin the mission stays valid with, when that is
    /// below [`MAX_MARGIN`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit: Option<MarginLimit>,
    /// The largest spacing scale the mission stays valid with, when that
    /// is below [`MAX_SPACING`] (its `margin` is the scale).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spacing_limit: Option<MarginLimit>,
}

impl MarginSearch {
    /// Whether the search found a plan whose check meets the target.
    pub fn met(&self) -> bool {
        self.report.is_some()
    }
}

/// What stops the margin search short of [`MAX_MARGIN`] (or the spacing
/// short of [`MAX_SPACING`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MarginLimit {
    /// The largest valid margin, metres (or spacing scale).
    pub margin: f64,
    /// The validator's message just above it.
    pub why: String,
}

/// `mission` asked to keep `m` more from the obstacles ([`find_margin`]):
/// the pipeline's margin field (`Pipeline::margin_field`: θ-PSO's
/// `formation.obstacle_margin`, which verification holds as a hard limit,
/// so a plan that passes keeps it everywhere, in a named IWP's gap too;
/// the fleet's `fleet.safety_distance`).
pub fn with_margin(mission: &mut Mission, pipeline: Kind, m: f64) {
    pipeline.face().add_margin(mission, m);
}

/// `mission` with its vehicles `scale` times as far apart
/// (`Pipeline::widen_spacing`: θ-PSO's slots).
pub fn with_spacing(mission: &mut Mission, pipeline: Kind, scale: f64) {
    if scale != 1.0 {
        pipeline.face().widen_spacing(mission, scale);
    }
}

/// The field [`with_margin`] adds to, and its value in `mission`; `None`
/// for a pipeline the check does not fly.
pub fn margin_field(mission: &Mission, pipeline: Kind) -> Option<(&'static str, f64)> {
    pipeline.face().margin_field(mission)
}

/// A plan to check: `pipeline` run cold on `mission` with `seed`, as the
/// export writes it; `Err` (the run's error, or its headline when its
/// verdict fails) when there is none that passes. What [`find_margin`]'s
/// callers plan each margin with.
pub fn passing_plan(
    pipeline: Kind,
    mission: &Mission,
    seed: u64,
    cancel: &CancelToken,
) -> Result<Planned, String> {
    let request = pipeline.request();
    let ask = crate::pipelines::Ask {
        seed,
        options: crate::pipelines::PlanOptions::default(),
        request: &request,
    };
    let outcome = pipeline
        .face()
        .run(mission, ask, &mut crate::pipelines::Silent, cancel)
        .map_err(|e| e.to_string())?;
    if !outcome.ok() {
        return Err(outcome.headline());
    }
    Ok(Planned::from_outcome(mission, &outcome))
}

/// The margin search stops refining at this width, metres (and the
/// spacing search at this step of its scale).
pub const MARGIN_RESOLUTION: f64 = 0.05;
/// The largest extra clearance tried, metres.
pub const MAX_MARGIN: f64 = 8.0;
/// The largest spacing scale tried: the slots three times as far apart.
pub const MAX_SPACING: f64 = 3.0;

/// Why `change` makes the mission one `pipeline` refuses, in the
/// validator's words (its rules, then what the pipeline finds before a run:
/// θ-PSO's inspections that the margin leaves no room for); `None` when the
/// mission stays valid with it.
fn invalid_with(
    mission: &Mission,
    pipeline: Kind,
    change: &dyn Fn(&mut Mission),
) -> Option<String> {
    let mut changed = mission.clone();
    change(&mut changed);
    let rules = crate::pipelines::validate(&changed);
    let is_error = |d: &crate::mission::Diagnostic| d.severity == crate::mission::Severity::Error;
    let findings = || pipeline.face().findings(&changed);
    rules
        .into_iter()
        .find(is_error)
        .or_else(|| findings().into_iter().find(is_error))
        .map(|d| format!("{}: {}", d.path, d.message))
}

/// The largest x in [`low`, `high`] the mission stays valid with under
/// `change(x)`, a [`MARGIN_RESOLUTION`] step inside the boundary, and why
/// not more; `None` when `high` is valid.
fn valid_up_to(
    mission: &Mission,
    pipeline: Kind,
    low: f64,
    high: f64,
    change: &dyn Fn(&mut Mission, f64),
) -> Option<(f64, String)> {
    let mut why = invalid_with(mission, pipeline, &|m| change(m, high))?;
    let (base, mut low, mut high) = (low, low, high);
    while high - low > MARGIN_RESOLUTION / 4.0 {
        let mid = 0.5 * (low + high);
        match invalid_with(mission, pipeline, &|m| change(m, mid)) {
            Some(message) => (high, why) = (mid, message),
            None => low = mid,
        }
    }
    // A step inside the boundary: a plan keeps its limits with a little
    // room (a pair exactly at 2 r_Q + the margin fails verification).
    let step = MARGIN_RESOLUTION;
    let inside = base + (((low - base) / step).ceil() - 1.0).max(0.0) * step;
    Some(((100.0 * inside).round() / 100.0, why))
}

/// The smallest x in [`from`, `highest`] for which `attempt(x)` gives a
/// report that `meets`: `from` (unless it is known to fail), then
/// `from` + 0.25 doubling the step, then halving the interval between the
/// last that failed and the first that met it to [`MARGIN_RESOLUTION`]
/// (each halving on a centimetre grid: the value reported is the value
/// planned with, as the user will write it).
fn smallest(
    from: f64,
    from_fails: bool,
    highest: f64,
    attempt: &mut dyn FnMut(f64) -> Result<Option<Report>, FlightError>,
    meets: &dyn Fn(&Report) -> bool,
) -> Result<Option<(f64, Report)>, FlightError> {
    let mut failed = from_fails.then_some(from);
    let mut met: Option<(f64, Report)> = None;
    // The first step beyond `from`; each later one doubles the distance.
    const FIRST: f64 = 0.25;
    let mut x = if from_fails {
        (from + FIRST).min(highest)
    } else {
        from
    };
    loop {
        match attempt(x)? {
            Some(report) if meets(&report) => {
                met = Some((x, report));
                break;
            }
            _ => failed = Some(x),
        }
        if x >= highest {
            break;
        }
        // The highest value is tried before giving up.
        x = if x == from {
            from + FIRST
        } else {
            from + 2.0 * (x - from)
        }
        .min(highest);
    }
    let Some((mut high, mut best)) = met else {
        return Ok(None);
    };
    let Some(mut low) = failed else {
        return Ok(Some((high, best)));
    };
    while high - low > MARGIN_RESOLUTION {
        // On a centimetre grid, so that the value printed is the one planned.
        let mid = (50.0 * (low + high)).round() / 100.0;
        match attempt(mid)? {
            Some(report) if meets(&report) => {
                high = mid;
                best = report;
            }
            _ => low = mid,
        }
    }
    Ok(Some((high, best)))
}

/// The smallest extra clearance m from the obstacles whose plan, flown
/// `options.flights` times, breaks r_Q in at most `target` of the flights
/// (0, then doubling from 0.25 m, then halving to [`MARGIN_RESOLUTION`]; see
/// [`with_margin`] for what m is added to). When the pairs still break
/// 2 r_Q in more than `target` of the flights with it (set by the slots'
/// spacing against each receiver's own fix error and the take-off skew, which
/// no margin from the site moves), the smallest spacing scale that brings
/// the pairs within `target` (1.25, doubling the step, then halving), for
/// a pipeline that can widen its spacing; and when the wider formation,
/// passing closer to the site, breaks r_Q again, the margin once more at
/// that spacing, up from the one found. Values that make the mission
/// invalid are not tried beyond the largest valid one, and the search says
/// so ([`MarginSearch::limit`], [`MarginSearch::spacing_limit`]). `plan`
/// plans a mission (`Err`: no plan, and why). The share is the flights' own
/// (its 95 % interval is in the report).
pub fn find_margin(
    pipeline: Kind,
    mission: &Mission,
    target: f64,
    options: Options,
    plan: &mut dyn FnMut(&Mission) -> Result<Planned, String>,
    cancel: &CancelToken,
) -> Result<MarginSearch, FlightError> {
    let cap = valid_up_to(mission, pipeline, 0.0, MAX_MARGIN, &|m, x| {
        with_margin(m, pipeline, x)
    });
    let mut tried = Vec::new();
    let mut attempt = |m: f64, spacing: f64| -> Result<Option<Report>, FlightError> {
        if cancel.is_cancelled() {
            return Err(FlightError::Cancelled);
        }
        let mut changed = mission.clone();
        with_margin(&mut changed, pipeline, m);
        with_spacing(&mut changed, pipeline, spacing);
        let planned = match plan(&changed) {
            Ok(p) => p,
            Err(why) => {
                tried.push(Tried {
                    margin: m,
                    spacing,
                    share: None,
                    note: why,
                });
                return Ok(None);
            }
        };
        let setup = Setup::new(&changed, &planned)?;
        let report = check(&setup, options, &|_, _| {}, cancel)?;
        tried.push(Tried {
            margin: m,
            spacing,
            share: Some(report.break_any.share),
            note: tried_note(&report),
        });
        Ok(Some(report))
    };
    let highest = cap.as_ref().map_or(MAX_MARGIN, |(m, _)| *m);
    // First the obstacles: r_Q.
    let keeps_clearance = |r: &Report| r.break_clearance.share <= target;
    let found = smallest(
        0.0,
        false,
        highest,
        &mut |m| attempt(m, 1.0),
        &keeps_clearance,
    )?;
    let mut search = MarginSearch {
        target,
        margin: found.as_ref().map(|(m, _)| *m),
        spacing: None,
        report: None,
        tried: Vec::new(),
        limit: cap.map(|(m, why)| MarginLimit { margin: m, why }),
        spacing_limit: None,
    };
    let keeps_all = |r: &Report| r.break_any.share <= target;
    match found {
        Some((_, report)) if keeps_all(&report) => search.report = Some(report),
        // Then the pairs: 2 r_Q, at that margin.
        Some((m, _)) if pipeline.face().spacing_field().is_some() => {
            let spacing_cap = valid_up_to(mission, pipeline, 1.0, MAX_SPACING, &|changed, s| {
                with_margin(changed, pipeline, m);
                with_spacing(changed, pipeline, s);
            });
            let widest = spacing_cap.as_ref().map_or(MAX_SPACING, |(s, _)| *s);
            search.spacing_limit = spacing_cap.map(|(s, why)| MarginLimit { margin: s, why });
            let keeps_pairs = |r: &Report| r.break_separation.share <= target;
            let widened = if widest > 1.0 {
                smallest(1.0, true, widest, &mut |s| attempt(m, s), &keeps_pairs)?
            } else {
                None
            };
            match widened {
                Some((s, report)) if keeps_all(&report) => {
                    search.spacing = Some(s);
                    search.report = Some(report);
                }
                // A wider formation passes closer to the site: the margin
                // again, at that spacing, from where it was.
                Some((s, _)) => {
                    search.spacing = Some(s);
                    let cap = valid_up_to(mission, pipeline, m, MAX_MARGIN, &|changed, x| {
                        with_margin(changed, pipeline, x);
                        with_spacing(changed, pipeline, s);
                    });
                    let highest = cap.as_ref().map_or(MAX_MARGIN, |(x, _)| *x);
                    if let Some((x, why)) = cap {
                        search.limit = Some(MarginLimit { margin: x, why });
                    }
                    if highest > m
                        && let Some((x, report)) =
                            smallest(m, true, highest, &mut |x| attempt(x, s), &keeps_all)?
                    {
                        search.margin = Some(x);
                        search.report = Some(report);
                    }
                }
                None => {}
            }
        }
        _ => {}
    }
    search.tried = tried;
    Ok(search)
}

/// A try's counts, and its worst place when a flight broke a limit.
fn tried_note(report: &Report) -> String {
    let counts = format!(
        "{} of {} flights break a limit ({} 2 r_Q, {} r_Q",
        report.break_any.count,
        report.break_any.of,
        report.break_separation.count,
        report.break_clearance.count
    );
    match &report.worst {
        Some(w) if report.break_any.count > 0 => format!("{counts}; worst: {})", w.what),
        _ => format!("{counts})"),
    }
}
