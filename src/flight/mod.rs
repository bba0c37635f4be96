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
//! The `--target` margin search that plans and flies again is `margin.rs`;
//! the air, the autopilot and the report are submodules too.

pub mod air;
pub mod autopilot;
mod margin;
pub mod odds;
pub mod rare;
mod recording;
mod report;
pub mod shard;

use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Point3, Vector3};
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::geometry::segment_point_distance_3d;
use crate::base::shape::Prism;
use crate::export::reverify::Flight;
use crate::export::{Placement, Planned, VehiclePlan, reduce};
use crate::mission::Mission;
use crate::pipelines::CancelToken;
use crate::pipelines::quadrotor::Body;

pub use margin::{
    BetterFixes, GNSS_GRADES, MARGIN_RESOLUTION, MAX_MARGIN, MAX_SPACING, MarginLimit,
    MarginSearch, Tried, find_margin, margin_field, passing_plan, with_margin, with_spacing,
};
pub use recording::{RECORDED_WORST, Recording};
pub use report::{Report, Share, Spread, Worst, wilson};

use air::Normals;
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
    /// The pipeline that planned it (`Words::name`).
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
            pipeline: planned.pipeline.words().name,
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
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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

impl Flown {
    /// The least room to 2 r_Q (+ margin) over the flight, metres: the
    /// closest pair less `setup.closest` (negative: broken; ∞ for one
    /// vehicle).
    pub fn separation_room(&self, setup: &Setup) -> f64 {
        let closest = self.pairs.iter().map(|c| c.distance);
        closest.fold(f64::INFINITY, f64::min) - setup.closest
    }

    /// The least room to r_Q (+ margins) from the obstacles over the
    /// flight, metres: the closest any vehicle came less `setup.clearance`.
    pub fn clearance_room(&self, setup: &Setup) -> f64 {
        let closest = self.obstacles.iter().flatten().map(|c| c.distance);
        closest.fold(f64::INFINITY, f64::min) - setup.clearance
    }

    /// Whether some pair came closer than `setup.closest` (2 r_Q + margin).
    pub fn broke_separation(&self, setup: &Setup) -> bool {
        self.separation_room(setup) < 0.0
    }

    /// Whether some vehicle came closer than `setup.clearance` to an obstacle.
    pub fn broke_clearance(&self, setup: &Setup) -> bool {
        self.clearance_room(setup) < 0.0
    }
}

/// Flies flight `k` of the check seeded `seed`.
pub fn fly(setup: &Setup, seed: u64, k: usize, keep_tracks: bool) -> Flown {
    fly_keeping(setup, seed, k, keep_tracks, false)
}

/// [`fly`], keeping each sample's cross-track error when `keep_spread`.
fn fly_keeping(setup: &Setup, seed: u64, k: usize, keep_tracks: bool, keep_spread: bool) -> Flown {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(k as u64);
    fly_on(setup, &mut rng, k, keep_tracks, keep_spread)
}

/// Flies one flight (numbered `k` in its report) on the standard normal
/// draws of `rng`: the skews, the air, the fixes, in that order.
fn fly_on(
    setup: &Setup,
    rng: &mut impl Normals,
    k: usize,
    keep_tracks: bool,
    keep_spread: bool,
) -> Flown {
    let p = &setup.mission.flight;
    let body = Body::of(setup.mission);
    let gains = autopilot::Gains::of(&setup.mission.vehicle);
    let n = setup.plans.len();
    let mut takeoff = Vec::with_capacity(n);
    let mut fixes = Vec::with_capacity(n);
    let mut pilots: Vec<Autopilot> = Vec::with_capacity(n);
    let mut air = air::Air::new(p, rng);
    let mut common = air::Gnss::new(p, false, rng);
    for plan in &setup.plans {
        let skew = rng.normal() * p.takeoff_skew;
        let start = plan.waypoints.first().map_or(0.0, |w| w.t) + skew;
        takeoff.push(skew);
        fixes.push(air::Gnss::new(p, true, rng));
        pilots.push(Autopilot::new(
            plan,
            setup.mission.vehicle.limits(plan.vehicle),
            gains,
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
    // The flight begins with the earliest take-off: a negative skew flies
    // early (issue 52: the clock began at the plan's start, so an early
    // vehicle waited and flew on time).
    let early = takeoff.iter().copied().fold(0.0, f64::min);
    let start = setup.start() + early;
    let steps = setup.steps() + (-early / dt).ceil() as usize;
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
        let wind = air.step(rng, dt, height, &velocity);
        let shared = common.step(rng, dt);
        for (pilot, own) in pilots.iter_mut().zip(&mut fixes) {
            let gnss = shared + own.step(rng, dt);
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
    let recording = recording::recording(setup, options, &report, &flown);
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
    fly_range(
        setup,
        options,
        0..options.flights,
        keep_spread,
        progress,
        cancel,
    )
}

/// Flights `range` of a check (a shard's, or all), in flight order.
fn fly_range(
    setup: &Setup,
    options: Options,
    range: std::ops::Range<usize>,
    keep_spread: bool,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancel: &CancelToken,
) -> Result<Vec<Flown>, FlightError> {
    let done = AtomicUsize::new(0);
    let total = range.len();
    let flown: Vec<Option<Flown>> = on_threads(options.threads, || {
        range
            .into_par_iter()
            .map(|k| {
                if cancel.is_cancelled() {
                    return None;
                }
                let flown = fly_keeping(setup, options.seed, k, false, keep_spread);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                Some(flown)
            })
            .collect()
    });
    flown
        .into_iter()
        .collect::<Option<Vec<Flown>>>()
        .ok_or(FlightError::Cancelled)
}
