//! A grove's trees: Poisson-disk positions inside its region at its density (the rock fields'
//! sampler, [`crate::rocks::poisson::saturate`]), each tree a preset drawn from the grove's mix,
//! a height within ±20 % of the grove's and its own seed. The same grove gives the same trees on
//! any machine (every draw from ChaCha8 streams of the grove's seed).
//!
//! Saturated random sequential adsorption of disks covers [`JAMMING`] of the plane, so trees at
//! least `r` apart with `r = √(4·0.547 / (π·n))` come out at about `n` per square metre.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::species::Preset;
use crate::document::{Grove, Point};
use crate::geometry::{self, Side};

/// The fraction of the plane that saturated random disks cover (random sequential adsorption).
pub const JAMMING: f64 = 0.547;

/// Pixels of the sampling image per spacing: finer places the trees more freely.
pub const PIXELS_PER_SPACING: f64 = 8.0;

/// The most pixels a grove's sampling image may have (the rock fields' limit).
pub const MAX_PIXELS: u64 = crate::rocks::MAX_PIXELS;

/// The most trees a grove may expect (`density × area`).
pub const MAX_TREES: f64 = 20_000.0;

/// One tree of a grove.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroveTree {
    /// Where it stands, metres.
    pub at: Point,
    /// Its species.
    pub preset: Preset,
    /// Its height, metres.
    pub height: f64,
    /// Its own seed (its turn about the trunk).
    pub seed: u64,
}

/// The least distance between two trees of a grove of `density` trees per hectare, metres.
pub fn spacing(density: f64) -> f64 {
    let per_m2 = density / 10_000.0;
    (4.0 * JAMMING / (std::f64::consts::PI * per_m2)).sqrt()
}

/// The region's bounding box: `(min, max)`.
pub fn bounds(region: &[Point]) -> ([f64; 2], [f64; 2]) {
    region
        .iter()
        .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), p| {
            ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])])
        })
}

/// The sampling image of a grove: pixel size and `(width, height)` in pixels.
pub fn image(grove: &Grove) -> (f64, u32, u32) {
    let pixel = spacing(grove.density) / PIXELS_PER_SPACING;
    let (lo, hi) = bounds(&grove.region);
    let w = ((hi[0] - lo[0]) / pixel).ceil().max(1.0);
    let h = ((hi[1] - lo[1]) / pixel).ceil().max(1.0);
    (
        pixel,
        w.min(f64::from(u32::MAX)) as u32,
        h.min(f64::from(u32::MAX)) as u32,
    )
}

/// The area of a closed polygon (shoelace), square metres.
pub fn area(region: &[Point]) -> f64 {
    0.5 * region
        .windows(2)
        .map(|e| e[0][0] * e[1][1] - e[1][0] * e[0][1])
        .sum::<f64>()
        .abs()
}

/// The trees of `grove` (valid: `crate::validate` checked its region, density and mix).
pub fn trees(grove: &Grove) -> Vec<GroveTree> {
    let (pixel, w, h) = image(grove);
    let (lo, _) = bounds(&grove.region);
    let mut rng = ChaCha8Rng::seed_from_u64(grove.seed);
    let seeds = crate::rocks::poisson::saturate(w, h, PIXELS_PER_SPACING, &mut rng);
    // A second stream for the trees' own draws, so they do not shift the positions.
    let mut own = ChaCha8Rng::seed_from_u64(grove.seed);
    own.set_stream(1);
    let mix: Vec<(Preset, f64)> = if grove.mix.is_empty() {
        vec![(Preset::Table31, 1.0)]
    } else {
        grove
            .mix
            .iter()
            .map(|m| (Preset::named(&m.preset).unwrap_or(Preset::Table31), m.weight.max(0.0)))
            .collect()
    };
    let total: f64 = mix.iter().map(|m| m.1).sum();
    let mut sorted = seeds;
    // Pixel order: the trees of a grove come out row by row, whatever the sampler's order.
    sorted.sort_unstable();
    let mut out = Vec::new();
    for p in sorted {
        let (px, py) = (p % w, p / w);
        let at = [
            lo[0] + (f64::from(px) + 0.5) * pixel,
            lo[1] + (f64::from(py) + 0.5) * pixel,
        ];
        // Drawn for every seed, inside or not, so a seed's tree does not depend on the others.
        let pick = own.random::<f64>() * total;
        let scale = 0.8 + 0.4 * own.random::<f64>();
        let seed = own.random::<u64>();
        if geometry::locate(&grove.region, at) != Side::Inside {
            continue;
        }
        let mut acc = 0.0;
        let preset = mix
            .iter()
            .find(|(_, wgt)| {
                acc += wgt;
                pick < acc
            })
            .or(mix.last())
            .map_or(Preset::Table31, |m| m.0);
        out.push(GroveTree {
            at,
            preset,
            height: grove.height * scale,
            seed,
        });
    }
    out
}
