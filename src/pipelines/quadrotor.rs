//! The multicopter every multicopter of a mission is: the fleet paper's
//! quadrotor, rigid-body dynamics (eq. 10) under the quaternion position and
//! attitude laws (eqs. 11-13). The fleet's agents fly it, and the flight
//! check (`flight`) flies every multicopter plan's vehicles on it, whichever
//! pipeline planned them: so it is shared, not the fleet's own. Its
//! parameters are read from the mission ([`Body::of`]).
//!
//! State: position p and velocity ṗ (m, m/s, ENU), attitude q (body → world)
//! and body rate ω (rad/s). Thrust F along body z (b = [0 0 1]), torque τ.
//! Readings (docs/fleet.md): eq. 11's u_pos is the acceleration command, so
//! the thrust vector is m(u_pos + g e_z); eq. 12's quaternion turns b onto it
//! with the least rotation; eq. 13 acts on the attitude error
//! 2 ln(q_d* ⊗ q) = `scaled_axis()` (nalgebra's `ln` is already θ·axis, not
//! halved), scaled by J so the gains are rates.

use nalgebra::{Matrix3, Point3, Quaternion, SVector, UnitQuaternion, Vector3};

use crate::mission::{FleetParams, Mission};

/// Standard gravity, m/s².
pub const G: f64 = crate::mission::GRAVITY;

/// p (0..3), ṗ (3..6), q = (w, x, y, z) (6..10), ω (10..13).
pub type State = SVector<f64, 13>;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    pub mass: f64,
    pub inertia: Matrix3<f64>,
    pub inertia_inv: Matrix3<f64>,
    pub position_gains: [f64; 2],
    pub attitude_gains: [f64; 2],
    pub max_thrust: f64,
    pub max_tilt: f64,
    /// tan(max_tilt), which every command reads (the flight check's
    /// vehicles ask for one at every step).
    tan_tilt: f64,
}

/// Thrust N along body z, torque N·m in the body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    pub thrust: f64,
    pub torque: Vector3<f64>,
}

impl Body {
    /// The airframe of `mission`'s multicopters: the body the `[fleet]`
    /// section describes (mass, inertia, gains, thrust and tilt limits), the
    /// one quadrotor the file states.
    pub fn of(mission: &Mission) -> Self {
        Self::from_params(&mission.fleet)
    }

    pub fn from_params(p: &FleetParams) -> Self {
        let inertia = Matrix3::from_diagonal(&p.inertia_diag);
        Body {
            mass: p.mass,
            inertia,
            inertia_inv: inertia.try_inverse().unwrap_or_else(Matrix3::identity),
            position_gains: p.position_gains,
            attitude_gains: p.attitude_gains,
            max_thrust: p.max_thrust,
            max_tilt: p.max_tilt_deg.to_radians(),
            tan_tilt: p.max_tilt_deg.to_radians().tan(),
        }
    }

    /// Eq. 10.
    pub fn derivative(&self, x: &State, u: &Command) -> State {
        let q = attitude(x);
        let v = velocity(x);
        let w = rate(x);
        let accel = q * Vector3::new(0.0, 0.0, u.thrust / self.mass) - Vector3::new(0.0, 0.0, G);
        let qdot = quaternion(x) * Quaternion::from_imag(w) * 0.5;
        let wdot = self.inertia_inv * (u.torque - w.cross(&(self.inertia * w)));
        let mut d = State::zeros();
        d.fixed_rows_mut::<3>(0).copy_from(&v);
        d.fixed_rows_mut::<3>(3).copy_from(&accel);
        d[6] = qdot.w;
        d[7] = qdot.i;
        d[8] = qdot.j;
        d[9] = qdot.k;
        d.fixed_rows_mut::<3>(10).copy_from(&wdot);
        d
    }

    /// Eqs. 11-13: the command that flies towards `reference` (ẏ_d neglected,
    /// as in the paper).
    pub fn control(&self, x: &State, reference: &Point3<f64>) -> Command {
        let [kp, kv] = self.position_gains;
        // Eq. 11, plus gravity: the thrust vector wanted.
        let u_pos = -(position(x) - reference) * kp - velocity(x) * kv;
        self.command_for(x, &u_pos)
    }

    /// Eqs. 12-13: the thrust and torque that give the acceleration
    /// `acceleration` (m/s², gravity not included), within the tilt and
    /// thrust limits. The fleet's eq. 11 and the flight check's cascaded
    /// controller both end here.
    pub fn command_for(&self, x: &State, acceleration: &Vector3<f64>) -> Command {
        let mut f = (acceleration + Vector3::new(0.0, 0.0, G)) * self.mass;
        // Tilt and thrust limits: keep the vertical part, shorten the horizontal.
        f.z = f.z.max(0.1 * self.mass * G);
        let horizontal = f.xy().norm();
        let allowed = f.z * self.tan_tilt;
        if horizontal > allowed {
            let scale = allowed / horizontal;
            f.x *= scale;
            f.y *= scale;
        }
        if f.norm() > self.max_thrust {
            f *= self.max_thrust / f.norm();
        }
        // Eq. 12: the least rotation taking b = e_z onto f.
        let b = Vector3::z();
        let q_raw = Quaternion::from_parts(b.dot(&f) + f.norm(), b.cross(&f));
        let q_d = UnitQuaternion::from_quaternion(q_raw);
        // Eq. 13 on the attitude error, 2 ln(q_d* ⊗ q).
        let mut error = q_d.inverse() * attitude(x);
        if error.w < 0.0 {
            error = UnitQuaternion::from_quaternion(-error.into_inner());
        }
        let [ka, kw] = self.attitude_gains;
        let torque = self.inertia * (-error.scaled_axis() * ka - rate(x) * kw);
        Command {
            thrust: f.norm(),
            torque,
        }
    }
}

pub fn hover_at(p: Point3<f64>) -> State {
    let mut x = State::zeros();
    x.fixed_rows_mut::<3>(0).copy_from(&p.coords);
    x[6] = 1.0;
    x
}

pub fn position(x: &State) -> Point3<f64> {
    Point3::new(x[0], x[1], x[2])
}

pub fn velocity(x: &State) -> Vector3<f64> {
    Vector3::new(x[3], x[4], x[5])
}

fn quaternion(x: &State) -> Quaternion<f64> {
    Quaternion::new(x[6], x[7], x[8], x[9])
}

pub fn attitude(x: &State) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(quaternion(x))
}

pub fn rate(x: &State) -> Vector3<f64> {
    Vector3::new(x[10], x[11], x[12])
}

/// Keeps q a unit quaternion after an integration step.
pub fn renormalize(x: &mut State) {
    let n = (x[6] * x[6] + x[7] * x[7] + x[8] * x[8] + x[9] * x[9]).sqrt();
    if n > 0.0 {
        for i in 6..10 {
            x[i] /= n;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::ode::rk4_step;

    fn body() -> Body {
        Body::from_params(&FleetParams::default())
    }

    fn fly(body: &Body, mut x: State, reference: Point3<f64>, seconds: f64) -> State {
        let dt = 0.005;
        for k in 0..(seconds / dt) as usize {
            let u = body.control(&x, &reference);
            x = rk4_step(|_, s| body.derivative(s, &u), k as f64 * dt, &x, dt);
            renormalize(&mut x);
        }
        x
    }

    #[test]
    fn hover_thrust_balances_gravity() {
        let b = body();
        let x = hover_at(Point3::new(0.0, 0.0, 1.0));
        let u = b.control(&x, &Point3::new(0.0, 0.0, 1.0));
        assert!((u.thrust - b.mass * G).abs() < 1e-9);
        assert!(u.torque.norm() < 1e-12);
        assert!(b.derivative(&x, &u).norm() < 1e-9);
    }

    #[test]
    fn a_tilted_body_accelerates_sideways() {
        // Rolled by +0.1 rad about x, thrust tilts toward −y.
        let b = body();
        let mut x = hover_at(Point3::origin());
        let q = UnitQuaternion::from_euler_angles(0.1, 0.0, 0.0);
        x[6] = q.w;
        x[7] = q.i;
        x[8] = q.j;
        x[9] = q.k;
        let d = b.derivative(
            &x,
            &Command {
                thrust: b.mass * G,
                torque: Vector3::zeros(),
            },
        );
        assert!(d[4] < 0.0 && d[3].abs() < 1e-12, "{}", d);
    }

    #[test]
    fn the_quaternion_laws_fly_to_a_point_and_hold_it() {
        let b = body();
        let x = fly(
            &b,
            hover_at(Point3::new(0.0, 0.0, 1.0)),
            Point3::new(1.0, -0.5, 1.2),
            8.0,
        );
        assert!(
            (position(&x) - Point3::new(1.0, -0.5, 1.2)).norm() < 0.01,
            "{}",
            position(&x)
        );
        assert!(velocity(&x).norm() < 0.01);
        let tilt = (attitude(&x) * Vector3::z()).angle(&Vector3::z());
        assert!(tilt < 0.01);
    }

    #[test]
    fn tilt_stays_within_its_limit_on_a_big_step() {
        let b = body();
        let dt = 0.005;
        let mut x = hover_at(Point3::new(0.0, 0.0, 1.0));
        let mut worst: f64 = 0.0;
        for k in 0..1000 {
            let u = b.control(&x, &Point3::new(10.0, 0.0, 1.0));
            assert!(u.thrust <= b.max_thrust + 1e-9);
            x = rk4_step(|_, s| b.derivative(s, &u), k as f64 * dt, &x, dt);
            renormalize(&mut x);
            worst = worst.max((attitude(&x) * Vector3::z()).angle(&Vector3::z()));
        }
        // The commanded tilt is capped; the attitude loop overshoots a little.
        assert!(worst < b.max_tilt * 1.15, "worst tilt {} rad", worst);
    }
}
