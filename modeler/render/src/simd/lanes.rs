//! The lane helpers of the stages, each a safe function with one body per target: SSE2
//! intrinsics on x86-64 (part of the architecture, so no run-time choice) and plain arrays
//! elsewhere, or a portable vector type (`wide`), or a fold the compiler vectorises. Which
//! helpers are written in intrinsics is measured (issue 38): only those that pay 5 % of a frame
//! or more.
//!
//! - [`RowLanes`]: the rasteriser's edge tests over a narrow box's row, sixteen pixels at once.
//!   SSE2 (`pmovmskb` gathers the covered lanes' bits, where the compiler built the mask a few
//!   bits at a time): the terrain's frames take 0.84–0.91 of the time of the plain arrays, the
//!   trees' 0.97 (one core, the two paths switched frame by frame in one process).
//! - [`lanes_where`], [`lanes_set`]: which pixels of a land-look stretch are covered, far, or of
//!   another surface. Folds: SSE2 movemasks bought at most 1–2 % of a land frame, and were
//!   dropped.
//! - [`lerp4`]: the ground's bilinear colour, four channels in one `wide::f32x4`.
//!
//! (The textured polygons' pixels had an AVX2 path in intrinsics, eight pixels to a group; the
//! tree frames took as long with it as without — 1.00–1.03 of the time without — and it was
//! dropped. Their runs keep its values: each pixel's attributes are its row's start plus its
//! offset times the step.)

use wide::f32x4;

/// Pixels in a narrow box's row: [`RowLanes`] tests this many at once.
pub(crate) const ROW_LANES: usize = 16;

/// The edge functions' offsets along a row, lane by lane, for the rasteriser's test of a narrow
/// box's rows (`rows_by_mask`; three edges for a triangle, four for a quad). On x86-64 in SSE2 registers, four lanes to each: the
/// covered lanes' bits come from the lanes' signs packed to bytes and gathered by one
/// instruction (`pmovmskb`), where the compiler built the mask from the sixteen comparisons a
/// few bits at a time, most of a sliver's row.
#[cfg(target_arch = "x86_64")]
pub(crate) struct RowLanes<const N: usize>([[std::arch::x86_64::__m128i; ROW_LANES / 4]; N]);

#[cfg(target_arch = "x86_64")]
impl<const N: usize> RowLanes<N> {
    /// Lane `k`'s offset `k·step` from the row's first pixel, per edge. (No overflow:
    /// `fits_lanes` bounds `|step|·ROW_LANES`.)
    #[inline(always)]
    #[allow(unsafe_code)]
    pub(crate) fn new(steps: [i32; N]) -> RowLanes<N> {
        use std::arch::x86_64::{_mm_add_epi32, _mm_set1_epi32, _mm_setr_epi32};
        // SAFETY: SSE2 is part of x86-64 itself (every x86-64 CPU has it), the one requirement
        // of these intrinsics; they take no pointers.
        unsafe {
            let mut lanes = [[_mm_set1_epi32(0); ROW_LANES / 4]; N];
            for (edge, s) in lanes.iter_mut().zip(steps) {
                let four = _mm_set1_epi32(4 * s);
                let mut at = _mm_setr_epi32(0, s, 2 * s, 3 * s);
                for quad in edge.iter_mut() {
                    *quad = at;
                    at = _mm_add_epi32(at, four);
                }
            }
            RowLanes(lanes)
        }
    }

    /// Bit `k` set where every edge function `rows[i] + k·step_i` is ≥ 0: its sign is clear.
    /// The packs saturate, which keeps each lane's sign.
    #[inline(always)]
    #[allow(unsafe_code)]
    pub(crate) fn covered(&self, rows: [i32; N]) -> u32 {
        use std::arch::x86_64::{
            _mm_add_epi32, _mm_movemask_epi8, _mm_or_si128, _mm_packs_epi16, _mm_packs_epi32, _mm_set1_epi32,
        };
        // SAFETY: as in `new`: SSE2 only, no pointers.
        unsafe {
            let mut v = [_mm_set1_epi32(0); ROW_LANES / 4];
            for (offsets, &r) in self.0.iter().zip(&rows) {
                let r = _mm_set1_epi32(r);
                for (v, &o) in v.iter_mut().zip(offsets) {
                    *v = _mm_or_si128(*v, _mm_add_epi32(r, o));
                }
            }
            let low = _mm_packs_epi32(v[0], v[1]);
            let high = _mm_packs_epi32(v[2], v[3]);
            let negative = _mm_movemask_epi8(_mm_packs_epi16(low, high)) as u32;
            !negative & 0xffff
        }
    }
}

/// [`RowLanes`] in plain arrays, elsewhere.
#[cfg(not(target_arch = "x86_64"))]
pub(crate) struct RowLanes<const N: usize>([[i32; ROW_LANES]; N]);

#[cfg(not(target_arch = "x86_64"))]
impl<const N: usize> RowLanes<N> {
    #[inline(always)]
    pub(crate) fn new(steps: [i32; N]) -> RowLanes<N> {
        RowLanes(steps.map(|s| std::array::from_fn(|k| k as i32 * s)))
    }

    #[inline(always)]
    pub(crate) fn covered(&self, rows: [i32; N]) -> u32 {
        let mut mask = 0u32;
        for k in 0..ROW_LANES {
            let v = self.0.iter().zip(&rows).fold(0, |acc, (o, r)| acc | (r + o[k]));
            mask |= u32::from(v >= 0) << k;
        }
        mask
    }
}

/// `a + t·(b − a)` on four lanes, as one vector each (the compiler did it a lane at a time: the
/// bilinear colour was about 110 instructions a pixel); each lane is the same IEEE operations in
/// the same order, so the same bits.
#[inline(always)]
pub(crate) fn lerp4(a: f32x4, b: f32x4, t: f32) -> f32x4 {
    a + (b - a) * f32x4::splat(t)
}

/// Bit `k` set where `values[k] > t` (`ABOVE`) or `values[k] < t` (else), IEEE compares (a NaN
/// fails both); `N` is at most 64.
#[inline(always)]
pub(crate) fn lanes_where<const ABOVE: bool, const N: usize>(values: &[f32; N], t: f32) -> u64 {
    const { assert!(N <= 64) };
    let test = |v: f32| if ABOVE { v > t } else { v < t };
    values
        .iter()
        .enumerate()
        .fold(0u64, |m, (k, &v)| m | u64::from(test(v)) << k)
}

/// Bit `k` set where `flags[k]` is not 0; `N` is at most 64.
#[inline(always)]
pub(crate) fn lanes_set<const N: usize>(flags: &[u8; N]) -> u64 {
    const { assert!(N <= 64) };
    flags
        .iter()
        .enumerate()
        .fold(0u64, |m, (k, &f)| m | u64::from(f != 0) << k)
}
