//! Runtime dispatch of the engine's hot loops to AVX2 and AVX-512 (issue 18).
//!
//! The workspace builds for baseline x86-64, whose vector instructions (SSE2) hold two `f64`
//! lanes; the machines the modeler runs on (and CI's) have AVX2, four, and AVX-512, eight. The
//! loops over a stretch of cells (eq. 1–3's blend, the paint, a slope's shapes, the distance
//! transforms' passes) are therefore compiled three times: once for the baseline, and inside a
//! `#[target_feature(enable = "avx2")]` and a `#[target_feature(enable = "avx512f,…")]`
//! function that call the same `#[inline(always)]` body, so that LLVM vectorises those copies
//! four and eight lanes wide. [`level`] picks one at run time, the widest the CPU has.
//!
//! The copies give the same numbers to the bit: they add no operation the baseline copy does
//! not have, and an IEEE addition, multiplication, division, square root or conversion gives the
//! same result in any lane of any width. Fused multiply-adds would not (they round once where the
//! baseline rounds twice): the AVX2 copy does not enable FMA, and in the AVX-512 copy, where
//! LLVM's `avx512f` brings FMA with it, nothing fuses either, since Rust never contracts `a*b + c`
//! on its own. The tests (`tests/simd.rs`) run every copy the CPU has on the same documents and
//! edits and compare the bits, so the baseline and AVX2 copies stay tested on an AVX-512 machine.
//! The renderer does the same for its pixel loops (`penmodel_render::simd`, AVX2 only).
//!
//! Valgrind's CPU has no AVX-512: callgrind counts the AVX2 copy.

use std::sync::atomic::{AtomicU8, Ordering};

/// The copies of the hot loops, narrowest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// Baseline x86-64 (SSE2), or another architecture.
    Baseline,
    /// AVX2, without FMA.
    Avx2,
    /// AVX-512 (F, DQ, VL, BW).
    Avx512,
}

/// The widest copy allowed to run (tests only lower it): a [`Level`] as a number.
static CAP: AtomicU8 = AtomicU8::new(Level::Avx512 as u8);

/// The widest copy this CPU has. The standard library caches the CPU's features after the first
/// question, so this is a few loads.
#[inline(always)]
pub fn available() -> Level {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if has!("avx512f") && has!("avx512dq") && has!("avx512vl") && has!("avx512bw") {
            Level::Avx512
        } else if has!("avx2") {
            Level::Avx2
        } else {
            Level::Baseline
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Level::Baseline
    }
}

/// The copy that runs: the widest the CPU has, at most the cap [`force_at_most`] set.
#[inline(always)]
pub fn level() -> Level {
    let cap = match CAP.load(Ordering::Relaxed) {
        0 => Level::Baseline,
        1 => Level::Avx2,
        _ => Level::Avx512,
    };
    available().min(cap)
}

/// Runs at most copy `cap` from now on, on every thread (`Level::Avx512`: the CPU's choice again):
/// for tests that compare the copies' terrains. The results are the same whichever runs, so a
/// test running meanwhile is not disturbed.
#[doc(hidden)]
pub fn force_at_most(cap: Level) {
    CAP.store(cap as u8, Ordering::Relaxed);
}

/// Defines `fn $name(args) -> R` calling `$body(args)`, an `#[inline(always)]` function, through
/// the copy [`level`] picks (what is inlined into the body is compiled with its features):
///
/// ```text
/// copies! {
///     /// Docs of `paint`.
///     fn paint(out: &mut [f32], coef: &[f32]) = paint_body;
/// }
/// ```
macro_rules! copies {
    ($(#[$attr:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? = $body:path;) => {
        $(#[$attr])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                // Without FMA (the module says why).
                #[target_feature(enable = "avx2")]
                fn avx2_copy($($arg: $ty),*) $(-> $ret)? {
                    $body($($arg),*)
                }
                #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
                fn avx512_copy($($arg: $ty),*) $(-> $ret)? {
                    $body($($arg),*)
                }
                match $crate::simd::level() {
                    // SAFETY: the CPU has the copy's features (`level()` asked it), the one
                    // requirement of calling a function compiled for them.
                    #[allow(unsafe_code)]
                    $crate::simd::Level::Avx512 => return unsafe { avx512_copy($($arg),*) },
                    #[allow(unsafe_code)]
                    $crate::simd::Level::Avx2 => return unsafe { avx2_copy($($arg),*) },
                    $crate::simd::Level::Baseline => {}
                }
            }
            $body($($arg),*)
        }
    };
}
pub(crate) use copies;
