//! Trees in the renderer: alpha-tested textured quads (the background shows through texels of
//! alpha 0; texture coordinates perspective-correct), the simplified shape's facing polygon, its
//! images against a render of the full group, and the level of detail per tree.

use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3};
use penmodel_render::impostor::{self, Side};
use penmodel_render::{Camera, Frame, Orbit, Renderer, Scene, View};
use penmodel_render::{Eye, Projection, Quad, Texture, Viewport};
use penmodel_terrain::Heightmap;
use penmodel_terrain::trees::nodes::STOP;
use penmodel_terrain::trees::{NodeTree, Preset, Roughness, Source, Species, Standing};

fn flat(n: u32, h: f32) -> Heightmap {
    Heightmap::from_heights(n, n, 1.0, vec![h; (n * n) as usize]).expect("heights")
}

/// An orbit camera at `azimuth` degrees, `elevation` degrees, `distance` from `target`.
fn orbit(target: [f64; 3], azimuth: f64, elevation: f64, distance: f64, fov: f64) -> Camera {
    Camera {
        view: View::Orbit(Orbit {
            target: [target[0], target[2]],
            target_height: target[1],
            azimuth: azimuth.to_radians(),
            elevation: elevation.to_radians(),
            distance,
            fov_y: fov.to_radians(),
            separation: 1.0 / 30.0,
        }),
        tilt: 0.0,
    }
}

fn projection(camera: &Camera, w: u32, h: u32) -> Projection {
    let vp = camera.viewpoint(Eye::Centre, f64::from(w) / f64::from(h));
    Projection::new(
        &vp,
        camera.tilt,
        Viewport {
            x: 0.0,
            y: 0.0,
            width: f64::from(w),
            height: f64::from(h),
        },
    )
}

const RED: [u8; 4] = [255, 0, 0, 255];

/// A 16 × 16 texture: opaque red left of column `split`, alpha 0 from it on (its colour white,
/// so a texel drawn by mistake would show).
fn half_texture(split: u32) -> Texture {
    let texels = (0..16 * 16)
        .map(|i| if i % 16 < split { RED } else { [255, 255, 255, 0] })
        .collect();
    Texture::new(16, 16, texels).expect("texture")
}

fn render(scene: &Scene, renderer: &mut Renderer, w: u32, h: u32) -> Frame {
    let mut frame = Frame::new(w, h).expect("frame");
    renderer.render(scene, &mut frame).expect("render");
    frame
}

#[test]
fn an_alpha_tested_quad_leaves_the_background_where_alpha_is_zero() {
    // A quad standing upright on flat ground, slanted 60° to the view so that perspective
    // matters: its texture's left half red, the right half transparent.
    let map = flat(64, 0.0);
    let camera = orbit([32.0, 4.5, 32.0], 0.0, 10.0, 12.0, 80.0);
    let (w, h) = (320, 240);
    let scene = Scene::new(&map, camera);
    let mut renderer = Renderer::new();
    let bare = render(&scene, &mut renderer, w, h);
    let (c, s) = (60f32.to_radians().cos(), 60f32.to_radians().sin());
    let at = |t: f32, y: f32| [32.0 + 8.0 * (t - 0.5) * c, y, 32.0 + 8.0 * (t - 0.5) * s];
    let quad = Quad {
        corners: [at(0.0, 8.0), at(1.0, 8.0), at(1.0, 1.0), at(0.0, 1.0)],
        uv: [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        texture: 0,
    };
    let (quads, textures) = ([quad], [half_texture(8)]);
    let with = Scene {
        polygons: &quads,
        textures: &textures,
        ..scene.clone()
    };
    let textured = render(&with, &mut renderer, w, h);
    let mut changed = 0;
    let p = projection(&scene.camera, w, h);
    // The texture's split (u = ½) is the 3D line through the quad's middle, projected.
    let mid_top = p.pixel(DVec3::from(at(0.5, 8.0).map(f64::from))).expect("in front");
    let mid_bottom = p.pixel(DVec3::from(at(0.5, 1.0).map(f64::from))).expect("in front");
    let left_top = p.pixel(DVec3::from(at(0.0, 8.0).map(f64::from))).expect("in front");
    let right_top = p.pixel(DVec3::from(at(1.0, 8.0).map(f64::from))).expect("in front");
    let screen_mid = 0.5 * (left_top[0] + right_top[0]);
    assert!(
        (screen_mid - mid_top[0]).abs() > 3.0,
        "the slant makes the screen midpoint differ from the 3D midpoint"
    );
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (a, b) = (bare.pixels()[i], textured.pixels()[i]);
            if a == b {
                continue;
            }
            changed += 1;
            assert_eq!(b, RED, "only the opaque red texels are drawn, at ({x}, {y})");
            // Left of the projected 3D midline (within a pixel), never right of it.
            let t = (y as f64 + 0.5 - mid_top[1]) / (mid_bottom[1] - mid_top[1]);
            let mid_x = mid_top[0] + t * (mid_bottom[0] - mid_top[0]);
            let lo = left_top[0].min(right_top[0]);
            let side = if right_top[0] > left_top[0] {
                x as f64 + 0.5 - mid_x
            } else {
                mid_x - x as f64 - 0.5
            };
            assert!(
                side < 1.5,
                "a red pixel at ({x}, {y}) beyond the texture's split at {mid_x:.1} (quad from {lo:.1})"
            );
        }
    }
    assert!(changed > 300, "{changed} pixels of the red half drawn");
    // A fully transparent texture changes nothing; the depth buffer is not written either, so
    // the terrain behind is unchanged (the same bytes).
    let clear_texture = [half_texture(0)];
    let clear = Scene {
        polygons: &quads,
        textures: &clear_texture,
        ..scene.clone()
    };
    let clear = render(&clear, &mut renderer, w, h);
    assert_eq!(clear.pixels(), bare.pixels());
}

#[test]
fn the_facing_polygon_flips_as_the_camera_moves_round() {
    let bounds = [Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 3.0, 1.0)];
    let id = DAffine3::IDENTITY;
    let cases = [
        (DVec3::new(0.0, 1.5, 10.0), Side::Front),
        (DVec3::new(10.0, 1.5, 1.0), Side::Right),
        (DVec3::new(1.0, 1.5, -10.0), Side::Back),
        (DVec3::new(-10.0, 1.5, -1.0), Side::Left),
    ];
    for (eye, side) in cases {
        assert_eq!(impostor::facing(&id, &bounds, eye), side, "eye at {eye}");
    }
    // Turned 90° about +Y, the node's +Z points along world +X: an eye on +X sees its front.
    let turned = DAffine3::from_rotation_y(std::f64::consts::FRAC_PI_2);
    assert_eq!(
        impostor::facing(&turned, &bounds, DVec3::new(10.0, 1.5, 0.0)),
        Side::Front
    );
    assert_eq!(
        impostor::facing(&turned, &bounds, DVec3::new(0.0, 1.5, 10.0)),
        Side::Left
    );
    // The chosen polygon faces the eye: its normal (from its corners) points within 45° of it.
    for (eye, _) in cases {
        let q = impostor::quad(&id, &bounds, impostor::facing(&id, &bounds, eye), 0);
        let [a, b, _, d] = q.corners.map(Vec3::from_array);
        let normal = (b - a).cross(d - a).normalize().as_dvec3();
        let to_eye = (eye - DVec3::new(0.0, 1.5, 0.0)).normalize();
        assert!(normal.dot(to_eye).abs() > 0.70, "eye {eye}: normal {normal}");
    }
}

/// A simplified shape's polygon is cut to the texels its image covers: the rectangle is the
/// opaque texels' bounding box (found here by scanning rows and columns), and the cut polygon
/// draws what the whole one draws (within a few pixels where the texture coordinates round
/// differently at a texel's edge); an empty image gives no polygon.
#[test]
fn a_simplified_shapes_polygon_is_cut_to_its_opaque_texels() {
    // Opaque red in columns 3..9 of rows 5..12, transparent elsewhere.
    let texels = (0..16 * 16)
        .map(|i| {
            let (x, y) = (i % 16, i / 16);
            if (3..9).contains(&x) && (5..12).contains(&y) {
                RED
            } else {
                [255, 255, 255, 0]
            }
        })
        .collect();
    let texture = Texture::new(16, 16, texels).expect("texture");
    let rows: Vec<usize> = (0..16)
        .filter(|y| (0..16).any(|x| texture.texels()[y * 16 + x][3] >= 128))
        .collect();
    let cols: Vec<usize> = (0..16)
        .filter(|x| (0..16).any(|y| texture.texels()[y * 16 + x][3] >= 128))
        .collect();
    let expected = [
        cols[0] as f32 / 16.0,
        rows[0] as f32 / 16.0,
        (cols[cols.len() - 1] + 1) as f32 / 16.0,
        (rows[rows.len() - 1] + 1) as f32 / 16.0,
    ];
    let crop = impostor::opaque(&texture).expect("some opaque texels");
    assert_eq!(crop, expected);
    assert_eq!(impostor::opaque(&half_texture(0)), None);

    // A box 8 m wide and 7 m tall standing on flat ground, its front polygon drawn whole and cut.
    let map = flat(64, 0.0);
    let camera = orbit([32.0, 4.5, 32.0], 20.0, 10.0, 14.0, 70.0);
    let (w, h) = (320, 240);
    let scene = Scene::new(&map, camera);
    let mut renderer = Renderer::new();
    let bounds = [Vec3::new(-4.0, 1.0, -1.0), Vec3::new(4.0, 8.0, 1.0)];
    let place = DAffine3::from_translation(DVec3::new(32.0, 0.0, 32.0));
    let whole = [impostor::quad(&place, &bounds, Side::Front, 0)];
    let cut = [impostor::quad_within(&place, &bounds, Side::Front, 0, crop)];
    let textures = [texture];
    let draw = |quads: &[Quad], renderer: &mut Renderer| {
        let with = Scene {
            polygons: quads,
            textures: &textures,
            ..scene.clone()
        };
        render(&with, renderer, w, h)
    };
    let bare = render(&scene, &mut renderer, w, h);
    let a = draw(&whole, &mut renderer);
    let b = draw(&cut, &mut renderer);
    let drawn = a.pixels().iter().zip(bare.pixels()).filter(|(x, y)| x != y).count();
    let differ = a.pixels().iter().zip(b.pixels()).filter(|(x, y)| x != y).count();
    assert!(drawn > 500, "{drawn} pixels of the red texels drawn");
    assert!(differ * 100 <= drawn, "{differ} of {drawn} pixels differ");
    // The cut polygon's area is the rectangle's share of the whole one's.
    let area = |q: &Quad| {
        let [p0, p1, _, p3] = q.corners.map(Vec3::from_array);
        (p1 - p0).cross(p3 - p0).length()
    };
    let share = (expected[2] - expected[0]) * (expected[3] - expected[1]);
    assert!((area(&cut[0]) / area(&whole[0]) - share).abs() < 1e-5);
}

fn standing(nodes: &Arc<NodeTree>, at: [f64; 2], height: f64) -> Standing {
    Standing {
        source: Source::Tree(0),
        at,
        base: 0.0,
        height,
        turn: 0.0,
        nodes: Arc::clone(nodes),
        wind: None,
    }
}

/// Pixels that differ from the background, as a mask.
fn mask(frame: &Frame, bare: &Frame) -> Vec<bool> {
    frame.pixels().iter().zip(bare.pixels()).map(|(a, b)| a != b).collect()
}

#[test]
fn a_simplified_shape_looks_like_the_full_group() {
    // One tree seen from the front, far away through a narrow field (nearly the parallel
    // projection the images were made with), drawn in full and as one simplified shape (Q = 1
    // makes the trunk's node, the whole tree, one shape). The silhouettes agree by
    // intersection over union ≥ 0.6 (measured 0.716: the 64-texel image is magnified and
    // twigs under a texel drop out).
    let nodes = Arc::new(NodeTree::build(&Species::preset(Preset::Table31)));
    let trees = [standing(&nodes, [32.0, 32.0], 10.0)];
    let map = flat(64, -50.0);
    let (w, h) = (240, 240);
    let camera = orbit([32.0, 5.0, 32.0], 0.0, 0.0, 400.0, 2.2);
    let mut scene = Scene::new(&map, camera);
    let mut renderer = Renderer::new();
    let bare = render(&scene, &mut renderer, w, h);
    scene.trees = &trees;
    scene.tree_lod = None;
    let full = mask(&render(&scene, &mut renderer, w, h), &bare);
    assert_eq!(renderer.tree_stats().impostors, 0);
    assert_eq!(renderer.tree_stats().polygons, nodes.polygons());
    scene.tree_lod = Some(Roughness {
        q0: 1.0,
        a: 0.0,
        n: 5.0,
    });
    let shape = mask(&render(&scene, &mut renderer, w, h), &bare);
    assert_eq!(renderer.tree_stats().impostors, 1);
    assert_eq!(renderer.tree_stats().polygons, 0);
    let both = full.iter().zip(&shape).filter(|(a, b)| **a && **b).count() as f64;
    let either = full.iter().zip(&shape).filter(|(a, b)| **a || **b).count() as f64;
    let (nf, ns) = (
        full.iter().filter(|a| **a).count(),
        shape.iter().filter(|a| **a).count(),
    );
    assert!(nf > 2000, "{nf} pixels of the full tree");
    let iou = both / either;
    assert!(iou >= 0.6, "IoU {iou:.3} (full {nf} px, shape {ns} px)");
}

#[test]
fn near_the_gaze_a_tree_is_full_and_far_in_the_periphery_it_is_simplified() {
    let nodes = Arc::new(NodeTree::build(&Species::preset(Preset::Table31)));
    let map = flat(256, 0.0);
    // Looking at a tree 30 m away (within B = 2·L0 of a 20 m tree).
    let camera = orbit([128.0, 10.0, 128.0], 0.0, 5.0, 30.0, 60.0);
    let near = [standing(&nodes, [128.0, 128.0], 20.0)];
    let mut scene = Scene::new(&map, camera);
    scene.trees = &near;
    let mut renderer = Renderer::new();
    render(&scene, &mut renderer, 160, 120);
    let stats = renderer.tree_stats();
    assert_eq!(stats.impostors, 0, "Q0 = {STOP} draws the full model");
    assert_eq!(stats.polygons, nodes.polygons());
    // The same tree 150 m away and 30° off the gaze: Q well above Q0, far fewer polygons.
    let off = 150.0 * 30f64.to_radians().sin();
    let far = [standing(
        &nodes,
        [128.0 + off, 158.0 - 150.0 * 30f64.to_radians().cos()],
        20.0,
    )];
    scene.trees = &far;
    render(&scene, &mut renderer, 160, 120);
    let lod = renderer.tree_stats();
    assert!(lod.impostors > 0);
    assert!(
        lod.total_polygons() * 10 < nodes.polygons(),
        "{lod:?} of {}",
        nodes.polygons()
    );
    // The pen's tip on that tree while modeling: the gaze turns to it, so only its distance
    // simplifies it, and it keeps several times the polygons it had in the periphery.
    let middle = [far[0].at[0], 10.0, far[0].at[1]];
    scene.looking_at = Some(middle);
    render(&scene, &mut renderer, 160, 120);
    let looked = renderer.tree_stats();
    assert!(
        looked.total_polygons() > 3 * lod.total_polygons(),
        "looked at {looked:?}, in the periphery {lod:?}"
    );
    let (eye, gaze) = penmodel_render::eye_and_gaze(&scene, 160.0 / 120.0);
    let to = (glam::DVec3::from_array(middle) - eye).normalize();
    assert!(gaze.dot(to) > 0.999_999, "gaze {gaze} towards {to}");
}

/// Draws `mesh` with `paint` into a 160 × 120 depth buffer seen by `camera`.
fn samples_of(
    mesh: &penmodel_terrain::export::Mesh,
    paint: penmodel_render::Paint,
    camera: &Camera,
) -> Vec<penmodel_render::Sample> {
    use penmodel_render::Affine;
    use penmodel_render::{Bounds, Sample};
    let (w, h) = (160u32, 120u32);
    let p = projection(camera, w, h);
    let affine = Affine::new(&p, 1.0, 1.0);
    let style = penmodel_render::Style::default();
    let mut projected = penmodel_render::ProjectedMeshes::default();
    projected.clear((h as usize, h as usize));
    projected.add([mesh], paint, &affine, 1.0, p.near as f32, &style);
    let mut samples = vec![Sample::default(); (w * h) as usize];
    let bounds = Bounds {
        x0: 0,
        x1: w as i32,
        y0: 0,
        y1: h as i32,
    };
    projected.draw(&bounds, &mut samples, w as usize, p.near as f32);
    samples
}

#[test]
fn a_branchs_frustum_is_drawn_from_its_front_only_with_the_same_pixels() {
    use penmodel_render::Paint;
    use penmodel_terrain::trees::shapes::{self, Parts};
    // A bark frustum, leaning towards the eye so that its open top shows, and a leaf.
    let mut parts = Parts::default();
    let lean = DAffine3::from_translation(DVec3::new(3.0, 0.5, 3.0)) * DAffine3::from_rotation_x(0.5);
    parts.branch(&lean, 3.0, 0.6, 0.4);
    parts.leaf(&DAffine3::from_translation(DVec3::new(4.5, 1.0, 3.0)), 1.0);
    let mesh = penmodel_terrain::export::Mesh {
        positions: parts.positions.clone(),
        normals: parts.normals.clone(),
        colors: parts.colors.clone(),
        indices: parts.indices.clone(),
    };
    let camera = orbit([3.0, 2.0, 3.0], 30.0, 8.0, 7.0, 45.0);
    let both = samples_of(&mesh, Paint::Own, &camera);
    let front = samples_of(&mesh, Paint::Tree, &camera);
    let drawn = both.iter().filter(|s| s.invw > 0.0).count();
    assert!(drawn > 500, "the frustum and the leaf cover {drawn} pixels");
    // Where the two differ, the two-sided draw shows a nearer surface: the inside of the tube
    // seen through its open top, whose back faces the front-only draw skips. Everywhere else
    // the same pixel, and from the side that is nearly everywhere.
    let differ: Vec<usize> = (0..both.len()).filter(|&i| both[i] != front[i]).collect();
    for &i in &differ {
        assert!(
            both[i].invw > front[i].invw,
            "pixel {i}: {:?} against {:?}",
            both[i],
            front[i]
        );
    }
    assert!(
        differ.len() * 10 < drawn,
        "{} of {drawn} pixels differ: more than the open top",
        differ.len()
    );
    // The frustum wound the other way round (inside out): the front-only draw then shows its far
    // wall from inside, farther than the two-sided draw's near wall in most of its pixels; so
    // the winding `Paint::Tree` takes for the front is the one the shapes use.
    let mut inside_out = mesh.clone();
    let bark = shapes::BRANCH_POLYGONS * 2 * 3;
    for t in inside_out.indices[..bark].chunks_exact_mut(3) {
        t.swap(1, 2);
    }
    let culled = samples_of(&inside_out, Paint::Tree, &camera);
    let farther = (0..both.len())
        .filter(|&i| both[i].invw > 0.0 && culled[i].invw < both[i].invw)
        .count();
    assert!(farther * 2 > drawn, "inside out: {farther} of {drawn} pixels farther");
}
