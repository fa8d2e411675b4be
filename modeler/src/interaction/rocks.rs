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

use pen_host::events::DisplayPoint;
use penmodel_render::Rgba;
use penmodel_terrain::document::{Document, FigureKind, Point, RockField, RockLayer};
use penmodel_terrain::edit::Edit;
use penmodel_terrain::geometry::{Side, locate};

use super::figures::tolerances;
use super::stroke;
use super::tool::{Context, Counter, DELETING_COLOUR, Layers, MOVING_COLOUR, Phase, Release, Seen, Tool};
use super::view::View;

/// Gain of the density and size gestures, per mm.
pub const GAIN_PER_MM: f64 = 0.02;
/// The largest rocks' radius on the display, mm: sets a new field's cell size.
pub const LARGEST_ROCK_MM: f64 = 4.0;
/// Colour of a rock field's outline.
pub const ROCK_FIELD_COLOUR: Rgba = [200, 170, 130, 255];

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

/// The rock tool: the field under the pen and the one held.
#[derive(Debug, Clone, Default)]
pub struct Rocks {
    hover: Option<usize>,
    grab: Option<FieldGrab>,
}

impl Rocks {
    /// The rock field under the pen, or held.
    pub fn field(&self) -> Option<usize> {
        self.grab.as_ref().map(|g| g.index).or(self.hover)
    }

    /// The held rock field's outline where the pen is taking it (ground metres, closed).
    pub fn moving(&self, doc: &Document) -> Option<(usize, Vec<Point>)> {
        let g = self.grab.as_ref()?;
        let f = doc.rocks.get(g.index)?;
        Some((
            g.index,
            f.outline_at()
                .into_iter()
                .map(|p| [p[0] + g.by[0], p[1] + g.by[1]])
                .collect(),
        ))
    }

    /// Drops the held rock field where the pen has taken it; outside every region it goes, as a
    /// figure dropped outside its region.
    fn drop_field(&mut self, cx: &mut Context) {
        let Some(grab) = &self.grab else { return };
        if !grab.moving || grab.by == [0.0, 0.0] {
            return;
        }
        let (index, by) = (grab.index, grab.by);
        let doc = cx.editor.document();
        let outside = self
            .moving(doc)
            .is_some_and(|(_, outline)| outside_every_region(doc, &outline));
        if outside {
            if cx.commit(Edit::DeleteRocks { index }, "delete") {
                cx.stats.deletes += 1;
                cx.say(format!("rock field {index} deleted"));
            }
            return;
        }
        if cx.commit(Edit::MoveRocks { index, by }, "moving the rock field") {
            cx.stats.moves += 1;
        }
    }
}

impl Tool for Rocks {
    fn name(&self) -> &'static str {
        "rocks"
    }

    fn title(&self) -> String {
        "rock tool".into()
    }

    fn picked(&self) -> String {
        "rock tool: draw a field's outline, SW3 ends it".into()
    }

    fn counters(&self) -> &'static [Counter] {
        &[Counter {
            key: "rock_fields",
            noun: Some("rock field"),
        }]
    }

    fn clear_hover(&mut self) {
        self.hover = None;
    }

    fn hover(&mut self, cx: &mut Context, g: Point) {
        self.hover = field_at(cx.editor.document(), g);
    }

    /// A closed outline becomes a rock field.
    fn stroke(&mut self, cx: &mut Context, positions: &[Point]) {
        let Some(shape) = stroke::classify(positions, &tolerances(cx)) else {
            return;
        };
        if shape.kind != FigureKind::Closed {
            cx.refuse(format!(
                "a rock field needs a closed outline (this was a {}): come back to the start",
                shape.kind.name()
            ));
            return;
        }
        let index = cx.editor.document().rocks.len();
        let field = new_field(&shape.points, cx.view, index as u64 + 1);
        if cx.commit(Edit::AddRocks { index, field }, &format!("rock field {index}")) {
            cx.stats.count("rock_fields");
            let n = cx
                .editor
                .rocks()
                .fields()
                .get(index)
                .map_or(0, |f| f.scatter.rocks.len());
            cx.say(format!("added rock field {index}: {n} rocks"));
        }
    }

    fn grab(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) -> bool {
        let Some(index) = field_at(cx.editor.document(), g) else {
            cx.say("no rock field here to grab".into());
            return false;
        };
        self.grab = Some(FieldGrab {
            index,
            at_mm: [p.u_mm, p.v_mm],
            by: [0.0, 0.0],
            moving: false,
            tuning: None,
            tuned: false,
        });
        true
    }

    fn motion(&mut self, cx: &mut Context, g: Point, p: DisplayPoint) {
        let Some(grab) = &mut self.grab else { return };
        let slid = (p.u_mm - grab.at_mm[0]).hypot(p.v_mm - grab.at_mm[1]);
        if let Some((start, _, _)) = grab.tuning {
            let density = ((p.u_mm - start[0]) * GAIN_PER_MM).exp();
            let size = ((p.h_mm - start[1]) * GAIN_PER_MM).exp();
            grab.tuning = Some((start, density, size));
        } else if cx.sw[0] && !grab.tuned && (grab.moving || slid > cx.tuning.move_mm) {
            grab.moving = true;
            let from = cx.view.to_ground(grab.at_mm[0], grab.at_mm[1]);
            grab.by = [g[0] - from[0], g[1] - from[1]];
        }
    }

    fn tip_up(&mut self, cx: &mut Context) -> Release {
        if !self.grab.as_ref().is_some_and(|g| g.moving) {
            return Release::Keep;
        }
        self.drop_field(cx);
        self.grab = None;
        Release::Armed
    }

    fn sw2_up(&mut self, cx: &mut Context) -> Release {
        self.drop_field(cx);
        self.grab = None;
        Release::Idle
    }

    fn sw3_down(&mut self, cx: &mut Context) -> Release {
        if let Some(grab) = &mut self.grab
            && let Some(p) = cx.pen
            && !grab.moving
        {
            grab.tuning = Some(([p.u_mm, p.h_mm], 1.0, 1.0));
            grab.tuned = true;
        }
        Release::Keep
    }

    /// Sets the density and size the gesture chose, as one edit.
    fn sw3_up(&mut self, cx: &mut Context) {
        let Some(grab) = &mut self.grab else { return };
        let Some((_, density, size)) = grab.tuning.take() else {
            return;
        };
        let index = grab.index;
        let Some(field) = cx.editor.document().rocks.get(index) else {
            return;
        };
        let field = tuned(field, density, size);
        if cx.commit(Edit::ReplaceRocks { index, field }, "the rock field's density and size") {
            cx.say(format!("rock field {index}: density ×{density:.2}, size ×{size:.2}"));
        }
    }

    fn lost(&mut self, cx: &mut Context, reason: &str) -> Release {
        cx.say(format!("pen lost ({reason}): the rock field stays where it was"));
        self.grab = None;
        Release::Idle
    }

    fn delete(&mut self, cx: &mut Context) {
        let Some(index) = self.field() else {
            cx.say("no rock field highlighted to delete".into());
            return;
        };
        if cx.commit(Edit::DeleteRocks { index }, "delete") {
            cx.stats.deletes += 1;
            self.hover = None;
        }
    }

    fn status(&self, seen: &Seen) -> Option<String> {
        Some(match (seen.phase, &self.grab) {
            (Phase::Held, Some(g)) => match g.tuning {
                Some((_, d, z)) => format!(
                    "rock field {}: density ×{d:.2}, size ×{z:.2} | sideways: density, up/down: size",
                    g.index
                ),
                None if g.moving => format!("moving rock field {} | lift to drop", g.index),
                None => format!("rock field {}: slide to move | SW3 + move: density, size", g.index),
            },
            (Phase::Idle, _) => match self.hover {
                Some(i) => format!("rocks: rock field {i}: SW2 + touch grabs it | tap the palette for figures"),
                None => "rocks: draw a field's outline | SW3 ends it | tap the palette for figures".to_string(),
            },
            (Phase::Armed, _) => "rocks: SW2: touch a rock field to grab it | SW3: redo".to_string(),
            _ => return None,
        })
    }

    /// Every field's outline: the held one where the pen takes it (grey where dropping it
    /// deletes it), the one under the pen highlighted while the tool is on.
    fn overlays(&self, seen: &Seen, active: bool, layers: &mut Layers) {
        let doc = seen.doc;
        let moving = self.moving(doc);
        for (i, f) in doc.rocks.iter().enumerate() {
            let (points, colour) = match &moving {
                Some((m, pts)) if *m == i && outside_every_region(doc, pts) => (pts.clone(), DELETING_COLOUR),
                Some((m, pts)) if *m == i => (pts.clone(), MOVING_COLOUR),
                _ => (f.outline_at(), ROCK_FIELD_COLOUR),
            };
            let line = Layers::line(points, true, colour, 2.0);
            if active && self.field() == Some(i) {
                layers.push_selected(line);
            } else {
                layers.push(line);
            }
        }
    }

    fn help(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("SW1 outline, SW3", "a rock field inside it"),
            ("SW2 + touch a field", "grab it; slide to move it"),
            ("held, SW3 + move", "sideways: density; up, down: rock size"),
            ("Del", "delete the highlighted field"),
        ]
    }
}
