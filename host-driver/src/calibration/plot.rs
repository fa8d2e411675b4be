//! The calibration's residual plot: the display's outline, each target (a ring), where its touch
//! landed after the fit (a dot), and the residual magnified 100 times (a line from the target),
//! with a scale bar of 1 mm × 100. Written as a PNG; the numbers are in the calibration file.

use std::path::Path;

use glam::DVec2;

use crate::calibration::Calibration;

/// How much the residuals are magnified.
pub const MAGNIFY: f64 = 100.0;

struct Canvas {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn new(w: usize, h: usize) -> Canvas {
        Canvas {
            w,
            h,
            rgb: vec![255; w * h * 3],
        }
    }

    fn dot(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as usize) < self.w && (y as usize) < self.h {
            let i = (y as usize * self.w + x as usize) * 3;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// A line with a square pen of half-width `r` (Bresenham).
    fn line(&mut self, a: DVec2, b: DVec2, r: i64, c: [u8; 3]) {
        let (mut x0, mut y0, x1, y1) = (
            a.x.round() as i64,
            a.y.round() as i64,
            b.x.round() as i64,
            b.y.round() as i64,
        );
        let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
        let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
        let mut err = dx + dy;
        loop {
            for ox in -r..=r {
                for oy in -r..=r {
                    self.dot(x0 + ox, y0 + oy, c);
                }
            }
            if x0 == x1 && y0 == y1 {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x0 += sx;
            }
            if e2 <= dx {
                err += dx;
                y0 += sy;
            }
        }
    }

    fn ring(&mut self, at: DVec2, radius: f64, c: [u8; 3]) {
        let steps = 64;
        for i in 0..steps {
            let a = std::f64::consts::TAU * i as f64 / steps as f64;
            let b = std::f64::consts::TAU * (i + 1) as f64 / steps as f64;
            self.line(
                at + DVec2::from_angle(a) * radius,
                at + DVec2::from_angle(b) * radius,
                0,
                c,
            );
        }
    }

    fn disc(&mut self, at: DVec2, radius: f64, c: [u8; 3]) {
        let r = radius.ceil() as i64;
        for ox in -r..=r {
            for oy in -r..=r {
                if ((ox * ox + oy * oy) as f64) <= radius * radius {
                    self.dot(at.x.round() as i64 + ox, at.y.round() as i64 + oy, c);
                }
            }
        }
    }
}

/// Draws `calibration`'s residuals and writes them to `path` as a PNG of `width` pixels.
pub fn write_residual_plot(calibration: &Calibration, path: &Path, width: usize) -> std::io::Result<()> {
    let d = calibration.display;
    let margin = 40.0;
    let scale = (width as f64 - 2.0 * margin) / d.width_mm;
    let height = (d.height_mm * scale + 2.0 * margin).round() as usize;
    let mut c = Canvas::new(width, height);
    // Display coordinates have v up; the image has y down.
    let to_px = |p: DVec2| DVec2::new(margin + p.x * scale, height as f64 - margin - p.y * scale);
    let corners = [
        DVec2::ZERO,
        DVec2::new(d.width_mm, 0.0),
        DVec2::new(d.width_mm, d.height_mm),
        DVec2::new(0.0, d.height_mm),
    ];
    for i in 0..4 {
        c.line(to_px(corners[i]), to_px(corners[(i + 1) % 4]), 0, [120, 120, 120]);
    }
    for r in &calibration.residuals {
        let fitted = calibration.transform.apply(r.touched_mm).truncate();
        let target = to_px(r.target_mm);
        let landed = to_px(r.target_mm + (fitted - r.target_mm) * MAGNIFY);
        c.ring(target, 8.0, [30, 90, 200]);
        c.line(target, landed, 1, [220, 60, 40]);
        c.disc(landed, 3.0, [220, 60, 40]);
    }
    // Scale bar: 1 mm of residual, as drawn.
    let start = DVec2::new(margin, margin / 2.0);
    c.line(start, start + DVec2::new(MAGNIFY * scale, 0.0), 1, [0, 0, 0]);
    c.line(start - DVec2::new(0.0, 4.0), start + DVec2::new(0.0, 4.0), 0, [0, 0, 0]);
    let end = start + DVec2::new(MAGNIFY * scale, 0.0);
    c.line(end - DVec2::new(0.0, 4.0), end + DVec2::new(0.0, 4.0), 0, [0, 0, 0]);

    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width as u32, height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .add_text_chunk(
            "Title".into(),
            format!("calibration residuals ×{MAGNIFY}, RMS {:.3} mm", calibration.rms_mm()),
        )
        .map_err(std::io::Error::other)?;
    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
    writer.write_image_data(&c.rgb).map_err(std::io::Error::other)?;
    writer.finish().map_err(std::io::Error::other)
}
