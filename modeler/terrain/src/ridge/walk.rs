//! The sky view's hull walks ([`super::sun::sky_view`]), the [`LANES`] lines of a block side by
//! side: one walk step for all of them at a time.
//!
//! A line's walk (the tests' reference, `sections::Hull`) is bound by its data-dependent branch — how many
//! vertices a sample pops — not by its instructions. Nine steps in ten pop at most one vertex,
//! and those need only the top two vertices of the stack: each lane keeps them apart (`s1, h1`
//! and `s2, h2`) from the rest of its stack, so that the common step is the same branch-free
//! arithmetic in every lane, eight lanes to a vector. The lanes that push the previous sample (no
//! pop), pop two or more, or restart (below) are finished one by one afterwards, from bit masks:
//! a branch per such lane rather than a guess per sample. The arithmetic is `Hull`'s, operation
//! for operation (positions are whole steps, exact in `f32`), so the values are the same to the
//! bit; a test compares them.
//!
//! Only horizons above the horizontal are wanted (the sky view's `sin² H` is 0 below): a sample
//! at least as high as every sample ahead gets rise 0 and empties its lane's stack: everything
//! ahead of it is lower and farther from the samples walked later, so it can give none of them
//! a larger positive tangent. About a fifth of the bench's samples are such running maxima.

use wide::f32x8;

/// Lines walked side by side: the block of [`super::sun`].
pub(super) const LANES: usize = 32;

/// The height a lane's samples off the grid get: below any terrain, so the first sample on the
/// grid is a running maximum and starts the lane afresh; what the walk gives the samples off
/// the grid is not used.
pub(super) const OFF_GRID: f32 = -1.0e30;

/// The bottom of every stack: a vertex no line to the next one passes over (infinitely low), so
/// that the pop tests need no check for an empty stack. Its position only has to be finite.
const BOTTOM_S: f32 = 1.0;
const BOTTOM_H: f32 = f32::NEG_INFINITY;

type Lanes<T> = [T; LANES];

/// Lanes a vector holds (explicit SIMD by `wide`: safe, and plain SSE2 pairs on x86-64's
/// baseline — the compiler did not vectorise the selects and masks of the step on its own).
const V: usize = 8;
/// Vectors per block.
const G: usize = LANES / V;

/// The walks of one block's lines: per lane the top two vertices of its upper hull (`s1, h1`
/// and `s2, h2`: positions and heights), the previous sample (one step ahead, not yet on the
/// hull), the highest sample ahead and the vertex count `n`; the vertices under the top two in
/// memory, `cap` per lane.
pub(super) struct Walk {
    s1: Lanes<f32>,
    h1: Lanes<f32>,
    s2: Lanes<f32>,
    h2: Lanes<f32>,
    prev: Lanes<f32>,
    max: Lanes<f32>,
    n: Lanes<u32>,
    cap: usize,
    ms: Vec<f32>,
    mh: Vec<f32>,
}

impl Default for Walk {
    fn default() -> Walk {
        let all = |v: f32| [v; LANES];
        Walk {
            s1: all(BOTTOM_S),
            h1: all(BOTTOM_H),
            s2: all(BOTTOM_S),
            h2: all(BOTTOM_H),
            prev: all(OFF_GRID),
            max: all(f32::NEG_INFINITY),
            n: [0; LANES],
            cap: 0,
            ms: Vec::new(),
            mh: Vec::new(),
        }
    }
}

/// `sin² H` of a horizon `rise / (steps·spacing)`, 0 for one at or below the horizontal;
/// `sp2` is the spacing squared.
#[inline]
fn sin2(rise: f32, steps: f32, sp2: f32) -> f32 {
    let r = if rise > 0.0 { rise } else { 0.0 };
    r * r / (r * r + steps * steps * sp2)
}

/// [`sin2`] in every lane, operation for operation (so a lane's value does not depend on which
/// path computed it).
#[inline(always)]
fn sin2_lanes(rise: f32x8, steps: f32x8, sp2: f32x8) -> f32x8 {
    let zero = f32x8::ZERO;
    let r = rise.simd_gt(zero).select(rise, zero);
    r * r / (r * r + steps * steps * sp2)
}

/// Vector g of lanes `v`.
#[inline(always)]
fn get(v: &Lanes<f32>, g: usize) -> f32x8 {
    f32x8::new(v.as_chunks::<V>().0[g])
}

/// Sets vector g of lanes `v`.
#[inline(always)]
fn set(v: &mut Lanes<f32>, g: usize, x: f32x8) {
    v.as_chunks_mut::<V>().0[g] = x.to_array();
}

impl Walk {
    /// Walks the lanes of `heights` (`w` columns of [`LANES`] samples: line j's sample at column
    /// u is `heights[u·LANES + j]`, [`OFF_GRID`] where the line is off the grid) from the far
    /// end back — from the last column to the first when `AHEAD_UP`, else from the first — and
    /// stores each sample's `sin² H` in `out` (laid out the same), or adds it with `ADD`; `sp2`
    /// is the spacing of the samples squared. Horizons above the horizontal only (below).
    pub fn sky<const AHEAD_UP: bool, const ADD: bool>(&mut self, heights: &[f32], sp2: f32, out: &mut [f32]) {
        self.run::<AHEAD_UP, true, ADD>(heights, sp2, out);
    }

    /// [`Walk::sky`]'s walk for whole horizons: each sample's horizon tangent
    /// `rise / (steps·spacing)` into `out`, NaN for the first sample on the grid (nothing ahead),
    /// as a line's walk (`sections::Hull::pass`) gives them. The lanes restart where they are off the
    /// grid rather than at running maxima.
    pub fn horizons<const AHEAD_UP: bool>(&mut self, heights: &[f32], spacing: f32, out: &mut [f32]) {
        self.run::<AHEAD_UP, false, false>(heights, spacing, out);
    }

    fn run<const AHEAD_UP: bool, const SKY: bool, const ADD: bool>(
        &mut self,
        heights: &[f32],
        k: f32,
        out: &mut [f32],
    ) {
        let (columns, _) = heights.as_chunks::<LANES>();
        let (outs, _) = out.as_chunks_mut::<LANES>();
        self.reset(columns.len());
        let mut s = 0.0f32;
        let mut walk = |h: &Lanes<f32>, o: &mut Lanes<f32>| {
            self.step::<SKY, ADD>(h, s, k, o);
            s -= 1.0;
        };
        if AHEAD_UP {
            columns.iter().zip(outs.iter_mut()).rev().for_each(|(h, o)| walk(h, o));
        } else {
            columns.iter().zip(outs.iter_mut()).for_each(|(h, o)| walk(h, o));
        }
    }

    /// Every lane empty, with room for `w` vertices.
    fn reset(&mut self, w: usize) {
        let cap = w + 1;
        if self.cap < cap {
            self.cap = cap;
            self.ms.resize(cap * LANES, 0.0);
            self.mh.resize(cap * LANES, 0.0);
        }
        // Nothing behind the first column: no previous sample (off the grid), no vertex.
        *self = Walk {
            cap: self.cap,
            ms: std::mem::take(&mut self.ms),
            mh: std::mem::take(&mut self.mh),
            ..Walk::default()
        };
    }

    /// One sample per lane, `h`, at position `s` (minus the steps walked, so positions grow
    /// ahead; exact integers in `f32`). With `SKY` the value is `sin² H` (`k` the spacing
    /// squared), else the tangent (`k` the spacing).
    #[inline(always)]
    fn step<const SKY: bool, const ADD: bool>(&mut self, h: &Lanes<f32>, s: f32, k: f32, out: &mut Lanes<f32>) {
        let sv = f32x8::splat(s);
        let (zero, one, kv) = (f32x8::ZERO, f32x8::ONE, f32x8::splat(k));
        let (off, nan) = (f32x8::splat(OFF_GRID), f32x8::splat(f32::NAN));
        let (mut push, mut slow, mut restart) = (0u32, 0u32, 0u32);
        // The common step, the same in every lane: the previous sample tested against the top
        // vertex (`Hull`'s first test), and, popped, the top vertex against the one under it (its
        // second). The lanes that need more are bits of `push`, `slow` and `restart`; the lanes
        // of `slow` keep their output for below.
        for g in 0..G {
            let hl = get(h, g);
            let prev = get(&self.prev, g);
            let a = prev - hl;
            let (c1, d1) = (get(&self.s1, g) - sv, get(&self.h1, g) - hl);
            let (c2, d2) = (get(&self.s2, g) - sv, get(&self.h2, g) - hl);
            // The previous sample's `b` is 1: `d1 · 1` is `d1` exactly.
            let keep_prev = (a * c1).simd_gt(d1);
            let keep_top = (d1 * c2).simd_gt(d2 * c1);
            let top = if SKY {
                hl.simd_ge(get(&self.max, g))
            } else {
                hl.simd_eq(off)
            };
            let more = !(keep_prev | keep_top | top);
            let rise = top.select(zero, keep_prev.select(a, d1));
            let steps = (top | keep_prev).select(one, c1);
            let v = if SKY {
                sin2_lanes(rise, steps, kv)
            } else {
                // Nothing ahead of the first sample on the grid.
                prev.simd_eq(off).select(nan, rise / (steps * kv))
            };
            let old = get(out, g);
            set(out, g, more.select(old, if ADD { old + v } else { v }));
            push |= (keep_prev & !top).to_bitmask() << (g * V);
            slow |= more.to_bitmask() << (g * V);
            restart |= top.to_bitmask() << (g * V);
        }
        // The lanes that push the previous sample, those that pop on, and those that restart
        // (a branch per such lane, not per lane; `& (LANES - 1)` spares the bounds checks).
        while push != 0 {
            let l = push.trailing_zeros() as usize & (LANES - 1);
            push &= push - 1;
            self.push(l, s + 1.0);
        }
        while slow != 0 {
            let l = slow.trailing_zeros() as usize & (LANES - 1);
            slow &= slow - 1;
            let (rise, steps) = self.pop_more(l, s, h[l]);
            let v = if SKY { sin2(rise, steps, k) } else { rise / (steps * k) };
            out[l] = if ADD { out[l] + v } else { v };
        }
        while restart != 0 {
            let l = restart.trailing_zeros() as usize & (LANES - 1);
            restart &= restart - 1;
            (self.max[l], self.n[l]) = (h[l], 0);
            (self.s1[l], self.h1[l], self.s2[l], self.h2[l]) = (BOTTOM_S, BOTTOM_H, BOTTOM_S, BOTTOM_H);
        }
        // Every sample becomes its lane's previous one.
        self.prev = *h;
    }

    /// Lane l's previous sample, at position `s`, onto its hull.
    #[inline]
    fn push(&mut self, l: usize, s: f32) {
        let n = self.n[l] as usize;
        if n >= 2 {
            let i = l * self.cap + n - 2;
            (self.ms[i], self.mh[i]) = (self.s2[l], self.h2[l]);
        }
        (self.s2[l], self.h2[l]) = (self.s1[l], self.h1[l]);
        (self.s1[l], self.h1[l]) = (s, self.prev[l]);
        self.n[l] += 1;
    }

    /// Lane l's step when the top vertex is popped too: the walk goes on down the stack in
    /// memory from the second vertex (the candidate) until the candidate lies above the line to
    /// the vertex under it. Returns the candidate's rise and steps.
    #[inline]
    fn pop_more(&mut self, l: usize, s: f32, h: f32) -> (f32, f32) {
        let base = l * self.cap;
        let n = self.n[l] as usize;
        let (sv, hv) = (self.s2[l], self.h2[l]);
        // The candidate, vertex i of the stack (from the bottom, the top being n − 1).
        let (mut a, mut b, mut sv, mut hv) = (hv - h, sv - s, sv, hv);
        let mut i = n - 2;
        while i > 0 {
            let (sk, hk) = (self.ms[base + i - 1], self.mh[base + i - 1]);
            let (c, d) = (sk - s, hk - h);
            if a * c > d * b {
                break;
            }
            (a, b, sv, hv) = (d, c, sk, hk);
            i -= 1;
        }
        // The candidate becomes the top, the vertex under it (or the bottom) the second.
        self.n[l] = (i + 1) as u32;
        (self.s1[l], self.h1[l]) = (sv, hv);
        (self.s2[l], self.h2[l]) = if i > 0 {
            (self.ms[base + i - 1], self.mh[base + i - 1])
        } else {
            (BOTTOM_S, BOTTOM_H)
        };
        (a, b)
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::super::sections::Hull;
    use super::*;

    /// Lanes of random lines, each on the grid over its own span of columns (off it elsewhere),
    /// with whole-metre heights so that plateaus and collinear vertices (ties) are common.
    fn lanes(w: usize, seed: u64) -> (Vec<f32>, Vec<std::ops::Range<usize>>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut heights = vec![OFF_GRID; w * LANES];
        let mut spans = Vec::new();
        for l in 0..LANES {
            let a = rng.random_range(0..w / 3);
            let b = rng.random_range(a..=w);
            let mut z = rng.random_range(0.0f32..20.0).round();
            for u in a..b {
                z = (z + rng.random_range(-3.0f32..3.0)).round();
                heights[u * LANES + l] = z;
            }
            spans.push(a..b);
        }
        (heights, spans)
    }

    #[test]
    fn the_lanes_give_each_lines_walk_to_the_bit_and_the_brute_force_horizon() {
        let (sp, sp2) = (1.3f32, 1.69f32);
        for seed in 0..40 {
            let w = 5 + (seed as usize * 37) % 300;
            let (heights, spans) = lanes(w, seed);
            let mut walk = Walk::default();
            let mut both = vec![0.0f32; w * LANES];
            walk.sky::<true, false>(&heights, sp2, &mut both);
            walk.sky::<false, true>(&heights, sp2, &mut both);
            let (mut up, mut down) = (vec![0.0f32; w * LANES], vec![0.0f32; w * LANES]);
            walk.horizons::<true>(&heights, sp, &mut up);
            walk.horizons::<false>(&heights, sp, &mut down);
            let mut hull = Hull::default();
            for (l, span) in spans.iter().enumerate() {
                let z: Vec<f32> = span.clone().map(|u| heights[u * LANES + l]).collect();
                let n = z.len();
                let (mut ru, mut su, mut rd, mut sd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
                hull.pass::<true>(&z, &mut ru, &mut su);
                hull.pass::<false>(&z, &mut rd, &mut sd);
                for (k, u) in span.clone().enumerate() {
                    let at = u * LANES + l;
                    let line = sin2(ru[k], su[k], sp2) + sin2(rd[k], sd[k], sp2);
                    assert_eq!(both[at].to_bits(), line.to_bits(), "seed {seed}, lane {l}, column {u}");
                    // Whole horizons: the line's tangents, NaN (the same bits) with nothing ahead.
                    for (lanes, r, d) in [(&up, ru[k], su[k]), (&down, rd[k], sd[k])] {
                        let t = r / (d * sp);
                        assert!(
                            lanes[at].to_bits() == t.to_bits() || (lanes[at].is_nan() && t.is_nan()),
                            "seed {seed}, lane {l}, column {u}: tangent {} against {t}",
                            lanes[at]
                        );
                    }
                    // Brute force: the largest tangent over the samples ahead each way.
                    let best = |ahead: &mut dyn Iterator<Item = usize>| {
                        ahead
                            .map(|q| (f64::from(z[q]) - f64::from(z[k])) / (q.abs_diff(k) as f64))
                            .fold(0.0f64, f64::max)
                    };
                    let s2 = |t: f64| t * t / (t * t + f64::from(sp2));
                    let brute = s2(best(&mut (k + 1..n))) + s2(best(&mut (0..k)));
                    assert!(
                        (f64::from(both[at]) - brute).abs() < 1e-5,
                        "seed {seed}, lane {l}, column {u}: {} against {brute}",
                        both[at]
                    );
                }
            }
        }
    }
}
