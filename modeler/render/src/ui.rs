//! The 2D layer drawn over the terrain: the slope bar and the mode line.
//!
//! Both are laid out in the eye's viewport (for side-by-side stereo, each half gets its own,
//! squeezed like the rest of the half), at zero parallax. They sit on translucent dark panels so
//! they read on snow as well as on water.

use super::frame::{Frame, Rgba};
use super::rasterise::Bounds;
use super::scene::{SlopeBar, Style};
use super::text;

/// Colour of the slope bar's track.
pub const TRACK_COLOUR: Rgba = [70, 70, 76, 255];
/// Colour of the slope bar's tick at the neutral value 0.
pub const TICK_COLOUR: Rgba = [180, 180, 180, 255];
/// How much of the frame shows through a panel, 0 to 1.
const PANEL_SHOW: f32 = 0.45;
/// Margin around panels, pixels.
const MARGIN: i64 = 8;

/// Where the slope bar's track is, in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BarLayout {
    /// Left end.
    pub x: i64,
    /// Top.
    pub y: i64,
    /// Length.
    pub width: i64,
    /// Thickness.
    pub height: i64,
}

impl BarLayout {
    /// The track's layout in `viewport`: centred, 40 % of its width, near the bottom.
    pub fn of(viewport: &Bounds, style: &Style) -> BarLayout {
        let vw = i64::from(viewport.x1 - viewport.x0);
        let width = (vw * 2 / 5).max(16);
        let height = (i64::from(style.text_scale) * 5).max(6);
        let text_h = i64::from(text::height(style.text_scale));
        BarLayout {
            x: i64::from(viewport.x0) + (vw - width) / 2,
            y: i64::from(viewport.y1) - MARGIN * 2 - text_h - height,
            width,
            height,
        }
    }

    /// The column of a value at `position` (0 to 1) along the track.
    pub fn column(&self, position: f64) -> i64 {
        self.x + (position * (self.width - 1) as f64).round() as i64
    }
}

fn fill(frame: &mut Frame, clip: &Bounds, (x0, y0, x1, y1): (i64, i64, i64, i64), colour: Rgba, show: f32) {
    let w = frame.width() as usize;
    let x0 = x0.max(i64::from(clip.x0));
    let x1 = x1.min(i64::from(clip.x1));
    let y0 = y0.max(i64::from(clip.y0));
    let y1 = y1.min(i64::from(clip.y1));
    let pixels = frame.pixels_mut();
    for y in y0.max(0)..y1 {
        for x in x0.max(0)..x1 {
            let p = &mut pixels[y as usize * w + x as usize];
            for i in 0..3 {
                p[i] = (f32::from(p[i]) * show + f32::from(colour[i]) * (1.0 - show)).round() as u8;
            }
            p[3] = 255;
        }
    }
}

/// Draws the slope bar into `viewport`: a panel, the track, a tick at 0 when the range holds it,
/// the marker at the value's position (selection colour), the label and value above, the range's
/// ends below.
pub fn slope_bar(frame: &mut Frame, viewport: &Bounds, bar: &SlopeBar, style: &Style) {
    let l = BarLayout::of(viewport, style);
    let s = style.text_scale.max(1);
    let th = i64::from(text::height(s));
    fill(
        frame,
        viewport,
        (
            l.x - MARGIN,
            l.y - th - MARGIN,
            l.x + l.width + MARGIN,
            l.y + l.height + th + MARGIN,
        ),
        [0, 0, 0, 255],
        PANEL_SHOW,
    );
    fill(
        frame,
        viewport,
        (l.x, l.y, l.x + l.width, l.y + l.height),
        TRACK_COLOUR,
        0.0,
    );
    if bar.min < 0.0 && bar.max > 0.0 || bar.min > 0.0 && bar.max < 0.0 {
        let zero = SlopeBar {
            value: 0.0,
            ..bar.clone()
        };
        let x = l.column(zero.position());
        fill(frame, viewport, (x, l.y, x + 1, l.y + l.height), TICK_COLOUR, 0.0);
    }
    let x = l.column(bar.position());
    let half = i64::from(s) * 2;
    fill(
        frame,
        viewport,
        (x - half, l.y - 2, x + half + 1, l.y + l.height + 2),
        style.selection_colour,
        0.0,
    );
    let caption = format!("{} {:.2}", bar.label, bar.value);
    let cw = i64::from(text::width(&caption, s));
    text::draw(
        frame,
        viewport,
        (l.x + (l.width - cw) / 2, l.y - th - 2),
        &caption,
        style.text_colour,
        s,
    );
    let (lo, hi) = (format!("{:.1}", bar.min), format!("{:.1}", bar.max));
    text::draw(frame, viewport, (l.x, l.y + l.height + 4), &lo, style.text_colour, s);
    let hw = i64::from(text::width(&hi, s));
    text::draw(
        frame,
        viewport,
        (l.x + l.width - hw, l.y + l.height + 4),
        &hi,
        style.text_colour,
        s,
    );
}

/// Draws the mode line at the top left of `viewport`, on a panel.
pub fn mode_line(frame: &mut Frame, viewport: &Bounds, mode: &str, style: &Style) {
    if mode.is_empty() {
        return;
    }
    let s = style.text_scale.max(1);
    let (x, y) = (i64::from(viewport.x0) + MARGIN, i64::from(viewport.y0) + MARGIN);
    let w = i64::from(text::width(mode, s));
    let h = i64::from(text::height(s));
    fill(
        frame,
        viewport,
        (x - MARGIN / 2, y - MARGIN / 2, x + w + MARGIN / 2, y + h + MARGIN / 2),
        [0, 0, 0, 255],
        PANEL_SHOW,
    );
    text::draw(frame, viewport, (x, y), mode, style.text_colour, s);
}
