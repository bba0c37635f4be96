//! Standard formation shapes for n UAVs, offered by the TUI's formation editor.
//!
//! Offsets are in the formation frame (x forward along the path, y left, z up),
//! metres, with the centroid at the origin so that the θ-PSO centroid path is
//! the formation's centre.

use nalgebra::Vector3;

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

    /// `n` slot offsets with neighbours `spacing` metres apart, centred on the origin.
    pub fn slots(self, n: usize, spacing: f64) -> Vec<Vector3<f64>> {
        let raw: Vec<Vector3<f64>> = (0..n)
            .map(|i| {
                let (x, y) = match self {
                    Preset::Triangle => triangle_cell(i),
                    Preset::LineAbreast => (0.0, -(i as f64)),
                    Preset::Column => (-(i as f64), 0.0),
                    Preset::Vee => vee_cell(i),
                    Preset::Diamond => diamond_cell(i),
                };
                Vector3::new(x * spacing, y * spacing, 0.0)
            })
            .collect();
        centred(raw)
    }
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
        // -0.0 would be written "-0.0" in the TOML; keep files tidy.
        s.apply(|c| {
            if c.abs() < 1e-12 {
                *c = 0.0
            }
        });
    }
    slots
}

#[cfg(test)]
mod tests {
    use super::*;

    fn min_pair_distance(slots: &[Vector3<f64>]) -> f64 {
        let mut best = f64::INFINITY;
        for (i, a) in slots.iter().enumerate() {
            for b in &slots[i + 1..] {
                best = best.min((a - b).norm());
            }
        }
        best
    }

    #[test]
    fn every_preset_is_centred_and_keeps_its_spacing() {
        for preset in Preset::ALL {
            for n in 2..=9 {
                let slots = preset.slots(n, 3.0);
                assert_eq!(slots.len(), n);
                let centroid = slots.iter().sum::<Vector3<f64>>() / n as f64;
                assert!(centroid.norm() < 1e-9, "{} n={n}", preset.name());
                let d = min_pair_distance(&slots);
                // Diamond's first ring is a square of side spacing: min is spacing.
                assert!(
                    (d - 3.0).abs() < 1e-9,
                    "{} n={n}: min distance {d}",
                    preset.name()
                );
            }
        }
    }

    #[test]
    fn triangle_of_three_is_equilateral_point_forward() {
        let s = Preset::Triangle.slots(3, 2.0);
        let d01 = (s[0] - s[1]).norm();
        let d12 = (s[1] - s[2]).norm();
        let d02 = (s[0] - s[2]).norm();
        assert!((d01 - 2.0).abs() < 1e-12 && (d12 - 2.0).abs() < 1e-12);
        assert!((d02 - 2.0).abs() < 1e-12);
        assert!(s[0].x > s[1].x && s[0].x > s[2].x, "the point leads");
    }

    #[test]
    fn line_abreast_is_across_and_column_along() {
        assert!(Preset::LineAbreast.slots(4, 2.0).iter().all(|s| s.x == 0.0));
        assert!(Preset::Column.slots(4, 2.0).iter().all(|s| s.y == 0.0));
    }
}
