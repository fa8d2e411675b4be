//! The textured triangles' pixels eight at a time with AVX2 (issue 14): a row's run, or a narrow
//! box's row mask, in groups of eight lanes. Each group loads the eight samples' `1/w`, tests
//! depth, divides and finds the texels in lanes, loads the texels, and writes only the pixels
//! that pass both tests, with four masked vector stores (no branch per written pixel).
//!
//! Why: one pixel at a time, the depth test and the alpha test are branches on data, and each
//! pixel's chain — the sample's load, the division, the texel's address, its load — is long; a
//! visited pixel cost about 16 ns, and the simplified shapes visit 620,000 pixels per eye in the
//! 30-tree scene. In lanes the tests are masks and the branch left is on whether a group writes
//! anything. Measured frame by frame, the 30-tree frames take 0.96–1.0 of the time without
//! (`docs/renderer.md`): a group's chain (division, 32-bit multiply, texel load) stays long, and
//! narrow triangles' rows fill 4.6 of a group's eight lanes on average. The written pixels were
//! stored one set bit after another until 25 Nov: that loop's exit was mispredicted in most
//! groups, and the masked stores took the frames to 0.93–0.98 of the time (switched frame by
//! frame in one process).
//!
//! The same values as [`TexelSink::pixel`](super::TexelSink): a lane's attributes are the row's
//! start plus its offset times the step (the rasteriser's rule, [`crate::raster::rasterise::Sink`]), the
//! depth test is "not `1/w` ≤ the sample's" (a NaN passes, as there), the division and the
//! products are the same IEEE operations, the texel index is clamped as the 16-bit cast and
//! `min` clamp it, and alpha ≥ 128 is the texel's top bit. A test in `textured.rs` compares the
//! samples bit for bit, and `tests/simd.rs` whole frames.

use std::arch::x86_64::*;
use std::ops::Range;

use super::{Level, texel_sample};
use crate::raster::rasterise::{Sample, Surface};

/// Lanes in a group.
const LANES: i32 = 8;

/// Whether the texels' indices fit the lanes' `i32`.
fn fits(level: &Level<'_>) -> bool {
    level.texels.len() <= i32::MAX as usize
}

/// Draws pixels `k` in `ks` of the row whose first box column is sample `at` (the sink's
/// [`run`](crate::raster::rasterise::Sink::run)). `false` (nothing drawn) when the texels' indices do not
/// fit the lanes or a pixel lies past the samples: the caller draws them one at a time.
///
/// Safe to call where the CPU has AVX2.
#[target_feature(enable = "avx2")]
pub(super) fn run(
    samples: &mut [Sample],
    at: usize,
    level: &Level<'_>,
    ks: Range<i32>,
    row: [f32; 3],
    step: [f32; 3],
) -> bool {
    if ks.is_empty() {
        return true;
    }
    if ks.start < 0 || at + ks.end as usize > samples.len() || !fits(level) {
        return false;
    }
    let mut k0 = ks.start;
    while k0 < ks.end {
        let n = (ks.end - k0).min(LANES);
        group(samples, at, level, k0, (1 << n) - 1, row, step);
        k0 += LANES;
    }
    true
}

/// Draws pixels `k` for the set bits of `mask` of the row whose first box column is sample `at`
/// (the sink's [`masked`](crate::raster::rasterise::Sink::masked)); `false` as [`run`].
///
/// Safe to call where the CPU has AVX2.
#[target_feature(enable = "avx2")]
pub(super) fn masked(
    samples: &mut [Sample],
    at: usize,
    level: &Level<'_>,
    mask: u32,
    row: [f32; 3],
    step: [f32; 3],
) -> bool {
    if mask == 0 {
        return true;
    }
    let last = (31 - mask.leading_zeros()) as usize;
    if at + last >= samples.len() || !fits(level) {
        return false;
    }
    let (mut rest, mut k0) = (mask, 0);
    while rest != 0 {
        let live = rest & 0xff;
        if live != 0 {
            group(samples, at, level, k0, live, row, step);
        }
        rest >>= LANES;
        k0 += LANES;
    }
    true
}

/// One group: pixels `k0 + j` for the set bits `j` of `live` (8 bits). The caller checked that
/// every pixel from the group's first to its last live one has its sample.
#[target_feature(enable = "avx2")]
#[inline]
fn group(samples: &mut [Sample], at: usize, level: &Level<'_>, k0: i32, live: u32, row: [f32; 3], step: [f32; 3]) {
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let live_lanes = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(live as i32), bits), bits);
    let f = _mm256_cvtepi32_ps(_mm256_add_epi32(
        _mm256_set1_epi32(k0),
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
    ));
    // Row start plus offset times step: a product, then a sum, as one pixel at a time.
    let invw = _mm256_add_ps(_mm256_set1_ps(row[0]), _mm256_mul_ps(f, _mm256_set1_ps(step[0])));

    // The depth test against the samples' `1/w`, loaded one by one (a gather instruction took
    // longer than the eight loads here).
    let first = at + k0 as usize;
    let held = match samples.get(first..first + 8) {
        Some(s) => _mm256_setr_ps(
            s[0].invw, s[1].invw, s[2].invw, s[3].invw, s[4].invw, s[5].invw, s[6].invw, s[7].invw,
        ),
        // The row's last samples: lanes past the last live one read it again.
        None => {
            let last = first + (31 - live.leading_zeros()) as usize;
            let held = |j: usize| samples[(first + j).min(last)].invw;
            _mm256_setr_ps(held(0), held(1), held(2), held(3), held(4), held(5), held(6), held(7))
        }
    };
    let nearer_lanes = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_NLE_UQ>(invw, held),
        _mm256_castsi256_ps(live_lanes),
    );
    let nearer = _mm256_movemask_ps(nearer_lanes) as u32;
    if nearer == 0 {
        return;
    }

    // The texel: `(u/w) · w` across the level, truncated and clamped to its edges (so every
    // lane's index is a texel's, live or not).
    let uw = _mm256_add_ps(_mm256_set1_ps(row[1]), _mm256_mul_ps(f, _mm256_set1_ps(step[1])));
    let vw = _mm256_add_ps(_mm256_set1_ps(row[2]), _mm256_mul_ps(f, _mm256_set1_ps(step[2])));
    let w = _mm256_div_ps(_mm256_set1_ps(1.0), invw);
    let x = coordinate(
        _mm256_mul_ps(_mm256_mul_ps(uw, w), _mm256_set1_ps(level.size[0])),
        level.last[0],
    );
    let y = coordinate(
        _mm256_mul_ps(_mm256_mul_ps(vw, w), _mm256_set1_ps(level.size[1])),
        level.last[1],
    );
    let at_texel = _mm256_add_epi32(_mm256_mullo_epi32(y, _mm256_set1_epi32(level.stride as i32)), x);
    let low = _mm256_castsi256_si128(at_texel);
    let high = _mm256_extracti128_si256::<1>(at_texel);
    let index = [
        _mm_extract_epi32::<0>(low),
        _mm_extract_epi32::<1>(low),
        _mm_extract_epi32::<2>(low),
        _mm_extract_epi32::<3>(low),
        _mm_extract_epi32::<0>(high),
        _mm_extract_epi32::<1>(high),
        _mm_extract_epi32::<2>(high),
        _mm_extract_epi32::<3>(high),
    ];
    let texels = index.map(|i| u32::from_le_bytes(level.texels[i as usize]));
    // Alpha ≥ 128: the top bit of the little-endian RGBA word, each lane's sign.
    let [t0, t1, t2, t3, t4, t5, t6, t7] = texels.map(|t| t as i32);
    let texels_v = _mm256_setr_epi32(t0, t1, t2, t3, t4, t5, t6, t7);
    let won_lanes = _mm256_and_si256(_mm256_castps_si256(nearer_lanes), _mm256_srai_epi32::<31>(texels_v));
    match samples.get_mut(first..first + 8) {
        Some(eight) => store(eight, invw, texels_v, won_lanes),
        // The row's last samples: one at a time.
        None => {
            let mut won = nearer & _mm256_movemask_ps(_mm256_castsi256_ps(texels_v)) as u32;
            while won != 0 {
                let j = won.trailing_zeros() as usize;
                won &= won - 1;
                // The lane's `1/w` again: the same operations give the same bits.
                let invw = row[0] + (k0 + j as i32) as f32 * step[0];
                let [r, g, b, _] = texels[j].to_le_bytes();
                samples[first + j] = texel_sample(invw, [r, g, b]);
            }
        }
    }
}

/// Writes [`texel_sample`]`(invw, texel's colour)` into the samples of the lanes set in `won`
/// (all bits of a lane), without a branch per pixel: the eight samples are put together from
/// the lanes (`invw`, 0, `2·invw`, the colour's surface word: a 4 × 8 transpose) and written by
/// four masked stores. (Stored one set bit after another, the loop's exit was mispredicted in
/// most groups: about a fifth of the simplified shapes' time.)
#[target_feature(enable = "avx2")]
#[inline]
fn store(eight: &mut [Sample], invw: __m256, texels: __m256i, won: __m256i) {
    const { assert!(std::mem::size_of::<Sample>() == 16) };
    // The sample's fields in `repr(C)` order: `invw`, `hw` (0), `lw` (twice `invw`, as
    // `texel_sample` makes it: the same IEEE product) and the surface's word, the texel's
    // red, green and blue above the tag byte.
    let a = invw;
    let b = _mm256_setzero_ps();
    let c = _mm256_mul_ps(_mm256_set1_ps(2.0), invw);
    let d = _mm256_castsi256_ps(_mm256_or_si256(
        _mm256_slli_epi32::<8>(texels),
        _mm256_set1_epi32(i32::from(Surface::COLOUR_TAG)),
    ));
    // Per 128-bit half: [a0 b0 a1 b1], [a2 b2 a3 b3], [c0 d0 c1 d1], [c2 d2 c3 d3] (and lanes
    // 4–7 in the high halves), then whole samples: s0 | s4, s1 | s5, s2 | s6, s3 | s7.
    let (ab_low, ab_high) = (_mm256_unpacklo_ps(a, b), _mm256_unpackhi_ps(a, b));
    let (cd_low, cd_high) = (_mm256_unpacklo_ps(c, d), _mm256_unpackhi_ps(c, d));
    let pair = |x: __m256, y: __m256, high: bool| {
        let (x, y) = (_mm256_castps_pd(x), _mm256_castps_pd(y));
        _mm256_castpd_ps(if high {
            _mm256_unpackhi_pd(x, y)
        } else {
            _mm256_unpacklo_pd(x, y)
        })
    };
    let s04 = pair(ab_low, cd_low, false);
    let s15 = pair(ab_low, cd_low, true);
    let s26 = pair(ab_high, cd_high, false);
    let s37 = pair(ab_high, cd_high, true);
    let samples = [
        _mm256_permute2f128_ps::<0x20>(s04, s15),
        _mm256_permute2f128_ps::<0x20>(s26, s37),
        _mm256_permute2f128_ps::<0x31>(s04, s15),
        _mm256_permute2f128_ps::<0x31>(s26, s37),
    ];
    // Lane j's mask over its sample's four words.
    let spread = [
        _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1),
        _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3),
        _mm256_setr_epi32(4, 4, 4, 4, 5, 5, 5, 5),
        _mm256_setr_epi32(6, 6, 6, 6, 7, 7, 7, 7),
    ];
    let at = eight.as_mut_ptr().cast::<f32>();
    for (k, (s, spread)) in samples.into_iter().zip(spread).enumerate() {
        let mask = _mm256_permutevar8x32_epi32(won, spread);
        // SAFETY: `eight` holds eight 16-byte samples, 32 words, and this writes words
        // `8k .. 8k + 8` (k < 4) where the mask is set: within it. `Sample` is `repr(C)` of
        // three `f32` and a 4-byte `Surface` (`repr(u8)`: the tag then the colour's bytes), so
        // the words written are a whole sample's fields, and the surface word is a valid
        // `Surface::Colour`.
        #[allow(unsafe_code)]
        unsafe {
            _mm256_maskstore_ps(at.add(8 * k), mask, s);
        }
    }
}

/// `(t as u16).min(last)` per lane: NaN and below 0 give 0, past 65,535 it saturates (`max`
/// returns its second operand, 0, when the first is NaN).
#[target_feature(enable = "avx2")]
#[inline]
fn coordinate(t: __m256, last: u16) -> __m256i {
    let t = _mm256_min_ps(
        _mm256_max_ps(t, _mm256_setzero_ps()),
        _mm256_set1_ps(f32::from(u16::MAX)),
    );
    _mm256_min_epi32(_mm256_cvttps_epi32(t), _mm256_set1_epi32(i32::from(last)))
}
