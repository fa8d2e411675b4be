//! How the pen's display shows the ground: the seed's set-up, where the display surface *is* the
//! ground plane. A point the pen touches at `(u, v)` on the display is the ground point drawn
//! there, and a height above the display is a height above the ground.

use penmodel_terrain::document::{Grid, Point};

/// The display-to-ground mapping, with pan, zoom, the vertical scale and the ground's tilt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// The display's picture, `[width, height]` in mm.
    pub display_mm: [f64; 2],
    /// The ground point at the display's centre, metres.
    pub centre: Point,
    /// Display mm per ground metre (the map scale).
    pub scale: f64,
    /// How much the rendered terrain's heights are exaggerated (1 = true to the map scale).
    pub exaggeration: f64,
    /// The ground plane's current tilt towards the viewer, radians (the seed's proposal for
    /// judging heights while pulling).
    pub tilt: f64,
}

impl View {
    /// Shows all of `grid` on a display of `display_mm`, centred, heights true to scale.
    pub fn fit(display_mm: [f64; 2], grid: &Grid) -> View {
        let scale = (display_mm[0] / grid.width()).min(display_mm[1] / grid.height());
        View {
            display_mm,
            centre: [0.5 * grid.width(), 0.5 * grid.height()],
            scale,
            exaggeration: 1.0,
            tilt: 0.0,
        }
    }

    /// The ground point under display point `(u, v)` mm (`v` up from the bottom edge; ground `y`
    /// grows downwards on the display, as image rows do).
    pub fn to_ground(&self, u_mm: f64, v_mm: f64) -> Point {
        [
            self.centre[0] + (u_mm - 0.5 * self.display_mm[0]) / self.scale,
            self.centre[1] - (v_mm - 0.5 * self.display_mm[1]) / self.scale,
        ]
    }

    /// Where ground point `p` is on the display, `[u, v]` mm.
    pub fn to_display(&self, p: Point) -> [f64; 2] {
        [
            0.5 * self.display_mm[0] + (p[0] - self.centre[0]) * self.scale,
            0.5 * self.display_mm[1] - (p[1] - self.centre[1]) * self.scale,
        ]
    }

    /// Ground metres per display mm, for tolerances given on the display.
    pub fn metres(&self, mm: f64) -> f64 {
        mm / self.scale
    }

    /// The terrain height, metres, drawn `h_mm` above the display: the vertical scale of a pull,
    /// chosen so that the pulled figure stays at the pen's tip in the rendered view.
    pub fn height_at(&self, h_mm: f64) -> f64 {
        h_mm / (self.scale * self.exaggeration)
    }

    /// Moves the view so that ground point `ground` is shown at display point `at_mm`.
    pub fn put(&mut self, ground: Point, at_mm: [f64; 2]) {
        self.centre = [
            ground[0] - (at_mm[0] - 0.5 * self.display_mm[0]) / self.scale,
            ground[1] + (at_mm[1] - 0.5 * self.display_mm[1]) / self.scale,
        ];
    }

    /// Zooms by `factor` (> 1 magnifies) keeping the ground under display point `at_mm` in place;
    /// the scale stays within `[min, max]`.
    pub fn zoom_about(&mut self, factor: f64, at_mm: [f64; 2], min: f64, max: f64) {
        if !factor.is_finite() || factor <= 0.0 {
            return;
        }
        let ground = self.to_ground(at_mm[0], at_mm[1]);
        self.scale = (self.scale * factor).clamp(min, max);
        self.put(ground, at_mm);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_and_ground_round_trip() {
        let grid = Grid {
            cols: 480,
            rows: 272,
            cell_size: 12.5,
        };
        let mut v = View::fit([600.0, 340.0], &grid);
        assert!((v.scale - 0.1).abs() < 1e-12);
        // The display's lower-left corner shows the ground's last row, first column.
        assert_eq!(v.to_ground(0.0, 0.0), [0.0, 3400.0]);
        assert_eq!(v.to_ground(600.0, 340.0), [6000.0, 0.0]);
        let p = [1234.5, 987.25];
        let d = v.to_display(p);
        let back = v.to_ground(d[0], d[1]);
        assert!((back[0] - p[0]).abs() < 1e-9 && (back[1] - p[1]).abs() < 1e-9);
        // 90 mm above the display is 900 m at 1:10 000.
        assert!((v.height_at(90.0) - 900.0).abs() < 1e-9);
        // Zooming keeps the point under the pen.
        let under = v.to_ground(100.0, 50.0);
        v.zoom_about(2.0, [100.0, 50.0], 0.01, 10.0);
        assert!((v.scale - 0.2).abs() < 1e-12);
        let still = v.to_ground(100.0, 50.0);
        assert!((still[0] - under[0]).abs() < 1e-9 && (still[1] - under[1]).abs() < 1e-9);
    }
}
