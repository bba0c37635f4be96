//! The point-mass aircraft of the FLATLO paper (eqs. 1-6, Anderson and
//! Robbins) and the autopilot that makes it follow a reference.
//!
//! State (V, γ, χ, x, y, h): airspeed m/s, flight-path angle and heading rad
//! (heading counter-clockwise from east), position metres ENU. Controls:
//! thrust T (N), load factor n, bank μ (rad). Drag D = q S (C_D0 + k C_L²)
//! with C_L = n W / (q S), q = ρ V² / 2.

use nalgebra::{Point3, Vector3, Vector6};
use serde::Serialize;

use crate::mission::FlatloParams;

/// Standard gravity, m/s².
pub const G: f64 = crate::mission::GRAVITY;

/// Below this airspeed the model's 1/V terms are held (a stalled model is
/// meaningless anyway; the controller never asks for it).
const MIN_AIRSPEED: f64 = 1.0;

pub type State = Vector6<f64>;

/// Indices into [`State`].
pub const V: usize = 0;
pub const GAMMA: usize = 1;
pub const CHI: usize = 2;

/// Thrust N, load factor, bank rad.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Controls {
    pub thrust: f64,
    pub load_factor: f64,
    pub bank: f64,
}

/// Mass, aerodynamics and control limits, from the mission.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Airframe {
    pub mass: f64,
    pub wing_area: f64,
    pub air_density: f64,
    pub cd0: f64,
    pub k: f64,
    pub max_thrust: f64,
    pub load_factor: [f64; 2],
    pub max_bank: f64,
    /// [min, max] airspeed, m/s (`airspeed_range`).
    pub airspeed: [f64; 2],
}

impl Airframe {
    pub fn from_params(p: &FlatloParams) -> Self {
        Airframe {
            mass: p.mass,
            wing_area: p.wing_area,
            air_density: p.air_density,
            cd0: p.drag_cd0,
            k: p.drag_k,
            max_thrust: p.max_thrust,
            load_factor: p.load_factor,
            max_bank: p.max_bank_deg.to_radians(),
            airspeed: p.airspeed_range,
        }
    }

    pub fn weight(&self) -> f64 {
        self.mass * G
    }

    /// D at airspeed v and load factor n, N.
    pub fn drag(&self, v: f64, n: f64) -> f64 {
        let qs = 0.5 * self.air_density * v * v * self.wing_area;
        if qs <= 0.0 {
            return 0.0;
        }
        let cl = n * self.weight() / qs;
        qs * (self.cd0 + self.k * cl * cl)
    }

    /// Eqs. 1-6: the state's time derivative under constant controls.
    pub fn derivative(&self, x: &State, u: &Controls) -> State {
        let v = x[V].max(MIN_AIRSPEED);
        let (gamma, chi) = (x[GAMMA], x[CHI]);
        let (sg, cg) = gamma.sin_cos();
        let (sc, cc) = chi.sin_cos();
        let (sm, cm) = u.bank.sin_cos();
        let drag = self.drag(v, u.load_factor);
        Vector6::new(
            G * ((u.thrust - drag) / self.weight() - sg), // (1)
            G / v * (u.load_factor * cm - cg),            // (2)
            G * u.load_factor * sm / (v * cg.max(1e-6)),  // (3)
            v * cg * cc,                                  // (4)
            v * cg * sc,                                  // (5)
            v * sg,                                       // (6)
        )
    }
}

pub fn position(x: &State) -> Point3<f64> {
    Point3::new(x[3], x[4], x[5])
}

pub fn velocity(x: &State) -> Vector3<f64> {
    let (sg, cg) = x[GAMMA].sin_cos();
    let (sc, cc) = x[CHI].sin_cos();
    Vector3::new(cg * cc, cg * sc, sg) * x[V]
}

/// Where the reference is at an instant: position, velocity, acceleration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Target {
    pub position: Point3<f64>,
    pub velocity: Vector3<f64>,
    pub acceleration: Vector3<f64>,
}

/// Dynamic inversion of eqs. 1-3 behind a PID on the position error with the
/// reference's acceleration fed forward:
/// a = a_ref + kp e + ki ∫e + kd ė, e = p_ref − p; the acceleration is split
/// along the velocity (→ V̇ → T) and across it (→ γ̇, χ̇ → n, μ), then
/// thrust, load factor and bank are saturated. V̇ is held to the airspeed
/// envelope first, as a fixed-wing autopilot's speed protection does
/// (ArduPlane's TECS between AIRSPEED_MIN and AIRSPEED_MAX): an aircraft
/// ahead of its reference slows to the envelope's floor, never below.
#[derive(Debug, Clone, PartialEq)]
pub struct Autopilot {
    pub gains: [f64; 3],
    integral: Vector3<f64>,
}

/// The integral term never asks for more than this, m/s² (anti-windup).
const MAX_INTEGRAL_ACCEL: f64 = 1.0;

/// The airspeed envelope the autopilot keeps, as a share of each limit
/// inside it: the noise (0.25 % of V a step) and the lag of the speed loop
/// stay within this of the limit (the paper's case: 13.86 m/s at the
/// lowest over seeds 0-19, against a floor of 14.11 and a limit of 13.7).
const ENVELOPE_GUARD: f64 = 0.03;

/// Seconds in which the autopilot brings an airspeed outside its envelope
/// back to its edge.
const ENVELOPE_TIME: f64 = 0.5;

impl Autopilot {
    pub fn new(gains: [f64; 3]) -> Self {
        Autopilot {
            gains,
            integral: Vector3::zeros(),
        }
    }

    /// Controls for the next `dt` seconds.
    pub fn command(
        &mut self,
        airframe: &Airframe,
        x: &State,
        target: &Target,
        dt: f64,
    ) -> Controls {
        let [kp, ki, kd] = self.gains;
        let error = target.position - position(x);
        let rate = target.velocity - velocity(x);
        if ki > 0.0 {
            self.integral += error * dt;
            let cap = MAX_INTEGRAL_ACCEL / ki;
            if self.integral.norm() > cap {
                self.integral *= cap / self.integral.norm();
            }
        }
        let a = target.acceleration + error * kp + self.integral * ki + rate * kd;

        let v = x[V].max(MIN_AIRSPEED);
        let (sg, cg) = x[GAMMA].sin_cos();
        let (sc, cc) = x[CHI].sin_cos();
        let along = Vector3::new(cg * cc, cg * sc, sg);
        let up = Vector3::new(-sg * cc, -sg * sc, cg);
        let side = Vector3::new(-sc, cc, 0.0);
        // The envelope, kept a guard inside the range, but never narrower
        // than the reference's own speed: a plan that flies near a limit is
        // flown there (and judged there).
        let [slowest, fastest] = airframe.airspeed;
        let planned = target.velocity.norm();
        let floor = (slowest * (1.0 + ENVELOPE_GUARD)).min(planned);
        let ceiling = (fastest * (1.0 - ENVELOPE_GUARD)).max(planned);
        let v_dot = a
            .dot(&along)
            .max((floor - x[V]) / ENVELOPE_TIME)
            .min((ceiling - x[V]) / ENVELOPE_TIME);
        let gamma_dot = a.dot(&up) / v;
        let chi_dot = a.dot(&side) / (v * cg.max(1e-6));

        // Eqs. 2-3 solved for n cos μ and n sin μ.
        let vertical = v * gamma_dot / G + cg;
        let lateral = v * cg * chi_dot / G;
        let (mut n, mut mu) = if vertical >= 0.0 {
            (vertical.hypot(lateral), lateral.atan2(vertical))
        } else {
            // Pushing over: negative load factor, wings near level.
            (-vertical.hypot(lateral), (-lateral).atan2(-vertical))
        };
        mu = mu.clamp(-airframe.max_bank, airframe.max_bank);
        n = n.clamp(airframe.load_factor[0], airframe.load_factor[1]);
        // Eq. 1 solved for T, with the drag of the load factor used.
        let thrust = airframe.weight() * (v_dot / G + sg) + airframe.drag(v, n);
        Controls {
            thrust: thrust.clamp(0.0, airframe.max_thrust),
            load_factor: n,
            bank: mu,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::ode::rk4_step;

    fn airframe() -> Airframe {
        Airframe::from_params(&FlatloParams::default())
    }

    #[test]
    fn level_flight_trim_holds_speed_and_height() {
        // n = 1, μ = 0, T = D: eqs. 1-3 give zero rates.
        let a = airframe();
        let x = Vector6::new(30.5, 0.0, 0.3, 0.0, 0.0, 3050.0);
        let u = Controls {
            thrust: a.drag(30.5, 1.0),
            load_factor: 1.0,
            bank: 0.0,
        };
        let d = a.derivative(&x, &u);
        assert!(d[V].abs() < 1e-12 && d[GAMMA].abs() < 1e-12 && d[CHI].abs() < 1e-12);
        assert!((d[3] - 30.5 * 0.3f64.cos()).abs() < 1e-12);
        assert_eq!(d[5], 0.0);
    }

    #[test]
    fn a_coordinated_turn_has_the_textbook_rate() {
        // Level turn: n cos μ = 1 → χ̇ = g tan μ / V (eq. 3).
        let a = airframe();
        let mu: f64 = 0.4;
        let x = Vector6::new(30.5, 0.0, 0.0, 0.0, 0.0, 3050.0);
        let u = Controls {
            thrust: 0.0,
            load_factor: 1.0 / mu.cos(),
            bank: mu,
        };
        let d = a.derivative(&x, &u);
        assert!(d[GAMMA].abs() < 1e-12);
        assert!((d[CHI] - G * mu.tan() / 30.5).abs() < 1e-12);
    }

    #[test]
    fn the_autopilot_holds_a_straight_reference() {
        let a = airframe();
        let mut pilot = Autopilot::new(FlatloParams::default().pid);
        // Start 50 m left of and 30 m below a reference flying east at 30.5 m/s.
        let mut x = Vector6::new(30.5, 0.0, 0.0, 0.0, 50.0, 3020.0);
        let dt = 0.1;
        for k in 0..6000 {
            let t = k as f64 * dt;
            let target = Target {
                position: Point3::new(30.5 * t, 0.0, 3050.0),
                velocity: Vector3::new(30.5, 0.0, 0.0),
                acceleration: Vector3::zeros(),
            };
            let u = pilot.command(&a, &x, &target, dt);
            assert!(u.thrust >= 0.0 && u.thrust <= a.max_thrust);
            x = rk4_step(|_, s| a.derivative(s, &u), t, &x, dt);
        }
        let t = 6000.0 * dt;
        let error = (position(&x) - Point3::new(30.5 * t, 0.0, 3050.0)).norm();
        assert!(error < 1.0, "tracking error after 10 min: {error} m");
    }
}
