//! The seam every landscape tool plugs into: the [`Tool`] trait, what a tool may touch
//! ([`Context`]) and what it may look at ([`Seen`]) while it handles the pen, and the
//! [`Layers`] it draws into.
//!
//! The hub ([`super::Interaction`]) keeps what all tools share: the pen, its switches, the view,
//! the stroke being drawn on the surface, the SW3 press that undoes or pans, the palette and the
//! session's counts. It hands each pen gesture to the tool that is on, as RMK's input processors
//! get their events: every method has a default that does nothing, so a tool implements only the
//! gestures it gives a meaning to. While a tool holds the pen (a grab, or a stroke of its own),
//! the hub's state is [`Phase::Held`] and every gesture goes to that tool until it lets go
//! ([`Release`]).

use std::any::Any;

use pen_host::events::DisplayPoint;
use penmodel_render::{Overlay, Rgba, SlopeBar};
use penmodel_terrain::document::{Document, Point};
use penmodel_terrain::edit::Edit;
use penmodel_terrain::editor::Editor;

use super::{Stats, Tuning, View};

/// Colour of a tool button while its tool is on.
pub const PALETTE_ON_COLOUR: Rgba = [255, 200, 90, 255];
/// Colour of a tool button while another tool is on.
pub const PALETTE_OFF_COLOUR: Rgba = [170, 170, 170, 255];
/// Colour of the stroke being drawn.
pub const DRAWING_COLOUR: Rgba = [64, 224, 255, 255];
/// Colour of what is being moved.
pub const MOVING_COLOUR: Rgba = [255, 160, 32, 255];
/// Colour of what would be deleted where it is dropped.
pub const DELETING_COLOUR: Rgba = [120, 120, 120, 255];

/// What the hub is doing with the pen, as tools see it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Nothing pressed but the pen in range or out of it.
    Idle,
    /// SW2 held, nothing grabbed yet.
    Armed,
    /// A stroke is being drawn on the surface (the hub's, ended by SW3).
    Drawing,
    /// The tip is on a tool button.
    Palette,
    /// SW3 held with nothing drawn or grabbed, `held_us` so far; `moved` once it pans.
    Pressing {
        /// How long SW3 has been held, µs of the device's clock.
        held_us: u64,
        /// Whether the pen has moved enough to make it a pan.
        moved: bool,
    },
    /// The tool on holds the pen (a grab, or a stroke of its own).
    Held,
}

/// What a tool's handler leaves the hub in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Release {
    /// The tool still holds the pen.
    Keep,
    /// The tool let go; nothing pressed.
    Idle,
    /// The tool let go; SW2 is still held (the next touch grabs again).
    Armed,
}

/// Read-only: what a tool may look at while it tells its status or draws.
#[derive(Debug, Clone, Copy)]
pub struct Seen<'a> {
    /// The document as the editor holds it (with any preview shown).
    pub doc: &'a Document,
    /// How the display shows the ground.
    pub view: &'a View,
    /// The gestures' thresholds and gains.
    pub tuning: &'a Tuning,
    /// What the hub is doing.
    pub phase: Phase,
    /// Where the pen is on the display, if in range.
    pub pen: Option<DisplayPoint>,
}

/// What a tool may touch while it handles a gesture: the editor (every change of the document
/// goes through it: undo, the journal), the view (read-only), the tuning, the session's counts
/// and the messages.
pub struct Context<'a> {
    /// The document's editor.
    pub editor: &'a mut Editor,
    /// How the display shows the ground.
    pub view: &'a View,
    /// The gestures' thresholds and gains.
    pub tuning: &'a Tuning,
    /// The session's counts.
    pub stats: &'a mut Stats,
    /// What the hub is doing.
    pub phase: Phase,
    /// Where the pen is on the display, if in range.
    pub pen: Option<DisplayPoint>,
    /// The switches SW1 (the tip), SW2 and SW3, pressed or not.
    pub sw: [bool; 3],
    pub(super) messages: &'a mut Messages,
}

impl Context<'_> {
    /// Tells the user something: the messages list and the status line for a few seconds.
    pub fn say(&mut self, message: String) {
        self.messages.say(message);
    }

    /// Counts a refused edit and says why.
    pub fn refuse(&mut self, message: String) {
        self.stats.refused += 1;
        self.say(message);
    }

    /// Applies a recorded edit; a refusal is counted and said (`what` refused: why). Whether it
    /// was applied.
    pub fn commit(&mut self, edit: Edit, what: &str) -> bool {
        match self.editor.apply(edit) {
            Ok(_) => true,
            Err(e) => {
                self.refuse(format!("{what} refused: {e}"));
                false
            }
        }
    }

    /// The ground metres `mm` display millimetres span.
    pub fn metres(&self, mm: f64) -> f64 {
        self.view.metres(mm)
    }

    /// The pick tolerance in ground metres.
    pub fn pick_m(&self) -> f64 {
        self.view.metres(self.tuning.pick_mm)
    }
}

/// The messages said since the hub last handed them out, and the latest with its time for the
/// status line.
#[derive(Debug, Clone, Default)]
pub(super) struct Messages {
    pub(super) list: Vec<String>,
    pub(super) last: Option<(u64, String)>,
    /// The device clock's latest time, µs.
    pub(super) now: Option<u64>,
}

impl Messages {
    pub(super) fn say(&mut self, message: String) {
        if let Some(t) = self.now {
            self.last = Some((t, message.clone()));
        }
        self.list.push(message);
    }
}

/// The lines a frame draws on the terrain, in order, and which one is highlighted.
#[derive(Debug, Clone, Default)]
pub struct Layers {
    /// The lines, in drawing order.
    pub overlays: Vec<Overlay>,
    /// The highlighted one's index.
    pub selection: Option<usize>,
}

impl Layers {
    /// Adds a line.
    pub fn push(&mut self, overlay: Overlay) {
        self.overlays.push(overlay);
    }

    /// Adds a line and highlights it.
    pub fn push_selected(&mut self, overlay: Overlay) {
        self.selection = Some(self.overlays.len());
        self.overlays.push(overlay);
    }

    /// A draped line through `points`.
    pub fn line(points: Vec<Point>, closed: bool, colour: Rgba, width: f32) -> Overlay {
        Overlay {
            points,
            closed,
            colour,
            width,
            height: None,
        }
    }

    /// A dot at `at`, draped, or at `height` metres when given.
    pub fn dot(at: Point, height: Option<f64>, colour: Rgba, width: f32) -> Overlay {
        Overlay {
            points: vec![at],
            closed: false,
            colour,
            width,
            height,
        }
    }
}

/// A count the session keeps for a tool: how many of its elements were made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Counter {
    /// Its key in the session's JSON summary (`rock_fields`).
    pub key: &'static str,
    /// The element's name in the summary line (`rock field`); `None` to leave it out of the line.
    pub noun: Option<&'static str>,
}

/// A landscape tool: how the pen's gestures edit one kind of element while it is on.
///
/// Gestures arrive in the hub's terms. With nothing held: [`hover`](Tool::hover) as the pen
/// moves, [`touch`](Tool::touch) when the tip goes down (a tool may take the pen for a stroke of
/// its own; otherwise the hub draws one and hands it to [`stroke`](Tool::stroke)),
/// [`grab`](Tool::grab) when the tip goes down with SW2 held, [`press`](Tool::press) when SW3 is
/// released where it was pressed. While the tool holds the pen, every gesture is its own:
/// [`motion`](Tool::motion), [`tip_down`](Tool::tip_down), [`tip_up`](Tool::tip_up),
/// [`sw2_up`](Tool::sw2_up), [`sw3_down`](Tool::sw3_down), [`sw3_up`](Tool::sw3_up) and
/// [`lost`](Tool::lost). A new tool is its file and one line in [`super::palette::tools`].
pub trait Tool: Any + std::fmt::Debug + Send {
    /// The tool's name: its identity in the palette and on the status line (`rocks`).
    fn name(&self) -> &'static str;

    /// What the status line says while the tip rests on the tool's button.
    fn title(&self) -> String {
        format!("{} tool", self.name())
    }

    /// The message when the tool's button picks it.
    fn picked(&self) -> String {
        self.title()
    }

    /// The tool's button was tapped, with the tool on (`again`) or not: whether it is on after.
    /// By default a tap picks it and a second tap goes back to figures.
    fn tapped(&mut self, again: bool) -> bool {
        !again
    }

    /// The counts the session keeps for the tool, in the summary's order.
    fn counters(&self) -> &'static [Counter] {
        &[]
    }

    /// Forgets what the pen was over (the tool was switched, or the pen left).
    fn clear_hover(&mut self) {}

    /// The pen moved to ground point `g` with nothing held.
    fn hover(&mut self, _cx: &mut Context, _g: Point) {}

    /// The tip went down at `g` with nothing held and not on a button: `true` when the tool takes
    /// the pen for a stroke of its own; by default the hub draws a stroke on the surface.
    fn touch(&mut self, _cx: &mut Context, _g: Point, _p: DisplayPoint) -> bool {
        false
    }

    /// Whether lifting the tip ends the hub's stroke (by default SW3 does).
    fn ends_stroke_on_lift(&self) -> bool {
        false
    }

    /// The hub's stroke ended: its ground positions.
    fn stroke(&mut self, _cx: &mut Context, _positions: &[Point]) {}

    /// The tip went down at `g` with SW2 held: `true` when the tool now holds something.
    fn grab(&mut self, cx: &mut Context, _g: Point, _p: DisplayPoint) -> bool {
        cx.say("nothing here to grab".into());
        false
    }

    /// Held: the pen moved.
    fn motion(&mut self, _cx: &mut Context, _g: Point, _p: DisplayPoint) {}

    /// Held: the tip went down.
    fn tip_down(&mut self, _cx: &mut Context, _g: Point, _p: DisplayPoint) {}

    /// Held: the tip came up.
    fn tip_up(&mut self, _cx: &mut Context) -> Release {
        Release::Keep
    }

    /// Held: SW2 was released.
    fn sw2_up(&mut self, _cx: &mut Context) -> Release {
        Release::Idle
    }

    /// Held: SW3 went down.
    fn sw3_down(&mut self, _cx: &mut Context) -> Release {
        Release::Keep
    }

    /// Held: SW3 came up.
    fn sw3_up(&mut self, _cx: &mut Context) {}

    /// Held: the pen was lost (unplugged, out of range for too long).
    fn lost(&mut self, cx: &mut Context, reason: &str) -> Release {
        cx.say(format!("pen lost ({reason})"));
        Release::Idle
    }

    /// SW3 was released where it was pressed, `held_us` after, with nothing held (`click`: short
    /// enough to be a click): `true` when the tool gave it a meaning; otherwise a click undoes.
    fn press(&mut self, _cx: &mut Context, _held_us: u64, _click: bool) -> bool {
        false
    }

    /// The Delete key: deletes what is highlighted.
    fn delete(&mut self, cx: &mut Context) {
        cx.say("nothing highlighted to delete".into());
    }

    /// Whether the ground tilts towards the viewer (a pull in progress).
    fn pulling(&self) -> bool {
        false
    }

    /// The status line for `seen.phase`; `None` for the hub's own line.
    fn status(&self, _seen: &Seen) -> Option<String> {
        None
    }

    /// Draws the tool's elements (all of them, the tool on or not: `active`), the highlight and
    /// what is held.
    fn overlays(&self, _seen: &Seen, _active: bool, _layers: &mut Layers) {}

    /// A gauge the frame shows (the slope bar while a slope is set).
    fn gauge(&self, _seen: &Seen) -> Option<SlopeBar> {
        None
    }

    /// The help panel's lines for the tool's gestures: what to do, then what it does.
    fn help(&self) -> &'static [(&'static str, &'static str)] {
        &[]
    }
}
