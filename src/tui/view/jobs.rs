//! The jobs panel: every launched run with its progress, and the selected
//! one's result (its pipeline's table, `PipelineOutcome::table`, drawn
//! here with the flight check and STALE under its verdict) and
//! convergence chart.

use std::time::Instant;

use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{
    Axis, Block, BorderType, Borders, Chart, Dataset, GraphType, Paragraph, Wrap,
};

use crate::outcome::Outcome;
use crate::pipelines::table::{Cell, Row, Tone};
use crate::tui::action::Action;
use crate::tui::app::{App, Focus};
use crate::tui::jobs::{Job, JobState};
use crate::tui::keys::KEYS;
use crate::tui::view::title::{Part, fit};

/// `██████░░░░ 60%` in `width` cells.
fn bar(progress: f64, width: usize) -> String {
    let progress = progress.clamp(0.0, 1.0);
    let filled = ((progress * width as f64).round() as usize).min(width);
    format!(
        "{}{} {:>3.0}%",
        "█".repeat(filled),
        "░".repeat(width - filled),
        progress * 100.0
    )
}

/// The live plan's line: which, how long it took (edit to plan), whether it
/// was warm-started, and whether the next is on its way or waits.
fn live_line(app: &App, job: &Job) -> Line<'static> {
    let l = app.board().live();
    let warm = job
        .outcome
        .as_ref()
        .and_then(|o| o.face().warm_from())
        .unwrap_or_else(|| "cold".to_owned());
    let state = match (l.is_on(), l.paused(), l.replanning()) {
        (false, ..) => "live off (L)".to_owned(),
        (true, Some(why), _) => format!("paused: {why}"),
        (true, None, true) => "re-planning…".to_owned(),
        (true, None, false) => "follows every edit".to_owned(),
    };
    let ms = job.elapsed(Instant::now()).as_secs_f64() * 1e3;
    Line::styled(
        format!(
            "{} · {} · {ms:.0} ms · {warm} · {state}",
            crate::tui::live::label(job.id),
            job.pipeline.words().name
        ),
        Style::default().cyan(),
    )
}

/// A distributed fleet's agents alive, of how many (red once one is lost).
fn agents_span(job: &Job) -> Option<Span<'static>> {
    job.distributed?;
    // The run reports each loss as it happens (`Event::Vehicles`).
    let (alive, total) = job.agents?;
    let style = if alive < total {
        Style::default().red().bold()
    } else {
        Style::default().green()
    };
    Some(Span::styled(format!(" ⇄{alive}/{total}"), style))
}

fn state_span(job: &Job) -> Span<'static> {
    match &job.state {
        JobState::Running => Span::styled(job.stage.clone(), Style::default().cyan()),
        JobState::Cancelled => Span::styled("cancelled", Style::default().yellow()),
        JobState::Failed(_) => Span::styled("FAILED", Style::default().red().bold()),
        JobState::Done => {
            let passed = job.outcome.as_ref().is_some_and(Outcome::ok);
            let word = job
                .outcome
                .as_ref()
                .and_then(Outcome::verdict_word)
                .unwrap_or("FAIL");
            let style = if passed {
                Style::default().green()
            } else {
                Style::default().red().bold()
            };
            Span::styled(word, style)
        }
    }
}

/// Long (~185 lines): the jobs panel's parts top to bottom (title, list,
/// progress, the shown result's table, the convergence chart).
pub fn draw(frame: &mut Frame, app: &App, area: Rect, now: Instant) {
    let focused = app.focus() == Focus::Jobs;
    let border = if focused {
        Color::Yellow
    } else {
        Color::DarkGray
    };
    let rec = match (app.board().record_rrd(), app.board().viewer()) {
        (false, crate::tui::jobs::Viewer::Off) => String::new(),
        (rrd, viewer) => format!(
            "· rec{}{} ",
            if rrd { " .rrd" } else { "" },
            if viewer != crate::tui::jobs::Viewer::Off {
                format!(" viewer:{}", viewer.label())
            } else {
                String::new()
            }
        ),
    };
    let block = Block::default()
        .borders(Borders::ALL)
        .border_type(BorderType::Rounded)
        .border_style(Style::default().fg(border))
        .title(fit(
            vec![
                Part::keep(Span::styled(" Jobs ", Style::default().bold())),
                Part::optional(1, Span::styled(rec, Style::default().red())),
            ],
            area.width.saturating_sub(2),
        ));
    let inner = block.inner(area);
    frame.render_widget(block, area);
    // The newest live plan, when the map shows it, is what the panel details.
    let live = app.shown().filter(|j| crate::tui::live::Live::owns(j.id));
    if app.jobs().is_empty() && live.is_none() {
        // The Run keys of the key table, each with its help up to any
        // parenthesis.
        let mut text = vec![Line::raw("No runs yet.")];
        if let Some(why) = app.board().live().held_off() {
            text.push(Line::styled(why.to_owned(), Style::default().yellow()));
        }
        for row in KEYS.iter().filter(|row| {
            row.bindings.iter().any(|b| {
                matches!(
                    b.action,
                    Action::Run(_)
                        | Action::RunNewSeed
                        | Action::ToggleRecording
                        | Action::CycleViewer
                )
            })
        }) {
            let help = row.help.split(" (").next().unwrap_or(row.help);
            text.push(Line::from(vec![
                Span::styled(row.keys.to_string(), Style::default().yellow().bold()),
                Span::raw(format!(" {help}")),
            ]));
        }
        frame.render_widget(Paragraph::new(text).wrap(Wrap { trim: false }), inner);
        return;
    }
    let list_height = (app.jobs().len().max(1) as u16)
        .min(inner.height / 3)
        .max(1);
    let [list, detail] =
        Layout::vertical([Constraint::Length(list_height), Constraint::Min(0)]).areas(inner);

    // The list, scrolled to keep the cursor in view.
    let first = app
        .board()
        .cursor()
        .saturating_sub(list_height as usize - 1);
    let bar_width = (inner.width as usize).saturating_sub(50).clamp(4, 12);
    let lines: Vec<Line> = app
        .jobs()
        .iter()
        .enumerate()
        .skip(first)
        .take(list_height as usize)
        .map(|(k, job)| {
            let cursor = k == app.board().cursor();
            let shown = app.board().shown_id() == Some(job.id);
            let head = format!(
                "{}{}{:>2} {} s{:<3} ",
                if cursor { "▶" } else { " " },
                if shown { "◉" } else { " " },
                job.id,
                job.pipeline.words().name,
                job.seed
            );
            let style = if cursor && focused {
                Style::default().black().on_yellow()
            } else {
                Style::default()
            };
            let cost = job
                .best_cost()
                .map_or(String::new(), |c| format!("J {c:.1} "));
            // A row too long for the panel drops its elapsed time, then
            // its cost, then its bar: never its verdict ("J 280.2 f" at 80
            // columns).
            let mut parts = vec![
                Part::keep(Span::styled(head, style)),
                Part::optional(
                    2,
                    Span::styled(
                        format!("{} ", bar(job.progress, bar_width)),
                        Style::default().fg(Color::LightBlue),
                    ),
                ),
                Part::optional(
                    4,
                    Span::raw(format!("{:>5.1}s ", job.elapsed(now).as_secs_f64())),
                ),
                Part::optional(3, Span::raw(cost)),
                Part::keep(state_span(job)),
            ];
            parts.extend(agents_span(job).map(Part::keep));
            fit(parts, inner.width)
        })
        .collect();
    frame.render_widget(Paragraph::new(lines), list);

    let Some(job) = live.or_else(|| app.jobs().get(app.board().cursor())) else {
        return;
    };
    let mut facts: Vec<Line> = Vec::new();
    if let Some(job) = live {
        facts.push(live_line(app, job));
    }
    if let JobState::Failed(e) = &job.state {
        facts.push(Line::styled(format!("error: {e}"), Style::default().red()));
    }
    if let Some(outcome) = &job.outcome {
        // The result as its pipeline words it (`PipelineOutcome::table`):
        // the flight check under the verdict it qualifies, then STALE.
        let mut table: Vec<Line> = outcome
            .face()
            .table()
            .into_iter()
            .map(|row| table_line(row, detail.width))
            .collect();
        if app.is_stale(job) {
            // Second, under the verdict, where a short panel still shows it.
            table.insert(table.len().min(1), stale_line());
        }
        let at = table.len().min(1);
        table.splice(at..at, flight_lines(job));
        facts.extend(table);
        // A result without a convergence series fills the panel.
        if outcome.convergence().is_empty() {
            frame.render_widget(Paragraph::new(facts), detail);
            return;
        }
    } else if let Some(w) = &job.last_warning {
        facts.push(Line::styled(w.clone(), Style::default().yellow()));
    }
    if job.is_running()
        && let Some(d) = job.distributed
    {
        let alive = job.agents.map_or_else(
            || "starting".to_owned(),
            |(alive, total)| format!("{alive} of {total} agents alive"),
        );
        facts.push(Line::raw(format!(
            "{} agent process(es) over Zenoh: {alive}",
            d.count
        )));
    }
    // The verdict and the table first, from the top: the chart takes what
    // they leave, when that is enough to read.
    let needed = wrapped_rows(&facts, detail.width);
    let chart_room = detail.height.saturating_sub(needed);
    let chart_height = if chart_room >= 6 { chart_room } else { 0 };
    let [facts_area, chart_area] = Layout::vertical([
        Constraint::Length(detail.height - chart_height),
        Constraint::Length(chart_height),
    ])
    .areas(detail);
    frame.render_widget(Paragraph::new(facts).wrap(Wrap { trim: false }), facts_area);
    draw_chart(frame, job, chart_area);
}

/// The job's flight check (`G`): under way, or its verdict and the worst
/// place (the map draws the envelope).
fn flight_lines(job: &Job) -> Vec<Line<'static>> {
    use crate::tui::jobs::FlightCheck;
    match &job.flight {
        None => Vec::new(),
        Some(FlightCheck::Running { done, total }) => vec![Line::styled(
            format!("flight check: {done} of {total} flights…"),
            Style::default().cyan(),
        )],
        Some(FlightCheck::Failed(e)) => vec![Line::styled(
            format!("flight check failed: {e}"),
            Style::default().red(),
        )],
        Some(FlightCheck::Done(r)) => {
            let mut lines = vec![Line::styled(
                format!("flight check: {}", r.verdict),
                Style::default().cyan().bold(),
            )];
            if let Some((worst, _)) = &r.worst {
                lines.push(Line::styled(
                    format!("worst: {worst}"),
                    Style::default().red(),
                ));
            }
            lines
        }
    }
}

/// Under a result's verdict once the mission changed after its run.
fn stale_line() -> Line<'static> {
    Line::styled(
        "STALE: the mission changed since this run",
        Style::default().black().on_yellow(),
    )
}

/// Rows `lines` take once wrapped at `width` cells.
fn wrapped_rows(lines: &[Line], width: u16) -> u16 {
    let width = usize::from(width.max(1));
    lines
        .iter()
        .map(|l| l.width().max(1).div_ceil(width) as u16)
        .sum()
}

/// How a result table's tone looks in the panel.
fn tone_style(tone: Tone) -> Style {
    match tone {
        Tone::Plain => Style::default(),
        Tone::Strong => Style::default().bold(),
        Tone::Good => Style::default().green(),
        Tone::GoodStrong => Style::default().green().bold(),
        Tone::Bad => Style::default().red(),
        Tone::BadStrong => Style::default().red().bold(),
        Tone::Warn => Style::default().yellow(),
    }
}

/// A row of a pipeline's result table as a line `width` cells wide: a row
/// with shorter forms gives way to them on a narrow panel (`title::fit`).
fn table_line(row: Row, width: u16) -> Line<'static> {
    if row.iter().any(|cell| cell.short.is_some()) {
        let parts = row
            .into_iter()
            .map(|cell| {
                let style = tone_style(cell.tone);
                match cell.short {
                    Some(short) => Part::shortened(
                        1,
                        Span::styled(cell.text, style),
                        Span::styled(short, style),
                    ),
                    None => Part::keep(Span::styled(cell.text, style)),
                }
            })
            .collect();
        return fit(parts, width);
    }
    match <[Cell; 1]>::try_from(row) {
        Ok([cell]) => Line::styled(cell.text, tone_style(cell.tone)),
        Err(row) => Line::from(
            row.into_iter()
                .map(|cell| Span::styled(cell.text, tone_style(cell.tone)))
                .collect::<Vec<_>>(),
        ),
    }
}

/// Best total cost per iteration (the convergence curve).
fn draw_chart(frame: &mut Frame, job: &Job, area: Rect) {
    if area.height < 4 || job.convergence.is_empty() {
        return;
    }
    let points: Vec<(f64, f64)> = job
        .convergence
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_finite())
        .map(|(i, c)| (i as f64, *c))
        .collect();
    if points.is_empty() {
        return;
    }
    let n = points.len() as f64;
    let scale = ChartScale::of(&points);
    let plotted: Vec<(f64, f64)> = points.iter().map(|&(x, y)| (x, scale.to_axis(y))).collect();
    let dataset = Dataset::default()
        .marker(Marker::Braille)
        .graph_type(GraphType::Line)
        .style(Style::default().fg(Color::LightBlue))
        .data(&plotted);
    let chart = Chart::new(vec![dataset])
        .x_axis(
            Axis::default()
                .bounds([0.0, (n - 1.0).max(1.0)])
                .labels(["0".to_owned(), format!("{}", points.len() - 1)])
                .style(Style::default().fg(Color::DarkGray)),
        )
        .y_axis(
            Axis::default()
                .bounds(scale.bounds)
                .labels(scale.labels())
                .style(Style::default().fg(Color::DarkGray)),
        );
    frame.render_widget(chart, area);
}

/// The convergence chart's y axis: every cost from the first iteration to
/// the last is on it (none clipped). Costs spanning more than 20× (the
/// penalties of the first iterations) go on a log scale so the end of the
/// curve stays readable; labels always show costs, with enough digits to
/// tell the two ends apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartScale {
    log: bool,
    /// Axis bounds (log10 of the cost on a log scale).
    bounds: [f64; 2],
}

impl ChartScale {
    pub fn of(points: &[(f64, f64)]) -> Self {
        let lo = points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        let hi = points.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        let log = lo > 0.0 && hi / lo > 20.0;
        let (a, b) = if log {
            (lo.log10(), hi.log10())
        } else {
            (lo, hi)
        };
        let pad = ((b - a) * 0.05).max(if log { 1e-3 } else { 1e-6 * b.abs().max(1.0) });
        ChartScale {
            log,
            bounds: [a - pad, b + pad],
        }
    }

    pub fn to_axis(&self, y: f64) -> f64 {
        if self.log { y.log10() } else { y }
    }

    fn cost(&self, axis: f64) -> f64 {
        if self.log { 10f64.powf(axis) } else { axis }
    }

    /// Bottom, middle and top, as costs.
    pub fn labels(&self) -> [String; 3] {
        let [a, b] = self.bounds;
        let values = [self.cost(a), self.cost((a + b) / 2.0), self.cost(b)];
        let spread = (values[2] - values[0]).abs();
        let digits = if spread >= 10.0 {
            1
        } else {
            (2.0 - spread.max(1e-9).log10().floor()).clamp(1.0, 9.0) as usize
        };
        values.map(|v| crate::mission::compact_digits(v, digits))
    }
}

#[cfg(test)]
mod tests {
    use super::{ChartScale, bar};

    /// Issue 16: no cost is clipped, and the labels tell the ends apart.
    #[test]
    fn the_chart_axis_holds_every_cost() {
        // A run from 150.8 down to 49.7: linear (under 20×), first point on it.
        let points: Vec<(f64, f64)> = (0..100)
            .map(|i| (i as f64, 49.7 + 101.1 * (-(i as f64) / 10.0).exp()))
            .collect();
        let s = ChartScale::of(&points);
        for &(_, y) in &points {
            let a = s.to_axis(y);
            assert!(
                a >= s.bounds[0] && a <= s.bounds[1],
                "{y} off {:?}",
                s.bounds
            );
        }
        let [lo, _, hi] = s.labels();
        assert!(lo.parse::<f64>().unwrap() < 49.7 && hi.parse::<f64>().unwrap() > 150.8);
        // Penalties 1000× the end: log scale, still every point on it.
        let points = [(0.0, 1e5), (1.0, 300.0), (2.0, 120.0), (3.0, 119.9)];
        let s = ChartScale::of(&points);
        assert!(s.log);
        assert!(s.to_axis(1e5) <= s.bounds[1] && s.to_axis(119.9) >= s.bounds[0]);
        // A flat tail: two different labels.
        let s = ChartScale::of(&[(0.0, 49.71), (1.0, 49.70)]);
        let [lo, _, hi] = s.labels();
        assert_ne!(lo, hi);
    }

    #[test]
    fn the_bar_fills_in_proportion() {
        assert_eq!(bar(0.5, 10), "█████░░░░░  50%");
        assert_eq!(bar(1.2, 4), "████ 100%");
        assert_eq!(bar(0.0, 4), "░░░░   0%");
    }
}
