//! An obstacle as a mission writes it: one of three shapes standing from
//! its base to its top (a cylinder; a polygon footprint, a building or a
//! deck; a wire's span, a power line flown under or over), what the planner
//! keeps of it, and the face an inspection looks at. Every planner reads an
//! obstacle through [`Obstacle::prism`] (the solid kept clear of); a wire
//! settles into the box round its span (`Obstacle::settle`), so the
//! planners, the map and the exports know it as a thin footprint at its
//! height.

use nalgebra::{Point2, Point3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::base::shape::{Footprint, Polygon, Prism};

use super::model::{Formation, is_yes, is_zero, unset, unset_point, yes};

/// A vertical prism from `base` (the ground unless set) up to `height`: a
/// cylinder (`center`, `radius`), or a polygon `footprint` (a building, a
/// transformer bay), whose bounding circle `center` and `radius` then are;
/// or a `wire` (a power line's span), which sets all of those itself.
///
/// Written through [`ObstacleFile`], which leaves out what a wire derives.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, into = "ObstacleFile")]
pub struct Obstacle {
    pub name: String,
    /// Axis position, metres ENU; derived from the footprint when there is
    /// one (then the file may leave it out).
    #[serde(default = "unset_point")]
    pub center: Point2<f64>,
    /// Metres; derived from the footprint when there is one.
    #[serde(default = "unset")]
    pub radius: f64,
    /// A simple polygon's vertices, metres ENU, either winding, not closed;
    /// empty for a cylinder.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub footprint: Vec<Point2<f64>>,
    /// Its top, metres above ground; derived from a wire.
    #[serde(default = "unset")]
    pub height: f64,
    /// Its underside, metres above ground: 0 for what stands on the ground,
    /// the clear height under a deck or a gantry beam otherwise.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub base: f64,
    /// A wire between two supports (a power line's span, a cable): a thin
    /// obstacle at its height, flown under or over; `center`, `radius`,
    /// `footprint`, `base` and `height` are then its box's, not written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wire: Option<Wire>,
    /// May the formation fly over its top? `false` for live equipment or
    /// people: the planner then treats it as reaching the sky.
    #[serde(default = "yes", skip_serializing_if = "is_yes")]
    pub overfly: bool,
    /// Metres the formation keeps above its top when it flies over, beyond
    /// r_Q and the margins (a roof's aerials, a crane's swing): the planner
    /// treats it as that much taller.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub clearance_above: f64,
    /// Free label ("pier", "pole", "tree", …), for display only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    /// Free text (a survey's description), kept and exported.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Inspect this obstacle's surface (θ-PSO eq. 8): the plan flies the
    /// formation past it so that the UAV facing it stays within the stand-off
    /// band over a pass of `formation.inspection_pass` metres.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub inspect: bool,
    /// [d_min^s, d_max^s] for this obstacle, metres from its surface (eq. 8);
    /// `formation.surface_distance` when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stand_off: Option<[f64; 2]>,
    /// The face to inspect: the bearing of its outward normal, degrees
    /// clockwise from north (`90` or `"east"`); any face when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inspect_side: Option<Side>,
}

/// The face of an obstacle an inspection looks at: the compass bearing of
/// its outward normal, written as degrees (`inspect_side = 90`) or as a
/// compass point (`inspect_side = "east"`, `"north-west"`, `"NW"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Side {
    Degrees(f64),
    Named(String),
}

impl Side {
    /// The compass points a side may be named by, and their bearings.
    pub const NAMES: [(&'static str, &'static str, f64); 8] = [
        ("north", "n", 0.0),
        ("north-east", "ne", 45.0),
        ("east", "e", 90.0),
        ("south-east", "se", 135.0),
        ("south", "s", 180.0),
        ("south-west", "sw", 225.0),
        ("west", "w", 270.0),
        ("north-west", "nw", 315.0),
    ];

    /// The bearing, degrees clockwise from north in [0, 360); `None` for a
    /// name that is no compass point or a number that is not finite.
    pub fn bearing(&self) -> Option<f64> {
        match self {
            Side::Degrees(d) => d.is_finite().then(|| d.rem_euclid(360.0)),
            Side::Named(name) => {
                let key = name.trim().to_ascii_lowercase().replace([' ', '_'], "-");
                Side::NAMES
                    .iter()
                    .find(|(long, short, _)| {
                        *long == key || *short == key || long.replace('-', "") == key
                    })
                    .map(|(_, _, b)| *b)
            }
        }
    }

    /// The outward normal in the ENU plane (x east, y north).
    pub fn normal(&self) -> Option<Vector2<f64>> {
        let b = self.bearing()?.to_radians();
        Some(Vector2::new(b.sin(), b.cos()))
    }

    /// As the file writes it: the name given, or the degrees (`90`).
    pub fn label(&self) -> String {
        match self {
            Side::Degrees(d) => format!("{d}"),
            Side::Named(n) => n.clone(),
        }
    }

    /// As people read it: the name given, or `90°`.
    pub fn words(&self) -> String {
        match self {
            Side::Degrees(d) => format!("{d}°"),
            Side::Named(n) => n.clone(),
        }
    }
}

/// A wire's span: a straight conductor between two supports, with the
/// room the planner keeps round it beyond r_Q and the margins.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wire {
    /// One end, metres ENU; its z above the ground.
    pub from: Point3<f64>,
    /// The other end.
    pub to: Point3<f64>,
    /// Metres round the conductor kept as the obstacle: the spread of its
    /// conductors and their sway (0.5 m by default).
    #[serde(default = "default_wire_radius")]
    pub radius: f64,
}

/// A wire's radius when the file gives none, metres.
pub const DEFAULT_WIRE_RADIUS: f64 = 0.5;

fn default_wire_radius() -> f64 {
    DEFAULT_WIRE_RADIUS
}

impl Wire {
    /// The footprint of the box the planners keep clear of: the span's
    /// strip `radius` either side, `radius` beyond each end (a square for a
    /// vertical one), anticlockwise.
    pub fn footprint(&self) -> Vec<Point2<f64>> {
        let (a, b) = (self.from.xy(), self.to.xy());
        let r = self.radius.max(0.0);
        let along = b - a;
        let length = along.norm();
        let d = if length > 1e-9 {
            along / length
        } else {
            Vector2::new(1.0, 0.0)
        };
        let n = Vector2::new(-d.y, d.x);
        vec![
            a - d * r - n * r,
            b + d * r - n * r,
            b + d * r + n * r,
            a - d * r + n * r,
        ]
    }

    /// The box's underside and top, metres above the ground: the lower
    /// end less the radius (not below the ground), the higher plus it.
    pub fn heights(&self) -> [f64; 2] {
        let r = self.radius.max(0.0);
        [
            (self.from.z.min(self.to.z) - r).max(0.0),
            self.from.z.max(self.to.z) + r,
        ]
    }

    /// Its horizontal length, metres.
    pub fn span(&self) -> f64 {
        (self.to.xy() - self.from.xy()).norm()
    }
}

/// An obstacle as a file writes it: a wire's derived box left out.
#[derive(Serialize)]
pub struct ObstacleFile {
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    center: Option<Point2<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    radius: Option<f64>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    footprint: Vec<Point2<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    height: Option<f64>,
    #[serde(skip_serializing_if = "is_zero")]
    base: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    wire: Option<Wire>,
    #[serde(skip_serializing_if = "is_yes")]
    overfly: bool,
    #[serde(skip_serializing_if = "is_zero")]
    clearance_above: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    kind: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    description: Option<String>,
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    inspect: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    stand_off: Option<[f64; 2]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    inspect_side: Option<Side>,
}

impl From<Obstacle> for ObstacleFile {
    fn from(o: Obstacle) -> Self {
        let wire = o.wire.is_some();
        // A footprint's bounding circle is derived (read back, it is worked
        // out again): written to the millimetre, the radius rounded up.
        let derived = o.footprint.len() >= 3;
        let (center, radius) = if derived {
            let mm = |v: f64| (v * 1000.0).round() / 1000.0;
            (
                Point2::new(mm(o.center.x), mm(o.center.y)),
                (o.radius * 1000.0).ceil() / 1000.0,
            )
        } else {
            (o.center, o.radius)
        };
        ObstacleFile {
            name: o.name,
            center: (!wire).then_some(center),
            radius: (!wire).then_some(radius),
            footprint: if wire { Vec::new() } else { o.footprint },
            height: (!wire).then_some(o.height),
            base: if wire { 0.0 } else { o.base },
            wire: o.wire,
            overfly: o.overfly,
            clearance_above: o.clearance_above,
            kind: o.kind,
            description: o.description,
            inspect: o.inspect,
            stand_off: o.stand_off,
            inspect_side: o.inspect_side,
        }
    }
}

impl Obstacle {
    /// The eq. 8 band for this obstacle: its own, or the formation's.
    pub fn stand_off_band(&self, formation: &Formation) -> [f64; 2] {
        self.stand_off.unwrap_or(formation.surface_distance)
    }

    /// The top the planner keeps under the formation: the sky when it may
    /// not be flown over.
    pub fn top(&self) -> f64 {
        if self.overfly {
            self.height + self.clearance_above.max(0.0)
        } else {
            f64::INFINITY
        }
    }

    /// Does it stand in the way of a UAV at altitude `z` (between its base
    /// and its top)?
    pub fn spans(&self, z: f64) -> bool {
        self.base < z && z < self.top()
    }

    /// Does any of it lie within the altitudes `band`?
    pub fn within(&self, band: [f64; 2]) -> bool {
        self.top() > band[0] && self.base < band[1]
    }

    /// Does it close the altitudes `band` to a UAV that keeps `clearance`
    /// from it: no room over its top, nor under its base?
    pub fn closes(&self, band: [f64; 2], clearance: f64) -> bool {
        self.top() + clearance > band[1] && self.base - clearance < band[0]
    }

    /// Its shape in the plane, as the file writes it: a polygon when it has
    /// a footprint (a wire's is its box), else a circle. Every planner,
    /// check, drawing and export reads the shape through this; a new shape
    /// is read here.
    pub fn outline(&self) -> Footprint {
        if self.footprint.is_empty() {
            Footprint::circle(self.center, self.radius)
        } else {
            Footprint::new(Polygon::bounded(&self.footprint, self.center, self.radius))
        }
    }

    /// The solid the planner keeps clear of: up to the sky when it may not
    /// be flown over.
    pub fn prism(&self) -> Prism {
        Prism {
            center: self.center,
            radius: self.radius,
            outline: self.outline(),
            base: self.base,
            height: self.top(),
        }
    }

    /// A polygon's `center` and `radius` are its bounding circle's: set
    /// them from the footprint (after reading a file, after an edit of a
    /// vertex); a wire's box sets its footprint, base and height too.
    pub fn settle(&mut self) {
        if let Some(w) = &self.wire {
            self.footprint = w.footprint();
            [self.base, self.height] = w.heights();
        }
        if self.footprint.len() >= 3 {
            (self.center, self.radius) = crate::base::geometry::bounding_circle(&self.footprint);
        }
    }

    /// Is it a wire?
    pub fn is_wire(&self) -> bool {
        self.wire.is_some()
    }

    /// What it is, in a word or two: "wire", "footprint", "cylinder".
    pub fn shape_name(&self) -> &'static str {
        if self.is_wire() {
            "wire"
        } else {
            self.outline().kind()
        }
    }

    /// Moves the obstacle, its footprint (a wire's ends) with it, so its
    /// centre is at `p`.
    pub fn move_to(&mut self, p: Point2<f64>) {
        let by = p - self.center;
        for v in &mut self.footprint {
            *v += by;
        }
        if let Some(w) = &mut self.wire {
            w.from += Vector3::new(by.x, by.y, 0.0);
            w.to += Vector3::new(by.x, by.y, 0.0);
        }
        self.center = p;
    }

    /// Sets the radius; a footprint is scaled about the centre to match; a
    /// wire's radius is the room round the conductor.
    pub fn set_radius(&mut self, radius: f64) {
        if let Some(w) = &mut self.wire {
            w.radius = radius;
            self.settle();
            return;
        }
        if !self.footprint.is_empty() && self.radius > 0.0 && radius.is_finite() && radius > 0.0 {
            let k = radius / self.radius;
            for v in &mut self.footprint {
                *v = self.center + (*v - self.center) * k;
            }
        }
        self.radius = radius;
    }

    /// A cylinder standing on the ground, to be overflown: the fields every
    /// obstacle has, with the rest at their defaults.
    pub fn standing(
        name: impl Into<String>,
        center: Point2<f64>,
        radius: f64,
        height: f64,
    ) -> Self {
        Obstacle {
            name: name.into(),
            center,
            radius,
            height,
            footprint: Vec::new(),
            base: 0.0,
            overfly: true,
            clearance_above: 0.0,
            kind: None,
            description: None,
            inspect: false,
            stand_off: None,
            wire: None,
            inspect_side: None,
        }
    }

    /// A wire from `from` to `to` (metres ENU, z above the ground) with
    /// `radius` of room round it, its box settled.
    pub fn wire(name: impl Into<String>, from: Point3<f64>, to: Point3<f64>, radius: f64) -> Self {
        let mut o = Obstacle::standing(name, nalgebra::center(&from.xy(), &to.xy()), radius, 0.0);
        o.wire = Some(Wire { from, to, radius });
        o.settle();
        o
    }
}

/// The name among `names` a mistyped `name` most likely meant: the same
/// but for case, else the one within two edits (Levenshtein) nearest it.
pub fn nearest_name<'a>(name: &str, names: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    fn edits(a: &str, b: &str) -> usize {
        let b: Vec<char> = b.chars().collect();
        let mut row: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.chars().enumerate() {
            let mut diagonal = row[0];
            row[0] = i + 1;
            for (j, cb) in b.iter().enumerate() {
                let up = row[j + 1];
                row[j + 1] = (up + 1)
                    .min(row[j] + 1)
                    .min(diagonal + usize::from(ca != *cb));
                diagonal = up;
            }
        }
        row[b.len()]
    }
    let lower = name.to_lowercase();
    names
        .map(|n| {
            (
                n,
                if n.to_lowercase() == lower {
                    0
                } else {
                    edits(&lower, &n.to_lowercase())
                },
            )
        })
        .filter(|(_, d)| *d <= 2)
        .min_by_key(|(_, d)| *d)
        .map(|(n, _)| n)
}
