//! How an autopilot flies one leg of a waypoint file, and the speed each
//! leg is written with.
//!
//! A multicopter reads `DO_CHANGE_SPEED` with speed type 1 as its
//! horizontal (ground) speed: PX4's position smoothing flies along the line
//! to the next waypoint with the horizontal speed at most the commanded one
//! and the vertical speed at most its climb or descent limit, whichever
//! binds; beyond `[vehicle].max_speed` it flies at that limit. So a leg of
//! horizontal length h and height change dz takes
//! `max(h / min(v, v_max), dz / climb, −dz / descent)`. A fixed wing flies
//! the leg's whole length at the commanded airspeed (in still air).
//!
//! Speeds and holds are rounded to [`SPEED_STEP`] and [`HOLD_STEP`]; a
//! multicopter leg slower than [`MIN_SPEED`] becomes a hold at its start,
//! then that speed.

use nalgebra::Point3;
use serde::Serialize;

use crate::mission::VehicleLimits;

/// Slowest commanded speed of a multicopter leg, m/s; a vehicle that must
/// go slower waits at the leg's start instead.
pub const MIN_SPEED: f64 = 0.1;

/// Holds are written to this step, seconds (PX4 reads param1 as a float;
/// ArduCopter keeps whole seconds).
pub const HOLD_STEP: f64 = 0.01;

/// Commanded speeds are written to this step, m/s.
pub const SPEED_STEP: f64 = 0.01;

/// What one vehicle's autopilot lets a leg fly (m/s; `None`: no limit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LegLimits {
    /// Fixed wing: the written speed is an airspeed along the leg.
    pub fixed_wing: bool,
    /// Multicopters: the largest horizontal speed; fixed wing: the
    /// largest airspeed.
    pub speed: Option<f64>,
    /// Fixed wing: the smallest airspeed.
    pub min_speed: Option<f64>,
    /// Multicopters: the largest climb and descent rates.
    pub climb: Option<f64>,
    pub descent: Option<f64>,
}

impl LegLimits {
    /// A multicopter under `[vehicle]`.
    pub fn multicopter(v: VehicleLimits) -> Self {
        LegLimits {
            fixed_wing: false,
            speed: Some(v.speed),
            min_speed: None,
            climb: Some(v.climb),
            descent: Some(v.descent),
        }
    }

    /// A fixed wing within an airspeed range [min, max] (m/s), when the
    /// mission gives one.
    pub fn fixed_wing(airspeed: Option<[f64; 2]>) -> Self {
        LegLimits {
            fixed_wing: true,
            speed: airspeed.map(|r| r[1]),
            min_speed: airspeed.map(|r| r[0]),
            climb: None,
            descent: None,
        }
    }

    /// The name of the written speed, as the reports say it.
    pub fn speed_name(&self) -> &'static str {
        if self.fixed_wing {
            "commanded airspeed"
        } else {
            "commanded ground speed"
        }
    }

    /// Seconds the autopilot takes from `a` to `b` at the written `speed`.
    pub fn duration(&self, a: &Point3<f64>, b: &Point3<f64>, speed: f64) -> f64 {
        let d = b - a;
        if self.fixed_wing {
            let v = clamp(speed, self.min_speed, self.speed);
            return if v > 0.0 { d.norm() / v } else { 0.0 };
        }
        let h = d.xy().norm();
        let v = self.speed.map_or(speed, |max| speed.min(max));
        let horizontal = if v > 0.0 { h / v } else { 0.0 };
        let vertical = match (d.z >= 0.0, self.climb, self.descent) {
            (true, Some(up), _) if up > 0.0 => d.z / up,
            (false, _, Some(down)) if down > 0.0 => -d.z / down,
            _ => 0.0,
        };
        horizontal.max(vertical)
    }

    /// The leg's length as its written speed measures it: horizontal for a
    /// multicopter, the whole length for a fixed wing.
    pub fn measured(&self, a: &Point3<f64>, b: &Point3<f64>) -> f64 {
        let d = b - a;
        if self.fixed_wing {
            d.norm()
        } else {
            d.xy().norm()
        }
    }

    /// Hold at `a` (seconds) and the speed to write for the leg a → b that
    /// the plan flies in `planned` seconds and that has `available` seconds
    /// from when the vehicle, flown as written, leaves `a`: the speed that
    /// arrives on time, rounded; a multicopter that would be slower than
    /// [`MIN_SPEED`] (or that stays put, or only climbs) waits first. A
    /// vehicle running late catches up no faster than its limit (or than the
    /// plan's own speed on the leg, when that is above the limit: the
    /// figure the refusal names).
    pub fn command(
        &self,
        a: &Point3<f64>,
        b: &Point3<f64>,
        planned: f64,
        available: f64,
    ) -> (f64, f64) {
        let available = available.max(0.0);
        let length = self.measured(a, b);
        let own = length / planned.max(1e-3);
        let catch_up = |needed: f64| {
            let v = self.speed.map_or(needed, |max| needed.min(max.max(own)));
            round(v, SPEED_STEP).max(SPEED_STEP)
        };
        if self.fixed_wing {
            // A fixed wing cannot wait: the speed that arrives on time.
            return (0.0, catch_up(length / available.max(1e-3)));
        }
        if length > 1e-9 && length / available.max(1e-3) >= MIN_SPEED {
            return (0.0, catch_up(length / available.max(1e-3)));
        }
        let speed = if length > 1e-9 { MIN_SPEED } else { 0.0 };
        let flying = self.duration(a, b, speed.max(MIN_SPEED));
        (round(available - flying, HOLD_STEP).max(0.0), speed)
    }

    /// The vertical rate (m/s, positive up) of the leg a → b flown in
    /// `seconds`.
    pub fn vertical_rate(a: &Point3<f64>, b: &Point3<f64>, seconds: f64) -> f64 {
        if seconds <= 0.0 {
            return 0.0;
        }
        (b.z - a.z) / seconds
    }
}

fn round(v: f64, step: f64) -> f64 {
    (v / step).round() * step
}

fn clamp(v: f64, min: Option<f64>, max: Option<f64>) -> f64 {
    let v = min.map_or(v, |m| v.max(m));
    max.map_or(v, |m| v.min(m))
}
