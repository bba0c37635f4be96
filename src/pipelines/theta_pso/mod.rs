//! θ-PSO formation planning with reconfiguration (Hoang et al.; Fig. 3 is the
//! algorithm): find the IWPs (eq. 9), search the centroid path with the
//! angle-encoded swarm (eq. 1) against J (eqs. 2-5, 10-11), derive each UAV's
//! timed trajectory through the reconfigurations (eqs. 12-15), and verify the
//! result against the hard constraints and the inspection passes (eq. 8).

pub mod benchmark;
pub mod chart;
pub mod cost;
pub mod face;
pub mod flight;
pub mod inspection;
pub mod iwp;
pub mod motion;
pub mod path;
pub mod plan;
pub mod recording;
pub mod reference;
pub mod repair;
pub mod route;
mod section;
pub mod seeding;
pub mod spso;
pub mod summary;
pub mod timing;
pub mod trajectory;
pub mod unusable;

use std::f64::consts::FRAC_PI_2;

use nalgebra::Point3;
use serde::{Deserialize, Serialize};

use crate::base::swarm::SearchSpace;
use crate::mission::{Diagnostic, FieldPath, Mission};

pub use crate::pipelines::verify::{Check, InspectionResult, Verification};
pub use cost::{CostModel, CostTerms};
pub use inspection::PassGeometry;
pub use iwp::{Iwp, Shape, find_iwps};
pub use path::{CentroidPath, PathBuilder};
pub use plan::{PlanSource, passed_by_altitude, plan, plan_warm};
pub use trajectory::{Reconfiguration, Sample, Trajectory};

pub use crate::pipelines::PlanOptions;

/// What a θ-PSO run asks beyond the mission and the seed: a plan to start
/// part of its swarm from (the designer's live re-plans, `--warm-from`);
/// `None`, a cold run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Request {
    pub warm: Option<std::sync::Arc<WarmStart>>,
}

/// Where a warm-started run's swarm starts besides the corridor: a plan of
/// an earlier run (of this mission or of one a little different), so a
/// small edit converges in a few iterations. Recorded in the outcome, so the
/// run can be repeated (`skyform run theta-pso --warm-from`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WarmStart {
    /// Which plan, in words ("job 3's plan, J 172.65").
    #[serde(default)]
    pub from: String,
    /// Its free waypoints, metres ENU (refitted to the count this run needs).
    pub waypoints: Vec<Point3<f64>>,
    /// Its pass angles round each inspected obstacle, radians (builder order).
    #[serde(default)]
    pub pass_angles: Vec<f64>,
    /// Its route stage's corridor: reused, without a search, when it still
    /// holds on this mission (`route::reuse`).
    #[serde(default)]
    pub corridor: Option<route::Corridor>,
}

/// A warm-started swarm stops once its best has not improved by more than
/// this share of J for `WARM_STALL` iterations: it starts next to the answer.
/// 0.1 % over 8: since J_T became continuous (issue 36) a warm swarm keeps
/// shaving centimetres off the corners for its whole budget (the bridge
/// after a 1 m nudge: 0.03 of J 173 per iteration); stopped at iteration 47
/// it is within 0.5 % of a cold run's J.
const WARM_TOLERANCE: f64 = 1e-3;
const WARM_STALL: usize = 8;

/// A warm-started swarm's particles: the earlier plan, a few about it and
/// the corridor's seeds, up to this many (fewer when `swarm_size` is).
const WARM_SWARM: usize = 25;

/// Everything a θ-PSO run produces.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThetaPsoOutcome {
    /// The pipeline, the mission, the seed and how the run ended.
    #[serde(flatten)]
    pub header: crate::pipelines::Header,
    /// Swarm iterations completed, over every run of the swarm.
    pub iterations: usize,
    /// Cost evaluations made, over every run of the swarm.
    pub evaluations: usize,
    /// Runs of the swarm after the first because the best still failed
    /// verification (at most `theta_pso.restarts`).
    pub restarts: usize,
    /// The best path's cost terms.
    pub cost: CostTerms,
    /// Best total cost after each iteration of the run kept (iteration 0 =
    /// initial swarm).
    pub convergence: Vec<f64>,
    /// The intermediate waypoints of eq. 9, enabled or not.
    pub iwps: Vec<Iwp>,
    /// The free waypoints the swarm chose, decoded (eq. 1).
    pub waypoints: Vec<Point3<f64>>,
    /// Where each inspection pass lies round its obstacle, radians (the
    /// particle's pass angles, decoded; builder order).
    pub pass_angles: Vec<f64>,
    /// The plan the swarm was warm-started from (`None`: a cold run, the same
    /// for the same mission and seed whatever ran before).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warm_start: Option<WarmStart>,
    /// P_F*: start, waypoints, IWP crossings and inspection passes, goal.
    pub centroid_path: Vec<Point3<f64>>,
    /// The centroid's path as flown: P_F* simplified and its corners
    /// rounded (`path::rounding`), metres ENU.
    pub flown_path: Vec<Point3<f64>>,
    /// Where the centroid is along `flown_path` at each trajectory sample,
    /// metres (the flight's time law: from rest, slowed by the vehicle's
    /// limits, to rest).
    pub flown_arcs: Vec<f64>,
    /// Metres.
    pub path_length: f64,
    /// Seconds at the formation's ground speed.
    pub duration: f64,
    /// Length of the shortest 2-D route any feasible plan's centroid is at
    /// least as long as (`reference`), metres; `None` when none exists.
    pub reference_length: Option<f64>,
    /// J1 / reference length: 1 would be a perfect plan.
    pub length_ratio: Option<f64>,
    /// Where each inspection pass lies along the centroid path, seconds.
    pub passes: Vec<PlannedPass>,
    pub reconfigurations: Vec<Reconfiguration>,
    /// Usable, enabled IWPs the plan does not cross (it goes round them),
    /// as indices into `iwps`.
    pub bypassed: Vec<usize>,
    /// The `[[reconfiguration.waypoints]]` entries that name no IWP, each
    /// with why (`unused_choices`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unused_choices: Vec<String>,
    /// The obstacles some UAV flies over (above the top, inside the
    /// footprint) and under (below the base), by name, in mission order:
    /// what the summary states, the site being the user's to allow.
    #[serde(default)]
    pub passed_over: Vec<String>,
    #[serde(default)]
    pub passed_under: Vec<String>,
    /// Where the plan kept comes from: the swarm, its repair, or the corridor.
    pub source: PlanSource,
    /// The route stage's corridor length, metres.
    pub route_length: f64,
    /// The route stage's corridor: points, legs (free in a layer, a
    /// crossing, a pass) and pass angles.
    pub corridor: route::Corridor,
    pub trajectories: Vec<Trajectory>,
    pub verification: Verification,
}

/// An inspection pass as planned.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlannedPass {
    pub obstacle: String,
    /// Start and end of the pass, seconds.
    pub time: [f64; 2],
    /// The obstacle is on the formation's left.
    pub on_left: bool,
}

impl ThetaPsoOutcome {
    pub fn feasible(&self) -> bool {
        self.verification.feasible
    }

    /// Where the centroid is along `flown_path` at `t` seconds, metres
    /// (between samples, as the samples' straight line has it).
    pub fn arc_at(&self, t: f64) -> f64 {
        let times = self
            .trajectories
            .first()
            .map(|tr| &tr.samples[..])
            .unwrap_or(&[]);
        let k = times.partition_point(|s| s.t <= t);
        match (k.checked_sub(1), times.get(k)) {
            (Some(a), Some(b)) if b.t > times[a].t => {
                let u = (t - times[a].t) / (b.t - times[a].t);
                let (sa, sb) = (self.flown_arcs[a], self.flown_arcs[k]);
                sa + (sb - sa) * u
            }
            (Some(a), _) => self.flown_arcs.get(a).copied().unwrap_or(0.0),
            (None, _) => 0.0,
        }
    }

    /// Where the centroid is at `t` seconds, metres ENU.
    pub fn centroid_at(&self, t: f64) -> Point3<f64> {
        path::ArcWalker::new(&self.flown_path).at(self.arc_at(t))
    }
}

/// The dimensions and cost of the swarm search for one mission.
#[derive(Debug, Clone)]
pub struct Problem {
    pub iwps: Vec<Iwp>,
    pub builder: PathBuilder,
    pub cost: CostModel,
    pub space: SearchSpace,
}

impl Problem {
    /// The search for `mission`, or the first inspected obstacle whose pass
    /// cannot be flown (its index and why).
    pub fn new(mission: &Mission) -> Result<Self, (usize, String)> {
        Self::given(mission, find_iwps(mission))
    }

    /// [`Self::new`] with the mission's IWPs already found.
    pub fn given(mission: &Mission, iwps: Vec<Iwp>) -> Result<Self, (usize, String)> {
        let passes = inspection::pass_geometries(mission)?;
        let builder = PathBuilder::new(mission, &iwps, &passes);
        let cost = CostModel::new(mission, &iwps);
        // θ and Δθ both live in [-π/2, π/2] (Fig. 3, line 10).
        let space =
            SearchSpace::uniform(path::dimensions(mission), -FRAC_PI_2, FRAC_PI_2, FRAC_PI_2);
        Ok(Problem {
            iwps,
            builder,
            cost,
            space,
        })
    }

    /// Particles follow the route stage's corridor: as many free waypoints
    /// as it needs, and its squeezed stretches flown shrunk.
    pub fn follow(&mut self, mission: &Mission, corridor: &route::Corridor) {
        let free = seeding::free_waypoints(mission, corridor);
        self.builder.set_free_waypoints(free);
        self.builder.set_squeeze(corridor.squeeze.clone());
        self.builder.widen_to(&mission.bounds, &corridor.points);
        let inspected = mission.obstacles.iter().filter(|o| o.inspect).count();
        self.space = SearchSpace::uniform(3 * free + inspected, -FRAC_PI_2, FRAC_PI_2, FRAC_PI_2);
    }

    /// The centroid path a particle stands for.
    pub fn path(&self, angles: &[f64]) -> CentroidPath {
        self.builder.build(angles)
    }

    /// J and its terms for a particle.
    pub fn evaluate(&self, angles: &[f64]) -> CostTerms {
        self.cost.terms(&self.path(angles))
    }

    /// The swarm's objective for a particle, or a partial sum once it
    /// reaches `bound` (`CostModel::evaluate_below`).
    pub fn objective_below(&self, angles: &[f64], bound: f64) -> f64 {
        let placed = self.builder.place(angles);
        let lead = self.cost.lead(&placed.points);
        if lead.total >= bound {
            return lead.total;
        }
        self.cost
            .evaluate_rest(&self.builder.finish(placed), lead, bound)
            .objective
    }
}

/// Usable IWPs the run's log names one by one (a forest has hundreds).
const USABLE_LOGGED: usize = 10;

/// Unusable IWPs under the default shape that `check` warns of one by one;
/// more are grouped by reason.
const UNUSABLE_WARNED: usize = 3;

/// What θ-PSO can tell about a mission before planning it: unusable IWPs
/// (warnings: the plan goes round) and inspection passes that cannot hold
/// eq. 8 (errors). Shown by `check` and the designer beside validation.
pub fn diagnostics(mission: &Mission) -> Vec<Diagnostic> {
    diagnostics_given(mission, &find_iwps(mission))
}

/// [`diagnostics`] with the mission's IWPs already found (a run finds them
/// once, for its admission and its search).
pub fn diagnostics_given(mission: &Mission, iwps: &[Iwp]) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    // IWPs under the default shape that cannot be used: on a maze or a
    // forest there are hundreds (pairs of posts on two walls no route
    // takes), so beyond a few they are one warning per reason; an IWP with
    // its own entry in the file is always warned of by itself.
    let chosen = |iwp: &Iwp| {
        mission
            .reconfiguration
            .position(&iwp.between[0], &iwp.between[1])
            .is_some()
    };
    for iwp in iwps.iter().filter(|i| i.gate.is_some()) {
        if let (Some(g), Some(reason)) = (iwp.gate, &iwp.unusable) {
            // A warning: the file is right, the plan it asks for does not
            // exist (`run` says NO PLAN, naming it).
            out.push(Diagnostic::warning(
                FieldPath::root()
                    .key("route")
                    .key("via")
                    .index(g)
                    .key("between"),
                format!(
                    "no plan can keep it: the route cannot pass between '{}' and '{}': {reason}",
                    iwp.between[0], iwp.between[1]
                ),
            ));
        }
    }
    out.extend(unused_choices(mission, iwps));
    let defaulted: Vec<Iwp> = iwps
        .iter()
        .filter(|i| i.enabled && i.unusable.is_some() && !chosen(i) && i.gate.is_none())
        .cloned()
        .collect();
    let grouped = defaulted.len() > UNUSABLE_WARNED;
    if grouped {
        let route = [mission.route.start, mission.route.goal];
        for group in unusable::unusable_groups(&defaulted, &route, UNUSABLE_WARNED) {
            let nearest: Vec<String> = group
                .nearest
                .iter()
                .map(|b| format!("'{}' ↔ '{}'", b[0], b[1]))
                .collect();
            out.push(Diagnostic::warning(
                FieldPath::root()
                    .key("reconfiguration")
                    .key("default_shape"),
                format!(
                    "{} IWPs are unusable: {}; the plan will not go through them \
                     (nearest the start-goal line: {})",
                    group.count,
                    group.reason,
                    nearest.join(", ")
                ),
            ));
        }
    }
    for iwp in iwps.iter().filter(|i| i.gate.is_none()) {
        if grouped && !chosen(iwp) {
            continue;
        }
        if let (true, Some(reason)) = (iwp.enabled, &iwp.unusable) {
            let at = mission
                .reconfiguration
                .position(&iwp.between[0], &iwp.between[1])
                .map_or_else(
                    || {
                        FieldPath::root()
                            .key("reconfiguration")
                            .key("default_shape")
                    },
                    |i| {
                        FieldPath::root()
                            .key("reconfiguration")
                            .key("waypoints")
                            .index(i)
                            .key("shape")
                    },
                );
            out.push(Diagnostic::warning(
                at,
                format!(
                    "the IWP between '{}' and '{}' ({:.2} m gap) is unusable: {reason}; \
                     the plan will not go through it",
                    iwp.between[0], iwp.between[1], iwp.gap
                ),
            ));
        }
    }
    if let Err((k, reason)) = inspection::pass_geometries(mission) {
        out.push(Diagnostic::error(
            FieldPath::root().key("obstacles").index(k).key("stand_off"),
            format!(
                "'{}' cannot be inspected: {reason}",
                mission.obstacles[k].name
            ),
        ));
    }
    for (k, reason) in inspection::thin_face_passes(mission) {
        out.push(Diagnostic::warning(
            FieldPath::root().key("obstacles").index(k).key("stand_off"),
            format!(
                "'{}' is hard to inspect: {reason}",
                mission.obstacles[k].name
            ),
        ));
    }
    out
}

/// The `[[reconfiguration.waypoints]]` entries that name no IWP, each a
/// warning saying why (the pair is no gap eq. 9 places an IWP in) and what
/// would make the route pass there: a choice is never silently ignored.
pub fn unused_choices(mission: &Mission, iwps: &[Iwp]) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let index = |name: &str| mission.obstacles.iter().position(|o| o.name == name);
    for (i, w) in mission.reconfiguration.waypoints.iter().enumerate() {
        let [a, b] = &w.between;
        if iwps
            .iter()
            .any(|iwp| w.is_between(&iwp.between[0], &iwp.between[1]))
        {
            continue;
        }
        let (Some(p), Some(q)) = (index(a), index(b)) else {
            continue; // a name that is no obstacle: validation says so
        };
        let why = iwp::why_no_iwp(mission, p.min(q), p.max(q));
        out.push(Diagnostic::warning(
            FieldPath::root()
                .key("reconfiguration")
                .key("waypoints")
                .index(i)
                .key("between"),
            format!("not used: no IWP between '{a}' and '{b}': {why}"),
        ));
    }
    out
}

/// θ-PSO's predicted size against `pipeline::limits`: particles, decision
/// dimensions, cost evaluations (particles × iterations × (1 + restarts)) and
/// trajectory samples. The flight is at least the straight start-goal
/// distance long, so its samples are at least that distance over the ground
/// speed, every 0.1 s, for every UAV; `plan` checks the real figure again
/// before it samples the planned path.
pub fn budget(mission: &Mission) -> Vec<Diagnostic> {
    use crate::pipelines::{figure, limits};
    let p = &mission.theta_pso;
    let at = |key: &str| FieldPath::root().key("theta_pso").key(key);
    let mut out = Vec::new();
    if p.swarm_size > limits::THETA_PSO_PARTICLES {
        out.push(Diagnostic::error(
            at("swarm_size"),
            format!(
                "{} particles is over the limit of {} (memory grows with particles × dimensions)",
                figure(p.swarm_size as f64),
                figure(limits::THETA_PSO_PARTICLES as f64)
            ),
        ));
    }
    if p.waypoints > limits::THETA_PSO_WAYPOINTS {
        out.push(Diagnostic::error(
            at("waypoints"),
            format!(
                "{} free waypoints is over the limit of {}",
                figure(p.waypoints as f64),
                limits::THETA_PSO_WAYPOINTS
            ),
        ));
    }
    if p.segments > limits::THETA_PSO_SEGMENTS {
        out.push(Diagnostic::error(
            at("segments"),
            format!(
                "{} segments is over the limit of {} (every cost evaluation walks them)",
                figure(p.segments as f64),
                figure(limits::THETA_PSO_SEGMENTS as f64)
            ),
        ));
    }
    let evaluations = p.swarm_size as f64 * p.iterations as f64 * (1.0 + p.restarts as f64);
    if crate::pipelines::exceeds(evaluations, limits::THETA_PSO_EVALUATIONS) {
        let key = crate::pipelines::largest_factor(&[
            ("restarts", p.restarts as f64),
            ("swarm_size", p.swarm_size as f64),
            ("iterations", p.iterations as f64),
        ]);
        out.push(Diagnostic::error(
            at(key),
            format!(
                "{} particles × {} iterations × {} runs make {} cost evaluations (limit {})",
                figure(p.swarm_size as f64),
                figure(p.iterations as f64),
                figure(1.0 + p.restarts as f64),
                figure(evaluations),
                figure(limits::THETA_PSO_EVALUATIONS)
            ),
        ));
    }
    // Every evaluation looks at every obstacle from every leg of its path.
    let legs = (p.waypoints + 1) as f64;
    let checks = evaluations * legs * mission.obstacles.len() as f64;
    // Named on the swarm (the count of obstacles is no field to edit), and
    // only when the evaluations alone are within their limit.
    if !crate::pipelines::exceeds(evaluations, limits::THETA_PSO_EVALUATIONS)
        && crate::pipelines::exceeds(checks, limits::THETA_PSO_OBSTACLE_CHECKS)
    {
        out.push(Diagnostic::error(
            at("swarm_size"),
            format!(
                "{} obstacles × {} cost evaluations × {} legs make {} obstacle checks (limit {}): \
                 fewer obstacles (a row of posts as one footprint) or a smaller swarm",
                mission.obstacles.len(),
                figure(evaluations),
                figure(legs),
                figure(checks),
                figure(limits::THETA_PSO_OBSTACLE_CHECKS)
            ),
        ));
    }
    let (field, value, unit, duration) = shortest_flight(mission);
    let samples = trajectory_samples(duration, mission.formation.slots.len());
    if crate::pipelines::exceeds(samples, limits::TRAJECTORY_SAMPLES) {
        out.push(Diagnostic::error(
            field,
            format!(
                "{} {unit} makes a flight of at least {} s ({} trajectory samples for {} UAVs, limit {})",
                figure(value),
                figure(duration),
                figure(samples),
                mission.formation.slots.len(),
                figure(limits::TRAJECTORY_SAMPLES)
            ),
        ));
    }
    out
}

/// A lower bound of the flight's duration over the straight start-goal
/// line, and the limit that sets it (its field, value and unit): the
/// horizontal and the vertical distance each at most at the slowest UAV's
/// speed (and the ground speed), and each from rest to rest at most at its
/// acceleration (2 √(d / a)). The time law (`timing`) keeps every one of
/// these, so the flight is never shorter.
fn shortest_flight(mission: &Mission) -> (FieldPath, f64, &'static str, f64) {
    let (start, goal) = (mission.route.start, mission.route.goal);
    let across = (goal.xy() - start.xy()).norm();
    let rise = goal.z - start.z;
    let limits: Vec<_> = (0..mission.formation.slots.len().max(1))
        .map(|n| mission.vehicle.limits(n))
        .collect();
    // The field of UAV n's limit: its own entry's when it has one.
    let field = |n: usize, key: &str, own: fn(&crate::mission::VehicleOverride) -> Option<f64>| {
        let path = FieldPath::root().key("vehicle");
        match mission
            .vehicle
            .uavs
            .iter()
            .position(|o| o.uav == n + 1 && own(o).is_some())
        {
            Some(i) => path.key("uavs").index(i).key(key),
            None => path.key(key),
        }
    };
    let slowest = |get: fn(&crate::mission::VehicleLimits) -> f64| {
        limits
            .iter()
            .enumerate()
            .map(|(n, l)| (n, get(l)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, f64::NAN))
    };
    let speed = mission.formation.ground_speed;
    let mut bounds = vec![(
        FieldPath::root().key("formation").key("ground_speed"),
        speed,
        "m/s",
        across / speed,
    )];
    let (n, v) = slowest(|l| l.speed);
    bounds.push((field(n, "max_speed", |o| o.max_speed), v, "m/s", across / v));
    let (n, a) = slowest(|l| l.acceleration);
    let key = "max_acceleration";
    bounds.push((
        field(n, key, |o| o.max_acceleration),
        a,
        "m/s²",
        2.0 * (across / a).sqrt(),
    ));
    let climbing = rise >= 0.0;
    let (n, rate) = if climbing {
        slowest(|l| l.climb)
    } else {
        slowest(|l| l.descent)
    };
    bounds.push(if climbing {
        (
            field(n, "max_climb_rate", |o| o.max_climb_rate),
            rate,
            "m/s",
            rise.abs() / rate,
        )
    } else {
        (
            field(n, "max_descent_rate", |o| o.max_descent_rate),
            rate,
            "m/s",
            rise.abs() / rate,
        )
    });
    let (n, a) = slowest(|l| l.up.min(l.down));
    let (key, own): (&str, fn(&crate::mission::VehicleOverride) -> Option<f64>) =
        if limits[n].up <= limits[n].down {
            ("max_acceleration_up", |o| o.max_acceleration_up)
        } else {
            ("max_acceleration_down", |o| o.max_acceleration_down)
        };
    bounds.push((field(n, key, own), a, "m/s²", 2.0 * (rise.abs() / a).sqrt()));
    bounds
        .into_iter()
        .filter(|b| !b.3.is_nan())
        .max_by(|a, b| a.3.total_cmp(&b.3))
        .unwrap_or((
            FieldPath::root().key("formation").key("ground_speed"),
            speed,
            "m/s",
            0.0,
        ))
}

/// Samples of every UAV's trajectory over `duration` seconds.
fn trajectory_samples(duration: f64, uavs: usize) -> f64 {
    (duration / trajectory::SAMPLE_PERIOD + 1.0) * uavs as f64
}
