//! The plan as KML, to look at over the imagery a site is checked with
//! (Google Earth, QGIS, …): written with the `kml` crate.
//!
//! One Document: its description carries the run's verdict; a folder
//! "Mission" with the bounds, the start and goal, every obstacle as an
//! extruded circle as tall as the obstacle, and each inspected obstacle's
//! stand-off band (eq. 8) as a ring on the ground; then one folder per
//! vehicle with its home and its planned track, in the vehicle's colour on
//! the map. Altitudes are `absolute`, in the export's one convention
//! (`geodesy`): `[origin].altitude + z`, the altitudes the waypoint files'
//! homes and relative heights add up to, so the KML shows where the
//! vehicles fly, not heights above Google Earth's own terrain. The bounds
//! and the bands are on the ground. Positions go through the mission's
//! geodesy (`mission::geodesy`), to 1e-9° (0.1 mm) and 1 mm.

use std::collections::HashMap;

use kml::types::{
    AltitudeMode, Coord, Element, Folder, Geometry, LineString, LineStyle, LinearRing,
    MultiGeometry, Placemark, Point, PolyStyle, Polygon, Style,
};
use kml::{Kml, KmlDocument, KmlVersion, KmlWriter};
use nalgebra::{Point2, Point3};

use super::{Placement, Planned, VehiclePlan, noun};
use crate::mission::{Mission, Obstacle};
use crate::outcome::tracks::vehicle_color;

/// How far an outline drawn in the KML (an obstacle, a band's edge) may
/// stray inside a curve: a centimetre, finer than a survey.
const OUTLINE_TOLERANCE: f64 = 0.01;

/// The folder of vehicle `i` (0-based), as readers find it: "UAV 1",
/// "aircraft 1", "agent 1".
pub fn vehicle_folder(noun: &str, i: usize) -> String {
    format!("{noun} {}", i + 1)
}

/// KML's `aabbggrr` colour of an RGB colour with alpha `a`.
pub fn kml_color([r, g, b]: [u8; 3], a: u8) -> String {
    format!("{a:02x}{b:02x}{g:02x}{r:02x}")
}

/// The KML text of the plan, and its number of placemarks: `plans` give
/// each vehicle's home (the waypoint files' home).
pub fn render(
    mission: &Mission,
    planned: &Planned,
    plans: &[VehiclePlan],
    placement: &Placement,
) -> (String, usize) {
    let noun = noun(planned.pipeline);
    let mut placemarks = 0;
    let mut elements = vec![
        text(
            "name",
            &format!("{} — {}", mission.name, planned.pipeline.words().slug),
        ),
        text("open", "1"),
        text("description", &description(mission, planned)),
    ];
    elements.extend(styles(planned));
    let mission_folder = mission_folder(mission, placement, &mut placemarks);
    elements.push(mission_folder);
    for track in &planned.tracks {
        let mut coords: Vec<Coord<f64>> = track
            .samples
            .iter()
            .map(|s| absolute(placement, &s.position))
            .collect();
        // A vehicle holding still: one vertex (readers drop repeats anyway).
        coords.dedup();
        let line = LineString {
            coords,
            altitude_mode: AltitudeMode::Absolute,
            ..LineString::default()
        };
        let name = vehicle_folder(noun, track.vehicle);
        let style = format!("uav{}", track.vehicle + 1);
        let placemark = Placemark {
            name: Some(format!("{name} track")),
            description: Some(format!(
                "{} samples over {:.1} s, seed {}; absolute altitudes ([origin].altitude + z)",
                track.samples.len(),
                track.duration(),
                planned.seed
            )),
            geometry: Some(Geometry::LineString(line)),
            children: vec![style_url(&style)],
            ..Placemark::default()
        };
        let mut folder_elements = vec![Kml::Placemark(placemark)];
        placemarks += 1;
        if let Some(home) = plans
            .iter()
            .find(|p| p.vehicle == track.vehicle)
            .and_then(|p| p.home)
        {
            folder_elements.push(Kml::Placemark(Placemark {
                name: Some(format!("{name} home")),
                description: Some(format!(
                    "where {name} is armed: the ground under its first waypoint, at {} m \
                     (the waypoint files' home; their heights are above it)",
                    home.altitude
                )),
                geometry: Some(Geometry::Point(Point {
                    coord: Coord {
                        x: home.longitude_deg(),
                        y: home.latitude_deg(),
                        z: Some(home.altitude),
                    },
                    altitude_mode: AltitudeMode::Absolute,
                    ..Point::default()
                })),
                children: vec![style_url(&style)],
                ..Placemark::default()
            }));
            placemarks += 1;
        }
        elements.push(Kml::Folder(Folder {
            name: Some(name),
            elements: folder_elements,
            ..Folder::default()
        }));
    }
    let root = Kml::KmlDocument(KmlDocument {
        version: KmlVersion::V22,
        attrs: HashMap::from([(
            "xmlns".to_owned(),
            "http://www.opengis.net/kml/2.2".to_owned(),
        )]),
        elements: vec![Kml::Document {
            attrs: HashMap::new(),
            elements,
        }],
    });
    let mut body = Vec::new();
    let written = KmlWriter::<_, f64>::new(quick_xml::Writer::new_with_indent(&mut body, b' ', 2))
        .write(&root);
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    if written.is_ok() {
        out.push_str(&String::from_utf8_lossy(&body));
    }
    out.push('\n');
    (out, placemarks)
}

/// The verdict, what the altitudes mean, and the run.
fn description(mission: &Mission, planned: &Planned) -> String {
    let mut out = format!(
        "{} plan, seed {}: {}\n\nAltitudes are absolute: [origin].altitude plus the \
         mission's z (its height above the mission's ground), as the exported waypoint \
         files' homes and relative heights add up to.",
        planned.pipeline.words().slug,
        planned.seed,
        planned.verdict
    );
    if !mission.description.is_empty() {
        out.push_str("\n\n");
        out.push_str(&mission.description);
    }
    out
}

/// One style per vehicle (its colour on the map), obstacles, inspected
/// obstacles, the bands and the bounds.
fn styles(planned: &Planned) -> Vec<Kml<f64>> {
    let style = |id: String, line: (String, f64), poly: Option<String>| {
        Kml::Style(Style {
            id: Some(id),
            line: Some(LineStyle {
                color: line.0,
                width: line.1,
                ..LineStyle::default()
            }),
            poly: poly.map(|color| PolyStyle {
                color,
                ..PolyStyle::default()
            }),
            ..Style::default()
        })
    };
    let mut out: Vec<Kml<f64>> = planned
        .tracks
        .iter()
        .map(|t| {
            let rgb = vehicle_color(t.vehicle);
            style(
                format!("uav{}", t.vehicle + 1),
                (kml_color(rgb, 0xff), 3.0),
                None,
            )
        })
        .collect();
    out.push(style(
        "obstacle".into(),
        (kml_color([200, 200, 200], 0xff), 1.0),
        Some(kml_color([150, 150, 150], 0xb0)),
    ));
    out.push(style(
        "inspected".into(),
        (kml_color([255, 170, 40], 0xff), 2.0),
        Some(kml_color([255, 170, 40], 0xb0)),
    ));
    out.push(style(
        "band".into(),
        (kml_color([255, 170, 40], 0xff), 1.0),
        Some(kml_color([255, 170, 40], 0x50)),
    ));
    out.push(style(
        "bounds".into(),
        (kml_color([255, 255, 255], 0xff), 2.0),
        None,
    ));
    out
}

/// The bounds, start and goal, obstacles and inspection bands.
fn mission_folder(mission: &Mission, placement: &Placement, placemarks: &mut usize) -> Kml<f64> {
    let b = &mission.bounds;
    let corners = [
        (b.x[0], b.y[0]),
        (b.x[1], b.y[0]),
        (b.x[1], b.y[1]),
        (b.x[0], b.y[1]),
        (b.x[0], b.y[0]),
    ];
    let ring: Vec<Coord<f64>> = corners
        .iter()
        .map(|(x, y)| on_ground(placement, &Point2::new(*x, *y)))
        .collect();
    let mut elements = vec![placemark(
        "bounds",
        format!(
            "x {:?}, y {:?} m about [origin]; altitude band z {:?} m",
            b.x, b.y, b.z
        ),
        Geometry::LineString(LineString {
            coords: ring,
            tessellate: true,
            altitude_mode: AltitudeMode::ClampToGround,
            ..LineString::default()
        }),
        "bounds",
    )];
    for (name, p) in [("start", mission.route.start), ("goal", mission.route.goal)] {
        elements.push(placemark(
            name,
            format!(
                "formation centroid at {:.1} m above the ground",
                p.z - mission.ground(p.x, p.y)
            ),
            Geometry::Point(Point {
                coord: absolute(placement, &p),
                altitude_mode: AltitudeMode::Absolute,
                ..Point::default()
            }),
            "bounds",
        ));
    }
    let obstacles: Vec<Kml<f64>> = mission
        .obstacles
        .iter()
        .map(|o| obstacle(mission, o, placement))
        .collect();
    let bands: Vec<Kml<f64>> = mission
        .obstacles
        .iter()
        .filter(|o| o.inspect)
        .map(|o| band(mission, o, placement))
        .collect();
    *placemarks += elements.len() + obstacles.len() + bands.len();
    elements.push(folder("Obstacles", obstacles));
    if !bands.is_empty() {
        elements.push(folder("Inspection bands", bands));
    }
    folder("Mission", elements)
}

/// An obstacle: its circle at its top (absolute: [origin].altitude, the
/// ground under its centre and its height), extruded to the ground; one
/// with room under it (a deck) as a closed solid from its base to its top.
fn obstacle(mission: &Mission, o: &Obstacle, placement: &Placement) -> Kml<f64> {
    let ground = mission.ground(o.center.x, o.center.y);
    if let Some(w) = &o.wire {
        // A wire as the conductor it is: a line at its height.
        let end = |p: &Point3<f64>| {
            absolute(
                placement,
                &Point3::new(p.x, p.y, mission.ground(p.x, p.y) + p.z),
            )
        };
        let mut text = format!(
            "wire from {} to {} m above the ground, kept {} m round",
            w.from.z, w.to.z, w.radius
        );
        if let Some(kind) = &o.kind {
            text = format!("{kind}: {text}");
        }
        if let Some(d) = &o.description {
            text = format!("{text}\n{d}");
        }
        return placemark(
            &o.name,
            text,
            Geometry::LineString(kml::types::LineString {
                coords: vec![end(&w.from), end(&w.to)],
                altitude_mode: AltitudeMode::Absolute,
                ..kml::types::LineString::default()
            }),
            "obstacle",
        );
    }
    let ring_at = |z: f64| {
        let at = |p: &Point2<f64>| absolute(placement, &Point3::new(p.x, p.y, ground + z));
        // The outline (a footprint as surveyed, a curve at a centimetre),
        // closed, counter-clockwise (KML's outer boundary winding).
        let outline = o.outline().ring(OUTLINE_TOLERANCE);
        let mut ring: Vec<_> = outline.iter().map(at).collect();
        if signed_area(&outline) < 0.0 {
            ring.reverse();
        }
        ring.push(ring[0]);
        ring
    };
    let geometry = if o.base > 0.0 {
        let (top, bottom) = (ring_at(o.height), ring_at(o.base));
        let walls = top.windows(2).zip(bottom.windows(2)).map(|(t, b)| {
            let quad = vec![t[0], t[1], b[1], b[0], t[0]];
            polygon(quad, Vec::new(), AltitudeMode::Absolute, false)
        });
        let mut faces = vec![
            polygon(top.clone(), Vec::new(), AltitudeMode::Absolute, false),
            polygon(bottom.clone(), Vec::new(), AltitudeMode::Absolute, false),
        ];
        faces.extend(walls);
        Geometry::MultiGeometry(MultiGeometry {
            geometries: faces,
            attrs: HashMap::new(),
        })
    } else {
        polygon(ring_at(o.height), Vec::new(), AltitudeMode::Absolute, true)
    };
    let outline = o.outline().words();
    let mut text = if o.base > 0.0 {
        format!(
            "{outline}, from {} to {} m above the ground",
            o.base, o.height
        )
    } else {
        format!("{outline}, height {} m above the ground", o.height)
    };
    if !o.overfly {
        text.push_str("; not to be flown over");
    }
    if let Some(kind) = &o.kind {
        text = format!("{kind}: {text}");
    }
    if o.inspect {
        text.push_str("; inspected (eq. 8)");
        if let Some(side) = &o.inspect_side {
            text.push_str(&format!(", its {} face", side.words()));
        }
    }
    // The survey's own words, kept.
    if let Some(d) = &o.description {
        text = format!("{text}\n{d}");
    }
    placemark(
        &o.name,
        text,
        geometry,
        if o.inspect { "inspected" } else { "obstacle" },
    )
}

/// Twice the signed area of a polygon: positive counter-clockwise.
fn signed_area(v: &[Point2<f64>]) -> f64 {
    (0..v.len())
        .map(|i| v[i].coords.perp(&v[(i + 1) % v.len()].coords))
        .sum()
}

/// An inspected obstacle's stand-off band [d_min, d_max] from its surface,
/// as a ring on the ground: about a cylinder two circles, about a
/// footprint its outline offset by each (`geo`'s buffer, round corners).
fn band(mission: &Mission, o: &Obstacle, placement: &Placement) -> Kml<f64> {
    let [d_min, d_max] = o.stand_off_band(&mission.formation);
    let outline = o.outline().ring(OUTLINE_TOLERANCE);
    let offset = |d: f64| footprint_offset(&outline, d, |p| on_ground(placement, p));
    let (outer, inner) = (offset(d_max), offset(d_min.max(1e-3)));
    placemark(
        &format!("{} band", o.name),
        format!(
            "eq. 8: the facing UAV stays {d_min}-{d_max} m from the surface over {} m of path, \
             within the altitude band z {:?} m",
            mission.formation.inspection_pass, mission.bounds.z
        ),
        polygon(outer, vec![inner], AltitudeMode::ClampToGround, false),
        "band",
    )
}

/// The outline of a footprint grown by `d` metres (round corners), as a
/// closed ring counter-clockwise, through `at`.
fn footprint_offset(
    footprint: &[Point2<f64>],
    d: f64,
    at: impl Fn(&Point2<f64>) -> Coord<f64>,
) -> Vec<Coord<f64>> {
    use geo::Buffer;
    let mut ring: Vec<geo::Coord<f64>> = footprint
        .iter()
        .map(|p| geo::coord! { x: p.x, y: p.y })
        .collect();
    ring.push(ring[0]);
    let grown = geo::Polygon::new(geo::LineString::new(ring), Vec::new()).buffer(d);
    let outline: Vec<Point2<f64>> = grown
        .0
        .first()
        .map(|p| {
            p.exterior()
                .coords()
                .map(|c| Point2::new(c.x, c.y))
                .collect()
        })
        .unwrap_or_default();
    let mut out: Vec<Coord<f64>> = outline.iter().map(&at).collect();
    if signed_area(&outline) < 0.0 {
        out.reverse();
    }
    out
}

fn placemark(name: &str, description: String, geometry: Geometry<f64>, style: &str) -> Kml<f64> {
    Kml::Placemark(Placemark {
        name: Some(name.to_owned()),
        description: Some(description),
        geometry: Some(geometry),
        children: vec![style_url(style)],
        ..Placemark::default()
    })
}

/// `<styleUrl>#id</styleUrl>`, as a child: the `kml` crate writes its own
/// `style_url` after the geometry, where the KML 2.2 schema does not allow
/// it (fastkml's validating reader refuses it); children come before.
fn style_url(id: &str) -> Element {
    Element {
        name: "styleUrl".into(),
        content: Some(format!("#{id}")),
        ..Element::default()
    }
}

fn folder(name: &str, elements: Vec<Kml<f64>>) -> Kml<f64> {
    Kml::Folder(Folder {
        name: Some(name.to_owned()),
        elements,
        ..Folder::default()
    })
}

fn polygon(
    outer: Vec<Coord<f64>>,
    holes: Vec<Vec<Coord<f64>>>,
    mode: AltitudeMode,
    extrude: bool,
) -> Geometry<f64> {
    let ring = |coords| LinearRing {
        coords,
        altitude_mode: mode,
        ..LinearRing::default()
    };
    Geometry::Polygon(Polygon {
        outer: ring(outer),
        inner: holes.into_iter().map(ring).collect(),
        extrude,
        altitude_mode: mode,
        ..Polygon::default()
    })
}

/// Through the decimal text, so the file shows the short form.
fn round(v: f64, digits: usize) -> f64 {
    format!("{v:.digits$}").parse().unwrap_or(v)
}

/// Longitude and latitude of an ENU point (to 1e-9°) and its absolute
/// altitude (to 1 mm), in the export's convention.
fn absolute(placement: &Placement, p: &Point3<f64>) -> Coord<f64> {
    let g = placement.absolute(p);
    Coord {
        x: round(g.longitude, 9),
        y: round(g.latitude, 9),
        z: Some(round(g.altitude, 3)),
    }
}

/// A ground point (clamped to the ground: no altitude).
fn on_ground(placement: &Placement, p: &Point2<f64>) -> Coord<f64> {
    let g = placement.frame().ground_to_geodetic(p);
    Coord {
        x: round(g.longitude, 9),
        y: round(g.latitude, 9),
        z: Some(0.0),
    }
}

fn text(name: &str, content: &str) -> Kml<f64> {
    Kml::Element(Element {
        name: name.to_owned(),
        content: Some(content.to_owned()),
        ..Element::default()
    })
}
