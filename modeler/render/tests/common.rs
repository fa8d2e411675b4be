//! What the render test modules share: terrains from a function, orbit cameras, and a count of
//! the pixels lit in one colour.

use penmodel_render::{Camera, Frame, Orbit, View};
use penmodel_terrain::Heightmap;

/// An `n × n` heightmap of cell size 1 with heights `f(x, y)` at the cell centres.
pub fn terrain(n: u32, f: impl Fn(f64, f64) -> f64) -> Heightmap {
    let heights = (0..n * n)
        .map(|i| f(f64::from(i % n) + 0.5, f64::from(i / n) + 0.5) as f32)
        .collect();
    Heightmap::from_heights(n, n, 1.0, heights).unwrap()
}

/// An orbit camera (angles in degrees) with a 45° field of view.
pub fn orbit(target: [f64; 2], azimuth: f64, elevation: f64, distance: f64) -> Camera {
    Camera {
        view: View::Orbit(Orbit {
            target,
            target_height: 0.0,
            azimuth: azimuth.to_radians(),
            elevation: elevation.to_radians(),
            distance,
            fov_y: 45f64.to_radians(),
            separation: 1.0 / 30.0,
        }),
        tilt: 0.0,
    }
}

/// An orbit camera 80° above a grid of `n` × `n` one-metre cells, looking at its middle.
pub fn above(n: f64) -> Camera {
    Camera {
        view: View::Orbit(Orbit {
            target: [n / 2.0, n / 2.0],
            target_height: 0.0,
            azimuth: 0.0,
            elevation: 80f64.to_radians(),
            distance: n * 1.5,
            fov_y: 45f64.to_radians(),
            separation: 1.0 / 30.0,
        }),
        tilt: 0.0,
    }
}

/// Pixels of `colour`'s hue, lit by a factor from 0.2 to 1: the factor read from channel
/// `by` (the colour's strongest), the other two channels within 3 of the colour times it.
pub fn lit_pixels(frame: &Frame, colour: [u8; 4], by: usize) -> usize {
    frame
        .pixels()
        .iter()
        .filter(|p| {
            let k = f32::from(p[by]) / f32::from(colour[by]);
            k > 0.2
                && (0..3)
                    .filter(|&c| c != by)
                    .all(|c| (f32::from(p[c]) - k * f32::from(colour[c])).abs() < 3.0)
        })
        .count()
}
