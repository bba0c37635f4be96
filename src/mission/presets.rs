//! Standard formation shapes for n UAVs, offered by the TUI's formation editor.
//!
//! Offsets are in the formation frame (x forward along the path, y left, z up),
//! metres, with the centroid at the origin so that the θ-PSO centroid path is
//! the formation's centre.

use nalgebra::Vector3;

use super::model::{Formation, Mission, Reconfiguration};

/// A named family of formation shapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Preset {
    /// Rows of 1, 2, 3 … UAVs, the point forward (n = 3 is an equilateral triangle).
    Triangle,
    /// All side by side, across the direction of travel.
    LineAbreast,
    /// All one behind the other (single file).
    Column,
    /// A wedge: the leader ahead, the others alternately left and right behind it.
    Vee,
    /// Front, left, right, back on a square turned 45°; more UAVs on wider rings.
    Diamond,
}

impl Preset {
    pub const ALL: [Preset; 5] = [
        Preset::Triangle,
        Preset::LineAbreast,
        Preset::Column,
        Preset::Vee,
        Preset::Diamond,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Preset::Triangle => "triangle",
            Preset::LineAbreast => "line abreast",
            Preset::Column => "column",
            Preset::Vee => "V",
            Preset::Diamond => "diamond",
        }
    }

    /// The next preset, wrapping around (the editor cycles with one key).
    pub fn next(self) -> Preset {
        let i = Preset::ALL.iter().position(|&p| p == self).unwrap_or(0);
        Preset::ALL[(i + 1) % Preset::ALL.len()]
    }

    /// The preset called `name` (as [`Preset::name`] writes it, any case).
    pub fn named(name: &str) -> Option<Preset> {
        let wanted = name.trim().to_lowercase();
        Preset::ALL
            .into_iter()
            .find(|p| p.name().to_lowercase() == wanted || (wanted == "vee" && *p == Preset::Vee))
    }

    /// `n` slot offsets with neighbours `spacing` metres apart, centred on
    /// the origin, each coordinate to the millimetre (as a file would have
    /// them; the centroid stays within half a millimetre of the origin).
    pub fn slots(self, n: usize, spacing: f64) -> Vec<Vector3<f64>> {
        let mut slots = centred(self.unit_cells(n));
        for s in &mut slots {
            *s = (*s * spacing).map(round_mm);
        }
        slots
    }

    /// The shape at spacing 1, centred (not rounded).
    fn unit_cells(self, n: usize) -> Vec<Vector3<f64>> {
        (0..n)
            .map(|i| {
                let (x, y) = match self {
                    Preset::Triangle => triangle_cell(i),
                    Preset::LineAbreast => (0.0, -(i as f64)),
                    Preset::Column => (-(i as f64), 0.0),
                    Preset::Vee => vee_cell(i),
                    Preset::Diamond => diamond_cell(i),
                };
                Vector3::new(x, y, 0.0)
            })
            .collect()
    }

    /// The presets that draw different shapes for `n` UAVs, in cycling
    /// order: a preset whose shape an earlier one already draws is left out
    /// (a V of 3 or 4 is the triangle; for one UAV there is one shape).
    pub fn distinct(n: usize) -> Vec<Preset> {
        let mut out: Vec<Preset> = Vec::new();
        let shape = |p: Preset| centred(p.unit_cells(n));
        for p in Preset::ALL {
            if !out.iter().any(|q| same_shape(&shape(*q), &shape(p))) {
                out.push(p);
            }
        }
        out
    }

    /// The spacings for which this preset of `n` UAVs is a valid formation
    /// of `f` (eq. 7: every pair at least 2 r_Q + the safety margin apart in the closest shape
    /// the formation takes, `smallest_scale` of a shrink, and at most d_com
    /// apart), with a 2 % margin and to the millimetre; `None` when no
    /// spacing is (the line abreast of 20 is longer than d_com allows).
    pub fn spacing_range(self, n: usize, f: &Formation, smallest_scale: f64) -> Option<[f64; 2]> {
        let cells = self.unit_cells(n);
        let widest = max_pair_distance(&cells);
        let scale = smallest_scale.clamp(1e-6, 1.0);
        let low = ((f.closest_pair() / scale) * 1.02 * 1000.0).ceil() / 1000.0;
        let high = if widest > 0.0 {
            (f.comm_range / widest * 0.98 * 1000.0).floor() / 1000.0
        } else {
            f64::INFINITY
        };
        (low.is_finite() && low <= high).then_some([low, high])
    }

    /// The preset (and its spacing) the slots are, if they are one: the
    /// same points up to their order, to the millimetre.
    pub fn detect(slots: &[Vector3<f64>]) -> Option<(Preset, f64)> {
        let n = slots.len();
        // The scale that best fits the slots' distances from the origin
        // (robust to the millimetre rounding, unlike one pair's distance).
        let reach: f64 = slots.iter().map(|s| s.norm()).sum();
        Preset::distinct(n.max(1)).into_iter().find_map(|p| {
            let unit: f64 = centred(p.unit_cells(n)).iter().map(|c| c.norm()).sum();
            let spacing = if unit > 0.0 { reach / unit } else { 1.0 };
            same_shape(&p.slots(n, spacing), slots).then(|| (p, round_mm(spacing)))
        })
    }
}

/// The smallest scale the formation is flown at: the shrink's, or an IWP's
/// own, when below 1 (1 without a shrink).
pub fn smallest_scale(r: &Reconfiguration) -> f64 {
    r.waypoints
        .iter()
        .filter_map(|w| w.scale)
        .chain([r.shrink_scale])
        .filter(|s| s.is_finite() && *s > 0.0 && *s < 1.0)
        .fold(1.0, f64::min)
}

/// The spacing of `m`'s formation: its preset's, else its closest pair's
/// (3 m for a single UAV).
pub fn spacing_of(m: &Mission) -> f64 {
    let slots = &m.formation.slots;
    match Preset::detect(slots) {
        Some((_, spacing)) if slots.len() > 1 => spacing,
        _ => Some(min_pair_distance(slots))
            .filter(|d| d.is_finite() && *d > 0.0)
            .map_or(3.0, round_mm),
    }
}

/// Reshapes `m`'s formation into `preset` of `n` UAVs: at `spacing` when
/// given (a number the user typed, kept as is), else at the formation's
/// spacing moved into the range where the preset is valid for this
/// mission's r_Q, shrink and d_com. Returns the spacing used; the error
/// says why no spacing fits.
pub fn reshape(
    m: &mut Mission,
    preset: Preset,
    n: usize,
    spacing: Option<f64>,
) -> Result<f64, String> {
    if n == 0 {
        return Err("a formation needs at least one UAV".into());
    }
    let spacing = match spacing {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(s) => return Err(format!("the spacing must be positive, got {s} m")),
        None => {
            let scale = smallest_scale(&m.reconfiguration);
            let [lo, hi] = preset
                .spacing_range(n, &m.formation, scale)
                .ok_or_else(|| misfit(preset, n, &m.formation, scale))?;
            spacing_of(m).clamp(lo, hi)
        }
    };
    m.formation.slots = preset.slots(n, spacing);
    Ok(spacing)
}

/// Why `preset` of `n` fits no spacing.
fn misfit(preset: Preset, n: usize, f: &Formation, scale: f64) -> String {
    let closest = f.closest_pair() / scale.clamp(1e-6, 1.0);
    let far = max_pair_distance(&preset.slots(n, closest));
    format!(
        "a {} of {n} does not fit: at the {} m spacing that keeps 2 r_Q + the safety margin apart{}, its farthest \
         UAVs are {} m apart, beyond d_com = {} m",
        preset.name(),
        round_mm(closest),
        if scale < 1.0 {
            format!(" when shrunk to {scale}")
        } else {
            String::new()
        },
        round_mm(far),
        f.comm_range
    )
}

/// `n` slots from a custom shape: the first `n` kept, new ones one
/// `spacing` behind the rearmost, the whole centred again, to the millimetre.
pub fn resize_custom(slots: &[Vector3<f64>], n: usize, spacing: f64) -> Vec<Vector3<f64>> {
    let mut out: Vec<Vector3<f64>> = slots.iter().take(n).copied().collect();
    while out.len() < n {
        let back = out.iter().map(|s| s.x).fold(f64::INFINITY, f64::min);
        let back = if back.is_finite() { back } else { 0.0 };
        out.push(Vector3::new(back - spacing, 0.0, 0.0));
    }
    centred(out).into_iter().map(|s| s.map(round_mm)).collect()
}

/// The slots scaled about the centroid (the origin) by `factor`, to the millimetre.
pub fn rescale(slots: &[Vector3<f64>], factor: f64) -> Vec<Vector3<f64>> {
    slots.iter().map(|s| (s * factor).map(round_mm)).collect()
}

/// A length to the millimetre (`-0` as `0`, so files do not say `-0.0`).
pub fn round_mm(v: f64) -> f64 {
    let r = (v * 1000.0).round() / 1000.0;
    if r == 0.0 { 0.0 } else { r }
}

/// The same points, in any order, within 2 mm (slots are written to the
/// millimetre).
fn same_shape(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> bool {
    a.len() == b.len()
        && a.iter().all(|p| b.iter().any(|q| (p - q).norm() < 2e-3))
        && b.iter().all(|q| a.iter().any(|p| (p - q).norm() < 2e-3))
}

/// The smallest distance between two slots (∞ for fewer than two).
pub fn min_pair_distance(slots: &[Vector3<f64>]) -> f64 {
    let mut best = f64::INFINITY;
    for (i, a) in slots.iter().enumerate() {
        for b in &slots[i + 1..] {
            best = best.min((a - b).norm());
        }
    }
    best
}

/// The largest distance between two slots (0 for fewer than two).
pub fn max_pair_distance(slots: &[Vector3<f64>]) -> f64 {
    let mut worst: f64 = 0.0;
    for (i, a) in slots.iter().enumerate() {
        for b in &slots[i + 1..] {
            worst = worst.max((a - b).norm());
        }
    }
    worst
}

/// Row r holds r + 1 UAVs spread across, rows √3/2 apart: an equilateral lattice.
fn triangle_cell(i: usize) -> (f64, f64) {
    let mut row = 0;
    let mut first = 0;
    while i > first + row {
        first += row + 1;
        row += 1;
    }
    let k = (i - first) as f64;
    let x = -(row as f64) * 3f64.sqrt() / 2.0;
    let y = row as f64 / 2.0 - k;
    (x, y)
}

/// Leader at the front; UAV 2k-1 left and 2k right, k rows back, at 60° sweep.
fn vee_cell(i: usize) -> (f64, f64) {
    if i == 0 {
        return (0.0, 0.0);
    }
    let k = i.div_ceil(2) as f64;
    let side = if i % 2 == 1 { 1.0 } else { -1.0 };
    (-k * 3f64.sqrt() / 2.0, side * k / 2.0)
}

/// Four per ring (front, left, right, back); the first ring is a square of
/// side one spacing, each further ring one spacing wider.
fn diamond_cell(i: usize) -> (f64, f64) {
    let r = (i / 4) as f64 + std::f64::consts::FRAC_1_SQRT_2;
    match i % 4 {
        0 => (r, 0.0),
        1 => (0.0, r),
        2 => (0.0, -r),
        _ => (-r, 0.0),
    }
}

fn centred(mut slots: Vec<Vector3<f64>>) -> Vec<Vector3<f64>> {
    if slots.is_empty() {
        return slots;
    }
    let centroid = slots.iter().sum::<Vector3<f64>>() / slots.len() as f64;
    for s in &mut slots {
        *s -= centroid;
    }
    slots
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_centred_and_keeps_its_spacing() {
        for preset in Preset::ALL {
            for n in 2..=9 {
                let slots = preset.slots(n, 3.0);
                assert_eq!(slots.len(), n);
                let centroid = slots.iter().sum::<Vector3<f64>>() / n as f64;
                assert!(centroid.norm() < 5e-4, "{} n={n}", preset.name());
                let d = min_pair_distance(&slots);
                // Diamond's first ring is a square of side spacing: min is spacing.
                assert!(
                    (d - 3.0).abs() < 2e-3,
                    "{} n={n}: min distance {d}",
                    preset.name()
                );
            }
        }
    }

    /// Issue 24, item 11: slots are written to the millimetre, not as
    /// `2.5495097567963914`.
    #[test]
    fn preset_slots_are_millimetres() {
        for preset in Preset::ALL {
            for n in 1..=20 {
                for s in preset.slots(n, 2.7) {
                    for c in s.iter() {
                        assert_eq!(*c, round_mm(*c), "{} of {n}: {c}", preset.name());
                        assert!(format!("{c}").len() <= 8, "{c}");
                    }
                }
            }
        }
    }

    /// Issue 24, item 4: no two presets offered for n UAVs draw the same
    /// shape (the triangle and the V of 3 or 4 are one shape), and each
    /// preset of a formation is detected as itself.
    #[test]
    fn no_two_offered_presets_draw_the_same_shape() {
        assert_eq!(Preset::distinct(1).len(), 1);
        assert!(
            !Preset::distinct(4).contains(&Preset::Vee),
            "the V of 4 is the triangle"
        );
        assert!(Preset::distinct(5).contains(&Preset::Vee));
        for n in 1..=20 {
            let offered = Preset::distinct(n);
            for (i, a) in offered.iter().enumerate() {
                for b in &offered[i + 1..] {
                    assert!(
                        !same_shape(&a.slots(n, 3.0), &b.slots(n, 3.0)),
                        "{} and {} of {n} are one shape",
                        a.name(),
                        b.name()
                    );
                }
                assert_eq!(
                    Preset::detect(&a.slots(n, 2.5)).map(|d| d.0),
                    Some(*a),
                    "{} of {n}",
                    a.name()
                );
            }
        }
    }

    /// Issue 24, item 11: a preset's spacing range keeps every pair within
    /// [(2 r_Q + the safety margin) / shrink, d_com]; a line abreast of 20
    /// does not fit d_com = 20 m.
    #[test]
    fn the_spacing_range_keeps_every_pair_within_eq_7() {
        let f = Formation::default();
        for preset in Preset::ALL {
            for n in 2..=20 {
                let Some([lo, hi]) = preset.spacing_range(n, &f, 0.5) else {
                    continue;
                };
                for spacing in [lo, hi] {
                    let slots = preset.slots(n, spacing);
                    let (near, far) = (min_pair_distance(&slots), max_pair_distance(&slots));
                    assert!(near * 0.5 >= f.closest_pair(), "{} of {n}", preset.name());
                    assert!(far <= f.comm_range, "{} of {n}: {far}", preset.name());
                }
            }
        }
        assert!(Preset::LineAbreast.spacing_range(20, &f, 0.5).is_none());
        assert!(Preset::Diamond.spacing_range(16, &f, 0.5).is_some());
    }

    #[test]
    fn triangle_of_three_is_equilateral_point_forward() {
        let s = Preset::Triangle.slots(3, 2.0);
        let d01 = (s[0] - s[1]).norm();
        let d12 = (s[1] - s[2]).norm();
        let d02 = (s[0] - s[2]).norm();
        assert!((d01 - 2.0).abs() < 2e-3 && (d12 - 2.0).abs() < 2e-3);
        assert!((d02 - 2.0).abs() < 2e-3);
        assert!(s[0].x > s[1].x && s[0].x > s[2].x, "the point leads");
    }

    #[test]
    fn line_abreast_is_across_and_column_along() {
        assert!(Preset::LineAbreast.slots(4, 2.0).iter().all(|s| s.x == 0.0));
        assert!(Preset::Column.slots(4, 2.0).iter().all(|s| s.y == 0.0));
    }
}
