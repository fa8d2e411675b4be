//! Rock meshes in the renderer: drawn in the rock colour where they stand, hidden behind a
//! nearer hill, and the same picture from one tile or many.

use penmodel_render::{Frame, Renderer, Scene};
use penmodel_terrain::Heightmap;
use penmodel_terrain::export::Mesh;
use penmodel_terrain::rocks::place::normals;

use crate::common::{above, lit_pixels};

/// A square pyramid (a rock) of half-width `r` and height `h` at `(x, z)` on the ground `g`.
fn pyramid(x: f32, z: f32, r: f32, h: f32, g: f32) -> Mesh {
    let positions = vec![
        [x - r, g, z - r],
        [x + r, g, z - r],
        [x + r, g, z + r],
        [x - r, g, z + r],
        [x, g + h, z],
    ];
    // Counter-clockwise seen from above (+Y) in the exports' frame: X right, Z towards the viewer.
    let indices = vec![0, 4, 1, 1, 4, 2, 2, 4, 3, 3, 4, 0];
    let normals = normals(&positions, &indices);
    Mesh {
        positions,
        normals,
        indices,
        colors: Vec::new(),
    }
}

fn flat(n: u32, h: f32) -> Heightmap {
    Heightmap::from_heights(n, n, 1.0, vec![h; (n * n) as usize]).expect("heights")
}

/// Lit rock: a grey of the rock colour's hue, within its brightness.
fn rock_pixels(frame: &Frame, colour: [u8; 4]) -> usize {
    lit_pixels(frame, colour, 0)
}

#[test]
fn a_rock_is_drawn_in_its_colour_where_it_stands() {
    let map = flat(64, 0.0);
    let rocks = vec![("rocks 0".to_string(), pyramid(32.0, 32.0, 6.0, 8.0, 0.0))];
    let mut scene = Scene::new(&map, above(64.0));
    let colour = scene.style.rock_colour;
    let render = |scene: &Scene, tiles: usize| {
        let mut frame = Frame::new(320, 240).expect("frame");
        Renderer::with_tile_rows(tiles)
            .render(scene, &mut frame)
            .expect("render");
        frame
    };
    let bare = render(&scene, 32);
    assert_eq!(rock_pixels(&bare, colour), 0, "no rock without a mesh");
    scene.rocks = &rocks;
    let with = render(&scene, 32);
    let n = rock_pixels(&with, colour);
    // A 12 m square seen from 96 m over a 45° field of view covers a few thousand pixels.
    assert!(n > 1000, "{n} rock pixels");
    // The centre of the frame looks at the rock.
    let centre = with.pixels()[120 * 320 + 160];
    let mut one = Frame::new(1, 1).expect("frame");
    one.pixels_mut()[0] = centre;
    assert_eq!(rock_pixels(&one, colour), 1, "{centre:?}");
    // Tiles do not change the picture.
    assert_eq!(render(&scene, 1).pixels(), with.pixels());
    // Buried under a plateau higher than its top, the rock is not seen.
    let high = flat(64, 10.0);
    let mut buried = Scene::new(&high, above(64.0));
    buried.rocks = &rocks;
    assert_eq!(rock_pixels(&render(&buried, 32), colour), 0);
}
