//! The mission as it is written in a TOML file.
//!
//! Frames and units: positions are metres in the local East-North-Up frame
//! (x east, y north, z up), angles in the file are degrees, times seconds.
//! Every parameter defaults to the value used in its paper, so a mission file
//! only has to say what differs. Unknown keys are rejected (`deny_unknown_fields`)
//! so that a typo is an error instead of a silently ignored setting.
//!
//! Long (~1150 lines) because it is the model of every mission section, one serde struct
//! each (every pipeline's parameters included), with their paper defaults and the small
//! queries on them (an obstacle's band, the formation's radius) that every stage shares.

use nalgebra::{Point2, Point3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use super::obstacle::Obstacle;

/// A complete mission: the operating space, what is in it, the formation that
/// flies it, and the parameters of the three planning pipelines.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mission {
    /// Short human name, shown in the TUI and in recordings.
    pub name: String,
    /// Free text: what the mission is for.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// Seed of every random number the pipelines draw; same mission + seed → same result.
    #[serde(default)]
    pub seed: u64,
    /// Geodetic anchor of the local ENU frame, for export to real autopilots.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<GeoOrigin>,
    pub bounds: Bounds,
    pub route: Route,
    #[serde(default)]
    pub formation: Formation,
    /// What each multicopter of the formation can fly (`[vehicle]`).
    #[serde(default, skip_serializing_if = "is_default")]
    pub vehicle: Vehicle,
    #[serde(default)]
    pub reconfiguration: Reconfiguration,
    #[serde(default)]
    pub theta_pso: ThetaPsoParams,
    #[serde(default)]
    pub flatlo: FlatloParams,
    #[serde(default)]
    pub fleet: FleetParams,
    /// The air `skyform fly` flies a plan in (`[flight]`).
    #[serde(default, skip_serializing_if = "is_default")]
    pub flight: FlightParams,
    /// Vertical cylinders standing on the ground (z = 0).
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// A height map: the altitude band is then above the ground under each point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub terrain: Option<Terrain>,
}

/// `[terrain]`: a GeoTIFF height map placed in the ENU frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Terrain {
    /// The GeoTIFF, relative to the mission file (one sample per pixel, metres).
    pub file: String,
    /// ENU x, y of the centre of the first pixel (row 0, column 0), metres.
    pub origin: [f64; 2],
    /// ENU step from one column and from one row to the next, metres; a
    /// north-up GeoTIFF has a negative y step.
    pub pixel_size: [f64; 2],
    /// How the ground between pixel centres is read.
    #[serde(default, skip_serializing_if = "is_default")]
    pub lookup: crate::base::terrain::Lookup,
    /// The map as loaded when the mission was read (or why it could not be).
    #[serde(skip)]
    pub map: crate::base::terrain::Loaded,
}

fn is_default<T: Default + PartialEq>(v: &T) -> bool {
    *v == T::default()
}

impl Mission {
    /// The loaded height map, if the mission has one that loaded.
    pub fn height_map(&self) -> Option<&std::sync::Arc<crate::base::terrain::HeightMap>> {
        self.terrain
            .as_ref()
            .and_then(|t| t.map.0.as_ref())
            .and_then(|m| m.as_ref().ok())
    }

    /// The ground height under (x, y), metres: 0 without terrain; with
    /// terrain, the mission's lookup, at the map's edge outside it.
    pub fn ground(&self, x: f64, y: f64) -> f64 {
        match (self.terrain.as_ref(), self.height_map()) {
            (Some(t), Some(map)) => map.ground_clamped(t.lookup, x, y),
            _ => 0.0,
        }
    }

    /// The loaded map with the mission's lookup.
    pub fn ground_model(&self) -> Option<crate::base::terrain::Ground> {
        let t = self.terrain.as_ref()?;
        Some(crate::base::terrain::Ground {
            map: self.height_map()?.clone(),
            lookup: t.lookup,
        })
    }

    /// The lowest centroid altitude at which the nominal shape passes over
    /// obstacle `o` (its lowest UAV r_Q + the safety margin + θ-PSO's
    /// clearance margin above the top; ∞ for one that may not be flown
    /// over) and the highest at which it passes under it (its highest UAV
    /// as far below the base). Between the two, `o` stands in the way.
    pub fn passing_altitudes(&self, o: &Obstacle) -> [f64; 2] {
        let f = &self.formation;
        let below = f.slots.iter().map(|s| -s.z).fold(0.0, f64::max);
        let above = f.slots.iter().map(|s| s.z).fold(0.0, f64::max);
        let clearance = f.least_clearance() + self.theta_pso.clearance_margin.max(0.0);
        [o.top() + clearance + below, o.base - clearance - above]
    }

    /// The centroid altitudes at which every UAV of the nominal shape is in
    /// the band and level with obstacle `o`'s side (between its base and
    /// its top), so the one facing it measures eq. 8's distance to the side
    /// wall, not over the top; for a shape taller than the side, the
    /// altitudes that keep the centroid level with it. `None` when no
    /// altitude of the band is level with it.
    pub fn inspection_altitudes(&self, o: &Obstacle) -> Option<[f64; 2]> {
        let half = self
            .formation
            .slots
            .iter()
            .map(|s| s.z.abs())
            .fold(0.0, f64::max);
        let (floor, ceiling) = (self.bounds.z[0] + half, self.bounds.z[1] - half);
        [half, 0.0].into_iter().find_map(|level| {
            let lo = floor.max(o.base + level);
            let hi = ceiling.min(o.height - level);
            (lo <= hi).then_some([lo, hi])
        })
    }

    /// Obstacle `o` as a cylinder in the ENU frame: with terrain, standing on
    /// the ground under its centre (its height is above that ground).
    pub fn prism(&self, o: &Obstacle) -> crate::base::shape::Prism {
        let mut c = o.prism();
        if self.terrain.is_some() {
            let ground = self.ground(o.center.x, o.center.y);
            c.height += ground;
            c.base += ground;
        }
        c
    }

    /// Loads the terrain file (relative to `base`) into `terrain.map`,
    /// keeping the reason when it fails (validation reports it, located).
    pub fn load_terrain(&mut self, base: &std::path::Path) {
        if let Some(t) = self.terrain.as_mut() {
            t.map = crate::base::terrain::Loaded(Some(crate::base::terrain::load_cached(
                base,
                &t.file,
                t.origin,
                t.pixel_size,
            )));
        }
    }
}

/// Most free nodes (`theta_pso.waypoints`) a path may have with
/// `cost = "spso"`: that cost keeps a path's points in fixed-size arrays.
pub const SPSO_MAX_NODES: usize = 30;

/// The cost a θ-PSO run minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CostKind {
    /// The θ-PSO paper's J (eqs. 2-5, 10-11) over every UAV.
    #[default]
    Paper,
    /// The SPSO benchmark's J = 5 J1 + J2 + 10 J3 + J4, exactly as its
    /// reference code computes it (`docs/spso.md`); needs `[terrain]`.
    Spso,
}

/// How a particle encodes the path (with `cost = "spso"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Encoding {
    /// θ-PSO eq. 1: one angle per coordinate of each free node.
    #[default]
    Angle,
    /// SPSO: a spherical vector (r, ψ, φ) per node, relative to the one before.
    Spherical,
}

/// Standard gravity, m/s² (ISO 80000-3): one constant for validation and
/// every vehicle model.
pub const GRAVITY: f64 = 9.80665;

/// WGS-84 position of the ENU origin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeoOrigin {
    /// Degrees, positive north.
    pub latitude: f64,
    /// Degrees, positive east.
    pub longitude: f64,
    /// Metres above the WGS-84 ellipsoid.
    #[serde(default)]
    pub altitude: f64,
}

/// The operating box (θ-PSO eq. 1 decodes into it) and the altitude band
/// [z_min, z_max] of θ-PSO eq. 5. Metres, ENU.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    /// [x_min, x_max]
    pub x: [f64; 2],
    /// [y_min, y_max]
    pub y: [f64; 2],
    /// Altitude band [z_min, z_max] above ground.
    pub z: [f64; 2],
}

impl Bounds {
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        self.contains_xy(&p.xy()) && (self.z[0]..=self.z[1]).contains(&p.z)
    }

    /// The middle of the x-y box.
    pub fn center_xy(&self) -> Point2<f64> {
        Point2::new((self.x[0] + self.x[1]) / 2.0, (self.y[0] + self.y[1]) / 2.0)
    }

    /// Horizontal distance from `p` to the nearest side of the x-y box:
    /// positive inside, negative outside.
    pub fn horizontal_margin(&self, p: &Point3<f64>) -> f64 {
        (p.x - self.x[0])
            .min(self.x[1] - p.x)
            .min(p.y - self.y[0])
            .min(self.y[1] - p.y)
    }

    pub fn contains_xy(&self, p: &Point2<f64>) -> bool {
        (self.x[0]..=self.x[1]).contains(&p.x) && (self.y[0]..=self.y[1]).contains(&p.y)
    }
}

/// Where the formation centroid starts and ends, and what it must pass on
/// the way, in order. Metres ENU.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Route {
    pub start: Point3<f64>,
    pub goal: Point3<f64>,
    /// The passages and points the route must take, in this order
    /// (`[[route.via]]`): a plan keeps every one or is refused naming it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub via: Vec<Via>,
}

/// One place the route must take: between two named obstacles (a gate),
/// or by a point within a radius.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Via {
    /// The two obstacles the route passes between (`between = ["pier 3",
    /// "pier 4"]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub between: Option<[String; 2]>,
    /// A point the centroid passes, metres ENU (z above the ground).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<Point3<f64>>,
    /// How near the centroid passes `point`, metres (1 m by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
}

/// A via point's radius when the file gives none, metres.
pub const DEFAULT_VIA_RADIUS: f64 = 1.0;

impl Via {
    /// How near the centroid must pass a via point, metres.
    pub fn radius(&self) -> f64 {
        self.radius.unwrap_or(DEFAULT_VIA_RADIUS)
    }

    /// As people read it: `between 'pier 3' and 'pier 4'`, `by (40, 10, 12)`.
    pub fn label(&self) -> String {
        match (&self.between, &self.point) {
            (Some([a, b]), _) => format!("between '{a}' and '{b}'"),
            (None, Some(p)) => format!(
                "by ({}, {}, {}) within {} m",
                crate::mission::compact(p.x),
                crate::mission::compact(p.y),
                crate::mission::compact(p.z),
                crate::mission::compact(self.radius())
            ),
            (None, None) => "(nothing)".to_owned(),
        }
    }
}

/// The formation flown by the θ-PSO pipeline (θ-PSO paper, Section III).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Formation {
    /// r_Q: safe radius of one UAV, metres (eq. 7).
    pub uav_radius: f64,
    /// d_com: communication range, metres (eq. 7).
    pub comm_range: f64,
    /// Constant ground speed of the centroid, m/s.
    pub ground_speed: f64,
    /// [d_min^s, d_max^s]: distance band to the inspected surface, metres
    /// (eq. 8); the default stand-off of every inspected obstacle.
    pub surface_distance: [f64; 2],
    /// The room a plan must keep beyond r_Q from every obstacle and beyond
    /// 2 r_Q between two UAVs, metres: verification holds every flight to
    /// it, the automatic shapes keep it. Not in the paper, whose margins are
    /// zero by construction: 0.1 m by default, room for a tracking autopilot
    /// that a zero margin never leaves.
    pub safety_margin: f64,
    /// Room kept from every obstacle beyond r_Q and the safety margin,
    /// metres (0 by default): what `skyform fly --target` finds when GNSS
    /// fixes need more room from the site than the slots leave between the
    /// UAVs, so the obstacles can be given it without moving the slots.
    #[serde(skip_serializing_if = "is_zero")]
    pub obstacle_margin: f64,
    /// Length of the straight inspection pass along an inspected obstacle,
    /// metres of centroid path over which eq. 8 must hold. Not in the paper:
    /// 6 m is 2 s of video at 3 m/s past a pier of the bridge.
    pub inspection_pass: f64,
    /// Offsets of each UAV from the centroid in the formation frame
    /// (x forward along the horizontal path tangent, y left, z up), metres.
    pub slots: Vec<Vector3<f64>>,
}

impl Default for Formation {
    /// The paper's experiment: a triangle ΔT1..ΔT3, 3 m/s, d^s ∈ [1, 5] m.
    fn default() -> Self {
        Formation {
            uav_radius: 0.5,
            comm_range: 20.0,
            ground_speed: 3.0,
            safety_margin: 0.1,
            obstacle_margin: 0.0,
            surface_distance: [1.0, 5.0],
            inspection_pass: 6.0,
            slots: vec![
                Vector3::new(0.0, 2.0, 0.0),
                Vector3::new(-2.0, -1.0, 0.0),
                Vector3::new(2.0, -1.0, 0.0),
            ],
        }
    }
}

/// `[vehicle]`: what one multicopter of the formation can fly, as its
/// autopilot limits it. Every UAV's trajectory is timed within these limits
/// (`theta_pso::timing`) and verification holds every flight to them. The
/// defaults are PX4's multicopter position-controller parameters
/// (MPC_XY_VEL_MAX, MPC_Z_VEL_MAX_UP, MPC_Z_VEL_MAX_DN, MPC_ACC_HOR_MAX,
/// MPC_ACC_UP_MAX, MPC_ACC_DOWN_MAX; see docs/theta-pso.md). Metres, seconds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Vehicle {
    /// Largest horizontal speed, m/s (PX4 MPC_XY_VEL_MAX: 12).
    pub max_speed: f64,
    /// Largest climb rate, m/s (PX4 MPC_Z_VEL_MAX_UP: 3).
    pub max_climb_rate: f64,
    /// Largest descent rate, m/s (PX4 MPC_Z_VEL_MAX_DN: 1.5).
    pub max_descent_rate: f64,
    /// Largest horizontal acceleration, m/s² (PX4 MPC_ACC_HOR_MAX: 5).
    pub max_acceleration: f64,
    /// Largest upward acceleration, m/s² (PX4 MPC_ACC_UP_MAX: 4).
    pub max_acceleration_up: f64,
    /// Largest downward acceleration, m/s² (PX4 MPC_ACC_DOWN_MAX: 3).
    pub max_acceleration_down: f64,
    /// The autopilot's horizontal position gain, 1/s (PX4 MPC_XY_P: 0.95):
    /// with the velocity gain, how stiffly the flight check's vehicle holds
    /// its track against a gust (docs/flight-check.md).
    pub position_gain_xy: f64,
    /// Vertical position gain, 1/s (PX4 MPC_Z_P: 1).
    pub position_gain_z: f64,
    /// Horizontal velocity gain, 1/s (PX4 MPC_XY_VEL_P_ACC: 1.8).
    pub velocity_gain_xy: f64,
    /// Vertical velocity gain, 1/s (PX4 MPC_Z_VEL_P_ACC: 4).
    pub velocity_gain_z: f64,
    /// The horizontal velocity loop's integral gain, 1/s² (PX4
    /// MPC_XY_VEL_I_ACC: 0.4): what takes a steady wind's offset, and a
    /// slow gust's, out of the track; 0 for none (a PD controller).
    pub velocity_integral_xy: f64,
    /// The vertical velocity loop's integral gain, 1/s² (PX4
    /// MPC_Z_VEL_I_ACC: 2).
    pub velocity_integral_z: f64,
    /// UAVs with limits of their own (a heavier camera ship, say):
    /// `uavs = [{ uav = 2, max_speed = 8.0 }]`, UAVs numbered from 1; a
    /// limit not given is the formation's.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub uavs: Vec<VehicleOverride>,
}

impl Default for Vehicle {
    fn default() -> Self {
        Vehicle {
            max_speed: 12.0,
            max_climb_rate: 3.0,
            max_descent_rate: 1.5,
            max_acceleration: 5.0,
            max_acceleration_up: 4.0,
            max_acceleration_down: 3.0,
            position_gain_xy: 0.95,
            position_gain_z: 1.0,
            velocity_gain_xy: 1.8,
            velocity_gain_z: 4.0,
            velocity_integral_xy: 0.4,
            velocity_integral_z: 2.0,
            uavs: Vec::new(),
        }
    }
}

/// One UAV's own limits in `[vehicle]` (`uavs = [{ uav = 2, … }]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleOverride {
    /// The UAV, numbered from 1 (its slot).
    pub uav: usize,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_speed: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_climb_rate: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_descent_rate: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_acceleration: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_acceleration_up: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_acceleration_down: Option<f64>,
}

/// `[flight]`: the air and the autopilots a plan is flown by in the Monte
/// Carlo flight check (`skyform fly`, docs/flight-check.md). Each flight
/// draws its own gusts, GNSS errors and take-off times; the vehicle is the
/// fleet's quadrotor (`[fleet]`'s body) flown by a cascaded position and
/// velocity controller within `[vehicle]`, along the exported waypoints.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FlightParams {
    /// Flights per check (`--flights` overrides).
    pub flights: usize,
    /// Mean wind speed, m/s, the same at every altitude.
    pub wind_speed: f64,
    /// Where the wind blows from, degrees clockwise from north (270: a
    /// westerly, blowing east).
    pub wind_from_deg: f64,
    /// Dryden turbulence (MIL-F-8785C, low altitude): `none`, `light`,
    /// `moderate` or `severe` (the wind at 6 m of 15, 30, 45 kt).
    pub turbulence: Turbulence,
    /// GNSS position error, σ of each horizontal axis, metres (1-2 m
    /// without RTK).
    pub gnss_sigma_horizontal: f64,
    /// GNSS altitude error σ, metres.
    pub gnss_sigma_vertical: f64,
    /// Correlation time of the GNSS error (first-order Gauss-Markov), s.
    pub gnss_correlation_time: f64,
    /// The share of the GNSS error's variance that is each receiver's own
    /// (multipath, receiver noise); the rest (satellite orbits and clocks,
    /// the atmosphere) is common to receivers a few metres apart.
    pub gnss_own_share: f64,
    /// σ of each vehicle's take-off time about the plan's, seconds.
    pub takeoff_skew: f64,
    /// The autopilot takes a waypoint as reached within this distance, m
    /// (PX4 NAV_ACC_RAD).
    pub acceptance_radius: f64,
    /// Linear drag per unit mass, 1/s: the force of the air moving past
    /// the airframe is drag × mass × (wind − velocity).
    pub drag: f64,
    /// Integration and control step, seconds.
    pub step: f64,
}

impl Default for FlightParams {
    fn default() -> Self {
        FlightParams {
            flights: 1000,
            wind_speed: 0.0,
            wind_from_deg: 270.0,
            turbulence: Turbulence::None,
            gnss_sigma_horizontal: 1.0,
            gnss_sigma_vertical: 1.5,
            gnss_correlation_time: 60.0,
            gnss_own_share: 0.16,
            takeoff_skew: 0.3,
            acceptance_radius: 2.0,
            drag: 0.3,
            step: 0.01,
        }
    }
}

/// Dryden turbulence intensity (MIL-F-8785C: the wind 20 ft above the
/// ground that sets σ_w = 0.1 W20 at low altitude).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Turbulence {
    #[default]
    None,
    Light,
    Moderate,
    Severe,
}

impl Turbulence {
    /// W20, m/s: 15, 30 and 45 knots; 0 without turbulence.
    pub fn wind_at_20_ft(self) -> f64 {
        const KNOT: f64 = 0.514_444;
        match self {
            Turbulence::None => 0.0,
            Turbulence::Light => 15.0 * KNOT,
            Turbulence::Moderate => 30.0 * KNOT,
            Turbulence::Severe => 45.0 * KNOT,
        }
    }
}

/// The limits one UAV flies within: `[vehicle]` with its own entry applied.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct VehicleLimits {
    /// Horizontal speed, m/s.
    pub speed: f64,
    /// Climb and descent rates, m/s.
    pub climb: f64,
    pub descent: f64,
    /// Horizontal acceleration, m/s².
    pub acceleration: f64,
    /// Upward and downward acceleration, m/s².
    pub up: f64,
    pub down: f64,
}

impl VehicleLimits {
    /// Every limit times `factor` (the timing plans a little inside them).
    pub fn scaled(self, factor: f64) -> Self {
        VehicleLimits {
            speed: self.speed * factor,
            climb: self.climb * factor,
            descent: self.descent * factor,
            acceleration: self.acceleration * factor,
            up: self.up * factor,
            down: self.down * factor,
        }
    }
}

impl Vehicle {
    /// The limits of UAV `uav` (0-based).
    pub fn limits(&self, uav: usize) -> VehicleLimits {
        let own = self.uavs.iter().find(|o| o.uav == uav + 1);
        let pick = |base: f64, mine: Option<Option<f64>>| mine.flatten().unwrap_or(base);
        VehicleLimits {
            speed: pick(self.max_speed, own.map(|o| o.max_speed)),
            climb: pick(self.max_climb_rate, own.map(|o| o.max_climb_rate)),
            descent: pick(self.max_descent_rate, own.map(|o| o.max_descent_rate)),
            acceleration: pick(self.max_acceleration, own.map(|o| o.max_acceleration)),
            up: pick(self.max_acceleration_up, own.map(|o| o.max_acceleration_up)),
            down: pick(
                self.max_acceleration_down,
                own.map(|o| o.max_acceleration_down),
            ),
        }
    }
}

/// The shapes a formation can take at an intermediate waypoint (Fig. 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeChoice {
    /// The least change that fits the gap.
    #[default]
    Auto,
    /// A single-file column along the direction of travel.
    Alignment,
    /// The shape turned rigidly into the vertical plane across the path.
    Rotation,
    /// The shape scaled toward the centroid by `shrink_scale`.
    Shrink,
}

/// How the formation reconfigures at intermediate waypoints (Section III.B).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Reconfiguration {
    /// Shape used at IWPs that have no entry in `waypoints`.
    pub default_shape: ShapeChoice,
    /// Scale of the shrink shape, in (0, 1].
    pub shrink_scale: f64,
    /// Path length over which the shape changes ([t1, t2] and [t3, t4]), metres.
    /// The paper's rotation experiment takes 6 s at 3 m/s (Fig. 7).
    pub transition_distance: f64,
    /// The new shape is complete this far before the IWP and held until this
    /// far after it, metres (1 m in the paper's experiment).
    pub hold_distance: f64,
    /// Choices for individual IWPs, named by the obstacle pair they lie between.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub waypoints: Vec<WaypointChoice>,
}

impl Default for Reconfiguration {
    fn default() -> Self {
        Reconfiguration {
            default_shape: ShapeChoice::Auto,
            shrink_scale: 0.5,
            transition_distance: 18.0,
            hold_distance: 1.0,
            waypoints: Vec::new(),
        }
    }
}

impl Reconfiguration {
    /// Where the choice for the IWP between obstacles `a` and `b` is in
    /// `waypoints` (the pair is unordered).
    pub fn position(&self, a: &str, b: &str) -> Option<usize> {
        self.waypoints.iter().position(|w| w.is_between(a, b))
    }

    /// The choice for the IWP between obstacles `a` and `b`, if any.
    pub fn choice(&self, a: &str, b: &str) -> Option<&WaypointChoice> {
        self.position(a, b).map(|i| &self.waypoints[i])
    }
}

impl WaypointChoice {
    /// The choice names obstacles `a` and `b`, in either order.
    pub fn is_between(&self, a: &str, b: &str) -> bool {
        same_pair(&self.between, a, b)
    }
}

/// The unordered pair `between` names obstacles `a` and `b`.
pub fn same_pair(between: &[String; 2], a: &str, b: &str) -> bool {
    (between[0] == a && between[1] == b) || (between[0] == b && between[1] == a)
}

/// The operator's choice for the IWP between two named obstacles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaypointChoice {
    /// Names of the two obstacles whose gap holds the IWP (eq. 9).
    pub between: [String; 2],
    /// A disabled IWP takes no part in J_R (eq. 11) and causes no reconfiguration.
    #[serde(default = "yes")]
    pub enabled: bool,
    #[serde(default)]
    pub shape: ShapeChoice,
    /// Overrides `shrink_scale` for this IWP.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
}

/// A centre or a radius the file left out: NaN, which validation names
/// unless a footprint sets them.
pub(super) fn unset() -> f64 {
    f64::NAN
}

pub(super) fn unset_point() -> Point2<f64> {
    Point2::new(f64::NAN, f64::NAN)
}

pub(super) fn is_yes(b: &bool) -> bool {
    *b
}

pub(super) fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

pub(super) fn yes() -> bool {
    true
}

/// θ-PSO parameters (θ-PSO paper, eqs. 1-5, 10-11, Section IV.A).
///
/// From the paper: the swarm size, waypoints and iterations (IV.A). Not from
/// the paper, which gives neither: the PSO gains w, c1, c2 are Clerc and
/// Kennedy's constriction values (IEEE TEC 6(1), 2002), the usual defaults of
/// the PSO literature; the β weights are skyform's, chosen so that any
/// violation (β2 J2, β3 J3) outweighs any length difference between paths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThetaPsoParams {
    /// N: number of particles (100 in the paper).
    pub swarm_size: usize,
    /// Number of free waypoints between start and goal (7 in the paper).
    pub waypoints: usize,
    /// Swarm iterations (150 in the paper).
    pub iterations: usize,
    /// w: inertia weight of eq. 1 (0.7298, Clerc-Kennedy; not in the paper).
    pub inertia: f64,
    /// c1: cognitive gain of eq. 1 (1.49618, Clerc-Kennedy; not in the paper).
    pub cognitive: f64,
    /// c2: social gain of eq. 1 (1.49618, Clerc-Kennedy; not in the paper).
    pub social: f64,
    /// L: straight segments the path is split into for the cost (eqs. 3-5, 11).
    pub segments: usize,
    /// β1: weight of the path length J1 (eq. 2; skyform's choice, 1).
    pub weight_length: f64,
    /// β2: weight of the obstacle violation J2 (eq. 2; skyform's choice, 10⁵).
    pub weight_obstacle: f64,
    /// β3: weight of the altitude violation J3 (eq. 2; skyform's choice, 100).
    pub weight_altitude: f64,
    /// Weight of J_R (eq. 10 adds it with weight 1).
    pub weight_waypoints: f64,
    /// δ_l for a segment at or below the ground. The paper's ∞ is replaced by
    /// a large finite value so that costs stay comparable.
    pub ground_penalty: f64,
    /// Weight of the x-y bounds term: how far any UAV leaves the bounds
    /// (not in the paper, which decodes the centroid inside them).
    pub weight_bounds: f64,
    /// Weight of the turning term J_T, metres of path per radian of turn
    /// beyond 90° (not in the paper): a hairpin costs as much as 47 m of path.
    pub weight_turning: f64,
    /// Extra clearance the cost asks of every UAV beyond r_Q, metres: room for
    /// the sampling of verification and for the tracking of a real autopilot.
    /// Reduced automatically where an IWP gap leaves less room.
    pub clearance_margin: f64,
    /// Runs of the swarm with new random streams when the best plan still
    /// fails verification, before the plan is reported infeasible.
    pub restarts: usize,
    /// Particles that start on the reference route (the shortest 2-D route
    /// around the obstacles inflated by the formation's safe radius) instead
    /// of at random; 0 for the paper's purely random start (Fig. 3, line 9).
    pub seeded_particles: usize,
    /// The cost: the paper's (default) or the SPSO benchmark's.
    #[serde(skip_serializing_if = "is_default")]
    pub cost: CostKind,
    /// The encoding of a particle with `cost = "spso"`, each with its
    /// published settings (gains, inertia damping, velocity limits).
    #[serde(skip_serializing_if = "is_default")]
    pub encoding: Encoding,
}

impl Default for ThetaPsoParams {
    fn default() -> Self {
        ThetaPsoParams {
            swarm_size: 100,
            waypoints: 7,
            iterations: 150,
            inertia: 0.7298,
            cognitive: 1.49618,
            social: 1.49618,
            segments: 64,
            weight_length: 1.0,
            weight_obstacle: 100_000.0,
            weight_altitude: 100.0,
            weight_waypoints: 1.0,
            ground_penalty: 1.0e6,
            weight_bounds: 100.0,
            weight_turning: 30.0,
            clearance_margin: 0.1,
            restarts: 3,
            seeded_particles: 10,
            cost: CostKind::Paper,
            encoding: Encoding::Angle,
        }
    }
}

/// FLATLO parameters (FLATLO paper, Algorithms 1-2, eqs. 1-6, Section 3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FlatloParams {
    /// N: aircraft in the squadron (4 in the paper).
    pub aircraft: usize,
    /// Δ_d: spacing between neighbours, before and after, metres (18,300 m).
    pub spacing: f64,
    /// Nominal airspeed, m/s (30.5 m/s).
    pub airspeed: f64,
    /// r: radius of the turn manoeuvres, metres (4,575 m).
    pub turn_radius: f64,
    /// Initial height, metres (3,050 m).
    pub altitude: f64,
    /// φ: initial heading, degrees from the x axis (east), counter-clockwise.
    pub heading_deg: f64,
    /// β: flight-path climb angle, degrees.
    pub climb_deg: f64,
    /// Position of aircraft 0 at the start (x, y), metres ENU; height is `altitude`.
    pub start: Point2<f64>,
    /// K_2: length of the final straight leg on the longitudinal line (Alg. 1 line 51), metres.
    pub final_leg: f64,
    /// T: sampling period of the references, s.
    pub sample_period: f64,
    /// Fixed RK4 step of the aircraft simulation, s.
    pub sim_step: f64,
    /// Aircraft mass, kg.
    pub mass: f64,
    /// Wing area, m².
    pub wing_area: f64,
    /// Air density at the flight altitude, kg/m³.
    pub air_density: f64,
    /// Zero-lift drag coefficient C_D0.
    pub drag_cd0: f64,
    /// Induced drag factor k in C_D = C_D0 + k C_L².
    pub drag_k: f64,
    /// Thrust limit, N.
    pub max_thrust: f64,
    /// Load factor limits [n_min, n_max].
    pub load_factor: [f64; 2],
    /// Bank angle limit |μ|, degrees.
    pub max_bank_deg: f64,
    /// [min, max] airspeed the aircraft may fly, m/s: every aircraft's
    /// transition airspeed must lie in it, the autopilot keeps the flight in
    /// it and verification judges it. Defaults from the airframe
    /// (docs/flatlo.md): 1.25 × the stall speed at C_L,max = 1.8, and the
    /// fastest level flight at full thrust.
    pub airspeed_range: [f64; 2],
    /// Position-error PID gains [kp, ki, kd] of the tracking controller.
    pub pid: [f64; 3],
    /// Relative standard deviation of the multiplicative Gaussian noise on
    /// airspeed, heading and flight-path angle (0.25 % in the paper; 0 = exact).
    pub noise: f64,
    /// Pass/fail threshold on the minimum pairwise distance, metres.
    pub min_separation: f64,
}

impl Default for FlatloParams {
    fn default() -> Self {
        FlatloParams {
            aircraft: 4,
            spacing: 18_300.0,
            airspeed: 30.5,
            turn_radius: 4_575.0,
            altitude: 3_050.0,
            heading_deg: 0.0,
            climb_deg: 0.0,
            start: Point2::origin(),
            final_leg: 20_000.0,
            sample_period: 1.0,
            sim_step: 0.1,
            // The paper gives no airframe. A 25 kg fixed-wing UAV: the slowest
            // aircraft of the paper case flies its transition at 14.4 m/s
            // (C_L ≈ 1.05), the cruise is 30.5 m/s; both well within thrust.
            mass: 25.0,
            wing_area: 2.5,
            air_density: 0.905,
            drag_cd0: 0.03,
            drag_k: 0.05,
            max_thrust: 100.0,
            load_factor: [-1.0, 3.0],
            max_bank_deg: 60.0,
            // V_s = √(2W / (ρ S C_L,max)) = 10.97 m/s at C_L,max = 1.8;
            // ArduPlane's AIRSPEED_MIN "at least 25 % above the stall speed";
            // T_max = D(V) at 54.0 m/s.
            airspeed_range: [13.7, 54.0],
            pid: [0.02, 0.0002, 0.4],
            noise: 0.0025,
            min_separation: 1_000.0,
        }
    }
}

/// One target of the fleet's timed sequence: a point the formation forms
/// around (`position`), or one point per agent (`positions`), which agent
/// to which the planner assigns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FleetTarget {
    /// When the target becomes active, s.
    pub time: f64,
    /// Target point P_d in the flight plane, metres ENU: the fleet forms
    /// around it (d_ip^d from it, d_ij^d apart).
    #[serde(default = "unset_point", skip_serializing_if = "is_unset_point")]
    pub position: Point2<f64>,
    /// One target point per agent, metres ENU: each agent flies to the one
    /// the planner assigns it (the least total distance), the formation
    /// being their arrangement.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub positions: Vec<Point2<f64>>,
}

impl FleetTarget {
    /// A target the formation forms around.
    pub fn around(time: f64, position: Point2<f64>) -> Self {
        FleetTarget {
            time,
            position,
            positions: Vec::new(),
        }
    }

    /// Where it is on the map: its point, or the middle of its points.
    pub fn centre(&self) -> Point2<f64> {
        if self.positions.is_empty() {
            self.position
        } else {
            let sum: Vector2<f64> = self.positions.iter().map(|p| p.coords).sum();
            Point2::from(sum / self.positions.len() as f64)
        }
    }

    /// Moves it (every point of it) so its centre is at `p`.
    pub fn move_to(&mut self, p: Point2<f64>) {
        let by = p - self.centre();
        for q in &mut self.positions {
            *q += by;
        }
        if self.positions.is_empty() {
            self.position = p;
        }
    }
}

fn is_unset_point(p: &Point2<f64>) -> bool {
    p.x.is_nan() && p.y.is_nan()
}

/// A push on one agent, as in the disturbance experiment (fleet paper, 4.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FleetPush {
    /// Index of the agent pushed (0-based).
    pub agent: usize,
    /// When, s.
    pub time: f64,
    /// Impulse, N·s, in the flight plane.
    pub impulse: Vector2<f64>,
}

/// Distributed-fleet parameters (fleet paper, eqs. 2-13, Table 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FleetParams {
    /// n: number of quadrotors (3 in Section 4.4).
    pub agents: usize,
    /// ρ ≫ 1: weight of the distance to the target (eq. 6); 5 in Table 1.
    pub rho: f64,
    /// σ: steepness of a_ij and Obs_ik (eqs. 3, 9); 0.4 in Table 1.
    pub sigma: f64,
    /// c: safety distance between agents and to obstacles, metres (0.8 m).
    pub safety_distance: f64,
    /// d_obs: obstacle detection range, metres (3 m).
    pub detection_range: f64,
    /// l: neighbourhood radius of eq. 2, metres.
    pub neighbourhood: f64,
    /// h_max: each PSO searches h ∈ [-h_max, h_max]², metres (0.4 m).
    pub step_max: f64,
    /// τ: re-planning period, s (0.1 s).
    pub replan_period: f64,
    /// d_ip^d: desired distance of each agent to the target, metres (1 m → 1.732 m
    /// between three agents).
    pub target_distance: f64,
    /// Desired inter-agent distances d_ij^d; empty = uniform polygon around the target.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub distances: Vec<Vec<f64>>,
    /// Flight altitude of the plane the fleet moves in, metres.
    pub altitude: f64,
    /// Particles of each agent's PSO.
    pub swarm_size: usize,
    /// Iterations of each agent's PSO per re-plan.
    pub iterations: usize,
    /// PSO inertia w.
    pub inertia: f64,
    /// PSO cognitive gain c1.
    pub cognitive: f64,
    /// PSO social gain c2.
    pub social: f64,
    /// Simulation step of the quadrotor dynamics, s.
    pub sim_step: f64,
    /// Simulated duration, s; absent: as long as the fleet needs at its
    /// cruise speed to reach its last target ([`FleetParams::run_duration`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    /// Quadrotor mass, kg (Parrot AR.Drone 2).
    pub mass: f64,
    /// Diagonal of the inertia matrix J, kg·m².
    pub inertia_diag: Vector3<f64>,
    /// K_pos (eq. 11): [position gain, velocity gain].
    pub position_gains: [f64; 2],
    /// K_att (eq. 13): [attitude gain, rate gain].
    pub attitude_gains: [f64; 2],
    /// Thrust limit, N.
    pub max_thrust: f64,
    /// Tilt limit, degrees.
    pub max_tilt_deg: f64,
    /// Convergence tolerance on every distance, as a fraction of its desired value.
    pub tolerance: f64,
    /// Initial positions (x, y); empty = seeded random inside the bounds.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub initial_positions: Vec<Point2<f64>>,
    /// The timed sequence of targets.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub targets: Vec<FleetTarget>,
    /// Disturbances.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pushes: Vec<FleetPush>,
    /// What each agent hears of the others (`[fleet.network]`); ideal when
    /// absent: every neighbour's state of this very step.
    #[serde(skip_serializing_if = "FleetNetwork::is_ideal")]
    pub network: FleetNetwork,
}

/// The network between the fleet's agents: each agent broadcasts its state
/// (position, velocity, reference) every simulation step; a neighbour hears
/// it `latency` steps later, unless it is lost or out of `range`. Whether a
/// message is lost is a pure function of (seed, sender, receiver, step), so a
/// run is reproducible. See docs/fleet.md.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct FleetNetwork {
    /// Metres a message carries; absent: the neighbourhood radius l.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range: Option<f64>,
    /// Whole simulation steps (`fleet.sim_step`) from sending to hearing.
    pub latency: usize,
    /// Probability that one message to one receiver is lost, in [0, 1).
    pub loss: f64,
    /// Links with a latency of their own (both ways), in place of `latency`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub links: Vec<FleetLink>,
    /// Agents deciding on a clock of their own (asynchronous agents), in
    /// place of the fleet's rounds every τ.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub updates: Vec<FleetUpdate>,
}

/// One agent's own update clock: `updates = [{ agent = 2, period = 30,
/// phase = 7 }]` (agents from 1) has agent 2 decide at steps 7, 37, 67, …
/// instead of at the fleet's rounds (it still decides at once when a
/// neighbour comes closer than c, and still broadcasts every step).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FleetUpdate {
    /// The agent, numbered from 1.
    pub agent: usize,
    /// Whole simulation steps between its decisions.
    pub period: usize,
    /// The step of its first decision, below `period`.
    #[serde(default)]
    pub phase: usize,
}

/// One link of the fleet's network with its own latency:
/// `links = [{ between = [1, 3], latency = 20 }]` (agents from 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FleetLink {
    /// The two agents, numbered from 1.
    pub between: [usize; 2],
    /// Whole simulation steps from sending to hearing, both ways.
    pub latency: usize,
}

impl FleetNetwork {
    /// No latency, no loss, the range of the neighbourhood, every agent on
    /// the fleet's rounds: the fleet as the paper simulates it.
    pub fn is_ideal(&self) -> bool {
        self.range.is_none()
            && self.latency == 0
            && self.loss == 0.0
            && self.links.is_empty()
            && self.updates.is_empty()
    }
}

impl Default for FleetParams {
    fn default() -> Self {
        FleetParams {
            agents: 3,
            rho: 5.0,
            sigma: 0.4,
            safety_distance: 0.8,
            detection_range: 3.0,
            neighbourhood: 5.0,
            step_max: 0.4,
            replan_period: 0.1,
            target_distance: 1.0,
            distances: Vec::new(),
            altitude: 1.0,
            // The paper gives no swarm size: a 2-D step converges well within 20 × 20.
            swarm_size: 20,
            iterations: 20,
            inertia: 0.7298,
            cognitive: 1.49618,
            social: 1.49618,
            sim_step: 0.005,
            duration: None,
            mass: 0.42,
            inertia_diag: Vector3::new(0.0022, 0.0029, 0.0048),
            position_gains: [4.0, 3.0],
            attitude_gains: [60.0, 12.0],
            max_thrust: 8.0,
            max_tilt_deg: 30.0,
            tolerance: 0.05,
            initial_positions: Vec::new(),
            targets: Vec::new(),
            pushes: Vec::new(),
            network: FleetNetwork::default(),
        }
    }
}

/// The longest a fleet run lasts when `fleet.duration` is left out, s:
/// ten minutes of flight, well within the run's budget for the fleets the
/// limits allow (a longer one is written, and `check` says when it is needed).
pub const AUTO_DURATION_MAX: f64 = 600.0;

impl FleetParams {
    /// The speed an agent cruises at on its way, m/s: its reference is at
    /// most h_max ahead on each axis, and the position law (eq. 11) flies
    /// it at K_p / K_d of the distance to it in the steady state.
    pub fn cruise_speed(&self) -> f64 {
        let [kp, kd] = self.position_gains;
        if kd > 0.0 {
            kp / kd * self.step_max
        } else {
            self.step_max / self.replan_period.max(1e-9)
        }
    }

    /// The simulated duration: `duration` when written, else the last
    /// target's time plus twice the time the farthest agent needs to reach
    /// it at the cruise speed (`farthest`, metres) and 20 s to settle,
    /// rounded up to a whole 10 s, at most [`AUTO_DURATION_MAX`].
    pub fn run_duration(&self, last_target: f64, farthest: f64) -> f64 {
        match self.duration {
            Some(d) => d,
            None => {
                let travel = 2.0 * farthest / self.cruise_speed().max(1e-6);
                (((last_target.max(0.0) + travel + 20.0) / 10.0).ceil() * 10.0)
                    .min(AUTO_DURATION_MAX)
            }
        }
    }
}

impl Formation {
    /// r_F = max_n ‖ΔT_n‖: distance of the farthest UAV from the centroid (eq. 6).
    pub fn radius(&self) -> f64 {
        crate::base::geometry::farthest_offset(&self.slots)
    }

    /// The least distance a plan keeps between two UAVs: 2 r_Q + the safety
    /// margin (eq. 7's lower bound with the margin verification holds).
    pub fn closest_pair(&self) -> f64 {
        2.0 * self.uav_radius + self.safety_margin
    }

    /// The least clearance a plan keeps from every obstacle's surface:
    /// r_Q + the safety margin + the obstacle margin.
    pub fn least_clearance(&self) -> f64 {
        self.uav_radius + self.safety_margin + self.obstacle_margin
    }

    /// Safe radius of the whole formation around its centroid, r_F + r_Q.
    pub fn safe_radius(&self) -> f64 {
        self.radius() + self.uav_radius
    }

    /// Centroid of the slots; eq. 6 puts it at the origin of the formation frame.
    pub fn slot_centroid(&self) -> Vector3<f64> {
        if self.slots.is_empty() {
            return Vector3::zeros();
        }
        self.slots.iter().sum::<Vector3<f64>>() / self.slots.len() as f64
    }
}
