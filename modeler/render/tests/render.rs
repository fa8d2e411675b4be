//! The renderer checked by properties of fixed scenes, not by golden images: depth, overlays,
//! colour, coverage, clipping, stereo, tiles, degenerate input, and the 2D layer.

use glam::DVec3;
use penmodel_render::{
    self, BarLayout, Camera, Eye, Frame, Orbit, Overlay, Projection, RenderError, Renderer, Scene, SlopeBar, Stereo,
    Tracked, View, Viewpoint, Viewport,
};
use penmodel_terrain::Heightmap;

use crate::common::{orbit, terrain};
use proptest::prelude::*;

const MAGENTA: [u8; 4] = [255, 0, 255, 255];

fn render(scene: &Scene, w: u32, h: u32) -> Frame {
    let mut frame = Frame::new(w, h).unwrap();
    Renderer::new().render(scene, &mut frame).unwrap();
    frame
}

fn bump(x: f64, y: f64, cx: f64, cy: f64, r: f64, h: f64) -> f64 {
    let d = ((x - cx).powi(2) + (y - cy).powi(2)).sqrt();
    if d < r { h * (1.0 - d / r) } else { 0.0 }
}

fn differing(a: &Frame, b: &Frame) -> Vec<bool> {
    a.pixels().iter().zip(b.pixels()).map(|(p, q)| p != q).collect()
}

#[test]
fn a_near_peak_hides_a_far_one() {
    // Seen from the south, low: the near peak (larger y) stands in front of the taller far one.
    let near = |x: f64, y: f64| bump(x, y, 64.0, 84.0, 14.0, 30.0);
    let far = |x: f64, y: f64| bump(x, y, 64.0, 44.0, 14.0, 40.0);
    let cam = orbit([64.0, 64.0], 0.0, 12.0, 150.0);
    let (w, h) = (320, 180);
    let flat = terrain(128, |_, _| 0.0);
    let only_near = terrain(128, near);
    let only_far = terrain(128, far);
    let both = terrain(128, |x, y| near(x, y) + far(x, y));
    let [f0, fnear, ffar, fboth] = [&flat, &only_near, &only_far, &both].map(|t| render(&Scene::new(t, cam), w, h));
    let p_near = differing(&f0, &fnear);
    let p_far = differing(&f0, &ffar);
    let mut overlap = 0;
    let mut far_visible = 0;
    for i in 0..p_near.len() {
        if p_near[i] && p_far[i] {
            overlap += 1;
            assert_eq!(
                fboth.pixels()[i],
                fnear.pixels()[i],
                "pixel {i}: the far peak shows through"
            );
        } else if p_far[i] && fboth.pixels()[i] == ffar.pixels()[i] {
            far_visible += 1;
        }
    }
    assert!(overlap > 300, "the peaks overlap on screen in {overlap} pixels only");
    assert!(far_visible > 100, "the far peak's top should show above the near one");
}

fn overlay(points: Vec<[f64; 2]>, height: Option<f64>) -> Overlay {
    Overlay {
        points,
        closed: false,
        colour: MAGENTA,
        width: 3.0,
        height,
    }
}

fn magenta(frame: &Frame) -> Vec<usize> {
    (0..frame.pixels().len())
        .filter(|&i| frame.pixels()[i] == MAGENTA)
        .collect()
}

#[test]
fn overlays_are_drawn_on_top_and_hidden_behind_a_ridge() {
    // A ridge along x at y = 60; the camera looks from the south, low.
    let ridge = terrain(128, |_, y| bump(0.0, y, 0.0, 60.0, 10.0, 35.0));
    let flat = terrain(128, |_, _| 0.0);
    let cam = orbit([64.0, 64.0], 0.0, 15.0, 150.0);
    let front = [overlay(vec![[30.0, 100.0], [98.0, 100.0]], None)];
    let behind = [overlay(vec![[40.0, 45.0], [88.0, 45.0]], None)];
    let above = [overlay(vec![[40.0, 60.0], [88.0, 60.0]], Some(45.0))];
    let shot = |map: &Heightmap, ov: &[Overlay]| {
        let mut s = Scene::new(map, cam);
        s.overlays = ov;
        magenta(&render(&s, 320, 180))
    };
    // In front of the ridge, on flat ground: the same pixels with or without the ridge.
    let a = shot(&ridge, &front);
    assert!(a.len() > 150, "front line: {} pixels", a.len());
    assert_eq!(a, shot(&flat, &front));
    // Behind it: visible on flat ground, hidden by the ridge.
    let b_flat = shot(&flat, &behind);
    assert!(
        b_flat.len() > 100,
        "behind line on flat ground: {} pixels",
        b_flat.len()
    );
    assert_eq!(shot(&ridge, &behind), Vec::<usize>::new());
    // Held above the ridge's crest (a figure being pulled): visible.
    assert!(shot(&ridge, &above).len() > 100);
}

#[test]
fn draped_lines_follow_a_slope_facing_the_camera() {
    // A line across the south face of a hill, draped: every pixel of it passes the depth test,
    // so it shows as a continuous band (each screen column it spans has a magenta pixel).
    let hill = terrain(128, |x, y| bump(x, y, 64.0, 64.0, 40.0, 30.0));
    let cam = orbit([64.0, 64.0], 0.0, 25.0, 140.0);
    let ov = [overlay(vec![[44.0, 84.0], [84.0, 84.0]], None)];
    let mut s = Scene::new(&hill, cam);
    s.overlays = &ov;
    let f = render(&s, 320, 180);
    let cols: Vec<u32> = magenta(&f).iter().map(|&i| i as u32 % 320).collect();
    let (lo, hi) = (*cols.iter().min().unwrap(), *cols.iter().max().unwrap());
    assert!(hi - lo > 40, "the line spans {} columns", hi - lo);
    for x in lo..=hi {
        assert!(cols.contains(&x), "gap in the draped line at column {x}");
    }
}

fn mean(p: [u8; 4]) -> f64 {
    (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0
}

#[test]
fn colour_follows_height() {
    // A plane rising along x from −20 m to 100 m, seen from straight above.
    let map = terrain(120, |x, _| x - 20.0);
    let mut s = Scene::new(&map, orbit([60.0, 60.0], 0.0, 90.0, 600.0));
    s.style.ramp_top = 100.0;
    s.style.ramp_depth = 20.0;
    let f = render(&s, 300, 300);
    let vp = s.camera.viewpoint(Eye::Centre, 1.0);
    let proj = Projection::new(
        &vp,
        0.0,
        Viewport {
            x: 0.0,
            y: 0.0,
            width: 300.0,
            height: 300.0,
        },
    );
    let at = |x: f64| {
        let [px, py, _] = proj.pixel(DVec3::new(x, x - 20.0, 60.0)).unwrap();
        f.pixel(px as u32, py as u32).unwrap()
    };
    let water = at(10.0); // −10 m
    let grass = at(35.0); // 15 m
    let snow = at(117.0); // 97 m
    assert!(
        water[2] > water[0] && water[2] > water[1],
        "below sea level is blue: {water:?}"
    );
    assert!(
        grass[1] > grass[0] && grass[1] > grass[2],
        "low land is green: {grass:?}"
    );
    assert!(
        mean(snow) > 150.0 && mean(snow) > mean(grass) + 60.0,
        "high land is snow: {snow:?}"
    );
    assert!(snow[0].abs_diff(snow[2]) < 20, "snow is grey-white: {snow:?}");
}

#[test]
fn lit_slopes_are_brighter_than_shadowed_ones() {
    // A roof along y: the west face looks at the light from the west, the east face away from it.
    let roof = terrain(120, |x, _| 40.0 - (x - 60.0).abs() * 0.6);
    let mut s = Scene::new(&roof, orbit([60.0, 60.0], 0.0, 90.0, 200.0));
    s.style.light = [-1.0, 0.0, 1.0];
    s.style.ramp_top = 100.0;
    let f = render(&s, 300, 300);
    let vp = s.camera.viewpoint(Eye::Centre, 1.0);
    let proj = Projection::new(
        &vp,
        0.0,
        Viewport {
            x: 0.0,
            y: 0.0,
            width: 300.0,
            height: 300.0,
        },
    );
    for d in [10.0, 20.0, 30.0] {
        let pixel = |x: f64| {
            let [px, py, _] = proj.pixel(DVec3::new(x, 40.0 - (x - 60.0).abs() * 0.6, 60.0)).unwrap();
            f.pixel(px as u32, py as u32).unwrap()
        };
        let (west, east) = (pixel(60.0 - d), pixel(60.0 + d));
        assert!(
            mean(west) > mean(east) + 20.0,
            "west {west:?} vs east {east:?} at ±{d} m"
        );
    }
}

/// Where the ray through pixel centre `(px, py)` meets the ground plane y = 0, or `None`.
fn ground_hit(vp: &Viewpoint, w: u32, h: u32, px: f64, py: f64) -> Option<DVec3> {
    let across = vp.lower_right - vp.lower_left;
    let up = vp.upper_left - vp.lower_left;
    let on_screen = vp.lower_left + across * (px / f64::from(w)) + up * (1.0 - py / f64::from(h));
    let dir = on_screen - vp.eye;
    let t = -vp.eye.y / dir.y;
    (t > 0.0 && t.is_finite()).then(|| vp.eye + dir * t)
}

/// Renders the coverage of a flat `n × n` plane and checks that every pixel whose ray meets the
/// plane inside the grid of cell centres (by more than `margin` metres) is covered once, every
/// pixel whose ray misses it by more than the margin none, and no pixel more than once.
fn check_flat_coverage(camera: Camera, n: u32, (w, h): (u32, u32)) -> usize {
    let map = terrain(n, |_, _| 0.0);
    let scene = Scene::new(&map, camera);
    let counts = Renderer::with_tile_rows(7).coverage(&scene, w, h).unwrap();
    let vp = camera.viewpoint(Eye::Centre, f64::from(w) / f64::from(h));
    let (lo, hi) = (0.5, f64::from(n) - 0.5);
    let near = vp.near;
    let mut inside = 0;
    for y in 0..h {
        for x in 0..w {
            let c = counts[(y * w + x) as usize];
            assert!(c <= 1, "pixel ({x}, {y}) covered {c} times");
            let Some(p) = ground_hit(&vp, w, h, f64::from(x) + 0.5, f64::from(y) + 0.5) else {
                assert_eq!(c, 0, "pixel ({x}, {y}) looks at the sky but is covered");
                continue;
            };
            let margin = 1e-3 * (p - vp.eye).length().max(1.0);
            let d = (p.x - lo).min(hi - p.x).min(p.z - lo).min(hi - p.z);
            let too_near = (p - vp.eye).length() < near * 4.0;
            if d > margin && !too_near {
                assert_eq!(c, 1, "pixel ({x}, {y}) inside the plane (at {p}) is not covered");
                inside += 1;
            } else if d < -margin {
                assert_eq!(c, 0, "pixel ({x}, {y}) outside the plane (at {p}) is covered");
            }
        }
    }
    inside
}

#[test]
fn a_flat_plane_is_covered_exactly_once() {
    for (az, el, dist) in [
        (0.0, 90.0, 90.0),
        (30.0, 35.0, 70.0),
        (-70.0, 12.0, 60.0),
        (200.0, 55.0, 40.0),
    ] {
        let inside = check_flat_coverage(orbit([32.0, 32.0], az, el, dist), 64, (240, 135));
        assert!(inside > 3000, "only {inside} pixels inside at az {az} el {el}");
    }
}

#[test]
fn near_plane_clipping_keeps_the_plane_watertight() {
    // The eye 0.4 m above a plane that extends behind it: triangles cross the near plane and the
    // guard band, and are cut, not dropped.
    let inside = check_flat_coverage(orbit([30.0, 30.0], 10.0, 4.0, 5.0), 64, (240, 135));
    assert!(inside > 8000, "only {inside} pixels of the plane covered");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    #[test]
    fn coverage_is_exact_from_any_viewpoint(
        az in -180.0f64..180.0, el in 5.0f64..89.0, dist in 3.0f64..120.0, tx in 5.0f64..27.0, ty in 5.0f64..27.0,
    ) {
        check_flat_coverage(orbit([tx, ty], az, el, dist), 32, (96, 64));
    }
}

#[test]
fn a_camera_inside_the_terrain_renders_cleanly() {
    let hills = terrain(64, |x, y| 20.0 * ((x / 7.0).sin() * (y / 9.0).cos()) + 5.0);
    for cam in [
        // Below the surface, inside the terrain's bounding box.
        Camera {
            view: View::Orbit(Orbit {
                target_height: -3.0,
                ..orbit_params([32.0, 32.0], 40.0, 10.0, 0.5)
            }),
            tilt: 0.0,
        },
        // Skimming the surface.
        orbit([20.0, 20.0], 120.0, 1.0, 0.05),
        // Very close, steeply down.
        orbit([32.0, 32.0], 0.0, 80.0, 0.01),
    ] {
        let s = Scene::new(&hills, cam);
        let f = render(&s, 200, 120);
        assert!(f.pixels().iter().all(|p| p[3] == 255), "every pixel is drawn");
        let counts = Renderer::new().coverage(&s, 200, 120).unwrap();
        assert!(counts.iter().all(|&c| c <= 2), "no runaway coverage");
    }
}

fn orbit_params(target: [f64; 2], azimuth: f64, elevation: f64, distance: f64) -> Orbit {
    match orbit(target, azimuth, elevation, distance).view {
        View::Orbit(o) => o,
        View::Tracked(_) => unreachable!(),
    }
}

#[test]
fn anaglyph_takes_red_from_the_left_eye_and_cyan_from_the_right() {
    let hill = terrain(64, |x, y| bump(x, y, 32.0, 32.0, 20.0, 15.0));
    let mut s = Scene::new(&hill, orbit([32.0, 32.0], 20.0, 30.0, 60.0));
    s.stereo = Stereo::Anaglyph;
    let (w, h) = (200, 120);
    let mut r = Renderer::new();
    let mut left = Frame::new(w, h).unwrap();
    let mut right = Frame::new(w, h).unwrap();
    r.render_eye(&s, Eye::Left, &mut left).unwrap();
    r.render_eye(&s, Eye::Right, &mut right).unwrap();
    assert_ne!(left, right, "the eyes see different images");
    let a = render(&s, w, h);
    for ((p, l), q) in a.pixels().iter().zip(left.pixels()).zip(right.pixels()) {
        assert_eq!(p[0], penmodel_render::luma(*l));
        assert_eq!([p[1], p[2]], [q[1], q[2]]);
    }
}

/// Mean column of the magenta pixels of columns `x0..x1`, relative to `x0`.
fn magenta_x(f: &Frame, x0: u32, x1: u32) -> f64 {
    let xs: Vec<f64> = magenta(f)
        .iter()
        .map(|&i| i as u32 % f.width())
        .filter(|x| (x0..x1).contains(x))
        .map(|x| f64::from(x - x0) + 0.5)
        .collect();
    assert!(!xs.is_empty(), "no marker in columns {x0}..{x1}");
    xs.iter().sum::<f64>() / xs.len() as f64
}

#[test]
fn side_by_side_halves_differ_by_the_expected_parallax() {
    // Dots on the orbit camera's axis: at the target (zero parallax), nearer (crossed), farther
    // (uncrossed). Eye separation e, screen at the target's distance D: a point at depth d has
    // parallax e·(1 − D/d) on the screen, which spans the frame's aspect in each half.
    let flat = terrain(64, |_, _| -50.0);
    let o = Orbit {
        separation: 0.05,
        ..orbit_params([32.0, 32.0], 0.0, 30.0, 60.0)
    };
    let (w, h) = (400, 200);
    let cam = Camera {
        view: View::Orbit(o),
        tilt: 0.0,
    };
    let vp = cam.viewpoint(Eye::Centre, f64::from(w) / f64::from(h));
    let forward = (DVec3::new(o.target[0], o.target_height, o.target[1]) - vp.eye).normalize();
    let screen_width = (vp.lower_right - vp.lower_left).length();
    for d in [30.0, 60.0, 90.0] {
        let p = vp.eye + forward * d;
        let dot = [Overlay {
            points: vec![[p.x, p.z]],
            closed: false,
            colour: MAGENTA,
            width: 2.0,
            height: Some(p.y),
        }];
        let mut s = Scene::new(&flat, cam);
        s.overlays = &dot;
        s.stereo = Stereo::SideBySide;
        let f = render(&s, w, h);
        let (xl, xr) = (magenta_x(&f, 0, w / 2), magenta_x(&f, w / 2, w));
        let expected = o.separation * o.distance * (1.0 - o.distance / d) * f64::from(w / 2) / screen_width;
        assert!(
            (xr - xl - expected).abs() < 0.75,
            "depth {d}: parallax {} px, expected {expected} px",
            xr - xl
        );
    }
}

#[test]
fn the_tracked_view_maps_the_display_onto_the_frame_from_any_head_position() {
    // The off-axis projection: whatever the head position, the display's corners are the frame's
    // corners, and a point on the display surface is seen at the same pixel by both eyes.
    let t = Tracked::fit([1.6, 0.9], [320.0, 180.0], 0.7);
    for head in [[0.0, 0.0, 0.7], [0.5, -0.3, 0.4], [-0.8, 0.6, 1.5]] {
        let cam = Camera {
            view: View::Tracked(Tracked { head, ..t }),
            tilt: 0.0,
        };
        let vport = Viewport {
            x: 0.0,
            y: 0.0,
            width: 1600.0,
            height: 900.0,
        };
        let left = Projection::new(&cam.viewpoint(Eye::Left, 16.0 / 9.0), 0.0, vport);
        let right = Projection::new(&cam.viewpoint(Eye::Right, 16.0 / 9.0), 0.0, vport);
        for (ground, pixel) in [
            ([0.0, 0.0], [0.0, 0.0]),
            ([320.0, 180.0], [1600.0, 900.0]),
            ([0.0, 180.0], [0.0, 900.0]),
        ] {
            for p in [&left, &right] {
                let [x, y, _] = p.pixel(DVec3::new(ground[0], 0.0, ground[1])).unwrap();
                assert!(
                    (x - pixel[0]).abs() < 1e-6 && (y - pixel[1]).abs() < 1e-6,
                    "{head:?}: {x}, {y}"
                );
            }
        }
        // Above the display (towards the viewer): crossed parallax, the left eye's image to the right.
        let above = DVec3::new(160.0, 40.0, 90.0);
        let (l, r) = (left.pixel(above).unwrap(), right.pixel(above).unwrap());
        assert!(l[0] > r[0], "{head:?}: {l:?} {r:?}");
    }
}

#[test]
fn tilting_shows_heights_in_profile_and_keeps_the_shading() {
    let cam = orbit([32.0, 32.0], 0.0, 60.0, 80.0);
    let tilted = Camera {
        tilt: 25f64.to_radians(),
        ..cam
    };
    let vport = Viewport {
        x: 0.0,
        y: 0.0,
        width: 320.0,
        height: 180.0,
    };
    let height_on_screen = |c: &Camera| {
        let p = Projection::new(&c.viewpoint(Eye::Centre, 16.0 / 9.0), c.tilt, vport);
        let (base, top) = (
            p.pixel(DVec3::new(32.0, 0.0, 32.0)).unwrap(),
            p.pixel(DVec3::new(32.0, 20.0, 32.0)).unwrap(),
        );
        base[1] - top[1]
    };
    assert!(height_on_screen(&tilted) > height_on_screen(&cam) * 1.2);
    // The view changes; the flat ground keeps its colour (light fixed to the terrain).
    let flat = terrain(64, |_, _| 0.0);
    let (a, b) = (
        render(&Scene::new(&flat, cam), 320, 180),
        render(&Scene::new(&flat, tilted), 320, 180),
    );
    let ground = |f: &Frame| -> std::collections::BTreeSet<[u8; 4]> {
        f.pixels()
            .iter()
            .filter(|p| p[0] > 150 && p[2] < 170)
            .copied()
            .collect()
    };
    assert_ne!(a, b);
    assert_eq!(ground(&a), ground(&b));
}

#[test]
fn tiles_do_not_change_the_image() {
    let map = terrain(96, |x, y| {
        bump(x, y, 40.0, 50.0, 30.0, 25.0) + bump(x, y, 70.0, 30.0, 20.0, 15.0)
    });
    let ov = [overlay(vec![[10.0, 10.0], [80.0, 70.0], [20.0, 90.0]], None)];
    let mut s = Scene::new(&map, orbit([48.0, 48.0], 35.0, 30.0, 110.0));
    s.overlays = &ov;
    s.selection = Some(0);
    s.mode = "pull";
    let one = {
        let mut f = Frame::new(250, 141).unwrap();
        Renderer::with_tile_rows(141).render(&s, &mut f).unwrap();
        f
    };
    for rows in [1, 7, 16, 64] {
        let mut f = Frame::new(250, 141).unwrap();
        Renderer::with_tile_rows(rows).render(&s, &mut f).unwrap();
        assert!(f == one, "{rows} rows per tile differ from one tile");
    }
}

#[test]
fn degenerate_input() {
    // Zero-size frames are refused.
    assert_eq!(Frame::new(0, 10), Err(RenderError::FrameSize { width: 0, height: 10 }));
    assert!(Frame::new(10, 0).is_err());
    let one = Heightmap::from_heights(1, 1, 1.0, vec![0.0]).unwrap();
    let s = Scene::new(&one, orbit([0.5, 0.5], 0.0, 45.0, 5.0));
    assert!(Renderer::new().coverage(&s, 0, 5).is_err());
    // A 1 × 1 grid has no triangle: sky only, and the overlays still draw.
    let ov = [overlay(vec![[0.5, 0.5]], None)];
    let mut s1 = s.clone();
    s1.overlays = &ov;
    let f = render(&s1, 64, 48);
    assert!(!magenta(&f).is_empty());
    assert!(Renderer::new().coverage(&s, 64, 48).unwrap().iter().all(|&c| c == 0));
    // An empty grid.
    let empty = Heightmap::from_heights(0, 0, 1.0, vec![]).unwrap();
    render(&Scene::new(&empty, orbit([0.0, 0.0], 0.0, 45.0, 5.0)), 16, 16);
    // Unusable cameras are refused.
    let map = terrain(8, |_, _| 0.0);
    for cam in [
        orbit([4.0, 4.0], 0.0, 45.0, 0.0),
        orbit([f64::NAN, 4.0], 0.0, 45.0, 5.0),
    ] {
        let mut f = Frame::new(8, 8).unwrap();
        assert!(matches!(
            Renderer::new().render(&Scene::new(&map, cam), &mut f),
            Err(RenderError::Camera(_))
        ));
    }
    let behind = Tracked {
        head: [0.0, 0.0, -0.5],
        ..Tracked::fit([1.0, 1.0], [8.0, 8.0], 0.5)
    };
    let mut f = Frame::new(8, 8).unwrap();
    let cam = Camera {
        view: View::Tracked(behind),
        tilt: 0.0,
    };
    assert!(Renderer::new().render(&Scene::new(&map, cam), &mut f).is_err());
    // Overlays without points or with non-finite points draw nothing and do not panic.
    // A line reaching far off the grid is drawn where it crosses it, in bounded time.
    let far = [overlay(vec![[-1e12, 4.0], [1e12, 4.5]], None)];
    let mut s3 = Scene::new(&map, orbit([4.0, 4.0], 0.0, 60.0, 20.0));
    s3.overlays = &far;
    assert!(!magenta(&render(&s3, 32, 32)).is_empty());
    let odd = [
        overlay(vec![], None),
        overlay(vec![[f64::NAN, 1.0], [2.0, 2.0]], None),
        overlay(vec![[1.0, 1.0]], Some(f64::INFINITY)),
    ];
    let mut s2 = Scene::new(&map, orbit([4.0, 4.0], 0.0, 45.0, 20.0));
    s2.overlays = &odd;
    render(&s2, 32, 32);
}

#[test]
fn non_finite_heights_leave_holes() {
    let mut heights = vec![0.0f32; 32 * 32];
    heights[16 * 32 + 16] = f32::NAN;
    heights[3 * 32 + 5] = f32::INFINITY;
    let map = Heightmap::from_heights(32, 32, 1.0, heights).unwrap();
    let s = Scene::new(&map, orbit([16.0, 16.0], 0.0, 90.0, 45.0));
    let mut f = Frame::new(160, 160).unwrap();
    let stats = Renderer::new().render(&s, &mut f).unwrap();
    assert_eq!(stats.skipped_vertices, 2);
    // The six triangles around the NaN vertex are missing: the pixel at its centre is sky.
    let counts = Renderer::new().coverage(&s, 160, 160).unwrap();
    let vp = s.camera.viewpoint(Eye::Centre, 1.0);
    let p = Projection::new(
        &vp,
        0.0,
        Viewport {
            x: 0.0,
            y: 0.0,
            width: 160.0,
            height: 160.0,
        },
    );
    let [x, y, _] = p.pixel(DVec3::new(16.5, 0.0, 16.5)).unwrap();
    assert_eq!(counts[y as usize * 160 + x as usize], 0);
    let [x, y, _] = p.pixel(DVec3::new(8.5, 0.0, 24.5)).unwrap();
    assert_eq!(counts[y as usize * 160 + x as usize], 1);
}

#[test]
fn the_slope_bar_shows_the_value_at_its_position() {
    let map = terrain(16, |_, _| 0.0);
    let (w, h) = (400, 240);
    for value in [-4.0, -1.0, 0.0, 2.5, 4.0, 9.0] {
        let mut s = Scene::new(&map, orbit([8.0, 8.0], 0.0, 45.0, 30.0));
        s.slope_bar = Some(SlopeBar {
            value,
            min: -4.0,
            max: 4.0,
            label: "slope".into(),
        });
        let f = render(&s, w, h);
        let layout = BarLayout::of(
            &penmodel_render::Bounds {
                x0: 0,
                x1: w as i32,
                y0: 0,
                y1: h as i32,
            },
            &s.style,
        );
        let row = (layout.y + layout.height / 2) as u32;
        let xs: Vec<f64> = (0..w)
            .filter(|&x| f.pixel(x, row).unwrap() == s.style.selection_colour)
            .map(f64::from)
            .collect();
        assert!(!xs.is_empty(), "no marker for {value}");
        let centre = xs.iter().sum::<f64>() / xs.len() as f64;
        let t = ((value + 4.0) / 8.0f64).clamp(0.0, 1.0);
        assert!(
            (centre - layout.column(t) as f64).abs() <= 0.5,
            "value {value}: marker at {centre}"
        );
    }
}

#[test]
fn the_mode_line_is_drawn_in_the_text_colour() {
    let map = terrain(16, |_, _| 0.0);
    let mut s = Scene::new(&map, orbit([8.0, 8.0], 0.0, 45.0, 30.0));
    s.style.text_colour = [1, 2, 3, 255];
    let count = |f: &Frame| f.pixels().iter().filter(|p| **p == [1, 2, 3, 255]).count();
    assert_eq!(count(&render(&s, 300, 100)), 0);
    s.mode = "grab: figure 2";
    let f = render(&s, 300, 100);
    let lit: usize = "grab: figure 2"
        .chars()
        .map(|c| {
            penmodel_render::glyph(c)
                .iter()
                .map(|b| b.count_ones() as usize)
                .sum::<usize>()
        })
        .sum();
    let scale = s.style.text_scale as usize;
    assert_eq!(count(&f), lit * scale * scale);
}

#[test]
fn every_glyph_is_distinct() {
    let glyphs: Vec<[u8; 5]> = (32u8..127).map(|c| penmodel_render::glyph(c as char)).collect();
    for (i, g) in glyphs.iter().enumerate() {
        if i > 0 {
            assert!(g.iter().any(|&b| b != 0), "glyph {:?} is empty", (i as u8 + 32) as char);
        }
        for (j, other) in glyphs.iter().enumerate().skip(i + 1) {
            assert_ne!(
                g,
                other,
                "{:?} and {:?} look the same",
                (i as u8 + 32) as char,
                (j as u8 + 32) as char
            );
        }
    }
    assert_eq!(penmodel_render::glyph('é'), penmodel_render::glyph('?'));
}
