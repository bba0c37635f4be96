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
//! - `live/orchard_nudge_1m` (issue 51): a tree beside the route of
//!   `tests/all/sites/orchard.rs` (200 trees, twelve UAVs in a 4 × 3 grid)
//!   nudged 1 m east and back, with live planning on by default. Target:
//!   median ≤ 100 ms.
//! - `live/flatlo_spacing`: FLATLO's paper case, Δ_d typed in alternately
//!   18,300 and 18,400 m. Target: median ≤ 60 ms.
//! - `live/validate_bridge`: the rules every run holds the bridge to
//!   (`mission::validate`), which a live re-plan checks again after the
//!   designer's own check of the edit (`outcome::diagnose`, also timed:
//!   `live/diagnose_bridge`): what validating once per revision would save
//!   of `bridge_nudge_1m` (issue 38).
//!
//! Criterion's figure is the mean per edit over a sample; the median and
//! p95 over every edit of the run are printed at the end of each group.

#[path = "../tests/all/sites/orchard.rs"]
mod orchard;

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

/// The designer on `m`, live planning on by default (asserted) and its
/// first plan in, with `obstacle`'s index.
fn live_app(m: mission::Mission, obstacle: &str) -> (App, usize) {
    let k = m
        .obstacles
        .iter()
        .position(|o| o.name == obstacle)
        .unwrap_or_else(|| panic!("'{}' has an obstacle '{obstacle}'", m.name));
    let name = m.name.clone();
    let mut app = App::new(Document::new(m, None), std::env::temp_dir());
    app.enable_live();
    assert!(app.board().live().is_on(), "{name} is planned live");
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

/// `obstacle` nudged 1 m east, then back west, and so on: the time from
/// each nudge to its plan.
fn nudges(c: &mut Criterion, name: &str, app: &mut App, k: usize, samples: usize) {
    let cold = app
        .board()
        .live()
        .latest()
        .map(|j| j.elapsed(Instant::now()));
    app.update(Action::Select(Item::Obstacle(k)));
    let mut all = Vec::new();
    let mut east = true;
    let mut group = c.benchmark_group("live");
    group.sample_size(samples);
    group.bench_function(name, |b| {
        b.iter_custom(|iterations| {
            (0..iterations)
                .map(|_| {
                    let step = if east { 1.0 } else { -1.0 };
                    east = !east;
                    let took = edit_and_settle(app, Action::Nudge(step, 0.0));
                    all.push(took);
                    took
                })
                .sum()
        })
    });
    report(&format!("live/{name}"), all, cold);
    group.finish();
}

fn bridge(c: &mut Criterion) {
    let (mut app, k) = live_app(mission::default_mission().mission, "pier 3");
    nudges(c, "bridge_nudge_1m", &mut app, k, 50);
    let mut all = Vec::new();
    let mut group = c.benchmark_group("live");

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
    app.update(Action::Select(Item::Section(
        skyform::pipelines::Kind::Flatlo,
    )));
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

/// Issue 51: live planning on by default for a site of 200 obstacles and
/// twelve UAVs; the tree of the middle row nearest the route nudged.
fn orchard(c: &mut Criterion) {
    let m = orchard::orchard(1);
    let near_route = m
        .obstacles
        .iter()
        .filter(|o| o.name.starts_with("tree 5."))
        .min_by(|a, b| {
            (a.center.y - 81.0)
                .abs()
                .total_cmp(&(b.center.y - 81.0).abs())
        })
        .map(|o| o.name.clone())
        .unwrap_or_else(|| panic!("the orchard has a fifth row"));
    let (mut app, k) = live_app(m, &near_route);
    nudges(c, "orchard_nudge_1m", &mut app, k, 20);
}

fn validation(c: &mut Criterion) {
    let m = mission::default_mission().mission;
    let mut group = c.benchmark_group("live");
    group.bench_function("validate_bridge", |b| {
        b.iter(|| skyform::mission::validate(std::hint::black_box(&m)))
    });
    group.bench_function("diagnose_bridge", |b| {
        b.iter(|| skyform::outcome::diagnose::diagnose(std::hint::black_box(&m)))
    });
    group.finish();
}

criterion_group!(benches, bridge, orchard, flatlo, validation);
criterion_main!(benches);
