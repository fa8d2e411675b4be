//! Stereo: combining the two eyes' images.
//!
//! Each eye is its own off-axis projection from the tracked head (or the orbit camera) ± half
//! the eye separation ([`crate::raster::camera`]); this module only combines the pictures.
//!
//! - **Anaglyph**, red–cyan, *half-colour*: the red channel is the left eye's luminance
//!   (Rec. 601 weights), green and blue are the right eye's. A full-colour anaglyph would take the
//!   left eye's red channel alone, and grass, forest and water — most of a landscape — have
//!   little red, so the left eye would see a dark picture and the two would not fuse.
//! - **Side by side**: each eye drawn into its half of the frame at the full frame's aspect, i.e.
//!   squeezed to half width ("half side-by-side", which 3D displays stretch back).

use rayon::prelude::*;

use super::frame::{Frame, Rgba};

/// Rec. 601 luminance of a colour.
#[inline(always)]
pub fn luma(p: Rgba) -> u8 {
    ((299 * u32::from(p[0]) + 587 * u32::from(p[1]) + 114 * u32::from(p[2]) + 500) / 1000) as u8
}

/// Replaces `right`'s red channel by the luminance of `left` (same size): the anaglyph.
pub(crate) fn anaglyph(left: &Frame, right: &mut Frame) {
    right
        .pixels_mut()
        .par_chunks_mut(4096)
        .zip(left.pixels().par_chunks(4096))
        .for_each(|(r, l)| crate::simd::dispatch!(red_from_luma, (r, l)));
}

/// `right`'s red channels from `left`'s luminance, compiled for the baseline and for AVX2
/// ([`crate::simd`]: AVX2 multiplies eight 32-bit lanes, which SSE2 cannot).
#[inline(always)]
fn red_from_luma(right: &mut [Rgba], left: &[Rgba]) {
    for (r, l) in right.iter_mut().zip(left) {
        r[0] = luma(*l);
    }
}
