//! Scripted sessions: what the hand does, as a timeline of tip movements and switch presses.
//!
//! Coordinates are in the display frame, mm: x, y on the display surface, z the height above
//! it. Movements follow the minimum-jerk profile of point-to-point human reaching (Flash and
//! Hogan, 1985), with durations that grow with distance. The builder's methods are the seed's
//! operations (section 3.2 of 000_84d195d16f2dca2f.txt): draw a point, a polyline or a closed
//! curve on the surface and end it with SW3; hover; grab (SW2 + touch); pull up; slope (SW2 +
//! SW3, moving left or right); and the accuracy scenarios' holds and sweeps.

use glam::{DVec2, DVec3};

/// SW1, the tip switch.
pub const SW1: usize = 0;
/// SW2, the barrel button.
pub const SW2: usize = 1;
/// SW3, the second barrel button.
pub const SW3: usize = 2;

/// One movement of the tip.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment {
    t0: f64,
    t1: f64,
    from: DVec3,
    to: DVec3,
}

/// A switch changing state as the hand intends it (before contact bounce).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwitchEvent {
    /// When, s.
    pub t_s: f64,
    /// Which: [`SW1`], [`SW2`] or [`SW3`].
    pub switch: usize,
    /// Pressed (true) or released.
    pub pressed: bool,
}

/// The hand's intended motion and switch presses.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Timeline {
    segments: Vec<Segment>,
    events: Vec<SwitchEvent>,
    /// Spans (start, end, s) in which the hand tilts the pen about its still tip.
    pivots: Vec<(f64, f64)>,
}

/// The minimum-jerk profile: position fraction at time fraction `s` ∈ [0, 1].
fn min_jerk(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
}

impl Timeline {
    /// The session's length, s.
    pub fn duration_s(&self) -> f64 {
        let moves = self.segments.last().map_or(0.0, |s| s.t1);
        let presses = self.events.last().map_or(0.0, |e| e.t_s);
        moves.max(presses)
    }

    /// Where the hand puts the tip at `t_s` (before tremor).
    pub fn tip(&self, t_s: f64) -> DVec3 {
        let i = self.segments.partition_point(|s| s.t1 < t_s);
        match self.segments.get(i) {
            Some(s) if t_s >= s.t0 => {
                let f = if s.t1 > s.t0 {
                    min_jerk((t_s - s.t0) / (s.t1 - s.t0))
                } else {
                    1.0
                };
                s.from + (s.to - s.from) * f
            }
            Some(s) => s.from,
            None => self.segments.last().map_or(DVec3::ZERO, |s| s.to),
        }
    }

    /// How far through a pivot ([`Script::pivot`]) the hand is at `t_s`, from 0 to 1; `None`
    /// outside one.
    pub fn pivot_at(&self, t_s: f64) -> Option<f64> {
        self.pivots
            .iter()
            .find(|(t0, t1)| t_s >= *t0 && t_s <= *t1 && t1 > t0)
            .map(|(t0, t1)| (t_s - t0) / (t1 - t0))
    }

    /// The switch presses and releases, in time order.
    pub fn events(&self) -> &[SwitchEvent] {
        &self.events
    }

    /// The intended switch states at `t_s`.
    pub fn switches(&self, t_s: f64) -> [bool; 3] {
        let mut state = [false; 3];
        for e in self.events.iter().take_while(|e| e.t_s <= t_s) {
            state[e.switch] = e.pressed;
        }
        state
    }

    /// This timeline followed by `other`, shifted to start when this one ends.
    pub fn then(mut self, other: &Timeline) -> Timeline {
        let offset = self.duration_s();
        self.segments.extend(other.segments.iter().map(|s| Segment {
            t0: s.t0 + offset,
            t1: s.t1 + offset,
            ..*s
        }));
        self.events.extend(other.events.iter().map(|e| SwitchEvent {
            t_s: e.t_s + offset,
            ..*e
        }));
        self.pivots
            .extend(other.pivots.iter().map(|(t0, t1)| (t0 + offset, t1 + offset)));
        self
    }
}

/// Height the pen hovers at between operations, mm.
pub const HOVER_MM: f64 = 40.0;
/// The pen's average speed over a movement, mm/s; each movement also takes a reaction time.
const SPEED_MM_S: f64 = 350.0;
const REACTION_S: f64 = 0.15;
/// How long a button is held in a click, s.
const CLICK_S: f64 = 0.12;
/// Pause after a switch press before the hand moves on, s.
const SETTLE_S: f64 = 0.08;

/// Builds a [`Timeline`] from the seed's operations.
#[derive(Debug, Clone)]
pub struct Script {
    t: f64,
    at: DVec3,
    pressed: [bool; 3],
    timeline: Timeline,
}

impl Script {
    /// The hand starts hovering at `start` (display frame, mm).
    pub fn new(start: DVec3) -> Script {
        Script {
            t: 0.0,
            at: start,
            pressed: [false; 3],
            timeline: Timeline::default(),
        }
    }

    /// The current time in the script, s.
    pub fn now(&self) -> f64 {
        self.t
    }

    /// Where the tip is now.
    pub fn at(&self) -> DVec3 {
        self.at
    }

    /// Moves the tip to `to` in `duration_s`.
    pub fn move_in(&mut self, to: DVec3, duration_s: f64) -> &mut Self {
        self.timeline.segments.push(Segment {
            t0: self.t,
            t1: self.t + duration_s,
            from: self.at,
            to,
        });
        self.t += duration_s;
        self.at = to;
        self
    }

    /// Moves the tip to `to` at a hand's pace.
    pub fn move_to(&mut self, to: DVec3) -> &mut Self {
        let d = (to - self.at).length();
        self.move_in(to, REACTION_S + d / SPEED_MM_S)
    }

    /// Keeps still for `duration_s`.
    pub fn hold(&mut self, duration_s: f64) -> &mut Self {
        self.move_in(self.at, duration_s)
    }

    /// Presses a switch.
    pub fn press(&mut self, switch: usize) -> &mut Self {
        self.set(switch, true)
    }

    /// Releases a switch.
    pub fn release(&mut self, switch: usize) -> &mut Self {
        self.set(switch, false)
    }

    fn set(&mut self, switch: usize, pressed: bool) -> &mut Self {
        if self.pressed[switch] != pressed {
            self.timeline.events.push(SwitchEvent {
                t_s: self.t,
                switch,
                pressed,
            });
            self.pressed[switch] = pressed;
        }
        self.hold(SETTLE_S)
    }

    /// Presses and releases a switch.
    pub fn click(&mut self, switch: usize) -> &mut Self {
        self.press(switch).hold(CLICK_S).release(switch)
    }

    /// Hovers over `xy` at the hover height.
    pub fn hover(&mut self, xy: DVec2) -> &mut Self {
        self.move_to(xy.extend(HOVER_MM))
    }

    /// Lowers the tip onto the surface; SW1 closes on contact.
    pub fn touch(&mut self) -> &mut Self {
        let down = self.at.truncate().extend(0.0);
        self.move_in(down, 0.25).press(SW1)
    }

    /// Lifts the tip to `height`; SW1 opens as it leaves the surface.
    pub fn lift(&mut self, height: f64) -> &mut Self {
        self.release(SW1);
        let up = self.at.truncate().extend(height);
        self.move_in(up, 0.2 + height / SPEED_MM_S)
    }

    /// Slides the tip along the surface to `xy`.
    pub fn drag_to(&mut self, xy: DVec2) -> &mut Self {
        self.move_to(xy.extend(0.0))
    }

    /// Draws a point figure at `xy` and ends it with SW3.
    pub fn draw_point(&mut self, xy: DVec2) -> &mut Self {
        self.hover(xy).touch().lift(HOVER_MM).click(SW3)
    }

    /// Draws a polyline through `points` in one stroke and ends it with SW3.
    pub fn draw_polyline(&mut self, points: &[DVec2]) -> &mut Self {
        let Some((first, rest)) = points.split_first() else {
            return self;
        };
        self.hover(*first).touch();
        for p in rest {
            self.drag_to(*p);
        }
        self.lift(HOVER_MM).click(SW3)
    }

    /// Draws a closed curve through `points`, back to the first, and ends it with SW3.
    pub fn draw_closed(&mut self, points: &[DVec2]) -> &mut Self {
        let mut loop_points = points.to_vec();
        if let Some(first) = points.first() {
            loop_points.push(*first);
        }
        self.draw_polyline(&loop_points)
    }

    /// Grabs the figure at `xy`: hovers over it, holds SW2 and touches the surface.
    pub fn grab(&mut self, xy: DVec2) -> &mut Self {
        self.hover(xy).press(SW2).touch()
    }

    /// Pulls the grabbed figure up (or down, back towards the surface) to `height`, SW2 held.
    pub fn pull_to(&mut self, height: f64) -> &mut Self {
        if self.pressed[SW1] {
            self.lift(height)
        } else {
            let to = self.at.truncate().extend(height);
            self.move_to(to)
        }
    }

    /// Adjusts the grabbed figure's slope: SW3 with SW2, moving `dx_mm` sideways (negative is
    /// left: sharper; positive right: bell-shaped), then, the slope bar read, SW3 released.
    pub fn slope(&mut self, dx_mm: f64) -> &mut Self {
        let to = self.at + DVec3::new(dx_mm, 0.0, 0.0);
        self.press(SW3).move_to(to).hold(0.3).release(SW3)
    }

    /// Lets go of the grabbed figure.
    pub fn let_go(&mut self) -> &mut Self {
        self.release(SW2)
    }

    /// Keeps the tip still for `duration_s` while tilting the pen about it, its top circling
    /// once at a lean that rises and falls (the calibration's pivot: the emitter sweeps part of
    /// a sphere about the tip; the hand's motion is [`crate::hand::Hand::axis`]).
    pub fn pivot(&mut self, duration_s: f64) -> &mut Self {
        self.timeline.pivots.push((self.t, self.t + duration_s));
        self.hold(duration_s)
    }

    /// The finished timeline.
    pub fn build(&self) -> Timeline {
        self.timeline.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_jerk_moves_start_and_end_at_rest() {
        let mut s = Script::new(DVec3::new(0.0, 0.0, 40.0));
        s.move_in(DVec3::new(100.0, 0.0, 40.0), 1.0);
        let t = s.build();
        assert_eq!(t.tip(0.0), DVec3::new(0.0, 0.0, 40.0));
        assert!((t.tip(0.5).x - 50.0).abs() < 1e-9, "symmetric about the middle");
        assert_eq!(t.tip(1.0).x, 100.0);
        assert_eq!(t.tip(5.0).x, 100.0);
        // Speed is zero at both ends.
        assert!((t.tip(0.001).x - t.tip(0.0).x) < 1e-3);
        assert!((t.tip(1.0).x - t.tip(0.999).x) < 1e-3);
    }

    #[test]
    fn drawing_a_point_touches_lifts_and_ends_with_sw3() {
        let mut s = Script::new(DVec3::new(0.0, 0.0, 40.0));
        s.draw_point(DVec2::new(100.0, 50.0));
        let t = s.build();
        let kinds: Vec<(usize, bool)> = t.events().iter().map(|e| (e.switch, e.pressed)).collect();
        assert_eq!(kinds, [(SW1, true), (SW1, false), (SW3, true), (SW3, false)]);
        let touch = t.events()[0].t_s;
        assert_eq!(t.tip(touch), DVec3::new(100.0, 50.0, 0.0));
        assert_eq!(t.switches(touch), [true, false, false]);
    }
}
