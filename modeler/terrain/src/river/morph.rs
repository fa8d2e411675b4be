//! Binary morphology by a diamond: the seed's structuring element of level `n` is the
//! `(2n − 1) × (2n − 1)` diamond `{(dx, dy) : |dx| + |dy| ≤ n − 1}`, which is `n − 1` iterated
//! 4-neighbour crosses (level 1 is the single cell, the identity).
//!
//! Dilating by it keeps every cell within city-block distance `n − 1` of the set; eroding keeps
//! every cell farther than `n − 1` from the complement. Both are `n − 1` crosses on the image
//! packed 64 cells to a word ([`Bits`]): a few word operations per 64 cells and cross, so even
//! the largest diamond costs less than one pass over the bytes. Cells outside the image count as
//! background, as in `scipy.ndimage.binary_dilation`/`binary_erosion` with their default
//! `border_value=0`. The river's yearly step uses the same crosses ([`super::Shape`]).
//!
//! [`distance`] and [`distance_to_other`] (city-block distance transforms, two raster passes
//! whatever the level) did both before the crosses; they stay for callers that want the
//! distances themselves.

/// The largest structuring-element level (the seed's 6: an 11 × 11 diamond).
pub const MAX_LEVEL: u8 = 6;

/// A distance no cell of an image reaches (distances saturate here).
const FAR: u16 = u16::MAX;

/// The diamond of `level` (1 to [`MAX_LEVEL`]) as a `(2n − 1)²` row-major image of 0/1.
pub fn diamond(level: u8) -> Vec<u8> {
    let r = i32::from(level.max(1)) - 1;
    let side = 2 * r + 1;
    (0..side * side)
        .map(|i| u8::from((i % side - r).abs() + (i / side - r).abs() <= r))
        .collect()
}

/// City-block distance from every cell of a `width × height` image to the nearest cell whose
/// value is `target != 0` (saturating at `u16::MAX`). With `outside_is_target`, the cells beyond
/// the image's edge count as target cells (distance 1 from the edge cells).
pub fn distance(image: &[u8], width: usize, height: usize, target: bool, outside_is_target: bool) -> Vec<u16> {
    // The distance of a cell beyond the edge.
    let outside = if outside_is_target { 0 } else { FAR };
    let mut d: Vec<u16> = image
        .iter()
        .map(|&v| if (v != 0) == target { 0 } else { FAR })
        .collect();
    transform(&mut d, width, height, outside);
    d
}

/// The two raster passes of [`distance`] over `d` (0 at the targets, [`FAR`] elsewhere), the
/// cells beyond the edge at distance `outside`.
fn transform(d: &mut [u16], width: usize, height: usize, outside: u16) {
    if width == 0 {
        return;
    }
    // Forward pass: from above, then from the left along the row.
    for r in 0..height {
        let (done, rest) = d.split_at_mut(r * width);
        let row = &mut rest[..width];
        match done.len().checked_sub(width) {
            Some(up) => {
                for (v, &u) in row.iter_mut().zip(&done[up..]) {
                    *v = (*v).min(u.saturating_add(1));
                }
            }
            None => row.iter_mut().for_each(|v| *v = (*v).min(outside.saturating_add(1))),
        }
        let mut left = outside;
        for v in row.iter_mut() {
            left = (*v).min(left.saturating_add(1));
            *v = left;
        }
    }
    // Backward pass: from below, then from the right.
    for r in (0..height).rev() {
        let (head, below) = d.split_at_mut((r + 1) * width);
        let row = &mut head[r * width..];
        if below.is_empty() {
            row.iter_mut().for_each(|v| *v = (*v).min(outside.saturating_add(1)));
        } else {
            for (v, &u) in row.iter_mut().zip(&below[..width]) {
                *v = (*v).min(u.saturating_add(1));
            }
        }
        let mut right = outside;
        for v in row.iter_mut().rev() {
            right = (*v).min(right.saturating_add(1));
            *v = right;
        }
    }
}

/// City-block distance from every cell to the nearest cell of the other value (land to water,
/// water to land; saturating at `u16::MAX` where there is none; the outside counts as neither):
/// what [`distance`] gives for the land cells with `target = true` and for the water cells with
/// `target = false`, in one transform instead of two.
///
/// The nearest cell `w` of the other value is reached from a cell by a monotone path of length
/// `d` whose cells but `w` all have the cell's value (any of them with the other value would be
/// nearer), so the cell before `w` is on the boundary of the cell's class (a cell with a
/// 4-neighbour of the other value) at distance `d − 1`; and every boundary cell of the class is
/// within 1 of the other value. So `d` is 1 + the distance to the nearest boundary cell of the
/// class — and the nearest boundary cell of either class is of the cell's own: one of the other
/// class is of the other value, so at least `d` away.
pub fn distance_to_other(image: &[u8], width: usize, height: usize) -> Vec<u16> {
    let mut d = vec![FAR; image.len()];
    if width == 0 {
        return d;
    }
    // 0 on the boundary cells, row by row against the four neighbours' rows; a missing
    // neighbour (beyond the edge) stands in as the cell itself, which never differs.
    let bit: Vec<u8> = image.iter().map(|&v| u8::from(v != 0)).collect();
    for (r, out) in d.chunks_mut(width).enumerate() {
        let row = &bit[r * width..(r + 1) * width];
        let up = r.checked_sub(1).map_or(row, |u| &bit[u * width..(u + 1) * width]);
        let down = bit.get((r + 1) * width..(r + 2) * width).unwrap_or(row);
        let left = std::iter::once(row[0]).chain(row.iter().copied());
        let right = row.iter().skip(1).copied().chain(std::iter::once(row[width - 1]));
        for ((((o, &v), (&u, &w)), l), q) in out.iter_mut().zip(row).zip(up.iter().zip(down)).zip(left).zip(right) {
            if (v ^ u) | (v ^ w) | (v ^ l) | (v ^ q) != 0 {
                *o = 0;
            }
        }
    }
    separable(&mut d, width, height);
    for v in &mut d {
        *v = v.saturating_add(1);
    }
    d
}

/// The exact city-block distance transform of `d` (0 at the targets, [`FAR`] elsewhere, nothing
/// beyond the edge), as two 1-D passes: along each row, then down and up each column (the
/// city-block distance is the least `|dy|` + the row distance of row `y + dy`). Rows are
/// independent, and so are columns, so each pass runs as two halves on the thread pool; the
/// distance is unique, so this equals [`transform`]'s.
fn separable(d: &mut [u16], width: usize, height: usize) {
    let rows = |chunk: &mut [u16]| {
        for row in chunk.chunks_mut(width) {
            let mut left = FAR;
            for v in row.iter_mut() {
                left = (*v).min(left.saturating_add(1));
                *v = left;
            }
            let mut right = FAR;
            for v in row.iter_mut().rev() {
                right = (*v).min(right.saturating_add(1));
                *v = right;
            }
        }
    };
    let (top, bottom) = d.split_at_mut(height / 2 * width);
    rayon::join(|| rows(top), || rows(bottom));
    // Columns: each half of every row, down then up, vectorised along the row.
    let columns = |mut part: Vec<&mut [u16]>| {
        for r in 1..part.len() {
            let (above, here) = part.split_at_mut(r);
            for (v, &u) in here[0].iter_mut().zip(above[r - 1].iter()) {
                *v = (*v).min(u.saturating_add(1));
            }
        }
        for r in (0..part.len().saturating_sub(1)).rev() {
            let (here, below) = part.split_at_mut(r + 1);
            for (v, &u) in here[r].iter_mut().zip(below[0].iter()) {
                *v = (*v).min(u.saturating_add(1));
            }
        }
    };
    let (left, right): (Vec<&mut [u16]>, Vec<&mut [u16]>) =
        d.chunks_mut(width).map(|row| row.split_at_mut(width / 2)).unzip();
    rayon::join(|| columns(left), || columns(right));
}

/// The image dilated by the diamond of `level` (the cells within `level − 1` of the set): `level − 1`
/// crosses on the bit-packed image ([`Bits`]).
pub fn dilate(image: &[u8], width: usize, height: usize, level: u8) -> Vec<u8> {
    crosses(image, width, height, level, true)
}

/// The image eroded by the diamond of `level` (the cells farther than `level − 1` from the
/// complement, the outside counting as complement): `level − 1` crosses on the bit-packed image
/// (eroding by a diamond is eroding by its crosses in turn, the outside unset each time).
pub fn erode(image: &[u8], width: usize, height: usize, level: u8) -> Vec<u8> {
    crosses(image, width, height, level, false)
}

/// `level − 1` 4-neighbour crosses on the bit-packed image, growing the set with `grow`, else
/// shrinking it.
fn crosses(image: &[u8], width: usize, height: usize, level: u8, grow: bool) -> Vec<u8> {
    let mut bits = Bits::of(image, width, height, true);
    let mut spare = Bits::empty(width, height);
    for _ in 1..level.max(1) {
        bits.cross(&mut spare, grow);
        std::mem::swap(&mut bits, &mut spare);
    }
    bits.to_bytes()
}

/// Eight cells (bytes, any non-zero value set) as the low eight bits of a word, the first cell
/// lowest: each byte's "non-zero" moved to its bit 0, then one multiplication gathers the eight
/// bits into the top byte (byte `i`'s bit lands at `56 + i`; the other products fall at distinct
/// places below it or beyond the word, so nothing carries into it).
fn pack8(eight: &[u8]) -> u64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(eight);
    let x = u64::from_le_bytes(b);
    const LOW7: u64 = 0x7f7f_7f7f_7f7f_7f7f;
    let nonzero = (((x & LOW7) + LOW7) | x) >> 7 & 0x0101_0101_0101_0101;
    nonzero.wrapping_mul(0x0102_0408_1020_4080) >> 56
}

/// Sixteen cells (bytes, any non-zero value set) as the low sixteen bits of a word, the first
/// cell lowest: one compare with zero and one gather of the bytes' top bits.
fn pack16(sixteen: &[u8]) -> u64 {
    let mut b = [0u8; 16];
    b.copy_from_slice(sixteen);
    let zero = wide::u8x16::new(b).simd_eq(wide::u8x16::ZERO).to_bitmask();
    u64::from(!zero & 0xffff)
}

/// A binary image packed 64 cells to a word, row by row (each row starts a word; the bits past
/// the width are 0). A cross over it is a few word operations per 64 cells, so the iterated
/// crosses of a diamond cost less than one pass of a distance transform over bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bits {
    width: usize,
    height: usize,
    /// Words per row.
    stride: usize,
    words: Vec<u64>,
}

impl Bits {
    /// All cells unset.
    pub fn empty(width: usize, height: usize) -> Bits {
        let stride = width.div_ceil(64);
        Bits {
            width,
            height,
            stride,
            words: vec![0; stride * height],
        }
    }

    /// An image of `width × height` cells in `words`, resized to fit. Its cells are whatever the
    /// buffer held: for a caller that sets every word before it reads one ([`Bits::set_from`],
    /// [`Bits::complement`] and [`Bits::cross`] do).
    pub fn in_buffer(width: usize, height: usize, mut words: Vec<u64>) -> Bits {
        let stride = width.div_ceil(64);
        words.resize(stride * height, 0);
        Bits {
            width,
            height,
            stride,
            words,
        }
    }

    /// Its buffer of words.
    pub fn into_buffer(self) -> Vec<u64> {
        self.words
    }

    /// The cells of `image` (row-major 0/1) whose value is `value != 0`.
    pub fn of(image: &[u8], width: usize, height: usize, value: bool) -> Bits {
        let mut bits = Bits::empty(width, height);
        bits.set_from(image, value);
        bits
    }

    /// Sets the cells of `image` whose value is `value != 0`, the others unset.
    pub fn set_from(&mut self, image: &[u8], value: bool) {
        self.pack(image, value, 1 << 16);
    }

    /// [`Bits::set_from`] on the calling thread: a river's year packs its mask (about 1.3
    /// instructions a cell) on the way to its crosses, where a fork and join, and waking the
    /// other thread, would cost more than it saves.
    pub fn set_from_here(&mut self, image: &[u8], value: bool) {
        self.pack(image, value, usize::MAX);
    }

    /// [`Bits::set_from`], in two bands of rows on the thread pool from `split` cells.
    fn pack(&mut self, image: &[u8], value: bool, split: usize) {
        let flip = if value { 0 } else { u64::MAX };
        if self.width == 0 {
            return;
        }
        let (width, stride) = (self.width, self.stride);
        let pack = |image: &[u8], words: &mut [u64]| {
            for (row, out) in image.chunks(width).zip(words.chunks_mut(stride)) {
                // Sixteen cells at a time, four to a word.
                let mut w = 0u64;
                let mut sixteens = row.chunks_exact(16);
                for (g, sixteen) in sixteens.by_ref().enumerate() {
                    w |= pack16(sixteen) << (16 * (g % 4));
                    if g % 4 == 3 {
                        out[g / 4] = w ^ flip;
                        w = 0;
                    }
                }
                // The last word, if the groups did not fill it: the cells left, and the bits past
                // the row's end 0 whichever value is asked for.
                let mut done = row.len() / 16 * 16;
                if done % 64 != 0 || done < row.len() {
                    let last = done / 64;
                    let mut eights = sixteens.remainder().chunks_exact(8);
                    for eight in eights.by_ref() {
                        w |= pack8(eight) << (done % 64);
                        done += 8;
                    }
                    for (j, &v) in eights.remainder().iter().enumerate() {
                        w |= u64::from(v != 0) << (done % 64 + j);
                    }
                    out[last] = (w ^ flip) & (u64::MAX >> (64 - (row.len() - last * 64)));
                }
            }
        };
        // Large images in two bands of rows on the thread pool.
        let mid = self.height / 2;
        if self.height < 2 || width * self.height < split {
            pack(image, &mut self.words);
            return;
        }
        let (i0, i1) = image.split_at(mid * width);
        let (w0, w1) = self.words.split_at_mut(mid * stride);
        rayon::join(|| pack(i0, w0), || pack(i1, w1));
    }

    /// The cells of the window that are not set, into `out` (the same size).
    pub fn complement(&self, out: &mut Bits) {
        let tail = self.tail();
        for (dst, src) in out.words.chunks_mut(self.stride).zip(self.words.chunks(self.stride)) {
            for (k, (d, s)) in dst.iter_mut().zip(src).enumerate() {
                *d = if k + 1 == self.stride { !s & tail } else { !s };
            }
        }
    }

    /// The bits of a row's last word that are cells.
    fn tail(&self) -> u64 {
        match self.width % 64 {
            0 => u64::MAX,
            k => u64::MAX >> (64 - k),
        }
    }

    /// Whether cell `i` (row-major index) is set.
    pub fn get(&self, i: usize) -> bool {
        let (r, c) = (i / self.width, i % self.width);
        self.words[r * self.stride + c / 64] >> (c % 64) & 1 != 0
    }

    /// The words of row `r`.
    pub fn row(&self, r: usize) -> &[u64] {
        &self.words[r * self.stride..(r + 1) * self.stride]
    }

    /// Words per row.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// The image as row-major 0/1 bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        (0..self.width * self.height).map(|i| u8::from(self.get(i))).collect()
    }

    /// One 4-neighbour cross into `out` (the same size): dilation (a cell or any of its four
    /// neighbours set) or erosion (the cell and all four set, cells beyond the edge unset).
    pub fn cross(&self, out: &mut Bits, dilate: bool) {
        let (s, h) = (self.stride, self.height);
        let tail = self.tail();
        let zero = vec![0u64; s];
        for r in 0..h {
            let here = self.row(r);
            let up = if r > 0 { self.row(r - 1) } else { &zero };
            let down = if r + 1 < h { self.row(r + 1) } else { &zero };
            let dst = &mut out.words[r * s..(r + 1) * s];
            for k in 0..s {
                let x = here[k];
                // The left neighbour's bit moves up one place (from the word before at bit 0),
                // the right neighbour's down one (from the word after at bit 63).
                let left = x << 1 | if k > 0 { here[k - 1] >> 63 } else { 0 };
                let right = x >> 1 | if k + 1 < s { here[k + 1] << 63 } else { 0 };
                let w = if dilate {
                    x | left | right | up[k] | down[k]
                } else {
                    x & left & right & up[k] & down[k]
                };
                dst[k] = if k + 1 == s { w & tail } else { w };
            }
        }
    }
}
