//! The textured triangles' pixels eight at a time with AVX2 (issue 14): a row's run, or a narrow
//! box's row mask, in groups of eight lanes. Each group loads the eight samples' `1/w`, tests
//! depth, divides and finds the texels in lanes, loads the texels, and writes only the pixels
//! that pass both tests.
//!
//! Why: one pixel at a time, the depth test and the alpha test are branches on data, and each
//! pixel's chain — the sample's load, the division, the texel's address, its load — is long; a
//! visited pixel cost about 16 ns, and the simplified shapes visit 620,000 pixels per eye in the
//! 30-tree scene. In lanes the tests are masks and the branch left is on whether a group writes
//! anything. Measured frame by frame, the 30-tree frames take 0.96–1.0 of the time without
//! (`docs/renderer.md`): a group's chain (division, 32-bit multiply, texel load) stays long, and
//! narrow triangles' rows fill 4.6 of a group's eight lanes on average.
//!
//! The same values as [`TexelSink::pixel`](super::TexelSink): a lane's attributes are the row's
//! start plus its offset times the step (the rasteriser's rule, [`crate::rasterise::Sink`]), the
//! depth test is "not `1/w` ≤ the sample's" (a NaN passes, as there), the division and the
//! products are the same IEEE operations, the texel index is clamped as the 16-bit cast and
//! `min` clamp it, and alpha ≥ 128 is the texel's top bit. A test in `textured.rs` compares the
//! samples bit for bit, and `tests/simd.rs` whole frames.

use std::arch::x86_64::*;
use std::ops::Range;

use super::{Level, texel_sample};
use crate::rasterise::Sample;

/// Lanes in a group.
const LANES: i32 = 8;

/// Whether the texels' indices fit the lanes' `i32`.
fn fits(level: &Level<'_>) -> bool {
    level.texels.len() <= i32::MAX as usize
}

/// Draws pixels `k` in `ks` of the row whose first box column is sample `at` (the sink's
/// [`run`](crate::rasterise::Sink::run)). `false` (nothing drawn) when the texels' indices do not
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
/// (the sink's [`masked`](crate::rasterise::Sink::masked)); `false` as [`run`].
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
    let nearer = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_NLE_UQ>(invw, held),
        _mm256_castsi256_ps(live_lanes),
    );
    let nearer = _mm256_movemask_ps(nearer) as u32;
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
    let opaque = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_setr_epi32(t0, t1, t2, t3, t4, t5, t6, t7))) as u32;
    let mut won = nearer & opaque;
    while won != 0 {
        let j = won.trailing_zeros() as usize;
        won &= won - 1;
        // The lane's `1/w` again: the same operations give the same bits.
        let invw = row[0] + (k0 + j as i32) as f32 * step[0];
        let [r, g, b, _] = texels[j].to_le_bytes();
        samples[first + j] = texel_sample(invw, [r, g, b]);
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
