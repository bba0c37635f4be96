//! Screens of the TUI drawn on ratatui's `TestBackend` and compared with the
//! reviewed snapshots in `tests/all/snapshots/` (insta). A change to a screen
//! shows up as a diff; accept it with `cargo insta review` (or
//! `INSTA_UPDATE=always cargo test --test all tui_snapshots::`) after looking at it.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use nalgebra::Point3;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use skyform::mission::default_mission;
use skyform::tui::app::Focus;
use skyform::tui::fields::Item;
use skyform::tui::fixtures::{app_with_result, app_with_run, bridge_with_oaks, type_into};
use skyform::tui::jobs::{Job, JobMsg, Kind};
use skyform::tui::{Action, App, Document, view};

const WIDTH: u16 = 140;
const HEIGHT: u16 = 42;

fn render(app: &App, now: Instant) -> String {
    render_at(app, now, (WIDTH, HEIGHT))
}

fn render_at(app: &App, now: Instant, (width, height): (u16, u16)) -> String {
    let mut terminal = Terminal::new(TestBackend::new(width, height)).unwrap();
    terminal
        .draw(|frame| {
            view::draw(frame, app, now);
        })
        .unwrap();
    terminal.backend().to_string()
}

fn default_app() -> App {
    App::new(
        Document::new(default_mission().mission, None),
        PathBuf::from("/missions"),
    )
}

#[test]
fn main_screen_on_the_default_mission() {
    let screen = render(&default_app(), Instant::now());
    assert!(screen.contains("(built-in) bridge-inspection.toml"));
    assert!(screen.contains("light pole 4"));
    insta::assert_snapshot!(screen);
}

#[test]
fn inspector_with_a_validation_error() {
    let mut app = default_app();
    app.update(Action::Select(Item::Obstacle(2)));
    app.update(Action::FocusOn(Focus::Inspector));
    // name, kind, centre x, y, lat, lon: radius
    for _ in 0..6 {
        app.update(Action::FieldDown);
    }
    app.update(Action::EditStart(Some('0')));
    app.update(Action::EditCommit);
    let screen = render(&app, Instant::now());
    assert!(screen.contains("must be positive, got 0 m"), "{screen}");
    assert!(screen.contains("1 error(s)"));
    insta::assert_snapshot!(screen);
}

#[test]
fn help_overlay() {
    let mut app = default_app();
    app.update(Action::ToggleHelp);
    let screen = render(&app, Instant::now());
    assert!(screen.contains("Keys · any key closes"));
    insta::assert_snapshot!(screen);
}

#[test]
fn jobs_panel_mid_run() {
    let mut app = default_app();
    let started = Instant::now();
    let m = app.mission().clone();
    app.adopt_job(Job::new(1, Kind::ThetaPso, 7, m.clone(), started));
    app.update(Action::ShowJob);
    app.update(Action::FocusOn(Focus::Jobs));
    let path = vec![m.route.start, Point3::new(60.0, 45.0, 8.0), m.route.goal];
    app.on_job_msg(JobMsg::Stage(1, "planning".into()), started);
    for (k, cost) in [420.0, 300.0, 240.0, 200.0, 190.0, 185.0]
        .into_iter()
        .enumerate()
    {
        let path = (k == 0).then(|| path.clone());
        app.on_job_msg(JobMsg::Iteration { id: 1, cost, path }, started);
    }
    app.on_job_msg(JobMsg::Progress(1, 0.4), started);
    let screen = render(&app, started + Duration::from_millis(1500));
    assert!(screen.contains("40%"), "{screen}");
    assert!(screen.contains("1.5s"));
    assert!(screen.contains("planning"), "{screen}");
    insta::assert_snapshot!(screen);
}

#[test]
fn jobs_panel_with_a_finished_result() {
    let mut app = app_with_result(crate::common::quick(default_mission().mission, 150), 7);
    app.update(Action::FocusOn(Focus::Jobs));
    let started = app.jobs()[0].started;
    let screen = render(&app, started);
    // The verdict, then the CLI's verification table, row by row.
    assert!(
        screen.contains("✓ FEASIBLE · all 12 checks pass"),
        "{screen}"
    );
    // r_Q 0.5 + the safety margin 0.1.
    assert!(
        screen.contains("✓ obstacle clearance worst 0.750 ≥ 0.6"),
        "{screen}"
    );
    // The flight's own rows, against [vehicle]'s default 12 m/s.
    assert!(
        screen.contains("✓ horizontal speed (m/s) worst 4.335 ≤ 12"),
        "{screen}"
    );
    insta::assert_snapshot!(screen);
}

#[test]
fn a_stale_result_is_marked_on_the_map() {
    let mut app = app_with_result(crate::common::quick(default_mission().mission, 20), 7);
    app.update(Action::Select(Item::Goal));
    app.update(Action::FocusOn(Focus::Map));
    app.update(Action::Nudge(-1.0, 0.0));
    let screen = render(&app, app.jobs()[0].started);
    assert!(screen.contains("STALE"), "{screen}");
}

#[test]
fn a_terminal_too_small_gets_a_message() {
    let mut terminal = Terminal::new(TestBackend::new(60, 20)).unwrap();
    terminal
        .draw(|frame| {
            view::draw(frame, &default_app(), Instant::now());
        })
        .unwrap();
    let screen = terminal.backend().to_string();
    assert!(screen.contains("Terminal too small"));
    assert!(screen.contains("60×20: skyform needs at least 80×24."));
}

#[test]
fn the_formation_editor_shows_slots_and_iwps() {
    let mut app = default_app();
    app.update(Action::ShowFormation);
    let screen = render(&app, Instant::now());
    assert!(screen.contains("3 UAVs"));
    assert!(screen.contains("light pole 4 ↔ pier 5"), "{screen}");
    insta::assert_snapshot!(screen);
}

#[test]
fn a_flatlo_result_on_the_kilometre_map_with_its_verification_table() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/missions/flatlo-squadron.toml");
    let m = skyform::mission::load(std::path::Path::new(path))
        .unwrap()
        .mission;
    let mut app = app_with_run(Kind::Flatlo, m, 3, "squadron.toml");
    app.update(Action::FocusOn(Focus::Jobs));
    let screen = render(&app, app.jobs()[0].started);
    assert!(screen.contains("✓ separation kept"), "{screen}");
    assert!(
        screen.contains("1-3"),
        "the closest pair is listed: {screen}"
    );
    assert!(
        screen.contains("✈3"),
        "the aircraft are on the map: {screen}"
    );
    insta::assert_snapshot!(screen);
}

/// Issue 24, item 17: the mission's summary counts each pipeline's
/// vehicles: the FLATLO squadron's 4 aircraft, not the formation's 3 UAVs alone.
#[test]
fn the_mission_summary_counts_every_pipelines_vehicles() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/missions/flatlo-squadron.toml");
    let m = skyform::mission::load(std::path::Path::new(path))
        .unwrap()
        .mission;
    let app = App::new(Document::new(m, None), PathBuf::from("."));
    let screen = render(&app, Instant::now());
    assert!(
        screen.contains("0 obstacles · valid")
            && screen.contains("θ-PSO 3 UAVs · FLATLO 4 aircraft · fleet 3 agents"),
        "{screen}"
    );
}

/// The README's screenshot is what the designer draws (issue 16): the
/// finished-result snapshot above, character for character.
#[test]
fn the_readme_screenshot_is_the_finished_result_snapshot() {
    let root = env!("CARGO_MANIFEST_DIR");
    let snap = std::fs::read_to_string(format!(
        "{root}/tests/all/snapshots/all__tui_snapshots__jobs_panel_with_a_finished_result.snap"
    ))
    .unwrap();
    let screen: Vec<String> = snap
        .lines()
        .filter(|l| l.starts_with('"'))
        .map(|l| l[1..l.len() - 1].replace("\\\"", "\""))
        .collect();
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let start = readme
        .find("```text\n╭ Map")
        .expect("the README shows the designer")
        + 8;
    let shown: Vec<&str> = readme[start..].lines().take(screen.len()).collect();
    assert_eq!(
        shown, screen,
        "refresh the README screenshot from the snapshot"
    );
}

/// The screen's rows, without the quotes the backend's text puts around them.
fn rows_of(screen: &str) -> Vec<String> {
    screen
        .lines()
        .map(|l| l.trim_start_matches('"').trim_end_matches('"').to_owned())
        .collect()
}

/// At 80×24 the bridge's piers are a few cells apart: each name drawn is
/// whole, with a cell free on either side (none written over another).
#[test]
fn map_labels_do_not_cover_each_other_at_80_by_24() {
    let app = default_app();
    let screen = render_at(&app, Instant::now(), (80, 24));
    let map = map_rows(&screen, 80);
    let mut drawn = 0;
    for o in &app.mission().obstacles {
        for row in &map {
            let Some(at) = row.find(&o.name) else {
                continue;
            };
            drawn += 1;
            let before = row[..at].chars().next_back();
            let after = row[at + o.name.len()..].chars().next();
            for c in [before, after].into_iter().flatten() {
                assert!(
                    !c.is_alphanumeric(),
                    "'{}' runs into another label: {row}",
                    o.name
                );
            }
        }
    }
    assert!(drawn >= 8, "most names still fit: {drawn}\n{screen}");
    insta::assert_snapshot!(screen);
}

/// The selected obstacle's name is drawn even where another would have been.
#[test]
fn the_selected_obstacles_label_wins() {
    let mut app = default_app();
    // Beside the inspector, where the map has 36 columns.
    app.update(Action::FocusOn(Focus::Inspector));
    let i = app
        .mission()
        .obstacles
        .iter()
        .position(|o| o.name == "light pole 4")
        .unwrap();
    // The map's columns only (the inspector names the pole too).
    let map = |app: &App| -> String {
        rows_of(&render_at(app, Instant::now(), (80, 24)))
            .iter()
            .map(|r| r.chars().take(36).collect::<String>() + "\n")
            .collect()
    };
    assert!(
        !map(&app).contains("light pole 4"),
        "hidden when not selected"
    );
    app.update(Action::Select(Item::Obstacle(i)));
    let screen = map(&app);
    assert!(screen.contains("light pole 4"), "{screen}");
}

#[test]
fn the_iwp_table_stays_readable_at_80_by_24() {
    let mut app = default_app();
    app.update(Action::ShowFormation);
    // The formation editor focused has the width: the table's five columns.
    let screen = render_at(&app, Instant::now(), (80, 24));
    assert!(screen.contains("IWP between"), "{screen}");
    assert!(screen.contains("light pole 4 ↔ pier 5"), "{screen}");
    insta::assert_snapshot!(screen);
    // Beside the inspector, two lines an IWP.
    app.update(Action::FocusOn(Focus::Inspector));
    let screen = render_at(&app, Instant::now(), (80, 24));
    assert!(screen.contains("◆ light pole 4 ↔ pier 5"), "{screen}");
    assert!(
        screen.contains("gap 1.50 m · alignment (chosen)"),
        "{screen}"
    );
}

/// The row after the one holding `text` continues it: blank up to the
/// column `text` starts at, then words (a hanging indent).
fn assert_hangs(screen: &str, text: &str) {
    let rows: Vec<Vec<char>> = rows_of(screen)
        .iter()
        .map(|r| r.chars().collect())
        .collect();
    let (k, column) = rows
        .iter()
        .enumerate()
        .find_map(|(k, r)| {
            let s: String = r.iter().collect();
            s.find(text).map(|at| (k, s[..at].chars().count()))
        })
        .unwrap_or_else(|| panic!("'{text}' is not on screen:\n{screen}"));
    let next = &rows[k + 1];
    // Where this column of the overlay starts: after its border, or after
    // the other column's text.
    let start = rows[k][..column]
        .iter()
        .rposition(|c| *c == '║')
        .map_or(0, |b| b + 1);
    let start = start.max(column.saturating_sub(18));
    assert!(
        next[start..column].iter().all(|c| *c == ' '),
        "the continuation starts left of the description:\n{}\n{}",
        rows[k].iter().collect::<String>(),
        next.iter().collect::<String>()
    );
    assert_ne!(next[column], ' ', "no continuation under '{text}'");
}

#[test]
fn help_overlay_at_160_by_48_wraps_under_the_descriptions() {
    let mut app = default_app();
    app.update(Action::ToggleHelp);
    let screen = render_at(&app, Instant::now(), (160, 48));
    assert_hangs(&screen, "next / previous item");
    assert_hangs(&screen, "run the distributed fleet");
    insta::assert_snapshot!(screen);
}

#[test]
fn help_overlay_at_80_by_24_wraps_under_the_descriptions() {
    let mut app = default_app();
    app.update(Action::ToggleHelp);
    let screen = render_at(&app, Instant::now(), (80, 24));
    assert_hangs(&screen, "next / previous item");
    insta::assert_snapshot!(screen);
}

#[test]
fn the_open_dialog_filters_and_takes_a_typed_path_at_80_by_24() {
    let mut app = default_app();
    app.update(Action::AddObstacle(None));
    app.update(Action::Open);
    for c in "narrow".chars() {
        app.update(Action::PromptInput(c));
    }
    let screen = render_at(&app, Instant::now(), (80, 24));
    assert!(screen.contains("Path or filter: narrow"), "{screen}");
    assert!(
        screen.contains("▶ (built-in) narrow-passage.toml"),
        "{screen}"
    );
    assert!(
        !screen.contains("║  (built-in) bridge"),
        "filtered out: {screen}"
    );
    insta::assert_snapshot!(screen);

    app.update(Action::PromptClear);
    for c in "elsewhere/mine.toml".chars() {
        app.update(Action::PromptInput(c));
    }
    let screen = render_at(&app, Instant::now(), (80, 24));
    // Issue 24, item 18: a .toml path that does not exist is a new mission.
    assert!(
        screen.contains("elsewhere/mine.toml  (new: Enter starts a new mission there)"),
        "{screen}"
    );
    app.update(Action::PromptClear);
    for c in "elsewhere/mine".chars() {
        app.update(Action::PromptInput(c));
    }
    let screen = render_at(&app, Instant::now(), (80, 24));
    assert!(
        screen.contains("elsewhere/mine  (not listed: Enter opens this path)"),
        "{screen}"
    );

    app.update(Action::PromptClear);
    for c in "narrow".chars() {
        app.update(Action::PromptInput(c));
    }
    app.update(Action::Confirm);
    let screen = render_at(&app, Instant::now(), (80, 24));
    assert!(screen.contains("s save, then open"), "{screen}");
    assert!(screen.contains("y discard and open"), "{screen}");
    assert!(screen.contains("Esc cancel"), "{screen}");
}

/// The bridge with four clusters of three posts near the start: each
/// cluster's gaps are narrower than the formation, and the third post stands
/// where the shape would be held, so every IWP there is unusable.
fn bridge_with_post_clusters() -> skyform::mission::Mission {
    let mut m = default_mission().mission;
    for (k, x) in [20.0, 35.0, 50.0, 65.0].into_iter().enumerate() {
        for (j, (dx, dy)) in [(0.0, 0.0), (2.5, 0.0), (1.25, 2.0)]
            .into_iter()
            .enumerate()
        {
            m.obstacles.push(skyform::mission::Obstacle {
                name: format!("post {}{}", k + 1, ["a", "b", "c"][j]),
                center: nalgebra::Point2::new(x + dx, 8.0 + dy),
                radius: 0.5,
                height: 20.0,
                footprint: Vec::new(),
                base: 0.0,
                overfly: true,
                clearance_above: 0.0,
                kind: Some("post".into()),
                inspect: false,
                stand_off: None,
                description: None,
                wire: None,
                inspect_side: None,
            });
        }
    }
    m
}

/// The rows of the jobs panel below its title, at a screen where it is the
/// rightmost pane.
fn jobs_panel(screen: &str) -> Vec<String> {
    screen
        .lines()
        .skip_while(|l| !l.contains("╭ Jobs"))
        .skip(1)
        .take_while(|l| !l.contains('╰'))
        .map(|l| {
            let row = l.trim_matches('"');
            let row = row.rsplit("││").next().unwrap_or(row);
            row.trim_end_matches('│').trim_end().to_owned()
        })
        .collect()
}

/// Issue 23, item 4 (the designer half): a dozen unusable IWPs read as a
/// count by reason with the nearest named, not a dozen lines.
#[test]
fn the_jobs_panel_groups_unusable_iwps_and_names_the_nearest_at_80_by_24() {
    let mut app = app_with_result(crate::common::quick(bridge_with_post_clusters(), 20), 7);
    app.update(Action::FocusOn(Focus::Jobs));
    let screen = render_at(&app, app.jobs()[0].started, (80, 24));
    let panel = jobs_panel(&screen).join(" ");
    assert!(panel.contains("12 unusable"), "{screen}");
    // The posts in the way named (issue 36: it said '…'), the one nearest
    // the route first.
    assert!(
        panel.contains(
            "12 held through the gap, the alignment would pass within r_Q of 'post 4b' or 11 others"
        ),
        "{screen}"
    );
    // The two nearest the route are named, the other ten are not.
    assert!(
        panel.contains("post 4a ↔ post 4c, post 4b ↔ post 4c, …"),
        "{screen}"
    );
    assert!(!panel.contains("post 1a"), "{screen}");
}

/// Issue 24, item 13: an infeasible result says so and names its first
/// failing check in the panel's first row under the job list, where an
/// 80 × 24 terminal shows it without scrolling.
#[test]
fn the_jobs_panel_puts_the_verdict_and_the_first_failure_on_top_at_80_by_24() {
    use skyform::pipelines::theta_pso::{PlanOptions, plan};
    use skyform::pipelines::{CancelToken, Silent};
    use skyform::tui::jobs::Outcome;

    let mut mission = default_mission().mission;
    mission.theta_pso.iterations = 20;
    let mut outcome = plan(
        &mission,
        7,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap();
    // The flown result as if a UAV had come within 0.31 m of an obstacle:
    // what the panel draws of a failed check, from the outcome's table.
    let clearance = &mut outcome.verification.checks[0];
    assert_eq!(clearance.name, "obstacle clearance");
    clearance.worst = Some(0.31);
    clearance.ok = false;
    outcome.verification.feasible = false;
    let mut app = App::new(
        Document::new(mission.clone(), Some(PathBuf::from("mission.toml"))),
        PathBuf::from("."),
    );
    let started = Instant::now();
    app.adopt_job(Job::new(1, Kind::ThetaPso, 7, mission, started));
    app.on_job_msg(
        JobMsg::Done(1, Ok(Outcome::ThetaPso(Box::new(outcome)))),
        started,
    );
    app.update(Action::FocusOn(Focus::Jobs));
    let screen = render_at(&app, started, (80, 24));
    let panel = jobs_panel(&screen);
    assert!(panel[0].contains("θ-PSO s7"), "{screen}");
    assert!(panel[1].starts_with("✗ INFEASIBLE · "), "{screen}");
    let detail = panel[1..].join(" ");
    assert!(
        detail.starts_with("✗ INFEASIBLE · obstacle clearance worst 0.310 ≥ 0.6 (UAV 3 at t ="),
        "{screen}"
    );
}

/// Issue 24, item 5: the side view draws every inspected obstacle (a tower
/// the path keeps its distance from too), named, and its altitude axis has
/// numbers.
#[test]
fn the_side_view_draws_the_inspected_towers_and_numbers_the_altitudes() {
    let mut m = default_mission().mission;
    m.obstacles.push(skyform::mission::Obstacle {
        name: "far tower".into(),
        center: nalgebra::Point2::new(70.0, 95.0),
        radius: 2.0,
        height: 12.0,
        footprint: Vec::new(),
        base: 0.0,
        overfly: true,
        clearance_above: 0.0,
        kind: Some("tower".into()),
        inspect: true,
        stand_off: None,
        description: None,
        wire: None,
        inspect_side: None,
    });
    let mut app = App::new(Document::new(m, None), PathBuf::from("."));
    app.update(Action::ToggleSideView);
    let screen = render(&app, Instant::now());
    assert!(screen.contains("Side view"), "{screen}");
    assert!(screen.contains("far tower"), "{screen}");
    assert!(screen.contains("pier 6"), "{screen}");
    assert!(screen.contains("z max 15 m"), "{screen}");
    assert!(screen.contains("z min 7 m"), "{screen}");
}

/// Issue 24, item 3: while the mission has an error, the IWP table does
/// not say that no gap is narrower than the formation (it did, for a 7 m
/// gap a 24 m formation meets): it says the IWPs wait for the fix.
#[test]
fn the_iwp_table_does_not_say_none_while_the_mission_has_errors() {
    let mut m = default_mission().mission;
    m.bounds.z = [15.0, 7.0];
    let mut app = App::new(Document::new(m, None), PathBuf::from("."));
    app.update(Action::ShowFormation);
    let screen = render(&app, Instant::now());
    assert!(
        screen.contains("IWPs (eq. 9): not found until the mission's errors are fixed"),
        "{screen}"
    );
    assert!(!screen.contains("no gap narrower"), "{screen}");
}

/// Issue 24, item 16: at 80 × 24 the map's title keeps the result's state
/// whole ("STALE" was cut to "STAL" behind the scale), the scale after it.
#[test]
fn a_stale_result_is_marked_on_the_map_at_80_by_24() {
    let mut app = app_with_result(crate::common::quick(default_mission().mission, 20), 7);
    app.update(Action::Select(Item::Goal));
    app.update(Action::FocusOn(Focus::Map));
    let fresh = render_at(&app, app.jobs()[0].started, (80, 24));
    let title = map_title(&fresh);
    assert!(title.ends_with("  job 1 seed 7: feasible "), "{title}");
    app.update(Action::Nudge(-1.0, 0.0));
    let screen = render_at(&app, app.jobs()[0].started, (80, 24));
    let title = map_title(&screen);
    assert!(
        title.ends_with("  STALE job 1 seed 7: feasible (mission edited) "),
        "{title}"
    );
}

/// The rows of the map's canvas (inside its border: neither its title nor
/// its bottom line), the map being `columns` wide from the left edge.
fn map_rows(screen: &str, columns: usize) -> Vec<String> {
    let rows = rows_of(screen);
    rows[1..rows.len() - 2]
        .iter()
        .map(|r| r.chars().take(columns).collect())
        .collect()
}

/// The bridge among 114 oaks and three masts, quick to plan (the
/// obstacles alone are over live planning's sizes).
fn oak_site() -> skyform::mission::Mission {
    small_swarm(bridge_with_oaks())
}

/// The oaks in eleven rows: 221 obstacles, over live planning's 200.
fn wood_site() -> skyform::mission::Mission {
    small_swarm(skyform::tui::fixtures::bridge_with_oak_rows(11))
}

fn small_swarm(mut m: skyform::mission::Mission) -> skyform::mission::Mission {
    m.theta_pso.swarm_size = 20;
    m.theta_pso.iterations = 10;
    m
}

fn obstacle_named(app: &App, name: &str) -> usize {
    obstacle_named_in(app.mission(), name)
}

/// Issue 36, item 7: a site over live planning's limits (221 obstacles
/// since issue 51 raised them to 200) opens with live planning off and
/// says why (the size over `outcome::interactive`'s limit, with its
/// figure) and that `L` turns it on, on the status line and in the empty
/// jobs panel; `L` does, and a live plan comes in. The 126 of issue 36 are
/// now planned live.
#[test]
fn a_221_obstacle_site_says_why_live_planning_is_off_and_l_turns_it_on() {
    assert!(skyform::outcome::over_live_limits(Kind::ThetaPso, &oak_site()).is_empty());
    let m = wood_site();
    assert_eq!(m.obstacles.len(), 221);
    assert_eq!(
        skyform::outcome::over_live_limits(Kind::ThetaPso, &m),
        ["221 obstacles (live up to 200)"]
    );
    let mut app = App::new(
        Document::new(m, Some(PathBuf::from("site.toml"))),
        PathBuf::from("."),
    );
    app.enable_live();
    assert!(!app.board().live().is_on());
    let why = "live planning off: 221 obstacles (live up to 200); L turns it on";
    let screen = render(&app, Instant::now());
    assert!(
        rows_of(&screen).last().is_some_and(|r| r.contains(why)),
        "{screen}"
    );
    let panel = jobs_panel(&screen).join(" ");
    assert!(
        panel.contains(why),
        "the empty jobs panel says it too: {screen}"
    );
    let small = render_at(&app, Instant::now(), (80, 24));
    assert!(
        rows_of(&small).last().is_some_and(|r| r.contains(why)),
        "{small}"
    );

    app.update(Action::ToggleLive);
    assert!(app.board().live().is_on(), "L turns it on anyway");
    assert_eq!(
        app.status().map(|s| s.text.as_str()),
        Some("live planning on: 221 obstacles (live up to 200), re-plans may take seconds")
    );
    assert!(app.board().live().held_off().is_none());
    assert!(app.settle_live(Duration::from_secs(600)));
    let plan = app.shown().expect("a live plan");
    assert!(skyform::tui::live::Live::owns(plan.id));
    assert!(plan.outcome.as_ref().and_then(|o| o.theta_pso()).is_some());
}

/// Whether `name` is drawn on `map` as a whole name (`oak 1` is not in
/// `oak 11`).
fn drawn(map: &str, name: &str) -> bool {
    map.match_indices(name).any(|(i, _)| {
        map[i + name.len()..]
            .chars()
            .next()
            .is_none_or(|c| !c.is_ascii_digit())
    })
}

/// Issue 36, item 7: on a site of more than 40 obstacles the map leaves
/// most names out, but the selected obstacle's is drawn (it was not).
/// Issue 50: and the names of the obstacles nearest the path (start to
/// goal, with no plan yet) are drawn where they fit; the farthest are not.
#[test]
fn the_selected_obstacles_name_is_drawn_on_a_126_obstacle_site() {
    let mut app = App::new(
        Document::new(oak_site(), Some(PathBuf::from("site.toml"))),
        PathBuf::from("."),
    );
    let m = app.mission().clone();
    let (s, g) = (m.route.start.xy(), m.route.goal.xy());
    let mut by_distance: Vec<(f64, String)> = m
        .obstacles
        .iter()
        .map(|o| {
            let d = o.prism().segment_distance(&s, &g);
            (
                if o.inspect { f64::NEG_INFINITY } else { d },
                o.name.clone(),
            )
        })
        .collect();
    by_distance.sort_by(|a, b| a.0.total_cmp(&b.0));
    let screen = render_at(&app, Instant::now(), (WIDTH, HEIGHT));
    let map = map_rows(&screen, 84).join("\n");
    let nearest_drawn = by_distance[..12]
        .iter()
        .filter(|(_, n)| drawn(&map, n))
        .count();
    assert!(
        nearest_drawn >= 4,
        "{nearest_drawn} of the 12 nearest:\n{screen}"
    );
    for (_, far) in &by_distance[by_distance.len() - 40..] {
        assert!(
            !drawn(&map, far),
            "'{far}' far from the path, drawn:\n{screen}"
        );
    }
    app.update(Action::Select(Item::Obstacle(obstacle_named(
        &app, "mast 2",
    ))));
    // The map is the whole width at 80 × 24, 84 of 140 columns beside
    // the inspector.
    for (size, columns) in [((80, 24), 80), ((WIDTH, HEIGHT), 84)] {
        let screen = render_at(&app, Instant::now(), size);
        let map = map_rows(&screen, columns).join("\n");
        assert!(drawn(&map, "mast 2"), "{screen}");
    }
    insta::assert_snapshot!(render_at(&app, Instant::now(), (80, 24)));
}

/// Issue 36, item 7: `/` finds an obstacle by name on a 126-obstacle site
/// (one mast took 79 presses of `n`): the matches narrow as the name is
/// typed, the first is selected and the map pans to it; Enter keeps it,
/// `n` / `N` step through the matches until Esc, and Esc while typing goes
/// back to what was selected.
#[test]
fn find_by_name_narrows_as_typed_selects_pans_and_steps_with_n() {
    use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    use skyform::tui::input::key_action;
    let key = |c: char| {
        let shift = if c.is_ascii_uppercase() {
            KeyModifiers::SHIFT
        } else {
            KeyModifiers::NONE
        };
        KeyEvent::new(KeyCode::Char(c), shift)
    };
    let mut app = App::new(
        Document::new(oak_site(), Some(PathBuf::from("site.toml"))),
        PathBuf::from("."),
    );
    app.update(Action::Zoom(4.0, None));
    assert_eq!(key_action(&app, key('/')), Some(Action::Find));
    app.update(Action::Find);
    assert!(app.finder().is_typing());
    let (mut counts, mut obstacles) = (Vec::new(), Vec::new());
    for c in "oak 11".chars() {
        let typed = key_action(&app, key(c)).expect("typed into the prompt");
        assert_eq!(typed, Action::FindInput(c));
        app.update(typed);
        let found = app.finder().matches();
        counts.push(found.len());
        obstacles.push(
            found
                .iter()
                .filter(|i| matches!(i, Item::Obstacle(_)))
                .count(),
        );
    }
    // o (every name with an o), oa, oak, "oak " (the oaks, and the IWPs
    // an oak is one side of), oak 1, oak 11.
    assert!(counts.windows(2).all(|w| w[1] <= w[0]), "{counts:?}");
    assert!(counts[0] > counts[1], "{counts:?}");
    assert_eq!(&obstacles[1..], [114, 114, 114, 26, 6], "{obstacles:?}");
    assert_eq!(counts[5], 6, "{counts:?}");
    let oak_11 = obstacle_named(&app, "oak 11");
    assert_eq!(
        app.selected(),
        &Item::Obstacle(oak_11),
        "the name itself first"
    );
    let at = app.mission().obstacles[oak_11].center;
    assert_eq!(
        app.camera().panned_center(),
        Some(at),
        "the map looks at it"
    );
    let screen = render_at(&app, Instant::now(), (80, 24));
    assert!(screen.contains("/oak 11▏"), "{screen}");
    assert!(screen.contains("1 of 6: Obstacle 20 'oak 11'"), "{screen}");
    assert!(screen.contains("6 matches"), "{screen}");
    assert!(screen.contains("▶ Obstacle 20 'oak 11'"), "{screen}");
    assert!(screen.contains("Obstacle 123 'oak 114'"), "{screen}");
    insta::assert_snapshot!(screen);

    app.update(Action::FindKeep);
    assert!(!app.finder().is_typing() && app.finder().is_stepping());
    assert_eq!(
        app.status().map(|s| s.text.as_str()),
        Some(
            "Obstacle 20 'oak 11': 1 of 6 matches for 'oak 11' (n / N next / previous, Esc ends the find)"
        )
    );
    assert_eq!(key_action(&app, key('n')), Some(Action::FindStep(1)));
    assert_eq!(key_action(&app, key('N')), Some(Action::FindStep(-1)));
    app.update(Action::FindStep(1));
    let oak_110 = obstacle_named(&app, "oak 110");
    assert_eq!(app.selected(), &Item::Obstacle(oak_110));
    assert_eq!(
        app.camera().panned_center(),
        Some(app.mission().obstacles[oak_110].center)
    );
    app.update(Action::FindStep(-1));
    app.update(Action::FindStep(-1));
    assert_eq!(
        app.selected(),
        &Item::Obstacle(obstacle_named(&app, "oak 114")),
        "round the ends"
    );
    app.update(Action::Dismiss);
    assert!(!app.finder().is_stepping());
    assert_eq!(key_action(&app, key('n')), Some(Action::SelectNext));
    assert_eq!(key_action(&app, key('N')), Some(Action::RunNewSeed));

    // Esc while typing: back to the selection and the view before.
    let (selected, center) = (app.selected().clone(), app.camera().panned_center());
    app.update(Action::Find);
    for c in "mast".chars() {
        app.update(Action::FindInput(c));
    }
    assert_eq!(
        app.selected(),
        &Item::Obstacle(obstacle_named(&app, "mast 1"))
    );
    app.update(Action::FindCancel);
    assert_eq!(app.selected(), &selected);
    assert_eq!(app.camera().panned_center(), center);
    // A name nothing has: said, and nothing selected.
    app.update(Action::Find);
    for c in "zzz".chars() {
        app.update(Action::FindInput(c));
    }
    app.update(Action::FindKeep);
    assert_eq!(app.selected(), &selected);
    let status = app.status().expect("a message");
    assert!(status.error, "{status:?}");
    assert_eq!(status.text, "no obstacle or IWP has 'zzz' in its name");
}

/// An IWP is found by either obstacle's name and drawn selected on the
/// map, named.
#[test]
fn find_selects_an_iwp_and_the_map_names_it() {
    let mut app = default_app();
    app.update(Action::Find);
    for c in "pier 5".chars() {
        app.update(Action::FindInput(c));
    }
    assert_eq!(app.finder().matches().len(), 2, "the pier, then its IWP");
    app.update(Action::FindStep(1));
    app.update(Action::FindKeep);
    let iwp = Item::Waypoint(["light pole 4".into(), "pier 5".into()]);
    assert_eq!(app.selected(), &iwp);
    let screen = render(&app, Instant::now());
    let map = map_rows(&screen, 84).join("\n");
    assert!(map.contains("light pole 4 ↔ pier 5"), "{screen}");
    assert!(
        screen.contains("Inspector · IWP light pole 4 ↔ pier 5"),
        "{screen}"
    );
}

/// The map's title row, up to its first run of border.
fn map_title(screen: &str) -> String {
    let top = rows_of(screen).into_iter().next().unwrap_or_default();
    let inner = top.trim_start_matches('╭');
    inner.split("──").next().unwrap_or_default().to_owned()
}

/// Issue 36, item 7: a FLATLO result turns STALE after an edit, on the map
/// (whose title names it) and under the verdict in the jobs panel; undo
/// makes it fresh again. At 80 × 24 too.
#[test]
fn a_flatlo_result_turns_stale_after_an_edit() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/missions/flatlo-squadron.toml");
    let m = skyform::mission::load(std::path::Path::new(path))
        .unwrap()
        .mission;
    let mut app = app_with_run(Kind::Flatlo, m, 3, "squadron.toml");
    let started = app.jobs()[0].started;
    let fresh = render(&app, started);
    assert!(
        map_title(&fresh).contains("job 1 FLATLO seed 3: pass"),
        "{fresh}"
    );
    assert!(!fresh.contains("STALE"), "{fresh}");
    app.update(Action::Select(Item::Section(
        skyform::pipelines::Kind::Flatlo,
    )));
    type_into(&mut app, "airspeed (m/s)", "35");
    app.update(Action::FocusOn(Focus::Jobs));
    let stale = render(&app, started);
    assert!(
        map_title(&stale).contains("STALE job 1 FLATLO seed 3: pass (mission edited)"),
        "{stale}"
    );
    let panel = jobs_panel(&stale);
    assert!(panel[1].contains("✓ separation kept"), "{stale}");
    assert!(
        panel[2].contains("STALE: the mission changed since this run"),
        "{stale}"
    );
    app.update(Action::FocusOn(Focus::Map));
    let small = render_at(&app, started, (80, 24));
    assert!(map_title(&small).contains("STALE job 1 "), "{small}");
    insta::assert_snapshot!(small);
    app.update(Action::Undo);
    assert!(!render(&app, started).contains("STALE"));
}

/// The fleet's result turns STALE after an edit, as the others do.
#[test]
fn a_fleet_result_turns_stale_after_an_edit() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/missions/fleet-triangle.toml");
    let mut m = skyform::mission::load(std::path::Path::new(path))
        .unwrap()
        .mission;
    m.fleet.duration = Some(6.0);
    let mut app = skyform::tui::fixtures::app_with_run(Kind::Fleet, m, 1, "fleet.toml");
    let started = app.jobs()[0].started;
    let fresh = map_title(&render(&app, started));
    assert!(fresh.contains("job 1 fleet seed 1: "), "{fresh}");
    assert!(!fresh.contains("STALE"), "{fresh}");
    app.update(Action::Select(Item::Point(
        skyform::pipelines::points::PointRef {
            pipeline: skyform::pipelines::Kind::Fleet,
            kind: 0,
            index: 0,
        },
    )));
    app.update(Action::FocusOn(Focus::Map));
    app.update(Action::Nudge(1.0, 0.0));
    app.update(Action::FocusOn(Focus::Jobs));
    let screen = render(&app, started);
    assert!(map_title(&screen).contains("STALE job 1 fleet"), "{screen}");
    let panel = jobs_panel(&screen);
    assert!(
        panel[2].contains("STALE: the mission changed since this run"),
        "{screen}"
    );
}

/// Issue 36, item 7: at 80 × 24 the map has the width while it has the
/// focus (78 columns, not 34: the inspector and the jobs fold away, its
/// bottom line names the selection and says Tab); Tab brings them back
/// beside a narrower map. No title is cut mid-word: the map's drops its
/// step, then its scale, then shortens the result; a job's row keeps its
/// verdict whole.
#[test]
fn at_80_by_24_the_map_has_the_width_and_no_title_is_cut_mid_word() {
    let mut app = app_with_result(crate::common::quick(default_mission().mission, 20), 7);
    app.update(Action::FocusOn(Focus::Map));
    let started = app.jobs()[0].started;
    let screen = render_at(&app, started, (80, 24));
    let rows = rows_of(&screen);
    assert!(
        !screen.contains("Inspector") && !screen.contains("Jobs"),
        "{screen}"
    );
    assert!(
        rows[0].starts_with("╭ Map · ") && rows[0].ends_with('╮'),
        "{screen}"
    );
    let title = map_title(&screen);
    let scale: f64 = title
        .split("· ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no scale in {title:?}"));
    // 4.4 m/cell on 34 columns beside the inspector before.
    assert!(scale < 3.0, "{scale} m/cell: {title}");
    assert_eq!(
        title,
        " Map · 2.6 m/cell · step 1 m  job 1 seed 7: feasible "
    );
    assert!(
        rows[22].contains("Mission · Tab: inspector and jobs"),
        "{screen}"
    );
    insta::assert_snapshot!(screen);

    // Tab: the inspector and the jobs beside a 36-column map, whose title
    // drops the step and the scale, whole.
    app.update(Action::FocusNext);
    let screen = render_at(&app, started, (80, 24));
    assert!(screen.contains("Inspector · Mission"), "{screen}");
    assert_eq!(map_title(&screen), " Map  job 1 seed 7: feasible ");
    app.update(Action::FocusNext);
    let screen = render_at(&app, started, (80, 24));
    let row = jobs_panel(&screen).into_iter().next().unwrap_or_default();
    assert!(
        row.starts_with("▶◉ 1 θ-PSO s7") && row.ends_with("feasible"),
        "{screen}"
    );
    insta::assert_snapshot!("at_80_by_24_the_jobs_focus_unfolds_the_panels", screen);

    // A stale result on the narrow map: STALE and the job, whole.
    app.update(Action::Select(Item::Goal));
    app.update(Action::Nudge(-1.0, 0.0));
    let screen = render_at(&app, started, (80, 24));
    assert_eq!(map_title(&screen), " Map  STALE job 1 ");
}

/// Issue 36, item 7: `s` on an IWP says the shape and that the route must
/// now cross there (the choice it writes in `reconfiguration.waypoints`
/// makes the IWP a stop of the route stage: `route::find`'s requested
/// crossings); Space off says the route need not; Del gives the route its
/// choice back.
#[test]
fn the_shape_and_the_crossing_the_route_must_make_are_said() {
    let mut m = default_mission().mission;
    m.reconfiguration.waypoints.clear();
    let mut app = App::new(Document::new(m, None), PathBuf::from("."));
    app.update(Action::ShowFormation);
    let iwp = Item::Waypoint(["light pole 4".into(), "pier 5".into()]);
    app.update(Action::Select(iwp.clone()));
    let said = |app: &App| app.status().map(|s| s.text.clone()).unwrap_or_default();
    let chosen = |app: &App| {
        app.mission()
            .reconfiguration
            .choice("light pole 4", "pier 5")
            .cloned()
    };
    assert_eq!(chosen(&app), None, "no choice yet: the route may go round");
    app.update(Action::CycleShape);
    assert_eq!(
        said(&app),
        "alignment (chosen): the route must cross between 'light pole 4' and 'pier 5'"
    );
    assert!(
        chosen(&app).is_some_and(|c| c.enabled),
        "a choice in the file"
    );
    // Rotation keeps the formation's width: no shape passes, and it says why.
    app.update(Action::CycleShape);
    assert!(
        said(&app).starts_with(
            "rotation (chosen): no shape passes between 'light pole 4' and 'pier 5': "
        ),
        "{}",
        said(&app)
    );
    app.update(Action::CycleShape);
    assert!(
        said(&app).starts_with("shrink (chosen): "),
        "{}",
        said(&app)
    );
    app.update(Action::CycleShape);
    assert!(
        said(&app).starts_with("auto → ")
            && said(&app).ends_with(": the route must cross between 'light pole 4' and 'pier 5'"),
        "auto, but still a choice: {}",
        said(&app)
    );
    app.update(Action::ToggleWaypoint);
    assert!(
        said(&app).starts_with("IWP off (")
            && said(&app).contains("the route need not cross between 'light pole 4' and 'pier 5'"),
        "{}",
        said(&app)
    );
    app.update(Action::Delete);
    assert_eq!(chosen(&app), None);
    assert!(said(&app).contains("the route may cross between 'light pole 4' and 'pier 5' or not"));
}

/// Issue 39, item 4: `G` flies the shown plan in the mission's `[flight]`
/// air as a background job; its verdict and its worst place stand under the
/// plan's verdict, and the map draws each UAV's p99 envelope and marks the
/// worst place, at 80 × 24 and at 140 × 42.
#[test]
fn the_flight_check_shows_its_verdict_the_worst_place_and_the_envelope() {
    let mut m = default_mission().mission;
    m.flight.flights = 40;
    let dir = tempfile::tempdir().expect("tempdir");
    let mut app = App::new(Document::new(m, None), dir.path().to_path_buf());
    app.update(Action::Run(Kind::ThetaPso));
    assert!(app.wait_for_jobs(Duration::from_secs(120)));
    app.update(Action::FlightCheck);
    let job = &app.jobs()[0];
    assert!(
        matches!(
            job.flight,
            Some(skyform::tui::jobs::FlightCheck::Running { .. })
        ),
        "{:?}",
        job.flight
    );
    assert!(app.wait_for_jobs(Duration::from_secs(120)));
    let job = &app.jobs()[0];
    let Some(skyform::tui::jobs::FlightCheck::Done(r)) = &job.flight else {
        panic!("{:?}", job.flight);
    };
    assert_eq!(r.envelope.len(), 3, "one envelope a UAV");
    assert!(
        r.envelope
            .iter()
            .all(|e| e.len() > 100 && e.iter().all(|(_, radius)| radius.is_finite()))
    );
    let (worst, _) = r.worst.as_ref().expect("a worst place");
    assert!(worst.starts_with("flight "), "{worst}");
    app.update(Action::FocusOn(Focus::Jobs));
    for size in [(80, 24), (140, 42)] {
        let screen = render_at(&app, Instant::now(), size);
        assert!(screen.contains("flight check:"), "{size:?}\n{screen}");
        assert!(screen.contains("worst"), "{size:?}\n{screen}");
    }
    // Wide enough, the map marks the worst place itself (its ✕ may sit
    // under an IWP's ◆: the word stays), and so does the side view.
    let screen = render_at(&app, Instant::now(), (140, 42));
    assert!(screen.matches("worst").count() >= 2, "{screen}");
    app.update(Action::ToggleSideView);
    let side = render_at(&app, Instant::now(), (140, 42));
    assert!(
        side.contains("Side view") && side.contains("✕ worst"),
        "{side}"
    );
}

/// Issue 50: the side view of a plan under the viaduct's deck draws the
/// deck over the few metres the path passes under it (not over 126 m of
/// it), with the piers the path passes between and the wire it flies
/// under, each named.
#[test]
fn the_side_view_under_a_deck_draws_it_where_the_path_passes_under() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/missions/viaduct-inspection.toml"
    );
    let m = skyform::mission::load(std::path::Path::new(path))
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    let mut app = app_with_run(Kind::ThetaPso, m, 0, "viaduct-inspection.toml");
    app.update(Action::ToggleSideView);
    let screen = render_at(&app, Instant::now(), (WIDTH, HEIGHT));
    for name in ["deck", "pier 3", "pier 4", "11 kV line"] {
        assert!(screen.contains(name), "'{name}' not drawn:\n{screen}");
    }
    // The deck's bar: the row it is named on holds its name once, and the
    // bar under it spans a few columns of the 80 the path fills.
    let row = screen
        .lines()
        .find(|l| l.contains("deck"))
        .unwrap_or_else(|| panic!("{screen}"));
    assert_eq!(row.matches("deck").count(), 1, "{row}");
    insta::assert_snapshot!(screen);
}

/// Issue 51: live planning is on by default for a site of 200 obstacles and
/// twelve UAVs (the orchard of `sites::orchard`); a tree nudged 1 m is
/// re-planned from the plan before (warm), and the plan passes
/// verification. Its time is `cargo bench --bench live -- orchard`'s.
#[test]
fn an_orchard_of_200_trees_and_twelve_uavs_is_planned_live() {
    let m = crate::sites::orchard::orchard(1);
    assert_eq!((m.obstacles.len(), m.formation.slots.len()), (200, 12));
    assert!(skyform::outcome::over_live_limits(Kind::ThetaPso, &m).is_empty());
    let tree = obstacle_named_in(&m, "tree 5.10");
    let mut app = App::new(Document::new(m, None), PathBuf::from("."));
    app.enable_live();
    assert!(app.board().live().is_on(), "live planning is on by default");
    assert!(app.settle_live(Duration::from_secs(600)));
    app.update(Action::Select(Item::Obstacle(tree)));
    app.update(Action::Nudge(1.0, 0.0));
    assert!(app.settle_live(Duration::from_secs(600)));
    let job = app
        .board()
        .live()
        .latest()
        .expect("a live plan of the nudge");
    assert_eq!(
        job.mission.obstacles[tree].center,
        app.mission().obstacles[tree].center
    );
    let outcome = job.outcome.as_ref().expect("the plan came in");
    let plan = outcome.theta_pso().expect("a θ-PSO plan");
    assert!(plan.warm_start.is_some(), "re-planned warm");
    assert!(outcome.ok(), "{}", outcome.headline());
}

fn obstacle_named_in(m: &skyform::mission::Mission, name: &str) -> usize {
    m.obstacles
        .iter()
        .position(|o| o.name == name)
        .unwrap_or_else(|| panic!("no obstacle '{name}'"))
}

/// Issue 51: a run the route search refuses draws why on the map: the
/// passage that closes the way, across its gap with its width and the
/// width it needs, and the route that was tried up to it.
#[test]
fn a_refused_run_draws_the_passage_that_closes_the_way_and_the_route_tried() {
    let m = crate::passages::bays(2.0 * (0.33 + 0.1) - 0.05, 0.0, 100.0);
    let dir = tempfile::tempdir().expect("tempdir");
    let mut app = App::new(Document::new(m, None), dir.path().to_path_buf());
    app.update(Action::Run(Kind::ThetaPso));
    assert!(app.wait_for_jobs(Duration::from_secs(120)));
    let job = app.shown().expect("the run is shown");
    assert!(
        matches!(
            &job.state,
            skyform::tui::jobs::JobState::Failed(skyform::tui::jobs::JobError::Pipeline(
                skyform::pipelines::PipelineError::NoRoute(no)
            )) if no.route.len() >= 2 && !no.passages.is_empty()
        ),
        "{:?}",
        job.state
    );
    let screen = render_at(&app, Instant::now(), (140, 42));
    assert!(screen.contains("✕ 0.81 m < 0.86 m"), "{screen}");
    // Without the refusal (the same site, the aisle open) nothing is marked.
    let open = crate::passages::bays(2.0 * (0.33 + 0.1) + 0.5, 0.0, 100.0);
    let mut app = App::new(Document::new(open, None), dir.path().to_path_buf());
    app.update(Action::Run(Kind::ThetaPso));
    assert!(app.wait_for_jobs(Duration::from_secs(120)));
    let screen = render_at(&app, Instant::now(), (140, 42));
    assert!(!screen.contains('✕'), "{screen}");
}
