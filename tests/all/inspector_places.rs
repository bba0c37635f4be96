//! Issue 24: every message a mission can carry is shown where the user
//! looks, under the field whose path it names.
//!
//! The missions: the shipped ones, and missions generated from them: every
//! numeric leaf of each (its defaults filled in) set to each of a few
//! extreme values, as `tests/all/extreme_values.rs` does, and a few structural
//! changes (obstacles deleted under an IWP choice, a duplicate name, no
//! slots, an unusable shape). For every diagnostic of every one of them,
//! some item of the designer shows it at a place whose path is the
//! diagnostic's: the field at that path, the group of fields that are that
//! array's elements, or the item at that path. For the first diagnostic of
//! each path, the inspector is drawn and the message must be on a line
//! below that field (or group), above the next field.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::Instant;

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use skyform::mission::{
    self, BUILTIN, Diagnostic, FieldPath, Mission, ShapeChoice, WaypointChoice,
};
use skyform::tui::fields::{self, Field, Item, Place};
use skyform::tui::{Action, App, Document, view};

const FLOATS: [f64; 7] = [0.0, -1.0, 1e-9, 1e9, 1e300, f64::NAN, f64::INFINITY];
const INTEGERS: [i64; 3] = [0, -1, 1 << 31];

/// A mission text and the file it is read as (terrain files are relative to it).
struct Source {
    text: String,
    file: PathBuf,
}

fn sources() -> Vec<Source> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out: Vec<Source> = BUILTIN
        .iter()
        .map(|b| Source {
            text: b.text.to_owned(),
            file: root.join("missions").join(b.file_name),
        })
        .collect();
    let spso = root.join("missions/spso-benchmark.toml");
    out.push(Source {
        text: std::fs::read_to_string(&spso).expect("the SPSO mission"),
        file: spso,
    });
    out
}

use crate::common::toml_leaves;
use toml_leaves::{leaf_mut, leaves};

/// The mission `text` (read as `file`), as the designer opens it: `None`
/// when it is not a mission at all (the designer refuses to open those).
fn opened(text: &str, file: &Path) -> Option<Mission> {
    let name = file.display().to_string();
    skyform::outcome::diagnose::check_text(text, Some(&name)).mission
}

/// Every generated mission: the shipped ones, each numeric leaf at each
/// extreme value, and the structural changes.
fn generated() -> Vec<(String, Mission, PathBuf)> {
    let mut out = Vec::new();
    for source in sources() {
        let Some(base) = opened(&source.text, &source.file) else {
            panic!("{} does not open", source.file.display());
        };
        let label = source.file.display().to_string();
        out.push((label.clone(), base.clone(), source.file.clone()));
        let tree = toml::Value::try_from(&base).expect("a TOML tree");
        let mut all = Vec::new();
        leaves(&tree, &mut Vec::new(), &mut all);
        for (at, integer) in all {
            let values: Vec<toml::Value> = if integer {
                INTEGERS.iter().map(|v| toml::Value::Integer(*v)).collect()
            } else {
                FLOATS.iter().map(|v| toml::Value::Float(*v)).collect()
            };
            for value in values {
                let mut t = tree.clone();
                *leaf_mut(&mut t, &at) = value.clone();
                let Ok(text) = toml::to_string(&t) else {
                    continue;
                };
                if let Some(m) = opened(&text, &source.file) {
                    out.push((format!("{label} {at:?} = {value}"), m, source.file.clone()));
                }
            }
        }
        for (what, m) in structural(&base) {
            out.push((format!("{label}: {what}"), m, source.file.clone()));
        }
    }
    out
}

/// Changes a user makes that numbers alone do not: deletions, names, shapes.
fn structural(base: &Mission) -> Vec<(&'static str, Mission)> {
    let mut out = Vec::new();
    let mut m = base.clone();
    m.obstacles.clear();
    m.reconfiguration.waypoints.push(WaypointChoice {
        between: ["light pole 4".into(), "pier 5".into()],
        enabled: true,
        shape: ShapeChoice::Alignment,
        scale: Some(0.6),
    });
    out.push(("obstacles deleted under an IWP choice", m));
    if base.obstacles.len() >= 2 {
        let mut m = base.clone();
        m.obstacles[1].name = m.obstacles[0].name.clone();
        out.push(("a duplicate obstacle name", m));
        let mut m = base.clone();
        m.obstacles[0].name = " ".into();
        m.obstacles[1].inspect = true;
        m.obstacles[1].height = 0.5;
        out.push(("an empty name, a short inspected obstacle", m));
    }
    let mut m = base.clone();
    m.formation.slots.clear();
    out.push(("no slots", m));
    let mut m = base.clone();
    m.name = String::new();
    m.route.goal = m.route.start;
    m.formation.slots.push(m.formation.slots[0]);
    out.push(("no name, the goal on the start, two slots on one spot", m));
    let mut m = base.clone();
    m.reconfiguration.default_shape = ShapeChoice::Shrink;
    for w in &mut m.reconfiguration.waypoints {
        w.shape = ShapeChoice::Shrink;
    }
    out.push(("shrink everywhere (unusable IWPs)", m));
    let mut m = base.clone();
    m.fleet.targets.reverse();
    out.push(("fleet targets out of order", m));
    out
}

/// Every item the designer lists for the app's mission (map and formation editor).
fn items(app: &App) -> Vec<Item> {
    let m = app.mission();
    let mut all = fields::map_items(m);
    for item in fields::formation_items(m, app.iwps()) {
        if !all.contains(&item) {
            all.push(item);
        }
    }
    all
}

/// The path of a place among `fields` of `item`, as the user reads it.
fn path_of(place: Place, item: &Item, m: &Mission, fields: &[Field]) -> Option<FieldPath> {
    match place {
        Place::Field(k) => Some(fields[k].path().clone()),
        Place::Group(a, b) => {
            // The elements' common array: each is that path with its index.
            let parent = FieldPath(fields[a].path().0[..fields[a].path().0.len() - 1].to_vec());
            let all = (a..=b).all(|k| {
                fields[k].path().starts_with(&parent)
                    && fields[k].path().0.len() == parent.0.len() + 1
            });
            all.then_some(parent)
        }
        Place::Item => item.path(m),
    }
}

/// The item and place that show `d` at its own path.
fn shown_at(app: &App, d: &Diagnostic) -> Option<(Item, Place)> {
    let m = app.mission();
    items(app).into_iter().find_map(|item| {
        let fields = fields::fields(&item, m);
        let (place, _) = fields::place(&item, m, &fields, &d.path)?;
        (path_of(place, &item, m, &fields).as_ref() == Some(&d.path)).then_some((item, place))
    })
}

/// Draws the designer with `item` selected on a screen tall enough for the
/// whole inspector; the inspector's rows.
fn inspector_rows(app: &mut App, item: &Item) -> Vec<String> {
    app.update(Action::Select(item.clone()));
    let (width, height) = (200, 160);
    let mut terminal = Terminal::new(TestBackend::new(width, height)).expect("a terminal");
    terminal
        .draw(|frame| {
            view::draw(frame, app, Instant::now());
        })
        .expect("drawn");
    let areas = view::layout(ratatui::layout::Rect::new(0, 0, width, height)).expect("room");
    let r = areas.inspector;
    let buffer = terminal.backend().buffer();
    (r.y..r.y + r.height)
        .map(|y| {
            (r.x..r.x + r.width)
                .map(|x| buffer[(x, y)].symbol().to_owned())
                .collect::<String>()
        })
        .collect()
}

#[test]
fn every_message_is_under_the_field_whose_path_it_names() {
    let started = Instant::now();
    let cwd = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut missions = 0;
    let mut messages = 0;
    let mut drawn: BTreeSet<String> = BTreeSet::new();
    let mut lost = Vec::new();
    for (label, m, file) in generated() {
        missions += 1;
        let mut app = App::new(Document::new(m, Some(file)), cwd.clone());
        let diagnostics = app.doc().diagnostics().to_vec();
        for d in &diagnostics {
            messages += 1;
            let Some((item, place)) = shown_at(&app, d) else {
                lost.push(format!("{label}: {}: {}", d.path, d.message));
                continue;
            };
            // Draw the first message of each path and find it under its field.
            if !drawn.insert(d.path.to_string()) {
                continue;
            }
            let rows = inspector_rows(&mut app, &item);
            let m = app.mission().clone();
            let fields = fields::fields(&item, &m);
            let label_row = |k: usize| {
                let wanted = format!("│{}  ", fields[k].label());
                rows.iter().position(|r| r.starts_with(&wanted))
            };
            let head: String = d.message.chars().take(24).collect();
            let at = rows.iter().position(|r| r.contains(&head));
            let (above, below) = match place.after() {
                Some(k) => (
                    label_row(k),
                    (k + 1 < fields.len()).then(|| label_row(k + 1)),
                ),
                None => (fields.len().checked_sub(1).and_then(label_row), None),
            };
            let ok = match (at, above) {
                (Some(at), Some(above)) => {
                    at > above && below.flatten().is_none_or(|next| at < next)
                }
                (Some(_), None) => fields.is_empty(),
                _ => false,
            };
            assert!(
                ok,
                "{label}: '{}: {}' is not drawn under its place {place:?} of {item:?}:\n{}",
                d.path,
                d.message,
                rows.join("\n")
            );
        }
    }
    eprintln!(
        "{missions} missions, {messages} messages, {} paths drawn, in {:.1} s",
        drawn.len(),
        started.elapsed().as_secs_f64()
    );
    assert!(missions > 1000, "{missions} missions");
    assert!(
        lost.is_empty(),
        "{} of {messages} messages have no place at their path, e.g.:\n{}",
        lost.len(),
        lost.iter()
            .collect::<BTreeSet<_>>()
            .into_iter()
            .take(40)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// The structural cases give the messages they are there for.
#[test]
fn the_generated_missions_reach_the_dangling_choice_and_the_unusable_shape() {
    let all: Vec<Diagnostic> = generated()
        .into_iter()
        .flat_map(|(_, m, _)| skyform::outcome::diagnose::diagnose(&m))
        .collect();
    let said = |path: &str, words: &str| {
        all.iter()
            .any(|d| d.path.to_string() == path && d.message.contains(words))
    };
    assert!(said(
        "reconfiguration.waypoints[0].between",
        "no obstacle named"
    ));
    assert!(all.iter().any(|d| d.message.contains("unusable")));
    assert!(said("bounds.x[1]", "local plane"));
    assert!(said("route.start[2]", "altitude band"));
    let _ = mission::BUILTIN;
}
