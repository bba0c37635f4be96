//! What a squadron must stay within to be flyable and where it was sent:
//! each aircraft's airspeed range and bank limit, and the mission's x-y
//! bounds and altitude band (above the ground, as the export judges them).
//! Verification judges the flight against it; `check` predicts it from the
//! references before a run (`flatlo::diagnostics`).

use nalgebra::Point3;
use serde::Serialize;

use super::Reference;
use super::maneuver::Primitive;
use crate::base::terrain::Ground;
use crate::mission::{Bounds, Mission};

/// A limit an aircraft (or its reference) broke.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Check {
    /// Below `airspeed_range[0]`.
    AirspeedLow,
    /// Above `airspeed_range[1]`.
    AirspeedHigh,
    /// |μ| beyond `max_bank_deg`.
    Bank,
    /// x below `bounds.x[0]` (`Low`) or above `bounds.x[1]`.
    XLow,
    XHigh,
    YLow,
    YHigh,
    /// Height above the ground below `bounds.z[0]` or above `bounds.z[1]`.
    BelowBand,
    AboveBand,
}

/// The first limit an aircraft broke: which, when, the figure and the limit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Violation {
    /// 0-based.
    pub aircraft: usize,
    pub check: Check,
    /// Seconds from the start.
    pub time: f64,
    /// The figure: m/s, degrees, or metres (the coordinate or the height).
    pub value: f64,
    /// The limit it broke, in the same unit.
    pub limit: f64,
    /// The reference broke it (the plan), not the flown aircraft.
    pub reference: bool,
}

impl Violation {
    /// In words, aircraft from 1: `aircraft 4 flew 13.52 m/s at t = 12.3 s,
    /// below airspeed_range[0] = 13.7 m/s`.
    pub fn describe(&self) -> String {
        let who = if self.reference {
            format!("aircraft {}'s reference", self.aircraft + 1)
        } else {
            format!("aircraft {}", self.aircraft + 1)
        };
        let at = format!("at t = {:.1} s", self.time);
        let (value, limit) = (self.value, self.limit);
        let beyond = (value - limit).abs();
        match self.check {
            Check::AirspeedLow => {
                format!("{who} flew {value:.2} m/s {at}, below airspeed_range[0] = {limit} m/s")
            }
            Check::AirspeedHigh => {
                format!("{who} flew {value:.2} m/s {at}, above airspeed_range[1] = {limit} m/s")
            }
            Check::Bank => {
                format!("{who} banked {value:.1}° {at}, beyond max_bank_deg = {limit}°")
            }
            Check::XLow | Check::XHigh | Check::YLow | Check::YHigh => {
                let (axis, end) = match self.check {
                    Check::XLow => ("x", 0),
                    Check::XHigh => ("x", 1),
                    Check::YLow => ("y", 0),
                    _ => ("y", 1),
                };
                format!(
                    "{who} is at {axis} = {value:.0} m {at}, {beyond:.0} m outside \
                     bounds.{axis}[{end}] = {limit} m"
                )
            }
            Check::BelowBand => format!(
                "{who} is {value:.0} m above the ground {at}, {beyond:.0} m below \
                 bounds.z[0] = {limit} m"
            ),
            Check::AboveBand => format!(
                "{who} is {value:.0} m above the ground {at}, {beyond:.0} m above \
                 bounds.z[1] = {limit} m"
            ),
        }
    }

    /// Metres (or m/s, degrees) beyond its limit.
    pub fn excess(&self) -> f64 {
        (self.value - self.limit).abs()
    }
}

/// The limits of one mission's squadron.
#[derive(Debug, Clone)]
pub struct Envelope {
    bounds: Bounds,
    ground: Option<Ground>,
    /// [min, max] m/s.
    pub airspeed: [f64; 2],
    /// Radians.
    pub max_bank: f64,
}

/// Arcs are checked at this many points (and their ends): a 45° turn of
/// 4,575 m radius between two points bulges by 0.3 m at most.
const ARC_POINTS: usize = 32;

impl Envelope {
    pub fn of(mission: &Mission) -> Self {
        let p = &mission.flatlo;
        Envelope {
            bounds: mission.bounds.clone(),
            ground: mission.ground_model(),
            airspeed: p.airspeed_range,
            max_bank: p.max_bank_deg.to_radians(),
        }
    }

    /// The airspeed `v` (m/s) if outside the range: (check, limit).
    pub fn airspeed_outside(&self, v: f64) -> Option<(Check, f64)> {
        let [lo, hi] = self.airspeed;
        if v < lo {
            Some((Check::AirspeedLow, lo))
        } else if v > hi {
            Some((Check::AirspeedHigh, hi))
        } else {
            None
        }
    }

    /// The height of `p` above the ground under it, metres.
    fn height(&self, p: &Point3<f64>) -> f64 {
        p.z - self.ground.as_ref().map_or(0.0, |g| g.at(p.x, p.y))
    }

    /// The least distance of `p` inside the x-y bounds and the altitude
    /// band, metres (negative outside).
    pub fn margin(&self, p: &Point3<f64>) -> f64 {
        let h = self.height(p);
        let b = &self.bounds;
        b.horizontal_margin(p).min(h - b.z[0]).min(b.z[1] - h)
    }

    /// The bound `p` is furthest beyond, if any: (check, value, limit).
    pub fn outside(&self, p: &Point3<f64>) -> Option<(Check, f64, f64)> {
        let b = &self.bounds;
        let h = self.height(p);
        [
            (Check::XLow, p.x, b.x[0], b.x[0] - p.x),
            (Check::XHigh, p.x, b.x[1], p.x - b.x[1]),
            (Check::YLow, p.y, b.y[0], b.y[0] - p.y),
            (Check::YHigh, p.y, b.y[1], p.y - b.y[1]),
            (Check::BelowBand, h, b.z[0], b.z[0] - h),
            (Check::AboveBand, h, b.z[1], h - b.z[1]),
        ]
        .into_iter()
        .filter(|c| c.3 > 0.0)
        .max_by(|a, b| a.3.total_cmp(&b.3))
        .map(|(check, value, limit, _)| (check, value, limit))
    }

    /// Where aircraft `aircraft`'s reference leaves the bounds or the band:
    /// the first point outside (when) and the one furthest outside (how
    /// far), with the least margin of the whole reference. Each straight leg
    /// is judged at its ends (bounds and band are convex) unless the ground
    /// varies under it; each arc at [`ARC_POINTS`]; a primitive with a point
    /// outside is walked every `spacing` metres for the time it leaves.
    pub fn reference_exit(
        &self,
        aircraft: usize,
        reference: &Reference,
        spacing: f64,
    ) -> ReferenceExit {
        let path = &reference.path;
        let mut exit = ReferenceExit {
            first: None,
            worst: None,
            margin: f64::INFINITY,
        };
        let spacing = spacing.max(1.0);
        for (k, primitive) in path.primitives.iter().enumerate() {
            let start = path.starts[k];
            let length = primitive.length();
            let coarse = match primitive {
                Primitive::Forward { .. } if self.ground.is_none() => 1,
                Primitive::Forward { .. } => (length / spacing).ceil().max(1.0) as usize,
                Primitive::Turn { .. } => ARC_POINTS,
            };
            let mut any_outside = false;
            for i in 0..=coarse {
                let p = primitive.at(length * i as f64 / coarse as f64).position;
                exit.margin = exit.margin.min(self.margin(&p));
                any_outside |= self.outside(&p).is_some();
            }
            if !any_outside {
                continue;
            }
            let fine = (length / spacing).ceil().max(1.0) as usize;
            for i in 0..=fine {
                let s = length * i as f64 / fine as f64;
                let p = primitive.at(s).position;
                let Some((check, value, limit)) = self.outside(&p) else {
                    continue;
                };
                let v = Violation {
                    aircraft,
                    check,
                    time: reference.time_at(start + s),
                    value,
                    limit,
                    reference: true,
                };
                if exit.first.is_none() {
                    exit.first = Some(v);
                }
                if exit.worst.is_none_or(|w| v.excess() > w.excess()) {
                    exit.worst = Some(v);
                }
            }
        }
        exit
    }
}

/// Where a reference leaves the bounds: first and furthest, and the least
/// margin inside them over the whole reference (negative: it leaves).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceExit {
    pub first: Option<Violation>,
    pub worst: Option<Violation>,
    pub margin: f64,
}
