//! Reconstructing a tree from a front and a side silhouette (seed 004, §7): the maps' parameters
//! (`y`, `s`, `θz`, `θy` of each map: 20 for five maps) that maximise the sum of the normalised
//! cross-correlations between the candidate's silhouettes and the given ones.
//!
//! As in the seed: a template-matching start (the presets whose silhouettes correlate best;
//! the ascent runs from the best [`STARTS`] and keeps the higher result), then gradient ascent
//! with a line search. The gradient is by central differences, each parameter
//! measured in its own step ([`STEPS`]), on silhouettes blurred twice (a rasterised outline is a
//! step function of the parameters; blurred, small changes change the objective smoothly).

use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::silhouette::{self, Image, View, ncc};
use super::species::{Preset, Species};
use crate::document::IfsMap;

/// The difference step of each parameter: `y`, `s`, `θz` (degrees), `θy` (degrees).
pub const STEPS: [f64; 4] = [0.02, 0.02, 4.0, 8.0];

/// Canvas side, pixels.
pub const SIZE: usize = 64;

/// Branches stop at this scale in the fit's renders (coarser than the full tree's 2 %).
pub const FIT_STOP: f64 = 0.05;

/// The ranges each parameter is held in: `y` and `s` keep the tree contracting and its
/// branches countable, the angles any lean and turn.
pub const BOUNDS: [(f64, f64); 4] = [(0.02, 1.0), (0.1, 0.75), (-90.0, 90.0), (-360.0, 360.0)];

/// Options of a fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Most gradient steps of each ascent.
    pub iterations: usize,
    /// How many of the best templates an ascent starts from ([`STARTS`] by default).
    pub starts: usize,
    /// The longest the ascents may take together ([`BUDGET`] by default): past it the best
    /// result so far is kept and [`Fit::out_of_time`] says so. Checked before each step, so a
    /// fit overruns it by at most one step.
    pub budget: Duration,
}

/// The default time budget of a fit's ascents: 120 s. The seed's examples fit in a few seconds
/// to a minute on two cores; a budget turns a fit that would run for many minutes into an
/// answer with a message.
pub const BUDGET: Duration = Duration::from_secs(120);

impl Default for Options {
    fn default() -> Options {
        Options {
            iterations: 30,
            starts: STARTS,
            budget: BUDGET,
        }
    }
}

/// A fit's result.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The preset the kept ascent started from.
    pub preset: Preset,
    /// The fitted species.
    pub species: Species,
    /// Correlations of the start with the front and side silhouettes.
    pub start: [f64; 2],
    /// Correlations reached.
    pub reached: [f64; 2],
    /// Gradient steps the kept ascent took.
    pub iterations: usize,
    /// Whether the time budget ended the ascents before they converged or ran their steps.
    pub out_of_time: bool,
}

/// Why a fit could not start.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// A silhouette has nothing in it.
    #[error("the {0} silhouette is blank")]
    Blank(&'static str),
    /// A silhouette no tree casts: a dot, a line, a filled rectangle.
    #[error(
        "the {which} silhouette is {what}: a tree's outline is needed (a crown and a trunk, at least 3 × 3 pixels, not filling its box)"
    )]
    Degenerate {
        /// `front` or `side`.
        which: &'static str,
        /// What it is.
        what: String,
    },
    /// The fitted maps make a tree past the branch limit.
    #[error("the fitted tree is refused: {0}")]
    Refused(String),
    /// No preset to start from.
    #[error("no template to start from")]
    NoTemplate,
}

struct Target {
    front: Image,
    side: Image,
}

fn prepare(img: &Image) -> Option<Image> {
    Some(img.framed(SIZE)?.blurred(2))
}

impl Target {
    fn score(&self, s: &Species) -> [f64; 2] {
        // A tree past the branch limit is no answer (`trees stats` would refuse its maps, issue
        // 47), and rendering one is what made a fit run for minutes: the lowest correlation.
        if !within_branch_limit(s) {
            return [-1.0, -1.0];
        }
        let f = silhouette::render(s, View::Front, SIZE, FIT_STOP).blurred(2);
        let d = silhouette::render(s, View::Side, SIZE, FIT_STOP).blurred(2);
        [ncc(&f, &self.front), ncc(&d, &self.side)]
    }
}

fn params(s: &Species) -> Vec<f64> {
    s.maps.iter().flat_map(|m| [m.y, m.s, m.theta_z, m.theta_y]).collect()
}

fn species(p: &[f64]) -> Species {
    Species {
        maps: p
            .chunks_exact(4)
            .map(|c| {
                let b = |k: usize| c[k].clamp(BOUNDS[k].0, BOUNDS[k].1);
                IfsMap {
                    y: b(0),
                    s: b(1),
                    theta_z: b(2),
                    theta_y: b(3),
                }
            })
            .collect(),
    }
}

/// How many of the best templates an ascent starts from by default (the best result is kept):
/// one template's basin may hold a lower maximum than the next one's.
pub const STARTS: usize = 2;

fn sum(v: [f64; 2]) -> f64 {
    v[0] + v[1]
}

/// Gradient ascent from `p` (scoring `score`), at most `iterations` steps: the parameters, their
/// correlations and the steps taken.
/// Stops at `until`, saying so with the last value.
fn ascend(
    target: &Target,
    mut p: Vec<f64>,
    mut best: [f64; 2],
    iterations: usize,
    until: Instant,
) -> (Vec<f64>, [f64; 2], usize, bool) {
    let mut steps = 0;
    let mut stride = 1.0;
    while steps < iterations {
        if Instant::now() >= until {
            return (p, best, steps, true);
        }
        steps += 1;
        // The gradient in step units, its 2·4M renders on all cores.
        let grad: Vec<f64> = (0..p.len())
            .into_par_iter()
            .map(|k| {
                let h = STEPS[k % 4];
                let mut up = p.clone();
                up[k] += h;
                let mut down = p.clone();
                down[k] -= h;
                0.5 * (sum(target.score(&species(&up))) - sum(target.score(&species(&down))))
            })
            .collect();
        let norm = grad.iter().map(|g| g * g).sum::<f64>().sqrt();
        if norm < 1e-9 {
            break;
        }
        // Line search along the gradient: the best of four strides around the last one.
        let tried: Vec<(Vec<f64>, [f64; 2], f64)> = [2.0 * stride, stride, 0.5 * stride, 0.25 * stride]
            .into_par_iter()
            .map(|t| {
                let q: Vec<f64> = p
                    .iter()
                    .enumerate()
                    .map(|(k, v)| v + t * grad[k] / norm * STEPS[k % 4])
                    .collect();
                let v = target.score(&species(&q));
                (q, v, t)
            })
            .collect();
        let moved = tried
            .into_iter()
            .filter(|(_, v, _)| sum(*v) > sum(best) + 1e-6)
            .max_by(|a, b| sum(a.1).total_cmp(&sum(b.1)));
        match moved {
            Some((q, v, t)) => {
                p = params(&species(&q));
                best = v;
                stride = t;
            }
            None if stride > 0.1 => stride *= 0.25,
            None => break,
        }
    }
    (p, best, steps, false)
}

/// Fits a species to a front and a side silhouette (coverage images of any size; each is
/// framed on its own).
pub fn fit(front: &Image, side: &Image, options: Options) -> Result<Fit, FitError> {
    check_outline(front, "front")?;
    check_outline(side, "side")?;
    let target = Target {
        front: prepare(front).ok_or(FitError::Blank("front"))?,
        side: prepare(side).ok_or(FitError::Blank("side"))?,
    };
    // Template matching: the presets ranked by their correlations; the best few start.
    let mut templates: Vec<(Preset, [f64; 2])> = Preset::ALL
        .into_par_iter()
        .map(|p| (p, target.score(&Species::preset(p))))
        .collect();
    templates.sort_by(|a, b| sum(b.1).total_cmp(&sum(a.1)));
    let until = Instant::now() + options.budget;
    let mut result: Option<Fit> = None;
    let mut out_of_time = false;
    for &(preset, start) in templates.iter().take(options.starts.max(1)) {
        let (p, reached, iterations, late) = ascend(
            &target,
            params(&Species::preset(preset)),
            start,
            options.iterations,
            until,
        );
        out_of_time |= late;
        if result.as_ref().is_none_or(|r| sum(reached) > sum(r.reached)) {
            result = Some(Fit {
                preset,
                species: species(&p),
                start,
                reached,
                iterations,
                out_of_time: false,
            });
        }
    }
    let mut result = result.ok_or(FitError::NoTemplate)?;
    result.out_of_time = out_of_time;
    if !within_branch_limit(&result.species) {
        return Err(FitError::Refused(format!(
            "more than {} branches",
            super::nodes::MAX_NODES
        )));
    }
    Ok(result)
}

/// Whether `s` stays within the branch limit `validate::species` enforces. The parameters are
/// clamped to `BOUNDS`, so this is the one check of it a fitted species can fail.
fn within_branch_limit(s: &Species) -> bool {
    super::nodes::count_nodes(s, super::nodes::STOP, super::nodes::MAX_NODES).is_some()
}

/// Refuses a silhouette that is a dot or a line (its covered box under 3 pixels across) or a
/// filled rectangle (over 95 % of its box covered): no tree casts one, and the ascent would
/// chase it into a degenerate tree (issue 47: one pixel "fitted" at 0.85 with 568,000 polygons).
fn check_outline(img: &Image, which: &'static str) -> Result<(), FitError> {
    let (mut c0, mut c1, mut r0, mut r1, mut covered) = (usize::MAX, 0, usize::MAX, 0, 0usize);
    for (i, &v) in img.data.iter().enumerate() {
        if v > 0.5 {
            let (c, r) = (i % img.width.max(1), i / img.width.max(1));
            (c0, c1, r0, r1) = (c0.min(c), c1.max(c), r0.min(r), r1.max(r));
            covered += 1;
        }
    }
    if covered == 0 {
        return Err(FitError::Blank(which));
    }
    let (w, h) = (c1 - c0 + 1, r1 - r0 + 1);
    let what = if w < 3 || h < 3 {
        format!(
            "{} ({w} × {h} pixels covered)",
            if w * h == 1 { "a single pixel" } else { "a line" }
        )
    } else if covered as f64 > 0.95 * (w * h) as f64 {
        format!(
            "a filled rectangle ({w} × {h} pixels, {:.0} % covered)",
            100.0 * covered as f64 / (w * h) as f64
        )
    } else {
        return Ok(());
    };
    Err(FitError::Degenerate { which, what })
}

/// A few deterministic numbers in [−1, 1] from `seed` (xorshift64), for experiments.
fn offsets(seed: u64) -> impl FnMut() -> f64 {
    let mut x = seed | 1;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % 2001) as f64 / 1000.0 - 1.0
    }
}

/// `species` with every parameter nudged by up to `amount` fit steps ([`STEPS`]; y and s held
/// in [0.05, 0.9] and [0.15, 0.7]): the unknown tree of the fit's experiments.
pub fn nudged(species: &Species, amount: f64, seed: u64) -> Species {
    let mut next = offsets(seed);
    let mut s = species.clone();
    for m in &mut s.maps {
        m.y = (m.y + amount * STEPS[0] * next()).clamp(0.05, 0.9);
        m.s = (m.s + amount * STEPS[1] * next()).clamp(0.15, 0.7);
        m.theta_z += amount * STEPS[2] * next();
        m.theta_y += amount * STEPS[3] * next();
    }
    s
}

/// `img` with a `fraction` of its pixels flipped (`c → 1 − c`) at seeded places: noise for the
/// fit's experiments.
pub fn speckled(img: &Image, fraction: f64, seed: u64) -> Image {
    let mut next = offsets(seed);
    let mut out = img.clone();
    for v in &mut out.data {
        if 0.5 * (next() + 1.0) < fraction {
            *v = 1.0 - *v;
        }
    }
    out
}
