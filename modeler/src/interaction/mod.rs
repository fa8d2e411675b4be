//! The seed's pen interaction (000, section 3.2) as a state machine over calibrated pen events.
//!
//! | gesture | what it does |
//! |---|---|
//! | SW1 on the surface (SW2 up) | draws: starts a figure, or adds to the one being drawn |
//! | SW3 while drawing | ends the figure: a point, a polyline, or a closed curve when the end came back to the start; a closed curve outside every region becomes a generation region |
//! | pen near a figure | highlights it: a point when near it, a polyline near its line, a closed curve inside it, a region near its boundary |
//! | SW2 + touch | grabs the highlighted figure (at a vertex, that vertex) |
//! | grabbed, lift | pulls it up: height = pen height × the vertical scale, the terrain following live; the ground tilts towards the viewer |
//! | grabbed, SW3 held, move left/right | sets the slope: left sharper, right bell-shaped; a slope bar shows it |
//! | release SW2 | commits the pull and slope as one undoable edit |
//! | grabbed, slide on the surface | moves the figure, or the grabbed vertex; dropped outside its region, deletes it |
//! | SW3 click (nothing drawn or grabbed) | undo |
//! | SW2 held + SW3 click (not touching) | redo |
//! | SW3 held, move (nothing drawn or grabbed) | pans the ground with the pen; up and down zooms |
//! | SW1 tap on the palette button (display corner) | picks the rock tool, or back to figures ([`rocks`]) |
//! | rock tool: SW1 outline, SW3 | a closed outline becomes a rock field, its rocks on the terrain |
//! | rock tool: SW2 + touch in a field, slide | moves the field (the same rocks) |
//! | rock tool: field held, SW3 held, move | sideways: density; up and down: rock size; release SW3 sets both |
//! | ridge tool ([`ridge`]): touch, lift and draw in the air, SW3 | a 3D ridgeline at the pen's height |
//! | ridge tool: draw on the surface, SW3 | a 2D ridgeline tree (or a branch of the tree it starts on) |
//! | ridge tool: SW2 + touch a node, slide or lift | carries or pulls the node, the terrain following; release SW2 sets it |
//! | ridge tool: node held, SW3 held, move left/right | the flank slope α: left steeper, right gentler |
//! | ridge tool: SW3 click over a ridgeline | grows one round of valleys (Alg. 2.5) |
//! | tree button ([`trees`]): SW1 taps | the tree tool with the first preset, the next preset, back to figures |
//! | tree tool: SW1 tap | plants one tree of the current preset |
//! | tree tool: SW1 outline back to its start, lift | plants a grove inside it |
//! | tree tool: SW2 + touch a tree or grove, slide | moves it |
//! | tree tool: held, lift | pulls: the height follows the pen's; release SW2 sets it |
//! | tree tool: held, SW3 held, move left/right | a tree's height, a grove's density (right more) |
//!
//! [`KeyCommand`]s give the same edits to a keyboard or a script. Times come from the device clock
//! that reports carry (a click is timed the same at any replay speed); events that are not from
//! a report (device found or lost) do not move it.
//! A refused edit is a message and a count, never a lost document: the editor keeps it valid.

pub mod palette;
pub mod pick;
pub mod ridge;
pub mod river;
pub mod rocks;
pub mod stroke;
pub mod trees;
pub mod view;

use pen_host::events::{DisplayPoint, EventKind, PenEvent};

use penmodel_terrain::address::CurvePath;
use penmodel_terrain::document::{Document, Figure, FigureKind, Point, Region};
use penmodel_terrain::edit::Edit;
use penmodel_terrain::editor::Outcome;
use penmodel_terrain::editor::{Editor, EditorError};
use penmodel_terrain::geometry::{Side, locate};

pub use pick::Hit;
pub use stroke::{Shape, Tolerances};
pub use view::View;

/// How the gestures are recognised and how strongly they act: distances, times and gains that
/// tune the seed's operations to a pen's noise and a hand's reach; lengths are display mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tuning {
    /// How near the tip a point or line must be to be highlighted.
    pub pick_mm: f64,
    /// A stroke staying this close to its start is a point figure.
    pub point_mm: f64,
    /// A stroke ending this close to its start is a closed curve.
    pub close_mm: f64,
    /// The simplification tolerance of a drawn figure: above the pen's noise while it moves.
    pub simplify_mm: f64,
    /// Sliding this far on the surface after a grab makes it a move.
    pub move_mm: f64,
    /// Lifting this high after a grab makes it a pull.
    pub lift_mm: f64,
    /// Slope change per mm of sideways pen motion (right is positive: bell-shaped).
    pub slope_per_mm: f64,
    /// The slope bar's range, ±.
    pub slope_limit: f64,
    /// An SW3 press shorter than this, µs, and moving less than `click_mm`, is a click.
    pub click_us: u64,
    /// See `click_us`.
    pub click_mm: f64,
    /// Raising the pen this much while panning zooms out by a factor e.
    pub zoom_mm: f64,
    /// The ground's tilt towards the viewer while pulling, radians.
    pub pull_tilt: f64,
    /// Time constant of the tilt's easing, s.
    pub tilt_time_s: f64,
}

impl Default for Tuning {
    fn default() -> Tuning {
        Tuning {
            pick_mm: 6.0,
            point_mm: 3.0,
            close_mm: 10.0,
            simplify_mm: 2.0,
            move_mm: 3.0,
            lift_mm: 3.0,
            slope_per_mm: 0.04,
            slope_limit: 6.0,
            click_us: 600_000,
            click_mm: 4.0,
            zoom_mm: 150.0,
            pull_tilt: 20f64.to_radians(),
            tilt_time_s: 0.3,
        }
    }
}

/// An operation given without a pen gesture: a key in the live window, or a script's step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KeyCommand {
    /// Undo the last edit.
    Undo,
    /// Redo the last undone edit.
    Redo,
    /// Delete the highlighted figure or region.
    Delete,
    /// Move the view by display mm (the ground follows).
    Pan {
        /// Rightwards.
        du_mm: f64,
        /// Upwards.
        dv_mm: f64,
    },
    /// Magnify by `factor` about the display's centre.
    Zoom {
        /// > 1 magnifies.
        factor: f64,
    },
    /// Show the whole grid again.
    Fit,
}

/// What was done, for the session's summary.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Stats {
    /// Figures drawn and added.
    pub figures: u32,
    /// Generation regions drawn and added.
    pub regions: u32,
    /// Rock fields drawn and added.
    pub rock_fields: u32,
    /// Rivers drawn and added.
    pub rivers: u32,
    /// Ridgelines and ridgeline trees (or branches) drawn and added.
    pub ridgelines: u32,
    /// Rounds of valleys grown from the ridgelines.
    pub grown: u32,
    /// Single trees planted.
    pub trees: u32,
    /// Groves planted.
    pub groves: u32,
    /// Grabs committed with a height change.
    pub pulls: u32,
    /// Grabs committed with a slope change.
    pub slopes: u32,
    /// Figures, regions and vertices moved.
    pub moves: u32,
    /// Figures and regions deleted.
    pub deletes: u32,
    /// Undos that changed the document (not those with nothing to undo, or refused).
    pub undos: u32,
    /// Redos that changed the document (not those with nothing to redo, or refused).
    pub redos: u32,
    /// Edits the document refused (each with a message).
    pub refused: u32,
    /// Pen events the source reported lost.
    pub missed: u64,
}

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

#[derive(Debug, Clone, PartialEq)]
enum State {
    Idle,
    /// Positions of the figure being drawn (ground metres); `touching` while SW1 is down.
    Drawing {
        positions: Vec<Point>,
        touching: bool,
    },
    /// SW2 held, nothing grabbed.
    Armed,
    Grabbed(Grab),
    /// The tip on the palette button: the tool was switched; nothing more until it lifts.
    Palette,
    /// A rock field held with SW2.
    Field(rocks::FieldGrab),
    /// A river (or one of its control points) held with SW2.
    River(river::RiverGrab),
    /// A tree or grove held with SW2 (tree tool).
    Tree(trees::TreeGrab),
    /// A ridge stroke being drawn (ridge tool): the pen's positions since the first touch.
    RidgeStroke(Vec<ridge::Sample>),
    /// A ridgeline's or tree's node held with SW2, with the ridges from before the grab.
    Node(ridge::NodeGrab, Box<penmodel_terrain::document::Ridges>),
    /// SW3 held with nothing drawn or grabbed: a click (undo) or a pan.
    Sw3 {
        t0: u64,
        at_mm: [f64; 2],
        h0: f64,
        ground: Point,
        scale0: f64,
        moved: bool,
    },
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

/// The pen interaction: turns pen events into edits of an [`Editor`]'s document.
#[derive(Debug, Clone)]
pub struct Interaction {
    tuning: Tuning,
    view: View,
    home: View,
    state: State,
    hover: Option<Hit>,
    pen: Option<DisplayPoint>,
    sw: [bool; 3],
    last_t: Option<u64>,
    stats: Stats,
    messages: Vec<String>,
    last_message: Option<(u64, String)>,
    tool: rocks::Tool,
    /// The rock field under the pen, with the rock tool.
    field_hover: Option<usize>,
    /// The river under the pen, with the river tool.
    river_hover: Option<usize>,
    /// The held river's next erosion and deposition cells (ground metres), while it is edited.
    river_preview: Option<(Vec<Point>, Vec<Point>)>,
    /// The ridgeline or tree under the pen, with the ridge tool.
    ridge_hover: Option<ridge::Part>,
    /// The preset a tap plants, with the tree tool.
    tree_preset: penmodel_terrain::trees::Preset,
    /// The tree or grove under the pen, with the tree tool.
    tree_hover: Option<trees::Held>,
}

/// The event's time on the device's clock, µs; `None` for events not from a report (device
/// found or lost, missed), which carry only the host's clock.
fn event_time(ev: &PenEvent) -> Option<u64> {
    ev.seq.map(|(_, device_us)| device_us)
}

fn plus(a: Point, b: Point) -> Point {
    [a[0] + b[0], a[1] + b[1]]
}

fn minus(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

/// The points of a curve in the document.
fn curve_points<'a>(doc: &'a Document, curve: &CurvePath) -> Option<(&'a [Point], bool)> {
    match curve {
        CurvePath::Boundary(r) => doc.regions.get(*r).map(|g| (g.boundary.as_slice(), true)),
        CurvePath::Figure(at) => at.get(doc).map(|f| (f.points.as_slice(), f.kind == FigureKind::Closed)),
    }
}

impl Interaction {
    /// An interaction showing the ground through `view`.
    pub fn new(view: View, tuning: Tuning) -> Interaction {
        Interaction {
            tuning,
            view,
            home: view,
            state: State::Idle,
            hover: None,
            pen: None,
            sw: [false; 3],
            last_t: None,
            stats: Stats::default(),
            messages: Vec::new(),
            last_message: None,
            tool: rocks::Tool::Figures,
            field_hover: None,
            river_hover: None,
            river_preview: None,
            ridge_hover: None,
            tree_preset: penmodel_terrain::trees::Preset::Table31,
            tree_hover: None,
        }
    }

    /// The preset an SW1 tap plants with the tree tool.
    pub fn tree_preset(&self) -> penmodel_terrain::trees::Preset {
        self.tree_preset
    }

    /// The tree or grove under the pen (tree tool), or held.
    pub fn tree_hover(&self) -> Option<trees::Held> {
        match &self.state {
            State::Tree(g) => Some(g.held),
            _ => self.tree_hover,
        }
    }

    /// The held tree or grove and how far the pen has slid it, ground metres.
    pub fn tree_moving(&self) -> Option<(trees::Held, Point)> {
        match &self.state {
            State::Tree(g) if g.moving => Some((g.held, g.by)),
            _ => None,
        }
    }

    /// The ridgeline or tree under the pen (ridge tool), or whose node is held.
    pub fn ridge_hover(&self) -> Option<ridge::Part> {
        match &self.state {
            State::Node(g, _) => Some(g.node.0),
            _ => self.ridge_hover,
        }
    }

    /// The ridge stroke being drawn: ground points and the pen's height, mm.
    pub fn ridge_drawing(&self) -> Option<&[ridge::Sample]> {
        match &self.state {
            State::RidgeStroke(samples) => Some(samples),
            _ => None,
        }
    }

    /// The river under the pen (river tool), or held.
    pub fn river_hover(&self) -> Option<usize> {
        match &self.state {
            State::River(g) => Some(g.index),
            _ => self.river_hover,
        }
    }

    /// The held river as the pen is making it: `(index, river)`.
    pub fn river_moving(&self, doc: &Document) -> Option<(usize, penmodel_terrain::River)> {
        let State::River(g) = &self.state else { return None };
        Some((g.index, g.river(doc)?))
    }

    /// The held river's next erosion and deposition cells (ground metres), while it is edited.
    pub fn river_preview(&self) -> Option<&(Vec<Point>, Vec<Point>)> {
        match &self.state {
            State::River(_) => self.river_preview.as_ref(),
            _ => None,
        }
    }

    /// The tool SW1 draws with.
    pub fn tool(&self) -> rocks::Tool {
        self.tool
    }

    /// The rock field under the pen (rock tool), or held.
    pub fn field_hover(&self) -> Option<usize> {
        match &self.state {
            State::Field(g) => Some(g.index),
            _ => self.field_hover,
        }
    }

    /// The held rock field's outline where the pen is taking it (ground metres, closed).
    pub fn field_moving(&self, doc: &Document) -> Option<(usize, Vec<Point>)> {
        let State::Field(g) = &self.state else { return None };
        let f = doc.rocks.get(g.index)?;
        Some((g.index, f.outline_at().into_iter().map(|p| plus(p, g.by)).collect()))
    }

    /// The view: how the display shows the ground.
    pub fn view(&self) -> &View {
        &self.view
    }

    /// The thresholds and gains the gestures are recognised with.
    pub fn tuning(&self) -> &Tuning {
        &self.tuning
    }

    /// What has been done so far.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// The messages since the last call (refused edits, undos, the pen lost and found).
    pub fn take_messages(&mut self) -> Vec<String> {
        std::mem::take(&mut self.messages)
    }

    /// Where the pen is on the display, if in range.
    pub fn pen(&self) -> Option<&DisplayPoint> {
        self.pen.as_ref()
    }

    /// The highlighted figure or region, if nothing is grabbed.
    pub fn hover(&self) -> Option<&Hit> {
        match self.state {
            State::Idle | State::Armed => self.hover.as_ref(),
            _ => None,
        }
    }

    /// The grabbed figure or region.
    pub fn grabbed(&self) -> Option<&CurvePath> {
        match &self.state {
            State::Grabbed(g) => Some(&g.hit.curve),
            _ => None,
        }
    }

    /// The positions of the figure being drawn (ground metres).
    pub fn drawing(&self) -> Option<&[Point]> {
        match &self.state {
            State::Drawing { positions, .. } => Some(positions),
            _ => None,
        }
    }

    /// The grabbed figure, region or vertex where the pen is moving it.
    pub fn moving(&self, doc: &Document) -> Option<Moving> {
        let State::Grabbed(g) = &self.state else { return None };
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

    /// The slope bar while setting a slope: `(value, −limit, +limit)`.
    pub fn slope_bar(&self, doc: &Document) -> Option<(f64, f64, f64)> {
        let State::Grabbed(g) = &self.state else { return None };
        let Action::Slope { .. } = g.action else { return None };
        let CurvePath::Figure(at) = &g.hit.curve else {
            return None;
        };
        let s = at.get(doc)?.slope;
        Some((s, -self.tuning.slope_limit, self.tuning.slope_limit))
    }

    /// Whether a pull or slope is in progress (the ground tilts).
    pub fn pulling(&self) -> bool {
        matches!(
            &self.state,
            State::Grabbed(Grab {
                action: Action::Pull | Action::Slope { .. },
                ..
            })
        )
    }

    /// One line saying what the pen is doing and what it can do next.
    pub fn status(&self, doc: &Document) -> String {
        let line = match &self.state {
            State::Idle if self.tool == rocks::Tool::Rocks => match self.field_hover {
                Some(i) => format!("rocks: rock field {i}: SW2 + touch grabs it | tap the palette for figures"),
                None => "rocks: draw a field's outline | SW3 ends it | tap the palette for figures".to_string(),
            },
            State::Armed if self.tool == rocks::Tool::Rocks => {
                "rocks: SW2: touch a rock field to grab it | SW3: redo".to_string()
            }
            State::Idle if self.tool == rocks::Tool::Rivers => match self.river_hover {
                Some(i) => format!("rivers: river {i}: SW3 click: one more year | SW2 + touch grabs it"),
                None => "rivers: draw a course from source to mouth | SW3 ends it | tap the river button for figures"
                    .to_string(),
            },
            State::Armed if self.tool == rocks::Tool::Rivers => {
                "rivers: SW2: touch a control point to move it, the course to hold it | SW3: redo".to_string()
            }
            State::River(g) => match (g.tuning, g.control) {
                (Some((_, w, d)), _) => format!(
                    "river {}: width ×{w:.2}, depth ×{d:.2} | sideways: width, up/down: depth",
                    g.index
                ),
                (None, Some(k)) if g.moving => format!("river {}: moving point {k} | lift to set", g.index),
                (None, _) => format!("river {}: slide a point to reshape | SW3 + move: width, depth", g.index),
            },
            State::Idle if self.tool == rocks::Tool::Ridges => match self.ridge_hover {
                Some(part) => format!(
                    "ridges: {}: SW3 click grows valleys | SW2 + touch a node grabs it",
                    part.name()
                ),
                None => {
                    "ridges: touch, lift and draw in the air (a ridgeline), or on the surface (a tree) | SW3 ends it"
                        .to_string()
                }
            },
            State::Armed if self.tool == rocks::Tool::Ridges => {
                "ridges: SW2: touch a node to grab it | SW3: redo".to_string()
            }
            State::RidgeStroke(samples) => match samples.last() {
                Some(s) if s.h_mm > 0.0 => format!(
                    "ridgeline: {:.0} m high | touch: on the surface | SW3 ends it",
                    self.view.height_at(s.h_mm)
                ),
                _ => "ridge stroke on the surface | lift to draw in the air | SW3 ends it".to_string(),
            },
            State::Node(g, _) if g.slope_from.is_some() => format!(
                "flank slope {:.1}° | left steeper, right gentler | release SW2 to set",
                g.slope.unwrap_or(0.0)
            ),
            State::Node(g, _) => match (g.height, g.moving) {
                (Some(h), _) => format!("{} node {}: {h:.0} m | release SW2 to set", g.node.0.name(), g.node.1),
                (None, true) => format!("moving {} node {} | lift to set", g.node.0.name(), g.node.1),
                (None, false) => format!("{} node {}: slide to move, lift to pull", g.node.0.name(), g.node.1),
            },
            State::Idle if self.tool == rocks::Tool::Trees => match self.tree_hover {
                Some(h) => format!("trees: {}: SW2 + touch grabs it | tap: plant a tree", h.name()),
                None => format!(
                    "trees ({}): tap plants a tree, an outline back to its start a grove | tap the tree button: next preset",
                    self.tree_preset.name()
                ),
            },
            State::Armed if self.tool == rocks::Tool::Trees => {
                "trees: SW2: touch a tree or grove to grab it | SW3: redo".to_string()
            }
            State::Tree(g) => match (g.tuning, g.pull) {
                (Some((_, k)), _) => format!(
                    "{}: {} ×{k:.2} | sideways: more or less",
                    g.held.name(),
                    if matches!(g.held, trees::Held::Tree(_)) {
                        "height"
                    } else {
                        "density"
                    }
                ),
                (None, Some(h)) => format!("{}: {h:.0} m high | release SW2 to set", g.held.name()),
                (None, None) if g.moving => format!("moving {} | lift to drop", g.held.name()),
                (None, None) => format!("{}: slide to move, lift to pull | SW3 + sideways", g.held.name()),
            },
            State::Palette => match self.tool {
                rocks::Tool::Trees => format!("tree tool: {}", self.tree_preset.name()),
                rocks::Tool::Ridges => "ridge tool".to_string(),
                rocks::Tool::Rocks => "rock tool".to_string(),
                rocks::Tool::Rivers => "river tool".to_string(),
                rocks::Tool::Figures => "figures".to_string(),
            },
            State::Field(g) => match g.tuning {
                Some((_, d, z)) => format!(
                    "rock field {}: density ×{d:.2}, size ×{z:.2} | sideways: density, up/down: size",
                    g.index
                ),
                None if g.moving => format!("moving rock field {} | lift to drop", g.index),
                None => format!("rock field {}: slide to move | SW3 + move: density, size", g.index),
            },
            State::Idle => match &self.hover {
                Some(h) => format!("{}: SW2 + touch grabs it", describe(doc, &h.curve)),
                None => "draw with the tip | SW3 ends a figure | SW3 click: undo".to_string(),
            },
            State::Drawing { positions, touching } => format!(
                "drawing: {} positions{} | SW3 ends the figure",
                positions.len(),
                if *touching { "" } else { ", pen lifted" }
            ),
            State::Armed => match &self.hover {
                Some(h) => format!("{}: touch to grab | SW3: redo", describe(doc, &h.curve)),
                None => "SW2: touch a figure to grab it | SW3: redo".to_string(),
            },
            State::Grabbed(g) => {
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
                    (Action::Move { .. }, _) if deletes(g, doc) => {
                        format!("{what}: drop here to delete it")
                    }
                    (Action::Move { .. }, _) => match g.hit.vertex {
                        Some(i) => format!("moving vertex {i} of {what}"),
                        None => format!("moving {what}"),
                    },
                    _ => format!("grabbed {what}: lift to pull, slide to move"),
                }
            }
            State::Sw3 { moved: true, .. } => format!("view: 1 mm = {:.1} m", 1.0 / self.view.scale),
            State::Sw3 { t0, .. } if self.tool == rocks::Tool::Rivers && self.river_hover.is_some() => {
                let index = self.river_hover.unwrap_or_default();
                let held = self.last_t.unwrap_or(*t0).saturating_sub(*t0);
                let years = river::years_held(held, self.tuning.click_us);
                let had = doc.rivers.get(index).map_or(0, |r| r.iterations);
                let to = doc
                    .rivers
                    .get(index)
                    .and_then(|r| river::aged(r, years))
                    .map_or(had, |r| r.iterations);
                format!(
                    "river {index}: +{} years ({to} in all) | hold to count on, release to commit, move to pan",
                    to - had
                )
            }
            State::Sw3 { .. } => "SW3: release to undo, or move to pan and zoom".to_string(),
        };
        match (&self.last_message, self.last_t) {
            (Some((t, m)), Some(now)) if now.saturating_sub(*t) < 3_000_000 => format!("{line}  | {m}"),
            _ => line,
        }
    }

    fn say(&mut self, message: String) {
        if let Some(t) = self.last_t {
            self.last_message = Some((t, message.clone()));
        }
        self.messages.push(message);
    }

    /// Eases the ground's tilt towards its target up to time `t_us`.
    /// A clock that goes back (a device reattached starts its own again) restarts the easing.
    pub fn advance(&mut self, t_us: u64) {
        let dt = match self.last_t {
            Some(last) if t_us >= last => (t_us - last) as f64 * 1e-6,
            _ => 0.0,
        };
        self.last_t = Some(t_us);
        let target = if self.pulling() { self.tuning.pull_tilt } else { 0.0 };
        let k = 1.0 - (-dt / self.tuning.tilt_time_s).exp();
        self.view.tilt += (target - self.view.tilt) * k;
    }

    /// Handles one pen event.
    pub fn handle(&mut self, editor: &mut Editor, ev: &PenEvent) {
        if let Some(t) = event_time(ev) {
            self.advance(t);
        }
        if let Some(p) = ev.point {
            self.pen = Some(p);
        }
        if let Some(sw) = ev.sw {
            self.sw = sw;
        }
        let t = self.last_t.unwrap_or(0);
        match &ev.kind {
            EventKind::ProximityIn | EventKind::Motion => self.on_motion(editor),
            EventKind::ProximityOut => {
                self.pen = None;
                self.hover = None;
            }
            EventKind::TipDown => self.on_tip_down(editor),
            EventKind::TipUp => self.on_tip_up(editor),
            EventKind::ButtonDown { button: 2 } => self.on_sw2_down(),
            EventKind::ButtonUp { button: 2 } => self.on_sw2_up(editor),
            EventKind::ButtonDown { button: 3 } => self.on_sw3_down(editor, t),
            EventKind::ButtonUp { button: 3 } => self.on_sw3_up(editor, t),
            EventKind::ButtonDown { .. } | EventKind::ButtonUp { .. } => {}
            EventKind::DeviceLost { reason } => self.on_lost(editor, reason),
            EventKind::DeviceFound { device } => self.say(format!("pen found: {device}")),
            EventKind::Missed { count } => {
                self.stats.missed += count;
                self.say(format!("{count} pen events were lost"));
            }
            // The tracked head (issue 16) drives the view, not the pen's interaction.
            EventKind::Head(_) => {}
        }
    }

    /// Carries out a command.
    pub fn command(&mut self, editor: &mut Editor, command: KeyCommand) {
        match command {
            KeyCommand::Undo => self.undo(editor),
            KeyCommand::Redo => self.redo(editor),
            KeyCommand::Delete if self.tool == rocks::Tool::Ridges => self.delete_ridge(editor),
            KeyCommand::Delete if self.tool == rocks::Tool::Rivers => {
                let Some(index) = self.river_hover() else {
                    self.say("no river highlighted to delete".into());
                    return;
                };
                if self.commit(editor, Edit::DeleteRiver { index }, "delete") {
                    self.stats.deletes += 1;
                    self.river_hover = None;
                }
            }
            KeyCommand::Delete if self.tool == rocks::Tool::Trees => {
                let Some(held) = self.tree_hover() else {
                    self.say("no tree or grove highlighted to delete".into());
                    return;
                };
                let edit = match held {
                    trees::Held::Tree(index) => Edit::DeleteTree { index },
                    trees::Held::Grove(index) => Edit::DeleteGrove { index },
                };
                if self.commit(editor, edit, "delete") {
                    self.stats.deletes += 1;
                    self.tree_hover = None;
                }
            }
            KeyCommand::Delete if self.tool == rocks::Tool::Rocks => {
                let Some(index) = self.field_hover() else {
                    self.say("no rock field highlighted to delete".into());
                    return;
                };
                if self.commit(editor, Edit::DeleteRocks { index }, "delete") {
                    self.stats.deletes += 1;
                    self.field_hover = None;
                }
            }
            KeyCommand::Delete => {
                let Some(hit) = self.hover().cloned() else {
                    self.say("nothing highlighted to delete".into());
                    return;
                };
                let edit = match hit.curve {
                    CurvePath::Figure(at) => Edit::DeleteFigure { at },
                    CurvePath::Boundary(index) => Edit::DeleteRegion { index },
                };
                if self.commit(editor, edit, "delete") {
                    self.stats.deletes += 1;
                    self.hover = None;
                }
            }
            KeyCommand::Pan { du_mm, dv_mm } => {
                let c = self.view.to_display(self.view.centre);
                let g = self.view.centre;
                self.view.put(g, [c[0] + du_mm, c[1] + dv_mm]);
            }
            KeyCommand::Zoom { factor } => {
                let (min, max) = self.scale_limits();
                let c = [0.5 * self.view.display_mm[0], 0.5 * self.view.display_mm[1]];
                self.view.zoom_about(factor, c, min, max);
            }
            KeyCommand::Fit => {
                let tilt = self.view.tilt;
                self.view = View { tilt, ..self.home };
            }
        }
    }

    fn scale_limits(&self) -> (f64, f64) {
        (0.25 * self.home.scale, 64.0 * self.home.scale)
    }

    fn ground(&self) -> Option<(Point, DisplayPoint)> {
        let p = self.pen?;
        Some((self.view.to_ground(p.u_mm, p.v_mm), p))
    }

    fn on_motion(&mut self, editor: &mut Editor) {
        let Some((g, p)) = self.ground() else { return };
        let s = self.tuning;
        match &mut self.state {
            State::Idle | State::Armed if self.tool == rocks::Tool::Ridges => {
                self.hover = None;
                self.ridge_hover = ridge::part_at(editor.document(), g, self.view.metres(s.pick_mm));
            }
            State::RidgeStroke(samples) => {
                let h_mm = if self.sw[0] { 0.0 } else { p.h_mm.max(0.0) };
                samples.push(ridge::Sample { at: g, h_mm });
            }
            State::Node(..) => self.follow_node(editor, g, p),
            State::Idle | State::Armed if self.tool == rocks::Tool::Rivers => {
                self.hover = None;
                self.river_hover = river::river_at(editor.document(), g, self.view.metres(s.pick_mm));
            }
            State::River(grab) => {
                let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
                if let Some((start, _, _)) = grab.tuning {
                    let width = ((p.u_mm - start[0]) * river::GAIN_PER_MM).exp();
                    let depth = ((p.h_mm - start[1]) * river::GAIN_PER_MM).exp();
                    grab.tuning = Some((start, width, depth));
                } else if self.sw[0] && grab.control.is_some() && (grab.moving || slid > s.move_mm) {
                    grab.moving = true;
                    grab.by = minus(g, self.view.to_ground(grab.at_mm[0], grab.at_mm[1]));
                }
                let doc = editor.document();
                self.river_preview = grab.preview(doc);
            }
            State::Idle | State::Armed if self.tool == rocks::Tool::Rocks => {
                self.hover = None;
                self.field_hover = rocks::field_at(editor.document(), g);
            }
            State::Idle | State::Armed if self.tool == rocks::Tool::Trees => {
                self.hover = None;
                self.tree_hover = trees::held_at(editor.document(), g, self.view.metres(s.pick_mm));
            }
            State::Tree(grab) => {
                let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
                if let Some((u0, _)) = grab.tuning {
                    grab.tuning = Some((u0, ((p.u_mm - u0) * trees::GAIN_PER_MM).exp()));
                } else if grab.pull.is_some() {
                    grab.pull = Some(trees::clamp_height(self.view.height_at(p.h_mm.max(0.0))));
                } else if self.sw[0] && !grab.tuned && (grab.moving || slid > s.move_mm) {
                    grab.moving = true;
                    grab.by = minus(g, self.view.to_ground(grab.at_mm[0], grab.at_mm[1]));
                }
                self.show_tree(editor);
            }
            State::Idle | State::Armed => {
                self.hover = pick::pick(editor.document(), g, self.view.metres(s.pick_mm));
            }
            State::Palette => {}
            State::Field(grab) => {
                let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
                if let Some((start, _, _)) = grab.tuning {
                    let density = ((p.u_mm - start[0]) * rocks::GAIN_PER_MM).exp();
                    let size = ((p.h_mm - start[1]) * rocks::GAIN_PER_MM).exp();
                    grab.tuning = Some((start, density, size));
                } else if self.sw[0] && !grab.tuned && (grab.moving || slid > s.move_mm) {
                    grab.moving = true;
                    grab.by = minus(g, self.view.to_ground(grab.at_mm[0], grab.at_mm[1]));
                }
            }
            State::Drawing { positions, touching } => {
                if *touching {
                    positions.push(g);
                }
            }
            State::Grabbed(grab) => {
                let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
                let is_figure = matches!(grab.hit.curve, CurvePath::Figure(_));
                if grab.action == Action::Pending {
                    if is_figure && (!self.sw[0] || p.h_mm > s.lift_mm) {
                        grab.action = Action::Pull;
                        grab.pulled = true;
                    } else if self.sw[0] && slid > s.move_mm {
                        grab.action = Action::Move {
                            by: [0.0, 0.0],
                            outside: false,
                        };
                    }
                }
                let grab = grab.clone();
                self.follow(editor, grab, g, p);
            }
            State::Sw3 {
                at_mm,
                h0,
                ground,
                scale0,
                moved,
                ..
            } => {
                let d = (p.u_mm - at_mm[0]).hypot(p.v_mm - at_mm[1]);
                if d > s.click_mm || (p.h_mm - *h0).abs() > 2.0 * s.click_mm {
                    *moved = true;
                }
                if *moved {
                    // The ground point under the pen at the press stays under it; height zooms.
                    let factor = (-(p.h_mm - *h0) / s.zoom_mm).exp();
                    let (ground, scale0) = (*ground, *scale0);
                    let (min, max) = self.scale_limits();
                    self.view.scale = (scale0 * factor).clamp(min, max);
                    self.view.put(ground, [p.u_mm, p.v_mm]);
                }
            }
        }
    }

    /// A grabbed figure follows the pen: its height, its slope, or its place.
    fn follow(&mut self, editor: &mut Editor, grab: Grab, g: Point, p: DisplayPoint) {
        let s = self.tuning;
        let CurvePath::Figure(at) = &grab.hit.curve else {
            if let Action::Move { .. } = grab.action {
                self.track_move(editor, g);
            }
            return;
        };
        let edit = match grab.action {
            Action::Pending => return,
            Action::Pull => Edit::SetHeight {
                at: at.clone(),
                height: self.view.height_at(p.h_mm.max(0.0)),
            },
            Action::Slope { u0, s0 } => Edit::SetSlope {
                at: at.clone(),
                slope: (s0 + (p.u_mm - u0) * s.slope_per_mm).clamp(-s.slope_limit, s.slope_limit),
            },
            Action::Move { .. } => return self.track_move(editor, g),
        };
        if let Err(e) = editor.preview(&edit) {
            self.stats.refused += 1;
            self.say(format!("cannot show the change: {e}"));
        }
    }

    fn track_move(&mut self, editor: &Editor, g: Point) {
        let State::Grabbed(grab) = &mut self.state else { return };
        let start = self.view.to_ground(grab.at_mm[0], grab.at_mm[1]);
        let doc = editor.document();
        let outside = match &grab.hit.curve {
            CurvePath::Figure(at) => at.edge(doc).is_some_and(|edge| locate(edge, g) == Side::Outside),
            CurvePath::Boundary(_) => {
                !(0.0..=doc.grid.width()).contains(&g[0]) || !(0.0..=doc.grid.height()).contains(&g[1])
            }
        };
        grab.action = Action::Move {
            by: minus(g, start),
            outside,
        };
    }

    fn on_tip_down(&mut self, editor: &mut Editor) {
        let Some((g, p)) = self.ground() else { return };
        match &mut self.state {
            State::Idle if ridge::on_palette(&self.view, p.u_mm, p.v_mm) => {
                self.tool = match self.tool {
                    rocks::Tool::Ridges => rocks::Tool::Figures,
                    _ => rocks::Tool::Ridges,
                };
                self.hover = None;
                self.field_hover = None;
                self.river_hover = None;
                self.ridge_hover = None;
                self.state = State::Palette;
                self.say(match self.tool {
                    rocks::Tool::Ridges => {
                        "ridge tool: touch, lift and draw a ridgeline in the air, or draw a tree on the surface; SW3 ends it"
                            .into()
                    }
                    _ => "figures: draw with the tip".into(),
                });
            }
            State::Idle if self.tool == rocks::Tool::Ridges => {
                self.state = State::RidgeStroke(vec![ridge::Sample { at: g, h_mm: 0.0 }]);
            }
            State::RidgeStroke(samples) => samples.push(ridge::Sample { at: g, h_mm: 0.0 }),
            State::Armed if self.tool == rocks::Tool::Ridges => {
                let doc = editor.document();
                match ridge::node_at(doc, g, self.view.metres(self.tuning.pick_mm)) {
                    Some(node) => {
                        let base = Box::new(doc.ridges.clone().unwrap_or_default());
                        self.state = State::Node(
                            ridge::NodeGrab {
                                node,
                                at_mm: [p.u_mm, p.v_mm],
                                by: [0.0, 0.0],
                                moving: false,
                                height: None,
                                slope_from: None,
                                slope: None,
                            },
                            base,
                        );
                    }
                    None => self.say("no ridgeline node here to grab".into()),
                }
            }
            State::Idle if river::on_palette(p.u_mm, p.v_mm) => {
                self.tool = match self.tool {
                    rocks::Tool::Rivers => rocks::Tool::Figures,
                    _ => rocks::Tool::Rivers,
                };
                self.hover = None;
                self.field_hover = None;
                self.river_hover = None;
                self.state = State::Palette;
                self.say(match self.tool {
                    rocks::Tool::Rivers => "river tool: draw a course from source to mouth, SW3 ends it".into(),
                    _ => "figures: draw with the tip".into(),
                });
            }
            State::Idle if trees::on_palette(p.u_mm, p.v_mm) => {
                // Each tap picks the next preset; after the last, back to figures.
                let next = match self.tool {
                    rocks::Tool::Trees => trees::next_preset(self.tree_preset),
                    _ => Some(penmodel_terrain::trees::Preset::Table31),
                };
                match next {
                    Some(preset) => {
                        self.tool = rocks::Tool::Trees;
                        self.tree_preset = preset;
                    }
                    None => self.tool = rocks::Tool::Figures,
                }
                self.hover = None;
                self.field_hover = None;
                self.river_hover = None;
                self.ridge_hover = None;
                self.tree_hover = None;
                self.state = State::Palette;
                self.say(match self.tool {
                    rocks::Tool::Trees => format!(
                        "tree tool ({}): tap to plant a tree, draw an outline for a grove",
                        self.tree_preset.name()
                    ),
                    _ => "figures: draw with the tip".into(),
                });
            }
            State::Idle if rocks::on_palette(p.u_mm, p.v_mm) => {
                self.tool = match self.tool {
                    rocks::Tool::Rocks => rocks::Tool::Figures,
                    _ => rocks::Tool::Rocks,
                };
                self.river_hover = None;
                self.hover = None;
                self.field_hover = None;
                self.state = State::Palette;
                self.say(match self.tool {
                    rocks::Tool::Rocks => "rock tool: draw a field's outline, SW3 ends it".into(),
                    _ => "figures: draw with the tip".into(),
                });
            }
            State::Idle => {
                self.state = State::Drawing {
                    positions: vec![g],
                    touching: true,
                }
            }
            State::Armed if self.tool == rocks::Tool::Rivers => {
                let doc = editor.document();
                let tol = self.view.metres(self.tuning.pick_mm);
                let grab = match river::control_at(doc, g, tol) {
                    Some((index, k)) => Some((index, Some(k))),
                    None => river::river_at(doc, g, tol).map(|i| (i, None)),
                };
                match grab {
                    Some((index, control)) => {
                        let grab = river::RiverGrab::new(doc, index, control, [p.u_mm, p.v_mm]);
                        self.river_preview = grab.preview(doc);
                        self.state = State::River(grab);
                    }
                    None => self.say("no river here to grab".into()),
                }
            }
            State::Armed if self.tool == rocks::Tool::Trees => {
                match trees::held_at(editor.document(), g, self.view.metres(self.tuning.pick_mm)) {
                    Some(held) => self.state = State::Tree(trees::TreeGrab::new(held, [p.u_mm, p.v_mm])),
                    None => self.say("no tree or grove here to grab".into()),
                }
            }
            State::Armed if self.tool == rocks::Tool::Rocks => match rocks::field_at(editor.document(), g) {
                Some(index) => {
                    self.state = State::Field(rocks::FieldGrab {
                        index,
                        at_mm: [p.u_mm, p.v_mm],
                        by: [0.0, 0.0],
                        moving: false,
                        tuning: None,
                        tuned: false,
                    })
                }
                None => self.say("no rock field here to grab".into()),
            },
            State::Drawing { positions, touching } => {
                *touching = true;
                positions.push(g);
            }
            State::Armed => {
                let hit = self
                    .hover
                    .clone()
                    .or_else(|| pick::pick(editor.document(), g, self.view.metres(self.tuning.pick_mm)));
                match hit {
                    Some(hit) => {
                        self.state = State::Grabbed(Grab {
                            hit,
                            at_mm: [p.u_mm, p.v_mm],
                            action: Action::Pending,
                            pulled: false,
                        })
                    }
                    None => self.say("nothing here to grab".into()),
                }
            }
            State::Grabbed(_)
            | State::Sw3 { .. }
            | State::Palette
            | State::Field(_)
            | State::River(_)
            | State::Tree(_)
            | State::Node(..) => {}
        }
    }

    fn on_tip_up(&mut self, editor: &mut Editor) {
        let g = self.ground().map(|(g, _)| g);
        match &mut self.state {
            // A tree-tool stroke is one touch: lifting the tip ends it.
            State::Drawing { positions, .. } if self.tool == rocks::Tool::Trees => {
                let mut positions = std::mem::take(positions);
                if let Some(g) = g
                    && positions.last() != Some(&g)
                {
                    positions.push(g);
                }
                self.state = State::Idle;
                self.finish_trees(editor, &positions);
            }
            State::Tree(grab) if grab.moving => {
                self.drop_tree(editor);
                self.state = State::Armed;
            }
            State::Tree(grab) if !grab.tuned && grab.tuning.is_none() => {
                let h = self.pen.map_or(0.0, |p| p.h_mm.max(0.0));
                grab.pull = Some(trees::clamp_height(self.view.height_at(h)));
                self.show_tree(editor);
            }
            State::Drawing { positions, touching } => {
                *touching = false;
                if let Some(g) = g
                    && positions.last() != Some(&g)
                {
                    positions.push(g);
                }
            }
            State::Grabbed(grab) => match grab.action {
                Action::Pending if matches!(grab.hit.curve, CurvePath::Figure(_)) => {
                    grab.action = Action::Pull;
                    grab.pulled = true;
                }
                Action::Pending => {
                    self.say("a region's boundary is moved, not pulled: pull the figures inside it".into())
                }
                Action::Move { .. } => {
                    self.drop_move(editor);
                    self.state = State::Armed;
                }
                _ => {}
            },
            State::Palette => self.state = State::Idle,
            State::Node(grab, _) if grab.moving => {
                self.commit_node(editor);
                self.state = State::Armed;
            }
            State::Field(grab) if grab.moving => {
                self.drop_field(editor);
                self.state = State::Armed;
            }
            State::River(grab) if grab.moving => {
                self.drop_river(editor);
                self.state = State::Armed;
            }
            _ => {}
        }
    }

    /// Drops the held rock field where the pen has taken it.
    fn drop_field(&mut self, editor: &mut Editor) {
        let State::Field(grab) = &self.state else { return };
        if !grab.moving || grab.by == [0.0, 0.0] {
            return;
        }
        let index = grab.index;
        let outside = self
            .field_moving(editor.document())
            .is_some_and(|(_, outline)| rocks::outside_every_region(editor.document(), &outline));
        // As a figure dropped outside its region, a field dropped outside every region goes.
        if outside {
            if self.commit(editor, Edit::DeleteRocks { index }, "delete") {
                self.stats.deletes += 1;
                self.say(format!("rock field {index} deleted"));
            }
            return;
        }
        let edit = Edit::MoveRocks { index, by: grab.by };
        if self.commit(editor, edit, "moving the rock field") {
            self.stats.moves += 1;
        }
    }

    fn on_sw2_down(&mut self) {
        if self.state == State::Idle {
            self.state = State::Armed;
        }
    }

    /// Sets the held river's point where the pen has taken it.
    fn drop_river(&mut self, editor: &mut Editor) {
        let State::River(grab) = &self.state else { return };
        if !grab.moving || grab.by == [0.0, 0.0] {
            return;
        }
        let (index, k) = (grab.index, grab.control);
        let Some(river) = grab.river(editor.document()) else {
            return;
        };
        if self.commit(editor, Edit::ReplaceRiver { index, river }, "moving the river's point") {
            self.stats.moves += 1;
            self.say(format!("river {index}: point {} moved", k.unwrap_or(0)));
        }
    }

    fn on_sw2_up(&mut self, editor: &mut Editor) {
        if let State::Node(..) = &self.state {
            self.commit_node(editor);
            self.state = State::Idle;
            return;
        }
        if let State::River(_) = &self.state {
            self.drop_river(editor);
            self.state = State::Idle;
            return;
        }
        if let State::Field(_) = &self.state {
            self.drop_field(editor);
            self.state = State::Idle;
            return;
        }
        if let State::Tree(_) = &self.state {
            self.drop_tree(editor);
            self.state = State::Idle;
            return;
        }
        let State::Grabbed(grab) = &self.state else {
            if self.state == State::Armed {
                self.state = State::Idle;
            }
            return;
        };
        match grab.action {
            Action::Move { .. } => self.drop_move(editor),
            _ => self.commit_preview(editor),
        }
        self.state = State::Idle;
    }

    fn on_sw3_down(&mut self, editor: &mut Editor, t: u64) {
        let at = self.pen.map(|p| ([p.u_mm, p.v_mm], p.h_mm));
        match &mut self.state {
            State::Drawing { positions, .. } => {
                let positions = std::mem::take(positions);
                self.state = State::Idle;
                self.finish(editor, &positions);
            }
            State::RidgeStroke(samples) => {
                let samples = std::mem::take(samples);
                self.state = State::Idle;
                self.finish_ridge(editor, &samples);
            }
            State::Idle => {
                let Some((at_mm, h0)) = at else { return };
                self.state = State::Sw3 {
                    t0: t,
                    at_mm,
                    h0,
                    ground: self.view.to_ground(at_mm[0], at_mm[1]),
                    scale0: self.view.scale,
                    moved: false,
                };
            }
            State::Armed => self.redo(editor),
            State::Grabbed(grab) => {
                let CurvePath::Figure(at_path) = &grab.hit.curve else {
                    return;
                };
                if matches!(grab.action, Action::Pending | Action::Pull)
                    && let Some((at_mm, _)) = at
                {
                    let s0 = at_path.get(editor.document()).map_or(0.0, |f| f.slope);
                    grab.action = Action::Slope { u0: at_mm[0], s0 };
                }
            }
            State::Field(grab) => {
                if let Some(p) = self.pen
                    && !grab.moving
                {
                    grab.tuning = Some(([p.u_mm, p.h_mm], 1.0, 1.0));
                    grab.tuned = true;
                }
            }
            State::River(grab) => {
                if let Some(p) = self.pen
                    && !grab.moving
                {
                    grab.tuning = Some(([p.u_mm, p.h_mm], 1.0, 1.0));
                }
            }
            State::Tree(grab) => {
                if let Some(p) = self.pen
                    && !grab.moving
                    && grab.pull.is_none()
                    && let Some(size) = trees::size_of(editor.document(), grab.held)
                {
                    grab.tuning = Some((p.u_mm, 1.0));
                    grab.tuned_from = size;
                    grab.tuned = true;
                }
            }
            State::Node(grab, base) => {
                if let Some(p) = self.pen {
                    grab.slope_from = Some((p.u_mm, grab.slope.unwrap_or(base.slope)));
                }
            }
            State::Sw3 { .. } | State::Palette => {}
        }
    }

    fn on_sw3_up(&mut self, editor: &mut Editor, t: u64) {
        match &mut self.state {
            State::Node(grab, _) => grab.slope_from = None,
            State::Grabbed(grab) => {
                if let Action::Slope { .. } = grab.action {
                    grab.action = if grab.pulled { Action::Pull } else { Action::Pending };
                }
            }
            State::Field(grab) => {
                let Some((_, density, size)) = grab.tuning.take() else {
                    return;
                };
                let index = grab.index;
                let Some(field) = editor.document().rocks.get(index) else {
                    return;
                };
                let field = rocks::tuned(field, density, size);
                if self.commit(
                    editor,
                    Edit::ReplaceRocks { index, field },
                    "the rock field's density and size",
                ) {
                    self.say(format!("rock field {index}: density ×{density:.2}, size ×{size:.2}"));
                }
            }
            State::Tree(grab) => {
                let Some((_, k)) = grab.tuning else { return };
                let held = grab.held;
                let what = if matches!(held, trees::Held::Tree(_)) {
                    "height"
                } else {
                    "density"
                };
                if self.commit_tree(editor, &format!("the {what} of {}", held.name())) {
                    self.say(format!("{}: {what} ×{k:.2}", held.name()));
                }
                if let State::Tree(grab) = &mut self.state {
                    grab.tuning = None;
                }
            }
            State::River(grab) => {
                let Some((_, width, depth)) = grab.tuning else {
                    return;
                };
                let index = grab.index;
                let Some(river) = grab.river(editor.document()) else {
                    return;
                };
                grab.tuning = None;
                if self.commit(
                    editor,
                    Edit::ReplaceRiver { index, river },
                    "the river's width and depth",
                ) {
                    self.say(format!("river {index}: width ×{width:.2}, depth ×{depth:.2}"));
                }
            }
            State::Sw3 { t0, moved, .. } => {
                let click = !*moved && t.saturating_sub(*t0) < self.tuning.click_us;
                // With the river tool, a click over a river is one more year of its change, and
                // a press held still there one more per `river::YEAR_HOLD_US` past the click.
                let held = (!*moved).then(|| river::years_held(t.saturating_sub(*t0), self.tuning.click_us));
                self.state = State::Idle;
                let over = self.river_hover.filter(|_| self.tool == rocks::Tool::Rivers);
                let ridge_over = self.ridge_hover.filter(|_| self.tool == rocks::Tool::Ridges);
                if click && let Some(part) = ridge_over {
                    self.grow(editor, part);
                } else if let (Some(index), Some(more)) = (over, held) {
                    let Some(river) = editor.document().rivers.get(index).and_then(|r| river::aged(r, more)) else {
                        self.say(format!("river {index} has had the most years a river may have"));
                        return;
                    };
                    let years = river.iterations;
                    if self.commit(editor, Edit::ReplaceRiver { index, river }, "the river's years") {
                        self.say(format!("river {index}: {years} years of erosion and deposition"));
                    }
                } else if click {
                    self.undo(editor);
                }
            }
            _ => {}
        }
    }

    fn on_lost(&mut self, editor: &mut Editor, reason: &str) {
        match &mut self.state {
            State::Field(_) => {
                self.say(format!("pen lost ({reason}): the rock field stays where it was"));
                self.state = State::Idle;
            }
            State::River(_) => {
                self.say(format!("pen lost ({reason}): the river stays as it was"));
                self.state = State::Idle;
            }
            State::Tree(g) => {
                let name = g.held.name();
                if let Err(e) = editor.cancel_preview() {
                    self.say(format!("cannot restore {name}: {e}"));
                }
                self.say(format!("pen lost ({reason}): {name} stays as it was"));
                self.state = State::Idle;
            }
            State::Node(..) => {
                if let Err(e) = editor.cancel_preview() {
                    self.say(format!("cannot restore the ridgeline: {e}"));
                }
                self.say(format!("pen lost ({reason}): the node stays where it was"));
                self.state = State::Idle;
            }
            State::RidgeStroke(_) => {
                self.say(format!("pen lost ({reason}): the ridge stroke is kept; SW3 ends it"));
            }
            State::Grabbed(_) => {
                if let Err(e) = editor.cancel_preview() {
                    self.say(format!("cannot restore the grabbed figure: {e}"));
                }
                self.say(format!("pen lost ({reason}): the grab was cancelled"));
                self.state = State::Idle;
            }
            State::Drawing { touching, .. } => {
                *touching = false;
                self.say(format!(
                    "pen lost ({reason}): the figure being drawn is kept; SW3 ends it"
                ));
            }
            _ => {
                self.say(format!("pen lost ({reason})"));
                self.state = State::Idle;
            }
        }
        self.pen = None;
        self.hover = None;
    }

    /// Applies a recorded edit; a refusal is a message.
    fn commit(&mut self, editor: &mut Editor, edit: Edit, what: &str) -> bool {
        match editor.apply(edit) {
            Ok(_) => true,
            Err(e) => {
                self.stats.refused += 1;
                self.say(format!("{what} refused: {e}"));
                false
            }
        }
    }

    fn commit_preview(&mut self, editor: &mut Editor) {
        match editor.commit_preview() {
            Ok(Some(edit)) => {
                let (height, slope) = match &edit {
                    Edit::SetHeight { .. } => (true, false),
                    Edit::SetSlope { .. } => (false, true),
                    _ => (true, true),
                };
                self.stats.pulls += u32::from(height);
                self.stats.slopes += u32::from(slope);
            }
            Ok(None) => {}
            Err(e) => {
                self.stats.refused += 1;
                self.say(format!("the pull was not recorded: {e}"));
            }
        }
    }

    fn drop_move(&mut self, editor: &mut Editor) {
        let State::Grabbed(grab) = &self.state else { return };
        let Action::Move { by, .. } = grab.action else { return };
        let doc = editor.document();
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
        if self.commit(editor, edit, if delete { "delete" } else { "move" }) {
            if delete {
                self.stats.deletes += 1;
            } else {
                self.stats.moves += 1;
            }
        }
        self.hover = None;
    }

    fn undo(&mut self, editor: &mut Editor) {
        let result = editor.undo();
        if self.history(result, "undo", "undone") {
            self.stats.undos += 1;
        }
    }

    fn redo(&mut self, editor: &mut Editor) {
        let result = editor.redo();
        if self.history(result, "redo", "redone") {
            self.stats.redos += 1;
        }
    }

    /// Tells what an undo or redo did; whether it did something.
    fn history(&mut self, result: Result<Option<Outcome>, EditorError>, verb: &str, done: &str) -> bool {
        self.hover = None;
        match result {
            Ok(Some(_)) => {
                self.say(done.into());
                true
            }
            Ok(None) => {
                self.say(format!("nothing to {verb}"));
                false
            }
            Err(e) => {
                self.say(format!("cannot {verb}: {e}"));
                false
            }
        }
    }

    /// Ends the river being drawn: its course fitted to Bézier segments, a new river.
    fn finish_river(&mut self, editor: &mut Editor, positions: &[Point]) {
        let Some(river) = river::new_river(positions, &self.view) else {
            self.say("a river's course needs a longer stroke".into());
            return;
        };
        let index = editor.document().rivers.len();
        let points = river.points.len();
        if self.commit(editor, Edit::AddRiver { index, river }, &format!("river {index}")) {
            self.stats.rivers += 1;
            self.say(format!(
                "river {index}: {points} control points | SW3 click over it: one year"
            ));
        }
    }

    /// Ends the figure being drawn: classifies it and adds it where it belongs.
    fn finish(&mut self, editor: &mut Editor, positions: &[Point]) {
        if self.tool == rocks::Tool::Rivers {
            return self.finish_river(editor, positions);
        }
        if self.tool == rocks::Tool::Trees {
            return self.finish_trees(editor, positions);
        }
        let v = self.view;
        let tol = Tolerances {
            point: v.metres(self.tuning.point_mm),
            close: v.metres(self.tuning.close_mm),
            simplify: v.metres(self.tuning.simplify_mm),
        };
        let Some(shape) = stroke::classify(positions, &tol) else {
            return;
        };
        if self.tool == rocks::Tool::Rocks {
            return self.finish_field(editor, shape);
        }
        let doc = editor.document();
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
                self.stats.refused += 1;
                self.say(format!(
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
        if self.commit(editor, edit, &format!("the new {name}")) {
            if region {
                self.stats.regions += 1;
            } else {
                self.stats.figures += 1;
            }
            self.say(format!("added {name}"));
        }
    }
}

impl Interaction {
    /// A closed outline drawn with the rock tool becomes a rock field.
    fn finish_field(&mut self, editor: &mut Editor, shape: Shape) {
        if shape.kind != FigureKind::Closed {
            self.stats.refused += 1;
            self.say(format!(
                "a rock field needs a closed outline (this was a {}): come back to the start",
                shape.kind.name()
            ));
            return;
        }
        let doc = editor.document();
        let index = doc.rocks.len();
        let field = rocks::new_field(&shape.points, &self.view, index as u64 + 1);
        if self.commit(editor, Edit::AddRocks { index, field }, &format!("rock field {index}")) {
            self.stats.rock_fields += 1;
            let n = editor.rocks().fields().get(index).map_or(0, |f| f.scatter.rocks.len());
            self.say(format!("added rock field {index}: {n} rocks"));
        }
    }
}

impl Interaction {
    /// Ends a tree-tool stroke: a tap (a point figure's stroke) plants a tree, a closed outline a
    /// grove.
    fn finish_trees(&mut self, editor: &mut Editor, positions: &[Point]) {
        let v = self.view;
        let tol = Tolerances {
            point: v.metres(self.tuning.point_mm),
            close: v.metres(self.tuning.close_mm),
            simplify: v.metres(self.tuning.simplify_mm),
        };
        let doc = editor.document();
        match stroke::classify(positions, &tol) {
            Some(Shape {
                kind: FigureKind::Point,
                points,
            }) => {
                let index = doc.trees.len();
                let tree = trees::new_tree(points[0], &v, self.tree_preset, index as u64 + 1);
                let name = format!("{} tree {index}", self.tree_preset.name());
                if self.commit(editor, Edit::AddTree { index, tree }, &name) {
                    self.stats.trees += 1;
                    self.say(format!("planted {name}"));
                }
            }
            Some(Shape {
                kind: FigureKind::Closed,
                points,
            }) => {
                let index = doc.groves.len();
                let grove = trees::new_grove(&points, &v, index as u64 + 1);
                if self.commit(editor, Edit::AddGrove { index, grove }, &format!("grove {index}")) {
                    self.stats.groves += 1;
                    let n = editor
                        .document()
                        .groves
                        .get(index)
                        .map_or(0, |g| penmodel_terrain::trees::grove::trees(g).len());
                    self.say(format!("planted grove {index}: {n} trees"));
                }
            }
            _ => {
                self.stats.refused += 1;
                self.say("a grove needs an outline back to its start (a tap plants one tree)".into());
            }
        }
    }

    /// Sets the held tree or grove: where the pen slid it, or the height it pulled to (or the
    /// SW3 gesture's size, when SW2 is released first), shown since the pull began.
    fn drop_tree(&mut self, editor: &mut Editor) {
        let State::Tree(grab) = &self.state else { return };
        let (held, by) = (grab.held, grab.by);
        if !grab.moving {
            let pulled = grab.tuning.is_none() && grab.pull.is_some();
            if self.commit_tree(editor, &format!("the height of {}", held.name())) && pulled {
                self.stats.pulls += 1;
            }
            return;
        }
        let edit = match held {
            _ if by == [0.0, 0.0] => return,
            trees::Held::Tree(index) => Edit::MoveTree { index, by },
            trees::Held::Grove(index) => Edit::MoveGrove { index, by },
        };
        if self.commit(editor, edit, &format!("moving {}", held.name())) {
            self.stats.moves += 1;
        }
    }

    /// Shows the held tree or grove as the pen sizes it (the pull, the SW3 gesture) at once,
    /// unrecorded: the forest and the frames follow it before the release records it.
    fn show_tree(&mut self, editor: &mut Editor) {
        let State::Tree(grab) = &self.state else { return };
        let Some(edit) = trees::sized(editor.document(), grab) else {
            return;
        };
        if let Err(e) = editor.preview_tree(&edit) {
            self.stats.refused += 1;
            self.say(format!("cannot show {}: {e}", grab.held.name()));
        }
    }

    /// Records the tree preview shown as one edit; whether there was one and it was recorded.
    fn commit_tree(&mut self, editor: &mut Editor, what: &str) -> bool {
        match editor.commit_tree_preview() {
            Ok(edit) => edit.is_some(),
            Err(e) => {
                self.stats.refused += 1;
                self.say(format!("{what} refused: {e}"));
                false
            }
        }
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
fn short(at: &penmodel_terrain::address::FigurePath) -> String {
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

impl Interaction {
    /// Ends the ridge stroke: a 3D ridgeline if it went into the air, else a tree or a branch.
    fn finish_ridge(&mut self, editor: &mut Editor, samples: &[ridge::Sample]) {
        let map = editor.heightmap();
        let surface = |g: Point| {
            let cell = map.cell_size();
            let c = ((g[0] / cell).floor().max(0.0) as u32).min(map.cols() - 1);
            let r = ((g[1] / cell).floor().max(0.0) as u32).min(map.rows() - 1);
            f64::from(map.get(c, r))
        };
        let tol = (self.tuning.lift_mm, self.tuning.close_mm);
        let doc = editor.document();
        let (ridges, what) = match ridge::drawn(samples, &self.view, tol, surface) {
            None => {
                self.say("a ridgeline needs a longer stroke".into());
                return;
            }
            Some(ridge::Drawn::Line(points)) => {
                let n = points.len();
                let top = points.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
                let r = ridge::with_line(doc, points);
                let i = r.lines.len() - 1;
                (r, format!("ridgeline {i}: {n} nodes, up to {top:.0} m"))
            }
            Some(ridge::Drawn::Tree(points)) => {
                let before = doc.ridges.as_ref().map_or(0, |r| r.trees.len());
                let (r, j) = ridge::with_tree_stroke(doc, &points, self.view.metres(self.tuning.pick_mm));
                let how = if j < before { "a branch of" } else { "new" };
                (r, format!("{how} ridgeline tree {j}: elevations computed"))
            }
        };
        if self.commit(editor, Edit::SetRidges { ridges: Some(ridges) }, "the ridgeline") {
            self.stats.ridgelines += 1;
            self.say(what);
        }
    }

    /// The held node follows the pen: carried along the surface, or pulled to the pen's height.
    fn follow_node(&mut self, editor: &mut Editor, g: Point, p: DisplayPoint) {
        let s = self.tuning;
        let touching = self.sw[0];
        let State::Node(grab, base) = &mut self.state else {
            return;
        };
        let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
        if let Some((u0, a0)) = grab.slope_from {
            let (lo, hi) = ridge::SLOPE_LIMITS;
            grab.slope = Some((a0 - (p.u_mm - u0) * ridge::SLOPE_DEG_PER_MM).clamp(lo, hi));
        } else if touching && grab.height.is_none() && grab.slope.is_none() && (grab.moving || slid > s.move_mm) {
            grab.moving = true;
            grab.by = minus(g, self.view.to_ground(grab.at_mm[0], grab.at_mm[1]));
        } else if !touching && !grab.moving && p.h_mm > s.lift_mm {
            grab.height = Some(self.view.height_at(p.h_mm));
        } else {
            return;
        }
        if let Err(e) = editor.preview_ridges(Some(grab.ridges(base))) {
            self.stats.refused += 1;
            self.say(format!("cannot show the change: {e}"));
        }
    }

    /// Records the held node's move or pull.
    fn commit_node(&mut self, editor: &mut Editor) {
        let State::Node(grab, _) = &self.state else { return };
        let (moved, pulled, sloped) = (grab.moving, grab.height.is_some(), grab.slope.is_some());
        match editor.commit_ridges_preview() {
            Ok(Some(_)) => {
                self.stats.moves += u32::from(moved);
                self.stats.pulls += u32::from(pulled);
                self.stats.slopes += u32::from(sloped);
            }
            Ok(None) => {}
            Err(e) => {
                self.stats.refused += 1;
                self.say(format!("the ridgeline change was not recorded: {e}"));
            }
        }
    }

    /// One round of valleys (Alg. 2.5) grown from the clicked ridgeline or tree.
    fn grow(&mut self, editor: &mut Editor, part: ridge::Part) {
        let doc = editor.document();
        let seed = doc
            .ridges
            .as_ref()
            .map_or(0, |r| (r.lines.len() + r.trees.len()) as u64);
        match ridge::grown(doc, part, seed) {
            Ok((ridges, n)) => {
                let slope = ridges.slope;
                if self.commit(editor, Edit::SetRidges { ridges: Some(ridges) }, "the grown valleys") {
                    self.stats.grown += 1;
                    self.say(format!(
                        "grew {n} valley lines from {}; slope now {slope:.0}°",
                        part.name()
                    ));
                }
            }
            Err(e) => {
                self.stats.refused += 1;
                self.say(format!("cannot grow valleys: {e}"));
            }
        }
    }

    /// Deletes the highlighted ridgeline or tree.
    fn delete_ridge(&mut self, editor: &mut Editor) {
        let Some(part) = self.ridge_hover() else {
            self.say("no ridgeline highlighted to delete".into());
            return;
        };
        let Some(mut r) = editor.document().ridges.clone() else {
            return;
        };
        match part {
            ridge::Part::Line(i) if i < r.lines.len() => {
                r.lines.remove(i);
            }
            ridge::Part::Tree(j) if j < r.trees.len() => {
                r.trees.remove(j);
            }
            _ => return,
        }
        if self.commit(editor, Edit::SetRidges { ridges: Some(r) }, "delete") {
            self.stats.deletes += 1;
            self.ridge_hover = None;
            self.say(format!("{} deleted", part.name()));
        }
    }
}
