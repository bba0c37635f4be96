//! Surveyed lines as the cylinders the planners know: a row of discs along
//! each (a fence, a hedge, an overhead line's corridor). Polygons are kept
//! as footprints (`obstacles.rs`). Metres, ENU, in the x-y plane. Pure
//! geometry: no file, no mission.

use nalgebra::Point2;

/// A disc of the x-y plane: an obstacle's footprint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disc {
    pub center: Point2<f64>,
    pub radius: f64,
}

/// A row of discs of `radius` along `line` (ENU points): one at every
/// vertex and between them at most `radius × √2` apart, so neighbours
/// overlap and every point within `radius / √2` of the line is covered
/// (on a segment, the farthest point from both neighbours is √(r²/2 + r²/2)
/// = r away from them; at a vertex a disc stands on it).
pub fn cover_line(line: &[Point2<f64>], radius: f64) -> Vec<Disc> {
    let spacing = radius * std::f64::consts::SQRT_2;
    let mut centres: Vec<Point2<f64>> = Vec::new();
    for pair in line.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let length = (b - a).norm();
        let steps = (length / spacing).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let p = a + (b - a) * (k as f64 / steps as f64);
            if centres.last().is_none_or(|q| (p - q).norm() > 1e-9) {
                centres.push(p);
            }
        }
    }
    if centres.is_empty()
        && let Some(p) = line.first()
    {
        centres.push(*p);
    }
    centres
        .into_iter()
        .map(|center| Disc { center, radius })
        .collect()
}

/// The half-width of the strip along a line that [`cover_line`] covers.
pub fn line_half_width(radius: f64) -> f64 {
    radius / std::f64::consts::SQRT_2
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    impl Disc {
        fn contains(&self, p: &Point2<f64>) -> bool {
            (p - self.center).norm() <= self.radius
        }
    }

    #[test]
    fn a_line_row_has_a_disc_on_every_vertex_and_no_gap() {
        let line = [
            Point2::new(0.0, 0.0),
            Point2::new(10.0, 0.0),
            Point2::new(10.0, 7.0),
        ];
        let r = 1.0;
        let discs = cover_line(&line, r);
        for v in &line {
            assert!(discs.iter().any(|d| (d.center - v).norm() < 1e-9));
        }
        // Every point within r/√2 of the line is covered.
        let h = line_half_width(r) * 0.999;
        for k in 0..=200 {
            let t = k as f64 / 200.0;
            for (a, b, n) in [
                (line[0], line[1], Vector2::new(0.0, 1.0)),
                (line[1], line[2], Vector2::new(1.0, 0.0)),
            ] {
                let p = a + (b - a) * t;
                for q in [p + n * h, p - n * h] {
                    assert!(discs.iter().any(|d| d.contains(&q)), "{q}");
                }
            }
        }
        assert_eq!(cover_line(&[Point2::new(3.0, 4.0)], r).len(), 1);
    }
}
