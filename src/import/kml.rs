//! KML and KMZ into a survey, with the `kml` crate: every Placemark in
//! document order, however deep its Documents and Folders nest (Google
//! Earth's "My Places" export), the folder it is in as its kind, its
//! ExtendedData (`Data`/`value` and `SchemaData`/`SimpleData`) as its
//! properties, its description. Each geometry keeps the altitude of every
//! coordinate (`lon,lat,alt`), its `altitudeMode` and its `extrude`; Google
//! Earth's `gx:altitudeMode` (`clampToSeaFloor`, `relativeToSeaFloor`) is
//! read as the ground's (skyform's ground is the ground, sea or not). A KMZ
//! is a zip: its KML is `doc.kml`, else the first `.kml` in it (what Google
//! Earth reads).

use std::io::Read;

use kml::types::{Element, Geometry, Placemark};
use kml::{Kml, KmlReader};
use serde_json::{Map, Value};

use super::{AltitudeMode, Drawn, Feature, Position, Shape, Survey, Vertical};

pub fn read_kmz(bytes: &[u8]) -> Result<Survey, String> {
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| format!("not a KMZ (zip) archive: {e}"))?;
    let names: Vec<String> = archive
        .file_names()
        .filter_map(Result::ok)
        .map(|n| n.into_owned())
        .collect();
    let kml_name = names
        .iter()
        .find(|n| n.eq_ignore_ascii_case("doc.kml"))
        .or_else(|| {
            names
                .iter()
                .find(|n| n.to_ascii_lowercase().ends_with(".kml"))
        })
        .cloned()
        .ok_or_else(|| "the KMZ holds no .kml file".to_owned())?;
    let mut text = String::new();
    archive
        .by_name(&kml_name)
        .map_err(|e| format!("cannot read {kml_name} in the KMZ: {e}"))?
        .read_to_string(&mut text)
        .map_err(|e| format!("cannot read {kml_name} in the KMZ: {e}"))?;
    read_kml(&text, "KMZ")
}

pub fn read_kml(text: &str, format: &'static str) -> Result<Survey, String> {
    let text = normalize_flags(text);
    let root: Kml<f64> = KmlReader::<_, f64>::from_string(&text)
        .read()
        .map_err(|e| format!("not KML: {e}"))?;
    let mut features = Vec::new();
    walk(&root, None, &mut features);
    Ok(Survey { format, features })
}

/// Collects the placemarks below `kml`, numbering them in order; `folder`
/// is the name of the innermost folder around them.
fn walk(kml: &Kml<f64>, folder: Option<&str>, out: &mut Vec<Feature>) {
    match kml {
        Kml::KmlDocument(d) => d.elements.iter().for_each(|e| walk(e, folder, out)),
        Kml::Document { elements, .. } => elements.iter().for_each(|e| walk(e, folder, out)),
        Kml::Folder(f) => {
            let name = f.name.as_deref().map(str::trim).filter(|n| !n.is_empty());
            let inner = name.or(folder);
            f.elements.iter().for_each(|e| walk(e, inner, out));
        }
        Kml::Placemark(p) => out.push(feature(p, out.len() + 1, folder)),
        _ => {}
    }
}

fn feature(p: &Placemark<f64>, number: usize, folder: Option<&str>) -> Feature {
    let mut f = Feature {
        number,
        name: p
            .name
            .as_deref()
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .map(str::to_owned),
        folder: folder.map(str::to_owned),
        description: p
            .description
            .as_deref()
            .map(str::trim)
            .filter(|d| !d.is_empty())
            .map(str::to_owned),
        properties: extended_data(&p.children),
        ..Feature::default()
    };
    match &p.geometry {
        Some(g) => geometry(g, &mut f),
        None => f.unusable = Some("it has no geometry".into()),
    }
    if f.shapes.is_empty() && f.unusable.is_none() {
        f.unusable = Some("its geometry is empty".into());
    }
    f
}

fn geometry(g: &Geometry<f64>, f: &mut Feature) {
    let ring = |coords: &[kml::types::Coord<f64>]| -> Vec<Position> {
        coords
            .iter()
            .map(|c| Position {
                lon: c.x,
                lat: c.y,
                alt: c.z,
            })
            .collect()
    };
    let vertical = |mode: kml::types::AltitudeMode, extrude: bool| Vertical {
        mode: match mode {
            kml::types::AltitudeMode::ClampToGround => AltitudeMode::ClampToGround,
            kml::types::AltitudeMode::RelativeToGround => AltitudeMode::RelativeToGround,
            kml::types::AltitudeMode::Absolute => AltitudeMode::AboveSeaLevel,
        },
        extrude: Some(extrude),
    };
    let drawn = |shape: Shape, vertical: Vertical| Drawn { shape, vertical };
    match g {
        Geometry::Point(p) => f.shapes.push(drawn(
            Shape::Point(Position {
                lon: p.coord.x,
                lat: p.coord.y,
                alt: p.coord.z,
            }),
            vertical(p.altitude_mode, p.extrude),
        )),
        Geometry::LineString(l) => f.shapes.push(drawn(
            Shape::Line(ring(&l.coords)),
            vertical(l.altitude_mode, l.extrude),
        )),
        Geometry::LinearRing(r) => f.shapes.push(drawn(
            Shape::Polygon(vec![ring(&r.coords)]),
            vertical(r.altitude_mode, r.extrude),
        )),
        Geometry::Polygon(p) => {
            let mut rings = vec![ring(&p.outer.coords)];
            rings.extend(p.inner.iter().map(|r| ring(&r.coords)));
            f.shapes.push(drawn(
                Shape::Polygon(rings),
                vertical(p.altitude_mode, p.extrude),
            ));
        }
        Geometry::MultiGeometry(m) => m.geometries.iter().for_each(|g| geometry(g, f)),
        Geometry::Element(e) => {
            f.unusable.get_or_insert_with(|| {
                format!(
                    "its geometry is a {} (not a point, line or polygon)",
                    e.name
                )
            });
        }
        _ => {
            f.unusable
                .get_or_insert_with(|| "its geometry is of a kind skyform does not read".into());
        }
    }
}

/// The text with every `altitudeMode` (KML's, `gx:`'s) and `extrude` as
/// the `kml` crate reads them: trimmed, Google Earth's sea-floor modes as
/// the ground's, `true`/`false` as `1`/`0`. Nothing else changes.
fn normalize_flags(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = ["altitudeMode>", "extrude>"]
        .iter()
        .filter_map(|tag| rest.find(tag).map(|i| (i, tag.len())))
        .min()
    {
        let (i, len) = at;
        let open = i + len;
        // An opening tag (`<altitudeMode>`, `<gx:altitudeMode>`), not a closing one.
        let is_open = rest[..i]
            .rfind('<')
            .is_some_and(|lt| !rest[lt..i].starts_with("</"));
        out.push_str(&rest[..open]);
        rest = &rest[open..];
        if !is_open {
            continue;
        }
        let end = rest.find('<').unwrap_or(rest.len());
        let value = rest[..end].trim();
        out.push_str(match value {
            "clampToSeaFloor" => "clampToGround",
            "relativeToSeaFloor" => "relativeToGround",
            "true" => "1",
            "false" => "0",
            other => other,
        });
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// `<ExtendedData>`: `<Data name="k"><value>v</value></Data>` and
/// `<SchemaData><SimpleData name="k">v</SimpleData></SchemaData>`, as text.
fn extended_data(children: &[Element]) -> Map<String, Value> {
    let mut out = Map::new();
    for data in children.iter().filter(|e| local(&e.name) == "ExtendedData") {
        for item in &data.children {
            match local(&item.name) {
                "Data" => {
                    let value = item
                        .children
                        .iter()
                        .find(|c| local(&c.name) == "value")
                        .and_then(|c| c.content.clone());
                    if let (Some(key), Some(v)) = (item.attrs.get("name"), value) {
                        out.insert(key.clone(), Value::String(v.trim().to_owned()));
                    }
                }
                "SchemaData" => {
                    for simple in item
                        .children
                        .iter()
                        .filter(|c| local(&c.name) == "SimpleData")
                    {
                        if let (Some(key), Some(v)) = (simple.attrs.get("name"), &simple.content) {
                            out.insert(key.clone(), Value::String(v.trim().to_owned()));
                        }
                    }
                }
                _ => {}
            }
        }
    }
    out
}

/// An element's name without its namespace prefix (`kml:Data` → `Data`).
fn local(name: &str) -> &str {
    name.rsplit(':').next().unwrap_or(name)
}
