//! The land look (issue 20): colours by height in metres and slope, cast shadows from a wall
//! measured against the shadow's length, the table beyond the terrain, and the maps kept and
//! remade as the terrain changes (a changed terrain renders as a fresh renderer renders it).

use glam::DVec3;
use penmodel_render::land::{self, Shore, material};
use penmodel_render::{Camera, Eye, Frame, Orbit, Projection, Renderer, Scene, Stereo, Style, View, Viewport};
use penmodel_terrain::Heightmap;

use crate::common::{self, orbit};

fn style() -> Style {
    Style::land()
}

fn luma(c: [f32; 3]) -> f32 {
    0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]
}

#[test]
fn snow_is_an_absolute_height_not_a_share_of_the_terrain() {
    let s = style();
    let snow = land::SNOW.map(f32::from);
    for (broad, fine) in [(0.0, 0.0), (0.5, 0.5), (0.99, 0.99)] {
        // A 70 m summit and a lowland are far from white; above the snow line on gentle ground is
        // within 12 of white in every channel (the fine noise moves brightness by at most 7 %·30 %).
        for h in [0.0, 70.0, 0.5 * s.snow_line] {
            let c = material(&s, h, 5.0, broad, fine, Shore::NONE);
            assert!(c.iter().zip(snow).any(|(a, b)| b - a > 60.0), "{h} m: {c:?}");
        }
        let c = material(&s, 1.2 * s.snow_line, 5.0, broad, fine, Shore::NONE);
        assert!(c.iter().zip(snow).all(|(a, b)| (a - b).abs() < 12.0), "{c:?}");
        // No snow lies on a 70° face: rock.
        let c = material(&s, 1.2 * s.snow_line, 70.0, broad, fine, Shore::NONE);
        assert!(luma(c) < 180.0, "{c:?}");
    }
}

#[test]
fn steep_faces_are_rock_and_gentle_ones_grass() {
    let s = style();
    for broad in [0.0, 0.3, 0.7, 0.99] {
        let grass = material(&s, 20.0, 3.0, broad, 0.5, Shore::NONE);
        let rock = material(&s, 20.0, s.rock_slope[1] + 4.0, broad, 0.5, Shore::NONE);
        // Grass is green (green above red and blue); rock is not (green at most red).
        assert!(grass[1] > grass[0] && grass[1] > grass[2], "{grass:?}");
        assert!(rock[1] <= rock[0], "{rock:?}");
        let expect = land::ROCK.map(f32::from);
        assert!(rock.iter().zip(expect).all(|(a, b)| (a - b).abs() < 8.0), "{rock:?}");
    }
}

#[test]
fn no_hard_bands_in_height_or_slope() {
    // A centimetre of height in the beach's band, a metre above it, or a tenth of a degree of
    // slope changes no channel by more than 2.
    let s = style();
    let heights = (0..500)
        .map(|i| i as f32 * 0.01)
        .chain((5..=(1.3 * s.snow_line) as i32).map(|i| i as f32));
    for shore in [Shore::NONE, Shore { near: 1.0, level: 0.0 }] {
        let mut last = material(&s, 0.0, 20.0, 0.4, 0.6, shore);
        for h in heights.clone() {
            let c = material(&s, h, 20.0, 0.4, 0.6, shore);
            assert!(
                c.iter().zip(last).all(|(a, b)| (a - b).abs() <= 2.0),
                "{h} m: {c:?} after {last:?}"
            );
            last = c;
        }
        let mut last = material(&s, 0.5, 0.0, 0.4, 0.6, shore);
        for i in 1..=900 {
            let c = material(&s, 0.5, i as f32 * 0.1, 0.4, 0.6, shore);
            assert!(
                c.iter().zip(last).all(|(a, b)| (a - b).abs() <= 2.0),
                "{i}: {c:?} after {last:?}"
            );
            last = c;
        }
    }
}

#[test]
fn a_beach_only_beside_water_and_just_above_its_level() {
    let s = style();
    let sand = land::SAND.map(f32::from);
    let near = |c: [f32; 3]| c.iter().zip(sand).all(|(a, b)| (a - b).abs() < 16.0);
    let sea = Shore { near: 1.0, level: 0.0 };
    assert!(near(material(&s, 0.2, 3.0, 0.5, 0.5, sea)));
    assert!(!near(material(&s, 0.2, 3.0, 0.5, 0.5, Shore::NONE)));
    // Above the band it is grass again; a river's beach is above the river's level.
    assert!(!near(material(&s, 3.0 * s.beach_height, 3.0, 0.5, 0.5, sea)));
    let river = Shore {
        near: 1.0,
        level: 400.0,
    };
    assert!(near(material(&s, 400.3, 3.0, 0.5, 0.5, river)));
    assert!(!near(material(&s, 0.3, 3.0, 0.5, 0.5, river)));
}

#[test]
fn value_noise_is_deterministic_and_continuous() {
    for i in 0..200 {
        let (x, y) = (i as f64 * 0.173, i as f64 * 0.091);
        let v = land::value_noise(x, y, 7);
        assert_eq!(v, land::value_noise(x, y, 7));
        assert!((0.0..1.0).contains(&v));
        assert!((v - land::value_noise(x + 1e-4, y, 7)).abs() < 1e-3);
    }
}

/// A camera straight above the middle of an `n`-metre square, looking down, north up.
fn overhead(n: f64) -> Camera {
    orbit([n / 2.0, n / 2.0], 0.0, 89.9, n * 1.4)
}

/// The pixel of ground point `(x, y)` at height `h`.
fn pixel(camera: &Camera, (w, h_px): (u32, u32), p: [f64; 3]) -> (usize, usize) {
    let vp = camera.viewpoint(Eye::Centre, f64::from(w) / f64::from(h_px));
    let proj = Projection::new(
        &vp,
        0.0,
        Viewport {
            x: 0.0,
            y: 0.0,
            width: f64::from(w),
            height: f64::from(h_px),
        },
    );
    let [px, py, _] = proj.pixel(DVec3::new(p[0], p[2], p[1])).expect("in front of the eye");
    (px as usize, py as usize)
}

fn brightness(frame: &Frame, (x, y): (usize, usize)) -> f32 {
    let p = frame.pixels()[y * frame.width() as usize + x];
    luma([f32::from(p[0]), f32::from(p[1]), f32::from(p[2])])
}

#[test]
fn a_wall_casts_a_shadow_as_long_as_its_height_over_the_suns_tangent() {
    // A wall 20 m high across a flat 128 m square (one-metre cells), columns 40 to 43; the sun
    // in the west (towards −x) at elevation atan(1/2): the shadow reaches 20·2 = 40 m east of the
    // wall's east face (x = 44), to x = 84.
    let n = 128u32;
    let heights = (0..n * n)
        .map(|i| if (40..44).contains(&(i % n)) { 20.0 } else { 0.0 })
        .collect();
    let map = Heightmap::from_heights(n, n, 1.0, heights).expect("heights");
    let camera = overhead(f64::from(n));
    let mut scene = Scene::new(&map, camera);
    scene.style = style();
    scene.style.light = [-1.0, 0.0, 0.5];
    scene.style.light_cells = 0;
    scene.style.haze = 0.0;
    let size = (480, 480);
    let mut frame = Frame::new(size.0, size.1).expect("frame");
    Renderer::new().render(&scene, &mut frame).expect("render");
    let at = |x: f64| brightness(&frame, pixel(&camera, size, [x, 64.0, 0.0]));
    let (west, shadow, east) = (at(20.0), [at(50.0), at(64.0), at(80.0)], at(100.0));
    // Flat ground has the same normal everywhere: lit ground west and far east alike (the noise
    // moves the colour by a few per cent), the shadow well under both.
    assert!((west - east).abs() < 0.15 * west, "{west} {east}");
    for s in shadow {
        assert!(s < 0.7 * west.min(east), "shadow {s}, lit {west} {east}");
    }
}

#[test]
fn the_table_surrounds_the_terrain_and_the_sky_is_above_the_horizon() {
    let n = 64u32;
    let map = Heightmap::from_heights(n, n, 1.0, vec![0.0; (n * n) as usize]).expect("heights");
    let camera = overhead(f64::from(n) * 1.6);
    let mut scene = Scene::new(
        &map,
        Camera {
            view: match camera.view {
                View::Orbit(o) => View::Orbit(Orbit {
                    target: [32.0, 32.0],
                    ..o
                }),
                v => v,
            },
            ..camera
        },
    );
    scene.style = style();
    scene.style.haze = 0.0;
    scene.style.table_margin = 0.25;
    let size = (400, 400);
    let mut frame = Frame::new(size.0, size.1).expect("frame");
    Renderer::new().render(&scene, &mut frame).expect("render");
    // 8 m beyond the west edge, within the 16 m table: the table's colour (lit, flat).
    let (x, y) = pixel(&scene.camera, size, [-8.0, 32.0, 0.0]);
    let p = frame.pixels()[y * size.0 as usize + x];
    let t = scene.style.table_colour;
    let k = f32::from(p[0]) / f32::from(t[0]);
    assert!(k > 0.5 && k <= 1.0, "{p:?}");
    for c in 1..3 {
        assert!(
            (f32::from(p[c]) - k * f32::from(t[c])).abs() < 3.0,
            "{p:?} against {t:?}"
        );
    }
    // A level view: the top row is the zenith's side of the gradient, bluer than the horizon.
    let level = Camera {
        view: View::Orbit(Orbit {
            target: [32.0, 32.0],
            target_height: 5.0,
            azimuth: 0.0,
            elevation: 0.0,
            distance: 200.0,
            fov_y: 60f64.to_radians(),
            separation: 1.0 / 30.0,
        }),
        tilt: 0.0,
    };
    scene.camera = level;
    Renderer::new().render(&scene, &mut frame).expect("render");
    let top = frame.pixels()[size.0 as usize / 2];
    let horizon = scene.style.sky_bottom;
    assert!(top[2] > top[0] && top[0] < horizon[0], "{top:?}");
}

#[test]
fn the_maps_are_kept_until_the_terrain_changes_and_then_match_a_fresh_render() {
    assert_eq!(style().light_lag, 2);
    let n = 96u32;
    let hill = |cx: f64, h: f64| {
        (0..n * n)
            .map(|i| {
                let (x, y) = (f64::from(i % n) + 0.5, f64::from(i / n) + 0.5);
                (h * (-((x - cx).powi(2) + (y - 48.0).powi(2)) / 300.0).exp()) as f32
            })
            .collect::<Vec<f32>>()
    };
    let a = Heightmap::from_heights(n, n, 1.0, hill(40.0, 30.0)).expect("heights");
    let mut changed = hill(40.0, 30.0);
    // A local change: a bump on the east.
    for r in 40..50 {
        for c in 70..80 {
            changed[r * n as usize + c] += 6.0;
        }
    }
    let b = Heightmap::from_heights(n, n, 1.0, changed).expect("heights");
    let camera = crate::common::above(f64::from(n));
    let mut renderer = Renderer::new();
    let mut frame = Frame::new(320, 200).expect("frame");
    let mut render = |map: &Heightmap, renderer: &mut Renderer| {
        let mut s = Scene::new(map, camera);
        s.style = style();
        renderer.render(&s, &mut frame).expect("render");
        frame.clone()
    };
    let first = render(&a, &mut renderer);
    assert_eq!(renderer.land_remakes(), 1);
    assert_eq!(render(&a, &mut renderer).pixels(), first.pixels());
    assert_eq!(renderer.land_remakes(), 1, "the same terrain: nothing remade");
    // The terrain moved since the last frame: the maps may lag it (Style::light_lag = 2)...
    render(&b, &mut renderer);
    assert_eq!(renderer.land_remakes(), 1);
    // ... and once it has stopped they are remade for it.
    let after = render(&b, &mut renderer);
    assert_eq!(renderer.land_remakes(), 2);
    let fresh = render(&b, &mut Renderer::new());
    assert_eq!(
        after.pixels(),
        fresh.pixels(),
        "a change renders as a fresh renderer renders it"
    );
    assert_ne!(after.pixels(), first.pixels());
    // And the same picture from tiles of 7 rows, up to rounding: the rasteriser's attributes
    // are stepped from each tile's first row, and an ulp can move a pixel's ground colour by one
    // (the classic ramp is smooth enough to hide it; a cell's colour is not).
    let tiled = render(&b, &mut Renderer::with_tile_rows(7));
    let off: Vec<(&[u8; 4], &[u8; 4])> = tiled
        .pixels()
        .iter()
        .zip(fresh.pixels())
        .filter(|(p, q)| p != q)
        .collect();
    assert!(off.len() * 1000 <= fresh.pixels().len(), "{} pixels differ", off.len());
    for (p, q) in off {
        assert!((0..3).all(|c| p[c].abs_diff(q[c]) <= 2), "{p:?} {q:?}");
    }
}

/// A terrain edited locally: two regions, the second small, with point figures.
fn edited_document() -> penmodel_terrain::Document {
    use penmodel_terrain::{Document, Figure, FigureKind, Grid, Region};
    let square = |x0: f64, y0: f64, x1: f64, y1: f64| vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]];
    let point = |x: f64, y: f64, height: f64| Figure {
        kind: FigureKind::Point,
        points: vec![[x, y]],
        height,
        slope: 0.0,
        figures: Vec::new(),
    };
    let mut doc = Document::new(Grid {
        cols: 120,
        rows: 120,
        cell_size: 2.0,
    });
    doc.regions.push(Region {
        boundary: square(4.0, 4.0, 150.0, 150.0),
        figures: vec![point(60.0, 70.0, 80.0), point(110.0, 40.0, 40.0)],
        metric: None,
    });
    doc.regions.push(Region {
        boundary: square(170.0, 20.0, 230.0, 90.0),
        figures: vec![point(200.0, 50.0, 30.0)],
        metric: None,
    });
    doc
}

#[test]
fn the_maps_follow_the_editors_revisions_and_equal_fresh_ones_exactly() {
    use penmodel_render::land::Land;
    use penmodel_terrain::{Edit, Editor, FigurePath};
    let camera = crate::common::above(240.0);
    for light_cells in [40, 0] {
        let mut editor = Editor::new(edited_document()).expect("valid");
        let mut style = style();
        style.light_cells = light_cells;
        let mut land = Land::default();
        let mut light = Vec::new();
        let mut renderer = Renderer::new();
        let mut frame = Frame::new(200, 160).expect("frame");
        fn scene<'a>(editor: &'a Editor, camera: Camera, style: &Style) -> Scene<'a> {
            let mut s = Scene::new(editor.heightmap(), camera);
            s.style = style.clone();
            s
        }
        fn tracked<'a>(editor: &'a Editor, camera: Camera, style: &Style) -> Scene<'a> {
            let mut s = scene(editor, camera, style);
            s.revisions = Some(editor.revisions());
            s
        }
        land.prepare(&tracked(&editor, camera, &style), &mut light);
        renderer
            .render(&tracked(&editor, camera, &style), &mut frame)
            .expect("render");
        let cells = 120 * 120;
        let everything = land.remade();
        assert_eq!(
            [everything.coloured, everything.relit],
            [cells as u64; 2],
            "the first frame makes everything"
        );
        let remakes = land.remakes();
        land.prepare(&tracked(&editor, camera, &style), &mut light);
        assert_eq!(land.remakes(), remakes, "an unchanged terrain: nothing remade");
        // Local edits, a frame after each (some of them lag: Style::light_lag), then frames
        // of the still terrain until the maps have caught up.
        let small = FigurePath::new(1, 0);
        let edits = [
            Edit::SetHeight {
                at: small.clone(),
                height: 45.0,
            },
            Edit::MoveFigure {
                at: small.clone(),
                by: [6.0, -4.0],
            },
            Edit::SetHeight {
                at: small.clone(),
                height: 20.0,
            },
            Edit::SetHeight {
                at: FigurePath::new(0, 1),
                height: 55.0,
            },
        ];
        let mut remade = Vec::new();
        for edit in edits {
            editor.apply(edit).expect("applies");
            let before = land.remakes();
            for _ in 0..=style.light_lag {
                land.prepare(&tracked(&editor, camera, &style), &mut light);
                renderer
                    .render(&tracked(&editor, camera, &style), &mut frame)
                    .expect("render");
            }
            assert_eq!(land.remakes(), before + 1, "remade once the terrain stood still");
            remade.push(land.remade());
        }
        // The small region's edits recolour less than a fifth of the grid (the sky light may
        // change across the grid: a hill changes the horizon of all that see it).
        assert!(remade[..3].iter().all(|r| r.coloured * 5 < cells as u64), "{remade:?}");
        let mut fresh = Land::default();
        let mut fresh_light = Vec::new();
        fresh.prepare(&scene(&editor, camera, &style), &mut fresh_light);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
        assert_eq!(bits(&light), bits(&fresh_light), "light, {light_cells} light cells");
        let albedo = |l: &Land| l.albedo().iter().flatten().map(|x| x.to_bits()).collect::<Vec<u32>>();
        assert_eq!(albedo(&land), albedo(&fresh), "colours, {light_cells} light cells");
        let mut other = Frame::new(200, 160).expect("frame");
        Renderer::new()
            .render(&scene(&editor, camera, &style), &mut other)
            .expect("render");
        assert_eq!(frame.pixels(), other.pixels(), "{light_cells} light cells");
    }
}

#[test]
fn the_maps_follow_changes_to_the_edge_of_the_rectangle_told() {
    use penmodel_render::land::Land;
    use penmodel_terrain::rect::Rect;
    use penmodel_terrain::revision::Revisions;
    let n = 90u32;
    let mut heights: Vec<f32> = (0..n * n)
        .map(|i| {
            let (x, y) = (f64::from(i % n), f64::from(i / n));
            (20.0 * (-((x - 40.0).powi(2) + (y - 50.0).powi(2)) / 400.0).exp()) as f32
        })
        .collect();
    let mut revisions = Revisions::new();
    let mut land = Land::default();
    let mut light = Vec::new();
    let mut s = style();
    s.light_cells = 30;
    s.light_lag = 0;
    let camera = crate::common::above(f64::from(n));
    // Bumps whose changed cells fill the rectangle told, up to its edges.
    for (k, (c0, r0, w, h)) in [(10u32, 12u32, 7u32, 5u32), (60, 3, 4, 9), (33, 70, 1, 1), (0, 0, 3, 3)]
        .into_iter()
        .enumerate()
    {
        let map = Heightmap::from_heights(n, n, 1.0, heights.clone()).expect("heights");
        let mut scene = Scene::new(&map, camera);
        scene.style = s.clone();
        scene.revisions = Some(&revisions);
        land.prepare(&scene, &mut light);
        for r in r0..r0 + h {
            for c in c0..c0 + w {
                heights[(r * n + c) as usize] += 3.0 + (k as f32) + (c % 3) as f32;
            }
        }
        revisions.record(Rect {
            c0,
            r0,
            width: w,
            height: h,
        });
    }
    let map = Heightmap::from_heights(n, n, 1.0, heights).expect("heights");
    let mut scene = Scene::new(&map, camera);
    scene.style = s.clone();
    scene.revisions = Some(&revisions);
    land.prepare(&scene, &mut light);
    scene.revisions = None;
    let (mut fresh, mut fresh_light) = (Land::default(), Vec::new());
    fresh.prepare(&scene, &mut fresh_light);
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
    assert_eq!(bits(&light), bits(&fresh_light));
    let albedo = |l: &Land| l.albedo().iter().flatten().map(|x| x.to_bits()).collect::<Vec<u32>>();
    assert_eq!(albedo(&land), albedo(&fresh));
}

#[test]
fn the_classic_light_is_kept_for_an_unchanged_revision_and_remade_after_an_edit() {
    use penmodel_terrain::{Edit, Editor, FigurePath};
    let camera = crate::common::above(240.0);
    let mut editor = Editor::new(edited_document()).expect("valid");
    let mut renderer = Renderer::new();
    let mut frame = Frame::new(160, 120).expect("frame");
    let mut render = |editor: &Editor, renderer: &mut Renderer, tracked: bool| {
        let mut s = Scene::new(editor.heightmap(), camera);
        s.revisions = tracked.then(|| editor.revisions());
        renderer.render(&s, &mut frame).expect("render");
        frame.clone()
    };
    let first = render(&editor, &mut renderer, true);
    assert_eq!(render(&editor, &mut renderer, true).pixels(), first.pixels());
    for height in [45.0, 12.0] {
        editor
            .apply(Edit::SetHeight {
                at: FigurePath::new(1, 0),
                height,
            })
            .expect("applies");
        let after = render(&editor, &mut renderer, true);
        assert_ne!(after.pixels(), first.pixels());
        assert_eq!(after.pixels(), render(&editor, &mut Renderer::new(), false).pixels());
    }
}

#[test]
fn a_still_views_kept_background_equals_the_one_computed_per_pixel() {
    // While the view moves the shading computes the background of the empty pixels only; once it
    // stays, the whole background is made and kept. Every frame of a still view, mono and
    // stereo, is then the same as the first.
    let n = 64u32;
    let map = common::terrain(n, |x, y| 4.0 * ((x / 9.0).sin() + (y / 13.0).cos()));
    for stereo in [Stereo::None, Stereo::Anaglyph, Stereo::SideBySide] {
        // Low over the terrain: sky, far land, table and the model's side all show.
        let mut scene = Scene::new(&map, orbit([32.0, 32.0], 20.0, 12.0, 110.0));
        scene.style = style();
        scene.stereo = stereo;
        let mut renderer = Renderer::new();
        let mut frames = Vec::new();
        for _ in 0..4 {
            let mut frame = Frame::new(320, 200).expect("frame");
            renderer.render(&scene, &mut frame).expect("render");
            frames.push(frame);
        }
        let sky = frames[0].pixels().iter().filter(|p| p[2] > p[0] + 20).count();
        assert!(sky > 1000, "{sky} sky pixels");
        for (i, f) in frames.iter().enumerate().skip(1) {
            assert!(f == &frames[0], "{stereo:?}: frame {i} differs from the first");
        }
    }
}

/// A frame latched to the tracked head prepares the terrain before it takes the pose
/// (`Renderer::prepare_terrain`); its frames and the maps' remakes are those of frames that do
/// not, through a pull (the maps lag it) and after it stops.
#[test]
fn preparing_the_terrain_first_changes_neither_the_frames_nor_the_lag() {
    use penmodel_terrain::{Edit, Editor, FigurePath};
    let camera = crate::common::above(240.0);
    let mut editor = Editor::new(edited_document()).expect("valid");
    let (mut plain, mut first) = (Renderer::new(), Renderer::new());
    let (mut a, mut b) = (
        Frame::new(160, 120).expect("frame"),
        Frame::new(160, 120).expect("frame"),
    );
    fn tracked(editor: &Editor, camera: penmodel_render::Camera) -> Scene<'_> {
        let mut s = Scene::new(editor.heightmap(), camera);
        s.style = style();
        s.revisions = Some(editor.revisions());
        s
    }
    // A pull: the height changes frame after frame, then stands still for a few frames.
    let heights = [22.0, 26.0, 30.0, 34.0, 38.0, 42.0];
    for frame in 0..heights.len() + 4 {
        if let Some(&height) = heights.get(frame) {
            let at = FigurePath::new(1, 0);
            editor.apply(Edit::SetHeight { at, height }).expect("applies");
        }
        plain.render(&tracked(&editor, camera), &mut a).expect("render");
        first.prepare_terrain(&tracked(&editor, camera));
        first.render(&tracked(&editor, camera), &mut b).expect("render");
        assert!(a.pixels() == b.pixels(), "frame {frame}: the frames differ");
        assert_eq!(plain.land_remakes(), first.land_remakes(), "frame {frame}");
    }
    // The pull lagged: fewer remakes than frames that changed.
    assert!(
        plain.land_remakes() < heights.len() as u64 + 1,
        "{}",
        plain.land_remakes()
    );
}
