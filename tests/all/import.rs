//! `skyform import`: site surveys written by other tools (QGIS GeoJSON with
//! a crs member, a Google Earth KML nest, a KMZ) come in as the obstacles
//! they describe; a re-import changes nothing; bad files are refused naming
//! the feature, and nothing is written; a mission with the survey in it plans.

use std::path::{Path, PathBuf};

use nalgebra::Point2;
use skyform::import::{self, Change, Imported};
use skyform::mission::{self, Mission, Obstacle};

use crate::common::skyform;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fixture(name: &str) -> PathBuf {
    root().join("tests/fixtures/import").join(name)
}

fn bridge() -> Mission {
    mission::load(&root().join("missions/bridge-inspection.toml"))
        .unwrap_or_else(|e| panic!("{e}"))
        .mission
}

fn import_into(m: &Mission, file: &Path) -> Imported {
    let survey = import::read_survey(file).unwrap_or_else(|e| panic!("{e}"));
    import::import(m, &survey, &import::stem(file)).unwrap_or_else(|e| panic!("{e}"))
}

fn named<'m>(m: &'m Mission, name: &str) -> &'m Obstacle {
    m.obstacles
        .iter()
        .find(|o| o.name == name)
        .unwrap_or_else(|| panic!("no obstacle '{name}' in {:?}", names(m)))
}

fn names(m: &Mission) -> Vec<&str> {
    m.obstacles.iter().map(|o| o.name.as_str()).collect()
}

fn pieces<'m>(m: &'m Mission, base: &str) -> Vec<&'m Obstacle> {
    let prefix = format!("{base} #");
    m.obstacles
        .iter()
        .filter(|o| o.name.starts_with(&prefix))
        .collect()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Issue 37: a surveyed polygon is kept as a footprint, vertex for vertex
/// (within a millimetre of the ENU corners, in order, from any start).
fn assert_footprint(polygon: &[(f64, f64)], o: &Obstacle) {
    let v = &o.footprint;
    assert_eq!(v.len(), polygon.len(), "{}: {v:?}", o.name);
    let first = v
        .iter()
        .position(|p| (p - Point2::new(polygon[0].0, polygon[0].1)).norm() < 1e-3)
        .unwrap_or_else(|| panic!("{}: no vertex at {:?}: {v:?}", o.name, polygon[0]));
    let forward = (0..v.len()).all(|k| {
        let (x, y) = polygon[k];
        (v[(first + k) % v.len()] - Point2::new(x, y)).norm() < 1e-3
    });
    let backward = (0..v.len()).all(|k| {
        let (x, y) = polygon[k];
        (v[(first + v.len() - k) % v.len()] - Point2::new(x, y)).norm() < 1e-3
    });
    assert!(forward || backward, "{}: {v:?} is not {polygon:?}", o.name);
    // Its bounding circle holds every vertex.
    assert!(v.iter().all(|p| (p - o.center).norm() <= o.radius + 1e-9));
}

#[test]
fn a_qgis_geojson_with_a_crs_member_brings_in_points_multipolygons_and_lines() {
    let before = bridge();
    let imported = import_into(&before, &fixture("qgis-site.geojson"));
    let m = &imported.mission;
    assert_eq!(imported.format, "GeoJSON");
    assert_eq!(imported.features, 5);

    let pylon = named(m, "pylon A");
    assert!(
        (pylon.center - Point2::new(40.0, 20.0)).norm() < 1e-3,
        "{}",
        pylon.center
    );
    assert_eq!((pylon.radius, pylon.height), (0.8, 18.0));
    assert_eq!(pylon.kind.as_deref(), Some("pylon"));

    // The L-shaped workshop (a MultiPolygon, as QGIS writes polygons):
    // kept as its footprint (issue 37; a cover of cylinders once made it
    // 20 % larger), and the report says so.
    let workshop = named(m, "workshop");
    assert_eq!(workshop.height, 8.5);
    let footprint = [
        (20.0, 70.0),
        (36.0, 70.0),
        (36.0, 80.0),
        (28.0, 80.0),
        (28.0, 88.0),
        (20.0, 88.0),
    ];
    assert_footprint(&footprint, workshop);
    let note = imported
        .notes
        .iter()
        .map(ToString::to_string)
        .find(|n| n.contains("'workshop'"))
        .unwrap_or_else(|| panic!("no note on the workshop"));
    assert!(
        note.contains("kept as 1 footprint(s) of 6 vertices, 224.0 m²"),
        "{note}"
    );

    // The hedge: a row of 1.5 m cylinders, the default height with a warning.
    let hedge = pieces(m, "hedge");
    assert!(hedge.len() >= 10 && hedge.iter().all(|o| o.radius == 1.5));
    let band_top = before.bounds.z[1];
    assert!(
        hedge
            .iter()
            .all(|o| o.height == band_top + import::HEIGHT_ABOVE_BAND)
    );
    assert!(
        imported
            .warnings
            .iter()
            .any(|w| w.contains("no height in feature 3 'hedge'")),
        "{:?}",
        imported.warnings
    );

    // Listed, not dropped: no geometry, and outside the bounds.
    let skipped = imported.skipped.join("\n");
    assert!(
        skipped.contains("feature 4 'planned mast': it has no geometry"),
        "{skipped}"
    );
    assert!(
        skipped.contains("feature 5 'car park light': outside the bounds"),
        "{skipped}"
    );
    assert!(m.obstacles.iter().all(|o| o.name != "car park light"));
    // The bridge's own obstacles are untouched.
    assert_eq!(
        &m.obstacles[..before.obstacles.len()],
        &before.obstacles[..]
    );
    let report = imported.report();
    assert!(
        report.contains("added 'pylon A', 'workshop', 'hedge #1…#"),
        "{report}"
    );
}

#[test]
fn a_google_earth_document_folder_placemark_nest_brings_in_kinds_and_extended_data() {
    let imported = import_into(&bridge(), &fixture("google-earth-site.kml"));
    let m = &imported.mission;
    assert_eq!((imported.format, imported.features), ("KML", 3));
    let a = named(m, "pole A");
    assert!((a.center - Point2::new(40.0, 20.0)).norm() < 1e-3);
    assert_eq!((a.radius, a.height), (0.4, 14.0));
    assert_eq!(a.kind.as_deref(), Some("Poles"), "the folder is the kind");
    let b = named(m, "pole B");
    assert_eq!(b.radius, import::DEFAULT_POINT_RADIUS);
    assert!(
        imported
            .warnings
            .iter()
            .any(|w| w.contains("no radius in feature 2 'pole B'"))
    );
    // The kiosk, two folders deep, its height in SchemaData.
    let kiosk = named(m, "kiosk");
    assert!(kiosk.height == 4.5 && kiosk.kind.as_deref() == Some("Kiosks"));
    assert_footprint(
        &[(110.0, 20.0), (118.0, 20.0), (118.0, 26.0), (110.0, 26.0)],
        kiosk,
    );
}

#[test]
fn a_kmz_brings_in_the_kml_inside_it() {
    let imported = import_into(&bridge(), &fixture("site.kmz"));
    assert_eq!(imported.format, "KMZ");
    let tree = named(&imported.mission, "gum tree");
    assert!((tree.center - Point2::new(100.0, 90.0)).norm() < 1e-3);
    assert_eq!(
        (tree.radius, tree.height, tree.kind.as_deref()),
        (3.0, 12.0, Some("Trees"))
    );
}

#[test]
fn importing_the_same_survey_again_changes_nothing() {
    for file in ["qgis-site.geojson", "google-earth-site.kml", "site.kmz"] {
        let once = import_into(&bridge(), &fixture(file));
        let twice = import_into(&once.mission, &fixture(file));
        assert!(twice.changes.is_empty(), "{file}: {:?}", twice.changes);
        assert_eq!(twice.mission, once.mission, "{file}");
        assert_eq!(twice.changes.unchanged, once.changes.added().count());
    }
    // The shipped survey of the bridge, imported into the bridge: its nine
    // obstacles are the bridge's (their positions through the geodesy and
    // back within a millimetre), the site office and fence are new.
    let into_bridge = import_into(&bridge(), &root().join("missions/bridge-site.geojson"));
    assert_eq!(into_bridge.changes.unchanged, 9);
    assert!(
        into_bridge.changes.list.iter().all(
            |c| matches!(c, Change::Added(n) if n == "site office" || n.starts_with("fence #"))
        )
    );
}

#[test]
fn a_crs_other_than_wgs84_longitude_latitude_is_refused_naming_it() {
    let text = r#"{"type": "FeatureCollection",
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28356"}},
        "features": [{"type": "Feature", "properties": {"name": "a"},
                      "geometry": {"type": "Point", "coordinates": [334000.0, 6250000.0]}}]}"#;
    let err = import::parse_survey(text.as_bytes(), "mga56.geojson")
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.contains("its crs is urn:ogc:def:crs:EPSG::28356"),
        "{err}"
    );
    assert!(err.contains("EPSG:4326"), "{err}");
}

#[test]
fn a_mission_without_an_origin_cannot_place_a_survey() {
    let mut m = bridge();
    m.origin = None;
    let survey = import::read_survey(&fixture("site.kmz")).unwrap_or_else(|e| panic!("{e}"));
    let err = import::import(&m, &survey, "site")
        .err()
        .map(|e| e.to_string());
    assert!(err.is_some_and(|e| e.contains("has no [origin]")));
}

/// A copy of `name` (a shipped mission) in a fresh folder.
fn copy_of(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let path = dir.path().join(name);
    std::fs::copy(root().join("missions").join(name), &path).unwrap_or_else(|e| panic!("{e}"));
    (dir, path)
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{e}"))
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Done-when of issue 28: the shipped survey imported into a copy of a
/// mission, then `skyform run theta-pso` plans it; in place, comments kept,
/// and a second import writes nothing.
#[test]
fn the_shipped_survey_imported_into_a_copy_plans_and_a_second_import_writes_nothing() {
    for name in ["bridge-site.toml", "bridge-inspection.toml"] {
        let (dir, path) = copy_of(name);
        let before = read(&path);
        let mission = path.display().to_string();
        let out = skyform(&["import", "missions/bridge-site.geojson", "--into", &mission]);
        let stdout = text(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{name}: {stdout}{}",
            text(&out.stderr)
        );
        assert!(stdout.contains("wrote "), "{stdout}");
        let after = read(&path);
        // In place: the file as it was, then the new obstacles.
        assert!(after.starts_with(before.trim_end()), "{name}:\n{after}");
        assert!(after.contains("name = \"site office\""), "{after}");
        assert!(after.contains("footprint = ["), "{after}");
        assert_eq!(
            files_in(dir.path()),
            vec![name.to_owned()],
            "no stray files"
        );

        let again = skyform(&["import", "missions/bridge-site.geojson", "--into", &mission]);
        assert_eq!(again.status.code(), Some(0));
        assert!(
            text(&again.stdout).contains("nothing to write"),
            "{}",
            text(&again.stdout)
        );
        assert_eq!(
            read(&path),
            after,
            "a second import leaves the file as it is"
        );

        let run = skyform(&["run", "theta-pso", &mission]);
        let summary = text(&run.stdout);
        assert_eq!(
            run.status.code(),
            Some(0),
            "{name}: {summary}{}",
            text(&run.stderr)
        );
        assert!(summary.contains("FEASIBLE"), "{summary}");
    }
}

#[test]
fn bad_survey_files_are_refused_naming_the_feature_and_nothing_is_written() {
    let zurich = "name = \"Limmat quay\"\n\n[origin]\nlatitude = 47.3769\nlongitude = 8.5417\n\n\
                  [bounds]\nx = [0.0, 100.0]\ny = [0.0, 60.0]\nz = [5.0, 12.0]\n\n\
                  [route]\nstart = [5.0, 10.0, 8.0]\ngoal = [95.0, 50.0, 8.0]\n";
    let cases: [(&str, Option<&str>, &[&str]); 4] = [
        ("not-json.geojson", None, &["not JSON", "line 1, column"]),
        (
            "open-ring.geojson",
            None,
            &[
                "feature 2 'shed': its outer ring does not close",
                "the last position must repeat the first",
            ],
        ),
        (
            "out-of-range.geojson",
            None,
            &[
                "feature 3 'mast': coordinate (251.",
                "out of range",
                "longitude must be within ±180°",
            ],
        ),
        (
            "swapped.geojson",
            Some(zurich),
            &[
                "feature 2 'bollard 2' is ",
                "km from the mission's bounds",
                "latitude and longitude are swapped",
            ],
        ),
    ];
    for (file, mission_text, expected) in cases {
        let (dir, path) = copy_of("bridge-inspection.toml");
        if let Some(t) = mission_text {
            std::fs::write(&path, t).unwrap_or_else(|e| panic!("{e}"));
        }
        let before = read(&path);
        let survey = fixture(file).display().to_string();
        let out = skyform(&["import", &survey, "--into", &path.display().to_string()]);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{file}: {stderr}");
        for e in expected {
            assert!(stderr.contains(e), "{file}: '{e}' not in:\n{stderr}");
        }
        assert!(stderr.contains("nothing written"), "{stderr}");
        assert_eq!(read(&path), before, "{file}: the mission is unchanged");
        assert_eq!(files_in(dir.path()).len(), 1, "{file}: no stray files");
    }
}

/// A survey point on the start would make the mission invalid: refused
/// (exit 2, nothing written) unless --force.
#[test]
fn an_import_that_would_break_the_mission_is_refused_unless_forced() {
    let (dir, path) = copy_of("bridge-site.toml");
    let m = mission::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    let frame = skyform::mission::geodesy::Frame::new(
        m.origin.as_ref().unwrap_or_else(|| panic!("origin")),
    );
    let g = frame.ground_to_geodetic(&m.route.start.xy());
    let survey = dir.path().join("on-start.geojson");
    let body = format!(
        r#"{{"type": "Feature", "properties": {{"name": "skip bin", "radius": 3.0, "height": 12.0}},
             "geometry": {{"type": "Point", "coordinates": [{}, {}]}}}}"#,
        g.longitude, g.latitude
    );
    std::fs::write(&survey, body).unwrap_or_else(|e| panic!("{e}"));
    let before = read(&path);
    let args = |force: bool| {
        let mut a = vec![
            "import".to_owned(),
            survey.display().to_string(),
            "--into".to_owned(),
            path.display().to_string(),
        ];
        if force {
            a.push("--force".into());
        }
        a
    };
    let run = |a: Vec<String>| {
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        skyform(&refs)
    };
    let refused = run(args(false));
    let stderr = text(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("route.start: the formation does not fit at the start in any heading"),
        "{stderr}"
    );
    assert!(stderr.contains("nothing written"), "{stderr}");
    assert_eq!(read(&path), before);
    let forced = run(args(true));
    assert_eq!(forced.status.code(), Some(0), "{}", text(&forced.stderr));
    assert!(read(&path).contains("name = \"skip bin\""));
}

/// Saving keeps the form the file uses: into a mission whose obstacles are
/// written in latitude/longitude, the survey's come in latitude/longitude.
#[test]
fn into_a_mission_written_in_latitude_longitude_the_survey_comes_in_latitude_longitude() {
    let (_dir, path) = copy_of("bridge-site.toml");
    let with_one = format!(
        "{}\n[[obstacles]]\nname = \"marker\"\ncenter = {{ latitude = -33.8757, longitude = 151.1917 }}\nradius = 0.5\nheight = 3.0\n",
        read(&path)
    );
    std::fs::write(&path, &with_one).unwrap_or_else(|e| panic!("{e}"));
    let out = skyform(&[
        "import",
        "tests/fixtures/import/site.kmz",
        "--into",
        &path.display().to_string(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let after = read(&path);
    let tail = &after[after.rfind("[[obstacles]]").unwrap_or(0)..];
    assert!(tail.contains("name = \"gum tree\""), "{tail}");
    assert!(tail.contains("center = { latitude = -33."), "{tail}");
    let m = mission::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    assert!((named(&m, "gum tree").center - Point2::new(100.0, 90.0)).norm() < 1e-3);
}

/// The designer's `I`: the survey's path typed into the prompt, Enter.
fn import_in_designer(app: &mut skyform::tui::App, typed: &str) {
    use skyform::tui::Action;
    app.update(Action::Import);
    for c in typed.chars() {
        app.update(Action::PromptInput(c));
    }
    app.update(Action::Confirm);
}

#[test]
fn the_designers_import_is_one_undo_step_and_a_re_import_adds_nothing() {
    use skyform::tui::{Action, App, Document};
    let dir = tempfile::tempdir().unwrap();
    let site = dir.path().join("site.toml");
    std::fs::copy(root().join("missions/bridge-site.toml"), &site).unwrap();
    std::fs::copy(
        root().join("missions/bridge-site.geojson"),
        dir.path().join("survey.geojson"),
    )
    .unwrap();
    let before = mission::load(&site).unwrap().mission;
    let mut app = App::new(
        Document::new(before.clone(), Some(site.clone())),
        dir.path().to_path_buf(),
    );

    import_in_designer(&mut app, "survey.geojson");
    let status = app.status().expect("a status line").clone();
    assert!(!status.error, "{}", status.text);
    assert!(
        status.text.contains("imported survey.geojson"),
        "{}",
        status.text
    );
    let once = app.mission().clone();
    // The CLI's import of the same file gives the same obstacles.
    let cli = import_into(&before, &dir.path().join("survey.geojson")).mission;
    assert_eq!(once.obstacles, cli.obstacles);
    assert!(named(&once, "pier 5").radius > 0.0);
    assert!(app.doc().is_modified());
    assert_eq!(
        std::fs::read_to_string(&site).unwrap(),
        std::fs::read_to_string(root().join("missions/bridge-site.toml")).unwrap(),
        "the designer's import writes nothing until a save"
    );

    import_in_designer(&mut app, "survey.geojson");
    assert_eq!(app.mission(), &once, "a re-import duplicates nothing");
    let again = app.status().expect("a status line");
    assert!(again.text.contains("nothing to import"), "{}", again.text);

    app.update(Action::Undo);
    assert_eq!(
        app.mission(),
        &before,
        "one undo takes the whole import back"
    );
    assert!(!app.doc().is_modified());
    app.update(Action::Redo);
    assert_eq!(app.mission(), &once);
}

#[test]
fn a_bad_survey_in_the_designer_changes_nothing_and_says_why() {
    use skyform::tui::{App, Document};
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("broken.geojson"), "{ not json").unwrap();
    let m = bridge();
    let mut app = App::new(Document::new(m.clone(), None), dir.path().to_path_buf());
    import_in_designer(&mut app, "broken.geojson");
    let status = app.status().expect("a status line");
    assert!(status.error);
    assert!(
        status.text.starts_with("not imported:") && status.text.contains("broken.geojson"),
        "{}",
        status.text
    );
    assert_eq!(app.mission(), &m);
    assert!(!app.doc().is_modified());
    import_in_designer(&mut app, "missing.kml");
    assert!(app.status().expect("a status line").error);
    assert_eq!(app.mission(), &m);
}

/// Issue 37: a survey of two transformer bays (8 × 6 m, 4 m apart) and a
/// gantry beam, written with their tops and undersides as properties
/// (`height`, OSM's `min_height`, `overfly`): the footprints come in as
/// surveyed with their heights, and the report names the narrowest aisle
/// between the footprints and what the formation makes of it.
#[test]
fn footprints_come_in_with_their_heights_and_the_narrowest_aisle_is_named() {
    use skyform::mission::geodesy::Frame;
    let m = bridge();
    let frame = Frame::new(m.origin.as_ref().expect("the bridge has an origin"));
    let ring = |corners: &[(f64, f64)]| -> String {
        let mut points: Vec<String> = corners
            .iter()
            .chain(corners.first())
            .map(|&(x, y)| {
                let g = frame.ground_to_geodetic(&Point2::new(x, y));
                format!("[{:.10}, {:.10}]", g.longitude, g.latitude)
            })
            .collect();
        points.dedup();
        format!("[[{}]]", points.join(", "))
    };
    let feature = |name: &str, corners: &[(f64, f64)], properties: &str| {
        format!(
            "{{\"type\": \"Feature\", \"properties\": {{\"name\": \"{name}\", {properties}}}, \
             \"geometry\": {{\"type\": \"Polygon\", \"coordinates\": {}}}}}",
            ring(corners)
        )
    };
    let t1 = [(20.0, 70.0), (28.0, 70.0), (28.0, 76.0), (20.0, 76.0)];
    let t2 = [(32.0, 70.0), (40.0, 70.0), (40.0, 76.0), (32.0, 76.0)];
    let beam = [(20.0, 80.0), (40.0, 80.0), (40.0, 81.0), (20.0, 81.0)];
    let text = format!(
        "{{\"type\": \"FeatureCollection\", \"features\": [{}, {}, {}]}}",
        feature("T1", &t1, "\"height\": 7.5, \"overfly\": false"),
        feature("T2", &t2, "\"height\": 7.5, \"overfly\": \"no\""),
        feature("gantry", &beam, "\"height\": 13.0, \"min_height\": 12.0"),
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bays.geojson");
    std::fs::write(&file, text).unwrap();
    let imported = import_into(&m, &file);
    let (a, b) = (
        named(&imported.mission, "T1"),
        named(&imported.mission, "T2"),
    );
    assert_footprint(&t1, a);
    assert_footprint(&t2, b);
    assert!(a.height == 7.5 && a.base == 0.0 && !a.overfly && !b.overfly);
    let gantry = named(&imported.mission, "gantry");
    assert!(gantry.base == 12.0 && gantry.height == 13.0 && gantry.overfly);
    let (x, y, width) = imported.aisle.clone().expect("an aisle between the bays");
    assert_eq!((x.as_str(), y.as_str()), ("T1", "T2"));
    assert!((width - 4.0).abs() < 0.01, "{width}");
    let report = imported.report();
    assert!(
        report.contains("narrowest aisle between footprints: 'T1' | 'T2', 4.00 m"),
        "{report}"
    );
}

/// The viaduct mission of `tests/fixtures/import/viaduct.py`, before its
/// survey.
fn viaduct_base() -> Mission {
    mission::load(&fixture("viaduct-base.toml"))
        .unwrap_or_else(|e| panic!("{e}"))
        .mission
}

/// Every obstacle's underside and top as imported, metres, checked against
/// the survey's as drawn (`viaduct.py`): piers 0-22, the deck 22-25 (its
/// surface at 25 m, resting on the piers), the mast 0-30, poplars 0-18, the
/// 11 kV line a wire at 12 m, never a fence.
fn assert_viaduct_heights(m: &Mission, what: &str) {
    for k in 1..=7 {
        let pier = named(m, &format!("pier {k}"));
        assert_eq!((pier.base, pier.height), (0.0, 22.0), "{what}: {pier:?}");
        assert_eq!(pier.footprint.len(), 4, "{what}");
    }
    let deck = named(m, "deck");
    assert_eq!((deck.base, deck.height), (22.0, 25.0), "{what}: {deck:?}");
    let mast = named(m, "signal mast");
    assert_eq!((mast.base, mast.height), (0.0, 30.0), "{what}");
    for k in 1..=5 {
        let poplar = named(m, &format!("poplar {k}"));
        assert_eq!((poplar.base, poplar.height), (0.0, 18.0), "{what}");
    }
    let wire: Vec<&Obstacle> = m.obstacles.iter().filter(|o| o.is_wire()).collect();
    assert!(
        (1..=3).contains(&wire.len()),
        "{what}: the line is {} spans",
        wire.len()
    );
    for w in &wire {
        let span = w.wire.as_ref().unwrap_or_else(|| panic!("a wire"));
        assert!(
            (span.from.z - 12.0).abs() < 1e-3 && (span.to.z - 12.0).abs() < 1e-3,
            "{what}: {span:?}"
        );
        // Its box: the wire's radius either side of 12 m, not from the ground.
        assert!(w.base > 11.0 && w.height < 13.0, "{what}: {w:?}");
    }
    // Over the bounds' width (160 m) the line runs 160.1 m, all of it kept.
    let length: f64 = wire
        .iter()
        .filter_map(|w| w.wire.as_ref().map(|s| s.span()))
        .sum();
    assert!((length - 160.06).abs() < 0.1, "{what}: {length} m of wire");
    assert_eq!(
        m.obstacles.len(),
        15 + wire.len() - 1,
        "{what}: {:?}",
        names(m)
    );
}

/// Issue 50: a site drawn as Google Earth draws it (heights only in the
/// coordinates, `relativeToGround`, piers, mast and trees extruded, the deck
/// and the line not) imports with every height as drawn; the same survey
/// with `absolute` altitudes (less the origin's 480 m) and as QGIS writes it
/// in GeoJSON (the third coordinate above the ellipsoid) comes in the same.
#[test]
fn a_survey_as_google_earth_and_qgis_draw_it_imports_with_every_height() {
    let base = viaduct_base();
    for file in [
        "viaduct-google-earth.kml",
        "viaduct-absolute.kml",
        "viaduct-qgis.geojson",
    ] {
        let imported = import_into(&base, &fixture(file));
        assert_viaduct_heights(&imported.mission, file);
        let report = imported.report();
        assert!(
            report.contains("'deck': a deck from 22 m to 25 m, resting on what stands under it"),
            "{file}: {report}"
        );
        assert!(report.contains("'11 kV line': a wire at 12 m"), "{report}");
        // The survey's description is kept.
        if file.ends_with(".kml") {
            assert_eq!(
                named(&imported.mission, "signal mast")
                    .description
                    .as_deref(),
                Some("Lattice mast, 30 m")
            );
        }
    }
}

/// Issue 50: what `import` writes passes `check --strict`, its numbers to
/// the millimetre (no `0.0002999999999993008`), the wire written as a wire.
#[test]
fn an_imported_survey_passes_check_strict_and_is_written_to_the_millimetre() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let path = dir.path().join("viaduct.toml");
    std::fs::copy(fixture("viaduct-base.toml"), &path).unwrap_or_else(|e| panic!("{e}"));
    let mission = path.display().to_string();
    let survey = fixture("viaduct-google-earth.kml").display().to_string();
    let out = skyform(&["import", &survey, "--into", &mission]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let check = skyform(&["check", "--strict", &mission]);
    assert_eq!(
        check.status.code(),
        Some(0),
        "{}{}",
        text(&check.stdout),
        text(&check.stderr)
    );
    let written = read(&path);
    assert!(written.contains("[obstacles.wire]"), "{written}");
    let imported = &written[written.find("[[obstacles]]").unwrap_or(0)..];
    for line in imported.lines() {
        for number in line
            .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
            .filter(|t| t.contains('.'))
        {
            let decimals = number.split('.').nth(1).map_or(0, str::len);
            assert!(decimals <= 3, "{number} in `{line}`");
        }
    }
}

/// Issue 50: a survey that would lower a known obstacle is refused without
/// `--force`, naming it, and nothing is written; a survey without any
/// height never replaces a known one.
#[test]
fn a_reimport_that_lowers_a_known_obstacle_is_refused_unless_forced() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let path = dir.path().join("viaduct.toml");
    std::fs::copy(fixture("viaduct-base.toml"), &path).unwrap_or_else(|e| panic!("{e}"));
    let mission = path.display().to_string();
    let survey = fixture("viaduct-google-earth.kml").display().to_string();
    assert_eq!(
        skyform(&["import", &survey, "--into", &mission])
            .status
            .code(),
        Some(0)
    );
    let before = read(&path);
    // The mast surveyed again at 21 m, and with no height at all.
    let lower = dir.path().join("mast.kml");
    let mast = |coordinates: &str, mode: &str| {
        format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\
             <Document><Folder><name>Masts</name><Placemark><name>signal mast</name><Point>\
             <extrude>1</extrude>{mode}<coordinates>{coordinates}</coordinates></Point>\
             </Placemark></Folder></Document></kml>"
        )
    };
    let frame = skyform::mission::geodesy::Frame::new(
        viaduct_base()
            .origin
            .as_ref()
            .unwrap_or_else(|| panic!("origin")),
    );
    let g = frame.ground_to_geodetic(&Point2::new(30.0, 45.0));
    let at = |alt: f64| format!("{},{},{alt}", g.longitude, g.latitude);
    std::fs::write(
        &lower,
        mast(&at(21.0), "<altitudeMode>relativeToGround</altitudeMode>"),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let refused = skyform(&["import", &lower.display().to_string(), "--into", &mission]);
    assert_eq!(refused.status.code(), Some(2), "{}", text(&refused.stdout));
    assert!(
        text(&refused.stdout).contains("loss: 'signal mast' lowered: its top 30 → 21 m"),
        "{}",
        text(&refused.stdout)
    );
    assert!(text(&refused.stderr).contains("--force"));
    assert_eq!(read(&path), before, "nothing written");
    let forced = skyform(&[
        "import",
        &lower.display().to_string(),
        "--into",
        &mission,
        "--force",
    ]);
    assert_eq!(forced.status.code(), Some(0), "{}", text(&forced.stderr));
    let m = mission::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    assert_eq!(named(&m, "signal mast").height, 21.0);

    // Clamped to the ground, with no height: the known 21 m stays.
    std::fs::write(&lower, mast(&at(0.0), "")).unwrap_or_else(|e| panic!("{e}"));
    let kept = skyform(&["import", &lower.display().to_string(), "--into", &mission]);
    assert_eq!(kept.status.code(), Some(0), "{}", text(&kept.stderr));
    let m = mission::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    assert_eq!(
        named(&m, "signal mast").height,
        21.0,
        "a default never lowers it"
    );
}
