//! The formation editor's drawing: the slots at the top, the IWP table
//! below.

use super::*;

/// Narrower than this inside its border (an 80-column screen), the IWP
/// table gives each IWP two lines instead of five columns squeezed to a few
/// letters each.
const IWP_TABLE_WIDE: u16 = 56;

fn iwp_table_is_narrow(area: Rect) -> bool {
    area.width.saturating_sub(2) < IWP_TABLE_WIDE
}

/// The formation editor's drawing (top) and IWP table (bottom).
pub fn formation_split(app: &App, area: Rect) -> [Rect; 2] {
    let n = app.iwps().len() as u16;
    // Borders, plus a header row or a second line per IWP.
    let wanted = if iwp_table_is_narrow(area) {
        2 * n + 2
    } else {
        n + 3
    };
    let list_height = wanted.clamp(4, area.height / 2);
    ratatui::layout::Layout::vertical([
        ratatui::layout::Constraint::Min(6),
        ratatui::layout::Constraint::Length(list_height),
    ])
    .areas(area)
}

/// The formation editor: slots in the formation frame (drawn through `vp`,
/// the viewport `Drawn` reports), and the IWPs' shapes.
///
/// `folded`: the pane has the whole width (a narrow screen, its focus):
/// its bottom line names the selection and says Tab.
///
/// Long (~170 lines): its two panes top to bottom, the slots' canvas (title, axes, rings,
/// labels) then the IWP table (rows, wide or narrow, its title and header).
pub fn draw_formation(frame: &mut Frame, app: &App, area: Rect, vp: &Viewport, folded: bool) {
    let m = app.mission();
    let [top, bottom] = formation_split(app, area);
    let vp = *vp;
    let title = fit(
        vec![
            Part::keep(Span::styled(" Formation ", Style::default().bold())),
            Part::keep(Span::raw(format!("· {} UAVs ", m.formation.slots.len()))),
            Part::optional(
                2,
                Span::raw(format!("· r_F {:.2} m ", m.formation.radius())),
            ),
            Part::optional(4, Span::raw("· forward ↑ ")),
            Part::shortened_optional(
                1,
                Span::raw(format!(
                    "· P preset ({}) ",
                    app.current_preset().map_or("custom", Preset::name)
                )),
                Span::raw(format!(
                    "· {} ",
                    app.current_preset().map_or("custom", Preset::name)
                )),
            ),
            Part::optional(3, Span::raw("· a add · Del remove ")),
        ],
        top.width.saturating_sub(2),
    );
    let dot = vp.metres_per_column() / 2.0;
    let canvas = Canvas::default()
        .block(pane_block(title, app.focus() == Focus::Map))
        .marker(Marker::Braille)
        .x_bounds(vp.x)
        .y_bounds(vp.y)
        .paint(|ctx| {
            // Axes through the centroid.
            ctx.draw(&Line::new(vp.x[0], 0.0, vp.x[1], 0.0, Color::DarkGray));
            ctx.draw(&Line::new(0.0, vp.y[0], 0.0, vp.y[1], Color::DarkGray));
            ctx.draw(&Ring {
                x: 0.0,
                y: 0.0,
                radius: m.formation.radius(),
                color: Color::DarkGray,
                dot,
            });
            ctx.layer();
            for (i, s) in m.formation.slots.iter().enumerate() {
                let selected = *app.selected() == Item::Slot(i);
                let color = if selected {
                    Color::Yellow
                } else {
                    uav_color(i)
                };
                ctx.draw(&Ring {
                    x: -s.y,
                    y: s.x,
                    radius: m.formation.uav_radius,
                    color,
                    dot,
                });
                let style = if selected {
                    Style::default().yellow().bold()
                } else {
                    Style::default().fg(color)
                };
                ctx.print(-s.y, s.x, Span::styled(format!("{}", i + 1), style));
            }
            ctx.print(
                vp.x[0],
                vp.y[1],
                Span::styled("forward", Style::default().fg(Color::DarkGray)),
            );
        });
    frame.render_widget(canvas, top);

    let narrow = iwp_table_is_narrow(bottom);
    let rows: Vec<Row> = app
        .iwps()
        .iter()
        .map(|w| {
            let selected = *app.selected() == Item::Waypoint(w.between.clone());
            let style = if selected {
                Style::default().black().on_yellow()
            } else if w.enabled {
                Style::default()
            } else {
                Style::default().fg(Color::DarkGray)
            };
            let between = format!("{} ↔ {}", w.between[0], w.between[1]);
            let choice = if w.choice == ShapeChoice::Auto {
                "auto".to_owned()
            } else {
                shape_name(w.choice).to_owned()
            };
            if narrow {
                let mark = if w.enabled { "◆" } else { "◇" };
                let off = if w.enabled { "" } else { " · off" };
                let shape = if w.choice == ShapeChoice::Auto {
                    format!("auto → {}", w.shape_name())
                } else {
                    format!("{} (chosen)", w.shape_name())
                };
                let text = ratatui::text::Text::from(vec![
                    TextLine::raw(format!("{mark} {between}{off}")),
                    TextLine::raw(format!("  gap {:.2} m · {shape}", w.gap)),
                ]);
                return Row::new([Cell::from(text)]).height(2).style(style);
            }
            Row::new([
                Cell::from(between),
                Cell::from(format!("{:.2}", w.gap)),
                Cell::from(if w.enabled { "yes" } else { "no" }),
                Cell::from(choice),
                Cell::from(w.shape_name()),
            ])
            .style(style)
        })
        .collect();
    let empty = app.iwps().is_empty();
    // With errors elsewhere the IWPs are not looked for: "none" would say
    // no gap needs one.
    let errors = app.doc().diagnostics().iter().any(|d| d.is_error());
    let name = Part::keep(Span::raw(" IWPs (eq. 9)"));
    let parts = match (empty, errors) {
        (true, true) => vec![
            name,
            Part::shortened(
                1,
                Span::raw(": not found until the mission's errors are fixed "),
                Span::raw(": not found: fix the errors first "),
            ),
        ],
        (true, false) => vec![
            name,
            Part::shortened(
                1,
                Span::raw(": none: no gap narrower than the formation "),
                Span::raw(": none "),
            ),
        ],
        (false, _) => vec![
            name,
            Part::shortened(1, Span::raw(" · s cycle shape"), Span::raw(" · s shape")),
            Part::optional(2, Span::raw(" · Space on/off")),
            Part::keep(Span::raw(" ")),
        ],
    };
    let mut block = pane_block(fit(parts, bottom.width.saturating_sub(2)), false);
    if folded {
        block = block.title_bottom(super::folded_hint(app, bottom.width));
    }
    let table = if narrow {
        Table::new(rows, [ratatui::layout::Constraint::Fill(1)]).block(block)
    } else {
        let header = Row::new(["IWP between", "gap m", "on", "choice", "shape used"])
            .style(Style::default().bold());
        Table::new(
            rows,
            [
                ratatui::layout::Constraint::Min(20),
                ratatui::layout::Constraint::Length(6),
                ratatui::layout::Constraint::Length(3),
                ratatui::layout::Constraint::Length(10),
                ratatui::layout::Constraint::Length(10),
            ],
        )
        .header(header)
        .block(block)
    };
    frame.render_widget(table, bottom);
}
