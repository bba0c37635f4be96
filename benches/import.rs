//! Import speed: a 200-feature site survey (120 points, 50 building
//! footprints, 30 fences) into a mission. Target (issue 28): < 1 s.
//!
//! `import/geojson_200_features`: reading the GeoJSON, placing every
//! feature in the ENU frame, the polygon covers and line rows, the merge by
//! name. `import/geojson_200_features_saved_and_checked`: that, then the
//! mission file's text edited in place and checked as `skyform import`
//! does before writing (validation and every pipeline's findings, the IWPs
//! of all the obstacles). Only the disk is left out.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point2;
use serde_json::{Value, json};
use skyform::import;
use skyform::mission::geodesy::Frame;
use skyform::mission::{self, Mission};

/// The bridge-site mission on a 600 m × 400 m site.
fn site() -> (String, Mission) {
    let text = include_str!("../missions/bridge-site.toml")
        .replace("x = [0.0, 138.0]", "x = [0.0, 600.0]")
        .replace("y = [0.0, 103.0]", "y = [0.0, 400.0]");
    let m = mission::check_str(&text, Some("site.toml"))
        .mission
        .expect("the site mission");
    (text, m)
}

/// 200 features east of the route, placed by a fixed sequence.
fn survey(frame: &Frame) -> String {
    let mut state = 12_345u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let ll = |x: f64, y: f64| {
        let g = frame.ground_to_geodetic(&Point2::new(x, y));
        json!([g.longitude, g.latitude])
    };
    let mut features = Vec::new();
    for i in 0..200 {
        let (x, y) = (160.0 + 420.0 * next(), 20.0 + 360.0 * next());
        let geometry = if i < 120 {
            json!({"type": "Point", "coordinates": ll(x, y)})
        } else if i < 170 {
            let (w, h, a) = (8.0 + 12.0 * next(), 6.0 + 10.0 * next(), next() * 3.0);
            let (c, s) = (a.cos(), a.sin());
            let ring: Vec<Value> = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h), (0.0, 0.0)]
                .iter()
                .map(|(u, v)| ll(x + c * u - s * v, y + s * u + c * v))
                .collect();
            json!({"type": "Polygon", "coordinates": [ring]})
        } else {
            let (l, a) = (20.0 + 40.0 * next(), next() * 3.0);
            let end = (x + l * a.cos(), y + l * a.sin());
            json!({"type": "LineString", "coordinates": [ll(x, y), ll(end.0, end.1)]})
        };
        // Points and lines carry their radius; footprints are covered as
        // the import chooses (a radius would fix the cover's discs).
        let mut properties = json!({"name": format!("feature {i}"), "height": 12.0});
        if !(120..170).contains(&i) {
            properties["radius"] = json!(0.5 + next());
        }
        features.push(json!({"type": "Feature", "properties": properties, "geometry": geometry}));
    }
    json!({"type": "FeatureCollection", "features": features}).to_string()
}

fn import_200(c: &mut Criterion) {
    let (text, m) = site();
    let frame = Frame::new(m.origin.as_ref().expect("origin"));
    let geojson = survey(&frame);
    let once = || {
        let survey = import::parse_survey(geojson.as_bytes(), "site.geojson").expect("survey");
        import::import(&m, &survey, "site").expect("import")
    };
    let imported = once();
    assert_eq!(imported.features, 200);
    eprintln!(
        "200 features → {} obstacles ({} polygon covers)",
        imported.changes.added().count(),
        imported
            .notes
            .iter()
            .filter(|n| matches!(n, import::Note::Polygon { .. }))
            .count()
    );
    c.bench_function("import/geojson_200_features", |b| b.iter(once));
    c.bench_function("import/geojson_200_features_saved_and_checked", |b| {
        b.iter(|| {
            let imported = once();
            let saved = mission::edit_in_place(&imported.mission, &text).expect("a mission");
            skyform::outcome::diagnose::check_text(&saved, Some("site.toml"))
                .report
                .error_count()
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = import_200
}
criterion_main!(benches);
