//! A built-in bitmap font: 5 × 7 pixel glyphs for printable ASCII, no font files.
//!
//! Each glyph is five column bytes, bit 0 the top row (the classic public-domain 5 × 7 LCD
//! character set), and bit 7 the descender row below the baseline, which `g j p q y` use — in
//! the 5 × 7 set they sit on the baseline, and `g` reads as `9`. A glyph cell is 6 × 8 font
//! pixels (one column of spacing; the eighth row is the descenders' or the line's spacing), drawn
//! at an integer scale. Beyond ASCII 32–126 only the symbols the messages use (`°`, `×`, `µ`,
//! dashes, `±`, `²`) have glyphs; anything else is drawn as `?`.

use crate::output::frame::{Frame, Rgba};
use crate::raster::rasterise::Bounds;

/// Font pixels per glyph cell, horizontally.
pub(crate) const CELL_WIDTH: u32 = 6;
/// Font pixels per glyph cell, vertically.
pub(crate) const CELL_HEIGHT: u32 = 8;

#[rustfmt::skip]
const GLYPHS: [[u8; 5]; 95] = [
    [0x00, 0x00, 0x00, 0x00, 0x00], // ' '
    [0x00, 0x00, 0x5F, 0x00, 0x00], // !
    [0x00, 0x07, 0x00, 0x07, 0x00], // "
    [0x14, 0x7F, 0x14, 0x7F, 0x14], // #
    [0x24, 0x2A, 0x7F, 0x2A, 0x12], // $
    [0x23, 0x13, 0x08, 0x64, 0x62], // %
    [0x36, 0x49, 0x55, 0x22, 0x50], // &
    [0x00, 0x05, 0x03, 0x00, 0x00], // '
    [0x00, 0x1C, 0x22, 0x41, 0x00], // (
    [0x00, 0x41, 0x22, 0x1C, 0x00], // )
    [0x08, 0x2A, 0x1C, 0x2A, 0x08], // *
    [0x08, 0x08, 0x3E, 0x08, 0x08], // +
    [0x00, 0x50, 0x30, 0x00, 0x00], // ,
    [0x08, 0x08, 0x08, 0x08, 0x08], // -
    [0x00, 0x60, 0x60, 0x00, 0x00], // .
    [0x20, 0x10, 0x08, 0x04, 0x02], // /
    [0x3E, 0x51, 0x49, 0x45, 0x3E], // 0
    [0x00, 0x42, 0x7F, 0x40, 0x00], // 1
    [0x42, 0x61, 0x51, 0x49, 0x46], // 2
    [0x21, 0x41, 0x45, 0x4B, 0x31], // 3
    [0x18, 0x14, 0x12, 0x7F, 0x10], // 4
    [0x27, 0x45, 0x45, 0x45, 0x39], // 5
    [0x3C, 0x4A, 0x49, 0x49, 0x30], // 6
    [0x01, 0x71, 0x09, 0x05, 0x03], // 7
    [0x36, 0x49, 0x49, 0x49, 0x36], // 8
    [0x06, 0x49, 0x49, 0x29, 0x1E], // 9
    [0x00, 0x36, 0x36, 0x00, 0x00], // :
    [0x00, 0x56, 0x36, 0x00, 0x00], // ;
    [0x08, 0x14, 0x22, 0x41, 0x00], // <
    [0x14, 0x14, 0x14, 0x14, 0x14], // =
    [0x00, 0x41, 0x22, 0x14, 0x08], // >
    [0x02, 0x01, 0x51, 0x09, 0x06], // ?
    [0x32, 0x49, 0x79, 0x41, 0x3E], // @
    [0x7E, 0x11, 0x11, 0x11, 0x7E], // A
    [0x7F, 0x49, 0x49, 0x49, 0x36], // B
    [0x3E, 0x41, 0x41, 0x41, 0x22], // C
    [0x7F, 0x41, 0x41, 0x22, 0x1C], // D
    [0x7F, 0x49, 0x49, 0x49, 0x41], // E
    [0x7F, 0x09, 0x09, 0x09, 0x01], // F
    [0x3E, 0x41, 0x49, 0x49, 0x7A], // G
    [0x7F, 0x08, 0x08, 0x08, 0x7F], // H
    [0x00, 0x41, 0x7F, 0x41, 0x00], // I
    [0x20, 0x40, 0x41, 0x3F, 0x01], // J
    [0x7F, 0x08, 0x14, 0x22, 0x41], // K
    [0x7F, 0x40, 0x40, 0x40, 0x40], // L
    [0x7F, 0x02, 0x0C, 0x02, 0x7F], // M
    [0x7F, 0x04, 0x08, 0x10, 0x7F], // N
    [0x3E, 0x41, 0x41, 0x41, 0x3E], // O
    [0x7F, 0x09, 0x09, 0x09, 0x06], // P
    [0x3E, 0x41, 0x51, 0x21, 0x5E], // Q
    [0x7F, 0x09, 0x19, 0x29, 0x46], // R
    [0x46, 0x49, 0x49, 0x49, 0x31], // S
    [0x01, 0x01, 0x7F, 0x01, 0x01], // T
    [0x3F, 0x40, 0x40, 0x40, 0x3F], // U
    [0x1F, 0x20, 0x40, 0x20, 0x1F], // V
    [0x3F, 0x40, 0x38, 0x40, 0x3F], // W
    [0x63, 0x14, 0x08, 0x14, 0x63], // X
    [0x07, 0x08, 0x70, 0x08, 0x07], // Y
    [0x61, 0x51, 0x49, 0x45, 0x43], // Z
    [0x00, 0x7F, 0x41, 0x41, 0x00], // [
    [0x02, 0x04, 0x08, 0x10, 0x20], // backslash
    [0x00, 0x41, 0x41, 0x7F, 0x00], // ]
    [0x04, 0x02, 0x01, 0x02, 0x04], // ^
    [0x40, 0x40, 0x40, 0x40, 0x40], // _
    [0x00, 0x01, 0x02, 0x04, 0x00], // `
    [0x20, 0x54, 0x54, 0x54, 0x78], // a
    [0x7F, 0x48, 0x44, 0x44, 0x38], // b
    [0x38, 0x44, 0x44, 0x44, 0x20], // c
    [0x38, 0x44, 0x44, 0x48, 0x7F], // d
    [0x38, 0x54, 0x54, 0x54, 0x18], // e
    [0x08, 0x7E, 0x09, 0x01, 0x02], // f
    [0x18, 0xA4, 0xA4, 0xA4, 0x7C], // g
    [0x7F, 0x08, 0x04, 0x04, 0x78], // h
    [0x00, 0x44, 0x7D, 0x40, 0x00], // i
    [0x40, 0x80, 0x84, 0x7D, 0x00], // j
    [0x7F, 0x10, 0x28, 0x44, 0x00], // k
    [0x00, 0x41, 0x7F, 0x40, 0x00], // l
    [0x7C, 0x04, 0x18, 0x04, 0x78], // m
    [0x7C, 0x08, 0x04, 0x04, 0x78], // n
    [0x38, 0x44, 0x44, 0x44, 0x38], // o
    [0xFC, 0x24, 0x24, 0x24, 0x18], // p
    [0x18, 0x24, 0x24, 0x24, 0xFC], // q
    [0x7C, 0x08, 0x04, 0x04, 0x08], // r
    [0x48, 0x54, 0x54, 0x54, 0x20], // s
    [0x04, 0x3F, 0x44, 0x40, 0x20], // t
    [0x3C, 0x40, 0x40, 0x20, 0x7C], // u
    [0x1C, 0x20, 0x40, 0x20, 0x1C], // v
    [0x3C, 0x40, 0x30, 0x40, 0x3C], // w
    [0x44, 0x28, 0x10, 0x28, 0x44], // x
    [0x1C, 0xA0, 0xA0, 0xA0, 0x7C], // y
    [0x44, 0x64, 0x54, 0x4C, 0x44], // z
    [0x00, 0x08, 0x36, 0x41, 0x00], // {
    [0x00, 0x00, 0x7F, 0x00, 0x00], // |
    [0x00, 0x41, 0x36, 0x08, 0x00], // }
    [0x08, 0x04, 0x08, 0x10, 0x08], // ~
];

/// The symbols beyond ASCII that the modeler's messages use, in the same form.
#[rustfmt::skip]
const EXTRA: [(char, [u8; 5]); 10] = [
    ('°', [0x00, 0x06, 0x09, 0x09, 0x06]),
    ('×', [0x00, 0x22, 0x14, 0x08, 0x14]),
    ('µ', [0xFC, 0x40, 0x40, 0x20, 0x7C]),
    ('—', [0x08, 0x08, 0x08, 0x08, 0x08]),
    ('–', [0x00, 0x08, 0x08, 0x08, 0x00]),
    ('−', [0x08, 0x08, 0x08, 0x08, 0x08]),
    ('·', [0x00, 0x00, 0x08, 0x00, 0x00]),
    ('…', [0x40, 0x00, 0x40, 0x00, 0x40]),
    ('±', [0x44, 0x44, 0x5F, 0x44, 0x44]),
    ('²', [0x00, 0x19, 0x15, 0x12, 0x00]),
];

/// The five column bytes of `ch` (bit 0 = top row, bit 7 = the descender row).
pub fn glyph(ch: char) -> [u8; 5] {
    let code = ch as u32;
    if (32..127).contains(&code) {
        return GLYPHS[(code - 32) as usize];
    }
    EXTRA
        .iter()
        .find(|(c, _)| *c == ch)
        .map_or(GLYPHS[usize::from(b'?' - 32)], |(_, g)| *g)
}

/// Width in pixels of `text` drawn at `scale`.
pub(crate) fn width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * CELL_WIDTH * scale
}

/// Height in pixels of a line at `scale`.
pub(crate) fn height(scale: u32) -> u32 {
    CELL_HEIGHT * scale
}

/// How many glyphs fit in `max_px` at `scale` (0 when none does).
pub(crate) fn fitting(max_px: i64, scale: u32) -> usize {
    let cell = i64::from(CELL_WIDTH * scale.max(1));
    (max_px.max(0) / cell) as usize
}

/// `text` cut to `chars` glyphs, its last one `…` when anything was cut.
pub(crate) fn ellipsize(text: &str, chars: usize) -> String {
    if text.chars().count() <= chars {
        return text.to_string();
    }
    if chars == 0 {
        return String::new();
    }
    let mut cut: String = text.chars().take(chars - 1).collect();
    cut.truncate(cut.trim_end().len());
    cut.push('…');
    cut
}

/// `text` in lines of at most `chars` glyphs, broken at spaces; a word longer than a line is cut
/// with `…`. At least one line (empty for empty text).
pub(crate) fn wrap(text: &str, chars: usize) -> Vec<String> {
    let chars = chars.max(1);
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let word = ellipsize(word, chars);
        let (have, add) = (line.chars().count(), word.chars().count());
        if have > 0 && have + 1 + add > chars {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(&word);
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// Draws `text` with its top-left corner at `(x, y)`; pixels outside `clip` or the frame are
/// skipped.
pub(crate) fn draw(frame: &mut Frame, clip: &Bounds, (x, y): (i64, i64), text: &str, colour: Rgba, scale: u32) {
    let scale = i64::from(scale.max(1));
    let xs = i64::from(clip.x0).max(0)..i64::from(clip.x1).min(i64::from(frame.width()));
    let ys = i64::from(clip.y0).max(0)..i64::from(clip.y1).min(i64::from(frame.height()));
    let stride = frame.width() as usize;
    let pixels = frame.pixels_mut();
    for (i, ch) in text.chars().enumerate() {
        let gx = x + i as i64 * i64::from(CELL_WIDTH) * scale;
        for (col, bits) in glyph(ch).iter().enumerate() {
            for row in 0..8 {
                if bits >> row & 1 == 0 {
                    continue;
                }
                for dy in 0..scale {
                    let py = y + row * scale + dy;
                    for dx in 0..scale {
                        let px = gx + col as i64 * scale + dx;
                        if xs.contains(&px) && ys.contains(&py) {
                            pixels[py as usize * stride + px as usize] = colour;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_messages_symbols_have_glyphs() {
        let unknown = glyph('\u{2603}');
        assert_eq!(unknown, glyph('?'));
        for ch in "°×µ—–−·…±²".chars() {
            assert_ne!(glyph(ch), unknown, "{ch}");
        }
    }

    #[test]
    fn a_long_text_is_cut_with_an_ellipsis_or_wrapped_at_spaces() {
        assert_eq!(ellipsize("short", 5), "short");
        assert_eq!(ellipsize("a longer line", 8), "a longe…");
        assert_eq!(ellipsize("a b  c", 4), "a b…");
        assert_eq!(ellipsize("any", 0), "");
        assert_eq!(fitting(60, 2), 5);
        assert_eq!(fitting(-3, 1), 0);
        assert_eq!(
            wrap("the polyline is outside every region", 14),
            ["the polyline", "is outside", "every region"]
        );
        assert_eq!(wrap("unbreakable_word here", 6), ["unbre…", "here"]);
        assert_eq!(wrap("", 10), [""]);
        for line in wrap("x ".repeat(40).as_str(), 7) {
            assert!(line.chars().count() <= 7, "{line}");
        }
    }

    /// The rows a glyph lights, as a bit set (bit 0 the top row).
    fn rows(ch: char) -> u8 {
        glyph(ch).iter().fold(0, |acc, col| acc | col)
    }

    #[test]
    fn lowercase_letters_without_ascenders_stay_below_the_x_height() {
        // Rows 0 and 1 belong to capitals, digits and ascenders; a lowercase letter that uses them
        // reads as something else (the old `g` read as `9`).
        for ch in "acegmnopqrsuvwxyz".chars() {
            assert_eq!(rows(ch) & 0b11, 0, "{ch} reaches above the x-height");
            assert_ne!(rows(ch) >> 2, 0, "{ch} is empty");
        }
        for ch in "bdfhklt0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ".chars() {
            assert_ne!(rows(ch) & 0b11, 0, "{ch} should reach above the x-height");
        }
    }

    #[test]
    fn only_descenders_go_below_the_baseline() {
        for code in 32u8..127 {
            let ch = char::from(code);
            let below = rows(ch) & 0x80 != 0;
            assert_eq!(below, "gjpqy".contains(ch), "{ch}");
        }
    }

    #[test]
    fn letters_that_look_alike_differ_in_several_pixels() {
        let differ = |a: char, b: char| {
            glyph(a)
                .iter()
                .zip(glyph(b))
                .map(|(x, y)| (x ^ y).count_ones())
                .sum::<u32>()
        };
        for (a, b) in [('g', '9'), ('g', 'q'), ('g', 'y'), ('a', 'g'), ('o', '0')] {
            assert!(differ(a, b) >= 4, "{a} and {b} differ in {} pixels", differ(a, b));
        }
    }
}
