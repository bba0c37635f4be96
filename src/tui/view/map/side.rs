//! The side view: distance along the path against altitude.

use super::*;

/// Distance along the path vs altitude, with the altitude band and the
/// obstacles the path passes.
///
/// Long (~150 lines): the side view's layers in drawing order (band, obstacles, vehicles, the
/// flight check's envelope, path).
pub(super) fn draw_side(frame: &mut Frame, app: &App, area: Rect) {
    let m = app.mission();
    // The shown result that has a path to unroll, else start to goal.
    let result = shown_chart(app).filter(|(o, _)| o.face().flown_path().is_some());
    let centroid: Vec<Point3<f64>> = match result.as_ref().and_then(|(o, _)| o.face().flown_path())
    {
        Some(path) => path.to_vec(),
        None => vec![m.route.start, m.route.goal],
    };
    let along = cumulative(&centroid);
    let length = along.last().copied().unwrap_or(0.0).max(1.0);
    // With terrain: the ground under the path, and the band above it.
    let ground = super::super::terrain::ground_profile(m, &centroid, &along, 400);
    let highest = ground.iter().map(|g| g.1).fold(0.0, f64::max);
    // The obstacles' tops on the ground under them (drawn so below).
    let top = m
        .obstacles
        .iter()
        .map(|o| o.height + m.ground(o.center.x, o.center.y))
        .fold(m.bounds.z[1] + highest, f64::max)
        .max(1.0)
        * 1.15;
    let title = fit(
        vec![
            Part::keep(Span::styled(" Side view ", Style::default().bold())),
            Part::shortened(
                1,
                Span::raw(format!(
                    "· distance along the path (0-{length:.0} m) vs altitude (0-{top:.0} m) "
                )),
                Span::raw(format!("· 0-{length:.0} m × 0-{top:.0} m ")),
            ),
            Part::optional(2, Span::raw("· v: top view ")),
        ],
        area.width.saturating_sub(2),
    );
    let stale = result.as_ref().is_some_and(|(_, view)| view.stale);
    let canvas = Canvas::default()
        .block(pane_block(title, app.focus() == Focus::Map))
        .marker(Marker::Braille)
        .x_bounds([-0.02 * length, 1.02 * length])
        .y_bounds([0.0, top])
        .paint(|ctx| {
            if ground.is_empty() {
                for z in m.bounds.z {
                    ctx.draw(&Line::new(0.0, z, length, z, Color::DarkGray));
                }
            } else {
                for z in m.bounds.z {
                    let band: Vec<(f64, f64)> = ground.iter().map(|&(s, g)| (s, g + z)).collect();
                    ctx.draw(&Polyline {
                        points: &band,
                        color: Color::DarkGray,
                    });
                }
                ctx.draw(&Polyline {
                    points: &ground,
                    color: Color::Yellow,
                });
                ctx.print(
                    length * 0.85,
                    highest,
                    Span::styled("ground", Style::default().fg(Color::Yellow)),
                );
            }
            // The altitude axis: the band's limits with their numbers.
            for (z, name) in [(m.bounds.z[1], "z max"), (m.bounds.z[0], "z min")] {
                ctx.print(
                    0.0,
                    z,
                    Span::styled(
                        format!("{name} {} m", crate::tui::fields::fmt_num(z)),
                        Style::default().fg(Color::DarkGray),
                    ),
                );
            }
            draw_obstacles(
                ctx,
                m,
                (&centroid, &along),
                [length, top],
                area,
                result.is_none(),
            );
            // The route's vias, each a line up the altitudes where the path
            // takes it (nearest along the path), numbered.
            for (k, at) in super::via_marks(m) {
                if let Some((s, _)) = closest_along(&centroid, &along, &at) {
                    ctx.draw(&Line::new(s, 0.0, s, top * 0.95, Color::LightGreen));
                    ctx.print(
                        s,
                        top * 0.97,
                        Span::styled(
                            format!("via {}", k + 1),
                            Style::default().fg(Color::LightGreen),
                        ),
                    );
                }
            }
            ctx.layer();
            if let Some((o, view)) = &result {
                let mut canvas = OnCanvas {
                    ctx,
                    step: length / 400.0,
                    dot: length / 400.0,
                };
                o.face().chart_side(view, &mut canvas);
            }
            // The flight check's p99 envelope (`G`): a bar of its radius
            // above and below each UAV's plan, one a second, and the worst place.
            if let Some(crate::tui::jobs::FlightCheck::Done(r)) =
                app.shown().and_then(|j| j.flight.as_ref())
            {
                for (v, points) in r.envelope.iter().enumerate() {
                    for &(p, radius) in points.iter().step_by(20) {
                        if let Some((s, _)) = closest_along(&centroid, &along, &p.xy()) {
                            ctx.draw(&Line::new(s, p.z - radius, s, p.z + radius, uav_color(v)));
                        }
                    }
                }
                if let Some((_, at)) = &r.worst
                    && let Some((s, _)) = closest_along(&centroid, &along, &at.xy())
                {
                    ctx.print(
                        s,
                        at.z,
                        Span::styled("✕ worst", Style::default().red().bold()),
                    );
                }
            }
            let pts: Vec<(f64, f64)> = along
                .iter()
                .zip(&centroid)
                .map(|(s, p)| (*s, p.z))
                .collect();
            ctx.draw(&Polyline {
                points: &pts,
                color: if stale { Color::Gray } else { Color::White },
            });
            if result.is_none() {
                ctx.print(
                    0.05 * length,
                    top * 0.9,
                    Span::raw("straight line start → goal; run θ-PSO (r) for the plan"),
                );
            }
        });
    frame.render_widget(canvas, area);
}

/// The obstacles near the path, each over the stretch of it that passes
/// under, over or beside it, and their names where they fit (`Names`).
fn draw_obstacles(
    ctx: &mut ratatui::widgets::canvas::Context,
    m: &crate::mission::Mission,
    (centroid, along): (&[Point3<f64>], &[f64]),
    [length, top]: [f64; 2],
    area: Rect,
    no_plan: bool,
) {
    // Each obstacle over the stretch of the path that passes under,
    // over or beside it (within the formation's reach of its
    // footprint), at its own heights; one near the path but not
    // that near (within `NEAR` of the reach), and every inspected
    // one, as a bar at its closest point, named.
    let reach = m.formation.safe_radius();
    // Names raised a row where they would cover one already printed.
    let mut names = Names {
        column: 1.04 * length / f64::from(area.width.saturating_sub(2).max(1)),
        row: top / f64::from(area.height.saturating_sub(2).max(1)),
        taken: Vec::new(),
    };
    if no_plan {
        // The line printed there below (no plan yet).
        let x = 0.05 * length;
        names.taken.push((x, x + 60.0 * names.column, top * 0.9));
    }
    let mut labels: Vec<(bool, f64, f64, String, Color)> = Vec::new();
    for o in &m.obstacles {
        let prism = m.prism(o);
        let (stretches, closest) = stretches_by(centroid, along, &prism, reach, length);
        let near = closest.is_some_and(|(_, d)| d <= reach + NEAR);
        if stretches.is_empty() && !near && !o.inspect {
            continue;
        }
        let color = if o.inspect {
            Color::LightMagenta
        } else {
            Color::LightRed
        };
        let base = prism.base;
        // Its physical top (not the sky a no-overfly one is kept as),
        // on the ground under it.
        let height = o.height + (prism.base - o.base);
        let bars: Vec<[f64; 2]> = if stretches.is_empty() {
            let s = closest.map_or(0.0, |(s, _)| s);
            let half = (length / 300.0).max(0.3);
            vec![[s - half, s + half]]
        } else {
            stretches
        };
        for [a, b] in &bars {
            ctx.draw(&Rectangle {
                x: *a,
                y: base,
                width: (b - a).max(length / 400.0),
                height: (height - base).max(0.0),
                color,
            });
        }
        if o.inspect || stretches_named(o, &bars) {
            labels.push((o.inspect, bars[0][0], height, o.name.clone(), color));
        }
    }
    // The inspected ones' names first (the mission's subject), then
    // the others', each where it covers no other.
    labels.sort_by_key(|l| !l.0);
    for (_, x, z, name, color) in labels {
        if let Some(at) = names.place(x, z, name.chars().count(), top) {
            ctx.print(x, at, Span::styled(name, Style::default().fg(color)));
        }
    }
}

fn cumulative(points: &[Point3<f64>]) -> Vec<f64> {
    let mut s = 0.0;
    let mut out = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        if i > 0 {
            s += (p - points[i - 1]).xy().norm();
        }
        out.push(s);
    }
    out
}

/// Along-path distance of the closest approach to `c`, and that distance.
fn closest_along(points: &[Point3<f64>], along: &[f64], c: &Point2<f64>) -> Option<(f64, f64)> {
    let mut best: Option<(f64, f64)> = None;
    for i in 1..points.len() {
        let (a, b) = (points[i - 1].xy(), points[i].xy());
        let (t, d) = segment_projection(&a, &b, c);
        if best.is_none_or(|(_, bd)| d < bd) {
            best = Some((along[i - 1] + t * (b - a).norm(), d));
        }
    }
    best
}

/// The side view's obstacle names so far, in data units (metres along,
/// metres up), and the size of a cell in them.
struct Names {
    column: f64,
    row: f64,
    taken: Vec<(f64, f64, f64)>,
}

impl Names {
    /// The altitude to print a name of `chars` at `x`: `z`, else a row at
    /// a time up to `top`, else down to the ground, where it covers no name
    /// already placed; taken from then on. `None` where none is free.
    fn place(&mut self, x: f64, z: f64, chars: usize, top: f64) -> Option<f64> {
        let width = (chars as f64 + 1.0) * self.column;
        let free = |at: f64| {
            !self
                .taken
                .iter()
                .any(|&(x0, x1, z0)| (at - z0).abs() < self.row && x < x1 && x0 < x + width)
        };
        let row = self.row.max(1e-9);
        let up = (0..)
            .map(|k| z + k as f64 * row)
            .take_while(|at| *at < top - row);
        let down = (1..)
            .map(|k| z - k as f64 * row)
            .take_while(|at| *at >= 0.0);
        let at = up.chain(down).find(|at| free(*at))?;
        self.taken.push((x, x + width, at));
        Some(at)
    }
}

/// Beyond the formation's reach, how near the path an obstacle may stand
/// and still be drawn (as a bar at its closest point), metres.
const NEAR: f64 = 5.0;

/// The stretches of the path (along-path distances [from, to]) whose
/// centroid comes within `reach` of `prism`'s footprint, sampled every
/// `length / 400` m, and the closest approach (along, distance to the
/// footprint) over the whole path.
fn stretches_by(
    points: &[Point3<f64>],
    along: &[f64],
    prism: &crate::base::shape::Prism,
    reach: f64,
    length: f64,
) -> (Vec<[f64; 2]>, Option<(f64, f64)>) {
    let step = (length / 400.0).max(0.05);
    let mut stretches: Vec<[f64; 2]> = Vec::new();
    let mut closest: Option<(f64, f64)> = None;
    let mut open: Option<f64> = None;
    for i in 1..points.len() {
        let (a, b) = (points[i - 1].xy(), points[i].xy());
        let leg = (b - a).norm();
        let n = (leg / step).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let s = along[i - 1] + t * leg;
            let d = prism.outward(&(a + (b - a) * t));
            if closest.is_none_or(|(_, cd)| d < cd) {
                closest = Some((s, d));
            }
            match (d <= reach, open) {
                (true, None) => open = Some(s),
                (false, Some(from)) => {
                    stretches.push([from, s]);
                    open = None;
                }
                _ => {}
            }
        }
    }
    if let Some(from) = open {
        stretches.push([from, along.last().copied().unwrap_or(from)]);
    }
    (stretches, closest)
}

/// Whether to name an obstacle drawn over `bars`: one the path passes
/// beside for long enough to print its name over.
fn stretches_named(o: &crate::mission::Obstacle, bars: &[[f64; 2]]) -> bool {
    !o.name.is_empty() && bars.iter().any(|[a, b]| b - a > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 50: a deck 126 m long across a straight path is drawn over
    /// the stretch the path passes under it (its 5 m width and the
    /// formation's reach each side), not over its length; a mast beside
    /// the path, out of reach, has no stretch but its closest point.
    #[test]
    fn a_deck_across_the_path_is_drawn_where_the_path_passes_under_it() {
        let path = [
            Point3::new(-70.0, -9.0, 10.0),
            Point3::new(70.0, -9.0, 10.0),
        ];
        let along = cumulative(&path);
        let mut deck = crate::mission::Obstacle::standing("deck", Point2::origin(), 0.0, 25.0);
        deck.footprint = vec![
            Point2::new(-2.5, -63.0),
            Point2::new(2.5, -63.0),
            Point2::new(2.5, 63.0),
            Point2::new(-2.5, 63.0),
        ];
        deck.base = 22.0;
        deck.settle();
        let reach = 5.15;
        let (stretches, _) = stretches_by(&path, &along, &deck.prism(), reach, 140.0);
        assert_eq!(stretches.len(), 1, "{stretches:?}");
        let [a, b] = stretches[0];
        let step = 140.0 / 400.0;
        assert!((a - (70.0 - 2.5 - reach)).abs() <= step, "{a}");
        assert!((b - (70.0 + 2.5 + reach)).abs() <= step, "{b}");
        let mast = crate::mission::Obstacle::standing("mast", Point2::new(30.0, 0.0), 1.0, 30.0);
        let (none, closest) = stretches_by(&path, &along, &mast.prism(), reach, 140.0);
        assert!(none.is_empty());
        let (s, d) = closest.unwrap_or_default();
        assert!(
            (s - 100.0).abs() <= step && (d - 8.0).abs() < 1e-2,
            "{s} {d}"
        );
        assert!(d <= reach + NEAR, "near enough to be drawn as a bar");
    }
}
