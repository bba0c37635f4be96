//! The inspector: the selected item's fields, with the validation messages
//! that concern each field right under it.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, BorderType, Borders, Paragraph, Wrap};

use crate::mission::Severity;
use crate::tui::app::{App, Focus};
use crate::tui::fields::{self, Item};

fn severity_span(severity: Severity, text: String) -> Span<'static> {
    match severity {
        Severity::Error => {
            Span::styled(format!("  ✗ {text}"), Style::default().fg(Color::LightRed))
        }
        Severity::Warning => {
            Span::styled(format!("  ⚠ {text}"), Style::default().fg(Color::Yellow))
        }
    }
}

pub fn draw(frame: &mut Frame, app: &App, area: Rect) {
    let focused = app.focus() == Focus::Inspector;
    let m = app.mission();
    let fields = app.fields();
    let diagnostics = app.doc().diagnostics();
    // Which field shows each message, worked out once per frame.
    let owners: Vec<Option<usize>> = diagnostics
        .iter()
        .map(|d| fields::owner(&fields, &d.path))
        .collect();
    let label_width = fields
        .iter()
        .map(|f| f.label().chars().count())
        .max()
        .unwrap_or(0);
    let mut lines: Vec<Line> = Vec::new();
    let mut cursor_line = 0;
    for (k, f) in fields.iter().enumerate() {
        let cursor = k == app.editor().field();
        let editing = cursor && app.editor().editing().is_some();
        let label = format!("{:<label_width$}  ", f.label());
        let label_style = if cursor && focused {
            Style::default().black().on_yellow()
        } else if cursor {
            Style::default().yellow()
        } else {
            Style::default().fg(Color::Gray)
        };
        let value = match (app.editor().editing(), editing) {
            (Some(e), true) => {
                Span::styled(format!("{}▏", e.buffer), Style::default().white().on_blue())
            }
            _ => Span::raw(f.value().to_owned()),
        };
        if cursor {
            cursor_line = lines.len();
        }
        lines.push(Line::from(vec![Span::styled(label, label_style), value]));
        if editing {
            if let Some(Some((severity, text))) = app.editor().editing().map(|e| e.problem.clone())
            {
                lines.push(Line::from(severity_span(severity, text)));
            }
        } else {
            // Each message once, under the field it belongs to.
            for (d, _) in diagnostics
                .iter()
                .zip(&owners)
                .filter(|(_, owner)| **owner == Some(k))
            {
                lines.push(Line::from(severity_span(d.severity, d.message.clone())));
            }
        }
    }
    // Messages about the item that no field shows (e.g. an obstacle outside the bounds).
    if let Some(prefix) = app.selected().path(app.mission()) {
        for (d, _) in diagnostics
            .iter()
            .zip(&owners)
            .filter(|(d, owner)| owner.is_none() && d.path.starts_with(&prefix))
        {
            lines.push(Line::from(severity_span(
                d.severity,
                format!("{}: {}", d.path, d.message),
            )));
        }
    }
    if *app.selected() == Item::Mission {
        let errors = app.doc().error_count();
        let warnings = diagnostics.len() - errors;
        lines.push(Line::raw(""));
        lines.push(Line::from(vec![
            Span::raw(format!(
                "{} obstacles · {} UAVs · ",
                m.obstacles.len(),
                m.formation.slots.len()
            )),
            if errors == 0 {
                Span::styled("valid", Style::default().green())
            } else {
                Span::styled(format!("{errors} error(s)"), Style::default().red().bold())
            },
            Span::raw(if warnings > 0 {
                format!(" · {warnings} warning(s)")
            } else {
                String::new()
            }),
        ]));
        for d in diagnostics.iter().take(6) {
            lines.push(Line::from(severity_span(
                d.severity,
                format!("{}: {}", d.path, d.message),
            )));
        }
    }
    lines.push(Line::raw(""));
    let hint = if app.editor().editing().is_some() {
        "Enter apply · Esc cancel"
    } else {
        "↑↓ field · Enter/type to edit · n/p next/prev item"
    };
    lines.push(Line::styled(hint, Style::default().fg(Color::DarkGray)));

    let border = if focused {
        Color::Yellow
    } else {
        Color::DarkGray
    };
    let block = Block::default()
        .borders(Borders::ALL)
        .border_type(BorderType::Rounded)
        .border_style(Style::default().fg(border))
        .title(Line::from(vec![
            Span::styled(" Inspector ", Style::default().bold()),
            Span::raw(format!("· {} ", app.selected().title(m))),
        ]));
    // Keep the cursor visible in a long list.
    let inner_height = area.height.saturating_sub(2) as usize;
    let scroll = cursor_line.saturating_sub(inner_height.saturating_sub(3)) as u16;
    frame.render_widget(
        Paragraph::new(lines)
            .block(block)
            .wrap(Wrap { trim: false })
            .scroll((scroll, 0)),
        area,
    );
}
