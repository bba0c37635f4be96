//! The air and the fixes a flight is flown in: Dryden turbulence
//! (MIL-F-8785C, low altitude) on a mean wind, and a GNSS position error
//! that drifts as a first-order Gauss-Markov process. Both are exact
//! discretisations of their continuous models, so a step of any length
//! keeps the model's variance and spectrum (docs/flight-check.md).

use nalgebra::{Matrix2, Vector2, Vector3};
use rand::RngExt;
use rand::rngs::ChaCha8Rng;
use rand_distr::StandardNormal;

use crate::mission::{FlightParams, Turbulence};

/// Where a flight's randomness comes from: standard normal draws, taken in
/// the order the flight asks for them. A check draws them from one ChaCha8
/// stream per flight; the rare-event estimate (`rare.rs`) holds them as a
/// vector it moves (every input of a flight is one of these draws).
pub trait Normals {
    fn normal(&mut self) -> f64;
}

impl Normals for ChaCha8Rng {
    fn normal(&mut self) -> f64 {
        self.sample(StandardNormal)
    }
}

const FOOT: f64 = 0.3048;

/// The Dryden low-altitude scales at height `h` metres above the ground
/// (MIL-F-8785C, h < 1000 ft; below 10 ft the 10 ft values): the turbulence
/// scale lengths L_u = L_v and L_w (metres) and the intensities σ_u = σ_v
/// and σ_w (m/s) for the wind `w20` (m/s) 20 ft above the ground.
pub fn dryden_scales(h: f64, w20: f64) -> DrydenScales {
    let h_ft = (h / FOOT).clamp(10.0, 1000.0);
    let k = 0.177 + 0.000823 * h_ft;
    let sigma_w = 0.1 * w20;
    DrydenScales {
        length_uv: h_ft / k.powf(1.2) * FOOT,
        length_w: h_ft * FOOT,
        sigma_uv: sigma_w / k.powf(0.4),
        sigma_w,
    }
}

/// [`dryden_scales`]' figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrydenScales {
    pub length_uv: f64,
    pub length_w: f64,
    pub sigma_uv: f64,
    pub sigma_w: f64,
}

/// The one-sided power spectral density of a Dryden component at ω rad/s,
/// (m/s)²/(rad/s): the longitudinal form (first order) or the lateral and
/// vertical form (second order), for intensity σ, scale L and airspeed V.
pub fn dryden_psd(longitudinal: bool, sigma: f64, length: f64, airspeed: f64, omega: f64) -> f64 {
    let x = length * omega / airspeed;
    if longitudinal {
        sigma * sigma * 2.0 * length / (std::f64::consts::PI * airspeed) / (1.0 + x * x)
    } else {
        sigma * sigma * length / (std::f64::consts::PI * airspeed) * (1.0 + 3.0 * x * x)
            / ((1.0 + x * x) * (1.0 + x * x))
    }
}

/// A first-order gust component (Dryden's longitudinal u), in units of its
/// σ: an Ornstein-Uhlenbeck process with time constant L/V.
#[derive(Debug, Clone, Copy)]
pub struct FirstOrder(f64);

impl FirstOrder {
    /// A stationary draw.
    pub fn new(rng: &mut impl Normals) -> Self {
        FirstOrder(rng.normal())
    }

    /// Advances by `dt` with time constant `tau`; the value in units of σ.
    pub fn step(&mut self, rng: &mut impl Normals, dt: f64, tau: f64) -> f64 {
        let phi = (-dt / tau).exp();
        let n = rng.normal();
        self.0 = phi * self.0 + (1.0 - phi * phi).max(0.0).sqrt() * n;
        self.0
    }
}

/// A second-order gust component (Dryden's lateral v and vertical w), in
/// units of its σ: white noise through (1 + √3 τs)/(1 + τs)², written as
/// two first-order lags z₁ → z₂ with output √3 z₁ + (1 − √3) z₂. The state
/// is scaled so that its stationary covariance is P = [[1, ½], [½, ½]]
/// whatever τ, and the output's variance is then 2 (so it is divided by √2).
#[derive(Debug, Clone, Copy)]
pub struct SecondOrder(Vector2<f64>);

/// The stationary covariance of [`SecondOrder`]'s scaled state.
fn stationary() -> Matrix2<f64> {
    Matrix2::new(1.0, 0.5, 0.5, 0.5)
}

impl SecondOrder {
    /// A stationary draw.
    pub fn new(rng: &mut impl Normals) -> Self {
        let (a, b) = (rng.normal(), rng.normal());
        // Cholesky of P: [[1, 0], [½, ½]].
        SecondOrder(Vector2::new(a, 0.5 * a + 0.5 * b))
    }

    /// Advances by `dt` with time constant `tau`; the output in units of σ.
    /// Exact: x ← Φx + w, Φ = e^{A dt}, w ~ N(0, P − ΦPΦᵀ) (P stationary).
    pub fn step(&mut self, rng: &mut impl Normals, dt: f64, tau: f64) -> f64 {
        let phi = (-dt / tau).exp();
        let transition = Matrix2::new(phi, 0.0, phi * dt / tau, phi);
        let p = stationary();
        let q = p - transition * p * transition.transpose();
        let l11 = q[(0, 0)].max(0.0).sqrt();
        let l21 = if l11 > 0.0 { q[(1, 0)] / l11 } else { 0.0 };
        let l22 = (q[(1, 1)] - l21 * l21).max(0.0).sqrt();
        let (a, b) = (rng.normal(), rng.normal());
        self.0 = transition * self.0 + Vector2::new(l11 * a, l21 * a + l22 * b);
        (3f64.sqrt() * self.0.x + (1.0 - 3f64.sqrt()) * self.0.y) / std::f64::consts::SQRT_2
    }
}

/// A flight's air: the mean wind and Dryden gusts, u along the mean wind,
/// v across it, w up (frozen turbulence carried past the formation at its
/// airspeed; vehicles a few metres apart, far less than the scale lengths,
/// meet the same gusts).
#[derive(Debug, Clone)]
pub struct Air {
    mean: Vector3<f64>,
    /// Unit vectors of u and v in ENU (horizontal).
    along: Vector3<f64>,
    across: Vector3<f64>,
    w20: f64,
    u: FirstOrder,
    v: SecondOrder,
    w: SecondOrder,
}

impl Air {
    pub fn new(p: &FlightParams, rng: &mut impl Normals) -> Self {
        // From `wind_from_deg` (clockwise from north) the air moves the other way.
        let to = (p.wind_from_deg + 180.0).to_radians();
        let along = Vector3::new(to.sin(), to.cos(), 0.0);
        Air {
            mean: along * p.wind_speed,
            along,
            across: Vector3::new(-along.y, along.x, 0.0),
            w20: match p.turbulence {
                Turbulence::None => 0.0,
                t => t.wind_at_20_ft(),
            },
            u: FirstOrder::new(rng),
            v: SecondOrder::new(rng),
            w: SecondOrder::new(rng),
        }
    }

    /// The wind (m/s ENU) over the next `dt` at height `h` for a vehicle
    /// moving at `velocity`: the gusts' time constants are L / V, V the
    /// airspeed (at least 1 m/s: a hovering vehicle in still air still
    /// meets eddies).
    pub fn step(
        &mut self,
        rng: &mut impl Normals,
        dt: f64,
        h: f64,
        velocity: &Vector3<f64>,
    ) -> Vector3<f64> {
        if self.w20 <= 0.0 {
            return self.mean;
        }
        let s = dryden_scales(h, self.w20);
        let airspeed = (velocity - self.mean).norm().max(1.0);
        let u = self.u.step(rng, dt, s.length_uv / airspeed) * s.sigma_uv;
        let v = self.v.step(rng, dt, s.length_uv / airspeed) * s.sigma_uv;
        let w = self.w.step(rng, dt, s.length_w / airspeed) * s.sigma_w;
        self.mean + self.along * u + self.across * v + Vector3::new(0.0, 0.0, w)
    }
}

/// A GNSS receiver's position error: each axis a first-order Gauss-Markov
/// process (σ horizontal on x and y, σ vertical on z, one correlation time).
#[derive(Debug, Clone)]
pub struct Gnss {
    error: Vector3<f64>,
    sigma: Vector3<f64>,
    tau: f64,
}

impl Gnss {
    /// The part of the error common to every receiver of a flight
    /// (`own = false`) or one receiver's own part (`own = true`): their
    /// variances are `gnss_own_share` apart and add to the σ² given.
    pub fn new(p: &FlightParams, own: bool, rng: &mut impl Normals) -> Self {
        let share = p.gnss_own_share.clamp(0.0, 1.0);
        let k = if own {
            share.sqrt()
        } else {
            (1.0 - share).sqrt()
        };
        let sigma = Vector3::new(
            p.gnss_sigma_horizontal,
            p.gnss_sigma_horizontal,
            p.gnss_sigma_vertical,
        ) * k;
        let error = Vector3::new(rng.normal(), rng.normal(), rng.normal()).component_mul(&sigma);
        Gnss {
            error,
            sigma,
            tau: p.gnss_correlation_time,
        }
    }

    /// The error after `dt` more seconds, metres ENU.
    pub fn step(&mut self, rng: &mut impl Normals, dt: f64) -> Vector3<f64> {
        let phi = (-dt / self.tau).exp();
        let spread = (1.0 - phi * phi).max(0.0).sqrt();
        for axis in 0..3 {
            let n = rng.normal();
            self.error[axis] = phi * self.error[axis] + spread * self.sigma[axis] * n;
        }
        self.error
    }
}
