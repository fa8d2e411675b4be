//! The terrain's level of detail (issue 18): the pyramid's errors against a decimation computed
//! here, its update by rectangle against a rebuild, the image at LOD against full detail, and no
//! crack between levels.

use penmodel_render::{Area, Pyramid};
use penmodel_render::{Camera, Frame, Renderer, Scene, Style};
use penmodel_terrain::Heightmap;

use crate::common::{orbit, terrain};

/// A rough `n × n` terrain of 1 m cells: broad hills, a ridge and fine ripples, so the pyramid's
/// errors vary over the grid.
fn rough(n: u32) -> Heightmap {
    let f = |x: f64, y: f64| {
        let s = n as f64;
        30.0 * ((x / s * 5.0).sin() * (y / s * 4.0).cos())
            + 18.0 * (-((x - 0.6 * s).powi(2) / (0.02 * s * s))).exp()
            + 0.15 * (x * 0.9).sin() * (y * 1.3).cos()
            + 0.05 * (x * 2.7 + y * 1.9).sin()
    };
    terrain(n, f)
}

/// The height at vertex `(c, r)` of the node's decimated surface, interpolated here with
/// barycentric coordinates from the three corners of the coarse triangle holding it.
fn decimated(map: &Heightmap, a: &Area, c: usize, r: usize) -> f64 {
    let cols = map.cols() as usize;
    let h = |c: usize, r: usize| f64::from(map.heights()[r * cols + c]);
    // The coarse quad holding the vertex; on the node's last column or row, the one before it.
    let back = |k: usize, first: usize, last: usize| {
        let k = first + (k - first) / a.step * a.step;
        if k == last && k > first { k - a.step } else { k }
    };
    let (ca, ra) = (back(c, a.c0, a.c1), back(r, a.r0, a.r1));
    let (cb, rb) = ((ca + a.step).min(a.c1), (ra + a.step).min(a.r1));
    let p = (c as f64, r as f64);
    // The quad's two triangles, split along (cb, ra)–(ca, rb).
    let tris = [[(ca, ra), (cb, ra), (ca, rb)], [(cb, ra), (cb, rb), (ca, rb)]];
    for t in tris {
        let [(x0, y0), (x1, y1), (x2, y2)] = t.map(|(c, r)| (c as f64, r as f64));
        let det = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2);
        if det == 0.0 {
            continue;
        }
        let l0 = ((y1 - y2) * (p.0 - x2) + (x2 - x1) * (p.1 - y2)) / det;
        let l1 = ((y2 - y0) * (p.0 - x2) + (x0 - x2) * (p.1 - y2)) / det;
        let l2 = 1.0 - l0 - l1;
        if l0 >= -1e-9 && l1 >= -1e-9 && l2 >= -1e-9 {
            return l0 * h(t[0].0, t[0].1) + l1 * h(t[1].0, t[1].1) + l2 * h(t[2].0, t[2].1);
        }
    }
    unreachable!("vertex ({c}, {r}) outside its coarse quad")
}

/// The largest deviation of the full grid from node `(i, j)`'s decimated surface, by
/// [`decimated`].
fn deviation(map: &Heightmap, a: &Area) -> f64 {
    let cols = map.cols() as usize;
    let mut worst = 0f64;
    for r in a.r0..=a.r1 {
        for c in a.c0..=a.c1 {
            let z = f64::from(map.heights()[r * cols + c]);
            worst = worst.max((z - decimated(map, a, c, r)).abs());
        }
    }
    worst
}

#[test]
fn node_errors_are_the_largest_deviation_of_the_node_or_its_children() {
    // 100 vertices: 99 quads, so the last nodes of every level are cut short by the grid's end.
    let map = rough(100);
    let p = Pyramid::new(&map);
    assert!(p.levels() >= 3, "{} levels", p.levels());
    let cols = map.cols() as usize;
    for level in 0..p.levels() as u32 {
        let mut j = 0;
        while p.node(level, 0, j).is_some() {
            let mut i = 0;
            while let Some(node) = p.node(level, i, j) {
                let a = p.area(level, i, j);
                // Its own decimation's deviation, or a child's error if larger (each child is
                // checked at its own level).
                let mut want = if level == 0 { 0.0 } else { deviation(&map, &a) };
                if level > 0 {
                    for (ci, cj) in [
                        (2 * i, 2 * j),
                        (2 * i + 1, 2 * j),
                        (2 * i, 2 * j + 1),
                        (2 * i + 1, 2 * j + 1),
                    ] {
                        want = want.max(child_error(&p, level - 1, ci, cj));
                    }
                }
                assert!(
                    (f64::from(node.error) - want).abs() <= 1e-4 * want.max(1.0),
                    "level {level} node ({i}, {j}): error {} against {want}",
                    node.error
                );
                // The box holds every height of the node.
                for r in a.r0..=a.r1 {
                    for c in a.c0..=a.c1 {
                        let z = map.heights()[r * cols + c];
                        assert!(node.min <= z && z <= node.max);
                    }
                }
                i += 1;
            }
            j += 1;
        }
    }
}

/// A node's stored error, for its parent's expectation (checked itself at its own level).
fn child_error(p: &Pyramid, level: u32, i: u32, j: u32) -> f64 {
    p.node(level, i, j).map_or(0.0, |n| f64::from(n.error))
}

#[test]
fn an_update_over_the_changed_rectangle_equals_a_rebuild() {
    let map = rough(150);
    let mut p = Pyramid::new(&map);
    let mut heights = map.heights().to_vec();
    let cols = 150usize;
    // Raise a block of cells (columns 40..57, rows 90..101) by a bump.
    for r in 90..101 {
        for c in 40..57 {
            heights[r * cols + c] += 7.0 + (c as f32 * 0.7).sin();
        }
    }
    let changed = Heightmap::from_heights(150, 150, 1.0, heights).unwrap();
    let before = p.visited();
    p.update(&changed, (40, 57, 90, 101));
    let fresh = Pyramid::new(&changed);
    for level in 0..p.levels() as u32 {
        for j in 0..20 {
            for i in 0..20 {
                assert_eq!(
                    p.node(level, i, j),
                    fresh.node(level, i, j),
                    "level {level} node ({i}, {j})"
                );
            }
        }
    }
    // Only the nodes over the rectangle were visited: far fewer cells than a rebuild.
    let visited = p.visited() - before;
    assert!(
        visited < fresh.visited() / 2,
        "{visited} cells against {}",
        fresh.visited()
    );
}

/// A frame of `scene` from a fresh renderer, and the renderer (its LOD picks).
fn frame(scene: &Scene, (w, h): (u32, u32)) -> (Frame, Renderer) {
    let mut f = Frame::new(w, h).unwrap();
    let mut r = Renderer::new();
    r.render(scene, &mut f).unwrap();
    (f, r)
}

/// Mean absolute difference per channel, and the fraction of pixels whose largest channel
/// difference exceeds `levels`, over the pixels `keep` accepts, between `a` and `b` offset by
/// `dx` columns (`b`'s pixel `x + dx` against `a`'s `x`).
fn compare(a: &Frame, b: &Frame, dx: usize, levels: u8) -> (f64, f64) {
    let w = a.width() as usize;
    let (mut sum, mut over, mut n) = (0.0, 0usize, 0usize);
    for (ra, rb) in a.pixels().chunks(w).zip(b.pixels().chunks(w)) {
        for (p, q) in ra[..w - dx].iter().zip(&rb[dx..]) {
            let d: Vec<u8> = (0..3).map(|c| p[c].abs_diff(q[c])).collect();
            sum += d.iter().map(|&v| f64::from(v)).sum::<f64>();
            over += usize::from(d.iter().any(|&v| v > levels));
            n += 1;
        }
    }
    (sum / (3.0 * n as f64), over as f64 / n as f64)
}

#[test]
fn a_frame_at_one_pixel_of_error_differs_from_full_detail_less_than_a_one_pixel_shift() {
    // The bound: LOD may move the surface by at most τ = 1 pixel on screen, so the frame at LOD
    // should differ from the full-detail frame by less than the full-detail frame differs from
    // itself shifted by one pixel (the difference a 1-pixel error everywhere would make).
    let map = rough(384);
    for style in [Style::land(), Style::default()] {
        let mut scene = Scene::new(&map, orbit([192.0, 192.0], 30.0, 30.0, 420.0));
        scene.style = style.clone();
        scene.vertical_scale = 1.5;
        scene.terrain_lod = 0.0;
        let (full, _) = frame(&scene, (480, 270));
        scene.terrain_lod = 1.0;
        let (lod, r) = frame(&scene, (480, 270));
        let picks = r.lod_picks();
        assert!(picks.iter().any(|p| p.level >= 2), "the view uses coarse levels");
        let (mad, frac) = compare(&full, &lod, 0, 24);
        let (shift_mad, shift_frac) = compare(&full, &full, 1, 24);
        assert!(mad > 0.0, "LOD changed the image");
        assert!(
            mad < shift_mad && frac < shift_frac,
            "{:?}: LOD against full: mean {mad:.3}/255, {frac:.4} over 24 levels; one-pixel shift: {shift_mad:.3}, {shift_frac:.4}",
            style.look
        );
    }
}

/// Renders the terrain's coverage (triangles per pixel, no depth test) at full detail and at
/// LOD `pixels`.
fn coverages(map: &Heightmap, camera: Camera, pixels: f32, (w, h): (u32, u32)) -> (Vec<u16>, Vec<u16>, usize) {
    let mut scene = Scene::new(map, camera);
    scene.terrain_lod = 0.0;
    let full = Renderer::new().coverage(&scene, w, h).unwrap();
    scene.terrain_lod = pixels;
    let mut r = Renderer::with_tile_rows(5);
    let lod = r.coverage(&scene, w, h).unwrap();
    let levels = r.lod_picks().iter().map(|p| p.level).max().unwrap_or(0) as usize;
    (full, lod, levels)
}

#[test]
fn no_crack_between_levels() {
    // Gentle hills seen from above at 60°: no triangle faces away, so every pixel of the
    // terrain's footprint is covered exactly once by a watertight surface. At LOD, the levels
    // change from node to node; a crack between two levels would leave a pixel inside the
    // footprint uncovered, an overlap would cover one twice.
    let n = 257u32;
    let heights = (0..n * n)
        .map(|i| {
            let (x, y) = (f64::from(i % n), f64::from(i / n));
            (6.0 * (x / 40.0).sin() * (y / 33.0).cos() + 0.6 * (x / 3.0).sin() * (y / 4.0).cos()) as f32
        })
        .collect();
    let map = Heightmap::from_heights(n, n, 1.0, heights).unwrap();
    let (w, h) = (400u32, 240u32);
    for (az, el, dist, tau) in [
        (20.0, 60.0, 240.0, 1.0),
        (-50.0, 55.0, 180.0, 2.0),
        (140.0, 70.0, 120.0, 4.0),
    ] {
        let (full, lod, levels) = coverages(&map, orbit([128.0, 128.0], az, el, dist), tau, (w, h));
        assert!(levels >= 2, "the view mixes levels (coarsest {levels})");
        let (w, h) = (w as usize, h as usize);
        let mut inside = 0;
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let k = y * w + x;
                assert!(lod[k] <= 1, "pixel ({x}, {y}) covered {} times at LOD", lod[k]);
                // Well inside the footprint: the full-detail surface covers its 3×3 neighbourhood.
                let deep = (0..3).all(|dy| (0..3).all(|dx| full[(y + dy - 1) * w + x + dx - 1] == 1));
                if deep {
                    inside += 1;
                    assert_eq!(lod[k], 1, "a crack at pixel ({x}, {y}), view az {az} el {el} τ {tau}");
                }
            }
        }
        assert!(inside > 20_000, "only {inside} pixels inside");
    }
}

#[test]
fn a_grazing_view_shows_no_background_through_the_terrain() {
    // A unique background colour: a pixel of it inside the terrain at LOD, where the full-detail
    // frame shows terrain and its neighbours above and below do too, would be a crack.
    // The eye inside the grid's square, so its open sides stay out of view but the far ones.
    let map = rough(512);
    let mut scene = Scene::new(&map, orbit([256.0, 256.0], 10.0, 8.0, 90.0));
    let key = [255, 0, 255, 255];
    scene.style = Style {
        sky_top: key,
        sky_bottom: key,
        ..Style::default()
    };
    scene.terrain_lod = 0.0;
    let (full, _) = frame(&scene, (480, 270));
    scene.terrain_lod = 2.0;
    let (lod, r) = frame(&scene, (480, 270));
    assert!(r.lod_picks().iter().any(|p| p.level >= 2), "the view mixes levels");
    let w = 480usize;
    let (f, l) = (full.pixels(), lod.pixels());
    let sky = |p: &[u8; 4]| *p == key;
    let mut terrain = 0;
    for y in 2..268 {
        for x in 0..w {
            let k = y * w + x;
            if sky(&f[k]) {
                continue;
            }
            terrain += 1;
            if x < 2 || x + 2 >= w {
                continue;
            }
            // Terrain two pixels around in both frames: not the silhouette, which LOD may move
            // by up to τ pixels.
            let enclosed = (1..=2).all(|d| {
                [k - d * w, k + d * w, k - d, k + d]
                    .iter()
                    .all(|&n| !sky(&f[n]) && !sky(&l[n]))
            });
            if enclosed && sky(&l[k]) {
                let mut txt = String::new();
                for yy in y - 4..y + 5 {
                    for xx in x - 8..x + 9 {
                        let kk = yy * w + xx;
                        txt.push(match (sky(&f[kk]), sky(&l[kk])) {
                            (true, true) => ' ',
                            (false, false) => '#',
                            (true, false) => '+',
                            (false, true) => '-',
                        });
                    }
                    txt.push('\n');
                }
                panic!("background through the terrain at ({x}, {y})\n{txt}");
            }
        }
    }
    assert!(terrain > 40_000, "{terrain} terrain pixels");
}
