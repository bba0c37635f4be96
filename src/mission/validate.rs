//! The rules a mission must follow, checked on the typed value.
//!
//! Every rule runs, so one pass reports every problem. Each finding names the
//! field it concerns; `Diagnostic::locate` later adds the file and line.
//! Over 700 lines: it is the list of every rule of every section, kept in
//! one place so a reader sees all that a mission must satisfy.

use nalgebra::Point3;

use super::diagnostic::Diagnostic;
use super::model::{
    Bounds, FlatloParams, FleetParams, Formation, GeoOrigin, Mission, Reconfiguration, Route,
    ThetaPsoParams,
};
use super::source::FieldPath;

use super::model::GRAVITY as G;

/// Checks every rule; errors and warnings in the order of the file.
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
    c.reconfiguration(
        &root.key("reconfiguration"),
        &mission.reconfiguration,
        mission,
    );
    c.theta_pso(&root.key("theta_pso"), &mission.theta_pso);
    c.flatlo(&root.key("flatlo"), &mission.flatlo);
    c.fleet(&root.key("fleet"), &mission.fleet, mission);
    c.obstacles(&root.key("obstacles"), mission);
    c.terrain(&root.key("terrain"), mission);
    c.physical(mission);
    c.out
}

/// What no UAV mission needs: beyond these a value is a typo or a unit
/// mistake, and the pipelines would spend minutes or gigabytes on it. The
/// ENU frame is a local tangent plane: a few hundred km across is already
/// far from flat, so a span of 1,000 km is refused.
mod physical {
    /// Metres across any axis of the bounds, and the FLATLO distances.
    pub const SPAN: f64 = 1e6;
    /// Metres above the ground: far above any UAV's ceiling (~20 km).
    pub const CEILING: f64 = 5e4;
    /// m/s: the speed of sound at sea level.
    pub const SPEED: f64 = 343.0;
    /// m/s above which a multirotor formation speed gets a warning.
    pub const FORMATION_SPEED_WARNING: f64 = 50.0;
    /// Metres: a "UAV" bigger than this is not one.
    pub const UAV_RADIUS: f64 = 50.0;
}

#[derive(Default)]
struct Checker {
    out: Vec<Diagnostic>,
}

impl Checker {
    fn error(&mut self, path: FieldPath, message: impl Into<String>) {
        self.out.push(Diagnostic::error(path, message));
    }

    fn warning(&mut self, path: FieldPath, message: impl Into<String>) {
        self.out.push(Diagnostic::warning(path, message));
    }

    /// NaN and ±inf are legal TOML but never a legal length, time or gain.
    /// Checked once over the serialised tree so no float field can be missed.
    fn finite_everywhere(&mut self, mission: &Mission) {
        if let Ok(tree) = toml::Value::try_from(mission) {
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
    fn at_most(&mut self, path: FieldPath, value: f64, max: f64, unit: &str, why: &str) {
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
        let p = &mission.flatlo;
        let flatlo = root.key("flatlo");
        self.at_most(
            flatlo.key("airspeed"),
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
                flatlo.key(key),
                value,
                SPAN,
                " m",
                "the ENU frame is a local plane and no squadron spans more",
            );
        }
        self.at_most(
            flatlo.key("altitude"),
            p.altitude,
            CEILING,
            " m",
            "far above any aircraft's ceiling",
        );
        self.at_most(
            root.key("fleet").key("altitude"),
            mission.fleet.altitude,
            CEILING,
            " m",
            "far above any UAV's ceiling",
        );
    }

    /// `value > 0`; non-finite values are reported once, by `finite_everywhere`.
    fn positive(&mut self, path: FieldPath, value: f64, unit: &str) {
        if value.is_finite() && value <= 0.0 {
            self.error(
                path,
                format!("must be positive, got {}{unit}", compact(value)),
            );
        }
    }

    fn non_negative(&mut self, path: FieldPath, value: f64, unit: &str) {
        if value.is_finite() && value < 0.0 {
            self.error(
                path,
                format!("must not be negative, got {}{unit}", compact(value)),
            );
        }
    }

    fn at_least_one(&mut self, path: FieldPath, value: usize, what: &str) {
        if value == 0 {
            self.error(path, format!("needs at least one {what}, got 0"));
        }
    }

    /// `[lo, hi]` with lo < hi.
    fn range(&mut self, path: FieldPath, range: [f64; 2], unit: &str) -> bool {
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
    fn in_half_open(&mut self, path: FieldPath, value: f64, lo: f64, hi: f64) {
        if value.is_finite() && !(value > lo && value <= hi) {
            self.error(
                path,
                format!("must be in ({lo}, {hi}], got {}", compact(value)),
            );
        }
    }

    fn origin(&mut self, path: &FieldPath, origin: &GeoOrigin) {
        if origin.latitude.abs() > 90.0 {
            self.error(
                path.key("latitude"),
                format!("must be within ±90°, got {}", origin.latitude),
            );
        }
        if origin.longitude.abs() > 180.0 {
            self.error(
                path.key("longitude"),
                format!("must be within ±180°, got {}", origin.longitude),
            );
        }
    }

    fn bounds(&mut self, path: &FieldPath, b: &Bounds) {
        self.range(path.key("x"), b.x, " m");
        self.range(path.key("y"), b.y, " m");
        if self.range(path.key("z"), b.z, " m") && b.z[0] < 0.0 {
            self.error(
                path.key("z"),
                format!("z_min is below the ground: {} m < 0 m", b.z[0]),
            );
        }
    }

    fn route(&mut self, path: &FieldPath, mission: &Mission) {
        let Route { start, goal } = &mission.route;
        self.route_point(path.key("start"), "start", start, mission);
        self.route_point(path.key("goal"), "goal", goal, mission);
        if (goal - start).norm() < 1e-9 {
            self.error(path.key("goal"), "is the same point as the start");
        }
    }

    fn route_point(&mut self, path: FieldPath, what: &str, p: &Point3<f64>, mission: &Mission) {
        if !p.iter().all(|v| v.is_finite()) {
            return;
        }
        // Each coordinate outside its range is an error on that coordinate.
        let b = &mission.bounds;
        for (k, (v, [lo, hi], range)) in [
            (p.x, b.x, "the bounds' x"),
            (p.y, b.y, "the bounds' y"),
            (p.z, b.z, "the altitude band z"),
        ]
        .into_iter()
        .enumerate()
        {
            if !(lo..=hi).contains(&v) {
                self.error(
                    path.index(k),
                    format!(
                        "{what} ({}, {}, {}) is outside the bounds: {} m is not in {range} [{}, {}] m",
                        p.x,
                        p.y,
                        p.z,
                        compact(v),
                        compact(lo),
                        compact(hi)
                    ),
                );
            }
        }
        self.formation_fits(path, what, p, mission);
    }

    /// The formation standing at `p` in its nominal shape: an error when no
    /// heading keeps every UAV inside the bounds and r_Q clear of every
    /// obstacle (naming the UAV and by how much, at the best heading), a
    /// warning when only some headings do (the plan must leave that way).
    fn formation_fits(&mut self, path: FieldPath, what: &str, p: &Point3<f64>, mission: &Mission) {
        let f = &mission.formation;
        // Non-finite numbers have errors of their own; the fit means nothing then.
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let b = &mission.bounds;
        if f.slots.is_empty()
            || !f.uav_radius.is_finite()
            || !finite(p.coords.as_slice())
            || !f.slots.iter().all(|s| finite(s.as_slice()))
            || !finite(&[b.x[0], b.x[1], b.y[0], b.y[1], b.z[0], b.z[1]])
            || !mission
                .obstacles
                .iter()
                .all(|o| finite(&[o.center.x, o.center.y, o.radius, o.height]))
        {
            return;
        }
        // Every UAV within `reach` of the centroid: clear of everything by
        // that much, every heading fits (the usual case, decided at once).
        let reach = f.slots.iter().map(|o| o.xy().norm()).fold(0.0, f64::max);
        let roomy = mission.bounds.horizontal_margin(p) >= reach
            && mission
                .obstacles
                .iter()
                .all(|o| mission.cylinder(o).clearance(p) >= reach + f.uav_radius);
        if roomy {
            return;
        }
        let misfit = |heading: f64| fit_at(mission, p, heading);
        let headings: Vec<(f64, Misfit)> = (0..HEADINGS)
            .map(|k| {
                let degrees = 360.0 * k as f64 / HEADINGS as f64;
                (degrees, misfit(degrees.to_radians()))
            })
            .collect();
        let fitting = headings.iter().filter(|(_, m)| m.depth <= 0.0).count();
        if fitting == headings.len() {
            return;
        }
        let Some((best, worst)) = headings
            .iter()
            .min_by(|a, b| a.1.depth.total_cmp(&b.1.depth))
            .map(|(h, m)| (*h, m.clone()))
        else {
            return;
        };
        if fitting == 0 {
            self.error(
                path,
                format!(
                    "the formation does not fit at the {what} in any heading: even facing {best:.0}° \
                     (from east, anticlockwise), UAV {} is {:.2} m {}",
                    worst.uav + 1,
                    worst.depth,
                    worst.what
                ),
            );
        } else {
            self.warning(
                path,
                format!(
                    "the formation fits at the {what} only in {fitting} of {HEADINGS} headings (facing \
                     {best:.0}° from east, anticlockwise, is one): the plan must leave that way"
                ),
            );
        }
    }

    fn formation(&mut self, path: &FieldPath, f: &Formation) {
        self.positive(path.key("uav_radius"), f.uav_radius, " m");
        self.positive(path.key("comm_range"), f.comm_range, " m");
        self.positive(path.key("ground_speed"), f.ground_speed, " m/s");
        if self.range(path.key("surface_distance"), f.surface_distance, " m") {
            self.non_negative(path.key("surface_distance"), f.surface_distance[0], " m");
        }
        self.positive(path.key("inspection_pass"), f.inspection_pass, " m");
        if f.comm_range.is_finite() && f.comm_range < 2.0 * f.uav_radius {
            self.error(
                path.key("comm_range"),
                format!(
                    "{} m is less than 2 r_Q = {} m: no two UAVs can satisfy eq. 7",
                    f.comm_range,
                    2.0 * f.uav_radius
                ),
            );
        }
        let slots = path.key("slots");
        if f.slots.is_empty() {
            self.error(slots.clone(), "needs at least one slot");
        }
        self.slot_spacing(&slots, f, 1.0, "slots");
        let centroid = f.slot_centroid();
        // Slots are written to the millimetre: a centroid within one of the
        // origin is at it.
        if centroid.norm() > 1e-3 {
            self.warning(
                slots,
                format!(
                    "the slots' centroid is at ({:.3}, {:.3}, {:.3}), not at the origin; \
                     the planned path is for the centroid (eq. 6)",
                    centroid.x, centroid.y, centroid.z
                ),
            );
        }
    }

    /// Eq. 7 on every pair of slots scaled by `scale`: 2 r_Q ≤ d ≤ d_com.
    fn slot_spacing(&mut self, path: &FieldPath, f: &Formation, scale: f64, what: &str) {
        for i in 0..f.slots.len() {
            for j in (i + 1)..f.slots.len() {
                let d = scale * (f.slots[i] - f.slots[j]).norm();
                if !d.is_finite() {
                    continue;
                }
                let at = if what == "slots" {
                    path.index(j)
                } else {
                    path.clone()
                };
                if d < 2.0 * f.uav_radius {
                    self.error(
                        at,
                        format!(
                            "{what}: slots {} and {} are {d:.3} m apart, closer than \
                             2 r_Q = {:.3} m (eq. 7)",
                            i + 1,
                            j + 1,
                            2.0 * f.uav_radius
                        ),
                    );
                } else if d > f.comm_range {
                    self.error(
                        at,
                        format!(
                            "{what}: slots {} and {} are {d:.3} m apart, beyond the \
                             communication range d_com = {} m (eq. 7)",
                            i + 1,
                            j + 1,
                            f.comm_range
                        ),
                    );
                }
            }
        }
    }

    fn reconfiguration(&mut self, path: &FieldPath, r: &Reconfiguration, mission: &Mission) {
        self.in_half_open(path.key("shrink_scale"), r.shrink_scale, 0.0, 1.0);
        if r.shrink_scale > 0.0 && r.shrink_scale < 1.0 {
            self.slot_spacing(
                &path.key("shrink_scale"),
                &mission.formation,
                r.shrink_scale,
                "shrunk",
            );
        }
        self.positive(path.key("transition_distance"), r.transition_distance, " m");
        self.non_negative(path.key("hold_distance"), r.hold_distance, " m");
        let names: Vec<&str> = mission.obstacles.iter().map(|o| o.name.as_str()).collect();
        for (i, w) in r.waypoints.iter().enumerate() {
            let at = path.key("waypoints").index(i);
            // A second entry for one IWP is never used: said on the first,
            // the one the designer shows (its Del removes both).
            if let Some(first) = r.waypoints[..i]
                .iter()
                .position(|v| super::model::same_pair(&v.between, &w.between[0], &w.between[1]))
            {
                self.error(
                    path.key("waypoints").index(first),
                    format!(
                        "entry {} names this IWP ('{}' ↔ '{}') again and is never used: \
                         delete it in the file (Del on the IWP deletes both)",
                        i + 1,
                        w.between[0],
                        w.between[1]
                    ),
                );
                continue;
            }
            for name in &w.between {
                if !names.contains(&name.as_str()) {
                    self.error(
                        at.key("between"),
                        format!("there is no obstacle named '{name}'"),
                    );
                }
            }
            if w.between[0] == w.between[1] {
                self.error(
                    at.key("between"),
                    format!(
                        "names '{}' twice; an IWP lies between two obstacles",
                        w.between[0]
                    ),
                );
            }
            if let Some(scale) = w.scale {
                self.in_half_open(at.key("scale"), scale, 0.0, 1.0);
                if scale > 0.0 && scale < 1.0 {
                    self.slot_spacing(&at.key("scale"), &mission.formation, scale, "shrunk");
                }
            }
        }
    }

    fn theta_pso(&mut self, path: &FieldPath, p: &ThetaPsoParams) {
        self.at_least_one(path.key("swarm_size"), p.swarm_size, "particle");
        self.at_least_one(path.key("waypoints"), p.waypoints, "waypoint");
        self.at_least_one(path.key("iterations"), p.iterations, "iteration");
        if p.segments < p.waypoints + 1 {
            self.error(
                path.key("segments"),
                format!(
                    "{} segments cannot split a path through {} waypoints; \
                     needs at least {}",
                    p.segments,
                    p.waypoints,
                    p.waypoints + 1
                ),
            );
        }
        for (key, value) in [
            ("inertia", p.inertia),
            ("cognitive", p.cognitive),
            ("social", p.social),
            ("weight_length", p.weight_length),
            ("weight_obstacle", p.weight_obstacle),
            ("weight_altitude", p.weight_altitude),
            ("weight_waypoints", p.weight_waypoints),
            ("weight_bounds", p.weight_bounds),
            ("weight_turning", p.weight_turning),
            ("clearance_margin", p.clearance_margin),
        ] {
            self.non_negative(path.key(key), value, "");
        }
        self.positive(path.key("ground_penalty"), p.ground_penalty, "");
        if p.inertia >= 1.0 {
            self.warning(
                path.key("inertia"),
                format!(
                    "w = {} ≥ 1 lets the swarm's velocities grow without bound",
                    p.inertia
                ),
            );
        }
        if p.weight_obstacle == 0.0 {
            self.warning(
                path.key("weight_obstacle"),
                "is 0: the planner will ignore obstacles (the result is still verified)",
            );
        }
    }

    /// `[terrain]`: the file loaded, its pixels placed, the bounds on it; and
    /// what `cost = "spso"` and the spherical encoding need.
    fn terrain(&mut self, path: &FieldPath, mission: &Mission) {
        use super::model::{CostKind, Encoding};
        let p = &mission.theta_pso;
        let at = FieldPath::root().key("theta_pso");
        if p.cost == CostKind::Spso {
            if mission.terrain.is_none() {
                self.error(
                    at.key("cost"),
                    "\"spso\" needs a [terrain] height map (its J3 and J4 read the ground)",
                );
            }
            let most = super::SPSO_MAX_NODES;
            if p.waypoints > most {
                self.error(
                    at.key("waypoints"),
                    format!("the SPSO cost takes at most {most} free nodes"),
                );
            }
        } else if p.encoding == Encoding::Spherical {
            self.error(
                at.key("encoding"),
                "\"spherical\" encodes the SPSO benchmark's paths: it needs cost = \"spso\"",
            );
        }
        let Some(t) = &mission.terrain else { return };
        for (i, v) in t.pixel_size.iter().enumerate() {
            if *v == 0.0 {
                self.error(path.key("pixel_size").index(i), "must not be 0");
            }
        }
        match &t.map.0 {
            None => self.error(path.key("file"), "was not loaded"),
            Some(Err(e)) => self.error(path.key("file"), e.clone()),
            Some(Ok(map)) => {
                let b = &mission.bounds;
                // The bounds must lie on the map (half a pixel beyond the
                // outer centres still reads the edge pixel).
                let half = [map.pixel[0].abs() / 2.0, map.pixel[1].abs() / 2.0];
                let [x0, x1] = map.x_extent();
                let [y0, y1] = map.y_extent();
                if b.x[0] < x0 - half[0]
                    || b.x[1] > x1 + half[0]
                    || b.y[0] < y0 - half[1]
                    || b.y[1] > y1 + half[1]
                {
                    self.error(
                        path.key("origin"),
                        format!(
                            "the map covers x [{}, {}], y [{}, {}] (pixel centres), \
                             not the bounds x {:?}, y {:?}",
                            compact(x0),
                            compact(x1),
                            compact(y0),
                            compact(y1),
                            b.x,
                            b.y
                        ),
                    );
                }
            }
        }
    }

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
    }

    /// Long (~130 lines): one rule per key of `[fleet]`, in the order of the section.
    fn fleet(&mut self, path: &FieldPath, p: &FleetParams, mission: &Mission) {
        let bounds = &mission.bounds;
        let obstacles = &mission.obstacles;
        self.at_least_one(path.key("agents"), p.agents, "agent");
        self.at_least_one(path.key("swarm_size"), p.swarm_size, "particle");
        self.at_least_one(path.key("iterations"), p.iterations, "iteration");
        for (key, value, unit) in [
            ("rho", p.rho, ""),
            ("sigma", p.sigma, ""),
            ("safety_distance", p.safety_distance, " m"),
            ("detection_range", p.detection_range, " m"),
            ("neighbourhood", p.neighbourhood, " m"),
            ("step_max", p.step_max, " m"),
            ("replan_period", p.replan_period, " s"),
            ("altitude", p.altitude, " m"),
            ("sim_step", p.sim_step, " s"),
            ("duration", p.duration, " s"),
            ("mass", p.mass, " kg"),
            ("max_thrust", p.max_thrust, " N"),
            ("max_tilt_deg", p.max_tilt_deg, "°"),
            ("tolerance", p.tolerance, ""),
        ] {
            self.positive(path.key(key), value, unit);
        }
        self.non_negative(path.key("target_distance"), p.target_distance, " m");
        for (i, v) in p.inertia_diag.iter().enumerate() {
            self.positive(path.key("inertia_diag").index(i), *v, " kg·m²");
        }
        for (key, gains) in [
            ("position_gains", p.position_gains),
            ("attitude_gains", p.attitude_gains),
        ] {
            for (i, v) in gains.iter().enumerate() {
                self.positive(path.key(key).index(i), *v, "");
            }
        }
        if p.max_thrust.is_finite() && p.mass > 0.0 && p.max_thrust <= p.mass * G {
            self.error(
                path.key("max_thrust"),
                format!(
                    "{} N cannot lift {} kg (weight {:.2} N)",
                    p.max_thrust,
                    p.mass,
                    p.mass * G
                ),
            );
        }
        if p.max_tilt_deg >= 90.0 {
            self.error(
                path.key("max_tilt_deg"),
                format!("must be below 90°, got {}°", p.max_tilt_deg),
            );
        }
        if p.replan_period < p.sim_step {
            self.error(
                path.key("replan_period"),
                format!(
                    "τ = {} s is shorter than the simulation step {} s",
                    p.replan_period, p.sim_step
                ),
            );
        }
        self.fleet_distances(path, p);
        if !p.initial_positions.is_empty() && p.initial_positions.len() != p.agents {
            self.error(
                path.key("initial_positions"),
                format!(
                    "gives {} positions for {} agents",
                    p.initial_positions.len(),
                    p.agents
                ),
            );
        }
        for (i, q) in p.initial_positions.iter().enumerate() {
            if !bounds.contains_xy(q) {
                self.error(
                    path.key("initial_positions").index(i),
                    format!("({}, {}) is outside the bounds", q.x, q.y),
                );
            }
        }
        let mut previous = f64::NEG_INFINITY;
        for (i, t) in p.targets.iter().enumerate() {
            let at = path.key("targets").index(i);
            self.non_negative(at.key("time"), t.time, " s");
            if t.time < previous {
                self.error(
                    at.key("time"),
                    format!(
                        "targets must be in time order: {} s comes after {previous} s",
                        t.time
                    ),
                );
            }
            previous = t.time;
            if !bounds.contains_xy(&t.position) {
                self.error(
                    at.key("position"),
                    format!("({}, {}) is outside the bounds", t.position.x, t.position.y),
                );
            }
            for o in obstacles.iter().filter(|o| o.height > p.altitude) {
                let gap = (o.center - t.position).norm() - o.radius;
                if gap < p.safety_distance {
                    self.warning(
                        at.key("position"),
                        format!(
                            "({}, {}) is within the safety distance c = {} m of obstacle '{}' \
                             ({gap:.2} m from it): the agents cannot form around it",
                            t.position.x, t.position.y, p.safety_distance, o.name
                        ),
                    );
                }
            }
        }
        for (i, push) in p.pushes.iter().enumerate() {
            let at = path.key("pushes").index(i);
            if push.agent >= p.agents {
                self.error(
                    at.key("agent"),
                    format!(
                        "there are only {} agents (0-based index {})",
                        p.agents, push.agent
                    ),
                );
            }
            self.non_negative(at.key("time"), push.time, " s");
        }
    }

    /// The desired distances must be a symmetric n×n matrix that keeps every
    /// pair at least the safety distance c apart (fleet paper, eq. 5).
    fn fleet_distances(&mut self, path: &FieldPath, p: &FleetParams) {
        let n = p.agents;
        let at = path.key("distances");
        if p.distances.is_empty() {
            if n >= 2 {
                let side = 2.0 * p.target_distance * (std::f64::consts::PI / n as f64).sin();
                if side < p.safety_distance {
                    self.error(
                        path.key("target_distance"),
                        format!(
                            "{n} agents at {} m from the target are {side:.3} m apart, \
                             closer than the safety distance c = {} m",
                            p.target_distance, p.safety_distance
                        ),
                    );
                }
            }
            return;
        }
        if p.distances.len() != n || p.distances.iter().any(|row| row.len() != n) {
            self.error(at, format!("must be a {n}×{n} matrix (one row per agent)"));
            return;
        }
        for i in 0..n {
            if p.distances[i][i] != 0.0 {
                self.error(at.index(i).index(i), "the diagonal must be 0");
            }
            for j in (i + 1)..n {
                let (a, b) = (p.distances[i][j], p.distances[j][i]);
                if a != b {
                    self.error(
                        at.index(i).index(j),
                        format!("is {a} but distances[{j}][{i}] is {b}; must be symmetric"),
                    );
                } else if a < p.safety_distance {
                    self.error(
                        at.index(i).index(j),
                        format!(
                            "{a} m is below the safety distance c = {} m",
                            p.safety_distance
                        ),
                    );
                }
            }
        }
    }

    fn obstacles(&mut self, path: &FieldPath, mission: &Mission) {
        let (obstacles, bounds) = (&mission.obstacles, &mission.bounds);
        for (i, o) in obstacles.iter().enumerate() {
            let at = path.index(i);
            if let Some(band) = o.stand_off
                && self.range(at.key("stand_off"), band, " m")
            {
                self.non_negative(at.key("stand_off"), band[0], " m");
            }
            if o.inspect {
                let [d_min, _] = o.stand_off_band(&mission.formation);
                if o.height.is_finite() && o.height <= bounds.z[0] {
                    self.error(
                        at.key("inspect"),
                        format!(
                            "'{}' is {} m tall, below the altitude band's floor z_min = {} m: \
                             the formation cannot fly beside its surface (eq. 8)",
                            o.name, o.height, bounds.z[0]
                        ),
                    );
                }
                if d_min < mission.formation.uav_radius {
                    self.warning(
                        at.key("stand_off"),
                        format!(
                            "the stand-off band starts at {d_min} m, inside the UAV's safe radius \
                             r_Q = {} m: clearance (≥ r_Q) binds first",
                            mission.formation.uav_radius
                        ),
                    );
                }
            }
            if o.name.trim().is_empty() {
                self.error(at.key("name"), "must not be empty");
            } else if let Some(j) = obstacles
                .iter()
                .enumerate()
                .position(|(j, p)| j != i && p.name == o.name)
            {
                // Both carry the error: the one just renamed shows it too.
                self.error(
                    at.key("name"),
                    format!(
                        "'{}' is also the name of obstacle {}; names must be unique",
                        o.name,
                        j + 1
                    ),
                );
            }
            self.positive(at.key("radius"), o.radius, " m");
            self.positive(at.key("height"), o.height, " m");
            if !o.center.iter().all(|v| v.is_finite()) {
                continue;
            }
            if !bounds.contains_xy(&o.center) {
                self.error(
                    at.key("center"),
                    format!(
                        "({}, {}) is outside the bounds x {:?}, y {:?}",
                        o.center.x, o.center.y, bounds.x, bounds.y
                    ),
                );
            } else if o.radius > 0.0 {
                let inside = o.center.x - o.radius >= bounds.x[0]
                    && o.center.x + o.radius <= bounds.x[1]
                    && o.center.y - o.radius >= bounds.y[0]
                    && o.center.y + o.radius <= bounds.y[1];
                if !inside {
                    self.warning(at.key("radius"), "the cylinder reaches outside the bounds");
                }
            }
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

/// Headings the start and the goal are tried in, evenly round.
const HEADINGS: usize = 72;

/// How badly a formation fails to fit at one heading: the UAV that fails
/// worst, by how much (metres; ≤ 0 when every UAV fits), and what it hits.
#[derive(Debug, Clone)]
struct Misfit {
    uav: usize,
    depth: f64,
    what: String,
}

/// The nominal formation with its centroid at `p`, turned to `heading`
/// (radians from east, anticlockwise): the worst UAV's distance outside the
/// x-y bounds or inside r_Q of an obstacle.
fn fit_at(mission: &Mission, p: &Point3<f64>, heading: f64) -> Misfit {
    let f = &mission.formation;
    let b = &mission.bounds;
    let (sin, cos) = heading.sin_cos();
    let mut worst = Misfit {
        uav: 0,
        depth: f64::NEG_INFINITY,
        what: String::new(),
    };
    for (n, o) in f.slots.iter().enumerate() {
        let q = Point3::new(
            p.x + cos * o.x - sin * o.y,
            p.y + sin * o.x + cos * o.y,
            p.z + o.z,
        );
        let sides = [
            (b.x[0] - q.x, "west of x min"),
            (q.x - b.x[1], "east of x max"),
            (b.y[0] - q.y, "south of y min"),
            (q.y - b.y[1], "north of y max"),
        ];
        for (out, side) in sides {
            if out > worst.depth {
                worst = Misfit {
                    uav: n,
                    depth: out,
                    what: format!("outside the bounds ({side})"),
                };
            }
        }
        for obstacle in &mission.obstacles {
            let inside = f.uav_radius - mission.cylinder(obstacle).clearance(&q);
            if inside > worst.depth {
                worst = Misfit {
                    uav: n,
                    depth: inside,
                    what: format!("inside r_Q of '{}'", obstacle.name),
                };
            }
        }
    }
    worst
}
