//! Screens of the TUI drawn on ratatui's `TestBackend` and compared with the
//! reviewed snapshots in `tests/snapshots/` (insta). A change to a screen
//! shows up as a diff; accept it with `cargo insta review` (or
//! `INSTA_UPDATE=always cargo test --test tui_snapshots`) after looking at it.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use nalgebra::Point3;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use skyform::mission::default_mission;
use skyform::tui::app::Focus;
use skyform::tui::fields::Item;
use skyform::tui::fixtures::{app_with_flatlo_result, app_with_result};
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
    let mut app = app_with_result(default_mission().mission, 7, 150);
    app.update(Action::FocusOn(Focus::Jobs));
    let started = app.jobs()[0].started;
    let screen = render(&app, started);
    assert!(screen.contains("feasible"), "{screen}");
    assert!(screen.contains("all checks pass"), "{screen}");
    insta::assert_snapshot!(screen);
}

#[test]
fn a_stale_result_is_marked_on_the_map() {
    let mut app = app_with_result(default_mission().mission, 7, 20);
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
    let mut app = app_with_flatlo_result(m, 3);
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

/// The README's screenshot is what the designer draws (issue 16): the
/// finished-result snapshot above, character for character.
#[test]
fn the_readme_screenshot_is_the_finished_result_snapshot() {
    let root = env!("CARGO_MANIFEST_DIR");
    let snap = std::fs::read_to_string(format!(
        "{root}/tests/snapshots/tui_snapshots__jobs_panel_with_a_finished_result.snap"
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

/// At 80×24 the bridge's piers are a cell or two apart: each name drawn is
/// whole, with a cell free on either side (none written over another).
#[test]
fn map_labels_do_not_cover_each_other_at_80_by_24() {
    let app = default_app();
    let screen = render_at(&app, Instant::now(), (80, 24));
    let map: Vec<String> = rows_of(&screen)
        .iter()
        .map(|r| r.chars().take(36).collect())
        .collect();
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
    let screen = render_at(&app, Instant::now(), (80, 24));
    assert!(screen.contains("◆ light pole 4 ↔ pier 5"), "{screen}");
    assert!(
        screen.contains("gap 1.50 m · alignment (chosen)"),
        "{screen}"
    );
    insta::assert_snapshot!(screen);
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
    assert!(
        screen.contains("elsewhere/mine.toml  (not listed: Enter opens this path)"),
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
