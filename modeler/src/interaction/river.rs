//! The river tool (seed 003): rivers drawn, reshaped, widened and aged with the pen.
//!
//! Gestures follow seed 000's, as the rock tool's do (docs/modeler.md, "The river tool"):
//!
//! - **Pick the tool**: tap the river button (below the rock button) with the tip; tap it again
//!   to go back to figures.
//! - **Draw a river**: SW1 strokes the course on the surface, from its source to its mouth; SW3
//!   ends it. The stroke is fitted to a chain of cubic Bézier segments (an anchor every
//!   [`SEGMENT_MM`] of stroke), shown as its control polygon and points.
//! - **Reshape**: SW2 + touch on a control point grabs it; sliding carries it, and the next
//!   iteration's erosion (red) and deposition (light blue) follow it as a preview; lifting the tip
//!   (or releasing SW2) sets it.
//! - **Width and depth**: holding a river (SW2 + touch on its course or a point), hold SW3 and
//!   move: sideways widens (right) or narrows (left), up and down deepens or shallows —
//!   × e^(k·d), k = [`GAIN_PER_MM`] per mm, the same sideways SW3 gesture as slope; releasing
//!   SW3 sets both as one undoable edit.
//! - **Commit a year, or several**: an SW3 click over a river adds one iteration (elsewhere it
//!   undoes, as everywhere). Holding SW3 still over it counts on, one more year every
//!   [`YEAR_HOLD_US`] past the click's time, shown on the status line as it counts; releasing
//!   commits them as one undoable edit, moving (a pan) commits none.

use glam::DVec2;
use penmodel_terrain::document::{Document, Grid, Point, River};
use penmodel_terrain::river::drag::{Cells, Drag};
use penmodel_terrain::river::{Constants, MAX_ITERATIONS, Shape, course};

use super::palette::Button;
use super::view::View;

/// The river button on the display (below the rock tool's).
pub const BUTTON: Button = Button {
    corner_mm: [8.0, 32.0],
    side_mm: 20.0,
};
/// Gain of the width and depth gestures, per mm.
pub const GAIN_PER_MM: f64 = 0.02;
/// A new river's width (the disc radius) on the display, mm.
pub const WIDTH_MM: f64 = 2.0;
/// Stroke length per Bézier segment, mm.
pub const SEGMENT_MM: f64 = 25.0;
/// Holding SW3 still over a river past a click's time counts one more year per this many µs
/// (as a key repeats: slow enough to stop on the count wanted, about two years a second).
pub const YEAR_HOLD_US: u64 = 450_000;

/// The years an SW3 press held `held_us` over a river commits: 1 for a click (shorter than
/// `click_us`), then one more per [`YEAR_HOLD_US`].
pub fn years_held(held_us: u64, click_us: u64) -> u32 {
    let more = (held_us.saturating_sub(click_us) / YEAR_HOLD_US).min(u64::from(MAX_ITERATIONS));
    1 + more as u32
}

/// Whether display point `(u, v)` mm is on the river button.
pub fn on_palette(u_mm: f64, v_mm: f64) -> bool {
    BUTTON.contains(u_mm, v_mm)
}

/// The river button's outline on the ground (closed), for drawing.
pub fn palette_outline(view: &View) -> Vec<Point> {
    BUTTON.outline(view)
}

/// A river along a stroke (ground metres): its Bézier fit, [`WIDTH_MM`] wide on the display, half
/// as deep, the seed's water amount and hardness, no iteration yet. `None` for a stroke too short
/// to be a course.
pub fn new_river(stroke: &[Point], view: &View) -> Option<River> {
    let pts: Vec<DVec2> = stroke.iter().map(|p| DVec2::from(*p)).collect();
    let length: f64 = pts.windows(2).map(|w| w[0].distance(w[1])).sum();
    let width = view.metres(WIDTH_MM);
    if length < 2.0 * width {
        return None;
    }
    let anchors = ((length / view.metres(1.0) / SEGMENT_MM).round() as usize + 1).clamp(2, 40);
    let points = course::fit(&pts, anchors).iter().map(|p| [p.x, p.y]).collect();
    Some(River {
        points,
        width,
        depth: width / 2.0,
        water: 60.0,
        hardness: 1.0,
        iterations: 0,
    })
}

/// The control point nearest `g` within `tol` metres: `(river, point)`, the last drawn first.
pub fn control_at(doc: &Document, g: Point, tol: f64) -> Option<(usize, usize)> {
    let g = DVec2::from(g);
    let mut best: Option<(f64, usize, usize)> = None;
    for (i, r) in doc.rivers.iter().enumerate().rev() {
        for (k, p) in r.points.iter().enumerate() {
            let d = DVec2::from(*p).distance(g);
            if d <= tol && best.is_none_or(|b| d < b.0) {
                best = Some((d, i, k));
            }
        }
    }
    best.map(|(_, i, k)| (i, k))
}

/// The river whose course passes within its width and `tol` metres of `g`, the last drawn first.
pub fn river_at(doc: &Document, g: Point, tol: f64) -> Option<usize> {
    let g = DVec2::from(g);
    (0..doc.rivers.len()).rev().find(|&i| {
        let r = &doc.rivers[i];
        let ctrl: Vec<DVec2> = r.points.iter().map(|p| DVec2::from(*p)).collect();
        course::sample(&ctrl, (r.width * 0.5).max(1e-3))
            .iter()
            .any(|s| s.p.distance(g) <= r.width + tol)
    })
}

/// The river with its width and depth scaled.
pub fn tuned(river: &River, width: f64, depth: f64) -> River {
    River {
        width: river.width * width,
        depth: river.depth * depth,
        ..river.clone()
    }
}

/// The river with control point `k` moved by `by`.
pub fn moved(river: &River, k: usize, by: Point) -> River {
    let mut r = river.clone();
    if let Some(p) = r.points.get_mut(k) {
        *p = [p[0] + by[0], p[1] + by[1]];
    }
    r
}

/// The river with `years` more iterations, as many as it may still have (at most
/// [`MAX_ITERATIONS`] in all); `None` if it may have no more.
pub fn aged(river: &River, years: u32) -> Option<River> {
    (river.iterations < MAX_ITERATIONS).then(|| River {
        iterations: river.iterations.saturating_add(years).min(MAX_ITERATIONS),
        ..river.clone()
    })
}

/// The next iteration's erosion (red) and deposition (light blue) cells of `river` on `grid`, as
/// their centres in metres.
pub fn preview(river: &River, grid: &Grid) -> (Vec<Point>, Vec<Point>) {
    in_metres(&Cells::of(&Shape::process(river, grid, &Constants::default())), grid)
}

/// Grid cells as their centres in metres.
fn in_metres(cells: &Cells, grid: &Grid) -> (Vec<Point>, Vec<Point>) {
    let s = grid.cell_size;
    let centres = |c: &[[u32; 2]]| {
        c.iter()
            .map(|p| [(f64::from(p[0]) + 0.5) * s, (f64::from(p[1]) + 0.5) * s])
            .collect()
    };
    (centres(&cells.erosion), centres(&cells.deposition))
}

/// A river held with SW2.
#[derive(Debug, Clone, PartialEq)]
pub struct RiverGrab {
    /// Which river.
    pub index: usize,
    /// The control point held, if one was touched.
    pub control: Option<usize>,
    /// Where it was grabbed, display mm.
    pub at_mm: [f64; 2],
    /// How far the held point has been carried, ground metres.
    pub by: Point,
    /// Whether the point is being carried.
    pub moving: bool,
    /// SW3 held: where it was pressed (u, h mm) and the width and depth factors so far.
    pub tuning: Option<([f64; 2], f64, f64)>,
    /// With a control point held: the river as grabbed, processed once, so that the preview
    /// while the point moves redoes only the part of the course it reaches (`river::drag`). The
    /// river committed when the pen lets go is processed whole, as every edit's.
    pub drag: Option<std::sync::Arc<Drag>>,
}

impl RiverGrab {
    /// A grab of river `index` (control point `control`, if one), at `at_mm` on the display.
    pub fn new(doc: &Document, index: usize, control: Option<usize>, at_mm: [f64; 2]) -> RiverGrab {
        let drag = control
            .zip(doc.rivers.get(index))
            .map(|(k, r)| std::sync::Arc::new(Drag::new(r, k, &doc.grid, &Constants::default())));
        RiverGrab {
            index,
            control,
            at_mm,
            by: [0.0, 0.0],
            moving: false,
            tuning: None,
            drag,
        }
    }

    /// The held river's next erosion and deposition cells (metres) as the pen is making it: a
    /// carried point's from its drag, anything else from the whole river.
    pub fn preview(&self, doc: &Document) -> Option<(Vec<Point>, Vec<Point>)> {
        let river = self.river(doc)?;
        Some(match (&self.drag, self.moving, self.tuning) {
            (Some(drag), true, None) => in_metres(&drag.preview(&river), &doc.grid),
            (Some(drag), false, None) => in_metres(drag.base_cells(), &doc.grid),
            _ => preview(&river, &doc.grid),
        })
    }

    /// The river as the pen is making it: the point carried, the width and depth tuned.
    pub fn river(&self, doc: &Document) -> Option<River> {
        let r = doc.rivers.get(self.index)?;
        let r = match self.control {
            Some(k) if self.moving => moved(r, k, self.by),
            _ => r.clone(),
        };
        Some(match self.tuning {
            Some((_, w, d)) => tuned(&r, w, d),
            None => r,
        })
    }
}
