//! A rock field seen from straight above, like the seed's fig. 6 (d): each kept cell filled in
//! its diagram's colour (a little lighter or darker per cell, so neighbours stand apart), the
//! ground between them dark, so the gaps between cells of different sizes show.

use std::io::Write;

use crate::export::ExportError;

use super::Scatter;

/// Colours by selection order (largest cells first): sandstone, slate, lichen, then again.
const COLOURS: [[f64; 3]; 3] = [[196.0, 150.0, 104.0], [112.0, 138.0, 168.0], [150.0, 176.0, 96.0]];
const GROUND: [u8; 3] = [28, 26, 24];

/// The top view, `scale` pixels per field cell: RGB rows, `width·scale × height·scale`.
pub fn top_view(scatter: &Scatter, scale: u32) -> (u32, u32, Vec<u8>) {
    let scale = scale.max(1);
    let (w, h) = (scatter.width * scale, scatter.height * scale);
    let mut rgb: Vec<u8> = GROUND
        .iter()
        .copied()
        .cycle()
        .take(w as usize * h as usize * 3)
        .collect();
    let s = f64::from(scale);
    for rock in &scatter.rocks {
        let poly = rock.polygon;
        let order = scatter.diagrams[rock.diagram].order;
        // A cell's shade from its index, spread by a multiplicative hash.
        let shade = 0.8 + 0.4 * f64::from(rock.cell.wrapping_mul(2_654_435_761) >> 24) / 255.0;
        let colour = COLOURS[order % COLOURS.len()].map(|c| (c * shade).min(255.0) as u8);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in poly {
            lo = [lo[0].min(p[0]), lo[1].min(p[1])];
            hi = [hi[0].max(p[0]), hi[1].max(p[1])];
        }
        let x0 = ((lo[0] * s).floor().max(0.0)) as u32;
        let y0 = ((lo[1] * s).floor().max(0.0)) as u32;
        let x1 = ((hi[0] * s).ceil() as u32).min(w);
        let y1 = ((hi[1] * s).ceil() as u32).min(h);
        for py in y0..y1 {
            for px in x0..x1 {
                let q = [(f64::from(px) + 0.5) / s, (f64::from(py) + 0.5) / s];
                let inside = (0..poly.len()).all(|i| {
                    let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                    (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0]) >= 0.0
                });
                if inside {
                    let at = (py as usize * w as usize + px as usize) * 3;
                    rgb[at..at + 3].copy_from_slice(&colour);
                }
            }
        }
    }
    (w, h, rgb)
}

/// Writes the top view as an 8-bit RGB PNG.
pub fn write_top_view_png(scatter: &Scatter, scale: u32, out: impl Write) -> Result<(), ExportError> {
    let (w, h, rgb) = top_view(scatter, scale);
    let mut enc = png::Encoder::new(out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let png_error = |e: png::EncodingError| ExportError::Png(e.to_string());
    let mut writer = enc.write_header().map_err(png_error)?;
    writer.write_image_data(&rgb).map_err(png_error)?;
    writer.finish().map_err(png_error)?;
    Ok(())
}
