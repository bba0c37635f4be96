//! The SPSO benchmark's cost (Phung & Ha 2021, reference code duongpm/SPSO,
//! `MyCost.m`), bit for bit: J = ((5 J1 + J2) + 10 J3) + J4.
//!
//! Every MATLAB detail is kept (see `docs/spso.md`): the ground is
//! H(round(y), round(x)) with 1-based pixel coordinates and round half away
//! from zero, negative heights count as 0, the absolute altitude is a float32
//! sum `(z as f32) + H` widened to f64, J2 is ∞ strictly below R + 1, J3 is ∞
//! strictly below z = 0 (relative), J4 uses atan2-based angles in degrees with
//! borrowed projections where a segment has no x-y extent, and strict `> 45`.
//!
//! Where the reference raises an index error (a point whose rounded pixel is
//! outside the map) skyform returns J = +∞ ([`Terms::off_map`] is set).

use std::sync::Arc;

use crate::base::terrain::HeightMap;

/// (180/π)·atan2(y, x): Octave 7.3's `atan2d`, the product 180/π first.
const DEG: f64 = 180.0 / std::f64::consts::PI;

/// Most points (start, free nodes, goal) a path may have: the free nodes
/// validation allows, and start and goal.
pub const MAX_POINTS: usize = crate::mission::SPSO_MAX_NODES + 2;

// J2 keeps one bit per segment in a u64.
const _: () = assert!(MAX_POINTS - 1 <= 64);

/// A vertical cylinder threat: centre (x, y) and radius; only the x-y
/// distance counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Threat {
    pub x: f64,
    pub y: f64,
    pub radius: f64,
}

/// Everything the cost needs: the scenario of `CreateModel.m` and the
/// constants of `MyCost.m`.
#[derive(Debug, Clone)]
pub struct Model {
    /// Start and goal (x, y, z above the ground).
    pub start: [f64; 3],
    pub goal: [f64; 3],
    /// n, the free nodes between them.
    pub nodes: usize,
    pub threats: Vec<Threat>,
    /// [z_min, z_max], above the ground; J3 measures from their middle.
    pub band: [f64; 2],
    pub map: Arc<HeightMap>,
    /// drone_size (1) and danger_dist (10).
    pub drone_size: f64,
    pub danger_distance: f64,
    /// turning_max, climb_max, degrees (45, 45).
    pub turning_max: f64,
    pub climb_max: f64,
    /// b1..b4 (5, 1, 10, 1).
    pub weights: [f64; 4],
    /// The map uses the benchmark's own convention (origin 1, step 1).
    unit_grid: bool,
}

/// J and its four terms.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Terms {
    pub total: f64,
    pub length: f64,
    pub threat: f64,
    pub altitude: f64,
    pub smoothness: f64,
    /// A point's pixel is outside the map (the reference's index error): J = ∞.
    pub off_map: bool,
}

impl Model {
    /// The benchmark's constants around a scenario.
    pub fn new(
        start: [f64; 3],
        goal: [f64; 3],
        nodes: usize,
        threats: Vec<Threat>,
        band: [f64; 2],
        map: Arc<HeightMap>,
    ) -> Self {
        let unit_grid = map.origin == [1.0, 1.0] && map.pixel == [1.0, 1.0];
        Model {
            start,
            goal,
            nodes,
            threats,
            band,
            map,
            drone_size: 1.0,
            danger_distance: 10.0,
            turning_max: 45.0,
            climb_max: 45.0,
            weights: [5.0, 1.0, 10.0, 1.0],
            unit_grid,
        }
    }

    /// H(round(y), round(x)) with negative heights set to 0, or `None` outside.
    #[inline]
    pub fn ground(&self, x: f64, y: f64) -> Option<f32> {
        let h = self.pixel_index(x, y).map(|i| self.map.heights[i])?;
        Some(if h < 0.0 { 0.0 } else { h })
    }

    /// The index into the height array of the pixel under (x, y), or `None`
    /// off the map.
    #[inline(always)]
    fn pixel_index(&self, x: f64, y: f64) -> Option<usize> {
        if self.unit_grid {
            let (inside, k) = self.unit_grid_pixel(x, y);
            inside.then_some(k)
        } else {
            let m = &*self.map;
            m.nearest_index(x, y).map(|(c, r)| r * m.width + c)
        }
    }

    /// With the benchmark's own convention (origin 1, step 1): whether the
    /// 1-based pixel round(x), round(y) is on the map, and its index
    /// (meaningless, but harmless, when it is not). MATLAB's round without
    /// a libm call ([`round_half_away`]) and without branches (the points'
    /// pixels are as good as random to the branch predictor).
    #[inline(always)]
    fn unit_grid_pixel(&self, x: f64, y: f64) -> (bool, usize) {
        let m = &*self.map;
        let (c, r) = (round_half_away(x), round_half_away(y));
        let inside = (c >= 1.0) & (r >= 1.0) & (c <= m.width as f64) & (r <= m.height as f64);
        let k = (r as usize)
            .wrapping_sub(1)
            .wrapping_mul(m.width)
            .wrapping_add((c as usize).wrapping_sub(1));
        (inside, k)
    }

    /// [`Self::pixel_index`] of every point into `index`; false when one is
    /// off the map. On the benchmark's own grid, every point without a
    /// branch, then one test.
    #[inline(always)]
    fn pixel_indices(&self, xs: &[f64], ys: &[f64], index: &mut [usize]) -> bool {
        let mut all_inside = true;
        for ((&x, &y), k) in xs.iter().zip(ys).zip(index.iter_mut()) {
            if self.unit_grid {
                let (inside, i) = self.unit_grid_pixel(x, y);
                all_inside &= inside;
                *k = i;
            } else {
                match self.pixel_index(x, y) {
                    Some(i) => *k = i,
                    None => return false,
                }
            }
        }
        all_inside
    }

    /// J for free nodes given as x1..xn, y1..yn, z1..zn (z above the ground).
    pub fn cost(&self, xyz: &[f64]) -> f64 {
        self.cost_below(xyz, f64::INFINITY)
    }

    /// J, or a lower bound of it that is ≥ `bound` once J is known to reach
    /// `bound` (a candidate that cannot beat a personal best).
    pub fn cost_below(&self, xyz: &[f64], bound: f64) -> f64 {
        self.evaluate(xyz, bound).total
    }

    /// J and its terms.
    pub fn terms(&self, xyz: &[f64]) -> Terms {
        self.evaluate(xyz, f64::INFINITY)
    }

    /// Long (~200 lines) on purpose: the SPSO reference's cost loop in its own order, term by term, so a parity check reads it line by line.
    fn evaluate(&self, xyz: &[f64], bound: f64) -> Terms {
        let n = self.nodes;
        let points = n + 2;
        assert!(
            xyz.len() == 3 * n && points <= MAX_POINTS,
            "an SPSO path has 3 n numbers, n ≤ {}",
            MAX_POINTS - 2
        );
        let mut px = [0.0f64; MAX_POINTS];
        let mut py = [0.0f64; MAX_POINTS];
        let mut pz = [0.0f64; MAX_POINTS];
        px[0] = self.start[0];
        py[0] = self.start[1];
        pz[0] = self.start[2];
        px[1..=n].copy_from_slice(&xyz[..n]);
        py[1..=n].copy_from_slice(&xyz[n..2 * n]);
        pz[1..=n].copy_from_slice(&xyz[2 * n..]);
        px[n + 1] = self.goal[0];
        py[n + 1] = self.goal[1];
        pz[n + 1] = self.goal[2];
        let (px, py, pz) = (&px[..points], &py[..points], &pz[..points]);
        let segments = points - 1;
        let [b1, b2, b3, b4] = self.weights;

        // J3 over the free nodes, relative z: no terrain needed.
        let mid = (self.band[1] + self.band[0]) / 2.0;
        let mut j3 = 0.0;
        for &z in &pz[1..=n] {
            j3 += if z < 0.0 {
                f64::INFINITY
            } else {
                (z - mid).abs()
            };
        }

        // Per segment: the x-y step and its length.
        let mut dx = [0.0f64; MAX_POINTS];
        let mut dy = [0.0f64; MAX_POINTS];
        let mut flat = [0.0f64; MAX_POINTS];
        let mut flat_sum = 0.0;
        for k in 0..segments {
            dx[k] = px[k + 1] - px[k];
            dy[k] = py[k + 1] - py[k];
            flat[k] = (dx[k] * dx[k] + dy[k] * dy[k]).sqrt();
            flat_sum += flat[k];
        }
        // Each 3-D length is ≥ its x-y length in floating point too (adding
        // dz² ≥ 0, sqrt and sums are monotone), so 5 Σ|xy| (+ J2) + 10 J3 ≤
        // J: a candidate that cannot beat `bound` stops before touching the
        // map, whose random reads are the slowest part of an evaluation.
        if bound.is_finite() && b1 * flat_sum + b3 * j3 >= bound {
            return Terms {
                total: b1 * flat_sum + b3 * j3,
                altitude: j3,
                ..Terms::default()
            };
        }

        // J2 needs no heights, so it comes before the map reads: a path
        // through a threat stops without them. Threat-major. A threat whose
        // centre lies outside a segment's x-y box grown by its danger
        // radius is certainly farther than that (cost 0): the boxes once,
        // then per threat one bit per segment, built without branches, and
        // only the near segments measured.
        let (mut x0, mut x1) = ([0.0f64; MAX_POINTS], [0.0f64; MAX_POINTS]);
        let (mut y0, mut y1) = ([0.0f64; MAX_POINTS], [0.0f64; MAX_POINTS]);
        for k in 0..segments {
            (x0[k], x1[k]) = (px[k].min(px[k + 1]), px[k].max(px[k + 1]));
            (y0[k], y1[k]) = (py[k].min(py[k + 1]), py[k].max(py[k + 1]));
        }
        let mut j2 = 0.0;
        for t in &self.threats {
            let inner = t.radius + self.drone_size;
            let outer = t.radius + self.drone_size + self.danger_distance;
            let reach = outer * (1.0 + 1e-9) + 1e-9;
            let mut near = 0u64;
            for k in 0..segments {
                let far = (t.x < x0[k] - reach)
                    | (t.x > x1[k] + reach)
                    | (t.y < y0[k] - reach)
                    | (t.y > y1[k] + reach);
                near |= u64::from(!far) << k;
            }
            while near != 0 {
                let k = near.trailing_zeros() as usize;
                near &= near - 1;
                let d = dist_p2s([t.x, t.y], [px[k], py[k]], [px[k + 1], py[k + 1]]);
                j2 += if d > outer {
                    0.0
                } else if d < inner {
                    f64::INFINITY
                } else {
                    outer - d
                };
            }
            // J2 only grows, so the sum so far bounds J from below (∞ once
            // a threat is crossed).
            let low = b1 * flat_sum + b2 * j2 + b3 * j3;
            if bound.is_finite() && low >= bound {
                return Terms {
                    total: low,
                    threat: j2,
                    altitude: j3,
                    ..Terms::default()
                };
            }
        }

        // z_abs = z + H: single + double is single in MATLAB, then stored in
        // a double array. Every pixel index first, then the reads, so the
        // cache misses on the map overlap.
        let mut index = [0usize; MAX_POINTS];
        if !self.pixel_indices(&px[..points], &py[..points], &mut index) {
            return Terms {
                total: f64::INFINITY,
                off_map: true,
                ..Terms::default()
            };
        }
        let heights = &self.map.heights;
        let mut za = [0.0f64; MAX_POINTS];
        for i in 0..points {
            let h = heights[index[i]];
            let h = if h < 0.0 { 0.0 } else { h };
            za[i] = f64::from(pz[i] as f32 + h);
        }

        let mut dz = [0.0f64; MAX_POINTS];
        let mut j1 = 0.0;
        for k in 0..segments {
            dz[k] = za[k + 1] - za[k];
            j1 += (dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k]).sqrt();
        }
        let mut terms = Terms {
            length: j1,
            threat: j2,
            altitude: j3,
            ..Terms::default()
        };
        let partial = b1 * j1 + b2 * j2 + b3 * j3;
        if bound.is_finite() && partial >= bound {
            terms.total = partial;
            return terms;
        }

        // J4: for each interior point, the borrowed projections.
        let nonzero = |k: usize| dx[k] != 0.0 || dy[k] != 0.0;
        let mut j4 = 0.0;
        let mut before = 0usize; // last non-zero segment ≤ i, else 0
        let mut climb: Option<(f64, f64, f64)> = None; // (Δz, |xy|, angle)
        for i in 0..points - 2 {
            if nonzero(i) {
                before = i;
            }
            let s1 = if nonzero(i) { i } else { before };
            let s2 = (i + 1..segments)
                .find(|&k| nonzero(k))
                .unwrap_or(segments - 1);
            // Turning angle atan2d(|s1 × s2|, s1 · s2), exactly as printed.
            let cz = (dx[s1] * dy[s2] - dy[s1] * dx[s2]).abs();
            let dot = dx[s1] * dx[s2] + dy[s1] * dy[s2];
            if !(dot > 0.0 && cz < dot * (1.0 - 1e-10)) {
                let turning = DEG * cz.atan2(dot);
                if turning.abs() > self.turning_max {
                    j4 += turning.abs();
                }
            }
            // Climb angles: Δz_abs of the adjacent segments over the
            // (borrowed) horizontal length.
            let (z1, h1, z2, h2) = (dz[i], flat[s1], dz[i + 1], flat[s2]);
            let cross = h1 * z2 - z1 * h2;
            let along = h1 * h2 + z1 * z2;
            let slack = 1e-12 * ((h1 * z2).abs() + (z1 * h2).abs());
            if !(along > 0.0 && cross.abs() + slack < along * (1.0 - 1e-9)) {
                // This point's outgoing climb angle is usually the next
                // point's incoming one: computed once.
                let a1 = match climb {
                    Some((z, h, a)) if z == z1 && h == h1 => a,
                    _ => DEG * z1.atan2(h1),
                };
                let a2 = DEG * z2.atan2(h2);
                climb = Some((z2, h2, a2));
                let change = a2 - a1;
                if change.abs() > self.climb_max {
                    j4 += change.abs();
                }
            }
            // As for J2: J4 only grows.
            if bound.is_finite() && partial + b4 * j4 >= bound {
                terms.smoothness = j4;
                terms.total = partial + b4 * j4;
                return terms;
            }
        }
        terms.smoothness = j4;
        terms.total = ((b1 * j1 + b2 * j2) + b3 * j3) + b4 * j4;
        terms
    }
}

/// `DistP2S.m`: x-y distance from `x` to the segment a-b, with Octave's
/// branch on the dot products and LAPACK's 2×2 determinant.
#[inline]
pub fn dist_p2s(x: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d_ab = norm2(a[0] - b[0], a[1] - b[1]);
    let d_ax = norm2(a[0] - x[0], a[1] - x[1]);
    if d_ab != 0.0 {
        let dot1 = (a[0] - b[0]) * (x[0] - b[0]) + (a[1] - b[1]) * (x[1] - b[1]);
        let dot2 = (b[0] - a[0]) * (x[0] - a[0]) + (b[1] - a[1]) * (x[1] - a[1]);
        if dot1 * dot2 >= 0.0 {
            det2([b[0] - a[0], b[1] - a[1]], [x[0] - a[0], x[1] - a[1]]).abs() / d_ab
        } else {
            let d_bx = norm2(b[0] - x[0], b[1] - x[1]);
            d_ax.min(d_bx)
        }
    } else {
        d_ax
    }
}

/// MATLAB's `round` (half away from zero) without a libm call: the integer
/// part by conversion (exact below 2^52; larger, infinite and NaN inputs
/// land off any map), then the half step from the exact fraction.
#[inline]
fn round_half_away(x: f64) -> f64 {
    let whole = x as i64 as f64;
    let fraction = x - whole;
    // Without branches: the fraction's half step is unpredictable.
    whole + f64::from(u8::from(fraction >= 0.5)) - f64::from(u8::from(fraction <= -0.5))
}

#[inline]
fn norm2(a: f64, b: f64) -> f64 {
    (a * a + b * b).sqrt()
}

/// det([r1; r2]) as LAPACK's dgetrf does it: partial pivoting on the first
/// column, l = a_21 · (1 / pivot), u22 = a_22 − l · a_12.
#[inline]
fn det2(r1: [f64; 2], r2: [f64; 2]) -> f64 {
    let (p, q, sign) = if r2[0].abs() > r1[0].abs() {
        (r2, r1, -1.0)
    } else {
        (r1, r2, 1.0)
    };
    if p[0] == 0.0 {
        return 0.0;
    }
    let l = q[0] * (1.0 / p[0]);
    let u22 = q[1] - l * p[1];
    sign * (p[0] * u22)
}

// The expected values are the reference's, printed with %.17g.
#[cfg(test)]
#[allow(clippy::excessive_precision)]
mod tests {
    use super::*;

    /// Flat ground H ≡ `h` on 300 × 300 pixels, band [100, 200] (SPEC §9).
    fn flat(start: [f64; 3], goal: [f64; 3], n: usize, threats: &[[f64; 3]], h: f32) -> Model {
        let map =
            HeightMap::new(300, vec![h; 300 * 300], [1.0, 1.0], [1.0, 1.0]).expect("a flat map");
        let threats = threats
            .iter()
            .map(|t| Threat {
                x: t[0],
                y: t[1],
                radius: t[2],
            })
            .collect();
        Model::new(start, goal, n, threats, [100.0, 200.0], Arc::new(map))
    }

    fn nodes(p: &[[f64; 3]]) -> Vec<f64> {
        (0..3).flat_map(|c| p.iter().map(move |q| q[c])).collect()
    }

    fn check(m: &Model, p: &[[f64; 3]], want: [f64; 5]) {
        let t = m.terms(&nodes(p));
        let got = [t.total, t.length, t.threat, t.altitude, t.smoothness];
        for (g, w) in got.iter().zip(&want) {
            let ok = g == w || (g - w).abs() <= 1e-15 * w.abs();
            assert!(ok, "got {got:?}, want {want:?}");
        }
    }

    const S: [f64; 3] = [10.0, 10.0, 150.0];

    #[test]
    fn e1_straight() {
        let m = flat(S, [100.0, 130.0, 150.0], 2, &[], 0.0);
        check(
            &m,
            &[[40.0, 50.0, 150.0], [70.0, 90.0, 150.0]],
            [750.0, 150.0, 0.0, 0.0, 0.0],
        );
    }

    #[test]
    fn e2_turns_above_and_at_45_degrees() {
        let m = flat(S, [80.0, 20.0, 150.0], 1, &[], 0.0);
        check(&m, &[[40.0, 50.0, 150.0]], [590.0, 100.0, 0.0, 0.0, 90.0]);
        let m = flat([10.0, 60.0, 150.0], [40.0, 50.0, 150.0], 1, &[], 0.0);
        check(
            &m,
            &[[40.0, 100.0, 150.0]],
            [643.13010235415595, 100.0, 0.0, 0.0, 143.13010235415598],
        );
        let m = flat(S, [110.0, 260.0, 150.0], 1, &[], 0.0);
        check(
            &m,
            &[[10.0, 160.0, 150.0]],
            [1457.1067811865476, 291.42135623730951, 0.0, 0.0, 0.0],
        );
    }

    #[test]
    fn e3_climbs() {
        let m = flat(S, [70.0, 90.0, 150.0], 1, &[], 0.0);
        check(
            &m,
            &[[40.0, 50.0, 200.0]],
            [1297.1067811865476, 141.42135623730951, 0.0, 50.0, 90.0],
        );
        let m = flat(S, [70.0, 90.0, 200.0], 1, &[], 0.0);
        check(
            &m,
            &[[40.0, 50.0, 200.0]],
            [1103.5533905932739, 120.71067811865476, 0.0, 50.0, 0.0],
        );
        // E8: the same over ground at 100 m: J3 stays relative.
        let m = flat(S, [70.0, 90.0, 150.0], 1, &[], 100.0);
        check(
            &m,
            &[[40.0, 50.0, 200.0]],
            [1297.1067811865476, 141.42135623730951, 0.0, 50.0, 90.0],
        );
    }

    #[test]
    fn e4_threats_inside_on_the_boundaries_and_over_a_repeated_point() {
        let m = flat(S, [100.0, 130.0, 150.0], 2, &[[25.0, 30.0, 5.0]], 0.0);
        check(
            &m,
            &[[40.0, 50.0, 150.0], [70.0, 90.0, 150.0]],
            [f64::INFINITY, 150.0, f64::INFINITY, 0.0, 0.0],
        );
        let g = [100.0, 10.0, 150.0];
        let m = flat(S, g, 1, &[[55.0, 20.0, 5.0]], 0.0);
        check(&m, &[[55.0, 10.0, 150.0]], [462.0, 90.0, 12.0, 0.0, 0.0]);
        let m = flat(S, g, 1, &[[30.0, 16.0, 5.0], [80.0, 26.0, 5.0]], 0.0);
        check(&m, &[[55.0, 10.0, 150.0]], [460.0, 90.0, 10.0, 0.0, 0.0]);
        let m = flat(S, g, 2, &[[40.0, 17.0, 0.0]], 0.0);
        check(
            &m,
            &[[40.0, 10.0, 150.0], [40.0, 10.0, 150.0]],
            [462.0, 90.0, 12.0, 0.0, 0.0],
        );
    }

    #[test]
    fn e5_a_node_below_the_ground_is_infinite() {
        let m = flat(S, [70.0, 90.0, 150.0], 1, &[], 0.0);
        check(
            &m,
            &[[40.0, 50.0, -1.0]],
            [
                f64::INFINITY,
                318.12576129574921,
                0.0,
                f64::INFINITY,
                143.35791827474222,
            ],
        );
    }

    #[test]
    fn e6_e7_repeated_x_y_points_borrow_projections() {
        let m = flat(S, [70.0, 90.0, 150.0], 2, &[], 0.0);
        check(
            &m,
            &[[40.0, 50.0, 150.0], [40.0, 50.0, 190.0]],
            [
                1247.4758283798226,
                154.03124237432849,
                0.0,
                40.0,
                77.319616508180175,
            ],
        );
        let m = flat(S, [40.0, 50.0, 150.0], 1, &[], 0.0);
        check(
            &m,
            &[[10.0, 10.0, 170.0]],
            [
                681.05964984307707,
                73.851648071345039,
                0.0,
                20.0,
                111.80140948635182,
            ],
        );
    }

    #[test]
    fn a_point_off_the_map_is_infinite() {
        let m = flat(S, [70.0, 90.0, 150.0], 1, &[], 0.0);
        let t = m.terms(&nodes(&[[0.4999999999999999, 50.0, 150.0]]));
        assert!(t.off_map && t.total.is_infinite());
        assert!(!m.terms(&nodes(&[[0.5, 50.0, 150.0]])).off_map);
        assert!(m.terms(&nodes(&[[300.5, 50.0, 150.0]])).off_map);
        assert!(m.terms(&nodes(&[[f64::NAN, 50.0, 150.0]])).off_map);
    }

    #[test]
    fn round_half_away_is_matlab_round() {
        for x in [
            0.0,
            0.49999999999999994,
            0.5,
            1.5,
            2.5,
            -0.5,
            -2.5,
            -0.49999999999999994,
            1044.5,
            878.49999999999989,
            4503599627370495.5,
            9007199254740993.0,
            -9007199254740993.0,
        ] {
            assert_eq!(round_half_away(x), x.round(), "round({x:e})");
        }
        // Beyond i64 the value only has to stay off any map.
        assert!(round_half_away(1e300) > 1e18);
        assert!(round_half_away(-1e300) < -1e18);
        assert!(round_half_away(f64::INFINITY) > 1e18);
        assert_eq!(round_half_away(f64::NAN), 0.0);
    }

    #[test]
    fn the_bound_gives_a_lower_bound_at_least_the_bound() {
        let m = flat(S, [70.0, 90.0, 150.0], 1, &[], 0.0);
        let p = nodes(&[[40.0, 50.0, 200.0]]);
        let full = m.cost(&p);
        assert_eq!(m.cost_below(&p, f64::INFINITY), full);
        let partial = m.cost_below(&p, 100.0);
        assert!(partial >= 100.0 && partial <= full);
        // Through a threat: infinite under any bound the path could beat,
        // and the terms still all computed without one.
        let m = flat(S, [100.0, 130.0, 150.0], 2, &[[25.0, 30.0, 5.0]], 0.0);
        let p = nodes(&[[40.0, 50.0, 150.0], [70.0, 90.0, 150.0]]);
        assert_eq!(m.cost_below(&p, 1e6), f64::INFINITY);
        assert_eq!(m.terms(&p).length, 150.0);
    }

    /// What the swarm relies on: under a bound, the cost is exact when
    /// below it, and otherwise some value between the bound and J.
    #[test]
    fn a_bounded_cost_is_exact_below_the_bound_and_a_lower_bound_above() {
        let threats = [
            [100.0, 120.0, 8.0],
            [200.0, 150.0, 6.0],
            [150.0, 250.0, 5.0],
        ];
        let m = flat([20.0, 20.0, 150.0], [280.0, 280.0, 150.0], 6, &threats, 0.0);
        let mut state = 12345u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut exact, mut stopped) = (0, 0);
        for _ in 0..20_000 {
            let mut p: Vec<f64> = (0..12).map(|_| 1.0 + 298.0 * next()).collect();
            p.extend((0..6).map(|_| 80.0 + 140.0 * next()));
            let full = m.cost(&p);
            let bound = if full.is_finite() {
                full * (0.5 + next())
            } else {
                1e3 + 1e4 * next()
            };
            let got = m.cost_below(&p, bound);
            if full < bound {
                assert_eq!(got.to_bits(), full.to_bits());
                exact += 1;
            } else {
                assert!(
                    got >= bound && got <= full,
                    "{got} not in [{bound}, {full}]"
                );
                stopped += 1;
            }
        }
        assert!(
            exact > 1000 && stopped > 1000,
            "{exact} exact, {stopped} stopped"
        );
    }
}
