//! The pen interaction driven by scripted pen events: each gesture of seed 000's section 3.2
//! gives the expected document.
//!
//! The script moves an ideal pen (no noise) and samples it at the device's 153.8 Hz; the samples
//! go through the host's real event detector, so the events arrive in the order and with the
//! fields a device's do.

use glam::DVec3;
use pen_host::calibration::{Calibration, DisplaySize};
use pen_host::events::{EventDetector, PenEvent};
use pen_host::sample::Sample;
use pen_protocol::Quality;
use penmodel::interaction::figures::Figures;
use penmodel::interaction::ridge::Ridges;
use penmodel::interaction::river::Rivers;
use penmodel::interaction::{Interaction, KeyCommand, Tuning, View};
use penmodel_terrain::{Document, Editor, FigureKind, FigurePath, Grid, Point, generate};

const HOVER: f64 = 40.0;
const CYCLE_US: u64 = 6_500;

/// An ideal pen on the reference display, fed straight into an interaction.
struct Pen {
    at: DVec3,
    sw: [bool; 3],
    t_us: u64,
    seq: u16,
    detector: EventDetector,
    calibration: Calibration,
    events: Vec<PenEvent>,
    editor: Editor,
    ui: Interaction,
}

impl Pen {
    fn new(doc: Document) -> Pen {
        let view = View::fit([600.0, 340.0], &doc.grid);
        Pen {
            at: DVec3::new(300.0, 170.0, HOVER),
            sw: [false; 3],
            t_us: 1_000_000,
            seq: 0,
            detector: EventDetector::new(),
            calibration: Calibration::identity(DisplaySize::REFERENCE),
            events: Vec::new(),
            editor: Editor::new(doc).expect("valid"),
            ui: Interaction::new(view, Tuning::default()),
        }
    }

    fn sample(&mut self) {
        let s = Sample {
            seq: self.seq,
            device_us: self.t_us,
            host_us: self.t_us,
            sw: self.sw,
            in_range: true,
            display_frame: true,
            position_mm: self.at,
            quality: Quality::new(4, 0.5, 1.5),
        };
        let mut out = Vec::new();
        self.detector.on_sample(&s, self.calibration.point(self.at), &mut out);
        for ev in &out {
            self.ui.handle(&mut self.editor, ev);
        }
        self.events.extend(out);
        self.t_us += CYCLE_US;
        self.seq = self.seq.wrapping_add(1);
    }

    /// Moves in a straight line at 300 mm/s, one sample per cycle.
    fn move_to(&mut self, to: DVec3) -> &mut Self {
        let from = self.at;
        let n = ((to - from).length() / (300.0 * CYCLE_US as f64 * 1e-6))
            .ceil()
            .max(1.0) as usize;
        for i in 1..=n {
            self.at = from.lerp(to, i as f64 / n as f64);
            self.sample();
        }
        self
    }

    fn hold(&mut self, seconds: f64) -> &mut Self {
        for _ in 0..(seconds * 1e6 / CYCLE_US as f64) as usize {
            self.sample();
        }
        self
    }

    fn set(&mut self, switch: usize, pressed: bool) -> &mut Self {
        self.sw[switch] = pressed;
        self.sample();
        self
    }

    fn hover(&mut self, u: f64, v: f64) -> &mut Self {
        self.move_to(DVec3::new(u, v, HOVER))
    }

    fn touch(&mut self) -> &mut Self {
        let down = self.at.with_z(0.0);
        self.move_to(down).set(0, true)
    }

    fn lift(&mut self, h: f64) -> &mut Self {
        self.set(0, false);
        let up = self.at.with_z(h);
        self.move_to(up)
    }

    fn drag_to(&mut self, u: f64, v: f64) -> &mut Self {
        self.move_to(DVec3::new(u, v, 0.0))
    }

    fn click(&mut self, switch: usize) -> &mut Self {
        self.set(switch, true).hold(0.1).set(switch, false)
    }

    /// Draws `points` on the surface and lifts the tip (no SW3: a tool that ends on lifting).
    fn trace(&mut self, points: &[(f64, f64)]) -> &mut Self {
        let (u, v) = points[0];
        self.hover(u, v).touch();
        for &(u, v) in &points[1..] {
            self.drag_to(u, v);
        }
        self.lift(HOVER)
    }

    fn stroke(&mut self, points: &[(f64, f64)]) -> &mut Self {
        self.trace(points).click(2)
    }

    fn closed(&mut self, points: &[(f64, f64)]) -> &mut Self {
        let mut ring = points.to_vec();
        ring.push(points[0]);
        self.stroke(&ring)
    }

    fn grab(&mut self, u: f64, v: f64) -> &mut Self {
        self.hover(u, v).set(1, true).touch()
    }

    fn pull_to(&mut self, h: f64) -> &mut Self {
        if self.sw[0] {
            self.lift(h)
        } else {
            let to = self.at.with_z(h);
            self.move_to(to)
        }
    }

    fn slope(&mut self, du: f64) -> &mut Self {
        let to = self.at + DVec3::new(du, 0.0, 0.0);
        self.set(2, true).move_to(to).set(2, false)
    }

    fn let_go(&mut self) -> &mut Self {
        self.set(1, false)
    }

    fn figures(&self) -> &Figures {
        self.ui.tool::<Figures>().expect("the figures tool")
    }

    fn doc(&self) -> &Document {
        self.editor.document()
    }

    fn view(&self) -> View {
        *self.ui.view()
    }

    /// The ground point drawn at display `(u, v)`.
    fn ground(&self, u: f64, v: f64) -> Point {
        self.view().to_ground(u, v)
    }
}

/// 480 × 272 cells of 12.5 m: the reference display at 1:10 000.
fn blank() -> Document {
    Document::new(Grid {
        cols: 480,
        rows: 272,
        cell_size: 12.5,
    })
}

const REGION: [(f64, f64); 4] = [(60.0, 40.0), (540.0, 40.0), (540.0, 300.0), (60.0, 300.0)];

/// A grove's outline for the tree tool, back to its start (mm on the display).
const GROVE_OUTLINE: [(f64, f64); 5] = [
    (300.0, 100.0),
    (420.0, 100.0),
    (420.0, 200.0),
    (300.0, 200.0),
    (300.0, 100.0),
];

fn near(a: Point, b: Point, metres: f64) -> bool {
    (a[0] - b[0]).hypot(a[1] - b[1]) <= metres
}

#[test]
fn drawing_makes_a_region_then_figures_inside_it() {
    let mut pen = Pen::new(blank());
    pen.closed(&REGION);
    assert_eq!(pen.doc().regions.len(), 1, "{:?}", pen.ui.take_messages());
    let boundary = &pen.doc().regions[0].boundary;
    assert_eq!(boundary.len(), 5, "four corners and the repeat: {boundary:?}");
    for (p, &(u, v)) in boundary.iter().zip(&REGION) {
        assert!(near(*p, pen.ground(u, v), 10.0), "{p:?} vs {:?}", (u, v));
    }

    // A touch is a point; a stroke a polyline; a loop inside the region a closed figure.
    pen.hover(150.0, 200.0).touch().lift(HOVER).click(2);
    pen.stroke(&[(250.0, 90.0), (340.0, 130.0), (430.0, 110.0)]);
    pen.closed(&[(380.0, 190.0), (480.0, 195.0), (470.0, 270.0), (390.0, 265.0)]);
    let figures = &pen.doc().regions[0].figures;
    let kinds: Vec<FigureKind> = figures.iter().map(|f| f.kind).collect();
    assert_eq!(kinds, [FigureKind::Point, FigureKind::Polyline, FigureKind::Closed]);
    assert!(near(figures[0].points[0], pen.ground(150.0, 200.0), 1e-6));
    assert_eq!(figures[1].points.len(), 3, "{:?}", figures[1].points);
    assert!(near(figures[1].points[1], pen.ground(340.0, 130.0), 10.0));
    assert_eq!(figures[2].points.len(), 5);
    assert!(figures.iter().all(|f| f.height == 0.0 && f.slope == 0.0));

    // A point inside the closed figure nests in it and starts at its height.
    pen.grab(430.0, 230.0).pull_to(40.0).let_go();
    pen.hover(430.0, 230.0).touch().lift(HOVER).click(2);
    let plateau = &pen.doc().regions[0].figures[2];
    assert_eq!(plateau.figures.len(), 1);
    assert_eq!(plateau.figures[0].height, plateau.height);
    assert_eq!(pen.ui.stats().regions, 1);
    assert_eq!(pen.ui.stats().figures, 4);
    assert_eq!(pen.ui.stats().refused, 0);
}

#[test]
fn a_figure_outside_every_region_is_refused_with_a_message() {
    let mut pen = Pen::new(blank());
    pen.hover(100.0, 100.0).touch().lift(HOVER).click(2);
    assert!(pen.doc().regions.is_empty());
    assert_eq!(pen.ui.stats().refused, 1);
    let messages = pen.ui.take_messages();
    assert!(
        messages.iter().any(|m| m.contains("outside every region")),
        "{messages:?}"
    );
}

/// The status line carries a message for a while, unless the window shows it under the line
/// (issue 42: each message was shown twice there).
#[test]
fn a_message_is_on_the_status_line_unless_the_window_shows_it() {
    let mut pen = Pen::new(blank());
    pen.hover(100.0, 100.0).touch().lift(HOVER).click(2);
    let status = pen.ui.status(pen.doc());
    assert!(status.contains("outside every region"), "{status}");
    pen.ui.set_messages_on_status(false);
    let status = pen.ui.status(pen.doc());
    assert!(!status.contains("outside every region"), "{status}");
}

#[test]
fn grab_pull_and_slope_are_one_undoable_edit() {
    let mut pen = Pen::new(blank());
    pen.closed(&REGION);
    pen.hover(150.0, 200.0).touch().lift(HOVER).click(2);
    let before = pen.doc().clone();

    // Hovering over the point highlights it.
    pen.hover(151.0, 201.0);
    let hover = pen.figures().highlighted(pen.ui.phase()).cloned().expect("highlighted");
    assert_eq!(hover.curve.to_string(), "regions[0].figures[0]");

    pen.set(1, true).touch().pull_to(90.0);
    assert!(pen.ui.pulling());
    let at = FigurePath::new(0, 0);
    let height = at.get(pen.doc()).unwrap().height;
    assert!((height - pen.view().height_at(90.0)).abs() < 1e-9, "{height}");
    // The terrain follows the pull live.
    let live = pen.editor.heightmap().clone();
    let peak = live.range().1;
    assert!(peak > 0.99 * height as f32, "peak {peak} of {height}");
    // The ground tilts while pulling.
    assert!(pen.ui.view().tilt > 0.5 * Tuning::default().pull_tilt);

    pen.slope(-40.0);
    let slope = at.get(pen.doc()).unwrap().slope;
    assert!(
        (slope - (-40.0 * Tuning::default().slope_per_mm)).abs() < 1e-9,
        "{slope}"
    );
    pen.let_go();
    assert!(!pen.ui.pulling());
    let after = pen.doc().clone();
    assert_eq!(pen.editor.heightmap(), &generate(&after).unwrap());

    // One SW3 click undoes both height and slope; SW2 + SW3 redoes.
    pen.hover(300.0, 320.0).click(2);
    assert_eq!(pen.doc(), &before);
    pen.set(1, true).click(2).set(1, false);
    assert_eq!(pen.doc(), &after);
    assert_eq!(pen.ui.stats().pulls, 1);
    assert_eq!(pen.ui.stats().slopes, 1);
    assert_eq!(pen.ui.stats().undos, 1);
    assert_eq!(pen.ui.stats().redos, 1);
}

#[test]
fn sliding_a_grab_moves_a_vertex_or_the_figure_and_outside_deletes_it() {
    let mut pen = Pen::new(blank());
    pen.closed(&REGION);
    pen.stroke(&[(250.0, 90.0), (340.0, 130.0), (430.0, 110.0)]);
    pen.hover(150.0, 200.0).touch().lift(HOVER).click(2);
    let ridge = FigurePath::new(0, 0);
    let original = ridge.get(pen.doc()).unwrap().points.clone();

    // At a vertex: that vertex moves, the others stay.
    pen.grab(340.0, 130.0).drag_to(340.0, 160.0).lift(HOVER).let_go();
    let moved = ridge.get(pen.doc()).unwrap().points.clone();
    assert!(near(moved[1], pen.ground(340.0, 160.0), 10.0), "{:?}", moved[1]);
    assert_eq!(moved[0], original[0]);
    assert_eq!(moved[2], original[2]);

    // On the line between vertices: the whole figure moves.
    pen.grab(295.0, 125.0).drag_to(295.0, 105.0).lift(HOVER).let_go();
    let shifted = ridge.get(pen.doc()).unwrap().points.clone();
    let by = [shifted[0][0] - moved[0][0], shifted[0][1] - moved[0][1]];
    assert!(
        near(by, [0.0, 200.0], 10.0),
        "moved 20 mm down the display = 200 m: {by:?}"
    );

    // Dragged out of its region and dropped: deleted.
    pen.grab(150.0, 200.0).drag_to(30.0, 200.0);
    let moving = pen.figures().moving(pen.editor.document()).expect("moving");
    assert!(moving.deleting);
    pen.lift(HOVER).let_go();
    assert_eq!(pen.doc().regions[0].figures.len(), 1);
    assert_eq!(pen.ui.stats().moves, 2);
    assert_eq!(pen.ui.stats().deletes, 1);
    // Undo brings it back.
    pen.hover(300.0, 320.0).click(2);
    assert_eq!(pen.doc().regions[0].figures.len(), 2);
}

#[test]
fn sw3_held_and_moved_pans_and_zooms_without_undoing() {
    let mut pen = Pen::new(blank());
    pen.closed(&REGION);
    let doc = pen.doc().clone();
    let grabbed = pen.ground(200.0, 150.0);
    pen.hover(200.0, 150.0)
        .set(2, true)
        .move_to(DVec3::new(260.0, 120.0, HOVER))
        .set(2, false);
    assert_eq!(pen.doc(), &doc, "a pan is not an undo");
    // The ground point under the pen at the press is under it still.
    assert!(near(pen.ground(260.0, 120.0), grabbed, 1e-6));
    // Lowering the pen zooms in about it.
    let scale = pen.view().scale;
    pen.set(2, true).move_to(DVec3::new(260.0, 120.0, 10.0)).set(2, false);
    assert!(pen.view().scale > 1.2 * scale, "{} vs {scale}", pen.view().scale);
    assert!(near(pen.ground(260.0, 120.0), grabbed, 1e-6));
    pen.ui.command(&mut pen.editor, KeyCommand::Fit);
    assert_eq!(pen.view().scale, scale);
    assert_eq!(pen.ui.stats().undos, 0);
}

#[test]
fn losing_the_pen_mid_pull_cancels_the_pull_and_keeps_the_document() {
    let mut pen = Pen::new(blank());
    pen.closed(&REGION);
    pen.hover(150.0, 200.0).touch().lift(HOVER).click(2);
    let before = pen.doc().clone();
    pen.grab(150.0, 200.0).pull_to(70.0);
    assert!(FigurePath::new(0, 0).get(pen.doc()).unwrap().height > 0.0);
    let mut out = Vec::new();
    pen.detector.on_device_lost(pen.t_us, "unplugged", &mut out);
    for ev in &out {
        pen.ui.handle(&mut pen.editor, ev);
    }
    assert_eq!(pen.doc(), &before);
    assert_eq!(pen.editor.heightmap(), &generate(&before).unwrap());
    assert!(!pen.editor.can_redo());
    assert!(pen.ui.take_messages().iter().any(|m| m.contains("pen lost")));
    // The pen comes back and the session goes on. The notice carries the host's clock (µs since
    // 1970), which must not upset the device-clock timing of what follows.
    let mut out = Vec::new();
    pen.detector.on_device_found(1_763_700_000_000_000, "sim", &mut out);
    for ev in &out {
        pen.ui.handle(&mut pen.editor, ev);
    }
    pen.sw = [false; 3];
    pen.grab(150.0, 200.0).pull_to(50.0).let_go();
    let h = FigurePath::new(0, 0).get(pen.doc()).unwrap().height;
    assert!((h - pen.view().height_at(50.0)).abs() < 1e-9);
    // A click is still a click, and the ground has tilted back.
    pen.hover(300.0, 320.0).hold(1.5).click(2);
    assert_eq!(pen.ui.stats().undos, 1);
    assert_eq!(pen.doc(), &before);
    assert!(pen.ui.view().tilt < 0.01, "tilt {}", pen.ui.view().tilt);
}

/// The rock tool (issue 11): tapping the palette button picks it; an outline becomes a rock field.
#[test]
fn the_rock_tool_draws_moves_and_tunes_a_field() {
    let mut pen = Pen::new(blank());
    pen.closed(&REGION);
    // A tap on the palette button (8 to 28 mm in the corner) picks the rock tool.
    pen.hover(18.0, 18.0).touch().lift(HOVER);
    assert_eq!(pen.ui.tool_name(), "rocks");
    let outline = [(150.0, 100.0), (260.0, 100.0), (260.0, 180.0), (150.0, 180.0)];
    pen.closed(&outline);
    assert_eq!(pen.doc().rocks.len(), 1, "{:?}", pen.ui.take_messages());
    assert_eq!(pen.doc().regions[0].figures.len(), 0, "the outline is no figure");
    let field = pen.doc().rocks[0].clone();
    for (p, &(u, v)) in field.outline_at().iter().zip(&outline) {
        assert!(near(*p, pen.ground(u, v), 10.0), "{p:?} vs {:?}", (u, v));
    }
    let rocks = pen.editor.rocks().fields()[0].scatter.rocks.len();
    assert!(rocks > 100, "{rocks} rocks");
    assert_eq!(pen.ui.stats().made("rock_fields"), 1);

    // SW2 + touch inside it and a slide moves it by the slide: the same rocks.
    pen.grab(200.0, 140.0).drag_to(230.0, 150.0).lift(HOVER).let_go();
    let moved = &pen.doc().rocks[0];
    let by = [moved.at[0] - field.at[0], moved.at[1] - field.at[1]];
    let expected = {
        let (a, b) = (pen.ground(200.0, 140.0), pen.ground(230.0, 150.0));
        [b[0] - a[0], b[1] - a[1]]
    };
    assert!(near(by, expected, 5.0), "moved by {by:?}, slid {expected:?}");
    assert_eq!(moved.outline, field.outline);
    assert_eq!(
        pen.editor.rocks().fields()[0].scatter.rocks.len(),
        rocks,
        "a move scatters nothing new"
    );

    // Held, SW3 and a move right and up: denser and bigger, one edit.
    pen.grab(215.0, 145.0);
    pen.set(2, true).set(0, false);
    let to = pen.at + DVec3::new(35.0, 0.0, 20.0);
    pen.move_to(to).set(2, false).let_go();
    let tuned = &pen.doc().rocks[0];
    let density = (35.0f64 * 0.02).exp();
    for (a, b) in tuned.layers.iter().zip(&field.layers) {
        assert!(a.radius > b.radius * 1.3, "radius {} from {}", a.radius, b.radius);
        let (fa, fb) = (a.fraction.unwrap_or(0.0), b.fraction.unwrap_or(0.0));
        // Fig. 1's fractions sum to 1: denser is capped at the whole field.
        assert!(fa <= fb * density + 1e-9, "fraction {fa} from {fb}");
    }
    // Undo: the density and size, then the move, then the field.
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc().rocks[0].layers, field.layers);
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc().rocks[0], field);

    // Delete (the keyboard's) removes the highlighted field; undo brings it back.
    pen.hover(215.0, 145.0);
    pen.ui.command(&mut pen.editor, KeyCommand::Delete);
    assert!(pen.doc().rocks.is_empty());
    pen.ui.command(&mut pen.editor, KeyCommand::Undo);
    assert_eq!(pen.doc().rocks.len(), 1);

    // Back to figures: a tap on the palette again; an open stroke with the rock tool is refused.
    pen.hover(18.0, 18.0).touch().lift(HOVER);
    assert_eq!(pen.ui.tool_name(), "figures");
    pen.hover(18.0, 18.0).touch().lift(HOVER);
    pen.stroke(&[(300.0, 200.0), (400.0, 220.0)]);
    assert_eq!(pen.doc().rocks.len(), 1);
    let messages = pen.ui.take_messages();
    assert!(
        messages.iter().any(|m| m.contains("needs a closed outline")),
        "{messages:?}"
    );
}

/// A rock field dropped outside every region is deleted, as a figure dropped outside its region.
#[test]
fn a_rock_field_dropped_outside_every_region_goes() {
    let mut pen = Pen::new(blank());
    pen.closed(&[(200.0, 100.0), (400.0, 100.0), (400.0, 250.0), (200.0, 250.0)]);
    pen.hover(18.0, 18.0).touch().lift(HOVER);
    pen.closed(&[(250.0, 150.0), (320.0, 150.0), (320.0, 200.0), (250.0, 200.0)]);
    assert_eq!(pen.doc().rocks.len(), 1, "{:?}", pen.ui.take_messages());
    // Slid 250 mm to the right: every vertex beyond the region's right edge.
    pen.grab(285.0, 175.0).drag_to(535.0, 175.0).lift(HOVER).let_go();
    assert!(pen.doc().rocks.is_empty(), "{:?}", pen.ui.take_messages());
    assert_eq!(pen.ui.stats().deletes, 1);
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc().rocks.len(), 1);
}

/// The tree tool (issue 14): the tree button picks it (and, tapped again, the next preset); an
/// SW1 tap plants a tree, an outline back to its start a grove; SW2 grabs and slides either; a
/// pull sets a tree's height, SW3 sideways its height or a grove's density; each one undoable edit.
#[test]
fn the_tree_tool_plants_moves_and_sizes_trees_and_groves() {
    // The reference display shows the 6000 m grid on 600 mm: 10 m per mm, across and up.
    const M_PER_MM: f64 = 10.0;
    let mut pen = Pen::new(blank());
    // The tree button is the square 8 to 28 mm across and 56 to 76 mm down.
    pen.hover(18.0, 66.0).touch().lift(HOVER);
    assert_eq!(pen.ui.tool_name(), "trees");

    // A tap plants one table-3.1 tree where it touched, 8 mm tall on the display, swaying.
    pen.hover(200.0, 150.0).touch().lift(HOVER);
    assert_eq!(pen.doc().trees.len(), 1, "{:?}", pen.ui.take_messages());
    let tree = pen.doc().trees[0].clone();
    assert!(near(tree.at, pen.ground(200.0, 150.0), 1.0), "{:?}", tree.at);
    assert_eq!(tree.preset.as_deref(), Some("table-3.1"));
    assert!((tree.height - 8.0 * M_PER_MM).abs() < 1e-6, "{}", tree.height);
    assert!(tree.wind.is_some(), "a planted tree sways");
    // The button again: the next preset.
    pen.hover(18.0, 66.0).touch().lift(HOVER);
    assert_eq!(pen.ui.tool_name(), "trees");
    pen.hover(250.0, 150.0).touch().lift(HOVER);
    assert_eq!(pen.doc().trees.len(), 2);
    assert_eq!(pen.doc().trees[1].preset.as_deref(), Some("sample-3.2"));
    assert_eq!(pen.ui.stats().made("trees"), 2);

    // An outline back to its start plants a grove; lifting the tip ends it (no SW3).
    let outline = GROVE_OUTLINE;
    pen.trace(&outline);
    assert_eq!(pen.doc().groves.len(), 1, "{:?}", pen.ui.take_messages());
    assert_eq!(pen.doc().trees.len(), 2, "the outline planted no single tree");
    let grove = pen.doc().groves[0].clone();
    for &(u, v) in &outline[..4] {
        let g = pen.ground(u, v);
        let d = grove
            .region
            .iter()
            .map(|p| (p[0] - g[0]).hypot(p[1] - g[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 2.0 * M_PER_MM, "corner {:?} is {d} m from the region", (u, v));
    }
    // Trees 4 mm (40 m) apart: saturated random disks of diameter 40 m cover 0.547 of the plane.
    let per_m2 = 4.0 * 0.547 / (std::f64::consts::PI * 40.0 * 40.0);
    let expected = per_m2 * (120.0 * M_PER_MM) * (100.0 * M_PER_MM);
    let n = penmodel_terrain::trees::grove::trees(&grove).len() as f64;
    assert!((n / expected - 1.0).abs() < 0.2, "{n} trees, expected about {expected}");
    assert_eq!(pen.ui.stats().made("groves"), 1);

    // SW2 + touch on the first tree and a slide moves it by the slide.
    let second_at = pen.doc().trees[1].at;
    pen.grab(200.0, 150.0).drag_to(230.0, 160.0).lift(HOVER).let_go();
    let moved = pen.doc().trees[0].clone();
    assert!(
        near(moved.at, pen.ground(230.0, 160.0), 0.5 * M_PER_MM),
        "{:?}",
        moved.at
    );
    assert_eq!(moved.height, tree.height);
    assert_eq!(pen.doc().trees[1].at, second_at, "the other tree stays");

    // Held and lifted: the pull; the top follows the pen, 20 mm up is 200 m.
    pen.grab(230.0, 160.0).pull_to(20.0).hold(0.2).let_go();
    let pulled = pen.doc().trees[0].height;
    assert!(
        (pulled - 20.0 * M_PER_MM).abs() < 0.2 * M_PER_MM,
        "pulled to {pulled} m"
    );
    assert_eq!(pen.doc().trees[0].at, moved.at, "a pull moves nothing");

    // Held, SW3 and 35 mm right: the height × e^(0.02 × 35).
    pen.grab(230.0, 160.0);
    pen.set(2, true).set(0, false);
    let to = pen.at + DVec3::new(35.0, 0.0, 0.0);
    pen.move_to(to).set(2, false).let_go();
    let taller = pen.doc().trees[0].height;
    assert!(
        (taller / pulled - (0.02f64 * 35.0).exp()).abs() < 0.01,
        "{taller} m from {pulled} m"
    );

    // The grove held, SW3 and 35 mm left: sparser by e^(−0.7).
    pen.grab(360.0, 150.0);
    pen.set(2, true).set(0, false);
    let to = pen.at + DVec3::new(-35.0, 0.0, 0.0);
    pen.move_to(to).set(2, false).let_go();
    let sparser = pen.doc().groves[0].density;
    assert!(
        (sparser / grove.density - (-0.7f64).exp()).abs() < 0.01,
        "{sparser} from {}",
        grove.density
    );
    // And slid: its region moves by the slide.
    pen.grab(360.0, 150.0).drag_to(380.0, 170.0).lift(HOVER).let_go();
    let shifted = &pen.doc().groves[0];
    let (a, b) = (pen.ground(360.0, 150.0), pen.ground(380.0, 170.0));
    let by = [
        shifted.region[0][0] - grove.region[0][0],
        shifted.region[0][1] - grove.region[0][1],
    ];
    assert!(near(by, [b[0] - a[0], b[1] - a[1]], 0.5 * M_PER_MM), "moved by {by:?}");

    // Each was one edit: undo the grove's move and density, the tree's height twice and its move.
    for _ in 0..2 {
        pen.editor.undo().expect("undo");
    }
    assert_eq!(pen.doc().groves[0], grove);
    for _ in 0..3 {
        pen.editor.undo().expect("undo");
    }
    assert_eq!(pen.doc().trees[0], tree);

    // An open stroke is refused with a message; a tap on the button for each remaining preset,
    // and one more: figures.
    pen.hover(100.0, 250.0).touch().drag_to(200.0, 260.0).lift(HOVER);
    assert_eq!(pen.doc().groves.len(), 1);
    let messages = pen.ui.take_messages();
    assert!(
        messages.iter().any(|m| m.contains("grove needs an outline")),
        "{messages:?}"
    );
    for _ in 1..penmodel_terrain::trees::Preset::ALL.len() {
        pen.hover(18.0, 66.0).touch().lift(HOVER);
    }
    assert_eq!(pen.ui.tool_name(), "figures");
}

/// The tree tool's pull and SW3 gesture show as they go (issue 14): before the release, the held
/// tree's height in the document and in the editor's standing forest follows the pen, with nothing
/// journaled; the release records one edit (one journal line, one undo step). A grove's pull
/// scales its standing trees. Losing the pen mid-pull restores the tree.
#[test]
fn a_tree_pull_shows_as_it_goes_and_records_one_edit() {
    use penmodel_terrain::trees::Source;
    // The reference display shows the 6000 m grid on 600 mm: 10 m per mm, across and up.
    const M_PER_MM: f64 = 10.0;
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("trees.json");
    let mut pen = Pen::new(blank());
    pen.editor = Editor::create(&path, blank()).expect("create");
    let lines = |path: &std::path::Path| {
        std::fs::read_to_string(penmodel_terrain::journal::path_for(path)).map_or(0, |t| t.lines().count())
    };
    pen.hover(18.0, 66.0).touch().lift(HOVER);
    pen.hover(200.0, 150.0).touch().lift(HOVER);
    let planted = pen.doc().trees[0].clone();
    let before = lines(&path);

    pen.grab(200.0, 150.0);
    for h_mm in [10.0, 25.0, 15.0] {
        pen.pull_to(h_mm);
        let shown = pen.doc().trees[0].height;
        assert!(
            (shown - h_mm * M_PER_MM).abs() < 0.2 * M_PER_MM,
            "{shown} m at {h_mm} mm"
        );
        let standing = &pen.editor.trees().trees()[0];
        assert_eq!(standing.source, Source::Tree(0));
        assert_eq!(standing.height, shown, "the forest draws the height shown");
        assert!(pen.editor.previewing());
        assert_eq!(lines(&path), before, "nothing journaled while pulling");
    }
    pen.let_go();
    let set = pen.doc().trees[0].height;
    assert!((set - 15.0 * M_PER_MM).abs() < 0.2 * M_PER_MM, "{set} m");
    assert!(!pen.editor.previewing());
    assert_eq!(lines(&path), before + 1, "one journal entry");
    assert_eq!(pen.ui.stats().pulls, 1);
    // One undo step: it returns to the planted tree, the next undoes the planting.
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc().trees[0], planted);
    pen.editor.undo().expect("undo");
    assert!(pen.doc().trees.is_empty());
    pen.editor.redo().expect("redo");
    pen.editor.redo().expect("redo");
    assert_eq!(pen.doc().trees[0].height, set);

    // SW3 and 20 mm right: the height × e^(0.02 × 20) shows before SW3 is released, then is set.
    let before = lines(&path);
    pen.grab(200.0, 150.0);
    pen.set(2, true).set(0, false);
    let to = pen.at + DVec3::new(20.0, 0.0, 0.0);
    pen.move_to(to);
    let k = (0.02f64 * 20.0).exp();
    assert!((pen.doc().trees[0].height / set - k).abs() < 0.01, "shown while held");
    assert!((pen.editor.trees().trees()[0].height / set - k).abs() < 0.01);
    assert_eq!(lines(&path), before);
    pen.set(2, false).let_go();
    assert!((pen.doc().trees[0].height / set - k).abs() < 0.01);
    assert_eq!(lines(&path), before + 1, "one journal entry");
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc().trees[0].height, set);

    // A grove's pull: its standing trees are scattered again at the height shown, 0.8 to 1.2 of it.
    let outline = GROVE_OUTLINE;
    pen.trace(&outline);
    assert_eq!(pen.doc().groves.len(), 1, "{:?}", pen.ui.take_messages());
    pen.grab(360.0, 150.0).pull_to(30.0);
    let mean = pen.doc().groves[0].height;
    assert!((mean - 30.0 * M_PER_MM).abs() < 0.2 * M_PER_MM, "{mean} m");
    let grove: Vec<f64> = pen
        .editor
        .trees()
        .trees()
        .iter()
        .filter(|t| matches!(t.source, Source::Grove(0, _)))
        .map(|t| t.height)
        .collect();
    assert!(!grove.is_empty());
    assert!(
        grove
            .iter()
            .all(|h| (0.8 * mean - 1e-9..=1.2 * mean + 1e-9).contains(h)),
        "{grove:?}"
    );
    pen.let_go();
    assert!(!pen.editor.previewing());

    // Lost mid-pull: the tree is as it was before the grab.
    let doc = pen.doc().clone();
    pen.grab(200.0, 150.0).pull_to(40.0);
    assert_ne!(pen.doc(), &doc, "the pull shows");
    let mut out = Vec::new();
    pen.detector.on_device_lost(pen.t_us, "unplugged", &mut out);
    for ev in &out {
        pen.ui.handle(&mut pen.editor, ev);
    }
    assert_eq!(pen.doc(), &doc);
    assert_eq!(pen.editor.trees().trees()[0].height, doc.trees[0].height);
    assert!(!pen.editor.previewing());
}

/// The river tool (issue 13): the river button picks it; a stroke becomes a river fitted to
/// Bézier segments; an SW3 click over it adds a year; SW2 on a control point reshapes it, with
/// the next year's erosion and deposition previewed; SW2 + SW3 sideways widens it.
#[test]
fn the_river_tool_draws_ages_reshapes_and_widens_a_river() {
    let mut pen = Pen::new(blank());
    pen.closed(&REGION);
    // The river button: 8 to 28 mm across, 32 to 52 mm down.
    pen.hover(18.0, 42.0).touch().lift(HOVER);
    assert_eq!(pen.ui.tool_name(), "rivers");
    let course = [
        (100.0, 250.0),
        (180.0, 170.0),
        (260.0, 230.0),
        (340.0, 150.0),
        (420.0, 210.0),
        (500.0, 120.0),
    ];
    pen.stroke(&course);
    assert_eq!(pen.doc().rivers.len(), 1, "{:?}", pen.ui.take_messages());
    assert_eq!(pen.doc().regions[0].figures.len(), 0, "the course is no figure");
    let river = pen.doc().rivers[0].clone();
    assert_eq!(river.points.len() % 3, 1, "whole cubic segments");
    assert_eq!(pen.ui.stats().made("rivers"), 1);
    assert!(near(river.points[0], pen.ground(100.0, 250.0), 15.0));
    assert!(near(
        *river.points.last().expect("points"),
        pen.ground(500.0, 120.0),
        15.0
    ));
    // A year: SW3 click over the course.
    pen.hover(180.0, 170.0).click(2);
    let years = pen.doc().rivers[0].iterations;
    assert_eq!(years, 1, "{:?}", pen.ui.take_messages());
    // SW2 on control point 3 and a slide: the point moves by the slide, the preview shows.
    let p3 = pen.view().to_display(pen.doc().rivers[0].points[3]);
    pen.grab(p3[0], p3[1]).drag_to(p3[0] + 20.0, p3[1] + 10.0);
    let rivers = pen.ui.tool::<Rivers>().expect("the river tool");
    let (erosion, deposition) = rivers.preview().cloned().expect("a preview while reshaping");
    assert!(!erosion.is_empty() && !deposition.is_empty());
    pen.lift(HOVER).let_go();
    let moved = pen.doc().rivers[0].clone();
    let by = [
        moved.points[3][0] - river.points[3][0],
        moved.points[3][1] - river.points[3][1],
    ];
    let slide = {
        let (a, b) = (pen.ground(p3[0], p3[1]), pen.ground(p3[0] + 20.0, p3[1] + 10.0));
        [b[0] - a[0], b[1] - a[1]]
    };
    assert!(near(by, slide, 15.0), "moved by {by:?}, slid {slide:?}");
    assert_eq!(moved.points[0], river.points[0], "only the held point moves");
    // The drag's preview redid only part of the course; the river committed is processed whole:
    // the engine's shape is a full rebuild of the moved entry, exactly.
    let rebuilt = penmodel_terrain::river::Shape::process(
        &moved,
        &pen.doc().grid,
        &penmodel_terrain::river::Constants::default(),
    );
    assert_eq!(pen.editor.terrain().rivers().shape(0), Some(&rebuilt));
    // Held on its course, SW3 and a move right and up: wider and deeper, one edit.
    let on = pen.view().to_display(moved.points[0]);
    pen.grab(on[0], on[1]);
    pen.set(2, true).set(0, false);
    let to = pen.at + DVec3::new(35.0, 0.0, 20.0);
    pen.move_to(to).set(2, false).let_go();
    let wide = &pen.doc().rivers[0];
    assert!(
        wide.width > moved.width * 1.5 && wide.depth > moved.depth * 1.2,
        "{wide:?}"
    );
    // Undo: the width, the point, the year, the river.
    for _ in 0..4 {
        pen.editor.undo().expect("undo");
    }
    assert!(pen.doc().rivers.is_empty());
    // Back to figures with the button again.
    pen.hover(18.0, 42.0).touch().lift(HOVER);
    assert_eq!(pen.ui.tool_name(), "figures");
}

/// Several years in one gesture (issue 13): SW3 held still over a river counts on past the click,
/// one year per `river::YEAR_HOLD_US`, the count on the status line; the release commits them as
/// one edit; a press that moves pans and commits none; the count stops at the most years.
#[test]
fn sw3_held_over_a_river_commits_the_years_counted() {
    use penmodel::interaction::river::YEAR_HOLD_US;
    use penmodel_terrain::river::MAX_ITERATIONS;
    let mut pen = Pen::new(blank());
    pen.closed(&REGION);
    pen.hover(18.0, 42.0).touch().lift(HOVER);
    pen.stroke(&[(100.0, 250.0), (200.0, 170.0), (300.0, 230.0), (400.0, 160.0)]);
    assert_eq!(pen.doc().rivers.len(), 1, "{:?}", pen.ui.take_messages());
    let click_us = Tuning::default().click_us;
    // The years a press from `t0` to `t1` should give: 1, and one per YEAR_HOLD_US past a click.
    let want = |t0: u64, t1: u64| 1 + (t1 - t0).saturating_sub(click_us) / YEAR_HOLD_US;
    pen.hover(200.0, 170.0);
    let t0 = pen.t_us;
    pen.set(2, true).hold(1.4);
    let t1 = pen.t_us;
    let n = want(t0, t1);
    assert!(n >= 2, "held {} µs", t1 - t0);
    let status = pen.ui.status(pen.doc());
    assert!(status.contains(&format!("+{n} years")), "{status}");
    assert_eq!(pen.doc().rivers[0].iterations, 0, "nothing committed while held");
    pen.set(2, false);
    let years = pen.doc().rivers[0].iterations;
    assert_eq!(u64::from(years), n, "{:?}", pen.ui.take_messages());
    // One edit: one undo takes them all back.
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc().rivers[0].iterations, 0);
    pen.editor.redo().expect("redo");
    // A click is still one year.
    pen.click(2);
    assert_eq!(u64::from(pen.doc().rivers[0].iterations), n + 1);
    // Held and moved: a pan, no year.
    let before = pen.doc().clone();
    pen.set(2, true)
        .move_to(DVec3::new(260.0, 120.0, HOVER))
        .hold(1.4)
        .set(2, false);
    assert_eq!(pen.doc(), &before, "a pan commits no year");
    // Held long: the most years a river may have, and no more.
    pen.ui.command(&mut pen.editor, KeyCommand::Fit);
    pen.hover(200.0, 170.0).set(2, true).hold(12.0).set(2, false);
    let years = pen.doc().rivers[0].iterations;
    assert_eq!(years, MAX_ITERATIONS, "{:?}", pen.ui.take_messages());
}

#[test]
fn the_ridge_tool_draws_lines_in_the_air_trees_on_the_surface_pulls_grows_and_deletes() {
    use penmodel::interaction::ridge::Part;
    use penmodel_terrain::ridge::layer::tree_of;
    let mut pen = Pen::new(blank());
    // The ridge button: the top right corner, 572 to 592 mm across, 8 to 28 mm down.
    pen.hover(582.0, 18.0).touch().lift(HOVER);
    assert_eq!(pen.ui.tool_name(), "ridges");
    let view = pen.view();
    // A 3D ridgeline: touch at its start, lift and draw in the air at 30 then 50 mm, touch
    // again at its end (snapped to the surface), SW3.
    pen.hover(100.0, 150.0).touch().lift(30.0);
    pen.move_to(DVec3::new(200.0, 150.0, 30.0));
    pen.move_to(DVec3::new(300.0, 170.0, 50.0));
    pen.move_to(DVec3::new(380.0, 170.0, 20.0)).touch();
    pen.lift(HOVER).click(2);
    let r = pen.doc().ridges.clone().expect("a ridges entry");
    assert_eq!((r.lines.len(), r.trees.len()), (1, 0), "{:?}", pen.ui.take_messages());
    let line = &r.lines[0].points;
    // Independently: each node's elevation is the pen's height above its place on the straight
    // moves drawn (0 at the two touches, where the ground was flat).
    let height_along = |x: f64| {
        let u = view.to_display([x, 0.0])[0];
        let legs = [
            (100.0, 0.0),
            (100.0, 30.0),
            (200.0, 30.0),
            (300.0, 50.0),
            (380.0, 20.0),
            (380.0, 0.0),
        ];
        legs.windows(2)
            .find(|w| u >= w[0].0 && u <= w[1].0 && w[1].0 > w[0].0)
            .map_or(0.0, |w| w[0].1 + (u - w[0].0) / (w[1].0 - w[0].0) * (w[1].1 - w[0].1))
    };
    assert!(line.len() >= 10, "{line:?}");
    for p in &line[1..line.len() - 1] {
        let want = view.height_at(height_along(p[0]));
        assert!((p[2] - want).abs() <= view.height_at(1.0), "{p:?} vs {want}");
    }
    assert!(
        line[0][2].abs() < 1e-9 && line[line.len() - 1][2].abs() < 1e-9,
        "snapped: {line:?}"
    );
    let top = line.iter().map(|p| p[2]).fold(0.0, f64::max);
    assert!((top - view.height_at(50.0)).abs() <= view.height_at(1.0));
    // The terrain follows: the heightmap under the top node is at its elevation (filtered).
    let peak = pen.editor.heightmap().range().1 as f64;
    assert!(peak > 0.8 * top && peak <= top + 1e-6, "peak {peak} vs {top}");
    assert_eq!(pen.ui.stats().made("ridgelines"), 1);

    // A tree on the surface: a stroke, then a branch from its middle node.
    pen.stroke(&[(150.0, 250.0), (250.0, 250.0), (350.0, 250.0)]);
    let r = pen.doc().ridges.clone().expect("ridges");
    assert_eq!(r.trees.len(), 1, "{:?}", pen.ui.take_messages());
    let mid = pen.view().to_display(r.trees[0].nodes[6]);
    pen.stroke(&[(mid[0], mid[1]), (mid[0], mid[1] + 60.0)]);
    let t = pen.doc().ridges.clone().expect("ridges").trees[0].clone();
    assert_eq!(
        pen.doc().ridges.as_ref().map(|r| r.trees.len()),
        Some(1),
        "a branch, no new tree"
    );
    let degree = |k: usize| t.edges.iter().filter(|e| e.contains(&(k as u32))).count();
    assert_eq!(degree(6), 3, "the branch joins node 6: {t:?}");
    assert_eq!(t.edges.len() + 1, t.nodes.len(), "a tree");
    // Alg. 2.4 independently: Bellman-Ford relaxation from the end nodes.
    let mut d: Vec<f64> = (0..t.nodes.len())
        .map(|k| if degree(k) == 1 { 0.0 } else { f64::INFINITY })
        .collect();
    for _ in 0..t.nodes.len() {
        for &[a, b] in &t.edges {
            let (a, b) = (a as usize, b as usize);
            let len = (t.nodes[a][0] - t.nodes[b][0]).hypot(t.nodes[a][1] - t.nodes[b][1]);
            d[a] = d[a].min(d[b] + len);
            d[b] = d[b].min(d[a] + len);
        }
    }
    let z = tree_of(&t).elevations();
    for k in 0..t.nodes.len() {
        let want = t.h_end + d[k] * t.theta.to_radians().tan();
        assert!((z[k] - want).abs() < 1e-6, "node {k}: {} vs {want}", z[k]);
    }

    // Grab node 5 of the ridgeline and pull it to 80 mm: live, then one undoable edit.
    let before = pen.doc().ridges.clone();
    let n5 = pen.doc().ridges.as_ref().expect("ridges").lines[0].points[5];
    let at = pen.view().to_display([n5[0], n5[1]]);
    pen.grab(at[0], at[1]).pull_to(80.0);
    assert!(pen.editor.previewing(), "the terrain follows the pull live");
    let live = pen.doc().ridges.as_ref().expect("ridges").lines[0].points[5][2];
    assert!((live - view.height_at(80.0)).abs() <= view.height_at(1.0));
    pen.let_go();
    assert!(!pen.editor.previewing());
    let pulled = pen.doc().ridges.clone().expect("ridges");
    assert!((pulled.lines[0].points[5][2] - view.height_at(80.0)).abs() <= view.height_at(1.0));
    assert_eq!(
        pulled.lines[0].points[4],
        before.as_ref().expect("ridges").lines[0].points[4]
    );
    // A tree's end node pulled sets h_end.
    let end = pen.view().to_display(t.nodes[0]);
    pen.grab(end[0], end[1]).pull_to(20.0).let_go();
    let h_end = pen.doc().ridges.as_ref().expect("ridges").trees[0].h_end;
    assert!(
        (h_end - view.height_at(20.0)).abs() <= view.height_at(1.0),
        "h_end {h_end}"
    );
    // Slide the ridgeline's last node on the surface.
    let last = *pen.doc().ridges.as_ref().expect("ridges").lines[0]
        .points
        .last()
        .expect("nodes");
    let at = pen.view().to_display([last[0], last[1]]);
    pen.grab(at[0], at[1])
        .drag_to(at[0] + 20.0, at[1] + 10.0)
        .lift(HOVER)
        .let_go();
    let moved = *pen.doc().ridges.as_ref().expect("ridges").lines[0]
        .points
        .last()
        .expect("nodes");
    let want = pen.ground(at[0] + 20.0, at[1] + 10.0);
    assert!(
        near([moved[0], moved[1]], want, view.metres(1.0)),
        "{moved:?} vs {want:?}"
    );
    // Undo the slide and the h_end: back to the pulled state.
    pen.editor.undo().expect("undo");
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc().ridges.as_ref(), Some(&pulled));

    // An SW3 click over the ridgeline grows a round of valleys: new lines that start on a
    // ridge and run downhill (elevations never rising along them).
    let on = pen.view().to_display([line[8][0], line[8][1]]);
    pen.hover(on[0], on[1]);
    assert_eq!(pen.ui.tool::<Ridges>().and_then(Ridges::part), Some(Part::Line(0)));
    // It is highlighted: the ridgeline's line, not one of its nodes' dots.
    let layers = pen.ui.layers(pen.doc());
    let lit = &layers.overlays[layers.selection.expect("a highlight")];
    assert_eq!(
        lit.points.len(),
        pen.doc().ridges.as_ref().map_or(0, |r| r.lines[0].points.len())
    );
    pen.click(2);
    let grown = pen.doc().ridges.clone().expect("ridges");
    assert!(grown.lines.len() > 1, "{:?}", pen.ui.take_messages());
    assert_eq!(pen.ui.stats().made("valley_rounds"), 1);
    assert!(grown.slope > pulled.slope, "each round steepens the flanks");
    let clicked: Vec<Point> = pulled.lines[0].points.iter().map(|p| [p[0], p[1]]).collect();
    for l in &grown.lines[1..] {
        assert!(l.points[1..].windows(2).all(|w| w[1][2] <= w[0][2] + 1e-3), "{l:?}");
        let start = [l.points[0][0], l.points[0][1]];
        assert!(
            penmodel::interaction::pick::line_distance(&clicked, start) < 1e-6,
            "grown from the clicked ridgeline only: {start:?}"
        );
    }
    // Delete the highlighted ridgeline; undo brings it back.
    pen.hover(on[0], on[1]);
    pen.ui.command(&mut pen.editor, KeyCommand::Delete);
    assert_eq!(
        pen.doc().ridges.as_ref().map(|r| r.lines.len()),
        Some(grown.lines.len() - 1)
    );
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc().ridges.as_ref(), Some(&grown));
    // Back to figures.
    pen.hover(582.0, 18.0).touch().lift(HOVER);
    assert_eq!(pen.ui.tool_name(), "figures");
}

/// The pen lost while a ridgeline's node is pulled: the ridges and terrain are as before the grab.
#[test]
fn losing_the_pen_mid_node_pull_restores_the_ridges() {
    let mut pen = Pen::new(blank());
    pen.hover(582.0, 18.0).touch().lift(HOVER);
    pen.hover(100.0, 150.0).touch().lift(30.0);
    pen.move_to(DVec3::new(250.0, 150.0, 30.0)).click(2);
    let before = pen.doc().clone();
    assert_eq!(before.ridges.as_ref().map(|r| r.lines.len()), Some(1));
    let n = before.ridges.as_ref().expect("ridges").lines[0].points[3];
    let at = pen.view().to_display([n[0], n[1]]);
    pen.grab(at[0], at[1]).pull_to(90.0);
    assert_ne!(pen.doc(), &before, "the pull shows");
    let mut out = Vec::new();
    pen.detector.on_device_lost(pen.t_us, "unplugged", &mut out);
    for ev in &out {
        pen.ui.handle(&mut pen.editor, ev);
    }
    assert_eq!(pen.doc(), &before);
    assert_eq!(pen.editor.heightmap(), &generate(&before).expect("valid"));
    assert!(!pen.editor.previewing());
    assert!(pen.ui.take_messages().iter().any(|m| m.contains("pen lost")));
}

/// Holding a ridgeline's node, SW3 and a move sideways set the flank slope α: left steeper.
#[test]
fn sw3_sideways_on_a_held_node_sets_the_flank_slope() {
    use penmodel::interaction::ridge::SLOPE_DEG_PER_MM;
    let mut pen = Pen::new(blank());
    pen.hover(582.0, 18.0).touch().lift(HOVER);
    pen.hover(100.0, 150.0).touch().lift(30.0);
    pen.move_to(DVec3::new(250.0, 150.0, 30.0)).click(2);
    let before = pen.doc().clone();
    let r0 = before.ridges.clone().expect("ridges");
    let n = r0.lines[0].points[3];
    let at = pen.view().to_display([n[0], n[1]]);
    pen.grab(at[0], at[1]).set(2, true);
    pen.move_to(DVec3::new(at[0] - 20.0, at[1], 0.0));
    let live = pen.doc().ridges.as_ref().expect("ridges").slope;
    assert!(pen.ui.status(pen.doc()).contains("flank slope"));
    pen.set(2, false).let_go();
    let r = pen.doc().ridges.clone().expect("ridges");
    let want = r0.slope + 20.0 * SLOPE_DEG_PER_MM;
    assert!((r.slope - want).abs() < 1e-6, "α {} vs {want}", r.slope);
    assert_eq!(live, r.slope, "shown live");
    assert_eq!(r.lines, r0.lines, "the node stays where it was");
    assert_eq!(pen.editor.heightmap(), &generate(pen.doc()).expect("valid"));
    assert_eq!(pen.ui.stats().slopes, 1);
    pen.editor.undo().expect("undo");
    assert_eq!(pen.doc(), &before);
}

/// Every tool button picks its tool from whichever tool is on, the ridge tool too (whose touch
/// elsewhere starts a stroke of its own), and the pen's help lists the tool on's gestures.
#[test]
fn any_tool_button_switches_from_any_tool() {
    let mut pen = Pen::new(blank());
    let buttons = [
        ("rocks", (18.0, 18.0)),
        ("rivers", (18.0, 42.0)),
        ("ridges", (582.0, 18.0)),
        ("trees", (18.0, 66.0)),
    ];
    for (from, (fu, fv)) in buttons {
        for (to, (tu, tv)) in buttons {
            if from == to {
                continue;
            }
            pen.hover(fu, fv).touch().lift(HOVER);
            assert_eq!(pen.ui.tool_name(), from);
            pen.hover(tu, tv).touch().lift(HOVER);
            assert_eq!(pen.ui.tool_name(), to, "from {from}");
            // The same button again: back to figures (the tree button steps through its presets
            // first).
            while pen.ui.tool_name() == to {
                pen.hover(tu, tv).touch().lift(HOVER);
            }
            assert_eq!(pen.ui.tool_name(), "figures");
        }
    }
    assert!(pen.doc().ridges.is_none(), "no tap drew a ridge stroke");
    pen.hover(18.0, 18.0).touch().lift(HOVER);
    let help: Vec<&str> = pen.ui.help().iter().map(|(g, _)| *g).collect();
    assert!(help.contains(&"SW1 outline, SW3"), "{help:?}");
    assert!(help.contains(&"SW3 click"), "{help:?}");
}
