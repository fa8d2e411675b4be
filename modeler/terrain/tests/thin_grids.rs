//! Long and thin grids lit and swept (issue 47, item 3): the sweeps once held every line over
//! every column, the square of the long side (262144 × 1 asked for 275 GB and aborted). Each
//! grid here is lit and its sky view found, with values a flat or sloped grid must have.

use std::f64::consts::PI;

use penmodel_terrain::ridge::sun::{self, Field, Sun};

/// Grids of every thin shape: along either axis, a single cell, a few cells.
const SHAPES: [(u32, u32); 7] = [(4096, 2), (2, 4096), (1, 1000), (1000, 1), (2, 3), (1, 1), (262_144, 1)];

fn field(z: &[f32], cols: u32, rows: u32) -> Field<'_> {
    Field {
        z,
        cols,
        rows,
        cell: 2.0,
    }
}

#[test]
fn flat_thin_grids_are_open_sky_and_lit_everywhere() {
    let sun = Sun {
        azimuth: 0.75 * PI,
        elevation: 0.4,
    };
    for (cols, rows) in SHAPES {
        let z = vec![10.0f32; cols as usize * rows as usize];
        let f = field(&z, cols, rows);
        // The diagonals, whose lines are as many as the long side, are among eight azimuths.
        let sky = sun::sky_view(f, 8);
        assert_eq!(sky.len(), z.len(), "{cols}×{rows}");
        assert!(
            sky.iter().all(|&v| (v - 1.0).abs() < 1e-6),
            "{cols}×{rows}: a flat grid sees the whole sky"
        );
        let direct = sun::direct(f, sun);
        let expect = sun.elevation.sin() as f32;
        assert!(
            direct.iter().all(|&v| (v - expect).abs() < 1e-5),
            "{cols}×{rows}: flat ground in the sun gets sin(elevation)"
        );
    }
}

#[test]
fn a_thin_wall_shades_the_cells_behind_it_on_a_long_grid() {
    // A long strip two cells wide with a 100 m wall at its middle: the sun low in +x's azimuth
    // lights the cells on its side and leaves those just behind it in shadow.
    let (cols, rows) = (65_536u32, 2u32);
    let mut z = vec![0.0f32; (cols * rows) as usize];
    let mid = cols as usize / 2;
    for r in 0..rows as usize {
        z[r * cols as usize + mid] = 100.0;
    }
    let f = field(&z, cols, rows);
    let sun = Sun {
        azimuth: 0.0,
        elevation: 0.3,
    };
    let direct = sun::direct(f, sun);
    for r in 0..rows as usize {
        let at = |c: usize| direct[r * cols as usize + c];
        assert!(at(mid - 10) == 0.0, "behind the wall (towards −x) is in shadow");
        assert!(at(mid + 10) > 0.0, "in front of it the sun shines");
        assert!(at(0) > 0.0, "far behind, past the shadow, the sun shines again");
    }
    let sky = sun::sky_view(f, 8);
    assert!(
        sky[mid - 1] < 0.95 && sky[mid + 2000] > 0.99,
        "the wall hides sky near it only"
    );
}
