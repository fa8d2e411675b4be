//! Silhouettes of trees: orthographic coverage images of a species from the front and the side,
//! read from and written to PNG, framed alike and compared by normalised cross-correlation (the
//! seed's objective for reconstructing a tree, [`super::fit`]).
//!
//! Framing makes a drawn silhouette and a rendered one comparable whatever their size in their
//! images: the object's bounding box (coverage above ½) is scaled so its height fills
//! [`FILL`] of a square canvas, centred across, standing on the canvas' bottom margin.

use std::io::{BufRead, Seek, Write};

use thiserror::Error;

use super::nodes::NodeTree;
use super::species::Species;

/// The fraction of the canvas' height the framed object fills.
pub const FILL: f64 = 0.9;

/// Samples per pixel side when rasterising (4 × 4 per pixel: grey edges).
const SUPER: usize = 4;

/// A grey image of coverage, 0 (background) to 1 (tree); row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width × height` coverages, row by row.
    pub data: Vec<f32>,
}

/// Which way a silhouette looks at the tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// Along −Z: across is X.
    Front,
    /// Along +X: across is Z.
    Side,
}

/// Why a silhouette could not be read or written.
#[derive(Debug, Error)]
pub enum SilhouetteError {
    /// Reading or writing failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// Not a PNG the decoder reads.
    #[error("not a readable PNG: {0}")]
    Png(String),
    /// No pixel differs from the background.
    #[error("the image is blank: no silhouette differs from its border")]
    Blank,
}

impl Image {
    /// A blank image.
    pub fn new(width: usize, height: usize) -> Image {
        Image {
            width,
            height,
            data: vec![0.0; width * height],
        }
    }

    /// The coverage at `(x, y)`.
    pub fn get(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }

    /// The bounding box `(x0, y0, x1, y1)` (inclusive) of coverage above ½, if any.
    pub fn bounds(&self) -> Option<(usize, usize, usize, usize)> {
        let mut b: Option<(usize, usize, usize, usize)> = None;
        for y in 0..self.height {
            for x in 0..self.width {
                if self.get(x, y) > 0.5 {
                    b = Some(match b {
                        None => (x, y, x, y),
                        Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x), y1.max(y)),
                    });
                }
            }
        }
        b
    }

    /// The object framed on a `size × size` canvas (bilinear resampling of its bounding box).
    pub fn framed(&self, size: usize) -> Option<Image> {
        let (x0, y0, x1, y1) = self.bounds()?;
        let (bw, bh) = ((x1 - x0 + 1) as f64, (y1 - y0 + 1) as f64);
        let scale = FILL * size as f64 / bh;
        let margin = 0.5 * (1.0 - FILL) * size as f64;
        let cx = 0.5 * (x0 as f64 + x1 as f64 + 1.0);
        let mut out = Image::new(size, size);
        for v in 0..size {
            for u in 0..size {
                // The canvas pixel's centre in the source's pixel coordinates.
                let sx = cx + (u as f64 + 0.5 - 0.5 * size as f64) / scale;
                let sy = y1 as f64 + 1.0 - (size as f64 - margin - (v as f64 + 0.5)) / scale;
                if sx < x0 as f64 - 1.0 || sx > x0 as f64 + bw + 1.0 || sy < y0 as f64 - 1.0 {
                    continue;
                }
                out.data[v * size + u] = self.sample(sx - 0.5, sy - 0.5);
            }
        }
        Some(out)
    }

    /// Bilinear sample at pixel coordinates (centres at integers), 0 outside.
    fn sample(&self, x: f64, y: f64) -> f32 {
        let (fx, fy) = (x.floor(), y.floor());
        let (tx, ty) = ((x - fx) as f32, (y - fy) as f32);
        let at = |xi: f64, yi: f64| {
            if xi < 0.0 || yi < 0.0 || xi >= self.width as f64 || yi >= self.height as f64 {
                0.0
            } else {
                self.get(xi as usize, yi as usize)
            }
        };
        let top = at(fx, fy) * (1.0 - tx) + at(fx + 1.0, fy) * tx;
        let bottom = at(fx, fy + 1.0) * (1.0 - tx) + at(fx + 1.0, fy + 1.0) * tx;
        top * (1.0 - ty) + bottom * ty
    }

    /// A 3 × 3 box blur applied `passes` times (smooths the fit's objective).
    pub fn blurred(&self, passes: usize) -> Image {
        let mut img = self.clone();
        for _ in 0..passes {
            let mut next = Image::new(self.width, self.height);
            for y in 0..self.height {
                for x in 0..self.width {
                    let mut sum = 0.0;
                    for dy in -1i64..=1 {
                        for dx in -1i64..=1 {
                            let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                            if xx >= 0 && yy >= 0 && (xx as usize) < self.width && (yy as usize) < self.height {
                                sum += img.get(xx as usize, yy as usize);
                            }
                        }
                    }
                    next.data[y * self.width + x] = sum / 9.0;
                }
            }
            img = next;
        }
        img
    }

    /// Reads a PNG (grey, grey and alpha, RGB or RGBA; 8 or 16 bits): coverage is the distance
    /// of each pixel's luminance from the border's mean, so a dark tree on a light ground and a
    /// light one on a dark ground both read as coverage; alpha multiplies it.
    pub fn read_png(input: impl BufRead + Seek) -> Result<Image, SilhouetteError> {
        let png_error = |e: png::DecodingError| SilhouetteError::Png(e.to_string());
        let mut decoder = png::Decoder::new(input);
        decoder.set_transformations(png::Transformations::normalize_to_color8());
        let mut reader = decoder.read_info().map_err(png_error)?;
        let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
        let info = reader.next_frame(&mut buf).map_err(png_error)?;
        let (w, h) = (info.width as usize, info.height as usize);
        let channels = info.color_type.samples();
        let luma_alpha = |px: &[u8]| -> (f32, f32) {
            let f = |v: u8| f32::from(v) / 255.0;
            match channels {
                1 => (f(px[0]), 1.0),
                2 => (f(px[0]), f(px[1])),
                3 => (0.2126 * f(px[0]) + 0.7152 * f(px[1]) + 0.0722 * f(px[2]), 1.0),
                _ => (0.2126 * f(px[0]) + 0.7152 * f(px[1]) + 0.0722 * f(px[2]), f(px[3])),
            }
        };
        let pixels: Vec<(f32, f32)> = buf[..info.buffer_size()]
            .chunks_exact(channels)
            .map(luma_alpha)
            .collect();
        if w == 0 || h == 0 || pixels.len() != w * h {
            return Err(SilhouetteError::Blank);
        }
        let border: Vec<f32> = (0..w)
            .flat_map(|x| [x, (h - 1) * w + x])
            .chain((0..h).flat_map(|y| [y * w, y * w + w - 1]))
            .map(|i| pixels[i].0)
            .collect();
        let ground = border.iter().sum::<f32>() / border.len() as f32;
        let far = ground.max(1.0 - ground);
        let data: Vec<f32> = pixels
            .iter()
            .map(|&(l, a)| ((l - ground).abs() / far * a).clamp(0.0, 1.0))
            .collect();
        let img = Image {
            width: w,
            height: h,
            data,
        };
        match img.bounds() {
            Some(_) => Ok(img),
            None => Err(SilhouetteError::Blank),
        }
    }

    /// Writes the image as an 8-bit grey PNG, the tree black on white.
    pub fn write_png(&self, out: impl Write) -> Result<(), SilhouetteError> {
        let png_error = |e: png::EncodingError| SilhouetteError::Png(e.to_string());
        let mut enc = png::Encoder::new(out, self.width as u32, self.height as u32);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(png_error)?;
        let data: Vec<u8> = self
            .data
            .iter()
            .map(|c| (255.0 * (1.0 - c.clamp(0.0, 1.0))).round() as u8)
            .collect();
        writer.write_image_data(&data).map_err(png_error)?;
        writer.finish().map_err(png_error)?;
        Ok(())
    }
}

/// The normalised cross-correlation of two images of one size: 1 for images equal up to
/// brightness and contrast, 0 for unrelated ones (and when either is flat).
pub fn ncc(a: &Image, b: &Image) -> f64 {
    let n = a.data.len().min(b.data.len()) as f64;
    if n == 0.0 {
        return 0.0;
    }
    let ma = a.data.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let mb = b.data.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for (&x, &y) in a.data.iter().zip(&b.data) {
        let (x, y) = (f64::from(x) - ma, f64::from(y) - mb);
        ab += x * y;
        aa += x * x;
        bb += y * y;
    }
    if aa <= 0.0 || bb <= 0.0 {
        0.0
    } else {
        ab / (aa * bb).sqrt()
    }
}

/// Fills the triangles of `tree` projected in `view` into an image of `size × size` pixels
/// framed like [`Image::framed`] (the tree's projected bounding box, height to [`FILL`]).
pub fn render_tree(tree: &NodeTree, view: View, size: usize) -> Image {
    let across = |p: &[f32; 3]| {
        f64::from(match view {
            View::Front => p[0],
            View::Side => p[2],
        })
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &tree.positions {
        let q = [across(p), f64::from(p[1])];
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let mut img = Image::new(size, size);
    if tree.positions.is_empty() || hi[1] <= lo[1] {
        return img;
    }
    let scale = FILL * size as f64 / (hi[1] - lo[1]);
    let margin = 0.5 * (1.0 - FILL) * size as f64;
    let cx = 0.5 * (lo[0] + hi[0]);
    // Canvas coordinates in samples (SUPER per pixel), y down.
    let n = size * SUPER;
    let to_canvas = |p: &[f32; 3]| {
        let u = (0.5 * size as f64 + (across(p) - cx) * scale) * SUPER as f64;
        let v = (size as f64 - margin - (f64::from(p[1]) - lo[1]) * scale) * SUPER as f64;
        [u, v]
    };
    let mut hits = vec![false; n * n];
    for node in &tree.nodes {
        let v0 = node.vertices.0 as usize;
        let (t0, t1) = (node.triangles.0 as usize, node.triangles.1 as usize);
        for t in tree.indices[t0..t1].chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| to_canvas(&tree.positions[v0 + i as usize]));
            fill_triangle(&mut hits, n, a, b, c);
        }
    }
    let per = (SUPER * SUPER) as f32;
    for y in 0..size {
        for x in 0..size {
            let mut k = 0;
            for sy in 0..SUPER {
                for sx in 0..SUPER {
                    k += usize::from(hits[(y * SUPER + sy) * n + x * SUPER + sx]);
                }
            }
            img.data[y * size + x] = k as f32 / per;
        }
    }
    img
}

/// Sets the samples (centres at `i + ½`) inside triangle `a b c`, either winding.
fn fill_triangle(hits: &mut [bool], n: usize, a: [f64; 2], b: [f64; 2], c: [f64; 2]) {
    let edge = |p: [f64; 2], q: [f64; 2], x: f64, y: f64| (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
    let area = edge(a, b, c[0], c[1]);
    if area == 0.0 {
        return;
    }
    let clampi = |v: f64| v.clamp(0.0, n as f64) as usize;
    let (x0, x1) = (
        clampi(a[0].min(b[0]).min(c[0]).floor()),
        clampi(a[0].max(b[0]).max(c[0]).ceil()),
    );
    let (y0, y1) = (
        clampi(a[1].min(b[1]).min(c[1]).floor()),
        clampi(a[1].max(b[1]).max(c[1]).ceil()),
    );
    let sign = area.signum();
    for y in y0..y1 {
        let py = y as f64 + 0.5;
        for x in x0..x1 {
            let px = x as f64 + 0.5;
            if sign * edge(a, b, px, py) >= 0.0 && sign * edge(b, c, px, py) >= 0.0 && sign * edge(c, a, px, py) >= 0.0
            {
                hits[y * n + x] = true;
            }
        }
    }
}

/// A species' silhouette in `view` on a `size × size` canvas, from its tree with branches down
/// to `stop` (a scale; coarser is faster, the leaves standing for larger groups).
pub fn render(species: &Species, view: View, size: usize, stop: f64) -> Image {
    render_tree(&NodeTree::build_to(species, stop), view, size)
}
