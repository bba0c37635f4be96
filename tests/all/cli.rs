//! The `skyform` binary as a script or CI sees it: output and exit status.

use std::path::Path;

use crate::common::skyform;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn check_passes_on_the_shipped_missions() {
    let out = skyform(&[
        "check",
        "missions/bridge-inspection.toml",
        "missions/flatlo-squadron.toml",
        "missions/fleet-triangle.toml",
        "missions/narrow-passage.toml",
        "missions/two-span-viaduct.toml",
        "missions/substation.toml",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
    // Issue 24, item 18: and without a warning (the fleet's route stood
    // closer to the bounds than its formation's radius).
    assert_eq!(
        text(&out.stdout)
            .matches(": ok (0 error(s), 0 warning(s))")
            .count(),
        6,
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn check_fails_with_file_line_and_field_on_a_bad_file() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let path = dir.path().join("bad.toml");
    let bad = "name = \"bad\"\n[bounds]\nx = [0.0, 10.0]\ny = [0.0, 10.0]\nz = [5.0, 1.0]\n\
               [route]\nstart = [1.0, 1.0, 2.0]\ngoal = [9.0, 9.0, 2.0]\n";
    std::fs::write(&path, bad).unwrap_or_else(|e| panic!("{e}"));
    let name = path.display().to_string();
    let out = skyform(&["check", &name]);
    assert_eq!(out.status.code(), Some(1));
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains(&format!("{name}:5:1: error: bounds.z: is inverted")),
        "{stdout}"
    );
    assert!(stdout.contains("FAILED"));

    let json = skyform(&["check", "--json", &name]);
    let parsed: serde_json::Value =
        serde_json::from_slice(&json.stdout).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(parsed[0]["valid"], serde_json::Value::Bool(false));
    assert_eq!(parsed[0]["diagnostics"][0]["path"], "bounds.z");
    assert_eq!(parsed[0]["diagnostics"][0]["location"]["line"], 5);
}

#[test]
fn a_missing_file_is_an_error_naming_it() {
    let out = skyform(&["check", "no/such/mission.toml"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stdout).contains("cannot read no/such/mission.toml"));
}

/// `skyform run NAME` for a name no pipeline registers: an error that lists
/// the registered ones (a pipeline without a subcommand of its own is run
/// through the same generic path, `RunCommand::Other`).
#[test]
fn running_an_unknown_pipeline_lists_the_registered_ones() {
    let out = skyform(&["run", "thetapso", "missions/bridge-inspection.toml"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("no pipeline 'thetapso' to run: theta-pso, flatlo, fleet"),
        "{stderr}"
    );
}

#[test]
fn run_theta_pso_prints_a_summary_and_the_outcome_as_json() {
    let out = skyform(&[
        "run",
        "theta-pso",
        "missions/bridge-inspection.toml",
        "--seed",
        "3",
        "--json",
        "-",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("FEASIBLE")
            && stderr.contains("alignment at the IWP between 'light pole 4' and 'pier 5'")
    );
    assert!(
        stderr.contains("progress: 100%"),
        "plain progress lines when not a terminal"
    );
    let outcome: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(outcome["seed"], 3);
    assert_eq!(outcome["verification"]["feasible"], true);
    assert_eq!(outcome["trajectories"].as_array().map(Vec::len), Some(3));
    assert_eq!(outcome["convergence"].as_array().map(Vec::len), Some(151));
}

#[test]
fn run_theta_pso_exits_2_on_an_infeasible_plan() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let path = dir.path().join("walled.toml");
    let mut text_toml = String::from(
        "name = \"walled in\"\n[bounds]\nx = [0.0, 100.0]\ny = [0.0, 100.0]\nz = [5.0, 15.0]\n\
         [route]\nstart = [20.0, 50.0, 10.0]\ngoal = [90.0, 50.0, 10.0]\n\
         [theta_pso]\nswarm_size = 20\niterations = 20\n",
    );
    for i in 0..24 {
        let a = i as f64 * std::f64::consts::TAU / 24.0;
        text_toml.push_str(&format!(
            "[[obstacles]]\nname = \"ring {i}\"\ncenter = [{}, {}]\nradius = 0.7\nheight = 30.0\n",
            20.0 + 6.0 * a.cos(),
            50.0 + 6.0 * a.sin()
        ));
    }
    std::fs::write(&path, text_toml).unwrap_or_else(|e| panic!("{e}"));
    let out = skyform(&["run", "theta-pso", &path.display().to_string()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    // The route stage refuses before the swarm flies: no plan, and where.
    let stdout = text(&out.stdout);
    assert!(stdout.contains("NO PLAN"), "{stdout}");
    assert!(stdout.contains("24 obstacles ('ring 0'"), "{stdout}");
    assert!(stdout.contains("round the start"), "{stdout}");
}

#[test]
fn run_theta_pso_on_an_invalid_mission_exits_1() {
    let out = skyform(&["run", "theta-pso", "Cargo.toml"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("Cargo.toml is not a valid mission"));
    assert!(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("Cargo.toml")
            .exists()
    );
}

#[test]
fn the_designer_refuses_a_file_that_is_not_a_mission_and_needs_a_terminal() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let path = dir.path().join("broken.toml");
    std::fs::write(&path, "name = \"x\"\n[bounds\n").unwrap_or_else(|e| panic!("{e}"));
    let name = path.display().to_string();
    for args in [vec![name.as_str()], vec!["edit", name.as_str()]] {
        let out = skyform(&args);
        assert_eq!(out.status.code(), Some(1));
        let stderr = text(&out.stderr);
        assert!(stderr.contains(&format!("{name}:2:")), "{stderr}");
    }
    // A good file, but the test's stdout is a pipe: no TUI, a clear message.
    let out = skyform(&["missions/bridge-inspection.toml"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("needs a terminal"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn run_flatlo_summarises_the_squadron_and_exits_by_its_verdict() {
    let out = skyform(&["run", "flatlo", "missions/flatlo-squadron.toml"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("FLATLO transition for \"FLATLO squadron transition\" (seed 3)"),
        "{stdout}"
    );
    assert!(stdout.contains("aircraft 4   right"), "{stdout}");
    assert!(stdout.contains("result       PASS"), "{stdout}");

    // A separation the squadron cannot keep: exit 2, and the summary says why.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let strict = dir.path().join("strict.toml");
    let source = std::fs::read_to_string("missions/flatlo-squadron.toml").unwrap_or_default();
    let edited = source.replace("min_separation = 1000.0", "min_separation = 16000.0");
    assert_ne!(edited, source);
    std::fs::write(&strict, edited).unwrap_or_else(|e| panic!("{e}"));
    let out = skyform(&["run", "flatlo", strict.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stdout).contains("result       FAIL: closest aircraft 2 and 4"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn run_fleet_reports_each_target_and_exits_by_its_verdict() {
    let out = skyform(&[
        "run",
        "fleet",
        "missions/fleet-triangle.toml",
        "--seed",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("Fleet for \"Fleet triangle\" (seed 2)"),
        "{stdout}"
    );
    assert_eq!(stdout.matches("formed ").count(), 4, "{stdout}");
    assert!(stdout.contains("result       PASS"), "{stdout}");

    // A formation the duration is too short for: exit 2.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let short = dir.path().join("short.toml");
    let source = std::fs::read_to_string("missions/fleet-triangle.toml").unwrap_or_default();
    let edited = source.replace("duration = 80.0", "duration = 3.0");
    assert_ne!(edited, source);
    std::fs::write(&short, edited).unwrap_or_else(|e| panic!("{e}"));
    let out = skyform(&["run", "fleet", short.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stdout));
    assert!(text(&out.stdout).contains("NOT REACHED"));
}

/// Issue 24, item 1: `skyform new FILE` writes the minimal mission;
/// `--from` copies a shipped mission on purpose (its text, comments and
/// all); neither replaces a file.
#[test]
fn new_writes_the_minimal_mission_or_a_copy_on_purpose() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let file = dir.path().join("turbines.toml");
    let name = file.display().to_string();
    let out = skyform(&["new", &name, "--no-open"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let written = std::fs::read_to_string(&file).unwrap_or_default();
    let m = skyform::mission::load(&file)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    assert_eq!(m.name, "turbines");
    assert!(m.origin.is_none() && m.obstacles.is_empty(), "{written}");
    assert!(!written.contains("bridge"), "{written}");

    let again = skyform(&["new", &name, "--no-open"]);
    assert_eq!(again.status.code(), Some(1));
    assert!(
        text(&again.stderr).contains("exists"),
        "{}",
        text(&again.stderr)
    );

    let copy = dir.path().join("my-bridge.toml");
    let copy_name = copy.display().to_string();
    let out = skyform(&[
        "new",
        &copy_name,
        "--from",
        "missions/bridge-inspection.toml",
        "--no-open",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        std::fs::read_to_string(&copy).unwrap_or_default(),
        std::fs::read_to_string("missions/bridge-inspection.toml").unwrap_or_default()
    );
    let by_name = dir.path().join("fleet.toml");
    let out = skyform(&[
        "new",
        &by_name.display().to_string(),
        "--from",
        "fleet-triangle",
        "--no-open",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let bad = skyform(&["new", "x.toml", "--from", "no-such-mission", "--no-open"]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(text(&bad.stderr).contains("bridge-inspection.toml"));
}

/// `--warm-from`: a run warm-started from an earlier outcome records what
/// it started from (so the JSON says it was warm) and settles early; its
/// `warm_start` record given back repeats it exactly; a file that is not a
/// plan is an error naming it.
#[test]
fn a_warm_started_run_is_recorded_and_can_be_repeated() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).display().to_string();
    let bridge = "missions/bridge-inspection.toml";
    let out = skyform(&["run", "theta-pso", bridge, "--json", &path("cold.json")]);
    assert_eq!(out.status.code(), Some(0));
    let out = skyform(&[
        "run",
        "theta-pso",
        bridge,
        "--warm-from",
        &path("cold.json"),
        "--json",
        &path("warm.json"),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(path(name)).unwrap()).unwrap()
    };
    let (cold, warm) = (read("cold.json"), read("warm.json"));
    assert!(
        cold.get("warm_start").is_none(),
        "a cold run says nothing of a warm start"
    );
    let from = warm["warm_start"]["from"].as_str().unwrap_or_default();
    assert!(from.contains("cold.json"), "{from}");
    assert!(warm["iterations"].as_u64().unwrap() < 150);
    assert_eq!(warm["verification"]["feasible"], true);
    std::fs::write(path("record.json"), warm["warm_start"].to_string()).unwrap();
    let out = skyform(&[
        "run",
        "theta-pso",
        bridge,
        "--warm-from",
        &path("record.json"),
        "--json",
        &path("again.json"),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let again = read("again.json");
    assert_eq!(again["cost"], warm["cost"], "repeated from its record");
    assert_eq!(again["waypoints"], warm["waypoints"]);

    std::fs::write(path("junk.json"), "{\"nothing\": 1}").unwrap();
    let out = skyform(&[
        "run",
        "theta-pso",
        bridge,
        "--warm-from",
        &path("junk.json"),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("junk.json") && err.contains("waypoints"),
        "{err}"
    );
}

/// Issue 37, "an answer a person can read": `check` on a valid maze of 150
/// posts in three walls 12 m apart (each with a gap the formation's column
/// takes) prints at most 12 lines: the IWPs between posts of two walls that
/// no route uses are counted, not listed one per pair (235 lines at the
/// issue's filing).
#[test]
fn check_on_a_maze_of_150_posts_is_a_few_lines() {
    let mut maze = String::from(
        "name = \"maze\"\n[bounds]\nx = [0.0, 80.0]\ny = [0.0, 80.0]\nz = [5.0, 20.0]\n\
         [route]\nstart = [5.0, 40.0, 10.0]\ngoal = [75.0, 40.0, 10.0]\n",
    );
    for (w, x) in [28.0, 40.0, 52.0].iter().enumerate() {
        // 50 posts of 0.5 m, 1.54 m apart, leaving out two for a gap.
        let gap = [10, 25, 40][w];
        for k in (0..52).filter(|k| *k != gap && *k != gap + 1) {
            maze.push_str(&format!(
                "[[obstacles]]\nname = \"wall {} post {}\"\ncenter = [{x}, {:.2}]\nradius = 0.5\nheight = 30.0\n",
                w + 1,
                k + 1,
                0.6 + 1.54 * k as f64
            ));
        }
    }
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let path = dir.path().join("maze.toml");
    std::fs::write(&path, &maze).unwrap_or_else(|e| panic!("{e}"));
    let out = skyform(&["check", &path.display().to_string()]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert_eq!(maze.matches("[[obstacles]]").count(), 150);
    let lines = stdout.lines().count();
    assert!(lines <= 12, "{lines} lines:\n{stdout}");
}
