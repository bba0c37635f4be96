//! Shipped missions, atomic saves and round trips.

use std::fs;
use std::path::Path;

use nalgebra::{Point2, Point3, Vector3};
use proptest::prelude::*;
use skyform::mission::{
    self, BUILTIN, Bounds, Formation, Mission, Obstacle, Route, ShapeChoice, check_str, load, save,
    validate,
};

fn missions_dir() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/missions"))
}

#[test]
fn every_shipped_mission_is_valid_without_errors() {
    let mut seen = 0;
    for entry in fs::read_dir(missions_dir()).into_iter().flatten().flatten() {
        let path = entry.path();
        if path.extension().is_some_and(|e| e == "toml") {
            let loaded = load(&path).map_err(|e| e.to_string());
            assert!(loaded.is_ok(), "{}", loaded.err().unwrap_or_default());
            seen += 1;
        }
    }
    assert_eq!(seen, 9, "the nine shipped missions");
}

#[test]
fn the_compiled_in_missions_are_the_files_on_disk() {
    for builtin in BUILTIN {
        let on_disk = fs::read_to_string(missions_dir().join(builtin.file_name));
        assert_eq!(
            on_disk.ok().as_deref(),
            Some(builtin.text),
            "{}",
            builtin.file_name
        );
    }
    let default = mission::default_mission();
    assert_eq!(default.mission.name, "Light-rail bridge inspection");
}

#[test]
fn the_bridge_mission_carries_the_papers_settings() {
    let m = mission::default_mission().mission;
    // θ-PSO paper, Section IV.A: 100 particles, 7 waypoints, 150 iterations,
    // altitude band 7-15 m, 3 m/s, triangle ΔT1..ΔT3, d_s ∈ [1, 5] m.
    assert_eq!(
        (
            m.theta_pso.swarm_size,
            m.theta_pso.waypoints,
            m.theta_pso.iterations
        ),
        (100, 7, 150)
    );
    assert_eq!(m.bounds.z, [7.0, 15.0]);
    assert_eq!(m.formation.ground_speed, 3.0);
    assert_eq!(m.formation.surface_distance, [1.0, 5.0]);
    assert_eq!(m.formation.slots, Formation::default().slots);
    let width = m.bounds.x[1] - m.bounds.x[0];
    let depth = m.bounds.y[1] - m.bounds.y[0];
    assert!((130.0..150.0).contains(&width) && (90.0..110.0).contains(&depth));
}

#[test]
fn shipped_missions_round_trip_through_save() {
    let dir = tempfile::tempdir().map_err(|e| e.to_string());
    let dir = dir.as_ref().map(|d| d.path()).unwrap_or(Path::new("."));
    for builtin in BUILTIN {
        let first = mission::parse_str(builtin.text, builtin.file_name)
            .map(|l| l.mission)
            .map_err(|e| e.to_string());
        let Ok(first) = first else {
            panic!("{first:?}")
        };
        let path = dir.join(builtin.file_name);
        save(&first, &path).map_err(|e| e.to_string()).ok();
        let again = load(&path).map(|l| l.mission).map_err(|e| e.to_string());
        assert_eq!(again.as_ref(), Ok(&first), "{}", builtin.file_name);
    }
}

#[test]
fn save_replaces_the_file_and_leaves_no_temporary_behind() {
    let dir = tempfile::tempdir().ok();
    let Some(dir) = dir else { return };
    let path = dir.path().join("m.toml");
    fs::write(&path, "old contents").ok();
    let m = mission::default_mission().mission;
    assert!(save(&m, &path).is_ok());
    let names: Vec<_> = fs::read_dir(dir.path())
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["m.toml".to_string()]);
    assert_eq!(load(&path).map(|l| l.mission).ok(), Some(m));
}

#[cfg(unix)]
#[test]
fn save_keeps_the_permissions_of_the_file_it_replaces() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().ok();
    let Some(dir) = dir else { return };
    let path = dir.path().join("m.toml");
    fs::write(&path, "old").ok();
    fs::set_permissions(&path, fs::Permissions::from_mode(0o640)).ok();
    assert!(save(&mission::default_mission().mission, &path).is_ok());
    let mode = fs::metadata(&path)
        .map(|m| m.permissions().mode() & 0o777)
        .ok();
    assert_eq!(mode, Some(0o640));
    let fresh = dir.path().join("new.toml");
    assert!(save(&mission::default_mission().mission, &fresh).is_ok());
    let mode = fs::metadata(&fresh)
        .map(|m| m.permissions().mode() & 0o777)
        .ok();
    assert_eq!(mode, Some(0o644));
}

#[test]
fn a_failed_save_names_the_path_and_keeps_nothing() {
    let dir = tempfile::tempdir().ok();
    let Some(dir) = dir else { return };
    let path = dir.path().join("no-such-dir").join("m.toml");
    let err = save(&mission::default_mission().mission, &path)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.contains("cannot save") && err.contains("no-such-dir"),
        "{err}"
    );
}

#[test]
fn a_missing_file_is_a_clear_error() {
    let err = load(Path::new("/definitely/not/here.toml"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.starts_with("cannot read /definitely/not/here.toml"),
        "{err}"
    );
}

/// A mission whose every section is at its defaults: the fields a TOML file
/// may leave out, left out.
fn with_default_sections() -> Mission {
    let text = r#"
        name = "defaults"
        [bounds]
        x = [0.0, 10.0]
        y = [0.0, 10.0]
        z = [0.0, 10.0]
        [route]
        start = [1.0, 1.0, 1.0]
        goal = [9.0, 9.0, 1.0]
    "#;
    toml::from_str(text).unwrap_or_else(|e| panic!("the defaults mission: {e}"))
}

/// Random missions that pass validation: a box, a route inside it, obstacles
/// away from the route, the default triangle.
fn valid_mission() -> impl Strategy<Value = Mission> {
    let obstacle = (
        0.2f64..0.8,
        0.2f64..0.8,
        0.1f64..3.0,
        1.0f64..30.0,
        "[a-z ]{0,12}",
    );
    (
        10.0f64..500.0,
        10.0f64..500.0,
        0.0f64..20.0,
        5.0f64..50.0,
        proptest::collection::vec(obstacle, 0..6),
        any::<u64>(),
        prop::sample::select(vec![
            ShapeChoice::Auto,
            ShapeChoice::Alignment,
            ShapeChoice::Rotation,
            ShapeChoice::Shrink,
        ]),
    )
        .prop_map(|(w, d, z0, band, obstacles, seed, shape)| {
            let bounds = Bounds {
                x: [-w / 2.0, w / 2.0],
                y: [0.0, d],
                z: [z0, z0 + band],
            };
            let z = z0 + band / 2.0;
            let route = Route {
                // 3 m in from the corners: the whole formation fits there.
                start: Point3::new(-w / 2.0 + 3.0, 3.0, z),
                goal: Point3::new(w / 2.0 - 3.0, d - 3.0, z),
                via: Vec::new(),
            };
            let obstacles = obstacles
                .into_iter()
                .enumerate()
                .map(|(i, (fx, fy, r, h, kind))| Obstacle {
                    name: format!("obstacle {i}"),
                    center: Point2::new(-w / 2.0 + fx * w, fy * d),
                    radius: r.min(w / 20.0),
                    height: h,
                    footprint: Vec::new(),
                    base: 0.0,
                    overfly: true,
                    clearance_above: 0.0,
                    kind: (!kind.is_empty()).then_some(kind),
                    inspect: false,
                    stand_off: None,
                    description: None,
                    wire: None,
                    inspect_side: None,
                })
                .collect();
            let mut m = Mission {
                name: "random".into(),
                description: String::new(),
                seed,
                origin: None,
                bounds,
                route,
                formation: Formation::default(),
                obstacles,
                terrain: None,
                // Every section at its defaults (a new section too).
                ..with_default_sections()
            };
            m.reconfiguration.default_shape = shape;
            m.formation.slots[0] = Vector3::new(0.0, 2.0, 0.0);
            m
        })
        .prop_filter("valid", |m| validate(m).iter().all(|d| !d.is_error()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_valid_missions_round_trip(m in valid_mission()) {
        let text = mission::to_toml_string(&m).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let back = check_str(&text, None);
        prop_assert!(!back.report.has_errors(), "{}", back.report);
        prop_assert_eq!(back.mission, Some(m));
    }

    #[test]
    fn arbitrary_bytes_give_errors_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        let checked = check_str(&text, Some("fuzz.toml"));
        prop_assert!(checked.mission.is_none() && checked.report.has_errors());
    }

    #[test]
    fn mutated_shipped_missions_never_panic(cut in 0usize..4000, insert in "[\\[\\]=\"a-z0-9., \n-]{0,8}") {
        let text = BUILTIN[0].text;
        let cut = text.char_indices().map(|(i, _)| i).nth(cut).unwrap_or(text.len());
        let mutated = format!("{}{}{}", &text[..cut], insert, &text[cut..]);
        let checked = check_str(&mutated, Some("m.toml"));
        // Either it still reads as a mission, or it says why not.
        prop_assert!(checked.mission.is_some() || checked.report.has_errors());
    }
}
