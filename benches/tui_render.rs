//! TUI drawing speed: one full frame of a 200-obstacle mission with a
//! planned result, at 200×60 cells. Target (issue 5): ≤ 2 ms per frame.
//! And the help overlay at 140×40, whose two columns are balanced on
//! every frame (issue 38).

use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use skyform::mission::default_mission;
use skyform::tui::fixtures::{app_with_result, crowded_mission};
use skyform::tui::{Action, App, Document, view};

fn full_frame(c: &mut Criterion) {
    // A plan on the map, not the best one: 20 iterations of the swarm.
    let mut mission = crowded_mission(200);
    mission.theta_pso.iterations = 20;
    let app = app_with_result(mission, 3);
    assert!(
        app.shown().and_then(|j| j.outcome.as_ref()).is_some(),
        "the frame must show a result"
    );
    bench_frame(c, "tui/frame_200_obstacles_200x60", &app, (200, 60));
}

fn help_overlay(c: &mut Criterion) {
    let mut app = App::new(
        Document::new(default_mission().mission, None),
        std::path::PathBuf::from("/missions"),
    );
    app.update(Action::ToggleHelp);
    bench_frame(c, "tui/help_overlay_140x40", &app, (140, 40));
}

/// One whole frame of `app` drawn on a `width` × `height` test terminal.
fn bench_frame(c: &mut Criterion, name: &str, app: &App, (width, height): (u16, u16)) {
    let mut terminal = Terminal::new(TestBackend::new(width, height)).expect("test backend");
    let now = Instant::now();
    c.bench_function(name, |b| {
        b.iter(|| {
            terminal
                .draw(|frame| {
                    view::draw(frame, app, now);
                })
                .map(|_| ())
        })
    });
}

criterion_group!(benches, full_frame, help_overlay);
criterion_main!(benches);
