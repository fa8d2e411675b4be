//! Exclusive selection of cells (the seed's fig. 5): cells of one diagram drawn at random, each
//! once, kept only if none of their pixels is taken yet, until the diagram's area or count is
//! reached. Diagrams go largest mean cell first, so the big rocks find room.

use rand::Rng;

use super::voronoi::CellPixels;

/// When a diagram stops taking cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Goal {
    /// Until at least this many pixels are taken by the diagram's cells.
    Pixels(usize),
    /// Until this many cells are taken.
    Cells(usize),
}

/// What one diagram's selection took.
#[derive(Debug, Clone, PartialEq)]
pub struct Taken {
    /// The kept cells, in the order they were drawn.
    pub cells: Vec<u32>,
    /// Their pixels in all.
    pub pixels: usize,
    /// Cells drawn (kept or not) before the goal was reached or the cells ran out.
    pub tried: usize,
}

/// Draws cells of `cells` in random order and keeps those whose pixels are all free in `taken`,
/// marking them, until `goal`.
pub fn select(cells: &CellPixels, taken: &mut [bool], goal: Goal, rng: &mut impl Rng) -> Taken {
    let n = cells.start.len() - 1;
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut out = Taken {
        cells: Vec::new(),
        pixels: 0,
        tried: 0,
    };
    let done = |t: &Taken| match goal {
        Goal::Pixels(p) => t.pixels >= p,
        Goal::Cells(c) => t.cells.len() >= c,
    };
    for i in 0..n {
        if done(&out) {
            break;
        }
        let j = super::poisson::below(rng, i, n);
        order.swap(i, j);
        let c = order[i];
        out.tried += 1;
        let pixels = cells.cell(c as usize);
        if pixels.is_empty() || pixels.iter().any(|&p| taken[p as usize]) {
            continue;
        }
        for &p in pixels {
            taken[p as usize] = true;
        }
        out.cells.push(c);
        out.pixels += pixels.len();
    }
    out
}
