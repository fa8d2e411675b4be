//! 4-neighbour distance maps over a region, in linear time.
//!
//! Both maps are breadth-first searches from a set of sources, moving only through the region's
//! cells: every cell is queued once and looks at its four neighbours once, so a map costs
//! O(cells of the region's box). The seed's method (repeat sweeps over the grid until nothing
//! changes) computes the same numbers in O(cells × largest distance); it is kept in the crate's
//! tests (`tests/baseline.rs`) as the reference and benchmark baseline.
//!
//! Maps are laid out over the region mask's bounding box, row-major; cells outside the region
//! hold [`UNREACHABLE`].
//!
//! [`figure_map`] and [`edge_map`] give the maps the engine reads in either metric, as `f32`
//! (infinite where unreachable): these 4-neighbour ones for `taxicab` (integers, exact in `f32`,
//! so seed 000's numbers are unchanged to the bit), [`crate::edt`]'s for `euclidean`.

use crate::cells::{Cell, Mask};
use crate::document::Metric;
use crate::edt;
use crate::pool;

/// Distance of a cell no path within the region reaches (and of cells outside the region).
pub const UNREACHABLE: u32 = u32::MAX;

/// The box indices of the 4-neighbours of box index `i` that lie in the box.
#[inline]
pub(crate) fn neighbours(mask: &Mask, i: usize) -> [Option<usize>; 4] {
    let w = mask.width as usize;
    let (x, y) = (i % w, i / w);
    [
        (x > 0).then(|| i - 1),
        (x + 1 < w).then(|| i + 1),
        (y > 0).then(|| i - w),
        (y + 1 < mask.height as usize).then(|| i + w),
    ]
}

/// Whether region cell `i` has a 4-neighbour outside the region (or the box, hence the grid).
pub(crate) fn on_edge(mask: &Mask, i: usize) -> bool {
    let bits = mask.bits();
    neighbours(mask, i).iter().any(|n| n.is_none_or(|j| !bits[j]))
}

/// A distance as a breadth-first search stores it: `u32` for the public maps, `f32` for the
/// maps the engine reads (whole numbers, exact in `f32` below 2^24, a bound the grid's cell
/// limit keeps), so that the engine's maps need no second pass to convert them.
trait Level: Copy + PartialEq {
    const ZERO: Self;
    const UNSEEN: Self;
    fn next(self) -> Self;
    /// A map of `len` cells, each [`Level::UNSEEN`].
    fn unseen(len: usize) -> Vec<Self>;
}

impl Level for u32 {
    const ZERO: u32 = 0;
    const UNSEEN: u32 = UNREACHABLE;
    fn next(self) -> u32 {
        self + 1
    }
    fn unseen(len: usize) -> Vec<u32> {
        vec![UNREACHABLE; len]
    }
}

impl Level for f32 {
    const ZERO: f32 = 0.0;
    const UNSEEN: f32 = f32::INFINITY;
    fn next(self) -> f32 {
        self + 1.0
    }
    /// The engine's maps come from (and go back to) [`pool::MAPS`].
    fn unseen(len: usize) -> Vec<f32> {
        pool::MAPS.filled(len, f32::INFINITY)
    }
}

/// The breadth-first search from the cells of `front` (each with its box column), which hold 0,
/// one layer at a time: each queued cell carries its column so that finding its neighbours needs
/// no division, and only two layers are held (not every cell of the box), so they stay in the
/// cache.
fn bfs<D: Level>(mask: &Mask, dist: &mut [D], mut front: Vec<(u32, u32)>) {
    let bits = mask.bits();
    let (w, n) = (mask.width as usize, bits.len());
    let mut next = Vec::with_capacity(front.len());
    let mut d = D::ZERO;
    while !front.is_empty() {
        d = d.next();
        for &(i, x) in &front {
            let (i, x) = (i as usize, x as usize);
            let mut visit = |j: usize, xj: usize| {
                if dist[j] == D::UNSEEN && bits[j] {
                    dist[j] = d;
                    next.push((j as u32, xj as u32));
                }
            };
            // The order of `neighbours`: left, right, up, down.
            if x > 0 {
                visit(i - 1, x - 1);
            }
            if x + 1 < w {
                visit(i + 1, x + 1);
            }
            if i >= w {
                visit(i - w, x);
            }
            if i + w < n {
                visit(i + w, x);
            }
        }
        front.clear();
        std::mem::swap(&mut front, &mut next);
    }
}

/// [`from_sources`] in either storage.
fn search_from<D: Level>(mask: &Mask, sources: &[Cell]) -> Vec<D> {
    let mut dist = D::unseen(mask.box_len());
    let mut front = Vec::new();
    for &s in sources {
        if let Some(i) = mask.index(s).filter(|&i| mask.bits()[i] && dist[i] != D::ZERO) {
            dist[i] = D::ZERO;
            front.push((i as u32, s.0 - mask.c0));
        }
    }
    bfs(mask, &mut dist, front);
    dist
}

/// [`edge_layers`] in either storage.
fn search_edge<D: Level>(mask: &Mask) -> Vec<D> {
    let mut dist = D::unseen(mask.box_len());
    let mut front = Vec::new();
    let w = (mask.width as usize).max(1);
    for (i, &inside) in mask.bits().iter().enumerate() {
        if inside && on_edge(mask, i) {
            dist[i] = D::ZERO;
            front.push((i as u32, (i % w) as u32));
        }
    }
    bfs(mask, &mut dist, front);
    dist
}

/// `dp`: the distance of every region cell from the nearest of `sources`, moving through region
/// cells only. Sources outside the region are ignored.
pub fn from_sources(mask: &Mask, sources: &[Cell]) -> Vec<u32> {
    search_from(mask, sources)
}

/// `df`: the layer count from the region's edge. Region cells with a 4-neighbour outside the
/// region (or the grid) are 0, the next layer 1, and so on.
pub fn edge_layers(mask: &Mask) -> Vec<u32> {
    search_edge(mask)
}

/// `dp` in `metric`: [`from_sources`] or [`edt::from_sources`].
pub fn figure_map(metric: Metric, mask: &Mask, sources: &[Cell]) -> Vec<f32> {
    match metric {
        Metric::Taxicab => search_from(mask, sources),
        Metric::Euclidean => edt::from_sources(mask, sources),
    }
}

/// `df` in `metric`: [`edge_layers`] or [`edt::to_edge`].
pub fn edge_map(metric: Metric, mask: &Mask) -> Vec<f32> {
    match metric {
        Metric::Taxicab => search_edge(mask),
        Metric::Euclidean => edt::to_edge(mask),
    }
}
