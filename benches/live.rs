//! Live planning (issue 27): the designer's state driven by its own actions,
//! with real background runs, from the edit to the new plan in the state
//! (the debounce included), as the designer's loop does it
//! (`App::settle_live`).
//!
//! - `live/bridge_nudge_1m`: one obstacle of the bridge (pier 3, beside the
//!   route) nudged 1 m east, then back west, and so on. Target: median ≤ 60
//!   ms, p95 ≤ 150 ms. The cold run (the first live plan) is printed beside.
//! - `live/bridge_drag_20_steps`: pier 3 dragged over 20 steps of 0.25 m, a
//!   step every 16 ms (a 60 Hz mouse); the time from the last step to the
//!   plan of the final position. Target ≤ 150 ms, and never more than one
//!   run at work (a superseded one winding down aside).
//! - `live/flatlo_spacing`: FLATLO's paper case, Δ_d typed in alternately
//!   18,300 and 18,400 m. Target: median ≤ 60 ms.
//! - `live/validate_bridge`: the rules every run holds the bridge to
//!   (`pipelines::validate`), which a live re-plan checks again after the
//!   designer's own check of the edit (`outcome::diagnose`, also timed:
//!   `live/diagnose_bridge`): what validating once per revision would save
//!   of `bridge_nudge_1m` (issue 38).
//!
//! Criterion's figure is the mean per edit over a sample; the median and
//! p95 over every edit of the run are printed at the end of each group.

use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use skyform::mission;
use skyform::pipelines::Kind;
use skyform::tui::action::Action;
use skyform::tui::app::App;
use skyform::tui::document::Document;
use skyform::tui::fields::Item;
use skyform::tui::fixtures::type_into;

const SETTLE: Duration = Duration::from_secs(30);

fn bridge_app() -> (App, usize) {
    let m = mission::default_mission().mission;
    let k = m
        .obstacles
        .iter()
        .position(|o| o.name == "pier 3")
        .unwrap_or_else(|| panic!("the bridge has a pier 3"));
    let mut app = App::new(Document::new(m, None), std::env::temp_dir());
    app.enable_live();
    assert!(app.board().live().is_on(), "the bridge is planned live");
    assert!(app.settle_live(SETTLE));
    (app, k)
}

/// The plans that came in, and the time the last edit took to give one.
fn edit_and_settle(app: &mut App, action: Action) -> Duration {
    let before = app.board().live().revision();
    let started = Instant::now();
    app.update(action);
    assert!(app.settle_live(SETTLE), "live planning settles");
    assert_eq!(app.board().live().revision(), before + 1, "one new plan");
    started.elapsed()
}

fn report(name: &str, mut all: Vec<Duration>, cold: Option<Duration>) {
    // A filter (`-- bridge_nudge`) leaves the other groups without edits.
    if all.is_empty() {
        return;
    }
    all.sort();
    let at = |q: f64| all[((all.len() - 1) as f64 * q).round() as usize].as_secs_f64() * 1e3;
    eprintln!(
        "{name}: {} edits, median {:.1} ms, p95 {:.1} ms, max {:.1} ms{}",
        all.len(),
        at(0.5),
        at(0.95),
        at(1.0),
        cold.map_or_else(String::new, |c| format!(
            "; the cold plan took {:.1} ms",
            c.as_secs_f64() * 1e3
        ))
    );
}

fn bridge(c: &mut Criterion) {
    let (mut app, k) = bridge_app();
    let cold = app
        .board()
        .live()
        .latest()
        .map(|j| j.elapsed(Instant::now()));
    app.update(Action::Select(Item::Obstacle(k)));
    let mut all = Vec::new();
    let mut east = true;
    let mut group = c.benchmark_group("live");
    group.sample_size(50);
    group.bench_function("bridge_nudge_1m", |b| {
        b.iter_custom(|iterations| {
            (0..iterations)
                .map(|_| {
                    let step = if east { 1.0 } else { -1.0 };
                    east = !east;
                    let took = edit_and_settle(&mut app, Action::Nudge(step, 0.0));
                    all.push(took);
                    took
                })
                .sum()
        })
    });
    report("live/bridge_nudge_1m", std::mem::take(&mut all), cold);

    // The drag: 20 steps of 0.25 m, one every 16 ms, then the plan.
    let start = {
        let o = &app.mission().obstacles[k];
        o.center
    };
    let mut outward = true;
    let mut most = 0;
    group.sample_size(10);
    group.bench_function("bridge_drag_20_steps", |b| {
        b.iter_custom(|iterations| {
            (0..iterations)
                .map(|_| {
                    let sign = if outward { 1.0 } else { -1.0 };
                    let from = if outward {
                        start
                    } else {
                        start + nalgebra::Vector2::new(5.0, 0.0)
                    };
                    outward = !outward;
                    app.update(Action::DragStart(Item::Obstacle(k), from));
                    for s in 1..=20 {
                        let at = from + nalgebra::Vector2::new(sign * 0.25 * s as f64, 0.0);
                        let step_end = Instant::now() + Duration::from_millis(16);
                        app.update(Action::DragTo(at));
                        // The loop runs while the mouse moves.
                        while Instant::now() < step_end {
                            if app.wake_at().is_some_and(|t| t <= Instant::now()) {
                                app.poll_live(Instant::now());
                            }
                            app.drain_job_messages();
                            std::thread::sleep(Duration::from_millis(1));
                        }
                    }
                    let last = Instant::now();
                    app.update(Action::DragEnd);
                    assert!(app.settle_live(SETTLE));
                    let final_spot = app.mission().obstacles[k].center;
                    let planned = app
                        .board()
                        .live()
                        .latest()
                        .map(|j| j.mission.obstacles[k].center);
                    assert_eq!(
                        planned,
                        Some(final_spot),
                        "the plan is of the final position"
                    );
                    most = most.max(app.board().live().most_running());
                    let took = last.elapsed();
                    all.push(took);
                    took
                })
                .sum()
        })
    });
    report("live/bridge_drag_20_steps", std::mem::take(&mut all), None);
    eprintln!(
        "live/bridge_drag_20_steps: at most {most} live run(s) at once (one at work, any other winding down)"
    );
    assert!(most <= 2, "{most} live runs at once");
    group.finish();
}

fn flatlo(c: &mut Criterion) {
    let text = include_str!("../missions/flatlo-squadron.toml");
    let m = mission::parse_str(text, "flatlo-squadron.toml")
        .map(|l| l.mission)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut app = App::new(Document::new(m, None), std::env::temp_dir());
    app.update(Action::Select(Item::Squadron));
    assert!(app.start_live(Kind::Flatlo).is_ok());
    assert!(app.settle_live(SETTLE));
    let cold = app
        .board()
        .live()
        .latest()
        .map(|j| j.elapsed(Instant::now()));
    let label = app
        .fields()
        .iter()
        .map(|f| f.label().to_owned())
        .find(|l| l.starts_with("Δ") || l.contains("spacing"))
        .unwrap_or_else(|| panic!("a spacing field among {:?}", app.fields()));
    let mut all = Vec::new();
    let mut wide = true;
    let mut group = c.benchmark_group("live");
    group.sample_size(50);
    group.bench_function("flatlo_spacing", |b| {
        b.iter_custom(|iterations| {
            (0..iterations)
                .map(|_| {
                    let value = if wide { "18400" } else { "18300" };
                    wide = !wide;
                    let before = app.board().live().revision();
                    let started = Instant::now();
                    type_into(&mut app, &label, value);
                    assert!(app.settle_live(SETTLE));
                    assert_eq!(app.board().live().revision(), before + 1);
                    let took = started.elapsed();
                    all.push(took);
                    took
                })
                .sum()
        })
    });
    report("live/flatlo_spacing", all, cold);
    group.finish();
}

fn validation(c: &mut Criterion) {
    let m = mission::default_mission().mission;
    let mut group = c.benchmark_group("live");
    group.bench_function("validate_bridge", |b| {
        b.iter(|| skyform::pipelines::validate(std::hint::black_box(&m)))
    });
    group.bench_function("diagnose_bridge", |b| {
        b.iter(|| skyform::outcome::diagnose::diagnose(std::hint::black_box(&m)))
    });
    group.finish();
}

criterion_group!(benches, bridge, flatlo, validation);
criterion_main!(benches);
