//! QGroundControl `.plan` files (JSON, plan version 1, mission version 2).
//!
//! What the readers need (QGroundControl's `PlanMasterController`, MAVSDK's
//! `mission_import.cpp`): `fileType "Plan"`, `groundStation`, a mission with
//! `firmwareType`, `vehicleType`, `plannedHomePosition` and items of type
//! `SimpleItem` (command, frame, autoContinue, 7 params, doJumpId, and the
//! Altitude/AltitudeMode/AMSLAltAboveTerrain keys together for positioned
//! items); a version-2 `geoFence` with `polygons` and `circles`; a version-2
//! `rallyPoints`. Without `geoFence` or `rallyPoints` MAVSDK refuses the file.
//!
//! Latitudes and longitudes are written on MAVLink's 1e-7° grid and
//! altitudes as the float32 they become: the file says what the autopilot
//! keeps.

use serde_json::{Value, json};

use super::{Item, Placement, Planned, VehiclePlan, items};
use crate::mission::Mission;

/// MAV_AUTOPILOT: PX4 for the quadrotor pipelines, ArduPilot for FLATLO's
/// fixed-wing aircraft (ArduPlane).
pub fn firmware_type(planned: &Planned) -> u8 {
    if planned.pipeline.words().fixed_wing {
        3
    } else {
        12
    }
}

/// MAV_TYPE: 1 fixed wing, 2 quadrotor.
pub fn vehicle_type(planned: &Planned) -> u8 {
    if planned.pipeline.words().fixed_wing {
        1
    } else {
        2
    }
}

fn item_json(item: &Item, jump: usize) -> Value {
    let [p1, p2, p3, p4] = item.params;
    match item.at {
        Some(at) => {
            let (lat, lon, alt) = (at.latitude_deg(), at.longitude_deg(), at.relative);
            json!({
                "type": "SimpleItem",
                "doJumpId": jump,
                "autoContinue": true,
                "command": item.command,
                "frame": item.frame,
                "params": [p1, p2, p3, p4, lat, lon, alt],
                "Altitude": alt,
                "AltitudeMode": 1,
                "AMSLAltAboveTerrain": null,
            })
        }
        None => json!({
            "type": "SimpleItem",
            "doJumpId": jump,
            "autoContinue": true,
            "command": item.command,
            "frame": item.frame,
            "params": [p1, p2, p3, p4, 0, 0, 0],
        }),
    }
}

/// The `.plan` text of one vehicle, and its number of mission items.
pub fn render(
    mission: &Mission,
    planned: &Planned,
    plan: &VehiclePlan,
    placement: &Placement,
    tolerance: f64,
) -> (String, usize) {
    let (home, list) = items(planned, plan, placement, tolerance);
    let json_items: Vec<Value> = list
        .iter()
        .enumerate()
        .map(|(i, item)| item_json(item, i + 1))
        .collect();
    // QGroundControl's estimate of the flight time; every leg's own speed
    // is a DO_CHANGE_SPEED (all within the vehicle's limits, or refused).
    let cruise = plan.waypoints.iter().map(|w| w.speed).fold(0.0, f64::max);
    let frame = placement.frame();
    let b = &mission.bounds;
    let corner = |x: f64, y: f64| {
        let g = frame.ground_to_geodetic(&nalgebra::Point2::new(x, y));
        json!([g.latitude, g.longitude])
    };
    // Clockwise from the north-west corner, as QGroundControl draws them.
    let polygon = json!([
        corner(b.x[0], b.y[1]),
        corner(b.x[1], b.y[1]),
        corner(b.x[1], b.y[0]),
        corner(b.x[0], b.y[0]),
    ]);
    let circles: Vec<Value> = super::fence_obstacles(mission, planned)
        .map(|o| {
            let g = frame.ground_to_geodetic(&o.center);
            json!({
                "circle": {"center": [g.latitude, g.longitude], "radius": o.radius},
                "inclusion": false,
                "version": 1,
            })
        })
        .collect();
    let doc = json!({
        "fileType": "Plan",
        "version": 1,
        "groundStation": "skyform",
        "mission": {
            "version": 2,
            "firmwareType": firmware_type(planned),
            "vehicleType": vehicle_type(planned),
            "cruiseSpeed": cruise,
            "hoverSpeed": cruise,
            "plannedHomePosition": [home.latitude_deg(), home.longitude_deg(), home.altitude],
            "items": json_items,
        },
        "geoFence": {
            "version": 2,
            "polygons": [{"inclusion": true, "version": 1, "polygon": polygon}],
            "circles": circles,
        },
        "rallyPoints": {"version": 2, "points": []},
    });
    let mut text = serde_json::to_string_pretty(&doc).unwrap_or_default();
    text.push('\n');
    (text, list.len())
}
