//! The key table: every key of the main screen, when it applies and what
//! it does, as data. Dispatch (`input::key_action`), the help overlay, the
//! empty jobs panel and the README's table all read it, so a key cannot do
//! one thing and be documented as another; a test dispatches every binding
//! and checks that every key that does something is in the table.
//! Windows (prompts, the help itself) keep their few keys in `input.rs` and
//! show them in their own hint lines.

use std::borrow::Cow;
use std::sync::LazyLock;

use ratatui::crossterm::event::KeyCode;

use super::action::{Action, Focus, Pane};
use crate::pipelines::Kind;

/// A key press as the table states it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    /// A printable character (Shift is part of the character).
    Char(char),
    /// Ctrl and a character.
    Ctrl(char),
    /// Any other key, unmodified (Shift-Tab arrives as `BackTab`).
    Code(KeyCode),
    /// An arrow with Shift.
    Shift(KeyCode),
}

/// When a binding applies; besides, no window is open and no field is
/// being typed into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum When {
    Always,
    Focus(Focus),
    NotFocus(Focus),
    Pane(Pane),
    /// A find was kept (`/`, then Enter): its matches are stepped through.
    Found,
}

/// What a binding's condition reads of the screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Context {
    pub focus: Focus,
    pub pane: Pane,
    /// A kept find's matches are being stepped through.
    pub found: bool,
}

impl When {
    pub fn holds(self, at: Context) -> bool {
        match self {
            When::Always => true,
            When::Focus(f) => at.focus == f,
            When::NotFocus(f) => at.focus != f,
            When::Pane(p) => at.pane == p,
            When::Found => at.found,
        }
    }
}

/// One key and the action it sends when its condition holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Binding {
    pub key: Key,
    pub when: When,
    pub action: Action,
}

const fn bind(key: Key, when: When, action: Action) -> Binding {
    Binding { key, when, action }
}

/// One row of the help overlay and the README: its keys as shown, what they
/// do, and the bindings behind them (none for the mouse).
#[derive(Debug)]
pub struct KeyRow {
    pub group: &'static str,
    pub keys: Cow<'static, str>,
    pub help: &'static str,
    pub bindings: Vec<Binding>,
}

/// The first binding for `key` that holds in `at`; a Shift-arrow nothing
/// binds acts as the plain arrow.
pub fn lookup(key: Key, at: Context) -> Option<&'static Binding> {
    let find = |key: Key| {
        KEYS.iter()
            .flat_map(|row| &row.bindings)
            .find(|b| b.key == key && b.when.holds(at))
    };
    find(key).or_else(|| match key {
        Key::Shift(code) => find(Key::Code(code)),
        _ => None,
    })
}

/// The keys shown for `action` in the key table (`T` for the fleet's run).
pub fn keys_for(action: &Action) -> Option<&'static str> {
    KEYS.iter()
        .find(|row| row.bindings.iter().any(|b| &b.action == action))
        .map(|row| row.keys.as_ref())
}

/// Every key, grouped as the help overlay shows them. Earlier bindings win.
pub static KEYS: LazyLock<Vec<KeyRow>> = LazyLock::new(table);

/// The table: the designer's own keys, and each pipeline's run keys where
/// the Run group lists them (from its face: `Words::run_key`,
/// `Words::processes_key`).
///
/// Long (~380 lines) because it is the key table itself, as data: one row of
/// four short fields per key, in the order the help shows them.
fn table() -> Vec<KeyRow> {
    let mut rows = vec![
        KeyRow {
            group: "General",
            keys: "?".into(),
            help: "this help (↑ ↓ PgUp PgDn scroll it on a small screen)",
            bindings: vec![bind(Key::Char('?'), When::Always, Action::ToggleHelp)],
        },
        KeyRow {
            group: "General",
            keys: "q  Ctrl-c".into(),
            help: "quit (asks when there are unsaved changes)",
            bindings: vec![
                bind(Key::Char('q'), When::Always, Action::Quit),
                bind(Key::Ctrl('c'), When::Always, Action::Quit),
            ],
        },
        KeyRow {
            group: "General",
            keys: "Tab  Shift-Tab".into(),
            help: "focus map → inspector → jobs",
            bindings: vec![
                bind(Key::Code(KeyCode::Tab), When::Always, Action::FocusNext),
                bind(
                    Key::Code(KeyCode::BackTab),
                    When::Always,
                    Action::FocusPrevious,
                ),
            ],
        },
        KeyRow {
            group: "General",
            keys: "1  2".into(),
            help: "map / formation editor",
            bindings: vec![
                bind(
                    Key::Char('1'),
                    When::NotFocus(Focus::Inspector),
                    Action::ShowMap,
                ),
                bind(
                    Key::Char('2'),
                    When::NotFocus(Focus::Inspector),
                    Action::ShowFormation,
                ),
            ],
        },
        KeyRow {
            group: "General",
            keys: "v".into(),
            help: "side view: distance along the path vs altitude",
            bindings: vec![bind(Key::Char('v'), When::Always, Action::ToggleSideView)],
        },
        KeyRow {
            group: "General",
            keys: "u  Ctrl-z".into(),
            help: "undo",
            bindings: vec![
                bind(Key::Char('u'), When::Always, Action::Undo),
                bind(Key::Ctrl('z'), When::Always, Action::Undo),
            ],
        },
        KeyRow {
            group: "General",
            keys: "Ctrl-r  Ctrl-y".into(),
            help: "redo",
            bindings: vec![
                bind(Key::Ctrl('r'), When::Always, Action::Redo),
                bind(Key::Ctrl('y'), When::Always, Action::Redo),
            ],
        },
        KeyRow {
            group: "General",
            keys: "Ctrl-s".into(),
            help: "save (atomic, into your file)",
            bindings: vec![bind(Key::Ctrl('s'), When::Always, Action::Save)],
        },
        KeyRow {
            group: "General",
            keys: "W".into(),
            help: "save as (Ctrl-u clears the name)",
            bindings: vec![bind(Key::Char('W'), When::Always, Action::SaveAs)],
        },
        KeyRow {
            group: "General",
            keys: "o".into(),
            help: "open (type to filter the list or give any path)",
            bindings: vec![bind(Key::Char('o'), When::Always, Action::Open)],
        },
        KeyRow {
            group: "General",
            keys: "I".into(),
            help: "import obstacles from a site survey (GeoJSON, KML, KMZ): one undo step",
            bindings: vec![bind(Key::Char('I'), When::Always, Action::Import)],
        },
        KeyRow {
            group: "Select & move",
            keys: "/".into(),
            help: "find an obstacle or IWP by name: type part of it, ↑ ↓ choose, Enter selects it (the map pans to it), Esc cancels",
            bindings: vec![bind(Key::Char('/'), When::Always, Action::Find)],
        },
        KeyRow {
            group: "Select & move",
            keys: "n  N  p".into(),
            help: "after a find: next / previous match (Esc ends the find)",
            bindings: vec![
                bind(Key::Char('n'), When::Found, Action::FindStep(1)),
                bind(Key::Char('N'), When::Found, Action::FindStep(-1)),
                bind(Key::Char('p'), When::Found, Action::FindStep(-1)),
            ],
        },
        KeyRow {
            group: "Select & move",
            keys: "n  p".into(),
            help: "next / previous item (map: mission, bounds, start, goal, obstacles, θ-PSO; formation: slots, IWPs)",
            bindings: vec![
                bind(Key::Char('n'), When::Always, Action::SelectNext),
                bind(Key::Char('p'), When::Always, Action::SelectPrevious),
            ],
        },
        KeyRow {
            group: "Select & move",
            keys: "← → ↑ ↓".into(),
            help: "nudge the selection one step (map & formation focus)",
            bindings: vec![
                bind(
                    Key::Code(KeyCode::Left),
                    When::Focus(Focus::Map),
                    Action::Nudge(-1.0, 0.0),
                ),
                bind(
                    Key::Code(KeyCode::Right),
                    When::Focus(Focus::Map),
                    Action::Nudge(1.0, 0.0),
                ),
                bind(
                    Key::Code(KeyCode::Up),
                    When::Focus(Focus::Map),
                    Action::Nudge(0.0, 1.0),
                ),
                bind(
                    Key::Code(KeyCode::Down),
                    When::Focus(Focus::Map),
                    Action::Nudge(0.0, -1.0),
                ),
            ],
        },
        KeyRow {
            group: "Select & move",
            keys: "↑  ↓".into(),
            help: "inspector: previous / next field; jobs: previous / next job",
            bindings: vec![
                bind(
                    Key::Code(KeyCode::Up),
                    When::Focus(Focus::Jobs),
                    Action::JobUp,
                ),
                bind(
                    Key::Code(KeyCode::Down),
                    When::Focus(Focus::Jobs),
                    Action::JobDown,
                ),
                bind(Key::Code(KeyCode::Up), When::Always, Action::FieldUp),
                bind(Key::Code(KeyCode::Down), When::Always, Action::FieldDown),
            ],
        },
        KeyRow {
            group: "Select & move",
            keys: "[  ]".into(),
            help: "smaller / larger nudge step",
            bindings: vec![
                bind(Key::Char('['), When::Always, Action::ChangeStep(-1)),
                bind(Key::Char(']'), When::Always, Action::ChangeStep(1)),
            ],
        },
        KeyRow {
            group: "Select & move",
            keys: "+  -  0".into(),
            help: "zoom in / out / fit",
            bindings: vec![
                bind(Key::Char('+'), When::Always, Action::Zoom(1.25, None)),
                bind(Key::Char('='), When::Always, Action::Zoom(1.25, None)),
                bind(
                    Key::Char('-'),
                    When::NotFocus(Focus::Inspector),
                    Action::Zoom(0.8, None),
                ),
                bind(
                    Key::Char('0'),
                    When::NotFocus(Focus::Inspector),
                    Action::Fit,
                ),
            ],
        },
        KeyRow {
            group: "Select & move",
            keys: "Shift-arrows".into(),
            help: "pan the map",
            bindings: vec![
                bind(
                    Key::Shift(KeyCode::Left),
                    When::Pane(Pane::Map),
                    Action::Pan(-0.1, 0.0),
                ),
                bind(
                    Key::Shift(KeyCode::Right),
                    When::Pane(Pane::Map),
                    Action::Pan(0.1, 0.0),
                ),
                bind(
                    Key::Shift(KeyCode::Up),
                    When::Pane(Pane::Map),
                    Action::Pan(0.0, 0.1),
                ),
                bind(
                    Key::Shift(KeyCode::Down),
                    When::Pane(Pane::Map),
                    Action::Pan(0.0, -0.1),
                ),
            ],
        },
        KeyRow {
            group: "Select & move",
            keys: "mouse".into(),
            help: "click selects, drag moves, wheel zooms",
            bindings: vec![],
        },
        KeyRow {
            group: "Edit",
            keys: "a".into(),
            help: "add an obstacle at the view's centre (formation: add a slot)",
            bindings: vec![
                bind(
                    Key::Char('a'),
                    When::Pane(Pane::Map),
                    Action::AddObstacle(None),
                ),
                bind(Key::Char('a'), When::Pane(Pane::Formation), Action::AddSlot),
            ],
        },
        KeyRow {
            group: "Edit",
            keys: "A".into(),
            help: "add tool: click an empty spot to place an obstacle",
            bindings: vec![bind(Key::Char('A'), When::Always, Action::ToggleAddTool)],
        },
        KeyRow {
            group: "Edit",
            keys: "d".into(),
            help: "duplicate the selected obstacle (a vertex: add one halfway to the next)",
            bindings: vec![bind(Key::Char('d'), When::Always, Action::Duplicate)],
        },
        KeyRow {
            group: "Edit",
            keys: "c".into(),
            help: "a footprint's corners: select its first vertex (n/p step, arrows or drag move, d adds, Del deletes), again back to the footprint",
            bindings: vec![bind(Key::Char('c'), When::Always, Action::ToggleVertices)],
        },
        KeyRow {
            group: "Edit",
            keys: "g".into(),
            help: "route via: a gate by the selected obstacle, else a point",
            bindings: vec![bind(Key::Char('g'), When::Pane(Pane::Map), Action::AddVia)],
        },
        KeyRow {
            group: "Edit",
            keys: "i".into(),
            help: "inspect the selected obstacle (eq. 8) or stop inspecting it",
            bindings: vec![bind(Key::Char('i'), When::Always, Action::ToggleInspect)],
        },
        KeyRow {
            group: "Edit",
            keys: "Del  D".into(),
            help: "delete the selected obstacle / vertex / slot / IWP choice",
            bindings: vec![
                bind(Key::Code(KeyCode::Delete), When::Always, Action::Delete),
                bind(Key::Char('D'), When::Always, Action::Delete),
            ],
        },
        KeyRow {
            group: "Edit",
            keys: "Enter".into(),
            help: "edit the field (inspector); type a number to replace it; Enter applies",
            bindings: vec![bind(
                Key::Code(KeyCode::Enter),
                When::NotFocus(Focus::Jobs),
                Action::EditStart(None),
            )],
        },
        KeyRow {
            group: "Edit",
            keys: "Esc".into(),
            help: "cancel typing, close a window, end a find, leave the add tool",
            bindings: vec![bind(Key::Code(KeyCode::Esc), When::Always, Action::Dismiss)],
        },
        KeyRow {
            group: "Formation",
            keys: "P".into(),
            help: "apply the next preset: triangle, line abreast, column, V, diamond",
            bindings: vec![bind(Key::Char('P'), When::Always, Action::CyclePreset)],
        },
        KeyRow {
            group: "Formation",
            keys: "s  Space".into(),
            help: "cycle the IWP's shape / enable or disable it",
            bindings: vec![
                bind(Key::Char('s'), When::Always, Action::CycleShape),
                bind(Key::Char(' '), When::Always, Action::ToggleWaypoint),
            ],
        },
    ];
    rows.extend(Kind::ALL.into_iter().map(run_row));
    rows.extend([
        KeyRow {
            group: "Run",
            keys: "L".into(),
            help: "live planning on / off: the plan follows every edit (θ-PSO, or FLATLO when shown)",
            bindings: vec![bind(Key::Char('L'), When::Always, Action::ToggleLive)],
        },
        KeyRow {
            group: "Run",
            keys: "G".into(),
            help: "flight check of the plan on the map, live or not ([flight])",
            bindings: vec![bind(Key::Char('G'), When::Always, Action::FlightCheck)],
        },
    ]);
    rows.extend(Kind::ALL.into_iter().filter_map(processes_row));
    rows.extend([
        KeyRow {
            group: "Run",
            keys: ",  .  >".into(),
            help: "fleet replay: back / forward one second, play or pause",
            bindings: vec![
                bind(Key::Char(','), When::Always, Action::Scrub(-1.0)),
                bind(
                    Key::Char('.'),
                    When::NotFocus(Focus::Inspector),
                    Action::Scrub(1.0),
                ),
                bind(Key::Char('>'), When::Always, Action::TogglePlay),
            ],
        },
        KeyRow {
            group: "Run",
            keys: "N".into(),
            help: "re-run the last pipeline with a new seed",
            bindings: vec![bind(Key::Char('N'), When::Always, Action::RunNewSeed)],
        },
        KeyRow {
            group: "Run",
            keys: "x".into(),
            help: "cancel the selected (or latest) running job",
            bindings: vec![bind(Key::Char('x'), When::Always, Action::Cancel)],
        },
        KeyRow {
            group: "Run",
            keys: "Enter".into(),
            help: "jobs focus: show that job's result on the map",
            bindings: vec![bind(
                Key::Code(KeyCode::Enter),
                When::Focus(Focus::Jobs),
                Action::ShowJob,
            )],
        },
        KeyRow {
            group: "Run",
            keys: "e".into(),
            help: "record runs to .rrd beside the mission (on / off)",
            bindings: vec![bind(Key::Char('e'), When::Always, Action::ToggleRecording)],
        },
        KeyRow {
            group: "Run",
            keys: "E".into(),
            help: "Rerun viewer: off, connect, spawn",
            bindings: vec![bind(Key::Char('E'), When::Always, Action::CycleViewer)],
        },
        KeyRow {
            group: "Run",
            keys: "X".into(),
            help: "export the shown result per vehicle (.plan, .waypoints, CSV) and a .kml to <mission>-export/",
            bindings: vec![bind(Key::Char('X'), When::Always, Action::Export)],
        },
    ]);
    rows
}

/// `kind`'s run key: runs it with the mission's seed.
fn run_row(kind: Kind) -> KeyRow {
    let (key, help) = kind.face().words().run_key;
    KeyRow {
        group: "Run",
        keys: key.to_string().into(),
        help,
        bindings: vec![bind(Key::Char(key), When::Always, Action::Run(kind))],
    }
}

/// `kind`'s key that runs it as agent processes, for one that flies so.
fn processes_row(kind: Kind) -> Option<KeyRow> {
    let (key, help) = kind.face().words().processes_key?;
    Some(KeyRow {
        group: "Run",
        keys: key.to_string().into(),
        help,
        bindings: vec![bind(
            Key::Char(key),
            When::Always,
            Action::RunDistributed(kind),
        )],
    })
}
