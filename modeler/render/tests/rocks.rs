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

/// The seed's fig. 1 field (256 × 256 cells of 0.25 m) on flat ground, as the renderer gets it.
fn field() -> Mesh {
    use penmodel_terrain::rocks::{Recipe, place, scatter};
    let recipe = Recipe::figure_1(256, 256, 7);
    let scatter = scatter(&recipe, None).expect("scatter");
    let at = place::Placement {
        origin: [16.0, 16.0],
        cell_size: 0.125,
    };
    place::mesh(&scatter, at, |_, _| 0.0)
}

#[test]
fn rocks_under_the_level_of_detail_error_are_drawn_as_quads_and_look_the_same() {
    let map = flat(64, 0.0);
    let rocks = vec![("rocks 0".to_string(), field())];
    let triangles = rocks[0].1.indices.len() / 3;
    let render = |lod: f32, distance: f64| {
        let mut scene = Scene::new(&map, crate::common::orbit([32.0, 32.0], 20.0, 50.0, distance));
        scene.rocks = &rocks;
        scene.terrain_lod = lod;
        let mut frame = Frame::new(640, 360).expect("frame");
        Renderer::new().render(&scene, &mut frame).expect("render");
        frame
    };
    // Far: the field's rocks are a pixel or two across.
    let (whole, simplified) = (render(0.0, 120.0), render(1.0, 120.0));
    let (mean, psnr) = whole.difference(&simplified).expect("same size");
    // Measured: 0.32 of 255 and 38.3 dB (the terrain's own level of detail included), 9717 and
    // 9738 rock pixels, 40 281 of 168 892 triangles.
    assert!(mean < 0.6 && psnr > 35.0, "mean {mean}, PSNR {psnr} dB");
    let colour = Scene::new(&map, above(64.0)).style.rock_colour;
    let (a, b) = (rock_pixels(&whole, colour), rock_pixels(&simplified, colour));
    assert!(
        a > 1000 && b.abs_diff(a) * 50 < a,
        "rock pixels {a} whole, {b} simplified"
    );
    // What was drawn: 2 triangles for a simplified rock; near, every rock is many pixels across
    // and drawn whole.
    let drawn = |lod: f32, distance: f64| {
        use penmodel_render::{Affine, Eye, ProjectedMeshes, Projection, Viewport};
        let camera = crate::common::orbit([32.0, 32.0], 20.0, 50.0, distance);
        let viewport = Viewport {
            x: 0.0,
            y: 0.0,
            width: 640.0,
            height: 360.0,
        };
        let projection = Projection::new(&camera.viewpoint(Eye::Centre, 640.0 / 360.0), 0.0, viewport);
        let affine = Affine::new(&projection, 1.0, 1.0);
        let mut projected = ProjectedMeshes::default();
        projected.clear((360, 16));
        let style = Scene::new(&map, camera).style;
        projected.add_rocks(
            rocks.iter().map(|(_, m)| m),
            lod,
            &affine,
            1.0,
            projection.near as f32,
            &style,
        );
        projected.triangles()
    };
    assert_eq!(drawn(0.0, 120.0), triangles);
    assert_eq!(drawn(1.0, 6.0), triangles);
    let far = drawn(1.0, 120.0);
    assert!(far * 3 < triangles, "{far} of {triangles} triangles drawn far away");
}
