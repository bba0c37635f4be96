//! Drawing: a pure function of the app state (and the clock, for elapsed
//! times), so every screen can be snapshot-tested on a `TestBackend`.
//!
//! This file is the screen's frame: the layout, the status and find lines,
//! and the overlays (quit, save as, open, import, overwrite, recovery,
//! discard) with the popup helpers they share; the help overlay, the map,
//! the inspector and the jobs panes are submodules.

mod help;
pub mod inspector;
pub mod jobs;
pub mod map;
pub mod terrain;
pub mod title;
pub mod viewport;

use std::time::Instant;

use ratatui::Frame;
use ratatui::layout::{Constraint, Flex, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, BorderType, Borders, Clear, Paragraph, Wrap};

use super::app::{App, Focus, Overlay, Pane};
use title::Part;

/// Below this the layout cannot show a usable map and inspector.
pub const MIN_WIDTH: u16 = 80;
pub const MIN_HEIGHT: u16 = 24;

/// Narrower than this, the inspector and the jobs fold away while the map
/// (or the formation editor) has the focus, so it has the whole width: at
/// 80 columns beside them it had 34, at 5.7 m a cell on the bridge. `Tab`
/// unfolds them.
pub const FOLD_BELOW: u16 = 100;

/// Where each panel goes on a screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Areas {
    /// Map, side view or formation editor.
    pub left: Rect,
    /// Empty (and so are the jobs) while folded.
    pub inspector: Rect,
    pub jobs: Rect,
    pub status: Rect,
    /// The inspector and the jobs are folded away: the left pane has the
    /// whole width.
    pub folded: bool,
}

/// The panels for a screen of `area`, the inspector and the jobs shown;
/// None when it is too small.
pub fn layout(area: Rect) -> Option<Areas> {
    layout_for(area, Focus::Inspector)
}

/// The panels for a screen of `area` with `focus` on one of them; None
/// when it is too small. Under [`FOLD_BELOW`] columns, the map's focus
/// folds the inspector and the jobs away.
pub fn layout_for(area: Rect, focus: Focus) -> Option<Areas> {
    if area.width < MIN_WIDTH || area.height < MIN_HEIGHT {
        return None;
    }
    let [body, status] = Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(area);
    if area.width < FOLD_BELOW && focus == Focus::Map {
        let none = Rect::new(body.right(), body.y, 0, 0);
        return Some(Areas {
            left: body,
            inspector: none,
            jobs: none,
            status,
            folded: true,
        });
    }
    let side = (area.width * 2 / 5).clamp(44, 64);
    let [left, right] =
        Layout::horizontal([Constraint::Min(0), Constraint::Length(side)]).areas(body);
    let [inspector, jobs] =
        Layout::vertical([Constraint::Percentage(50), Constraint::Percentage(50)]).areas(right);
    Some(Areas {
        left,
        inspector,
        jobs,
        status,
        folded: false,
    })
}

/// What a frame showed where: its panels and the left pane's canvas. The
/// event loop keeps the last one and reads clicks against it (the picture
/// the user clicked on, not one recomputed from a state that may have
/// changed since).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drawn {
    pub areas: Areas,
    /// The map's or the formation editor's canvas.
    pub canvas: map::Viewport,
}

impl Drawn {
    /// What `draw` shows of `app` on a screen of `screen`; None when the
    /// screen is too small for the designer.
    pub fn of(app: &App, screen: Rect) -> Option<Drawn> {
        let areas = layout_for(screen, app.focus())?;
        let canvas = match app.pane() {
            Pane::Map => map::Viewport::map(app, areas.left),
            Pane::Formation => {
                map::Viewport::formation(app, map::formation_split(app, areas.left)[0])
            }
        };
        Some(Drawn { areas, canvas })
    }
}

/// Draws the whole screen; returns what it drew where (None on the "too
/// small" screen).
pub fn draw(frame: &mut Frame, app: &App, now: Instant) -> Option<Drawn> {
    let area = frame.area();
    let Some(drawn) = Drawn::of(app, area) else {
        let text = vec![
            Line::styled("Terminal too small", Style::default().bold()),
            Line::raw(format!(
                "{}×{}: skyform needs at least {MIN_WIDTH}×{MIN_HEIGHT}.",
                area.width, area.height
            )),
            Line::raw("Enlarge the window, or press q to quit."),
        ];
        frame.render_widget(
            Paragraph::new(text).wrap(Wrap { trim: true }).centered(),
            area,
        );
        return None;
    };
    let areas = drawn.areas;
    match app.pane() {
        Pane::Map => map::draw_map(frame, app, areas.left, &drawn.canvas, areas.folded),
        Pane::Formation => {
            map::draw_formation(frame, app, areas.left, &drawn.canvas, areas.folded);
        }
    }
    if !areas.folded {
        inspector::draw(frame, app, areas.inspector);
        jobs::draw(frame, app, areas.jobs, now);
    }
    if app.finder().is_typing() {
        draw_find(frame, app, areas);
    } else {
        draw_status(frame, app, areas.status);
    }
    if let Some(overlay) = app.overlay() {
        draw_overlay(frame, app, overlay, area);
    }
    Some(drawn)
}

fn draw_status(frame: &mut Frame, app: &App, area: Rect) {
    // The message matters most: on a narrow screen the file's name and the
    // badges give way to it.
    let mut parts = vec![Part::optional(
        2,
        Span::styled(
            format!(" {} ", app.doc().title()),
            Style::default().black().on_gray(),
        ),
    )];
    let modified = Style::default().black().on_yellow();
    parts.push(if app.doc().is_modified() {
        Part::shortened(
            1,
            Span::styled(" ● modified ", modified),
            Span::styled(" ● ", modified),
        )
    } else {
        Part::keep(Span::raw(" "))
    });
    let errors = app.doc().error_count();
    if errors > 0 {
        let style = Style::default().white().on_red();
        parts.push(Part::shortened(
            1,
            Span::styled(format!(" {errors} error(s) "), style),
            Span::styled(format!(" {errors}✗ "), style),
        ));
    }
    parts.push(Part::keep(Span::raw(" ")));
    if let Some(status) = app.status() {
        let style = if status.error {
            Style::default().light_red().bold()
        } else {
            Style::default()
        };
        parts.push(Part::keep(Span::styled(status.text.clone(), style)));
    }
    let mut spans = title::fit(parts, area.width).spans;
    let hints = match (app.focus(), app.pane()) {
        _ if app.editor().editing().is_some() => "Enter apply · Esc cancel · Ctrl-u clear",
        _ if app.finder().is_stepping() => "n/N next/previous match · Esc end the find · ? help",
        (Focus::Map, Pane::Map) => "/ find · n/p select · arrows move · r run · ? help",
        (Focus::Map, Pane::Formation) => "n/p select · arrows move · P preset · s shape · ? help",
        (Focus::Inspector, _) => "↑↓ field · Enter edit · Tab focus · ? help",
        (Focus::Jobs, _) => "↑↓ job · Enter show · x cancel · ? help",
    };
    let used: usize = spans.iter().map(|s| s.content.chars().count()).sum();
    let room = (area.width as usize).saturating_sub(used + 1);
    if room > hints.chars().count() {
        spans.push(Span::raw(" ".repeat(room - hints.chars().count())));
        spans.push(Span::styled(hints, Style::default().fg(Color::DarkGray)));
    }
    frame.render_widget(Paragraph::new(Line::from(spans)), area);
}

/// Most matches the find's list shows at once.
const FIND_ROWS: usize = 8;

/// The find prompt on the status line (what is typed, which match of how
/// many is selected, the keys), and the matches above it, over the left
/// pane's lower left, the selected one marked.
fn draw_find(frame: &mut Frame, app: &App, areas: Areas) {
    let find = app.finder();
    let m = app.mission();
    let matches = find.matches();
    let mut spans = vec![
        Span::styled(" find ", Style::default().black().on_gray()),
        Span::raw(" "),
        Span::styled(
            format!("/{}▏", find.query()),
            Style::default().white().on_blue(),
        ),
        Span::raw(" "),
    ];
    let said = match (find.query().trim().is_empty(), matches.len()) {
        (true, _) => "type part of an obstacle's or an IWP's name".to_owned(),
        (false, 0) => "no obstacle or IWP has that in its name".to_owned(),
        (false, n) => format!(
            "{} of {n}: {}",
            find.cursor() + 1,
            matches[find.cursor()].title(m)
        ),
    };
    let style = if !find.query().trim().is_empty() && matches.is_empty() {
        Style::default().light_red()
    } else {
        Style::default()
    };
    spans.push(Span::styled(said, style));
    let hints = "↑↓ choose · Enter select · Esc cancel";
    let used: usize = spans.iter().map(Span::width).sum();
    let room = usize::from(areas.status.width).saturating_sub(used + 1);
    if room > hints.chars().count() {
        spans.push(Span::raw(" ".repeat(room - hints.chars().count())));
        spans.push(Span::styled(hints, Style::default().fg(Color::DarkGray)));
    }
    frame.render_widget(Paragraph::new(Line::from(spans)), areas.status);
    if matches.is_empty() {
        return;
    }
    // The list: as many rows as fit over the lower half of the left pane.
    let room = usize::from(areas.left.height.saturating_sub(2) / 2).clamp(1, FIND_ROWS);
    let shown = matches.len().min(room);
    let first = (find.cursor() + 1).saturating_sub(shown);
    let lines: Vec<Line> = matches
        .iter()
        .enumerate()
        .skip(first)
        .take(shown)
        .map(|(k, item)| {
            let title = item.title(m);
            if k == find.cursor() {
                Line::styled(format!("▶ {title}"), Style::default().black().on_yellow())
            } else {
                Line::raw(format!("  {title}"))
            }
        })
        .collect();
    let inner_width = lines.iter().map(Line::width).max().unwrap_or(0) as u16;
    let width = (inner_width + 2)
        .max(16)
        .min(areas.left.width.saturating_sub(2));
    let height = shown as u16 + 2;
    let r = Rect::new(
        areas.left.x + 1,
        areas.left.bottom().saturating_sub(height + 1),
        width,
        height,
    );
    let title = match matches.len() {
        1 => " 1 match ".to_owned(),
        n => format!(" {n} matches "),
    };
    frame.render_widget(Clear, r);
    frame.render_widget(
        Paragraph::new(lines).block(
            Block::default()
                .borders(Borders::ALL)
                .border_type(BorderType::Rounded)
                .border_style(Style::default().fg(Color::Cyan))
                .title(Span::styled(title, Style::default().bold())),
        ),
        r,
    );
}

/// A centred box of at most `width` × `height` cells.
fn centred(area: Rect, width: u16, height: u16) -> Rect {
    let [v] = Layout::vertical([Constraint::Length(height.min(area.height))])
        .flex(Flex::Center)
        .areas(area);
    let [h] = Layout::horizontal([Constraint::Length(width.min(area.width))])
        .flex(Flex::Center)
        .areas(v);
    h
}

fn boxed(title: &str, color: Color) -> Block<'static> {
    Block::default()
        .borders(Borders::ALL)
        .border_type(BorderType::Double)
        .border_style(Style::default().fg(color))
        .title(Span::styled(format!(" {title} "), Style::default().bold()))
}

/// Rows `lines` take once wrapped at `width` cells.
fn rows(lines: &[Line], width: u16) -> u16 {
    let width = usize::from(width.max(1));
    lines
        .iter()
        .map(|l| l.width().max(1).div_ceil(width) as u16)
        .sum()
}

/// A `width` × `height` window in the middle of `area`, cleared, with
/// `body` inside a titled border.
fn popup(
    frame: &mut Frame,
    area: Rect,
    (width, height): (u16, u16),
    (title, color): (&str, Color),
    body: Paragraph<'_>,
) {
    let r = centred(area, width, height);
    frame.render_widget(Clear, r);
    frame.render_widget(body.block(boxed(title, color)), r);
}

/// A line of key hints: each key highlighted, followed by what it does.
fn hints(pairs: &[(&str, &str)]) -> Line<'static> {
    let mut spans = Vec::with_capacity(pairs.len() * 2);
    for (k, what) in pairs {
        spans.push(key(k));
        spans.push(Span::raw(what.to_string()));
    }
    Line::from(spans)
}

fn key(k: &str) -> Span<'static> {
    Span::styled(k.to_owned(), Style::default().yellow().bold())
}

/// "1 job is running (θ-PSO s7): quitting cancels it." when one is.
fn running_line(app: &App) -> Vec<Line<'static>> {
    let running: Vec<String> = app
        .jobs()
        .iter()
        .filter(|j| j.is_running())
        .map(|j| format!("job {} {} s{}", j.id, j.pipeline.words().name, j.seed))
        .collect();
    match running.len() {
        0 => Vec::new(),
        1 => vec![Line::raw(format!(
            "{} is running: quitting cancels it.",
            running[0]
        ))],
        n => vec![Line::raw(format!(
            "{n} jobs are running ({}): quitting cancels them.",
            running.join(", ")
        ))],
    }
}

fn draw_overlay(frame: &mut Frame, app: &App, overlay: &Overlay, area: Rect) {
    match overlay {
        Overlay::Help => help::draw_help(frame, app, area),
        Overlay::Quit => draw_quit(frame, app, area),
        Overlay::QuitRunning => draw_quit_running(frame, app, area),
        Overlay::SaveAs { input, .. } => draw_save_as(frame, app, area, input),
        Overlay::Import { input } => draw_import(frame, app, area, input),
        Overlay::SaveInvalid { errors, .. } => draw_save_invalid(frame, area, errors),
        Overlay::Open {
            input,
            matches,
            cursor,
            ..
        } => draw_open(frame, app, area, input, matches, *cursor),
        Overlay::Overwrite { path, .. } => draw_overwrite(frame, area, path),
        Overlay::Recover(copy) => draw_recover(frame, area, copy),
        Overlay::Discard(entry) => draw_discard(frame, area, entry),
    }
}

/// Quitting with unsaved changes.
fn draw_quit(frame: &mut Frame, app: &App, area: Rect) {
    let mut lines = vec![Line::raw(format!(
        "{} has unsaved changes.",
        app.doc().title()
    ))];
    lines.extend(running_line(app));
    lines.push(Line::raw(""));
    lines.push(hints(&[
        ("s", " save and quit   "),
        ("y", " quit without saving   "),
        ("Esc", " stay"),
    ]));
    let width = 70.min(area.width);
    let size = (width, rows(&lines, width.saturating_sub(2)) + 2);
    let body = Paragraph::new(lines).wrap(Wrap { trim: false });
    popup(frame, area, size, ("Quit?", Color::Yellow), body);
}

/// Quitting while runs are going.
fn draw_quit_running(frame: &mut Frame, app: &App, area: Rect) {
    let mut lines = running_line(app);
    lines.push(Line::raw(""));
    lines.push(hints(&[("y", " quit and cancel   "), ("Esc", " stay")]));
    let width = 70.min(area.width);
    let size = (width, rows(&lines, width.saturating_sub(2)) + 2);
    let body = Paragraph::new(lines).wrap(Wrap { trim: false });
    popup(frame, area, size, ("Quit?", Color::Yellow), body);
}

/// The file name to save as.
fn draw_save_as(frame: &mut Frame, app: &App, area: Rect, input: &str) {
    let lines = vec![
        Line::raw(format!("File (relative to {}):", app.cwd().display())),
        Line::from(Span::styled(
            format!("{input}▏"),
            Style::default().white().on_blue(),
        )),
        hints(&[("Enter", " save   "), ("Esc", " cancel")]),
    ];
    popup(
        frame,
        area,
        (72, 5),
        ("Save as", Color::Cyan),
        Paragraph::new(lines),
    );
}

/// The survey file to import.
fn draw_import(frame: &mut Frame, app: &App, area: Rect, input: &str) {
    let lines = vec![
        Line::raw(format!(
            "Survey: GeoJSON, KML or KMZ (relative to {}):",
            app.cwd().display()
        )),
        Line::from(Span::styled(
            format!("{input}▏"),
            Style::default().white().on_blue(),
        )),
        hints(&[("Enter", " import (one undo step)   "), ("Esc", " cancel")]),
    ];
    popup(
        frame,
        area,
        (72, 5),
        ("Import obstacles", Color::Cyan),
        Paragraph::new(lines),
    );
}

/// Saving a mission with errors.
fn draw_save_invalid(frame: &mut Frame, area: Rect, errors: &[String]) {
    let mut lines = vec![Line::raw(format!(
        "The mission has {} error(s):",
        errors.len()
    ))];
    for e in errors.iter().take(8) {
        lines.push(Line::styled(
            format!("  ✗ {e}"),
            Style::default().light_red(),
        ));
    }
    if errors.len() > 8 {
        lines.push(Line::raw(format!("  … and {} more", errors.len() - 8)));
    }
    lines.push(Line::raw(
        "It can be saved, but not run until they are fixed.",
    ));
    lines.push(hints(&[("y", " save anyway   "), ("Esc", " cancel")]));
    // Tall enough for the wrapped error lines, so the hints stay in view.
    let width = 90.min(area.width);
    let size = (width, rows(&lines, width.saturating_sub(2)) + 2);
    let body = Paragraph::new(lines).wrap(Wrap { trim: false });
    popup(
        frame,
        area,
        size,
        ("Save an invalid mission?", Color::Red),
        body,
    );
}

/// The open dialog: a prompt, the list it filters, the hints.
fn draw_open(
    frame: &mut Frame,
    app: &App,
    area: Rect,
    input: &str,
    matches: &[super::overlay::Entry],
    cursor: usize,
) {
    // Prompt line, list, hints: the list takes what the screen leaves.
    let inner = (matches.len() as u16 + 2).min(area.height.saturating_sub(6));
    let room = inner.saturating_sub(2) as usize;
    let first = (cursor + 1).saturating_sub(room.max(1));
    let mut lines = vec![Line::from(vec![
        Span::raw("Path or filter: "),
        Span::styled(format!("{input}▏"), Style::default().white().on_blue()),
    ])];
    let typed_only = !input.trim().is_empty()
        && matches.len() == 1
        && matches!(&matches[0], super::overlay::Entry::File(p)
            if *p == super::overlay::typed_path(app.cwd(), input));
    lines.extend(
        matches
            .iter()
            .enumerate()
            .skip(first)
            .take(room)
            .map(|(k, e)| {
                let mut label = super::overlay::entry_label(e, app.cwd());
                if typed_only {
                    label = format!("{label}  (not listed: Enter opens this path)");
                }
                if k == cursor {
                    Line::styled(format!("▶ {label}"), Style::default().black().on_yellow())
                } else {
                    Line::raw(format!("  {label}"))
                }
            }),
    );
    lines.push(hints(&[
        ("type", " filter or path   "),
        ("↑↓", " choose   "),
        ("Enter", " open   "),
        ("Esc", " cancel"),
    ]));
    let title = (
        "Open a mission (missions/, ./, built-in, a path)",
        Color::Cyan,
    );
    popup(frame, area, (72, inner + 2), title, Paragraph::new(lines));
}

/// Replacing an existing file.
fn draw_overwrite(frame: &mut Frame, area: Rect, path: &std::path::Path) {
    let lines = vec![
        Line::raw(format!("{} exists. Replace it?", path.display())),
        hints(&[("y", " replace   "), ("Esc", " cancel")]),
    ];
    let body = Paragraph::new(lines).wrap(Wrap { trim: false });
    popup(frame, area, (80, 5), ("Replace file?", Color::Yellow), body);
}

/// Restoring an earlier session's unsaved changes.
fn draw_recover(frame: &mut Frame, area: Rect, copy: &super::recovery::Copy) {
    let lines = vec![
        Line::raw("An earlier session left unsaved changes to this mission:"),
        Line::raw(copy.describe(std::time::SystemTime::now())),
        Line::raw(""),
        hints(&[
            ("y", " restore them (then Ctrl-s to save)   "),
            ("n", " discard them"),
        ]),
    ];
    let body = Paragraph::new(lines).wrap(Wrap { trim: false });
    popup(
        frame,
        area,
        (80, 7),
        ("Recover unsaved changes?", Color::Yellow),
        body,
    );
}

/// Opening another mission over unsaved changes.
fn draw_discard(frame: &mut Frame, area: Rect, entry: &super::overlay::Entry) {
    let lines = vec![
        Line::raw(format!(
            "Discard the unsaved changes and open {}?",
            entry.label()
        )),
        hints(&[
            ("s", " save, then open   "),
            ("y", " discard and open   "),
            ("Esc", " cancel"),
        ]),
    ];
    let width = 80.min(area.width);
    let size = (width, rows(&lines, width.saturating_sub(2)) + 2);
    let body = Paragraph::new(lines).wrap(Wrap { trim: false });
    popup(frame, area, size, ("Unsaved changes", Color::Yellow), body);
}
