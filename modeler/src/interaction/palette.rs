//! The tool buttons on the display: squares in display millimetres that pick a tool (rocks,
//! rivers, ridgelines), drawn as outlines on the ground.

use penmodel_terrain::document::Point;

use super::view::View;

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
