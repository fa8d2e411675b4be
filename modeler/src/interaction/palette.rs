//! The palette: the list of tools, in the order their elements are drawn, and where each one's
//! button sits on the display. Adding a tool is one line in [`tools`].

use penmodel_terrain::document::Point;

use super::figures::Figures;
use super::ridge::Ridges;
use super::river::Rivers;
use super::rocks::Rocks;
use super::tool::Tool;
use super::trees::Trees;
use super::view::View;

/// The side of a tool button, mm.
pub const BUTTON_MM: f64 = 20.0;

/// A square button on the display.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Button {
    /// Its corner nearest the display's origin, mm.
    pub corner_mm: [f64; 2],
    /// Its side, mm.
    pub side_mm: f64,
}

impl Button {
    /// Whether display point `(u, v)` mm is on the button.
    pub fn contains(&self, u_mm: f64, v_mm: f64) -> bool {
        let ([u0, v0], s) = (self.corner_mm, self.side_mm);
        (u0..=u0 + s).contains(&u_mm) && (v0..=v0 + s).contains(&v_mm)
    }

    /// The button's outline on the ground (closed), for drawing.
    pub fn outline(&self, view: &View) -> Vec<Point> {
        let ([u0, v0], s) = (self.corner_mm, self.side_mm);
        let mut pts: Vec<Point> = [[u0, v0], [u0 + s, v0], [u0 + s, v0 + s], [u0, v0 + s]]
            .iter()
            .map(|c| view.to_ground(c[0], c[1]))
            .collect();
        pts.push(pts[0]);
        pts
    }
}

/// Where a tool's button sits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Place {
    /// No button: the tool the others go back to (seed 000's figures).
    Home,
    /// On the display's left edge, 8 mm in, its lower edge `v` mm up from the display's lower
    /// edge (`v` grows up the display, as the pen's `v` does).
    Left(f64),
    /// In the display's lower right corner, 8 mm in from both edges.
    BottomRight,
}

impl Place {
    /// The button on a display of `display_mm`.
    pub fn button(self, display_mm: [f64; 2]) -> Option<Button> {
        let corner_mm = match self {
            Place::Home => return None,
            Place::Left(v) => [8.0, v],
            Place::BottomRight => [display_mm[0] - 8.0 - BUTTON_MM, 8.0],
        };
        Some(Button {
            corner_mm,
            side_mm: BUTTON_MM,
        })
    }
}

/// A tool and its button's place.
#[derive(Debug)]
pub struct Entry {
    /// The tool.
    pub tool: Box<dyn Tool>,
    /// Where its button sits.
    pub place: Place,
}

/// The tools, in the order their elements are drawn; the first is the home tool. One line per
/// tool.
pub fn tools() -> Vec<Entry> {
    vec![
        entry::<Figures>(Place::Home),
        entry::<Rocks>(Place::Left(8.0)),
        entry::<Rivers>(Place::Left(32.0)),
        entry::<Ridges>(Place::BottomRight),
        entry::<Trees>(Place::Left(56.0)),
    ]
}

fn entry<T: Tool + Default>(place: Place) -> Entry {
    Entry {
        tool: Box::<T>::default(),
        place,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_buttons_do_not_overlap() {
        let display = [600.0, 340.0];
        let list = tools();
        let names: std::collections::BTreeSet<_> = list.iter().map(|e| e.tool.name()).collect();
        assert_eq!(names.len(), list.len());
        assert_eq!(list[0].place, Place::Home);
        let buttons: Vec<Button> = list.iter().filter_map(|e| e.place.button(display)).collect();
        assert_eq!(
            buttons.len(),
            list.len() - 1,
            "every tool but the home one has a button"
        );
        for (i, a) in buttons.iter().enumerate() {
            for b in &buttons[i + 1..] {
                let apart = (a.corner_mm[0] - b.corner_mm[0]).abs() > BUTTON_MM
                    || (a.corner_mm[1] - b.corner_mm[1]).abs() > BUTTON_MM;
                assert!(apart, "{a:?} overlaps {b:?}");
            }
        }
    }
}
