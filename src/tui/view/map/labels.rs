//! The map's text: IWP marks, obstacle names where they fit without
//! covering another, start and goal.

use super::*;

/// Cells taken by the map's text, so a label is drawn only where it does
/// not cover another (at 80×24 the bridge's piers are a few cells apart).
struct Labels<'a> {
    vp: &'a Viewport,
    taken: Vec<Rect>,
}

impl Labels<'_> {
    /// The cell the canvas prints a label at `(x, y)` in (its own rounding,
    /// which is not [`Viewport::to_cell`]'s), or None outside the view.
    fn cell(&self, x: f64, y: f64) -> Option<(u16, u16)> {
        let (r, vp) = (self.vp.inner, self.vp);
        let inside = (vp.x[0]..=vp.x[1]).contains(&x) && (vp.y[0]..=vp.y[1]).contains(&y);
        if !inside || r.width == 0 || r.height == 0 {
            return None;
        }
        let fx = (x - vp.x[0]) * f64::from(r.width - 1) / (vp.x[1] - vp.x[0]);
        let fy = (vp.y[1] - y) * f64::from(r.height - 1) / (vp.y[1] - vp.y[0]);
        Some((r.x + fx as u16, r.y + fy as u16))
    }

    /// The cells text of `width` printed at `(x, y)` covers, when all of it
    /// is in view.
    fn rect(&self, x: f64, y: f64, width: usize) -> Option<Rect> {
        let (column, row) = self.cell(x, y)?;
        let width = u16::try_from(width).ok()?;
        let r = Rect::new(column, row, width, 1);
        (r.right() <= self.vp.inner.right()).then_some(r)
    }

    fn free(&self, r: Rect) -> bool {
        // One blank column between two labels, so they do not read as one.
        let padded = Rect::new(r.x.saturating_sub(1), r.y, r.width + 2, 1);
        !self.taken.iter().any(|t| t.intersects(padded))
    }

    /// Marks text printed regardless (markers) as taken.
    fn reserve(&mut self, x: f64, y: f64, width: usize) {
        if let Some((column, row)) = self.cell(x, y) {
            let width = u16::try_from(width).unwrap_or(u16::MAX);
            self.taken.push(Rect::new(column, row, width, 1));
        }
    }

    /// Prints `label` at the first of `spots` where it is in view and free;
    /// `force` prints it even when none is (the selection's): at the first
    /// spot where it is whole in view, else the first.
    fn place(
        &mut self,
        ctx: &mut Context,
        spots: &[(f64, f64)],
        label: Span<'static>,
        force: bool,
    ) {
        let width = label.width();
        let spot = spots
            .iter()
            .find(|(x, y)| self.rect(*x, *y, width).is_some_and(|r| self.free(r)))
            .or_else(|| {
                // Forced: where it is whole in view if it can be, not cut at
                // the map's edge.
                let whole = spots
                    .iter()
                    .find(|(x, y)| self.rect(*x, *y, width).is_some());
                whole.or(spots.first()).filter(|_| force)
            });
        if let Some(&(x, y)) = spot {
            if let Some(r) = self.rect(x, y, width) {
                self.taken.push(r);
            }
            ctx.print(x, y, label);
        }
    }
}

/// The map's text: IWP marks, obstacle names where they fit, start and goal.
/// Sites of at most this many obstacles have every name drawn (where it
/// fits); on larger ones, the selected, the found, the inspected and
/// `NEAREST_NAMED` nearest the path.
const ALL_NAMED: usize = 40;
const NEAREST_NAMED: usize = 12;

/// The map's text in the order it claims its cells: start, goal and the
/// fleet's targets, the IWPs and the selected one's name, then the
/// obstacles' names.
///
/// Long (~140 lines) because it places each kind of label in turn (marks, the selected IWP,
/// the obstacles in order: selected, found, nearest), each where no other text is.
pub(super) fn paint_labels(ctx: &mut Context, app: &App, m: &Mission, vp: &Viewport) {
    // A result drawn at kilometre scale (FLATLO's): the θ-PSO route, IWPs
    // and obstacle names would be letters piled on a few cells (the
    // selected obstacle's name is still drawn).
    let kilometres = shown_chart(app).is_some_and(|(o, _)| o.kind().words().dwarfs_the_site);
    let scale = vp.metres_per_column();
    let mut labels = Labels {
        vp,
        taken: Vec::new(),
    };
    let (s, g) = (&m.route.start, &m.route.goal);
    if !kilometres {
        labels.reserve(s.x, s.y, 1);
        labels.reserve(g.x, g.y, 1);
        for c in crate::pipelines::points::every_point(m)
            .iter()
            .filter_map(|p| p.centre(m))
        {
            labels.reserve(c.x, c.y, 2);
        }
        for (_, at) in super::via_marks(m) {
            labels.reserve(at.x, at.y, 2);
        }
        // IWPs (eq. 9): enabled ones bright, disabled ones dim, the
        // selected one highlighted and named.
        // A gate of the route is drawn as its via (‖), not as an IWP.
        for w in app.iwps().iter().filter(|w| w.gate.is_none()) {
            let selected = *app.selected() == Item::Waypoint(w.between.clone());
            let (glyph, style) = match (selected, w.enabled) {
                (true, true) => ("◆", Style::default().black().on_yellow()),
                (true, false) => ("◇", Style::default().black().on_yellow()),
                (false, true) => ("◆", Style::default().fg(Color::LightCyan)),
                (false, false) => ("◇", Style::default().fg(Color::DarkGray)),
            };
            labels.reserve(w.position.x, w.position.y, 1);
            ctx.print(w.position.x, w.position.y, Span::styled(glyph, style));
        }
        if let Some(w) = app
            .iwps()
            .iter()
            .find(|w| *app.selected() == Item::Waypoint(w.between.clone()))
        {
            let label = format!("{} ↔ {}", w.between[0], w.between[1]);
            let width = Span::raw(label.as_str()).width() as f64;
            let spots = [
                (w.position.x + 2.0 * scale, w.position.y),
                (w.position.x - scale * (width + 1.0), w.position.y),
            ];
            let style = Style::default().black().on_yellow().bold();
            labels.place(ctx, &spots, Span::styled(label, style), true);
        }
    }
    // Obstacle names, right of the obstacle or else left of it, where they
    // cover no other text: the selected one's always, first; then a find's
    // matches; then, on a site of at most 40 obstacles, the others, and on
    // a larger one the inspected ones and the 12 nearest the path.
    let selected = match *app.selected() {
        Item::Obstacle(i) => Some(i),
        _ => None,
    };
    let found: Vec<usize> = app
        .finder()
        .matches()
        .iter()
        .filter_map(|item| match item {
            Item::Obstacle(i) if Some(*i) != selected => Some(*i),
            _ => None,
        })
        .collect();
    // On a larger site, the inspected ones and those nearest the path on
    // the map (the shown plan's, else start to goal), nearest first.
    let others = (0..m.obstacles.len()).filter(|i| Some(*i) != selected && !found.contains(i));
    let rest: Vec<usize> = if kilometres {
        Vec::new()
    } else if m.obstacles.len() <= ALL_NAMED {
        others.collect()
    } else {
        let path: Vec<Point2<f64>> = shown_chart(app)
            .and_then(|(o, _)| {
                o.face()
                    .flown_path()
                    .map(|p| p.iter().map(|q| q.xy()).collect())
            })
            .unwrap_or_else(|| vec![s.xy(), g.xy()]);
        let distance = |i: usize| {
            let prism = m.obstacles[i].prism();
            path.windows(2)
                .map(|w| prism.segment_distance(&w[0], &w[1]))
                .fold(f64::INFINITY, f64::min)
        };
        let mut near: Vec<(usize, f64)> = others
            .map(|i| {
                (
                    i,
                    if m.obstacles[i].inspect {
                        f64::NEG_INFINITY
                    } else {
                        distance(i)
                    },
                )
            })
            .collect();
        near.sort_by(|a, b| a.1.total_cmp(&b.1));
        near.into_iter()
            .take(NEAREST_NAMED)
            .map(|(i, _)| i)
            .collect()
    };
    let order = selected
        .into_iter()
        .chain(found.iter().copied())
        .chain(rest);
    for i in order {
        let Some(o) = m.obstacles.get(i) else {
            continue;
        };
        let style = if selected == Some(i) {
            Style::default().black().on_yellow().bold()
        } else if found.contains(&i) {
            Style::default().yellow()
        } else if o.inspect {
            Style::default().fg(Color::LightMagenta)
        } else {
            Style::default().fg(Color::Gray)
        };
        let label = if o.inspect {
            format!("{} ◉", o.name)
        } else {
            o.name.clone()
        };
        let width = Span::raw(label.as_str()).width() as f64;
        // Beside the outline at its centre's height: a footprint's own
        // extent across, not its bounding circle's (a long beam's is wide).
        let shape = o.outline();
        let (west, east) = match shape.disc() {
            Some((c, r)) => (c.x - r, c.x + r),
            None => shape
                .ring(scale)
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p.x), hi.max(p.x))
                }),
        };
        let spots = [
            (east + scale, o.center.y),
            (west - scale * (width + 1.0), o.center.y),
        ];
        labels.place(ctx, &spots, Span::styled(label, style), selected == Some(i));
    }
    if kilometres {
        return;
    }
    let marker = |item: Item, glyph: &'static str, color: Color| {
        let style = if *app.selected() == item {
            Style::default().black().bg(color).bold()
        } else {
            Style::default().fg(color).bold()
        };
        Span::styled(glyph, style)
    };
    ctx.print(s.x, s.y, marker(Item::Start, "S", Color::Green));
    ctx.print(g.x, g.y, marker(Item::Goal, "G", Color::Red));
}
