//! The TUI's state machine, driven by actions as the keys would drive it:
//! edits, undo/redo, the modified flag, stale results, saving and quitting.

use std::path::PathBuf;
use std::time::Duration;

use nalgebra::Point2;
use skyform::mission::{self, Mission, Severity, default_mission};
use skyform::tui::app::{Focus, Overlay};
use skyform::tui::fields::Item;
use skyform::tui::fixtures::{app_with_result, type_into};
use skyform::tui::jobs::JobState;
use skyform::tui::{Action, App, Document};

fn app_in(dir: &std::path::Path) -> App {
    let path = dir.join("bridge.toml");
    let m = default_mission().mission;
    mission::save(&m, &path).unwrap();
    App::new(Document::new(m, Some(path)), dir.to_path_buf())
}

#[test]
fn add_move_edit_then_undo_three_times_and_redo() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let original = app.mission().clone();
    let n = original.obstacles.len();

    app.update(Action::AddObstacle(Some(Point2::new(30.0, 40.0))));
    assert_eq!(app.selected(), &Item::Obstacle(n));
    app.update(Action::FocusOn(Focus::Map));
    app.update(Action::Nudge(1.0, 0.0)); // one 1 m step east
    type_into(&mut app, "radius (m)", "3.5");

    let added = &app.mission().obstacles[n];
    assert_eq!(added.center, Point2::new(31.0, 40.0));
    assert_eq!(added.radius, 3.5);
    assert!(app.doc().is_modified());

    for _ in 0..3 {
        app.update(Action::Undo);
    }
    assert_eq!(
        app.mission(),
        &original,
        "three undos take back add, move and edit"
    );
    assert!(
        !app.doc().is_modified(),
        "back at the saved mission: not modified"
    );

    app.update(Action::Redo);
    let mut expected = original.clone();
    expected.obstacles.push(skyform::mission::Obstacle {
        center: Point2::new(30.0, 40.0),
        ..app.mission().obstacles[n].clone()
    });
    assert_eq!(
        app.mission(),
        &expected,
        "redo brings the obstacle back where it was added"
    );
    assert_eq!(app.mission().obstacles[n].radius, 1.0);
    assert!(app.doc().is_modified());
}

#[test]
fn a_drag_is_one_undo_step() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let before = app.mission().clone();
    let start = before.obstacles[0].center;
    app.update(Action::DragStart(Item::Obstacle(0), start));
    for k in 1..=10 {
        app.update(Action::DragTo(
            start + nalgebra::Vector2::new(k as f64, 0.5 * k as f64),
        ));
    }
    app.update(Action::DragEnd);
    assert_eq!(
        app.mission().obstacles[0].center,
        start + nalgebra::Vector2::new(10.0, 5.0)
    );
    app.update(Action::Undo);
    assert_eq!(app.mission(), &before);
    app.update(Action::Undo);
    assert_eq!(
        app.status().map(|s| s.text.as_str()),
        Some("nothing to undo")
    );
}

#[test]
fn a_click_without_moving_records_no_undo_step() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let at = app.mission().route.goal.xy();
    app.update(Action::DragStart(Item::Goal, at));
    app.update(Action::DragEnd);
    assert_eq!(app.selected(), &Item::Goal);
    assert!(!app.doc().can_undo());
    assert!(!app.doc().is_modified());
}

#[test]
fn validation_follows_the_typing() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Select(Item::Obstacle(0)));
    app.update(Action::FocusOn(Focus::Inspector));
    // name, kind, centre x, y, lat, lon: radius
    for _ in 0..6 {
        app.update(Action::FieldDown);
    }
    assert_eq!(app.fields()[app.editor().field()].label(), "radius (m)");
    app.update(Action::EditStart(Some('-')));
    let problem = app.editor().editing().unwrap().problem.clone();
    assert_eq!(
        problem,
        Some((Severity::Error, "'-' is not a number".into()))
    );
    app.update(Action::EditInput('2'));
    let (severity, message) = app.editor().editing().unwrap().problem.clone().unwrap();
    assert_eq!(severity, Severity::Error);
    assert!(message.contains("must be positive"), "{message}");
    app.update(Action::EditBackspace);
    app.update(Action::EditBackspace);
    app.update(Action::EditInput('2'));
    assert_eq!(app.editor().editing().unwrap().problem, None, "2 m is fine");
    // Nothing was applied while typing.
    assert_eq!(app.mission(), &default_mission().mission);
    app.update(Action::EditCancel);
    assert!(app.editor().editing().is_none());
    assert!(!app.doc().is_modified());
}

#[test]
fn an_edit_after_a_run_marks_the_result_stale_and_undo_makes_it_fresh() {
    let app = &mut app_with_result(crate::common::quick(default_mission().mission, 20), 7);
    let job = app.shown().expect("a shown result");
    assert!(!app.is_stale(job));
    app.update(Action::Select(Item::Goal));
    app.update(Action::FocusOn(Focus::Map));
    app.update(Action::Nudge(0.0, 1.0));
    assert!(app.is_stale(app.shown().unwrap()));
    app.update(Action::Undo);
    assert!(!app.is_stale(app.shown().unwrap()));
}

#[test]
fn a_run_in_the_background_gives_the_same_result_as_the_pipeline() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    assert_eq!(app.jobs().len(), 1);
    assert!(app.wait_for_jobs(Duration::from_secs(60)));
    let job = &app.jobs()[0];
    assert_eq!(job.state, JobState::Done);
    assert!(job.outcome.as_ref().is_some_and(|o| o.ok()));
    let direct = skyform::pipelines::theta_pso::plan(
        app.mission(),
        app.mission().seed,
        Default::default(),
        &mut skyform::pipelines::Silent,
        &Default::default(),
    )
    .unwrap();
    let outcome = job.outcome.as_ref().and_then(|o| o.theta_pso()).unwrap();
    assert_eq!(outcome.cost, direct.cost);
    assert_eq!(job.convergence, direct.convergence);
    assert_eq!(app.board().shown_id(), Some(job.id));

    app.update(Action::RunNewSeed);
    assert!(app.wait_for_jobs(Duration::from_secs(60)));
    assert_eq!(app.jobs()[1].seed, app.mission().seed + 1);
}

#[test]
fn cancel_keeps_the_best_so_far() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    type_into(&mut app, "seed", "3"); // any edit; then a long run
    app.update(Action::Select(Item::Section(
        skyform::pipelines::Kind::ThetaPso,
    )));
    // Long, but inside the budget (100 × 40,000 × 4 runs = 1.6e7 evaluations).
    type_into(&mut app, "iterations", "40000");
    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    // Let it get going, then cancel.
    while app.jobs()[0].convergence.len() < 3 {
        let msg = app
            .job_messages()
            .recv_timeout(Duration::from_secs(30))
            .unwrap();
        app.on_job_msg(msg, std::time::Instant::now());
    }
    app.update(Action::Cancel);
    assert!(app.wait_for_jobs(Duration::from_secs(30)));
    let job = &app.jobs()[0];
    assert_eq!(job.state, JobState::Cancelled);
    let outcome = job.outcome.as_ref().and_then(|o| o.theta_pso()).unwrap();
    assert!(outcome.iterations < 40_000);
    assert!(!outcome.trajectories.is_empty());
}

#[test]
fn an_invalid_mission_is_not_run() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Select(Item::Obstacle(0)));
    type_into(&mut app, "radius (m)", "0");
    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    assert!(app.jobs().is_empty());
    let status = app.status().cloned().unwrap();
    assert!(status.error);
    assert!(
        status.text.contains("obstacles[0].radius"),
        "{}",
        status.text
    );
}

/// Issue 12: a mission over a run's budget is refused before any job
/// starts, with the field and the predicted figure in the status line.
#[test]
fn a_run_over_its_budget_is_not_started() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Select(Item::Formation));
    type_into(&mut app, "ground speed (m/s)", "0.000001");
    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    assert!(app.jobs().is_empty());
    let status = app.status().cloned().unwrap();
    assert!(status.error);
    assert!(
        status.text.contains("formation.ground_speed")
            && status.text.contains("1.2e8 s")
            && status.text.contains("limit 1e7"),
        "{}",
        status.text
    );
    type_into(&mut app, "ground speed (m/s)", "3");
    app.update(Action::Select(Item::Section(
        skyform::pipelines::Kind::ThetaPso,
    )));
    type_into(&mut app, "swarm size", "100000000");
    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    assert!(app.jobs().is_empty());
    let status = app.status().cloned().unwrap();
    assert!(
        status.text.contains("theta_pso.swarm_size"),
        "{}",
        status.text
    );
}

#[test]
fn save_writes_the_file_and_clears_the_modified_flag() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::AddObstacle(Some(Point2::new(12.0, 34.0))));
    assert!(app.doc().is_modified());
    app.update(Action::Save);
    assert!(!app.doc().is_modified());
    let saved = mission::load(&dir.path().join("bridge.toml"))
        .unwrap()
        .mission;
    assert_eq!(&saved, app.mission());
    assert_eq!(
        saved.obstacles.last().unwrap().center,
        Point2::new(12.0, 34.0)
    );
    // No temporary file left behind.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

#[test]
fn an_invalid_mission_is_saved_only_after_a_confirmation_naming_the_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Select(Item::Obstacle(2)));
    type_into(&mut app, "radius (m)", "-1");
    app.update(Action::Save);
    match app.overlay() {
        Some(Overlay::SaveInvalid { errors, .. }) => {
            assert!(
                errors
                    .iter()
                    .any(|e| e.starts_with("obstacles[2].radius: must be positive")),
                "{errors:?}"
            )
        }
        other => panic!("expected the confirmation, got {other:?}"),
    }
    let path = dir.path().join("bridge.toml");
    assert_eq!(
        mission::load(&path).unwrap().mission,
        default_mission().mission,
        "not saved yet"
    );
    app.update(Action::Confirm);
    assert!(app.overlay().is_none());
    assert!(!app.doc().is_modified());
    let text = std::fs::read_to_string(&path).unwrap();
    let checked = mission::check_str(&text, None);
    assert_eq!(checked.mission.unwrap().obstacles[2].radius, -1.0);
}

#[test]
fn the_built_in_mission_is_saved_through_save_as() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = App::new(
        Document::new(default_mission().mission, None),
        dir.path().to_path_buf(),
    );
    app.update(Action::Save);
    assert!(matches!(app.overlay(), Some(Overlay::SaveAs { .. })));
    for _ in 0..60 {
        app.update(Action::PromptBackspace);
    }
    for c in "mine.toml".chars() {
        app.update(Action::PromptInput(c));
    }
    app.update(Action::Confirm);
    assert_eq!(
        app.doc().path(),
        Some(dir.path().join("mine.toml").as_path())
    );
    assert_eq!(
        mission::load(&dir.path().join("mine.toml"))
            .unwrap()
            .mission,
        default_mission().mission
    );
}

#[test]
fn quitting_with_unsaved_changes_asks_first() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Quit);
    assert!(app.should_quit(), "nothing to lose: quits at once");

    let mut app = app_in(dir.path());
    app.update(Action::AddObstacle(None));
    app.update(Action::Quit);
    assert!(!app.should_quit());
    assert_eq!(app.overlay(), Some(&Overlay::Quit));
    app.update(Action::Dismiss);
    assert!(app.overlay().is_none() && !app.should_quit());
    // Save and quit.
    app.update(Action::Quit);
    app.update(Action::Save);
    assert!(app.should_quit());
    assert_eq!(
        mission::load(&dir.path().join("bridge.toml"))
            .unwrap()
            .mission,
        *app.mission()
    );
}

#[test]
fn open_lists_the_missions_and_refuses_to_drop_changes_silently() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut app = App::new(Document::new(default_mission().mission, None), root.clone());
    app.update(Action::AddObstacle(None));
    app.update(Action::Open);
    let Some(Overlay::Open { entries, .. }) = app.overlay().cloned() else {
        panic!("no picker");
    };
    let narrow = entries
        .iter()
        .position(|e| e.label().ends_with("missions/narrow-passage.toml"))
        .expect("missions/ is listed");
    app.update(Action::PickerMove(narrow as i32));
    app.update(Action::Confirm);
    assert!(
        matches!(app.overlay(), Some(Overlay::Discard(_))),
        "asks before dropping the edit"
    );
    app.update(Action::Confirm);
    let expected: Mission = mission::load(&root.join("missions/narrow-passage.toml"))
        .unwrap()
        .mission;
    assert_eq!(app.mission(), &expected);
    assert!(!app.doc().is_modified());
}

#[test]
fn presets_and_slot_edits_change_the_formation() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::ShowFormation);
    assert_eq!(app.selected(), &Item::Formation);
    app.update(Action::CyclePreset); // triangle → line abreast
    let slots = &app.mission().formation.slots;
    assert_eq!(slots.len(), 3);
    assert!(slots.iter().all(|s| s.x == 0.0), "line abreast: {slots:?}");
    app.update(Action::AddSlot);
    assert_eq!(app.mission().formation.slots.len(), 4);
    assert_eq!(app.selected(), &Item::Slot(3));
    app.update(Action::Delete);
    assert_eq!(app.mission().formation.slots.len(), 3);

    // The bridge's IWP: cycle its shape and switch it off.
    app.update(Action::Select(Item::Waypoint([
        "light pole 4".into(),
        "pier 5".into(),
    ])));
    let before = app.iwps()[0].choice;
    app.update(Action::CycleShape);
    assert_ne!(app.iwps()[0].choice, before);
    app.update(Action::ToggleWaypoint);
    assert!(!app.iwps()[0].enabled);
}

mod mouse {
    use super::*;
    use ratatui::crossterm::event::{KeyModifiers, MouseButton, MouseEvent, MouseEventKind};
    use ratatui::layout::Rect;
    use skyform::tui::input::mouse_action;
    use skyform::tui::view::map::Viewport;
    use skyform::tui::view::{Drawn, layout};

    const SCREEN: Rect = Rect::new(0, 0, 140, 42);

    fn event(kind: MouseEventKind, (column, row): (u16, u16)) -> MouseEvent {
        MouseEvent {
            kind,
            column,
            row,
            modifiers: KeyModifiers::NONE,
        }
    }

    /// What a frame of `app` on `SCREEN` shows where.
    fn drawn(app: &App) -> Drawn {
        Drawn::of(app, SCREEN).expect("the screen is large enough")
    }

    /// Issue 13: a click is read against the frame the user clicked on. The
    /// view zooms (a wheel turn, say) before the next frame is drawn; a
    /// click on the obstacle as it was drawn still picks it.
    #[test]
    fn a_click_is_read_against_the_frame_that_was_drawn() {
        let dir = tempfile::tempdir().unwrap();
        let mut app = app_in(dir.path());
        let shown = drawn(&app);
        let target = app.mission().obstacles[0].center;
        let cell = shown.canvas.to_cell(target).expect("on the map");
        app.update(Action::Zoom(4.0, None));
        let now = drawn(&app);
        assert_ne!(now.canvas, shown.canvas, "the view changed");
        let click = mouse_action(
            &app,
            event(MouseEventKind::Down(MouseButton::Left), cell),
            &shown,
        );
        assert!(
            matches!(click, Some(Action::DragStart(Item::Obstacle(0), _))),
            "{click:?}"
        );
    }

    fn cell_of(app: &App, p: Point2<f64>) -> (u16, u16) {
        let areas = layout(SCREEN).unwrap();
        Viewport::map(app, areas.left)
            .to_cell(p)
            .expect("on the map")
    }

    #[test]
    fn click_selects_and_drag_moves_an_obstacle_as_one_step() {
        let dir = tempfile::tempdir().unwrap();
        let mut app = app_in(dir.path());
        let tree = app
            .mission()
            .obstacles
            .iter()
            .position(|o| o.name == "tree 9")
            .unwrap();
        let center = app.mission().obstacles[tree].center;
        let cell = cell_of(&app, center);
        let down = mouse_action(
            &app,
            event(MouseEventKind::Down(MouseButton::Left), cell),
            &drawn(&app),
        );
        assert!(
            matches!(down, Some(Action::DragStart(Item::Obstacle(i), _)) if i == tree),
            "{down:?}"
        );
        app.update(down.unwrap());
        let to = (cell.0 + 10, cell.1 + 3);
        let drag = mouse_action(
            &app,
            event(MouseEventKind::Drag(MouseButton::Left), to),
            &drawn(&app),
        )
        .unwrap();
        app.update(drag);
        app.update(
            mouse_action(
                &app,
                event(MouseEventKind::Up(MouseButton::Left), to),
                &drawn(&app),
            )
            .unwrap(),
        );
        let moved = app.mission().obstacles[tree].center;
        // Ten columns right and three rows down, at the map's scale.
        let areas = layout(SCREEN).unwrap();
        let metres = Viewport::map(&app, areas.left).metres_per_column();
        assert!(
            (moved.x - center.x - 10.0 * metres).abs() < metres,
            "{moved} from {center}"
        );
        assert!(
            (center.y - moved.y - 6.0 * metres).abs() < 2.0 * metres,
            "{moved} from {center}"
        );
        app.update(Action::Undo);
        assert_eq!(app.mission().obstacles[tree].center, center);
    }

    #[test]
    fn the_add_tool_places_an_obstacle_where_clicked() {
        let dir = tempfile::tempdir().unwrap();
        let mut app = app_in(dir.path());
        let spot = Point2::new(20.0, 80.0);
        let cell = cell_of(&app, spot);
        let plain = mouse_action(
            &app,
            event(MouseEventKind::Down(MouseButton::Left), cell),
            &drawn(&app),
        );
        assert_eq!(
            plain,
            Some(Action::FocusOn(Focus::Map)),
            "an empty spot selects nothing"
        );
        app.update(Action::ToggleAddTool);
        let add = mouse_action(
            &app,
            event(MouseEventKind::Down(MouseButton::Left), cell),
            &drawn(&app),
        )
        .unwrap();
        app.update(add);
        let placed = app.mission().obstacles.last().unwrap().center;
        assert!((placed - spot).norm() < 2.0, "{placed}");
    }

    #[test]
    fn the_wheel_zooms_about_the_pointer() {
        let dir = tempfile::tempdir().unwrap();
        let mut app = app_in(dir.path());
        let spot = Point2::new(100.0, 30.0);
        let cell = cell_of(&app, spot);
        let areas = layout(SCREEN).unwrap();
        let under = Viewport::map(&app, areas.left)
            .to_world(cell.0, cell.1)
            .unwrap();
        app.update(
            mouse_action(&app, event(MouseEventKind::ScrollUp, cell), &drawn(&app)).unwrap(),
        );
        assert!((app.camera().zoom() - 1.25).abs() < 1e-12);
        let after = Viewport::map(&app, areas.left)
            .to_world(cell.0, cell.1)
            .unwrap();
        assert!(
            (after - under).norm() < 1e-9,
            "the point under the pointer stays: {under} → {after}"
        );
    }
}

#[test]
fn the_readme_lists_every_key_the_help_overlay_shows() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    for key in skyform::tui::keys::KEYS.iter() {
        let row = format!("| `{}` | {} |", key.keys, key.help);
        assert!(readme.contains(&row), "README.md lacks the key row {row}");
    }
}

#[test]
fn a_fleet_run_replays_on_the_map() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/missions/fleet-triangle.toml");
    let mut m = mission::load(std::path::Path::new(path)).unwrap().mission;
    m.fleet.duration = Some(6.0);
    let mut app = App::new(Document::new(m, None), std::env::temp_dir());
    app.update(Action::Run(skyform::pipelines::Kind::Fleet));
    assert!(app.wait_for_jobs(Duration::from_secs(60)));
    assert_eq!(app.jobs()[0].pipeline, skyform::pipelines::Kind::Fleet);
    assert_eq!(app.replay_end(), Some(6.0));
    assert_eq!(app.replay_time(), Some(6.0), "the end until scrubbed");
    app.update(Action::Scrub(-2.5));
    assert_eq!(app.replay_time(), Some(3.5));
    app.update(Action::TogglePlay);
    assert!(app.is_playing() && app.wants_tick());
    app.tick(Duration::from_secs(1));
    assert!((app.replay_time().unwrap() - 4.5).abs() < 1e-9);
    app.tick(Duration::from_secs(10));
    assert_eq!(app.replay_time(), Some(6.0));
    assert!(!app.is_playing(), "stops at the end");
    // Fleet targets are items: select, move, add, delete.
    app.update(Action::Select(Item::Point(
        skyform::pipelines::points::PointRef {
            pipeline: skyform::pipelines::Kind::Fleet,
            kind: 0,
            index: 0,
        },
    )));
    app.update(Action::FocusOn(Focus::Map));
    app.update(Action::Nudge(1.0, 0.0));
    assert_eq!(
        app.mission().fleet.targets[0].position,
        Point2::new(3.0, 2.0)
    );
    let n = app.mission().fleet.targets.len();
    app.update(Action::Duplicate);
    assert_eq!(app.mission().fleet.targets.len(), n + 1);
    app.update(Action::Delete);
    assert_eq!(app.mission().fleet.targets.len(), n);
}

#[test]
fn applying_a_field_unchanged_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Select(Item::Obstacle(0)));
    app.update(Action::FocusOn(Focus::Inspector));
    for _ in 0..6 {
        app.update(Action::EditStart(None));
        app.update(Action::EditCommit);
    }
    assert!(!app.doc().can_undo(), "no undo step for an unchanged value");
    assert!(!app.doc().is_modified());
}

#[test]
fn a_release_over_a_window_still_ends_the_drag() {
    use ratatui::crossterm::event::{KeyModifiers, MouseButton, MouseEvent, MouseEventKind};
    use skyform::tui::input::mouse_action;
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let at = app.mission().obstacles[0].center;
    app.update(Action::DragStart(Item::Obstacle(0), at));
    app.update(Action::DragTo(at + nalgebra::Vector2::new(3.0, 0.0)));
    app.update(Action::ToggleHelp);
    let up = MouseEvent {
        kind: MouseEventKind::Up(MouseButton::Left),
        column: 10,
        row: 10,
        modifiers: KeyModifiers::NONE,
    };
    let drawn = skyform::tui::view::Drawn::of(&app, ratatui::layout::Rect::new(0, 0, 140, 42))
        .expect("large enough");
    let action = mouse_action(&app, up, &drawn);
    assert_eq!(action, Some(Action::DragEnd));
    app.update(Action::DragEnd);
    app.update(Action::Dismiss);
    // The drag was one step; a later move of another item is another.
    app.update(Action::Select(Item::Goal));
    app.update(Action::FocusOn(Focus::Map));
    app.update(Action::Nudge(1.0, 0.0));
    app.update(Action::Undo);
    assert_eq!(
        app.mission().obstacles[0].center,
        at + nalgebra::Vector2::new(3.0, 0.0)
    );
    app.update(Action::Undo);
    assert_eq!(app.mission().obstacles[0].center, at);
}

#[test]
fn save_as_onto_an_existing_file_asks_before_replacing_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let other = dir.path().join("other.toml");
    std::fs::write(&other, "# someone else's file\n").unwrap();
    app.update(Action::SaveAs);
    for _ in 0..200 {
        app.update(Action::PromptBackspace);
    }
    for c in "other.toml".chars() {
        app.update(Action::PromptInput(c));
    }
    app.update(Action::Confirm);
    assert!(
        matches!(app.overlay(), Some(Overlay::Overwrite { path, .. }) if path == &other),
        "{:?}",
        app.overlay()
    );
    assert_eq!(
        std::fs::read_to_string(&other).unwrap(),
        "# someone else's file\n"
    );
    // Esc keeps the file; asking again and answering y replaces it.
    app.update(Action::Dismiss);
    assert!(app.overlay().is_none());
    assert_eq!(
        app.doc().path(),
        Some(dir.path().join("bridge.toml").as_path())
    );
    app.update(Action::SaveAs);
    for _ in 0..200 {
        app.update(Action::PromptBackspace);
    }
    for c in "other.toml".chars() {
        app.update(Action::PromptInput(c));
    }
    app.update(Action::Confirm);
    app.update(Action::Confirm);
    assert_eq!(app.doc().path(), Some(other.as_path()));
    assert_eq!(mission::load(&other).unwrap().mission, *app.mission());
}

#[test]
fn renaming_an_obstacle_carries_its_iwp_choices_along() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let choice = app.mission().reconfiguration.waypoints[0].clone();
    let k = app
        .mission()
        .obstacles
        .iter()
        .position(|o| o.name == choice.between[0])
        .unwrap();
    app.update(Action::Select(Item::Obstacle(k)));
    type_into(&mut app, "name", "renamed pier");
    let after = &app.mission().reconfiguration.waypoints[0];
    assert_eq!(after.between[0], "renamed pier");
    assert_eq!(after.between[1], choice.between[1]);
    assert_eq!(app.doc().error_count(), 0, "{:?}", app.doc().error_lines());
}

#[test]
fn a_dangling_iwp_choice_can_be_selected_and_deleted() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dangling.toml");
    let mut m = default_mission().mission;
    m.reconfiguration.waypoints[0].between[0] = "no such pier".into();
    let pair = m.reconfiguration.waypoints[0].between.clone();
    mission::save(&m, &path).unwrap();
    let mut app = App::new(Document::new(m, Some(path)), dir.path().to_path_buf());
    assert!(app.doc().error_count() > 0);
    let items = skyform::tui::fields::formation_items(app.mission(), app.iwps());
    let item = Item::Waypoint(pair.clone());
    assert!(items.contains(&item), "{items:?}");
    app.update(Action::Select(item));
    assert_eq!(app.selected(), &Item::Waypoint(pair));
    app.update(Action::Delete);
    assert_eq!(app.doc().error_count(), 0, "{:?}", app.doc().error_lines());
}

#[test]
fn unsaved_edits_are_kept_in_a_recovery_copy_and_offered_back() {
    use skyform::tui::recovery::{Origin, Recovery};
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let file = dir.path().join("bridge.toml");
    let origin = Origin::File(file.clone());
    let recovery = || Recovery::in_dir(Some(state.path().to_path_buf()), &origin);
    let copies = || std::fs::read_dir(state.path()).unwrap().count();

    let mut app = app_in(dir.path());
    app.use_recovery(recovery());
    app.update(Action::AddObstacle(Some(Point2::new(12.0, 34.0))));
    let edited = app.mission().clone();
    let t0 = std::time::Instant::now();
    app.keep_recovery(t0, false);
    assert_eq!(copies(), 1, "written at the first edit");
    // A second edit within the interval waits for the tick after it.
    app.update(Action::Nudge(1.0, 0.0));
    app.keep_recovery(t0 + Duration::from_millis(300), false);
    assert!(app.wants_tick(), "a write is pending");
    app.keep_recovery(t0 + Duration::from_millis(1100), false);
    assert!(!app.wants_tick());
    let moved = app.mission().clone();
    assert_ne!(moved, edited);
    drop(app); // as a kill -9 would: nothing saved, the copy stays

    let mut app = app_in(dir.path());
    app.use_recovery(recovery());
    match app.overlay() {
        Some(Overlay::Recover(copy)) => {
            assert_eq!(copy.mission, moved);
            assert_eq!(copy.changes, 2);
        }
        other => panic!("expected the recovery question, got {other:?}"),
    }
    app.update(Action::Confirm);
    assert_eq!(app.mission(), &moved);
    assert!(app.doc().is_modified());
    app.update(Action::Save);
    app.keep_recovery(std::time::Instant::now(), false);
    assert_eq!(copies(), 0, "saved: the copy is gone");
    assert_eq!(mission::load(&file).unwrap().mission, moved);

    // Declining drops the copy.
    let mut app = app_in(dir.path());
    app.use_recovery(recovery());
    app.update(Action::AddObstacle(None));
    app.keep_recovery(std::time::Instant::now(), true);
    assert_eq!(copies(), 1);
    let mut app = app_in(dir.path());
    app.use_recovery(recovery());
    assert!(matches!(app.overlay(), Some(Overlay::Recover(_))));
    app.update(Action::Dismiss);
    assert_eq!(copies(), 0);
    assert!(!app.doc().is_modified());
}

/// Issue 16: the friction fixes that a state can hold.
#[test]
fn enter_applies_and_stays_and_a_good_edit_clears_an_old_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Select(Item::Bounds));
    type_into(&mut app, "x min (m)", "abc");
    assert!(app.status().is_some_and(|s| s.error));
    app.update(Action::Dismiss);
    let field = app.editor().field();
    type_into(&mut app, "x min (m)", "-5");
    assert_eq!(app.editor().field(), field, "Enter stays on the field");
    assert_eq!(app.mission().bounds.x[0], -5.0);
    let status = app.status().cloned().unwrap();
    assert!(!status.error, "the old error is gone: {}", status.text);
    app.update(Action::FieldDown);
    assert_eq!(
        app.editor().field(),
        field + 1,
        "↓ goes to the very next field"
    );
}

#[test]
fn s_outside_an_iwp_row_says_what_it_needs() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let before = app.mission().clone();
    app.update(Action::CycleShape);
    assert_eq!(app.mission(), &before);
    let status = app.status().cloned().unwrap();
    assert!(status.text.contains("select one of the"), "{}", status.text);
}

#[test]
fn the_formation_title_follows_undo_back_to_the_original_shape() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let original = app.current_preset();
    app.update(Action::CyclePreset);
    let first = app.current_preset();
    assert!(
        first.is_some() && first != original,
        "{first:?} {original:?}"
    );
    app.update(Action::Undo);
    assert_eq!(app.current_preset(), original);
}

#[test]
fn opening_another_mission_drops_the_jobs_of_the_first() {
    let mut app = app_with_result(crate::common::quick(default_mission().mission, 5), 7);
    assert_eq!(app.jobs().len(), 1);
    let b = mission::BUILTIN
        .iter()
        .find(|b| b.file_name == "narrow-passage.toml")
        .unwrap();
    app.open(skyform::tui::app::Entry::Builtin(b.file_name));
    assert!(app.jobs().is_empty());
    assert_eq!(app.doc().title(), "(built-in) narrow-passage.toml");
}

#[test]
fn opening_another_mission_stops_a_drag_and_the_add_tool_of_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let start = app.mission().obstacles[0].center;
    app.update(Action::DragStart(Item::Obstacle(0), start));
    app.update(Action::ToggleAddTool);
    assert!(app.editor().add_tool());
    app.open(skyform::tui::app::Entry::Builtin("narrow-passage.toml"));
    let before = app.mission().clone();
    // The rest of the old drag lands on the new mission: nothing moves.
    app.update(Action::DragTo(start + nalgebra::Vector2::new(40.0, 25.0)));
    app.update(Action::DragEnd);
    assert_eq!(app.mission(), &before);
    assert!(!app.doc().is_modified());
    assert!(!app.editor().add_tool());
}

#[test]
fn drags_snap_to_the_nudge_step_and_huge_values_show_short() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let start = app.mission().obstacles[0].center;
    app.update(Action::DragStart(Item::Obstacle(0), start));
    app.update(Action::DragTo(
        start + nalgebra::Vector2::new(3.2718, -1.0409),
    ));
    app.update(Action::DragEnd);
    let c = app.mission().obstacles[0].center;
    let step = app.step_size();
    for v in [c.x, c.y] {
        assert!(
            ((v / step).round() * step - v).abs() < 1e-9,
            "{v} is off the {step} m grid"
        );
    }
    assert_eq!(skyform::tui::fields::fmt_num(1e300), "1e300");
    assert_eq!(skyform::tui::fields::fmt_num(-2.5e-7), "-2.5e-7");
    assert_eq!(skyform::tui::fields::fmt_num(4.080851063829786), "4.0809");
}

#[test]
fn a_duplicate_obstacle_name_is_flagged_on_the_renamed_one_while_typing() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let other = app.mission().obstacles[4].name.clone();
    app.update(Action::Select(Item::Obstacle(1)));
    type_into(&mut app, "name", &other);
    let at = |i: usize| format!("obstacles[{i}].name");
    let lines = app.doc().error_lines();
    assert!(lines.iter().any(|l| l.starts_with(&at(1))), "{lines:?}");
    assert!(lines.iter().any(|l| l.starts_with(&at(4))), "{lines:?}");
}

/// Quitting without saving is a choice: no recovery copy is left behind.
#[test]
fn quitting_without_saving_leaves_no_recovery_copy() {
    use skyform::tui::recovery::{Origin, Recovery};
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let origin = Origin::File(dir.path().join("bridge.toml"));
    app.use_recovery(Recovery::in_dir(Some(state.path().to_path_buf()), &origin));
    app.update(Action::AddObstacle(None));
    app.keep_recovery(std::time::Instant::now(), true);
    assert_eq!(std::fs::read_dir(state.path()).unwrap().count(), 1);
    app.update(Action::Quit);
    assert!(matches!(app.overlay(), Some(Overlay::Quit)));
    app.update(Action::Confirm); // quit without saving
    // What the loop does after every action and on the way out:
    app.keep_recovery(std::time::Instant::now(), false);
    app.keep_recovery(std::time::Instant::now(), true);
    assert!(app.should_quit());
    assert_eq!(std::fs::read_dir(state.path()).unwrap().count(), 0);
}

/// Issue 16: an error in an IWP choice alone still leaves the IWPs marked.
#[test]
fn an_iwp_choice_error_alone_keeps_the_iwps_on_the_map() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = default_mission().mission;
    let n = skyform::pipelines::theta_pso::find_iwps(&m).len();
    assert!(n > 0);
    m.reconfiguration.waypoints[0].scale = Some(7.0); // not in (0, 1]
    let app = App::new(
        Document::new(m, Some(dir.path().join("m.toml"))),
        dir.path().to_path_buf(),
    );
    assert!(app.doc().error_count() > 0);
    assert_eq!(app.iwps().len(), n);
    // Any other error: no IWPs (the geometry may be wrong).
    let mut m = default_mission().mission;
    m.obstacles[0].radius = -1.0;
    let app = App::new(Document::new(m, None), dir.path().to_path_buf());
    assert!(app.iwps().is_empty());
}

/// Types `text` into the prompt on screen (save as, open).
fn type_prompt(app: &mut App, text: &str) {
    app.update(Action::PromptClear);
    for c in text.chars() {
        app.update(Action::PromptInput(c));
    }
}

/// A second mission (narrow passage) saved at `path`.
fn other_mission_at(path: &std::path::Path) -> Mission {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let m = mission::load(&root.join("missions/narrow-passage.toml"))
        .unwrap()
        .mission;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).unwrap();
    }
    mission::save(&m, path).unwrap();
    m
}

#[test]
fn open_takes_a_typed_path_relative_to_the_working_directory() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    // Not listed: only missions/ and ./ are.
    let other = other_mission_at(&dir.path().join("elsewhere/other.toml"));
    app.update(Action::Open);
    type_prompt(&mut app, "elsewhere/other.toml");
    let Some(Overlay::Open { matches, .. }) = app.overlay() else {
        panic!("no open dialog: {:?}", app.overlay());
    };
    assert_eq!(
        matches.first(),
        Some(&skyform::tui::app::Entry::File(
            dir.path().join("elsewhere/other.toml")
        )),
        "the typed path comes first"
    );
    app.update(Action::Confirm);
    assert!(app.overlay().is_none(), "{:?}", app.overlay());
    assert_eq!(app.mission(), &other);
    assert_eq!(
        app.doc().path(),
        Some(dir.path().join("elsewhere/other.toml").as_path())
    );
}

#[test]
fn open_filters_the_list_by_what_is_typed() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut app = App::new(Document::new(default_mission().mission, None), root);
    app.update(Action::Open);
    type_prompt(&mut app, "NARROW");
    let Some(Overlay::Open { matches, .. }) = app.overlay() else {
        panic!("no open dialog");
    };
    assert!(!matches.is_empty());
    assert!(
        matches.iter().all(|e| e.label().contains("narrow")),
        "{matches:?}"
    );
    app.update(Action::Confirm);
    assert!(
        app.doc().title().contains("narrow"),
        "{}",
        app.doc().title()
    );
}

#[test]
fn opening_a_missing_or_invalid_file_says_which_and_loses_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::AddObstacle(None));
    let edited = app.mission().clone();

    app.update(Action::Open);
    // Not a .toml name: not a new mission, a missing file.
    type_prompt(&mut app, "nope/missing");
    app.update(Action::Confirm);
    let status = app.status().cloned().expect("a status");
    assert!(status.error, "{status:?}");
    assert!(
        status.text.contains("missing") && status.text.contains("no such file"),
        "{}",
        status.text
    );
    assert!(
        matches!(app.overlay(), Some(Overlay::Open { .. })),
        "the dialog stays to fix the path"
    );

    std::fs::write(dir.path().join("notes.toml"), "this is = = not toml").unwrap();
    type_prompt(&mut app, "notes.toml");
    app.update(Action::Confirm);
    let status = app.status().cloned().expect("a status");
    assert!(
        status.error && status.text.contains("notes.toml"),
        "{status:?}"
    );
    assert!(
        matches!(app.overlay(), Some(Overlay::Open { .. })),
        "refused before asking to discard: {:?}",
        app.overlay()
    );

    std::fs::create_dir(dir.path().join("folder")).unwrap();
    type_prompt(&mut app, "folder");
    app.update(Action::Confirm);
    let status = app.status().cloned().expect("a status");
    assert!(status.text.contains("folder"), "{status:?}");

    app.update(Action::Dismiss);
    assert_eq!(app.mission(), &edited, "nothing is lost");
    assert!(app.doc().is_modified());
}

#[test]
fn the_unsaved_changes_prompt_on_open_can_save_first() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::AddObstacle(None));
    let edited = app.mission().clone();
    let other = other_mission_at(&dir.path().join("other.toml"));
    app.update(Action::Open);
    type_prompt(&mut app, "other.toml");
    app.update(Action::Confirm);
    assert!(matches!(app.overlay(), Some(Overlay::Discard(_))));
    app.update(Action::Save);
    assert_eq!(
        mission::load(&dir.path().join("bridge.toml"))
            .unwrap()
            .mission,
        edited,
        "saved first"
    );
    assert_eq!(app.mission(), &other, "then opened");
    assert!(!app.doc().is_modified());
    let status = app.status().cloned().unwrap();
    assert!(
        status.text.contains("saved") && status.text.contains("opened"),
        "{status:?}"
    );
}

#[test]
fn save_first_goes_through_save_as_and_opens_only_once_saved() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = App::new(
        Document::new(default_mission().mission, None),
        dir.path().to_path_buf(),
    );
    app.update(Action::AddObstacle(None));
    let edited = app.mission().clone();
    let other = other_mission_at(&dir.path().join("other.toml"));
    let open_other = |app: &mut App| {
        app.update(Action::Open);
        type_prompt(app, "other.toml");
        app.update(Action::Confirm);
        assert!(matches!(app.overlay(), Some(Overlay::Discard(_))));
        app.update(Action::Save);
        assert!(
            matches!(app.overlay(), Some(Overlay::SaveAs { .. })),
            "the built-in mission needs a name: {:?}",
            app.overlay()
        );
    };
    open_other(&mut app);
    app.update(Action::Dismiss);
    assert_eq!(app.mission(), &edited, "cancelled: nothing opened");
    assert!(app.doc().is_modified());

    open_other(&mut app);
    type_prompt(&mut app, "mine.toml");
    app.update(Action::Confirm);
    assert_eq!(
        mission::load(&dir.path().join("mine.toml"))
            .unwrap()
            .mission,
        edited
    );
    assert_eq!(app.mission(), &other);
}

#[test]
fn save_first_of_an_invalid_mission_asks_and_a_refusal_does_not_open() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::Select(Item::Obstacle(2)));
    type_into(&mut app, "radius (m)", "-1");
    let edited = app.mission().clone();
    let other = other_mission_at(&dir.path().join("other.toml"));
    let open_other = |app: &mut App| {
        app.update(Action::Open);
        type_prompt(app, "other.toml");
        app.update(Action::Confirm);
        app.update(Action::Save);
        assert!(
            matches!(app.overlay(), Some(Overlay::SaveInvalid { .. })),
            "{:?}",
            app.overlay()
        );
    };
    open_other(&mut app);
    app.update(Action::Dismiss);
    assert_eq!(app.mission(), &edited, "not saved, not opened");
    assert_eq!(
        mission::load(&dir.path().join("bridge.toml"))
            .unwrap()
            .mission,
        default_mission().mission
    );

    open_other(&mut app);
    app.update(Action::Confirm);
    let text = std::fs::read_to_string(dir.path().join("bridge.toml")).unwrap();
    assert_eq!(
        mission::check_str(&text, None).mission.unwrap().obstacles[2].radius,
        -1.0
    );
    assert_eq!(app.mission(), &other);
}

#[test]
fn the_open_dialog_types_letters_and_its_prompt_offers_save_first() {
    use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    use skyform::tui::input::key_action;
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::AddObstacle(None)); // unsaved: opening asks first
    app.update(Action::Open);
    let key = |c| KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE);
    assert_eq!(key_action(&app, key('q')), Some(Action::PromptInput('q')));
    type_prompt(&mut app, "bridge.toml");
    app.update(Action::Confirm);
    assert!(matches!(app.overlay(), Some(Overlay::Discard(_))));
    assert_eq!(key_action(&app, key('s')), Some(Action::Save));
    assert_eq!(key_action(&app, key('y')), Some(Action::Confirm));
}

/// Issue 13: one key table. Every binding dispatches to its action in a
/// state where its condition holds (and no earlier row shadows it), and
/// every key that does something on the main screen, in every focus and
/// pane, is a binding of the table, or a number typed over an inspector
/// field (the Enter row says so).
#[test]
fn every_binding_dispatches_and_every_key_that_acts_is_in_the_table() {
    use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    use skyform::tui::app::Pane;
    use skyform::tui::input::key_action;
    use skyform::tui::keys::{Context, KEYS, Key, lookup};

    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    let event = |k: Key| match k {
        Key::Char(c) if c.is_ascii_uppercase() => {
            KeyEvent::new(KeyCode::Char(c), KeyModifiers::SHIFT)
        }
        Key::Char(c) => KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE),
        Key::Ctrl(c) => KeyEvent::new(KeyCode::Char(c), KeyModifiers::CONTROL),
        Key::Code(KeyCode::BackTab) => KeyEvent::new(KeyCode::BackTab, KeyModifiers::SHIFT),
        Key::Code(code) => KeyEvent::new(code, KeyModifiers::NONE),
        Key::Shift(code) => KeyEvent::new(code, KeyModifiers::SHIFT),
    };
    let mut states = Vec::new();
    for found in [false, true] {
        for pane in [Pane::Map, Pane::Formation] {
            for focus in [Focus::Map, Focus::Inspector, Focus::Jobs] {
                states.push(Context { focus, pane, found });
            }
        }
    }
    let enter = |app: &mut App, at: Context| {
        // A find kept (its matches stepped through with n / N), or none.
        app.update(Action::Dismiss);
        if at.found {
            app.update(Action::Find);
            for c in "pier".chars() {
                app.update(Action::FindInput(c));
            }
            app.update(Action::FindKeep);
        }
        app.update(match at.pane {
            Pane::Map => Action::ShowMap,
            Pane::Formation => Action::ShowFormation,
        });
        app.update(Action::FocusOn(at.focus));
        assert_eq!(
            (app.focus(), app.pane(), app.finder().is_stepping()),
            (at.focus, at.pane, at.found)
        );
    };
    let mut bindings = 0;
    for row in KEYS.iter() {
        for b in &row.bindings {
            let Some(&state) = states
                .iter()
                .find(|at| b.when.holds(**at) && lookup(b.key, **at) == Some(b))
            else {
                panic!(
                    "{b:?} ('{}') is shadowed by an earlier binding everywhere",
                    row.keys
                );
            };
            enter(&mut app, state);
            assert_eq!(
                key_action(&app, event(b.key)),
                Some(b.action.clone()),
                "{b:?} in {state:?}"
            );
            bindings += 1;
        }
    }
    assert!(bindings > 50, "{bindings} bindings");

    let mut presses: Vec<KeyEvent> = (' '..='~')
        .map(|c| event(Key::Char(c)))
        .chain(('a'..='z').map(|c| event(Key::Ctrl(c))))
        .collect();
    for code in [
        KeyCode::Enter,
        KeyCode::Esc,
        KeyCode::Tab,
        KeyCode::BackTab,
        KeyCode::Delete,
        KeyCode::Backspace,
        KeyCode::Home,
        KeyCode::End,
        KeyCode::PageUp,
        KeyCode::PageDown,
        KeyCode::Insert,
        KeyCode::F(1),
        KeyCode::F(5),
        KeyCode::Left,
        KeyCode::Right,
        KeyCode::Up,
        KeyCode::Down,
    ] {
        presses.push(event(Key::Code(code)));
        presses.push(event(Key::Shift(code)));
    }
    let in_table = |action: &Action| {
        KEYS.iter()
            .flat_map(|row| &row.bindings)
            .any(|b| &b.action == action)
    };
    for &state in &states {
        enter(&mut app, state);
        for press in &presses {
            if let Some(action) = key_action(&app, *press) {
                let typing =
                    matches!(action, Action::EditStart(Some(_))) && state.focus == Focus::Inspector;
                assert!(
                    typing || in_table(&action),
                    "{press:?} in {state:?} gives {action:?}, which no row of the key table lists"
                );
            }
        }
    }
}

/// Issue 24, item 12: Ctrl-u in an inspector field clears the line typed
/// (not appends a 'u'), as in the save-as prompt and a shell.
#[test]
fn ctrl_u_clears_the_field_being_typed() {
    use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    use skyform::tui::input::key_action;
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::FocusOn(Focus::Inspector));
    app.update(Action::EditStart(None));
    assert_eq!(
        app.editor().editing().map(|e| e.buffer.as_str()),
        Some(app.mission().name.as_str())
    );
    let ctrl_u = KeyEvent::new(KeyCode::Char('u'), KeyModifiers::CONTROL);
    let action = key_action(&app, ctrl_u).expect("Ctrl-u acts while typing");
    app.update(action);
    assert_eq!(app.editor().editing().map(|e| e.buffer.as_str()), Some(""));
    for c in "Turbines".chars() {
        app.update(Action::EditInput(c));
    }
    app.update(Action::EditCommit);
    assert_eq!(app.mission().name, "Turbines");
}

/// Issue 24, item 15: quitting while a job runs says so and asks; yes
/// cancels the run and quits, Esc stays with the run going.
#[test]
fn quitting_with_a_job_running_says_so_and_asks() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.toml");
    let mut m = default_mission().mission;
    m.theta_pso.iterations = 20_000;
    mission::save(&m, &path).unwrap();
    let mut app = App::new(Document::new(m, Some(path)), dir.path().to_path_buf());
    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    assert!(app.jobs()[0].is_running());
    app.update(Action::Quit);
    assert!(!app.should_quit(), "a running job is not dropped silently");
    assert_eq!(app.overlay(), Some(&Overlay::QuitRunning));
    let screen = {
        let mut t = ratatui::Terminal::new(ratatui::backend::TestBackend::new(100, 30)).unwrap();
        t.draw(|f| {
            skyform::tui::view::draw(f, &app, std::time::Instant::now());
        })
        .unwrap();
        t.backend().to_string()
    };
    assert!(
        screen.contains("job 1 θ-PSO s7 is running: quitting cancels it."),
        "{screen}"
    );
    app.update(Action::Dismiss);
    assert!(!app.should_quit() && app.jobs()[0].is_running());
    app.update(Action::Quit);
    app.update(Action::Confirm);
    assert!(app.should_quit());
    assert!(app.wait_for_jobs(Duration::from_secs(60)));
    assert_eq!(app.jobs()[0].state, JobState::Cancelled);
}

/// Issue 24, item 14: a rerun with the same seed records to a new file
/// (`-2`) instead of over the first, and the status line names the file
/// written; the built-in mission's recordings follow `<mission>-…`
/// (`bridge-inspection-theta-pso-seed7.rrd`, not the name's slug).
#[test]
fn recordings_never_overwrite_and_the_status_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = default_mission().mission;
    m.theta_pso.iterations = 5;
    let doc = Document::new(m, None).with_builtin("bridge-inspection.toml");
    let mut app = App::new(doc, dir.path().to_path_buf());
    app.update(Action::ToggleRecording);
    let first = dir.path().join("bridge-inspection-theta-pso-seed7.rrd");
    let second = dir.path().join("bridge-inspection-theta-pso-seed7-2.rrd");
    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    assert!(
        app.status()
            .unwrap()
            .text
            .contains("recording to bridge-inspection-theta-pso-seed7.rrd"),
        "{:?}",
        app.status()
    );
    assert!(app.wait_for_jobs(Duration::from_secs(120)));
    let status = app.status().unwrap().text.clone();
    assert!(
        status.contains("job 1 done") && status.contains(&format!("recorded {}", first.display())),
        "{status}"
    );
    let size = std::fs::metadata(&first).unwrap().len();
    app.update(Action::Run(skyform::pipelines::Kind::ThetaPso));
    assert!(app.wait_for_jobs(Duration::from_secs(120)));
    let status = app.status().unwrap().text.clone();
    assert!(
        status.contains(&format!("recorded {}", second.display())),
        "{status}"
    );
    assert_eq!(
        std::fs::metadata(&first).unwrap().len(),
        size,
        "the first is kept"
    );
    assert!(second.exists());
}

/// Issue 24, items 1 and 18: a new file starts from the minimal mission,
/// not a copy of the bridge: `skyform NEW.toml` and a `.toml` path typed
/// into the open dialog (which can now create one) both give a box, a
/// start, a goal and the default formation, named after the file, unsaved.
#[test]
fn a_new_file_starts_from_the_minimal_mission_from_the_command_line_and_the_open_dialog() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("turbines.toml");
    let (doc, note) = skyform::tui::open_document(Some(&path)).unwrap();
    let minimal = |m: &Mission| {
        m.origin.is_none()
            && m.obstacles.is_empty()
            && m.reconfiguration.waypoints.is_empty()
            && m.formation == mission::Formation::default()
            && m.name == "turbines"
    };
    assert!(minimal(doc.mission()), "{:?}", doc.mission());
    assert!(doc.is_modified(), "not written until saved");
    assert!(!path.exists());
    assert!(note.unwrap().contains("new mission"));
    let source = doc.source().unwrap();
    let section = |text: &str, name: &str| text.lines().any(|l| l.trim_start().starts_with(name));
    assert!(
        !source.contains("bridge") && !section(source, "[origin]"),
        "{source}"
    );

    // The open dialog: a .toml path that does not exist is a new mission.
    let mut app = App::new(
        Document::new(default_mission().mission, None),
        dir.path().into(),
    );
    app.update(Action::Open);
    type_prompt(&mut app, "site/north.toml");
    let Some(Overlay::Open { matches, .. }) = app.overlay() else {
        panic!("no open dialog: {:?}", app.overlay());
    };
    let wanted = dir.path().join("site/north.toml");
    assert_eq!(
        matches.first(),
        Some(&skyform::tui::app::Entry::New(wanted.clone()))
    );
    app.update(Action::Confirm);
    assert!(app.overlay().is_none(), "{:?}", app.overlay());
    assert_eq!(app.mission().name, "north");
    assert!(app.mission().origin.is_none() && app.mission().obstacles.is_empty());
    assert_eq!(app.doc().path(), Some(wanted.as_path()));
    assert!(app.doc().is_modified());
    app.update(Action::Save);
    let saved = std::fs::read_to_string(&wanted).unwrap();
    assert!(saved.contains("name = \"north\""), "{saved}");
    assert!(
        !section(&saved, "[origin]") && !saved.contains("bridge"),
        "{saved}"
    );
}

/// The slot errors (eq. 7) of the app's mission.
fn slot_errors(app: &App) -> Vec<String> {
    app.doc()
        .diagnostics()
        .iter()
        .filter(|d| d.is_error() && d.path.to_string().starts_with("formation.slots"))
        .map(|d| d.to_string())
        .collect()
}

/// Issue 24, items 4 and 11: growing a formation keeps its shape and stays
/// valid for the mission's d_com and r_Q: a diamond of 4 typed to 16 UAVs
/// is a diamond of 16 without an error (with the safety margin of issue 36
/// a diamond of 20 no longer fits d_com = 20 m at the spacing a shrink to
/// 0.5 needs), `a` grows a preset as itself, P skips a preset that cannot
/// fit (the line abreast of 16) and says why, the spacing is a field, slots
/// are millimetres.
#[test]
fn presets_grow_valid_for_the_mission_with_their_spacing_as_a_field() {
    let dir = tempfile::tempdir().unwrap();
    let mut app = app_in(dir.path());
    app.update(Action::ShowFormation);
    app.update(Action::Select(Item::Formation));
    type_into(&mut app, "UAVs", "4");
    type_into(&mut app, "preset", "diamond");
    assert_eq!(
        app.current_preset(),
        Some(skyform::mission::Preset::Diamond)
    );
    assert_eq!(app.mission().formation.slots.len(), 4);
    assert!(slot_errors(&app).is_empty(), "{:?}", slot_errors(&app));

    type_into(&mut app, "UAVs", "16");
    assert_eq!(app.mission().formation.slots.len(), 16);
    assert_eq!(
        app.current_preset(),
        Some(skyform::mission::Preset::Diamond)
    );
    assert!(slot_errors(&app).is_empty(), "{:?}", slot_errors(&app));

    // P never lands on a shape that cannot fit, and says which it skipped.
    for _ in 0..6 {
        app.update(Action::CyclePreset);
        assert!(slot_errors(&app).is_empty(), "{:?}", slot_errors(&app));
        assert_ne!(
            app.current_preset(),
            Some(skyform::mission::Preset::LineAbreast)
        );
    }
    let status = app.status().unwrap().text.clone();
    assert!(
        status.contains("line abreast") && status.contains("d_com"),
        "{status}"
    );

    // The spacing is a field; the slots follow it, to the millimetre.
    type_into(&mut app, "preset", "diamond");
    type_into(&mut app, "UAVs", "4");
    type_into(&mut app, "spacing (m)", "3.3333");
    let spacing = skyform::mission::min_pair_distance(&app.mission().formation.slots);
    assert!((spacing - 3.333).abs() < 2e-3, "{spacing}");
    for s in &app.mission().formation.slots {
        for c in s.iter() {
            assert_eq!(*c, skyform::mission::round_mm(*c), "{c}");
        }
    }
    // `a` grows the diamond as a diamond.
    app.update(Action::AddSlot);
    assert_eq!(app.mission().formation.slots.len(), 5);
    assert_eq!(
        app.current_preset(),
        Some(skyform::mission::Preset::Diamond)
    );
    assert!(slot_errors(&app).is_empty(), "{:?}", slot_errors(&app));
    // A line abreast of 16 does not fit d_com = 20 m: refused, said why.
    app.update(Action::Select(Item::Formation));
    type_into(&mut app, "UAVs", "16");
    let before = app.mission().clone();
    type_into(&mut app, "preset", "line abreast");
    assert_eq!(app.mission(), &before);
    let status = app.status().unwrap();
    assert!(
        status.error && status.text.contains("does not fit"),
        "{status:?}"
    );
}

/// Live planning: the bridge is planned as live mode starts (cold), each
/// edit re-plans it warm from the last plan (outside the jobs list, shown
/// at once), a mission with an error pauses it naming the error and an edit
/// that mends it resumes it, and off it plans nothing.
#[test]
fn live_planning_follows_edits_pauses_on_errors_and_stops_when_off() {
    let wait = Duration::from_secs(120);
    let mut app = App::new(
        Document::new(default_mission().mission, None),
        std::env::temp_dir(),
    );
    assert!(app.start_live(skyform::pipelines::Kind::ThetaPso).is_ok());
    assert!(app.settle_live(wait));
    let first = app
        .board()
        .live()
        .latest()
        .map(|j| j.id)
        .expect("a live plan");
    assert_eq!(app.shown().map(|j| j.id), Some(first), "shown at once");
    assert!(app.jobs().is_empty(), "live runs stay out of the list");
    let o = app
        .shown()
        .and_then(|j| j.outcome.as_ref())
        .and_then(|o| o.theta_pso())
        .unwrap();
    assert!(
        o.feasible() && o.warm_start.is_none(),
        "the first live plan is cold"
    );

    // An edit: tree 9 one metre south.
    app.update(Action::Select(Item::Obstacle(7)));
    app.update(Action::Nudge(0.0, -1.0));
    assert!(app.board().live().replanning());
    assert!(app.settle_live(wait));
    assert_eq!(app.board().live().revision(), 2);
    let job = app.shown().unwrap();
    assert_eq!(
        &job.mission,
        app.mission(),
        "the plan is of the mission as edited"
    );
    assert!(!app.is_stale(job));
    let o = job.outcome.as_ref().and_then(|o| o.theta_pso()).unwrap();
    let warm = o.warm_start.as_ref().expect("warm-started");
    assert!(warm.from.contains("live 1"), "{}", warm.from);
    assert!(o.iterations < 150, "settled in {} iterations", o.iterations);

    // An error pauses live planning, naming it; mending it resumes.
    type_into(&mut app, "radius (m)", "-1");
    let paused = app.board().live().paused().map(str::to_owned);
    assert!(
        paused.as_deref().is_some_and(|p| p.contains("radius")),
        "{paused:?}"
    );
    assert!(app.settle_live(wait));
    assert_eq!(
        app.board().live().revision(),
        2,
        "nothing planned while invalid"
    );
    type_into(&mut app, "radius (m)", "3");
    assert!(app.board().live().paused().is_none());
    assert!(app.settle_live(wait));
    assert_eq!(app.board().live().revision(), 3);

    // Off: an edit plans nothing; the last live plan turns stale.
    app.update(Action::ToggleLive);
    assert!(!app.board().live().is_on());
    app.update(Action::Nudge(0.0, 1.0));
    assert!(app.settle_live(wait));
    assert_eq!(app.board().live().revision(), 3);
    assert!(app.shown().is_some_and(|j| app.is_stale(j)));
}

/// Issue 53, "once per revision": on the bridge with live planning, the
/// IWPs (eq. 9) are found once per edit, by the edit: the map, the
/// inspector, the findings and the live run read that one search
/// (`pipelines::Revision`), and the live plan is still of the mission as
/// edited and passes verification.
#[test]
fn a_live_replan_finds_the_iwps_once_per_edit() {
    use skyform::pipelines::theta_pso::iwp::searches;
    let wait = Duration::from_secs(120);
    let mut m = default_mission().mission;
    m.name = "IWPs once per edit".into();
    let name = m.name.clone();
    let mut app = App::new(Document::new(m, None), std::env::temp_dir());
    assert_eq!(searches::of(&name), 1, "opening the mission: one search");
    assert!(!app.iwps().is_empty(), "the map has the bridge's IWP");
    assert!(app.start_live(skyform::pipelines::Kind::ThetaPso).is_ok());
    assert!(app.settle_live(wait));
    assert_eq!(searches::of(&name), 1, "the first live plan read it");
    for (k, edit) in [(0.0, -1.0), (1.0, 0.0), (0.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        app.update(Action::Select(Item::Obstacle(1)));
        app.update(Action::Nudge(edit.0, edit.1));
        assert!(app.settle_live(wait));
        assert_eq!(searches::of(&name), 2 + k, "edit {}: one search", k + 1);
        let job = app.shown().expect("a live plan");
        assert_eq!(&job.mission, app.mission(), "of the mission as edited");
        let o = job.outcome.as_ref().and_then(|o| o.theta_pso()).unwrap();
        assert!(o.feasible(), "edit {}: not feasible", k + 1);
    }
}

/// Issue 37, a footprint's vertices edited with undo: `c` selects the
/// first corner of a selected footprint, `n` steps to the next, a nudge
/// moves it (its bounding circle follows), `d` adds a vertex halfway to the
/// next, `Del` removes one (never below three), the inspector types one;
/// each is one undo step (the refused third deletion none), and undoing
/// them all gives the footprint back.
#[test]
fn a_footprints_vertices_are_moved_added_and_deleted_with_undo() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = default_mission().mission;
    let mut bay = skyform::mission::Obstacle::standing("T1", Point2::new(0.0, 0.0), 1.0, 7.5);
    bay.footprint = vec![
        Point2::new(60.0, 70.0),
        Point2::new(68.0, 70.0),
        Point2::new(68.0, 76.0),
        Point2::new(60.0, 76.0),
    ];
    bay.settle();
    m.obstacles.push(bay);
    let k = m.obstacles.len() - 1;
    let path = dir.path().join("bay.toml");
    mission::save(&m, &path).unwrap();
    let mut app = App::new(Document::new(m, Some(path)), dir.path().to_path_buf());
    let original = app.mission().clone();

    app.update(Action::Select(Item::Obstacle(k)));
    app.update(Action::FocusOn(Focus::Map));
    app.update(Action::ToggleVertices);
    assert_eq!(app.selected(), &Item::Vertex(k, 0));
    app.update(Action::SelectNext);
    assert_eq!(app.selected(), &Item::Vertex(k, 1));
    app.update(Action::Nudge(1.0, 0.0)); // 1 m east
    let o = &app.mission().obstacles[k];
    assert_eq!(o.footprint[1], Point2::new(69.0, 70.0));
    assert_eq!(
        o.center,
        Point2::new(64.5, 73.0),
        "the bounding circle follows"
    );
    app.update(Action::Duplicate); // halfway to vertex 3
    assert_eq!(app.selected(), &Item::Vertex(k, 2));
    assert_eq!(app.mission().obstacles[k].footprint.len(), 5);
    assert_eq!(
        app.mission().obstacles[k].footprint[2],
        Point2::new(68.5, 73.0)
    );
    type_into(&mut app, "x (m)", "70");
    assert_eq!(
        app.mission().obstacles[k].footprint[2],
        Point2::new(70.0, 73.0)
    );
    app.update(Action::Delete);
    assert_eq!(app.mission().obstacles[k].footprint.len(), 4);
    // Down to three, and no further.
    app.update(Action::Delete);
    assert_eq!(app.mission().obstacles[k].footprint.len(), 3);
    app.update(Action::Delete);
    assert_eq!(app.mission().obstacles[k].footprint.len(), 3);
    app.update(Action::ToggleVertices);
    assert_eq!(app.selected(), &Item::Obstacle(k));
    for _ in 0..5 {
        app.update(Action::Undo);
    }
    assert_eq!(
        app.mission(),
        &original,
        "five undos give the footprint back"
    );
}

/// Issue 50: `G` flies the plan on the map, live or not: with a live plan
/// shown (no job run), it keeps that plan as a job of its own, shows it and
/// starts its flight check; the check comes back with its report.
#[test]
fn g_flies_the_live_plan_on_the_map() {
    let wait = Duration::from_secs(120);
    let mut m = default_mission().mission;
    m.flight.flights = 20;
    let mut app = App::new(Document::new(m, None), std::env::temp_dir());
    assert!(app.start_live(skyform::pipelines::Kind::ThetaPso).is_ok());
    assert!(app.settle_live(wait));
    assert!(app.jobs().is_empty());
    let live = app
        .shown()
        .map(|j| (j.id, j.outcome.clone()))
        .expect("a live plan");
    app.update(Action::FlightCheck);
    assert_eq!(app.jobs().len(), 1, "the live plan kept as job 1");
    let job = &app.jobs()[0];
    assert_eq!(job.id, 1);
    assert_eq!(job.outcome, live.1, "the plan that was on the map");
    assert_eq!(app.shown().map(|j| j.id), Some(1));
    assert!(
        matches!(
            job.flight,
            Some(skyform::tui::jobs::FlightCheck::Running { .. })
        ),
        "{:?}",
        app.status()
    );
    let deadline = std::time::Instant::now() + wait;
    while !matches!(
        app.jobs()[0].flight,
        Some(skyform::tui::jobs::FlightCheck::Done(_))
    ) {
        assert!(std::time::Instant::now() < deadline, "no report");
        if let Ok(msg) = app
            .board()
            .messages()
            .recv_timeout(Duration::from_millis(200))
        {
            app.on_job_msg(msg, std::time::Instant::now());
        }
    }
}

/// Issue 50: the designer edits the route's vias: `g` with an obstacle
/// selected adds a gate between it and its nearest (one undo step), its
/// names edited in the inspector (an unknown one refused, naming the
/// nearest); without one, a via point at the view's centre; `Del` removes
/// the selected via; the map draws each (‖1, ⊙2).
#[test]
fn g_adds_a_gate_or_a_via_point_with_undo() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/missions/viaduct-inspection.toml"
    );
    let mut m = skyform::mission::load(std::path::Path::new(path))
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    m.route.via.clear();
    let mut app = App::new(Document::new(m, None), std::env::temp_dir());
    let pier = app
        .mission()
        .obstacles
        .iter()
        .position(|o| o.name == "pier 3")
        .unwrap_or_else(|| panic!("no pier 3"));
    app.update(Action::Select(Item::Obstacle(pier)));
    app.update(Action::AddVia);
    let via = &app.mission().route.via;
    assert_eq!(via.len(), 1);
    let pair = via[0].between.clone().unwrap_or_default();
    assert_eq!(pair[0], "pier 3");
    assert!(pair[1] == "pier 2" || pair[1] == "pier 4", "{pair:?}");
    assert_eq!(*app.selected(), Item::Via(0));
    type_into(&mut app, "and", "pier 4");
    assert_eq!(
        app.mission().route.via[0].between,
        Some(["pier 3".to_owned(), "pier 4".to_owned()])
    );
    type_into(&mut app, "and", "pier 44");
    assert!(
        app.status().is_some_and(|s| s
            .text
            .contains("no obstacle is named 'pier 44' (did you mean 'pier 4'?)")),
        "{:?}",
        app.status()
    );
    app.update(Action::Select(Item::Start));
    app.update(Action::AddVia);
    let point = app.mission().route.via[1].point.expect("a via point");
    assert_eq!(point.z, app.mission().route.start.z);
    // Off the viaduct (the view's centre is pier 4's).
    type_into(&mut app, "x (m)", "-40");
    type_into(&mut app, "y (m)", "40");
    let mut terminal = ratatui::Terminal::new(ratatui::backend::TestBackend::new(160, 48))
        .unwrap_or_else(|e| panic!("{e}"));
    terminal
        .draw(|frame| {
            skyform::tui::view::draw(frame, &app, std::time::Instant::now());
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let screen = terminal.backend().to_string();
    assert!(screen.contains("‖1") && screen.contains("⊙2"), "{screen}");
    app.update(Action::Delete);
    assert_eq!(app.mission().route.via.len(), 1);
    app.update(Action::Undo);
    assert_eq!(app.mission().route.via.len(), 2, "undo brings it back");
}
