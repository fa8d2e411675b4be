//! The output: an RGBA8 frame buffer, and why a frame could not be rendered.

use thiserror::Error;

/// A colour: red, green, blue, alpha, 8 bits each (sRGB, alpha 255 = opaque).
pub type Rgba = [u8; 4];

/// The largest frame side the rasteriser's fixed-point coordinates allow (see [`crate::raster::rasterise`]).
pub const MAX_SIDE: u32 = 16384;

/// Refuses a zero side or one above [`MAX_SIDE`].
pub(crate) fn check_size(width: u32, height: u32) -> Result<(), RenderError> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(RenderError::FrameSize { width, height });
    }
    Ok(())
}

/// Why a frame could not be rendered.
#[derive(Debug, Error, PartialEq)]
pub enum RenderError {
    /// The frame has a zero side or one too large for the rasteriser.
    #[error("frame size {width} × {height} is not drawable (each side 1 to {max})", max = MAX_SIDE)]
    FrameSize {
        /// Width asked for.
        width: u32,
        /// Height asked for.
        height: u32,
    },
    /// The camera's parameters are not usable.
    #[error("camera: {0}")]
    Camera(&'static str),
    /// [`Renderer::reproject`](crate::Renderer::reproject) has no held eye to move.
    #[error("nothing to reproject: {0}")]
    NotHeld(&'static str),
}

/// An RGBA8 image, row-major, top row first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Frame {
    width: u32,
    height: u32,
    pixels: Vec<Rgba>,
}

impl Frame {
    /// A frame of `width × height` pixels, all transparent black. A zero side or one above
    /// [`MAX_SIDE`] is refused.
    pub fn new(width: u32, height: u32) -> Result<Frame, RenderError> {
        check_size(width, height)?;
        Ok(Frame {
            width,
            height,
            pixels: vec![[0; 4]; width as usize * height as usize],
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixels, row-major: pixel `(x, y)` is at `y·width + x`.
    pub fn pixels(&self) -> &[Rgba] {
        &self.pixels
    }

    /// The pixels, mutable.
    pub fn pixels_mut(&mut self) -> &mut [Rgba] {
        &mut self.pixels
    }

    /// The pixel at `(x, y)`, or `None` off the frame.
    pub fn pixel(&self, x: u32, y: u32) -> Option<Rgba> {
        (x < self.width && y < self.height).then(|| self.pixels[y as usize * self.width as usize + x as usize])
    }

    /// Copies `other` into this frame with its top-left corner at `(x, y)`, clipped to this
    /// frame (a picture in the picture).
    pub fn blit(&mut self, other: &Frame, x: u32, y: u32) {
        let w = other.width.min(self.width.saturating_sub(x)) as usize;
        for row in 0..other.height.min(self.height.saturating_sub(y)) {
            let src = row as usize * other.width as usize;
            let dst = (y + row) as usize * self.width as usize + x as usize;
            self.pixels[dst..dst + w].copy_from_slice(&other.pixels[src..src + w]);
        }
    }

    /// The pixels as bytes, `R G B A` per pixel.
    pub fn as_bytes(&self) -> &[u8] {
        self.pixels.as_flattened()
    }

    /// How far `other` is from this frame over R, G and B (alpha ignored): the mean absolute
    /// difference per channel (0–255) and the PSNR in dB (infinite for equal frames); `None`
    /// when the sizes differ.
    pub fn difference(&self, other: &Frame) -> Option<(f64, f64)> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        let (mut sum, mut sq) = (0.0, 0.0);
        for (p, q) in self.pixels.iter().zip(&other.pixels) {
            for c in 0..3 {
                let d = f64::from(p[c]) - f64::from(q[c]);
                sum += d.abs();
                sq += d * d;
            }
        }
        let n = 3.0 * self.pixels.len() as f64;
        Some((sum / n, 10.0 * (255.0 * 255.0 / (sq / n)).log10()))
    }

    /// The share of pixels whose colour differs from `other`'s by more than `levels` in R, G or
    /// B: where the frames differ visibly, beside a shading that differs by a level or two;
    /// `None` when the sizes differ.
    pub fn visibly_different(&self, other: &Frame, levels: u8) -> Option<f64> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        let n = self
            .pixels
            .iter()
            .zip(&other.pixels)
            .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > levels))
            .count();
        Some(n as f64 / self.pixels.len().max(1) as f64)
    }
}
