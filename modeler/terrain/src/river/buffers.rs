//! A river shape's per-cell buffers, kept from a shape that is done with for the next one.
//!
//! A drag's preview processes the river and drops it at every pen sample. Its mask, lakes and
//! nearest-sample field (12 bytes a cell: 1.9 MB for `drag/512/10`'s window) were freed and
//! allocated again each time, and the allocator handed the freed pages back to the kernel often
//! enough that they were faulted in and zeroed again (some 480 page faults a call).
//! [`Shape::recycle`](super::Shape::recycle) gives them back here and [`Shape::new`](super::Shape::new)
//! takes them. A year's bit-packed crosses (some dozen images) are kept here too.

use crate::pool::Pool;

/// A 1024² window's buffers of each kind.
const KEEP: usize = 1 << 20;

/// Masks.
pub(super) static MASKS: Pool<u8> = Pool::new(KEEP);
/// Lake ids.
pub(super) static LAKES: Pool<u16> = Pool::new(KEEP);
/// The field's owners.
pub(super) static OWNERS: Pool<u32> = Pool::new(KEEP);
/// The field's distances.
pub(super) static DISTS: Pool<f32> = Pool::new(KEEP);
/// The field's sides.
pub(super) static SIDES: Pool<i8> = Pool::new(KEEP);
/// Bit-packed images (a year's crosses of the water and the land).
pub(super) static WORDS: Pool<u64> = Pool::new(KEEP);
