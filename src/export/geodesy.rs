//! Where the files put a point: one altitude convention for `.plan`, WPL,
//! CSV and KML, and the precision each of them stores.
//!
//! The mission is planned on flat ground: z is the height above the
//! mission's ground (the ENU plane z = 0, or `[terrain]` in that frame),
//! and `[origin]` gives the altitude of that ground at the origin. An
//! autopilot holds altitudes above its home (MAVLink's frame 3) on the
//! real, curved Earth. So a point (x, y, z) is written:
//!
//! - at the latitude and longitude of the ground point (x, y) (the mission's
//!   own geodesy, `mission::geodesy`, exact ENU ↔ WGS-84: the same point an
//!   obstacle's centre or a surveyed position is read from);
//! - at the altitude `[origin].altitude + z`: z metres above the level
//!   ground through the origin, not the ellipsoidal height of the ENU point
//!   (the tangent plane climbs away from the Earth: 0.8 mm at 100 m from the
//!   origin, 950 m at 110 km, which put FLATLO's homes at 1108.8 m over
//!   ground at 160 m before);
//! - relative to the vehicle's home (frame 3) as `z − ground(home)`.
//!
//! A vehicle's home is the ground under its first waypoint, where it is
//! armed: without terrain that is the origin's ground, `[origin].altitude`,
//! for every vehicle.
//!
//! Precision: MAVLink carries latitude and longitude as int32 in 1e-7° (what
//! MAVSDK's importer, QGroundControl's upload and the autopilot keep) and the
//! altitude as float32. The waypoint files hold exactly those values, and
//! the re-verification flies them ([`Placement::stored`]).

pub use crate::mission::geodesy::{Frame, Geodetic};

use nalgebra::{Point2, Point3};

use crate::mission::Mission;

/// 1e-7°: MAVLink's unit of latitude and longitude (`MISSION_ITEM_INT` x, y).
pub const E7: f64 = 1e7;

/// The most a stored position is from the point it stands for, metres: half
/// a 1e-7° step in latitude (5.6 mm) and in longitude (up to 5.6 mm, at the
/// equator) at once, plus float32's half step at 10 km of altitude (0.5 mm).
pub const RESOLUTION: f64 = 0.0085;

/// Latitude or longitude in whole 1e-7° (rounded to the nearest, as
/// QGroundControl and MAVSDK do).
pub fn to_e7(degrees: f64) -> i64 {
    (degrees * E7).round() as i64
}

/// A value as MAVLink's float32 keeps it, written as the shortest decimal
/// that reads back to that float32 (so `10.000531`, not `10.000530242919922`):
/// every reader that stores it as float32 gets this very number.
pub fn as_f32(v: f64) -> f64 {
    let f = v as f32;
    format!("{f}").parse().unwrap_or(f64::from(f))
}

/// What a waypoint file stores of a point, for one vehicle's home.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stored {
    /// Whole 1e-7°.
    pub latitude: i64,
    pub longitude: i64,
    /// Metres above the home, as float32 keeps it.
    pub relative: f64,
}

impl Stored {
    pub fn latitude_deg(&self) -> f64 {
        self.latitude as f64 / E7
    }

    pub fn longitude_deg(&self) -> f64 {
        self.longitude as f64 / E7
    }
}

/// A vehicle's home: where it is armed, the ground under its first waypoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Home {
    /// ENU, metres (z: the mission's ground there).
    pub enu: Point3<f64>,
    /// Whole 1e-7°.
    pub latitude: i64,
    pub longitude: i64,
    /// `[origin].altitude` + the ground's z, metres (as float32 keeps it).
    pub altitude: f64,
}

impl Home {
    pub fn latitude_deg(&self) -> f64 {
        self.latitude as f64 / E7
    }

    pub fn longitude_deg(&self) -> f64 {
        self.longitude as f64 / E7
    }
}

/// The convention of this module for one mission (it needs an `[origin]`).
#[derive(Clone, Copy)]
pub struct Placement<'a> {
    frame: Frame,
    /// `[origin].altitude`, metres.
    datum: f64,
    mission: &'a Mission,
}

impl<'a> Placement<'a> {
    /// `None` without `[origin]`.
    pub fn new(mission: &'a Mission) -> Option<Self> {
        let origin = mission.origin.as_ref()?;
        Some(Placement {
            frame: Frame::new(origin),
            datum: origin.altitude,
            mission,
        })
    }

    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// `[origin].altitude`: the altitude of the mission's ground z = 0.
    pub fn datum(&self) -> f64 {
        self.datum
    }

    /// Latitude and longitude (degrees) of the ground point under `p` and
    /// its altitude, `[origin].altitude + z` (unrounded: the KML and CSV).
    pub fn absolute(&self, p: &Point3<f64>) -> Geodetic {
        let g = self.frame.ground_to_geodetic(&p.xy());
        Geodetic {
            latitude: g.latitude,
            longitude: g.longitude,
            altitude: self.datum + p.z,
        }
    }

    /// The ENU point of a latitude and longitude (degrees) at height `z`.
    pub fn enu(&self, latitude: f64, longitude: f64, z: f64) -> Point3<f64> {
        let p = self.frame.ground_to_enu(latitude, longitude);
        Point3::new(p.x, p.y, z)
    }

    /// The home of a vehicle whose first waypoint is over `first`: the ground
    /// under the stored position of that waypoint.
    pub fn home(&self, first: &Point2<f64>) -> Home {
        let g = self.frame.ground_to_geodetic(first);
        let (latitude, longitude) = (to_e7(g.latitude), to_e7(g.longitude));
        let xy = self
            .frame
            .ground_to_enu(latitude as f64 / E7, longitude as f64 / E7);
        let ground = self.mission.ground(xy.x, xy.y);
        Home {
            enu: Point3::new(xy.x, xy.y, ground),
            latitude,
            longitude,
            altitude: as_f32(self.datum + ground),
        }
    }

    /// What a waypoint file stores of `p` for a vehicle armed at `home`.
    pub fn stored(&self, p: &Point3<f64>, home: &Home) -> Stored {
        let g = self.frame.ground_to_geodetic(&p.xy());
        Stored {
            latitude: to_e7(g.latitude),
            longitude: to_e7(g.longitude),
            relative: as_f32(p.z - home.enu.z),
        }
    }

    /// Where the autopilot puts what the file stores (ENU, metres).
    pub fn flown(&self, s: &Stored, home: &Home) -> Point3<f64> {
        self.enu(s.latitude_deg(), s.longitude_deg(), home.enu.z + s.relative)
    }

    /// `p` moved to where its stored coordinates put it.
    pub fn round_trip(&self, p: &Point3<f64>, home: &Home) -> Point3<f64> {
        self.flown(&self.stored(p, home), home)
    }
}
