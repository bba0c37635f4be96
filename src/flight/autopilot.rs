//! One vehicle flown as its autopilot flies an exported mission: the
//! waypoints in turn, each leg at its written speed, each hold waited (the
//! export's schedule, `reverify::Flight`, the flight the export's
//! re-verification judges), a waypoint taken once the vehicle (as its GNSS
//! puts it) is within the acceptance radius, the mission waiting at a
//! waypoint until then.
//!
//! The vehicle is the schedule plus a departure from it. In still air, on
//! exact fixes, the autopilot's trajectory generator and feed-forward fly
//! the written legs (the plan was verified within `[vehicle]`): the
//! departure stays zero and the flight is the re-verification's. Wind,
//! gusts and fix errors push it off; the departure is flown by the fleet's
//! quadrotor (eqs. 10, 12-13, integrated with RK4) under a cascaded
//! controller with PX4's multicopter structure and default gains (position
//! P → velocity PID → acceleration, within `[vehicle]`'s speeds and
//! accelerations). Superposing the two is exact for the translation (it is
//! linear in position); it leaves out the coupling of the schedule's own
//! tilt with the departure's, and the corner-cutting of a real trajectory
//! generator (docs/flight-check.md).

use nalgebra::{Point3, Vector3};

use crate::base::ode::rk4_step;
use crate::export::VehiclePlan;
use crate::export::reverify::Flight;
use crate::mission::VehicleLimits;
use crate::pipelines::quadrotor::{self, Body, State};

/// PX4's multicopter position and velocity gains (MPC_XY_P, MPC_Z_P,
/// MPC_XY_VEL_P/I/D_ACC, MPC_Z_VEL_P/I/D_ACC, their defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    pub position_xy: f64,
    pub position_z: f64,
    pub velocity_xy: [f64; 3],
    pub velocity_z: [f64; 3],
}

impl Default for Gains {
    fn default() -> Self {
        Gains::of(&crate::mission::Vehicle::default())
    }
}

impl Gains {
    /// The proportional and integral gains `[vehicle]` states (PX4's by
    /// default: MPC_XY_VEL_I_ACC 0.4, MPC_Z_VEL_I_ACC 2); the derivative
    /// terms stay PX4's (MPC_XY_VEL_D_ACC 0.2, MPC_Z_VEL_D_ACC 0).
    pub fn of(v: &crate::mission::Vehicle) -> Self {
        Gains {
            position_xy: v.position_gain_xy,
            position_z: v.position_gain_z,
            velocity_xy: [v.velocity_gain_xy, v.velocity_integral_xy, 0.2],
            velocity_z: [v.velocity_gain_z, v.velocity_integral_z, 0.0],
        }
    }
}

/// One vehicle's autopilot, airframe and state.
#[derive(Debug, Clone)]
pub struct Autopilot<'a> {
    plan: &'a VehiclePlan,
    /// The written mission flown on time (legs at their speeds, holds).
    schedule: Flight<'a>,
    limits: VehicleLimits,
    gains: Gains,
    body: Body,
    acceptance: f64,
    /// Take-off, seconds on the plan's clock.
    takeoff: f64,
    /// Where the autopilot is in its mission, seconds on the schedule's
    /// clock: it runs with time, and stops at a waypoint not yet taken
    /// (farther than the acceptance radius when due) until it is.
    clock: f64,
    /// The first waypoint not yet taken.
    next: usize,
    /// Where the schedule has it (at the mission clock).
    nominal: Point3<f64>,
    /// The quadrotor's departure from the schedule: position, velocity,
    /// attitude and rates (module doc).
    pub state: State,
    integral: Vector3<f64>,
    last_velocity: Vector3<f64>,
}

impl<'a> Autopilot<'a> {
    /// Hovering at the plan's first waypoint until `takeoff` (seconds on
    /// the plan's clock).
    pub fn new(
        plan: &'a VehiclePlan,
        limits: VehicleLimits,
        gains: Gains,
        body: Body,
        acceptance: f64,
        takeoff: f64,
    ) -> Self {
        let first = plan
            .waypoints
            .first()
            .map_or(Point3::origin(), |w| w.position);
        let start = plan.waypoints.first().map_or(0.0, |w| w.t);
        Autopilot {
            plan,
            schedule: Flight::new(plan),
            limits,
            gains,
            body,
            acceptance,
            takeoff,
            clock: start,
            next: 1,
            nominal: first,
            state: quadrotor::hover_at(Point3::origin()),
            integral: Vector3::zeros(),
            last_velocity: Vector3::zeros(),
        }
    }

    /// Has it taken its last waypoint?
    pub fn done(&self) -> bool {
        self.next >= self.plan.waypoints.len()
    }

    pub fn position(&self) -> Point3<f64> {
        self.nominal + quadrotor::position(&self.state).coords
    }

    /// Its velocity: the schedule's leg and its departure from it.
    pub fn velocity(&self) -> Vector3<f64> {
        let leg = if self.done() {
            Vector3::zeros()
        } else {
            self.schedule.at(self.clock).1
        };
        leg + quadrotor::velocity(&self.state)
    }

    /// The leg its mission has it on now (both ends the same while it
    /// waits, holds or has finished).
    pub fn line(&self) -> (Point3<f64>, Point3<f64>) {
        let w = &self.plan.waypoints;
        let at = |i: usize| w.get(i).map_or(Point3::origin(), |w| w.position);
        let i = self.schedule.leg(self.clock);
        if i == 0 || self.clock >= self.schedule.arrivals()[i] || self.done() {
            let k = if self.done() {
                w.len().saturating_sub(1)
            } else {
                i
            };
            (at(k), at(k))
        } else {
            (at(i - 1), at(i))
        }
    }

    /// Advances the mission clock to plan time `t` (after take-off), taking
    /// the waypoints that fall due where the vehicle believes itself within
    /// the acceptance radius, stopping at the first it is not within.
    /// Returns where the vehicle is held: its first waypoint before
    /// take-off, a waypoint not yet taken.
    fn advance(&mut self, t: f64, dt: f64, believed: &Point3<f64>) -> Option<Point3<f64>> {
        let w = &self.plan.waypoints;
        if t < self.takeoff {
            return w.first().map(|w| w.position);
        }
        let clock = self.clock + dt;
        while self.next < w.len() && self.schedule.arrivals()[self.next] <= clock {
            if (believed - w[self.next].position).norm() <= self.acceptance {
                self.next += 1;
            } else {
                self.clock = self.schedule.arrivals()[self.next];
                return Some(w[self.next].position);
            }
        }
        self.clock = clock;
        None
    }

    /// One control and integration step of `dt` at plan time `t`: the
    /// autopilot believes itself at its position + `gnss` and flies in
    /// `wind`. The schedule's motion is flown exactly (module doc); the
    /// deviation from it is the quadrotor's, under the cascaded loops.
    pub fn step(&mut self, t: f64, dt: f64, gnss: &Vector3<f64>, wind: &Vector3<f64>, drag: f64) {
        let e = quadrotor::position(&self.state).coords;
        let believed = self.nominal + e + gnss;
        let held = self.advance(t, dt, &believed);
        self.nominal = held.unwrap_or_else(|| self.schedule.at(self.clock).0);
        let g = self.gains;
        // Position P → velocity setpoint, within the speed, climb and
        // descent limits.
        let error = -(e + gnss);
        let mut wanted = Vector3::new(
            g.position_xy * error.x,
            g.position_xy * error.y,
            g.position_z * error.z,
        );
        let horizontal = wanted.xy().norm();
        if horizontal > self.limits.speed {
            let k = self.limits.speed / horizontal;
            wanted.x *= k;
            wanted.y *= k;
        }
        wanted.z = wanted.z.clamp(-self.limits.descent, self.limits.climb);
        // Velocity PID → acceleration, the derivative on the measured
        // acceleration (PX4's form), the integral frozen while the output
        // is limited (anti-windup).
        let v = quadrotor::velocity(&self.state);
        let e_v = wanted - v;
        let measured = (v - self.last_velocity) / dt;
        self.last_velocity = v;
        let pid = |k: [f64; 3], e: f64, i: f64, d: f64| k[0] * e + k[1] * i - k[2] * d;
        let mut a = Vector3::new(
            pid(g.velocity_xy, e_v.x, self.integral.x, measured.x),
            pid(g.velocity_xy, e_v.y, self.integral.y, measured.y),
            pid(g.velocity_z, e_v.z, self.integral.z, measured.z),
        );
        let horizontal = a.xy().norm();
        let limited_xy = horizontal > self.limits.acceleration;
        if limited_xy {
            let k = self.limits.acceleration / horizontal;
            a.x *= k;
            a.y *= k;
        }
        let limited_z = a.z > self.limits.up || a.z < -self.limits.down;
        a.z = a.z.clamp(-self.limits.down, self.limits.up);
        if !limited_xy {
            self.integral.x += e_v.x * dt;
            self.integral.y += e_v.y * dt;
        }
        if !limited_z {
            self.integral.z += e_v.z * dt;
        }
        let command = self.body.command_for(&self.state, &a);
        let body = self.body;
        self.state = rk4_step(
            |_, s| {
                let mut d = body.derivative(s, &command);
                // The air past the airframe, beyond what flying the
                // schedule in still air meets (its own feed-forward holds).
                let air = (wind - quadrotor::velocity(s)) * drag;
                d[3] += air.x;
                d[4] += air.y;
                d[5] += air.z;
                d
            },
            t,
            &self.state,
            dt,
        );
        quadrotor::renormalize(&mut self.state);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::Waypoint;
    use crate::export::legs::LegLimits;
    use crate::mission::{FleetParams, Vehicle};

    /// A vehicle holding at one point (two waypoints, the same place).
    fn hovering(limits: VehicleLimits) -> VehiclePlan {
        let at = Point3::new(0.0, 0.0, 10.0);
        let w = Waypoint {
            t: 0.0,
            position: at,
            speed: 0.0,
            hold: 1000.0,
        };
        VehiclePlan {
            vehicle: 0,
            home: None,
            legs: LegLimits::multicopter(limits),
            waypoints: vec![w, Waypoint { hold: 0.0, ..w }],
        }
    }

    /// The step response documented in docs/flight-check.md: the fix jumps
    /// 1 m east (GNSS), the vehicle moves 1 m west to put its belief back on
    /// the waypoint. Rise (10-90 %) 1-2 s, overshoot under 15 %, within
    /// 2 % after 8 s; the tilt stays far inside the quadrotor's limit.
    #[test]
    fn a_one_metre_step_is_taken_in_under_two_seconds_with_little_overshoot() {
        let limits = Vehicle::default().limits(0);
        let plan = hovering(limits);
        let body = Body::from_params(&FleetParams::default());
        let mut pilot = Autopilot::new(&plan, limits, Gains::default(), body, 2.0, 0.0);
        let dt = 0.01;
        let (mut t10, mut t90, mut most, mut after8) = (None, None, 0.0f64, 0.0f64);
        for k in 0..1200 {
            let t = k as f64 * dt;
            pilot.step(t, dt, &Vector3::new(1.0, 0.0, 0.0), &Vector3::zeros(), 0.3);
            let moved = -quadrotor::position(&pilot.state).x;
            if moved >= 0.1 && t10.is_none() {
                t10 = Some(t);
            }
            if moved >= 0.9 && t90.is_none() {
                t90 = Some(t);
            }
            most = most.max(moved);
            if t >= 8.0 {
                after8 = after8.max((moved - 1.0).abs());
            }
        }
        let rise = t90.zip(t10).map(|(a, b)| a - b).expect("it moved");
        eprintln!(
            "rise {rise:.2} s, overshoot {:.1} %, error after 8 s {after8:.3} m",
            100.0 * (most - 1.0)
        );
        assert!((1.0..=2.0).contains(&rise), "rise {rise} s");
        assert!(most - 1.0 < 0.15, "overshoot {most}");
        assert!(after8 < 0.02, "{after8}");
    }

    /// In a steady 8 m/s wind the integral takes the drag: the vehicle's
    /// departure settles back to the schedule (under 2 cm after 20 s).
    #[test]
    fn a_steady_wind_is_held_off_by_the_integral() {
        let limits = Vehicle::default().limits(0);
        let plan = hovering(limits);
        let body = Body::from_params(&FleetParams::default());
        let mut pilot = Autopilot::new(&plan, limits, Gains::default(), body, 2.0, 0.0);
        let (dt, wind) = (0.01, Vector3::new(8.0, 0.0, 0.0));
        let mut worst = 0.0f64;
        for k in 0..3000 {
            pilot.step(k as f64 * dt, dt, &Vector3::zeros(), &wind, 0.3);
            worst = worst.max(quadrotor::position(&pilot.state).coords.norm());
        }
        let settled = quadrotor::position(&pilot.state).coords.norm();
        eprintln!("pushed off {worst:.3} m at most, {settled:.4} m after 30 s");
        assert!(worst > 0.1, "the gust of wind moved it: {worst}");
        assert!(settled < 0.02, "{settled}");
    }

    /// Without an integral (`vehicle.velocity_integral_xy = 0`, a PD loop
    /// such as RotorPy's SE3Control) a steady wind's drag is held off by
    /// the position error alone: it settles at drag · wind / (K_p K_v) =
    /// 0.3 · 8 / (0.95 · 1.8) = 1.40 m downwind, and stays there.
    #[test]
    fn without_an_integral_a_steady_wind_leaves_its_offset() {
        let vehicle = Vehicle {
            velocity_integral_xy: 0.0,
            ..Vehicle::default()
        };
        let limits = vehicle.limits(0);
        let plan = hovering(limits);
        let body = Body::from_params(&FleetParams::default());
        let mut pilot = Autopilot::new(&plan, limits, Gains::of(&vehicle), body, 2.0, 0.0);
        let (dt, wind) = (0.01, Vector3::new(8.0, 0.0, 0.0));
        for k in 0..3000 {
            pilot.step(k as f64 * dt, dt, &Vector3::zeros(), &wind, 0.3);
        }
        let offset = quadrotor::position(&pilot.state).x;
        let expected = 0.3 * 8.0 / (vehicle.position_gain_xy * vehicle.velocity_gain_xy);
        eprintln!("settled {offset:.3} m downwind, expected {expected:.3} m");
        assert!(
            (offset - expected).abs() < 0.05 * expected,
            "{offset} vs {expected}"
        );
    }
}
