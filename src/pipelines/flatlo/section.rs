//! `[flatlo]` as a unit of the mission: its rules (the squadron, its aircraft
//! and its controller), registered with the file's (`mission::SECTION_RULES`),
//! and its start, which a file may write as latitude/longitude
//! (`mission::geodetic::SECTION_POSITIONS`). The mission's floor runs and
//! converts them whenever a mission is read, naming no pipeline.

use crate::mission::geodetic::{Position, SECTION_POSITIONS, SectionPositions, Slot, Step};
use crate::mission::{Checker, FieldPath, FlatloParams, SECTION_RULES, SectionRules, compact};
use crate::pipelines::rows::{Row, count, num, number, put, text};

#[linkme::distributed_slice(SECTION_RULES)]
static RULES: SectionRules = SectionRules {
    key: "flatlo",
    check: |c, path, mission| c.flatlo(path, &mission.flatlo),
};

#[linkme::distributed_slice(SECTION_POSITIONS)]
static POSITIONS: SectionPositions = SectionPositions {
    slots: &[Slot {
        steps: &[Step::Key("flatlo"), Step::Key("start")],
        air: false,
    }],
    positions: |m| {
        let start = FieldPath::root().key("flatlo").key("start");
        vec![(start, Position::Ground(m.flatlo.start))]
    },
};

/// The inspector's rows of `[flatlo]`, the squadron and its aircraft model:
/// every key (`Pipeline::rows`).
#[rustfmt::skip]
pub(super) static ROWS: &[Row] = &[
    Row { name: "aircraft N", unit: "", keys: &["aircraft"], get: |m| text(m.flatlo.aircraft), set: |m, t| put(&mut m.flatlo.aircraft, count(t)) },
    Row { name: "spacing Δd", unit: "m", keys: &["spacing"], get: |m| num(m.flatlo.spacing), set: |m, t| put(&mut m.flatlo.spacing, number(t)) },
    Row { name: "airspeed", unit: "m/s", keys: &["airspeed"], get: |m| num(m.flatlo.airspeed), set: |m, t| put(&mut m.flatlo.airspeed, number(t)) },
    Row { name: "turn radius r", unit: "m", keys: &["turn_radius"], get: |m| num(m.flatlo.turn_radius), set: |m, t| put(&mut m.flatlo.turn_radius, number(t)) },
    Row { name: "heading φ", unit: "°", keys: &["heading_deg"], get: |m| num(m.flatlo.heading_deg), set: |m, t| put(&mut m.flatlo.heading_deg, number(t)) },
    Row { name: "climb β", unit: "°", keys: &["climb_deg"], get: |m| num(m.flatlo.climb_deg), set: |m, t| put(&mut m.flatlo.climb_deg, number(t)) },
    Row { name: "altitude", unit: "m", keys: &["altitude"], get: |m| num(m.flatlo.altitude), set: |m, t| put(&mut m.flatlo.altitude, number(t)) },
    Row { name: "start x", unit: "m", keys: &["start"], get: |m| num(m.flatlo.start.x), set: |m, t| put(&mut m.flatlo.start.x, number(t)) },
    Row { name: "start y", unit: "m", keys: &["start"], get: |m| num(m.flatlo.start.y), set: |m, t| put(&mut m.flatlo.start.y, number(t)) },
    Row { name: "final leg K2", unit: "m", keys: &["final_leg"], get: |m| num(m.flatlo.final_leg), set: |m, t| put(&mut m.flatlo.final_leg, number(t)) },
    Row { name: "noise σ", unit: "", keys: &["noise"], get: |m| num(m.flatlo.noise), set: |m, t| put(&mut m.flatlo.noise, number(t)) },
    Row { name: "min separation", unit: "m", keys: &["min_separation"], get: |m| num(m.flatlo.min_separation), set: |m, t| put(&mut m.flatlo.min_separation, number(t)) },
    Row { name: "sample period T", unit: "s", keys: &["sample_period"], get: |m| num(m.flatlo.sample_period), set: |m, t| put(&mut m.flatlo.sample_period, number(t)) },
    Row { name: "RK4 step", unit: "s", keys: &["sim_step"], get: |m| num(m.flatlo.sim_step), set: |m, t| put(&mut m.flatlo.sim_step, number(t)) },
    Row { name: "mass", unit: "kg", keys: &["mass"], get: |m| num(m.flatlo.mass), set: |m, t| put(&mut m.flatlo.mass, number(t)) },
    Row { name: "wing area", unit: "m²", keys: &["wing_area"], get: |m| num(m.flatlo.wing_area), set: |m, t| put(&mut m.flatlo.wing_area, number(t)) },
    Row { name: "air density", unit: "kg/m³", keys: &["air_density"], get: |m| num(m.flatlo.air_density), set: |m, t| put(&mut m.flatlo.air_density, number(t)) },
    Row { name: "drag C_D0", unit: "", keys: &["drag_cd0"], get: |m| num(m.flatlo.drag_cd0), set: |m, t| put(&mut m.flatlo.drag_cd0, number(t)) },
    Row { name: "drag k", unit: "", keys: &["drag_k"], get: |m| num(m.flatlo.drag_k), set: |m, t| put(&mut m.flatlo.drag_k, number(t)) },
    Row { name: "max thrust", unit: "N", keys: &["max_thrust"], get: |m| num(m.flatlo.max_thrust), set: |m, t| put(&mut m.flatlo.max_thrust, number(t)) },
    Row { name: "load factor min", unit: "", keys: &["load_factor"], get: |m| num(m.flatlo.load_factor[0]), set: |m, t| put(&mut m.flatlo.load_factor[0], number(t)) },
    Row { name: "load factor max", unit: "", keys: &["load_factor"], get: |m| num(m.flatlo.load_factor[1]), set: |m, t| put(&mut m.flatlo.load_factor[1], number(t)) },
    Row { name: "max bank", unit: "°", keys: &["max_bank_deg"], get: |m| num(m.flatlo.max_bank_deg), set: |m, t| put(&mut m.flatlo.max_bank_deg, number(t)) },
    Row { name: "airspeed min", unit: "m/s", keys: &["airspeed_range"], get: |m| num(m.flatlo.airspeed_range[0]), set: |m, t| put(&mut m.flatlo.airspeed_range[0], number(t)) },
    Row { name: "airspeed max", unit: "m/s", keys: &["airspeed_range"], get: |m| num(m.flatlo.airspeed_range[1]), set: |m, t| put(&mut m.flatlo.airspeed_range[1], number(t)) },
    Row { name: "PID kp", unit: "", keys: &["pid"], get: |m| num(m.flatlo.pid[0]), set: |m, t| put(&mut m.flatlo.pid[0], number(t)) },
    Row { name: "PID ki", unit: "", keys: &["pid"], get: |m| num(m.flatlo.pid[1]), set: |m, t| put(&mut m.flatlo.pid[1], number(t)) },
    Row { name: "PID kd", unit: "", keys: &["pid"], get: |m| num(m.flatlo.pid[2]), set: |m, t| put(&mut m.flatlo.pid[2], number(t)) },
];

impl Checker {
    fn flatlo(&mut self, path: &FieldPath, p: &FlatloParams) {
        if p.aircraft < 2 {
            self.error(
                path.key("aircraft"),
                format!(
                    "a squadron transition needs at least 2 aircraft, got {}",
                    p.aircraft
                ),
            );
        }
        for (key, value, unit) in [
            ("spacing", p.spacing, " m"),
            ("airspeed", p.airspeed, " m/s"),
            ("turn_radius", p.turn_radius, " m"),
            ("altitude", p.altitude, " m"),
            ("final_leg", p.final_leg, " m"),
            ("sample_period", p.sample_period, " s"),
            ("sim_step", p.sim_step, " s"),
            ("mass", p.mass, " kg"),
            ("wing_area", p.wing_area, " m²"),
            ("air_density", p.air_density, " kg/m³"),
            ("max_thrust", p.max_thrust, " N"),
            ("max_bank_deg", p.max_bank_deg, "°"),
        ] {
            self.positive(path.key(key), value, unit);
        }
        for (key, value) in [
            ("drag_cd0", p.drag_cd0),
            ("drag_k", p.drag_k),
            ("noise", p.noise),
            ("min_separation", p.min_separation),
        ] {
            self.non_negative(path.key(key), value, "");
        }
        for (i, gain) in p.pid.iter().enumerate() {
            self.non_negative(path.key("pid").index(i), *gain, "");
        }
        if self.range(path.key("load_factor"), p.load_factor, "") && p.load_factor[1] <= 1.0 {
            self.error(
                path.key("load_factor"),
                format!(
                    "n_max = {} cannot hold level flight (needs n > 1 to turn)",
                    p.load_factor[1]
                ),
            );
        }
        let speeds = path.key("airspeed_range");
        for (i, v) in p.airspeed_range.iter().enumerate() {
            self.positive(speeds.index(i), *v, " m/s");
        }
        if self.range(speeds.clone(), p.airspeed_range, " m/s") {
            let [lo, hi] = p.airspeed_range;
            if p.airspeed.is_finite() && !(lo..=hi).contains(&p.airspeed) {
                self.error(
                    path.key("airspeed"),
                    format!(
                        "the nominal airspeed {} m/s is outside airspeed_range [{}, {}] m/s \
                         (every aircraft flies it after the transition)",
                        compact(p.airspeed),
                        compact(lo),
                        compact(hi)
                    ),
                );
            }
        }
        if p.max_bank_deg >= 90.0 {
            self.error(
                path.key("max_bank_deg"),
                format!("must be below 90°, got {}°", p.max_bank_deg),
            );
        }
        if p.climb_deg.abs() >= 90.0 {
            self.error(
                path.key("climb_deg"),
                format!("must be within ±90°, got {}°", p.climb_deg),
            );
        }
        if p.sim_step > p.sample_period {
            self.warning(
                path.key("sim_step"),
                format!(
                    "the RK4 step {} s is longer than the reference period {} s",
                    p.sim_step, p.sample_period
                ),
            );
        }
        // Algorithm 1, line 41: Δ2 = √2 (Δ − 2r(1 − cos π/4)) must not be
        // negative for the smallest lateral offset Δ that is not zero.
        let smallest_offset = if p.aircraft.is_multiple_of(2) {
            p.spacing / 2.0
        } else {
            p.spacing
        };
        let needed = 2.0 * p.turn_radius * (1.0 - std::f64::consts::FRAC_PI_4.cos());
        if smallest_offset < needed {
            self.error(
                path.key("turn_radius"),
                format!(
                    "a turn radius of {} m needs a lateral offset of at least {needed:.1} m \
                     (Algorithm 1, line 41), but the innermost aircraft is {smallest_offset} m \
                     from the longitudinal line",
                    p.turn_radius
                ),
            );
        }
        if p.noise > 0.05 {
            self.warning(
                path.key("noise"),
                format!(
                    "{} % noise is far above the paper's 0.25 %",
                    p.noise * 100.0
                ),
            );
        }
        self.flatlo_physical(path, p);
    }

    /// Physically absurd values (`mission::physical`): errors that say why.
    fn flatlo_physical(&mut self, path: &FieldPath, p: &FlatloParams) {
        use crate::mission::physical::{CEILING, SPAN, SPEED};
        self.at_most(
            path.key("airspeed"),
            p.airspeed,
            SPEED,
            " m/s",
            "faster than sound",
        );
        for (key, value) in [
            ("spacing", p.spacing),
            ("turn_radius", p.turn_radius),
            ("final_leg", p.final_leg),
        ] {
            self.at_most(
                path.key(key),
                value,
                SPAN,
                " m",
                "the ENU frame is a local plane and no squadron spans more",
            );
        }
        self.at_most(
            path.key("altitude"),
            p.altitude,
            CEILING,
            " m",
            "far above any aircraft's ceiling",
        );
    }
}
