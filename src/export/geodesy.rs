//! ENU ↔ WGS-84 about the mission's `[origin]`.
//!
//! The conversion is `map_3d`'s exact one (ENU → ECEF by the rotation at the
//! origin, ECEF → geodetic in closed form with one correction step), not a
//! flat-earth approximation: FLATLO's squadron spans tens of kilometres,
//! where the ground plane of the ENU frame is already 100 m above the
//! ellipsoid (at 35 km; `tests/export.rs` holds the vectors).

use map_3d::Ellipsoid;
use nalgebra::Point3;
use serde::Serialize;

use crate::mission::GeoOrigin;

/// A WGS-84 position: degrees, degrees, metres above the ellipsoid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Geodetic {
    pub latitude: f64,
    pub longitude: f64,
    pub altitude: f64,
}

/// The ENU frame of a mission, anchored at its `[origin]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Radians, radians, metres.
    lat0: f64,
    lon0: f64,
    alt0: f64,
}

impl Frame {
    pub fn new(origin: &GeoOrigin) -> Self {
        Frame {
            lat0: origin.latitude.to_radians(),
            lon0: origin.longitude.to_radians(),
            alt0: origin.altitude,
        }
    }

    /// The WGS-84 position of an ENU point (metres: x east, y north, z up).
    pub fn to_geodetic(&self, p: &Point3<f64>) -> Geodetic {
        let (lat, lon, alt) = map_3d::enu2geodetic(
            p.x,
            p.y,
            p.z,
            self.lat0,
            self.lon0,
            self.alt0,
            Ellipsoid::WGS84,
        );
        Geodetic {
            latitude: lat.to_degrees(),
            longitude: lon.to_degrees(),
            altitude: alt,
        }
    }

    /// The ENU point (metres) of a WGS-84 position.
    pub fn to_enu(&self, g: &Geodetic) -> Point3<f64> {
        let (e, n, u) = map_3d::geodetic2enu(
            g.latitude.to_radians(),
            g.longitude.to_radians(),
            g.altitude,
            self.lat0,
            self.lon0,
            self.alt0,
            Ellipsoid::WGS84,
        );
        Point3::new(e, n, u)
    }
}
