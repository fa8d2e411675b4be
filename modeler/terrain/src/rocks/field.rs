//! A document's rock field as the method's input: its image (the outline's bounding box in
//! field cells, and which cells lie inside the outline) and its recipe.

use crate::document::{Point, RockField};

use super::{Amount, Layer, Recipe, Sampler, Shape};

/// A field's image: `width × height` cells of `cell_size`, its corner `(0, 0)` at `origin`
/// relative to the field's `at`; `inside` flags the cells whose centre is inside the outline.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Cells along x.
    pub width: u32,
    /// Cells along y.
    pub height: u32,
    /// The image's corner relative to the field's `at`, metres.
    pub origin: Point,
    /// One flag per cell, row-major.
    pub inside: Vec<bool>,
}

/// The outline's cell counts along x and y, before allocating anything (for the size check).
pub fn extent(field: &RockField) -> (f64, f64, Point) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &field.outline {
        lo = [lo[0].min(p[0]), lo[1].min(p[1])];
        hi = [hi[0].max(p[0]), hi[1].max(p[1])];
    }
    let s = field.cell_size;
    (
        ((hi[0] - lo[0]) / s).ceil().max(1.0),
        ((hi[1] - lo[1]) / s).ceil().max(1.0),
        lo,
    )
}

/// The field's image. The outline is closed (validated); cells are inside when their centre is
/// (even-odd rule, a scanline per row).
pub fn image(field: &RockField) -> Image {
    let (w, h, origin) = extent(field);
    let (width, height) = (w as u32, h as u32);
    let s = field.cell_size;
    let mut inside = vec![false; width as usize * height as usize];
    let pts: Vec<[f64; 2]> = field
        .outline
        .iter()
        .map(|p| [(p[0] - origin[0]) / s, (p[1] - origin[1]) / s])
        .collect();
    let mut xs = Vec::new();
    for row in 0..height {
        let y = f64::from(row) + 0.5;
        xs.clear();
        for e in pts.windows(2) {
            let (a, b) = (e[0], e[1]);
            if (a[1] > y) != (b[1] > y) {
                xs.push(a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]));
            }
        }
        xs.sort_by(f64::total_cmp);
        for span in xs.chunks_exact(2) {
            // Cells whose centre c + ½ lies in [x0, x1).
            let c0 = (span[0] - 0.5).ceil().max(0.0) as u32;
            let c1 = ((span[1] - 0.5).ceil().max(0.0) as u32).min(width);
            for c in c0..c1 {
                inside[(row * width + c) as usize] = true;
            }
        }
    }
    Image {
        width,
        height,
        origin,
        inside,
    }
}

/// The recipe of `field` on an image of `width × height` cells.
pub fn recipe(field: &RockField, width: u32, height: u32) -> Recipe {
    Recipe {
        width,
        height,
        layers: field
            .layers
            .iter()
            .map(|l| Layer {
                radius: l.radius,
                amount: match (l.fraction, l.count) {
                    (_, Some(c)) => Amount::Count(c),
                    (Some(f), None) => Amount::Fraction(f),
                    (None, None) => Amount::Fraction(0.0),
                },
                shape: Shape {
                    widths: l.widths,
                    heights: l.heights,
                },
            })
            .collect(),
        seed: field.seed,
        sampler: Sampler::Saturate,
    }
}
