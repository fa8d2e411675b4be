//! The chosen level-of-detail nodes of one eye ([`crate::lod`]), projected and stitched, and
//! drawn by the tiles.
//!
//! Each node's sampled vertices are projected once per eye into a slot of its own, with the same
//! [`Affine::clip_vertex`] and snapping as the full grid's (a vertex two nodes share has the same
//! bits in both). A node's edge against a coarser neighbour is stitched ([`crate::lod`]): its
//! vertex indices along that edge point at the vertex before them on the coarser node's lattice.
//! Nodes carry their screen bounds and the pixel rows of each quad row, and are sorted near to
//! far, as the full grid's chunks are ([`crate::raster::transform`]).

use rayon::prelude::*;

use crate::lod::{Levels, NODE, Pick, Pyramid};
use crate::raster::clip::ClipVertex;
use crate::raster::rasterise::{self, Bounds, Sink, Vtx};
use crate::raster::transform::{self, Affine, CLIP, ChunkState, OK, SKIP};
use penmodel_terrain::Heightmap;

/// Vertices per node row.
const PITCH: usize = NODE + 1;
/// Vertices per node.
const SLOT: usize = PITCH * PITCH;

/// A node and where it lands on screen.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NodeChunk {
    /// Its first vertex in [`Projected::vertices`].
    pub base: usize,
    /// Quads across.
    pub nc: usize,
    /// Quads down.
    pub nr: usize,
    /// Pixels it may cover (for a node with clipped vertices, the whole viewport).
    pub bounds: Bounds,
    /// Direct, mixed or culled.
    pub state: ChunkState,
    /// Nearest depth of its vertices.
    pub near: f32,
    /// Per quad row, the pixel rows its triangles may cover.
    pub spans: [(i32, i32); NODE],
    /// Per edge (north, east, south, west), the vertex used for each sampled vertex along it:
    /// itself, or the one before it on a coarser neighbour's lattice.
    pub stitch: [[u8; PITCH]; 4],
}

impl NodeChunk {
    /// The vertex index of the node's sampled vertex `(qc, qr)`, stitched.
    #[inline]
    fn index(&self, qc: usize, qr: usize) -> usize {
        let (qc, qr) = if qr == 0 {
            (usize::from(self.stitch[0][qc]), 0)
        } else if qr == self.nr {
            (usize::from(self.stitch[2][qc]), qr)
        } else if qc == 0 {
            (0, usize::from(self.stitch[3][qr]))
        } else if qc == self.nc {
            (qc, usize::from(self.stitch[1][qr]))
        } else {
            (qc, qr)
        };
        self.base + qr * PITCH + qc
    }
}

/// One eye's chosen nodes, projected.
#[derive(Debug, Default)]
pub(crate) struct Projected {
    /// Projected vertices, [`NODE`]+1 squared per node.
    pub vertices: Vec<Vtx>,
    /// The same vertices before the division, for the clipping path.
    pub clip: Vec<ClipVertex>,
    /// [`OK`], [`CLIP`] or [`SKIP`] per vertex.
    pub flags: Vec<u8>,
    /// Visible nodes, near to far.
    pub chunks: Vec<NodeChunk>,
    /// The nodes chosen, in the pyramid's order.
    pub picks: Vec<Pick>,
    levels: Levels,
}

impl Projected {
    /// How many nodes of each level were chosen (level 0 first): the picture of the choice.
    pub(crate) fn per_level(&self) -> Vec<usize> {
        let mut n = Vec::new();
        for p in &self.picks {
            let l = p.level as usize;
            if n.len() <= l {
                n.resize(l + 1, 0);
            }
            n[l] += 1;
        }
        n
    }
}

/// Chooses the nodes of `pyramid` for the view of `affine` (at most `pixels` of error on
/// screen), and projects them; `light` is per grid vertex.
#[allow(clippy::too_many_arguments)]
pub(crate) fn project(
    pyramid: &Pyramid,
    map: &Heightmap,
    light: &[f32],
    affine: &Affine,
    near: f32,
    viewport: Bounds,
    pixels: f32,
    out: &mut Projected,
) {
    pyramid.select(affine, near, viewport, pixels, &mut out.picks);
    out.levels.fill(pyramid, &out.picks);
    let n = out.picks.len();
    out.vertices.resize(n * SLOT, Vtx::default());
    out.clip.resize(
        n * SLOT,
        ClipVertex {
            x: 0.0,
            y: 0.0,
            w: 0.0,
            h: 0.0,
            l: 0.0,
        },
    );
    out.flags.resize(n * SLOT, OK);
    let cols = map.cols() as usize;
    let heights = map.heights();
    let levels = &out.levels;
    out.picks
        .par_iter()
        .zip(out.vertices.par_chunks_mut(SLOT))
        .zip(out.clip.par_chunks_mut(SLOT))
        .zip(out.flags.par_chunks_mut(SLOT))
        .enumerate()
        .map(|(k, (((pick, verts), clips), flags))| {
            let area = pyramid.area(pick.level, pick.i, pick.j);
            let (nc, nr) = area.quads();
            let mut state = ChunkState::Direct;
            let (mut x0, mut x1) = (i32::MAX, i32::MIN);
            let mut nearest = f32::INFINITY;
            let mut any_drawable = false;
            let mut vrows = [(i32::MAX, i32::MIN); PITCH];
            for (qr, vrow) in vrows.iter_mut().enumerate().take(nr + 1) {
                let r = area.row(qr);
                for qc in 0..=nc {
                    let c = area.col(qc);
                    let g = r * cols + c;
                    let s = qr * PITCH + qc;
                    let h = heights[g];
                    if !h.is_finite() {
                        flags[s] = SKIP;
                        if state == ChunkState::Direct {
                            state = ChunkState::Mixed;
                        }
                        continue;
                    }
                    let v = affine.clip_vertex(c, r, h, light[g]);
                    clips[s] = v;
                    if v.inside(near) {
                        flags[s] = OK;
                        let p = transform::project(&v);
                        verts[s] = p;
                        x0 = x0.min(p.x);
                        x1 = x1.max(p.x);
                        vrow.0 = vrow.0.min(p.y);
                        vrow.1 = vrow.1.max(p.y);
                        nearest = nearest.min(v.w);
                        any_drawable = true;
                    } else {
                        flags[s] = CLIP;
                        state = ChunkState::Mixed;
                        any_drawable = true;
                        nearest = 0.0;
                    }
                }
            }
            let stitch = stitching(&area, levels.coarser(pick));
            let mut spans = [(viewport.y0, viewport.y1); NODE];
            let (mut y0, mut y1) = (i32::MAX, i32::MIN);
            for v in &vrows[..=nr] {
                y0 = y0.min(v.0);
                y1 = y1.max(v.1);
            }
            if nearest > 0.0 {
                for (qr, span) in spans.iter_mut().enumerate().take(nr) {
                    // A stitched side edge may reach back to an earlier row.
                    let first = usize::from(stitch[3][qr].min(stitch[1][qr])).min(qr);
                    let (lo, hi) = vrows[first..=qr + 1]
                        .iter()
                        .fold((i32::MAX, i32::MIN), |(lo, hi), v| (lo.min(v.0), hi.max(v.1)));
                    *span = if lo <= hi { (lo >> 8, (hi >> 8) + 1) } else { (0, 0) };
                }
            }
            let (bounds, state) = transform::screen_bounds(state, nearest, any_drawable, [x0, x1, y0, y1], viewport);
            NodeChunk {
                base: k * SLOT,
                nc,
                nr,
                bounds,
                state,
                near: nearest,
                spans,
                stitch,
            }
        })
        // Into last frame's list: a frame allocates nothing.
        .collect_into_vec(&mut out.chunks);
    out.chunks.retain(|c| c.state != ChunkState::Culled);
    out.chunks.sort_unstable_by(|a, b| a.near.total_cmp(&b.near));
}

/// Per edge (north, east, south, west), the sampled vertex each one is drawn with: where a
/// coarser neighbour of level `coarser[e]` lies across edge `e`, the vertex before it on that
/// neighbour's lattice (the grid's last column or row is on every lattice).
fn stitching(area: &super::Area, coarser: [Option<u32>; 4]) -> [[u8; PITCH]; 4] {
    let mut out = [[0u8; PITCH]; 4];
    let (nc, nr) = area.quads();
    for (e, (line, level)) in out.iter_mut().zip(coarser).enumerate() {
        let across_columns = e == 0 || e == 2;
        let (n, first, last) = if across_columns {
            (nc, area.c0, area.c1)
        } else {
            (nr, area.r0, area.r1)
        };
        for (k, slot) in line.iter_mut().enumerate().take(n + 1) {
            *slot = k as u8;
            let Some(level) = level else { continue };
            let at = (first + k * area.step).min(last);
            if at == last {
                continue;
            }
            let coarse = 1usize << level;
            let kept = at / coarse * coarse;
            *slot = ((kept.max(first) - first) / area.step) as u8;
        }
    }
    out
}

/// Draws the nodes' triangles over `bounds` into `sink`.
pub(crate) fn draw<S: Sink>(p: &Projected, near: f32, bounds: &Bounds, sink: &mut S) {
    let (v, f, cv) = (&p.vertices, &p.flags, &p.clip);
    for ch in &p.chunks {
        let b = &ch.bounds;
        if b.y1 <= bounds.y0 || b.y0 >= bounds.y1 || b.x1 <= bounds.x0 || b.x0 >= bounds.x1 {
            continue;
        }
        for (qr, span) in ch.spans.iter().enumerate().take(ch.nr) {
            if ch.state == ChunkState::Direct && (span.1 <= bounds.y0 || span.0 >= bounds.y1) {
                continue;
            }
            for qc in 0..ch.nc {
                // As the full grid: (a, b, d) and (b, e, d), split along b–d.
                let (a, bb, d, e) = (
                    ch.index(qc, qr),
                    ch.index(qc + 1, qr),
                    ch.index(qc, qr + 1),
                    ch.index(qc + 1, qr + 1),
                );
                if ch.state == ChunkState::Direct {
                    let (va, vb, vd, ve) = (&v[a], &v[bb], &v[d], &v[e]);
                    if rasterise::holds_no_pixel([va, vb, vd, ve], bounds) {
                        continue;
                    }
                    rasterise::triangle(va, vb, vd, bounds, sink);
                    rasterise::triangle(vb, ve, vd, bounds, sink);
                    continue;
                }
                for t in [[a, bb, d], [bb, e, d]] {
                    let flags = [f[t[0]], f[t[1]], f[t[2]]];
                    if flags.contains(&SKIP) {
                        continue;
                    }
                    if flags.contains(&CLIP) {
                        transform::draw_clipped([cv[t[0]], cv[t[1]], cv[t[2]]], near, bounds, sink);
                    } else {
                        rasterise::triangle(&v[t[0]], &v[t[1]], &v[t[2]], bounds, sink);
                    }
                }
            }
        }
    }
}
