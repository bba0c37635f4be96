//! Terrain in the views: the map's cells shaded by the ground under them,
//! and the ground profile under a path (side view).

use nalgebra::Point3;
use ratatui::buffer::Buffer;
use ratatui::style::{Color, Style};
use ratatui::text::Span;

use super::viewport::Viewport;
use crate::mission::Mission;

/// The shade of a cell whose ground is at `t` of the map's height range
/// (0 lowest, 1 highest): dark green low to brown high, dim enough for the
/// braille layer and the labels drawn over it to stay readable.
pub fn ground_shade(t: f64) -> Color {
    let [r, g, b] = crate::base::terrain::height_ramp(t, [18, 44, 22], [96, 66, 30]);
    Color::Rgb(r, g, b)
}

/// Sets the background of every map cell over the terrain to the shade of
/// the ground at the cell's centre (nearest pixel); the glyphs drawn there
/// keep their colour. Cells off the height map stay unshaded.
pub fn shade_map(buffer: &mut Buffer, mission: &Mission, viewport: &Viewport) {
    let Some(map) = mission.height_map() else {
        return;
    };
    let [low, high] = map.range;
    let span = f64::from(high - low).max(1e-9);
    let area = viewport.inner.intersection(buffer.area);
    for row in area.top()..area.bottom() {
        for column in area.left()..area.right() {
            let Some(p) = viewport.to_world(column, row) else {
                continue;
            };
            let Some(h) = map.nearest(p.x, p.y) else {
                continue;
            };
            if let Some(cell) = buffer.cell_mut((column, row)) {
                cell.set_bg(ground_shade(f64::from(h - low) / span));
            }
        }
    }
}

/// The map title's note of the terrain's height range, in the shades used.
pub fn legend(mission: &Mission) -> Option<Span<'static>> {
    let [low, high] = mission.height_map()?.range;
    Some(Span::styled(
        format!(" ground {low:.0}–{high:.0} m "),
        Style::default().fg(Color::White).bg(ground_shade(0.5)),
    ))
}

/// (distance along the path, ground height) at about `samples` points of
/// the path's horizontal track; empty without terrain. `along[i]` is the
/// horizontal distance of `points[i]` from the start.
pub fn ground_profile(
    mission: &Mission,
    points: &[Point3<f64>],
    along: &[f64],
    samples: usize,
) -> Vec<(f64, f64)> {
    if mission.height_map().is_none() || points.len() < 2 {
        return Vec::new();
    }
    let length = along.last().copied().unwrap_or(0.0);
    let step = (length / samples.max(1) as f64).max(1e-9);
    let mut out = Vec::with_capacity(samples + points.len());
    for (i, leg) in points.windows(2).enumerate() {
        let (a, b) = (leg[0], leg[1]);
        let (s0, s1) = (along[i], along[i + 1]);
        let pieces = ((s1 - s0) / step).ceil().max(1.0) as usize;
        for k in 0..=pieces {
            let t = k as f64 / pieces as f64;
            let p = a + (b - a) * t;
            out.push((s0 + t * (s1 - s0), mission.ground(p.x, p.y)));
        }
    }
    out
}
