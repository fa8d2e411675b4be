//! 4-neighbour distance maps over a region, in linear time.
//!
//! Both maps are path lengths from a set of sources, moving only through the region's cells, in
//! O(cells of the region's box). They are taken from the separable taxicab distance transform of
//! the box (a column pass and a row pass, a few branch-free steps per cell): the edge layers
//! always (the straight staircase to the nearest outside cell runs inside), the distances from a
//! figure when one sweep shows that every region cell has a region neighbour one closer (no bay of
//! the region lies across a shortest path); otherwise by a breadth-first search, in which every
//! cell is queued once and looks at its four neighbours once. The seed's method (repeat sweeps
//! over the grid until nothing changes) computes the same numbers in O(cells × largest
//! distance); it is kept in the crate's tests (`tests/baseline.rs`) as the reference and
//! benchmark baseline.
//!
//! Maps are laid out over the region mask's bounding box, row-major; cells outside the region
//! hold [`UNREACHABLE`].
//!
//! [`figure_map`] and [`edge_map`] give the maps the engine reads in either metric, as `f32`
//! (infinite where unreachable): these 4-neighbour ones for `taxicab` (integers, exact in `f32`,
//! so seed 000's numbers are unchanged to the bit), [`crate::edt`]'s for `euclidean`.

use crate::cells::{Cell, Mask};
use crate::document::Metric;
use crate::edt;
use crate::pool;
use crate::simd;

/// Distance of a cell no path within the region reaches (and of cells outside the region).
pub const UNREACHABLE: u32 = u32::MAX;

/// A distance as a breadth-first search stores it: `u32` for the public maps, `f32` for the
/// maps the engine reads (whole numbers, exact in `f32` below 2^24, a bound the grid's cell
/// limit keeps), so that the engine's maps need no second pass to convert them.
trait Level: Copy + PartialEq {
    const ZERO: Self;
    const UNSEEN: Self;
    fn next(self) -> Self;
    /// A map of `len` cells, each [`Level::UNSEEN`].
    fn unseen(len: usize) -> Vec<Self>;
    /// A map of `len` cells for a caller that writes each of them.
    fn blank(len: usize) -> Vec<Self>;
    /// Distance `d` (below 2^24).
    fn of(d: u32) -> Self;
}

impl Level for u32 {
    const ZERO: u32 = 0;
    const UNSEEN: u32 = UNREACHABLE;
    fn next(self) -> u32 {
        self + 1
    }
    fn unseen(len: usize) -> Vec<u32> {
        vec![UNREACHABLE; len]
    }
    fn blank(len: usize) -> Vec<u32> {
        vec![UNREACHABLE; len]
    }
    fn of(d: u32) -> u32 {
        d
    }
}

impl Level for f32 {
    const ZERO: f32 = 0.0;
    const UNSEEN: f32 = f32::INFINITY;
    fn next(self) -> f32 {
        self + 1.0
    }
    /// The engine's maps come from (and go back to) [`pool::MAPS`].
    fn unseen(len: usize) -> Vec<f32> {
        pool::MAPS.filled(len, f32::INFINITY)
    }
    fn blank(len: usize) -> Vec<f32> {
        pool::MAPS.unfilled(len, f32::INFINITY)
    }
    fn of(d: u32) -> f32 {
        // Through `i32` (exact: `d` is below 2^24), which converts four or eight at a time; a
        // `u32` has no vector conversion before AVX-512.
        d as i32 as f32
    }
}

/// The breadth-first search from the cells of `front` (each with its box column), which hold 0,
/// one layer at a time: each queued cell carries its column so that finding its neighbours needs
/// no division, and only two layers are held (not every cell of the box), so they stay in the
/// cache.
fn bfs<D: Level>(mask: &Mask, dist: &mut [D], mut front: Vec<(u32, u32)>) {
    let bits = mask.bits();
    let (w, n) = (mask.width as usize, bits.len());
    let mut next = Vec::with_capacity(front.len());
    let mut d = D::ZERO;
    while !front.is_empty() {
        d = d.next();
        for &(i, x) in &front {
            let (i, x) = (i as usize, x as usize);
            let mut visit = |j: usize, xj: usize| {
                if dist[j] == D::UNSEEN && bits[j] {
                    dist[j] = d;
                    next.push((j as u32, xj as u32));
                }
            };
            // The order of `neighbours`: left, right, up, down.
            if x > 0 {
                visit(i - 1, x - 1);
            }
            if x + 1 < w {
                visit(i + 1, x + 1);
            }
            if i >= w {
                visit(i - w, x);
            }
            if i + w < n {
                visit(i + w, x);
            }
        }
        front.clear();
        std::mem::swap(&mut front, &mut next);
    }
}

/// The taxicab distance transform of a `w × h` box, in place: each cell's distance to the nearest
/// cell holding 0 in `g`, over every cell of the box, region or not ([`edt::FAR`] where no cell
/// holds 0). It is separable, like the Euclidean one: the column pass, then per row the least
/// column distance plus the horizontal one, by a sweep each way. A few branch-free operations per
/// cell, against some sixty (and mispredicted branches) for a breadth-first search. Called
/// through [`taxicab_transform`].
#[inline(always)]
fn taxicab_body(w: usize, h: usize, g: &mut [u32]) {
    edt::columns_body(w, h, g);
    let w = w.max(1);
    // A sweep is a chain of dependent steps (each a minimum with the last plus one), which waits
    // on each step's latency; four rows swept together are four chains the core runs side by
    // side.
    let mut quads = g.chunks_exact_mut(4 * w);
    for quad in &mut quads {
        let (ab, cd) = quad.split_at_mut(2 * w);
        let ((a, b), (c, d)) = (ab.split_at_mut(w), cd.split_at_mut(w));
        let step = |run: &mut u32, d: &mut u32| {
            *run = (*d).min(run.saturating_add(1));
            *d = *run;
        };
        let mut run = [edt::FAR; 4];
        for (((a, b), c), d) in a.iter_mut().zip(&mut *b).zip(&mut *c).zip(&mut *d) {
            step(&mut run[0], a);
            step(&mut run[1], b);
            step(&mut run[2], c);
            step(&mut run[3], d);
        }
        let mut run = [edt::FAR; 4];
        for (((a, b), c), d) in a.iter_mut().zip(b).zip(c).zip(d).rev() {
            step(&mut run[0], a);
            step(&mut run[1], b);
            step(&mut run[2], c);
            step(&mut run[3], d);
        }
    }
    for row in quads.into_remainder().chunks_mut(w) {
        let mut run = edt::FAR;
        for d in row.iter_mut() {
            run = (*d).min(run.saturating_add(1));
            *d = run;
        }
        let mut run = edt::FAR;
        for d in row.iter_mut().rev() {
            run = (*d).min(run.saturating_add(1));
            *d = run;
        }
    }
}

/// Whether the taxicab distances `g` over the region's box with a one-cell border (`pw` wide;
/// [`edt::FAR`] on the border and outside the region) are the distances through the region's
/// cells: every region cell but a source (0) has a region 4-neighbour one closer, so a path of its
/// length inside the region leads down to a source, and no path is shorter than the straight
/// taxicab distance. A bay of the region that a shortest path would cross fails it. Called
/// through [`inside_paths`].
#[inline(always)]
fn inside_body(pw: usize, g: &[u32]) -> bool {
    let mut bad = false;
    for y in 1..(g.len() / pw).saturating_sub(1) {
        let i = y * pw;
        let cells = g[i..i + pw].iter().zip(&g[i - 1..]).zip(&g[i + 1..]);
        for (((&d, &l), &r), (&u, &b)) in cells.zip(g[i - pw..].iter().zip(&g[i + pw..])) {
            // FAR + 1 wraps to 0, which no cell but a source (excluded) holds.
            let closest = l.min(r).min(u.min(b)).wrapping_add(1);
            bad |= d != edt::FAR && d != 0 && closest != d;
        }
    }
    !bad
}

simd::copies! {
    /// [`taxicab_body`], in the widest copy the CPU has ([`crate::simd`]).
    fn taxicab_transform(w: usize, h: usize, g: &mut [u32]) = taxicab_body;
}

simd::copies! {
    /// [`inside_body`], in the widest copy the CPU has.
    fn inside_paths(pw: usize, g: &[u32]) -> bool = inside_body;
}

/// [`from_sources`] in either storage: the taxicab transform of the box (with a border) when its
/// distances are those through the region ([`inside_paths`]: no bay of the region in the way),
/// else the breadth-first search.
fn search_from<D: Level>(mask: &Mask, sources: &[Cell]) -> Vec<D> {
    let (w, h, bits) = (mask.width as usize, mask.height as usize, mask.bits());
    let mut inside = sources.iter().filter_map(|&s| mask.index(s).filter(|&i| bits[i]));
    if let Some(first) = inside.next()
        && inside.all(|i| i == first)
        && let Some(out) = from_one(mask, first)
    {
        return out;
    }
    let pw = w + 2;
    let mut g = pool::COLUMNS.filled(pw * (h + 2), edt::FAR);
    let mut any = false;
    for &s in sources {
        if let Some(i) = mask.index(s).filter(|&i| bits[i]) {
            g[(i / w + 1) * pw + i % w + 1] = 0;
            any = true;
        }
    }
    if any {
        // The border's cells only lengthen paths through them (a shortest taxicab path stays in
        // the box of its ends), so the box's distances are those of the box alone.
        taxicab_transform(pw, h + 2, &mut g);
        for (row, inside) in g.chunks_mut(pw).skip(1).zip(bits.chunks(w.max(1))) {
            row[0] = edt::FAR;
            row[w + 1] = edt::FAR;
            for (d, &b) in row[1..].iter_mut().zip(inside) {
                *d = if b { *d } else { edt::FAR };
            }
        }
        g[..pw].fill(edt::FAR);
        let last = g.len() - pw;
        g[last..].fill(edt::FAR);
        if inside_paths(pw, &g) {
            let mut out = D::blank(mask.box_len());
            for (row, line) in g.chunks(pw).skip(1).zip(out.chunks_mut(w.max(1))) {
                for (o, &d) in line.iter_mut().zip(&row[1..]) {
                    *o = if d == edt::FAR { D::UNSEEN } else { D::of(d) };
                }
            }
            pool::COLUMNS.give(g);
            return out;
        }
    }
    pool::COLUMNS.give(g);
    let mut dist = D::unseen(mask.box_len());
    let mut front = Vec::new();
    for &s in sources {
        if let Some(i) = mask.index(s).filter(|&i| bits[i] && dist[i] != D::ZERO) {
            dist[i] = D::ZERO;
            front.push((i as u32, s.0 - mask.c0));
        }
    }
    bfs(mask, &mut dist, front);
    dist
}

/// The taxicab distances from the one source cell at box index `s` (a point figure), when they
/// are those through the region: `|x − sx| + |y − sy|` directly, which is what the transform of
/// [`search_from`] gives for one source, and [`inside_paths`]' test on them by the mask alone —
/// every region cell but the source has a region neighbour one step toward it (left of it, right,
/// above or below, as the source lies). `None` when a bay is in the way.
fn from_one<D: Level>(mask: &Mask, s: usize) -> Option<Vec<D>> {
    let (w, bits) = ((mask.width as usize).max(1), mask.bits());
    let (sx, sy) = (s % w, s / w);
    let ok = bits.chunks(w).enumerate().all(|(y, row)| {
        // The row toward the source (none on its row): its flags, or no cell.
        let toward = match y.cmp(&sy) {
            std::cmp::Ordering::Less => Some(&bits[(y + 1) * w..][..w]),
            std::cmp::Ordering::Equal => None,
            std::cmp::Ordering::Greater => Some(&bits[(y - 1) * w..][..w]),
        };
        one_row_ok(row, toward, sx)
    });
    if !ok {
        return None;
    }
    let mut out = D::blank(mask.box_len());
    for (y, (line, row)) in out.chunks_mut(w).zip(bits.chunks(w)).enumerate() {
        // In `i32` (a box is narrower than 2^31, and distances stay below 2^24), whose
        // differences and absolute values take vector instructions.
        let (dy, sx) = (y.abs_diff(sy) as i32, sx as i32);
        for (x, (o, &b)) in (0..line.len() as i32).zip(line.iter_mut().zip(row)) {
            *o = if b {
                D::of(((x - sx).abs() + dy) as u32)
            } else {
                D::UNSEEN
            };
        }
    }
    Some(out)
}

/// Whether every region cell of `row` has a region neighbour one step toward the source at column
/// `sx`: the cell beside it toward `sx`, or the one in the row `toward` (the row nearer the
/// source's; `None` on the source's row, where the source itself needs none).
fn one_row_ok(row: &[bool], toward: Option<&[bool]>, sx: usize) -> bool {
    // The source's column lies in the box: `sx < row.len()`.
    let w = row.len();
    let (left, right) = (&row[..sx], &row[sx + 1..]);
    // Left of the source the neighbour toward it is on the right, right of it on the left.
    let (beside_left, beside_right) = (&row[1..=sx], &row[sx..w - 1]);
    let mut bad = false;
    match toward {
        Some(t) => {
            for ((&c, &n), &v) in left.iter().zip(beside_left).zip(t) {
                bad |= c & !n & !v;
            }
            for ((&c, &n), &v) in right.iter().zip(beside_right).zip(&t[sx + 1..]) {
                bad |= c & !n & !v;
            }
            bad |= row[sx] & !t[sx];
        }
        None => {
            for (&c, &n) in left.iter().zip(beside_left).chain(right.iter().zip(beside_right)) {
                bad |= c & !n;
            }
        }
    }
    !bad
}

/// [`edge_layers`] in either storage: the taxicab distance to the nearest cell outside the region
/// (or the box, hence the grid) less one, by the taxicab transform of the box with a border of
/// outside cells. It is the layer count through the region's cells for any region: the cells on
/// a shortest straight staircase to the nearest outside cell are all closer than it, hence inside.
fn search_edge<D: Level>(mask: &Mask) -> Vec<D> {
    let (w, h) = (mask.width as usize, mask.height as usize);
    let bits = mask.bits();
    let pw = w + 2;
    let mut g = pool::COLUMNS.filled(pw * (h + 2), 0);
    for (row, inside) in g.chunks_mut(pw).skip(1).zip(bits.chunks(w.max(1))) {
        for (d, &b) in row[1..].iter_mut().zip(inside) {
            *d = if b { edt::FAR } else { 0 };
        }
    }
    taxicab_transform(pw, h + 2, &mut g);
    let mut out = D::blank(mask.box_len());
    let rows = g.chunks(pw).skip(1).zip(bits.chunks(w.max(1)));
    for ((row, inside), line) in rows.zip(out.chunks_mut(w.max(1))) {
        for ((o, &d), &b) in line.iter_mut().zip(&row[1..]).zip(inside) {
            *o = if b { D::of(d - 1) } else { D::UNSEEN };
        }
    }
    pool::COLUMNS.give(g);
    out
}

/// `dp`: the distance of every region cell from the nearest of `sources`, moving through region
/// cells only. Sources outside the region are ignored.
pub fn from_sources(mask: &Mask, sources: &[Cell]) -> Vec<u32> {
    search_from(mask, sources)
}

/// `df`: the layer count from the region's edge. Region cells with a 4-neighbour outside the
/// region (or the grid) are 0, the next layer 1, and so on.
pub fn edge_layers(mask: &Mask) -> Vec<u32> {
    search_edge(mask)
}

/// `dp` in `metric`: [`from_sources`] or [`edt::from_sources`].
pub fn figure_map(metric: Metric, mask: &Mask, sources: &[Cell]) -> Vec<f32> {
    match metric {
        Metric::Taxicab => search_from(mask, sources),
        Metric::Euclidean => edt::from_sources(mask, sources),
    }
}

/// `df` in `metric`: [`edge_layers`] or [`edt::to_edge`].
pub fn edge_map(metric: Metric, mask: &Mask) -> Vec<f32> {
    match metric {
        Metric::Taxicab => search_edge(mask),
        Metric::Euclidean => edt::to_edge(mask),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distances through the region by relaxation until nothing changes (no transform, no
    /// queue), for comparison.
    fn relaxed(mask: &Mask, sources: &[Cell]) -> Vec<u32> {
        let (w, h, bits) = (mask.width as usize, mask.height as usize, mask.bits());
        let mut d = vec![UNREACHABLE; w * h];
        for &s in sources {
            d[mask.index(s).unwrap()] = 0;
        }
        let mut changed = true;
        while changed {
            changed = false;
            for i in (0..w * h).filter(|&i| bits[i]) {
                let (x, y) = (i % w, i / w);
                let near = [
                    (x > 0).then(|| i - 1),
                    (x + 1 < w).then(|| i + 1),
                    (y > 0).then(|| i - w),
                    (y + 1 < h).then(|| i + w),
                ];
                let best = near.into_iter().flatten().filter(|&j| bits[j]).map(|j| d[j]).min();
                if let Some(b) = best.filter(|&b| b != UNREACHABLE && b + 1 < d[i]) {
                    d[i] = b + 1;
                    changed = true;
                }
            }
        }
        d
    }

    #[test]
    fn a_bay_across_the_straight_path_leaves_the_distances_through_the_region() {
        // A U: two arms 3 wide joined at the bottom, a bay 4 wide between them.
        let cells: Vec<Cell> = (0..10u32)
            .flat_map(|x| (0..12u32).map(move |y| (x + 5, y + 7)))
            .filter(|&(x, y)| !((8..12).contains(&x) && y < 16))
            .collect();
        let mask = Mask::from_cells(&cells);
        let tip = (5, 7);
        let d = from_sources(&mask, &[tip]);
        assert_eq!(d, relaxed(&mask, &[tip]));
        // The other arm's tip, 9 columns across, is reached round the bay: 9 rows down, 9 columns
        // across, 9 rows up.
        let other = mask.index((14, 7)).unwrap();
        assert_eq!(d[other], 27);
        // Without the bay (a full rectangle) the straight distances.
        let full: Vec<Cell> = (0..10u32)
            .flat_map(|x| (0..12u32).map(move |y| (x + 5, y + 7)))
            .collect();
        let rect = Mask::from_cells(&full);
        assert_eq!(from_sources(&rect, &[tip]), relaxed(&rect, &[tip]));
        assert_eq!(from_sources(&rect, &[tip])[rect.index((14, 7)).unwrap()], 9);
    }

    /// One source cell (the direct distances and the mask's test, [`from_one`]) gives the
    /// distances through the region, on regions with and without bays, from sources anywhere in
    /// them — the same numbers as the transform or the search take for several sources.
    #[test]
    fn one_source_gives_the_distances_through_the_region() {
        let (w, h) = (23u32, 17u32);
        for seed in 0..40u64 {
            // A blob of cells: a disc with notches cut by a hash, and a wall with a gap on some.
            let cells: Vec<Cell> = (0..w * h)
                .map(|i| (i % w, i / w))
                .filter(|&(x, y)| {
                    let (dx, dy) = (f64::from(x) - 11.0, f64::from(y) - 8.0);
                    let hash = (u64::from(x * 31 + y * 7) + seed).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 58;
                    let wall = seed % 3 == 0 && x == 12 && y > 3;
                    dx * dx / 121.0 + dy * dy / 64.0 <= 1.0 && hash > 3 && !wall
                })
                .map(|(x, y)| (x + 3, y + 5))
                .collect();
            let mask = Mask::from_cells(&cells);
            for k in [0, cells.len() / 3, cells.len() / 2, cells.len() - 1] {
                let source = cells[(k + seed as usize) % cells.len()];
                let want = relaxed(&mask, &[source]);
                assert_eq!(from_sources(&mask, &[source]), want, "seed {seed} source {source:?}");
                // The same source twice is still one cell; an outside one is ignored.
                assert_eq!(from_sources(&mask, &[source, source, (0, 0)]), want);
                let engine: Vec<u32> = search_from::<f32>(&mask, &[source])
                    .iter()
                    .map(|&d| if d.is_finite() { d as u32 } else { UNREACHABLE })
                    .collect();
                assert_eq!(engine, want);
            }
        }
    }
}
