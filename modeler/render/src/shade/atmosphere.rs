//! The land look's world around the terrain (issue 20), per eye and pixel: the sky, the display's
//! table, the land beyond it, and the haze (aerial perspective).
//!
//! - **View rays**: with the projection's rows `r₀`, `r₁`, `r₂` (their world parts: `X`, `Y`, `w`
//!   as linear functions of the world point), the ray through pixel `(x, y)` lies in the planes
//!   `(r₀ − x·r₂)·q = 0` and `(r₁ − y·r₂)·q = 0` through the eye, so its direction is their
//!   normals' cross product, `r₀×r₁ + x·(r₁×r₂) + y·(r₂×r₀)`: affine in the pixel, a step per
//!   pixel. Along it `w` grows by `r₂·(r₀×r₁)` (the determinant) per unit, so a sample of depth `w`
//!   is at `eye + dir·w/det` — the world point a terrain pixel shows, whose ground colour
//!   the ground's `albedo_at` ([`super::land`]) gives, and its distance from the eye.
//! - **Sky**: a gradient by the ray's elevation, from [`Style::sky_bottom`] at the horizon to
//!   [`Style::sky_top`] at the zenith (`√sin` of the elevation: the pale band stays near the
//!   horizon), instead of a gradient down the screen.
//! - **Table**: rays below the horizon meet a level plane at the lowest height of the terrain's
//!   edge. Within [`Style::table_margin`] of the terrain it is the display's table
//!   ([`Style::table_colour`]); under the terrain's own footprint (seen between the terrain's edge
//!   and the table, where the edge stands higher than the plane) it is the model's side, dark
//!   earth; beyond the table it is distant land, a muted green fading into the horizon's colour.
//!   So the flat plane is only the display's table around the model, and the world's edge is a
//!   horizon.
//! - **Haze**: `f = 1 − exp(−d/L)` at distance `d` metres from the eye along the view's axis, `L` =
//!   [`Style::haze_distance`] (by default three times the terrain's diagonal: at true scale a 320 m
//!   model would show no aerial perspective at all, so the haze is scaled to the model, a look and
//!   not physics); surfaces tend to the horizon's colour by `haze·f`, the land beyond the table by
//!   `f` at three times the distance, so it is mostly haze and meets the sky at the horizon.

use rayon::prelude::*;

use crate::output::frame::Rgba;
use crate::raster::camera::Projection;
use crate::scene::Style;
use crate::simd::floor::floor_small;
use penmodel_terrain::Heightmap;

/// Distant land beyond the table, before light and haze.
pub(crate) const FAR_LAND: [u8; 3] = [118, 136, 96];
/// The model's side (its cut-away earth), before light.
pub(crate) const SIDE: [u8; 3] = [104, 86, 66];

/// Entries of the haze table over `d/L` in `[0, HAZE_SPAN]`.
const HAZE_ENTRIES: usize = 512;
// `Atmosphere::fog` indexes the table through a 16-bit cast.
const _: () = assert!(HAZE_ENTRIES <= 1 << 16);
const HAZE_SPAN: f32 = 8.0;

fn rgb(c: Rgba) -> [f32; 3] {
    [f32::from(c[0]), f32::from(c[1]), f32::from(c[2])]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// One eye's view of the world around the terrain.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Atmosphere {
    /// The ray through pixel `(x, y)` (pixel coordinates, centres at `+½`) is `a + x·b + y·c`.
    a: [f32; 3],
    b: [f32; 3],
    c: [f32; 3],
    /// `1/|det|`: a sample of depth `w` is at `eye + dir·w/|det|` (the rays' sign chosen so).
    inv_det: f32,
    eye: [f32; 3],
    /// World metres along the view's axis per unit of `w`: `1/|r₂|`.
    metres_per_w: f32,
    /// At most the pixels a metre across the view spans at `w = 1`: `max(|r₀|, |r₁|)`.
    pixels_per_metre: f32,
    /// The table's plane, world Y.
    table_y: f32,
    /// The terrain's footprint, metres, and the table's outer edge.
    extent: [f32; 2],
    margin: f32,
    /// `1/L`.
    inv_haze: f32,
    haze: f32,
    /// `1 − exp(−d/L)` over `d/L ∈ [0, HAZE_SPAN]`.
    table: Box<[f32; HAZE_ENTRIES]>,
    horizon: [f32; 3],
    zenith: [f32; 3],
    /// Lit colours of the table, the model's side and the far land.
    lit_table: [f32; 3],
    lit_side: [f32; 3],
    lit_far: [f32; 3],
}

impl Atmosphere {
    /// The atmosphere of `projection` (one eye) around `map` drawn × `vertical_scale`.
    pub(crate) fn new(projection: &Projection, map: &Heightmap, vertical_scale: f32, style: &Style) -> Atmosphere {
        let r = projection.rows.map(|row| [row[0], row[1], row[2]]);
        let a = cross(r[0], r[1]);
        let b = cross(r[1], r[2]);
        let c = cross(r[2], r[0]);
        let det = dot(r[2], a);
        // Rays point ahead (w grows along them) whatever the determinant's sign.
        let sign = if det < 0.0 { -1.0 } else { 1.0 };
        let (a, b, c) = (a.map(|v| v * sign), b.map(|v| v * sign), c.map(|v| v * sign));
        // The eye: where X, Y and w all vanish.
        let (m, t) = projection.parts();
        let eye = if m.determinant().abs() > 0.0 {
            -(m.inverse() * t)
        } else {
            projection.eye
        };
        let (cols, rows) = (map.cols() as usize, map.rows() as usize);
        let s = map.cell_size() as f32;
        let extent = [cols as f32 * s, rows as f32 * s];
        let table_y = edge_low(map) * vertical_scale;
        let diagonal = extent[0].hypot(extent[1]).max(f32::MIN_POSITIVE);
        let l = if style.haze_distance > 0.0 {
            style.haze_distance
        } else {
            3.0 * diagonal
        };
        // A fixed-size table: the clamped index needs no bounds check per pixel.
        let table = Box::new(std::array::from_fn(|i| {
            1.0 - (-(i as f32) * HAZE_SPAN / (HAZE_ENTRIES - 1) as f32).exp()
        }));
        let [lx, ly, lup] = style.light;
        let len = (lx * lx + ly * ly + lup * lup).sqrt();
        let up = if len > 0.0 && len.is_finite() {
            (lup / len).max(0.0)
        } else {
            1.0
        };
        let ambient = style.ambient.clamp(0.0, 1.0);
        let flat = ambient + (1.0 - ambient) * up;
        let lit = |c: [f32; 3], k: f32| c.map(|v| v * k);
        let f3 = |c: [u8; 3]| c.map(f32::from);
        Atmosphere {
            a: a.map(|v| v as f32),
            b: b.map(|v| v as f32),
            c: c.map(|v| v as f32),
            inv_det: (1.0 / det.abs()) as f32,
            metres_per_w: (1.0 / dot(r[2], r[2]).sqrt()) as f32,
            pixels_per_metre: dot(r[0], r[0]).sqrt().max(dot(r[1], r[1]).sqrt()) as f32,
            eye: [eye.x as f32, eye.y as f32, eye.z as f32],
            table_y,
            extent,
            margin: style.table_margin.max(0.0) * extent[0].max(extent[1]),
            inv_haze: 1.0 / l.max(f32::MIN_POSITIVE),
            haze: style.haze.clamp(0.0, 1.0),
            table,
            horizon: rgb(style.sky_bottom),
            zenith: rgb(style.sky_top),
            lit_table: lit(rgb(style.table_colour), flat),
            // The side faces the viewer, away from the sun's plane: ambient light.
            lit_side: lit(f3(SIDE), ambient + 0.3 * (1.0 - ambient)),
            lit_far: lit(f3(FAR_LAND), flat),
        }
    }

    /// The ray through pixel `(x, y)` (a pixel's centre is at `+½`), not unit length.
    #[inline]
    pub(crate) fn ray(&self, x: f32, y: f32) -> [f32; 3] {
        let (a, b, c) = (self.a, self.b, self.c);
        [
            a[0] + x * b[0] + y * c[0],
            a[1] + x * b[1] + y * c[1],
            a[2] + x * b[2] + y * c[2],
        ]
    }

    /// The world height of the table's plane: what a pixel below the horizon that shows no
    /// surface sees (the table, the model's side, the land beyond).
    pub(crate) fn table_y(&self) -> f32 {
        self.table_y
    }

    /// The ground position `(x, z)` of the point of depth `w` along `ray`, and its distance from
    /// the eye along the view's axis (the haze's distance: within the 45° of a view it is at most
    /// 8 % short of the distance along the ray, and it costs no square root per pixel).
    #[inline(always)]
    pub(crate) fn point(&self, ray: [f32; 3], w: f32) -> ([f32; 2], f32) {
        let k = w * self.inv_det;
        (
            [self.eye[0] + ray[0] * k, self.eye[2] + ray[2] * k],
            w * self.metres_per_w,
        )
    }

    /// At most how many pixels `metres` span across the view at depth `1/invw`.
    #[inline]
    pub(crate) fn pixels(&self, metres: f32, invw: f32) -> f32 {
        metres * self.pixels_per_metre * invw
    }

    /// `1 − exp(−d/L)`.
    #[inline(always)]
    fn fog(&self, d: f32) -> f32 {
        let x = d * self.inv_haze * ((HAZE_ENTRIES - 1) as f32 / HAZE_SPAN);
        // A 16-bit cast saturates as the 32- and 64-bit ones did (the table is shorter than 2¹⁶:
        // the same entry), in three instructions where 32 bits took six. The entry is read
        // whatever `x` is (a NaN casts to 0) and then chosen.
        let t = self.table[usize::from(x as u16).min(HAZE_ENTRIES - 1)];
        if x.is_finite() { t } else { 1.0 }
    }

    /// [`Atmosphere::fog`] without the table: the same entry's `1 − exp(−i·HAZE_SPAN/(E − 1))`
    /// for the same `i`, with the exponential computed ([`exp_small`], within 2 ulp of the
    /// table's), so that the resolve computes it in vector lanes (a lookup per pixel was a tenth
    /// of the resolve's instructions and stays scalar).
    #[inline(always)]
    fn fog_computed(&self, d: f32) -> f32 {
        let x = d * self.inv_haze * ((HAZE_ENTRIES - 1) as f32 / HAZE_SPAN);
        // The table's index: `x` truncated and clamped (a NaN and anything below 0: entry 0).
        let i = if x > 0.0 { x } else { 0.0 };
        let i = if i < (HAZE_ENTRIES - 1) as f32 {
            i
        } else {
            (HAZE_ENTRIES - 1) as f32
        };
        // Truncated without a cast (which the compiler keeps scalar).
        let (_, i) = floor_small(i);
        let t = 1.0 - exp_small(-i * HAZE_SPAN / (HAZE_ENTRIES - 1) as f32);
        if x.is_finite() { t } else { 1.0 }
    }

    /// `colour` (lit) seen from `d` metres away.
    #[inline(always)]
    pub(crate) fn hazed(&self, colour: [f32; 3], d: f32) -> [f32; 3] {
        self.hazed_by(colour, self.haze_at(d))
    }

    /// How far a surface `d` metres away tends to the horizon's colour: [`Atmosphere::hazed`]
    /// in two steps, this one a table lookup, the other arithmetic (the resolve vectorises it).
    #[inline(always)]
    pub(crate) fn haze_at(&self, d: f32) -> f32 {
        self.haze * self.fog(d)
    }

    /// [`Atmosphere::haze_at`] without a lookup, for vector lanes ([`Atmosphere::fog_computed`]:
    /// it may differ from the table's by an ulp or two).
    #[inline(always)]
    pub(crate) fn haze_computed(&self, d: f32) -> f32 {
        self.haze * self.fog_computed(d)
    }

    /// `colour` tended to the horizon's by `t` ([`Atmosphere::haze_at`]).
    #[inline(always)]
    pub(crate) fn hazed_by(&self, colour: [f32; 3], t: f32) -> [f32; 3] {
        lerp(colour, self.horizon, t)
    }

    /// What a pixel that shows no surface sees along `ray`: the table, the model's side, the
    /// land beyond, or the sky.
    #[inline(always)]
    pub(crate) fn background(&self, ray: [f32; 3]) -> [f32; 3] {
        let len = (ray[0] * ray[0] + ray[1] * ray[1] + ray[2] * ray[2]).sqrt();
        if len.is_nan() || len <= 0.0 {
            return self.horizon;
        }
        let sin = ray[1] / len;
        if sin < 0.0 {
            if self.eye[1] <= self.table_y {
                return self.horizon;
            }
            let t = (self.table_y - self.eye[1]) / ray[1];
            let (x, z) = (self.eye[0] + t * ray[0], self.eye[2] + t * ray[2]);
            let d = t * len;
            let [w, h] = self.extent;
            let m = self.margin;
            let inside = |m: f32| x >= -m && x <= w + m && z >= -m && z <= h + m;
            return if inside(0.0) {
                self.hazed(self.lit_side, d)
            } else if inside(m) {
                self.hazed(self.lit_table, d)
            } else {
                // The far land fades three times faster than the model: it is the atmosphere
                // beyond the table more than land.
                let f = self.fog(3.0 * d);
                lerp(self.lit_far, self.horizon, f)
            };
        }
        let t = sin.sqrt();
        lerp(self.horizon, self.zenith, t)
    }

    /// [`Atmosphere::background`] of row `y`'s pixels `x0..x1` as opaque pixels
    /// ([`Atmosphere::background_pixel`]), the ray of the `k`-th the row's first plus `k` steps
    /// ([`Atmosphere::row_ray`], as the shading computes it, so both give the same bytes).
    pub(crate) fn background_row(&self, y: usize, (x0, x1): (usize, usize), out: &mut [u32]) {
        let first = self.ray(x0 as f32 + 0.5, y as f32 + 0.5);
        for (k, p) in out.iter_mut().take(x1.saturating_sub(x0)).enumerate() {
            *p = self.background_pixel(self.row_ray(first, k as f32));
        }
    }

    /// The ray `k` pixels along a row from `first` (the row's first pixel's ray): `first + k·step`.
    #[inline(always)]
    pub(crate) fn row_ray(&self, first: [f32; 3], k: f32) -> [f32; 3] {
        let b = self.b;
        [first[0] + k * b[0], first[1] + k * b[1], first[2] + k * b[2]]
    }

    /// [`Atmosphere::background`] as an opaque pixel, the bytes `r, g, b, 255` of a
    /// little-endian `u32` (the channels truncated, as `as u8` does).
    #[inline(always)]
    pub(crate) fn background_pixel(&self, ray: [f32; 3]) -> u32 {
        let c = self.background(ray);
        u32::from(c[0] as u8) | u32::from(c[1] as u8) << 8 | u32::from(c[2] as u8) << 16 | 0xff00_0000
    }
}

/// `e^y` for `y` in `[−HAZE_SPAN, 0]` (beyond it too, less precisely, down to where `e^y` is
/// subnormal), by arithmetic that vectorises: `y·log₂e` split into an integer `n` (by the 1.5·2²³
/// rounding trick: no `round` instruction in baseline x86-64) and `f` in `[−½, ½]`, `e^(f·ln 2)`
/// by Cephes' `expf` polynomial (`f·ln 2` reduced in two parts), scaled by `2^n` through the
/// exponent's bits. Within 2 ulp of `f32::exp` over the haze's range (the test checks every entry).
#[inline(always)]
fn exp_small(y: f32) -> f32 {
    const ROUND: f32 = 12_582_912.0;
    let y = if y > -87.0 { y } else { -87.0 };
    let t = y * std::f32::consts::LOG2_E + ROUND;
    let n = t - ROUND;
    // The integer `n`, from the bits of `t` (1.5·2²³ + n, exactly).
    let ni = t.to_bits().wrapping_sub(ROUND.to_bits()) as i32;
    // `y − n·ln 2`, in two parts (the first exact in `f32` for such `n`).
    let r = y - n * 0.693_359_4 + n * 2.121_944_4e-4;
    let p = 1.987_569_1e-4;
    let p = p * r + 1.398_199_9e-3;
    let p = p * r + 8.333_452e-3;
    let p = p * r + 4.166_579_6e-2;
    let p = p * r + 1.666_666_5e-1;
    let p = p * r + 0.5;
    let e = p * r * r + r + 1.0;
    e * f32::from_bits(((ni + 127) as u32) << 23)
}

/// `a + t·(b − a)`, spelled out (an array `map` here costs a tenth of the frame).
#[inline(always)]
pub(crate) fn lerp(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    [
        a[0] + t * (b[0] - a[0]),
        a[1] + t * (b[1] - a[1]),
        a[2] + t * (b[2] - a[2]),
    ]
}

/// The lowest finite height on the terrain's edge (0 for a terrain without any).
fn edge_low(map: &Heightmap) -> f32 {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    let h = map.heights();
    if cols == 0 || rows == 0 {
        return 0.0;
    }
    let top = &h[..cols];
    let bottom = &h[(rows - 1) * cols..];
    let sides = (0..rows).flat_map(|r| [h[r * cols], h[r * cols + cols - 1]]);
    let low = top
        .iter()
        .chain(bottom)
        .copied()
        .chain(sides)
        .filter(|v| v.is_finite())
        .fold(f32::INFINITY, f32::min);
    if low.is_finite() { low } else { 0.0 }
}

/// An eye's background (what pixels that show no surface see), kept between frames while the
/// eye's atmosphere and the frame stay the same: it depends on the camera, the style and the
/// terrain's extent and edge only, and costs about a square root and a division per pixel.
///
/// While the view moves it is not made at all: the shading computes the background of the
/// pixels that show no surface only (the same ray, [`Atmosphere::row_ray`], so the same bytes): the
/// whole frame's background was 85 M of a turning view's 290 M instructions a frame (1024², LOD
/// at 1 px). Once the view has stayed for a frame it is made whole and kept.
#[derive(Debug, Default)]
pub(crate) struct Backdrop {
    key: Option<(Atmosphere, [usize; 4])>,
    /// Whether `pixels` holds the background of `key`.
    made: bool,
    /// Opaque pixels ([`Atmosphere::background_pixel`]): the shading copies them as they are.
    pixels: Vec<u32>,
}

impl Backdrop {
    /// The background of `air` over the columns `x0..x1` of a `width × height` frame, row-major
    /// over the whole frame (other columns unset), when the view is the last frame's; `None`
    /// when it changed (the caller computes [`Atmosphere::background`] where it needs it).
    pub(crate) fn of(
        &mut self,
        air: &Atmosphere,
        width: usize,
        height: usize,
        (x0, x1): (usize, usize),
    ) -> Option<&[u32]> {
        let key = [width, height, x0, x1];
        if !self.key.as_ref().is_some_and(|(a, k)| a == air && *k == key) {
            self.key = Some((air.clone(), key));
            self.made = false;
            return None;
        }
        if self.made {
            return Some(&self.pixels);
        }
        self.pixels.resize(width * height, 0);
        self.pixels
            .par_chunks_mut(width.max(1))
            .enumerate()
            .for_each(|(y, row)| air.background_row(y, (x0, x1), &mut row[x0..x1]));
        self.made = true;
        Some(&self.pixels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::camera::{Camera, Eye, Tracked, View, Viewport};

    fn atmosphere(haze_distance: f32) -> Atmosphere {
        let camera = Camera {
            view: View::Tracked(Tracked::fit([0.6, 0.34], [100.0, 60.0], 0.45)),
            tilt: 0.2,
        };
        let vp = camera.viewpoint(Eye::Left, 16.0 / 9.0);
        let viewport = Viewport {
            x: 0.0,
            y: 0.0,
            width: 64.0,
            height: 36.0,
        };
        let projection = Projection::new(&vp, camera.tilt, viewport);
        let map = Heightmap::from_heights(4, 4, 25.0, vec![0.0; 16]).expect("a 4 × 4 map");
        let style = Style {
            haze_distance,
            ..Style::land()
        };
        Atmosphere::new(&projection, &map, 1.0, &style)
    }

    #[test]
    fn the_computed_exponential_is_within_two_ulp_of_the_tables() {
        for i in 0..HAZE_ENTRIES {
            let y = -(i as f32) * HAZE_SPAN / (HAZE_ENTRIES - 1) as f32;
            let (got, want) = (exp_small(y), y.exp());
            let ulps = (i64::from(got.to_bits()) - i64::from(want.to_bits())).abs();
            assert!(ulps <= 2, "e^{y}: {got:e} against {want:e} ({ulps} ulp)");
        }
    }

    #[test]
    fn the_computed_haze_is_the_tables() {
        let air = atmosphere(1000.0);
        // Distances over the table and past it, on and between its entries, and the edges.
        let mut ds: Vec<f32> = (0..=20_000).map(|i| i as f32 * 0.5).collect();
        ds.extend([-5.0, -0.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, f32::MAX]);
        for d in ds {
            let (got, want) = (air.fog_computed(d), air.fog(d));
            assert!(
                (got - want).abs() <= 2.0 * f32::EPSILON,
                "fog at {d}: {got:e} against the table's {want:e}"
            );
        }
    }

    #[test]
    fn a_rows_rays_are_its_first_plus_steps() {
        let air = atmosphere(0.0);
        let first = air.ray(3.5, 7.5);
        for k in 0..64 {
            let want = air.ray(3.5 + k as f32, 7.5);
            let got = air.row_ray(first, k as f32);
            let norm = want.iter().map(|w| w * w).sum::<f32>().sqrt();
            for (g, w) in got.iter().zip(want) {
                assert!((g - w).abs() <= 1e-5 * norm, "pixel {k}: {got:?} against {want:?}");
            }
        }
    }
}
