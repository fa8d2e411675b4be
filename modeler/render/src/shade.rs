//! Shading: samples become colours.
//!
//! - The rasteriser leaves the interpolated height and light ([`crate::light`]) in each sample;
//!   the classic look's colour is `ramp(height) × light` ([`crate::ramp`]), per pixel.
//! - Empty samples show the sky, a vertical gradient.
//! - The land look ([`crate::scene::Look::Land`]) colours a terrain sample by the ground colour at
//!   its world point ([`crate::land`]) instead of the ramp, hazes every surface by its distance
//!   and shows the sky, the table and the land beyond where nothing was drawn
//!   ([`crate::atmosphere`]).
//!
//! The ramp and the light live in their own modules, which the land look uses too: shading
//! depends on the land look, not the other way round.

use super::atmosphere::Atmosphere;
use super::frame::Rgba;
use super::land::Land;
use super::mips;
use super::ramp::Ramp;
use super::rasterise::{Sample, Surface};
use super::scene::Style;

fn mix(a: Rgba, b: Rgba, t: f32) -> Rgba {
    [0, 1, 2, 3].map(|i| (f32::from(a[i]) + t * (f32::from(b[i]) - f32::from(a[i]))).round() as u8)
}

/// How one eye's samples become colours: the classic ramp, or the land look's ground colours and
/// atmosphere.
pub struct Shading<'a> {
    /// The classic look's colour table (unused by the land look).
    pub ramp: &'a Ramp,
    /// The land look's maps of the terrain, this eye's atmosphere and its background when kept
    /// (row-major over the frame: [`crate::atmosphere::Backdrop`]; else computed per pixel that
    /// shows no surface).
    pub land: Option<LandShading<'a>>,
}

/// The land look's part of [`Shading`]: the terrain's maps, the eye's atmosphere, its kept
/// background if any.
pub type LandShading<'a> = (&'a Land, &'a Atmosphere, Option<&'a [[u8; 3]]>);

/// A sample's colour before light, for surfaces other than the terrain.
#[inline]
fn surface_colour(surface: Surface, style: &Style) -> Option<[f32; 3]> {
    let flat = |r: Rgba| [f32::from(r[0]), f32::from(r[1]), f32::from(r[2])];
    match surface {
        Surface::Rock => Some(flat(style.rock_colour)),
        Surface::Water => Some(flat(style.water_colour)),
        Surface::Colour([r, g, b]) => Some([f32::from(r), f32::from(g), f32::from(b)]),
        Surface::Terrain => None,
    }
}

/// Resolves a tile of samples into colours: terrain where covered, sky elsewhere. `y0` is the
/// tile's first row in a frame of `frame_height` rows; only columns `x0..x1` are written.
#[allow(clippy::too_many_arguments)]
pub fn resolve(
    samples: &[Sample],
    pixels: &mut [Rgba],
    width: usize,
    (x0, x1): (usize, usize),
    y0: usize,
    frame_height: usize,
    shading: &Shading,
    style: &Style,
) {
    if let Some((land, air, back)) = shading.land {
        let back = back.map(|b| &b[(y0 * width).min(b.len())..]);
        resolve_land(samples, pixels, width, (x0, x1), y0, (land, air, back), style);
        return;
    }
    let ramp = shading.ramp;
    for (row, (srow, prow)) in samples.chunks(width).zip(pixels.chunks_mut(width)).enumerate() {
        let t = (y0 + row) as f32 / frame_height.max(1) as f32;
        let sky = mix(style.sky_top, style.sky_bottom, t);
        for (s, p) in srow[x0..x1].iter().zip(&mut prow[x0..x1]) {
            if s.invw > 0.0 {
                let w = 1.0 / s.invw;
                let c = surface_colour(s.surface, style).unwrap_or_else(|| ramp.get(s.hw * w));
                let l = (s.lw * w).clamp(0.0, 1.0);
                *p = [(c[0] * l) as u8, (c[1] * l) as u8, (c[2] * l) as u8, 255];
            } else {
                *p = sky;
            }
        }
    }
}

/// [`resolve`] in the land look: a terrain sample's ground colour where its world point lies
/// ([`crate::land::Ground::albedo_at`]) with as much of the fine noise as its footprint resolves
/// ([`crate::land::FINE_FADE`]), every surface hazed by its distance, the atmosphere behind.
#[allow(clippy::too_many_arguments)]
fn resolve_land(
    samples: &[Sample],
    pixels: &mut [Rgba],
    width: usize,
    (x0, x1): (usize, usize),
    y0: usize,
    (land, air, back): LandShading,
    style: &Style,
) {
    let step = air.step();
    let ground = land.ground();
    let levels = ground.levels();
    // Pixels a metre spans across the view at `w = 1`.
    let per_metre = air.pixels(1.0, 1.0);
    // Where a cell spans less than a pixel (1/w below this), the nearest cell's colour.
    let fine = 1.0 / (per_metre * land.cell).max(f32::MIN_POSITIVE);
    let rows = samples.chunks(width).zip(pixels.chunks_mut(width));
    let sine = |r: [f32; 3]| {
        let len = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        if len > 0.0 { r[1].abs() / len } else { 0.0 }
    };
    for (row, (srow, prow)) in rows.enumerate() {
        let brow = back.and_then(|b| b.get(row * width + x0..row * width + x1));
        let y = (y0 + row) as f32 + 0.5;
        let mut ray = air.ray(x0 as f32 + 0.5, y);
        // The ray's elevation, for the ground's foreshortening: linear along the tile's row
        // between its ends (it is smooth, and a fade needs no more).
        let mut sin = sine(ray);
        let last = sine(air.ray(x1.max(x0 + 1) as f32 - 0.5, y));
        let d_sin = (last - sin) / (x1.saturating_sub(x0 + 1)).max(1) as f32;
        for (k, (s, p)) in srow[x0..x1].iter().zip(&mut prow[x0..x1]).enumerate() {
            let c = if s.invw > 0.0 {
                let w = 1.0 / s.invw;
                let (at, d) = air.point(ray, w);
                // The terrain tested first, by itself: most covered samples are ground, and the
                // match in `surface_colour` was a jump through a table for every one.
                let own = if s.surface == Surface::Terrain {
                    None
                } else {
                    surface_colour(s.surface, style)
                };
                let c = own.unwrap_or_else(|| {
                    let fade = ground.fine_fade(per_metre * s.invw, sin);
                    if s.invw < fine {
                        // The level whose cells are about the pixel's length: `fine / invw`
                        // cells span a pixel across the view, that over `sin` along the ray
                        // (the longer side, as a GPU's mipmaps choose without anisotropic
                        // filtering: sharper would alias, and read far more cells).
                        let level = mips::level_for(fine / (s.invw * sin.max(1e-3)), levels);
                        ground.nearest_at(level, at[0], at[1], fade)
                    } else {
                        ground.albedo_at(at[0], at[1], fade)
                    }
                });
                let l = (s.lw * w).clamp(0.0, 1.0);
                let c = air.hazed([c[0] * l, c[1] * l, c[2] * l], d);
                [c[0] as u8, c[1] as u8, c[2] as u8]
            } else if let Some(b) = brow {
                b[k]
            } else {
                air.background_bytes(ray)
            };
            // One 32-bit store (the array literal was written a byte at a time).
            let rgba = u32::from(c[0]) | u32::from(c[1]) << 8 | u32::from(c[2]) << 16 | 0xff00_0000;
            *p = rgba.to_le_bytes();
            ray = [ray[0] + step[0], ray[1] + step[1], ray[2] + step[2]];
            sin += d_sin;
        }
    }
}
