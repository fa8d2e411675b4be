//! The terrain engine's caches per region and per figure, and how an edit updates them (issue 18).
//!
//! Per region, over its bounding box: the edge distances `df`, the owned cells (the region's
//! minus its nested regions'), and eq. 3's normaliser per cell, `norm`: `−n` on a cell where n
//! figures stand, else `Σ_j 1/dp_j` in figure order (0 where no figure reaches). Per figure:
//! its distances `dp`, its shape term `shape = eq. 2(w, s)` (eq. 1's `w`, eq. 4's slope for a
//! nested figure) evaluated as `fastmath::shape_from_log` and rounded to `f32`, the logarithm that
//! takes (`fastmath::shape_log`, kept for a top-level figure so that a slope change of the same
//! sign is one `exp` per cell), and its coefficient `coef = shape × share` (an `f32` product),
//! where `share` is eq. 3's weight read from `norm` and `dp` ([`share`]).
//!
//! Every path computes a cell's numbers with the same functions, and a cell's height always as
//! `base + Σ_k relief_k·coef_k` in `f32`, figures in order ([`RegionNode::paint_own`]), so an
//! updated terrain equals a full regeneration to the bit. Eq. 2's logarithm and exponential are
//! [`crate::fastmath`]'s polynomials, not `libm`'s, so that a stretch of cells takes them in
//! vector instructions (since 24 Nov: heights no longer bit-identical to earlier builds; over
//! `engine_digest`'s terrains at most 2·10⁻¹⁰ of the relief from the `libm` ones):
//!
//! - **a moved figure** (a vertex, the whole figure; not a closed one): its new `dp` in full
//!   (one breadth-first search or distance transform over the box, linear in its cells),
//!   compared with the old one; only the cells where it changed get a new `norm`, the figure's
//!   shape and every figure's coefficient (the other figures' shapes are kept: their `w` and
//!   slope did not change), and only those cells are painted.
//! - **a slope**: the figure's shape and coefficient on the owned cells (`norm` and, for a slope
//!   of the same sign, the logarithms are kept), then the region painted; a closed figure's
//!   nested region gets all its shapes again (eq. 4 reads the enclosing slope).
//! - **a height** (a pull): the region painted (K multiply-adds per cell), and a closed figure's
//!   nested region, whose base it is.
//! - **a figure added, removed or replaced**: the region's `norm` and coefficients, and only the
//!   new figure's shape; when a closed figure comes, goes or changes its outline, the owned cells
//!   change, and every shape is computed again.
//!
//! The per-cell work runs on all cores (rayon), in bands of rows; the figures' distance maps of
//! a region are computed in parallel. The maps come
//! from and go back to [`crate::pool::MAPS`], so that a new engine does not fault in fresh pages. Within a row the cells are taken a stretch at a time (an
//! owned run, or its dirty cells), each step over the whole stretch for one figure, in figure
//! order: every cell still sees the arithmetic of a cell-by-cell evaluation, and the loops over
//! the stretch (the sums of a paint, the shares) compile to vector instructions — in the widest
//! copy the CPU has ([`crate::simd`]: baseline, AVX2 or AVX-512, the same bits from each).

use rayon::prelude::*;

use crate::cells::{self, Cell, Mask};
use crate::change::ListChange;
use crate::detail;
use crate::distance;
use crate::document::{Figure, FigureKind, Grid, Metric, Point};
use crate::fastmath;
use crate::heightmap::Heightmap;
use crate::pool::{MAPS, Pool};
use crate::profile;
use crate::rect::Rect;
use crate::simd;

/// The regions' normalisers of the regions dropped, for the next ones ([`crate::pool`]): 16 MB,
/// a 1024² region's.
static NORMS: Pool<f64> = Pool::new(2 << 20);

/// Box rows per band of parallel work: small enough that two cores share the work evenly.
const BAND_ROWS: usize = 8;

/// A run of cells in one row of a region's box: `start..end` in box columns.
#[derive(Debug, Clone, Copy)]
struct Run {
    row: u32,
    start: u32,
    end: u32,
}

/// Per-figure caches, over the owning region's box. `shape`, `coef` and `log` hold numbers only on
/// the owned cells (elsewhere whatever their buffers held before, never read).
pub(super) struct FigureNode {
    dp: Vec<f32>,
    /// Eq. 2's shape term on the owned cells, rounded to `f32`.
    shape: Vec<f32>,
    /// `shape × share` on the owned cells.
    coef: Vec<f32>,
    /// Eq. 2's logarithm ([`profile::shape_log`]) on the owned cells, kept for a top-level
    /// figure so that a slope change is one `exp` per cell; valid for slopes of the sign
    /// `log_sign` (0: not valid).
    log: Vec<f32>,
    log_sign: i8,
    /// The nested region of a closed figure.
    pub(super) child: Option<Box<RegionNode>>,
}

/// Per-region caches, over the region's box; `norm` holds numbers only on the owned cells.
pub(super) struct RegionNode {
    pub(super) mask: Mask,
    /// The distances' metric, the region's (its nested regions inherit it).
    pub(super) metric: Metric,
    df: Vec<f32>,
    /// The cells this region decides: its cells minus its nested regions', by rows.
    owned: Vec<Run>,
    /// Where each box row's runs start in `owned` (one more entry than rows).
    row_runs: Vec<usize>,
    /// Eq. 3's normaliser per cell (see the module's documentation).
    norm: Vec<f64>,
    pub(super) figures: Vec<FigureNode>,
}

/// A figure list as its region sees it: the figures (after the change), the region's base
/// height and, for a nested list, the enclosing figure's slope.
#[derive(Clone, Copy)]
pub(super) struct List<'a> {
    pub(super) figs: &'a [Figure],
    pub(super) base: f64,
    pub(super) outer: Option<f64>,
}

/// Which figures' shape terms a blend recomputes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shapes {
    All,
    One(usize),
    None,
}

impl Shapes {
    fn has(self, k: usize) -> bool {
        match self {
            Shapes::All => true,
            Shapes::One(j) => j == k,
            Shapes::None => false,
        }
    }
}

/// Eq. 3's weight of a figure at distance `dp` on a cell with normaliser `norm`: `1/n` on each
/// of the n figures a cell stands on, `(1/dp)/Σ(1/dp_j)` elsewhere, 0 where no figure reaches.
#[inline(always)]
fn share(norm: f64, dp: f32) -> f32 {
    share_of(norm, dp, || profile::inverse_distance_real(f64::from(dp)))
}

/// [`share`] with the figure's inverse distance `inv` (computed only when needed). One division
/// whichever the case: a loop over cells compiles the cases to selects, which take both sides,
/// and the divisions are the blend's bottleneck (`x/1` and `0/x` are the `x` and `0` of the
/// cases without one).
#[inline(always)]
fn share_of(norm: f64, dp: f32, inv: impl FnOnce() -> f64) -> f32 {
    let (num, den) = if norm < 0.0 {
        (if dp == 0.0 { 1.0 } else { 0.0 }, -norm)
    } else if norm > 0.0 {
        (inv(), norm)
    } else {
        (0.0, 1.0)
    };
    (num / den) as f32
}

/// The sign of a slope, as the kept logarithms are valid for it.
fn sign(s: f64) -> i8 {
    if s > 0.0 {
        1
    } else if s < 0.0 {
        -1
    } else {
        0
    }
}

/// Eq. 1, 2 and 4: a figure of slope `s1` (nested in a figure of slope `outer`) at a cell; its
/// shape term and eq. 2's logarithm. With `log`, the logarithm kept for this `w` and the sign of
/// `s1` (a top-level figure), instead of computing it again.
fn shape(df: f32, dp: f32, s1: f64, outer: Option<f64>, log: Option<f32>) -> (f32, f32) {
    let w = profile::weight_real(f64::from(df), f64::from(dp));
    let s = outer.map_or(s1, |s0| profile::nested_slope(s1, s0, w));
    let l = log.unwrap_or_else(|| fastmath::shape_log(w, s));
    (fastmath::shape_from_log(w, l, s) as f32, l)
}

/// Cells per step of [`shapes`]: its working rows live on the stack.
const STEP: usize = 64;

/// [`shape`] for a stretch of cells (their `df` and `dp`): each cell's shape term into `shape`,
/// and its logarithm into `log` if given. A step of cells at a time: every cell's weight,
/// logarithm and power, then every cell's exponential, then its shape term. The numbers are
/// [`shape`]'s (the same operations in the same order), but each loop is free of branches and
/// calls, and compiles to vector instructions.
#[inline(always)]
fn shapes(df: &[f32], dp: &[f32], (s1, outer): (f64, Option<f64>), shape: &mut [f32], mut log: Option<&mut [f32]>) {
    // A few cells (a moved figure's changed cells come in short stretches) do not pay for
    // setting up the working rows.
    if df.len() < STEP / 4 {
        for (i, ((o, &f), &d)) in shape.iter_mut().zip(df).zip(dp).enumerate() {
            let l;
            (*o, l) = self::shape(f, d, s1, outer, None);
            if let Some(log) = log.as_deref_mut() {
                log[i] = l;
            }
        }
        return;
    }
    if s1 == 0.0 && outer.is_none() {
        // Eq. 2 at slope 0 is `w` itself: what the steps below give (`shape_log` takes
        // `ln 1 = 0`, and `shape_from_exp` returns `w`), without a logarithm or an exponential.
        for ((o, &f), &d) in shape.iter_mut().zip(df).zip(dp) {
            *o = profile::weight_real(f64::from(f), f64::from(d)) as f32;
        }
        if let Some(log) = log {
            log[..df.len()].fill(0.0);
        }
        return;
    }
    // The working rows, set up once for all the steps.
    let (mut w, mut s, mut l, mut y) = ([0.0; STEP], [0.0; STEP], [0.0f32; STEP], [0.0; STEP]);
    for a in (0..df.len()).step_by(STEP) {
        let e = (a + STEP).min(df.len());
        let cells = w.iter_mut().zip(&mut s).zip(&mut l).zip(&mut y);
        for ((((w, s), l), y), (&f, &d)) in cells.zip(df[a..e].iter().zip(&dp[a..e])) {
            *w = profile::weight_real(f64::from(f), f64::from(d));
            *s = outer.map_or(s1, |s0| profile::nested_slope(s1, s0, *w));
            *l = fastmath::shape_log(*w, *s);
            *y = fastmath::power(*l, *s);
        }
        // The exponentials alone in their loop: it compiles to vector instructions.
        for y in &mut y[..e - a] {
            *y = fastmath::exp(*y);
        }
        for (((o, &w), &s), &e) in shape[a..e].iter_mut().zip(&w).zip(&s).zip(&y) {
            *o = fastmath::shape_from_exp(w, e, s) as f32;
        }
        if let Some(log) = log.as_deref_mut() {
            log[a..e].copy_from_slice(&l[..e - a]);
        }
    }
}

/// The shape terms of a top-level figure of slope `s ≠ 0` from its kept logarithms `log`:
/// [`fastmath::shape_from_log`] a step of cells at a time, the exponentials in a loop of their own
/// (vector instructions).
#[inline(always)]
fn shapes_from_logs(log: &[f32], s: f64, shape: &mut [f32]) {
    for (log, shape) in log.chunks(STEP).zip(shape.chunks_mut(STEP)) {
        let mut y = [0.0; STEP];
        for (y, &l) in y.iter_mut().zip(log) {
            *y = fastmath::power(l, s);
        }
        for y in &mut y {
            *y = fastmath::exp(*y);
        }
        for (o, &e) in shape.iter_mut().zip(&y) {
            *o = fastmath::shape_from_exp(0.0, e, s) as f32;
        }
    }
}

/// The cells of the nested region a closed curve bounds. Validation keeps a closed figure strictly
/// inside its region, which puts its cells inside the region's; the intersection only guards
/// against a rounding tie at a cell border, so that no region paints outside its parent.
fn nested_mask(grid: &Grid, points: &[Point], parent: &Mask) -> Mask {
    cells::closed_mask(grid, points).intersect(parent)
}

/// The cells a figure stands on; a closed figure's are its nested region's.
fn sources(grid: &Grid, f: &Figure, child: Option<&RegionNode>) -> Vec<Cell> {
    match child {
        Some(c) if f.kind == FigureKind::Closed => c.mask.cells().collect(),
        _ => cells::figure_cells(grid, f),
    }
}

/// The box of the cells where `dirty` holds (`width` wide), on the grid; empty when none.
fn dirty_rect(mask: &Mask, dirty: &[bool]) -> Rect {
    let w = mask.width as usize;
    let bounds = dirty
        .par_chunks(w.max(1))
        .enumerate()
        .filter_map(|(r, row)| {
            let first = row.iter().position(|&d| d)?;
            let last = row.iter().rposition(|&d| d)?;
            Some((r, r, first, last))
        })
        .reduce_with(|a, b| (a.0.min(b.0), a.1.max(b.1), a.2.min(b.2), a.3.max(b.3)));
    match bounds {
        Some((r0, r1, c0, c1)) => Rect {
            c0: mask.c0 + c0 as u32,
            r0: mask.r0 + r0 as u32,
            width: (c1 - c0 + 1) as u32,
            height: (r1 - r0 + 1) as u32,
        },
        None => Rect::EMPTY,
    }
}

/// The stretches `start..end` of consecutive `true` in `flags`.
fn stretches(flags: &[bool]) -> impl Iterator<Item = (usize, usize)> + '_ {
    let mut x = 0;
    std::iter::from_fn(move || {
        x += flags.get(x..)?.iter().position(|&f| f)?;
        let start = x;
        x += flags[x..].iter().position(|&f| !f).unwrap_or(flags.len() - x);
        Some((start, x))
    })
}

/// What a blend computes, the same for every band.
#[derive(Clone, Copy)]
struct Blend<'a> {
    slopes: &'a [f64],
    /// Per figure, whether its logarithms are kept.
    keep: &'a [bool],
    outer: Option<f64>,
    shapes: Shapes,
}

/// One band's slices of the region's and its figures' maps.
struct Band<'b, 'm> {
    norm: &'b mut [f64],
    df: &'b [f32],
    dps: &'b [&'m [f32]],
    /// Per figure its shape, coefficient and logarithm.
    maps: &'b mut [(&'m mut [f32], &'m mut [f32], &'m mut [f32])],
}

/// Per-stretch working rows of a band: each figure's inverse distances, the cells' sums of them
/// and counts of figures stood on.
struct Scratch {
    inv: Vec<f64>,
    sum: Vec<f64>,
    on: Vec<u32>,
    width: usize,
}

impl Scratch {
    fn new(figures: usize, width: usize) -> Scratch {
        Scratch {
            inv: vec![0.0; figures * width],
            sum: vec![0.0; width],
            on: vec![0; width],
            width,
        }
    }
}

impl Band<'_, '_> {
    /// Eq. 3's normaliser, the shapes `how` names and every figure's coefficient on the band's
    /// cells `cells` (a stretch of one row): each step over the stretch for one figure at a time,
    /// in figure order, so that each cell sees the arithmetic of a cell-by-cell evaluation.
    /// Called through [`blend_stretch`].
    #[inline(always)]
    fn blend(self, cells: std::ops::Range<usize>, scratch: &mut Scratch, how: Blend) {
        let Band { norm, df, dps, maps } = self;
        let (a, len) = (cells.start, cells.len());
        let width = scratch.width;
        let (sum, on) = (&mut scratch.sum[..len], &mut scratch.on[..len]);
        sum.fill(0.0);
        on.fill(0);
        for (dp, inv) in dps.iter().zip(scratch.inv.chunks_mut(width)) {
            for (((v, s), n), &d) in inv[..len]
                .iter_mut()
                .zip(&mut *sum)
                .zip(&mut *on)
                .zip(&dp[cells.clone()])
            {
                *v = profile::inverse_distance_real(f64::from(d));
                *s += *v;
                *n += u32::from(d == 0.0);
            }
        }
        let norm = &mut norm[cells.clone()];
        for ((out, &s), &n) in norm.iter_mut().zip(&*sum).zip(&*on) {
            *out = if n > 0 { -f64::from(n) } else { s };
        }
        let df = &df[cells.clone()];
        for (k, ((dp, (shape_k, coef_k, log_k)), inv)) in dps
            .iter()
            .zip(maps.iter_mut())
            .zip(scratch.inv.chunks(width))
            .enumerate()
        {
            let dp = &dp[cells.clone()];
            let (shape_k, coef_k) = (&mut shape_k[cells.clone()], &mut coef_k[cells.clone()]);
            if how.shapes.has(k) {
                let log = how.keep[k].then(|| &mut log_k[a..a + len]);
                shapes(df, dp, (how.slopes[k], how.outer), shape_k, log);
            }
            for ((((c, &sh), &n), &d), &v) in coef_k.iter_mut().zip(&*shape_k).zip(&*norm).zip(dp).zip(&inv[..len]) {
                *c = sh * share_of(n, d, || v);
            }
        }
    }
}

simd::copies! {
    /// [`Band::blend`], in the widest copy the CPU has ([`crate::simd`]).
    fn blend_stretch(band: Band<'_, '_>, cells: std::ops::Range<usize>, scratch: &mut Scratch, how: Blend<'_>) = Band::blend;
}

/// Paints a stretch of cells `out`: `base + Σ relief_k·coef_k` in `f32`, figures in order (each
/// step over the stretch for one figure). Called through [`paint_stretch`].
#[inline(always)]
fn paint_body(out: &mut [f32], base: f32, coefs: &[&[f32]], reliefs: &[f32], a: usize) {
    out.fill(base);
    let e = a + out.len();
    for (coef, &rel) in coefs.iter().zip(reliefs) {
        for (d, &c) in out.iter_mut().zip(&coef[a..e]) {
            *d += rel * c;
        }
    }
}

simd::copies! {
    /// [`paint_body`], in the widest copy the CPU has.
    fn paint_stretch(out: &mut [f32], base: f32, coefs: &[&[f32]], reliefs: &[f32], a: usize) = paint_body;
}

/// A slope's work on one owned run (box columns `xs` of a row, its cells from `i0` on): the shape
/// terms, from the kept logarithms (`reuse`) or computed (keeping the logarithms in `log_row` when
/// `keep`), and the coefficients. Called through [`reshape_run`].
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn reshape_body(
    (df, dp, norm): (&[f32], &[f32], &[f64]),
    xs: std::ops::Range<usize>,
    (shape_row, coef_row, log_row): (&mut [f32], &mut [f32], &mut [f32]),
    (s1, outer): (f64, Option<f64>),
    reuse: bool,
    keep: bool,
) {
    let len = xs.len();
    let shape_run = &mut shape_row[xs.clone()];
    if reuse && s1 != 0.0 {
        // The kept logarithm and the slope make the shape: eq. 1's `w`, which
        // `shape_from_log` reads only at slope 0, is not needed.
        shapes_from_logs(&log_row[xs.clone()], s1, shape_run);
    } else {
        let log = keep.then(|| &mut log_row[xs.clone()]);
        shapes(&df[..len], &dp[..len], (s1, outer), shape_run, log);
    }
    for (((c, &sh), &d), &n) in coef_row[xs].iter_mut().zip(&*shape_run).zip(dp).zip(norm) {
        *c = sh * share(n, d);
    }
}

simd::copies! {
    /// [`reshape_body`], in the widest copy the CPU has.
    fn reshape_run(
        maps: (&[f32], &[f32], &[f64]),
        xs: std::ops::Range<usize>,
        rows: (&mut [f32], &mut [f32], &mut [f32]),
        slope: (f64, Option<f64>),
        reuse: bool,
        keep: bool,
    ) = reshape_body;
}

impl FigureNode {
    pub(super) fn build(grid: &Grid, region: &Mask, metric: Metric, f: &Figure) -> FigureNode {
        let child = (f.kind == FigureKind::Closed).then(|| {
            let mask = nested_mask(grid, &f.points, region);
            Box::new(RegionNode::build(grid, mask, metric, &f.figures, Some(f.slope)))
        });
        let n = region.box_len();
        FigureNode {
            dp: distance::figure_map(metric, region, &sources(grid, f, child.as_deref())),
            shape: MAPS.unfilled(n, 0.0),
            coef: MAPS.unfilled(n, 0.0),
            log: MAPS.unfilled(n, 0.0),
            log_sign: 0,
            child,
        }
    }
}

/// The maps go back to their pools, for the next regions and figures built.
impl Drop for FigureNode {
    fn drop(&mut self) {
        for v in [&mut self.dp, &mut self.shape, &mut self.coef, &mut self.log] {
            MAPS.give(std::mem::take(v));
        }
    }
}

impl Drop for RegionNode {
    fn drop(&mut self) {
        MAPS.give(std::mem::take(&mut self.df));
        NORMS.give(std::mem::take(&mut self.norm));
    }
}

/// `v` replaced by `new` (its old buffer back to the pool).
fn replace_map(v: &mut Vec<f32>, new: Vec<f32>) {
    MAPS.give(std::mem::replace(v, new));
}

impl RegionNode {
    pub(super) fn build(grid: &Grid, mask: Mask, metric: Metric, figs: &[Figure], outer: Option<f64>) -> RegionNode {
        // The edge distances and each figure's (with its nested region) on all cores.
        let (df, figures) = rayon::join(
            || distance::edge_map(metric, &mask),
            || {
                figs.par_iter()
                    .map(|f| FigureNode::build(grid, &mask, metric, f))
                    .collect()
            },
        );
        let n = mask.box_len();
        let mut node = RegionNode {
            mask,
            metric,
            df,
            owned: Vec::new(),
            row_runs: Vec::new(),
            norm: NORMS.unfilled(n, 0.0),
            figures,
        };
        node.owned_runs();
        node.blend(figs, outer, Shapes::All, None);
        node
    }

    /// New cells for the region; its figures' nested regions are kept.
    pub(super) fn reshape(&mut self, grid: &Grid, mask: Mask, figs: &[Figure], outer: Option<f64>) {
        self.mask = mask;
        let n = self.mask.box_len();
        let (mask, metric) = (&self.mask, self.metric);
        let (df, ()) = rayon::join(
            || distance::edge_map(metric, mask),
            || {
                figs.par_iter().zip(&mut self.figures).for_each(|(f, node)| {
                    let dp = distance::figure_map(metric, mask, &sources(grid, f, node.child.as_deref()));
                    replace_map(&mut node.dp, dp);
                    for v in [&mut node.shape, &mut node.coef, &mut node.log] {
                        replace_map(v, MAPS.unfilled(n, 0.0));
                    }
                    node.log_sign = 0;
                })
            },
        );
        replace_map(&mut self.df, df);
        NORMS.give(std::mem::replace(&mut self.norm, NORMS.unfilled(n, 0.0)));
        self.owned_runs();
        self.blend(figs, outer, Shapes::All, None);
    }

    /// Brings the caches up to date after `change` in the region's figure list `figs` (the list
    /// after it; `outer` the enclosing figure's slope for a nested list) and paints what changed.
    /// `None` when the change does not fit the caches.
    pub(super) fn change(
        &mut self,
        grid: &Grid,
        change: ListChange,
        list: List,
        map: &mut Heightmap,
        gate: Option<&mut [f32]>,
    ) -> Option<Rect> {
        let List { figs, base, outer } = list;
        let fits = match change {
            ListChange::Added(k) => k < figs.len() && k <= self.figures.len(),
            ListChange::Removed(k) => k < self.figures.len(),
            ListChange::Replaced(k) | ListChange::Outline(k) => k < figs.len() && k < self.figures.len(),
        };
        if !fits {
            return None;
        }
        let closed = |f: &Figure| f.kind == FigureKind::Closed;
        // With a nested region coming, going or changing its cells, the owned cells change and
        // every shape is computed again; otherwise only the changed figure's.
        let shapes = match change {
            ListChange::Added(k) => {
                let node = FigureNode::build(grid, &self.mask, self.metric, &figs[k]);
                self.figures.insert(k, node);
                if closed(&figs[k]) { Shapes::All } else { Shapes::One(k) }
            }
            ListChange::Removed(k) => {
                let node = self.figures.remove(k);
                if node.child.is_some() {
                    Shapes::All
                } else {
                    Shapes::None
                }
            }
            ListChange::Replaced(k) => {
                let node = FigureNode::build(grid, &self.mask, self.metric, &figs[k]);
                let old = std::mem::replace(&mut self.figures[k], node);
                if old.child.is_some() || closed(&figs[k]) {
                    Shapes::All
                } else {
                    Shapes::One(k)
                }
            }
            ListChange::Outline(k) if !closed(&figs[k]) && self.figures[k].child.is_none() => {
                return Some(self.move_figure(grid, k, list, map, gate));
            }
            ListChange::Outline(k) => {
                self.outline(grid, k, figs);
                Shapes::All
            }
        };
        if self.figures.len() != figs.len() {
            return None;
        }
        if shapes == Shapes::All {
            self.owned_runs();
        }
        self.blend(figs, outer, shapes, None);
        self.paint_all(figs, base, map);
        if let Some(g) = gate {
            self.paint_gates(g, grid.cols);
        }
        Some(Rect::of(&self.mask))
    }

    /// Figure k (not closed) moved: its new distances, and the cells where they changed blended
    /// and painted again. Returns those cells' box.
    fn move_figure(
        &mut self,
        grid: &Grid,
        k: usize,
        list: List,
        map: &mut Heightmap,
        gate: Option<&mut [f32]>,
    ) -> Rect {
        let List { figs, base, outer } = list;
        let dp = distance::figure_map(self.metric, &self.mask, &cells::figure_cells(grid, &figs[k]));
        let old = std::mem::replace(&mut self.figures[k].dp, dp);
        let dirty: Vec<bool> = old
            .par_iter()
            .zip(&self.figures[k].dp)
            .map(|(a, b)| a.to_bits() != b.to_bits())
            .collect();
        MAPS.give(old);
        self.blend(figs, outer, Shapes::One(k), Some(&dirty));
        self.paint_own(figs, base, map, Some(&dirty));
        if let Some(g) = gate {
            self.paint_gates(g, grid.cols);
        }
        dirty_rect(&self.mask, &dirty)
    }

    /// Figure k's points changed (its nested figures did not).
    fn outline(&mut self, grid: &Grid, k: usize, figs: &[Figure]) {
        let f = &figs[k];
        if let Some(child) = self.figures[k].child.as_deref_mut() {
            child.reshape(
                grid,
                nested_mask(grid, &f.points, &self.mask),
                &f.figures,
                Some(f.slope),
            );
        }
        let node = &mut self.figures[k];
        let dp = distance::figure_map(self.metric, &self.mask, &sources(grid, f, node.child.as_deref()));
        replace_map(&mut node.dp, dp);
    }

    /// Figure k's height changed (a pull): the region painted again, and a closed figure's
    /// nested region, whose base it is. Returns the cells painted.
    pub(super) fn pull(&self, k: usize, figs: &[Figure], base: f64, map: &mut Heightmap) -> Rect {
        self.paint_own(figs, base, map, None);
        let mut rect = Rect::of(&self.mask);
        if let Some(child) = self.figures[k].child.as_deref() {
            let f = &figs[k];
            child.paint_own(&f.figures, f.height, map, None);
            rect = rect.union(Rect::of(&child.mask));
        }
        rect
    }

    /// Figure k's slope changed: its shape and coefficient, the region painted again, and a
    /// closed figure's nested region blended and painted again. Returns the cells painted.
    pub(super) fn slope(&mut self, k: usize, list: List, map: &mut Heightmap) -> Rect {
        let List { figs, base, outer } = list;
        self.reshape_one(k, figs[k].slope, outer);
        self.paint_own(figs, base, map, None);
        let mut rect = Rect::of(&self.mask);
        if let Some(child) = self.figures[k].child.as_deref_mut() {
            let f = &figs[k];
            child.blend(&f.figures, Some(f.slope), Shapes::All, None);
            child.paint_own(&f.figures, f.height, map, None);
            rect = rect.union(Rect::of(&child.mask));
        }
        rect
    }

    /// The owned runs and the index of each row's first.
    fn owned_runs(&mut self) {
        let mut own = self.mask.bits().to_vec();
        for child in self.figures.iter().filter_map(|f| f.child.as_deref()) {
            for cell in child.mask.cells() {
                if let Some(i) = self.mask.index(cell) {
                    own[i] = false;
                }
            }
        }
        let w = self.mask.width as usize;
        let mut runs = Vec::new();
        let mut row_runs = Vec::with_capacity(self.mask.height as usize + 1);
        for (row, line) in own.chunks(w.max(1)).enumerate() {
            row_runs.push(runs.len());
            let mut c = 0;
            while c < line.len() {
                if line[c] {
                    let start = c;
                    while c < line.len() && line[c] {
                        c += 1;
                    }
                    runs.push(Run {
                        row: row as u32,
                        start: start as u32,
                        end: c as u32,
                    });
                } else {
                    c += 1;
                }
            }
        }
        row_runs.resize(self.mask.height as usize + 1, runs.len());
        self.owned = runs;
        self.row_runs = row_runs;
    }

    /// The owned runs of box row `row`.
    fn runs(&self, row: usize) -> &[Run] {
        &self.owned[self.row_runs[row]..self.row_runs[row + 1]]
    }

    /// Eq. 3's normaliser, the shapes `shapes` names and every figure's coefficient, on the
    /// owned cells where `dirty` holds (every owned cell without it); in bands of rows on all
    /// cores.
    fn blend(&mut self, figs: &[Figure], outer: Option<f64>, shapes: Shapes, dirty: Option<&[bool]>) {
        let w = (self.mask.width as usize).max(1);
        let band = w * BAND_ROWS;
        let slopes: Vec<f64> = figs.iter().map(|f| f.slope).collect();
        let RegionNode {
            df,
            owned,
            row_runs,
            norm,
            figures,
            ..
        } = self;
        // The logarithms are kept for top-level figures of nonzero slope.
        let keep: Vec<bool> = slopes.iter().map(|&s| outer.is_none() && s != 0.0).collect();
        for (k, f) in figures.iter_mut().enumerate().filter(|(k, _)| shapes.has(*k)) {
            // Valid after a blend of every cell; after one of some cells only if it was before.
            f.log_sign = match dirty {
                None if keep[k] => sign(slopes[k]),
                Some(_) if keep[k] && f.log_sign == sign(slopes[k]) => f.log_sign,
                _ => 0,
            };
        }
        // Each band's slices of every figure's maps, so that bands can be written in parallel.
        let mut per_figure: Vec<_> = figures
            .iter_mut()
            .map(|f| {
                f.dp.chunks(band)
                    .zip(f.shape.chunks_mut(band))
                    .zip(f.coef.chunks_mut(band).zip(f.log.chunks_mut(band)))
            })
            .collect();
        let mut bands = Vec::with_capacity(norm.len().div_ceil(band));
        for (b, (norm, df)) in norm.chunks_mut(band).zip(df.chunks(band)).enumerate() {
            let mut dps = Vec::with_capacity(per_figure.len());
            let mut maps = Vec::with_capacity(per_figure.len());
            for ((dp, shape), (coef, log)) in per_figure.iter_mut().filter_map(Iterator::next) {
                dps.push(dp);
                maps.push((shape, coef, log));
            }
            bands.push((b, norm, df, dps, maps));
        }
        let (owned, row_runs) = (&*owned, &*row_runs);
        let (slopes, keep) = (&slopes[..], &keep[..]);
        bands.into_par_iter().for_each(|(b, norm, df, dps, mut maps)| {
            let (row0, rows) = (b * BAND_ROWS, norm.len() / w);
            let mut scratch = Scratch::new(dps.len(), w);
            let mut cells = |a: usize, e: usize| {
                let band = Band {
                    norm: &mut *norm,
                    df,
                    dps: &dps,
                    maps: &mut maps,
                };
                blend_stretch(
                    band,
                    a..e,
                    &mut scratch,
                    Blend {
                        slopes,
                        keep,
                        outer,
                        shapes,
                    },
                );
            };
            for r in 0..rows {
                for run in &owned[row_runs[row0 + r]..row_runs[row0 + r + 1]] {
                    let (a, e) = (r * w + run.start as usize, r * w + run.end as usize);
                    match dirty {
                        None => cells(a, e),
                        // The run's stretches of dirty cells.
                        Some(d) => {
                            for (s, t) in stretches(&d[row0 * w + a..row0 * w + e]) {
                                cells(a + s, a + t);
                            }
                        }
                    }
                }
            }
        });
    }

    /// Figure k's shape (slope `s1`) and coefficient on the owned cells; `norm` is kept.
    fn reshape_one(&mut self, k: usize, s1: f64, outer: Option<f64>) {
        let w = (self.mask.width as usize).max(1);
        let RegionNode {
            df,
            owned,
            row_runs,
            norm,
            figures,
            ..
        } = self;
        let f = &mut figures[k];
        // A top-level figure reads its kept logarithms when they are for this slope's sign (or
        // the slope is 0, where they are not read), else computes and keeps them.
        let top = outer.is_none();
        let reuse = top && (s1 == 0.0 || f.log_sign == sign(s1));
        let keep = top && !reuse;
        if keep {
            f.log_sign = sign(s1);
        }
        let dp = &f.dp;
        f.shape
            .par_chunks_mut(w)
            .zip(f.coef.par_chunks_mut(w))
            .zip(f.log.par_chunks_mut(w))
            .enumerate()
            .for_each(|(r, ((shape_row, coef_row), log_row))| {
                for run in &owned[row_runs[r]..row_runs[r + 1]] {
                    let xs = run.start as usize..run.end as usize;
                    let i0 = r * w + xs.start;
                    reshape_run(
                        (&df[i0..], &dp[i0..], &norm[i0..]),
                        xs,
                        (&mut *shape_row, &mut *coef_row, &mut *log_row),
                        (s1, outer),
                        reuse,
                        keep,
                    );
                }
            });
    }

    /// Paints the owned cells (those where `dirty` holds, if given): `base + Σ relief_k·coef_k`
    /// in `f32`, figures in order — the one way every path computes a height.
    fn paint_own(&self, figs: &[Figure], base: f64, map: &mut Heightmap, dirty: Option<&[bool]>) {
        let cols = map.cols() as usize;
        let (w, r0, c0) = (self.mask.width as usize, self.mask.r0 as usize, self.mask.c0 as usize);
        let h = self.mask.height as usize;
        if w == 0 || h == 0 {
            return;
        }
        let reliefs: Vec<f32> = figs.iter().map(|f| (f.height - base) as f32).collect();
        let coefs: Vec<&[f32]> = self.figures.iter().map(|f| f.coef.as_slice()).collect();
        let base = base as f32;
        map.heights_mut()[r0 * cols..(r0 + h) * cols]
            .par_chunks_mut(cols)
            .enumerate()
            .for_each(|(r, line)| {
                // A stretch of cells, one figure at a time: each cell's sum in figure order.
                let paint = |a: usize, e: usize, line: &mut [f32]| {
                    let out = &mut line[c0 + a - r * w..c0 + e - r * w];
                    paint_stretch(out, base, &coefs, &reliefs, a);
                };
                for run in self.runs(r) {
                    let (a, e) = (r * w + run.start as usize, r * w + run.end as usize);
                    match dirty {
                        None => paint(a, e, line),
                        Some(d) => {
                            for (s, t) in stretches(&d[a..e]) {
                                paint(a + s, a + t, line);
                            }
                        }
                    }
                }
            });
    }

    /// Paints the owned cells and every nested region.
    pub(super) fn paint_all(&self, figs: &[Figure], base: f64, map: &mut Heightmap) {
        self.paint_own(figs, base, map, None);
        for (node, f) in self.figures.iter().zip(figs) {
            if let Some(child) = node.child.as_deref() {
                child.paint_all(&f.figures, f.height, map);
            }
        }
    }

    pub(super) fn clear(&self, map: &mut Heightmap, gate: Option<&mut [f32]>) {
        let cols = map.cols() as usize;
        let out = map.heights_mut();
        for (c, r) in self.mask.cells() {
            out[r as usize * cols + c as usize] = 0.0;
        }
        if let Some(gate) = gate {
            for (c, r) in self.mask.cells() {
                gate[r as usize * cols + c as usize] = 0.0;
            }
        }
    }

    /// Paints the detail's gates ([`detail::gate`]) of the owned cells and every nested region's:
    /// they follow the distances, so only a change of shape repaints them.
    pub(super) fn paint_gates(&self, gate: &mut [f32], cols: u32) {
        let w = self.mask.width as usize;
        for run in &self.owned {
            let b = run.row as usize * w + run.start as usize;
            let len = (run.end - run.start) as usize;
            let g = (self.mask.r0 + run.row) as usize * cols as usize + (self.mask.c0 + run.start) as usize;
            for (i, out) in (b..b + len).zip(&mut gate[g..]) {
                let near = self.figures.iter().map(|f| f.dp[i]).fold(f32::INFINITY, f32::min);
                *out = detail::gate(self.df[i], near);
            }
        }
        for child in self.figures.iter().filter_map(|f| f.child.as_deref()) {
            child.paint_gates(gate, cols);
        }
    }
}
