//! Tiles: one eye's frame rendered in parallel, tile by tile.
//!
//! A tile is a band of whole rows, so its pixels are a contiguous slice that rayon hands to
//! threads without locks or `unsafe`. Its depth samples are its thread's: one tile's worth,
//! reused tile after tile, so that they stay in the thread's cache (a whole frame's did not).
//! Each tile clears its samples, draws the chunks whose screen bounds reach it (near to far),
//! resolves colours and draws the overlays. A triangle that spans two tiles is set up in both and
//! each draws only its own rows, so the image does not depend on the tile height (a test renders
//! with one tile and with many and compares the bytes). Chunks carry the pixel rows of each row
//! of quads, so a tile skips the quad rows of a chunk that cannot reach it: that took the
//! triangles looked at per 512² frame from 2.2 to 1.5 times the grid's (instructions per frame
//! 345M → 311M).

use std::cell::RefCell;

use rayon::prelude::*;

use crate::lod::nodes;
use crate::output::frame::Rgba;
use crate::raster::rasterise::{self, Bounds, Capsule, Sample, Sink};
use crate::raster::transform::{self, Affine, ChunkState, Projected};
use crate::scene::Style;
use crate::shade::{self, Shading};
use penmodel_terrain::Heightmap;

/// What the tiles of one eye share.
#[allow(missing_docs)] // fields named for what they hold.
pub(crate) struct EyePass<'a> {
    pub map: &'a Heightmap,
    /// Per-vertex light.
    pub light: &'a [f32],
    /// The eye's clip-space map.
    pub affine: &'a Affine,
    /// The eye's projected grid and chunks.
    pub projected: &'a Projected,
    /// The eye's level-of-detail nodes, drawn instead of the grid's chunks when given.
    pub nodes: Option<&'a nodes::Projected>,
    /// The near plane.
    pub near: f32,
    /// The eye's columns.
    pub viewport: Bounds,
}

impl EyePass<'_> {
    fn clipped<S: Sink>(&self, corners: [(usize, usize); 3], bounds: &Bounds, sink: &mut S) {
        let cols = self.map.cols() as usize;
        let h = self.map.heights();
        let tri = corners.map(|(c, r)| {
            let k = r * cols + c;
            self.affine.clip_vertex(c, r, h[k], self.light[k])
        });
        transform::draw_clipped(tri, self.near, bounds, sink);
    }

    /// Draws the terrain's triangles over `bounds` into `sink`.
    pub(crate) fn terrain<S: Sink>(&self, bounds: &Bounds, sink: &mut S) {
        if let Some(nodes) = self.nodes {
            nodes::draw(nodes, self.near, bounds, sink);
            return;
        }
        let cols = self.map.cols() as usize;
        let v = &self.projected.vertices;
        let f = &self.projected.flags;
        for ch in &self.projected.chunks {
            let b = &ch.bounds;
            if b.y1 <= bounds.y0 || b.y0 >= bounds.y1 || b.x1 <= bounds.x0 || b.x0 >= bounds.x1 {
                continue;
            }
            if ch.state == ChunkState::Direct {
                for (r, span) in (ch.r0..ch.r1).zip(&ch.spans) {
                    if span.1 <= bounds.y0 || span.0 >= bounds.y1 {
                        continue;
                    }
                    for a in r * cols + ch.c0..r * cols + ch.c1 {
                        // Two triangles per quad, split along b–d, clockwise on screen seen from
                        // above: (a, b, d) and (b, e, d) with b = a + 1, d = a + cols, e = d + 1.
                        let (va, vb, vd, ve) = (&v[a], &v[a + 1], &v[a + cols], &v[a + cols + 1]);
                        if rasterise::holds_no_pixel([va, vb, vd, ve], bounds) {
                            continue;
                        }
                        rasterise::triangle(va, vb, vd, bounds, sink);
                        rasterise::triangle(vb, ve, vd, bounds, sink);
                    }
                }
                continue;
            }
            for r in ch.r0..ch.r1 {
                for c in ch.c0..ch.c1 {
                    let a = r * cols + c;
                    let (bb, d, e) = (a + 1, a + cols, a + cols + 1);
                    for (t, corners) in [
                        ([a, bb, d], [(c, r), (c + 1, r), (c, r + 1)]),
                        ([bb, e, d], [(c + 1, r), (c + 1, r + 1), (c, r + 1)]),
                    ] {
                        let flags = [f[t[0]], f[t[1]], f[t[2]]];
                        if flags.contains(&transform::SKIP) {
                            continue;
                        }
                        if flags.contains(&transform::CLIP) {
                            self.clipped(corners, bounds, sink);
                        } else {
                            rasterise::triangle(&v[t[0]], &v[t[1]], &v[t[2]], bounds, sink);
                        }
                    }
                }
            }
        }
    }
}

thread_local! {
    /// This thread's tile of samples, the depth buffer of the tile it draws (cleared by each).
    /// Reused tile after tile and frame after frame, it stays in the thread's cache; a whole
    /// frame's samples (14.7 MB at 1280 × 720) did not, and every tile fetched its own from
    /// memory and wrote them back. One tile's worth per pool thread: 655 KB at 1280 × 32.
    static TILE: RefCell<Vec<Sample>> = const { RefCell::new(Vec::new()) };
}

/// Renders one eye into the `viewport` columns of `pixels` (a frame `width` wide and
/// `frame_height` tall), `tile_rows` rows per tile, each tile with its thread's samples as the
/// depth buffer; the meshes and the textured polygons are each in parts, drawn in turn. With
/// `depths` (a frame's worth), each pixel's `1/w` is kept there too (0: no surface), for the
/// reprojection of a held frame.
#[allow(clippy::too_many_arguments)]
pub(crate) fn render(
    pass: &EyePass,
    meshes: &[crate::scene::meshes::Projected],
    (textured, textures): (
        &[crate::raster::textured::Projected],
        &[&crate::raster::textured::Texture],
    ),
    capsules: &[Capsule],
    shading: &Shading,
    style: &Style,
    pixels: &mut [Rgba],
    depths: Option<&mut [f32]>,
    width: usize,
    tile_rows: usize,
) {
    let frame_height = pixels.len() / width;
    let tile = tile_rows.max(1) * width;
    let vp = pass.viewport;
    let (x0, x1) = (vp.x0 as usize, vp.x1 as usize);
    let draw = |i: usize, pix: &mut [Rgba], depth: Option<&mut [f32]>| {
        let y0 = i * tile_rows.max(1);
        let rows = pix.len() / width;
        let bounds = Bounds {
            x0: vp.x0,
            x1: vp.x1,
            y0: y0 as i32,
            y1: (y0 + rows) as i32,
        };
        let draw_in = |smp: &mut [Sample]| {
            // Only the depth marks a sample empty: every reader looks at `invw` first, and a
            // surface that wins a sample writes all of it (one store a sample, where the whole
            // sample took three).
            for row in smp.chunks_mut(width) {
                row[x0..x1].iter_mut().for_each(|s| s.invw = 0.0);
            }
            let mut sink = rasterise::DepthSink {
                samples: smp,
                width,
                y0: bounds.y0,
                surface: rasterise::Surface::Terrain,
            };
            pass.terrain(&bounds, &mut sink);
            // Part after part: the scene's order ([`crate::Renderer`] projects them in parts).
            for part in meshes {
                part.draw(&bounds, smp, width, pass.near);
            }
            for part in textured {
                part.draw(&bounds, smp, width, pass.near, textures);
            }
            shade::resolve(smp, pix, width, (x0, x1), y0, frame_height, shading, style);
            let (top, bottom) = (bounds.y0 as f32, bounds.y1 as f32);
            for cap in capsules {
                let (lo, hi) = cap.rows();
                if hi >= top && lo < bottom {
                    cap.draw(&bounds, width, smp, pix, style.overlay_bias);
                }
            }
            if let Some(depth) = depth {
                for (d, s) in depth.chunks_mut(width).zip(smp.chunks(width)) {
                    for (d, s) in d[x0..x1].iter_mut().zip(&s[x0..x1]) {
                        *d = s.invw;
                    }
                }
            }
        };
        let n = rows * width;
        TILE.with(|cell| match cell.try_borrow_mut() {
            Ok(mut smp) => {
                if smp.len() < n {
                    smp.resize(n, Sample::default());
                }
                draw_in(&mut smp[..n]);
            }
            // Taken further up this thread's stack (a tile's draw waited and the pool gave the
            // thread another): samples of its own.
            Err(_) => draw_in(&mut vec![Sample::default(); n]),
        });
    };
    match depths {
        Some(depths) => pixels
            .par_chunks_mut(tile)
            .zip(depths.par_chunks_mut(tile))
            .enumerate()
            .for_each(|(i, (pix, depth))| draw(i, pix, Some(depth))),
        None => pixels
            .par_chunks_mut(tile)
            .enumerate()
            .for_each(|(i, pix)| draw(i, pix, None)),
    }
}

/// Counts the terrain's coverage of each pixel of the viewport (no depth test).
pub(crate) fn coverage(pass: &EyePass, counts: &mut [u16], width: usize, tile_rows: usize) {
    let tile = tile_rows.max(1) * width;
    counts.par_chunks_mut(tile).enumerate().for_each(|(i, cnt)| {
        let y0 = (i * tile_rows.max(1)) as i32;
        let bounds = Bounds {
            x0: pass.viewport.x0,
            x1: pass.viewport.x1,
            y0,
            y1: y0 + (cnt.len() / width) as i32,
        };
        let mut sink = rasterise::CountSink { counts: cnt, width, y0 };
        pass.terrain(&bounds, &mut sink);
    });
}
