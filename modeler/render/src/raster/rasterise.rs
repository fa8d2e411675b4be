//! Rasterisation: triangles into a tile's depth-tested samples.
//!
//! - **Fixed point, 8 fractional bits** ([`SUBPIXEL`]): vertices are snapped once, when they are
//!   projected, and every triangle sharing a vertex reads the same snapped value. Edge functions
//!   are then exact integers (`i64`: coordinates within the guard band need 23 bits, products 47),
//!   so two triangles sharing an edge agree exactly on which side of it each pixel centre lies.
//! - **Top-left fill rule**: a pixel centre exactly on an edge belongs to the triangle for which
//!   that edge is a top or left edge, never to both. With the exact edge functions this leaves no
//!   cracks and no pixel covered twice between adjacent triangles (the `coverage` tests count).
//! - **Back faces are culled**: seen from above, the heightfield's triangles wind one way on
//!   screen; triangles seen from below (only possible with the eye under the surface) are not
//!   drawn, so a camera inside a hill looks out through it instead of at its underside.
//! - **Depth is `1/w`**, which is affine in screen space: interpolated exactly with a plane
//!   equation, larger is nearer, and `0` marks an empty sample. Height and light are interpolated
//!   as `h/w` and `l/w` (perspective-correct); the shade stage divides once per pixel, so hidden
//!   samples never pay for it.
//! - A triangle visits the pixel centres inside its bounding box clipped to the tile. Most of a
//!   large grid's triangles are smaller than a pixel (a 512² grid at 1280 × 720 has about 0.65
//!   covered pixels per triangle), so the box test rejects the many that hold no pixel centre
//!   before any attribute is set up, and [`holds_no_pixel`] does it once for both triangles of
//!   a quad (311M → 303M instructions per 512² frame; see `docs/renderer.md`). A special path that
//!   interpolated tiny triangles from their edge functions instead of attribute planes was
//!   measured and dropped: 344.6M → 344.3M instructions per frame, no gain.
//! - A box `SPAN_BOX` (16) pixels or wider (a near triangle, a tree's card) does not test every
//!   pixel of its rows: each row's covered run is found from the edge functions (`run`: the
//!   bound estimated by a multiplication and corrected to the exact integer, not an `i64`
//!   division), exact integers as the test is, so the same pixels are drawn.
//! - A narrower box tests each row's pixels at once in 32-bit lanes (`rows_by_mask`, when the
//!   edge functions fit) and visits only the covered ones: a branch per pixel on the test
//!   missed at both ends of every row, and a tree's branches are slivers whose boxes are nine
//!   tenths empty.
//! - A pixel's attributes come from its row's start on the planes plus its offset times the
//!   step, so a run can start anywhere; stepped one addition at a time from the tile's first
//!   row before, they differ in the last bits only. (Within a wide run the sink steps them one
//!   addition at a time from its first pixel, unless it takes the run several pixels at once:
//!   [`Sink::run`], [`Sink::masked`].)

use std::ops::Range;

use crate::output::frame::Rgba;
use crate::simd::lanes::{ROW_LANES, RowLanes};

/// Fractional bits of fixed-point pixel coordinates.
pub(crate) const SUBPIXEL: i32 = 8;
const ONE: i32 = 1 << SUBPIXEL;
const HALF: i32 = ONE / 2;

/// A projected vertex: fixed-point pixel position, `1/w`, `h/w`, `l/w`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Vtx {
    /// Pixel x × 2⁸.
    pub x: i32,
    /// Pixel y × 2⁸.
    pub y: i32,
    /// `1/w`.
    pub invw: f32,
    /// Height / w.
    pub hw: f32,
    /// Light / w.
    pub lw: f32,
}

/// Pixel coordinate → fixed point. Deterministic (the same input gives the same bits), which is
/// all watertightness needs; the offset keeps the truncating conversion rounding to nearest
/// over the guard band. A vertex far outside the guard band (behind the eye, say) saturates the
/// conversion; it is clipped, never drawn from these coordinates, so the subtraction wraps as a
/// release build's does instead of panicking in a debug one.
#[inline]
pub(crate) fn snap(p: f32) -> i32 {
    const OFFSET: f32 = 16384.0;
    (((p + OFFSET) * ONE as f32 + 0.5) as i32).wrapping_sub((OFFSET as i32) * ONE)
}

/// A pixel rectangle `[x0, x1) × [y0, y1)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bounds {
    /// First column.
    pub x0: i32,
    /// Past the last column.
    pub x1: i32,
    /// First row.
    pub y0: i32,
    /// Past the last row.
    pub y1: i32,
}

/// A depth-buffer entry: `1/w` (0 = empty) and the perspective-divided attributes.
///
/// Laid out as written (`repr(C)`, 16 bytes: `invw`, `hw`, `lw`, then the surface's 4 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C)]
pub struct Sample {
    /// `1/w` of the nearest surface, 0 if none.
    pub invw: f32,
    /// Height / w.
    pub hw: f32,
    /// Light / w.
    pub lw: f32,
    /// Whose surface: the terrain's (the height ramp), a rock's or the water's (their colours), or
    /// a colour of its own.
    pub surface: Surface,
}

/// What a sample shows, which decides its colour.
///
/// Four bytes with a fixed layout (`repr(u8)`: the tag, then a colour's bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(u8)]
pub enum Surface {
    /// The terrain: the height ramp.
    #[default]
    Terrain = 0,
    /// A rock: [`crate::Style::rock_colour`].
    Rock = 1,
    /// River or lake water: [`crate::Style::water_colour`].
    Water = 2,
    /// A colour of its own, sRGB, before light: a tree's bark or leaf, a texel of a simplified
    /// shape ([`crate::scene::meshes`], [`super::textured`]).
    Colour([u8; 3]) = 3,
}

/// Where covered pixels go.
///
/// A row's pixels come with its start on the attribute planes (`row`: `1/w`, `h/w`, `l/w` at
/// the box's first column `px0`) and the step along the row (`step`), so that a sink may take
/// them several at once ([`Sink::run`], [`Sink::masked`]).
pub(crate) trait Sink {
    /// Pixel `(x, y)` is covered with these interpolated values.
    fn pixel(&mut self, x: i32, y: i32, invw: f32, hw: f32, lw: f32);

    /// Pixels `px0 + k` of row `y` for `k` in `ks` are covered: a wide triangle's run. By
    /// default its first pixel's values are the row's start plus its offset times the step,
    /// and the next pixels' are stepped one addition at a time from it (the same values to the
    /// last bits, and cheaper than a product per pixel); a sink that takes pixels several at
    /// once gives each the product ([`each_in_run`]).
    #[inline(always)]
    fn run(&mut self, y: i32, px0: i32, ks: Range<i32>, row: [f32; 3], step: [f32; 3]) {
        let f = ks.start as f32;
        let (mut iw, mut h, mut l) = (row[0] + f * step[0], row[1] + f * step[1], row[2] + f * step[2]);
        for k in ks {
            self.pixel(px0 + k, y, iw, h, l);
            iw += step[0];
            h += step[1];
            l += step[2];
        }
    }

    /// Pixels `px0 + k` of row `y` for the set bits `k` of `mask` are covered: a narrow box's
    /// row ([`rows_by_mask`]).
    #[inline(always)]
    fn masked(&mut self, y: i32, px0: i32, mask: u32, row: [f32; 3], step: [f32; 3]) {
        each_in_mask(self, y, px0, mask, row, step);
    }
}

/// A run's pixels one at a time, each pixel's values its row's start plus its offset times the
/// step (as a sink that takes pixels several at once gives them; [`Sink::run`]'s default steps
/// them one addition at a time instead).
#[inline(always)]
pub(crate) fn each_in_run<S: Sink + ?Sized>(
    sink: &mut S,
    y: i32,
    px0: i32,
    ks: Range<i32>,
    row: [f32; 3],
    step: [f32; 3],
) {
    for k in ks {
        at_offset(sink, y, px0, k, row, step);
    }
}

/// [`Sink::masked`] one pixel at a time.
#[inline(always)]
pub(crate) fn each_in_mask<S: Sink + ?Sized>(
    sink: &mut S,
    y: i32,
    px0: i32,
    mut mask: u32,
    row: [f32; 3],
    step: [f32; 3],
) {
    while mask != 0 {
        let k = mask.trailing_zeros() as i32;
        mask &= mask - 1;
        at_offset(sink, y, px0, k, row, step);
    }
}

/// Pixel `px0 + k` of row `y`, its values the row's start plus `k` times the step.
#[inline(always)]
fn at_offset<S: Sink + ?Sized>(sink: &mut S, y: i32, px0: i32, k: i32, row: [f32; 3], step: [f32; 3]) {
    let f = k as f32;
    sink.pixel(
        px0 + k,
        y,
        row[0] + f * step[0],
        row[1] + f * step[1],
        row[2] + f * step[2],
    );
}

/// The depth test into a tile of samples whose first row is `y0`; a winning pixel is marked as
/// the `surface` drawn.
pub(crate) struct DepthSink<'a> {
    /// The tile's samples, row-major.
    pub samples: &'a mut [Sample],
    /// Frame width.
    pub width: usize,
    /// The tile's first row.
    pub y0: i32,
    /// Whose triangles are drawn.
    pub surface: Surface,
}

impl Sink for DepthSink<'_> {
    #[inline]
    fn pixel(&mut self, x: i32, y: i32, invw: f32, hw: f32, lw: f32) {
        let i = (y - self.y0) as usize * self.width + x as usize;
        let s = &mut self.samples[i];
        if invw > s.invw {
            *s = Sample {
                invw,
                hw,
                lw,
                surface: self.surface,
            };
        }
    }
}

/// Counts how often each pixel is covered (no depth test): the coverage diagnostics.
pub(crate) struct CountSink<'a> {
    /// Counts of the tile, row-major.
    pub counts: &'a mut [u16],
    /// Frame width.
    pub width: usize,
    /// The tile's first row.
    pub y0: i32,
}

impl Sink for CountSink<'_> {
    #[inline]
    fn pixel(&mut self, x: i32, y: i32, _: f32, _: f32, _: f32) {
        let i = (y - self.y0) as usize * self.width + x as usize;
        self.counts[i] = self.counts[i].saturating_add(1);
    }
}

/// The edge function of `a → b` and its steps: `e(p) = (b.x − a.x)(p.y − a.y) − (b.y − a.y)(p.x − a.x)`.
#[derive(Clone, Copy)]
struct Edge {
    start: i64,
    step_x: i64,
    step_y: i64,
}

impl Edge {
    fn new(a: &Vtx, b: &Vtx, px: i32, py: i32) -> Edge {
        let ea = i64::from(a.y) - i64::from(b.y);
        let eb = i64::from(b.x) - i64::from(a.x);
        let dy = -ea;
        // Top edge: horizontal, going right; left edge: going up (rows grow downwards).
        let top_left = (dy == 0 && eb > 0) || dy < 0;
        let start = ea * (i64::from(px) - i64::from(a.x)) + eb * (i64::from(py) - i64::from(a.y));
        Edge {
            start: if top_left { start } else { start - 1 },
            step_x: ea * i64::from(ONE),
            step_y: eb * i64::from(ONE),
        }
    }
}

/// Boxes narrower and shorter than this many pixels are tested for a covered centre before
/// their triangle's attributes are set up ([`triangle`]).
const SMALL_BOX: i32 = 4;

/// Boxes at least this many pixels wide find each row's covered run from the edge functions
/// ([`run`]) instead of testing every pixel of the box: a big triangle leaves about half its box
/// empty, and the test's branch misses twice a row.
const SPAN_BOX: i32 = 16;

/// Narrows the run `lo..=hi` (pixel offsets along a row) to where the edge function `w + k·step`
/// is ≥ 0; an empty run comes back with `lo > hi`. `inv` is `1/step` (0 for a zero step): the
/// bound is estimated by a multiplication and then corrected to the exact integer (an `i64`
/// division per edge and row took a tenth of a wide triangle's time).
#[inline]
fn run(w: i64, step: i64, inv: f64, lo: i64, hi: i64) -> (i64, i64) {
    match step.signum() {
        // Growing along the row: from the first k with w + k·step ≥ 0.
        1 => (
            if w < 0 {
                lo.max(first_at_or_above(w, step, inv))
            } else {
                lo
            },
            hi,
        ),
        // Falling: up to the last such k (none if it starts below 0).
        -1 => (
            lo,
            if w < 0 {
                -1
            } else {
                hi.min(last_at_or_above(w, step, inv))
            },
        ),
        _ => (lo, if w < 0 { -1 } else { hi }),
    }
}

/// The first `k` with `w + k·step ≥ 0`, for `w < 0 < step`: `⌈−w / step⌉`. The quotient by
/// the product, truncated, is at most one short (|w| < 2⁵⁰: its rounding is far under one), and
/// the exact test corrects it. (Truncated, not `ceil`: without SSE4.1 that is a library call.)
#[inline(always)]
fn first_at_or_above(w: i64, step: i64, inv: f64) -> i64 {
    let k = (-(w as f64) * inv) as i64;
    if w + k * step < 0 {
        k + 1
    } else if w + (k - 1) * step >= 0 {
        k - 1
    } else {
        k
    }
}

/// The last `k` with `w + k·step ≥ 0`, for `step < 0 ≤ w`: `⌊w / −step⌋` (the quotient is not
/// negative, so truncating floors it), corrected as [`first_at_or_above`] is.
#[inline(always)]
fn last_at_or_above(w: i64, step: i64, inv: f64) -> i64 {
    let k = (-(w as f64) * inv) as i64;
    if w + k * step < 0 {
        k - 1
    } else if w + (k + 1) * step >= 0 {
        k + 1
    } else {
        k
    }
}

/// Whether the edges `es` (started at the box's first centre) cover a centre of the box of
/// `dx + 1` × `dy + 1` pixels: the same test as [`triangle`]'s loop.
#[inline]
fn covers_a_centre<const N: usize>(es: &[Edge; N], dx: i32, dy: i32) -> bool {
    let mut rows = es.map(|e| e.start);
    for _ in 0..dy + 1 {
        let mut w = rows;
        for _ in 0..dx + 1 {
            if w.iter().fold(0, |acc, w| acc | w) >= 0 {
                return true;
            }
            for (w, e) in w.iter_mut().zip(es) {
                *w += e.step_x;
            }
        }
        for (r, e) in rows.iter_mut().zip(es) {
            *r += e.step_y;
        }
    }
    false
}

/// Whether the bounding box of `vs` holds no pixel centre of `bounds`: then nothing made of these
/// vertices can cover a pixel. A 512² grid's quad is under a pixel across at 1280 × 720, so one
/// test per quad rejects most of them before either triangle is looked at.
#[inline]
pub(crate) fn holds_no_pixel(vs: [&Vtx; 4], bounds: &Bounds) -> bool {
    box_of(&vs, bounds).is_none()
}

/// Draws triangle `(a, b, c)` over the pixels of `bounds` into `sink`. Front faces are those
/// whose vertices run clockwise on screen (the grid's triangles seen from above); others are
/// culled, as are triangles of zero area.
#[inline]
pub(crate) fn triangle<S: Sink>(a: &Vtx, b: &Vtx, c: &Vtx, bounds: &Bounds, sink: &mut S) {
    let Some(tile) = box_in(a, b, c, bounds) else {
        return;
    };
    if area(a, b, c) > 0 {
        fill(a, b, c, tile, sink);
    }
}

/// Draws triangle `(a, b, c)` from whichever side faces the eye: as [`triangle`] of `(a, b, c)`
/// and then of `(a, c, b)` (one of them is culled; zero area draws nothing), with the box and
/// the area found once.
#[inline]
pub(crate) fn two_sided<S: Sink>(a: &Vtx, b: &Vtx, c: &Vtx, bounds: &Bounds, sink: &mut S) {
    let Some(tile) = box_in(a, b, c, bounds) else {
        return;
    };
    // The box does not depend on the order, and `(a, c, b)`'s area is exactly minus this one.
    match area(a, b, c) {
        0 => {}
        1.. => fill(a, b, c, tile, sink),
        _ => fill(a, c, b, tile, sink),
    }
}

/// Draws the quad `v` (corners in order round it) from whichever side faces the eye, as
/// [`two_sided`] of `(v0, v1, v2)` and then of `(v0, v2, v3)` would — the same pixels — in one
/// pass when it is strictly convex on screen: four edges instead of twice three, and each row
/// of its box visited once, where the two triangles each visited it for about half its pixels
/// (a simplified shape's polygon is one such quad). Every pixel centre inside the quad lies in
/// exactly one of the triangles (the diagonal's top-left rule gives it to one), and the outer
/// edges are the triangles' own, so the covered pixels are the same; the attributes come from
/// the plane of the larger of the two triangles, so a pixel of the other one may differ from
/// its own plane's value in the last bits. A quad that is not strictly convex (a corner on a
/// line, or bent by the snapping) is drawn as the two triangles.
#[inline]
pub(crate) fn quad_two_sided<S: Sink>(v: [&Vtx; 4], bounds: &Bounds, sink: &mut S) {
    let Some(tile) = box_of(&v, bounds) else {
        return;
    };
    // The turn at each corner is twice the area of the triangle it makes with its neighbours:
    // the turns at corners 0 and 2 are the areas of the two triangles, `(v0, v1, v2)` and
    // `(v0, v2, v3)`.
    let turns = [0, 1, 2, 3].map(|i| area(v[i], v[(i + 1) % 4], v[(i + 2) % 4]));
    let ([a, b, c, d], (abc, acd)) = if turns.iter().all(|&t| t > 0) {
        (v, (turns[0], turns[2]))
    } else if turns.iter().all(|&t| t < 0) {
        // Anticlockwise: the same quad the other way round, as `two_sided` turns each triangle;
        // its triangles `(v0, v3, v2)` and `(v0, v2, v1)` are the two above, turned.
        ([v[0], v[3], v[2], v[1]], (-turns[2], -turns[0]))
    } else {
        two_sided(v[0], v[1], v[2], bounds, sink);
        two_sided(v[0], v[2], v[3], bounds, sink);
        return;
    };
    let (px0, px1, py0, py1) = tile;
    let (sx, sy) = (px0 * ONE + HALF, py0 * ONE + HALF);
    let es = [
        Edge::new(a, b, sx, sy),
        Edge::new(b, c, sx, sy),
        Edge::new(c, d, sx, sy),
        Edge::new(d, a, sx, sy),
    ];
    if px1 - px0 < SMALL_BOX && py1 - py0 < SMALL_BOX && !covers_a_centre(&es, px1 - px0, py1 - py0) {
        return;
    }
    let planes = if abc >= acd {
        planes(a, b, c, px0, py0)
    } else {
        planes(a, c, d, px0, py0)
    };
    fill_rows(&es, tile, planes, sink);
}

/// The pixels `(px0, px1, py0, py1)` (inclusive) of `bounds` whose centres lie in the bounding
/// box of `vs`; `None` if there are none.
#[inline]
fn box_of(vs: &[&Vtx; 4], bounds: &Bounds) -> Option<(i32, i32, i32, i32)> {
    let (mut x0, mut x1, mut y0, mut y1) = (vs[0].x, vs[0].x, vs[0].y, vs[0].y);
    for v in &vs[1..] {
        x0 = x0.min(v.x);
        x1 = x1.max(v.x);
        y0 = y0.min(v.y);
        y1 = y1.max(v.y);
    }
    let px0 = ((x0 - HALF + ONE - 1) >> SUBPIXEL).max(bounds.x0);
    let px1 = ((x1 - HALF) >> SUBPIXEL).min(bounds.x1 - 1);
    let py0 = ((y0 - HALF + ONE - 1) >> SUBPIXEL).max(bounds.y0);
    let py1 = ((y1 - HALF) >> SUBPIXEL).min(bounds.y1 - 1);
    (px0 <= px1 && py0 <= py1).then_some((px0, px1, py0, py1))
}

/// The pixels `(px0, px1, py0, py1)` (inclusive) of `bounds` whose centres lie in the bounding
/// box of `a`, `b`, `c`; `None` if there are none.
#[inline]
fn box_in(a: &Vtx, b: &Vtx, c: &Vtx, bounds: &Bounds) -> Option<(i32, i32, i32, i32)> {
    let min_x = a.x.min(b.x).min(c.x);
    let max_x = a.x.max(b.x).max(c.x);
    let min_y = a.y.min(b.y).min(c.y);
    let max_y = a.y.max(b.y).max(c.y);
    // Pixel centres (p + ½) inside the box: p from ⌈min − ½⌉ to ⌊max − ½⌋.
    let px0 = ((min_x - HALF + ONE - 1) >> SUBPIXEL).max(bounds.x0);
    let px1 = ((max_x - HALF) >> SUBPIXEL).min(bounds.x1 - 1);
    let py0 = ((min_y - HALF + ONE - 1) >> SUBPIXEL).max(bounds.y0);
    let py1 = ((max_y - HALF) >> SUBPIXEL).min(bounds.y1 - 1);
    (px0 <= px1 && py0 <= py1).then_some((px0, px1, py0, py1))
}

/// Twice the signed area of `(a, b, c)` in fixed point: positive when clockwise on screen.
#[inline]
fn area(a: &Vtx, b: &Vtx, c: &Vtx) -> i64 {
    (i64::from(b.x) - i64::from(a.x)) * (i64::from(c.y) - i64::from(a.y))
        - (i64::from(c.x) - i64::from(a.x)) * (i64::from(b.y) - i64::from(a.y))
}

/// Draws the front-facing triangle `(a, b, c)` over the pixels `(px0, px1, py0, py1)` of its box.
#[inline]
fn fill<S: Sink>(a: &Vtx, b: &Vtx, c: &Vtx, (px0, px1, py0, py1): (i32, i32, i32, i32), sink: &mut S) {
    let sx = px0 * ONE + HALF;
    let sy = py0 * ONE + HALF;
    let es = [
        Edge::new(b, c, sx, sy),
        Edge::new(c, a, sx, sy),
        Edge::new(a, b, sx, sy),
    ];
    // A fine level of detail's triangles are a pixel or two, and many cover no pixel centre
    // although their box holds one: the integer edge test over a small box finds that before the
    // attribute planes and their division are set up (the pixels drawn are the same).
    if px1 - px0 < SMALL_BOX && py1 - py0 < SMALL_BOX && !covers_a_centre(&es, px1 - px0, py1 - py0) {
        return;
    }
    let planes = planes(a, b, c, px0, py0);
    fill_rows(&es, (px0, px1, py0, py1), planes, sink);
}

/// The attribute planes (`1/w`, `h/w`, `l/w`) of the triangle `(a, b, c)` in pixel units: each
/// one's value at the centre of pixel `(px0, py0)` and its steps along a row and down a column.
#[inline(always)]
fn planes(a: &Vtx, b: &Vtx, c: &Vtx, px0: i32, py0: i32) -> [(f32, f32, f32); 3] {
    // Relative to a.
    let (ax, ay) = (a.x as f32 / ONE as f32, a.y as f32 / ONE as f32);
    let (bx, by) = (b.x as f32 / ONE as f32 - ax, b.y as f32 / ONE as f32 - ay);
    let (cx, cy) = (c.x as f32 / ONE as f32 - ax, c.y as f32 / ONE as f32 - ay);
    let inv_area = 1.0 / (bx * cy - cx * by);
    let plane = |va: f32, vb: f32, vc: f32| {
        let (db, dc) = (vb - va, vc - va);
        let gx = (db * cy - dc * by) * inv_area;
        let gy = (dc * bx - db * cx) * inv_area;
        let start = va + gx * (px0 as f32 + 0.5 - ax) + gy * (py0 as f32 + 0.5 - ay);
        (start, gx, gy)
    };
    [
        plane(a.invw, b.invw, c.invw),
        plane(a.hw, b.hw, c.hw),
        plane(a.lw, b.lw, c.lw),
    ]
}

/// Draws the pixels of the box `(px0, px1, py0, py1)` whose centres every edge of `es` (started
/// at the box's first centre) holds, with the attribute `planes` ([`planes`]): a triangle's three
/// edges, or a convex quad's four ([`quad_two_sided`]).
#[inline(always)]
fn fill_rows<const N: usize, S: Sink>(
    es: &[Edge; N],
    (px0, px1, py0, py1): (i32, i32, i32, i32),
    planes: [(f32, f32, f32); 3],
    sink: &mut S,
) {
    let [(iw0, iwx, iwy), (h0, hx, hy), (l0, lx, ly)] = planes;
    let wide = px1 - px0 >= SPAN_BOX;
    if !wide && fits_lanes(es, py1 - py0) {
        rows_by_mask(es, (px0, px1, py0, py1), planes, sink);
        return;
    }
    let inv = es.map(|e| if e.step_x == 0 { 0.0 } else { 1.0 / e.step_x as f64 });
    let mut rows = es.map(|e| e.start);
    // Half-open ranges: an inclusive one costs a compare and a flag per step of these loops.
    for (row, y) in (py0..py1 + 1).enumerate() {
        // Each row's attributes from the planes (not stepped from the row before), so that a
        // run can start anywhere without stepping over the pixels before it.
        let fy = row as f32;
        let (riw, rh, rl) = (iw0 + fy * iwy, h0 + fy * hy, l0 + fy * ly);
        if wide {
            // The row's covered pixels are one run: find it from the edge functions (exact
            // integers, so the same pixels as testing each).
            let last = i64::from(px1 - px0);
            let (first, end) = rows
                .iter()
                .zip(es)
                .zip(&inv)
                .fold((0, last), |(lo, hi), ((&w, e), &inv)| run(w, e.step_x, inv, lo, hi));
            // Offsets within the box's width, an `i32` (the box is clipped to the tile).
            sink.run(y, px0, first as i32..end as i32 + 1, [riw, rh, rl], [iwx, hx, lx]);
        } else {
            let mut w = rows;
            let (mut iw, mut h, mut l) = (riw, rh, rl);
            for x in px0..px1 + 1 {
                if w.iter().fold(0, |acc, w| acc | w) >= 0 {
                    sink.pixel(x, y, iw, h, l);
                }
                for (w, e) in w.iter_mut().zip(es) {
                    *w += e.step_x;
                }
                iw += iwx;
                h += hx;
                l += lx;
            }
        }
        for (r, e) in rows.iter_mut().zip(es) {
            *r += e.step_y;
        }
    }
}

/// Pixels of a row a narrow box's mask holds: boxes narrower than [`SPAN_BOX`] fit.
const LANES: usize = SPAN_BOX as usize;
const _: () = assert!(LANES == ROW_LANES);

/// Whether the edge functions stay within `i32` over a box `LANES` wide and `dy + 1` rows tall
/// from their start (then [`rows_by_mask`] may test its rows in 32-bit lanes).
#[inline]
fn fits_lanes<const N: usize>(es: &[Edge; N], dy: i32) -> bool {
    let limit = i64::from(i32::MAX) / 2;
    es.iter()
        .all(|e| e.start.abs() + e.step_x.abs() * LANES as i64 + e.step_y.abs() * i64::from(dy + 1) < limit)
}

/// Fills a box narrower than [`SPAN_BOX`] row by row: each row's edge tests run over
/// [`LANES`] pixels at once in 32-bit lanes (vector instructions, no branch per pixel), giving a
/// mask of the covered pixels, and only those are visited. The test per pixel is the scalar
/// loop's (the same integers, in 32 bits because [`fits_lanes`] said they fit), so the same
/// pixels are covered; a pixel's attributes are its row's plus its offset times the step.
#[inline(always)]
fn rows_by_mask<const N: usize, S: Sink>(
    es: &[Edge; N],
    (px0, px1, py0, py1): (i32, i32, i32, i32),
    planes: [(f32, f32, f32); 3],
    sink: &mut S,
) {
    let lanes = RowLanes::new(es.map(|e| e.step_x as i32));
    let width = (px1 - px0 + 1) as u32;
    let in_box = if width >= 32 { u32::MAX } else { (1u32 << width) - 1 };
    let [(iw0, iwx, iwy), (h0, hx, hy), (l0, lx, ly)] = planes;
    let mut rows = es.map(|e| e.start as i32);
    let down = es.map(|e| e.step_y as i32);
    for (row, y) in (py0..py1 + 1).enumerate() {
        let mask = lanes.covered(rows) & in_box;
        if mask != 0 {
            let fy = row as f32;
            sink.masked(
                y,
                px0,
                mask,
                [iw0 + fy * iwy, h0 + fy * hy, l0 + fy * ly],
                [iwx, hx, lx],
            );
        }
        for (r, d) in rows.iter_mut().zip(down) {
            *r += d;
        }
    }
}

/// A thick line segment on screen: a capsule of `radius` around `a → b`, depth interpolated
/// along it; drawn where it passes the depth test against `samples` with `bias`.
#[allow(missing_docs)] // `colour` is the fill.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Capsule {
    /// Start: pixel x, y and `1/w`.
    pub a: [f32; 3],
    /// End: pixel x, y and `1/w`.
    pub b: [f32; 3],
    /// Half the line width, pixels.
    pub radius: f32,
    pub colour: Rgba,
}

impl Capsule {
    /// The pixel rows it may touch.
    pub(crate) fn rows(&self) -> (f32, f32) {
        (
            self.a[1].min(self.b[1]) - self.radius,
            self.a[1].max(self.b[1]) + self.radius,
        )
    }

    /// Draws the capsule's pixels (centres within `radius` of the segment) inside `bounds`,
    /// where `1/w·(1 + bias)` ≥ the sample's `1/w`. `pixels` and `samples` are the tile's, whose
    /// first row is `bounds.y0`.
    pub(crate) fn draw(&self, bounds: &Bounds, width: usize, samples: &[Sample], pixels: &mut [Rgba], bias: f32) {
        let r = self.radius;
        let x0 = ((self.a[0].min(self.b[0]) - r).floor() as i32).max(bounds.x0);
        let x1 = ((self.a[0].max(self.b[0]) + r).ceil() as i32).min(bounds.x1 - 1);
        let y0 = ((self.a[1].min(self.b[1]) - r).floor() as i32).max(bounds.y0);
        let y1 = ((self.a[1].max(self.b[1]) + r).ceil() as i32).min(bounds.y1 - 1);
        let (dx, dy) = (self.b[0] - self.a[0], self.b[1] - self.a[1]);
        let len2 = dx * dx + dy * dy;
        let r2 = r * r;
        for y in y0..=y1 {
            let py = y as f32 + 0.5 - self.a[1];
            for x in x0..=x1 {
                let px = x as f32 + 0.5 - self.a[0];
                let t = if len2 > 0.0 {
                    ((px * dx + py * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (px - t * dx, py - t * dy);
                if ex * ex + ey * ey > r2 {
                    continue;
                }
                let invw = self.a[2] + t * (self.b[2] - self.a[2]);
                let i = (y - bounds.y0) as usize * width + x as usize;
                if invw * (1.0 + bias) >= samples[i].invw {
                    pixels[i] = self.colour;
                }
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// [`run`] by division, as it was: the reference the estimate must equal.
    fn divided(w: i64, step: i64, lo: i64, hi: i64) -> (i64, i64) {
        match step.signum() {
            1 => (if w < 0 { lo.max((-w + step - 1) / step) } else { lo }, hi),
            -1 => (lo, if w < 0 { -1 } else { hi.min(w / -step) }),
            _ => (lo, if w < 0 { -1 } else { hi }),
        }
    }

    #[test]
    fn runs_are_the_divisions_bounds() {
        // A deterministic spread of edge values and steps: small and large, exact multiples and
        // one either side of them (where a rounded quotient would be off by one).
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for i in 0..200_000u32 {
            let step = ((next() % (1 << (8 + i % 23))) as i64 + 1) * if next() % 2 == 0 { 1 } else { -1 };
            let k = (next() % 70_000) as i64;
            let w = match i % 3 {
                0 => -(k * step.abs()),
                1 => -(k * step.abs()) + (next() % 3) as i64 - 1,
                _ => (next() % (1 << 46)) as i64 - (1 << 45),
            };
            let w = if step < 0 { -w } else { w };
            let inv = 1.0 / step as f64;
            let hi = (next() % 100_000) as i64;
            assert_eq!(run(w, step, inv, 0, hi), divided(w, step, 0, hi), "w {w} step {step}");
        }
        assert_eq!(run(-5, 0, 0.0, 0, 9), (0, -1));
        assert_eq!(run(5, 0, 0.0, 0, 9), (0, 9));
    }

    /// A deterministic sequence in `[0, 1]` from `seed` (xorshift), for the tests' cases here and
    /// in `textured.rs`.
    pub(crate) fn uniform(mut seed: u32) -> impl FnMut() -> f32 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32
        }
    }

    /// The pixels a sink was given, with their values.
    #[derive(Default)]
    struct Record(Vec<(i32, i32, [f32; 3])>);

    impl Sink for Record {
        fn pixel(&mut self, x: i32, y: i32, invw: f32, hw: f32, lw: f32) {
            self.0.push((x, y, [invw, hw, lw]));
        }
    }

    /// A vertex at pixel `(x, y)` whose attributes are one plane's values there (a planar quad's
    /// corners: its two triangles' planes are then the same but for the snapping).
    fn planar(x: f32, y: f32, plane: [[f32; 3]; 3]) -> Vtx {
        let at = |[a, b, c]: [f32; 3]| a + b * x + c * y;
        Vtx {
            x: snap(x),
            y: snap(y),
            invw: at(plane[0]),
            hw: at(plane[1]),
            lw: at(plane[2]),
        }
    }

    fn sorted(mut r: Record) -> Vec<(i32, i32, [f32; 3])> {
        r.0.sort_by_key(|&(x, y, _)| (y, x));
        r.0
    }

    /// A quad in one pass covers the pixels its two triangles cover, each once, with the same
    /// values but for the last bits; one that is not strictly convex is drawn as the triangles,
    /// bit for bit. Quads small and large (the masked rows, the runs, and boxes narrower than
    /// four pixels), both windings, reaching past the tile, and corners far off screen (edge
    /// values past the 32-bit lanes).
    #[test]
    fn a_quad_in_one_pass_covers_what_its_two_triangles_cover() {
        let mut next = uniform(0x9e37_79b9);
        let tile = Bounds {
            x0: 0,
            x1: 200,
            y0: 32,
            y1: 64,
        };
        let (mut convex, mut bent, mut pixels) = (0, 0, 0);
        for i in 0..4000 {
            let scale = [1.5, 6.0, 40.0, 300.0, 6000.0][i % 5];
            let (cx, cy) = (-20.0 + 240.0 * next(), 20.0 + 56.0 * next());
            let plane = [
                [0.5 + next(), 1e-3 * (next() - 0.5), 1e-3 * (next() - 0.5)],
                [next(), next() - 0.5, next() - 0.5],
                [next(), 0.1 * next(), 0.1 * next()],
            ];
            let corners: [Vtx; 4] = if i % 7 == 6 {
                // Any four points: often a bow tie or a dent.
                std::array::from_fn(|_| planar(cx + scale * (next() - 0.5), cy + scale * (next() - 0.5), plane))
            } else {
                // Four angles in order round an ellipse: convex, one way or the other round.
                let mut angles: [f32; 4] = std::array::from_fn(|_| std::f32::consts::TAU * next());
                angles.sort_by(f32::total_cmp);
                if i % 2 == 0 {
                    angles.reverse();
                }
                let (rx, ry) = (scale * (0.2 + next()), scale * (0.2 + next()));
                angles.map(|t| planar(cx + rx * t.cos(), cy + ry * t.sin(), plane))
            };
            let v = [&corners[0], &corners[1], &corners[2], &corners[3]];
            let mut one = Record::default();
            quad_two_sided(v, &tile, &mut one);
            let mut two = Record::default();
            two_sided(v[0], v[1], v[2], &tile, &mut two);
            two_sided(v[0], v[2], v[3], &tile, &mut two);
            let (one, two) = (sorted(one), sorted(two));
            let turns = [0, 1, 2, 3].map(|k| area(v[k], v[(k + 1) % 4], v[(k + 2) % 4]));
            let strictly = turns.iter().all(|&t| t > 0) || turns.iter().all(|&t| t < 0);
            if !strictly {
                bent += 1;
                assert!(one == two, "quad {i}: drawn other than as its triangles");
                continue;
            }
            convex += 1;
            pixels += one.len();
            let at = |r: &[(i32, i32, [f32; 3])]| r.iter().map(|&(x, y, _)| (x, y)).collect::<Vec<_>>();
            assert_eq!(at(&one), at(&two), "quad {i}: other pixels");
            for w in at(&one).windows(2) {
                assert_ne!(w[0], w[1], "quad {i}: a pixel twice");
            }
            // The two planes differ by the corners' snapping (1/256 pixel): the values agree to
            // what a fiftieth of a pixel changes, and to the rounding of values of their size
            // over the quad (a value near 0 in a plane of large ones is a difference of large
            // numbers).
            let size = corners.map(|c| [c.invw, c.hw, c.lw]);
            let size: [f32; 3] = std::array::from_fn(|k| size.iter().fold(1.0f32, |m, c| m.max(c[k].abs())));
            for ((x, y, a), (_, _, b)) in one.iter().zip(&two) {
                for (((a, b), size), [_, gx, gy]) in a.iter().zip(b).zip(size).zip(plane) {
                    let tolerance = (gx.abs() + gy.abs()) / 50.0 + 1e-5 * size;
                    assert!(
                        (a - b).abs() <= tolerance,
                        "quad {i}, pixel ({x}, {y}): {a} against {b} (tolerance {tolerance})"
                    );
                }
            }
        }
        // The cases the loop meant to reach were reached.
        assert!(
            convex > 3000 && bent > 100 && pixels > 100_000,
            "{convex} convex, {bent} bent, {pixels} pixels"
        );
    }
}
