//! `[flight]`: the air and autopilots of the Monte Carlo flight check.

use super::Checker;
use super::compact;
use crate::mission::model::FlightParams;
use crate::mission::source::FieldPath;

/// Most flights one check may fly: 100,000 gives a share of 10⁻⁴ to
/// within a few parts in 10⁵; more is minutes of CPU for nothing.
pub const MAX_FLIGHTS: usize = 100_000;

/// The longest step the quadrotor's attitude loop stays accurate at, s.
pub const MAX_STEP: f64 = 0.02;

/// The shortest step, s: below it a flight is millions of steps.
pub const MIN_STEP: f64 = 1e-4;

impl Checker {
    pub(super) fn flight(&mut self, path: &FieldPath, p: &FlightParams) {
        self.at_least_one(path.key("flights"), p.flights, "flight");
        if p.flights > MAX_FLIGHTS {
            self.error(
                path.key("flights"),
                format!(
                    "{} flights is over the limit of {MAX_FLIGHTS} (a share of 1e-4 is already \
                     known to a few parts in 1e5 at that count)",
                    p.flights
                ),
            );
        }
        for (key, value, unit) in [
            ("wind_speed", p.wind_speed, " m/s"),
            ("gnss_sigma_horizontal", p.gnss_sigma_horizontal, " m"),
            ("gnss_sigma_vertical", p.gnss_sigma_vertical, " m"),
            ("takeoff_skew", p.takeoff_skew, " s"),
            ("drag", p.drag, " 1/s"),
        ] {
            self.non_negative(path.key(key), value, unit);
        }
        self.positive(
            path.key("gnss_correlation_time"),
            p.gnss_correlation_time,
            " s",
        );
        if p.gnss_own_share.is_finite() && !(0.0..=1.0).contains(&p.gnss_own_share) {
            self.error(
                path.key("gnss_own_share"),
                format!(
                    "a share of the variance, in [0, 1], got {}",
                    compact(p.gnss_own_share)
                ),
            );
        }
        self.positive(path.key("acceptance_radius"), p.acceptance_radius, " m");
        // A wind no multicopter flies in, a skew longer than a flight: typos.
        self.at_most(
            path.key("wind_speed"),
            p.wind_speed,
            40.0,
            " m/s",
            "a gale no multicopter flies in",
        );
        self.at_most(
            path.key("gnss_sigma_horizontal"),
            p.gnss_sigma_horizontal,
            100.0,
            " m",
            "no GNSS receiver in use is that far off",
        );
        self.at_most(
            path.key("gnss_sigma_vertical"),
            p.gnss_sigma_vertical,
            100.0,
            " m",
            "no GNSS receiver in use is that far off",
        );
        self.at_most(
            path.key("gnss_correlation_time"),
            p.gnss_correlation_time,
            1e5,
            " s",
            "a day of correlation is a constant error",
        );
        self.at_most(
            path.key("takeoff_skew"),
            p.takeoff_skew,
            600.0,
            " s",
            "a take-off ten minutes late is another flight",
        );
        self.at_most(
            path.key("acceptance_radius"),
            p.acceptance_radius,
            1000.0,
            " m",
            "beyond any autopilot's acceptance radius",
        );
        self.at_most(
            path.key("drag"),
            p.drag,
            10.0,
            " 1/s",
            "an airframe is not a parachute",
        );
        if p.step.is_finite() && !(MIN_STEP..=MAX_STEP).contains(&p.step) {
            self.error(
                path.key("step"),
                format!(
                    "must be in [{}, {}] s (the attitude loop's accuracy, the flight's size), \
                     got {} s",
                    compact(MIN_STEP),
                    compact(MAX_STEP),
                    compact(p.step)
                ),
            );
        }
        if p.wind_from_deg.is_finite() && p.wind_from_deg.abs() > 360.0 {
            self.error(
                path.key("wind_from_deg"),
                format!("must be in [-360, 360]°, got {}°", compact(p.wind_from_deg)),
            );
        }
    }
}
