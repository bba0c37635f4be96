//! GeoJSON (RFC 7946) into a survey, with the `geojson` crate: a
//! FeatureCollection, one Feature or a bare Geometry. Each feature is read
//! on its own, so one that does not parse is named by its number and name
//! rather than failing the file at a byte offset. A `crs` member (the 2008
//! draft's, which QGIS and GDAL still write) must name WGS-84
//! longitude/latitude. A position's third coordinate is its altitude above
//! the WGS-84 ellipsoid (RFC 7946 §3.1.1), unless the feature's
//! `altitudeMode` property (as GDAL writes a KML's) says otherwise; an
//! `extrude` property (GDAL's, again) says whether it stands on the ground.

use serde_json::{Map, Value};

use super::{AltitudeMode, Drawn, Feature, Position, Shape, Survey, Vertical};

/// Why a GeoJSON file was not read.
pub enum Problem {
    /// Not JSON, not GeoJSON, or a CRS other than WGS-84.
    Format(String),
    /// Features that do not parse, each named.
    Features(Vec<String>),
}

pub fn read(text: &str) -> Result<Survey, Problem> {
    let root: Value = serde_json::from_str(text).map_err(|e| {
        let full = e.to_string();
        let what = full
            .rsplit_once(" at line ")
            .map_or(full.as_str(), |(w, _)| w);
        Problem::Format(format!(
            "not JSON, so not GeoJSON (line {}, column {}: {what})",
            e.line(),
            e.column()
        ))
    })?;
    let Some(object) = root.as_object() else {
        return Err(Problem::Format(
            "not GeoJSON: the file is not a JSON object".into(),
        ));
    };
    check_crs(object)?;
    let kind = object.get("type").and_then(Value::as_str).unwrap_or("");
    let values: Vec<Value> = match kind {
        "FeatureCollection" => match object.get("features") {
            Some(Value::Array(features)) => features.clone(),
            _ => {
                return Err(Problem::Format(
                    "not GeoJSON: a FeatureCollection needs a `features` array".into(),
                ));
            }
        },
        "Feature" => vec![root.clone()],
        "Point" | "MultiPoint" | "LineString" | "MultiLineString" | "Polygon" | "MultiPolygon"
        | "GeometryCollection" => {
            vec![serde_json::json!({"type": "Feature", "geometry": root, "properties": null})]
        }
        "" => {
            return Err(Problem::Format(
                "not GeoJSON: the top-level object has no `type`".into(),
            ));
        }
        other => {
            return Err(Problem::Format(format!(
                "not GeoJSON: unknown type `{other}` (a FeatureCollection, Feature or geometry)"
            )));
        }
    };
    let mut features = Vec::with_capacity(values.len());
    let mut problems = Vec::new();
    for (i, value) in values.into_iter().enumerate() {
        let mut feature = Feature {
            number: i + 1,
            name: raw_name(&value),
            ..Feature::default()
        };
        match serde_json::from_value::<geojson::Feature>(value) {
            Ok(f) => {
                feature.properties = f.properties.unwrap_or_default();
                feature.description = feature
                    .property("description")
                    .and_then(Value::as_str)
                    .map(str::trim)
                    .filter(|d| !d.is_empty())
                    .map(str::to_owned);
                match vertical(&feature) {
                    Ok(v) => match &f.geometry {
                        Some(g) => {
                            let mut found = Vec::new();
                            shapes(&g.value, &mut found);
                            feature.shapes = found
                                .into_iter()
                                .map(|shape| Drawn { shape, vertical: v })
                                .collect();
                        }
                        None => feature.unusable = Some("it has no geometry (null)".into()),
                    },
                    Err(why) => problems.push(format!("{}: {why}", feature.label())),
                }
                if feature.shapes.is_empty() && feature.unusable.is_none() {
                    feature.unusable = Some("its geometry is empty".into());
                }
                features.push(feature);
            }
            Err(e) => problems.push(format!("{}: not a GeoJSON Feature: {e}", feature.label())),
        }
    }
    if !problems.is_empty() {
        return Err(Problem::Features(problems));
    }
    Ok(Survey {
        format: "GeoJSON",
        features,
    })
}

/// The `name` property of a feature as written, before it is parsed (so a
/// feature that does not parse is still named).
fn raw_name(value: &Value) -> Option<String> {
    let properties = value.get("properties")?.as_object()?;
    properties
        .iter()
        .find(|(k, _)| k.eq_ignore_ascii_case("name"))
        .and_then(|(_, v)| match v {
            Value::String(s) if !s.trim().is_empty() => Some(s.trim().to_owned()),
            Value::Number(n) => Some(n.to_string()),
            _ => None,
        })
}

/// The old `crs` member: only WGS-84 longitude/latitude is read (CRS84,
/// EPSG:4326, as QGIS writes it with longitude first).
fn check_crs(object: &Map<String, Value>) -> Result<(), Problem> {
    let Some(crs) = object.get("crs") else {
        return Ok(());
    };
    let name = crs
        .pointer("/properties/name")
        .and_then(Value::as_str)
        .unwrap_or("");
    let upper = name.to_ascii_uppercase();
    let wgs84 = upper.contains("CRS84")
        || upper.ends_with("EPSG::4326")
        || upper.ends_with("EPSG:4326")
        || upper.ends_with("EPSG:4979");
    if crs.is_null() || wgs84 {
        Ok(())
    } else {
        let shown = if name.is_empty() {
            crs.to_string()
        } else {
            name.to_owned()
        };
        Err(Problem::Format(format!(
            "its crs is {shown}: skyform reads WGS-84 longitude/latitude (RFC 7946); \
             export the layer as EPSG:4326"
        )))
    }
}

/// The shapes of a geometry, collections flattened.
fn shapes(value: &geojson::GeometryValue, out: &mut Vec<Shape>) {
    use geojson::GeometryValue as G;
    let position = |p: &geojson::Position| {
        let s = p.as_slice();
        Position {
            lon: s.first().copied().unwrap_or(f64::NAN),
            lat: s.get(1).copied().unwrap_or(f64::NAN),
            alt: s.get(2).copied(),
        }
    };
    let line = |points: &[geojson::Position]| points.iter().map(position).collect::<Vec<_>>();
    let polygon =
        |rings: &[Vec<geojson::Position>]| Shape::Polygon(rings.iter().map(|r| line(r)).collect());
    match value {
        G::Point { coordinates } => out.push(Shape::Point(position(coordinates))),
        G::MultiPoint { coordinates } => {
            out.extend(coordinates.iter().map(|p| Shape::Point(position(p))));
        }
        G::LineString { coordinates } => out.push(Shape::Line(line(coordinates))),
        G::MultiLineString { coordinates } => {
            out.extend(coordinates.iter().map(|l| Shape::Line(line(l))));
        }
        G::Polygon { coordinates } => out.push(polygon(coordinates)),
        G::MultiPolygon { coordinates } => out.extend(coordinates.iter().map(|p| polygon(p))),
        G::GeometryCollection { geometries } => {
            for g in geometries {
                shapes(&g.value, out);
            }
        }
    }
}

/// How the feature's altitudes are meant: RFC 7946's ellipsoidal height,
/// or the `altitudeMode` property a KML converted by GDAL carries; its
/// `extrude` property, when it has one.
fn vertical(f: &Feature) -> Result<Vertical, String> {
    let mode = match f
        .property("altitudeMode")
        .or_else(|| f.property("altitude_mode"))
    {
        None | Some(Value::Null) => AltitudeMode::AboveEllipsoid,
        Some(Value::String(s)) => match s.trim() {
            "" => AltitudeMode::AboveEllipsoid,
            "clampToGround" | "clampToSeaFloor" => AltitudeMode::ClampToGround,
            "relativeToGround" | "relativeToSeaFloor" => AltitudeMode::RelativeToGround,
            "absolute" => AltitudeMode::AboveSeaLevel,
            other => {
                return Err(format!(
                    "its `altitudeMode` is \"{other}\": clampToGround, relativeToGround or \
                     absolute (KML's words)"
                ));
            }
        },
        Some(other) => return Err(format!("its `altitudeMode` must be text, got {other}")),
    };
    let extrude = match f.property("extrude") {
        None | Some(Value::Null) => None,
        Some(Value::Bool(b)) => Some(*b),
        Some(Value::Number(n)) if n.as_f64() == Some(1.0) => Some(true),
        Some(Value::Number(n)) if n.as_f64() == Some(0.0) => Some(false),
        Some(Value::String(s)) => match s.trim().to_ascii_lowercase().as_str() {
            "1" | "true" | "yes" => Some(true),
            "0" | "false" | "no" => Some(false),
            _ => return Err(format!("its `extrude` must be true or false, got \"{s}\"")),
        },
        Some(other) => return Err(format!("its `extrude` must be true or false, got {other}")),
    };
    Ok(Vertical { mode, extrude })
}
