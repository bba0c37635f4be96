//! Surveyed shapes as the cylinders the planners know: a polygon becomes a
//! cover of discs whose union contains it, a line a row of discs along it.
//! Metres, ENU, in the x-y plane. Pure geometry: no file, no mission.

use geo::{
    Area, BooleanOps, BoundingRect, Coord, LineString, MinimumRotatedRect, MultiPolygon, Polygon,
};
use nalgebra::{Point2, Vector2};

/// A disc of the x-y plane: an obstacle's footprint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disc {
    pub center: Point2<f64>,
    pub radius: f64,
}

impl Disc {
    fn contains(&self, p: &Point2<f64>) -> bool {
        (p - self.center).norm() <= self.radius
    }
}

/// A polygon's cover: its discs, the polygon's area and the union's.
#[derive(Debug, Clone, PartialEq)]
pub struct Cover {
    pub discs: Vec<Disc>,
    /// m².
    pub polygon_area: f64,
    /// m², of the union of the discs (exact).
    pub union_area: f64,
}

impl Cover {
    /// What the cylinders block beyond the polygon, m².
    pub fn excess(&self) -> f64 {
        (self.union_area - self.polygon_area).max(0.0)
    }
}

/// Most discs a polygon's automatic cover uses (a given radius may use more).
pub const AUTO_MAX_DISCS: usize = 64;

/// The excess, as a share of the polygon's area, at which the automatic
/// cover stops looking for smaller discs.
pub const AUTO_EXCESS: f64 = 0.25;

/// Most discs any cover may have: beyond it a radius is a unit mistake.
pub const MAX_DISCS: usize = 10_000;

/// Discs whose union contains `polygon`. The polygon is turned so that its
/// smallest enclosing rectangle is axis-aligned (its long side along x) and
/// that rectangle is cut into a grid of equal cells; each cell that meets
/// the polygon gives the smallest disc around the part of the polygon in
/// it. Every part is in its disc, so the union holds the polygon; a grid
/// that follows the polygon's own sides leaves no thin slivers, whose discs
/// would reach far out. With `radius`, the cells are the squares whose
/// enclosing disc has that radius. Without, grids from 1 × 1 up are tried
/// (1 to 3 cells across, more along) and the one with the fewest discs
/// whose excess is at most [`AUTO_EXCESS`] of the area is kept; failing
/// that within [`AUTO_MAX_DISCS`] discs, the one with the least excess.
/// `None` for an empty polygon, or when a cover would need more than
/// [`MAX_DISCS`] discs.
pub fn cover_polygon(polygon: &MultiPolygon<f64>, radius: Option<f64>) -> Option<Cover> {
    let polygon_area = polygon.unsigned_area();
    let grid = Grid::new(polygon)?;
    if let Some(r) = radius {
        if !(r > 0.0 && r.is_finite()) {
            return None;
        }
        let side = r * std::f64::consts::SQRT_2;
        let along = (grid.length / side).ceil().max(1.0);
        let across = (grid.width / side).ceil().max(1.0);
        if along * across > MAX_DISCS as f64 {
            return None;
        }
        let discs = grid.cover(along as usize, across as usize);
        return Some(measure(discs, polygon_area));
    }
    const ALONG: [usize; 17] = [1, 2, 3, 4, 5, 6, 7, 8, 10, 12, 14, 16, 20, 24, 28, 32, 40];
    let mut best: Option<Cover> = None;
    let mut fitting: Option<Cover> = None;
    // Families of grids: 1, 2 or 3 cells across (strips), or square cells.
    let aspect = grid.width / grid.length.max(1e-9);
    for family in 0..4 {
        for along in ALONG {
            let across = if family < 3 {
                family + 1
            } else {
                ((along as f64 * aspect).round() as usize).max(1)
            };
            if along * across > 2 * AUTO_MAX_DISCS
                || fitting
                    .as_ref()
                    .is_some_and(|f| f.discs.len() <= along.max(across) / 2)
            {
                break;
            }
            let discs = grid.cover(along, across);
            if discs.len() > AUTO_MAX_DISCS {
                break;
            }
            let cover = measure(discs, polygon_area);
            if best.as_ref().is_none_or(|b| cover.excess() < b.excess()) {
                best = Some(cover.clone());
            }
            if cover.excess() <= AUTO_EXCESS * polygon_area {
                if fitting
                    .as_ref()
                    .is_none_or(|f| cover.discs.len() < f.discs.len())
                {
                    fitting = Some(cover);
                }
                break;
            }
        }
    }
    fitting.or(best)
}

fn measure(discs: Vec<Disc>, polygon_area: f64) -> Cover {
    Cover {
        union_area: union_area(&discs),
        discs,
        polygon_area,
    }
}

/// A polygon in the frame of its smallest enclosing rectangle: x along the
/// rectangle's long side from its corner, y across.
struct Grid {
    /// The polygon turned into that frame.
    turned: MultiPolygon<f64>,
    /// Where the frame is: its origin and its x axis in the plane.
    corner: Point2<f64>,
    axis: Vector2<f64>,
    /// The rectangle's sides, metres (length ≥ width).
    length: f64,
    width: f64,
}

impl Grid {
    fn new(polygon: &MultiPolygon<f64>) -> Option<Grid> {
        let rect = polygon.minimum_rotated_rect()?;
        let corners: Vec<Point2<f64>> = rect
            .exterior()
            .coords()
            .map(|c| Point2::new(c.x, c.y))
            .collect();
        let [a, b, c] = [*corners.first()?, *corners.get(1)?, *corners.get(2)?];
        let (ab, bc) = (b - a, c - b);
        // x along the longer side, starting from the corner it leaves.
        let (corner, axis) = if ab.norm() >= bc.norm() {
            (a, ab.try_normalize(1e-12)?)
        } else {
            (b, bc.try_normalize(1e-12)?)
        };
        let turn = |c: &Coord<f64>| {
            let d = Point2::new(c.x, c.y) - corner;
            Coord {
                x: d.dot(&axis),
                y: axis.x * d.y - axis.y * d.x,
            }
        };
        let turned = MultiPolygon::new(
            polygon
                .0
                .iter()
                .map(|p| {
                    let ring =
                        |r: &LineString<f64>| LineString::new(r.coords().map(turn).collect());
                    Polygon::new(ring(p.exterior()), p.interiors().iter().map(ring).collect())
                })
                .collect(),
        );
        let bounds = turned.bounding_rect()?;
        // The rectangle, in its own frame, from the polygon's extent (the
        // turned polygon may start a hair off zero).
        let (min, max) = (bounds.min(), bounds.max());
        let corner = corner + axis * min.x + Vector2::new(-axis.y, axis.x) * min.y;
        let shift = |c: &Coord<f64>| Coord {
            x: c.x - min.x,
            y: c.y - min.y,
        };
        let turned = MultiPolygon::new(
            turned
                .0
                .iter()
                .map(|p| {
                    let ring =
                        |r: &LineString<f64>| LineString::new(r.coords().map(shift).collect());
                    Polygon::new(ring(p.exterior()), p.interiors().iter().map(ring).collect())
                })
                .collect(),
        );
        Some(Grid {
            turned,
            corner,
            axis,
            length: max.x - min.x,
            width: max.y - min.y,
        })
    }

    /// The discs of the `along` × `across` grid, in the plane.
    fn cover(&self, along: usize, across: usize) -> Vec<Disc> {
        let (dx, dy) = (
            self.length / along as f64,
            (self.width / across as f64).max(1e-9),
        );
        let normal = Vector2::new(-self.axis.y, self.axis.x);
        let mut discs = Vec::new();
        for i in 0..along {
            for j in 0..across {
                let (x0, y0) = (i as f64 * dx, j as f64 * dy);
                let cell = cell(x0, y0, x0 + dx, y0 + dy);
                let piece = if along == 1 && across == 1 {
                    self.turned.clone()
                } else {
                    self.turned.intersection(&cell)
                };
                if piece.unsigned_area() <= 1e-9 {
                    continue;
                }
                let points: Vec<Point2<f64>> = vertices(&piece).collect();
                if let Some(d) = enclosing_disc(&points) {
                    discs.push(Disc {
                        center: self.corner + self.axis * d.center.x + normal * d.center.y,
                        radius: d.radius,
                    });
                }
            }
        }
        discs
    }
}

/// Every vertex of every ring of `polygon`.
fn vertices(polygon: &MultiPolygon<f64>) -> impl Iterator<Item = Point2<f64>> + '_ {
    polygon.0.iter().flat_map(|p| {
        std::iter::once(p.exterior())
            .chain(p.interiors())
            .flat_map(|ring| ring.coords().map(|c| Point2::new(c.x, c.y)))
    })
}

/// The axis-aligned rectangle [x0, x1] × [y0, y1].
fn cell(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon<f64> {
    let ring = vec![
        Coord { x: x0, y: y0 },
        Coord { x: x1, y: y0 },
        Coord { x: x1, y: y1 },
        Coord { x: x0, y: y1 },
        Coord { x: x0, y: y0 },
    ];
    Polygon::new(LineString::new(ring), Vec::new())
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

/// The smallest disc holding every point (Welzl's incremental form), a
/// hair larger so that rounding never leaves a point outside. `None` for
/// no points.
pub fn enclosing_disc(points: &[Point2<f64>]) -> Option<Disc> {
    let first = *points.first()?;
    let mut d = Disc {
        center: first,
        radius: 0.0,
    };
    for i in 1..points.len() {
        if d.contains(&points[i]) {
            continue;
        }
        d = Disc {
            center: points[i],
            radius: 0.0,
        };
        for j in 0..i {
            if d.contains(&points[j]) {
                continue;
            }
            d = two_point_disc(points[i], points[j]);
            for k in 0..j {
                if !d.contains(&points[k]) {
                    d = three_point_disc(points[i], points[j], points[k]);
                }
            }
        }
    }
    // A relative and an absolute hair: the union must hold every vertex.
    d.radius = d.radius * (1.0 + 1e-12) + 1e-9;
    Some(d)
}

fn two_point_disc(a: Point2<f64>, b: Point2<f64>) -> Disc {
    Disc {
        center: nalgebra::center(&a, &b),
        radius: (a - b).norm() / 2.0,
    }
}

/// The circle through three points; for (nearly) collinear ones, the disc
/// on the farthest pair.
fn three_point_disc(a: Point2<f64>, b: Point2<f64>, c: Point2<f64>) -> Disc {
    let (ab, ac) = (b - a, c - a);
    let det = 2.0 * (ab.x * ac.y - ab.y * ac.x);
    let scale = ab.norm_squared().max(ac.norm_squared());
    if det.abs() <= 1e-12 * scale {
        let pairs = [(a, b), (a, c), (b, c)];
        let (p, q) = pairs
            .into_iter()
            .max_by(|x, y| (x.0 - x.1).norm().total_cmp(&(y.0 - y.1).norm()))
            .unwrap_or((a, b));
        return two_point_disc(p, q);
    }
    let (b2, c2) = (ab.norm_squared(), ac.norm_squared());
    let offset = Vector2::new(ac.y * b2 - ab.y * c2, ab.x * c2 - ac.x * b2) / det;
    Disc {
        center: a + offset,
        radius: offset.norm(),
    }
}

/// The exact area of the union of discs, m²: by Green's theorem over the
/// arcs of each circle that no other disc covers (traversed counter-
/// clockwise, they bound the union; around a hole they subtract it).
pub fn union_area(discs: &[Disc]) -> f64 {
    use std::f64::consts::TAU;
    let mut area = 0.0;
    'disc: for (i, a) in discs.iter().enumerate() {
        if a.radius <= 0.0 {
            continue;
        }
        let mut covered: Vec<(f64, f64)> = Vec::new();
        for (j, b) in discs.iter().enumerate() {
            if i == j || b.radius <= 0.0 {
                continue;
            }
            let d = (b.center - a.center).norm();
            let same = d <= 1e-12 && (a.radius - b.radius).abs() <= 1e-12;
            if same {
                if j < i {
                    continue 'disc; // counted once, as the first of its copies
                }
                continue;
            }
            if d + a.radius <= b.radius {
                continue 'disc; // inside another disc
            }
            if d >= a.radius + b.radius || d + b.radius <= a.radius {
                continue; // apart, or the other inside this one
            }
            let toward = (b.center.y - a.center.y).atan2(b.center.x - a.center.x);
            let cos = (a.radius * a.radius + d * d - b.radius * b.radius) / (2.0 * a.radius * d);
            let half = cos.clamp(-1.0, 1.0).acos();
            let start = (toward - half).rem_euclid(TAU);
            let end = start + 2.0 * half;
            if end > TAU {
                covered.push((start, TAU));
                covered.push((0.0, end - TAU));
            } else {
                covered.push((start, end));
            }
        }
        covered.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut from = 0.0;
        let arc = |t1: f64, t2: f64| {
            let (cx, cy, r) = (a.center.x, a.center.y, a.radius);
            0.5 * (r * r * (t2 - t1) + r * cx * (t2.sin() - t1.sin())
                - r * cy * (t2.cos() - t1.cos()))
        };
        for (s, e) in covered {
            if s > from {
                area += arc(from, s);
            }
            from = f64::max(from, e);
        }
        if from < TAU {
            area += arc(from, TAU);
        }
    }
    area
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn disc(x: f64, y: f64, r: f64) -> Disc {
        Disc {
            center: Point2::new(x, y),
            radius: r,
        }
    }

    fn rectangle(x0: f64, y0: f64, x1: f64, y1: f64) -> MultiPolygon<f64> {
        let ring = vec![
            Coord { x: x0, y: y0 },
            Coord { x: x1, y: y0 },
            Coord { x: x1, y: y1 },
            Coord { x: x0, y: y1 },
            Coord { x: x0, y: y0 },
        ];
        MultiPolygon::new(vec![Polygon::new(LineString::new(ring), Vec::new())])
    }

    /// Points of a fine grid over `polygon` that no disc holds.
    fn uncovered(polygon: &MultiPolygon<f64>, discs: &[Disc]) -> usize {
        use geo::Contains;
        let rect = polygon.bounding_rect().unwrap_or_else(|| panic!("empty"));
        let (min, max) = (rect.min(), rect.max());
        let n = 120;
        let mut missed = 0;
        for i in 0..=n {
            for j in 0..=n {
                let x = min.x + (max.x - min.x) * i as f64 / n as f64;
                let y = min.y + (max.y - min.y) * j as f64 / n as f64;
                let p = Point2::new(x, y);
                let inside = polygon.contains(&geo::Point::new(x, y));
                if inside && !discs.iter().any(|d| d.contains(&p)) {
                    missed += 1;
                }
            }
        }
        missed
    }

    #[test]
    fn the_union_area_is_exact_for_shapes_with_known_areas() {
        let r = 2.0;
        assert!((union_area(&[disc(1.0, 1.0, r)]) - PI * r * r).abs() < 1e-9);
        // Two equal discs d apart: twice the disc less the lens.
        let d = 3.0;
        let lens = 2.0 * r * r * (d / (2.0 * r)).acos() - d / 2.0 * (4.0 * r * r - d * d).sqrt();
        let two = union_area(&[disc(0.0, 0.0, r), disc(d, 0.0, r)]);
        assert!((two - (2.0 * PI * r * r - lens)).abs() < 1e-9, "{two}");
        // A disc inside another, a copy, and one far away.
        let nested = union_area(&[
            disc(0.0, 0.0, 3.0),
            disc(0.5, 0.0, 1.0),
            disc(0.0, 0.0, 3.0),
            disc(10.0, 0.0, 1.0),
        ]);
        assert!((nested - (9.0 * PI + PI)).abs() < 1e-9, "{nested}");
    }

    #[test]
    fn a_ring_of_discs_leaves_its_hole_out_of_the_area() {
        // Eight discs round a circle leave a hole in the middle; compare
        // with counting a fine grid.
        let discs: Vec<Disc> = (0..8)
            .map(|k| {
                let a = k as f64 * PI / 4.0;
                disc(5.0 * a.cos(), 5.0 * a.sin(), 2.2)
            })
            .collect();
        let n = 1400;
        let (lo, hi) = (-7.5, 7.5);
        let step = (hi - lo) / n as f64;
        let mut inside = 0usize;
        for i in 0..n {
            for j in 0..n {
                let p = Point2::new(lo + (i as f64 + 0.5) * step, lo + (j as f64 + 0.5) * step);
                if discs.iter().any(|d| d.contains(&p)) {
                    inside += 1;
                }
            }
        }
        let counted = inside as f64 * step * step;
        let exact = union_area(&discs);
        assert!(
            (exact - counted).abs() < 0.01 * exact,
            "{exact} vs {counted}"
        );
        assert!(exact < 8.0 * PI * 2.2 * 2.2);
    }

    #[test]
    fn the_enclosing_disc_is_the_smallest_for_simple_sets() {
        let square = [
            Point2::new(0.0, 0.0),
            Point2::new(2.0, 0.0),
            Point2::new(2.0, 2.0),
            Point2::new(0.0, 2.0),
            Point2::new(1.0, 1.0),
        ];
        let d = enclosing_disc(&square).unwrap_or_else(|| panic!("none"));
        assert!((d.center - Point2::new(1.0, 1.0)).norm() < 1e-9);
        assert!((d.radius - 2f64.sqrt()).abs() < 1e-6);
        // An obtuse triangle: the disc on its longest side.
        let t = [
            Point2::new(0.0, 0.0),
            Point2::new(10.0, 0.0),
            Point2::new(5.0, 1.0),
        ];
        let d = enclosing_disc(&t).unwrap_or_else(|| panic!("none"));
        assert!((d.radius - 5.0).abs() < 1e-6, "{d:?}");
        assert!(enclosing_disc(&[]).is_none());
    }

    #[test]
    fn a_polygon_cover_contains_the_polygon_and_states_its_excess() {
        // A 20 m × 6 m footprint and an L-shaped one.
        let l_shape = {
            let ring = [
                (0.0, 0.0),
                (30.0, 0.0),
                (30.0, 8.0),
                (8.0, 8.0),
                (8.0, 25.0),
                (0.0, 25.0),
                (0.0, 0.0),
            ]
            .map(|(x, y)| Coord { x, y });
            MultiPolygon::new(vec![Polygon::new(LineString::new(ring.to_vec()), vec![])])
        };
        // A tree line 60 m × 4 m at 30°, and a round crown (a 24-gon).
        let turned = {
            let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
            let ring =
                [(0.0, 0.0), (60.0, 0.0), (60.0, 4.0), (0.0, 4.0), (0.0, 0.0)].map(|(x, y)| {
                    Coord {
                        x: 5.0 + c * x - s * y,
                        y: 7.0 + s * x + c * y,
                    }
                });
            MultiPolygon::new(vec![Polygon::new(LineString::new(ring.to_vec()), vec![])])
        };
        let crown = {
            let ring: Vec<Coord<f64>> = (0..=24)
                .map(|k| {
                    let a = (k % 24) as f64 * PI / 12.0;
                    Coord {
                        x: 50.0 + 4.0 * a.cos(),
                        y: 50.0 + 4.0 * a.sin(),
                    }
                })
                .collect();
            MultiPolygon::new(vec![Polygon::new(LineString::new(ring), vec![])])
        };
        for (polygon, most) in [
            (rectangle(10.0, 20.0, 30.0, 26.0), 8),
            (l_shape, 24),
            (turned, 40),
            (crown, 1),
        ] {
            let cover = cover_polygon(&polygon, None).unwrap_or_else(|| panic!("no cover"));
            eprintln!(
                "{} discs, {:.1} m² for {:.1} m²",
                cover.discs.len(),
                cover.union_area,
                cover.polygon_area
            );
            assert_eq!(uncovered(&polygon, &cover.discs), 0);
            assert!(cover.discs.len() <= most, "{} discs", cover.discs.len());
            assert!(cover.union_area >= cover.polygon_area);
            assert!(
                cover.excess() <= AUTO_EXCESS * cover.polygon_area,
                "{} discs, excess {} of {}",
                cover.discs.len(),
                cover.excess(),
                cover.polygon_area
            );
        }
    }

    #[test]
    fn a_given_radius_bounds_the_discs_and_smaller_discs_waste_less() {
        let polygon = rectangle(0.0, 0.0, 40.0, 12.0);
        let coarse = cover_polygon(&polygon, Some(8.0)).unwrap_or_else(|| panic!("none"));
        let fine = cover_polygon(&polygon, Some(2.0)).unwrap_or_else(|| panic!("none"));
        for c in [&coarse, &fine] {
            assert_eq!(uncovered(&polygon, &c.discs), 0);
        }
        assert!(coarse.discs.iter().all(|d| d.radius <= 8.0 + 1e-6));
        assert!(fine.discs.len() > coarse.discs.len());
        assert!(fine.excess() < coarse.excess());
        // A radius that would need millions of discs is refused.
        assert!(cover_polygon(&polygon, Some(0.001)).is_none());
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
