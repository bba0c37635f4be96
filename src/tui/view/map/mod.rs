//! The map (top-down and side views) and the formation editor's drawing.
//!
//! Terminal cells are about twice as tall as wide, so a [`Viewport`] gives a
//! row twice the metres of a column: circles stay round at any zoom. The same
//! viewport turns a mouse position back into metres for hit-testing.
//! The side view (`side`) and the formation editor's drawing (`formation`)
//! share this module's viewport and painters.
//!
//! Each pipeline's result is charted by the pipeline (`pipelines::chart`)
//! and drawn here (`chart`); the map's text is placed by `labels`.

use nalgebra::{Point2, Point3};
use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line as TextLine, Span};
use ratatui::widgets::canvas::{Canvas, Context, Line, Painter, Rectangle, Shape};
use ratatui::widgets::{Block, BorderType, Borders, Cell, Row, Table};

use crate::base::geometry::segment_projection;
use crate::mission::{Mission, Preset, ShapeChoice};
use crate::outcome::Verdict;
use crate::pipelines::Kind;
use crate::pipelines::chart::ChartView;
use crate::tui::app::{App, Focus};
use crate::tui::fields::{Item, shape_name};
use crate::tui::jobs::{Job, Outcome};
use crate::tui::live::Live;

mod chart;
mod formation;
mod labels;
mod side;

use chart::OnCanvas;
pub use formation::{draw_formation, formation_split};
use labels::paint_labels;
use side::draw_side;

use super::title::{Part, fit};
pub use super::viewport::Viewport;

/// UAV `i`'s colour (0-based), the same as in the Rerun recording.
pub fn uav_color(i: usize) -> Color {
    let [r, g, b] = crate::outcome::tracks::vehicle_color(i);
    Color::Rgb(r, g, b)
}

/// A circle drawn with as many points as it has braille dots around it, so
/// small circles are cheap and large ones stay closed.
struct Ring {
    x: f64,
    y: f64,
    radius: f64,
    color: Color,
    /// Metres per braille dot horizontally.
    dot: f64,
}

impl Shape for Ring {
    fn draw(&self, painter: &mut Painter) {
        let around = std::f64::consts::TAU * self.radius / self.dot.max(1e-9);
        let n = (around * 1.5).clamp(8.0, 1440.0) as usize;
        // Step around by rotating one vector: no sin/cos per point.
        let (sin, cos) = (std::f64::consts::TAU / n as f64).sin_cos();
        let (mut dx, mut dy) = (self.radius, 0.0);
        for _ in 0..n {
            if let Some((px, py)) = painter.get_point(self.x + dx, self.y + dy) {
                painter.paint(px, py, self.color);
            }
            (dx, dy) = (dx * cos - dy * sin, dx * sin + dy * cos);
        }
    }
}

/// Consecutive points joined by lines, decimated to what the screen can show.
struct Polyline<'a> {
    points: &'a [(f64, f64)],
    color: Color,
}

impl Shape for Polyline<'_> {
    fn draw(&self, painter: &mut Painter) {
        for pair in self.points.windows(2) {
            Line::new(pair[0].0, pair[0].1, pair[1].0, pair[1].1, self.color).draw(painter);
        }
    }
}

/// Keeps points at least `min_step` apart (plus the last one).
fn decimate(points: impl Iterator<Item = (f64, f64)>, min_step: f64) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut last = None;
    let min_step2 = min_step * min_step;
    for p in points {
        match out.last() {
            Some(q) if (p.0 - q.0).powi(2) + (p.1 - q.1).powi(2) < min_step2 => last = Some(p),
            _ => {
                out.push(p);
                last = None;
            }
        }
    }
    if let Some(p) = last {
        out.push(p);
    }
    out
}

fn pane_block(title: TextLine<'static>, focused: bool) -> Block<'static> {
    let border = if focused {
        Color::Yellow
    } else {
        Color::DarkGray
    };
    Block::default()
        .borders(Borders::ALL)
        .border_type(BorderType::Rounded)
        .border_style(Style::default().fg(border))
        .title(title)
}

/// The shown result's part of the map's title, for every pipeline: which
/// run, its verdict (θ-PSO's live plan with its first failing check), and
/// once the mission changed STALE (a live plan: "re-planning…" while its
/// successor is under way or due, or why live planning waits); its full and
/// short forms.
fn result_part(app: &App, job: &Job, outcome: &Outcome) -> Part<'static> {
    let stale = app.is_stale(job);
    let live = app.board().live();
    let name = crate::tui::live::label(job.id);
    // θ-PSO's words are its own: a plan is feasible or not.
    let word = outcome.verdict_word().unwrap_or("cancelled");
    // The designer's own pipeline goes unnamed; the others say theirs.
    let what = if job.pipeline == Kind::default() {
        String::new()
    } else {
        format!("{} ", job.pipeline.words().name)
    };
    let yellow = Style::default().black().on_yellow();
    let (long, short, style) = if Live::owns(job.id) {
        match (stale, live.paused()) {
            (true, Some(why)) if live.is_on() => (
                format!(" {name}: live paused: {why} "),
                " live paused ".to_owned(),
                yellow,
            ),
            (true, _) if live.replanning() => (
                format!(" {name}: re-planning… "),
                " re-planning… ".to_owned(),
                Style::default().fg(Color::Gray),
            ),
            (true, _) => (
                format!(" STALE {name} {what}(mission edited) "),
                format!(" STALE {name} "),
                yellow,
            ),
            (false, _) => {
                let warm = match outcome.face().warm_from() {
                    Some(_) => "warm, ",
                    None => "",
                };
                let ms = job.elapsed(std::time::Instant::now()).as_secs_f64() * 1e3;
                match outcome.verdict() {
                    Verdict::Passed => (
                        format!(" {name} {what}({warm}{ms:.0} ms): {word} "),
                        format!(" {name} ✓ "),
                        Style::default().green(),
                    ),
                    Verdict::Failed(why) => (
                        format!(" {name} {what}{word}: {why} "),
                        format!(" {name} {word} "),
                        Style::default().red().bold(),
                    ),
                    Verdict::Cancelled => (
                        format!(" {name} {what}cancelled "),
                        format!(" {name} cancelled "),
                        Style::default().yellow(),
                    ),
                }
            }
        }
    } else {
        let text = format!(" job {} {what}seed {}: {word} ", job.id, job.seed);
        if stale {
            (
                format!(" STALE{text}(mission edited) "),
                format!(" STALE job {} ", job.id),
                yellow,
            )
        } else if outcome.ok() {
            (
                text,
                format!(" job {} ✓ ", job.id),
                Style::default().green(),
            )
        } else if matches!(outcome.verdict(), Verdict::Cancelled) {
            let short = format!(" job {} cancelled ", job.id);
            (text, short, Style::default().yellow())
        } else {
            let short = format!(" job {} {word} ", job.id);
            (text, short, Style::default().red().bold())
        }
    };
    Part::shortened(2, Span::styled(long, style), Span::styled(short, style))
}

/// The shown job's outcome and how the map charts it (stale, live, the
/// replay's instant).
fn shown_chart(app: &App) -> Option<(&Outcome, ChartView<'_>)> {
    let job = app.shown()?;
    let outcome = job.outcome.as_ref()?;
    let view = ChartView {
        mission: app.mission(),
        stale: app.is_stale(job),
        live: Live::owns(job.id),
        at: app.replay_time(),
    };
    Some((outcome, view))
}

/// The top-down map (or the side view when toggled).
/// The map in `area`, drawn through `vp` (the viewport `Drawn` reports).
///
/// `folded`: the map has the whole width (a narrow screen, the map
/// focused): its bottom line names the selection and says Tab.
///
/// Long (~125 lines) because it is the pane top to bottom: the title's parts
/// (scale, replay, add tool, the shown result, live state, terrain legend),
/// the block, the canvas, then the replay's slider row; most of it is the
/// title, whose parts give way in order on a narrow pane.
pub fn draw_map(frame: &mut Frame, app: &App, area: Rect, vp: &Viewport, folded: bool) {
    if app.side_view() {
        return draw_side(frame, app, area);
    }
    let m = app.mission();
    let vp = *vp;
    let scale = vp.metres_per_column();
    // The title's parts, the least important giving way first (`title::fit`).
    let mut title = vec![
        Part::keep(Span::styled(" Map ", Style::default().bold())),
        Part::optional(3, Span::raw(format!("· {scale:.1} m/cell "))),
        Part::optional(
            5,
            Span::raw(format!(
                "· step {} m ",
                crate::tui::fields::fmt_num(app.step_size())
            )),
        ),
    ];
    if let (Some(t), Some(end)) = (app.replay_time(), app.replay_end()) {
        let state = if app.is_playing() { "▶" } else { "‖" };
        title.push(Part::optional(
            4,
            Span::styled(
                format!(" t = {t:.1} / {end:.1} s {state} "),
                Style::default().black().on_cyan(),
            ),
        ));
    }
    if app.editor().add_tool() {
        let style = Style::default().black().on_green();
        title.push(Part::shortened(
            1,
            Span::styled(" ADD: click to place ", style),
            Span::styled(" ADD ", style),
        ));
    }
    let live = app.board().live();
    match app.shown() {
        Some(job) if job.outcome.is_some() => {
            if let Some(o) = &job.outcome {
                title.push(result_part(app, job, o));
            }
        }
        Some(job) if job.is_running() => {
            title.push(Part::shortened(
                2,
                Span::styled(
                    format!(
                        " {} {} running… {:.0}% ",
                        crate::tui::live::label(job.id),
                        job.pipeline.words().name,
                        job.progress * 100.0
                    ),
                    Style::default().cyan(),
                ),
                Span::styled(
                    format!(" {} running… ", crate::tui::live::label(job.id)),
                    Style::default().cyan(),
                ),
            ));
        }
        _ if live.replanning() => {
            title.push(Part::keep(Span::styled(
                " live: planning… ",
                Style::default().cyan(),
            )));
        }
        _ => {}
    }
    if live.is_on()
        && app.shown().and_then(|j| j.outcome.as_ref()).is_none()
        && let Some(why) = live.paused()
    {
        let style = Style::default().black().on_yellow();
        title.push(Part::shortened(
            1,
            Span::styled(format!(" live paused: {why} "), style),
            Span::styled(" live paused ", style),
        ));
    }
    if let Some(ground) = super::terrain::legend(m) {
        title.push(Part::optional(4, ground));
    }
    let mut block = pane_block(
        fit(title, area.width.saturating_sub(2)),
        app.focus() == Focus::Map,
    );
    if folded {
        block = block.title_bottom(folded_hint(app, area.width));
    }
    let dot = scale / 2.0;
    let canvas = Canvas::default()
        .block(block)
        .marker(Marker::Braille)
        .x_bounds(vp.x)
        .y_bounds(vp.y)
        .paint(|ctx| {
            paint_map(ctx, app, m, dot);
            paint_labels(ctx, app, m, &vp);
        });
    frame.render_widget(canvas, area);
    super::terrain::shade_map(frame.buffer_mut(), m, &vp);
    // The fleet replay's time slider, on the map's last row.
    if let (Some(t), Some(end)) = (app.replay_time(), app.replay_end())
        && area.height > 3
    {
        let row = Rect::new(
            area.x + 2,
            area.y + area.height - 2,
            area.width.saturating_sub(4),
            1,
        );
        let ratio = if end > 0.0 {
            (t / end).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let slider = ratatui::widgets::LineGauge::default()
            .filled_style(Style::default().fg(Color::Cyan))
            .unfilled_style(Style::default().fg(Color::DarkGray))
            .label(format!("t {t:.1} s"))
            .ratio(ratio);
        frame.render_widget(ratatui::widgets::Clear, row);
        frame.render_widget(slider, row);
    }
}

/// Long (~140 lines): the map's layers in drawing order (terrain, bounds,
/// obstacles, IWPs, plans, vehicles), each a short block.
fn paint_map(ctx: &mut Context, app: &App, m: &Mission, dot: f64) {
    let b = &m.bounds;
    ctx.draw(&Rectangle {
        x: b.x[0],
        y: b.y[0],
        width: b.x[1] - b.x[0],
        height: b.y[1] - b.y[0],
        color: Color::Gray,
    });
    let safe = m.formation.safe_radius();
    // Safe radii first, lightly, so obstacles and paths draw over them.
    for (center, radius) in m.obstacles.iter().filter_map(|o| o.outline().disc()) {
        ctx.draw(&Ring {
            x: center.x,
            y: center.y,
            radius: radius + safe,
            color: Color::DarkGray,
            dot,
        });
    }
    // Inspected obstacles (eq. 8): their stand-off band as two rings.
    for o in m.obstacles.iter().filter(|o| o.inspect) {
        for d in o.stand_off_band(&m.formation) {
            ctx.draw(&Ring {
                x: o.center.x,
                y: o.center.y,
                radius: o.radius + d,
                color: Color::Magenta,
                dot,
            });
        }
    }
    for (i, o) in m.obstacles.iter().enumerate() {
        let selected = matches!(*app.selected(), Item::Obstacle(k) | Item::Vertex(k, _) if k == i);
        let color = if selected {
            Color::Yellow
        } else if o.inspect {
            Color::LightMagenta
        } else if o.height <= b.z[0] {
            Color::Gray
        } else {
            Color::LightRed
        };
        let shape = o.outline();
        if let Some((center, radius)) = shape.disc() {
            ctx.draw(&Ring {
                x: center.x,
                y: center.y,
                radius,
                color,
                dot,
            });
            if selected {
                // A filled centre so a small selected obstacle is easy to see.
                ctx.draw(&Ring {
                    x: center.x,
                    y: center.y,
                    radius: radius * 0.5,
                    color,
                    dot,
                });
            }
        } else {
            // The outline, closed, drawn to a dot's width.
            let ring = shape.ring(dot);
            let outline: Vec<(f64, f64)> = ring
                .iter()
                .chain(ring.first())
                .map(|p| (p.x, p.y))
                .collect();
            ctx.draw(&Polyline {
                points: &outline,
                color,
            });
        }
        if selected && shape.disc().is_none() {
            // A selected footprint's corners, the one being edited filled.
            for (v, q) in o.footprint.iter().enumerate() {
                let edited = *app.selected() == Item::Vertex(i, v);
                ctx.draw(&Ring {
                    x: q.x,
                    y: q.y,
                    radius: dot * if edited { 1.5 } else { 0.8 },
                    color: if edited { Color::White } else { color },
                    dot,
                });
            }
        }
    }
    ctx.layer();

    // The result: live best path while running, else the shown outcome.
    if let Some(job) = app
        .shown()
        .filter(|j| j.is_running() && !j.live_path.is_empty())
    {
        let pts = decimate(job.live_path.iter().map(|p| (p.x, p.y)), dot);
        ctx.draw(&Polyline {
            points: &pts,
            color: Color::Blue,
        });
    } else if let Some(job) = app
        .jobs()
        .iter()
        .rev()
        .find(|j| j.is_running() && !j.live_path.is_empty())
    {
        let pts = decimate(job.live_path.iter().map(|p| (p.x, p.y)), dot);
        ctx.draw(&Polyline {
            points: &pts,
            color: Color::Blue,
        });
    }
    paint_refusal(ctx, app);
    // The route's vias: a gate (‖) at its gap's middle, a point (⊙).
    for (k, at) in via_marks(m) {
        let style = if *app.selected() == Item::Via(k) {
            Style::default().black().on_yellow().bold()
        } else {
            Style::default().fg(Color::LightGreen).bold()
        };
        let glyph = if m.route.via[k].point.is_some() {
            "⊙"
        } else {
            "‖"
        };
        ctx.print(at.x, at.y, Span::styled(format!("{glyph}{}", k + 1), style));
    }
    for point in crate::pipelines::points::every_point(m) {
        let (Some(kind), Some(c)) = (point.kind(), point.centre(m)) else {
            continue;
        };
        let style = if *app.selected() == Item::Point(point) {
            Style::default().black().on_yellow().bold()
        } else {
            Style::default().fg(Color::Yellow).bold()
        };
        // A point of several spots (a target of one per agent): each spot
        // a dot, the point's number at their middle.
        for q in (kind.spots)(m, point.index) {
            ctx.print(q.x, q.y, Span::styled("·", style));
        }
        ctx.print(
            c.x,
            c.y,
            Span::styled(format!("{}{}", kind.glyph, point.index + 1), style),
        );
    }
    let shown = shown_chart(app);
    if let Some((o, view)) = &shown {
        let mut canvas = OnCanvas {
            ctx,
            step: dot,
            dot,
        };
        o.face().chart(view, &mut canvas);
    }
    paint_flight_check(ctx, app, dot);
    if shown.is_none_or(|(o, _)| !o.kind().words().dwarfs_the_site) {
        draw_formation_at_start(ctx, app, m, dot);
    }
}

/// A refusal (NO PLAN) of the shown run: the route that was tried, and
/// each passage that closes the way across its gap; the widest, the one to
/// widen, with its width and what it needs.
fn paint_refusal(ctx: &mut Context, app: &App) {
    if let Some(no) = app.shown().and_then(refusal) {
        let tried: Vec<(f64, f64)> = no.route.iter().map(|p| (p[0], p[1])).collect();
        ctx.draw(&Polyline {
            points: &tried,
            color: Color::LightYellow,
        });
        for (k, p) in no.passages.iter().enumerate() {
            let [a, b] = p.ends;
            ctx.draw(&Line {
                x1: a[0],
                y1: a[1],
                x2: b[0],
                y2: b[1],
                color: Color::LightRed,
            });
            if k > 0 {
                continue;
            }
            ctx.print(
                (a[0] + b[0]) / 2.0,
                (a[1] + b[1]) / 2.0,
                Span::styled(
                    format!("✕ {:.2} m < {:.2} m", p.width, p.needs),
                    Style::default().fg(Color::LightRed).bold(),
                ),
            );
        }
    }
}

/// The job's refusal, when the route search found no way: what it names
/// and tried.
fn refusal(job: &Job) -> Option<&crate::pipelines::NoPlan> {
    match &job.state {
        crate::tui::jobs::JobState::Failed(crate::tui::jobs::JobError::Pipeline(
            crate::pipelines::PipelineError::NoRoute(no),
        )) => Some(no),
        _ => None,
    }
}

/// The shown job's flight check (`G`): each UAV's p99 envelope as rings
/// along its plan (a ring of that radius every second or so, in the UAV's
/// colour), and the worst place marked.
fn paint_flight_check(ctx: &mut Context, app: &App, dot: f64) {
    let Some(crate::tui::jobs::FlightCheck::Done(r)) = app.shown().and_then(|j| j.flight.as_ref())
    else {
        return;
    };
    for (v, points) in r.envelope.iter().enumerate() {
        // At 20 Hz, every 20th sample: one ring a second of flight.
        for &(p, radius) in points.iter().step_by(20) {
            if radius > dot {
                ctx.draw(&Ring {
                    x: p.x,
                    y: p.y,
                    radius,
                    color: uav_color(v),
                    dot,
                });
            }
        }
    }
    if let Some((_, at)) = &r.worst {
        ctx.print(
            at.x,
            at.y,
            Span::styled("✕ worst", Style::default().red().bold()),
        );
    }
}

/// The slots around the start, facing the goal (or the planned path's first leg).
fn draw_formation_at_start(ctx: &mut Context, app: &App, m: &Mission, dot: f64) {
    let start = m.route.start;
    let toward = shown_chart(app)
        .and_then(|(o, _)| {
            // The plan's first step off the start, where it has a path.
            o.face()
                .flown_path()?
                .iter()
                .find(|p| (p.xy() - start.xy()).norm() > 1e-6)
                .copied()
        })
        .unwrap_or(m.route.goal);
    let d = (toward - start).xy();
    let heading = if d.norm() > 1e-9 { d.y.atan2(d.x) } else { 0.0 };
    let (s, c) = heading.sin_cos();
    for (i, slot) in m.formation.slots.iter().enumerate() {
        let x = start.x + c * slot.x - s * slot.y;
        let y = start.y + s * slot.x + c * slot.y;
        ctx.draw(&Ring {
            x,
            y,
            radius: m.formation.uav_radius,
            color: uav_color(i),
            dot,
        });
    }
}

/// The bottom line of a pane that has the whole width (a narrow screen,
/// the map focused): what is selected, and that Tab brings the inspector.
pub fn folded_hint(app: &App, width: u16) -> TextLine<'static> {
    let selected = app.selected().title(app.mission());
    fit(
        vec![
            Part::keep(Span::styled(
                format!(" {selected} "),
                Style::default().yellow(),
            )),
            Part::shortened_optional(
                1,
                Span::raw("· Tab: inspector and jobs "),
                Span::raw("· Tab "),
            ),
        ],
        width.saturating_sub(2),
    )
}

/// Where each route via is marked on the map: a via point at its point, a
/// gate at the middle of its two obstacles' nearest points (none for a
/// gate naming an obstacle the mission does not have).
pub(super) fn via_marks(m: &crate::mission::Mission) -> Vec<(usize, Point2<f64>)> {
    m.route
        .via
        .iter()
        .enumerate()
        .filter_map(|(k, v)| {
            if let Some(p) = v.point {
                return Some((k, p.xy()));
            }
            let [a, b] = v.between.as_ref()?;
            let find = |n: &str| m.obstacles.iter().find(|o| o.name == n);
            let (pa, pb) = (m.prism(find(a)?), m.prism(find(b)?));
            let (p, q) = crate::base::shape::nearest_points(&*pa.outline, &*pb.outline);
            Some((k, nalgebra::center(&p, &q)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_the_ends() {
        let pts: Vec<(f64, f64)> = (0..=100).map(|i| (i as f64 * 0.01, 0.0)).collect();
        let d = decimate(pts.into_iter(), 0.25);
        assert_eq!(d.first(), Some(&(0.0, 0.0)));
        assert_eq!(d.last(), Some(&(1.0, 0.0)));
        assert!(d.len() <= 6, "{d:?}");
    }
}
