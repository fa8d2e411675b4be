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
//! them. The figures are in docs/renderer.md.

use std::fs::{self, File};
use std::io::{BufReader, BufWriter};
use std::path::{Path, PathBuf};

use super::OutputError;
use super::png::write_png;
use crate::Frame;

/// File name of the animation in the sequence's folder.
pub const ANIMATION: &str = "animation.png";

/// Frames being written to a folder.
pub struct Sequence {
    dir: PathBuf,
    fps: u16,
    size: Option<(u32, u32)>,
    frames: Vec<PathBuf>,
    colours: Colours,
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
        })
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
        self.frames.push(path);
        Ok(self.frames.last().map(PathBuf::as_path).unwrap_or(&self.dir))
    }

    /// Writes the animation ([`ANIMATION`]) of every frame pushed, looping forever, and returns its
    /// path; `None` when no frame was pushed.
    pub fn finish(self) -> Result<Option<PathBuf>, OutputError> {
        let Some((width, height)) = self.size else {
            return Ok(None);
        };
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
        enc.set_animated(self.frames.len() as u32, 0).map_err(png_error)?;
        enc.set_frame_delay(1, self.fps).map_err(png_error)?;
        // Every frame stays on the canvas for the next one to be drawn over.
        enc.set_dispose_op(png::DisposeOp::None).map_err(png_error)?;
        let mut writer = enc.write_header().map_err(png_error)?;
        let mut buf = Vec::new();
        let mut previous: Vec<u8> = Vec::new();
        let mut delta = Vec::new();
        for frame in &self.frames {
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
                writer.write_image_data(&delta).map_err(png_error)?;
            } else {
                let d = Delta::between(&previous, pixels, width as usize, key, &mut delta);
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
        Ok(Some(path))
    }
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
}
