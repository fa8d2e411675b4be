//! Seed 000's own tool: feature figures drawn inside generation regions, grabbed, pulled up,
//! sloped, moved and deleted (section 3.2; docs/modeler.md, "Figures").
//!
//! - **Draw**: SW1 on the surface draws; SW3 ends the stroke, a point, a polyline, or a closed
//!   curve when the end came back to the start ([`super::stroke`]); a closed curve outside every
//!   region becomes a generation region.
//! - **Highlight**: a point when the pen is near it, a polyline near its line, a closed curve
//!   inside it, a region near its boundary ([`super::pick`]).
//! - **Grab**: SW2 + touch grabs the highlighted figure (at a vertex, that vertex).
//! - **Pull**: grabbed, lift: the height follows the pen's (× the vertical scale), the terrain
//!   live, the ground tilting towards the viewer; releasing SW2 commits it.
//! - **Slope**: grabbed, SW3 held and the pen moved sideways: left sharper, right bell-shaped,
//!   with a slope bar.
//! - **Move**: grabbed, slide on the surface: the figure or the grabbed vertex follows; dropped
//!   outside its region, it is deleted.

use pen_host::events::DisplayPoint;
use penmodel_render::{Overlay, Rgba, SlopeBar};
use penmodel_terrain::address::{CurvePath, FigurePath};
use penmodel_terrain::document::{Document, Figure, FigureKind, Point, Region};
use penmodel_terrain::edit::Edit;
use penmodel_terrain::geometry::{Side, locate};

use super::pick::{self, Hit};
use super::stroke::{self, Tolerances};
use super::tool::{Context, DELETING_COLOUR, Layers, MOVING_COLOUR, Phase, Release, Seen, Tool};

/// Colour of region boundaries.
pub const REGION_COLOUR: Rgba = [245, 245, 245, 255];
/// Colour of control figures.
pub const FIGURE_COLOUR: Rgba = [220, 40, 40, 255];

/// What the grabbed figure is doing.
#[derive(Debug, Clone, PartialEq)]
enum Action {
    /// Grabbed; neither lifted nor slid yet.
    Pending,
    /// Following the pen's height.
    Pull,
    /// Following the pen's sideways motion.
    Slope { u0: f64, s0: f64 },
    /// Following the pen along the surface, by `by` metres; `outside` when the tip is outside the
    /// figure's region (dropping it there deletes it).
    Move { by: Point, outside: bool },
}

#[derive(Debug, Clone, PartialEq)]
struct Grab {
    hit: Hit,
    /// Where the tip touched, display mm.
    at_mm: [f64; 2],
    action: Action,
    /// Whether it has been pulled (a slope returns to the pull).
    pulled: bool,
}

/// A figure being moved, as it would be dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct Moving {
    /// What is moved.
    pub curve: CurvePath,
    /// Its points where the pen has taken them.
    pub points: Vec<Point>,
    /// Whether dropping it here deletes it.
    pub deleting: bool,
}

/// The figures tool: the highlighted figure and the grab.
#[derive(Debug, Clone, Default)]
pub struct Figures {
    hover: Option<Hit>,
    grab: Option<Grab>,
}

fn plus(a: Point, b: Point) -> Point {
    [a[0] + b[0], a[1] + b[1]]
}

/// The points of a curve in the document.
fn curve_points<'a>(doc: &'a Document, curve: &CurvePath) -> Option<(&'a [Point], bool)> {
    match curve {
        CurvePath::Boundary(r) => doc.regions.get(*r).map(|g| (g.boundary.as_slice(), true)),
        CurvePath::Figure(at) => at.get(doc).map(|f| (f.points.as_slice(), f.kind == FigureKind::Closed)),
    }
}

/// Whether dropping this grab deletes what it holds: a whole figure or region (not one vertex of
/// it) moved with the tip outside its region.
fn deletes(grab: &Grab, doc: &Document) -> bool {
    let whole = match (&grab.hit.curve, grab.hit.vertex) {
        (_, None) => true,
        (CurvePath::Figure(at), Some(_)) => at.get(doc).is_some_and(|f| f.kind == FigureKind::Point),
        (CurvePath::Boundary(_), Some(_)) => false,
    };
    whole && matches!(grab.action, Action::Move { outside: true, .. })
}

/// A figure's path for the status line: `regions[0].figures[3].figures[1]` is `0.3.1`.
fn short(at: &FigurePath) -> String {
    let mut s = at.region().to_string();
    for i in at.indices() {
        s.push('.');
        s.push_str(&i.to_string());
    }
    s
}

/// A figure or region named for the status line.
fn describe(doc: &Document, curve: &CurvePath) -> String {
    match curve {
        CurvePath::Boundary(r) => format!("region {r}"),
        CurvePath::Figure(at) => match at.get(doc) {
            Some(f) => format!("{} {}", f.kind.name(), short(at)),
            None => short(at),
        },
    }
}

/// The stroke tolerances of the view, in ground metres.
pub fn tolerances(cx: &Context) -> Tolerances {
    Tolerances {
        point: cx.metres(cx.tuning.point_mm),
        close: cx.metres(cx.tuning.close_mm),
        simplify: cx.metres(cx.tuning.simplify_mm),
    }
}

/// The document's region boundaries and figures as draped overlays, in document order, each with
/// the curve it draws: for each region its boundary, then its figures depth first (a closed
/// figure before the figures nested in it).
pub fn document_overlays(doc: &Document) -> Vec<(CurvePath, Overlay)> {
    fn figures(list: &[Figure], at: &dyn Fn(usize) -> FigurePath, out: &mut Vec<(CurvePath, Overlay)>) {
        for (i, f) in list.iter().enumerate() {
            let path = at(i);
            let closed = f.kind == FigureKind::Closed;
            out.push((
                CurvePath::Figure(path.clone()),
                Layers::line(f.points.clone(), closed, FIGURE_COLOUR, 3.0),
            ));
            figures(&f.figures, &|j| path.child(j), out);
        }
    }
    let mut out = Vec::new();
    for (r, region) in doc.regions.iter().enumerate() {
        out.push((
            CurvePath::Boundary(r),
            Layers::line(region.boundary.clone(), true, REGION_COLOUR, 2.0),
        ));
        figures(&region.figures, &|i| FigurePath::new(r, i), &mut out);
    }
    out
}

impl Figures {
    /// The highlighted figure or region, while nothing is grabbed or drawn.
    pub fn highlighted(&self, phase: Phase) -> Option<&Hit> {
        match phase {
            Phase::Idle | Phase::Armed => self.hover.as_ref(),
            _ => None,
        }
    }

    /// The grabbed figure or region.
    pub fn grabbed(&self) -> Option<&CurvePath> {
        self.grab.as_ref().map(|g| &g.hit.curve)
    }

    /// The grabbed figure, region or vertex where the pen is moving it.
    pub fn moving(&self, doc: &Document) -> Option<Moving> {
        let g = self.grab.as_ref()?;
        let Action::Move { by, outside } = g.action else {
            return None;
        };
        let (points, closed) = curve_points(doc, &g.hit.curve)?;
        let mut points = points.to_vec();
        match g.hit.vertex {
            Some(i) if points.len() > 1 => {
                points[i] = plus(points[i], by);
                if closed && i == 0 {
                    let last = points.len() - 1;
                    points[last] = points[0];
                }
            }
            _ => points.iter_mut().for_each(|p| *p = plus(*p, by)),
        }
        Some(Moving {
            curve: g.hit.curve.clone(),
            points,
            deleting: outside && deletes(g, doc),
        })
    }

    /// The grab follows the pen: its height, its slope, or its place, shown as a preview.
    fn follow(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) {
        let s = *cx.tuning;
        let Some(grab) = &self.grab else { return };
        let edit = match (&grab.hit.curve, &grab.action) {
            (_, Action::Move { .. }) => return self.track_move(cx, g),
            (CurvePath::Boundary(_), _) | (_, Action::Pending) => return,
            (CurvePath::Figure(at), Action::Pull) => Edit::SetHeight {
                at: at.clone(),
                height: cx.view.height_at(p.h_mm.max(0.0)),
            },
            (CurvePath::Figure(at), Action::Slope { u0, s0 }) => Edit::SetSlope {
                at: at.clone(),
                slope: (s0 + (p.u_mm - u0) * s.slope_per_mm).clamp(-s.slope_limit, s.slope_limit),
            },
        };
        if let Err(e) = cx.editor.preview(&edit) {
            cx.refuse(format!("cannot show the change: {e}"));
        }
    }

    fn track_move(&mut self, cx: &Context, g: Point) {
        let Some(grab) = &mut self.grab else { return };
        let start = cx.view.to_ground(grab.at_mm[0], grab.at_mm[1]);
        let doc = cx.editor.document();
        let outside = match &grab.hit.curve {
            CurvePath::Figure(at) => at.edge(doc).is_some_and(|edge| locate(edge, g) == Side::Outside),
            CurvePath::Boundary(_) => {
                !(0.0..=doc.grid.width()).contains(&g[0]) || !(0.0..=doc.grid.height()).contains(&g[1])
            }
        };
        grab.action = Action::Move {
            by: [g[0] - start[0], g[1] - start[1]],
            outside,
        };
    }

    /// Records the pull and slope shown as one edit.
    fn commit_preview(cx: &mut Context) {
        match cx.editor.commit_preview() {
            Ok(Some(edit)) => {
                let (height, slope) = match &edit {
                    Edit::SetHeight { .. } => (true, false),
                    Edit::SetSlope { .. } => (false, true),
                    _ => (true, true),
                };
                cx.stats.pulls += u32::from(height);
                cx.stats.slopes += u32::from(slope);
            }
            Ok(None) => {}
            Err(e) => cx.refuse(format!("the pull was not recorded: {e}")),
        }
    }

    /// Drops the moved figure, region or vertex where the pen has taken it (deletes it outside
    /// its region).
    fn drop_move(&mut self, cx: &mut Context) {
        let Some(grab) = &self.grab else { return };
        let Action::Move { by, .. } = grab.action else { return };
        let doc = cx.editor.document();
        let deletes = deletes(grab, doc);
        if by == [0.0, 0.0] && !deletes {
            return;
        }
        let vertex_to = |i: usize| {
            curve_points(doc, &grab.hit.curve)
                .and_then(|(pts, _)| pts.get(i))
                .map(|p| plus(*p, by))
        };
        let edit = match (&grab.hit.curve, grab.hit.vertex) {
            (CurvePath::Figure(at), _) if deletes => Edit::DeleteFigure { at: at.clone() },
            (CurvePath::Boundary(index), None) if deletes => Edit::DeleteRegion { index: *index },
            (CurvePath::Figure(at), Some(i)) if at.get(doc).is_some_and(|f| f.kind != FigureKind::Point) => {
                let Some(to) = vertex_to(i) else { return };
                Edit::MovePoint {
                    curve: grab.hit.curve.clone(),
                    index: i,
                    to,
                }
            }
            (CurvePath::Figure(at), _) => Edit::MoveFigure { at: at.clone(), by },
            (CurvePath::Boundary(_), Some(i)) => {
                let Some(to) = vertex_to(i) else { return };
                Edit::MovePoint {
                    curve: grab.hit.curve.clone(),
                    index: i,
                    to,
                }
            }
            (CurvePath::Boundary(index), None) => Edit::MoveRegion { index: *index, by },
        };
        let delete = matches!(edit, Edit::DeleteFigure { .. } | Edit::DeleteRegion { .. });
        if cx.commit(edit, if delete { "delete" } else { "move" }) {
            if delete {
                cx.stats.deletes += 1;
            } else {
                cx.stats.moves += 1;
            }
        }
        self.hover = None;
    }
}

impl Tool for Figures {
    fn name(&self) -> &'static str {
        "figures"
    }

    fn title(&self) -> String {
        "figures".into()
    }

    fn picked(&self) -> String {
        "figures: draw with the tip".into()
    }

    fn clear_hover(&mut self) {
        self.hover = None;
    }

    fn hover(&mut self, cx: &mut Context, g: Point) {
        self.hover = pick::pick(cx.editor.document(), g, cx.pick_m());
    }

    /// Classifies the stroke and adds it where it belongs: a figure in the region or closed
    /// figure around it, or a new region.
    fn stroke(&mut self, cx: &mut Context, positions: &[Point]) {
        let Some(shape) = stroke::classify(positions, &tolerances(cx)) else {
            return;
        };
        let doc = cx.editor.document();
        let edit = match pick::container(doc, &shape.points) {
            Some(at) => Edit::AddFigure {
                figure: Figure {
                    kind: shape.kind,
                    points: shape.points,
                    height: pick::base_height(doc, &at),
                    slope: 0.0,
                    figures: Vec::new(),
                },
                at,
            },
            None if shape.kind == FigureKind::Closed => Edit::AddRegion {
                index: doc.regions.len(),
                region: Region {
                    metric: None,
                    boundary: shape.points,
                    figures: Vec::new(),
                },
            },
            None => {
                cx.refuse(format!(
                    "the {} is outside every region: draw a closed curve around the place first",
                    shape.kind.name()
                ));
                return;
            }
        };
        let (name, region) = match &edit {
            Edit::AddFigure { at, figure } => (format!("{} {}", figure.kind.name(), short(at)), false),
            Edit::AddRegion { index, .. } => (format!("region {index}"), true),
            _ => (String::new(), false),
        };
        if cx.commit(edit, &format!("the new {name}")) {
            if region {
                cx.stats.regions += 1;
            } else {
                cx.stats.figures += 1;
            }
            cx.say(format!("added {name}"));
        }
    }

    fn grab(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) -> bool {
        let hit = self
            .hover
            .clone()
            .or_else(|| pick::pick(cx.editor.document(), g, cx.pick_m()));
        let Some(hit) = hit else {
            cx.say("nothing here to grab".into());
            return false;
        };
        self.grab = Some(Grab {
            hit,
            at_mm: [p.u_mm, p.v_mm],
            action: Action::Pending,
            pulled: false,
        });
        true
    }

    fn motion(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) {
        let s = *cx.tuning;
        let Some(grab) = &mut self.grab else { return };
        let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
        let is_figure = matches!(grab.hit.curve, CurvePath::Figure(_));
        if grab.action == Action::Pending {
            if is_figure && (!cx.sw[0] || p.h_mm > s.lift_mm) {
                grab.action = Action::Pull;
                grab.pulled = true;
            } else if cx.sw[0] && slid > s.move_mm {
                grab.action = Action::Move {
                    by: [0.0, 0.0],
                    outside: false,
                };
            }
        }
        self.follow(cx, g, p);
    }

    fn tip_up(&mut self, cx: &mut Context) -> Release {
        let Some(grab) = &mut self.grab else {
            return Release::Idle;
        };
        match grab.action {
            Action::Pending if matches!(grab.hit.curve, CurvePath::Figure(_)) => {
                grab.action = Action::Pull;
                grab.pulled = true;
            }
            Action::Pending => cx.say("a region's boundary is moved, not pulled: pull the figures inside it".into()),
            Action::Move { .. } => {
                self.drop_move(cx);
                self.grab = None;
                return Release::Armed;
            }
            _ => {}
        }
        Release::Keep
    }

    fn sw2_up(&mut self, cx: &mut Context) -> Release {
        match self.grab.as_ref().map(|g| &g.action) {
            Some(Action::Move { .. }) => self.drop_move(cx),
            _ => Figures::commit_preview(cx),
        }
        self.grab = None;
        Release::Idle
    }

    fn sw3_down(&mut self, cx: &mut Context) -> Release {
        let Some(grab) = &mut self.grab else {
            return Release::Keep;
        };
        let CurvePath::Figure(at) = &grab.hit.curve else {
            return Release::Keep;
        };
        if matches!(grab.action, Action::Pending | Action::Pull)
            && let Some(p) = cx.pen
        {
            let s0 = at.get(cx.editor.document()).map_or(0.0, |f| f.slope);
            grab.action = Action::Slope { u0: p.u_mm, s0 };
        }
        Release::Keep
    }

    fn sw3_up(&mut self, _cx: &mut Context) {
        if let Some(grab) = &mut self.grab
            && let Action::Slope { .. } = grab.action
        {
            grab.action = if grab.pulled { Action::Pull } else { Action::Pending };
        }
    }

    fn lost(&mut self, cx: &mut Context, reason: &str) -> Release {
        if let Err(e) = cx.editor.cancel_preview() {
            cx.say(format!("cannot restore the grabbed figure: {e}"));
        }
        cx.say(format!("pen lost ({reason}): the grab was cancelled"));
        self.grab = None;
        Release::Idle
    }

    fn delete(&mut self, cx: &mut Context) {
        let Some(hit) = self.highlighted(cx.phase).cloned() else {
            cx.say("nothing highlighted to delete".into());
            return;
        };
        let edit = match hit.curve {
            CurvePath::Figure(at) => Edit::DeleteFigure { at },
            CurvePath::Boundary(index) => Edit::DeleteRegion { index },
        };
        if cx.commit(edit, "delete") {
            cx.stats.deletes += 1;
            self.hover = None;
        }
    }

    fn pulling(&self) -> bool {
        self.grab
            .as_ref()
            .is_some_and(|g| matches!(g.action, Action::Pull | Action::Slope { .. }))
    }

    fn status(&self, seen: &Seen) -> Option<String> {
        let doc = seen.doc;
        Some(match (seen.phase, &self.grab) {
            (Phase::Held, Some(g)) => {
                let what = describe(doc, &g.hit.curve);
                let figure = match &g.hit.curve {
                    CurvePath::Figure(at) => at.get(doc),
                    CurvePath::Boundary(_) => None,
                };
                match (&g.action, figure) {
                    (Action::Pull, Some(f)) => format!("pull {what}: {:.0} m | release SW2 to set", f.height),
                    (Action::Slope { .. }, Some(f)) => {
                        format!("slope {what}: {:+.2} | left sharper, right rounder", f.slope)
                    }
                    (Action::Move { .. }, _) if deletes(g, doc) => format!("{what}: drop here to delete it"),
                    (Action::Move { .. }, _) => match g.hit.vertex {
                        Some(i) => format!("moving vertex {i} of {what}"),
                        None => format!("moving {what}"),
                    },
                    _ => format!("grabbed {what}: lift to pull, slide to move"),
                }
            }
            (Phase::Idle, _) => match &self.hover {
                Some(h) => format!("{}: SW2 + touch grabs it", describe(doc, &h.curve)),
                None => "draw with the tip | SW3 ends a figure | SW3 click: undo".to_string(),
            },
            (Phase::Armed, _) => match &self.hover {
                Some(h) => format!("{}: touch to grab | SW3: redo", describe(doc, &h.curve)),
                None => "SW2: touch a figure to grab it | SW3: redo".to_string(),
            },
            _ => return None,
        })
    }

    fn overlays(&self, seen: &Seen, _active: bool, layers: &mut Layers) {
        let doc = seen.doc;
        let at = document_overlays(doc);
        let highlighted = self.grabbed().or(self.highlighted(seen.phase).map(|h| &h.curve));
        let base = layers.overlays.len();
        let selected = highlighted.and_then(|c| at.iter().position(|(p, _)| p == c));
        layers.overlays.extend(at.into_iter().map(|(_, o)| o));
        match (selected, self.moving(doc)) {
            // The figure where the pen is taking it, in place of where it was, not highlighted.
            (Some(i), Some(m)) => {
                let o = &mut layers.overlays[base + i];
                o.points = m.points;
                o.colour = if m.deleting { DELETING_COLOUR } else { MOVING_COLOUR };
            }
            (Some(i), None) => layers.selection = Some(base + i),
            (None, _) => {}
        }
    }

    fn gauge(&self, seen: &Seen) -> Option<SlopeBar> {
        let g = self.grab.as_ref()?;
        let Action::Slope { .. } = g.action else { return None };
        let CurvePath::Figure(at) = &g.hit.curve else {
            return None;
        };
        let limit = seen.tuning.slope_limit;
        Some(SlopeBar {
            value: at.get(seen.doc)?.slope,
            min: -limit,
            max: limit,
            label: "slope".into(),
        })
    }

    fn help(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("SW1 on surface", "draw a figure; SW3 ends it"),
            ("closed, outside", "a new generation region"),
            ("SW2 + touch", "grab the highlighted figure"),
            ("grabbed, lift", "pull it up"),
            ("grabbed, SW3 sideways", "set its slope"),
            ("grabbed, slide", "move it (out of its region: delete)"),
        ]
    }
}
