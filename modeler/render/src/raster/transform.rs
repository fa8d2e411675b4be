//! The transform stage: the grid's vertices projected once per frame and eye, and the grid cut
//! into chunks with screen bounds so that each tile visits only the chunks that can touch it.
//!
//! - A vertex `(c, r)` stands at the cell centre, world `((c + ½)s, h·v, (r + ½)s)` (the mesh
//!   exports' convention), so its clip coordinates are affine in `c`, `r` and `h`: three
//!   multiply-adds per coordinate ([`Affine`]).
//! - Each vertex is snapped to fixed point here, once, which makes shared edges watertight
//!   ([`super::rasterise`]). Vertices behind the near plane or outside the guard band are marked;
//!   triangles using them take the clipping path ([`super::clip`]). Vertices with a non-finite
//!   height are marked too, and the triangles using them are skipped: a hole, not a panic and
//!   not an error, since one bad value should not blank a live view.
//! - Chunks of [`CHUNK`] × [`CHUNK`] quads carry their pixel bounding box and are sorted near to
//!   far, so the depth test rejects most hidden samples before they are written.

use rayon::prelude::*;

use super::camera::Projection;
use super::clip::ClipVertex;
use super::rasterise::{Bounds, Sink, Vtx, snap};
use penmodel_terrain::Heightmap;

/// A chunk's pixel bounds from its vertices' fixed-point extent `[x0, x1, y0, y1]` (8 fraction
/// bits), and its state: the whole viewport when a vertex is clipped at the near plane (clipped
/// triangles may reach anywhere), culled when nothing is drawable or the bounds are empty. The
/// grid's chunks ([`Projected`]) and the level-of-detail nodes (`lod/nodes.rs`) share it.
pub(crate) fn screen_bounds(
    state: ChunkState,
    nearest: f32,
    any_drawable: bool,
    [x0, x1, y0, y1]: [i32; 4],
    viewport: Bounds,
) -> (Bounds, ChunkState) {
    let bounds = if state == ChunkState::Mixed && nearest == 0.0 {
        viewport
    } else {
        Bounds {
            x0: (x0 >> 8).max(viewport.x0),
            x1: ((x1 >> 8) + 1).min(viewport.x1),
            y0: (y0 >> 8).max(viewport.y0),
            y1: ((y1 >> 8) + 1).min(viewport.y1),
        }
    };
    let empty = bounds.x0 >= bounds.x1 || bounds.y0 >= bounds.y1;
    (
        bounds,
        if !any_drawable || empty {
            ChunkState::Culled
        } else {
            state
        },
    )
}

/// Quads per chunk side.
pub(crate) const CHUNK: usize = 16;

/// The vertex may be drawn directly.
pub(crate) const OK: u8 = 0;
/// The vertex is behind the near plane or outside the guard band: clip its triangles.
pub(crate) const CLIP: u8 = 1;
/// The vertex's height is not finite: skip its triangles.
pub(crate) const SKIP: u8 = 2;

/// Clip coordinates as an affine function of column, row and height.
#[derive(Debug, Clone, Copy)]
pub struct Affine {
    base: [f32; 3],
    dc: [f32; 3],
    dr: [f32; 3],
    dh: [f32; 3],
}

impl Affine {
    /// The affine map of `projection` for a grid of `cell_size` and heights × `vertical_scale`.
    pub fn new(projection: &Projection, cell_size: f64, vertical_scale: f64) -> Affine {
        let m = &projection.rows;
        let half = 0.5 * cell_size;
        Affine {
            base: [0, 1, 2].map(|i| (m[i][0] * half + m[i][2] * half + m[i][3]) as f32),
            dc: [0, 1, 2].map(|i| (m[i][0] * cell_size) as f32),
            dr: [0, 1, 2].map(|i| (m[i][2] * cell_size) as f32),
            dh: [0, 1, 2].map(|i| (m[i][1] * vertical_scale) as f32),
        }
    }

    /// The clip-space vertex of cell `(c, r)` at height `h` with light `l`. Every path that needs
    /// a grid vertex computes it here, so the same vertex always has the same bits.
    #[inline]
    pub fn clip_vertex(&self, c: usize, r: usize, h: f32, l: f32) -> ClipVertex {
        let (cf, rf) = (c as f32, r as f32);
        let at = |i: usize| self.base[i] + cf * self.dc[i] + rf * self.dr[i] + h * self.dh[i];
        ClipVertex {
            x: at(0),
            y: at(1),
            w: at(2),
            h,
            l,
        }
    }
}

impl Affine {
    /// The change of the clip coordinates `(X, Y, w)` per metre of height (the vertical scale
    /// included): what a height error moves on screen ([`crate::lod::Bound`]).
    pub fn height_axis(&self) -> [f32; 3] {
        self.dh
    }

    /// The clip-space vertex at fractional column and row `(c, r)` (a point off the grid's
    /// centres: a rock's vertex), height `h`, light `l`.
    #[inline]
    pub fn clip_point(&self, c: f32, r: f32, h: f32, l: f32) -> ClipVertex {
        let at = |i: usize| self.base[i] + c * self.dc[i] + r * self.dr[i] + h * self.dh[i];
        ClipVertex {
            x: at(0),
            y: at(1),
            w: at(2),
            h,
            l,
        }
    }
}

/// A clip-space vertex after the perspective division.
#[inline]
pub(crate) fn project(v: &ClipVertex) -> Vtx {
    let invw = 1.0 / v.w;
    Vtx {
        x: snap(v.x * invw),
        y: snap(v.y * invw),
        invw,
        hw: v.h * invw,
        lw: v.l * invw,
    }
}

/// Draws the triangle `tri` cut by the near plane and the guard band, as a fan, over `bounds`.
pub(crate) fn draw_clipped<S: Sink>(tri: [ClipVertex; 3], near: f32, bounds: &Bounds, sink: &mut S) {
    let poly = super::clip::triangle(tri, near);
    if poly.len < 3 {
        return;
    }
    let v: Vec<Vtx> = poly.vertices[..poly.len].iter().map(project).collect();
    for i in 1..poly.len - 1 {
        super::rasterise::triangle(&v[0], &v[i], &v[i + 1], bounds, sink);
    }
}

/// What a chunk needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ChunkState {
    /// Every vertex drawable directly.
    Direct,
    /// Some vertices need clipping or are skipped: check each triangle.
    Mixed,
    /// Nothing of it can be seen.
    Culled,
}

/// A block of quads and where it lands on screen.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Chunk {
    /// First quad column.
    pub c0: usize,
    /// First quad row.
    pub r0: usize,
    /// Past the last quad column.
    pub c1: usize,
    /// Past the last quad row.
    pub r1: usize,
    /// Pixels it may cover (for a mixed chunk, the whole viewport).
    pub bounds: Bounds,
    /// Direct, mixed or culled.
    pub state: ChunkState,
    /// Nearest depth of its vertices, for the near-to-far order.
    pub near: f32,
    /// Per row of quads, the pixel rows its triangles may cover (first, past last), so that a
    /// tile skips the rows of a chunk that cannot reach it.
    pub spans: [(i32, i32); CHUNK],
}

/// The projected grid of one eye.
#[derive(Debug, Default)]
pub(crate) struct Projected {
    /// Projected vertices, row-major.
    pub vertices: Vec<Vtx>,
    /// [`OK`], [`CLIP`] or [`SKIP`] per vertex.
    pub flags: Vec<u8>,
    /// Visible chunks, near to far.
    pub chunks: Vec<Chunk>,
}

/// Projects every vertex of `map` and sorts its chunks; `light` is per vertex
/// ([`crate::scene::light::vertex_light`]), `viewport` the pixels this eye may draw.
pub(crate) fn project_grid(
    map: &Heightmap,
    light: &[f32],
    affine: &Affine,
    near: f32,
    viewport: Bounds,
    out: &mut Projected,
) {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    let n = cols * rows;
    out.vertices.resize(n, Vtx::default());
    out.flags.resize(n, OK);
    out.chunks.clear();
    if cols < 2 || rows < 2 {
        return;
    }
    let heights = map.heights();
    out.vertices
        .par_chunks_mut(cols)
        .zip(out.flags.par_chunks_mut(cols))
        .enumerate()
        .for_each(|(r, (verts, flags))| {
            let hrow = &heights[r * cols..(r + 1) * cols];
            let lrow = &light[r * cols..(r + 1) * cols];
            for c in 0..cols {
                let h = hrow[c];
                if !h.is_finite() {
                    flags[c] = SKIP;
                    continue;
                }
                let v = affine.clip_vertex(c, r, h, lrow[c]);
                if v.inside(near) {
                    flags[c] = OK;
                    verts[c] = project(&v);
                } else {
                    flags[c] = CLIP;
                }
            }
        });

    let chunk_cols = (cols - 1).div_ceil(CHUNK);
    let chunk_rows = (rows - 1).div_ceil(CHUNK);
    let vertices = &out.vertices;
    let flags = &out.flags;
    let mut chunks: Vec<Chunk> = (0..chunk_cols * chunk_rows)
        .into_par_iter()
        .map(|i| {
            let (c0, r0) = ((i % chunk_cols) * CHUNK, (i / chunk_cols) * CHUNK);
            let (c1, r1) = ((c0 + CHUNK).min(cols - 1), (r0 + CHUNK).min(rows - 1));
            let mut state = ChunkState::Direct;
            let (mut x0, mut y0, mut x1, mut y1) = (i32::MAX, i32::MAX, i32::MIN, i32::MIN);
            let mut nearest = f32::INFINITY;
            let mut any_drawable = false;
            // Pixel rows of each vertex row, then of each quad row (two vertex rows).
            let mut vrows = [(i32::MAX, i32::MIN); CHUNK + 1];
            for (r, vrow) in (r0..=r1).zip(&mut vrows) {
                for c in c0..=c1 {
                    let k = r * cols + c;
                    match flags[k] {
                        OK => {
                            let v = &vertices[k];
                            x0 = x0.min(v.x);
                            x1 = x1.max(v.x);
                            vrow.0 = vrow.0.min(v.y);
                            vrow.1 = vrow.1.max(v.y);
                            nearest = nearest.min(1.0 / v.invw);
                            any_drawable = true;
                        }
                        CLIP => {
                            state = ChunkState::Mixed;
                            any_drawable = true;
                            nearest = 0.0;
                        }
                        _ => {
                            if state == ChunkState::Direct {
                                state = ChunkState::Mixed;
                            }
                        }
                    }
                }
                y0 = y0.min(vrow.0);
                y1 = y1.max(vrow.1);
            }
            let mut spans = [(viewport.y0, viewport.y1); CHUNK];
            if nearest > 0.0 {
                for (span, pair) in spans.iter_mut().zip(vrows.windows(2)) {
                    let (lo, hi) = (pair[0].0.min(pair[1].0), pair[0].1.max(pair[1].1));
                    *span = if lo <= hi { (lo >> 8, (hi >> 8) + 1) } else { (0, 0) };
                }
            }
            let (bounds, state) = screen_bounds(state, nearest, any_drawable, [x0, x1, y0, y1], viewport);
            Chunk {
                c0,
                r0,
                c1,
                r1,
                bounds,
                state,
                near: nearest,
                spans,
            }
        })
        .collect();
    chunks.retain(|c| c.state != ChunkState::Culled);
    chunks.sort_unstable_by(|a, b| a.near.total_cmp(&b.near));
    out.chunks = chunks;
}
