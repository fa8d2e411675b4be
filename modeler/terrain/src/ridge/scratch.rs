//! The sky view's and the direct light's big working buffers, kept from call to call.
//!
//! A 1024² call works in some 30 MB of `f32` buffers. Freshly allocated, each page of them is
//! faulted in and zeroed by the kernel on first touch — on the bench's machine about a third of a
//! call's CPU time went to the system. A few freed buffers are kept here ([`crate::pool`]) and
//! handed out again.

use crate::pool::Pool;

/// The buffers kept, at most [`KEEP_FLOATS`] floats in all.
static POOL: Pool<f32> = Pool::new(KEEP_FLOATS);

/// 48 MB: a 1024² call's buffers; a bigger grid's are freed as before.
const KEEP_FLOATS: usize = 12 << 20;

/// A buffer of `len` zeros, a kept one when there is one.
pub(super) fn zeros(len: usize) -> Vec<f32> {
    POOL.filled(len, 0.0)
}

/// Gives buffers back, kept while the pool has room.
pub(super) fn give(buffers: impl IntoIterator<Item = Vec<f32>>) {
    for v in buffers {
        POOL.give(v);
    }
}
