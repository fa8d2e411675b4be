//! The rock tool (seed 001): rock fields drawn, moved and tuned with the pen.
//!
//! The seed has no pen gestures for rocks; these follow seed 000's, as a user of this pen would
//! expect them (docs/modeler.md, "The rock tool"):
//!
//! - **Pick the tool**: tap the palette button in the display's corner with the tip (SW1); tap
//!   it again to go back to figures. The button is drawn on the display, lit while the tool is on.
//! - **Draw a field**: with the tool on, SW1 draws an outline like a closed figure and SW3 ends
//!   it; a closed outline becomes a rock field (the seed's fig. 1 recipe) and its rocks appear.
//!   An outline that is not closed, or lies outside every region, is refused with a message.
//! - **Move a field**: SW2 + touch inside it grabs it; sliding the tip carries its outline, and
//!   lifting the tip (or releasing SW2) drops it there — the same rocks, on the ground there.
//! - **Density and size**: while holding a field (SW2), hold SW3 and move the pen: sideways
//!   changes the density (right denser, left sparser: the area fractions or counts × e^(k·du)),
//!   up and down the size (higher bigger: the radii × e^(k·dh)), k = 0.02 per mm — the same kind
//!   of sideways SW3 gesture as slope. Releasing SW3 sets both as one undoable edit.

use penmodel_terrain::Editor;
use penmodel_terrain::document::{Document, Point, RockField, RockLayer};
use penmodel_terrain::geometry::{Side, locate};

use super::palette::Button;
use super::view::View;

/// The rock tool's button on the display.
pub const BUTTON: Button = Button {
    corner_mm: [8.0, 8.0],
    side_mm: 20.0,
};
/// Gain of the density and size gestures, per mm.
pub const GAIN_PER_MM: f64 = 0.02;
/// The largest rocks' radius on the display, mm: sets a new field's cell size.
pub const LARGEST_ROCK_MM: f64 = 4.0;

/// Which tool SW1 draws with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tool {
    /// Seed 000's figures and regions.
    #[default]
    Figures,
    /// Rock fields.
    Rocks,
    /// Rivers (seed 003; [`super::river`]).
    Rivers,
    /// Ridgelines (seed 002; [`super::ridge`]).
    Ridges,
    /// Trees and groves (seed 004; [`super::trees`]).
    Trees,
}

/// Whether display point `(u, v)` mm is on the palette button.
pub fn on_palette(u_mm: f64, v_mm: f64) -> bool {
    BUTTON.contains(u_mm, v_mm)
}

/// The palette button's outline on the ground (closed), for drawing.
pub fn palette_outline(view: &View) -> Vec<Point> {
    BUTTON.outline(view)
}

/// The field whose outline holds ground point `g`, the last drawn first.
pub fn field_at(doc: &Document, g: Point) -> Option<usize> {
    (0..doc.rocks.len())
        .rev()
        .find(|&i| locate(&doc.rocks[i].outline_at(), g) == Side::Inside)
}

/// Whether a field with `outline` (ground metres, closed) would lie outside every region: none
/// of its vertices inside a top-level region (the document's own rule for fields).
pub fn outside_every_region(doc: &Document, outline: &[Point]) -> bool {
    !doc.regions
        .iter()
        .any(|r| outline.iter().any(|&p| locate(&r.boundary, p) == Side::Inside))
}

/// A new field with the seed's fig. 1 recipe inside `outline` (ground metres, closed), its cell
/// size such that the largest rocks are [`LARGEST_ROCK_MM`] across on the display.
pub fn new_field(outline: &[Point], view: &View, seed: u64) -> RockField {
    let at = outline[0];
    let layer = |radius, fraction, widths, heights| RockLayer {
        radius,
        fraction: Some(fraction),
        count: None,
        widths,
        heights,
    };
    RockField {
        at,
        outline: outline.iter().map(|p| [p[0] - at[0], p[1] - at[1]]).collect(),
        cell_size: view.metres(LARGEST_ROCK_MM) / 9.0,
        layers: vec![
            layer(9.0, 0.2, [0.0, 0.3, 0.3], [0.3, 0.3, 0.1]),
            layer(3.0, 0.24, [0.0, 0.3, 0.1], [0.3, 0.3, 0.1]),
            layer(1.0, 0.56, [0.1, 0.1, 0.1], [0.3, 0.0, 0.1]),
        ],
        seed,
    }
}

/// A field changed by the density and size gestures: fractions (and counts) × `density`, kept
/// to a sum of at most 1; radii × `size`, at least 0.5 cell and at most the image's smaller side.
pub fn tuned(field: &RockField, density: f64, size: f64) -> RockField {
    let mut f = field.clone();
    let sum: f64 = f.layers.iter().filter_map(|l| l.fraction).sum();
    let cap = if sum * density > 1.0 {
        1.0 / (sum * density)
    } else {
        1.0
    };
    let (w, h, _) = penmodel_terrain::rocks::field::extent(field);
    let largest = w.min(h);
    for l in &mut f.layers {
        l.fraction = l.fraction.map(|x| (x * density * cap).clamp(0.0, 1.0));
        l.count = l.count.map(|c| ((f64::from(c) * density).round().max(1.0)) as u32);
        l.radius = (l.radius * size).clamp(0.5, largest.max(0.5));
    }
    f
}

/// A grabbed field and what the pen is doing with it.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldGrab {
    /// The field's index.
    pub index: usize,
    /// Where the tip touched, display mm, and that point on the ground.
    pub at_mm: [f64; 2],
    /// Ground displacement so far.
    pub by: Point,
    /// Whether the tip has slid far enough to move it.
    pub moving: bool,
    /// The density and size gesture: the pen's `(u, h)` when SW3 went down, and the factors.
    pub tuning: Option<([f64; 2], f64, f64)>,
    /// Whether this grab has tuned the field: it then no longer moves it.
    pub tuned: bool,
}

/// Applies an edit for the rock tool; a refusal is the message returned.
pub fn apply(editor: &mut Editor, edit: penmodel_terrain::Edit) -> Result<(), String> {
    editor.apply(edit).map(|_| ()).map_err(|e| e.to_string())
}
