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
