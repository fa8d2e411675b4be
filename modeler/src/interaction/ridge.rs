//! The ridgeline tool (seed 002): 3D ridgelines drawn in the air, 2D ridgeline trees drawn on the
//! surface, their nodes grabbed and pulled, valleys grown.
//!
//! Gestures follow seed 000's, as the rock and river tools' do (docs/modeler.md, "The ridgeline
//! tool"). SW1 is the tip switch (the pen reports the tip on the surface while it is pressed), so
//! a line in the air cannot be drawn with SW1 held; it is started by a touch:
//!
//! - **Pick the tool**: tap the ridge button (the display's lower right corner) with the tip; tap it
//!   again to go back to figures.
//! - **A 3D ridgeline**: touch (SW1) where it starts, lift and draw in the air: the pen's height
//!   is the ridge's elevation (the vertical scale of a pull); touching again snaps it to the
//!   surface there; SW3 ends it. The stroke is kept every [`NODE_MM`] of horizontal travel.
//! - **A 2D ridgeline tree**: draw on the surface and SW3 (after lifting, as for a figure); its
//!   elevations are computed (Alg. 2.4, `h_end + d·tan θ`). A stroke that starts on a tree (a
//!   node, or a segment, which is split there) is a branch of it.
//! - **Grab a node**: SW2 + touch on a node; sliding carries it, lifting pulls it: a ridgeline's
//!   node to the pen's height; a tree's end node sets the tree's `h_end`, an inner node its θ
//!   (the slope that puts that node at the pen's height). The terrain follows live; releasing
//!   SW2 (or lifting after a slide) records it as one undoable edit.
//! - **Flank slope**: holding a node, SW3 held and the pen moved sideways sets α for all
//!   ridgelines: left steeper, right gentler, [`SLOPE_DEG_PER_MM`] per mm, live.
//! - **Grow valleys**: an SW3 click over a ridgeline or tree grows one round of Alg. 2.5 from it,
//!   on the terrain of the whole network (elsewhere the click undoes, as everywhere).
//! - **Delete**: the Delete key removes the highlighted ridgeline or tree.

use glam::DVec2;
use pen_host::events::DisplayPoint;
use penmodel_render::Rgba;
use penmodel_terrain::document::{Document, Point, RidgeTree, Ridgeline, Ridges as RidgeSet};
use penmodel_terrain::edit::Edit;
use penmodel_terrain::ridge::grow::{self, Growth};
use penmodel_terrain::ridge::layer;

use super::pick::line_distance;
use super::tool::{Context, Counter, DRAWING_COLOUR, Layers, Phase, Release, Seen, Tool};
use super::view::View;

/// Horizontal stroke travel between two nodes of a drawn ridgeline, mm.
pub const NODE_MM: f64 = 8.0;
/// A tree node pulled up sets θ within these limits, degrees (Alg. 2.4 needs (0°, 90°)).
const THETA_LIMITS: (f64, f64) = (0.5, 85.0);
/// Colour of ridgelines and ridgeline trees.
pub const RIDGE_COLOUR: Rgba = [150, 110, 60, 255];

/// One pen position of a ridge stroke: ground metres and the pen's height, mm (0 on the surface).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Ground point, metres.
    pub at: Point,
    /// The pen's height, mm; 0 while the tip touches.
    pub h_mm: f64,
}

/// What a ridge stroke becomes.
#[derive(Debug, Clone, PartialEq)]
pub enum Drawn {
    /// A 3D ridgeline, `[x, y, z]` metres.
    Line(Vec<[f64; 3]>),
    /// A 2D stroke for a tree, ground metres.
    Tree(Vec<Point>),
}

/// Whether the stroke went into the air: a position above `lift_mm` more than `away_mm`
/// (horizontally, on the display) from the last touched position. Lifting to end a stroke on
/// the surface rises in place, so it does not count.
pub fn in_air(samples: &[Sample], view: &View, lift_mm: f64, away_mm: f64) -> bool {
    let mut last_touch: Option<Point> = None;
    samples.iter().any(|s| {
        if s.h_mm <= 0.0 {
            last_touch = Some(s.at);
            return false;
        }
        s.h_mm > lift_mm
            && last_touch.is_some_and(|t| DVec2::from(t).distance(DVec2::from(s.at)) > view.metres(away_mm))
    })
}

/// What a finished stroke is: a 3D ridgeline (kept every [`NODE_MM`] of horizontal travel, air
/// positions at the pen's height, touched ones at `surface(x, y)`) if it went into the air, else
/// the touched positions for a tree. `None` for a stroke shorter than two nodes.
pub fn drawn(
    samples: &[Sample],
    view: &View,
    (lift_mm, away_mm): (f64, f64),
    surface: impl Fn(Point) -> f64,
) -> Option<Drawn> {
    let step = view.metres(NODE_MM);
    if in_air(samples, view, lift_mm, away_mm) {
        let z = |s: &Sample| {
            if s.h_mm <= 0.0 {
                surface(s.at)
            } else {
                view.height_at(s.h_mm)
            }
        };
        let mut line: Vec<[f64; 3]> = Vec::new();
        let mut last: Option<&Sample> = None;
        for s in samples {
            let far = last.is_none_or(|l| DVec2::from(l.at).distance(DVec2::from(s.at)) >= step);
            if far {
                line.push([s.at[0], s.at[1], z(s)]);
                last = Some(s);
            } else if s.h_mm <= 0.0
                && last.is_some_and(|l| l.h_mm > 0.0)
                && let Some(node) = line.last_mut()
            {
                // A touch near the last node snaps it to the surface there.
                *node = [s.at[0], s.at[1], z(s)];
                last = Some(s);
            }
        }
        // The end where SW3 was pressed, unless it is on the last node.
        if let (Some(end), Some(l)) = (samples.last(), last)
            && end != l
            && DVec2::from(end.at).distance(DVec2::from(l.at)) > 0.25 * step
        {
            line.push([end.at[0], end.at[1], z(end)]);
        }
        return (line.len() >= 2).then_some(Drawn::Line(line));
    }
    let touched: Vec<Point> = samples.iter().filter(|s| s.h_mm <= 0.0).map(|s| s.at).collect();
    let mut pts: Vec<Point> = Vec::new();
    for (i, p) in touched.iter().enumerate() {
        let far = pts
            .last()
            .is_none_or(|l| DVec2::from(*l).distance(DVec2::from(*p)) >= step);
        if far || (i + 1 == touched.len() && pts.len() == 1 && DVec2::from(pts[0]).distance(DVec2::from(*p)) > 0.0) {
            pts.push(*p);
        }
    }
    (pts.len() >= 2).then_some(Drawn::Tree(pts))
}

/// A ridgeline or tree of the document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// `ridges.lines[i]`.
    Line(usize),
    /// `ridges.trees[j]`.
    Tree(usize),
}

impl Part {
    /// The element's name in the document.
    pub fn name(self) -> String {
        match self {
            Part::Line(i) => format!("ridgeline {i}"),
            Part::Tree(j) => format!("ridgeline tree {j}"),
        }
    }
}

/// A tree's segments as 2-point polylines.
fn segments(t: &RidgeTree) -> impl Iterator<Item = (usize, [Point; 2])> + '_ {
    t.edges
        .iter()
        .enumerate()
        .filter_map(|(e, &[a, b])| Some((e, [*t.nodes.get(a as usize)?, *t.nodes.get(b as usize)?])))
}

/// The ridgeline or tree passing within `tol` metres of `g` (its ground projection), the last
/// drawn first, lines before trees.
pub fn part_at(doc: &Document, g: Point, tol: f64) -> Option<Part> {
    let r = doc.ridges.as_ref()?;
    let line = (0..r.lines.len()).rev().find(|&i| {
        let pts: Vec<Point> = r.lines[i].points.iter().map(|p| [p[0], p[1]]).collect();
        line_distance(&pts, g) <= tol
    });
    line.map(Part::Line).or_else(|| {
        (0..r.trees.len())
            .rev()
            .find(|&j| segments(&r.trees[j]).any(|(_, s)| line_distance(&s, g) <= tol))
            .map(Part::Tree)
    })
}

/// The node nearest `g` within `tol` metres: `(part, node)`.
pub fn node_at(doc: &Document, g: Point, tol: f64) -> Option<(Part, usize)> {
    let r = doc.ridges.as_ref()?;
    let g = DVec2::from(g);
    let lines = r.lines.iter().enumerate().flat_map(|(i, l)| {
        l.points
            .iter()
            .enumerate()
            .map(move |(k, p)| (Part::Line(i), k, DVec2::new(p[0], p[1])))
    });
    let trees = r.trees.iter().enumerate().flat_map(|(j, t)| {
        t.nodes
            .iter()
            .enumerate()
            .map(move |(k, p)| (Part::Tree(j), k, DVec2::from(*p)))
    });
    lines
        .chain(trees)
        .map(|(part, k, p)| (p.distance(g), part, k))
        .filter(|(d, _, _)| *d <= tol)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, part, k)| (part, k))
}

/// The ridges with a 3D ridgeline added.
pub fn with_line(doc: &Document, points: Vec<[f64; 3]>) -> RidgeSet {
    let mut r = doc.ridges.clone().unwrap_or_default();
    r.lines.push(Ridgeline { points });
    r
}

/// The ridges with a tree stroke added: a branch of the tree whose node or segment lies within
/// `tol` metres of the stroke's start (a segment is split there), else a new tree (θ 20°,
/// `h_end` 0). Returns the tree's index too.
pub fn with_tree_stroke(doc: &Document, stroke: &[Point], tol: f64) -> (RidgeSet, usize) {
    let mut r = doc.ridges.clone().unwrap_or_default();
    let start = stroke[0];
    let node = node_at(doc, start, tol).and_then(|(part, k)| match part {
        Part::Tree(j) => Some((j, k)),
        Part::Line(_) => None,
    });
    let split = || {
        let trees = &doc.ridges.as_ref()?.trees;
        (0..trees.len()).rev().find_map(|j| {
            segments(&trees[j])
                .find(|(_, s)| line_distance(s, start) <= tol)
                .map(|(e, _)| (j, e))
        })
    };
    let (j, from, rest) = if let Some((j, k)) = node {
        (j, k, &stroke[1..])
    } else if let Some((j, e)) = split() {
        let t = &mut r.trees[j];
        let [a, b] = t.edges[e];
        let n = t.nodes.len() as u32;
        t.nodes.push(start);
        t.edges[e] = [a, n];
        t.edges.push([n, b]);
        (j, n as usize, &stroke[1..])
    } else {
        r.trees.push(RidgeTree {
            nodes: vec![start],
            edges: Vec::new(),
            theta: 20.0,
            h_end: 0.0,
        });
        (r.trees.len() - 1, 0, &stroke[1..])
    };
    let t = &mut r.trees[j];
    let mut prev = from as u32;
    for p in rest {
        let n = t.nodes.len() as u32;
        t.nodes.push(*p);
        t.edges.push([prev, n]);
        prev = n;
    }
    (r, j)
}

/// The ridges with a node carried by `by` (ground metres) and, if `height` is given, pulled to
/// that elevation: a ridgeline node's z; a tree's end node sets `h_end`, an inner node θ.
pub fn with_node(ridges: &RidgeSet, (part, k): (Part, usize), by: Point, height: Option<f64>) -> RidgeSet {
    let mut r = ridges.clone();
    match part {
        Part::Line(i) => {
            if let Some(p) = r.lines.get_mut(i).and_then(|l| l.points.get_mut(k)) {
                *p = [p[0] + by[0], p[1] + by[1], height.unwrap_or(p[2])];
            }
        }
        Part::Tree(j) => {
            let Some(t) = r.trees.get_mut(j) else { return r };
            if let Some(p) = t.nodes.get_mut(k) {
                *p = [p[0] + by[0], p[1] + by[1]];
            }
            if let Some(h) = height {
                let d = layer::tree_of(t).distances().get(k).copied().unwrap_or(0.0);
                if d <= 0.0 {
                    t.h_end = h;
                } else {
                    let (lo, hi) = THETA_LIMITS;
                    t.theta = ((h - t.h_end) / d).atan().to_degrees().clamp(lo, hi);
                }
            }
        }
    }
    r
}

/// The ridges with one round of Alg. 2.5 grown from `from` (`seed`) on the DTM of all their
/// lines and trees, the grown lines added and the slope the next round's; `Err` names why it
/// cannot grow.
pub fn grown(doc: &Document, from: Part, seed: u64) -> Result<(RidgeSet, usize), String> {
    let r = doc.ridges.as_ref().ok_or("no ridgelines to grow from")?;
    let grid = doc.grid;
    let base: Vec<_> = layer::skeletons(r)
        .map_err(|e| e.to_string())?
        .into_iter()
        .map(|(_, s)| s)
        .collect();
    let k = match from {
        Part::Line(i) => i,
        Part::Tree(j) => r.lines.len() + j,
    };
    let first = base.get(k).cloned().ok_or("no such ridgeline")?;
    let g = Growth::new(1, seed, grid.cell_size);
    let out = grow::grow_from(
        &base,
        &[first],
        (grid.cols, grid.rows, grid.cell_size),
        layer::filter_of(r),
        r.slope.to_radians(),
        g,
    )
    .map_err(|e| e.to_string())?;
    let mut r = r.clone();
    let n = out.lines.len();
    r.lines.extend(out.lines.into_iter().map(|points| Ridgeline { points }));
    r.slope = out.slope.to_degrees();
    Ok((r, n))
}

/// A node held with SW2.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeGrab {
    /// Which node.
    pub node: (Part, usize),
    /// Where the tip touched, display mm.
    pub at_mm: [f64; 2],
    /// Ground displacement so far.
    pub by: Point,
    /// Whether it is being carried along the surface.
    pub moving: bool,
    /// The elevation it is pulled to, while lifted.
    pub height: Option<f64>,
    /// SW3 held: the pen's `u` (mm) when it went down and the flank slope α then, degrees.
    pub slope_from: Option<(f64, f64)>,
    /// The flank slope α the SW3 gesture set, degrees.
    pub slope: Option<f64>,
}

impl NodeGrab {
    /// The ridges as the pen is making them from `base`: the node carried or pulled, α set.
    pub fn ridges(&self, base: &RidgeSet) -> RidgeSet {
        let mut r = with_node(base, self.node, self.by, self.height);
        if let Some(a) = self.slope {
            r.slope = a;
        }
        r
    }
}

/// α's change per mm of sideways pen travel with SW3 held, degrees (right gentler, left steeper:
/// the figures' slope gesture, left sharper).
pub const SLOPE_DEG_PER_MM: f64 = 0.25;
/// The range the SW3 gesture keeps α in, degrees.
pub const SLOPE_LIMITS: (f64, f64) = (5.0, 80.0);

/// What the ridge tool holds: its own stroke (drawn in the air or on the surface), or a node.
#[derive(Debug, Clone)]
enum Held {
    /// The pen's positions since the first touch.
    Stroke(Vec<Sample>),
    /// A node held with SW2, with the ridges from before the grab.
    Node(NodeGrab, Box<RidgeSet>),
}

/// The ridgeline tool: the ridgeline or tree under the pen, and what it holds.
#[derive(Debug, Clone, Default)]
pub struct Ridges {
    hover: Option<Part>,
    held: Option<Held>,
}

impl Ridges {
    /// The ridgeline or tree under the pen, or whose node is held.
    pub fn part(&self) -> Option<Part> {
        match &self.held {
            Some(Held::Node(g, _)) => Some(g.node.0),
            _ => self.hover,
        }
    }

    /// The ridge stroke being drawn: ground points and the pen's height, mm.
    pub fn drawing(&self) -> Option<&[Sample]> {
        match &self.held {
            Some(Held::Stroke(samples)) => Some(samples),
            _ => None,
        }
    }

    /// Ends the ridge stroke: a 3D ridgeline if it went into the air, else a tree or a branch.
    fn finish(&mut self, cx: &mut Context, samples: &[Sample]) {
        let map = cx.editor.heightmap();
        let surface = |g: Point| {
            let cell = map.cell_size();
            let c = ((g[0] / cell).floor().max(0.0) as u32).min(map.cols() - 1);
            let r = ((g[1] / cell).floor().max(0.0) as u32).min(map.rows() - 1);
            f64::from(map.get(c, r))
        };
        let tol = (cx.tuning.lift_mm, cx.tuning.close_mm);
        let doc = cx.editor.document();
        let (ridges, what) = match drawn(samples, cx.view, tol, surface) {
            None => {
                cx.say("a ridgeline needs a longer stroke".into());
                return;
            }
            Some(Drawn::Line(points)) => {
                let n = points.len();
                let top = points.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
                let r = with_line(doc, points);
                let i = r.lines.len() - 1;
                (r, format!("ridgeline {i}: {n} nodes, up to {top:.0} m"))
            }
            Some(Drawn::Tree(points)) => {
                let before = doc.ridges.as_ref().map_or(0, |r| r.trees.len());
                let (r, j) = with_tree_stroke(doc, &points, cx.pick_m());
                let how = if j < before { "a branch of" } else { "new" };
                (r, format!("{how} ridgeline tree {j}: elevations computed"))
            }
        };
        if cx.commit(Edit::SetRidges { ridges: Some(ridges) }, "the ridgeline") {
            cx.stats.count("ridgelines");
            cx.say(what);
        }
    }

    /// The held node follows the pen: carried along the surface, or pulled to the pen's height.
    fn follow(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) {
        let s = *cx.tuning;
        let touching = cx.sw[0];
        let Some(Held::Node(grab, base)) = &mut self.held else {
            return;
        };
        let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
        if let Some((u0, a0)) = grab.slope_from {
            let (lo, hi) = SLOPE_LIMITS;
            grab.slope = Some((a0 - (p.u_mm - u0) * SLOPE_DEG_PER_MM).clamp(lo, hi));
        } else if touching && grab.height.is_none() && grab.slope.is_none() && (grab.moving || slid > s.move_mm) {
            grab.moving = true;
            let from = cx.view.to_ground(grab.at_mm[0], grab.at_mm[1]);
            grab.by = [g[0] - from[0], g[1] - from[1]];
        } else if !touching && !grab.moving && p.h_mm > s.lift_mm {
            grab.height = Some(cx.view.height_at(p.h_mm));
        } else {
            return;
        }
        if let Err(e) = cx.editor.preview_ridges(Some(grab.ridges(base))) {
            cx.refuse(format!("cannot show the change: {e}"));
        }
    }

    /// Records the held node's move, pull or slope.
    fn commit_node(&mut self, cx: &mut Context) {
        let Some(Held::Node(grab, _)) = &self.held else { return };
        let (moved, pulled, sloped) = (grab.moving, grab.height.is_some(), grab.slope.is_some());
        match cx.editor.commit_ridges_preview() {
            Ok(Some(_)) => {
                cx.stats.moves += u32::from(moved);
                cx.stats.pulls += u32::from(pulled);
                cx.stats.slopes += u32::from(sloped);
            }
            Ok(None) => {}
            Err(e) => cx.refuse(format!("the ridgeline change was not recorded: {e}")),
        }
        self.held = None;
    }

    /// One round of valleys (Alg. 2.5) grown from the clicked ridgeline or tree.
    fn grow(cx: &mut Context, part: Part) {
        let doc = cx.editor.document();
        let seed = doc
            .ridges
            .as_ref()
            .map_or(0, |r| (r.lines.len() + r.trees.len()) as u64);
        match grown(doc, part, seed) {
            Ok((ridges, n)) => {
                let slope = ridges.slope;
                if cx.commit(Edit::SetRidges { ridges: Some(ridges) }, "the grown valleys") {
                    cx.stats.count("valley_rounds");
                    cx.say(format!(
                        "grew {n} valley lines from {}; slope now {slope:.0}°",
                        part.name()
                    ));
                }
            }
            Err(e) => cx.refuse(format!("cannot grow valleys: {e}")),
        }
    }
}

impl Tool for Ridges {
    fn name(&self) -> &'static str {
        "ridges"
    }

    fn title(&self) -> String {
        "ridge tool".into()
    }

    fn picked(&self) -> String {
        "ridge tool: touch, lift and draw a ridgeline in the air, or draw a tree on the surface; SW3 ends it".into()
    }

    fn counters(&self) -> &'static [Counter] {
        &[
            Counter {
                key: "ridgelines",
                noun: Some("ridgeline"),
            },
            Counter {
                key: "valley_rounds",
                noun: None,
            },
        ]
    }

    fn clear_hover(&mut self) {
        self.hover = None;
    }

    fn hover(&mut self, cx: &mut Context, g: Point) {
        self.hover = part_at(cx.editor.document(), g, cx.pick_m());
    }

    /// A touch starts the tool's own stroke: it goes on in the air, which the hub's does not.
    fn touch(&mut self, _cx: &mut Context, g: Point, _p: DisplayPoint) -> bool {
        self.held = Some(Held::Stroke(vec![Sample { at: g, h_mm: 0.0 }]));
        true
    }

    fn grab(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) -> bool {
        let doc = cx.editor.document();
        let Some(node) = node_at(doc, g, cx.pick_m()) else {
            cx.say("no ridgeline node here to grab".into());
            return false;
        };
        let base = Box::new(doc.ridges.clone().unwrap_or_default());
        let grab = NodeGrab {
            node,
            at_mm: [p.u_mm, p.v_mm],
            by: [0.0, 0.0],
            moving: false,
            height: None,
            slope_from: None,
            slope: None,
        };
        self.held = Some(Held::Node(grab, base));
        true
    }

    fn motion(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) {
        match &mut self.held {
            Some(Held::Stroke(samples)) => {
                let h_mm = if cx.sw[0] { 0.0 } else { p.h_mm.max(0.0) };
                samples.push(Sample { at: g, h_mm });
            }
            Some(Held::Node(..)) => self.follow(cx, g, p),
            None => {}
        }
    }

    fn tip_down(&mut self, _cx: &mut Context, g: Point, _p: DisplayPoint) {
        if let Some(Held::Stroke(samples)) = &mut self.held {
            samples.push(Sample { at: g, h_mm: 0.0 });
        }
    }

    fn tip_up(&mut self, cx: &mut Context) -> Release {
        match &self.held {
            Some(Held::Node(grab, _)) if grab.moving => {
                self.commit_node(cx);
                Release::Armed
            }
            _ => Release::Keep,
        }
    }

    fn sw2_up(&mut self, cx: &mut Context) -> Release {
        match &self.held {
            Some(Held::Node(..)) => {
                self.commit_node(cx);
                Release::Idle
            }
            // SW2 plays no part in a stroke.
            _ => Release::Keep,
        }
    }

    fn sw3_down(&mut self, cx: &mut Context) -> Release {
        match &mut self.held {
            Some(Held::Stroke(samples)) => {
                let samples = std::mem::take(samples);
                self.held = None;
                self.finish(cx, &samples);
                Release::Idle
            }
            Some(Held::Node(grab, base)) => {
                if let Some(p) = cx.pen {
                    grab.slope_from = Some((p.u_mm, grab.slope.unwrap_or(base.slope)));
                }
                Release::Keep
            }
            None => Release::Idle,
        }
    }

    fn sw3_up(&mut self, _cx: &mut Context) {
        if let Some(Held::Node(grab, _)) = &mut self.held {
            grab.slope_from = None;
        }
    }

    fn lost(&mut self, cx: &mut Context, reason: &str) -> Release {
        if let Some(Held::Stroke(_)) = self.held {
            cx.say(format!("pen lost ({reason}): the ridge stroke is kept; SW3 ends it"));
            return Release::Keep;
        }
        if let Err(e) = cx.editor.cancel_preview() {
            cx.say(format!("cannot restore the ridgeline: {e}"));
        }
        cx.say(format!("pen lost ({reason}): the node stays where it was"));
        self.held = None;
        Release::Idle
    }

    /// An SW3 click over a ridgeline or tree grows one round of valleys from it.
    fn press(&mut self, cx: &mut Context, _held_us: u64, click: bool) -> bool {
        match self.hover {
            Some(part) if click => {
                Ridges::grow(cx, part);
                true
            }
            _ => false,
        }
    }

    fn delete(&mut self, cx: &mut Context) {
        let Some(part) = self.part() else {
            cx.say("no ridgeline highlighted to delete".into());
            return;
        };
        let Some(mut r) = cx.editor.document().ridges.clone() else {
            return;
        };
        match part {
            Part::Line(i) if i < r.lines.len() => {
                r.lines.remove(i);
            }
            Part::Tree(j) if j < r.trees.len() => {
                r.trees.remove(j);
            }
            _ => return,
        }
        if cx.commit(Edit::SetRidges { ridges: Some(r) }, "delete") {
            cx.stats.deletes += 1;
            self.hover = None;
            cx.say(format!("{} deleted", part.name()));
        }
    }

    fn status(&self, seen: &Seen) -> Option<String> {
        Some(match (seen.phase, &self.held) {
            (Phase::Held, Some(Held::Stroke(samples))) => match samples.last() {
                Some(s) if s.h_mm > 0.0 => format!(
                    "ridgeline: {:.0} m high | touch: on the surface | SW3 ends it",
                    seen.view.height_at(s.h_mm)
                ),
                _ => "ridge stroke on the surface | lift to draw in the air | SW3 ends it".to_string(),
            },
            (Phase::Held, Some(Held::Node(g, _))) if g.slope_from.is_some() => format!(
                "flank slope {:.1}° | left steeper, right gentler | release SW2 to set",
                g.slope.unwrap_or(0.0)
            ),
            (Phase::Held, Some(Held::Node(g, _))) => {
                let (part, k) = (g.node.0.name(), g.node.1);
                match (g.height, g.moving) {
                    (Some(h), _) => format!("{part} node {k}: {h:.0} m | release SW2 to set"),
                    (None, true) => format!("moving {part} node {k} | lift to set"),
                    (None, false) => format!("{part} node {k}: slide to move, lift to pull"),
                }
            }
            (Phase::Idle, _) => match self.hover {
                Some(part) => format!(
                    "ridges: {}: SW3 click grows valleys | SW2 + touch a node grabs it",
                    part.name()
                ),
                None => {
                    "ridges: touch, lift and draw in the air (a ridgeline), or on the surface (a tree) | SW3 ends it"
                        .to_string()
                }
            },
            (Phase::Armed, _) => "ridges: SW2: touch a node to grab it | SW3: redo".to_string(),
            _ => return None,
        })
    }

    /// Ridgelines and trees (their nodes as dots while the tool is on), and the stroke being
    /// drawn, its air part at the pen's height.
    fn overlays(&self, seen: &Seen, active: bool, layers: &mut Layers) {
        let lines = seen.doc.ridges.iter().flat_map(|r| {
            let lines = r.lines.iter().enumerate().map(|(i, l)| {
                let pts: Vec<Point> = l.points.iter().map(|p| [p[0], p[1]]).collect();
                (Part::Line(i), pts)
            });
            let trees = r
                .trees
                .iter()
                .enumerate()
                .flat_map(|(j, t)| segments(t).map(move |(_, s)| (Part::Tree(j), s.to_vec())));
            lines.chain(trees)
        });
        for (part, pts) in lines {
            if active {
                for p in &pts {
                    layers.push(Layers::dot(*p, None, RIDGE_COLOUR, 4.0));
                }
            }
            let line = Layers::line(pts, false, RIDGE_COLOUR, if active { 2.0 } else { 1.0 });
            // The highlight: a ridgeline's line, a tree's first segment (one overlay is lit).
            if active && self.part() == Some(part) && layers.selection.is_none() {
                layers.push_selected(line);
            } else {
                layers.push(line);
            }
        }
        for s in self.drawing().unwrap_or_default() {
            let h = (s.h_mm > 0.0).then(|| seen.view.height_at(s.h_mm));
            layers.push(Layers::dot(s.at, h, DRAWING_COLOUR, 3.0));
        }
    }

    fn help(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("touch, lift, draw, SW3", "a ridgeline in the air"),
            ("SW1 on surface, SW3", "a ridgeline tree (or a branch)"),
            ("SW2 + touch a node", "slide to move it, lift to pull it"),
            ("node held, SW3 sideways", "flank slope: left steeper"),
            ("SW3 click over one", "grow a round of valleys"),
            ("Del", "delete the highlighted ridgeline"),
        ]
    }
}
