//! The classic look's elevation colours: water below sea level (height 0) from shallow to deep
//! blue, so a depression is never mistaken for land; then sand, grass, forest, rock and snow up
//! to `ramp_top`. Looked up per pixel from a [`RAMP_ENTRIES`]-entry table over
//! `[−ramp_depth, ramp_top]` ([`Ramp`]), so the bands stay sharp on triangles large on screen.

use crate::scene::Style;

/// Entries of the colour table.
pub(crate) const RAMP_ENTRIES: usize = 1024;

/// Land colours at fractions of `ramp_top`.
pub(crate) const LAND: [(f32, [u8; 3]); 7] = [
    (0.0, [214, 200, 146]),  // sand at the shore
    (0.04, [120, 168, 82]),  // grass
    (0.35, [66, 120, 58]),   // forest
    (0.55, [128, 116, 96]),  // rock
    (0.75, [150, 146, 142]), // grey rock
    (0.88, [236, 238, 242]), // snow
    (1.0, [255, 255, 255]),
];

/// Water colours at fractions of `ramp_depth` below sea level.
pub(crate) const WATER: [(f32, [u8; 3]); 2] = [(0.0, [78, 150, 212]), (1.0, [16, 40, 104])];

pub(crate) fn interpolate(stops: &[(f32, [u8; 3])], t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    for pair in stops.windows(2) {
        let ((t0, c0), (t1, c1)) = (pair[0], pair[1]);
        if t <= t1 {
            let f = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
            return [0, 1, 2].map(|i| (f32::from(c0[i]) + f * (f32::from(c1[i]) - f32::from(c0[i]))).round() as u8);
        }
    }
    stops[stops.len() - 1].1
}

/// The colour tables: land over `[0, ramp_top]`, water over `[−ramp_depth, 0)`, so that sea level
/// is an exact boundary (height 0 is land, any height below it water).
#[derive(Debug, Clone)]
pub(crate) struct Ramp {
    land: Vec<[f32; 3]>,
    water: Vec<[f32; 3]>,
    land_scale: f32,
    water_scale: f32,
}

impl Ramp {
    /// The tables for `style`.
    pub(crate) fn new(style: &Style) -> Ramp {
        let top = style.ramp_top.max(f32::MIN_POSITIVE);
        let depth = style.ramp_depth.max(f32::MIN_POSITIVE);
        let last = (RAMP_ENTRIES - 1) as f32;
        let table = |stops: &[(f32, [u8; 3])]| -> Vec<[f32; 3]> {
            (0..RAMP_ENTRIES)
                .map(|i| interpolate(stops, i as f32 / last).map(f32::from))
                .collect()
        };
        Ramp {
            land: table(&LAND),
            water: table(&WATER),
            land_scale: last / top,
            water_scale: last / depth,
        }
    }

    /// The colour of height `h` before lighting.
    #[inline]
    pub(crate) fn get(&self, h: f32) -> [f32; 3] {
        let last = (RAMP_ENTRIES - 1) as f32;
        if h >= 0.0 {
            self.land[(h * self.land_scale + 0.5).min(last) as usize]
        } else {
            self.water[(-h * self.water_scale + 0.5).min(last) as usize]
        }
    }
}
