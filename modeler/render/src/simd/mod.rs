//! The renderer's lane code, all of it: the run-time dispatch of the per-pixel loops to AVX2
//! (issue 14), and the lane helpers the stages call ([`lanes`], [`floor`]).
//!
//! **One dispatch idiom.** The workspace builds for baseline x86-64 (SSE2: four `f32` lanes, no
//! 32-bit lane multiply, no variable shifts); the machines the modeler runs on, and CI's, have
//! AVX2. The loops over every pixel of a frame that vectorise — the land look's resolve
//! ([`crate::shade`], written in passes for it), the anaglyph ([`crate::output::stereo`]) and
//! the reprojection's rows ([`crate::lod::reproject`]) — are compiled twice: once for the
//! baseline, once inside a `#[target_feature(enable = "avx2")]` function that calls the same
//! `#[inline(always)]` body, so that LLVM uses eight lanes in that copy: `dispatch!` in place
//! of the call. [`avx2`] picks one at run time, from the terrain engine's choice of copy
//! (`penmodel_terrain::simd`: one detection of the CPU and one test switch for both crates).
//! Nothing else chooses at run time: the helpers in [`lanes`] are SSE2 (part of x86-64) or
//! portable, and inlined into whichever copy calls them. (The triangles' pixel loops step their
//! attributes one addition after another, which no vector width changes, so they are compiled
//! once.)
//!
//! The two copies give the same bytes: AVX2 adds no operation the baseline copy lacks, and an
//! IEEE addition, multiplication, division, square root or conversion gives the same result in
//! any lane of any width. FMA is deliberately **not** enabled (Rust never fuses on its own, but a
//! fused multiply-add written later would round once where the baseline rounds twice). The tests
//! render the same scenes with both copies and compare the bytes
//! (`tests/simd.rs`), so the baseline copy stays tested on an AVX2 machine.

pub(crate) mod floor;
pub(crate) mod lanes;

use std::sync::OnceLock;

use penmodel_terrain::simd::{Level, available, force_at_most, level};

/// The environment variable that, set to `1`, keeps the baseline copies for the whole process
/// (to measure what the AVX2 copies bring, or to rule them out).
pub const BASELINE_VARIABLE: &str = "PENMODEL_RENDER_BASELINE";

/// Whether the AVX2 copies run: the terrain engine's choice of copy ([`penmodel_terrain::simd`]:
/// the CPU's widest, unless a test capped it) is AVX2 or wider, and [`BASELINE_VARIABLE`] is not
/// `1` (asked once). A few loads.
#[inline(always)]
pub(crate) fn avx2() -> bool {
    static VARIABLE: OnceLock<bool> = OnceLock::new();
    level() >= Level::Avx2 && !*VARIABLE.get_or_init(|| std::env::var(BASELINE_VARIABLE).as_deref() == Ok("1"))
}

/// Forces the baseline copies (`true`) or lets the CPU choose again (`false`), for every thread
/// and the terrain engine's copies too (they give the same bits). Both copies draw the same
/// bytes, so a frame drawn meanwhile is not disturbed.
#[doc(hidden)]
pub fn force_baseline(on: bool) {
    force_at_most(if on { Level::Baseline } else { Level::Avx512 });
}

/// Whether this CPU runs the AVX2 copies at all (tests say which copies they compared).
#[doc(hidden)]
pub fn has_avx2() -> bool {
    available() >= Level::Avx2
}

/// Calls `body(args…)`, an `#[inline(always)]` function, compiled for AVX2 when [`avx2`] says
/// so, else for the baseline: `dispatch!(body, (a, b))` in place of `body(a, b)`. Only what is
/// inlined into the body is compiled twice: its hot callees are `#[inline(always)]` too.
macro_rules! dispatch {
    ($body:path, ( $($arg:expr),* $(,)? )) => {{
        #[cfg(target_arch = "x86_64")]
        {
            if $crate::simd::avx2() {
                #[target_feature(enable = "avx2")]
                fn avx2_copy<R>(f: impl FnOnce() -> R) -> R {
                    f()
                }
                // SAFETY: the CPU has AVX2 (`avx2()` asked it), the one requirement of calling a
                // function compiled for it.
                #[allow(unsafe_code)]
                unsafe {
                    avx2_copy(#[inline(always)] || $body($($arg),*))
                }
            } else {
                $body($($arg),*)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $body($($arg),*)
        }
    }};
}
pub(crate) use dispatch;
