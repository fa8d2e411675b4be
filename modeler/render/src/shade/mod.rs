//! Shading: samples become colours.
//!
//! - The rasteriser leaves the interpolated height and light ([`crate::scene::light`]) in each sample;
//!   the classic look's colour is `ramp(height) × light` ([`crate::shade::ramp`]), per pixel.
//! - Empty samples show the sky, a vertical gradient.
//! - The land look ([`crate::scene::Look::Land`]) colours a terrain sample by the ground colour at
//!   its world point ([`crate::shade::land`]) instead of the ramp, hazes every surface by its distance
//!   and shows the sky, the table and the land beyond where nothing was drawn
//!   ([`crate::shade::atmosphere`]).
//!
//! The ramp and the light live in their own modules, which the land look uses too: shading
//! depends on the land look, not the other way round.

pub(crate) mod atmosphere;
pub mod land;
pub(crate) mod ramp;

use crate::output::frame::Rgba;
use crate::raster::mips;
use crate::raster::rasterise::{Sample, Surface};
use crate::scene::Style;
use crate::shade::atmosphere::Atmosphere;
use crate::shade::land::{Corner, Land, faded};
use crate::shade::ramp::Ramp;
use crate::simd::lanes::{lanes_set, lanes_where};

fn mix(a: Rgba, b: Rgba, t: f32) -> Rgba {
    [0, 1, 2, 3].map(|i| (f32::from(a[i]) + t * (f32::from(b[i]) - f32::from(a[i]))).round() as u8)
}

/// How one eye's samples become colours: the classic ramp, or the land look's ground colours and
/// atmosphere.
pub(crate) struct Shading<'a> {
    /// The classic look's colour table (unused by the land look).
    pub ramp: &'a Ramp,
    /// The land look's maps of the terrain, this eye's atmosphere and its background when kept
    /// (row-major over the frame: [`crate::shade::atmosphere::Backdrop`]; else computed per pixel that
    /// shows no surface).
    pub land: Option<LandShading<'a>>,
}

/// The land look's part of [`Shading`]: the terrain's maps, the eye's atmosphere, its kept
/// background if any.
pub(crate) type LandShading<'a> = (&'a Land, &'a Atmosphere, Option<&'a [u32]>);

/// A sample's colour before light, for surfaces other than the terrain.
#[inline(always)]
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
pub(crate) fn resolve(
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

/// Pixels a row of the land look's resolve works on at a time ([`resolve_land`]): its lanes'
/// buffers stay in the first-level cache.
const LANES: usize = 64;

/// `0, 1, …, LANES − 1`: a lane's pixel along its stretch, for the rays and sines computed as
/// the stretch's first plus so many steps.
const LANE: [f32; LANES] = {
    let mut lane = [0.0; LANES];
    let mut k = 0;
    while k < LANES {
        lane[k] = k as f32;
        k += 1;
    }
    lane
};

/// One stretch of a row's pixels in the land look's resolve, field by field (structure of
/// arrays), so that the passes without branches or lookups compile to vector instructions: they
/// run over all [`LANES`] entries (a fixed count, no bounds checks), a short stretch's tail set
/// empty.
struct Stretch {
    /// The samples' `1/w` (0: empty) and `l/w`, and whether each shows another surface than the
    /// ground (1) or the ground (0).
    invw: [f32; LANES],
    lw: [f32; LANES],
    other: [u8; LANES],
    /// The sine of the view ray's elevation, the sample's ground position, the fine noise's
    /// fade, the light and the haze by the distance.
    sin: [f32; LANES],
    at: [[f32; LANES]; 2],
    fade: [f32; LANES],
    light: [f32; LANES],
    haze: [f32; LANES],
    /// Where the bilinear ground colour reads ([`crate::shade::land::Ground::corner`]), field by
    /// field.
    index: [u32; LANES],
    fu: [f32; LANES],
    fv: [f32; LANES],
    dc: [u32; LANES],
    dr: [u32; LANES],
    /// The colour before light and haze and the fine noise's factor (covered pixels; the
    /// factor 0 for surfaces other than the ground), and the background (the others).
    colour: [[f32; LANES]; 4],
    background: [u32; LANES],
    /// The finished pixels.
    out: [u32; LANES],
}

/// [`resolve`] in the land look: a terrain sample's ground colour where its world point lies
/// ([`crate::shade::land::Ground::bilinear`]) with as much of the fine noise as its footprint resolves
/// ([`crate::shade::land::FINE_FADE`]), every surface hazed by its distance, the atmosphere behind.
///
/// Each stretch of [`LANES`] pixels of a row goes through passes: the samples' fields; the
/// arithmetic (the rays and sines as the row's first plus `k` steps, the world point, the fade,
/// the light, the haze in closed form, where the bilinear colour reads: no branch or lookup, so
/// it is vectorised); the colour lookups (per pixel, by surface and level); the fine noise, the
/// light, the haze and the bytes (vectorised). A stretch that shows no surface is its background.
#[allow(clippy::too_many_arguments)]
fn resolve_land(
    samples: &[Sample],
    pixels: &mut [Rgba],
    width: usize,
    columns: (usize, usize),
    y0: usize,
    shading: LandShading,
    style: &Style,
) {
    crate::simd::dispatch!(resolve_land_body, (samples, pixels, width, columns, y0, shading, style));
}

/// [`resolve_land`]'s body, compiled for the baseline and for AVX2 ([`crate::simd`]).
#[inline(always)]
// The passes index a dozen arrays by one lane number over a count the compiler knows to be at
// most `LANES`, without checks (the samples iterated with `take(LANES)` cost 1.3 % more of
// the 30-tree scene's instructions).
#[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
fn resolve_land_body(
    samples: &[Sample],
    pixels: &mut [Rgba],
    width: usize,
    (x0, x1): (usize, usize),
    y0: usize,
    (land, air, back): LandShading,
    style: &Style,
) {
    let ground = land.ground();
    let levels = ground.levels();
    // Whether the bilinear colours' cells are found in vector lanes (every grid short of a
    // line of 2²³ cells), else per pixel.
    let computed = ground.corners_computed();
    // Pixels a metre spans across the view at `w = 1`.
    let per_metre = air.pixels(1.0, 1.0);
    // Where a cell spans less than a pixel (1/w below this), the nearest cell's colour.
    let fine = 1.0 / (per_metre * land.cell).max(f32::MIN_POSITIVE);
    let rows = samples.chunks(width).zip(pixels.chunks_mut(width));
    let sine = |r: [f32; 3]| {
        let len = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        if len > 0.0 { r[1].abs() / len } else { 0.0 }
    };
    let zero = [0.0; LANES];
    let mut st = Stretch {
        invw: zero,
        lw: zero,
        other: [0; LANES],
        sin: zero,
        at: [zero; 2],
        fade: zero,
        light: zero,
        haze: zero,
        index: [0; LANES],
        fu: zero,
        fv: zero,
        dc: [0; LANES],
        dr: [0; LANES],
        colour: [zero; 4],
        background: [0; LANES],
        out: [0; LANES],
    };
    for (row, (srow, prow)) in rows.enumerate() {
        let brow = back.and_then(|b| b.get(row * width + x0..row * width + x1));
        let y = (y0 + row) as f32 + 0.5;
        let ray = air.ray(x0 as f32 + 0.5, y);
        // The ray's elevation, for the ground's foreshortening: linear along the tile's row
        // between its ends (it is smooth, and a fade needs no more).
        let sin = sine(ray);
        let last = sine(air.ray(x1.max(x0 + 1) as f32 - 0.5, y));
        let d_sin = (last - sin) / (x1.saturating_sub(x0 + 1)).max(1) as f32;
        let srow = &srow[x0..x1];
        let prow = &mut prow[x0..x1];
        for (first, (ss, ps)) in srow.chunks(LANES).zip(prow.chunks_mut(LANES)).enumerate() {
            // At most `LANES` (a chunk is), said so that the indexing below needs no checks.
            let n = ss.len().min(LANES);
            let ss = &ss[..n];
            let ps = &mut ps[..n];
            // The stretch's first pixel along the row, and a pixel's ray.
            let base = (first * LANES) as f32;
            let ray_of = |k: usize| air.row_ray(ray, base + LANE[k]);
            // The samples' fields; past a short stretch's end, empty samples.
            for k in 0..n {
                st.invw[k] = ss[k].invw;
                st.lw[k] = ss[k].lw;
                st.other[k] = u8::from(ss[k].surface != Surface::Terrain);
            }
            st.invw[n..].fill(0.0);
            // The background where it is kept (the others computed per pixel below).
            if let Some(b) = brow {
                st.background[..n].copy_from_slice(&b[first * LANES..first * LANES + n]);
            }
            // A stretch that shows no surface (the sky, the table, the land beyond: a quarter of
            // the 30-tree scene's pixels) is its background, which needs none of the passes below
            // (they would give the same bytes: an empty pixel is its background).
            if !st.invw[..n].iter().any(|&invw| invw > 0.0) {
                if brow.is_none() {
                    for k in 0..n {
                        st.background[k] = air.background_pixel(ray_of(k));
                    }
                }
                for (p, c) in ps.iter_mut().zip(&st.background) {
                    *p = c.to_le_bytes();
                }
                continue;
            }
            // The samples' arithmetic, whether covered or not (an empty sample's is not used):
            // the ray `k` steps along (computed, not stepped: no chain of additions from pixel
            // to pixel), the world point and its distance, the fade, the light, the haze and
            // where the bilinear colour reads.
            for k in 0..LANES {
                let invw = st.invw[k];
                let w = 1.0 / invw;
                let along = base + LANE[k];
                let sin_k = sin + along * d_sin;
                let (at, d) = air.point(air.row_ray(ray, along), w);
                st.sin[k] = sin_k;
                st.at[0][k] = at[0];
                st.at[1][k] = at[1];
                st.fade[k] = ground.fine_fade(per_metre * invw, sin_k);
                st.light[k] = (st.lw[k] * w).clamp(0.0, 1.0);
                st.haze[k] = air.haze_computed(d);
            }
            if computed {
                for k in 0..LANES {
                    let c = ground.corner(st.at[0][k], st.at[1][k]);
                    st.index[k] = c.index;
                    st.fu[k] = c.fu;
                    st.fv[k] = c.fv;
                    st.dc[k] = c.dc;
                    st.dr[k] = c.dr;
                }
            }
            // The colours, per pixel: by surface, and for the ground by level. Each kind of
            // pixel in a loop of its own over its lanes' bits: tested pixel by pixel, the
            // surface and the level were branches on data that a crown's leaves against the
            // ground mispredicted, most of this loop's time.
            let covered = lanes_where::<true, LANES>(&st.invw, 0.0);
            let far = lanes_where::<false, LANES>(&st.invw, fine);
            let other = lanes_set(&st.other);
            // Other surfaces: their colours.
            for k in bits(covered & other) {
                let [r, g, b] = surface_colour(ss[k].surface, style).unwrap_or_default();
                set_colour(&mut st.colour, k, [r, g, b, 0.0]);
            }
            // The ground where its cells are under a pixel: the level whose cells are about
            // the pixel's length (`fine / invw` cells span a pixel across the view, that over
            // `sin` along the ray: the longer side, as a GPU's mipmaps choose without
            // anisotropic filtering: sharper would alias, and read far more cells).
            for k in bits(covered & !other & far) {
                let cells = fine / (st.invw[k] * st.sin[k].max(1e-3));
                let level = mips::level_for(cells, levels);
                let c = ground.nearest_parts(level, st.at[0][k], st.at[1][k]);
                set_colour(&mut st.colour, k, c);
            }
            // The ground nearer: bilinear between its cells.
            let near = covered & !other & !far;
            if computed {
                for k in bits(near) {
                    let c = ground.bilinear(Corner {
                        index: st.index[k],
                        fu: st.fu[k],
                        fv: st.fv[k],
                        dc: st.dc[k],
                        dr: st.dr[k],
                    });
                    set_colour(&mut st.colour, k, c);
                }
            } else {
                for k in bits(near) {
                    let c = ground.bilinear(ground.corner_cast(st.at[0][k], st.at[1][k]));
                    set_colour(&mut st.colour, k, c);
                }
            }
            // What the pixels that show no surface see, unless it is kept.
            if brow.is_none() {
                let stretch = if n == LANES { u64::MAX } else { (1u64 << n) - 1 };
                for k in bits(stretch & !covered) {
                    st.background[k] = air.background_pixel(ray_of(k));
                }
            }
            // The fine noise, the light, the haze and the bytes.
            for k in 0..LANES {
                let l = st.light[k];
                let c = &st.colour;
                let c = faded([c[0][k], c[1][k], c[2][k], c[3][k]], st.fade[k]);
                let c = [c[0] * l, c[1] * l, c[2] * l];
                let c = air.hazed_by(c, st.haze[k]);
                let lit = byte(c[0]) | byte(c[1]) << 8 | byte(c[2]) << 16 | 0xff00_0000;
                st.out[k] = if st.invw[k] > 0.0 { lit } else { st.background[k] };
            }
            for (p, c) in ps.iter_mut().zip(&st.out) {
                *p = c.to_le_bytes();
            }
        }
    }
}

/// Lane `k`'s colour and fine-noise factor in the stretch's channels.
#[inline(always)]
fn set_colour(channels: &mut [[f32; LANES]; 4], k: usize, c: [f32; 4]) {
    for (channel, v) in channels.iter_mut().zip(c) {
        channel[k] = v;
    }
}

/// The set bits of `mask`, lowest first.
#[inline(always)]
fn bits(mut mask: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let k = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            k
        })
    })
}

/// `v as u8` (NaN and below 0: 0; past 255: 255; else truncated) from the bits of `v` clamped to
/// `[0, 255]`: the clamps are compares and the rest integer shifts, which vectorise (the
/// compiler keeps the saturating cast scalar, seven instructions a channel). The mantissa with
/// its leading 1 is shifted right by `150 − exponent`: by 16 to 23 places for 1 to 255, and
/// past its 24 bits (31 places at most) for 0 and anything under 1. Equal to `v as u8` for every
/// `f32` (checked over all 2³² once; the test checks the edges and a sweep).
#[inline(always)]
fn byte(v: f32) -> u32 {
    let v = if v > 0.0 { v } else { 0.0 };
    let v = if v < 255.0 { v } else { 255.0 };
    let bits = v.to_bits();
    let mantissa = (bits & 0x007f_ffff) | 0x0080_0000;
    mantissa >> (150 - (bits >> 23)).min(31)
}

#[cfg(test)]
mod tests {
    use super::byte;

    #[test]
    fn byte_is_the_saturating_cast() {
        let mut values = vec![f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0];
        values.extend([
            f32::MIN_POSITIVE,
            f32::MAX,
            f32::MIN,
            f32::EPSILON,
            1e-40,
            0.5,
            0.999_999_94,
        ]);
        // Every integer to 300 and its neighbours one step either side.
        for k in 0..=300u16 {
            let v = f32::from(k);
            values.extend([
                v,
                f32::from_bits(v.to_bits() + 1),
                f32::from_bits(v.to_bits().wrapping_sub(1)),
                -v,
            ]);
        }
        // A sweep over all bit patterns, positive and negative.
        values.extend((0..=u32::MAX).step_by(4099).map(f32::from_bits));
        for v in values {
            assert_eq!(byte(v), u32::from(v as u8), "{v:e} ({:#x})", v.to_bits());
        }
    }
}
