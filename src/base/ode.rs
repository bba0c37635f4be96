//! Fixed-step Runge-Kutta 4 over nalgebra vectors: the one integrator of the
//! aircraft (FLATLO) and quadrotor (fleet) simulations.

use nalgebra::SVector;

/// One classical RK4 step of dx/dt = f(t, x) from (t, x) over `h`.
pub fn rk4_step<const N: usize>(
    f: impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, N> {
    let k1 = f(t, x);
    let k2 = f(t + h / 2.0, &(x + k1 * (h / 2.0)));
    let k3 = f(t + h / 2.0, &(x + k2 * (h / 2.0)));
    let k4 = f(t + h, &(x + k3 * h));
    x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn exponential_decay_to_fourth_order() {
        // dx/dt = -x, x(0) = 1 → x(1) = e⁻¹. Global error of RK4 is O(h⁴).
        let error = |h: f64| {
            let n = (1.0 / h).round() as usize;
            let mut x = SVector::<f64, 1>::new(1.0);
            for k in 0..n {
                x = rk4_step(|_, x| -x, k as f64 * h, &x, h);
            }
            (x[0] - (-1.0f64).exp()).abs()
        };
        let (e1, e2) = (error(0.1), error(0.05));
        assert!(e1 < 1e-6, "{e1}");
        let order = (e1 / e2).log2();
        assert!((order - 4.0).abs() < 0.2, "observed order {order}");
    }

    #[test]
    fn a_harmonic_oscillator_keeps_its_energy() {
        // x'' = -x as a first-order system; after one period the state returns.
        let h = 2.0 * std::f64::consts::PI / 1000.0;
        let mut x = Vector2::new(1.0, 0.0);
        for k in 0..1000 {
            x = rk4_step(|_, s| Vector2::new(s[1], -s[0]), k as f64 * h, &x, h);
        }
        assert!((x - Vector2::new(1.0, 0.0)).norm() < 1e-9, "{x}");
    }
}
