//! Keys and mouse events to actions. The main screen's keys are looked up
//! in the key table (`keys::KEYS`); windows and typing keep theirs here.

use ratatui::crossterm::event::{
    KeyCode, KeyEvent, KeyEventKind, KeyModifiers, MouseButton, MouseEvent, MouseEventKind,
};
use ratatui::layout::Position;

use super::action::Action;
use super::app::{App, Focus, Overlay, Pane};
use super::fields::Item;
use super::keys::{self, Key};
use super::view::Drawn;
use super::view::map::Viewport;
use super::view::viewport::formation_extent;

/// The action for a key press, given what is on screen.
pub fn key_action(app: &App, key: KeyEvent) -> Option<Action> {
    if key.kind == KeyEventKind::Release {
        return None;
    }
    let ctrl = key.modifiers.contains(KeyModifiers::CONTROL);
    let shift = key.modifiers.contains(KeyModifiers::SHIFT);
    if ctrl && key.code == KeyCode::Char('c') {
        return Some(Action::Quit);
    }
    if let Some(overlay) = app.overlay() {
        return overlay_key(overlay, key, ctrl);
    }
    if app.editor().editing().is_some() {
        return match key.code {
            KeyCode::Enter | KeyCode::Tab => Some(Action::EditCommit),
            KeyCode::Esc => Some(Action::EditCancel),
            KeyCode::Backspace => Some(Action::EditBackspace),
            KeyCode::Char('u') if ctrl => Some(Action::EditClear),
            KeyCode::Up => Some(Action::FieldUp),
            KeyCode::Down => Some(Action::FieldDown),
            KeyCode::Char(c) if !ctrl => Some(Action::EditInput(c)),
            _ => None,
        };
    }
    if app.finder().is_typing() {
        return find_key(key, ctrl);
    }
    let pressed = match key.code {
        KeyCode::Char(c) if ctrl => Key::Ctrl(c),
        KeyCode::Char(c) => Key::Char(c),
        code @ (KeyCode::Left | KeyCode::Right | KeyCode::Up | KeyCode::Down) if shift => {
            Key::Shift(code)
        }
        code => Key::Code(code),
    };
    let at = keys::Context {
        focus: app.focus(),
        pane: app.pane(),
        found: app.finder().is_stepping(),
    };
    if let Some(binding) = keys::lookup(pressed, at) {
        return Some(binding.action.clone());
    }
    // In the inspector a number typed over a field replaces it.
    match pressed {
        Key::Char(c)
            if app.focus() == Focus::Inspector && (c.is_ascii_digit() || c == '-' || c == '.') =>
        {
            Some(Action::EditStart(Some(c)))
        }
        _ => None,
    }
}

/// The find prompt's keys: letters type, the arrows choose among the
/// matches, Enter keeps the one chosen, Esc goes back.
fn find_key(key: KeyEvent, ctrl: bool) -> Option<Action> {
    match key.code {
        KeyCode::Enter => Some(Action::FindKeep),
        KeyCode::Esc => Some(Action::FindCancel),
        KeyCode::Backspace => Some(Action::FindBackspace),
        KeyCode::Down | KeyCode::Tab => Some(Action::FindStep(1)),
        KeyCode::Up | KeyCode::BackTab => Some(Action::FindStep(-1)),
        KeyCode::Char('u') if ctrl => Some(Action::FindClear),
        KeyCode::Char('n') if ctrl => Some(Action::FindStep(1)),
        KeyCode::Char('p') if ctrl => Some(Action::FindStep(-1)),
        KeyCode::Char(c) if !ctrl => Some(Action::FindInput(c)),
        _ => None,
    }
}

fn overlay_key(overlay: &Overlay, key: KeyEvent, ctrl: bool) -> Option<Action> {
    match overlay {
        Overlay::Help => match key.code {
            KeyCode::Down | KeyCode::Char('j') => Some(Action::ScrollHelp(1)),
            KeyCode::Up | KeyCode::Char('k') => Some(Action::ScrollHelp(-1)),
            KeyCode::PageDown | KeyCode::Char(' ') => Some(Action::ScrollHelp(10)),
            KeyCode::PageUp => Some(Action::ScrollHelp(-10)),
            _ => Some(Action::Dismiss),
        },
        Overlay::Quit => match key.code {
            KeyCode::Char('y') | KeyCode::Char('d') => Some(Action::Confirm),
            KeyCode::Char('s') => Some(Action::Save),
            KeyCode::Char('q') => Some(Action::Confirm),
            _ if ctrl && key.code == KeyCode::Char('s') => Some(Action::Save),
            KeyCode::Esc | KeyCode::Char('n') => Some(Action::Dismiss),
            _ => None,
        },
        Overlay::SaveAs { .. } | Overlay::Import { .. } => match key.code {
            KeyCode::Char('u') if ctrl => Some(Action::PromptClear),
            KeyCode::Enter => Some(Action::Confirm),
            KeyCode::Esc => Some(Action::Dismiss),
            KeyCode::Backspace => Some(Action::PromptBackspace),
            KeyCode::Char(c) if !ctrl => Some(Action::PromptInput(c)),
            _ => None,
        },
        Overlay::QuitRunning => match key.code {
            KeyCode::Char('y') | KeyCode::Char('q') => Some(Action::Confirm),
            KeyCode::Esc | KeyCode::Char('n') => Some(Action::Dismiss),
            _ => None,
        },
        Overlay::Recover(_) => match key.code {
            KeyCode::Char('y') => Some(Action::Confirm),
            KeyCode::Char('n') => Some(Action::Dismiss),
            _ => None,
        },
        Overlay::Discard(_) => match key.code {
            KeyCode::Char('s') => Some(Action::Save),
            KeyCode::Char('y') | KeyCode::Char('d') => Some(Action::Confirm),
            KeyCode::Esc | KeyCode::Char('n') => Some(Action::Dismiss),
            _ => None,
        },
        Overlay::SaveInvalid { .. } | Overlay::Overwrite { .. } => match key.code {
            KeyCode::Char('y') => Some(Action::Confirm),
            KeyCode::Esc | KeyCode::Char('n') => Some(Action::Dismiss),
            _ => None,
        },
        // Letters type (a filter or a path): only Esc cancels.
        Overlay::Open { .. } => match key.code {
            KeyCode::Up => Some(Action::PickerMove(-1)),
            KeyCode::Down => Some(Action::PickerMove(1)),
            KeyCode::PageUp => Some(Action::PickerMove(-10)),
            KeyCode::PageDown => Some(Action::PickerMove(10)),
            KeyCode::Enter => Some(Action::Confirm),
            KeyCode::Esc => Some(Action::Dismiss),
            KeyCode::Backspace => Some(Action::PromptBackspace),
            KeyCode::Char('u') if ctrl => Some(Action::PromptClear),
            KeyCode::Char(c) if !ctrl => Some(Action::PromptInput(c)),
            _ => None,
        },
    }
}

/// The action for a mouse event on the screen last drawn (`drawn`).
pub fn mouse_action(app: &App, mouse: MouseEvent, drawn: &Drawn) -> Option<Action> {
    // A release always ends a drag, even over a window opened meanwhile.
    if mouse.kind == MouseEventKind::Up(MouseButton::Left) {
        return Some(Action::DragEnd);
    }
    if app.overlay().is_some() {
        return None;
    }
    let areas = drawn.areas;
    let at = Position::new(mouse.column, mouse.row);
    match mouse.kind {
        MouseEventKind::Down(MouseButton::Left) => {
            if areas.left.contains(at) {
                let (item, point) = hit(app, &drawn.canvas, mouse.column, mouse.row)?;
                return match item {
                    Some(item) => Some(Action::DragStart(item, point)),
                    None if app.editor().add_tool() && app.pane() == Pane::Map => {
                        Some(Action::AddObstacle(Some(point)))
                    }
                    None => Some(Action::FocusOn(Focus::Map)),
                };
            }
            if areas.inspector.contains(at) {
                return Some(Action::FocusOn(Focus::Inspector));
            }
            if areas.jobs.contains(at) {
                return Some(Action::FocusOn(Focus::Jobs));
            }
            None
        }
        MouseEventKind::Drag(MouseButton::Left) => {
            let p = clamp_to(&drawn.canvas, mouse.column, mouse.row);
            Some(Action::DragTo(to_pane(app, p)))
        }
        MouseEventKind::Up(MouseButton::Left) => Some(Action::DragEnd),
        MouseEventKind::ScrollUp | MouseEventKind::ScrollDown if areas.left.contains(at) => {
            let factor = if mouse.kind == MouseEventKind::ScrollUp {
                1.25
            } else {
                0.8
            };
            let about = if app.pane() == Pane::Map && !app.side_view() {
                drawn.canvas.to_world(mouse.column, mouse.row)
            } else {
                None
            };
            Some(Action::Zoom(factor, about))
        }
        _ => None,
    }
}

/// Canvas point → the pane's plane (formation canvas is (−y, x)).
fn to_pane(app: &App, p: nalgebra::Point2<f64>) -> nalgebra::Point2<f64> {
    match app.pane() {
        Pane::Map => p,
        Pane::Formation => nalgebra::Point2::new(p.y, -p.x),
    }
}

/// The canvas point under a cell, clamped into the view (a drag can leave it).
fn clamp_to(vp: &Viewport, column: u16, row: u16) -> nalgebra::Point2<f64> {
    let r = vp.inner;
    let c = column.clamp(r.x, r.x + r.width.saturating_sub(1));
    let w = row.clamp(r.y, r.y + r.height.saturating_sub(1));
    vp.to_world(c, w)
        .unwrap_or_else(|| nalgebra::Point2::new(vp.x[0], vp.y[0]))
}

/// What is under a click in the left pane, and the point in the pane's plane.
fn hit(
    app: &App,
    vp: &Viewport,
    column: u16,
    row: u16,
) -> Option<(Option<Item>, nalgebra::Point2<f64>)> {
    if app.side_view() && app.pane() == Pane::Map {
        return None;
    }
    let canvas_point = vp.to_world(column, row)?;
    let p = to_pane(app, canvas_point);
    // About one cell around the click.
    let tolerance = vp.metres_per_column() * 1.5;
    let m = app.mission();
    let mut best: Option<(f64, Item)> = None;
    let mut consider = |d: f64, item: Item| {
        if best.as_ref().is_none_or(|(bd, _)| d < *bd) {
            best = Some((d, item));
        }
    };
    match app.pane() {
        Pane::Map => {
            for (item, q) in [
                (Item::Start, m.route.start.xy()),
                (Item::Goal, m.route.goal.xy()),
            ] {
                let d = (q - p).norm();
                if d <= tolerance * 1.5 {
                    // Markers win over the obstacle they may sit next to.
                    consider(d - tolerance * 2.0, item);
                }
            }
            for (i, o) in m.obstacles.iter().enumerate() {
                // To the outline: a footprint is hit on or inside it.
                let d = o.prism().outward(&p);
                if d <= tolerance {
                    consider(d, Item::Obstacle(i));
                }
            }
            // The corners of the footprint being edited win over its outline.
            if let Item::Obstacle(i) | Item::Vertex(i, _) = *app.selected()
                && let Some(o) = m.obstacles.get(i)
            {
                for (v, q) in o.footprint.iter().enumerate() {
                    let d = (q - p).norm();
                    if d <= tolerance * 1.5 {
                        consider(d - tolerance * 3.0, Item::Vertex(i, v));
                    }
                }
            }
            for point in crate::pipelines::points::every_point(m) {
                if let Some(d) = point.centre(m).map(|c| (c - p).norm())
                    && d <= tolerance * 1.5
                {
                    consider(d - tolerance * 2.0, Item::Point(point));
                }
            }
        }
        Pane::Formation => {
            let reach = m.formation.uav_radius.max(formation_extent(m) * 0.05) + tolerance;
            for (i, s) in m.formation.slots.iter().enumerate() {
                let d = (nalgebra::Point2::new(s.x, s.y) - p).norm();
                if d <= reach {
                    consider(d, Item::Slot(i));
                }
            }
        }
    }
    Some((best.map(|(_, item)| item), p))
}
