//! The formation's rules: its slots and their spacing, and the
//! reconfigurations (alignment, rotation, shrink) it may fly.

use super::*;
use crate::mission::model::ShapeChoice;

impl Checker {
    pub(super) fn formation(&mut self, path: &FieldPath, f: &Formation) {
        self.positive(path.key("uav_radius"), f.uav_radius, " m");
        self.positive(path.key("comm_range"), f.comm_range, " m");
        self.positive(path.key("ground_speed"), f.ground_speed, " m/s");
        if self.range(path.key("surface_distance"), f.surface_distance, " m") {
            self.non_negative(path.key("surface_distance"), f.surface_distance[0], " m");
        }
        self.positive(path.key("inspection_pass"), f.inspection_pass, " m");
        self.non_negative(path.key("safety_margin"), f.safety_margin, " m");
        self.at_most(
            path.key("safety_margin"),
            f.safety_margin,
            physical::UAV_RADIUS,
            " m",
            "a margin is room for tracking; no site leaves so much",
        );
        self.non_negative(path.key("obstacle_margin"), f.obstacle_margin, " m");
        self.at_most(
            path.key("obstacle_margin"),
            f.obstacle_margin,
            physical::UAV_RADIUS,
            " m",
            "a margin is room for tracking and fixes; no site leaves so much",
        );
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

    /// `[vehicle]`: every limit positive and physical, every UAV's own entry
    /// naming a UAV of the formation once.
    pub(super) fn vehicle(&mut self, path: &FieldPath, v: &Vehicle, f: &Formation) {
        let speeds = [
            ("max_speed", v.max_speed),
            ("max_climb_rate", v.max_climb_rate),
            ("max_descent_rate", v.max_descent_rate),
        ];
        let accelerations = [
            ("max_acceleration", v.max_acceleration),
            ("max_acceleration_up", v.max_acceleration_up),
            ("max_acceleration_down", v.max_acceleration_down),
        ];
        self.vehicle_limits(path, &speeds, &accelerations);
        for (key, gain) in [
            ("position_gain_xy", v.position_gain_xy),
            ("position_gain_z", v.position_gain_z),
            ("velocity_gain_xy", v.velocity_gain_xy),
            ("velocity_gain_z", v.velocity_gain_z),
        ] {
            self.positive(path.key(key), gain, " /s");
            self.at_most(
                path.key(key),
                gain,
                physical::GAIN,
                " /s",
                "a gain above 50 /s is faster than a multicopter's attitude loop follows",
            );
        }
        // An integral may be 0 (none: a PD loop), never negative.
        for (key, gain) in [
            ("velocity_integral_xy", v.velocity_integral_xy),
            ("velocity_integral_z", v.velocity_integral_z),
        ] {
            self.non_negative(path.key(key), gain, " /s²");
            self.at_most(
                path.key(key),
                gain,
                physical::GAIN,
                " /s²",
                "an integral gain above 50 /s² winds up faster than a multicopter follows",
            );
        }
        for (i, own) in v.uavs.iter().enumerate() {
            let at = path.key("uavs").index(i);
            if own.uav == 0 || own.uav > f.slots.len() {
                self.error(
                    at.key("uav"),
                    format!(
                        "there is no UAV {} (UAVs are numbered from 1; the formation has {})",
                        own.uav,
                        f.slots.len()
                    ),
                );
            } else if v.uavs[..i].iter().any(|o| o.uav == own.uav) {
                self.error(
                    at.key("uav"),
                    format!(
                        "UAV {} has limits of its own already (an earlier entry)",
                        own.uav
                    ),
                );
            }
            let speeds: Vec<(&str, f64)> = [
                ("max_speed", own.max_speed),
                ("max_climb_rate", own.max_climb_rate),
                ("max_descent_rate", own.max_descent_rate),
            ]
            .into_iter()
            .filter_map(|(k, x)| x.map(|x| (k, x)))
            .collect();
            let accelerations: Vec<(&str, f64)> = [
                ("max_acceleration", own.max_acceleration),
                ("max_acceleration_up", own.max_acceleration_up),
                ("max_acceleration_down", own.max_acceleration_down),
            ]
            .into_iter()
            .filter_map(|(k, x)| x.map(|x| (k, x)))
            .collect();
            self.vehicle_limits(&at, &speeds, &accelerations);
        }
        // The formation's pace is its slowest UAV's: a ground speed above a
        // UAV's speed limit is flown at that limit.
        let slowest = (0..f.slots.len())
            .map(|n| (n, v.limits(n).speed))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((n, speed)) = slowest
            && speed.is_finite()
            && speed > 0.0
            && f.ground_speed.is_finite()
            && f.ground_speed > speed
        {
            self.warning(
                FieldPath::root().key("formation").key("ground_speed"),
                format!(
                    "{} m/s is faster than UAV {}'s max_speed of {} m/s ([vehicle]): the \
                     formation flies at {} m/s at most",
                    compact(f.ground_speed),
                    n + 1,
                    compact(speed),
                    compact(speed)
                ),
            );
        }
    }

    /// Speeds positive and below the speed of sound; accelerations positive
    /// and below 10 g (no multicopter autopilot commands more).
    fn vehicle_limits(
        &mut self,
        path: &FieldPath,
        speeds: &[(&str, f64)],
        accelerations: &[(&str, f64)],
    ) {
        for &(key, value) in speeds {
            self.positive(path.key(key), value, " m/s");
            self.at_most(
                path.key(key),
                value,
                physical::SPEED,
                " m/s",
                "faster than sound; no multicopter flies so",
            );
        }
        for &(key, value) in accelerations {
            self.positive(path.key(key), value, " m/s²");
            self.at_most(
                path.key(key),
                value,
                physical::ACCELERATION,
                " m/s²",
                "above 10 g; no multicopter autopilot commands so much",
            );
        }
    }

    /// Eq. 7 on every pair of slots scaled by `scale`: 2 r_Q + the safety
    /// margin ≤ d ≤ d_com.
    pub(super) fn slot_spacing(&mut self, path: &FieldPath, f: &Formation, scale: f64, what: &str) {
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
                if d < f.closest_pair() {
                    self.error(
                        at,
                        format!(
                            "{what}: slots {} and {} are {d:.3} m apart, closer than \
                             2 r_Q + the safety margin = {:.3} m (eq. 7)",
                            i + 1,
                            j + 1,
                            f.closest_pair()
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

    pub(super) fn reconfiguration(
        &mut self,
        path: &FieldPath,
        r: &Reconfiguration,
        mission: &Mission,
    ) {
        self.in_half_open(path.key("shrink_scale"), r.shrink_scale, 0.0, 1.0);
        // Eq. 7 binds the scale only where a shrink flies it: the default
        // shape, or an IWP set to shrink without a scale of its own. Auto
        // picks its own scale (the largest that fits the gap and keeps 2 r_Q),
        // so a formation too tight for the default 0.5 is not refused for a
        // shrink nobody asked for.
        let used = r.default_shape == ShapeChoice::Shrink
            || r.waypoints
                .iter()
                .any(|w| w.shape == ShapeChoice::Shrink && w.scale.is_none());
        if used && r.shrink_scale > 0.0 && r.shrink_scale < 1.0 {
            self.slot_spacing(
                &path.key("shrink_scale"),
                &mission.formation,
                r.shrink_scale,
                "shrunk",
            );
        }
        self.positive(path.key("transition_distance"), r.transition_distance, " m");
        self.non_negative(path.key("hold_distance"), r.hold_distance, " m");
        // A change of shape or a hold longer than the whole operating box
        // cannot be flown inside it; unbounded, a value like 1e9 m made the
        // route stage's costs and the crossings' straights that long (a run
        // grew to 24 GB). The defaults always pass (18 m and 1 m on a fleet's
        // 10 m box are bounded, and θ-PSO shortens them to the path).
        let b = &mission.bounds;
        let diagonal = (b.x[1] - b.x[0]).hypot(b.y[1] - b.y[0]);
        let defaults = crate::mission::model::Reconfiguration::default();
        if diagonal.is_finite() && diagonal > 0.0 {
            for (field, value, default) in [
                (
                    "transition_distance",
                    r.transition_distance,
                    defaults.transition_distance,
                ),
                ("hold_distance", r.hold_distance, defaults.hold_distance),
            ] {
                if value.is_finite() && value > diagonal.max(default) {
                    self.error(
                        path.key(field),
                        format!(
                            "{} m is longer than the operating box (its x-y diagonal is {} m): \
                             no path inside the bounds could fly it",
                            compact(value),
                            compact((diagonal * 10.0).round() / 10.0)
                        ),
                    );
                }
            }
        }
        let names: Vec<&str> = mission.obstacles.iter().map(|o| o.name.as_str()).collect();
        for (i, w) in r.waypoints.iter().enumerate() {
            let at = path.key("waypoints").index(i);
            // A second entry for one IWP is never used: said on the first,
            // the one the designer shows (its Del removes both).
            if let Some(first) = r.waypoints[..i].iter().position(|v| {
                crate::mission::model::same_pair(&v.between, &w.between[0], &w.between[1])
            }) {
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
}
