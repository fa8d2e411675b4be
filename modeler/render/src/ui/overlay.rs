//! Overlays: figures and region boundaries as lines on the terrain, the selection, and figures
//! held at a height while they are pulled.
//!
//! - **Draped** lines follow the surface exactly: each segment is cut where it crosses a grid
//!   line or a quad's diagonal, and each piece's ends take the height of the triangle they lie on
//!   (the same triangles the rasteriser draws), so a piece is a straight line *on* one triangle.
//! - Lines at a **fixed height** (a figure being pulled) are straight in 3D and need no cutting.
//! - Lines are screen-space capsules (round caps, so joins need no extra work), drawn after the
//!   terrain of a tile and **depth-tested** against it with a relative bias
//!   ([`Style::overlay_bias`](crate::scene::Style::overlay_bias)): a line on the surface
//!   passes where the terrain beside it is slightly nearer (a line is several pixels wide, the
//!   surface under its edge is not the surface under its centre), a line behind a ridge does not.
//! - The selected overlay is drawn last, in the selection colour and width.
//! - Segments are clipped against the near plane and the guard band like triangles.

use glam::DVec3;

use crate::raster::camera::Projection;
use crate::raster::clip::{self, ClipVertex};
use crate::raster::rasterise::Capsule;
use crate::scene::{Overlay, Scene};
use penmodel_terrain::Heightmap;

/// The terrain's height at ground point `(x, y)` on the drawn surface: the triangle of the quad
/// of cell centres that holds the point (split along the same diagonal as the rasteriser's),
/// clamped to the grid of centres. `None` on an empty grid or where a corner is not finite.
pub fn surface_height(map: &Heightmap, x: f64, y: f64) -> Option<f64> {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    if cols == 0 || rows == 0 {
        return None;
    }
    let s = map.cell_size();
    let u = (x / s - 0.5).clamp(0.0, (cols - 1) as f64);
    let v = (y / s - 0.5).clamp(0.0, (rows - 1) as f64);
    let c = (u.floor() as usize).min(cols.saturating_sub(2));
    let r = (v.floor() as usize).min(rows.saturating_sub(2));
    let (fu, fv) = (u - c as f64, v - r as f64);
    let h = |c: usize, r: usize| f64::from(map.heights()[r.min(rows - 1) * cols + c.min(cols - 1)]);
    let (a, b, d, e) = (h(c, r), h(c + 1, r), h(c, r + 1), h(c + 1, r + 1));
    let z = if fu + fv <= 1.0 {
        a + fu * (b - a) + fv * (d - a)
    } else {
        e + (1.0 - fu) * (d - e) + (1.0 - fv) * (b - e)
    };
    z.is_finite().then_some(z)
}

/// Parameters in `(0, 1)` where segment `p → q` crosses the grid lines through cell centres and
/// the quads' diagonals, sorted, with 0 and 1 at the ends. Only lines within the grid count
/// (beyond it the surface is flat, clamped): a segment reaching far off the grid costs no more
/// than one across it.
fn crossings(map: &Heightmap, p: [f64; 2], q: [f64; 2]) -> Vec<f64> {
    let s = map.cell_size();
    let (u0, v0) = (p[0] / s - 0.5, p[1] / s - 0.5);
    let (u1, v1) = (q[0] / s - 0.5, q[1] / s - 0.5);
    let (cols, rows) = (f64::from(map.cols()), f64::from(map.rows()));
    let mut ts = vec![0.0, 1.0];
    let mut family = |a: f64, b: f64, limit: f64| {
        if (b - a).abs() < 1e-12 || !(a.is_finite() && b.is_finite()) {
            return;
        }
        let (lo, hi) = (a.min(b).max(-1.0), a.max(b).min(limit + 1.0));
        let mut k = lo.floor() + 1.0;
        while k < hi {
            ts.push((k - a) / (b - a));
            k += 1.0;
        }
    };
    family(u0, u1, cols);
    family(v0, v1, rows);
    family(u0 + v0, u1 + v1, cols + rows);
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    ts
}

/// The 3D points of an overlay's polyline (world coordinates), before projection; consecutive
/// points are joined. `None` entries break the line (no height there).
fn points(overlay: &Overlay, map: &Heightmap, vertical_scale: f64) -> Vec<Option<DVec3>> {
    let mut ground = overlay.points.clone();
    if overlay.closed && ground.len() > 2 && ground.first() != ground.last() {
        ground.push(ground[0]);
    }
    let world = |x: f64, y: f64, h: Option<f64>| h.map(|h| DVec3::new(x, h * vertical_scale, y));
    let mut out = Vec::new();
    match overlay.height {
        Some(h) => {
            out.extend(
                ground
                    .iter()
                    .map(|p| world(p[0], p[1], Some(h).filter(|h| h.is_finite()))),
            );
        }
        None => {
            if let [p] = ground.as_slice() {
                out.push(world(p[0], p[1], surface_height(map, p[0], p[1])));
            }
            for pair in ground.windows(2) {
                let (p, q) = (pair[0], pair[1]);
                let ts = crossings(map, p, q);
                let start = if out.is_empty() { 0 } else { 1 };
                for &t in &ts[start..] {
                    let (x, y) = (p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]));
                    out.push(world(x, y, surface_height(map, x, y)));
                }
            }
        }
    }
    out
}

fn clip_vertex(projection: &Projection, p: DVec3) -> ClipVertex {
    let [x, y, w] = projection.apply(p);
    ClipVertex {
        x: x as f32,
        y: y as f32,
        w: w as f32,
        h: 0.0,
        l: 0.0,
    }
}

fn screen(v: &ClipVertex) -> [f32; 3] {
    let invw = 1.0 / v.w;
    [v.x * invw, v.y * invw, invw]
}

/// The scene's overlays as screen-space capsules for `projection`, in drawing order (the
/// selection last).
pub(crate) fn capsules(scene: &Scene, projection: &Projection, out: &mut Vec<Capsule>) {
    out.clear();
    let near = projection.near as f32;
    let vs = f64::from(scene.vertical_scale);
    let order = (0..scene.overlays.len())
        .filter(|&i| Some(i) != scene.selection)
        .chain(scene.selection.filter(|&i| i < scene.overlays.len()));
    for i in order {
        let o = &scene.overlays[i];
        let selected = Some(i) == scene.selection;
        let (colour, width) = if selected {
            (scene.style.selection_colour, scene.style.selection_width)
        } else {
            (o.colour, o.width)
        };
        if !(width > 0.0 && width.is_finite()) {
            continue;
        }
        let pts = points(o, scene.terrain, vs);
        let radius = 0.5 * width;
        if let [Some(p)] = pts.as_slice() {
            // A point figure: a dot of three line widths.
            let v = clip_vertex(projection, *p);
            if let Some((a, _)) = clip::segment(v, v, near) {
                let a = screen(&a);
                out.push(Capsule {
                    a,
                    b: a,
                    radius: 3.0 * radius,
                    colour,
                });
            }
            continue;
        }
        for pair in pts.windows(2) {
            let (Some(p), Some(q)) = (pair[0], pair[1]) else {
                continue;
            };
            if let Some((a, b)) = clip::segment(clip_vertex(projection, p), clip_vertex(projection, q), near) {
                out.push(Capsule {
                    a: screen(&a),
                    b: screen(&b),
                    radius,
                    colour,
                });
            }
        }
    }
}
