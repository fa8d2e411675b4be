//! How much a terrain looks like land that drains: the standard signatures of river networks,
//! computed with D8 routing on the depression-filled surface ([`super::route`]), over the
//! raised land (cells more than 1 % of the relief above the lowest cell). `docs/erosion.md`
//! lists them with the values real land and fastscapelib give.

use serde::Serialize;

use super::route::{D8, Routing};
use crate::heightmap::Heightmap;

/// The land's drainage signatures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Signatures {
    /// τ of the drainage-area exceedance `P(A ≥ a) ~ a^−τ`, fitted for `a` from 10 cells to 1 %
    /// of the raised cells (river networks: 0.43–0.5).
    pub area_tau: f64,
    /// Hack's exponent `h` of the main-stream length `L ~ A^h`, fitted over log₂ bins of the
    /// area from 10 cells up (real land: about 0.5–0.6).
    pub hack_h: f64,
    /// The share of the sloped raised cells (over 1°) whose slope is within ±1° of the
    /// commonest slope (0.5° bins): near 1 on a roof of one flank angle.
    pub slope_mode_share: f64,
    /// Undrained depressions deeper than 0.5 % of the relief (8-connected groups of cells whose
    /// filled level is that far above them), outside the cells `water` marks.
    pub pits: u32,
    /// The deepest depression's depth, metres (0 when none), outside that water.
    pub pit_depth_max: f64,
}

/// Least-squares slope of `y` over `x`; NaN with fewer than two distinct points.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    if points.len() < 2 {
        return f64::NAN;
    }
    let (sx, sy) = points.iter().fold((0.0, 0.0), |(a, b), &(x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for &(x, y) in points {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
    }
    if sxx == 0.0 { f64::NAN } else { sxy / sxx }
}

/// The signatures of `map`; `water`, if given, marks cells (row-major) of water the user asked
/// for (rivers, lakes), whose depressions are not counted.
pub fn signatures(map: &Heightmap, water: Option<&[bool]>) -> Signatures {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    let cell = map.cell_size();
    let h: Vec<f64> = map
        .heights()
        .iter()
        .map(|&v| if v.is_finite() { f64::from(v) } else { 0.0 })
        .collect();
    let (lo, hi) = h
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let relief = (hi - lo).max(0.0);
    let raised: Vec<bool> = h.iter().map(|&v| relief > 0.0 && v > lo + 0.01 * relief).collect();
    let mut w = Routing::new(cols, rows);
    w.route(&h);
    let n_raised = raised.iter().filter(|&&r| r).count();

    // τ: exceedance at areas 10·2^k cells up to 1 % of the raised cells.
    let mut areas: Vec<f64> = (0..cols * rows).filter(|&i| raised[i]).map(|i| w.area[i]).collect();
    areas.sort_by(f64::total_cmp);
    let mut points = Vec::new();
    let mut a = 10.0;
    while a <= 0.01 * n_raised as f64 {
        let at_least = areas.len() - areas.partition_point(|&v| v < a);
        if at_least > 0 {
            points.push((a.ln(), (at_least as f64 / areas.len() as f64).ln()));
        }
        a *= 2.0;
    }
    let area_tau = -slope(&points);

    // Hack: the longest path from a divide to each cell, metres.
    let mut length = vec![0.0f64; cols * rows];
    for &i in w.stack.iter().rev() {
        let i = i as usize;
        let r = w.receiver[i] as usize;
        if r != i {
            let l = length[i] + w.dist[i] * cell;
            if l > length[r] {
                length[r] = l;
            }
        }
    }
    let mut bins: Vec<(f64, f64, u32)> = Vec::new();
    for i in (0..cols * rows).filter(|&i| raised[i] && w.area[i] >= 10.0 && length[i] > 0.0) {
        let b = w.area[i].log2().floor() as usize;
        if bins.len() <= b {
            bins.resize(b + 1, (0.0, 0.0, 0));
        }
        let a_m2 = w.area[i] * cell * cell;
        bins[b].0 += a_m2.ln();
        bins[b].1 += length[i].ln();
        bins[b].2 += 1;
    }
    let points: Vec<(f64, f64)> = bins
        .iter()
        .filter(|b| b.2 >= 5)
        .map(|&(x, y, n)| (x / f64::from(n), y / f64::from(n)))
        .collect();
    let hack_h = slope(&points);

    // Slopes by central differences, degrees.
    let mut hist = [0u32; 180];
    let mut angles = Vec::new();
    for r in 1..rows.saturating_sub(1) {
        for c in 1..cols.saturating_sub(1) {
            let i = r * cols + c;
            if !raised[i] {
                continue;
            }
            let sx = (h[i + 1] - h[i - 1]) / (2.0 * cell);
            let sy = (h[i + cols] - h[i - cols]) / (2.0 * cell);
            let deg = sx.hypot(sy).atan().to_degrees();
            if deg > 1.0 {
                hist[((deg * 2.0) as usize).min(179)] += 1;
                angles.push(deg);
            }
        }
    }
    let mode_bin = (0..180).max_by_key(|&b| (hist[b], std::cmp::Reverse(b))).unwrap_or(0);
    let mode = (mode_bin as f64 + 0.5) * 0.5;
    let near = angles.iter().filter(|&&d| (d - mode).abs() <= 1.0).count();
    let slope_mode_share = if angles.is_empty() {
        0.0
    } else {
        near as f64 / angles.len() as f64
    };

    // Depressions: cells the fill raised by more than 0.5 % of the relief, grouped.
    let deep = 0.005 * relief;
    let lake = |i: usize| water.and_then(|l| l.get(i)).copied().unwrap_or(false);
    let depth = |i: usize| w.filled[i] - h[i];
    let mut seen = vec![false; cols * rows];
    let (mut pits, mut pit_depth_max) = (0u32, 0.0f64);
    let mut todo = Vec::new();
    for start in 0..cols * rows {
        if seen[start] || lake(start) || depth(start) <= 0.0 {
            continue;
        }
        // One depression: the 8-connected cells the fill raised.
        let mut deepest = 0.0f64;
        seen[start] = true;
        todo.push(start);
        while let Some(i) = todo.pop() {
            deepest = deepest.max(depth(i));
            let (c, r) = ((i % cols) as i32, (i / cols) as i32);
            for (dc, dr) in D8 {
                let (nc, nr) = (c + dc, r + dr);
                if nc < 0 || nr < 0 || nc >= cols as i32 || nr >= rows as i32 {
                    continue;
                }
                let n = nr as usize * cols + nc as usize;
                if !seen[n] && !lake(n) && depth(n) > 0.0 {
                    seen[n] = true;
                    todo.push(n);
                }
            }
        }
        pit_depth_max = pit_depth_max.max(deepest);
        if deepest > deep {
            pits += 1;
        }
    }
    Signatures {
        area_tau,
        hack_h,
        slope_mode_share,
        pits,
        pit_depth_max,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cone_drains_like_a_cone_and_a_bowl_is_a_pit() {
        // A cone: water runs straight down, every flank cell's area small: τ is large.
        let n = 129u32;
        let heights: Vec<f32> = (0..n * n)
            .map(|i| {
                let (c, r) = ((i % n) as f32 - 64.0, (i / n) as f32 - 64.0);
                (500.0 - 8.0 * c.hypot(r)).max(0.0)
            })
            .collect();
        let cone = Heightmap::from_heights(n, n, 10.0, heights.clone()).expect("a grid");
        let s = signatures(&cone, None);
        assert!(s.area_tau > 0.8, "{s:?}");
        assert!(s.slope_mode_share > 0.5, "one flank angle: {s:?}");
        assert_eq!(s.pits, 0);
        // The same cone upside down inside a rim is one deep depression.
        let bowl: Vec<f32> = heights.iter().map(|&v| 600.0 - v).collect();
        let bowl = Heightmap::from_heights(n, n, 10.0, bowl).expect("a grid");
        let s = signatures(&bowl, None);
        assert_eq!(s.pits, 1, "{s:?}");
        assert!(s.pit_depth_max > 400.0, "{s:?}");
    }
}
