//! The rules a mission must follow, checked on the typed value.
//!
//! Every rule runs, so one pass reports every problem. Each finding names the
//! field it concerns; `Diagnostic::locate` later adds the file and line.
//! `validate` below is the list of every section's rules; each section's
//! rules live in a module of their own, a pipeline's section's in the
//! pipeline's `section.rs`, registered in [`SECTION_RULES`]. Reading a
//! file lists what they find in the order of its lines (`file.rs`).

use nalgebra::Point3;

use super::diagnostic::Diagnostic;
use super::source::FieldPath;
use crate::mission::model::{
    Bounds, Formation, GeoOrigin, Mission, Reconfiguration, Route, Vehicle,
};

mod flight;
pub use flight::MAX_FLIGHTS;
mod formation;
mod site;

/// A pipeline's own section's rules, registered by the pipeline's module
/// (`#[linkme::distributed_slice(SECTION_RULES)]`): the file's rules run
/// every registered section's, so a new pipeline's section is checked
/// wherever a mission is read, and this floor names none of them.
pub struct SectionRules {
    /// The section's TOML key (`[key]`): the root of its fields' paths.
    pub key: &'static str,
    /// Its rules, on the section at `path` of `mission`.
    pub check: fn(&mut Checker, &FieldPath, &Mission),
}

/// Every registered section's rules.
#[linkme::distributed_slice]
pub static SECTION_RULES: [SectionRules];

/// Checks every rule, the registered sections' among them.
pub fn validate(mission: &Mission) -> Vec<Diagnostic> {
    let mut c = Checker::default();
    let root = FieldPath::root();
    c.finite_everywhere(mission);
    if mission.name.trim().is_empty() {
        c.error(root.key("name"), "must not be empty");
    }
    if let Some(origin) = &mission.origin {
        c.origin(&root.key("origin"), origin);
    }
    c.bounds(&root.key("bounds"), &mission.bounds);
    c.route(&root.key("route"), mission);
    c.formation(&root.key("formation"), &mission.formation);
    c.vehicle(&root.key("vehicle"), &mission.vehicle, &mission.formation);
    c.reconfiguration(
        &root.key("reconfiguration"),
        &mission.reconfiguration,
        mission,
    );
    // Sections in the order of their keys: the order of the registry is
    // the linker's.
    let mut sections: Vec<&SectionRules> = SECTION_RULES.iter().collect();
    sections.sort_by_key(|s| s.key);
    for section in sections {
        (section.check)(&mut c, &root.key(section.key), mission);
    }
    c.flight(&root.key("flight"), &mission.flight);
    c.obstacles(&root.key("obstacles"), mission);
    c.terrain(&root.key("terrain"), mission);
    c.physical(mission);
    c.out
}

/// What no UAV mission needs: beyond these a value is a typo or a unit
/// mistake, and the pipelines would spend minutes or gigabytes on it. The
/// ENU frame is a local tangent plane: a few hundred km across is already
/// far from flat, so a span of 1,000 km is refused.
pub mod physical {
    /// Metres across any axis of the bounds, and the FLATLO distances.
    pub const SPAN: f64 = 1e6;
    /// Metres above the ground: far above any UAV's ceiling (~20 km).
    pub const CEILING: f64 = 5e4;
    /// m/s: the speed of sound at sea level.
    pub const SPEED: f64 = 343.0;
    /// m/s above which a multirotor formation speed gets a warning.
    pub const FORMATION_SPEED_WARNING: f64 = 50.0;
    /// m/s²: 10 g, beyond any multicopter autopilot's acceleration limit.
    pub const ACCELERATION: f64 = 98.0665;
    /// Per second: an autopilot's position or velocity gain (PX4's are
    /// 0.95-4; a multicopter's attitude loop does not follow 50).
    pub const GAIN: f64 = 50.0;
    /// Metres: a "UAV" bigger than this is not one.
    pub const UAV_RADIUS: f64 = 50.0;
}

/// The rules' findings as they are found: each rule says what is wrong
/// with the field at a path, in words for the operator.
#[derive(Default)]
pub struct Checker {
    out: Vec<Diagnostic>,
}

impl Checker {
    pub fn error(&mut self, path: FieldPath, message: impl Into<String>) {
        self.out.push(Diagnostic::error(path, message));
    }

    pub fn warning(&mut self, path: FieldPath, message: impl Into<String>) {
        self.out.push(Diagnostic::warning(path, message));
    }

    /// NaN and ±inf are legal TOML but never a legal length, time or gain.
    /// Checked once over the serialised tree so no float field can be missed.
    fn finite_everywhere(&mut self, mission: &Mission) {
        // A cylinder's centre or radius the file left out is NaN: the
        // obstacle's own check names it as missing.
        let mut mission = mission.clone();
        for o in &mut mission.obstacles {
            if o.center.iter().any(|v| v.is_nan()) {
                o.center = nalgebra::Point2::origin();
            }
            if o.radius.is_nan() {
                o.radius = 0.0;
            }
        }
        if let Ok(tree) = toml::Value::try_from(&mission) {
            self.finite_in(&FieldPath::root(), &tree);
        }
    }

    fn finite_in(&mut self, path: &FieldPath, value: &toml::Value) {
        match value {
            toml::Value::Float(x) if !x.is_finite() => {
                self.error(path.clone(), format!("must be a finite number, got {x}"));
            }
            toml::Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    self.finite_in(&path.index(i), item);
                }
            }
            toml::Value::Table(table) => {
                for (key, item) in table {
                    self.finite_in(&path.key(key), item);
                }
            }
            _ => {}
        }
    }

    /// An error when `value` exceeds what any UAV mission uses (`physical`).
    pub fn at_most(&mut self, path: FieldPath, value: f64, max: f64, unit: &str, why: &str) {
        if value.is_finite() && value > max {
            self.error(
                path,
                format!(
                    "{}{unit} is beyond {}{unit}: {why}",
                    compact(value),
                    compact(max)
                ),
            );
        }
    }

    /// Physically absurd values: errors that say why (`physical`).
    fn physical(&mut self, mission: &Mission) {
        use physical::*;
        let root = FieldPath::root();
        let b = &mission.bounds;
        for (key, [lo, hi]) in [("x", b.x), ("y", b.y)] {
            // On the end that is far off (the one a typo made huge).
            let end = usize::from(hi.abs() >= lo.abs());
            self.at_most(
                root.key("bounds").key(key).index(end),
                hi - lo,
                SPAN,
                " m",
                "the ENU frame is a local plane and no UAV mission spans more",
            );
        }
        self.at_most(
            root.key("bounds").key("z").index(1),
            b.z[1],
            CEILING,
            " m",
            "far above any UAV's ceiling",
        );
        let f = &mission.formation;
        self.at_most(
            root.key("formation").key("ground_speed"),
            f.ground_speed,
            SPEED,
            " m/s",
            "faster than sound",
        );
        if f.ground_speed.is_finite()
            && f.ground_speed > FORMATION_SPEED_WARNING
            && f.ground_speed <= SPEED
        {
            self.warning(
                root.key("formation").key("ground_speed"),
                format!(
                    "{} m/s is fast for a multirotor formation (typically 1-20 m/s): check the unit",
                    compact(f.ground_speed)
                ),
            );
        }
        self.at_most(
            root.key("formation").key("uav_radius"),
            f.uav_radius,
            UAV_RADIUS,
            " m",
            "no UAV is that large",
        );
        self.at_most(
            root.key("formation").key("comm_range"),
            f.comm_range,
            SPAN,
            " m",
            "no formation link reaches that far",
        );
    }

    /// `value > 0`; non-finite values are reported once, by `finite_everywhere`.
    pub fn positive(&mut self, path: FieldPath, value: f64, unit: &str) {
        if value.is_finite() && value <= 0.0 {
            self.error(
                path,
                format!("must be positive, got {}{unit}", compact(value)),
            );
        }
    }

    pub fn non_negative(&mut self, path: FieldPath, value: f64, unit: &str) {
        if value.is_finite() && value < 0.0 {
            self.error(
                path,
                format!("must not be negative, got {}{unit}", compact(value)),
            );
        }
    }

    pub fn at_least_one(&mut self, path: FieldPath, value: usize, what: &str) {
        if value == 0 {
            self.error(path, format!("needs at least one {what}, got 0"));
        }
    }

    /// `[lo, hi]` with lo < hi.
    pub fn range(&mut self, path: FieldPath, range: [f64; 2], unit: &str) -> bool {
        let [lo, hi] = range;
        if !(lo.is_finite() && hi.is_finite()) {
            return false;
        }
        if lo > hi {
            self.error(
                path,
                format!("is inverted: {}{unit} > {}{unit}", compact(lo), compact(hi)),
            );
            false
        } else if lo == hi {
            self.error(
                path,
                format!("is empty: both ends are {}{unit}", compact(lo)),
            );
            false
        } else {
            true
        }
    }

    /// An open interval (lo, hi].
    pub fn in_half_open(&mut self, path: FieldPath, value: f64, lo: f64, hi: f64) {
        if value.is_finite() && !(value > lo && value <= hi) {
            self.error(
                path,
                format!("must be in ({lo}, {hi}], got {}", compact(value)),
            );
        }
    }
}

/// A number for a message: shortest form, in scientific notation when huge
/// or tiny, so `1e300` is not printed as 301 digits.
pub fn compact(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `x` with `digits` decimals, in scientific notation when huge (a chart
/// label, a field shown in the inspector).
pub fn compact_digits(x: f64, digits: usize) -> String {
    if x.is_finite() && x.abs() >= 1e6 {
        format!("{x:.2e}")
    } else {
        format!("{x:.digits$}")
    }
}
