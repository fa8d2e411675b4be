//! The ridgeline tool (seed 002): 3D ridgelines drawn in the air, 2D ridgeline trees drawn on the
//! surface, their nodes grabbed and pulled, valleys grown.
//!
//! Gestures follow seed 000's, as the rock and river tools' do (docs/modeler.md, "The ridgeline
//! tool"). SW1 is the tip switch (the pen reports the tip on the surface while it is pressed), so
//! a line in the air cannot be drawn with SW1 held; it is started by a touch:
//!
//! - **Pick the tool**: tap the ridge button (the display's top right corner) with the tip; tap it
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
use penmodel_terrain::document::{Document, Point, RidgeTree, Ridgeline, Ridges};
use penmodel_terrain::ridge::grow::{self, Growth};
use penmodel_terrain::ridge::layer;

use super::palette::Button;
use super::pick::line_distance;
use super::view::View;

/// The ridge button's side on the display, mm; it sits in the top right corner, 8 mm in.
pub const BUTTON_MM: f64 = 20.0;
/// Horizontal stroke travel between two nodes of a drawn ridgeline, mm.
pub const NODE_MM: f64 = 8.0;
/// A tree node pulled up sets θ within these limits, degrees (Alg. 2.4 needs (0°, 90°)).
const THETA_LIMITS: (f64, f64) = (0.5, 85.0);

/// The ridge button: in the display's top right corner, 8 mm in.
fn button(view: &View) -> Button {
    Button {
        corner_mm: [view.display_mm[0] - 8.0 - BUTTON_MM, 8.0],
        side_mm: BUTTON_MM,
    }
}

/// Whether display point `(u, v)` mm is on the ridge button.
pub fn on_palette(view: &View, u_mm: f64, v_mm: f64) -> bool {
    button(view).contains(u_mm, v_mm)
}

/// The ridge button's outline on the ground (closed), for drawing.
pub fn palette_outline(view: &View) -> Vec<Point> {
    button(view).outline(view)
}

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
pub fn with_line(doc: &Document, points: Vec<[f64; 3]>) -> Ridges {
    let mut r = doc.ridges.clone().unwrap_or_default();
    r.lines.push(Ridgeline { points });
    r
}

/// The ridges with a tree stroke added: a branch of the tree whose node or segment lies within
/// `tol` metres of the stroke's start (a segment is split there), else a new tree (θ 20°,
/// `h_end` 0). Returns the tree's index too.
pub fn with_tree_stroke(doc: &Document, stroke: &[Point], tol: f64) -> (Ridges, usize) {
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
pub fn with_node(ridges: &Ridges, (part, k): (Part, usize), by: Point, height: Option<f64>) -> Ridges {
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
pub fn grown(doc: &Document, from: Part, seed: u64) -> Result<(Ridges, usize), String> {
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
    pub fn ridges(&self, base: &Ridges) -> Ridges {
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
