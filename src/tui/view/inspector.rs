//! The inspector: the selected item's fields, with the validation messages
//! that concern each field right under it.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, BorderType, Borders, Paragraph, Wrap};

use crate::mission::Severity;
use crate::pipelines::Kind;
use crate::tui::app::{App, Focus};
use crate::tui::fields::{self, Item, Place};

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

/// Long (~135 lines): the inspector's sections top to bottom, each a few lines.
pub fn draw(frame: &mut Frame, app: &App, area: Rect) {
    let focused = app.focus() == Focus::Inspector;
    let m = app.mission();
    let fields = app.fields();
    let diagnostics = app.doc().diagnostics();
    // Where each message is drawn, worked out once per frame.
    let places: Vec<Option<(Place, bool)>> = diagnostics
        .iter()
        .map(|d| fields::place(app.selected(), m, &fields, &d.path))
        .collect();
    // A message at its own place reads alone; one deeper than any field
    // says where it is.
    let message = |d: &crate::mission::Diagnostic, exact: bool| {
        let text = if exact {
            d.message.clone()
        } else {
            format!("{}: {}", d.path, d.message)
        };
        Line::from(severity_span(d.severity, text))
    };
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
            continue;
        }
        // Each message once: under its field, or after its group's last field.
        for (d, placed) in diagnostics.iter().zip(&places) {
            match placed {
                Some((Place::Field(at), exact)) if *at == k => lines.push(message(d, *exact)),
                Some((Place::Group(_, last), exact)) if *last == k => {
                    lines.push(message(d, *exact));
                }
                _ => {}
            }
        }
    }
    // Messages on the item itself (the start's position) or deeper than
    // any of its fields.
    for (d, placed) in diagnostics.iter().zip(&places) {
        if let Some((Place::Item, exact)) = placed {
            lines.push(message(d, *exact));
        }
    }
    if *app.selected() == Item::Mission {
        let errors = app.doc().error_count();
        let warnings = diagnostics.len() - errors;
        lines.push(Line::raw(""));
        lines.push(Line::from(vec![
            Span::raw(format!("{} obstacles · ", m.obstacles.len())),
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
        // Each pipeline flies its own vehicles: every count.
        let counts: Vec<String> = Kind::ALL
            .iter()
            .map(|k| {
                let face = k.face();
                format!(
                    "{} {} {}",
                    face.words().name,
                    face.vehicles(m),
                    face.words().nouns
                )
            })
            .collect();
        lines.push(Line::raw(counts.join(" · ")));
        for d in diagnostics.iter().take(6) {
            lines.push(Line::from(severity_span(
                d.severity,
                format!("{}: {}", d.path, d.message),
            )));
        }
    }
    lines.push(Line::raw(""));
    let hint = if app.editor().editing().is_some() {
        "Enter apply · Esc cancel · Ctrl-u clear"
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
        .title(super::title::fit(
            vec![
                super::title::Part::keep(Span::styled(" Inspector ", Style::default().bold())),
                super::title::Part::keep(Span::raw(format!("· {} ", app.selected().title(m)))),
            ],
            area.width.saturating_sub(2),
        ));
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
