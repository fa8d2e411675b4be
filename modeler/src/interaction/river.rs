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
use pen_host::events::DisplayPoint;
use penmodel_render::Rgba;
use penmodel_terrain::document::{Document, Grid, Point, River};
use penmodel_terrain::edit::Edit;
use penmodel_terrain::river::drag::{Cells, Drag};
use penmodel_terrain::river::{Constants, MAX_ITERATIONS, Shape, course};

use super::tool::{Context, Counter, Layers, MOVING_COLOUR, Phase, Release, Seen, Tool};
use super::view::View;

/// Colour of a river's control polygon and points.
pub const RIVER_COLOUR: Rgba = [90, 160, 255, 255];
/// Colour of the cells the next iteration erodes (the seed's red).
pub const EROSION_COLOUR: Rgba = [230, 40, 30, 255];
/// Colour of the cells the next iteration deposits (the seed's light blue).
pub const DEPOSITION_COLOUR: Rgba = [160, 215, 255, 255];
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

/// The river tool: the river under the pen, the one held and its next iteration's preview.
#[derive(Debug, Clone, Default)]
pub struct Rivers {
    hover: Option<usize>,
    grab: Option<RiverGrab>,
    /// The held river's next erosion and deposition cells (ground metres).
    preview: Option<(Vec<Point>, Vec<Point>)>,
}

impl Rivers {
    /// The river under the pen, or held.
    pub fn river(&self) -> Option<usize> {
        self.grab.as_ref().map(|g| g.index).or(self.hover)
    }

    /// The held river as the pen is making it: `(index, river)`.
    pub fn moving(&self, doc: &Document) -> Option<(usize, River)> {
        let g = self.grab.as_ref()?;
        Some((g.index, g.river(doc)?))
    }

    /// The held river's next erosion and deposition cells (ground metres), while it is edited.
    pub fn preview(&self) -> Option<&(Vec<Point>, Vec<Point>)> {
        self.grab.as_ref().and(self.preview.as_ref())
    }

    /// Sets the held river's point where the pen has taken it.
    fn drop_point(&mut self, cx: &mut Context) {
        let Some(grab) = &self.grab else { return };
        if !grab.moving || grab.by == [0.0, 0.0] {
            return;
        }
        let (index, k) = (grab.index, grab.control);
        let Some(river) = grab.river(cx.editor.document()) else {
            return;
        };
        if cx.commit(Edit::ReplaceRiver { index, river }, "moving the river's point") {
            cx.stats.moves += 1;
            cx.say(format!("river {index}: point {} moved", k.unwrap_or(0)));
        }
    }

    fn let_go(&mut self) {
        self.grab = None;
        self.preview = None;
    }
}

impl Tool for Rivers {
    fn name(&self) -> &'static str {
        "rivers"
    }

    fn title(&self) -> String {
        "river tool".into()
    }

    fn picked(&self) -> String {
        "river tool: draw a course from source to mouth, SW3 ends it".into()
    }

    fn counters(&self) -> &'static [Counter] {
        &[Counter {
            key: "rivers",
            noun: Some("river"),
        }]
    }

    fn clear_hover(&mut self) {
        self.hover = None;
    }

    fn hover(&mut self, cx: &mut Context, g: Point) {
        self.hover = river_at(cx.editor.document(), g, cx.pick_m());
    }

    /// The course drawn becomes a river: its Bézier fit.
    fn stroke(&mut self, cx: &mut Context, positions: &[Point]) {
        let Some(river) = new_river(positions, cx.view) else {
            cx.say("a river's course needs a longer stroke".into());
            return;
        };
        let index = cx.editor.document().rivers.len();
        let points = river.points.len();
        if cx.commit(Edit::AddRiver { index, river }, &format!("river {index}")) {
            cx.stats.count("rivers");
            cx.say(format!(
                "river {index}: {points} control points | SW3 click over it: one year"
            ));
        }
    }

    fn grab(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) -> bool {
        let doc = cx.editor.document();
        let tol = cx.pick_m();
        let held = match control_at(doc, g, tol) {
            Some((index, k)) => Some((index, Some(k))),
            None => river_at(doc, g, tol).map(|i| (i, None)),
        };
        let Some((index, control)) = held else {
            cx.say("no river here to grab".into());
            return false;
        };
        let grab = RiverGrab::new(doc, index, control, [p.u_mm, p.v_mm]);
        self.preview = grab.preview(doc);
        self.grab = Some(grab);
        true
    }

    fn motion(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) {
        let Some(grab) = &mut self.grab else { return };
        let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
        if let Some((start, _, _)) = grab.tuning {
            let width = ((p.u_mm - start[0]) * GAIN_PER_MM).exp();
            let depth = ((p.h_mm - start[1]) * GAIN_PER_MM).exp();
            grab.tuning = Some((start, width, depth));
        } else if cx.sw[0] && grab.control.is_some() && (grab.moving || slid > cx.tuning.move_mm) {
            grab.moving = true;
            let from = cx.view.to_ground(grab.at_mm[0], grab.at_mm[1]);
            grab.by = [g[0] - from[0], g[1] - from[1]];
        }
        self.preview = grab.preview(cx.editor.document());
    }

    fn tip_up(&mut self, cx: &mut Context) -> Release {
        if !self.grab.as_ref().is_some_and(|g| g.moving) {
            return Release::Keep;
        }
        self.drop_point(cx);
        self.let_go();
        Release::Armed
    }

    fn sw2_up(&mut self, cx: &mut Context) -> Release {
        self.drop_point(cx);
        self.let_go();
        Release::Idle
    }

    fn sw3_down(&mut self, cx: &mut Context) -> Release {
        if let Some(grab) = &mut self.grab
            && let Some(p) = cx.pen
            && !grab.moving
        {
            grab.tuning = Some(([p.u_mm, p.h_mm], 1.0, 1.0));
        }
        Release::Keep
    }

    /// Sets the width and depth the gesture chose, as one edit.
    fn sw3_up(&mut self, cx: &mut Context) {
        let Some(grab) = &mut self.grab else { return };
        let Some((_, width, depth)) = grab.tuning else {
            return;
        };
        let index = grab.index;
        let Some(river) = grab.river(cx.editor.document()) else {
            return;
        };
        grab.tuning = None;
        if cx.commit(Edit::ReplaceRiver { index, river }, "the river's width and depth") {
            cx.say(format!("river {index}: width ×{width:.2}, depth ×{depth:.2}"));
        }
    }

    fn lost(&mut self, cx: &mut Context, reason: &str) -> Release {
        cx.say(format!("pen lost ({reason}): the river stays as it was"));
        self.let_go();
        Release::Idle
    }

    /// SW3 released over a river: one more year, or as many as the press was held for.
    fn press(&mut self, cx: &mut Context, held_us: u64, _click: bool) -> bool {
        let Some(index) = self.hover else { return false };
        let more = years_held(held_us, cx.tuning.click_us);
        let Some(river) = cx.editor.document().rivers.get(index).and_then(|r| aged(r, more)) else {
            cx.say(format!("river {index} has had the most years a river may have"));
            return true;
        };
        let years = river.iterations;
        if cx.commit(Edit::ReplaceRiver { index, river }, "the river's years") {
            cx.say(format!(
                "river {index}: {} of erosion and deposition",
                self::years(years)
            ));
        }
        true
    }

    fn delete(&mut self, cx: &mut Context) {
        let Some(index) = self.river() else {
            cx.say("no river highlighted to delete".into());
            return;
        };
        if cx.commit(Edit::DeleteRiver { index }, "delete") {
            cx.stats.deletes += 1;
            self.hover = None;
        }
    }

    fn status(&self, seen: &Seen) -> Option<String> {
        Some(match (seen.phase, &self.grab) {
            (Phase::Held, Some(g)) => match (g.tuning, g.control) {
                (Some((_, w, d)), _) => format!(
                    "river {}: width ×{w:.2}, depth ×{d:.2} | sideways: width, up/down: depth",
                    g.index
                ),
                (None, Some(k)) if g.moving => format!("river {}: moving point {k} | lift to set", g.index),
                (None, _) => format!("river {}: slide a point to reshape | SW3 + move: width, depth", g.index),
            },
            (Phase::Idle, _) => match self.hover {
                Some(i) => format!("rivers: river {i}: SW3 click: one more year | SW2 + touch grabs it"),
                None => "rivers: draw a course from source to mouth | SW3 ends it | tap the river button for figures"
                    .to_string(),
            },
            (Phase::Armed, _) => {
                "rivers: SW2: touch a control point to move it, the course to hold it | SW3: redo".to_string()
            }
            // SW3 held still over a river counts the years a release commits.
            (Phase::Pressing { held_us, moved: false }, _) => {
                let index = self.hover?;
                let years = years_held(held_us, seen.tuning.click_us);
                let had = seen.doc.rivers.get(index).map_or(0, |r| r.iterations);
                let to = seen
                    .doc
                    .rivers
                    .get(index)
                    .and_then(|r| aged(r, years))
                    .map_or(had, |r| r.iterations);
                format!(
                    "river {index}: +{} ({to} in all) | hold to count on, release to commit, move to pan",
                    self::years(to - had)
                )
            }
            _ => return None,
        })
    }

    /// Each river's control polygon (the held one as the pen makes it; its points as dots while
    /// the tool is on), and the next iteration's erosion and deposition while one is held.
    fn overlays(&self, seen: &Seen, active: bool, layers: &mut Layers) {
        let doc = seen.doc;
        let moving = self.moving(doc);
        for (i, r) in doc.rivers.iter().enumerate() {
            let held = moving.as_ref().filter(|(m, _)| *m == i);
            let points = held.map_or_else(|| r.points.clone(), |(_, moved)| moved.points.clone());
            let colour = if held.is_some() { MOVING_COLOUR } else { RIVER_COLOUR };
            let line = Layers::line(points.clone(), false, colour, 1.0);
            if active && self.river() == Some(i) && held.is_none() {
                layers.push_selected(line);
            } else {
                layers.push(line);
            }
            if active {
                for p in &points {
                    layers.push(Layers::dot(*p, None, colour, 4.0));
                }
            }
        }
        if let Some((erosion, deposition)) = self.preview() {
            for p in erosion {
                layers.push(Layers::dot(*p, None, EROSION_COLOUR, 2.0));
            }
            for p in deposition {
                layers.push(Layers::dot(*p, None, DEPOSITION_COLOUR, 2.0));
            }
        }
    }

    fn help(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("SW1 course, SW3", "a river from source to mouth"),
            ("SW2 + touch a point", "slide it to reshape the course"),
            ("held, SW3 + move", "sideways: width; up, down: depth"),
            ("SW3 click over it", "one more year (hold: more)"),
            ("Del", "delete the highlighted river"),
        ]
    }
}

/// `n` years, in words: "1 year", "3 years".
fn years(n: u32) -> String {
    if n == 1 { "1 year".into() } else { format!("{n} years") }
}
