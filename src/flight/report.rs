//! What a flight check says: the verdict first (the share of flights that
//! break 2 r_Q and r_Q, with their 95 % intervals), the worst flight named,
//! then the tightest pairs and obstacles as percentiles over the flights,
//! and each vehicle's cross-track error.

use serde::Serialize;

use super::{Flown, Options, Setup, vehicle_pairs};
use crate::mission::Turbulence;

/// Lines of pairs and of obstacles the text lists (the tightest); the
/// JSON holds them all.
const LISTED: usize = 5;

/// A share of flights with its Wilson 95 % interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Share {
    pub count: usize,
    pub of: usize,
    pub share: f64,
    pub low: f64,
    pub high: f64,
}

/// The Wilson score interval at 95 % (z = 1.96) for `count` of `of`:
/// sound at a count of 0 (its high end is then about 3.8 / n).
pub fn wilson(count: usize, of: usize) -> Share {
    let n = of.max(1) as f64;
    let p = count as f64 / n;
    let z: f64 = 1.959_963_984_540_054;
    let z2 = z * z;
    let centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
    let half = z / (1.0 + z2 / n) * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    Share {
        count,
        of,
        share: p,
        low: (centre - half).max(0.0),
        high: (centre + half).min(1.0),
    }
}

/// A distance's spread over the flights, metres: the median, the 5th and
/// 1st percentiles (the low tail is what matters), and the least, with the
/// flight and time it came in.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    pub p50: f64,
    pub p5: f64,
    pub p1: f64,
    pub worst: f64,
    pub worst_flight: usize,
    pub worst_t: f64,
    /// The same figure for the plan as its files fly it (ideal vehicle).
    pub as_written: f64,
}

/// The q-quantile of sorted values (nearest rank).
pub(super) fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = (q * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

fn spread(values: &[(f64, usize, f64)], as_written: f64) -> Spread {
    let mut sorted: Vec<f64> = values.iter().map(|v| v.0).collect();
    sorted.sort_by(f64::total_cmp);
    let worst = values
        .iter()
        .copied()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or((f64::NAN, 0, 0.0));
    Spread {
        p50: quantile(&sorted, 0.5),
        p5: quantile(&sorted, 0.05),
        p1: quantile(&sorted, 0.01),
        worst: worst.0,
        worst_flight: worst.1,
        worst_t: worst.2,
        as_written,
    }
}

/// One pair's closest approach over the flights.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairSpread {
    /// Vehicles, 1-based.
    pub a: usize,
    pub b: usize,
    pub closest: Spread,
}

/// One vehicle's clearance to one obstacle over the flights.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObstacleSpread {
    pub vehicle: usize,
    pub obstacle: String,
    pub clearance: Spread,
}

/// Eq. 8 on one inspected obstacle over the flights: the longest stretch
/// flown within its band, and the share of flights that still inspect it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InspectionSpread {
    pub obstacle: String,
    /// The band [d_min, d_max] from the surface and the pass asked, metres.
    pub band: [f64; 2],
    pub required: f64,
    /// Flights whose stretch was at least `required`.
    pub inspected: Share,
    pub p50: f64,
    pub p5: f64,
    pub as_written: f64,
}

/// One vehicle's largest cross-track error per flight, over the flights.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrossTrack {
    pub vehicle: usize,
    pub p50: f64,
    pub p99: f64,
    pub max: f64,
}

/// The flight that came nearest to breaking (or furthest past) a limit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Worst {
    pub flight: usize,
    /// The vehicle (1-based; of a pair, the first).
    pub vehicle: usize,
    /// Metres left to the limit (negative: broken by that much).
    pub margin: f64,
    pub what: String,
    pub t: f64,
}

/// A flight check's report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    pub mission: String,
    pub pipeline: &'static str,
    pub seed: u64,
    pub flights: usize,
    /// r_Q and 2 r_Q, metres.
    pub clearance_limit: f64,
    pub separation_limit: f64,
    /// Flights in which some pair came closer than 2 r_Q.
    pub break_separation: Share,
    /// Flights in which some vehicle came closer than r_Q to an obstacle.
    pub break_clearance: Share,
    /// Flights that broke either.
    pub break_any: Share,
    /// Flights in which a vehicle had not reached its last waypoint by the
    /// horizon (1.5 × the plan's duration + 30 s).
    pub unfinished: usize,
    pub worst: Option<Worst>,
    pub pairs: Vec<PairSpread>,
    pub obstacles: Vec<ObstacleSpread>,
    pub cross_track: Vec<CrossTrack>,
    /// Eq. 8 on each inspected obstacle.
    pub inspections: Vec<InspectionSpread>,
    /// The conditions, in words.
    pub conditions: String,
}

impl Report {
    pub fn new(setup: &Setup, options: Options, flown: &[Flown], ideal: &Flown) -> Report {
        let n = setup.plans.len();
        let vehicle = |v: usize| setup.plans[v].vehicle + 1;
        let mut pairs: Vec<PairSpread> = vehicle_pairs(n)
            .enumerate()
            .map(|(k, (i, j))| {
                let values: Vec<(f64, usize, f64)> = flown
                    .iter()
                    .map(|f| (f.pairs[k].distance, f.flight, f.pairs[k].t))
                    .collect();
                PairSpread {
                    a: vehicle(i),
                    b: vehicle(j),
                    closest: spread(&values, ideal.pairs[k].distance),
                }
            })
            .collect();
        let mut obstacles = Vec::new();
        for (v, near) in setup.near.iter().enumerate() {
            for (slot, &o) in near.iter().enumerate() {
                let values: Vec<(f64, usize, f64)> = flown
                    .iter()
                    .map(|f| {
                        (
                            f.obstacles[v][slot].distance,
                            f.flight,
                            f.obstacles[v][slot].t,
                        )
                    })
                    .collect();
                obstacles.push(ObstacleSpread {
                    vehicle: vehicle(v),
                    obstacle: setup.mission.obstacles[o].name.clone(),
                    clearance: spread(&values, ideal.obstacles[v][slot].distance),
                });
            }
        }
        pairs.sort_by(|a, b| a.closest.p1.total_cmp(&b.closest.p1));
        obstacles.sort_by(|a, b| a.clearance.p1.total_cmp(&b.clearance.p1));
        let cross_track = (0..n)
            .map(|v| {
                let mut e: Vec<f64> = flown.iter().map(|f| f.cross_track[v]).collect();
                e.sort_by(f64::total_cmp);
                CrossTrack {
                    vehicle: vehicle(v),
                    p50: quantile(&e, 0.5),
                    p99: quantile(&e, 0.99),
                    max: e.last().copied().unwrap_or(f64::NAN),
                }
            })
            .collect();
        let broke_separation = flown.iter().filter(|f| f.broke_separation(setup)).count();
        let broke_clearance = flown.iter().filter(|f| f.broke_clearance(setup)).count();
        let broke_any = flown
            .iter()
            .filter(|f| f.broke_separation(setup) || f.broke_clearance(setup))
            .count();
        let inspections = setup
            .inspected
            .iter()
            .enumerate()
            .map(|(k, &(o, band, required))| {
                let mut stretch: Vec<f64> = flown.iter().map(|f| f.inspections[k]).collect();
                stretch.sort_by(f64::total_cmp);
                let kept = stretch.iter().filter(|&&s| s >= required).count();
                InspectionSpread {
                    obstacle: setup.mission.obstacles[o].name.clone(),
                    band,
                    required,
                    inspected: wilson(kept, flown.len()),
                    p50: quantile(&stretch, 0.5),
                    p5: quantile(&stretch, 0.05),
                    as_written: ideal.inspections[k],
                }
            })
            .collect();
        Report {
            inspections,
            mission: setup.mission.name.clone(),
            pipeline: setup.pipeline,
            seed: options.seed,
            flights: flown.len(),
            clearance_limit: setup.clearance,
            separation_limit: setup.closest,
            break_separation: wilson(broke_separation, flown.len()),
            break_clearance: wilson(broke_clearance, flown.len()),
            break_any: wilson(broke_any, flown.len()),
            unfinished: flown.iter().filter(|f| !f.finished).count(),
            worst: worst(setup, flown),
            pairs,
            obstacles,
            cross_track,
            conditions: conditions(setup),
        }
    }

    /// The report for people: the verdict on the first line after the
    /// heading, then the worst flight, then the tightest pairs and
    /// obstacles, then cross-track errors.
    pub fn text(&self, verbose: bool) -> String {
        let pct = |s: &Share| {
            format!(
                "{:.1} % (95 % CI {:.1}-{:.1} %)",
                100.0 * s.share,
                100.0 * s.low,
                100.0 * s.high
            )
        };
        let mut out = format!(
            "flight check of the {} plan for \"{}\" (seed {}): {} flights\n",
            self.pipeline, self.mission, self.seed, self.flights
        );
        let verdict = if self.break_separation.count == 0 && self.break_clearance.count == 0 {
            "KEPT"
        } else {
            "BROKEN"
        };
        out += &format!(
            "  result       {verdict}: {} of flights break 2 r_Q = {:.2} m, {} break r_Q = {:.2} m\n",
            pct(&self.break_separation),
            self.separation_limit,
            pct(&self.break_clearance),
            self.clearance_limit
        );
        if let Some(w) = &self.worst {
            out += &format!(
                "  worst        flight {}: {} at t = {:.1} s, {:.2} m {} the limit (replay: --flight {})\n",
                w.flight,
                w.what,
                w.t,
                w.margin.abs(),
                if w.margin < 0.0 { "past" } else { "inside" },
                w.flight
            );
        }
        if self.unfinished > 0 {
            out += &format!(
                "  unfinished   {} flight(s) had a vehicle short of its last waypoint at the horizon\n",
                self.unfinished
            );
        }
        out += &format!("  conditions   {}\n", self.conditions);
        let listed = if verbose { usize::MAX } else { LISTED };
        let row = |s: &Spread| {
            format!(
                "p50 {:.2}, p5 {:.2}, p1 {:.2}, worst {:.2} m (flight {}, t = {:.1} s); as written {:.2} m",
                s.p50, s.p5, s.p1, s.worst, s.worst_flight, s.worst_t, s.as_written
            )
        };
        for (i, p) in self.pairs.iter().take(listed).enumerate() {
            let label = if i == 0 { "pairs" } else { "" };
            out += &format!(
                "  {label:<12} UAV {} - UAV {}: {}\n",
                p.a,
                p.b,
                row(&p.closest)
            );
        }
        if self.pairs.len() > listed {
            out += &format!(
                "  {:<12} … {} more pairs (--verbose, --json)\n",
                "",
                self.pairs.len() - listed
            );
        }
        for (i, o) in self.obstacles.iter().take(listed).enumerate() {
            let label = if i == 0 { "obstacles" } else { "" };
            out += &format!(
                "  {label:<12} UAV {} - '{}': {}\n",
                o.vehicle,
                o.obstacle,
                row(&o.clearance)
            );
        }
        if self.obstacles.len() > listed {
            out += &format!(
                "  {:<12} … {} more (--verbose, --json)\n",
                "",
                self.obstacles.len() - listed
            );
        }
        for (i, s) in self.inspections.iter().enumerate() {
            let label = if i == 0 { "inspections" } else { "" };
            out += &format!(
                "  {label:<12} '{}': within [{}, {}] m for p50 {:.1} m, p5 {:.1} m (≥ {} m in {:.1} % of flights, \
                 95 % CI {:.1}-{:.1} %); as written {:.1} m\n",
                s.obstacle,
                s.band[0],
                s.band[1],
                s.p50,
                s.p5,
                s.required,
                100.0 * s.inspected.share,
                100.0 * s.inspected.low,
                100.0 * s.inspected.high,
                s.as_written
            );
        }
        let tracks: Vec<String> = self
            .cross_track
            .iter()
            .map(|c| {
                format!(
                    "UAV {} p50 {:.2} / p99 {:.2} / max {:.2} m",
                    c.vehicle, c.p50, c.p99, c.max
                )
            })
            .collect();
        out += &format!("  cross-track  {}\n", tracks.join("; "));
        out
    }
}

/// The flight with the least room to a limit: a pair's distance over
/// 2 r_Q, or a vehicle's clearance over r_Q, the smaller.
fn worst(setup: &Setup, flown: &[Flown]) -> Option<Worst> {
    let n = setup.plans.len();
    let vehicle = |v: usize| setup.plans[v].vehicle + 1;
    let mut best: Option<Worst> = None;
    let mut consider = |w: Worst| {
        if best.as_ref().is_none_or(|b| w.margin < b.margin) {
            best = Some(w);
        }
    };
    for f in flown {
        for ((i, j), c) in vehicle_pairs(n).zip(&f.pairs) {
            consider(Worst {
                flight: f.flight,
                vehicle: vehicle(i),
                margin: c.distance - setup.closest,
                what: format!(
                    "UAV {} and UAV {} {:.2} m apart",
                    vehicle(i),
                    vehicle(j),
                    c.distance
                ),
                t: c.t,
            });
        }
        for (v, near) in setup.near.iter().enumerate() {
            for (slot, &o) in near.iter().enumerate() {
                let c = f.obstacles[v][slot];
                consider(Worst {
                    flight: f.flight,
                    vehicle: vehicle(v),
                    margin: c.distance - setup.clearance,
                    what: if c.distance < 0.0 {
                        format!(
                            "UAV {} {:.2} m inside '{}'",
                            vehicle(v),
                            -c.distance,
                            setup.mission.obstacles[o].name
                        )
                    } else {
                        format!(
                            "UAV {} {:.2} m from '{}'",
                            vehicle(v),
                            c.distance,
                            setup.mission.obstacles[o].name
                        )
                    },
                    t: c.t,
                });
            }
        }
    }
    best
}

/// The air and the autopilot in one line.
fn conditions(setup: &Setup) -> String {
    let p = &setup.mission.flight;
    let v = &setup.mission.vehicle;
    let turbulence = match p.turbulence {
        Turbulence::None => "no turbulence".to_owned(),
        t => {
            let s = super::air::dryden_scales(10.0, t.wind_at_20_ft());
            format!(
                "{} turbulence (Dryden, MIL-F-8785C; at 10 m σ_u {:.2} m/s, L_u {:.0} m)",
                format!("{t:?}").to_lowercase(),
                s.sigma_uv,
                s.length_uv
            )
        }
    };
    format!(
        "wind {:.1} m/s from {:.0}°, {turbulence}; GNSS σ {:.2} m horizontal, {:.2} m vertical, \
         τ {:.0} s; take-off skew σ {:.2} s; acceptance radius {:.1} m (written in the files); \
         autopilot gains: position {:.2} /s xy, {:.2} /s z, velocity {:.2} /s xy, {:.2} /s z, \
         velocity integral {:.2} /s² xy, {:.2} /s² z ([vehicle], PX4's MPC_* by default), drag \
         {:.2} /s; step {} s",
        p.wind_speed,
        p.wind_from_deg,
        p.gnss_sigma_horizontal,
        p.gnss_sigma_vertical,
        p.gnss_correlation_time,
        p.takeoff_skew,
        p.acceptance_radius,
        v.position_gain_xy,
        v.position_gain_z,
        v.velocity_gain_xy,
        v.velocity_gain_z,
        v.velocity_integral_xy,
        v.velocity_integral_z,
        p.drag,
        p.step
    )
}
