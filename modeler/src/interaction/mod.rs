//! The pen interaction: calibrated pen events turned into edits of a document, through the tool
//! that is on (docs/modeler.md gives every gesture).
//!
//! This hub keeps what every tool shares and hands the rest to the tools ([`tool::Tool`]):
//!
//! | gesture | what it does |
//! |---|---|
//! | SW1 tap on a tool button | picks that tool; on its own button, back to figures ([`palette`]) |
//! | SW1 on the surface | draws a stroke; SW3 ends it and the tool makes it an element |
//! | SW2 + touch | the tool grabs what is under the tip; the gestures go to it until it lets go |
//! | SW3 click (nothing drawn or grabbed) | undo, unless the tool gives it a meaning over its element |
//! | SW2 held + SW3 click (not touching) | redo |
//! | SW3 held, move (nothing drawn or grabbed) | pans the ground with the pen; up and down zooms |
//!
//! The tools, one file each: seed 000's figures ([`figures`]), rock fields ([`rocks`]), rivers
//! ([`river`]), ridgelines ([`ridge`]) and trees ([`trees`]).
//!
//! [`KeyCommand`]s give the same edits to a keyboard or a script. Times come from the device clock
//! that reports carry (a click is timed the same at any replay speed); events that are not from
//! a report (device found or lost) do not move it.
//! A refused edit is a message and a count, never a lost document: the editor keeps it valid.

pub mod figures;
pub mod palette;
pub mod pick;
pub mod ridge;
pub mod river;
pub mod rocks;
pub mod stats;
pub mod stroke;
pub mod tool;
pub mod trees;
pub mod view;

use pen_host::events::{DisplayPoint, EventKind, PenEvent};
use penmodel_render::SlopeBar;
use penmodel_terrain::document::{Document, Point};
use penmodel_terrain::editor::{Editor, EditorError, Outcome};

pub use pick::Hit;
pub use stats::Stats;
pub use stroke::{Shape, Tolerances};
pub use tool::{Context, Counter, Layers, Phase, Release, Seen, Tool};
pub use view::View;

use palette::Entry;
use tool::Messages;

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
    /// Delete what the tool on has highlighted.
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

/// What the hub is doing with the pen.
#[derive(Debug, Clone, PartialEq)]
enum Hub {
    Idle,
    /// SW2 held, nothing grabbed.
    Armed,
    /// Positions of the stroke being drawn (ground metres); `touching` while SW1 is down.
    Drawing {
        positions: Vec<Point>,
        touching: bool,
    },
    /// The tip on a tool button: the tool was switched; nothing more until it lifts.
    Palette,
    /// SW3 held with nothing drawn or grabbed: a click (undo) or a pan.
    Sw3 {
        t0: u64,
        at_mm: [f64; 2],
        h0: f64,
        ground: Point,
        scale0: f64,
        moved: bool,
    },
    /// The tool on holds the pen.
    Held,
}

/// The help lines of the gestures every tool shares (the hub's own).
const SHARED_HELP: [(&str, &str); 3] = [
    ("tool button", "pick its tool; again: back to figures"),
    ("SW3 click", "undo; with SW2 held: redo"),
    ("SW3 held, move", "pan; up and down zooms"),
];

/// The pen interaction: turns pen events into edits of an [`Editor`]'s document.
#[derive(Debug)]
pub struct Interaction {
    tuning: Tuning,
    view: View,
    home: View,
    state: Hub,
    pen: Option<DisplayPoint>,
    sw: [bool; 3],
    stats: Stats,
    messages: Messages,
    tools: Vec<Entry>,
    /// The tool on, an index into `tools`; 0 is the home tool.
    active: usize,
    /// The status line carries the last message for a while.
    messages_on_status: bool,
}

/// The event's time on the device's clock, µs; `None` for events not from a report (device
/// found or lost, missed), which carry only the host's clock.
fn event_time(ev: &PenEvent) -> Option<u64> {
    ev.seq.map(|(_, device_us)| device_us)
}

impl Interaction {
    /// An interaction showing the ground through `view`, with the home tool on.
    pub fn new(view: View, tuning: Tuning) -> Interaction {
        let tools = palette::tools();
        let stats = Stats::with_counters(tools.iter().flat_map(|e| e.tool.counters()).copied());
        Interaction {
            tuning,
            view,
            home: view,
            state: Hub::Idle,
            pen: None,
            sw: [false; 3],
            stats,
            messages: Messages::default(),
            tools,
            active: 0,
            messages_on_status: true,
        }
    }

    /// The name of the tool on (`figures`, `rocks`, …).
    pub fn tool_name(&self) -> &'static str {
        self.tools[self.active].tool.name()
    }

    /// The palette's tool of type `T` (the tool's own state: what it holds, highlights, draws).
    pub fn tool<T: Tool>(&self) -> Option<&T> {
        self.tools
            .iter()
            .find_map(|e| (e.tool.as_ref() as &dyn std::any::Any).downcast_ref::<T>())
    }

    /// What the hub is doing with the pen.
    pub fn phase(&self) -> Phase {
        match &self.state {
            Hub::Idle => Phase::Idle,
            Hub::Armed => Phase::Armed,
            Hub::Drawing { .. } => Phase::Drawing,
            Hub::Palette => Phase::Palette,
            Hub::Sw3 { t0, moved, .. } => Phase::Pressing {
                held_us: self.messages.now.unwrap_or(*t0).saturating_sub(*t0),
                moved: *moved,
            },
            Hub::Held => Phase::Held,
        }
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
        std::mem::take(&mut self.messages.list)
    }

    /// Where the pen is on the display, if in range.
    pub fn pen(&self) -> Option<&DisplayPoint> {
        self.pen.as_ref()
    }

    /// The positions of the stroke being drawn on the surface (ground metres).
    pub fn drawing(&self) -> Option<&[Point]> {
        match &self.state {
            Hub::Drawing { positions, .. } => Some(positions),
            _ => None,
        }
    }

    /// Whether a pull or slope is in progress (the ground tilts).
    pub fn pulling(&self) -> bool {
        self.state == Hub::Held && self.tools[self.active].tool.pulling()
    }

    /// What the tools may look at in `doc`.
    pub fn seen<'a>(&'a self, doc: &'a Document) -> Seen<'a> {
        Seen {
            doc,
            view: &self.view,
            tuning: &self.tuning,
            phase: self.phase(),
            pen: self.pen,
        }
    }

    /// The lines every tool draws on the terrain, in the palette's order, each tool button after
    /// its tool's lines, and the highlighted one.
    pub fn layers(&self, doc: &Document) -> Layers {
        let seen = self.seen(doc);
        let mut layers = Layers::default();
        for (i, e) in self.tools.iter().enumerate() {
            let on = i == self.active;
            e.tool.overlays(&seen, on, &mut layers);
            if let Some(b) = e.place.button(self.view.display_mm) {
                let (colour, width) = if on {
                    (tool::PALETTE_ON_COLOUR, 5.0)
                } else {
                    (tool::PALETTE_OFF_COLOUR, 2.0)
                };
                layers.push(Layers::line(b.outline(&self.view), true, colour, width));
            }
        }
        layers
    }

    /// The tool buttons on the display: each tool's name, its button, and whether it is on.
    pub fn buttons(&self) -> Vec<(&'static str, palette::Button, bool)> {
        self.tools
            .iter()
            .enumerate()
            .filter_map(|(i, e)| {
                let b = e.place.button(self.view.display_mm)?;
                Some((e.tool.name(), b, i == self.active))
            })
            .collect()
    }

    /// The gauge the tool on shows (the slope bar while a slope is set).
    pub fn gauge(&self, doc: &Document) -> Option<SlopeBar> {
        self.tools[self.active].tool.gauge(&self.seen(doc))
    }

    /// The help panel's pen lines: the tool on's gestures, then those every tool shares.
    pub fn help(&self) -> Vec<(&'static str, &'static str)> {
        let mut lines = self.tools[self.active].tool.help().to_vec();
        lines.extend(SHARED_HELP);
        lines
    }

    /// Every tool's gestures, from each tool's own help lines: the tool on first (its name
    /// marked `on`), the others in the palette's order, then the gestures every tool shares
    /// (`every tool`). Each section is a title and its lines.
    pub fn help_by_tool(&self) -> Vec<(String, Vec<(&'static str, &'static str)>)> {
        let on = &self.tools[self.active].tool;
        let mut sections = vec![(format!("{} (on)", on.name()), on.help().to_vec())];
        sections.extend(
            self.tools
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != self.active)
                .map(|(_, e)| (e.tool.name().to_string(), e.tool.help().to_vec())),
        );
        sections.push(("every tool".to_string(), SHARED_HELP.to_vec()));
        sections
    }

    /// Whether [`status`](Interaction::status) ends with the last message for 3 s (the default:
    /// a headless animation shows messages nowhere else). The window shows each message once,
    /// under the status line, and turns this off.
    pub fn set_messages_on_status(&mut self, on: bool) {
        self.messages_on_status = on;
    }

    /// One line saying what the pen is doing and what it can do next.
    pub fn status(&self, doc: &Document) -> String {
        let seen = self.seen(doc);
        let tool = &self.tools[self.active].tool;
        let line = match (&self.state, tool.status(&seen)) {
            (Hub::Palette, _) => tool.title(),
            (Hub::Drawing { positions, touching }, _) => format!(
                "drawing: {} positions{} | SW3 ends the figure",
                positions.len(),
                if *touching { "" } else { ", pen lifted" }
            ),
            (Hub::Sw3 { moved: true, .. }, _) => format!("view: 1 mm = {:.1} m", 1.0 / self.view.scale),
            (_, Some(line)) => line,
            (Hub::Sw3 { .. }, None) => "SW3: release to undo, or move to pan and zoom".to_string(),
            (_, None) => String::new(),
        };
        match (&self.messages.last, self.messages.now) {
            (Some((t, m)), Some(now)) if self.messages_on_status && now.saturating_sub(*t) < 3_000_000 => {
                format!("{line}  | {m}")
            }
            _ => line,
        }
    }

    /// Runs `f` on the tool on with the context it may touch.
    fn with_tool<R>(&mut self, editor: &mut Editor, f: impl FnOnce(&mut dyn Tool, &mut Context) -> R) -> R {
        let phase = self.phase();
        let mut cx = Context {
            editor,
            view: &self.view,
            tuning: &self.tuning,
            stats: &mut self.stats,
            phase,
            pen: self.pen,
            sw: self.sw,
            messages: &mut self.messages,
        };
        f(self.tools[self.active].tool.as_mut(), &mut cx)
    }

    /// Leaves the hub as the tool's handler said.
    fn release(&mut self, r: Release) {
        match r {
            Release::Keep => {}
            Release::Idle => self.state = Hub::Idle,
            Release::Armed => self.state = Hub::Armed,
        }
    }

    fn say(&mut self, message: String) {
        self.messages.say(message);
    }

    /// Eases the ground's tilt towards its target up to time `t_us`.
    /// A clock that goes back (a device reattached starts its own again) restarts the easing.
    pub fn advance(&mut self, t_us: u64) {
        let dt = match self.messages.now {
            Some(last) if t_us >= last => (t_us - last) as f64 * 1e-6,
            _ => 0.0,
        };
        self.messages.now = Some(t_us);
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
        let t = self.messages.now.unwrap_or(0);
        match &ev.kind {
            EventKind::ProximityIn | EventKind::Motion => self.on_motion(editor),
            EventKind::ProximityOut => {
                self.pen = None;
                self.tools[self.active].tool.clear_hover();
            }
            EventKind::TipDown => self.on_tip_down(editor),
            EventKind::TipUp => self.on_tip_up(editor),
            EventKind::ButtonDown { button: 2 } => {
                if self.state == Hub::Idle {
                    self.state = Hub::Armed;
                }
            }
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
            KeyCommand::Delete => self.with_tool(editor, |tool, cx| tool.delete(cx)),
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

    /// Switches to tool `index` (its button was tapped): the tool decides whether it stays on
    /// (a second tap goes back to the home tool); every tool forgets what it hovered.
    fn switch(&mut self, index: usize) {
        let again = index == self.active;
        self.active = if self.tools[index].tool.tapped(again) { index } else { 0 };
        for e in &mut self.tools {
            e.tool.clear_hover();
        }
        self.state = Hub::Palette;
        let message = self.tools[self.active].tool.picked();
        self.say(message);
    }

    /// The tool whose button is at display point `p`.
    fn button_at(&self, p: DisplayPoint) -> Option<usize> {
        let display = self.view.display_mm;
        self.tools
            .iter()
            .position(|e| e.place.button(display).is_some_and(|b| b.contains(p.u_mm, p.v_mm)))
    }

    fn on_motion(&mut self, editor: &mut Editor) {
        let Some((g, p)) = self.ground() else { return };
        let s = self.tuning;
        match &mut self.state {
            Hub::Idle | Hub::Armed => self.with_tool(editor, |tool, cx| tool.hover(cx, g)),
            Hub::Held => self.with_tool(editor, |tool, cx| tool.motion(cx, g, p)),
            Hub::Drawing { positions, touching } => {
                if *touching {
                    positions.push(g);
                }
            }
            Hub::Palette => {}
            Hub::Sw3 {
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

    fn on_tip_down(&mut self, editor: &mut Editor) {
        let Some((g, p)) = self.ground() else { return };
        match &mut self.state {
            Hub::Idle => {
                if let Some(index) = self.button_at(p) {
                    self.switch(index);
                } else if self.with_tool(editor, |tool, cx| tool.touch(cx, g, p)) {
                    self.state = Hub::Held;
                } else {
                    self.state = Hub::Drawing {
                        positions: vec![g],
                        touching: true,
                    };
                }
            }
            Hub::Drawing { positions, touching } => {
                *touching = true;
                positions.push(g);
            }
            Hub::Armed => {
                if self.with_tool(editor, |tool, cx| tool.grab(cx, g, p)) {
                    self.state = Hub::Held;
                }
            }
            Hub::Held => self.with_tool(editor, |tool, cx| tool.tip_down(cx, g, p)),
            Hub::Sw3 { .. } | Hub::Palette => {}
        }
    }

    fn on_tip_up(&mut self, editor: &mut Editor) {
        let g = self.ground().map(|(g, _)| g);
        let on_lift = self.tools[self.active].tool.ends_stroke_on_lift();
        match &mut self.state {
            Hub::Drawing { positions, touching } => {
                *touching = false;
                if let Some(g) = g
                    && positions.last() != Some(&g)
                {
                    positions.push(g);
                }
                if on_lift {
                    let positions = std::mem::take(positions);
                    self.state = Hub::Idle;
                    self.with_tool(editor, |tool, cx| tool.stroke(cx, &positions));
                }
            }
            Hub::Held => {
                let r = self.with_tool(editor, |tool, cx| tool.tip_up(cx));
                self.release(r);
            }
            Hub::Palette => self.state = Hub::Idle,
            Hub::Idle | Hub::Armed | Hub::Sw3 { .. } => {}
        }
    }

    fn on_sw2_up(&mut self, editor: &mut Editor) {
        match self.state {
            Hub::Held => {
                let r = self.with_tool(editor, |tool, cx| tool.sw2_up(cx));
                self.release(r);
            }
            Hub::Armed => self.state = Hub::Idle,
            _ => {}
        }
    }

    fn on_sw3_down(&mut self, editor: &mut Editor, t: u64) {
        let at = self.pen.map(|p| ([p.u_mm, p.v_mm], p.h_mm));
        match &mut self.state {
            Hub::Drawing { positions, .. } => {
                let positions = std::mem::take(positions);
                self.state = Hub::Idle;
                self.with_tool(editor, |tool, cx| tool.stroke(cx, &positions));
            }
            Hub::Idle => {
                let Some((at_mm, h0)) = at else { return };
                self.state = Hub::Sw3 {
                    t0: t,
                    at_mm,
                    h0,
                    ground: self.view.to_ground(at_mm[0], at_mm[1]),
                    scale0: self.view.scale,
                    moved: false,
                };
            }
            Hub::Armed => self.redo(editor),
            Hub::Held => {
                let r = self.with_tool(editor, |tool, cx| tool.sw3_down(cx));
                self.release(r);
            }
            Hub::Sw3 { .. } | Hub::Palette => {}
        }
    }

    fn on_sw3_up(&mut self, editor: &mut Editor, t: u64) {
        match self.state {
            Hub::Held => self.with_tool(editor, |tool, cx| tool.sw3_up(cx)),
            Hub::Sw3 { t0, moved, .. } => {
                let held_us = t.saturating_sub(t0);
                let click = !moved && held_us < self.tuning.click_us;
                self.state = Hub::Idle;
                // A press released where it was made may mean something over the tool's element
                // (a river's years, a ridgeline's valleys); otherwise a click undoes.
                let used = !moved && self.with_tool(editor, |tool, cx| tool.press(cx, held_us, click));
                if click && !used {
                    self.undo(editor);
                }
            }
            _ => {}
        }
    }

    fn on_lost(&mut self, editor: &mut Editor, reason: &str) {
        match &mut self.state {
            Hub::Held => {
                let r = self.with_tool(editor, |tool, cx| tool.lost(cx, reason));
                self.release(r);
            }
            Hub::Drawing { touching, .. } => {
                *touching = false;
                self.say(format!(
                    "pen lost ({reason}): the figure being drawn is kept; SW3 ends it"
                ));
            }
            _ => {
                self.say(format!("pen lost ({reason})"));
                self.state = Hub::Idle;
            }
        }
        self.pen = None;
        self.tools[self.active].tool.clear_hover();
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
        self.tools[self.active].tool.clear_hover();
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
}
