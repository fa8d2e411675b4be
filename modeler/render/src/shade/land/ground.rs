//! The land look's maps as a pixel reads them: the ground's colour nearest or bilinear at a
//! world point, from the colour map or its box-filtered levels, with as much of the fine noise as
//! the pixel's footprint resolves.

use crate::raster::mips::Level;
use crate::simd::floor::{SMALL, floor_small};
use crate::simd::lanes::lerp4;

/// The land look's maps as a pixel reads them ([`Land::ground`](super::Land::ground)).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ground<'a> {
    pub(super) albedo: &'a [[f32; 4]],
    /// Levels 1, 2, … of `albedo`, box-filtered ([`crate::raster::mips`]).
    pub(super) mips: &'a [Level],
    pub(super) cols: usize,
    /// 1 / cell size.
    pub(super) inv: f32,
    /// The last column and row.
    pub(super) last: [f32; 2],
    pub(super) fine_metres: f32,
}

/// Where the fine noise fades, in pixels per wavelength along the ground's shorter side on
/// screen: its mean below the first, all of it above the second (smooth between). With the
/// noise's 3-cell wavelength on coarse grids that is a cell under 2 px on screen (the mean) to
/// over 4 px (all of it): finer, the noise would alias — shimmer as the view moves, and every
/// pixel of a moving frame changed.
pub const FINE_FADE: [f32; 2] = [6.0, 12.0];

impl Ground<'_> {
    /// How much of the fine noise a pixel shows (0 to 1): `pixels_per_metre` the screen's
    /// pixels per metre across the view at the sample's depth, `sin` the sine of the view ray's
    /// elevation (flat ground seen at a grazing angle is foreshortened by it along the ray).
    #[inline(always)]
    pub(crate) fn fine_fade(&self, pixels_per_metre: f32, sin: f32) -> f32 {
        let px = self.fine_metres * pixels_per_metre * sin;
        let t = ((px - FINE_FADE[0]) * (1.0 / (FINE_FADE[1] - FINE_FADE[0]))).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    }

    /// The cell position `(x, z)` metres falls in, clamped to the grid; a NaN (a point from a
    /// degenerate view) gives the first cell (`f32::max` returns the other operand).
    #[inline(always)]
    fn place(&self, x: f32, z: f32, half: f32) -> (f32, f32) {
        (
            within(x * self.inv - half, self.last[0]),
            within(z * self.inv - half, self.last[1]),
        )
    }

    /// The box-filtered levels above the colours ([`crate::raster::mips`]).
    #[inline]
    pub(crate) fn levels(&self) -> usize {
        self.mips.len()
    }

    /// The ground's colour (sRGB 0–255, before light) of the cell of `level` (0: the map's own
    /// cells; `L`: the mean of `2^L × 2^L` of them) holding world `(x, z)` metres, with `fade` of
    /// the fine noise: for pixels where a cell is smaller than a pixel, where interpolating
    /// between cells would show nothing more and costs three times as much. A level past the
    /// last one kept reads the last. (The resolve applies the fade itself, in vector lanes:
    /// [`Ground::nearest_parts`] and [`faded`].)
    #[cfg(test)]
    pub(crate) fn nearest_at(&self, level: usize, x: f32, z: f32, fade: f32) -> [f32; 3] {
        faded(self.nearest_parts(level, x, z), fade)
    }

    /// [`Ground::nearest_at`] before the fade: the colour and the fine noise's factor.
    #[inline(always)]
    pub(crate) fn nearest_parts(&self, level: usize, x: f32, z: f32) -> [f32; 4] {
        match level.min(self.mips.len()) {
            0 => {
                let (u, v) = self.place(x, z, 0.0);
                self.albedo[v as u32 as usize * self.cols + u as u32 as usize]
            }
            l => {
                let m = &self.mips[l - 1];
                let inv = self.inv / (1u32 << l) as f32;
                let u = within(x * inv, (m.cols - 1) as f32);
                let v = within(z * inv, (m.rows - 1) as f32);
                m.cells[v as u32 as usize * m.cols + u as u32 as usize].unpack()
            }
        }
    }

    /// The ground's colour (sRGB 0–255, before light) at world `(x, z)` metres, bilinear between
    /// the cell centres, with `fade` of the fine noise: [`Ground::corner`], [`Ground::bilinear`]
    /// and [`faded`], which the resolve calls in its passes.
    #[cfg(test)]
    pub(crate) fn albedo_at(&self, x: f32, z: f32, fade: f32) -> [f32; 3] {
        faded(self.bilinear(self.corner(x, z)), fade)
    }

    /// Whether [`Ground::corner`] is exact for every point: the grid is under 2²³ cells a side
    /// (so is any grid that fits in memory, short of a line of cells).
    #[inline]
    pub(crate) fn corners_computed(&self) -> bool {
        self.last[0] < SMALL && self.last[1] < SMALL
    }

    /// Where [`Ground::albedo_at`] reads `(x, z)`: arithmetic only, without a branch, a lookup
    /// or a float-to-integer cast (which the compiler keeps scalar), so that the resolve
    /// computes it for a stretch of pixels in vector lanes ([`crate::shade`]); exact where
    /// [`Ground::corners_computed`], [`Ground::corner_cast`] else. [`Ground::bilinear`] reads
    /// the cells.
    #[inline(always)]
    pub(crate) fn corner(&self, x: f32, z: f32) -> Corner {
        let (u, v) = self.place(x, z, 0.5);
        // `u` and `v` are in `[0, last]` (a NaN became 0).
        self.corner_at(u, v, floor_small(u), floor_small(v))
    }

    /// [`Ground::corner`] by casts, for any grid.
    #[inline(always)]
    pub(crate) fn corner_cast(&self, x: f32, z: f32) -> Corner {
        let (u, v) = self.place(x, z, 0.5);
        let (c, r) = (u as u32, v as u32);
        self.corner_at(u, v, (c, c as f32), (r, r as f32))
    }

    /// The [`Corner`] of the cell position `(u, v)` whose floors are `(c, cf)` and `(r, rf)`
    /// (as an integer and as a float), however [`Ground::corner`] or [`Ground::corner_cast`]
    /// found them.
    #[inline(always)]
    fn corner_at(&self, u: f32, v: f32, (c, cf): (u32, f32), (r, rf): (u32, f32)) -> Corner {
        Corner {
            index: r.wrapping_mul(self.cols as u32).wrapping_add(c),
            fu: u - cf,
            fv: v - rf,
            // The next column and row, or these on the last.
            dc: u32::from(u < self.last[0]),
            dr: if v < self.last[1] { self.cols as u32 } else { 0 },
        }
    }

    /// The colour and the fine noise's factor bilinear between the four cells at `corner`.
    #[inline(always)]
    pub(crate) fn bilinear(&self, corner: Corner) -> [f32; 4] {
        let Corner { index, fu, fv, dc, dr } = corner;
        let (i, dc, dr) = (index as usize, dc as usize, dr as usize);
        let a = self.albedo;
        let top = lerp4(a[i].into(), a[i + dc].into(), fu);
        lerp4(top, lerp4(a[i + dr].into(), a[i + dr + dc].into(), fu), fv).to_array()
    }
}

/// The cell at or before a point in both directions (row-major `index`), the point's fractions
/// `fu`, `fv` past it, and the offsets of the next column (`dc`: 1, or 0 on the last) and row
/// (`dr`: a row of cells, or 0 on the last): [`Ground::corner`]. (32 bits: a colour map of 2³²
/// cells would be 64 GB.)
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Corner {
    pub(crate) index: u32,
    pub(crate) fu: f32,
    pub(crate) fv: f32,
    pub(crate) dc: u32,
    pub(crate) dr: u32,
}

/// A colour with its fine noise's factor ([`Ground::bilinear`]) as a pixel shows it with `fade`
/// of the noise: `colour × (1 + fade·factor)`.
#[inline(always)]
pub(crate) fn faded(p: [f32; 4], fade: f32) -> [f32; 3] {
    let k = 1.0 + fade * p[3];
    [p[0] * k, p[1] * k, p[2] * k]
}

/// `v` clamped to `[0, last]`, a NaN to 0: `v.max(0.0).min(last)` as two compares (a NaN fails
/// the first), without the NaN handling `f32::max` and `min` compile to (a tenth of a ground
/// pixel's instructions). `last` is never NaN.
#[inline(always)]
pub(super) fn within(v: f32, last: f32) -> f32 {
    let v = if v > 0.0 { v } else { 0.0 };
    if v < last { v } else { last }
}
