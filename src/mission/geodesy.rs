//! ENU ↔ WGS-84 about the mission's `[origin]`.
//!
//! The conversion is `map_3d`'s exact one (ENU → ECEF by the rotation at the
//! origin, ECEF → geodetic in closed form with one correction step), not a
//! flat-earth approximation: FLATLO's squadron spans tens of kilometres,
//! where the ground plane of the ENU frame is already 100 m above the
//! ellipsoid (at 35 km; `tests/all/export.rs` holds the vectors).
//!
//! Missions read latitude/longitude positions through it (`geodetic.rs`)
//! and the exports write through it, so a point written either way is the
//! same point. A position on the ground (an obstacle's centre, a fleet
//! target) is the point of the ENU ground plane z = 0 at that latitude and
//! longitude: the exact inverse of how the exports place ground points.

use map_3d::Ellipsoid;
use nalgebra::{Point2, Point3};
use serde::Serialize;

use super::model::GeoOrigin;

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

    /// The WGS-84 position of the ground point (x, y, 0) of the ENU plane.
    pub fn ground_to_geodetic(&self, p: &Point2<f64>) -> Geodetic {
        self.to_geodetic(&Point3::new(p.x, p.y, 0.0))
    }

    /// The point (x, y) of the ENU ground plane z = 0 whose latitude and
    /// longitude are the given ones (degrees): the inverse of
    /// [`Frame::ground_to_geodetic`]. The ground plane leaves the ellipsoid
    /// as it curves away (0.8 mm at 100 m, 78 m at 32 km), so the ellipsoidal
    /// height of that point is found by fixed-point iteration; each step
    /// shrinks the error by about (distance / Earth radius)², so three give
    /// the point to well below a micrometre anywhere a mission can reach.
    pub fn ground_to_enu(&self, latitude: f64, longitude: f64) -> Point2<f64> {
        let mut altitude = self.alt0;
        let mut p = Point3::origin();
        for _ in 0..4 {
            p = self.to_enu(&Geodetic {
                latitude,
                longitude,
                altitude,
            });
            altitude = self.to_geodetic(&Point3::new(p.x, p.y, 0.0)).altitude;
        }
        Point2::new(p.x, p.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        Frame::new(&GeoOrigin {
            latitude: -33.87601,
            longitude: 151.191182,
            altitude: 0.0,
        })
    }

    #[test]
    fn a_ground_point_comes_back_from_its_latitude_and_longitude() {
        let f = frame();
        for (x, y) in [(70.0, 30.0), (-2500.0, 1800.0), (35_000.0, -35_700.0)] {
            let p = Point2::new(x, y);
            let g = f.ground_to_geodetic(&p);
            let back = f.ground_to_enu(g.latitude, g.longitude);
            assert!((back - p).norm() < 1e-6, "{p} -> {back}");
        }
    }

    #[test]
    fn far_from_the_origin_the_ground_plane_is_above_the_ellipsoid() {
        // Why the iteration: at 35 km the plane z = 0 is ~96 m above the
        // ellipsoid, and taking the ellipsoid (altitude 0) instead moves the
        // point by ~0.5 m horizontally.
        let f = frame();
        let p = Point2::new(35_000.0, 0.0);
        let g = f.ground_to_geodetic(&p);
        assert!(g.altitude > 90.0, "{g:?}");
        let naive = f.to_enu(&Geodetic { altitude: 0.0, ..g });
        assert!((naive.xy() - p).norm() > 0.1);
    }
}
