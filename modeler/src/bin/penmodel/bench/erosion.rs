//! `penmodel bench --erosion`: the fluvial erosion's time per step (`docs/erosion.md`), on the
//! surface `scripts/erosion_peer.py` gives fastscapelib: an N × N grid of 10 m cells, a cone
//! `h = 0.25·N·10 m · max(0, 1 − d/(0.45·N cells))` around the grid's middle, the default
//! settings (noise and seed included) for `--erosion-steps` steps.

use std::time::Instant;

use anyhow::{Context, Result};
use penmodel_terrain::{Fluvial, Heightmap, fluvial};

/// The bench's surface on an `n × n` grid (the peer script computes the same).
pub fn cone(n: u32) -> Result<Heightmap> {
    let cell = 10.0f64;
    let mid = (f64::from(n) - 1.0) / 2.0;
    let (radius, top) = (0.45 * f64::from(n), 0.25 * f64::from(n) * cell);
    let heights = (0..n * n)
        .map(|i| {
            let (c, r) = (f64::from(i % n) - mid, f64::from(i / n) - mid);
            (top * (1.0 - c.hypot(r) / radius)).max(0.0) as f32
        })
        .collect();
    Heightmap::from_heights(n, n, cell, heights).context("the bench's grid")
}

/// One grid's figures.
pub struct Figures {
    pub grid: u32,
    pub ms_per_step: f64,
    pub steps: u32,
}

/// Times `steps` steps on each grid: the best of three runs' mean per step.
pub fn measure(grids: &[u32], steps: u32, bar: &indicatif::ProgressBar) -> Result<Vec<Figures>> {
    let settings = Fluvial {
        steps,
        ..Fluvial::default()
    };
    let mut out = Vec::new();
    for &n in grids {
        let sketch = cone(n)?;
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let mut model = fluvial::Model::new(settings, &sketch);
            let t = Instant::now();
            while !model.finished() {
                model.advance(1);
                bar.inc(1);
            }
            best = best.min(t.elapsed().as_secs_f64() * 1e3 / f64::from(steps));
        }
        out.push(Figures {
            grid: n,
            ms_per_step: best,
            steps,
        });
    }
    Ok(out)
}
