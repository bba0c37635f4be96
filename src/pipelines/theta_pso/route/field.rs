//! The clearance field: for every cell of a grid over the site, how far its
//! centre is from the nearest obstacle's surface, and which obstacle that is.
//!
//! A formation whose UAVs all lie within `reach` of the centroid keeps every
//! UAV r_Q + margin clear of every obstacle, whatever its heading, where the
//! field is at least `reach + r_Q + margin` (the disc model: heading-free and
//! conservative). The route stage reads it at two reaches, the nominal shape
//! and the smallest shrink, so one field serves both.

use nalgebra::Point2;

use crate::base::shape::Footprint;

/// A grid of clearances over a rectangle.
#[derive(Debug, Clone)]
pub struct Field {
    /// Centre of cell (0, 0), metres ENU.
    origin: Point2<f64>,
    /// Side of a cell, metres.
    cell: f64,
    nx: usize,
    ny: usize,
    /// Distance from each cell centre to the nearest disc's edge (negative
    /// inside one), capped at `cap`.
    clearance: Vec<f32>,
    /// The disc that distance is to; `u32::MAX` where none is within the cap.
    nearest: Vec<u32>,
    cap: f64,
}

impl Field {
    /// The field over `area` ([x range, y range]) with cells of `cell`
    /// metres, clearances read up to `cap` (beyond it a cell is simply clear).
    pub fn new(area: [[f64; 2]; 2], discs: &[Footprint], cell: f64, cap: f64) -> Self {
        let [x, y] = area;
        let nx = (((x[1] - x[0]) / cell).ceil() as usize).max(1);
        let ny = (((y[1] - y[0]) / cell).ceil() as usize).max(1);
        let origin = Point2::new(x[0] + cell / 2.0, y[0] + cell / 2.0);
        let mut clearance = vec![cap as f32; nx * ny];
        let mut nearest = vec![u32::MAX; nx * ny];
        for (k, d) in discs.iter().enumerate() {
            // Only the cells within the cap of the disc's edge can change.
            let (center, radius) = d.bounding_circle();
            let reach = radius + cap;
            let (lo_x, hi_x) = span(center.x - reach, center.x + reach, origin.x, cell, nx);
            let (lo_y, hi_y) = span(center.y - reach, center.y + reach, origin.y, cell, ny);
            for iy in lo_y..hi_y {
                let cy = origin.y + iy as f64 * cell;
                for ix in lo_x..hi_x {
                    let cx = origin.x + ix as f64 * cell;
                    let gap = d.signed_distance(&Point2::new(cx, cy)) as f32;
                    let i = iy * nx + ix;
                    if gap < clearance[i] {
                        clearance[i] = gap;
                        nearest[i] = k as u32;
                    }
                }
            }
        }
        Field {
            origin,
            cell,
            nx,
            ny,
            clearance,
            nearest,
            cap,
        }
    }

    pub fn cell(&self) -> f64 {
        self.cell
    }

    pub fn size(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether `p` lies on the grid (within its cells).
    pub fn contains(&self, p: Point2<f64>) -> bool {
        let half = self.cell / 2.0;
        let (x0, y0) = (self.origin.x - half, self.origin.y - half);
        (x0..=x0 + self.nx as f64 * self.cell).contains(&p.x)
            && (y0..=y0 + self.ny as f64 * self.cell).contains(&p.y)
    }

    /// The cell holding `p`, clamped onto the grid.
    pub fn index_of(&self, p: Point2<f64>) -> usize {
        let ix = ((p.x - self.origin.x) / self.cell).round();
        let iy = ((p.y - self.origin.y) / self.cell).round();
        let ix = (ix.max(0.0) as usize).min(self.nx - 1);
        let iy = (iy.max(0.0) as usize).min(self.ny - 1);
        iy * self.nx + ix
    }

    pub fn center(&self, i: usize) -> Point2<f64> {
        let (ix, iy) = (i % self.nx, i / self.nx);
        Point2::new(
            self.origin.x + ix as f64 * self.cell,
            self.origin.y + iy as f64 * self.cell,
        )
    }

    /// Clearance of cell `i` (at most the cap).
    pub fn clearance(&self, i: usize) -> f64 {
        f64::from(self.clearance[i])
    }

    /// Clearance at a point: the exact distance to the nearest disc when one
    /// is within the cap of its cell (`discs` as given to `new`), the cap
    /// otherwise.
    pub fn clearance_at(&self, p: Point2<f64>, discs: &[Footprint]) -> f64 {
        let i = self.index_of(p);
        // The nearest disc of the cell is the nearest of the point's within
        // half a cell's diagonal; look at the cell's and its neighbours'.
        let mut best = self.cap;
        for j in self.neighbourhood(i) {
            if let Some(d) = self.nearest_disc(j).and_then(|k| discs.get(k)) {
                best = best.min(d.signed_distance(&p));
            }
        }
        best
    }

    /// The obstacle nearest cell `i`'s centre, if one is within the cap.
    pub fn nearest_disc(&self, i: usize) -> Option<usize> {
        let k = self.nearest[i];
        (k != u32::MAX).then_some(k as usize)
    }

    /// Cell `i` and its (up to) eight neighbours.
    pub fn neighbourhood(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let (ix, iy) = ((i % self.nx) as isize, (i / self.nx) as isize);
        (-1..=1).flat_map(move |dy| {
            (-1..=1).filter_map(move |dx| {
                let (x, y) = (ix + dx, iy + dy);
                (x >= 0 && y >= 0 && (x as usize) < self.nx && (y as usize) < self.ny)
                    .then(|| y as usize * self.nx + x as usize)
            })
        })
    }

    /// The eight neighbours of cell `i` with the length of the step there.
    pub fn steps(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let diagonal = self.cell * std::f64::consts::SQRT_2;
        self.neighbourhood(i)
            .filter(move |&j| j != i)
            .map(move |j| {
                let straight = j % self.nx == i % self.nx || j / self.nx == i / self.nx;
                (j, if straight { self.cell } else { diagonal })
            })
    }

    /// The cells whose centres lie in the square of half side `r` round `p`.
    pub fn cells_within(&self, p: Point2<f64>, r: f64) -> impl Iterator<Item = usize> + '_ {
        let (x0, x1) = span(p.x - r, p.x + r, self.origin.x, self.cell, self.nx);
        let (y0, y1) = span(p.y - r, p.y + r, self.origin.y, self.cell, self.ny);
        (y0..y1).flat_map(move |y| (x0..x1).map(move |x| y * self.nx + x))
    }

    /// The cells a segment passes, sampled at a third of a cell.
    pub fn cells_along(&self, a: Point2<f64>, b: Point2<f64>) -> impl Iterator<Item = usize> + '_ {
        let steps = (((b - a).norm() / (self.cell / 3.0)).ceil() as usize).max(1);
        (0..=steps).map(move |k| self.index_of(a + (b - a) * (k as f64 / steps as f64)))
    }
}

/// Items filed by cell, each cell's in the order given: the jumps leaving a
/// cell, read on every expansion of the searches (a slice per cell, no
/// hashing).
#[derive(Debug, Clone)]
pub struct CellLists<T> {
    /// Cell c's items are `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<T>,
}

impl<T> CellLists<T> {
    /// `pairs` (cell, item) over `cells` cells.
    pub fn new(cells: usize, pairs: Vec<(usize, T)>) -> Self {
        let mut start = vec![0u32; cells + 1];
        for (c, _) in &pairs {
            start[c + 1] += 1;
        }
        for c in 0..cells {
            start[c + 1] += start[c];
        }
        // A stable sort by cell keeps each cell's items in the given order.
        let mut pairs = pairs;
        pairs.sort_by_key(|(c, _)| *c);
        CellLists {
            start,
            items: pairs.into_iter().map(|(_, item)| item).collect(),
        }
    }

    /// The items of cell `c`.
    pub fn at(&self, c: usize) -> &[T] {
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

/// The index range of cells whose centres lie in [lo, hi] along one axis.
fn span(lo: f64, hi: f64, origin: f64, cell: f64, n: usize) -> (usize, usize) {
    let first = ((lo - origin) / cell).ceil().max(0.0) as usize;
    let last = (((hi - origin) / cell).floor() + 1.0).max(0.0) as usize;
    (first.min(n), last.min(n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_field_is_the_distance_to_the_nearest_edge() {
        let discs = [
            Footprint::circle(Point2::new(5.0, 5.0), 1.0),
            Footprint::circle(Point2::new(8.0, 5.0), 0.5),
        ];
        let f = Field::new([[0.0, 10.0], [0.0, 10.0]], &discs, 0.5, 3.0);
        let at = |x: f64, y: f64| f.clearance(f.index_of(Point2::new(x, y)));
        assert!((at(5.25, 5.25) - (0.25f64.hypot(0.25) - 1.0)).abs() < 1e-6);
        assert!(
            (at(7.25, 5.25) - (0.75f64.hypot(0.25) - 0.5)).abs() < 1e-6,
            "nearer the small one"
        );
        assert_eq!(f.nearest_disc(f.index_of(Point2::new(7.25, 5.25))), Some(1));
        assert_eq!(at(0.25, 9.75), 3.0, "capped far away");
        assert_eq!(f.nearest_disc(f.index_of(Point2::new(0.25, 9.75))), None);
    }
}
