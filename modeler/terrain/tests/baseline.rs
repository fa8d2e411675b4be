//! The seed's method, as the reference the engine is tested and benchmarked against: distance
//! maps by sweeping the whole grid again and again until nothing changes (section 4.3), and the
//! terrain evaluated cell by cell from them. O(cells × largest distance) per map against the
//! engine's breadth-first searches' O(cells), and no caches.
//!
//! Each sweep is synchronous: values assigned during a sweep are read only by the next one. That
//! is the reading under which the thesis' rules give true 4-neighbour distances (an in-place sweep
//! would let a value travel several cells in one pass and fix it too early).
//!
//! [`generate`] follows the `f32` arithmetic the engine documents (`shape_k` by
//! `fastmath::shape_from_log` and `share_k` each rounded to `f32`, `coef_k` their `f32` product, then `base + Σ relief_k·coef_k` in figure
//! order), so a correct engine matches it to the bit. Also compiled into the `terrain` bench (`#[path]`), hence the
//! `dead_code` allowance: each user calls only part of it.
#![allow(dead_code)]

use penmodel_terrain::cells::{self, Cell, Mask};
use penmodel_terrain::distance::UNREACHABLE;
use penmodel_terrain::{Document, Figure, FigureKind, Grid, Heightmap, ValidationError, fastmath, profile, validate};

/// The box indices of the 4-neighbours of box index `i` that lie in the box.
fn neighbours(mask: &Mask, i: usize) -> [Option<usize>; 4] {
    let w = mask.width as usize;
    let (x, y) = (i % w, i / w);
    [
        (x > 0).then(|| i - 1),
        (x + 1 < w).then(|| i + 1),
        (y > 0).then(|| i - w),
        (y + 1 < mask.height as usize).then(|| i + w),
    ]
}

/// `dp` by repeated sweeps: (1) the figure's cells hold 0; (2) a region cell without a value next
/// to a cell with one takes that value + 1; (3) repeat until no cell changes.
pub fn from_sources(mask: &Mask, sources: &[Cell]) -> Vec<u32> {
    let bits = mask.bits();
    let mut dist = vec![UNREACHABLE; mask.box_len()];
    for &s in sources {
        if let Some(i) = mask.index(s).filter(|&i| bits[i]) {
            dist[i] = 0;
        }
    }
    let mut sweep = 1u32;
    loop {
        let mut changed = false;
        for i in 0..dist.len() {
            // Only values from earlier sweeps propagate.
            if dist[i] < sweep {
                for j in neighbours(mask, i).into_iter().flatten() {
                    if bits[j] && dist[j] == UNREACHABLE {
                        dist[j] = dist[i] + 1;
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            return dist;
        }
        sweep += 1;
    }
}

/// `df` by repeated sweeps: (1) every region cell holds 0; (2) a cell whose four neighbours all
/// hold the same value v becomes v + 1 (a neighbour outside the region holds no value); (3)
/// repeat until no cell changes.
pub fn edge_layers(mask: &Mask) -> Vec<u32> {
    let bits = mask.bits();
    let mut dist: Vec<u32> = bits.iter().map(|&b| if b { 0 } else { UNREACHABLE }).collect();
    let mut next = dist.clone();
    loop {
        let mut changed = false;
        for i in 0..dist.len() {
            if !bits[i] {
                continue;
            }
            let ns = neighbours(mask, i);
            let Some(Some(first)) = ns.first().copied() else {
                continue;
            };
            let v = dist[first];
            let all_same = ns.iter().all(|n| n.is_some_and(|j| bits[j] && dist[j] == v));
            if all_same && v != UNREACHABLE && dist[i] != v + 1 {
                next[i] = v + 1;
                changed = true;
            }
        }
        if !changed {
            return dist;
        }
        dist.copy_from_slice(&next);
    }
}

/// The terrain of `doc` with every distance map computed by the sweeps above, evaluated cell by
/// cell: the same numbers as [`penmodel_terrain::generate`], at the seed's cost.
pub fn generate(doc: &Document) -> Result<Heightmap, ValidationError> {
    validate::document(doc)?;
    let grid = &doc.grid;
    let mut heights = vec![0.0f32; grid.cells()];
    for r in &doc.regions {
        let mask = cells::closed_mask(grid, &r.boundary);
        region(grid, &mask, &r.figures, 0.0, None, &mut heights);
    }
    Ok(Heightmap::from_heights(grid.cols, grid.rows, grid.cell_size, heights).expect("one height per cell"))
}

/// Paints the cells of the region `mask` with figures `figs`, base height `base` and, for a
/// nested region, the enclosing figure's slope `outer`; nested regions paint their own cells.
fn region(grid: &Grid, mask: &Mask, figs: &[Figure], base: f64, outer: Option<f64>, heights: &mut [f32]) {
    let df = edge_layers(mask);
    // A closed figure's nested region: its curve's cells within the parent's (as the engine).
    let nested: Vec<Option<Mask>> = figs
        .iter()
        .map(|f| (f.kind == FigureKind::Closed).then(|| cells::closed_mask(grid, &f.points).intersect(mask)))
        .collect();
    let dp: Vec<Vec<u32>> = figs
        .iter()
        .zip(&nested)
        .map(|(f, n)| match n {
            Some(n) => from_sources(mask, &n.cells().collect::<Vec<_>>()),
            None => from_sources(mask, &cells::figure_cells(grid, f)),
        })
        .collect();
    let reliefs: Vec<f32> = figs.iter().map(|f| (f.height - base) as f32).collect();
    for (i, cell) in (0..mask.box_len()).map(|i| (i, mask.cell(i))) {
        let owned = mask.bits()[i] && !nested.iter().flatten().any(|n| n.contains(cell));
        if !owned {
            continue;
        }
        // Eq. 3's share of each figure: the mean on figures, inverse distance elsewhere.
        let on = dp.iter().filter(|d| d[i] == 0).count();
        let total: f64 = dp.iter().map(|d| profile::inverse_distance(d[i])).sum();
        let mut h = base as f32;
        for ((f, d), &rel) in figs.iter().zip(&dp).zip(&reliefs) {
            let share = if on > 0 {
                if d[i] == 0 { (1.0 / on as f64) as f32 } else { 0.0 }
            } else if total > 0.0 {
                (profile::inverse_distance(d[i]) / total) as f32
            } else {
                0.0
            };
            // Eq. 1, 2 and 4.
            let w = profile::weight(df[i], d[i]);
            let s = outer.map_or(f.slope, |s0| profile::nested_slope(f.slope, s0, w));
            let coef = fastmath::shape_from_log(w, fastmath::shape_log(w, s), s) as f32 * share;
            h += rel * coef;
        }
        let (c, r) = cell;
        heights[r as usize * grid.cols as usize + c as usize] = h;
    }
    for (f, n) in figs.iter().zip(&nested) {
        if let Some(n) = n {
            region(grid, n, &f.figures, f.height, Some(f.slope), heights);
        }
    }
}
