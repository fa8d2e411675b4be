//! Water in the renderer (issue 13): a river's flat surface drawn in the water colour above the
//! bed it covers, hidden where the ground stands above it.

use penmodel_render::{Frame, Renderer, Scene};
use penmodel_terrain::Heightmap;
use penmodel_terrain::river::layer::Water;

use crate::common::{above, lit_pixels};

/// Pixels of the water colour's hue (lit: the colour times a light from 0.2 to 1).
fn water_pixels(frame: &Frame, colour: [u8; 4]) -> usize {
    lit_pixels(frame, colour, 2)
}

#[test]
fn water_is_drawn_flat_in_its_colour_where_it_lies_above_the_ground() {
    let n = 64u32;
    // Ground at 5 m with a 2 m deep channel along rows 28..36; water at 4 m over the channel and,
    // as a check of the depth test, over a patch of rows 8..12 where the ground (5 m) is above it
    // (away from the grid's edge, where the squares reach half a cell past the terrain's mesh).
    let heights: Vec<f32> = (0..n * n)
        .map(|i| if (28..36).contains(&(i / n)) { 3.0 } else { 5.0 })
        .collect();
    let map = Heightmap::from_heights(n, n, 1.0, heights).expect("heights");
    let level: Vec<f32> = (0..n * n)
        .map(|i| {
            if (28..36).contains(&(i / n)) || ((8..12).contains(&(i / n)) && (8..56).contains(&(i % n))) {
                4.0
            } else {
                f32::NAN
            }
        })
        .collect();
    let water = Water {
        cols: n,
        rows: n,
        lake: vec![false; level.len()],
        level,
    };
    let meshes = vec![("water".to_string(), water.mesh(1.0))];
    let mut scene = Scene::new(&map, above(f64::from(n)));
    let colour = scene.style.water_colour;
    let render = |scene: &Scene| {
        let mut frame = Frame::new(320, 240).expect("frame");
        Renderer::with_tile_rows(16).render(scene, &mut frame).expect("render");
        frame
    };
    assert_eq!(water_pixels(&render(&scene), colour), 0, "no water without a mesh");
    scene.water = &meshes;
    let frame = render(&scene);
    let wet = water_pixels(&frame, colour);
    // The 8-row channel of 64 seen from above over most of the frame's height: thousands of
    // pixels; the buried strip adds none (the ground hides it), so fewer than two strips' worth.
    assert!(wet > 1500, "{wet} water pixels");
    let channel_only = {
        let level: Vec<f32> = (0..n * n)
            .map(|i| if (28..36).contains(&(i / n)) { 4.0 } else { f32::NAN })
            .collect();
        let w = Water {
            cols: n,
            rows: n,
            lake: vec![false; level.len()],
            level,
        };
        let m = vec![("water".to_string(), w.mesh(1.0))];
        scene.water = &m;
        water_pixels(&render(&scene), colour)
    };
    assert_eq!(wet, channel_only, "water under the ground is hidden");
}
