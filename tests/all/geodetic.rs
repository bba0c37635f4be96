//! Latitude/longitude positions in mission files: a mission written with
//! them plans as its ENU twin does, a position without `[origin]` (or a bad
//! one) is a located error, and saving keeps the form the file used.

use std::path::Path;

use nalgebra::{Point2, Point3};
use skyform::mission::geodesy::Frame;
use skyform::mission::{Mission, check_str, edit_in_place};
use skyform::pipelines::theta_pso::{self, PlanOptions};
use skyform::pipelines::{CancelToken, Silent};
use toml_edit::{DocumentMut, InlineTable, Item, Value};

fn shipped(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("missions")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn load(text: &str) -> Mission {
    let checked = check_str(text, Some("twin.toml"));
    assert!(!checked.report.has_errors(), "{}", checked.report);
    checked.mission.unwrap_or_else(|| panic!("no mission"))
}

fn errors(text: &str) -> Vec<String> {
    let checked = check_str(text, Some("bad.toml"));
    assert!(checked.mission.is_none() || checked.report.has_errors());
    checked.report.errors().map(|d| d.to_string()).collect()
}

fn position(pairs: &[(&str, f64)]) -> Item {
    let mut t = InlineTable::new();
    for (k, v) in pairs {
        t.insert(*k, Value::from(*v));
    }
    Item::Value(Value::InlineTable(t))
}

fn ground(frame: &Frame, p: Point2<f64>) -> Item {
    let g = frame.ground_to_geodetic(&p);
    position(&[("latitude", g.latitude), ("longitude", g.longitude)])
}

/// `text` with every position written as latitude/longitude through its
/// own `[origin]`: the start with a height, the goal with an ellipsoidal
/// altitude, obstacle centres and fleet targets on the ground.
fn geodetic_twin(text: &str) -> String {
    let m = load(text);
    let frame = Frame::new(m.origin.as_ref().unwrap_or_else(|| panic!("no origin")));
    let mut doc: DocumentMut = text.parse().unwrap_or_else(|e| panic!("{e}"));
    let start = m.route.start;
    let g = frame.ground_to_geodetic(&start.xy());
    doc["route"]["start"] = position(&[
        ("latitude", g.latitude),
        ("longitude", g.longitude),
        ("height", start.z),
    ]);
    let g = frame.to_geodetic(&m.route.goal);
    doc["route"]["goal"] = position(&[
        ("latitude", g.latitude),
        ("longitude", g.longitude),
        ("altitude", g.altitude),
    ]);
    if let Some(obstacles) = doc["obstacles"].as_array_of_tables_mut() {
        for (table, o) in obstacles.iter_mut().zip(&m.obstacles) {
            table["center"] = ground(&frame, o.center);
        }
    }
    if let Some(targets) = doc["fleet"]["targets"].as_array_of_tables_mut() {
        for (table, t) in targets.iter_mut().zip(&m.fleet.targets) {
            table["position"] = ground(&frame, t.position);
        }
    }
    doc.to_string()
}

/// Largest distance between the positions of two missions, metres.
fn position_gap(a: &Mission, b: &Mission) -> f64 {
    let mut worst = (a.route.start - b.route.start)
        .norm()
        .max((a.route.goal - b.route.goal).norm());
    for (x, y) in a.obstacles.iter().zip(&b.obstacles) {
        worst = worst.max((x.center - y.center).norm());
    }
    for (x, y) in a.fleet.targets.iter().zip(&b.fleet.targets) {
        worst = worst.max((x.position - y.position).norm());
    }
    worst
}

#[test]
fn a_latitude_longitude_twin_reads_as_the_same_enu_mission() {
    for name in ["bridge-inspection.toml", "fleet-triangle.toml"] {
        let text = shipped(name);
        let twin = geodetic_twin(&text);
        assert!(twin.contains("latitude = "), "{twin}");
        let (enu, geo) = (load(&text), load(&twin));
        let gap = position_gap(&enu, &geo);
        eprintln!("{name}: largest position difference {gap:e} m");
        assert!(gap < 1e-6, "{name}: {gap} m");
        assert_eq!(enu.obstacles.len(), geo.obstacles.len());
        assert_eq!(enu.fleet.targets.len(), geo.fleet.targets.len());
    }
}

/// Done-when of issue 28: a mission written with latitude/longitude
/// plans as its ENU twin does (θ-PSO, every UAV sample within 1e-6 m).
#[test]
fn a_latitude_longitude_mission_plans_the_same_as_its_enu_twin() {
    let text = shipped("bridge-inspection.toml");
    let (enu, geo) = (load(&text), load(&geodetic_twin(&text)));
    let cancel = CancelToken::new();
    let plan = |m: &Mission| {
        theta_pso::plan(m, m.seed, PlanOptions::default(), &mut Silent, &cancel)
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let (a, b) = (plan(&enu), plan(&geo));
    assert!(a.feasible() && b.feasible());
    assert_eq!(a.trajectories.len(), b.trajectories.len());
    let mut worst = 0.0f64;
    let mut samples = 0;
    for (ta, tb) in a.trajectories.iter().zip(&b.trajectories) {
        assert_eq!(ta.samples.len(), tb.samples.len());
        for (sa, sb) in ta.samples.iter().zip(&tb.samples) {
            worst = worst.max((sa.position - sb.position).norm());
            samples += 1;
        }
    }
    eprintln!("{samples} samples, largest difference {worst:e} m");
    assert!(samples > 100);
    // Micrometres: the conversion's last bits, carried through the time
    // law's bisections (each grid point's speed to a part in 10⁹).
    assert!(worst < 1e-5, "{worst} m");
    assert!((a.cost.total - b.cost.total).abs() < 1e-6);
}

#[test]
fn a_position_in_latitude_longitude_without_an_origin_is_a_located_error() {
    let text = "name = \"no origin\"\n\n[bounds]\nx = [0.0, 100.0]\ny = [0.0, 100.0]\nz = [5.0, 15.0]\n\n\
                [route]\nstart = [10.0, 10.0, 10.0]\ngoal = { latitude = -33.875, longitude = 151.192, height = 10.0 }\n";
    let errs = errors(text);
    assert_eq!(errs.len(), 1, "{errs:?}");
    assert!(
        errs[0].starts_with("bad.toml:10:1: error: route.goal: "),
        "{}",
        errs[0]
    );
    assert!(
        errs[0].contains("needs the mission's [origin]"),
        "{}",
        errs[0]
    );
}

const HEAD: &str = "name = \"t\"\n\n[origin]\nlatitude = -33.87601\nlongitude = 151.191182\n\n\
                    [bounds]\nx = [0.0, 138.0]\ny = [0.0, 103.0]\nz = [7.0, 15.0]\n\n\
                    [route]\nstart = [10.0, 40.0, 10.0]\ngoal = [128.0, 42.0, 10.0]\n\n[[obstacles]]\n\
                    name = \"pier\"\nradius = 2.0\nheight = 16.0\n";

#[test]
fn bad_latitude_longitude_positions_say_what_is_wrong_on_their_field() {
    let cases = [
        (
            "center = { latitude = 151.1917, longitude = -33.8758 }",
            "obstacles[0].center.latitude: must be within ±90°, got 151.1917 (latitude and longitude swapped?)",
        ),
        (
            "center = { latitude = -33.8758, longitude = 191.0 }",
            "obstacles[0].center.longitude: must be within ±180°",
        ),
        (
            "center = { latitude = -33.8758 }",
            "obstacles[0].center: a latitude/longitude position needs `longitude`",
        ),
        (
            "center = { latitude = -33.8758, longitude = 151.1917, height = 3.0 }",
            "obstacles[0].center.height: unknown key `height`: a position on the ground",
        ),
        (
            "center = { latitude = \"south\", longitude = 151.1917 }",
            "obstacles[0].center.latitude: must be a finite number, got string",
        ),
        (
            // Swapped within range, at a site where that is possible: far away.
            "center = { latitude = 8.5, longitude = 47.4 }",
            "km from [origin]",
        ),
    ];
    for (line, expected) in cases {
        let text = format!("{HEAD}{line}\n");
        let errs = errors(&text);
        assert!(
            errs.iter()
                .any(|e| e.contains(expected) && e.contains("bad.toml:20:")),
            "{line}: {errs:?}"
        );
    }
    let air = HEAD.replace(
        "start = [10.0, 40.0, 10.0]",
        "start = { latitude = -33.8758, longitude = 151.1913 }",
    );
    let errs = errors(&format!("{air}center = [70.0, 30.0]\n"));
    assert!(
        errs.iter()
            .any(|e| e.contains("route.start: needs `height`")),
        "{errs:?}"
    );
}

#[test]
fn an_unchanged_latitude_longitude_mission_saves_byte_for_byte() {
    let twin = geodetic_twin(&shipped("bridge-inspection.toml"));
    let m = load(&twin);
    assert_eq!(edit_in_place(&m, &twin).as_deref(), Some(twin.as_str()));
}

/// Saving keeps the form the file used: a moved obstacle written as
/// latitude/longitude is written back as latitude/longitude (and reads as
/// where it was moved to), an ENU one stays ENU, and a new obstacle takes
/// the form of the file's last one.
#[test]
fn saving_keeps_each_position_in_the_form_the_file_wrote_it() {
    let text = shipped("bridge-inspection.toml");
    let m = load(&text);
    let frame = Frame::new(m.origin.as_ref().unwrap_or_else(|| panic!("origin")));
    // Only pier 1 and the goal in latitude/longitude.
    let mut doc: DocumentMut = text.parse().unwrap_or_else(|e| panic!("{e}"));
    if let Some(obstacles) = doc["obstacles"].as_array_of_tables_mut()
        && let Some(first) = obstacles.get_mut(0)
    {
        first["center"] = ground(&frame, m.obstacles[0].center);
    }
    let g = frame.ground_to_geodetic(&m.route.goal.xy());
    doc["route"]["goal"] = position(&[
        ("latitude", g.latitude),
        ("longitude", g.longitude),
        ("height", m.route.goal.z),
    ]);
    let mixed = doc.to_string();
    let mut edited = load(&mixed);
    edited.obstacles[0].center += nalgebra::Vector2::new(1.5, -2.0);
    edited.obstacles[1].center.x += 0.5;
    edited.route.goal = Point3::new(127.0, 43.0, 11.0);
    let mut added = edited.obstacles[8].clone();
    added.name = "new pole".into();
    added.center = Point2::new(120.0, 90.0);
    edited.obstacles.push(added);
    let saved = edit_in_place(&edited, &mixed).unwrap_or_else(|| panic!("not a mission"));

    let back = load(&saved);
    assert!(position_gap(&back, &edited) < 1e-6);
    let doc: DocumentMut = saved.parse().unwrap_or_else(|e| panic!("{e}"));
    let center = |i: usize| doc["obstacles"][i]["center"].clone();
    assert!(
        center(0)
            .as_inline_table()
            .is_some_and(|t| t.contains_key("latitude")),
        "pier 1 stays in latitude/longitude:\n{saved}"
    );
    assert!(center(1).as_array().is_some(), "pole 2 stays in metres");
    assert!(
        center(9).as_inline_table().is_none() && center(9).as_array().is_some(),
        "the new obstacle follows the last one (metres)"
    );
    let goal = doc["route"]["goal"].clone();
    assert_eq!(
        goal.get("height").and_then(toml_edit::Item::as_float),
        Some(11.0)
    );
    assert!(goal.get("altitude").is_none());
    // Only the changed lines changed (pier 1's centre, pole 2's, the goal),
    // plus the new obstacle at the end.
    let changed = mixed
        .lines()
        .zip(saved.lines())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(changed, 3, "{saved}");
}

/// A latitude/longitude obstacle in a file whose last obstacle is written
/// so: a new one is written the same way.
#[test]
fn a_new_obstacle_follows_a_last_obstacle_in_latitude_longitude() {
    let text = geodetic_twin(&shipped("bridge-inspection.toml"));
    let mut m = load(&text);
    let mut added = m.obstacles[8].clone();
    added.name = "new pole".into();
    added.center = Point2::new(120.0, 90.0);
    m.obstacles.push(added);
    let saved = edit_in_place(&m, &text).unwrap_or_else(|| panic!("not a mission"));
    let tail = &saved[saved.rfind("[[obstacles]]").unwrap_or(0)..];
    assert!(tail.contains("name = \"new pole\""), "{tail}");
    assert!(tail.contains("center = { latitude = "), "{tail}");
    assert!(position_gap(&load(&saved), &m) < 1e-6);
}

#[test]
fn with_terrain_a_position_gives_its_height_above_the_ground_not_an_altitude() {
    let base = HEAD.to_owned()
        + "center = [70.0, 30.0]\n\n[terrain]\nfile = \"x.tif\"\norigin = [0.0, 0.0]\npixel_size = [1.0, -1.0]\n";
    let text = base.replace(
        "goal = [128.0, 42.0, 10.0]",
        "goal = { latitude = -33.8756, longitude = 151.1926, altitude = 10.0 }",
    );
    let errs = errors(&text);
    assert!(
        errs.iter()
            .any(|e| e.contains("route.goal.altitude: with [terrain]")),
        "{errs:?}"
    );
}

/// The inspector shows a position in both forms: the lat/lon fields read
/// through `[origin]`, a typed latitude moves the item there (its longitude
/// kept), and without an origin they are empty and refuse a value.
#[test]
fn the_inspector_shows_and_edits_positions_in_latitude_longitude() {
    use skyform::tui::fields::Item as Selected;
    use skyform::tui::fixtures::type_into;
    use skyform::tui::{Action, App, Document};
    let m = load(&shipped("bridge-inspection.toml"));
    let frame = Frame::new(m.origin.as_ref().expect("the bridge has an origin"));
    let mut app = App::new(Document::new(m.clone(), None), std::env::temp_dir());
    app.update(Action::Select(Selected::Obstacle(2)));
    let field = |app: &App, label: &str| -> String {
        let fields = app.fields();
        let f = fields.iter().find(|f| f.label() == label);
        f.unwrap_or_else(|| panic!("no field {label} in {fields:?}"))
            .value()
            .to_owned()
    };
    let here = frame.ground_to_geodetic(&m.obstacles[2].center);
    let lat: f64 = field(&app, "centre lat (°)").parse().unwrap();
    let lon: f64 = field(&app, "centre lon (°)").parse().unwrap();
    assert!((lat - here.latitude).abs() < 1e-8 && (lon - here.longitude).abs() < 1e-8);

    // 0.0001° north is about 11.1 m.
    let typed = format!("{:.8}", here.latitude + 1e-4);
    type_into(&mut app, "centre lat (°)", &typed);
    let moved = app.mission().obstacles[2].center;
    let want = frame.ground_to_enu(typed.parse().unwrap(), here.longitude);
    assert!((moved - want).norm() < 1e-6, "{moved} vs {want}");
    assert!((moved.y - m.obstacles[2].center.y - 11.09).abs() < 0.05);
    assert!((moved.x - m.obstacles[2].center.x).abs() < 1e-3);
    app.update(Action::Undo);
    assert_eq!(app.mission(), &m, "the latitude edit is one undo step");

    let mut no_origin = m.clone();
    no_origin.origin = None;
    let mut app = App::new(Document::new(no_origin.clone(), None), std::env::temp_dir());
    app.update(Action::Select(Selected::Obstacle(2)));
    assert_eq!(field(&app, "centre lat (°)"), "");
    type_into(&mut app, "centre lat (°)", "-33.9");
    assert_eq!(app.mission(), &no_origin, "no origin: nothing moves");
    let status = app.status().expect("the refusal on the status line");
    assert!(status.text.contains("[origin]"), "{}", status.text);
}

/// Issue 53: the positions a pipeline's section registers
/// (`mission::geodetic::SECTION_POSITIONS`: FLATLO's start, the fleet's
/// initial positions) are read from latitude/longitude and saved back in
/// that form, as the file's own are.
#[test]
fn a_sections_registered_positions_read_and_save_as_latitude_longitude() {
    let text = shipped("bridge-inspection.toml");
    let m = load(&text);
    let frame = Frame::new(m.origin.as_ref().unwrap_or_else(|| panic!("origin")));
    let (start, first) = (Point2::new(20.0, 30.0), Point2::new(40.0, 50.0));
    let mut doc: DocumentMut = text.parse().unwrap_or_else(|e| panic!("{e}"));
    doc["flatlo"] = toml_edit::table();
    doc["flatlo"]["start"] = ground(&frame, start);
    let mut starts = toml_edit::Array::new();
    for p in [first, Point2::new(42.0, 50.0), Point2::new(44.0, 50.0)] {
        starts.push(toml_edit::Value::Array(toml_edit::Array::from_iter([
            p.x, p.y,
        ])));
    }
    doc["fleet"]["initial_positions"] = toml_edit::value(starts);
    doc["fleet"]["initial_positions"][0] = ground(&frame, first);
    let text = doc.to_string();
    let read = load(&text);
    assert!(
        (read.flatlo.start - start).norm() < 1e-6,
        "{}",
        read.flatlo.start
    );
    assert!((read.fleet.initial_positions[0] - first).norm() < 1e-6);

    let mut edited = read.clone();
    edited.flatlo.start.x += 5.0;
    edited.fleet.initial_positions[0].y -= 3.0;
    let saved = edit_in_place(&edited, &text).unwrap_or_else(|| panic!("not a mission"));
    let back = load(&saved);
    assert!((back.flatlo.start - edited.flatlo.start).norm() < 1e-6);
    assert!((back.fleet.initial_positions[0] - edited.fleet.initial_positions[0]).norm() < 1e-6);
    let doc: DocumentMut = saved.parse().unwrap_or_else(|e| panic!("{e}"));
    let written = |item: &Item| {
        item.as_inline_table()
            .is_some_and(|t| t.contains_key("latitude"))
            || item
                .as_value()
                .and_then(Value::as_inline_table)
                .is_some_and(|t| t.contains_key("latitude"))
    };
    assert!(written(&doc["flatlo"]["start"]), "{saved}");
    assert!(written(&doc["fleet"]["initial_positions"][0]), "{saved}");
    assert!(
        doc["fleet"]["initial_positions"][1].as_array().is_some(),
        "the second stays in metres:\n{saved}"
    );
}
