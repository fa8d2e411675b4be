//! Big working buffers kept from call to call.
//!
//! A freshly allocated buffer of a megabyte or more is mapped from the kernel, and each of its
//! pages is faulted in and zeroed on first touch; freed, it goes back to the kernel. A terrain
//! built again and again (a full regeneration, the sky view of every frame) paid that on every
//! call: a third of its CPU time went to the system. A [`Pool`] keeps some freed buffers, up to a
//! cap, and hands them out again.

use std::sync::Mutex;

/// The terrain engine's per-cell maps (distances, shape terms, coefficients) of the regions and
/// figures dropped, for the next ones: 64 MB, a 512² region's maps for some fifteen figures.
pub(crate) static MAPS: Pool<f32> = Pool::new(16 << 20);

/// The distance transforms' integer maps ([`crate::edt`], [`crate::distance`]), kept from call to
/// call: 16 MB, a 1024² box's.
pub(crate) static COLUMNS: Pool<u32> = Pool::new(4 << 20);

/// Freed buffers of `T`, at most `cap` elements of capacity in all.
pub(crate) struct Pool<T> {
    kept: Mutex<Vec<Vec<T>>>,
    cap: usize,
}

impl<T: Clone> Pool<T> {
    /// An empty pool that keeps at most `cap` elements.
    pub(crate) const fn new(cap: usize) -> Pool<T> {
        Pool {
            kept: Mutex::new(Vec::new()),
            cap,
        }
    }

    /// The kept buffer of the least capacity that holds `len` elements, if any.
    fn fitting(&self, len: usize) -> Option<Vec<T>> {
        let mut kept = self.kept.lock().ok()?;
        let best = (0..kept.len())
            .filter(|&i| kept[i].capacity() >= len)
            .min_by_key(|&i| kept[i].capacity())?;
        Some(kept.swap_remove(best))
    }

    /// A buffer of `len` copies of `value`.
    pub(crate) fn filled(&self, len: usize, value: T) -> Vec<T> {
        match self.fitting(len) {
            Some(mut v) => {
                v.clear();
                v.resize(len, value);
                v
            }
            None => vec![value; len],
        }
    }

    /// A buffer of `len` elements for a caller that writes every element before it reads it: a
    /// kept buffer's elements keep their old values (saving the fill), a new one's are `value`.
    pub(crate) fn unfilled(&self, len: usize, value: T) -> Vec<T> {
        match self.fitting(len) {
            Some(mut v) => {
                v.truncate(len);
                v.resize(len, value);
                v
            }
            None => vec![value; len],
        }
    }

    /// Keeps `v` while the pool has room (else frees it). Room is made by freeing kept buffers
    /// bigger than `v`, the biggest first: after a big terrain (the bench's memory case, a big
    /// document closed) the buffers of the smaller ones that follow are kept, not its.
    pub(crate) fn give(&self, v: Vec<T>) {
        if v.capacity() == 0 {
            return;
        }
        let Ok(mut kept) = self.kept.lock() else {
            return;
        };
        let mut held: usize = kept.iter().map(Vec::capacity).sum();
        while held + v.capacity() > self.cap {
            let bigger = (0..kept.len())
                .filter(|&i| kept[i].capacity() > v.capacity())
                .max_by_key(|&i| kept[i].capacity());
            let Some(i) = bigger else {
                break;
            };
            held -= kept.swap_remove(i).capacity();
        }
        if held + v.capacity() <= self.cap {
            kept.push(v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_kept_buffer_comes_back_filled_or_with_its_old_values() {
        let pool = Pool::<u32>::new(100);
        pool.give(vec![7; 10]);
        // Too long for the kept buffer: a new one.
        assert_eq!(pool.filled(20, 1), vec![1; 20]);
        let v = pool.filled(4, 2);
        assert_eq!(v, vec![2; 4]);
        assert!(v.capacity() >= 10, "the kept buffer");
        pool.give(v);
        let mut old = pool.unfilled(3, 0);
        assert_eq!(old, vec![2; 3]);
        old.resize(8, 5);
        pool.give(old);
        assert_eq!(pool.unfilled(9, 0), vec![2, 2, 2, 5, 5, 5, 5, 5, 0]);
    }

    #[test]
    fn the_pool_keeps_at_most_its_cap_and_hands_out_the_least_fitting() {
        let pool = Pool::<u8>::new(30);
        pool.give(vec![0; 20]);
        pool.give(vec![1; 20]);
        pool.give(vec![2; 10]);
        assert_eq!(pool.unfilled(5, 9), vec![2; 5]);
        assert_eq!(pool.unfilled(5, 9), vec![0; 5]);
        assert_eq!(pool.unfilled(5, 9), vec![9; 5], "the second 20 was not kept");
    }

    #[test]
    fn a_full_pool_frees_bigger_buffers_for_a_smaller_one() {
        let pool = Pool::<u8>::new(30);
        pool.give(vec![0; 25]);
        pool.give(vec![1; 5]);
        // 25 + 5 + 10 > 30: the 25 goes.
        pool.give(vec![2; 10]);
        assert_eq!(pool.unfilled(4, 9), vec![1; 4]);
        assert_eq!(pool.unfilled(4, 9), vec![2; 4]);
        assert_eq!(pool.unfilled(4, 9), vec![9; 4], "the 25 was freed");
    }
}
