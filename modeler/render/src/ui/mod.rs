//! The 2D layer drawn over the terrain: the slope bar, the mode line, and text panels (the
//! window's help, a notice under the mode line).
//!
//! Both are laid out in the eye's viewport (for side-by-side stereo, each half gets its own,
//! squeezed like the rest of the half), at zero parallax. They sit on translucent dark panels so
//! they read on snow as well as on water.

pub(crate) mod overlay;
pub(crate) mod text;

use crate::output::frame::{Frame, Rgba};
use crate::raster::rasterise::Bounds;
use crate::scene::{SlopeBar, Style};

/// Colour of the slope bar's track.
pub(crate) const TRACK_COLOUR: Rgba = [70, 70, 76, 255];
/// Colour of the slope bar's tick at the neutral value 0.
pub(crate) const TICK_COLOUR: Rgba = [180, 180, 180, 255];
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
pub(crate) fn slope_bar(frame: &mut Frame, viewport: &Bounds, bar: &SlopeBar, style: &Style) {
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

/// Draws the mode line at the top left of `viewport`, on a panel; a line wider than the viewport
/// is cut with `…`.
pub(crate) fn mode_line(frame: &mut Frame, viewport: &Bounds, mode: &str, style: &Style) {
    if mode.is_empty() {
        return;
    }
    let s = style.text_scale.max(1);
    let (x, y) = (i64::from(viewport.x0) + MARGIN, i64::from(viewport.y0) + MARGIN);
    let room = i64::from(viewport.x1) - i64::from(viewport.x0) - 2 * MARGIN;
    let mode = text::ellipsize(mode, text::fitting(room, s));
    let w = i64::from(text::width(&mode, s));
    let h = i64::from(text::height(s));
    fill(
        frame,
        viewport,
        (x - MARGIN / 2, y - MARGIN / 2, x + w + MARGIN / 2, y + h + MARGIN / 2),
        [0, 0, 0, 255],
        PANEL_SHOW,
    );
    text::draw(frame, viewport, (x, y), &mode, style.text_colour, s);
}

/// Where [`panel`] puts its text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// In the middle of the viewport (the help): in columns, and at a smaller scale, when the
    /// lines do not fit otherwise.
    Centre,
    /// At the top left, under the mode line (a notice): lines wider than the viewport wrap.
    UnderModeLine,
    /// Centred on this pixel of the frame (a tool button's label).
    CentredOn {
        /// Column.
        x: i64,
        /// Row.
        y: i64,
    },
}

/// Glyph cells between two columns of a panel.
const COLUMN_GAP_CELLS: u32 = 3;

/// A panel's text laid out: its scale, its columns of lines, and each column's width in glyphs.
struct Layout {
    scale: u32,
    columns: Vec<Vec<String>>,
    column_chars: usize,
}

impl Layout {
    fn line_h(&self) -> i64 {
        i64::from(text::height(self.scale)) + i64::from(self.scale)
    }

    fn gap(&self) -> i64 {
        i64::from(COLUMN_GAP_CELLS * text::CELL_WIDTH * self.scale)
    }

    fn column_w(&self) -> i64 {
        i64::from(text::CELL_WIDTH * self.scale) * self.column_chars as i64
    }

    fn size(&self) -> (i64, i64) {
        let cols = self.columns.len() as i64;
        let rows = self.columns.iter().map(Vec::len).max().unwrap_or(0) as i64;
        (
            cols * self.column_w() + (cols - 1).max(0) * self.gap(),
            rows * self.line_h(),
        )
    }

    /// `lines` in one column at `scale`, each cut to `chars` glyphs.
    fn one(lines: Vec<String>, scale: u32, chars: usize) -> Layout {
        let lines: Vec<String> = lines.iter().map(|l| text::ellipsize(l, chars)).collect();
        let column_chars = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0);
        Layout {
            scale,
            columns: vec![lines],
            column_chars,
        }
    }

    /// `lines` in as few columns as fit `room_h` and the largest scale up to `scale` at which
    /// those columns fit `room_w`; at scale 1 lines still too wide are cut with `…`.
    fn columns(lines: &[String], scale: u32, (room_w, room_h): (i64, i64)) -> Layout {
        let widest = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0);
        for s in (1..=scale.max(1)).rev() {
            let line_h = i64::from(text::height(s)) + i64::from(s);
            let rows = ((room_h / line_h).max(1) as usize).min(lines.len().max(1));
            let cols = lines.len().div_ceil(rows).max(1);
            // Balanced: as many rows in each column as the first needs.
            let rows = lines.len().div_ceil(cols);
            let cell = i64::from(text::CELL_WIDTH * s);
            let gap = i64::from(COLUMN_GAP_CELLS) * cell;
            let need = cols as i64 * cell * widest as i64 + (cols as i64 - 1) * gap;
            if need <= room_w || s == 1 {
                let chars = if need <= room_w {
                    widest
                } else {
                    text::fitting((room_w - (cols as i64 - 1) * gap) / cols as i64, s)
                };
                let columns: Vec<Vec<String>> = lines
                    .chunks(rows)
                    .map(|c| {
                        // A column does not start with the blank line between two sections.
                        let skip = usize::from(c.first().is_some_and(String::is_empty));
                        c[skip..].iter().map(|l| text::ellipsize(l, chars)).collect()
                    })
                    .collect();
                let column_chars = columns.iter().flatten().map(|l| l.chars().count()).max().unwrap_or(0);
                return Layout {
                    scale: s,
                    columns,
                    column_chars,
                };
            }
        }
        Layout::one(lines.to_vec(), 1, widest)
    }
}

/// Draws `lines` on a translucent panel in `viewport`, kept within its width: the help
/// ([`Place::Centre`]) in columns and smaller when it must, a notice wrapped, a label cut with
/// `…`. Nothing is drawn for no lines.
pub fn panel(frame: &mut Frame, viewport: &Bounds, lines: &[String], place: Place, style: &Style) {
    if lines.is_empty() {
        return;
    }
    let s = style.text_scale.max(1);
    let (vx0, vy0) = (i64::from(viewport.x0), i64::from(viewport.y0));
    let (vw, vh) = (i64::from(viewport.x1) - vx0, i64::from(viewport.y1) - vy0);
    let room = (vw - 2 * MARGIN, vh - 2 * MARGIN);
    let chars = text::fitting(room.0, s);
    let layout = match place {
        Place::Centre => Layout::columns(lines, s, room),
        Place::UnderModeLine => Layout::one(lines.iter().flat_map(|l| text::wrap(l, chars)).collect(), s, chars),
        Place::CentredOn { .. } => Layout::one(lines.to_vec(), s, chars),
    };
    let (w, h) = layout.size();
    let line_h = layout.line_h();
    let (x, y) = match place {
        Place::Centre => (vx0 + ((vw - w) / 2).max(MARGIN), vy0 + ((vh - h) / 2).max(MARGIN)),
        Place::UnderModeLine => (vx0 + MARGIN, vy0 + MARGIN * 2 + line_h),
        // Kept inside the viewport, so a label at its edge is read whole.
        Place::CentredOn { x, y } => (
            (x - w / 2).clamp(vx0 + MARGIN, (vx0 + vw - w - MARGIN).max(vx0 + MARGIN)),
            (y - h / 2).clamp(vy0 + MARGIN, (vy0 + vh - h - MARGIN).max(vy0 + MARGIN)),
        ),
    };
    fill(
        frame,
        viewport,
        (x - MARGIN, y - MARGIN, x + w + MARGIN, y + h + MARGIN),
        [0, 0, 0, 255],
        PANEL_SHOW / 2.0,
    );
    for (c, column) in layout.columns.iter().enumerate() {
        let cx = x + c as i64 * (layout.column_w() + layout.gap());
        for (i, line) in column.iter().enumerate() {
            text::draw(
                frame,
                viewport,
                (cx, y + i as i64 * line_h),
                line,
                style.text_colour,
                layout.scale,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lit(frame: &Frame, colour: Rgba) -> Vec<(u32, u32)> {
        let w = frame.width();
        frame
            .pixels()
            .iter()
            .enumerate()
            .filter(|(_, p)| **p == colour)
            .map(|(i, _)| (i as u32 % w, i as u32 / w))
            .collect()
    }

    /// The default style, a 320 × 200 grey frame and its whole bounds.
    fn grey_frame() -> (Style, Frame, Bounds) {
        let mut frame = Frame::new(320, 200).expect("frame");
        frame.pixels_mut().fill([100, 100, 100, 255]);
        let all = Bounds {
            x0: 0,
            x1: 320,
            y0: 0,
            y1: 200,
        };
        (Style::default(), frame, all)
    }

    #[test]
    fn a_label_centred_at_the_edge_is_kept_whole_inside() {
        let (style, mut frame, all) = grey_frame();
        let label = vec!["rivers".to_string()];
        panel(&mut frame, &all, &label, Place::CentredOn { x: 0, y: 100 }, &style);
        let text = lit(&frame, style.text_colour);
        let x0 = text.iter().map(|p| p.0).min().expect("text drawn");
        assert!(x0 >= MARGIN as u32, "starts inside, at {x0}");
        // As wide as the whole label: nothing was cut at the edge.
        let x1 = text.iter().map(|p| p.0).max().expect("text drawn");
        let s = style.text_scale.max(1);
        assert!(
            x1 - x0 + 1 >= text::width("rivers", s) - text::CELL_WIDTH * s,
            "{x0}..{x1}"
        );
    }

    #[test]
    fn a_panel_darkens_its_box_and_writes_each_line_inside_it() {
        let (style, mut frame, all) = grey_frame();
        let lines = vec!["keys".to_string(), "  u  undo".to_string()];
        panel(&mut frame, &all, &lines, Place::Centre, &style);
        let text = lit(&frame, style.text_colour);
        assert!(!text.is_empty());
        // Centred: the text's box has its middle near the frame's.
        let (x0, x1) = (
            text.iter().map(|p| p.0).min().unwrap(),
            text.iter().map(|p| p.0).max().unwrap(),
        );
        let (y0, y1) = (
            text.iter().map(|p| p.1).min().unwrap(),
            text.iter().map(|p| p.1).max().unwrap(),
        );
        assert!(((x0 + x1) as i64 - 320).abs() < 24, "{x0}..{x1}");
        assert!(((y0 + y1) as i64 - 200).abs() < 24, "{y0}..{y1}");
        // Two lines: text in two bands of rows.
        assert!(y1 - y0 > text::height(style.text_scale));
        // The panel is darker than the frame; the corners are untouched.
        let p = frame.pixels()[(y0 as usize - 2) * 320 + x0 as usize];
        assert!(p[0] < 100, "{p:?}");
        assert_eq!(frame.pixels()[0], [100, 100, 100, 255]);
    }

    /// The columns of text pixels `frame` shows, first and last.
    fn text_span(frame: &Frame, style: &Style) -> (u32, u32, u32, u32) {
        let text = lit(frame, style.text_colour);
        (
            text.iter().map(|p| p.0).min().expect("text drawn"),
            text.iter().map(|p| p.0).max().expect("text drawn"),
            text.iter().map(|p| p.1).min().expect("text drawn"),
            text.iter().map(|p| p.1).max().expect("text drawn"),
        )
    }

    #[test]
    fn a_long_mode_line_ends_in_an_ellipsis_inside_the_viewport() {
        let (style, mut frame, all) = grey_frame();
        let long = "grabbed point 3: pull 1200 m, slope 0.40 | the polyline is outside every region";
        mode_line(&mut frame, &all, long, &style);
        let (_, x1, _, _) = text_span(&frame, &style);
        assert!(i64::from(x1) < 320 - MARGIN, "text to column {x1} of 320");
        // The last glyph drawn is the ellipsis: three dots on the baseline row.
        let s = style.text_scale.max(1);
        let cells = text::fitting(320 - 2 * MARGIN, s) as i64;
        let last = MARGIN + (cells - 1) * i64::from(text::CELL_WIDTH * s);
        let dots = lit(&frame, style.text_colour)
            .iter()
            .filter(|p| i64::from(p.0) >= last)
            .count();
        assert_eq!(dots as u32, 3 * s * s, "an ellipsis at the end");
        // The panel behind it stops inside the frame too.
        assert_eq!(frame.pixels()[10 * 320 + 318], [100, 100, 100, 255]);
    }

    #[test]
    fn a_long_notice_wraps_within_the_viewport() {
        let (style, mut frame, all) = grey_frame();
        let long = "the polyline is outside every region: draw a closed curve around the place first".to_string();
        panel(&mut frame, &all, &[long], Place::UnderModeLine, &style);
        let (x0, x1, y0, y1) = text_span(&frame, &style);
        assert!(i64::from(x0) >= MARGIN && i64::from(x1) < 320 - MARGIN, "{x0}..{x1}");
        let line_h = text::height(style.text_scale) + style.text_scale;
        assert!(y1 - y0 > 2 * line_h, "wrapped on three lines or more: rows {y0}..{y1}");
    }

    #[test]
    fn a_help_taller_than_the_viewport_flows_into_columns_that_fit() {
        let (style, mut frame, all) = grey_frame();
        let lines: Vec<String> = (0..40).map(|i| format!("line {i:2} of the help")).collect();
        panel(&mut frame, &all, &lines, Place::Centre, &style);
        let (x0, x1, y0, y1) = text_span(&frame, &style);
        assert!(i64::from(x0) >= MARGIN && i64::from(x1) < 320 - MARGIN, "{x0}..{x1}");
        assert!(i64::from(y0) >= MARGIN && i64::from(y1) < 200 - MARGIN, "{y0}..{y1}");
        // Every line is there: the last line's number shows, at scale 1 in several columns.
        let layout = Layout::columns(&lines, style.text_scale, (320 - 2 * MARGIN, 200 - 2 * MARGIN));
        assert!(layout.columns.len() > 1, "columns");
        let shown: Vec<&String> = layout.columns.iter().flatten().collect();
        assert_eq!(shown.len(), 40);
        assert!(shown.iter().all(|l| !l.ends_with('…')), "{shown:?}");
    }

    #[test]
    fn a_notice_sits_under_the_mode_line_and_nothing_is_drawn_for_no_lines() {
        let style = Style::default();
        let all = Bounds {
            x0: 0,
            x1: 320,
            y0: 0,
            y1: 200,
        };
        let mut frame = Frame::new(320, 200).expect("frame");
        panel(&mut frame, &all, &[], Place::UnderModeLine, &style);
        assert!(frame.pixels().iter().all(|p| *p == [0, 0, 0, 0]));
        mode_line(&mut frame, &all, "mode", &style);
        let mode_bottom = lit(&frame, style.text_colour).iter().map(|p| p.1).max().unwrap();
        let mut notice = Frame::new(320, 200).expect("frame");
        panel(&mut notice, &all, &["saved".to_string()], Place::UnderModeLine, &style);
        let top = lit(&notice, style.text_colour).iter().map(|p| p.1).min().unwrap();
        assert!(top > mode_bottom, "notice at {top}, mode line down to {mode_bottom}");
    }
}
