//! Number forms of the JSON output (feature `serde`): numbers the device holds as `f32` written
//! as the shortest decimal that reads back as the same `f32` (`36.2f32` prints as `36.2`, not as
//! the `36.20000076293945` it widens to), and tenths as decimals. A leaf: the report types name these helpers in their
//! serde attributes, and the JSON module uses them too.

use serde::Serialize;
use serde::ser::{SerializeSeq, Serializer};

/// Tenths (logical position units, quality steps) as a decimal number: 123 → 12.3.
pub(crate) fn tenths<S: Serializer, T: Copy + Into<f64>>(v: &T, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64((*v).into() / 10.0)
}

/// An `f32` as its shortest decimal (serde_json and every other format with an `f32` of its own
/// write it so; this names the choice at each field).
pub(crate) fn wide<S: Serializer>(v: &f32, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f32(*v)
}

pub(crate) fn wide_opt<S: Serializer>(v: &Option<f32>, s: S) -> Result<S::Ok, S::Error> {
    match v {
        Some(v) => s.serialize_f32(*v),
        None => s.serialize_none(),
    }
}

/// A list of `f32` (or of `[f32; N]`), each as its shortest decimal.
pub(crate) fn wide_list<S: Serializer, T: Wide>(v: &&[T], s: S) -> Result<S::Ok, S::Error> {
    let mut seq = s.serialize_seq(Some(v.len()))?;
    for x in v.iter() {
        x.put(&mut seq)?;
    }
    seq.end()
}

/// What [`wide_list`] lists.
pub(crate) trait Wide {
    fn put<S: SerializeSeq>(&self, seq: &mut S) -> Result<(), S::Error>;
}

impl Wide for f32 {
    fn put<S: SerializeSeq>(&self, seq: &mut S) -> Result<(), S::Error> {
        seq.serialize_element(self)
    }
}

impl<const N: usize> Wide for [f32; N] {
    fn put<S: SerializeSeq>(&self, seq: &mut S) -> Result<(), S::Error> {
        seq.serialize_element(&WideSlice(self))
    }
}

/// `f32`s, each as its shortest decimal.
pub(crate) struct WideSlice<'a>(pub(crate) &'a [f32]);

impl Serialize for WideSlice<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.0.iter())
    }
}

pub(crate) fn wide_array<S: Serializer, const N: usize>(v: &[f32; N], s: S) -> Result<S::Ok, S::Error> {
    WideSlice(v).serialize(s)
}
