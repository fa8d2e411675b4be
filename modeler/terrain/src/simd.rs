//! Runtime dispatch of the engine's hot loops to AVX2 (issue 18).
//!
//! The workspace builds for baseline x86-64, whose vector instructions (SSE2) hold two `f64`
//! lanes; the machines the modeler runs on (and CI's) have AVX2, four. The loops over a stretch
//! of cells (eq. 1–3's blend, the paint, a slope's shapes, the distance transforms' passes) are
//! therefore compiled twice: once for the baseline, once inside a
//! `#[target_feature(enable = "avx2")]` function that calls the same `#[inline(always)]` body, so
//! that LLVM vectorises that copy four lanes wide. [`avx2`] picks one at run time.
//!
//! The two copies give the same numbers to the bit: AVX2 adds no operation the baseline copy
//! does not have, and an IEEE addition, multiplication, division, square root or conversion gives
//! the same result in any lane of any width. FMA is deliberately **not** enabled: a fused
//! multiply-add rounds once where the baseline rounds twice, so the heights would depend on the
//! machine. The tests run both copies on the same inputs and compare the bits, so the baseline
//! copy stays tested on an AVX2 machine (`tests/simd.rs`). The renderer does the same for its
//! pixel loops (`penmodel_render::simd`).

use std::sync::atomic::{AtomicBool, Ordering};

/// Set while the baseline copies are forced (tests only).
static BASELINE: AtomicBool = AtomicBool::new(false);

/// Whether the AVX2 copies run: the CPU has AVX2 and the baseline is not forced. The standard
/// library caches the CPU's features after the first question, so this is two loads.
#[inline(always)]
pub(crate) fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        !BASELINE.load(Ordering::Relaxed) && std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Forces the baseline copies (`true`) or lets [`avx2`] choose again (`false`), for every thread:
/// for tests that compare the two copies' terrains. The results are the same either way, so a
/// test running meanwhile is not disturbed.
#[doc(hidden)]
pub fn force_baseline(on: bool) {
    BASELINE.store(on, Ordering::Relaxed);
}

/// Whether this CPU has the AVX2 copies at all (tests say which copies they compared).
#[doc(hidden)]
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Defines `fn $name(args) -> R` calling `$body(args)`, an `#[inline(always)]` function, through
/// a copy compiled for AVX2 when [`avx2`] says so, else the baseline copy:
///
/// ```text
/// twice! {
///     /// Docs of `paint`.
///     fn paint(out: &mut [f32], coef: &[f32]) = paint_body;
/// }
/// ```
macro_rules! twice {
    ($(#[$attr:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? = $body:path;) => {
        $(#[$attr])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                // The body inlined here is compiled with AVX2, and without FMA (the module says
                // why).
                #[target_feature(enable = "avx2")]
                fn avx2_copy($($arg: $ty),*) $(-> $ret)? {
                    $body($($arg),*)
                }
                if $crate::simd::avx2() {
                    // SAFETY: the CPU has AVX2 (`avx2()` asked it), the one requirement of
                    // calling a function compiled for it.
                    #[allow(unsafe_code)]
                    return unsafe { avx2_copy($($arg),*) };
                }
            }
            $body($($arg),*)
        }
    };
}
pub(crate) use twice;
