//! A sequence of frames written to a folder: one PNG per frame as it comes, and at the end an
//! animated PNG (APNG) of them all.
//!
//! Frames go to disk as they are pushed, so a long session holds one frame in memory, not all of
//! them; [`Sequence::finish`] reads them back one at a time to write the animation. APNG rather
//! than GIF: the `png` crate (already used for heightmaps) writes it, it keeps full 24-bit colour
//! where a GIF would quantise the ramp's gradients to 256 colours, and browsers and image viewers
//! play it (a viewer without APNG support shows the first frame).

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
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        enc.set_animated(self.frames.len() as u32, 0).map_err(png_error)?;
        enc.set_frame_delay(1, self.fps).map_err(png_error)?;
        let mut writer = enc.write_header().map_err(png_error)?;
        let mut buf = Vec::new();
        for frame in &self.frames {
            let file = File::open(frame).map_err(io_error(frame))?;
            let mut reader = png::Decoder::new(BufReader::new(file)).read_info().map_err(png_error)?;
            buf.resize(reader.output_buffer_size().unwrap_or(0), 0);
            let info = reader.next_frame(&mut buf).map_err(png_error)?;
            writer.write_image_data(&buf[..info.buffer_size()]).map_err(png_error)?;
        }
        writer.finish().map_err(png_error)?;
        Ok(Some(path))
    }
}
