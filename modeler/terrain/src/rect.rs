//! A rectangle of grid cells: the unit in which the engine and the layers (ridges, rivers) say
//! what changed. Its own module so the layers can name it without naming the engine, which
//! names them.

use crate::cells::Mask;

/// A rectangle of cells: columns `c0..c0 + width`, rows `r0..r0 + height`.
#[allow(missing_docs)] // the fields are the ranges above.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rect {
    pub c0: u32,
    pub r0: u32,
    pub width: u32,
    pub height: u32,
}

impl Rect {
    /// No cells; the identity of [`Rect::union`].
    pub const EMPTY: Rect = Rect {
        c0: 0,
        r0: 0,
        width: 0,
        height: 0,
    };

    /// The box of a mask.
    pub(crate) fn of(mask: &Mask) -> Rect {
        Rect {
            c0: mask.c0,
            r0: mask.r0,
            width: mask.width,
            height: mask.height,
        }
    }

    /// The smallest rectangle holding both.
    pub fn union(self, other: Rect) -> Rect {
        if self.width == 0 || self.height == 0 {
            return other;
        }
        if other.width == 0 || other.height == 0 {
            return self;
        }
        let c0 = self.c0.min(other.c0);
        let r0 = self.r0.min(other.r0);
        let c1 = (self.c0 + self.width).max(other.c0 + other.width);
        let r1 = (self.r0 + self.height).max(other.r0 + other.height);
        Rect {
            c0,
            r0,
            width: c1 - c0,
            height: r1 - r0,
        }
    }
}

// A river's window and the engine's rectangle are the same cells; the rivers do not name the
// engine (it names them).
impl From<Rect> for crate::river::Window {
    fn from(r: Rect) -> crate::river::Window {
        crate::river::Window {
            c0: r.c0,
            r0: r.r0,
            width: r.width as usize,
            height: r.height as usize,
        }
    }
}

impl From<crate::river::Window> for Rect {
    fn from(w: crate::river::Window) -> Rect {
        Rect {
            c0: w.c0,
            r0: w.r0,
            width: w.width as u32,
            height: w.height as u32,
        }
    }
}
