//! Terrain: a height map read from a GeoTIFF, and the ground height under a
//! point.
//!
//! Frame: the map's pixel (row r, column c), 0-based, has its centre at
//! ENU x = origin_x + c · pixel_x, y = origin_y + r · pixel_y. A north-up
//! GeoTIFF has pixel_y < 0; the SPSO benchmark counts y down the rows with
//! 1-based pixel coordinates (origin (1, 1), pixel (1, 1)). Heights are
//! metres above the frame's datum (z = 0), stored as read (f32).

use std::collections::HashMap;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::SystemTime;

use serde::{Deserialize, Serialize};

/// The largest map skyform loads, pixels (64 Mpx = 256 MB of f32).
pub const MAX_PIXELS: u64 = 64 * 1024 * 1024;
/// Heights beyond ± this many metres are refused as malformed (no-data values).
pub const MAX_HEIGHT: f32 = 100_000.0;

/// How the ground height between pixel centres is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Lookup {
    /// The pixel whose 1-based index is round(u + 1), halves away from zero
    /// (MATLAB's `round`, the SPSO benchmark's H(round(y), round(x))).
    #[default]
    Nearest,
    /// Bilinear between the four surrounding pixel centres.
    Bilinear,
}

/// A loaded map and its lookup: what the planner carries to read the ground.
#[derive(Debug, Clone)]
pub struct Ground {
    pub map: Arc<HeightMap>,
    pub lookup: Lookup,
}

impl Ground {
    /// The ground under (x, y), at the map's edge outside it (`ground_clamped`).
    #[inline]
    pub fn at(&self, x: f64, y: f64) -> f64 {
        self.map.ground_clamped(self.lookup, x, y)
    }
}

/// A height map in memory: `heights[row * width + col]`.
#[derive(Clone, PartialEq)]
pub struct HeightMap {
    pub width: usize,
    pub height: usize,
    pub heights: Vec<f32>,
    /// ENU x, y of the centre of pixel (0, 0), metres.
    pub origin: [f64; 2],
    /// ENU step from one column / row to the next, metres (may be negative).
    pub pixel: [f64; 2],
    /// Lowest and highest height, metres.
    pub range: [f32; 2],
}

impl std::fmt::Debug for HeightMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeightMap")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("origin", &self.origin)
            .field("pixel", &self.pixel)
            .field("range", &self.range)
            .finish_non_exhaustive()
    }
}

impl HeightMap {
    /// A map from rows of heights (row 0 first). Fails on ragged rows,
    /// an empty map, non-finite or absurd heights.
    pub fn new(
        width: usize,
        heights: Vec<f32>,
        origin: [f64; 2],
        pixel: [f64; 2],
    ) -> Result<Self, String> {
        if width == 0 || heights.is_empty() || !heights.len().is_multiple_of(width) {
            return Err(format!(
                "{} heights do not make rows of {width} pixels",
                heights.len()
            ));
        }
        let mut range = [f32::INFINITY, f32::NEG_INFINITY];
        for (i, &h) in heights.iter().enumerate() {
            if !h.is_finite() || h.abs() > MAX_HEIGHT {
                return Err(format!(
                    "pixel (row {}, column {}) holds {h}, not a ground height \
                     (no-data values are not supported)",
                    i / width + 1,
                    i % width + 1
                ));
            }
            range = [range[0].min(h), range[1].max(h)];
        }
        if !(pixel[0].is_finite() && pixel[1].is_finite() && pixel[0] != 0.0 && pixel[1] != 0.0) {
            return Err("the pixel size must be finite and non-zero".into());
        }
        Ok(HeightMap {
            height: heights.len() / width,
            width,
            heights,
            origin,
            pixel,
            range,
        })
    }

    /// Reads the first image of a TIFF / GeoTIFF: one sample per pixel,
    /// float or integer. `origin` and `pixel` place it (see the module doc).
    pub fn read_tiff(path: &Path, origin: [f64; 2], pixel: [f64; 2]) -> Result<Self, String> {
        use tiff::decoder::{Decoder, DecodingResult, Limits};
        let file = File::open(path).map_err(|e| format!("cannot open {}: {e}", path.display()))?;
        let malformed =
            |e: tiff::TiffError| format!("{} is not a readable TIFF: {e}", path.display());
        let mut decoder = Decoder::new(BufReader::new(file)).map_err(malformed)?;
        let (w, h) = decoder.dimensions().map_err(malformed)?;
        if u64::from(w) * u64::from(h) > MAX_PIXELS {
            return Err(format!(
                "{} is {w} × {h} pixels, over the limit of {MAX_PIXELS}",
                path.display()
            ));
        }
        let mut limits = Limits::default();
        limits.decoding_buffer_size = (MAX_PIXELS * 8) as usize;
        limits.intermediate_buffer_size = (MAX_PIXELS * 8) as usize;
        let mut decoder = decoder.with_limits(limits);
        let image = decoder.read_image().map_err(malformed)?;
        let heights: Vec<f32> = match image {
            DecodingResult::F32(v) => v,
            DecodingResult::F64(v) => v.into_iter().map(|x| x as f32).collect(),
            DecodingResult::U8(v) => v.into_iter().map(f32::from).collect(),
            DecodingResult::U16(v) => v.into_iter().map(f32::from).collect(),
            DecodingResult::I8(v) => v.into_iter().map(f32::from).collect(),
            DecodingResult::I16(v) => v.into_iter().map(f32::from).collect(),
            DecodingResult::I32(v) => v.into_iter().map(|x| x as f32).collect(),
            DecodingResult::U32(v) => v.into_iter().map(|x| x as f32).collect(),
            _ => {
                return Err(format!(
                    "{}: unsupported sample type (one float or integer sample per pixel)",
                    path.display()
                ));
            }
        };
        if heights.len() != w as usize * h as usize {
            return Err(format!(
                "{} has {} samples for {w} × {h} pixels: one sample per pixel (a height) is needed",
                path.display(),
                heights.len()
            ));
        }
        Self::new(w as usize, heights, origin, pixel)
    }

    /// The 0-based (column, row) coordinates of ENU (x, y), in pixels.
    pub fn pixel_coordinates(&self, x: f64, y: f64) -> (f64, f64) {
        (
            (x - self.origin[0]) / self.pixel[0],
            (y - self.origin[1]) / self.pixel[1],
        )
    }

    /// The pixel under (x, y) with the nearest rule (the 1-based coordinate
    /// rounded half away from zero), or `None` outside the map.
    pub fn nearest_index(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        // The 1-based coordinate measured from the centre of pixel 0 (one
        // step before the first): with the SPSO convention (origin 1, step 1)
        // that is (x − 0) / 1 = x exactly, so round(x) is MATLAB's round(x)
        // even at 0.49999999999999994, where x − 1 + 1 would round to 0.5.
        let c = ((x - (self.origin[0] - self.pixel[0])) / self.pixel[0]).round();
        let r = ((y - (self.origin[1] - self.pixel[1])) / self.pixel[1]).round();
        if c >= 1.0 && r >= 1.0 && c <= self.width as f64 && r <= self.height as f64 {
            Some((c as usize - 1, r as usize - 1))
        } else {
            None
        }
    }

    /// The stored height of the nearest pixel, `None` outside the map.
    pub fn nearest(&self, x: f64, y: f64) -> Option<f32> {
        self.nearest_index(x, y)
            .map(|(c, r)| self.heights[r * self.width + c])
    }

    /// Bilinear between the four pixel centres around (x, y); within half a
    /// pixel outside the outer centres the edge is extended; `None` beyond.
    pub fn bilinear(&self, x: f64, y: f64) -> Option<f64> {
        let (u, v) = self.pixel_coordinates(x, y);
        let (wm, hm) = (self.width as f64 - 1.0, self.height as f64 - 1.0);
        if !(u >= -0.5 && v >= -0.5 && u <= wm + 0.5 && v <= hm + 0.5) {
            return None;
        }
        let (u, v) = (u.clamp(0.0, wm), v.clamp(0.0, hm));
        let (c0, r0) = (u.floor() as usize, v.floor() as usize);
        let (c1, r1) = ((c0 + 1).min(self.width - 1), (r0 + 1).min(self.height - 1));
        let (fu, fv) = (u - c0 as f64, v - r0 as f64);
        let at = |c: usize, r: usize| f64::from(self.heights[r * self.width + c]);
        let top = at(c0, r0) * (1.0 - fu) + at(c1, r0) * fu;
        let bottom = at(c0, r1) * (1.0 - fu) + at(c1, r1) * fu;
        Some(top * (1.0 - fv) + bottom * fv)
    }

    /// The ground under (x, y) with `lookup`, `None` outside the map.
    pub fn ground(&self, lookup: Lookup, x: f64, y: f64) -> Option<f64> {
        match lookup {
            Lookup::Nearest => self.nearest(x, y).map(f64::from),
            Lookup::Bilinear => self.bilinear(x, y),
        }
    }

    /// The ground under (x, y), with (x, y) moved onto the map's edge when it
    /// lies outside: what the planner's cost and verification use, so a UAV
    /// outside the map is judged against the nearest known ground.
    pub fn ground_clamped(&self, lookup: Lookup, x: f64, y: f64) -> f64 {
        let [x0, x1] = self.x_extent();
        let [y0, y1] = self.y_extent();
        // max/min rather than clamp: a map placed at NaN (an invalid
        // mission, reported elsewhere) must not panic here.
        let (x, y) = (x.max(x0).min(x1), y.max(y0).min(y1));
        self.ground(lookup, x, y)
            .unwrap_or_else(|| f64::from(self.heights[0]))
    }

    /// ENU x covered by pixel centres, [min, max].
    pub fn x_extent(&self) -> [f64; 2] {
        let a = self.origin[0];
        let b = self.origin[0] + (self.width as f64 - 1.0) * self.pixel[0];
        [a.min(b), a.max(b)]
    }

    /// ENU y covered by pixel centres, [min, max].
    pub fn y_extent(&self) -> [f64; 2] {
        let a = self.origin[1];
        let b = self.origin[1] + (self.height as f64 - 1.0) * self.pixel[1];
        [a.min(b), a.max(b)]
    }
}

/// The colour of ground at `t` of a map's height range (0 lowest, 1
/// highest) on a ramp from `low` to `high` (RGB); `t` outside [0, 1] is
/// clamped, NaN counts as the lowest.
pub fn height_ramp(t: f64, low: [u8; 3], high: [u8; 3]) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mix = |a: u8, b: u8| (f64::from(a) + t * (f64::from(b) - f64::from(a))).round() as u8;
    [
        mix(low[0], high[0]),
        mix(low[1], high[1]),
        mix(low[2], high[2]),
    ]
}

/// The Rerun recording's terrain colour: green low to brown high (the
/// designer's map uses a darker ramp of the same hues under its glyphs).
pub fn height_colour(t: f64) -> [u8; 3] {
    height_ramp(t, [56, 118, 62], [176, 132, 84])
}

/// A regular grid of ground points for drawing a map in 3-D: every
/// `stride`-th pixel centre (and the last row and column), at most
/// `max_side` points a side.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    pub columns: usize,
    pub rows: usize,
    /// ENU (x, y, ground) per point, row by row.
    pub points: Vec<[f64; 3]>,
}

impl Grid {
    /// The grid of `map` read with `lookup` (negative heights as stored).
    pub fn of(map: &HeightMap, lookup: Lookup, max_side: usize) -> Self {
        let pick = |count: usize| -> Vec<usize> {
            let stride = count.saturating_sub(1).div_ceil(max_side.max(2) - 1).max(1);
            let mut v: Vec<usize> = (0..count).step_by(stride).collect();
            if v.last() != Some(&(count - 1)) {
                v.push(count - 1);
            }
            v
        };
        let (cols, rows) = (pick(map.width), pick(map.height));
        let mut points = Vec::with_capacity(cols.len() * rows.len());
        for &r in &rows {
            for &c in &cols {
                let x = map.origin[0] + c as f64 * map.pixel[0];
                let y = map.origin[1] + r as f64 * map.pixel[1];
                points.push([x, y, map.ground_clamped(lookup, x, y)]);
            }
        }
        Grid {
            columns: cols.len(),
            rows: rows.len(),
            points,
        }
    }

    /// Two triangles per grid square, as indices into `points`.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::with_capacity(2 * self.columns * self.rows);
        for r in 1..self.rows {
            for c in 1..self.columns {
                let at = |r: usize, c: usize| (r * self.columns + c) as u32;
                out.push([at(r - 1, c - 1), at(r - 1, c), at(r, c)]);
                out.push([at(r - 1, c - 1), at(r, c), at(r, c - 1)]);
            }
        }
        out
    }
}

/// A loaded map shared by every copy of the mission, or why it could not be
/// loaded. Compares equal whatever it holds: the mission's `[terrain]` keys
/// say which map it is.
#[derive(Debug, Clone, Default)]
pub struct Loaded(pub Option<Result<Arc<HeightMap>, String>>);

impl PartialEq for Loaded {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Maps already read, by canonical path and modification time, so the
/// designer's re-validation on every key does not read the file again.
type Cache = HashMap<(PathBuf, [u64; 4]), Arc<HeightMap>>;
static CACHE: Mutex<Option<Cache>> = Mutex::new(None);

/// Loads `file` (relative to `base`), through the cache.
pub fn load_cached(
    base: &Path,
    file: &str,
    origin: [f64; 2],
    pixel: [f64; 2],
) -> Result<Arc<HeightMap>, String> {
    let path = base.join(file);
    let canonical = path
        .canonicalize()
        .map_err(|e| format!("cannot open {}: {e}", path.display()))?;
    let modified = std::fs::metadata(&canonical)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.duration_since(SystemTime::UNIX_EPOCH).ok())
        .map_or(0, |d| d.as_nanos() as u64);
    let key = (
        canonical.clone(),
        [
            modified,
            origin[0].to_bits() ^ origin[1].to_bits().rotate_left(1),
            pixel[0].to_bits(),
            pixel[1].to_bits(),
        ],
    );
    if let Ok(guard) = CACHE.lock()
        && let Some(map) = guard.as_ref().and_then(|c| c.get(&key))
    {
        return Ok(map.clone());
    }
    let map = Arc::new(HeightMap::read_tiff(&canonical, origin, pixel)?);
    if let Ok(mut guard) = CACHE.lock() {
        let cache = guard.get_or_insert_with(HashMap::new);
        // A few maps at most: drop the others when a new one comes.
        if cache.len() >= 4 {
            cache.clear();
        }
        cache.insert(key, map.clone());
    }
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-made 3×3 map: h = 10 r + c at row r, column c (0-based).
    fn map() -> HeightMap {
        let h: Vec<f32> = (0..9).map(|i| (10 * (i / 3) + i % 3) as f32).collect();
        HeightMap::new(3, h, [0.0, 0.0], [2.0, 2.0]).expect("valid map")
    }

    #[test]
    fn nearest_takes_the_pixel_under_the_point_halves_away_from_zero() {
        let m = map();
        assert_eq!(m.nearest(0.0, 0.0), Some(0.0));
        assert_eq!(m.nearest(4.0, 2.0), Some(12.0));
        assert_eq!(m.nearest(0.99, 3.01), Some(20.0));
        // u = 0.5 → round(1.5) = 2 → column 1 (half away from zero).
        assert_eq!(m.nearest(1.0, 0.0), Some(1.0));
        assert_eq!(m.nearest(-1.0, 0.0), Some(0.0), "u = -0.5 → round(0.5) = 1");
        assert_eq!(m.nearest(-1.01, 0.0), None);
        assert_eq!(m.nearest(5.0, 0.0), None, "u = 2.5 → round(3.5) = 4 > 3");
    }

    #[test]
    fn bilinear_interpolates_between_centres() {
        let m = map();
        assert_eq!(m.bilinear(0.0, 0.0), Some(0.0));
        assert_eq!(m.bilinear(1.0, 0.0), Some(0.5));
        assert_eq!(m.bilinear(1.0, 1.0), Some(5.5));
        assert_eq!(m.bilinear(4.0, 4.0), Some(22.0));
        assert_eq!(m.bilinear(3.0, 2.0), Some(11.5));
        assert_eq!(
            m.bilinear(4.9, 4.9),
            Some(22.0),
            "edge extended half a pixel"
        );
        assert_eq!(m.bilinear(5.1, 0.0), None);
        assert_eq!(m.ground_clamped(Lookup::Bilinear, 50.0, 1.0), 7.0);
    }

    #[test]
    fn a_negative_pixel_step_counts_rows_downward() {
        let h: Vec<f32> = (0..9).map(|i| (10 * (i / 3) + i % 3) as f32).collect();
        let m = HeightMap::new(3, h, [0.0, 4.0], [2.0, -2.0]).expect("valid map");
        assert_eq!(m.nearest(0.0, 4.0), Some(0.0));
        assert_eq!(m.nearest(0.0, 0.0), Some(20.0));
        assert_eq!(m.y_extent(), [0.0, 4.0]);
    }

    #[test]
    fn malformed_maps_are_refused() {
        assert!(HeightMap::new(2, vec![0.0; 3], [0.0; 2], [1.0; 2]).is_err());
        assert!(HeightMap::new(1, vec![f32::NAN], [0.0; 2], [1.0; 2]).is_err());
        assert!(HeightMap::new(1, vec![-3.4e38], [0.0; 2], [1.0; 2]).is_err());
        assert!(HeightMap::new(1, vec![1.0], [0.0; 2], [0.0, 1.0]).is_err());
    }

    #[test]
    fn a_grid_keeps_the_corners_and_the_heights() {
        let heights: Vec<f32> = (0..25).map(|k| k as f32).collect();
        let map = HeightMap::new(5, heights, [10.0, 20.0], [2.0, 2.0]).expect("5 × 5");
        let g = Grid::of(&map, Lookup::Nearest, 3);
        assert_eq!((g.columns, g.rows), (3, 3));
        assert_eq!(g.points[0], [10.0, 20.0, 0.0]);
        assert_eq!(g.points[8], [18.0, 28.0, 24.0]);
        assert_eq!(g.points[4], [14.0, 24.0, 12.0]);
        assert_eq!(g.triangles().len(), 8);
        assert!(
            g.triangles()
                .iter()
                .flatten()
                .all(|&i| (i as usize) < g.points.len())
        );
        assert!(height_colour(1.0)[0] > height_colour(0.0)[0]);
    }
}
