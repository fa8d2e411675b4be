//! The preview of a dragged control point, redone only on the part of the course the point
//! reaches.
//!
//! A drag's preview is the next year's erosion and deposition of the river with the point moved,
//! after all its committed years. Rebuilding the whole river at every pen sample costs a step per
//! year over the whole window (`preview/512/N` in the river bench). But moving one control point
//! changes only the one or two Bézier segments it shapes, and a year carries a change only
//! [`BEND_SPAN`] widths along the course each way (the bend is read, and the line's shift
//! averaged, over that span), so after N years the point reaches about `2·(N + 1)` spans each
//! way. [`Drag::preview`] processes only the segments within that reach (the *trusted* part)
//! and as far again beyond it (a margin, where cutting the course fixes its ends and truncates
//! its bends), and takes the rest of the preview from the river as it was when grabbed.
//!
//! So the preview during a drag is an approximation near the edges of the trusted part and
//! wherever a change travels further than the span (a neck cut off elsewhere, the even
//! resampling of the line shifting its samples by a fraction of a cell); the river committed
//! when the pen lets go is processed whole (the engine's layer does, from the edited entry), as
//! before. When the reach covers the whole course the drag processes the whole river.

use glam::DVec2;

use crate::document::{Grid, River};

use super::{BEND_SPAN, Constants, MAX_ITERATIONS, Shape, near::NONE};

/// Grid cells `[column, row]` the next year would erode and deposit.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Cells {
    /// Cells the outer banks would lose to the water.
    pub erosion: Vec<[u32; 2]>,
    /// Cells the inner banks would gain.
    pub deposition: Vec<[u32; 2]>,
}

impl Cells {
    /// The preview of `shape` as grid cells.
    pub fn of(shape: &Shape) -> Cells {
        // The preview's cells as window indices, in increasing order.
        let (add, remove) = shape.changes();
        let w = shape.window;
        let cells = |m: Vec<usize>| {
            m.into_iter()
                .map(|i| [w.c0 + (i % w.width) as u32, w.r0 + (i / w.width) as u32])
                .collect()
        };
        Cells {
            erosion: cells(add),
            deposition: cells(remove),
        }
    }
}

/// A river held by one of its control points: the river as grabbed, processed once.
#[derive(Debug, Clone, PartialEq)]
pub struct Drag {
    river: River,
    control: usize,
    grid: Grid,
    constants: Constants,
    base: Shape,
    base_cells: Cells,
}

/// What a drag processes: control points `first..=last` of the course, trusted between anchors
/// `trusted` (indices into the river's points; `None` at an end of the course, which is not cut).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Part {
    /// The first control point processed.
    pub first: usize,
    /// The last control point processed.
    pub last: usize,
    /// The anchors bounding the trusted part (`None`: the course's own end).
    pub trusted: (Option<usize>, Option<usize>),
}

impl Drag {
    /// `river` grabbed by control point `control`.
    pub fn new(river: &River, control: usize, grid: &Grid, constants: &Constants) -> Drag {
        let base = Shape::process(river, grid, constants);
        let base_cells = Cells::of(&base);
        Drag {
            river: river.clone(),
            control,
            grid: *grid,
            constants: *constants,
            base,
            base_cells,
        }
    }

    /// The river as grabbed, processed.
    pub fn base(&self) -> &Shape {
        &self.base
    }

    /// The preview of the river as grabbed.
    pub fn base_cells(&self) -> &Cells {
        &self.base_cells
    }

    /// The part of the course a drag of the held point processes, or `None` when that is all of
    /// it.
    pub fn part(&self) -> Option<Part> {
        let pts = &self.river.points;
        let n = pts.len();
        if n < 5 || self.control >= n {
            return None;
        }
        // The anchors are every third point; the point shapes the segments between the anchors
        // either side of it (an anchor: the segment before and the one after).
        let last_anchor = (n - 1) / 3 * 3;
        let (mut lo, mut hi) = (self.control.saturating_sub(1) / 3 * 3, self.control.div_ceil(3) * 3);
        if self.control.is_multiple_of(3) {
            lo = self.control.saturating_sub(3);
            hi = (self.control + 3).min(last_anchor);
        }
        hi = hi.min(n - 1);
        let cells = self.grid.cell_size;
        let radius = self.river.width / cells;
        let years = f64::from(self.river.iterations.min(MAX_ITERATIONS));
        // How far a change travels along the course by the next year's preview, in cells.
        let reach = 2.0 * BEND_SPAN * radius * (years + 1.0) + radius;
        let chord = |a: usize, b: usize| {
            let (p, q) = (pts[a], pts[b.min(n - 1)]);
            (p[0] - q[0]).hypot(p[1] - q[1]) / cells
        };
        // Anchors out from `lo` and `hi` until the chords (shorter than the course between them)
        // add up to `reach`.
        let back = |from: usize| {
            let (mut a, mut run) = (from, 0.0);
            while a > 0 && run < reach {
                run += chord(a - 3, a);
                a -= 3;
            }
            a
        };
        let ahead = |from: usize| {
            let (mut b, mut run) = (from, 0.0);
            while b < n - 1 && run < reach {
                let next = (b + 3).min(n - 1);
                run += chord(b, next);
                b = next;
            }
            b
        };
        let (t0, t1) = (back(lo), ahead(hi));
        let (first, last) = (back(t0), ahead(t1));
        if first == 0 && last == n - 1 {
            return None;
        }
        Some(Part {
            first,
            last,
            trusted: ((t0 > 0).then_some(t0), (t1 < n - 1).then_some(t1)),
        })
    }

    /// The next year's erosion and deposition of `moved` (the grabbed river with its held point
    /// moved: the same points otherwise).
    pub fn preview(&self, moved: &River) -> Cells {
        super::on_pool(|| self.preview_here(moved))
    }

    /// [`Drag::preview`] on the calling thread.
    fn preview_here(&self, moved: &River) -> Cells {
        let Some(part) = self.part().filter(|_| moved.points.len() == self.river.points.len()) else {
            let shape = Shape::process(moved, &self.grid, &self.constants);
            let cells = Cells::of(&shape);
            shape.recycle();
            return cells;
        };
        let sub_river = River {
            points: moved.points[part.first..=part.last].to_vec(),
            ..moved.clone()
        };
        let sub = Shape::process(&sub_river, &self.grid, &self.constants);
        // The anchors bounding the trusted part are not moved: the same points in both rivers.
        let anchor = |i: Option<usize>| {
            i.map(|i| {
                let s = self.grid.cell_size;
                DVec2::new(self.river.points[i][0] / s - 0.5, self.river.points[i][1] / s - 0.5)
            })
        };
        let (a, b) = (anchor(part.trusted.0), anchor(part.trusted.1));
        let sub_range = sample_range(&sub, a, b);
        let base_range = sample_range(&self.base, a, b);
        let in_range = |shape: &Shape, range: (u32, u32), c: [u32; 2]| {
            let w = shape.window;
            let (x, y) = (c[0].wrapping_sub(w.c0) as usize, c[1].wrapping_sub(w.r0) as usize);
            if x >= w.width || y >= w.height {
                return false;
            }
            let o = shape.near.owner[y * w.width + x];
            o != NONE && range.0 <= o && o <= range.1
        };
        let mut out = Cells::of(&sub);
        // The moved river's cells where its trusted part owns them; the grabbed river's
        // elsewhere, except where its own trusted part owned them (the water may have left).
        let keep = |c: &[u32; 2]| in_range(&sub, sub_range, *c);
        out.erosion.retain(keep);
        out.deposition.retain(keep);
        let from_base = |c: &&[u32; 2]| !in_range(&sub, sub_range, **c) && !in_range(&self.base, base_range, **c);
        out.erosion.extend(self.base_cells.erosion.iter().filter(from_base));
        out.deposition
            .extend(self.base_cells.deposition.iter().filter(from_base));
        sub.recycle();
        out
    }
}

/// The samples of `shape`'s line nearest `a` and `b` (its ends where `None`).
fn sample_range(shape: &Shape, a: Option<DVec2>, b: Option<DVec2>) -> (u32, u32) {
    let nearest = |p: DVec2| {
        shape
            .line
            .iter()
            .enumerate()
            .min_by(|x, y| x.1.p.distance_squared(p).total_cmp(&y.1.p.distance_squared(p)))
            .map_or(0, |(i, _)| i as u32)
    };
    let last = shape.line.len().saturating_sub(1) as u32;
    let (i, j) = (a.map_or(0, nearest), b.map_or(last, nearest));
    (i.min(j), i.max(j))
}
