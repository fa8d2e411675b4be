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

use penmodel_terrain::document::{Document, Grove, GroveSpecies, Point, Sway, Tree, Wind};
use penmodel_terrain::geometry::{Side, locate};
use penmodel_terrain::trees::{MAX_HEIGHT, Preset, grove};

use super::palette::Button;
use super::view::View;

/// The tree tool's button on the display: below the river button.
pub const BUTTON: Button = Button {
    corner_mm: [8.0, 56.0],
    side_mm: 20.0,
};
/// A new tree's (or grove's mean) height as drawn on the display, mm.
pub const TREE_MM: f64 = 8.0;
/// A new grove's least distance between trees on the display, mm.
pub const SPACING_MM: f64 = 4.0;
/// Gain of the height and density gestures, per mm.
pub const GAIN_PER_MM: f64 = 0.02;
/// The shortest tree the pen sets, metres.
pub const MIN_HEIGHT: f64 = 1.0;

/// Whether display point `(u, v)` mm is on the tree button.
pub fn on_palette(u_mm: f64, v_mm: f64) -> bool {
    BUTTON.contains(u_mm, v_mm)
}

/// The tree button's outline on the ground (closed), for drawing.
pub fn palette_outline(view: &View) -> Vec<Point> {
    BUTTON.outline(view)
}

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
pub fn sized(doc: &Document, grab: &TreeGrab) -> Option<penmodel_terrain::Edit> {
    use penmodel_terrain::Edit;
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
