//! `[fleet]`'s rules: its agents and their PSO, the formation they form
//! (d_ij^d that a plane can hold), its targets (a point to form around, or
//! one per agent), its network. `section.rs` registers them with the
//! file's (`mission::SECTION_RULES`).

use crate::mission::GRAVITY as G;
use crate::mission::{Checker, FieldPath, FleetParams, Mission, compact};

impl Checker {
    /// Long (~130 lines): one rule per key of `[fleet]`, in the order of the section.
    pub(super) fn fleet(&mut self, path: &FieldPath, p: &FleetParams, mission: &Mission) {
        let bounds = &mission.bounds;
        self.at_most(
            path.key("altitude"),
            p.altitude,
            crate::mission::physical::CEILING,
            " m",
            "far above any UAV's ceiling",
        );
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
            ("duration", p.duration.unwrap_or(1.0), " s"),
            ("mass", p.mass, " kg"),
            ("max_thrust", p.max_thrust, " N"),
            ("max_tilt_deg", p.max_tilt_deg, "°"),
            ("tolerance", p.tolerance, ""),
        ] {
            self.positive(path.key(key), value, unit);
        }
        self.non_negative(path.key("target_distance"), p.target_distance, " m");
        self.fleet_network(&path.key("network"), p);
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
        self.fleet_targets(path, p, mission);
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

    /// `[[fleet.targets]]`: in time order; each a `position` or one point
    /// per agent (`positions`), in the bounds, clear of the obstacles in the
    /// flight plane by c, a target's points c apart.
    fn fleet_targets(&mut self, path: &FieldPath, p: &FleetParams, mission: &Mission) {
        let (bounds, obstacles) = (&mission.bounds, &mission.obstacles);
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
            let around = t.position.iter().all(|v| v.is_finite());
            let each = !t.positions.is_empty();
            if around && each {
                self.error(
                    at.key("positions"),
                    "a target is a `position` the fleet forms around or `positions`, one per \
                     agent, not both",
                );
            } else if !around && !each {
                self.error(
                    at.key("position"),
                    "missing: give `position = [x, y]` (the fleet forms around it) or \
                     `positions = [[x, y], …]` (one per agent)",
                );
            } else if each && t.positions.len() != p.agents {
                self.error(
                    at.key("positions"),
                    format!(
                        "gives {} points for {} agents: one per agent",
                        t.positions.len(),
                        p.agents
                    ),
                );
            }
            let points: Vec<(FieldPath, nalgebra::Point2<f64>)> = if each {
                t.positions
                    .iter()
                    .enumerate()
                    .map(|(j, q)| (at.key("positions").index(j), *q))
                    .collect()
            } else if around {
                vec![(at.key("position"), t.position)]
            } else {
                Vec::new()
            };
            for (field, q) in points {
                if !bounds.contains_xy(&q) {
                    self.error(
                        field.clone(),
                        format!("({}, {}) is outside the bounds", q.x, q.y),
                    );
                }
                let own = if each {
                    "an agent cannot stop there"
                } else {
                    "the agents cannot form around it"
                };
                for o in obstacles.iter().filter(|o| o.spans(p.altitude)) {
                    let gap = o.prism().outward(&q);
                    if gap < p.safety_distance {
                        self.warning(
                            field.clone(),
                            format!(
                                "({}, {}) is within the safety distance c = {} m of obstacle '{}' \
                                 ({gap:.2} m from it): {own}",
                                q.x, q.y, p.safety_distance, o.name
                            ),
                        );
                    }
                }
            }
            if each {
                for a in 0..t.positions.len() {
                    for b in a + 1..t.positions.len() {
                        let d = (t.positions[a] - t.positions[b]).norm();
                        if d < p.safety_distance {
                            self.error(
                                at.key("positions").index(b),
                                format!(
                                    "is {d:.2} m from point {}: two agents there would be closer \
                                     than c = {} m",
                                    a + 1,
                                    p.safety_distance
                                ),
                            );
                        }
                    }
                }
            }
        }
    }

    /// The desired distances must be a symmetric n×n matrix that keeps every
    /// pair at least the safety distance c apart (fleet paper, eq. 5), and a
    /// formation must be able to stand: the agents in the plane, each d_ip^d
    /// from the target (eq. 6), every distance within `fleet.tolerance` of
    /// its value ([`Self::fleet_formable`]).
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
        let mut sound = true;
        for i in 0..n {
            if p.distances[i][i] != 0.0 {
                self.error(at.index(i).index(i), "the diagonal must be 0");
                sound = false;
            }
            for j in (i + 1)..n {
                let (a, b) = (p.distances[i][j], p.distances[j][i]);
                if a != b {
                    self.error(
                        at.index(i).index(j),
                        format!("is {a} but distances[{j}][{i}] is {b}; must be symmetric"),
                    );
                    sound = false;
                } else if a < p.safety_distance {
                    self.error(
                        at.index(i).index(j),
                        format!(
                            "{a} m is below the safety distance c = {} m",
                            p.safety_distance
                        ),
                    );
                    sound = false;
                }
            }
        }
        if sound && p.tolerance > 0.0 && p.target_distance >= 0.0 {
            self.fleet_formable(path, p);
        }
    }

    /// A formation no fleet can stand in is refused, naming its entries
    /// (docs/fleet.md, "Which distances a formation can have"): the agents
    /// must have a place in the plane, and then, with the target d_ip^d from
    /// each, on its circle. First every triangle of them must close (the
    /// triangle inequality); then, placed in the plane from the farthest two
    /// and the one farthest off their line, every other distance must come
    /// out within the tolerance `formed` allows it, `fleet.tolerance` ×
    /// max(d, c).
    fn fleet_formable(&mut self, path: &FieldPath, p: &FleetParams) {
        let n = p.agents;
        // Point n is the target.
        let d = |i: usize, j: usize| -> f64 {
            match (i == n, j == n) {
                (true, true) => 0.0,
                (true, false) | (false, true) => p.target_distance,
                (false, false) => p.distances[i][j],
            }
        };
        let name = |i: usize| {
            if i == n {
                "the target".to_owned()
            } else {
                format!("agent {}", i + 1)
            }
        };
        let entry = |i: usize, j: usize| {
            if i == n || j == n {
                "target_distance".to_owned()
            } else {
                format!("distances[{}][{}]", i.min(j), i.max(j))
            }
        };
        let field = |i: usize, j: usize| {
            if i == n || j == n {
                path.key("target_distance")
            } else {
                path.key("distances").index(i.min(j)).index(i.max(j))
            }
        };
        let slack = |want: f64| p.tolerance * want.max(p.safety_distance);
        // The agents alone, then with the target.
        for (points, around) in [(n, ""), (n + 1, " with the target")] {
            let Some((at, why)) = unformable(points, &d, &slack, &name, &entry) else {
                continue;
            };
            let circle = if around.is_empty() {
                String::new()
            } else {
                format!(
                    "; every agent is target_distance = {} m from the target, so the agents \
                     must lie on a circle of that radius",
                    compact(p.target_distance)
                )
            };
            self.error(
                field(at[0], at[1]),
                format!("no formation in the plane has these distances{around}: {why}{circle}"),
            );
            return;
        }
    }

    /// `[fleet.network]`: a range that carries, a latency within the run, a
    /// loss that leaves some messages, links and own clocks of real agents.
    fn fleet_network(&mut self, path: &FieldPath, p: &FleetParams) {
        let n = &p.network;
        if let Some(range) = n.range {
            self.positive(path.key("range"), range, " m");
        }
        if !(n.loss.is_finite() && (0.0..1.0).contains(&n.loss)) {
            self.error(
                path.key("loss"),
                format!(
                    "must be a probability in [0, 1) (1 would lose every message), got {}",
                    compact(n.loss)
                ),
            );
        }
        // An automatic duration is as long as the fleet needs: no limit here.
        let duration = p.duration.unwrap_or(f64::INFINITY);
        let steps = (duration / p.sim_step).round();
        let too_late = |latency: usize| {
            p.sim_step > 0.0 && duration > 0.0 && steps.is_finite() && latency as f64 > steps
        };
        let late = |latency: usize| {
            format!(
                "{} steps of {} s is longer than the whole run ({} s): no message would arrive",
                latency,
                compact(p.sim_step),
                compact(duration)
            )
        };
        if too_late(n.latency) {
            self.error(path.key("latency"), late(n.latency));
        }
        let mut seen = std::collections::HashSet::new();
        for (i, link) in n.links.iter().enumerate() {
            let at = path.key("links").index(i);
            let [a, b] = link.between;
            if a == 0 || b == 0 || a > p.agents || b > p.agents || a == b {
                self.error(
                    at.key("between"),
                    format!(
                        "must name two different agents from 1 to {} (the fleet's agents), got [{a}, {b}]",
                        p.agents
                    ),
                );
            } else if !seen.insert((a.min(b), a.max(b))) {
                self.error(
                    at.key("between"),
                    format!("the link between agents {a} and {b} is given twice"),
                );
            }
            if too_late(link.latency) {
                self.error(at.key("latency"), late(link.latency));
            }
        }
        let mut clocked = std::collections::HashSet::new();
        for (i, update) in n.updates.iter().enumerate() {
            let at = path.key("updates").index(i);
            let agent = update.agent;
            if agent == 0 || agent > p.agents {
                self.error(
                    at.key("agent"),
                    format!(
                        "must name an agent from 1 to {} (the fleet's agents), got {agent}",
                        p.agents
                    ),
                );
            } else if !clocked.insert(agent) {
                self.error(
                    at.key("agent"),
                    format!("agent {agent} is given a clock of its own twice"),
                );
            }
            if update.period == 0 {
                self.error(
                    at.key("period"),
                    "must be at least 1 step (the agent would never decide)",
                );
            } else if too_late(update.period) {
                self.error(
                    at.key("period"),
                    format!(
                        "{} steps of {} s is longer than the whole run ({} s): the agent would decide once at most",
                        update.period,
                        compact(p.sim_step),
                        compact(duration)
                    ),
                );
            } else if update.phase >= update.period {
                self.error(
                    at.key("phase"),
                    format!(
                        "must be below the period ({} steps), got {}",
                        update.period, update.phase
                    ),
                );
            }
        }
    }
}

/// Why `m` points with distances `d` have no place in the plane within
/// `slack` of each distance, and the two points of the entry to blame; None
/// when they have one. A triangle that does not close comes first (its
/// longest side is to blame); then the distance that misses most once the
/// points are placed ([`place_in_plane`]).
fn unformable(
    m: usize,
    d: &dyn Fn(usize, usize) -> f64,
    slack: &dyn Fn(f64) -> f64,
    name: &dyn Fn(usize) -> String,
    entry: &dyn Fn(usize, usize) -> String,
) -> Option<([usize; 2], String)> {
    let mut broken: Vec<[usize; 3]> = Vec::new();
    for i in 0..m {
        for j in i + 1..m {
            for k in j + 1..m {
                let mut sides = [
                    (d(i, j), [i, j, k]),
                    (d(i, k), [i, k, j]),
                    (d(j, k), [j, k, i]),
                ];
                sides.sort_by(|a, b| b.0.total_cmp(&a.0));
                let (long, [a, b, c]) = sides[0];
                if long > d(a, c) + d(c, b) + slack(long) {
                    broken.push([a, b, c]);
                }
            }
        }
    }
    if let Some(&[a, b, c]) = broken.first() {
        let mut three = [a, b, c];
        three.sort_unstable();
        let more = match broken.len() - 1 {
            0 => String::new(),
            more => format!(" ({more} more triangle(s) do not close either)"),
        };
        let why = format!(
            "{}, {} and {} cannot form a triangle, {} = {} m is longer than {} + {} = {} + {} \
             = {} m{more}",
            name(three[0]),
            name(three[1]),
            name(three[2]),
            entry(a, b),
            compact(d(a, b)),
            entry(a, c),
            entry(c, b),
            compact(d(a, c)),
            compact(d(c, b)),
            compact(d(a, c) + d(c, b)),
        );
        return Some(([a, b], why));
    }
    let placed = place_in_plane(m, d);
    let off = |j: usize, k: usize| {
        let planar = (placed.points[j] - placed.points[k]).norm();
        (planar, (planar - d(j, k)).abs() / slack(d(j, k)))
    };
    let (j, k) = (0..m)
        .flat_map(|j| (j + 1..m).map(move |k| (j, k)))
        .filter(|&(j, k)| off(j, k).1 > 1.0)
        .max_by(|x, y| off(x.0, x.1).1.total_cmp(&off(y.0, y.1).1))?;
    let [a, b, c] = placed.anchors;
    let why = format!(
        "placed from {}, {} and {}, {} and {} come {:.3} m apart, but {} = {} m \
         (fleet.tolerance allows ± {:.3} m)",
        name(a),
        name(b),
        name(c),
        name(j),
        name(k),
        off(j, k).0,
        entry(j, k),
        compact(d(j, k)),
        slack(d(j, k)),
    );
    Some(([j, k], why))
}

/// Points placed in the plane from their distances, and the three placed
/// first.
struct Placement {
    points: Vec<nalgebra::Point2<f64>>,
    anchors: [usize; 3],
}

/// Places `m` points (m ≥ 1) in the plane from their distances `d` (which
/// close every triangle): a and b, the farthest two, on the x axis; c, the
/// one farthest off their line, above it; every other point where its
/// distances to a and b put it, on the side its distance to c prefers.
/// When the distances are a plane's, every distance comes back.
fn place_in_plane(m: usize, d: &dyn Fn(usize, usize) -> f64) -> Placement {
    use nalgebra::Point2;
    let (mut a, mut b) = (0, 0);
    for i in 0..m {
        for j in i + 1..m {
            if d(i, j) > d(a, b) {
                (a, b) = (i, j);
            }
        }
    }
    let base = d(a, b);
    // Where each point falls on ab (x) and how far off it (|y|).
    let foot = |k: usize| -> (f64, f64) {
        if base <= 0.0 {
            return (0.0, 0.0);
        }
        let x = (d(a, k).powi(2) - d(b, k).powi(2) + base * base) / (2.0 * base);
        (x, (d(a, k).powi(2) - x * x).max(0.0).sqrt())
    };
    let c = (0..m)
        .max_by(|&i, &j| foot(i).1.total_cmp(&foot(j).1))
        .unwrap_or(0);
    let (cx, cy) = foot(c);
    let points = (0..m)
        .map(|k| {
            let (x, y) = foot(k);
            if k == c {
                return Point2::new(cx, cy);
            }
            let up = Point2::new(x, y);
            let down = Point2::new(x, -y);
            let miss = |q: &Point2<f64>| ((q - Point2::new(cx, cy)).norm() - d(c, k)).abs();
            if miss(&down) < miss(&up) { down } else { up }
        })
        .collect();
    Placement {
        points,
        anchors: [a, b, c],
    }
}
