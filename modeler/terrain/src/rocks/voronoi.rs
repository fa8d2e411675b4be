//! A Voronoi diagram of one radius's seeds: which cell each pixel is in, and a cell's polygon.
//!
//! Pixels: a pixel belongs to the seed nearest its centre; on a tie (seeds sit on pixel centres,
//! so squared distances are whole numbers and ties are common) to the seed with the lowest index.
//! Every pixel lies within the disk radius of some seed when the seeds are saturated
//! ([`super::poisson::saturate`]), so each seed paints the pixels of its disk, keeping the nearer
//! seed: about `3·A` steps for the whole image whatever the radius. Pixels no disk reached (the
//! seed's unsaturated darts leave holes) are found by a search over the seed buckets.
//!
//! Polygons: a cell is the field's rectangle cut by the bisector of its seed and each seed in a
//! square of buckets about it, the square widened until it holds every seed within twice the
//! cell's reach (no farther seed can cut). Only the selected cells need polygons.

/// Seeds sorted into square buckets of side `size`, for neighbour searches.
pub(crate) struct Buckets {
    size: f64,
    cols: i32,
    rows: i32,
    start: Vec<u32>,
    /// Seed indices and positions, bucket by bucket (stored together: a search reads them in
    /// bucket order instead of jumping about the seed list, which halved the polygon stage).
    seeds: Vec<(u32, [f64; 2])>,
}

impl Buckets {
    pub(crate) fn new(points: &[[f64; 2]], width: u32, height: u32, size: f64) -> Buckets {
        let cols = ((f64::from(width) / size).ceil() as i32).max(1);
        let rows = ((f64::from(height) / size).ceil() as i32).max(1);
        let cell = |p: &[f64; 2]| -> usize {
            let c = ((p[0] / size) as i32).clamp(0, cols - 1);
            let r = ((p[1] / size) as i32).clamp(0, rows - 1);
            (r * cols + c) as usize
        };
        let mut start = vec![0u32; (cols * rows) as usize + 1];
        for p in points {
            start[cell(p) + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut seeds = vec![(0u32, [0.0; 2]); points.len()];
        for (i, p) in points.iter().enumerate() {
            let b = cell(p);
            seeds[fill[b] as usize] = (i as u32, *p);
            fill[b] += 1;
        }
        Buckets {
            size,
            cols,
            rows,
            start,
            seeds,
        }
    }

    fn bucket_of(&self, p: [f64; 2]) -> (i32, i32) {
        (
            ((p[0] / self.size) as i32).clamp(0, self.cols - 1),
            ((p[1] / self.size) as i32).clamp(0, self.rows - 1),
        )
    }

    /// Calls `f` with each seed (index and position) in the buckets at Chebyshev distance
    /// exactly `ring` from `(c, r)`.
    fn ring(&self, (c, r): (i32, i32), ring: i32, mut f: impl FnMut(u32, [f64; 2])) {
        let mut visit = |bc: i32, br: i32| {
            if bc >= 0 && br >= 0 && bc < self.cols && br < self.rows {
                let b = (br * self.cols + bc) as usize;
                for &(s, p) in &self.seeds[self.start[b] as usize..self.start[b + 1] as usize] {
                    f(s, p);
                }
            }
        };
        if ring == 0 {
            visit(c, r);
            return;
        }
        for bc in c - ring..=c + ring {
            visit(bc, r - ring);
            visit(bc, r + ring);
        }
        for br in r - ring + 1..r + ring {
            visit(c - ring, br);
            visit(c + ring, br);
        }
    }

    /// Calls `f` with each seed (index and position) in the buckets that meet the square of
    /// half-side `half` about `p`: every seed within `half` of `p`, and some farther. A row of
    /// buckets is one run of `seeds`.
    fn square(&self, p: [f64; 2], half: f64, mut f: impl FnMut(u32, [f64; 2])) {
        let at = |v: f64, n: i32| ((v / self.size).floor().max(0.0) as i32).min(n - 1);
        let (c0, c1) = (at(p[0] - half, self.cols), at(p[0] + half, self.cols));
        let (r0, r1) = (at(p[1] - half, self.rows), at(p[1] + half, self.rows));
        for r in r0..=r1 {
            let row = (r * self.cols) as usize;
            let run = self.start[row + c0 as usize] as usize..self.start[row + c1 as usize + 1] as usize;
            for &(s, q) in &self.seeds[run] {
                f(s, q);
            }
        }
    }

    /// The largest ring index that still meets the grid from `(c, r)`.
    fn last_ring(&self, (c, r): (i32, i32)) -> i32 {
        c.max(self.cols - 1 - c).max(r).max(self.rows - 1 - r)
    }
}

/// Pixel → cell (seed index) for the whole `width × height` image; seeds at pixel indices, in
/// ascending order.
pub fn label(width: u32, height: u32, seeds: &[u32], radius: f64) -> Vec<u32> {
    use rayon::prelude::*;
    let n = width as usize * height as usize;
    let mut best = vec![u32::MAX; n];
    let mut owner = vec![u32::MAX; n];
    let rows_of_disk = super::poisson::disk_rows(radius);
    // Bands of rows painted in parallel, each by the seeds whose disks reach it, in index order
    // as a whole image would be (so a tie still keeps the lower index): the same labels on any
    // number of threads.
    let rows = (height as usize).div_ceil(LABEL_BANDS).max(1);
    let band = rows * width as usize;
    best.par_chunks_mut(band)
        .zip(owner.par_chunks_mut(band))
        .enumerate()
        .for_each(|(b, (best, owner))| {
            let first = (b * rows) as i32;
            paint(width, first, best, owner, seeds, &rows_of_disk);
        });
    if owner.contains(&u32::MAX) && !seeds.is_empty() {
        fill_holes(width, height, seeds, radius, &mut owner);
    }
    owner
}

/// Bands of rows [`label`] paints in parallel.
const LABEL_BANDS: usize = 4;

/// Paints the rows from `first` that `best` and `owner` hold (whole rows of `width`): each pixel
/// takes the seed nearest its centre, of the seeds (pixel indices, ascending) whose disk
/// (`disk`, [`super::poisson::disk_rows`]) reaches it.
fn paint(width: u32, first: i32, best: &mut [u32], owner: &mut [u32], seeds: &[u32], disk: &[(i32, i32)]) {
    let w = width as i32;
    let last = first + (best.len() / width as usize) as i32;
    let reach = disk.iter().map(|o| o.0.abs()).max().unwrap_or(0);
    // Seeds are in pixel order, so those within `reach` rows of the band are one run.
    let lo = seeds.partition_point(|&p| (p / width) as i32 + reach < first);
    let hi = seeds.partition_point(|&p| ((p / width) as i32) - reach < last);
    for (i, &p) in seeds.iter().enumerate().take(hi).skip(lo) {
        let (x, y) = ((p % width) as i32, (p / width) as i32);
        for &(dy, half) in disk {
            let py = y + dy;
            if py < first || py >= last {
                continue;
            }
            let (x0, x1) = ((x - half).max(0), (x + half).min(w - 1));
            let row = ((py - first) * w) as usize;
            let span = row + x0 as usize..=row + x1 as usize;
            let dy2 = dy * dy;
            for (dx, (b, o)) in (x0 - x..).zip(best[span.clone()].iter_mut().zip(&mut owner[span])) {
                let d = (dx * dx + dy2) as u32;
                // Seeds are painted in index order, so a tie keeps the lower index.
                if d < *b {
                    *b = d;
                    *o = i as u32;
                }
            }
        }
    }
}

/// Labels the pixels no disk reached by searching the seed buckets outwards.
fn fill_holes(width: u32, height: u32, seeds: &[u32], radius: f64, owner: &mut [u32]) {
    let points: Vec<[f64; 2]> = seeds.iter().map(|&p| centre(p, width)).collect();
    let buckets = Buckets::new(&points, width, height, radius.max(1.0) * 2.0);
    for (at, o) in owner.iter_mut().enumerate() {
        if *o != u32::MAX {
            continue;
        }
        let q = centre(at as u32, width);
        let home = buckets.bucket_of(q);
        let mut found: Option<(f64, u32)> = None;
        for ring in 0..=buckets.last_ring(home) {
            buckets.ring(home, ring, |s, p| {
                let d = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
                if found.is_none_or(|(bd, bs)| d < bd || (d == bd && s < bs)) {
                    found = Some((d, s));
                }
            });
            // Seeds beyond this ring are at least `ring·size` away.
            if let Some((d, _)) = found
                && d.sqrt() <= f64::from(ring) * buckets.size
            {
                break;
            }
        }
        if let Some((_, s)) = found {
            *o = s;
        }
    }
}

/// The centre of pixel index `p`.
pub(crate) fn centre(p: u32, width: u32) -> [f64; 2] {
    [f64::from(p % width) + 0.5, f64::from(p / width) + 0.5]
}

/// Pixels grouped by cell: `pixels[start[c]..start[c + 1]]` are cell `c`'s, ascending.
pub struct CellPixels {
    /// Offsets into `pixels`, one more than there are cells.
    pub start: Vec<u32>,
    /// Pixel indices.
    pub pixels: Vec<u32>,
}

impl CellPixels {
    /// Groups `labels` (pixel → cell, `u32::MAX` for none) for `cells` cells.
    pub fn of(labels: &[u32], cells: usize) -> CellPixels {
        let mut start = vec![0u32; cells + 1];
        for &l in labels {
            if (l as usize) < cells {
                start[l as usize + 1] += 1;
            }
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut pixels = vec![0u32; start[cells] as usize];
        for (p, &l) in labels.iter().enumerate() {
            if (l as usize) < cells {
                pixels[fill[l as usize] as usize] = p as u32;
                fill[l as usize] += 1;
            }
        }
        CellPixels { start, pixels }
    }

    /// Cell `c`'s pixels.
    pub fn cell(&self, c: usize) -> &[u32] {
        &self.pixels[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

/// Keeps the part of convex polygon `poly` on the seed's side of the bisector of `s` and `q`;
/// returns the new polygon's reach from `s` (the largest squared distance of a vertex), or
/// None when the bisector missed it (`poly` unchanged).
fn clip(poly: &mut Vec<[f64; 2]>, scratch: &mut Vec<[f64; 2]>, s: [f64; 2], q: [f64; 2]) -> Option<f64> {
    let n = [q[0] - s[0], q[1] - s[1]];
    let m = [(s[0] + q[0]) * 0.5, (s[1] + q[1]) * 0.5];
    let side = |p: [f64; 2]| (p[0] - m[0]) * n[0] + (p[1] - m[1]) * n[1];
    if poly.iter().all(|&p| side(p) <= 0.0) {
        return None;
    }
    scratch.clear();
    let len = poly.len();
    let mut sa = side(poly[0]);
    // The reach, kept as the vertices are written (rather than a pass over them after).
    let mut reach2 = 0.0;
    let mut keep = |p: [f64; 2], scratch: &mut Vec<[f64; 2]>| {
        let d2 = (p[0] - s[0]).powi(2) + (p[1] - s[1]).powi(2);
        if d2 > reach2 {
            reach2 = d2;
        }
        scratch.push(p);
    };
    for i in 0..len {
        // The next vertex without `% len` (a division per edge).
        let (a, b) = (poly[i], poly[if i + 1 == len { 0 } else { i + 1 }]);
        let sb = side(b);
        if sa <= 0.0 {
            keep(a, scratch);
        }
        if (sa <= 0.0) != (sb <= 0.0) {
            let t = sa / (sa - sb);
            keep([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t], scratch);
        }
        sa = sb;
    }
    std::mem::swap(poly, scratch);
    Some(reach2)
}

/// The polygon of the cell of `points[cell]` within the `width × height` rectangle, its
/// vertices counter-clockwise in (x, y) with y down (clockwise on screen), without repeats,
/// appended to `dst`.
pub(crate) fn cell_polygon(
    points: &[[f64; 2]],
    buckets: &Buckets,
    width: u32,
    height: u32,
    cell: usize,
    dst: &mut Vec<[f64; 2]>,
) {
    POLYGON.with_borrow_mut(|p| cell_polygon_with(points, buckets, width, height, cell, p, dst))
}

/// Working memory of [`cell_polygon`], one per thread (a field's tens of thousands of cells
/// would otherwise allocate and free it each time).
#[derive(Default)]
struct PolygonScratch {
    poly: Vec<[f64; 2]>,
    scratch: Vec<[f64; 2]>,
    out: Vec<[f64; 2]>,
}

thread_local! {
    static POLYGON: std::cell::RefCell<PolygonScratch> = std::cell::RefCell::default();
}

fn cell_polygon_with(
    points: &[[f64; 2]],
    buckets: &Buckets,
    width: u32,
    height: u32,
    cell: usize,
    work: &mut PolygonScratch,
    dst: &mut Vec<[f64; 2]>,
) {
    let s = points[cell];
    let (w, h) = (f64::from(width), f64::from(height));
    let PolygonScratch { poly, scratch, out } = work;
    poly.clear();
    poly.extend([[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]);
    let reach = |poly: &[[f64; 2]]| {
        poly.iter()
            .map(|p| (p[0] - s[0]).powi(2) + (p[1] - s[1]).powi(2))
            .fold(0.0, f64::max)
    };
    // A seed at distance d cuts the polygon only if the polygon reaches beyond d/2 from `s`, so
    // seeds farther than twice the reach are skipped. Seeds are taken from a square about `s`
    // of half-side `want`, first a guess from the bucket size (about the radius: cells of a
    // saturated diagram reach about r from their seed), widened while the polygon may reach
    // beyond half of what was taken; `done`: every seed within it has cut. Each cuts as it is
    // found, in bucket order (sorting by distance cost more than the cuts it saves).
    let mut reach2 = reach(poly);
    let (mut done, mut want) = (0.0f64, 1.5 * buckets.size + 1.0);
    let far = w.hypot(h);
    loop {
        let (done2, want2) = (done * done, want * want);
        buckets.square(s, want, |q, p| {
            let d2 = (p[0] - s[0]).powi(2) + (p[1] - s[1]).powi(2);
            // The reach changes only when the bisector cut (most seeds taken do not).
            if q as usize != cell
                && d2 > done2
                && d2 <= want2
                && d2 <= 4.0 * reach2
                && let Some(r2) = clip(poly, scratch, s, p)
            {
                reach2 = r2;
            }
        });
        done = want;
        if 4.0 * reach2 <= done * done || done >= far {
            break;
        }
        // At most doubled a round: a cell by a hole (the darts sampler leaves them) reaches the
        // field's corner until its far side is cut, and taking twice that at once searched the
        // whole field (issue 47: 40× slower); the square grows to twice the reach it has.
        want = (2.0 * reach2.sqrt()).clamp(1.5 * done, 2.0 * done).min(far);
    }
    // Clipping through a vertex shared by several bisectors repeats it; drop the repeats.
    out.clear();
    for &mut p in poly {
        let near = |a: &[f64; 2]| (a[0] - p[0]).abs() < 1e-9 && (a[1] - p[1]).abs() < 1e-9;
        if !out.last().is_some_and(near) {
            out.push(p);
        }
    }
    let same = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9;
    while out.len() > 1 && same(out[0], out[out.len() - 1]) {
        out.pop();
    }
    // A vertex on the straight line between its neighbours is not a corner.
    let mut i = 0;
    while out.len() > 3 && i < out.len() {
        let n = out.len();
        // Neighbours without `%` (a division per vertex).
        let (a, b, c) = (
            out[if i == 0 { n - 1 } else { i - 1 }],
            out[i],
            out[if i + 1 == n { 0 } else { i + 1 }],
        );
        let cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if cross.abs() < 1e-9 {
            out.remove(i);
        } else {
            i += 1;
        }
    }
    dst.extend_from_slice(out);
}
