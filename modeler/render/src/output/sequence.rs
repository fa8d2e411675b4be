//! A sequence of frames written to a folder: one PNG per frame as it comes, and at the end an
//! animated PNG (APNG) of them all.
//!
//! Frames go to disk as they are pushed, so a long session holds one frame in memory, not all of
//! them; [`Sequence::finish`] reads them back one at a time to write the animation. APNG rather
//! than GIF: the `png` crate (already used for heightmaps) writes it, it keeps full 24-bit colour
//! where a GIF would quantise the ramp's gradients to 256 colours, and browsers and image viewers
//! play it (a viewer without APNG support shows the first frame).
//!
//! Each frame after the first is stored as a delta, the way APNG optimisers do it: only the box
//! of pixels that changed, and inside it the unchanged pixels fully transparent, blended OVER the
//! previous frame so they leave it showing. Between two frames of a session most pixels stay, so
//! the runs of one value deflate to almost nothing. When every frame is opaque (the renderer's
//! always are) the animation is RGB, a quarter fewer bytes, and "transparent" is a colour no
//! frame uses, named in the tRNS chunk; otherwise it is RGBA, and a frame with pixels that are
//! not opaque is stored as its box alone, replacing (SOURCE) what was there, since OVER would mix
//! them. An unchanged pixel may as well be stored as its colour (it covers the same colour), and
//! where changes are scattered that deflates better than a key broken by every other pixel: each
//! delta is encoded both ways — every unchanged pixel transparent, or only those in runs of at
//! least [`RUN`] along a row — and the smaller kept.
//!
//! Frames where the view moves (most of the picture changes, as when the ground tilts or the
//! camera follows a head) cost a whole frame's bytes each: [`Sequence::moving_every`] keeps only
//! every n-th of them in the animation, the frame before each one shown the longer, so the
//! animation still holds the frames it shows exactly, on the session's clock. The figures are
//! in docs/renderer.md.

use std::fs::{self, File};
use std::io::{BufReader, BufWriter};
use std::path::{Path, PathBuf};

use super::OutputError;
use super::png::write_png;
use crate::Frame;

/// File name of the animation in the sequence's folder.
pub const ANIMATION: &str = "animation.png";

/// Unchanged pixels in a run of at least this many along a row of a delta are stored
/// transparent; shorter runs, between changed pixels, as their colour.
pub const RUN: usize = 16;

/// A frame "moves" when more than this share of its 8 × 8 tiles differ from the frame before.
pub const MOVING_SHARE: f64 = 0.25;

/// Frames being written to a folder.
pub struct Sequence {
    dir: PathBuf,
    fps: u16,
    size: Option<(u32, u32)>,
    frames: Vec<PathBuf>,
    colours: Colours,
    /// The last frame pushed (RGBA), to tell whether the next one moves.
    last: Vec<u8>,
    /// Per frame pushed: most of it differs from the frame before ([`MOVING_SHARE`]).
    moving: Vec<bool>,
    /// Of a run of moving frames, the animation keeps every `every`-th.
    every: usize,
}

/// What [`Sequence::finish_animation`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Animation {
    /// The file.
    pub path: PathBuf,
    /// The indices of the frames it holds (all frames, unless moving ones were thinned).
    pub held: Vec<usize>,
}

/// The RGB colours the frames use, one bit each (2 MB), while every pixel so far is opaque: the
/// animation's key colour is one they do not use.
struct Colours {
    used: Vec<u64>,
    opaque: bool,
}

impl Colours {
    fn note(&mut self, frame: &Frame) {
        if !self.opaque {
            return;
        }
        if self.used.is_empty() {
            self.used = vec![0; (1 << 24) / 64];
        }
        for px in frame.pixels() {
            if px[3] != 255 {
                self.opaque = false;
                self.used = Vec::new();
                return;
            }
            let c = usize::from(px[0]) << 16 | usize::from(px[1]) << 8 | usize::from(px[2]);
            self.used[c / 64] |= 1 << (c % 64);
        }
    }

    /// A colour no frame uses, when all are opaque (and not all 2²⁴ colours are used).
    fn key(&self) -> Option<[u8; 3]> {
        if !self.opaque {
            return None;
        }
        let (word, bits) = self.used.iter().enumerate().find(|(_, w)| **w != u64::MAX)?;
        let c = word * 64 + bits.trailing_ones() as usize;
        Some([(c >> 16) as u8, (c >> 8) as u8, c as u8])
    }
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |error| OutputError::Io {
        path: path.to_owned(),
        error,
    }
}

fn png_error(e: impl std::fmt::Display) -> OutputError {
    OutputError::Png(e.to_string())
}

impl Sequence {
    /// Starts a sequence in `dir` (created if missing), to be played at `fps` frames a second.
    pub fn create(dir: &Path, fps: u16) -> Result<Sequence, OutputError> {
        fs::create_dir_all(dir).map_err(io_error(dir))?;
        Ok(Sequence {
            dir: dir.to_owned(),
            fps: fps.max(1),
            size: None,
            frames: Vec::new(),
            colours: Colours {
                used: Vec::new(),
                opaque: true,
            },
            last: Vec::new(),
            moving: Vec::new(),
            every: 1,
        })
    }

    /// Of each run of frames where the view moves (more than [`MOVING_SHARE`] of the picture
    /// changes from one frame to the next), the animation keeps every `n`-th frame (and the frame
    /// after the run), each shown until the next one held; 1 (or 0) keeps every frame. The frame
    /// files are all written either way.
    pub fn moving_every(mut self, n: usize) -> Sequence {
        self.every = n.max(1);
        self
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The frame files written so far.
    pub fn frames(&self) -> &[PathBuf] {
        &self.frames
    }

    /// Writes `frame` as `frame_NNNNN.png`; every frame must have the first one's size.
    pub fn push(&mut self, frame: &Frame) -> Result<&Path, OutputError> {
        let got = (frame.width(), frame.height());
        let expected = *self.size.get_or_insert(got);
        if got != expected {
            return Err(OutputError::FrameSize {
                index: self.frames.len(),
                got,
                expected,
            });
        }
        let path = self.dir.join(format!("frame_{:05}.png", self.frames.len()));
        write_png(frame, &path)?;
        self.colours.note(frame);
        let moving = !self.last.is_empty() && moving_share(&self.last, frame.as_bytes(), got.0 as usize) > MOVING_SHARE;
        self.moving.push(moving);
        self.last.clear();
        self.last.extend_from_slice(frame.as_bytes());
        self.frames.push(path);
        Ok(self.frames.last().map(PathBuf::as_path).unwrap_or(&self.dir))
    }

    /// Writes the animation ([`ANIMATION`]) of every frame pushed, looping forever, and returns its
    /// path; `None` when no frame was pushed.
    pub fn finish(self) -> Result<Option<PathBuf>, OutputError> {
        Ok(self.finish_animation()?.map(|a| a.path))
    }

    /// The indices of the frames the animation holds: all but the moving frames left out by
    /// [`Sequence::moving_every`]. The first and the last are always held.
    pub fn held(&self) -> Vec<usize> {
        let n = self.moving.len();
        let mut held: Vec<usize> = Vec::with_capacity(n);
        for (i, &moving) in self.moving.iter().enumerate() {
            let since = held.last().map_or(usize::MAX, |&k| i - k);
            if !moving || since >= self.every || i + 1 == n {
                held.push(i);
            }
        }
        held
    }

    /// [`Sequence::finish`], saying which frames the animation holds.
    pub fn finish_animation(self) -> Result<Option<Animation>, OutputError> {
        let Some((width, height)) = self.size else {
            return Ok(None);
        };
        let held = self.held();
        let path = self.dir.join(ANIMATION);
        let file = File::create(&path).map_err(io_error(&path))?;
        let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
        let key = self.colours.key();
        match key {
            Some([r, g, b]) => {
                enc.set_color(png::ColorType::Rgb);
                // tRNS of an 8-bit RGB image: three 16-bit samples.
                enc.set_trns(vec![0, r, 0, g, 0, b]);
            }
            None => enc.set_color(png::ColorType::Rgba),
        }
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Balanced);
        enc.set_animated(held.len() as u32, 0).map_err(png_error)?;
        enc.set_frame_delay(1, self.fps).map_err(png_error)?;
        // Every frame stays on the canvas for the next one to be drawn over.
        enc.set_dispose_op(png::DisposeOp::None).map_err(png_error)?;
        let mut writer = enc.write_header().map_err(png_error)?;
        let mut buf = Vec::new();
        let mut previous: Vec<u8> = Vec::new();
        let mut delta = Vec::new();
        let mut runs = Vec::new();
        for (k, &i) in held.iter().enumerate() {
            let frame = &self.frames[i];
            // Shown until the next frame held: the session's time, whatever was left out.
            let shown = held.get(k + 1).map_or(1, |next| next - i);
            let shown = u16::try_from(shown).unwrap_or(u16::MAX);
            let file = File::open(frame).map_err(io_error(frame))?;
            let mut reader = png::Decoder::new(BufReader::new(file)).read_info().map_err(png_error)?;
            buf.resize(reader.output_buffer_size().unwrap_or(0), 0);
            let info = reader.next_frame(&mut buf).map_err(png_error)?;
            let pixels = &buf[..info.buffer_size()];
            if previous.is_empty() {
                // The first frame is the whole image (it is also what a viewer without APNG shows).
                delta.clear();
                match key {
                    Some(_) => pixels.chunks_exact(4).for_each(|px| delta.extend_from_slice(&px[..3])),
                    None => delta.extend_from_slice(pixels),
                }
                writer.set_frame_delay(shown, self.fps).map_err(png_error)?;
                writer.write_image_data(&delta).map_err(png_error)?;
            } else {
                let d = Delta::between(&previous, pixels, width as usize, key, &mut delta);
                // The other way to store it: unchanged pixels between changes as their colours.
                if d.blend == png::BlendOp::Over && d.w * d.h > 1 {
                    d.runs_kept(&previous, pixels, width as usize, key, &mut runs);
                    if deflated(&runs, &d, key)? < deflated(&delta, &d, key)? {
                        std::mem::swap(&mut runs, &mut delta);
                    }
                }
                writer.set_frame_delay(shown, self.fps).map_err(png_error)?;
                // Position reset first: the crate checks position + size against the image.
                writer.reset_frame_position().map_err(png_error)?;
                writer.set_frame_dimension(d.w as u32, d.h as u32).map_err(png_error)?;
                writer.set_frame_position(d.x as u32, d.y as u32).map_err(png_error)?;
                writer.set_blend_op(d.blend).map_err(png_error)?;
                writer.write_image_data(&delta).map_err(png_error)?;
            }
            previous.clear();
            previous.extend_from_slice(pixels);
        }
        writer.finish().map_err(png_error)?;
        Ok(Some(Animation { path, held }))
    }
}

/// The share of the 8 × 8 tiles of a frame (RGBA rows of `width` pixels) where `next` differs
/// from `previous`.
fn moving_share(previous: &[u8], next: &[u8], width: usize) -> f64 {
    const TILE: usize = 8;
    let height = next.len() / (width * 4).max(1);
    let tiles_x = width.div_ceil(TILE);
    let mut changed = vec![false; tiles_x * height.div_ceil(TILE)];
    let rows = next.chunks_exact(width * 4).zip(previous.chunks_exact(width * 4));
    for (y, (n, p)) in rows.enumerate() {
        if n == p {
            continue;
        }
        for (tx, (a, b)) in n.chunks(TILE * 4).zip(p.chunks(TILE * 4)).enumerate() {
            if a != b {
                changed[(y / TILE) * tiles_x + tx] = true;
            }
        }
    }
    changed.iter().filter(|&&c| c).count() as f64 / changed.len().max(1) as f64
}

/// The size of `data`, a delta's pixels as [`Delta::between`] writes them, deflated as a PNG at
/// the fast level: only to compare two ways of storing the same delta.
fn deflated(data: &[u8], d: &Delta, key: Option<[u8; 3]>) -> Result<usize, OutputError> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, d.w as u32, d.h as u32);
    enc.set_color(if key.is_some() {
        png::ColorType::Rgb
    } else {
        png::ColorType::Rgba
    });
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Fast);
    let mut writer = enc.write_header().map_err(png_error)?;
    writer.write_image_data(data).map_err(png_error)?;
    writer.finish().map_err(png_error)?;
    Ok(out.len())
}

/// Where and how a frame differs from the one before it, as an APNG frame.
#[derive(Debug, PartialEq, Eq)]
struct Delta {
    x: usize,
    y: usize,
    w: usize,
    h: usize,
    blend: png::BlendOp,
}

impl Delta {
    /// The box of `next` (RGBA rows of `width` pixels) that differs from `previous`, written to
    /// `out` as the animation stores it: RGB with the unchanged pixels in the `key` colour, or
    /// without a key RGBA, with OVER and the unchanged pixels transparent when every pixel in the
    /// box is opaque, else the box as it is with SOURCE. An unchanged frame is one transparent
    /// pixel (a frame cannot be empty).
    fn between(previous: &[u8], next: &[u8], width: usize, key: Option<[u8; 3]>, out: &mut Vec<u8>) -> Delta {
        let rows = next.chunks_exact(width * 4).zip(previous.chunks_exact(width * 4));
        let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
        for (y, (n, p)) in rows.enumerate() {
            if n == p {
                continue;
            }
            // First and last differing pixel of the row.
            let first = n.chunks_exact(4).zip(p.chunks_exact(4)).position(|(a, b)| a != b);
            let last = n.chunks_exact(4).zip(p.chunks_exact(4)).rposition(|(a, b)| a != b);
            if let (Some(a), Some(b)) = (first, last) {
                x0 = x0.min(a);
                x1 = x1.max(b);
                y0 = y0.min(y);
                y1 = y;
            }
        }
        out.clear();
        let transparent: &[u8] = match &key {
            Some(k) => k,
            None => &[0, 0, 0, 0],
        };
        if x0 == usize::MAX {
            out.extend_from_slice(transparent);
            return Delta {
                x: 0,
                y: 0,
                w: 1,
                h: 1,
                blend: png::BlendOp::Over,
            };
        }
        let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
        // The box's part of row y, in bytes.
        let row = |y: usize| (y * width + x0) * 4..(y * width + x0 + w) * 4;
        // With a key every frame is opaque.
        let over = key.is_some() || (y0..=y1).all(|y| next[row(y)].chunks_exact(4).all(|px| px[3] == 255));
        let channels = if key.is_some() { 3 } else { 4 };
        for y in y0..=y1 {
            let (n, p) = (&next[row(y)], &previous[row(y)]);
            for (a, b) in n.chunks_exact(4).zip(p.chunks_exact(4)) {
                out.extend_from_slice(if over && a == b { transparent } else { &a[..channels] });
            }
        }
        Delta {
            x: x0,
            y: y0,
            w,
            h,
            blend: if over { png::BlendOp::Over } else { png::BlendOp::Source },
        }
    }

    /// This OVER delta's box written to `out` with only the unchanged pixels in runs of at least
    /// [`RUN`] along a row transparent, the others as their colour (the colour already there).
    fn runs_kept(&self, previous: &[u8], next: &[u8], width: usize, key: Option<[u8; 3]>, out: &mut Vec<u8>) {
        out.clear();
        let transparent: &[u8] = match &key {
            Some(k) => k,
            None => &[0, 0, 0, 0],
        };
        let channels = if key.is_some() { 3 } else { 4 };
        for y in self.y..self.y + self.h {
            let at = (y * width + self.x) * 4..(y * width + self.x + self.w) * 4;
            let (n, p) = (&next[at.clone()], &previous[at]);
            let same: Vec<bool> = n.chunks_exact(4).zip(p.chunks_exact(4)).map(|(a, b)| a == b).collect();
            let mut x = 0;
            while x < self.w {
                // The run of pixels alike in being changed or not from x.
                let end = same[x..].iter().position(|&s| s != same[x]).map_or(self.w, |l| x + l);
                let keyed = same[x] && end - x >= RUN;
                for px in n[x * 4..end * 4].chunks_exact(4) {
                    out.extend_from_slice(if keyed { transparent } else { &px[..channels] });
                }
                x = end;
            }
        }
    }
}
