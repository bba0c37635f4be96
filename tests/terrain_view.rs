//! The designer over terrain (issue 15): the SPSO benchmark mission opens,
//! and its side view draws the ground profile under the path with the band
//! above it.

use std::path::PathBuf;
use std::time::Instant;

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use skyform::tui::{Action, App, Document, view};

fn benchmark_app() -> App {
    let path = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/missions/spso-benchmark.toml"
    ));
    let mission = skyform::mission::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    assert!(mission.height_map().is_some(), "the terrain loaded");
    // A relative name, so the status bar (and the snapshot) is the same anywhere.
    let shown = PathBuf::from("missions/spso-benchmark.toml");
    App::new(
        Document::new(mission, Some(shown)),
        PathBuf::from("/missions"),
    )
}

fn render(app: &App) -> String {
    let mut terminal = Terminal::new(TestBackend::new(140, 42)).expect("terminal");
    terminal
        .draw(|frame| view::draw(frame, app, Instant::now()))
        .expect("draw");
    terminal.backend().to_string()
}

#[test]
fn the_side_view_draws_the_ground_under_the_path() {
    let mut app = benchmark_app();
    let top = render(&app);
    assert!(top.contains("spso-benchmark.toml"), "{top}");
    app.update(Action::ToggleSideView);
    let side = render(&app);
    assert!(side.contains("Side view"), "{side}");
    assert!(side.contains("ground"), "{side}");
    insta::assert_snapshot!(side);
}
