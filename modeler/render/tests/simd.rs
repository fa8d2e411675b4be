//! The per-pixel loops' two copies (`penmodel_render::simd`: baseline x86-64 and AVX2, chosen at
//! run time) draw the same bytes: the same scenes rendered with the baseline forced and with the
//! CPU's choice. On a machine without AVX2 both runs take the baseline and the test says so.

use std::sync::Arc;

use penmodel_render::simd;
use penmodel_render::{Frame, Renderer, Scene, Stereo, Style};
use penmodel_terrain::trees::{NodeTree, Preset, Roughness, Source, Species, Standing};

use super::common::{orbit, terrain};

/// Hills with a valley below sea level (water colours), trees near and far (copied polygons and
/// simplified shapes), seen low so that sky, table and far land show.
fn frames(stereo: Stereo, style: &Style) -> Vec<Frame> {
    let map = terrain(96, |x, y| 6.0 * (x * 0.15).sin() * (y * 0.11).cos() + 0.05 * x - 1.0);
    let nodes = Arc::new(NodeTree::build(&Species::preset(Preset::Table31)));
    let trees: Vec<Standing> = (0..8)
        .map(|k| Standing {
            source: Source::Tree(k),
            at: [20.0 + 8.0 * k as f64, 30.0 + 5.0 * k as f64],
            base: 4.0,
            height: 9.0,
            turn: k as f64,
            nodes: Arc::clone(&nodes),
            wind: None,
        })
        .collect();
    let mut scene = Scene::new(&map, orbit([48.0, 48.0], 30.0, 12.0, 110.0));
    scene.style = style.clone();
    scene.trees = &trees;
    scene.tree_lod = Some(Roughness::default());
    scene.stereo = stereo;
    let mut renderer = Renderer::new();
    // Two frames of the same view: the first computes the background per pixel, the second
    // reads it kept.
    (0..2)
        .map(|_| {
            let mut frame = Frame::new(320, 200).expect("frame");
            renderer.render(&scene, &mut frame).expect("render");
            frame
        })
        .collect()
}

#[test]
fn the_baseline_and_the_avx2_copies_draw_the_same_bytes() {
    println!("AVX2 copies on this CPU: {}", simd::has_avx2());
    for style in [Style::land(), Style::default()] {
        for stereo in [Stereo::None, Stereo::Anaglyph] {
            simd::force_baseline(true);
            let baseline = frames(stereo, &style);
            simd::force_baseline(false);
            let chosen = frames(stereo, &style);
            for (b, c) in baseline.iter().zip(&chosen) {
                let differ = b.pixels().iter().zip(c.pixels()).filter(|(x, y)| x != y).count();
                assert_eq!(differ, 0, "{:?}, {stereo:?}: pixels that differ", style.look);
            }
            // The scene shows something besides the sky: the comparison is not of two blanks.
            let first = baseline[0].pixels()[0];
            assert!(baseline[0].pixels().iter().any(|p| *p != first));
        }
    }
}
