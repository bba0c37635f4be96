//! Rerun recordings, read back with the SDK's own decoder.

use std::fs::File;
use std::io::BufReader;
use std::net::TcpListener;
use std::path::Path;
use std::time::{Duration, Instant};

use re_chunk::{Chunk, ChunkComponentSlicer};
use re_log_encoding::DecoderApp;
use re_log_types::LogMsg;
use skyform::mission;

use crate::common::skyform;

/// Every chunk of an .rrd, decoded by the SDK.
fn chunks(path: &Path) -> Vec<Chunk> {
    let file = File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let messages = DecoderApp::decode_eager(BufReader::new(file))
        .unwrap_or_else(|e| panic!("{}: not an rrd: {e}", path.display()));
    messages
        .map(|m| m.unwrap_or_else(|e| panic!("decoding {}: {e}", path.display())))
        .filter_map(|m| match m {
            LogMsg::ArrowMsg(_, arrow) => Some(Chunk::from_arrow_msg(&arrow)),
            _ => None,
        })
        .map(|c| c.unwrap_or_else(|e| panic!("bad chunk: {e}")))
        .collect()
}

fn entity_paths(chunks: &[Chunk]) -> Vec<String> {
    let mut paths: Vec<String> = chunks.iter().map(|c| c.entity_path().to_string()).collect();
    paths.sort();
    paths.dedup();
    paths
}

/// All values of a primitive component ("Cylinders3D:radii" as f32,
/// "Scalars:scalars" as f64) logged at `entity`.
fn values<T>(chunks: &[Chunk], entity: &str, component: &str) -> Vec<T>
where
    T: Copy + for<'a> ChunkComponentSlicer<Item<'a> = &'a [T]>,
{
    let mut out = Vec::new();
    for c in chunks
        .iter()
        .filter(|c| c.entity_path().to_string() == entity)
    {
        for d in c.component_descriptors() {
            if d.component.as_str() == component {
                for slice in c.iter_slices::<T>(d.component) {
                    out.extend_from_slice(slice);
                }
            }
        }
    }
    out
}

/// The largest time on `timeline` in chunks of `entity`, raw (nanoseconds for durations).
fn last_time(chunks: &[Chunk], entity: &str, timeline: &str) -> Option<i64> {
    chunks
        .iter()
        .filter(|c| c.entity_path().to_string() == entity)
        .filter_map(|c| {
            c.timelines()
                .iter()
                .find(|(name, _)| name.as_str() == timeline)
                .and_then(|(_, col)| col.times_raw().iter().copied().max())
        })
        .max()
}

/// `skyform run PIPELINE MISSION ARGS… --rrd … --json …`, which must exit 0:
/// the outcome as JSON and the recording's chunks.
fn run_recorded(pipeline: &str, mission: &str, args: &[&str]) -> (serde_json::Value, Vec<Chunk>) {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let rrd = dir.path().join("run.rrd");
    let json = dir.path().join("run.json");
    let (rrd_arg, json_arg) = (rrd.display().to_string(), json.display().to_string());
    let mut all = vec!["run", pipeline, mission];
    all.extend_from_slice(args);
    all.extend(["--rrd", &rrd_arg, "--json", &json_arg]);
    let out = skyform(&all);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let outcome: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&json).unwrap_or_else(|e| panic!("{e}")))
            .unwrap_or_else(|e| panic!("{e}"));
    (outcome, chunks(&rrd))
}

#[test]
fn a_theta_pso_recording_holds_the_scene_the_plan_and_the_timelines() {
    let (outcome, chunks) = run_recorded(
        "theta-pso",
        "missions/bridge-inspection.toml",
        &["--seed", "5"],
    );
    let paths = entity_paths(&chunks);
    for expected in [
        "/world",
        "/world/bounds",
        "/world/obstacles",
        "/world/route",
        "/world/iwps",
        "/theta_pso/best_path",
        "/theta_pso/cost/J_total",
        "/theta_pso/cost/J2_obstacle",
        "/theta_pso/plan/centroid",
        "/theta_pso/events",
    ] {
        assert!(
            paths.iter().any(|p| p == expected),
            "missing {expected} in {paths:?}"
        );
    }

    // Obstacles: one cylinder per mission obstacle, true radius and height.
    let m = mission::default_mission().mission;
    let radii = values::<f32>(&chunks, "/world/obstacles", "Cylinders3D:radii");
    let lengths = values::<f32>(&chunks, "/world/obstacles", "Cylinders3D:lengths");
    assert_eq!(radii.len(), m.obstacles.len());
    for (o, (r, h)) in m.obstacles.iter().zip(radii.iter().zip(&lengths)) {
        assert_eq!(*r, o.radius as f32, "{}", o.name);
        assert_eq!(*h, o.height as f32, "{}", o.name);
    }

    // θ-PSO's scene (`Pipeline::scene`): the bridge's one IWP, enabled
    // (yellow), 0.4 m, at mid-band.
    let iwps = skyform::pipelines::theta_pso::find_iwps(&m);
    assert_eq!(iwps.len(), 1);
    let radii = values::<f32>(&chunks, "/world/iwps", "Points3D:radii");
    let colors = values::<u32>(&chunks, "/world/iwps", "Points3D:colors");
    assert_eq!((radii, colors), (vec![0.4f32], vec![0xFAC800FFu32]));
    let positions = values::<[f32; 3]>(&chunks, "/world/iwps", "Points3D:positions");
    let mid = ((m.bounds.z[0] + m.bounds.z[1]) / 2.0) as f32;
    assert_eq!(
        positions,
        vec![[iwps[0].position.x as f32, iwps[0].position.y as f32, mid]]
    );

    // One moving point per UAV, and the last sim_time is the mission duration.
    let uavs: Vec<_> = paths
        .iter()
        .filter(|p| p.starts_with("/theta_pso/uavs/uav_") && !p.ends_with("velocity"))
        .collect();
    assert_eq!(uavs.len(), 3, "{uavs:?}");
    let duration = outcome["duration"].as_f64().unwrap_or(f64::NAN);
    for uav in &uavs {
        let last = last_time(&chunks, uav, "sim_time").map(|ns| ns as f64 * 1e-9);
        let last = last.unwrap_or(f64::NAN);
        assert!(
            (last - duration).abs() < 1e-6,
            "{uav}: last sim_time {last} vs {duration}"
        );
    }
    // The convergence series covers every iteration, 0..=150.
    assert_eq!(
        last_time(&chunks, "/theta_pso/cost/J_total", "iteration"),
        Some(150)
    );
    // …and its values are the outcome's convergence history.
    let totals = values::<f64>(&chunks, "/theta_pso/cost/J_total", "Scalars:scalars");
    let history: Vec<f64> = outcome["convergence"]
        .as_array()
        .map(|a| a.iter().filter_map(|v| v.as_f64()).collect())
        .unwrap_or_default();
    // (serde_json's default float parsing can be one ulp off, hence the tolerance.)
    assert_eq!(totals.len(), history.len());
    for (a, b) in totals.iter().zip(&history) {
        assert!((a - b).abs() <= 1e-12 * a.abs(), "{a} vs {b}");
    }

    // Issue 16: the plot beside the scene has data on `sim_time`, the
    // timeline the viewer opens on: each UAV's clearance (beyond r_Q) over
    // the flight, whose smallest value is the verification's worst obstacle
    // clearance less its limit.
    let checks = outcome["verification"]["checks"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    let Some(check) = checks.iter().find(|c| c["name"] == "obstacle clearance") else {
        panic!("no obstacle clearance check in {checks:?}");
    };
    let expected =
        check["worst"].as_f64().unwrap_or(f64::NAN) - check["limit"].as_f64().unwrap_or(f64::NAN);
    let mut lowest = f64::INFINITY;
    for uav in 1..=3 {
        let entity = format!("/theta_pso/clearance/uav_{uav}");
        let series = values::<f64>(&chunks, &entity, "Scalars:scalars");
        assert!(!series.is_empty(), "no {entity}");
        assert!(
            last_time(&chunks, &entity, "sim_time").is_some(),
            "{entity} not on sim_time"
        );
        lowest = series.iter().copied().fold(lowest, f64::min);
    }
    assert!(
        (lowest - expected).abs() < 1e-6,
        "lowest clearance {lowest} vs {expected}"
    );
}

/// `skyform record MISSION --rrd …`, which must succeed, read back.
fn record_scene(mission: &str) -> Vec<Chunk> {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let rrd = dir.path().join("scene.rrd");
    let out = skyform(&["record", mission, "--rrd", &rrd.display().to_string()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    chunks(&rrd)
}

#[test]
fn record_writes_the_mission_scene_alone() {
    let chunks = record_scene("missions/narrow-passage.toml");
    let paths = entity_paths(&chunks);
    assert!(paths.iter().any(|p| p == "/world/obstacles"));
    assert!(
        !paths.iter().any(|p| p.starts_with("/theta_pso")),
        "{paths:?}"
    );
    assert_eq!(
        values::<f32>(&chunks, "/world/obstacles", "Cylinders3D:radii"),
        vec![7.0, 8.0]
    );
    assert!(
        !paths.iter().any(|p| p == "/world/terrain"),
        "no terrain here"
    );
}

/// Issue 15: a mission's terrain is in the recording as a mesh in the same
/// frame as the paths: the SPSO benchmark's 1045 × 879 map every 6th column
/// and 5th row (at most 200 points a side) plus the last, at its heights.
#[test]
fn the_terrain_is_recorded_as_a_mesh() {
    let chunks = record_scene("missions/spso-benchmark.toml");
    let vertices = values::<[f32; 3]>(&chunks, "/world/terrain", "Mesh3D:vertex_positions");
    assert_eq!(vertices.len(), 175 * 177);
    assert_eq!(&vertices[0][..2], &[1.0, 1.0]);
    assert_eq!(&vertices[vertices.len() - 1][..2], &[1045.0, 879.0]);
    let (low, high) = vertices
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), v| {
            (l.min(v[2]), h.max(v[2]))
        });
    assert!(
        low > 45.0 && high < 300.0 && high - low > 150.0,
        "{low}..{high}"
    );
    let colours = values::<u32>(&chunks, "/world/terrain", "Mesh3D:vertex_colors");
    assert_eq!(colours.len(), vertices.len());
}

#[test]
fn an_unreachable_viewer_costs_one_warning_and_no_time() {
    // A port that was just free: nothing listens there.
    let port = TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .unwrap_or(9);
    let url = format!("rerun+http://127.0.0.1:{port}/proxy");
    let started = Instant::now();
    let plain = skyform(&["run", "theta-pso", "missions/bridge-inspection.toml"]);
    let without = started.elapsed();
    let started = Instant::now();
    let out = skyform(&[
        "run",
        "theta-pso",
        "missions/bridge-inspection.toml",
        "--connect",
        &url,
    ]);
    let with = started.elapsed();
    assert_eq!(plain.status.code(), Some(0));
    assert_eq!(out.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let warnings: Vec<_> = stderr
        .lines()
        .filter(|l| l.starts_with("warning:"))
        .collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains(&url));
    // The probe gives up within 300 ms; nothing else waits for the viewer.
    assert!(
        with < without + Duration::from_secs(2),
        "{with:?} vs {without:?}"
    );
    assert_eq!(
        plain.stdout, out.stdout,
        "same plan with or without a viewer"
    );
}

#[test]
fn a_bad_viewer_url_or_rrd_directory_is_a_clear_error() {
    let out = skyform(&[
        "record",
        "missions/narrow-passage.toml",
        "--connect",
        "not a url",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("'not a url' is not a Rerun viewer URL"));
    let out = skyform(&[
        "record",
        "missions/narrow-passage.toml",
        "--rrd",
        "/no/such/dir/x.rrd",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("cannot create the recording file /no/such/dir/x.rrd")
    );
    let out = skyform(&["record", "missions/narrow-passage.toml"]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn a_flatlo_recording_holds_references_flights_series_and_events() {
    let (outcome, chunks) = run_recorded("flatlo", "missions/flatlo-squadron.toml", &[]);
    let paths = entity_paths(&chunks);
    for i in 0..4 {
        for prefix in [
            "reference",
            "flown",
            "aircraft",
            "airspeed",
            "gamma_deg",
            "chi_deg",
            "thrust",
            "load_factor",
            "bank_deg",
        ] {
            let entity = format!("/flatlo/{prefix}/aircraft_{i}");
            assert!(paths.contains(&entity), "{entity} missing from {paths:?}");
        }
        // One airspeed value per flown sample, equal to the outcome's.
        let airspeed: Vec<f64> = values(
            &chunks,
            &format!("/flatlo/airspeed/aircraft_{i}"),
            "Scalars:scalars",
        );
        let flown = outcome["aircraft"][i]["flown"]
            .as_array()
            .map(Vec::len)
            .unwrap_or(0);
        assert_eq!(airspeed.len(), flown);
        let first = outcome["aircraft"][i]["flown"][0]["airspeed"]
            .as_f64()
            .unwrap_or(f64::NAN);
        assert!((airspeed[0] - first).abs() < 1e-9);
        let last = last_time(
            &chunks,
            &format!("/flatlo/aircraft/aircraft_{i}"),
            "sim_time",
        )
        .unwrap_or(0);
        let duration = outcome["duration"].as_f64().unwrap_or(0.0);
        assert!(
            (last as f64 / 1e9 - duration).abs() < 0.2,
            "{last} ns vs {duration} s"
        );
    }
    assert!(paths.contains(&"/flatlo/events".to_owned()));
}

#[test]
fn a_fleet_recording_holds_agents_references_and_the_distance_series() {
    let (outcome, chunks) = run_recorded("fleet", "missions/fleet-triangle.toml", &[]);
    let paths = entity_paths(&chunks);
    for i in 0..3 {
        for prefix in ["agents", "references", "trails"] {
            let entity = format!("/fleet/{prefix}/agent_{i}");
            assert!(paths.contains(&entity), "{entity} missing from {paths:?}");
        }
    }
    // Fig. 13: one series per pair, equal to the outcome's.
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let series: Vec<f64> = values(
            &chunks,
            &format!("/fleet/distances/{}_{}", a + 1, b + 1),
            "Scalars:scalars",
        );
        let expected: Vec<f64> = outcome["distances"]
            .as_array()
            // The JSON numbers agents from 1, as the entity paths do.
            .and_then(|all| all.iter().find(|d| d["a"] == a + 1 && d["b"] == b + 1))
            .and_then(|d| d["values"].as_array())
            .map(|v| v.iter().filter_map(|x| x.as_f64()).collect())
            .unwrap_or_default();
        assert_eq!(series.len(), expected.len());
        assert!(
            series
                .iter()
                .zip(&expected)
                .all(|(x, y)| (x - y).abs() < 1e-9)
        );
    }
    assert!(paths.contains(&"/fleet/distances/safety_c".to_owned()));
    assert!(paths.contains(&"/fleet/events".to_owned()));
}

/// Each pipeline's log lines land under its own path, where its layout's
/// event panel shows them, and nothing lands under another pipeline's.
#[test]
fn each_pipelines_log_lines_land_under_its_own_path() {
    let runs = [
        ("theta-pso", "theta_pso", "missions/bridge-inspection.toml"),
        ("flatlo", "flatlo", "missions/flatlo-squadron.toml"),
        ("fleet", "fleet", "missions/fleet-triangle.toml"),
    ];
    for (pipeline, own, mission) in runs {
        let (_, chunks) = run_recorded(pipeline, mission, &[]);
        let paths = entity_paths(&chunks);
        let log = format!("/{own}/log");
        assert!(paths.contains(&log), "{pipeline}: no {log} in {paths:?}");
        for (_, other, _) in runs.iter().filter(|(_, o, _)| *o != own) {
            let prefix = format!("/{other}/");
            assert!(
                !paths.iter().any(|p| p.starts_with(&prefix)),
                "{pipeline} logged under {prefix}: {paths:?}"
            );
        }
    }
}

/// The network in a fleet recording: at every sample the links between the
/// agents that heard each other (`/fleet/links`), and an agent lost on the
/// way as a warning on the events log at its time and a marker where it was.
#[test]
fn a_fleet_recording_shows_the_links_and_the_lost_agents() {
    use skyform::outcome::Outcome;
    use skyform::pipelines::fleet::{self, simulation::LostAgent};
    use skyform::pipelines::{CancelToken, Silent};
    let mut m = skyform::mission::load(Path::new("missions/fleet-triangle.toml"))
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    m.fleet.duration = Some(4.0);
    let mut o =
        fleet::plan(&m, 3, &mut Silent, &CancelToken::new()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(o.links.len(), o.times.len(), "a set of links per sample");
    assert!(
        o.links.iter().any(|pairs| pairs.len() == 3),
        "all three hear each other"
    );
    // Agent 2 lost at 2 s: its samples end there.
    o.agents[1].samples.retain(|s| s.t <= 2.0);
    o.lost.push(LostAgent {
        agent: 1,
        step: 400,
        time: 2.0,
        reason: "its process went away".into(),
    });
    let chunks = recorded(&m.name, skyform::pipelines::Kind::Fleet, |r| {
        r.log_outcome(&Outcome::Fleet(Box::new(o.clone())));
    });
    let paths = entity_paths(&chunks);
    for entity in [
        "/fleet/links",
        "/fleet/lost/agent_1",
        "/fleet/agents/agent_1",
    ] {
        assert!(
            paths.contains(&entity.to_owned()),
            "{entity} missing from {paths:?}"
        );
    }
    // The links are logged at every sample, up to the end of the run.
    let end = last_time(&chunks, "/fleet/links", "sim_time");
    assert_eq!(end, Some(4_000_000_000));
    // The lost agent's point stops at 2 s; the others fly to the end.
    assert_eq!(
        last_time(&chunks, "/fleet/agents/agent_1", "sim_time"),
        Some(2_000_000_000)
    );
    assert_eq!(
        last_time(&chunks, "/fleet/agents/agent_0", "sim_time"),
        Some(4_000_000_000)
    );
    let texts: Vec<String> = chunks
        .iter()
        .filter(|c| c.entity_path().to_string() == "/fleet/events")
        .flat_map(|c| {
            c.component_descriptors()
                .filter(|d| d.component.as_str() == "TextLog:text")
                .flat_map(|d| {
                    c.iter_slices::<String>(d.component)
                        .flat_map(|s| s.into_iter().map(|t| t.to_string()))
                        .collect::<Vec<_>>()
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(
        texts
            .iter()
            .any(|t| t.contains("agent 2 lost: its process went away")),
        "{texts:?}"
    );
}

/// The designer's live plans in a recording: each a `revision` of the same
/// plan entities (the view follows the edit, the timeline keeps them all),
/// with its verdict on the live events.
#[test]
fn live_plans_are_revisions_of_one_recording() {
    use skyform::outcome::Outcome;
    use skyform::pipelines::theta_pso::{PlanOptions, plan};
    use skyform::pipelines::{CancelToken, Silent};
    let m = skyform::mission::default_mission().mission;
    let o = plan(
        &m,
        7,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let outcome = Outcome::ThetaPso(Box::new(o));
    let chunks = recorded(&m.name, skyform::pipelines::Kind::ThetaPso, |r| {
        r.log_mission(&m);
        for revision in 1..=3 {
            r.log_live(revision, &outcome);
        }
    });
    let paths = entity_paths(&chunks);
    for entity in [
        "/live/plan/centroid",
        "/live/plan/vehicle_1",
        "/live/plan/vehicle_3",
        "/live/events",
    ] {
        assert!(
            paths.contains(&entity.to_owned()),
            "{entity} missing from {paths:?}"
        );
    }
    assert_eq!(
        last_time(&chunks, "/live/plan/centroid", "revision"),
        Some(3)
    );
    assert_eq!(last_time(&chunks, "/live/events", "revision"), Some(3));
}

/// The chunks of a recording of a `kind` run of `name` to an `.rrd`, what
/// `log` logs to its recorder.
fn recorded(
    name: &str,
    kind: skyform::pipelines::Kind,
    log: impl FnOnce(&mut skyform::record::Recorder),
) -> Vec<Chunk> {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let rrd = dir.path().join("run.rrd");
    let sinks = skyform::record::Sinks {
        rrd: Some(rrd.clone()),
        connect: None,
        spawn: false,
    };
    let mut warnings = Vec::new();
    let mut recorder = skyform::record::Recorder::start(name, Some(kind), &sinks, &mut warnings)
        .unwrap_or_else(|e| panic!("{e}"))
        .unwrap_or_else(|| panic!("no recorder"));
    log(&mut recorder);
    recorder.finish();
    chunks(&rrd)
}

/// Issue 39, item 4: `skyform fly --rrd` records the plan as written, each
/// UAV's p99 envelope as a tube (balls whose radii are the p99 cross-track
/// error) and the worst flights as flown, read back here; the report says
/// which flight was worst, and that flight is among those recorded.
#[test]
fn a_flight_check_recording_holds_the_worst_flights_and_the_envelope() {
    let dir = tempfile::tempdir().expect("tempdir");
    let rrd = dir.path().join("fly.rrd");
    let json = dir.path().join("fly.json");
    let out = skyform(&[
        "fly",
        "missions/bridge-inspection.toml",
        "--seed",
        "1",
        "--flights",
        "24",
        "--rrd",
        &rrd.display().to_string(),
        "--json",
        &json.display().to_string(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        matches!(out.status.code(), Some(0) | Some(2)),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("a report");
    let worst = report["worst"]["flight"].as_u64().expect("a worst flight");
    let chunks = chunks(&rrd);
    let paths = entity_paths(&chunks);
    for uav in 1..=3 {
        for path in [
            format!("/flight/written/uav_{uav}"),
            format!("/flight/envelope/uav_{uav}"),
            format!("/flight/worst/flight_{worst}/uav_{uav}"),
        ] {
            assert!(paths.contains(&path), "{path} not in {paths:?}");
        }
        let radii: Vec<f32> = values(
            &chunks,
            &format!("/flight/envelope/uav_{uav}"),
            "Points3D:radii",
        );
        assert!(radii.len() > 50, "{} balls", radii.len());
        // The tube is the p99 of cross-track errors that GNSS alone (σ 1 m)
        // keeps above a few decimetres almost everywhere.
        let median = {
            let mut r = radii.clone();
            r.sort_by(f32::total_cmp);
            r[r.len() / 2]
        };
        assert!(median > 0.3 && median < 10.0, "median radius {median} m");
    }
    let recorded_worst = paths
        .iter()
        .filter(|p| p.starts_with("/flight/worst/"))
        .count();
    assert_eq!(
        recorded_worst,
        3 * 3,
        "three flights of three UAVs: {paths:?}"
    );
    assert!(paths.contains(&"/flight/report".to_owned()));
}

/// Issue 52, item 1: the most likely failing flight of `--rare` is
/// replayable. `--failure F` writes its inputs with the mission and seed;
/// `--inputs F` flies it again (the same pair, the same closest distance to
/// the centimetre as the estimate said) and records it as flown beside the
/// plan as written; a replay on another seed's plan is refused, naming the
/// seed to use.
#[test]
fn the_most_likely_failing_flight_is_written_flown_again_and_recorded() {
    let dir = tempfile::tempdir().expect("tempdir");
    let failing = dir.path().join("failing.json");
    let rrd = dir.path().join("failing.rrd");
    let f = failing.display().to_string();
    let out = skyform(&[
        "fly",
        "missions/bridge-inspection.toml",
        "--seed",
        "1",
        "--rare",
        "--per-level",
        "30",
        "--failure",
        &f,
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(2), "{stdout}");
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&failing).expect("written")).expect("json");
    let separation = file["flights"]
        .as_array()
        .and_then(|a| a.iter().find(|f| f["limit"] == "separation"))
        .unwrap_or_else(|| panic!("no separation failure in {stdout}"));
    assert!(
        separation["inputs"]
            .as_array()
            .is_some_and(|u| u.len() > 1000)
    );
    // "UAV 2 and UAV 3 0.98 m apart": the pair and its distance.
    let what = separation["failure"]["what"].as_str().expect("what");
    let words: Vec<&str> = what.split_whitespace().collect();
    let (a, b, d) = (words[1], words[4], words[5]);
    assert!(stdout.contains(what), "{stdout}");

    let again = skyform(&[
        "fly",
        "missions/bridge-inspection.toml",
        "--seed",
        "1",
        "--inputs",
        &f,
        "--rrd",
        &rrd.display().to_string(),
    ]);
    let replayed = String::from_utf8_lossy(&again.stdout);
    assert_eq!(again.status.code(), Some(2), "{replayed}");
    let line = format!("BREAKS UAV {a} - UAV {b}: closest {d} m");
    assert!(replayed.contains(&line), "{line} not in {replayed}");
    let paths = entity_paths(&chunks(&rrd));
    for uav in 1..=3 {
        for path in [
            format!("/flight/written/uav_{uav}"),
            format!("/flight/failing/most_likely_separation/uav_{uav}"),
        ] {
            assert!(paths.contains(&path), "{path} not in {paths:?}");
        }
    }

    let refused = skyform(&[
        "fly",
        "missions/bridge-inspection.toml",
        "--seed",
        "2",
        "--inputs",
        &f,
    ]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("add --seed 1"), "{stderr}");
}
