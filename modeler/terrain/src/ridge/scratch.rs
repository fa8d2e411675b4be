//! The sky view's and the direct light's big working buffers, kept from call to call.
//!
//! A 1024² call works in some 30 MB of `f32` buffers. Freshly allocated, each page of them is
//! faulted in and zeroed by the kernel on first touch — on the bench's machine about a third of a
//! call's CPU time went to the system. A few freed buffers are kept here and handed out again.

use std::sync::Mutex;

/// The buffers kept, at most [`KEEP_FLOATS`] floats in all.
static POOL: Mutex<Vec<Vec<f32>>> = Mutex::new(Vec::new());

/// 48 MB: a 1024² call's buffers; a bigger grid's are freed as before.
const KEEP_FLOATS: usize = 12 << 20;

/// A buffer of `len` zeros, a kept one when there is one.
pub(super) fn zeros(len: usize) -> Vec<f32> {
    let kept = POOL.lock().ok().and_then(|mut pool| pool.pop());
    match kept {
        Some(mut v) => {
            v.clear();
            v.resize(len, 0.0);
            v
        }
        None => vec![0.0; len],
    }
}

/// Gives buffers back, kept while the pool has room.
pub(super) fn give(buffers: impl IntoIterator<Item = Vec<f32>>) {
    let Ok(mut pool) = POOL.lock() else {
        return;
    };
    for v in buffers {
        let held: usize = pool.iter().map(Vec::capacity).sum();
        if held + v.capacity() <= KEEP_FLOATS {
            pool.push(v);
        }
    }
}
