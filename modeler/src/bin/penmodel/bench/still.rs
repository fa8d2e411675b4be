//! `penmodel bench`'s still frames (issue 18): the frame time of a terrain that does not change
//! while the view turns, with the terrain's level of detail off (every cell) and on, mono and
//! stereo — what a frame costs once the pen stops pulling, and what the head's movement costs.
//!
//! - Terrain: example 1 on N × N cells (the bench's document) up to 1024²; above that the
//!   1024² terrain resampled bilinearly with two octaves of value noise (8 m and 2 m across,
//!   ±0.6 m and ±0.15 m) added, since the engine of example 1 on 4096² would need gigabytes; the same 320 m square.
//! - View: the bench's overview (azimuth 30°, elevation 35°), the azimuth turning 0.1° a frame so
//!   every frame is drawn anew (the land look's background too); 1280 × 720; the stereo frames are
//!   the anaglyph (two eyes).
//! - The scene carries a terrain history that never changes, as a live session's does, so neither
//!   the level-of-detail pyramid nor the land look's maps are remade between frames.

use std::time::Instant;

use anyhow::{Context, Result};
use penmodel_render::{Camera, Frame, Renderer, Scene, Stereo};
use penmodel_terrain::revision::Revisions;
use penmodel_terrain::{Editor, Heightmap};

/// Untimed frames first (the pyramid, the land maps).
const WARM_UP: usize = 2;

/// One still-frame figure.
pub struct Still {
    pub grid: u32,
    pub lod_error: f32,
    pub stereo: bool,
    pub frame_ms: f64,
    /// Terrain nodes drawn per level in the last frame (level 0 first); empty at full detail.
    pub levels: Vec<usize>,
}

/// The terrain of `n` × `n` cells.
pub fn terrain(n: u32) -> Result<Heightmap> {
    if n <= 1024 {
        return Ok(Editor::new(super::document(n)?)?.heightmap().clone());
    }
    let base = Editor::new(super::document(1024)?)?.heightmap().clone();
    let k = f64::from(n) / 1024.0;
    let b = base.heights();
    let cell = base.cell_size() / k;
    let at = |c: usize, r: usize| f64::from(b[r.min(1023) * 1024 + c.min(1023)]);
    let mut heights = Vec::with_capacity(n as usize * n as usize);
    for r in 0..n {
        let v = ((f64::from(r) + 0.5) / k - 0.5).max(0.0);
        let (r0, fv) = (v as usize, v.fract());
        for c in 0..n {
            let u = ((f64::from(c) + 0.5) / k - 0.5).max(0.0);
            let (c0, fu) = (u as usize, u.fract());
            let top = at(c0, r0) + fu * (at(c0 + 1, r0) - at(c0, r0));
            let bottom = at(c0, r0 + 1) + fu * (at(c0 + 1, r0 + 1) - at(c0, r0 + 1));
            // Metres on the ground: hummocks of 8 m and 2 m.
            let (x, y) = (f64::from(c) * cell, f64::from(r) * cell);
            let detail = 1.2 * (f64::from(penmodel_render::land::value_noise(x / 8.0, y / 8.0, 7)) - 0.5)
                + 0.3 * (f64::from(penmodel_render::land::value_noise(x / 2.0, y / 2.0, 11)) - 0.5);
            heights.push((top + fv * (bottom - top) + detail) as f32);
        }
    }
    Heightmap::from_heights(n, n, cell, heights).context("the resampled terrain")
}

/// Times `frames` still frames of `map` at `lod_error` pixels (0: full detail); the last one is
/// written to `png` if given.
pub fn measure(
    map: &Heightmap,
    lod_error: f32,
    stereo: bool,
    look: crate::render::LookArg,
    frames: usize,
    png: Option<&std::path::Path>,
) -> Result<Still> {
    let extent = [
        map.cell_size() * f64::from(map.cols()),
        map.cell_size() * f64::from(map.rows()),
    ];
    let history = Revisions::new();
    let mut renderer = Renderer::new();
    let mut frame = Frame::new(super::FRAME.0, super::FRAME.1)?;
    let mut times = Vec::with_capacity(frames);
    for i in 0..WARM_UP + frames {
        let azimuth = 30.0 + 0.1 * i as f64;
        let camera = Camera::overview(extent, azimuth.to_radians(), 35f64.to_radians());
        let mut scene = Scene::new(map, camera);
        scene.revisions = Some(&history);
        scene.terrain_lod = lod_error;
        scene.stereo = if stereo { Stereo::Anaglyph } else { Stereo::None };
        scene.style = super::style(look);
        let t = Instant::now();
        renderer.render(&scene, &mut frame)?;
        if i >= WARM_UP {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    if let Some(path) = png {
        penmodel_render::output::png::write_png(&frame, path).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(Still {
        grid: map.cols(),
        lod_error,
        stereo,
        frame_ms: super::median(times),
        levels: renderer.lod_levels(),
    })
}
