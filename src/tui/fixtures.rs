//! Ready-made app states for the TUI's tests and render benchmark.

use std::path::PathBuf;
use std::time::Instant;

use nalgebra::{Point2, Point3};

use super::action::{Action, Focus};
use super::app::App;
use super::document::Document;
use super::jobs::{Job, JobError, JobMsg, Kind};
use crate::mission::{self, Mission, Obstacle};
use crate::pipelines::{CancelToken, PlanOptions, Silent};

/// A 400 m × 400 m field with `n` small posts on a jittered grid, clear of
/// the start and goal corners: a stress case for drawing.
pub fn crowded_mission(n: usize) -> Mission {
    let mut m = mission::default_mission().mission;
    m.name = format!("{n} posts");
    m.bounds.x = [0.0, 400.0];
    m.bounds.y = [0.0, 400.0];
    m.route.start = Point3::new(10.0, 10.0, 10.0);
    m.route.goal = Point3::new(390.0, 390.0, 10.0);
    m.reconfiguration.waypoints.clear();
    let side = (n as f64).sqrt().ceil() as usize;
    let pitch = 340.0 / side as f64;
    m.obstacles = (0..n)
        .map(|k| {
            let (i, j) = (k % side, k / side);
            let wobble = ((k * 7919) % 13) as f64 / 13.0 - 0.5;
            Obstacle {
                name: format!("post {}", k + 1),
                center: Point2::new(
                    30.0 + (i as f64 + 0.5) * pitch + wobble * 3.0,
                    30.0 + (j as f64 + 0.5) * pitch,
                ),
                radius: 1.0 + ((k * 31) % 5) as f64 * 0.3,
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
            }
        })
        .collect();
    m
}

/// The bridge with 114 oaks in six rows north of the route (7 m apart: no
/// gap among them is an IWP) and three masts south of it: a survey's
/// 126 obstacles (issue 36).
pub fn bridge_with_oaks() -> Mission {
    bridge_with_oak_rows(6)
}

/// The bridge with `rows` rows of 19 oaks north of the route, the site
/// stretched north to hold them, and three masts south of it: with 11 rows,
/// 221 obstacles, over live planning's 200 (issue 51).
pub fn bridge_with_oak_rows(rows: usize) -> Mission {
    let mut m = mission::default_mission().mission;
    m.name = "Bridge among oaks".into();
    let tree = |name: String, x: f64, y: f64, kind: &str| Obstacle {
        name,
        center: Point2::new(x, y),
        radius: 0.5,
        height: 12.0,
        footprint: Vec::new(),
        base: 0.0,
        overfly: true,
        clearance_above: 0.0,
        kind: Some(kind.into()),
        inspect: false,
        stand_off: None,
        description: None,
        wire: None,
        inspect_side: None,
    };
    for k in 0..19 * rows {
        let (column, row) = (k % 19, k / 19);
        let (x, y) = (5.0 + 7.0 * column as f64, 62.0 + 7.0 * row as f64);
        m.obstacles
            .push(tree(format!("oak {}", k + 1), x, y, "tree"));
    }
    m.bounds.y[1] = m.bounds.y[1].max(61.0 + 7.0 * rows as f64);
    for (k, x) in [30.0, 60.0, 100.0].into_iter().enumerate() {
        m.obstacles
            .push(tree(format!("mast {}", k + 1), x, 10.0, "mast"));
    }
    m
}

/// An app on `mission`, opened from `file`, whose map shows a finished
/// `kind` run with `seed`, planned synchronously through its face.
pub fn app_with_run(kind: Kind, mission: Mission, seed: u64, file: &str) -> App {
    let options = PlanOptions::default();
    let outcome = crate::outcome::run(
        kind,
        &mission,
        seed,
        options,
        &mut Silent,
        &CancelToken::new(),
    );
    let mut app = App::new(
        Document::new(mission.clone(), Some(PathBuf::from(file))),
        PathBuf::from("."),
    );
    let started = Instant::now();
    app.adopt_job(Job::new(1, kind, seed, mission, started));
    app.on_job_msg(JobMsg::Done(1, outcome.map_err(JobError::from)), started);
    app
}

/// An app on `mission` whose map shows a finished run of the designer's
/// default pipeline with seed `seed`.
pub fn app_with_result(mission: Mission, seed: u64) -> App {
    app_with_run(Kind::default(), mission, seed, "mission.toml")
}

/// Types `text` into the selected item's field labelled `label` and applies
/// it, by actions as a user would (focus, arrows, typing, Enter).
pub fn type_into(app: &mut App, label: &str, text: &str) {
    let Some(k) = app.fields().iter().position(|f| f.label() == label) else {
        panic!(
            "no field {label} among {:?} of {:?}",
            app.fields(),
            app.selected()
        );
    };
    app.update(Action::FocusOn(Focus::Inspector));
    while app.editor().field() > k {
        app.update(Action::FieldUp);
    }
    while app.editor().field() < k {
        app.update(Action::FieldDown);
    }
    let mut chars = text.chars();
    app.update(Action::EditStart(chars.next()));
    for c in chars {
        app.update(Action::EditInput(c));
    }
    app.update(Action::EditCommit);
}
