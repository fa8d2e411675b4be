//! The pictures of docs/renderer.md's "Level of detail" (issue 18): example 1 on 1024² cells seen
//! by the bench's overview (1280 × 720, land look), at full detail and at 1 pixel of error, and a
//! map of the levels chosen (the grid from above, each node filled by its level's colour).
//!
//! `cargo run --release -p penmodel-render --example lod_pictures -- OUT_DIR`

use std::path::PathBuf;

use penmodel_render::output::write_png;
use penmodel_render::{Camera, Frame, Renderer, Scene, Style};
use penmodel_terrain::{Document, Editor};

/// Level colours, level 0 first (then repeating).
const COLOURS: [[u8; 4]; 7] = [
    [215, 48, 39, 255],
    [252, 141, 89, 255],
    [254, 224, 139, 255],
    [217, 239, 139, 255],
    [145, 207, 96, 255],
    [26, 152, 80, 255],
    [69, 117, 180, 255],
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(std::env::args().nth(1).ok_or("usage: lod_pictures OUT_DIR")?);
    let mut doc = Document::from_json(include_str!("../../examples/01-ridges-and-peaks.json"))?;
    let extent = doc.grid.width();
    doc.grid.cols = 1024;
    doc.grid.rows = 1024;
    doc.grid.cell_size = extent / 1024.0;
    let editor = Editor::new(doc)?;
    let map = editor.heightmap();
    let camera = Camera::overview([extent, extent], 30f64.to_radians(), 35f64.to_radians());
    let mut scene = Scene::new(map, camera);
    scene.style = Style::land();
    let mut renderer = Renderer::new();
    let mut full = Frame::new(1280, 720)?;
    scene.terrain_lod = 0.0;
    renderer.render(&scene, &mut full)?;
    let mut lod = Frame::new(1280, 720)?;
    scene.terrain_lod = 1.0;
    renderer.render(&scene, &mut lod)?;
    write_png(&full, &out.join("lod-full.png"))?;
    write_png(&lod, &out.join("lod-1px.png"))?;
    let (mad, psnr) = full.difference(&lod).ok_or("sizes")?;
    let over = full
        .pixels()
        .iter()
        .zip(lod.pixels())
        .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > 24))
        .count() as f64
        / full.pixels().len() as f64;
    println!(
        "full vs 1 px: mean {mad:.3}/255 per channel, PSNR {psnr:.1} dB, {:.3} % of pixels off by > 24 levels; nodes per level {:?}",
        over * 100.0,
        renderer.lod_levels()
    );

    // The levels from above: 1 pixel per 2 cells.
    let side = 512u32;
    let mut levels = Frame::new(side, side)?;
    let k = f64::from(side) / f64::from(map.cols());
    let picks: Vec<_> = renderer.lod_picks().to_vec();
    let pyramid = renderer.pyramid();
    let px = levels.pixels_mut();
    px.fill([40, 40, 40, 255]);
    for p in &picks {
        let a = pyramid.area(p.level, p.i, p.j);
        let (x0, x1) = (
            (a.c0 as f64 * k) as usize,
            ((a.c1 as f64 * k) as usize).min(side as usize - 1),
        );
        let (y0, y1) = (
            (a.r0 as f64 * k) as usize,
            ((a.r1 as f64 * k) as usize).min(side as usize - 1),
        );
        let colour = COLOURS[p.level as usize % COLOURS.len()];
        for y in y0..=y1 {
            for x in x0..=x1 {
                let edge = x == x0 || y == y0;
                px[y * side as usize + x] = if edge { [30, 30, 30, 255] } else { colour };
            }
        }
    }
    write_png(&levels, &out.join("lod-levels.png"))?;
    Ok(())
}
