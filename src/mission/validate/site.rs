//! The site's rules: the origin, the bounds, start and goal (and whether the
//! formation fits there), the obstacles and the terrain.

use super::*;

/// Most vertices a footprint may have.
pub const MAX_FOOTPRINT_VERTICES: usize = 500;

/// Most obstacles a mission may have: every planner pairs them (θ-PSO's
/// IWPs, eq. 9, look at every pair), so 20,000 is 2·10⁸ pairs, seconds.
pub const MAX_OBSTACLES: usize = 20_000;

impl Checker {
    pub(super) fn origin(&mut self, path: &FieldPath, origin: &GeoOrigin) {
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

    pub(super) fn bounds(&mut self, path: &FieldPath, b: &Bounds) {
        self.range(path.key("x"), b.x, " m");
        self.range(path.key("y"), b.y, " m");
        if self.range(path.key("z"), b.z, " m") && b.z[0] < 0.0 {
            self.error(
                path.key("z"),
                format!("z_min is below the ground: {} m < 0 m", b.z[0]),
            );
        }
    }

    pub(super) fn route(&mut self, path: &FieldPath, mission: &Mission) {
        let Route { start, goal, via } = &mission.route;
        self.route_point(path.key("start"), "start", start, mission);
        self.route_point(path.key("goal"), "goal", goal, mission);
        if (goal - start).norm() < 1e-9 {
            self.error(path.key("goal"), "is the same point as the start");
        }
        for (i, v) in via.iter().enumerate() {
            self.via(path.key("via").index(i), v, mission);
        }
    }

    /// One `[[route.via]]`: a gate between two obstacles that exist (and
    /// are two), or a point in the bounds with a positive radius.
    fn via(&mut self, path: FieldPath, v: &crate::mission::Via, mission: &Mission) {
        match (&v.between, &v.point) {
            (Some(_), Some(_)) => self.error(
                path.key("point"),
                "a via is `between` two obstacles or a `point`, not both: write two [[route.via]]",
            ),
            (None, None) => self.error(
                path,
                "says nowhere to pass: give `between = [\"a\", \"b\"]` (two obstacles' names) \
                 or `point = [x, y, z]`",
            ),
            (Some(pair), None) => {
                for (k, name) in pair.iter().enumerate() {
                    if !mission.obstacles.iter().any(|o| &o.name == name) {
                        let near = crate::mission::nearest_name(
                            name,
                            mission.obstacles.iter().map(|o| o.name.as_str()),
                        );
                        self.error(
                            path.key("between").index(k),
                            format!(
                                "no obstacle is named '{name}'{}",
                                near.map(|n| format!(" (did you mean '{n}'?)"))
                                    .unwrap_or_default()
                            ),
                        );
                    }
                }
                if pair[0] == pair[1] {
                    self.error(
                        path.key("between").index(1),
                        "names the same obstacle twice: a gate is between two",
                    );
                }
                if v.radius.is_some() {
                    self.warning(
                        path.key("radius"),
                        "a gate's width is the gap between its obstacles: the radius is not used",
                    );
                }
            }
            (None, Some(p)) => {
                if p.iter().all(|c| c.is_finite()) {
                    let b = &mission.bounds;
                    if !b.contains(p) {
                        self.error(
                            path.key("point"),
                            format!(
                                "({}, {}, {}) is outside the bounds x {:?}, y {:?}, z {:?}",
                                compact(p.x),
                                compact(p.y),
                                compact(p.z),
                                b.x,
                                b.y,
                                b.z
                            ),
                        );
                    }
                } else {
                    self.error(path.key("point"), "must be three finite numbers");
                }
                if let Some(r) = v.radius {
                    self.positive(path.key("radius"), r, " m");
                }
            }
        }
    }

    pub(super) fn route_point(
        &mut self,
        path: FieldPath,
        what: &str,
        p: &Point3<f64>,
        mission: &Mission,
    ) {
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
    pub(super) fn formation_fits(
        &mut self,
        path: FieldPath,
        what: &str,
        p: &Point3<f64>,
        mission: &Mission,
    ) {
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
                .all(|o| finite(&[o.center.x, o.center.y, o.radius, o.height, o.base]))
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
                .all(|o| mission.prism(o).clearance(p) >= reach + f.uav_radius);
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

    /// The `[[obstacles]]` rows: their count, then each row's keys.
    ///
    /// Long (~195 lines) because it is one pass over the rows with one rule per key of an
    /// obstacle (stand-off, inspect, name, center and radius or footprint, heights, the
    /// bounds), each naming its field; the footprint's own rules are already `footprint`.
    pub(super) fn obstacles(&mut self, path: &FieldPath, mission: &Mission) {
        let (obstacles, bounds) = (&mission.obstacles, &mission.bounds);
        if obstacles.len() > MAX_OBSTACLES {
            self.error(
                path.clone(),
                format!(
                    "{} obstacles, more than {MAX_OBSTACLES}: the planners look at every pair; \
                     merge the rows of posts into footprints (a wall is one polygon)",
                    obstacles.len()
                ),
            );
            return;
        }
        // Each name's first obstacle, to name the other of a duplicate.
        let mut first: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
        for (i, o) in obstacles.iter().enumerate() {
            first.entry(o.name.as_str()).or_insert(i);
        }
        let mut last: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
        for (i, o) in obstacles.iter().enumerate() {
            last.insert(o.name.as_str(), i);
        }
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
            } else if let Some(j) = [first[o.name.as_str()], last[o.name.as_str()]]
                .into_iter()
                .find(|&j| j != i)
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
            if let Some(w) = &o.wire {
                self.wire(at.key("wire"), w, bounds);
                if o.inspect {
                    self.error(
                        at.key("inspect"),
                        format!(
                            "'{}' is a wire: eq. 8's stand-off is measured from a surface, \
                             inspect its towers instead",
                            o.name
                        ),
                    );
                }
                continue;
            }
            if o.footprint.is_empty() {
                for (key, unset) in [
                    ("center", !o.center.iter().all(|v| v.is_finite())),
                    ("radius", o.radius.is_nan()),
                ] {
                    if unset {
                        self.error(
                            at.key(key),
                            "missing or not a finite number: a cylinder needs `center` and `radius` (a \
                             building or a bay may give `footprint = [[x, y], …]` instead, a power \
                             line `wire = { from = [x, y, z], to = [x, y, z] }`)",
                        );
                    }
                }
            } else {
                self.footprint(at.key("footprint"), o, bounds);
            }
            if o.height.is_nan() {
                self.error(
                    at.key("height"),
                    "missing: every obstacle but a wire needs its top, metres above the ground",
                );
            }
            if let Some(side) = &o.inspect_side {
                match side.bearing() {
                    None => self.error(
                        at.key("inspect_side"),
                        format!(
                            "'{}' is no side: a bearing in degrees clockwise from north (90 is \
                             east) or a compass point ({})",
                            side.label(),
                            crate::mission::Side::NAMES
                                .iter()
                                .map(|(n, _, _)| format!("\"{n}\""))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ),
                    Some(_) if !o.inspect => self.warning(
                        at.key("inspect_side"),
                        format!(
                            "'{}' is not inspected (`inspect = true`): the side is not used",
                            o.name
                        ),
                    ),
                    Some(_) => {}
                }
            }
            self.positive(at.key("radius"), o.radius, " m");
            self.positive(at.key("height"), o.height, " m");
            self.non_negative(at.key("base"), o.base, " m");
            self.non_negative(at.key("clearance_above"), o.clearance_above, " m");
            if o.base.is_finite() && o.height.is_finite() && o.base >= o.height {
                self.error(
                    at.key("base"),
                    format!(
                        "{} m is at or above its top (height = {} m): the base is its underside",
                        compact(o.base),
                        compact(o.height)
                    ),
                );
            }
            if o.inspect
                && o.height > bounds.z[0]
                && [o.base, o.height, bounds.z[0], bounds.z[1]]
                    .iter()
                    .all(|v| v.is_finite())
                && mission.inspection_altitudes(o).is_none()
            {
                self.error(
                    at.key("inspect"),
                    format!(
                        "'{}' stands from {} to {} m; no altitude of the band z {:?} m (the \
                         centroid kept {} m inside it, half the shape's height) is level with \
                         its side: the UAV facing it would measure eq. 8 over its top",
                        o.name,
                        compact(o.base),
                        compact(o.height),
                        bounds.z,
                        compact(
                            mission
                                .formation
                                .slots
                                .iter()
                                .map(|s| s.z.abs())
                                .fold(0.0, f64::max)
                        ),
                    ),
                );
            }
            if !o.center.iter().all(|v| v.is_finite()) || !o.footprint.is_empty() {
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

    /// A wire: finite ends at or above the ground, a positive radius, some
    /// of it over the bounds (a span may run beyond them: a power line
    /// crosses the whole site).
    fn wire(&mut self, path: FieldPath, w: &crate::mission::Wire, bounds: &Bounds) {
        let mut finite = true;
        for (key, end) in [("from", &w.from), ("to", &w.to)] {
            for (k, v) in end.iter().enumerate() {
                if !v.is_finite() {
                    self.error(path.key(key).index(k), "must be a finite number");
                    finite = false;
                }
            }
            if end.z.is_finite() && end.z < 0.0 {
                self.error(
                    path.key(key).index(2),
                    format!(
                        "{} m is below the ground: a wire's z is its height above it",
                        end.z
                    ),
                );
            }
        }
        if !(w.radius.is_finite() && w.radius > 0.0) {
            self.error(
                path.key("radius"),
                format!("must be a positive number of metres, is {}", w.radius),
            );
        }
        if finite && (w.from - w.to).norm() < 1e-6 {
            self.error(
                path.key("to"),
                "is the same point as `from`: a span needs two ends",
            );
        }
        if !finite {
            return;
        }
        // Any point of the span over the box (its ends, or a crossing of a side).
        let (a, b) = (w.from.xy(), w.to.xy());
        let over = (0..=64).any(|k| bounds.contains_xy(&(a + (b - a) * (k as f64 / 64.0))));
        if !over {
            self.error(
                path,
                format!(
                    "runs outside the bounds x {:?}, y {:?}: no part of it is over them",
                    bounds.x, bounds.y
                ),
            );
        }
    }

    /// A footprint: a simple polygon of at least three distinct vertices
    /// with an area, inside the bounds (partly outside is a warning, as a
    /// cylinder's reach is).
    fn footprint(&mut self, path: FieldPath, o: &crate::mission::Obstacle, bounds: &Bounds) {
        use geo::{Area, Intersects, Validation};
        let v = &o.footprint;
        if !v.iter().all(|p| p.x.is_finite() && p.y.is_finite()) {
            return; // named by the finite check, located
        }
        let ring: Vec<geo::Coord<f64>> = v.iter().map(|p| geo::coord! { x: p.x, y: p.y }).collect();
        let polygon = geo::Polygon::new(geo::LineString::new(ring), Vec::new());
        if v.len() < 3 {
            self.error(path, format!("needs at least 3 vertices, got {}", v.len()));
            return;
        }
        if v.len() > MAX_FOOTPRINT_VERTICES {
            // Every clearance the planners take walks the outline.
            self.error(
                path,
                format!(
                    "has {} vertices, more than {MAX_FOOTPRINT_VERTICES}: simplify it (a survey \
                     tool's simplify to 0.1 m keeps a building's shape)",
                    v.len()
                ),
            );
            return;
        }
        if let Err(why) = polygon.check_validation() {
            let why = why.to_string().replace("exterior ring", "the outline");
            self.error(path, format!("is not a simple polygon: {why}"));
            return;
        }
        if polygon.unsigned_area() < 1e-6 {
            self.error(path, "is degenerate: its vertices enclose no area");
            return;
        }
        // Outside when it has no point in the box: a deck may cross the
        // whole site with every vertex beyond the bounds.
        let inside = v.iter().filter(|p| bounds.contains_xy(p)).count();
        let box_ = geo::Rect::new(
            geo::coord! { x: bounds.x[0], y: bounds.y[0] },
            geo::coord! { x: bounds.x[1], y: bounds.y[1] },
        );
        if !polygon.intersects(&box_) {
            self.error(
                path,
                format!(
                    "lies outside the bounds x {:?}, y {:?}: no part of it is inside",
                    bounds.x, bounds.y
                ),
            );
        } else if inside < v.len() {
            self.warning(path, "the footprint reaches outside the bounds");
        }
    }

    /// `[terrain]`: the file loaded, its pixels placed, the bounds on it.
    pub(super) fn terrain(&mut self, path: &FieldPath, mission: &Mission) {
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
            let inside = f.uav_radius - mission.prism(obstacle).clearance(&q);
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
