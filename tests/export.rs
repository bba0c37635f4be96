//! Exports: geodesy, simplification, re-verification as flown, the files, the
//! refusal, and the independent readers (pymavlink, MAVSDK) when available.

use std::path::{Path, PathBuf};

use nalgebra::{Point3, Vector3};
use serde_json::{Value, json};

use skyform::export::{
    self, ExportError, Exported, Format, Frame, Geodetic, Options, Planned, simplify,
};
use skyform::mission::{self, GeoOrigin, Mission};
use skyform::outcome::tracks::{Track, TrackSample};
use skyform::pipelines::theta_pso::{self, PlanOptions};
use skyform::pipelines::{CancelToken, Silent};
use skyform::pipelines::{flatlo, fleet};

mod common;
use common::skyform;

fn load(path: &str) -> Mission {
    let full = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    mission::load(&full)
        .unwrap_or_else(|e| panic!("{path}: {e}"))
        .mission
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The paper's bridge origin (the brief's test vectors use it).
fn bridge_origin() -> GeoOrigin {
    GeoOrigin {
        latitude: -33.87601,
        longitude: 151.191182,
        altitude: 0.0,
    }
}

/// Plans `path` with `pipeline` and its own seed.
fn planned(path: &str, pipeline: &str) -> (Mission, Planned) {
    let m = load(path);
    let cancel = CancelToken::new();
    let p = match pipeline {
        "theta-pso" => {
            let o = theta_pso::plan(&m, m.seed, PlanOptions::default(), &mut Silent, &cancel)
                .unwrap_or_else(|e| panic!("{e}"));
            Planned::theta_pso(&m, &o)
        }
        "flatlo" => {
            let o =
                flatlo::plan(&m, m.seed, &mut Silent, &cancel).unwrap_or_else(|e| panic!("{e}"));
            Planned::flatlo(&m, &o)
        }
        _ => {
            let o = fleet::plan(&m, m.seed, &mut Silent, &cancel).unwrap_or_else(|e| panic!("{e}"));
            Planned::fleet(&m, &o)
        }
    };
    (m, p)
}

fn options(dir: &Path, tolerance: Option<f64>, force: bool) -> Options {
    Options {
        formats: Format::ALL.to_vec(),
        out_dir: dir.to_owned(),
        tolerance,
        force,
    }
}

// ---------------------------------------------------------------- geodesy

/// Reference values from PROJ's `topocentric` conversion (pyproj 3.7.2,
/// pipeline `cart +ellps=WGS84` then `topocentric +lat_0 +lon_0 +h_0`,
/// inverse direction), an implementation independent of `map_3d`.
#[test]
fn enu_to_wgs84_matches_proj_near_and_50_km_away() {
    let frame = Frame::new(&bridge_origin());
    for (enu, lat, lon, alt) in [
        (
            Point3::new(70.0, 43.1, 10.0),
            -33.875621430459,
            151.191938598386,
            10.000529871736,
        ),
        (
            Point3::new(-35000.0, 35700.0, 120.0),
            -33.553584293943,
            150.814307780695,
            316.198501846917,
        ),
    ] {
        let g = frame.to_geodetic(&enu);
        assert!((g.latitude - lat).abs() < 1e-10, "{g:?}");
        assert!((g.longitude - lon).abs() < 1e-10, "{g:?}");
        assert!((g.altitude - alt).abs() < 1e-5, "{g:?}");
    }
}

#[test]
fn enu_geodetic_round_trip_is_within_a_millimetre_over_50_km() {
    let frame = Frame::new(&GeoOrigin {
        latitude: -31.0,
        longitude: 136.8,
        altitude: 160.0,
    });
    let mut worst = 0.0f64;
    for i in -5..=5 {
        for j in -5..=5 {
            for z in [0.0, 120.0, 3050.0] {
                let p = Point3::new(i as f64 * 7000.0, j as f64 * 7000.0, z);
                let back = frame.to_enu(&frame.to_geodetic(&p));
                worst = worst.max((back - p).norm());
            }
        }
    }
    assert!(worst < 1e-3, "round trip error {worst} m");
    // And the other way round from a geodetic position.
    let g = Geodetic {
        latitude: -31.3,
        longitude: 137.2,
        altitude: 2000.0,
    };
    let back = frame.to_geodetic(&frame.to_enu(&g));
    assert!((back.latitude - g.latitude).abs() < 1e-10);
    assert!((back.longitude - g.longitude).abs() < 1e-10);
    assert!((back.altitude - g.altitude).abs() < 1e-3);
}

// ---------------------------------------------------------- simplification

fn helix(n: usize) -> Vec<TrackSample> {
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.1;
            let a = t * 0.3;
            TrackSample {
                t,
                position: Point3::new(20.0 * a.cos(), 20.0 * a.sin(), 5.0 + 0.2 * t),
                velocity: Vector3::zeros(),
            }
        })
        .collect()
}

#[test]
fn every_sample_stays_within_the_tolerance_of_its_leg_at_the_same_instant() {
    let samples = helix(600);
    for tolerance in [0.01, 0.1, 0.5, 2.0] {
        let kept = simplify::simplify(&samples, tolerance);
        assert_eq!(kept.first(), Some(&0));
        assert_eq!(kept.last(), Some(&(samples.len() - 1)));
        let err = simplify::max_error(&samples, &kept);
        assert!(err <= tolerance, "tolerance {tolerance}: error {err}");
        assert!(kept.len() < samples.len());
    }
    // A coarser tolerance never needs more waypoints.
    let counts: Vec<usize> = [0.01, 0.1, 1.0]
        .iter()
        .map(|t| simplify::simplify(&samples, *t).len())
        .collect();
    assert!(counts.windows(2).all(|w| w[0] >= w[1]), "{counts:?}");
}

#[test]
fn a_change_of_speed_on_a_straight_line_is_kept() {
    // Straight east, 1 m/s for 10 s then 3 m/s: plain Douglas–Peucker would
    // keep only the ends; the synchronous distance keeps the corner in time.
    let samples: Vec<TrackSample> = (0..=200)
        .map(|k| {
            let t = k as f64 * 0.1;
            let x = if t <= 10.0 {
                t
            } else {
                10.0 + 3.0 * (t - 10.0)
            };
            TrackSample {
                t,
                position: Point3::new(x, 0.0, 5.0),
                velocity: Vector3::zeros(),
            }
        })
        .collect();
    let kept = simplify::simplify(&samples, 0.05);
    assert_eq!(kept, vec![0, 100, 200]);
    let plans = export::reduce(
        &[Track {
            vehicle: 0,
            samples,
        }],
        0.05,
        false,
    );
    let speeds: Vec<f64> = plans[0].waypoints.iter().map(|w| w.speed).collect();
    assert_eq!(speeds, vec![0.0, 1.0, 3.0]);
}

// ------------------------------------------------ shipped missions, files

struct Shipped {
    mission: &'static str,
    stem: &'static str,
    pipeline: &'static str,
}

const SHIPPED: [Shipped; 4] = [
    Shipped {
        mission: "missions/bridge-inspection.toml",
        stem: "bridge-inspection",
        pipeline: "theta-pso",
    },
    Shipped {
        mission: "missions/narrow-passage.toml",
        stem: "narrow-passage",
        pipeline: "theta-pso",
    },
    Shipped {
        mission: "missions/flatlo-squadron.toml",
        stem: "flatlo-squadron",
        pipeline: "flatlo",
    },
    Shipped {
        mission: "missions/fleet-triangle.toml",
        stem: "fleet-triangle",
        pipeline: "fleet",
    },
];

fn export_shipped(s: &Shipped, dir: &Path) -> (Mission, Planned, Exported) {
    let (m, p) = planned(s.mission, s.pipeline);
    let done = export::export(&m, s.stem, &p, &options(dir, None, false))
        .unwrap_or_else(|e| panic!("{} {}: {e}", s.mission, s.pipeline));
    (m, p, done)
}

#[test]
fn shipped_missions_export_and_re_verify_as_flown() {
    let dir = tempdir();
    for s in &SHIPPED {
        let (m, p, done) = export_shipped(s, dir.path());
        let r = &done.reverification;
        let counts: Vec<usize> = done.plans.iter().map(|p| p.waypoints.len()).collect();
        eprintln!(
            "{} {}: tolerance {:.3} m ({}), waypoints {counts:?}, deviation {:.3} m, timing {:.3} s",
            s.stem,
            s.pipeline,
            done.tolerance,
            done.tolerance_source,
            r.max_deviation,
            r.max_timing_error
        );
        assert!(r.passed(), "{}", r.failure_text());
        assert!(!done.forced);
        // Issue 24, item 7: the plans as flown (rounded speeds, holds)
        // stay within the tolerance the export announces.
        assert!(
            r.max_deviation <= done.tolerance,
            "{} {}: deviation {} > tolerance {}",
            s.stem,
            s.pipeline,
            r.max_deviation,
            done.tolerance
        );
        assert_eq!(
            done.files.len(),
            3 * p.tracks.len() + 1,
            "three per vehicle, one KML"
        );
        // Timing: speeds are written to 0.01 m/s and corrected leg by leg.
        assert!(r.max_timing_error < 0.5, "{}", r.max_timing_error);
        for f in done.files.iter().filter(|f| f.format.per_vehicle()) {
            let name = f.path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            assert_eq!(
                name,
                format!(
                    "{}-{}-uav{}.{}",
                    s.stem,
                    s.pipeline,
                    f.vehicle + 1,
                    f.format.extension()
                )
            );
            match f.format {
                Format::Plan => check_plan_file(&m, &p, &f.path),
                Format::Wpl => check_wpl_file(&f.path),
                Format::Csv => check_csv_file(&p.tracks[f.vehicle], &f.path, true),
                Format::Kml => {}
            }
        }
        let kml: Vec<_> = done
            .files
            .iter()
            .filter(|f| f.format == Format::Kml)
            .collect();
        assert_eq!(kml.len(), 1);
        assert_eq!(
            kml[0].path.file_name().and_then(|n| n.to_str()),
            Some(format!("{}-{}.kml", s.stem, s.pipeline).as_str())
        );
        assert_eq!(kml[0].waypoints, p.tracks.len());
        // No temporary files left behind.
        let stray = std::fs::read_dir(dir.path())
            .unwrap_or_else(|e| panic!("{e}"))
            .filter_map(Result::ok)
            .filter(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                name.starts_with(".tmp") || name.starts_with(".skyform-save-")
            })
            .count();
        assert_eq!(stray, 0);
    }
}

fn check_plan_file(m: &Mission, p: &Planned, path: &Path) {
    let v: Value = serde_json::from_str(&read(path)).unwrap_or_else(|e| panic!("{e}"));
    let fixed_wing = p.pipeline.fixed_wing();
    assert_eq!(v["fileType"], "Plan");
    assert_eq!(v["version"], 1);
    assert!(v["groundStation"].is_string());
    let mission = &v["mission"];
    assert_eq!(mission["version"], 2);
    assert_eq!(mission["firmwareType"], if fixed_wing { 3 } else { 12 });
    assert_eq!(mission["vehicleType"], if fixed_wing { 1 } else { 2 });
    assert_eq!(
        mission["plannedHomePosition"].as_array().map(Vec::len),
        Some(3)
    );
    let items = mission["items"].as_array().cloned().unwrap_or_default();
    let commands: Vec<i64> = items.iter().filter_map(|i| i["command"].as_i64()).collect();
    assert_eq!(commands.first(), Some(&22), "takeoff first");
    assert_eq!(commands.last(), Some(&if fixed_wing { 17 } else { 21 }));
    assert!(commands.contains(&178) && commands.contains(&16));
    for (k, item) in items.iter().enumerate() {
        assert_eq!(item["type"], "SimpleItem");
        assert_eq!(item["doJumpId"], k + 1);
        assert_eq!(item["autoContinue"], true);
        assert_eq!(item["params"].as_array().map(Vec::len), Some(7));
        let positioned = item["frame"] == 3;
        for key in ["Altitude", "AltitudeMode", "AMSLAltAboveTerrain"] {
            assert_eq!(item.get(key).is_some(), positioned, "{key} in {item}");
        }
    }
    // A speed change only where the speed changes.
    let speeds: Vec<f64> = items
        .iter()
        .filter(|i| i["command"] == 178)
        .filter_map(|i| i["params"][1].as_f64())
        .collect();
    assert!(
        speeds.windows(2).all(|w| (w[0] - w[1]).abs() > 1e-9),
        "{speeds:?}"
    );
    let fence = &v["geoFence"];
    assert_eq!(fence["version"], 2);
    let polygon = &fence["polygons"][0];
    assert_eq!(polygon["inclusion"], true);
    assert_eq!(polygon["polygon"].as_array().map(Vec::len), Some(4));
    let circles = fence["circles"].as_array().cloned().unwrap_or_default();
    assert_eq!(
        circles.len(),
        export::fence_obstacles(m, p).count(),
        "one exclusion circle per obstacle not overflown"
    );
    for c in &circles {
        assert_eq!(c["inclusion"], false);
        assert!(c["circle"]["radius"].as_f64().is_some_and(|r| r > 0.0));
    }
    assert_eq!(v["rallyPoints"]["version"], 2);
    assert!(v["rallyPoints"]["points"].is_array());
}

fn check_wpl_file(path: &Path) {
    let body = read(path);
    let mut lines = body.lines();
    assert_eq!(lines.next(), Some("QGC WPL 110"));
    for (k, line) in lines.enumerate() {
        let fields: Vec<&str> = line.split('\t').collect();
        assert_eq!(fields.len(), 12, "{line}");
        assert_eq!(fields[0], k.to_string());
        assert_eq!(fields[2], if k == 0 { "0" } else { "3" }, "{line}");
        for f in &fields {
            assert!(f.parse::<f64>().is_ok(), "{line}");
        }
        if fields[3] == "16" || fields[3] == "22" {
            // At least 8 decimals of latitude and longitude (1 mm).
            assert!(fields[8].split('.').nth(1).is_some_and(|d| d.len() >= 8));
        }
    }
}

fn check_csv_file(track: &Track, path: &Path, geodetic: bool) {
    let body = read(path);
    let mut lines = body.lines();
    let header = if geodetic {
        "t,x,y,z,vx,vy,vz,lat,lon,alt"
    } else {
        "t,x,y,z,vx,vy,vz"
    };
    assert_eq!(lines.next(), Some(header));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').filter_map(|f| f.parse().ok()).collect())
        .collect();
    assert_eq!(rows.len(), track.samples.len());
    for (row, s) in rows.iter().zip(&track.samples) {
        assert_eq!(row.len(), if geodetic { 10 } else { 7 });
        assert!((row[0] - s.t).abs() < 1e-3);
        assert!((row[1] - s.position.x).abs() < 1e-4);
        assert!((row[3] - s.position.z).abs() < 1e-4);
    }
}

/// The bridge's first waypoint of UAV 1, checked by hand: its ENU position
/// (from the CSV's first row) through PROJ (pyproj 3.7.2, `topocentric`
/// inverse about the bridge origin) gives the same latitude and longitude
/// as the `.waypoints` file within 1e-8°, as the CSV's own columns do.
#[test]
fn the_files_agree_with_each_other_and_with_the_geodesy() {
    let dir = tempdir();
    let (m, _, done) = export_shipped(&SHIPPED[0], dir.path());
    let frame = Frame::new(m.origin.as_ref().unwrap_or_else(|| panic!("origin")));
    let plan = &done.plans[0];
    let first = plan.waypoints[0].position;
    let g = frame.to_geodetic(&first);
    let wpl = read(
        &dir.path()
            .join("bridge-inspection-theta-pso-uav1.waypoints"),
    );
    // Line 3 (after header, home, takeoff) is the first waypoint.
    let fields: Vec<f64> = wpl
        .lines()
        .nth(3)
        .unwrap_or_default()
        .split('\t')
        .filter_map(|f| f.parse().ok())
        .collect();
    assert_eq!(fields[3], 16.0);
    assert!((fields[8] - g.latitude).abs() < 1e-8);
    assert!((fields[9] - g.longitude).abs() < 1e-8);
    let home = frame.to_geodetic(&Point3::new(first.x, first.y, 0.0));
    assert!((fields[10] - (g.altitude - home.altitude)).abs() < 1e-5);
}

// ------------------------------------------------------ refusal and force

#[test]
fn a_coarse_tolerance_that_cuts_an_obstacle_is_refused_naming_it() {
    let dir = tempdir();
    let (m, p) = planned("missions/bridge-inspection.toml", "theta-pso");
    let err = export::export(&m, "bridge", &p, &options(dir.path(), Some(3.0), false));
    let Err(ExportError::Refused(r)) = err else {
        panic!("expected a refusal, got {err:?}");
    };
    let f = &r.failures[0];
    assert_eq!(f.constraint, "obstacle clearance");
    assert!(f.value < f.limit);
    assert!(f.waypoint >= 1 && f.time > 0.0);
    let message = ExportError::Refused(r.clone()).to_string();
    assert!(message.contains("obstacle clearance: UAV "), "{message}");
    assert!(message.contains("leg to waypoint"), "{message}");
    assert_eq!(
        std::fs::read_dir(dir.path()).map(|d| d.count()).ok(),
        Some(0)
    );
}

#[test]
fn the_binary_refuses_with_exit_2_and_writes_with_force() {
    let dir = tempdir();
    let out_dir = dir.path().join("out");
    let out = out_dir.display().to_string();
    let args = [
        "export",
        "missions/bridge-inspection.toml",
        "--format",
        "plan",
        "--format",
        "wpl",
        "--out",
        &out,
        "--tolerance",
        "3",
    ];
    let refused = skyform(&args);
    let stderr = text(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("export refused"), "{stderr}");
    assert!(stderr.contains("obstacle clearance: UAV"), "{stderr}");
    assert!(stderr.contains("leg to waypoint"), "{stderr}");
    assert!(
        !out_dir
            .join("bridge-inspection-theta-pso-uav1.plan")
            .exists()
    );

    let mut forced_args = args.to_vec();
    forced_args.push("--force");
    let forced = skyform(&forced_args);
    let stderr = text(&forced.stderr);
    assert_eq!(forced.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("warning: written with --force"), "{stderr}");
    for n in 1..=3 {
        for ext in ["plan", "waypoints"] {
            assert!(
                out_dir
                    .join(format!("bridge-inspection-theta-pso-uav{n}.{ext}"))
                    .exists()
            );
        }
    }
    let stdout = text(&forced.stdout);
    assert!(stdout.contains("largest deviation"), "{stdout}");
    assert!(stdout.contains("waypoints"), "{stdout}");
}

#[test]
fn without_an_origin_csv_works_in_enu_and_geodetic_formats_say_to_add_it() {
    let dir = tempdir();
    let source = read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("missions/narrow-passage.toml"));
    let start = source
        .find("[origin]")
        .unwrap_or_else(|| panic!("no origin"));
    let end = source
        .find("[bounds]")
        .unwrap_or_else(|| panic!("no bounds"));
    let stripped = format!("{}{}", &source[..start], &source[end..]);
    let path = dir.path().join("no-origin.toml");
    std::fs::write(&path, stripped).unwrap_or_else(|e| panic!("{e}"));
    let mission = path.display().to_string();
    let out = dir.path().join("out").display().to_string();

    let geo = skyform(&["export", &mission, "--format", "wpl", "--out", &out]);
    assert_eq!(geo.status.code(), Some(1));
    let stderr = text(&geo.stderr);
    assert!(stderr.contains("add an [origin] section"), "{stderr}");

    let csv = skyform(&["export", &mission, "--format", "csv", "--out", &out]);
    assert_eq!(csv.status.code(), Some(0), "{}", text(&csv.stderr));
    let (m, p) = {
        let m = mission::load(&path)
            .unwrap_or_else(|e| panic!("{e}"))
            .mission;
        let o = theta_pso::plan(
            &m,
            m.seed,
            PlanOptions::default(),
            &mut Silent,
            &CancelToken::new(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let p = Planned::theta_pso(&m, &o);
        (m, p)
    };
    assert!(m.origin.is_none());
    check_csv_file(
        &p.tracks[0],
        &PathBuf::from(&out).join("no-origin-theta-pso-uav1.csv"),
        false,
    );
}

/// Issue 24, item 9: under umask 022 every exported file is 0644, as the
/// mission, the JSON and the sweep CSV are (not the 0600 of a private
/// temporary file): a ground station running as another user reads them.
#[cfg(unix)]
#[test]
fn exported_files_honour_the_umask_like_any_file() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempdir();
    let out = dir.path().join("out");
    let script = format!(
        "umask 022 && exec '{}' export missions/narrow-passage.toml --format plan \
         --format wpl --format csv --out '{}'",
        env!("CARGO_BIN_EXE_skyform"),
        out.display()
    );
    let run = std::process::Command::new("sh")
        .args(["-c", &script])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let files: Vec<PathBuf> = std::fs::read_dir(&out)
        .unwrap_or_else(|e| panic!("{e}"))
        .map(|e| e.map(|e| e.path()).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    assert!(files.len() >= 3, "{files:?}");
    for f in &files {
        let mode = std::fs::metadata(f)
            .unwrap_or_else(|e| panic!("{e}"))
            .permissions()
            .mode()
            & 0o777;
        assert_eq!(mode, 0o644, "{} is {mode:o}", f.display());
    }
}

// ------------------------------------------------ independent readers

/// The expectation files of `tests/export_readers` for every exported
/// `.plan` and `.waypoints`: the items skyform meant to write, which the
/// readers compare with what pymavlink and MAVSDK read.
fn expectations(m: &Mission, p: &Planned, done: &Exported, dir: &Path) -> (PathBuf, PathBuf) {
    let frame = Frame::new(m.origin.as_ref().unwrap_or_else(|| panic!("origin")));
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    let mut plans = Vec::new();
    let mut wpls = Vec::new();
    for (plan, f) in done.plans.iter().zip(&done.files) {
        let _ = f;
        let (home, items) = export::items(p, plan, &frame, done.tolerance);
        let expected = |zero_nan: bool, frame_of: &dyn Fn(u8) -> u8| -> Vec<Value> {
            items
                .iter()
                .map(|i| {
                    let params: Vec<Value> = i
                        .params
                        .iter()
                        .map(|&v| {
                            if zero_nan && !v.is_finite() {
                                json!(0.0)
                            } else {
                                num(v)
                            }
                        })
                        .collect();
                    let mut e =
                        json!({"command": i.command, "frame": frame_of(i.frame), "params": params});
                    if let Some([lat, lon, alt]) = i.at {
                        e["lat"] = json!(lat);
                        e["lon"] = json!(lon);
                        e["alt"] = json!(alt);
                    }
                    e
                })
                .collect()
        };
        let home_item = json!({"command": 16, "lat": home.latitude, "lon": home.longitude, "alt": home.altitude});
        let stem = |ext: &str| {
            done.files
                .iter()
                .find(|w| w.vehicle == plan.vehicle && w.format.extension() == ext)
                .map(|w| w.path.display().to_string())
                .unwrap_or_default()
        };
        let mut plan_items = expected(false, &|f| f);
        if p.pipeline.fixed_wing() {
            // MAVSDK puts plannedHomePosition first for ArduPilot.
            plan_items.insert(0, home_item.clone());
        }
        let circles = export::fence_obstacles(m, p).count();
        plans.push(json!({
            "path": stem("plan"),
            "items": plan_items,
            "geofence_count": 4 + circles,
            "rally_count": 0,
        }));
        let mut wpl_items = expected(true, &|_| 3);
        let mut home_wpl = home_item;
        home_wpl["frame"] = json!(0);
        home_wpl["current"] = json!(1);
        wpl_items.insert(0, home_wpl);
        wpls.push(json!({"path": stem("waypoints"), "items": wpl_items}));
    }
    let plan_path = dir.join("expect_plan.json");
    let wpl_path = dir.join("expect_wpl.json");
    let write = |path: &Path, files: Vec<Value>| {
        let text = serde_json::to_string_pretty(&json!({"files": files})).unwrap_or_default();
        std::fs::write(path, text).unwrap_or_else(|e| panic!("{e}"));
    };
    write(&plan_path, plans);
    write(&wpl_path, wpls);
    (plan_path, wpl_path)
}

/// The Python of a virtual environment with `tests/export_readers/requirements.txt`:
/// `SKYFORM_EXPORT_VENV`. Without it the check is skipped, except under CI
/// (`CI` set), where it fails: CI must run the readers.
fn reader_python() -> Option<PathBuf> {
    match std::env::var_os("SKYFORM_EXPORT_VENV") {
        Some(venv) => {
            let python = PathBuf::from(venv).join("bin").join("python");
            assert!(
                python.exists(),
                "SKYFORM_EXPORT_VENV has no {}",
                python.display()
            );
            Some(python)
        }
        None => {
            assert!(
                std::env::var_os("CI").is_none(),
                "CI is set but SKYFORM_EXPORT_VENV is not: .ci/run must create the readers' venv"
            );
            eprintln!(
                "skipped: set SKYFORM_EXPORT_VENV to a venv with tests/export_readers/requirements.txt"
            );
            None
        }
    }
}

#[test]
fn pymavlink_and_mavsdk_read_every_exported_file_as_written() {
    let Some(python) = reader_python() else {
        return;
    };
    let readers = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/export_readers");
    for s in &SHIPPED {
        let dir = tempdir();
        let (m, p, done) = export_shipped(s, dir.path());
        let (plan_expect, wpl_expect) = expectations(&m, &p, &done, dir.path());
        for (script, expect) in [
            ("check_wpl.py", &wpl_expect),
            ("check_plan.py", &plan_expect),
        ] {
            let out = std::process::Command::new(&python)
                .arg(readers.join(script))
                .arg(expect)
                .output()
                .unwrap_or_else(|e| panic!("cannot run {script}: {e}"));
            eprint!(
                "{script} on {} {}: {}",
                s.stem,
                s.pipeline,
                text(&out.stdout)
            );
            assert!(
                out.status.success(),
                "{script} on {} {}: {}{}",
                s.stem,
                s.pipeline,
                text(&out.stdout),
                text(&out.stderr)
            );
        }
    }
}

/// The expectation of `tests/export_readers/check_kml.py` for an export's
/// KML: the plan's samples (ENU, with their height above the ground), the
/// obstacles and inspection bands, the colours and the verdict.
fn kml_expectation(m: &Mission, p: &Planned, done: &Exported, dir: &Path) -> PathBuf {
    let origin = m.origin.as_ref().unwrap_or_else(|| panic!("origin"));
    let kml = done
        .files
        .iter()
        .find(|f| f.format == Format::Kml)
        .unwrap_or_else(|| panic!("no KML written"));
    let vehicles: Vec<Value> = p
        .tracks
        .iter()
        .map(|t| {
            let samples: Vec<Value> = t
                .samples
                .iter()
                .map(|s| {
                    let q = s.position;
                    json!([q.x, q.y, q.z, q.z - m.ground(q.x, q.y)])
                })
                .collect();
            json!({
                "folder": format!("UAV {}", t.vehicle + 1),
                "color": export::kml::kml_color(skyform::outcome::tracks::vehicle_color(t.vehicle), 0xff),
                "samples": samples,
            })
        })
        .collect();
    let obstacles: Vec<Value> = m
        .obstacles
        .iter()
        .map(|o| json!({"name": o.name, "center": [o.center.x, o.center.y], "radius": o.radius, "height": o.height}))
        .collect();
    let bands: Vec<Value> = m
        .obstacles
        .iter()
        .filter(|o| o.inspect)
        .map(|o| {
            let [d_min, d_max] = o.stand_off_band(&m.formation);
            json!({"name": format!("{} band", o.name), "center": [o.center.x, o.center.y],
                   "inner": o.radius + d_min, "outer": o.radius + d_max})
        })
        .collect();
    let spec = json!({
        "tolerance_m": 0.01,
        "files": [{
            "path": kml.path.display().to_string(),
            "origin": {"latitude": origin.latitude, "longitude": origin.longitude, "altitude": origin.altitude},
            "verdict": p.verdict,
            "vehicles": vehicles,
            "obstacles": obstacles,
            "bands": bands,
        }],
    });
    let path = dir.join("expect_kml.json");
    std::fs::write(&path, serde_json::to_string(&spec).unwrap_or_default())
        .unwrap_or_else(|e| panic!("{e}"));
    path
}

/// Issue 28: the KML export read back by fastkml (validating against the
/// KML 2.2 schema), every position within 0.01 m of the plan through
/// pymap3d's geodesy, one folder per vehicle in its colour, the verdict in
/// the description; for every shipped mission and pipeline.
#[test]
fn fastkml_reads_every_kml_export_within_a_centimetre_of_the_plan() {
    let Some(python) = reader_python() else {
        return;
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/export_readers/check_kml.py");
    for s in &SHIPPED {
        let dir = tempdir();
        let (m, p, done) = export_shipped(s, dir.path());
        assert!(!p.verdict.is_empty());
        let expect = kml_expectation(&m, &p, &done, dir.path());
        let out = std::process::Command::new(&python)
            .arg(&script)
            .arg(&expect)
            .output()
            .unwrap_or_else(|e| panic!("cannot run check_kml.py: {e}"));
        eprint!(
            "check_kml.py on {} {}: {}",
            s.stem,
            s.pipeline,
            text(&out.stdout)
        );
        assert!(
            out.status.success(),
            "check_kml.py on {} {}: {}{}",
            s.stem,
            s.pipeline,
            text(&out.stdout),
            text(&out.stderr)
        );
    }
}

/// The checker is not a rubber stamp: a track moved by 2 cm, or a file the
/// schema refuses, fails it.
#[test]
fn the_kml_checker_refuses_a_track_two_centimetres_off_and_an_invalid_file() {
    let Some(python) = reader_python() else {
        return;
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/export_readers/check_kml.py");
    let dir = tempdir();
    let (m, mut p, done) = export_shipped(&SHIPPED[1], dir.path());
    for t in &mut p.tracks {
        for s in &mut t.samples {
            s.position.x += 0.02;
        }
    }
    let expect = kml_expectation(&m, &p, &done, dir.path());
    let run = |expect: &Path| {
        std::process::Command::new(&python)
            .arg(&script)
            .arg(expect)
            .output()
            .unwrap_or_else(|e| panic!("cannot run check_kml.py: {e}"))
    };
    let off = run(&expect);
    assert_eq!(off.status.code(), Some(1), "{}", text(&off.stdout));
    assert!(
        text(&off.stderr).contains("off horizontally"),
        "{}",
        text(&off.stderr)
    );
    // A styleUrl after the geometry (as the kml crate's own field writes it)
    // is outside the KML 2.2 schema.
    let kml = done
        .files
        .iter()
        .find(|f| f.format == Format::Kml)
        .map(|f| f.path.clone());
    let kml = kml.unwrap_or_else(|| panic!("no KML"));
    let body = read(&kml).replacen("</LineString>", "</LineString><styleUrl>#x</styleUrl>", 1);
    std::fs::write(&kml, body).unwrap_or_else(|e| panic!("{e}"));
    let refused = run(&expect);
    assert_eq!(refused.status.code(), Some(1));
    assert!(
        text(&refused.stderr).contains("could not read"),
        "{}",
        text(&refused.stderr)
    );
}

// ------------------------------------------------------------ designer

#[test]
fn the_designer_exports_the_shown_result_beside_the_mission_and_edits_the_origin() {
    use skyform::tui::fields::Item;
    use skyform::tui::{Action, App, Document};

    let dir = tempdir();
    let path = dir.path().join("bridge.toml");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("missions/bridge-inspection.toml"),
        &path,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let m = mission::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    let mut app = App::new(Document::new(m, Some(path.clone())), dir.path().to_owned());

    app.update(Action::Export);
    let status = app.status().cloned().unwrap_or_else(|| panic!("no status"));
    assert!(
        status.error && status.text.contains("no result"),
        "{}",
        status.text
    );

    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    assert!(app.wait_for_jobs(std::time::Duration::from_secs(120)));
    app.update(Action::ShowJob);
    app.update(Action::Export);
    let status = app.status().cloned().unwrap_or_else(|| panic!("no status"));
    assert!(!status.error, "{}", status.text);
    let folder = dir.path().join("bridge-export");
    assert!(
        status.text.contains(&folder.display().to_string()),
        "{}",
        status.text
    );
    for ext in ["plan", "waypoints", "csv"] {
        assert!(folder.join(format!("bridge-theta-pso-uav1.{ext}")).exists());
    }
    assert!(folder.join("bridge-theta-pso.kml").exists(), "and the KML");

    // The inspector edits [origin] (Mission item): its three fields.
    let fields = skyform::tui::fields::fields(&Item::Mission, app.mission());
    let labels: Vec<&str> = fields.iter().map(|f| f.label()).collect();
    for label in ["origin lat (°)", "origin lon (°)", "origin alt (m)"] {
        assert!(labels.contains(&label), "{labels:?}");
    }
    let lat = fields
        .iter()
        .find(|f| f.label() == "origin lat (°)")
        .unwrap_or_else(|| panic!("no field"));
    assert_eq!(lat.value(), "-33.87601");
    let mut edited = app.mission().clone();
    lat.set(&mut edited, &Item::Mission, "-34.5")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(edited.origin.as_ref().map(|o| o.latitude), Some(-34.5));
    // Issue 24, item 18: clearing the latitude does not drop the whole
    // [origin] silently; it says how to remove it, and `none` does.
    let before = edited.clone();
    let refused = lat.set(&mut edited, &Item::Mission, "").unwrap_err();
    assert!(refused.contains("type none"), "{refused}");
    assert_eq!(edited, before, "the origin stays");
    let alt = fields
        .iter()
        .find(|f| f.label() == "origin alt (m)")
        .unwrap_or_else(|| panic!("no field"));
    alt.set(&mut edited, &Item::Mission, "")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(edited.origin.as_ref().map(|o| o.altitude), Some(0.0));
    assert_eq!(edited.origin.as_ref().map(|o| o.latitude), Some(-34.5));
    lat.set(&mut edited, &Item::Mission, "none")
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(edited.origin.is_none(), "none removes [origin]");
}
