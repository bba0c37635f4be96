//! Every validation rule on a small bad file: the diagnostic must name the
//! file, the field path and the line the field is written on.

use skyform::mission::{Diagnostic, Severity, check_str, parse_str};

const FILE: &str = "bad.toml";

/// A valid mission of 8 lines, plus whatever a test appends.
fn mission_with(extra: &str) -> String {
    format!(
        "name = \"test\"\n\
         [bounds]\n\
         x = [0.0, 100.0]\n\
         y = [0.0, 100.0]\n\
         z = [5.0, 15.0]\n\
         [route]\n\
         start = [10.0, 10.0, 10.0]\n\
         goal = [90.0, 90.0, 10.0]\n\
         {extra}"
    )
}

/// 1-based line of the first line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("{needle:?} not in the test text"))
}

/// All diagnostics of `text`.
fn diagnostics(text: &str) -> Vec<Diagnostic> {
    check_str(text, Some(FILE)).report.diagnostics
}

/// The one error at `path`; fails the test with every diagnostic otherwise.
fn error_at(text: &str, path: &str) -> Diagnostic {
    let all = diagnostics(text);
    let found: Vec<_> = all
        .iter()
        .filter(|d| d.severity == Severity::Error && d.path.to_string() == path)
        .cloned()
        .collect();
    assert!(
        !found.is_empty(),
        "no error at {path}; diagnostics:\n{}",
        all.iter()
            .map(|d| d.to_string())
            .collect::<Vec<_>>()
            .join("\n")
    );
    found[0].clone()
}

/// Asserts an error at `path` on the line holding `needle`, mentioning `words`.
fn assert_error(text: &str, path: &str, needle: &str, words: &str) {
    let d = error_at(text, path);
    let line = line_of(text, needle);
    assert_eq!(d.file.as_deref(), Some(FILE));
    assert_eq!(
        d.location.map(|l| l.line),
        Some(line),
        "wrong line for {path}: {d}"
    );
    assert!(
        d.message.contains(words),
        "message of {path} should mention {words:?}: {d}"
    );
    let printed = d.to_string();
    assert!(
        printed.starts_with(&format!("{FILE}:{line}:")) && printed.contains(path),
        "printed form must carry file:line and the path: {printed}"
    );
}

#[test]
fn the_minimal_mission_is_valid() {
    let text = mission_with("");
    let all = diagnostics(&text);
    assert!(all.is_empty(), "{all:?}");
}

#[test]
fn unknown_keys_are_errors_at_their_line() {
    // Top-level keys must come before the tables, so put the typo first.
    let text = format!("nmae = \"typo\"\n{}", mission_with(""));
    assert_error(&text, "nmae", "nmae", "unknown field");

    let text = mission_with("[formation]\nuav_radiuss = 0.5\n");
    assert_error(
        &text,
        "formation.uav_radiuss",
        "uav_radiuss",
        "unknown field",
    );

    let text = mission_with(
        "[[obstacles]]\nname = \"a\"\ncenter = [50.0, 50.0]\nradius = 1.0\nheight = 5.0\nheigth = 4.0\n",
    );
    assert_error(&text, "obstacles[0].heigth", "heigth", "unknown field");

    let text = mission_with("[theta_pso]\nswarm = 10\n");
    assert_error(&text, "theta_pso.swarm", "swarm = 10", "unknown field");
}

#[test]
fn syntax_errors_are_reported_with_their_line() {
    let text = mission_with("[formation\nuav_radius = 0.5\n");
    let all = diagnostics(&text);
    assert!(!all.is_empty());
    assert!(all.iter().all(|d| d.is_error()));
    assert_eq!(all[0].location.map(|l| l.line), Some(9), "{}", all[0]);
}

#[test]
fn wrong_types_name_the_field() {
    let text = mission_with("[formation]\nuav_radius = \"half a metre\"\n");
    assert_error(
        &text,
        "formation.uav_radius",
        "half a metre",
        "invalid type",
    );
}

#[test]
fn non_finite_numbers_are_errors() {
    let text = mission_with(
        "[[obstacles]]\nname = \"a\"\ncenter = [50.0, 50.0]\nradius = nan\nheight = 5.0\n",
    );
    assert_error(&text, "obstacles[0].radius", "radius = nan", "finite");
    let text = mission_with("[theta_pso]\ninertia = inf\n");
    assert_error(&text, "theta_pso.inertia", "inertia = inf", "finite");
    let text = mission_with("[formation]\nslots = [[0.0, 2.0, 0.0], [-inf, -1.0, 0.0]]\n");
    assert_error(&text, "formation.slots[1][0]", "slots =", "finite");
}

#[test]
fn non_positive_radius_height_and_speed_are_errors() {
    let obstacle = |radius: &str, height: &str| {
        mission_with(&format!(
            "[[obstacles]]\nname = \"a\"\ncenter = [50.0, 50.0]\nradius = {radius}\nheight = {height}\n\
             [[obstacles]]\nname = \"b\"\ncenter = [30.0, 60.0]\nradius = 1.0\nheight = 5.0\n"
        ))
    };
    assert_error(
        &obstacle("-1.0", "5.0"),
        "obstacles[0].radius",
        "radius = -1.0",
        "positive",
    );
    assert_error(
        &obstacle("1.0", "0.0"),
        "obstacles[0].height",
        "height = 0.0",
        "positive",
    );
    let text = mission_with("[formation]\nground_speed = 0.0\n");
    assert_error(&text, "formation.ground_speed", "ground_speed", "positive");
    let text = mission_with("[formation]\nuav_radius = -0.5\n");
    assert_error(&text, "formation.uav_radius", "uav_radius", "positive");
}

#[test]
fn inverted_and_empty_ranges_are_errors() {
    let text = mission_with("").replace("x = [0.0, 100.0]", "x = [100.0, 0.0]");
    assert_error(&text, "bounds.x", "x = [100.0, 0.0]", "inverted");
    // z_min ≥ z_max, both the equal and the inverted case.
    let text = mission_with("").replace("z = [5.0, 15.0]", "z = [10.0, 10.0]");
    assert_error(&text, "bounds.z", "z = [10.0, 10.0]", "empty");
    let text = mission_with("").replace("z = [5.0, 15.0]", "z = [15.0, 5.0]");
    assert_error(&text, "bounds.z", "z = [15.0, 5.0]", "inverted");
    let text = mission_with("[formation]\nsurface_distance = [5.0, 1.0]\n");
    assert_error(
        &text,
        "formation.surface_distance",
        "surface_distance",
        "inverted",
    );
}

#[test]
fn obstacles_outside_the_bounds_are_errors() {
    let text = mission_with(
        "[[obstacles]]\nname = \"far\"\ncenter = [150.0, 50.0]\nradius = 1.0\nheight = 5.0\n",
    );
    assert_error(
        &text,
        "obstacles[0].center",
        "[150.0, 50.0]",
        "outside the bounds",
    );
}

#[test]
fn start_and_goal_must_be_inside_the_bounds() {
    let text = mission_with("").replace("start = [10.0, 10.0, 10.0]", "start = [-5.0, 10.0, 10.0]");
    // On the coordinate that is out (issue 24, item 6: the inspector shows
    // it under that field).
    assert_error(&text, "route.start[0]", "start =", "outside the bounds");
    // Outside the altitude band counts too.
    let text = mission_with("").replace("goal = [90.0, 90.0, 10.0]", "goal = [90.0, 90.0, 30.0]");
    assert_error(&text, "route.goal[2]", "goal =", "altitude band");
}

#[test]
fn a_start_where_the_formation_fits_in_no_heading_is_an_error() {
    // Default triangle, start at (10, 10): a pole of 3 m radius 1 m east of
    // the start is inside the formation whatever its heading.
    let text = mission_with(
        "[[obstacles]]\nname = \"pole\"\ncenter = [11.0, 10.0]\nradius = 3.0\nheight = 20.0\n",
    );
    let d = error_at(&text, "route.start");
    assert!(
        d.message
            .contains("does not fit at the start in any heading")
            && d.message.contains("'pole'"),
        "{d}"
    );
    assert_eq!(d.location.map(|l| l.line), Some(line_of(&text, "start =")));
}

#[test]
fn a_start_the_formation_fits_only_in_some_headings_is_a_warning_naming_one() {
    // A pole 2 m east of the start, inside the old r_F + r_Q disc (2.74 m)
    // but clear of the triangle turned to face it edge-on: only a warning.
    let text = mission_with(
        "[[obstacles]]\nname = \"pole\"\ncenter = [12.0, 10.0]\nradius = 0.5\nheight = 20.0\n",
    );
    let all = diagnostics(&text);
    assert!(all.iter().all(|d| d.severity != Severity::Error), "{all:?}");
    let w = all
        .iter()
        .find(|d| d.path.to_string() == "route.start")
        .unwrap_or_else(|| panic!("no warning at route.start: {all:?}"));
    assert_eq!(w.severity, Severity::Warning);
    assert!(w.message.contains("of 72 headings"), "{w}");
}

#[test]
fn slots_closer_than_two_uav_radii_or_beyond_comm_range_are_errors() {
    let text = mission_with("[formation]\nslots = [[0.0, 0.3, 0.0], [0.0, -0.3, 0.0]]\n");
    let d = error_at(&text, "formation.slots[1]");
    assert!(d.message.contains("closer than 2 r_Q"), "{d}");
    let text = mission_with(
        "[formation]\ncomm_range = 5.0\nslots = [[0.0, 4.0, 0.0], [0.0, -4.0, 0.0]]\n",
    );
    let d = error_at(&text, "formation.slots[1]");
    assert!(d.message.contains("beyond the communication range"), "{d}");
}

#[test]
fn impossible_parameter_combinations_are_errors() {
    let text = mission_with("[theta_pso]\nswarm_size = 0\n");
    assert_error(
        &text,
        "theta_pso.swarm_size",
        "swarm_size = 0",
        "at least one",
    );
    let text = mission_with("[theta_pso]\nwaypoints = 9\nsegments = 5\n");
    assert_error(&text, "theta_pso.segments", "segments = 5", "at least 10");
    let text = mission_with("[flatlo]\naircraft = 1\n");
    assert_error(&text, "flatlo.aircraft", "aircraft = 1", "at least 2");
    let text = mission_with("[flatlo]\nspacing = 1000.0\nturn_radius = 4575.0\n");
    assert_error(&text, "flatlo.turn_radius", "turn_radius", "Algorithm 1");
    let text = mission_with("[fleet]\nmass = 1.0\nmax_thrust = 5.0\n");
    assert_error(&text, "fleet.max_thrust", "max_thrust", "cannot lift");
    let text = mission_with("[fleet]\nagents = 2\ndistances = [[0.0, 1.0], [2.0, 0.0]]\n");
    assert_error(&text, "fleet.distances[0][1]", "distances", "symmetric");
    let text = mission_with(
        "[fleet]\nagents = 2\n[[fleet.pushes]]\nagent = 5\ntime = 1.0\nimpulse = [0.1, 0.0]\n",
    );
    assert_error(&text, "fleet.pushes[0].agent", "agent = 5", "only 2 agents");
    let text = mission_with("[formation]\ncomm_range = 0.5\n");
    assert_error(&text, "formation.comm_range", "comm_range", "2 r_Q");
}

#[test]
fn reconfiguration_choices_must_name_existing_obstacles() {
    let text = mission_with(
        "[reconfiguration]\ndefault_shape = \"auto\"\nshrink_scale = 0.5\ntransition_distance = 5.0\n\
         hold_distance = 1.0\n[[reconfiguration.waypoints]]\nbetween = [\"a\", \"ghost\"]\n\
         [[obstacles]]\nname = \"a\"\ncenter = [50.0, 50.0]\nradius = 1.0\nheight = 5.0\n",
    );
    assert_error(
        &text,
        "reconfiguration.waypoints[0].between",
        "between",
        "'ghost'",
    );
    let text = mission_with("[reconfiguration]\ndefault_shape = \"squash\"\n");
    assert_error(
        &text,
        "reconfiguration.default_shape",
        "squash",
        "unknown variant",
    );
}

#[test]
fn a_shrink_that_brings_uavs_too_close_is_an_error() {
    // Triangle sides ≥ 3.6 m; scale 0.1 → 0.36 m < 2 r_Q = 1 m.
    let text = mission_with(
        "[reconfiguration]\ndefault_shape = \"shrink\"\nshrink_scale = 0.1\n\
         transition_distance = 5.0\nhold_distance = 1.0\n",
    );
    assert_error(
        &text,
        "reconfiguration.shrink_scale",
        "shrink_scale",
        "closer than",
    );
}

#[test]
fn a_tight_formation_is_valid_until_a_shrink_by_the_default_scale_is_asked_for() {
    // A 2 × 2 box 1.6 m apart: the default scale 0.5 would bring its UAVs
    // 0.8 m apart (< 2 r_Q = 1 m), but auto shrinks by a scale of its own,
    // so nothing flies 0.5 and the mission is valid.
    let tight = "[formation]\nslots = [[0.8, 0.8, 0.0], [0.8, -0.8, 0.0], [-0.8, 0.8, 0.0], \
                 [-0.8, -0.8, 0.0]]\n";
    let text = mission_with(tight);
    let shrink_errors = |text: &str| {
        diagnostics(text)
            .into_iter()
            .filter(|d| d.severity == Severity::Error && d.path.to_string().contains("shrink"))
            .count()
    };
    assert_eq!(shrink_errors(&text), 0, "{:?}", diagnostics(&text));
    assert!(parse_str(&text, FILE).is_ok());
    // Shrink as the default shape flies the scale: each pair too close is named.
    let text = mission_with(&format!(
        "{tight}[reconfiguration]\ndefault_shape = \"shrink\"\n"
    ));
    assert_eq!(shrink_errors(&text), 4);
    let d = error_at(&text, "reconfiguration.shrink_scale");
    assert!(d.message.contains("0.800 m apart"), "{d}");
    // So does one IWP set to shrink without a scale of its own; with its own
    // scale (0.7 → 1.12 m apart) it is valid again.
    let iwp = |scale: &str| {
        mission_with(&format!(
            "{tight}[[reconfiguration.waypoints]]\nbetween = [\"a\", \"b\"]\nshape = \"shrink\"\n{scale}\
             [[obstacles]]\nname = \"a\"\ncenter = [50.0, 45.0]\nradius = 1.0\nheight = 5.0\n\
             [[obstacles]]\nname = \"b\"\ncenter = [50.0, 55.0]\nradius = 1.0\nheight = 5.0\n"
        ))
    };
    assert_eq!(shrink_errors(&iwp("")), 4);
    assert_eq!(shrink_errors(&iwp("scale = 0.7\n")), 0);
}

#[test]
fn duplicate_obstacle_names_are_errors() {
    let text = mission_with(
        "[[obstacles]]\nname = \"a\"\ncenter = [50.0, 50.0]\nradius = 1.0\nheight = 5.0\n\
         [[obstacles]]\nname = \"a\"\ncenter = [30.0, 60.0]\nradius = 1.0\nheight = 5.0\n",
    );
    let d = error_at(&text, "obstacles[1].name");
    assert!(d.message.contains("unique"));
    // The second obstacle's name line, not the first's.
    let second = text.match_indices("name = \"a\"").nth(1).map(|(i, _)| i);
    let line = second.map(|i| text[..i].matches('\n').count() + 1);
    assert_eq!(d.location.map(|l| l.line), line);
}

#[test]
fn all_problems_are_collected_in_one_pass() {
    let text = mission_with(
        "[formation]\nground_speed = -3.0\nuav_radius = 0.0\n[theta_pso]\niterations = 0\n\
         [[obstacles]]\nname = \"x\"\ncenter = [500.0, 50.0]\nradius = -2.0\nheight = 5.0\n",
    )
    .replace("y = [0.0, 100.0]", "y = [100.0, 0.0]");
    let errors: Vec<String> = diagnostics(&text)
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.path.to_string())
        .collect();
    for expected in [
        "bounds.y",
        "formation.ground_speed",
        "formation.uav_radius",
        "theta_pso.iterations",
        "obstacles[0].center",
        "obstacles[0].radius",
    ] {
        assert!(
            errors.iter().any(|p| p == expected),
            "missing {expected} in {errors:?}"
        );
    }
}

#[test]
fn warnings_are_kept_apart_and_do_not_block_loading() {
    let text = mission_with("[formation]\nslots = [[1.0, 2.0, 0.0], [1.0, -2.0, 0.0]]\n");
    let checked = check_str(&text, Some(FILE));
    assert!(!checked.report.has_errors(), "{}", checked.report);
    let warnings: Vec<_> = checked.report.warnings().collect();
    assert_eq!(warnings.len(), 1);
    assert_eq!(warnings[0].path.to_string(), "formation.slots");
    assert!(warnings[0].to_string().contains("warning:"));
    let loaded = parse_str(&text, FILE).map_err(|e| e.to_string());
    assert!(loaded.is_ok_and(|l| l.warnings.warning_count() == 1));
}

#[test]
fn an_invalid_mission_does_not_load_and_the_error_lists_every_problem() {
    let text = mission_with("[formation]\nground_speed = -3.0\nuav_radius = 0.0\n");
    let err = parse_str(&text, FILE)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(err.contains("2 error(s)"), "{err}");
    assert!(err.contains("formation.ground_speed") && err.contains("formation.uav_radius"));
}

/// Issue 37 ("every input bounded"): a transition or a hold longer than the
/// operating box's diagonal (141.4 m here) cannot be flown inside it, and a
/// run once grew to 24 GB on `transition_distance = 1e9`: refused by
/// `check`, naming the field and the diagonal; the diagonal itself passes.
#[test]
fn a_transition_or_hold_longer_than_the_site_is_refused() {
    for field in ["transition_distance", "hold_distance"] {
        let text = mission_with(&format!("[reconfiguration]\n{field} = 1e9\n"));
        assert_error(
            &text,
            &format!("reconfiguration.{field}"),
            field,
            "longer than the operating box (its x-y diagonal is 141.4 m)",
        );
        let at_the_limit = mission_with(&format!("[reconfiguration]\n{field} = 141.4\n"));
        let errors: Vec<_> = diagnostics(&at_the_limit)
            .into_iter()
            .filter(|d| d.severity == Severity::Error)
            .collect();
        assert!(errors.is_empty(), "{errors:?}");
    }
}

/// Issue 37, obstacles in three dimensions: a base is an underside, so one
/// at or above the top is refused naming `base`; a deck with room below
/// loads and says nothing.
#[test]
fn a_base_at_or_above_the_top_is_refused() {
    let deck = |base: f64| {
        mission_with(&format!(
            "[[obstacles]]\nname = \"deck\"\ncenter = [50.0, 50.0]\nradius = 3.0\nheight = 10.0\n\
             base = {base:?}\n"
        ))
    };
    let d = error_at(&deck(10.0), "obstacles[0].base");
    assert!(d.message.contains("at or above its top"), "{}", d.message);
    let d = error_at(&deck(-1.0), "obstacles[0].base");
    assert!(d.message.contains("must not be negative"), "{}", d.message);
    assert!(
        diagnostics(&deck(8.0)).iter().all(|d| !d.is_error()),
        "{:?}",
        diagnostics(&deck(8.0))
    );
}

/// Issue 37, eq. 8 on a short obstacle: inspecting needs an altitude of the
/// band level with the obstacle's side. A tower 4 m high under a band
/// from 5 m is refused (the old "below the floor" rule); one standing from
/// 16 to 30 m over a band ending at 15 m is refused naming its heights;
/// one 9.3 m high in a band from 6.6 m is accepted.
#[test]
fn an_inspection_no_altitude_of_the_band_is_level_with_is_refused() {
    let tower = |base: f64, height: f64| {
        mission_with(&format!(
            "[[obstacles]]\nname = \"tower\"\ncenter = [50.0, 30.0]\nradius = 1.0\n\
             height = {height:?}\nbase = {base:?}\ninspect = true\n"
        ))
    };
    error_at(&tower(0.0, 4.0), "obstacles[0].inspect");
    let d = error_at(&tower(16.0, 30.0), "obstacles[0].inspect");
    assert!(d.message.contains("from 16 to 30 m"), "{}", d.message);
    let fine = tower(0.0, 9.3).replace("z = [5.0, 15.0]", "z = [6.6, 18.5]");
    assert!(
        diagnostics(&fine).iter().all(|d| !d.is_error()),
        "{:?}",
        diagnostics(&fine)
    );
}

/// Issue 37, footprints: a polygon that crosses itself, one of no area, one
/// outside the bounds and one of too many vertices are refused at
/// `footprint`; a cylinder without its radius is refused naming `radius`;
/// an L-shaped building loads, its centre and radius its bounding circle.
#[test]
fn a_footprint_must_be_a_simple_polygon_with_an_area_in_the_bounds() {
    let building = |footprint: &str| {
        mission_with(&format!(
            "[[obstacles]]\nname = \"hall\"\nfootprint = {footprint}\nheight = 8.0\n"
        ))
    };
    let message =
        |footprint: &str| error_at(&building(footprint), "obstacles[0].footprint").message;
    let bowtie = message("[[40.0, 40.0], [60.0, 60.0], [60.0, 40.0], [40.0, 60.0]]");
    assert!(bowtie.contains("not a simple polygon"), "{bowtie}");
    let flat = message("[[40.0, 40.0], [50.0, 40.0], [60.0, 40.0]]");
    assert!(
        flat.contains("no area") || flat.contains("not a simple"),
        "{flat}"
    );
    let away = message("[[140.0, 40.0], [160.0, 40.0], [160.0, 60.0]]");
    assert!(away.contains("outside the bounds"), "{away}");
    // A deck across the whole site has every vertex outside the bounds and
    // is inside all the same (a warning that it reaches outside, no error).
    let across = building("[[-5.0, 40.0], [150.0, 40.0], [150.0, 48.0], [-5.0, 48.0]]");
    assert!(
        diagnostics(&across).iter().all(|d| !d.is_error()),
        "{:?}",
        diagnostics(&across)
    );
    let many: Vec<String> = (0..600)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 600.0;
            format!(
                "[{:.4}, {:.4}]",
                50.0 + 10.0 * a.cos(),
                50.0 + 10.0 * a.sin()
            )
        })
        .collect();
    let dense = message(&format!("[{}]", many.join(", ")));
    assert!(dense.contains("600 vertices, more than 500"), "{dense}");
    let cylinder =
        mission_with("[[obstacles]]\nname = \"mast\"\ncenter = [50.0, 50.0]\nheight = 8.0\n");
    let d = error_at(&cylinder, "obstacles[0].radius");
    assert!(d.message.contains("missing"), "{}", d.message);
    let ell = building(
        "[[40.0, 40.0], [60.0, 40.0], [60.0, 50.0], [50.0, 50.0], [50.0, 60.0], [40.0, 60.0]]",
    );
    assert!(
        diagnostics(&ell).iter().all(|d| !d.is_error()),
        "{:?}",
        diagnostics(&ell)
    );
    let loaded = parse_str(&ell, FILE).unwrap_or_else(|e| panic!("{e}"));
    let hall = &loaded.mission.obstacles[0];
    assert_eq!(hall.center, nalgebra::Point2::new(50.0, 50.0));
    assert!((hall.radius - 200f64.sqrt()).abs() < 1e-12);
}

/// Issue 52, item 0: the autopilot's velocity integrals are `[vehicle]`
/// fields; 0 is a PD loop (no integral), a negative one is refused at its
/// line, and so is one no multicopter follows.
#[test]
fn the_velocity_integrals_may_be_zero_never_negative() {
    let zero = mission_with("[vehicle]\nvelocity_integral_xy = 0.0\nvelocity_integral_z = 0.0\n");
    assert!(
        diagnostics(&zero).iter().all(|d| !d.is_error()),
        "{:?}",
        diagnostics(&zero)
    );
    let negative = mission_with("[vehicle]\nvelocity_integral_xy = -0.4\n");
    assert_error(
        &negative,
        "vehicle.velocity_integral_xy",
        "velocity_integral_xy",
        "-0.4",
    );
    let huge = mission_with("[vehicle]\nvelocity_integral_z = 80.0\n");
    assert_error(
        &huge,
        "vehicle.velocity_integral_z",
        "velocity_integral_z",
        "50",
    );
}

/// Issue 53: a pipeline's section's rules live in its own module and are
/// registered with the file's (`mission::SECTION_RULES`); reading a file
/// runs every registered section's, and lists what they find in the order
/// of the file, whichever order the sections are written in.
#[test]
fn the_sections_rules_run_when_a_file_is_read_in_the_order_of_the_file() {
    let theta = "[theta_pso]\nswarm_size = 0\n";
    let fleet = "[fleet]\nagents = 0\n";
    let flatlo = "[flatlo]\naircraft = 1\n";
    for sections in [
        [theta, fleet, flatlo],
        [fleet, flatlo, theta],
        [flatlo, theta, fleet],
    ] {
        let text = mission_with(&sections.concat());
        let paths: Vec<String> = diagnostics(&text)
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .map(|d| d.path.to_string())
            .collect();
        let mut by_line: Vec<(usize, &str)> = [
            ("swarm_size = 0", "theta_pso.swarm_size"),
            ("agents = 0", "fleet.agents"),
            ("aircraft = 1", "flatlo.aircraft"),
        ]
        .into_iter()
        .map(|(needle, path)| (line_of(&text, needle), path))
        .collect();
        by_line.sort();
        let expected: Vec<&str> = by_line.iter().map(|(_, p)| *p).collect();
        assert_eq!(paths, expected, "{text}");
        assert!(parse_str(&text, FILE).is_err(), "{text}");
    }
}
