//! A floor without casts, for the vector passes ([`crate::shade`]'s resolve): the compiler
//! expands a vector `as i32` or `as u32` into one scalar conversion per lane, so the land look's
//! cell index and the haze's table index are floored from the float's bits instead. Its own
//! module because the ground's maps ([`crate::shade::land`]) and the atmosphere both use it.

/// 2²³: [`floor_small`]'s limit.
pub(crate) const SMALL: f32 = 8_388_608.0;

/// `⌊v⌋` as an integer and as a float for `v` in `[0, 2²³)`, without a cast: `v + 2²³` is `v`
/// rounded to an integer, which the float's low bits hold; one less where that rounded up.
#[inline(always)]
pub(crate) fn floor_small(v: f32) -> (u32, f32) {
    let t = v + SMALL;
    let rounded = t - SMALL;
    let i = t.to_bits().wrapping_sub(SMALL.to_bits());
    let up = rounded > v;
    (i.wrapping_sub(u32::from(up)), if up { rounded - 1.0 } else { rounded })
}

#[cfg(test)]
mod tests {
    use super::floor_small;

    #[test]
    fn the_computed_floor_is_the_cast() {
        let mut values: Vec<f32> = (0..=40_000).map(|i| i as f32 * 0.125).collect();
        values.extend([f32::EPSILON, 0.499_999_97, 0.5, 1.5, 2.5, 3.5, 8_388_607.0, 8_388_607.5]);
        values.extend((1..=1000).map(|i| 8_388_608.0 * i as f32 / 1001.0));
        for v in values {
            assert_eq!(floor_small(v), (v as u32, v.floor()), "⌊{v}⌋");
        }
    }
}
