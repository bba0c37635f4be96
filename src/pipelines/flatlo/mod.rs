//! FLATLO: the latitudinal-to-longitudinal squadron transition (Giacomin and
//! Hemerly). Each aircraft's reference comes from Algorithm 1 on its own (one
//! worker per aircraft, as the paper's one processor per aircraft); a common
//! arrival time fixes each aircraft's airspeed; then each point-mass aircraft
//! (eqs. 1-6) flies its reference under the autopilot, integrated by RK4 with
//! seeded noise; finally the squadron is verified: separation, final spacing,
//! lateral spread and tracking error.
//!
//! Long (~990 lines) because it holds the pipeline's three stages (references, the squadron
//! flown in chunks, the verification), the outcome types they fill, and the budget and
//! diagnostics that predict them from the same figures; the aircraft, the manoeuvres and
//! the envelope are already submodules.

pub mod aircraft;
pub mod algorithm;
pub mod chart;
pub mod envelope;
pub mod face;
pub mod maneuver;
pub mod recording;
mod section;
pub mod summary;

use nalgebra::{Point3, Vector3};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;
use serde::Serialize;

use crate::base::ode::rk4_step;
use crate::mission::{Diagnostic, FieldPath, FlatloParams, Mission, compact};
use crate::pipelines::{CancelToken, Completion, Event, Level, Observer, PipelineError};

use aircraft::{Airframe, Autopilot, Controls, State, Target};
use algorithm::Side;
use envelope::{Envelope, Violation};
use maneuver::{Path, Primitive};

/// Simulated seconds between progress reports and cancellation checks.
const CHUNK_SECONDS: f64 = 60.0;

/// Samples kept per aircraft for views and recordings (every k-th sample of
/// the `sample_period` grid, k chosen to stay under this, plus the last one).
/// Verification sees every sample as it is produced, so memory stays bounded
/// whatever the squadron and its flight time.
pub const KEPT_SAMPLES: usize = 2_000;

/// Squadrons up to this size get every pair's closest approach
/// (`FlatloOutcome::pairs`); larger ones only the closest pair overall.
pub const MAX_PAIR_TABLE: usize = 12;

/// One aircraft's reference: the manoeuvres and the speed along them.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    pub path: Path,
    /// Length of the transition (all but the final leg), metres.
    pub transition_length: f64,
    /// Airspeed until the common arrival time, m/s.
    pub airspeed: f64,
    /// Airspeed afterwards (the nominal one), m/s.
    pub nominal: f64,
    /// When every aircraft reaches the longitudinal line, s.
    pub arrival: f64,
}

impl Reference {
    /// The time the reference reaches arc length `s` (the inverse of
    /// [`Self::distance`]).
    pub fn time_at(&self, s: f64) -> f64 {
        if s <= self.transition_length && self.airspeed > 0.0 {
            s / self.airspeed
        } else if s <= self.transition_length {
            0.0
        } else {
            self.arrival + (s - self.transition_length) / self.nominal.max(f64::MIN_POSITIVE)
        }
    }

    /// Arc length reached at time t.
    pub fn distance(&self, t: f64) -> f64 {
        if t <= self.arrival {
            self.airspeed * t
        } else {
            self.transition_length + self.nominal * (t - self.arrival)
        }
    }

    /// Where the reference is at time t (position, velocity, acceleration).
    pub fn at(&self, t: f64, hint: &mut usize) -> Target {
        let speed = if t <= self.arrival {
            self.airspeed
        } else {
            self.nominal
        };
        let p = self.path.at(self.distance(t), hint);
        Target {
            position: p.position,
            velocity: p.tangent * speed,
            acceleration: p.curvature * (speed * speed),
        }
    }
}

/// The references of the whole squadron (noise-free geometry of Algorithm 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    pub references: Vec<Reference>,
    pub starts: Vec<Point3<f64>>,
    pub arrival: f64,
    /// Arrival plus the final leg at the nominal airspeed.
    pub duration: f64,
}

/// Builds every aircraft's reference (in parallel, each independent of the
/// others) and the airspeeds that bring them onto the line together: each
/// flies its transition length over the time the longest one takes at the
/// nominal airspeed.
pub fn references(p: &FlatloParams) -> Plan {
    let n = p.aircraft;
    let squadron = algorithm::Squadron::from_params(p);
    let phi = squadron.heading;
    let start0 = Point3::new(p.start.x, p.start.y, p.altitude);
    let built: Vec<(Point3<f64>, algorithm::Manoeuvres)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let start = algorithm::start_position(i, n, p.spacing, phi, start0);
            let m = algorithm::flatlo(i, &squadron, start);
            (start, m)
        })
        .collect();
    let lengths: Vec<f64> = built
        .iter()
        .map(|(_, m)| m.transition.iter().map(Primitive::length).sum())
        .collect();
    let longest = lengths.iter().copied().fold(0.0, f64::max);
    let arrival = longest / p.airspeed;
    let references = built
        .iter()
        .zip(&lengths)
        .map(|((_, m), &length)| {
            let mut primitives = m.transition.clone();
            primitives.push(m.final_leg);
            Reference {
                path: Path::new(primitives),
                transition_length: length,
                airspeed: if arrival > 0.0 {
                    length / arrival
                } else {
                    p.airspeed
                },
                nominal: p.airspeed,
                arrival,
            }
        })
        .collect();
    Plan {
        references,
        starts: built.iter().map(|(s, _)| *s).collect(),
        arrival,
        duration: arrival + p.final_leg / p.airspeed,
    }
}

/// A reference point, on the global time grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RefSample {
    pub t: f64,
    pub position: Point3<f64>,
}

/// Samples a reference every `period` seconds from 0 to `duration`: O(m).
pub fn sample(reference: &Reference, period: f64, duration: f64) -> Vec<RefSample> {
    let steps = (duration / period).ceil() as usize;
    let mut hint = 0;
    (0..=steps)
        .map(|k| {
            let t = (k as f64 * period).min(duration);
            RefSample {
                t,
                position: reference.at(t, &mut hint).position,
            }
        })
        .collect()
}

/// A flown state, on the sample grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FlownSample {
    pub t: f64,
    pub position: Point3<f64>,
    /// V, m/s.
    pub airspeed: f64,
    /// γ, rad.
    pub gamma: f64,
    /// χ, rad.
    pub chi: f64,
    pub controls: Controls,
}

/// One aircraft's plan, flight and tracking.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AircraftOutcome {
    pub index: usize,
    pub side: Side,
    /// Δ_m of Algorithm 2, metres.
    pub advance: f64,
    /// Δ of lines 32-40: distance from the centre line at the start, metres.
    pub lateral_distance: f64,
    pub start: Point3<f64>,
    /// Reference airspeed during the transition, m/s.
    pub airspeed: f64,
    /// Length of the transition manoeuvres, metres.
    pub transition_length: f64,
    pub manoeuvres: Vec<Primitive>,
    pub reference: Vec<RefSample>,
    pub flown: Vec<FlownSample>,
    /// max and RMS of |p − p_ref| over every simulation step, metres.
    pub tracking_max: f64,
    pub tracking_rms: f64,
}

/// The closest two aircraft came.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PairDistance {
    pub a: usize,
    pub b: usize,
    /// Metres.
    pub min_distance: f64,
    /// When, s.
    pub time: f64,
}

/// Along-line distance between consecutive aircraft of the final line.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spacing {
    /// The aircraft in front and the one behind it (0-based indices).
    pub front: usize,
    pub back: usize,
    pub spacing: f64,
}

/// The verdict on a squadron that flew the whole transition.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlatloVerification {
    /// The mission's threshold, metres.
    pub min_separation: f64,
    /// Every pair kept at least `min_separation` apart.
    pub passed: bool,
    /// Flown, at the end of the simulation.
    pub final_spacing: Vec<Spacing>,
    /// Largest |spacing − Δ_d| / Δ_d of the flown line.
    pub max_spacing_error: f64,
    /// Spread of the flown line across its direction, metres.
    pub lateral_spread: f64,
    /// The same for the exact references at the end (the theorem of Section 4.2).
    pub reference_spacing: Vec<Spacing>,
    pub reference_lateral_spread: f64,
    /// The lowest and highest airspeed any aircraft flew, at any step, m/s,
    /// and the range it must stay in (`airspeed_range`).
    pub airspeed_flown: [f64; 2],
    pub airspeed_range: [f64; 2],
    /// The largest |bank| any aircraft flew, and its limit, degrees.
    pub bank_flown_deg: f64,
    pub max_bank_deg: f64,
    /// The least distance inside the x-y bounds and the altitude band of
    /// any aircraft, flown (on the sample grid) or its reference, metres;
    /// negative when one left them.
    pub bounds_margin: f64,
    /// The first limit broken (airspeed, bank, bounds; by the flight or by a
    /// reference), the earliest; `None` when the squadron flew within all.
    pub violation: Option<Violation>,
}

/// Everything a FLATLO run produces.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlatloOutcome {
    /// The pipeline, the mission, the seed and how the run ended.
    #[serde(flatten)]
    pub header: crate::pipelines::Header,
    /// Common instant every aircraft reaches the longitudinal line, s.
    pub arrival_time: f64,
    /// Simulated time, s.
    pub duration: f64,
    /// Every `sample_stride`-th sample of the `sample_period` grid is kept in
    /// `AircraftOutcome::flown` and `reference` (1 for small runs).
    pub sample_stride: usize,
    pub aircraft: Vec<AircraftOutcome>,
    /// The closest two aircraft came over what was flown (every sample).
    pub closest: Option<PairDistance>,
    /// Every pair's closest approach, for squadrons of at most
    /// `MAX_PAIR_TABLE` aircraft; empty for larger ones.
    pub pairs: Vec<PairDistance>,
    /// `None` when the run was cancelled: a partial flight has no verdict.
    pub verification: Option<FlatloVerification>,
}

impl FlatloVerification {
    /// The closest pair kept `min_separation`.
    pub fn separated(&self, closest: Option<PairDistance>) -> bool {
        closest.is_none_or(|c| c.min_distance >= self.min_separation)
    }
}

impl FlatloOutcome {
    /// The whole transition was flown and verified, and passed.
    pub fn passed(&self) -> bool {
        self.verification.as_ref().is_some_and(|v| v.passed)
    }
}

/// One aircraft in flight.
struct Flight {
    airframe: Airframe,
    reference: Reference,
    state: State,
    pilot: Autopilot,
    rng: ChaCha8Rng,
    noise: f64,
    hint: usize,
    step: usize,
    /// Samples taken so far (every `every` steps, and the last step).
    samples: usize,
    /// Positions sampled in the current chunk, for verification; cleared by it.
    fresh: Vec<(f64, Point3<f64>)>,
    flown: Vec<FlownSample>,
    error_max: f64,
    error_sq: f64,
    /// What the flight is judged against, and what it flew so far.
    index: usize,
    envelope: Envelope,
    judged: Judged,
}

/// What one aircraft flew against its envelope: the first limit broken and
/// the extremes.
#[derive(Debug, Clone, Copy)]
struct Judged {
    first: Option<Violation>,
    airspeed: [f64; 2],
    bank: f64,
    margin: f64,
}

impl Judged {
    fn new() -> Self {
        Judged {
            first: None,
            airspeed: [f64::INFINITY, f64::NEG_INFINITY],
            bank: 0.0,
            margin: f64::INFINITY,
        }
    }

    fn note(&mut self, v: Violation) {
        if self.first.is_none() {
            self.first = Some(v);
        }
    }
}

impl Flight {
    /// A sample on the grid: always to verification, every `keep`-th (and
    /// the last) to `flown`.
    fn record(&mut self, t: f64, controls: Controls, keep: usize, is_last: bool) {
        let s = &self.state;
        let position = aircraft::position(s);
        self.fresh.push((t, position));
        self.judged.margin = self.judged.margin.min(self.envelope.margin(&position));
        if let Some((check, value, limit)) = self.envelope.outside(&position) {
            self.judged.note(Violation {
                aircraft: self.index,
                check,
                time: t,
                value,
                limit,
                reference: false,
            });
        }
        if self.samples.is_multiple_of(keep) || is_last {
            self.flown.push(FlownSample {
                t,
                position,
                airspeed: s[aircraft::V],
                gamma: s[aircraft::GAMMA],
                chi: s[aircraft::CHI],
                controls,
            });
        }
        self.samples += 1;
    }

    /// Flies steps up to (not including) `until`, sampling every `every`
    /// steps and keeping every `keep`-th sample.
    fn fly(&mut self, until: usize, dt: f64, every: usize, keep: usize, last: usize) {
        while self.step < until {
            let t = self.step as f64 * dt;
            let target = self.reference.at(t, &mut self.hint);
            let error = (target.position - aircraft::position(&self.state)).norm();
            self.error_max = self.error_max.max(error);
            self.error_sq += error * error;
            let u = self.pilot.command(&self.airframe, &self.state, &target, dt);
            self.judge_bank(t, &u);
            if self.step.is_multiple_of(every) {
                self.record(t, u, keep, false);
            }
            let airframe = self.airframe;
            self.state = rk4_step(|_, x| airframe.derivative(x, &u), t, &self.state, dt);
            if self.noise > 0.0 {
                // Section 3's 0.25 % noise, read as a relative perturbation of
                // the velocity vector: V ← V(1 + σξ), and its direction turned
                // by σξ radians in γ and in χ. (Multiplying the angles instead
                // would switch the noise off when flying level and east: the
                // paper's own case.)
                let [z1, z2, z3]: [f64; 3] =
                    std::array::from_fn(|_| self.rng.sample(StandardNormal));
                self.state[aircraft::V] *= 1.0 + self.noise * z1;
                self.state[aircraft::GAMMA] += self.noise * z2;
                self.state[aircraft::CHI] += self.noise * z3;
            }
            self.step += 1;
            self.judge_airspeed(self.step as f64 * dt);
            if self.step == last {
                let t = last as f64 * dt;
                let target = self.reference.at(t, &mut self.hint);
                let u = self.pilot.command(&self.airframe, &self.state, &target, dt);
                self.record(t, u, keep, true);
            }
        }
    }
}

impl Flight {
    /// The bank commanded at `t` against `max_bank_deg`.
    fn judge_bank(&mut self, t: f64, u: &Controls) {
        let bank = u.bank.abs();
        self.judged.bank = self.judged.bank.max(bank);
        if bank > self.envelope.max_bank * (1.0 + 1e-12) {
            self.judged.note(Violation {
                aircraft: self.index,
                check: envelope::Check::Bank,
                time: t,
                value: bank.to_degrees(),
                limit: self.envelope.max_bank.to_degrees(),
                reference: false,
            });
        }
    }

    /// The airspeed reached at `t` (after the step and its noise) against
    /// `airspeed_range`.
    fn judge_airspeed(&mut self, t: f64) {
        let v = self.state[aircraft::V];
        let [lo, hi] = &mut self.judged.airspeed;
        *lo = lo.min(v);
        *hi = hi.max(v);
        if let Some((check, limit)) = self.envelope.airspeed_outside(v) {
            self.judged.note(Violation {
                aircraft: self.index,
                check,
                time: t,
                value: v,
                limit,
                reference: false,
            });
        }
    }
}

/// FLATLO's predicted size against `pipeline::limits`: aircraft, integration
/// steps (aircraft × duration / sim_step) and sample instants verification
/// scans (aircraft × duration / sample_period). The duration comes from
/// Algorithm 1's references (cheap: no simulation), so the figure is exact.
pub fn budget(mission: &Mission) -> Vec<Diagnostic> {
    use crate::pipelines::{figure, limits};
    let p = &mission.flatlo;
    let at = |key: &str| FieldPath::root().key("flatlo").key(key);
    if p.aircraft > limits::FLATLO_AIRCRAFT {
        return vec![Diagnostic::error(
            at("aircraft"),
            format!(
                "{} aircraft is over the limit of {}",
                figure(p.aircraft as f64),
                limits::FLATLO_AIRCRAFT
            ),
        )];
    }
    let mut out = Vec::new();
    let duration = references(p).duration;
    let n = p.aircraft as f64;
    let steps = n * (duration / p.sim_step).ceil();
    if crate::pipelines::exceeds(steps, limits::FLATLO_STEPS) {
        // The step is the usual typo; a long flight comes from the squadron.
        let key = if p.sim_step < 1e-3 {
            "sim_step"
        } else {
            "aircraft"
        };
        out.push(Diagnostic::error(
            at(key),
            format!(
                "{} aircraft fly {} s in steps of {} s: {} integration steps (limit {})",
                p.aircraft,
                figure(duration),
                figure(p.sim_step),
                figure(steps),
                figure(limits::FLATLO_STEPS)
            ),
        ));
    }
    let samples = n * (duration / p.sample_period).ceil();
    if crate::pipelines::exceeds(samples, limits::FLATLO_SAMPLES) {
        out.push(Diagnostic::error(
            at("sample_period"),
            format!(
                "{} aircraft sampled every {} s over {} s: {} samples to verify (limit {})",
                p.aircraft,
                figure(p.sample_period),
                figure(duration),
                figure(samples),
                figure(limits::FLATLO_SAMPLES)
            ),
        ));
    }
    out
}

/// What a FLATLO run asks beyond the mission and the seed: nothing (its
/// section says it all).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Request;

/// Plans and simulates the mission's squadron with `seed` (the noise). Fails
/// only on an invalid mission; a squadron that comes too close is a failed
/// verification, not an error.
///
/// Long (~160 lines): references, simulation and verification in order, the paper's three
/// stages.
pub fn plan(
    mission: &Mission,
    seed: u64,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<FlatloOutcome, PipelineError> {
    crate::pipelines::require_admissible(mission, budget)?;
    // What `check` predicts from the references: an unflyable airspeed, or a
    // squadron that leaves the bounds it starts in, is refused before flying.
    let unflyable: Vec<String> = diagnostics(mission)
        .into_iter()
        .filter(Diagnostic::is_error)
        .map(|d| d.to_string())
        .collect();
    if !unflyable.is_empty() {
        return Err(PipelineError::InvalidMission(unflyable.join("\n")));
    }
    let p = &mission.flatlo;
    let n = p.aircraft;

    observer.on_event(Event::Stage("references"));
    let plan = references(p);
    for (i, r) in plan.references.iter().enumerate() {
        let text = format!(
            "aircraft {}: Δm {:.0} m, transition {:.0} m at {:.2} m/s",
            i + 1,
            algorithm::move_forward(i, n, p.spacing),
            r.transition_length,
            r.airspeed
        );
        observer.on_event(Event::Log(Level::Info, &text));
    }

    observer.on_event(Event::Stage("simulation"));
    let dt = p.sim_step;
    let every = ((p.sample_period / dt).round() as usize).max(1);
    let last = (plan.duration / dt).ceil() as usize;
    let keep = (last / every + 1).div_ceil(KEPT_SAMPLES).max(1);
    let airframe = Airframe::from_params(p);
    let envelope = Envelope::of(mission);
    let mut flights: Vec<Flight> = plan
        .references
        .iter()
        .zip(&plan.starts)
        .enumerate()
        .map(|(i, (reference, start))| {
            let dir = reference.path.at(0.0, &mut 0).tangent;
            let (chi, gamma) = maneuver::angles(&dir);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(i as u64);
            Flight {
                airframe,
                reference: reference.clone(),
                // Section 3: every aircraft starts at the nominal airspeed.
                state: State::new(p.airspeed, gamma, chi, start.x, start.y, start.z),
                pilot: Autopilot::new(p.pid),
                rng,
                noise: p.noise,
                hint: 0,
                step: 0,
                samples: 0,
                fresh: Vec::new(),
                flown: Vec::with_capacity((last / every) / keep + 2),
                error_max: 0.0,
                error_sq: 0.0,
                index: i,
                envelope: envelope.clone(),
                judged: Judged::new(),
            }
        })
        .collect();
    let chunk = ((CHUNK_SECONDS / dt).round() as usize).max(1);
    let mut done = 0;
    let mut completion = Completion::Finished;
    let mut separation = Separation::new(n);
    while done < last {
        let until = (done + chunk).min(last);
        flights
            .par_iter_mut()
            .for_each(|f| f.fly(until, dt, every, keep, last));
        separation.scan(&mut flights);
        done = until;
        observer.on_event(Event::Progress(0.95 * done as f64 / last as f64));
        if cancel.is_cancelled() && done < last {
            completion = Completion::Cancelled;
            let text = format!(
                "cancelled at t = {:.0} s of {:.0} s",
                done as f64 * dt,
                plan.duration
            );
            observer.on_event(Event::Log(Level::Warn, &text));
            break;
        }
    }

    observer.on_event(Event::Stage("verification"));
    let reference_period = p.sample_period * keep as f64;
    let judged: Vec<Judged> = flights.iter().map(|f| f.judged).collect();
    let aircraft: Vec<AircraftOutcome> = flights
        .into_iter()
        .enumerate()
        .map(|(i, f)| {
            let steps = f.step.max(1) as f64;
            AircraftOutcome {
                index: i,
                side: algorithm::side(i, n),
                advance: algorithm::move_forward(i, n, p.spacing),
                lateral_distance: algorithm::lateral_distance(i, n, p.spacing),
                start: plan.starts[i],
                airspeed: f.reference.airspeed,
                transition_length: f.reference.transition_length,
                manoeuvres: f.reference.path.primitives.clone(),
                reference: sample(&f.reference, reference_period, plan.duration),
                tracking_max: f.error_max,
                tracking_rms: (f.error_sq / steps).sqrt(),
                flown: f.flown,
            }
        })
        .collect();
    let closest = separation.closest;
    let verification = (completion == Completion::Finished)
        .then(|| verify(p, &plan, &aircraft, closest, &envelope, &judged));
    if let (Some(c), Some(v)) = (closest, &verification) {
        let separated = v.separated(Some(c));
        let text = format!(
            "closest approach: aircraft {} and {} at {:.0} m (t = {:.0} s); minimum separation {:.0} m: {}",
            c.a + 1,
            c.b + 1,
            c.min_distance,
            c.time,
            p.min_separation,
            if separated { "pass" } else { "FAIL" }
        );
        let level = if separated { Level::Info } else { Level::Warn };
        observer.on_event(Event::Log(level, &text));
    }
    if let Some(v) = verification.as_ref().and_then(|v| v.violation) {
        observer.on_event(Event::Log(
            Level::Warn,
            &format!("not flyable: {}", v.describe()),
        ));
    }
    // A cancelled run stays at the share it got through.
    if completion == Completion::Finished {
        observer.on_event(Event::Progress(1.0));
    }
    Ok(FlatloOutcome {
        header: crate::pipelines::Header {
            pipeline: crate::pipelines::Kind::Flatlo,
            mission: mission.name.clone(),
            seed,
            completion,
        },
        arrival_time: plan.arrival,
        duration: plan.duration,
        sample_stride: keep,
        aircraft,
        closest,
        pairs: separation.pairs,
        verification,
    })
}

/// Closest approaches, scanned chunk by chunk as the squadron flies: no
/// per-pair series is kept. Small squadrons keep every pair's minimum; for
/// larger ones a sweep along x over each sample instant finds the closest
/// pair in O(n log n), pruned by the closest distance seen so far.
struct Separation {
    closest: Option<PairDistance>,
    pairs: Vec<PairDistance>,
    order: Vec<usize>,
}

impl Separation {
    fn new(n: usize) -> Self {
        let mut pairs = Vec::new();
        if n <= MAX_PAIR_TABLE {
            for a in 0..n {
                for b in a + 1..n {
                    pairs.push(PairDistance {
                        a,
                        b,
                        min_distance: f64::INFINITY,
                        time: 0.0,
                    });
                }
            }
        }
        Separation {
            closest: None,
            pairs,
            order: (0..n).collect(),
        }
    }

    /// Takes every flight's fresh samples (all on the same instants).
    fn scan(&mut self, flights: &mut [Flight]) {
        let instants = flights.first().map_or(0, |f| f.fresh.len());
        let mut points = Vec::with_capacity(flights.len());
        for k in 0..instants {
            points.clear();
            points.extend(flights.iter().map(|f| f.fresh[k].1));
            let t = flights[0].fresh[k].0;
            if self.pairs.is_empty() {
                self.sweep(&points, t);
            } else {
                for pair in &mut self.pairs {
                    let d = (points[pair.a] - points[pair.b]).norm();
                    if d < pair.min_distance {
                        pair.min_distance = d;
                        pair.time = t;
                    }
                }
            }
        }
        if !self.pairs.is_empty() {
            self.closest = self
                .pairs
                .iter()
                .copied()
                .min_by(|a, b| a.min_distance.total_cmp(&b.min_distance));
        }
        for f in flights {
            f.fresh.clear();
        }
    }

    /// The closest pair of one instant, if closer than any so far.
    fn sweep(&mut self, points: &[Point3<f64>], t: f64) {
        self.order
            .sort_by(|&a, &b| points[a].x.total_cmp(&points[b].x));
        let mut best = self.closest.map_or(f64::INFINITY, |c| c.min_distance);
        for (i, &a) in self.order.iter().enumerate() {
            for &b in &self.order[i + 1..] {
                if points[b].x - points[a].x >= best {
                    break;
                }
                let d = (points[a] - points[b]).norm();
                if d < best {
                    best = d;
                    self.closest = Some(PairDistance {
                        a: a.min(b),
                        b: a.max(b),
                        min_distance: d,
                        time: t,
                    });
                }
            }
        }
    }
}

/// Spacing along `line` of consecutive points (front first) and their spread across it.
pub fn line_spacing(points: &[Point3<f64>], line: &Vector3<f64>) -> (Vec<Spacing>, f64) {
    let along: Vec<f64> = points.iter().map(|p| p.coords.dot(line)).collect();
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| along[b].total_cmp(&along[a]));
    let spacing = order
        .windows(2)
        .map(|w| Spacing {
            front: w[0],
            back: w[1],
            spacing: along[w[0]] - along[w[1]],
        })
        .collect();
    // Across the line, horizontally (a vertical line: along y).
    let left = Vector3::new(-line.y, line.x, 0.0);
    let left = if left.norm() > 1e-12 {
        left.normalize()
    } else {
        Vector3::y()
    };
    let across: Vec<f64> = points.iter().map(|p| p.coords.dot(&left)).collect();
    let spread = across.iter().copied().fold(f64::MIN, f64::max)
        - across.iter().copied().fold(f64::MAX, f64::min);
    (spacing, if points.is_empty() { 0.0 } else { spread })
}

/// The squadron's verdict: separation, the final line, and the envelope
/// (what each flight `judged` and each reference against the bounds).
fn verify(
    p: &FlatloParams,
    plan: &Plan,
    aircraft: &[AircraftOutcome],
    closest: Option<PairDistance>,
    envelope: &Envelope,
    judged: &[Judged],
) -> FlatloVerification {
    let spacing = p.sample_period * p.airspeed;
    let exits: Vec<envelope::ReferenceExit> = plan
        .references
        .iter()
        .enumerate()
        .map(|(i, r)| envelope.reference_exit(i, r, spacing))
        .collect();
    let violation = judged
        .iter()
        .filter_map(|j| j.first)
        .chain(exits.iter().filter_map(|e| e.first))
        .min_by(|a, b| a.time.total_cmp(&b.time));
    let bounds_margin = judged
        .iter()
        .map(|j| j.margin)
        .chain(exits.iter().map(|e| e.margin))
        .fold(f64::INFINITY, f64::min);
    let airspeed_flown = judged
        .iter()
        .fold([f64::INFINITY, f64::NEG_INFINITY], |a, j| {
            [a[0].min(j.airspeed[0]), a[1].max(j.airspeed[1])]
        });
    let bank_flown_deg = judged
        .iter()
        .map(|j| j.bank)
        .fold(0.0, f64::max)
        .to_degrees();
    let passed = closest.is_none_or(|c| c.min_distance >= p.min_separation) && violation.is_none();
    let line = algorithm::line_direction(p.heading_deg.to_radians(), p.climb_deg.to_radians());
    let flown_end: Vec<Point3<f64>> = aircraft
        .iter()
        .filter_map(|a| a.flown.last().map(|s| s.position))
        .collect();
    let (final_spacing, lateral_spread) = line_spacing(&flown_end, &line);
    let max_spacing_error = final_spacing
        .iter()
        .map(|s| (s.spacing - p.spacing).abs() / p.spacing)
        .fold(0.0, f64::max);
    let reference_end: Vec<Point3<f64>> = plan
        .references
        .iter()
        .map(|r| r.at(plan.duration, &mut 0).position)
        .collect();
    let (reference_spacing, reference_lateral_spread) = line_spacing(&reference_end, &line);
    FlatloVerification {
        min_separation: p.min_separation,
        passed,
        final_spacing,
        max_spacing_error,
        lateral_spread,
        reference_spacing,
        reference_lateral_spread,
        airspeed_flown,
        airspeed_range: p.airspeed_range,
        bank_flown_deg,
        max_bank_deg: p.max_bank_deg,
        bounds_margin,
        violation,
    }
}

/// What FLATLO predicts of a mission from its references alone (cheap: no
/// flight), as the budget is: each aircraft's common-arrival airspeed (its
/// transition length over the common duration) within `airspeed_range`,
/// the bank its turns need at that airspeed within `max_bank_deg`; and, for a squadron that starts inside the bounds (a mission for FLATLO:
/// a mission for another pipeline keeps the paper's squadron as its
/// `[flatlo]` defaults, far outside a bridge's bounds, and `run flatlo`
/// judges it there), every reference inside the x-y bounds and the
/// altitude band, as the export judges them. Errors name the aircraft and
/// the figure.
pub fn diagnostics(mission: &Mission) -> Vec<Diagnostic> {
    let p = &mission.flatlo;
    if p.aircraft > crate::pipelines::limits::FLATLO_AIRCRAFT || p.aircraft < 2 {
        return Vec::new(); // the budget and validation say why
    }
    let at = |key: &str| FieldPath::root().key("flatlo").key(key);
    let plan = references(p);
    let mut out = Vec::new();
    let [lo, hi] = p.airspeed_range;
    for (end, limit, word) in [(0, lo, "below"), (1, hi, "above")] {
        let off: Vec<(usize, &Reference)> = plan
            .references
            .iter()
            .enumerate()
            .filter(|(_, r)| {
                if end == 0 {
                    r.airspeed < lo
                } else {
                    r.airspeed > hi
                }
            })
            .collect();
        let Some(&(i, r)) = off.first() else {
            continue;
        };
        let others = match off.len() - 1 {
            0 => String::new(),
            1 => format!(" (and aircraft {})", off[1].0 + 1),
            more => format!(" (and {more} more aircraft)"),
        };
        out.push(Diagnostic::error(
            at("airspeed_range").index(end),
            format!(
                "aircraft {} would fly its transition at {:.2} m/s ({:.0} m in the common \
                 {:.0} s that brings the squadron onto the line together), {word} \
                 airspeed_range[{end}] = {} m/s{others}",
                i + 1,
                r.airspeed,
                r.transition_length,
                plan.arrival,
                compact(limit)
            ),
        ));
    }
    // The bank each aircraft's turns need at its transition airspeed
    // (coordinated: tan μ = a_horizontal / g, a = v²/r along the turn's normal).
    let needed = plan
        .references
        .iter()
        .enumerate()
        .flat_map(|(i, r)| {
            r.path.primitives.iter().filter_map(move |m| match *m {
                maneuver::Primitive::Turn { normal, radius, .. } if radius > 0.0 => {
                    let lateral = r.airspeed.powi(2) / radius * normal.xy().norm();
                    Some((i, (lateral / aircraft::G).atan().to_degrees()))
                }
                _ => None,
            })
        })
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((i, bank)) = needed.filter(|(_, bank)| *bank > p.max_bank_deg) {
        out.push(Diagnostic::error(
            at("max_bank_deg"),
            format!(
                "aircraft {}'s turns of {} m radius at {:.2} m/s need a bank of {bank:.1}°, \
                 beyond max_bank_deg = {}°",
                i + 1,
                compact(p.turn_radius),
                plan.references[i].airspeed,
                compact(p.max_bank_deg)
            ),
        ));
    }
    let envelope = Envelope::of(mission);
    let start = plan.starts.first().copied().unwrap_or_default();
    if envelope.outside(&start).is_none() {
        let exits: Vec<envelope::ReferenceExit> = plan
            .references
            .iter()
            .enumerate()
            .map(|(i, r)| envelope.reference_exit(i, r, p.sample_period * p.airspeed))
            .filter(|e| e.first.is_some())
            .collect();
        let first = exits
            .iter()
            .filter_map(|e| e.first)
            .min_by(|a, b| a.time.total_cmp(&b.time));
        let worst = exits
            .iter()
            .filter_map(|e| e.worst)
            .max_by(|a, b| a.excess().total_cmp(&b.excess()));
        if let (Some(first), Some(worst)) = (first, worst) {
            let furthest = if worst == first {
                String::new()
            } else {
                format!("; furthest, {}", worst.describe())
            };
            out.push(Diagnostic::error(
                at("aircraft"),
                format!(
                    "{} of the {} aircraft leave the bounds the export judges: first, {}{furthest}",
                    exits.len(),
                    p.aircraft,
                    first.describe()
                ),
            ));
        }
    }
    out
}
