//! The tree tool (seed 004): single trees and groves planted, moved and sized with the pen.
//!
//! The seed has no pen gestures; these follow seed 000's and the rock tool's (docs/modeler.md,
//! "The tree tool"):
//!
//! - **Pick the tool and a preset**: tap the tree button (the display's left edge, below the
//!   river button) with the tip: the tree tool with `table-3.1`; each further tap picks the next
//!   preset (cypress, oak, fir), and a tap after the last goes back to figures.
//! - **Plant a tree**: an SW1 tap (the tip down and up, staying within the tuning's `point_mm`
//!   of where it touched, as a point figure's stroke) plants one tree of the current preset at
//!   the touch's mean position, [`TREE_MM`] tall on the display.
//! - **Plant a grove**: an SW1 outline that comes back to its start (within `close_mm`) plants a
//!   grove there: trees [`SPACING_MM`] apart on the display, [`TREE_MM`] tall, every preset in
//!   equal shares. Lifting the tip (or SW3) ends the stroke; a stroke that is neither is refused.
//! - **Move**: SW2 + touch grabs the nearest tree (within `pick_mm` of its trunk), else the grove
//!   under the tip; sliding carries it and lifting the tip (or releasing SW2) drops it there.
//! - **Height**: with it held, lift the tip: the pull, as a figure's — the top follows the pen's
//!   height (× the view's vertical scale); releasing SW2 sets it. Or hold SW3 and move sideways:
//!   the height × e^(k·du) (right taller), k = [`GAIN_PER_MM`] per mm; releasing SW3 sets it.
//!   A held grove's pull sets its mean height.
//! - **Density**: a grove held, SW3 and sideways: its density × e^(k·du) (right denser).
//!
//! The pull and the SW3 gesture show as they go: each pen move previews the held element as
//! [`sized`] makes it ([`penmodel_terrain::Editor::preview_tree`]), so the tree grows in the
//! frames and a grove is scattered again; the release records it as one edit, losing the pen
//! restores it. Every change is one editor edit (undo, journal); new trees sway in [`breeze`].

use pen_host::events::DisplayPoint;
use penmodel_render::Rgba;
use penmodel_terrain::document::{Document, FigureKind, Grove, GroveSpecies, Point, Sway, Tree, Wind};
use penmodel_terrain::edit::Edit;
use penmodel_terrain::geometry::{Side, locate};
use penmodel_terrain::trees::{MAX_HEIGHT, Preset, grove};

use super::figures::tolerances;
use super::stroke::{self, Shape};
use super::tool::{Context, Counter, Layers, MOVING_COLOUR, Phase, Release, Seen, Tool};
use super::view::View;

/// Colour of a grove's outline and a single tree's trunk, with the tree tool.
pub const GROVE_COLOUR: Rgba = [60, 150, 70, 255];
/// A new tree's (or grove's mean) height as drawn on the display, mm.
pub const TREE_MM: f64 = 8.0;
/// A new grove's least distance between trees on the display, mm.
pub const SPACING_MM: f64 = 4.0;
/// Gain of the height and density gestures, per mm.
pub const GAIN_PER_MM: f64 = 0.02;
/// The shortest tree the pen sets, metres.
pub const MIN_HEIGHT: f64 = 1.0;

/// The preset after `p` in [`Preset::ALL`]; `None` after the last (back to figures).
pub fn next_preset(p: Preset) -> Option<Preset> {
    let i = Preset::ALL.iter().position(|&q| q == p)?;
    Preset::ALL.get(i + 1).copied()
}

/// The light wind new trees and groves sway in: the trunk barely, the twigs most.
pub fn breeze() -> Wind {
    let sway = |amplitude, frequency| Sway {
        amplitude,
        frequency,
        rest: 0.0,
    };
    Wind {
        direction: 30.0,
        generations: vec![sway(1.5, 0.35), sway(3.0, 0.6), sway(5.0, 0.9)],
    }
}

/// A height the pen sets, kept within what a document may hold.
pub fn clamp_height(h: f64) -> f64 {
    h.clamp(MIN_HEIGHT, MAX_HEIGHT)
}

/// A new tree of `preset` standing at `at`, [`TREE_MM`] tall on the display.
pub fn new_tree(at: Point, view: &View, preset: Preset, seed: u64) -> Tree {
    Tree {
        at,
        height: clamp_height(view.height_at(TREE_MM)),
        preset: Some(preset.name().to_owned()),
        maps: None,
        seed,
        wind: Some(breeze()),
    }
}

/// The density, trees per hectare, whose trees stand `spacing` metres apart: the inverse of
/// [`grove::spacing`].
pub fn density_for(spacing: f64) -> f64 {
    10_000.0 * 4.0 * grove::JAMMING / (std::f64::consts::PI * spacing * spacing)
}

/// A new grove inside `outline` (ground metres, closed): trees [`SPACING_MM`] apart and
/// [`TREE_MM`] tall on the display, every preset in equal shares.
pub fn new_grove(outline: &[Point], view: &View, seed: u64) -> Grove {
    Grove {
        region: outline.to_vec(),
        density: density_for(view.metres(SPACING_MM)),
        mix: Preset::ALL
            .iter()
            .map(|p| GroveSpecies {
                preset: p.name().to_owned(),
                weight: 1.0,
            })
            .collect(),
        height: clamp_height(view.height_at(TREE_MM)),
        seed,
        wind: Some(breeze()),
    }
}

/// What the tree tool holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Held {
    /// A single tree, by index.
    Tree(usize),
    /// A grove, by index.
    Grove(usize),
}

impl Held {
    /// Its name for messages: `tree 2`, `grove 0`.
    pub fn name(self) -> String {
        match self {
            Held::Tree(i) => format!("tree {i}"),
            Held::Grove(i) => format!("grove {i}"),
        }
    }
}

/// The tree whose trunk is nearest `g` within `tolerance` metres, else the grove whose region
/// holds `g` (the last drawn first).
pub fn held_at(doc: &Document, g: Point, tolerance: f64) -> Option<Held> {
    let d = |t: &Tree| (t.at[0] - g[0]).hypot(t.at[1] - g[1]);
    let tree = doc
        .trees
        .iter()
        .enumerate()
        .filter(|(_, t)| d(t) <= tolerance)
        .min_by(|a, b| d(a.1).total_cmp(&d(b.1)))
        .map(|(i, _)| Held::Tree(i));
    tree.or_else(|| {
        (0..doc.groves.len())
            .rev()
            .find(|&i| locate(&doc.groves[i].region, g) == Side::Inside)
            .map(Held::Grove)
    })
}

/// A held tree or grove and what the pen is doing with it.
#[derive(Debug, Clone, PartialEq)]
pub struct TreeGrab {
    /// What is held.
    pub held: Held,
    /// Where the tip touched, display mm.
    pub at_mm: [f64; 2],
    /// Ground displacement so far.
    pub by: Point,
    /// Whether the tip has slid far enough to move it.
    pub moving: bool,
    /// The pull: the height the pen's height sets, metres, once the tip is lifted.
    pub pull: Option<f64>,
    /// The sideways SW3 gesture: the pen's `u` when SW3 went down, and the factor.
    pub tuning: Option<(f64, f64)>,
    /// The held tree's height (a grove's density) when the SW3 gesture began: what the factor
    /// multiplies while the document shows the gesture's preview.
    pub tuned_from: f64,
    /// Whether this grab has tuned it: it then neither moves nor pulls.
    pub tuned: bool,
}

impl TreeGrab {
    /// A grab of `held` touched at `at_mm`.
    pub fn new(held: Held, at_mm: [f64; 2]) -> TreeGrab {
        TreeGrab {
            held,
            at_mm,
            by: [0.0, 0.0],
            moving: false,
            pull: None,
            tuning: None,
            tuned_from: 0.0,
            tuned: false,
        }
    }
}

/// Tree `tree` with height `height` (clamped).
pub fn with_height(tree: &Tree, height: f64) -> Tree {
    Tree {
        height: clamp_height(height),
        ..tree.clone()
    }
}

/// Grove `grove` with mean height `height` (clamped).
pub fn grove_with_height(grove: &Grove, height: f64) -> Grove {
    Grove {
        height: clamp_height(height),
        ..grove.clone()
    }
}

/// The edit that shows `held` in `doc` as `grab` makes it: the pulled height, or the SW3
/// gesture's height (a grove's density) × its factor; `None` while it neither pulls nor tunes,
/// or when `held` is not in `doc`. The editor previews it at each pen move
/// ([`penmodel_terrain::Editor::preview_tree`]) and records it on release.
pub fn sized(doc: &Document, grab: &TreeGrab) -> Option<Edit> {
    match (grab.held, grab.tuning, grab.pull) {
        (Held::Tree(index), Some((_, k)), _) => doc.trees.get(index).map(|t| Edit::ReplaceTree {
            index,
            tree: with_height(t, grab.tuned_from * k),
        }),
        (Held::Grove(index), Some((_, k)), _) => doc.groves.get(index).map(|g| Edit::ReplaceGrove {
            index,
            grove: Grove {
                density: grab.tuned_from * k,
                ..g.clone()
            },
        }),
        (Held::Tree(index), None, Some(h)) => doc.trees.get(index).map(|t| Edit::ReplaceTree {
            index,
            tree: with_height(t, h),
        }),
        (Held::Grove(index), None, Some(h)) => doc.groves.get(index).map(|g| Edit::ReplaceGrove {
            index,
            grove: grove_with_height(g, h),
        }),
        (_, None, None) => None,
    }
}

/// The held element's size the SW3 gesture multiplies: a tree's height, a grove's density.
pub fn size_of(doc: &Document, held: Held) -> Option<f64> {
    match held {
        Held::Tree(i) => doc.trees.get(i).map(|t| t.height),
        Held::Grove(i) => doc.groves.get(i).map(|g| g.density),
    }
}

/// The tree tool: the preset a tap plants, the tree or grove under the pen and the one held.
#[derive(Debug, Clone)]
pub struct Trees {
    preset: Preset,
    hover: Option<Held>,
    grab: Option<TreeGrab>,
}

impl Default for Trees {
    fn default() -> Trees {
        Trees {
            preset: Preset::Table31,
            hover: None,
            grab: None,
        }
    }
}

impl Trees {
    /// The preset an SW1 tap plants.
    pub fn preset(&self) -> Preset {
        self.preset
    }

    /// The tree or grove under the pen, or held.
    pub fn held(&self) -> Option<Held> {
        self.grab.as_ref().map(|g| g.held).or(self.hover)
    }

    /// The held tree or grove and how far the pen has slid it, ground metres.
    pub fn moving(&self) -> Option<(Held, Point)> {
        self.grab.as_ref().filter(|g| g.moving).map(|g| (g.held, g.by))
    }

    /// Sets the held tree or grove: where the pen slid it, or the height it pulled to (or the
    /// SW3 gesture's size, when SW2 is released first), shown since the pull began.
    fn drop(&mut self, cx: &mut Context) {
        let Some(grab) = &self.grab else { return };
        let (held, by) = (grab.held, grab.by);
        if !grab.moving {
            let pulled = grab.tuning.is_none() && grab.pull.is_some();
            if Trees::commit_preview(cx, &format!("the height of {}", held.name())) && pulled {
                cx.stats.pulls += 1;
            }
            return;
        }
        let edit = match held {
            _ if by == [0.0, 0.0] => return,
            Held::Tree(index) => Edit::MoveTree { index, by },
            Held::Grove(index) => Edit::MoveGrove { index, by },
        };
        if cx.commit(edit, &format!("moving {}", held.name())) {
            cx.stats.moves += 1;
        }
    }

    /// Shows the held tree or grove as the pen sizes it (the pull, the SW3 gesture) at once,
    /// unrecorded: the forest and the frames follow it before the release records it.
    fn show(&self, cx: &mut Context) {
        let Some(grab) = &self.grab else { return };
        let Some(edit) = sized(cx.editor.document(), grab) else {
            return;
        };
        if let Err(e) = cx.editor.preview_tree(&edit) {
            cx.refuse(format!("cannot show {}: {e}", grab.held.name()));
        }
    }

    /// Records the tree preview shown as one edit; whether there was one and it was recorded.
    fn commit_preview(cx: &mut Context, what: &str) -> bool {
        match cx.editor.commit_tree_preview() {
            Ok(edit) => edit.is_some(),
            Err(e) => {
                cx.refuse(format!("{what} refused: {e}"));
                false
            }
        }
    }
}

impl Tool for Trees {
    fn name(&self) -> &'static str {
        "trees"
    }

    fn title(&self) -> String {
        format!("tree tool: {}", self.preset.name())
    }

    fn picked(&self) -> String {
        format!(
            "tree tool ({}): tap to plant a tree, draw an outline for a grove",
            self.preset.name()
        )
    }

    /// Each tap picks the next preset; after the last, back to figures.
    fn tapped(&mut self, again: bool) -> bool {
        let next = if again {
            next_preset(self.preset)
        } else {
            Some(Preset::Table31)
        };
        match next {
            Some(preset) => {
                self.preset = preset;
                true
            }
            None => false,
        }
    }

    fn counters(&self) -> &'static [Counter] {
        &[
            Counter {
                key: "trees",
                noun: Some("tree"),
            },
            Counter {
                key: "groves",
                noun: Some("grove"),
            },
        ]
    }

    fn clear_hover(&mut self) {
        self.hover = None;
    }

    fn hover(&mut self, cx: &mut Context, g: Point) {
        self.hover = held_at(cx.editor.document(), g, cx.pick_m());
    }

    /// A tree-tool stroke is one touch: lifting the tip ends it.
    fn ends_stroke_on_lift(&self) -> bool {
        true
    }

    /// A tap (a point figure's stroke) plants a tree, a closed outline a grove.
    fn stroke(&mut self, cx: &mut Context, positions: &[Point]) {
        let doc = cx.editor.document();
        match stroke::classify(positions, &tolerances(cx)) {
            Some(Shape {
                kind: FigureKind::Point,
                points,
            }) => {
                let index = doc.trees.len();
                let tree = new_tree(points[0], cx.view, self.preset, index as u64 + 1);
                let name = format!("{} tree {index}", self.preset.name());
                if cx.commit(Edit::AddTree { index, tree }, &name) {
                    cx.stats.count("trees");
                    cx.say(format!("planted {name}"));
                }
            }
            Some(Shape {
                kind: FigureKind::Closed,
                points,
            }) => {
                let index = doc.groves.len();
                let grove = new_grove(&points, cx.view, index as u64 + 1);
                if cx.commit(Edit::AddGrove { index, grove }, &format!("grove {index}")) {
                    cx.stats.count("groves");
                    let n = cx
                        .editor
                        .document()
                        .groves
                        .get(index)
                        .map_or(0, |g| grove::trees(g).len());
                    cx.say(format!("planted grove {index}: {n} trees"));
                }
            }
            _ => cx.refuse("a grove needs an outline back to its start (a tap plants one tree)".into()),
        }
    }

    fn grab(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) -> bool {
        let Some(held) = held_at(cx.editor.document(), g, cx.pick_m()) else {
            cx.say("no tree or grove here to grab".into());
            return false;
        };
        self.grab = Some(TreeGrab::new(held, [p.u_mm, p.v_mm]));
        true
    }

    fn motion(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) {
        let Some(grab) = &mut self.grab else { return };
        let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
        if let Some((u0, _)) = grab.tuning {
            grab.tuning = Some((u0, ((p.u_mm - u0) * GAIN_PER_MM).exp()));
        } else if grab.pull.is_some() {
            grab.pull = Some(clamp_height(cx.view.height_at(p.h_mm.max(0.0))));
        } else if cx.sw[0] && !grab.tuned && (grab.moving || slid > cx.tuning.move_mm) {
            grab.moving = true;
            let from = cx.view.to_ground(grab.at_mm[0], grab.at_mm[1]);
            grab.by = [g[0] - from[0], g[1] - from[1]];
        }
        self.show(cx);
    }

    /// Lifting drops a slid tree or grove, or starts its pull.
    fn tip_up(&mut self, cx: &mut Context) -> Release {
        let Some(grab) = &mut self.grab else {
            return Release::Keep;
        };
        if grab.moving {
            self.drop(cx);
            self.grab = None;
            return Release::Armed;
        }
        if !grab.tuned && grab.tuning.is_none() {
            let h = cx.pen.map_or(0.0, |p| p.h_mm.max(0.0));
            grab.pull = Some(clamp_height(cx.view.height_at(h)));
            self.show(cx);
        }
        Release::Keep
    }

    fn sw2_up(&mut self, cx: &mut Context) -> Release {
        self.drop(cx);
        self.grab = None;
        Release::Idle
    }

    fn sw3_down(&mut self, cx: &mut Context) -> Release {
        if let Some(grab) = &mut self.grab
            && let Some(p) = cx.pen
            && !grab.moving
            && grab.pull.is_none()
            && let Some(size) = size_of(cx.editor.document(), grab.held)
        {
            grab.tuning = Some((p.u_mm, 1.0));
            grab.tuned_from = size;
            grab.tuned = true;
        }
        Release::Keep
    }

    /// Sets the height (a grove's density) the sideways gesture chose, as one edit.
    fn sw3_up(&mut self, cx: &mut Context) {
        let Some(grab) = &mut self.grab else { return };
        let Some((_, k)) = grab.tuning else { return };
        let held = grab.held;
        let what = if matches!(held, Held::Tree(_)) {
            "height"
        } else {
            "density"
        };
        if Trees::commit_preview(cx, &format!("the {what} of {}", held.name())) {
            cx.say(format!("{}: {what} ×{k:.2}", held.name()));
        }
        if let Some(grab) = &mut self.grab {
            grab.tuning = None;
        }
    }

    fn lost(&mut self, cx: &mut Context, reason: &str) -> Release {
        let name = self.grab.as_ref().map(|g| g.held.name()).unwrap_or_default();
        if let Err(e) = cx.editor.cancel_preview() {
            cx.say(format!("cannot restore {name}: {e}"));
        }
        cx.say(format!("pen lost ({reason}): {name} stays as it was"));
        self.grab = None;
        Release::Idle
    }

    fn delete(&mut self, cx: &mut Context) {
        let Some(held) = self.held() else {
            cx.say("no tree or grove highlighted to delete".into());
            return;
        };
        let edit = match held {
            Held::Tree(index) => Edit::DeleteTree { index },
            Held::Grove(index) => Edit::DeleteGrove { index },
        };
        if cx.commit(edit, "delete") {
            cx.stats.deletes += 1;
            self.hover = None;
        }
    }

    fn status(&self, seen: &Seen) -> Option<String> {
        Some(match (seen.phase, &self.grab) {
            (Phase::Held, Some(g)) => match (g.tuning, g.pull) {
                (Some((_, k)), _) => {
                    let what = if matches!(g.held, Held::Tree(_)) {
                        "height"
                    } else {
                        "density"
                    };
                    format!("{}: {what} ×{k:.2} | sideways: more or less", g.held.name())
                }
                (None, Some(h)) => format!("{}: {h:.0} m high | release SW2 to set", g.held.name()),
                (None, None) if g.moving => format!("moving {} | lift to drop", g.held.name()),
                (None, None) => format!("{}: slide to move, lift to pull | SW3 + sideways", g.held.name()),
            },
            (Phase::Idle, _) => match self.hover {
                Some(h) => format!("trees: {}: SW2 + touch grabs it | tap: plant a tree", h.name()),
                None => format!(
                    "trees ({}): tap plants a tree, an outline back to its start a grove | tap the tree button: next preset",
                    self.preset.name()
                ),
            },
            (Phase::Armed, _) => "trees: SW2: touch a tree or grove to grab it | SW3: redo".to_string(),
            _ => return None,
        })
    }

    /// While the tool is on: the groves' outlines and the single trees' trunks (the held one
    /// where the pen takes it, the one under the pen highlighted).
    fn overlays(&self, seen: &Seen, active: bool, layers: &mut Layers) {
        if !active {
            return;
        }
        let moving = self.moving();
        let shift = |held: Held, p: Point| match moving {
            Some((h, by)) if h == held => [p[0] + by[0], p[1] + by[1]],
            _ => p,
        };
        let colour = |held: Held| match moving {
            Some((h, _)) if h == held => MOVING_COLOUR,
            _ => GROVE_COLOUR,
        };
        let mut push = |held: Held, overlay| {
            if self.held() == Some(held) && layers.selection.is_none() {
                layers.push_selected(overlay);
            } else {
                layers.push(overlay);
            }
        };
        for (i, g) in seen.doc.groves.iter().enumerate() {
            let held = Held::Grove(i);
            let points = g.region.iter().map(|&p| shift(held, p)).collect();
            push(held, Layers::line(points, true, colour(held), 2.0));
        }
        for (i, t) in seen.doc.trees.iter().enumerate() {
            let held = Held::Tree(i);
            push(held, Layers::dot(shift(held, t.at), None, colour(held), 4.0));
        }
    }

    fn help(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("tree button again", "the next preset; after the last, figures"),
            ("SW1 tap", "plant a tree of the preset"),
            ("SW1 outline to its start", "plant a grove inside it"),
            ("SW2 + touch, slide", "move a tree or grove"),
            ("held, lift", "pull: its height follows the pen"),
            ("held, SW3 sideways", "a tree's height, a grove's density"),
            ("Del", "delete the highlighted tree or grove"),
        ]
    }
}
