//! The designer over terrain (issue 15): the SPSO benchmark mission opens,
//! and its side view draws the ground profile under the path with the band
//! above it.

use std::path::PathBuf;
use std::time::Instant;

use ratatui::Terminal;
use ratatui::backend::TestBackend;
use skyform::tui::fixtures::type_into;
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
        .draw(|frame| {
            view::draw(frame, app, Instant::now());
        })
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

/// Issue 15: the map shades the terrain (colour by height under the braille
/// layer): the cell over the highest ground is browner than the cell over
/// the lowest, cells off the map are not shaded, and the title gives the
/// range.
#[test]
fn the_map_shades_each_cell_by_the_ground_under_it() {
    use ratatui::style::Color;
    let app = benchmark_app();
    let mut terminal = Terminal::new(TestBackend::new(140, 42)).expect("terminal");
    let mut viewport = None;
    terminal
        .draw(|frame| {
            viewport = view::draw(frame, &app, Instant::now()).map(|d| d.canvas);
        })
        .expect("draw");
    let Some(vp) = viewport else {
        panic!("no map drawn");
    };
    let buffer = terminal.backend().buffer().clone();
    let map = app.mission().height_map().expect("terrain");
    let (mut lowest, mut highest) = ((f32::INFINITY, None), (f32::NEG_INFINITY, None));
    let mut shaded = std::collections::BTreeSet::new();
    for row in vp.inner.top()..vp.inner.bottom() {
        for column in vp.inner.left()..vp.inner.right() {
            let Some(p) = vp.to_world(column, row) else {
                continue;
            };
            let bg = buffer[(column, row)].bg;
            match map.nearest(p.x, p.y) {
                Some(h) => {
                    shaded.insert(format!("{bg:?}"));
                    if h < lowest.0 {
                        lowest = (h, Some(bg));
                    }
                    if h > highest.0 {
                        highest = (h, Some(bg));
                    }
                }
                None => assert_eq!(bg, Color::Reset, "off the map at ({column}, {row})"),
            }
        }
    }
    let red = |c: Option<Color>| match c {
        Some(Color::Rgb(r, _, _)) => r,
        other => panic!("not shaded: {other:?}"),
    };
    assert!(
        red(highest.1) > red(lowest.1) + 40,
        "{highest:?} vs {lowest:?}"
    );
    assert!(shaded.len() > 20, "only {} shades", shaded.len());
    assert!(render(&app).contains("ground 49–296 m"));
}

/// Issue 15: `[terrain]` in the inspector. Its keys are fields; a new file
/// is read at once, one that does not load is an error on `terrain.file`
/// and undo brings the map back.
#[test]
fn the_inspector_edits_the_terrain_and_reloads_its_map() {
    use skyform::base::terrain::Lookup;
    use skyform::tui::fields::Item;
    let mut app = benchmark_app();
    app.update(Action::Select(Item::Terrain));
    let fields = app.fields();
    let labels: Vec<&str> = fields.iter().map(|f| f.label()).collect();
    assert_eq!(
        labels,
        [
            "file",
            "origin x (m)",
            "origin y (m)",
            "pixel x (m)",
            "pixel y (m)",
            "lookup"
        ]
    );
    type_into(&mut app, "lookup", "bilinear");
    assert_eq!(
        app.mission().terrain.as_ref().map(|t| t.lookup),
        Some(Lookup::Bilinear)
    );
    type_into(&mut app, "lookup", "cubic");
    assert_eq!(
        app.mission().terrain.as_ref().map(|t| t.lookup),
        Some(Lookup::Bilinear)
    );

    type_into(&mut app, "file", "terrain/missing.tif");
    assert!(app.mission().height_map().is_none());
    let errors: Vec<String> = app
        .doc()
        .diagnostics()
        .iter()
        .map(|d| format!("{} {}", d.path, d.message))
        .collect();
    assert!(
        errors
            .iter()
            .any(|e| e.starts_with("terrain.file") && e.contains("missing.tif")),
        "{errors:?}"
    );
    assert!(render(&app).contains("missing.tif"));
    app.update(Action::Undo);
    assert!(
        app.mission().height_map().is_some(),
        "undo brings the map back"
    );
    assert_eq!(app.doc().error_count(), 0);
}
