//! Recursive ridgeline generation (Alg. 2.5): from the main ridgelines, rounds of
//!
//! 1. the DTM with flank slope α (every line, old and new, at this round's α);
//! 2. on a randomly chosen side of every segment of the lines added last (the main lines in the
//!    first round), water drops every d along the line, each started 1.5 cells off the segment
//!    and traced downhill as the rain is ([`super::rain`]); a drop that reaches a cell an earlier
//!    drop of the round passed joins that path there and stops, so the paths branch like a
//!    drainage network instead of running down the same valley twice;
//! 3. each drop's path, joined to the segment where it was dropped and sampled at the DTM's
//!    heights, becomes a new ridgeline;
//!
//! then α grows by `slope_step` and d shrinks by `spacing_factor`. The seed adds the paths as
//! ridgelines ("calling them valley lines might feel more natural"): with the next round's
//! steeper α the old flanks fall away faster than the new lines, which are left standing as
//! spurs with valleys between them. Randomness is one ChaCha8 stream named by the seed, drawn in
//! a fixed order, so the same input and seed grow the same lines everywhere.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::filter::Filter;
use super::{Dtm, RidgeError, Skeleton, rain};

/// Alg. 2.5's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Growth {
    /// Rounds.
    pub rounds: u32,
    /// The random seed.
    pub seed: u64,
    /// The first round's drop spacing d, metres.
    pub spacing: f64,
    /// d is multiplied by this after each round (0 to 1).
    pub spacing_factor: f64,
    /// α grows by this after each round, radians.
    pub slope_step: f64,
}

impl Growth {
    /// `rounds` rounds: d from 12 cells, × 0.7 a round; α + 5° a round.
    pub fn new(rounds: u32, seed: u64, cell: f64) -> Growth {
        Growth {
            rounds,
            seed,
            spacing: 12.0 * cell,
            spacing_factor: 0.7,
            slope_step: 5f64.to_radians(),
        }
    }
}

/// What growing gives: the new ridgelines (3D polylines) and the flank slope after the last
/// round, for the DTM of everything.
#[derive(Debug, Clone, PartialEq)]
pub struct Grown {
    /// The new lines, `[x, y, z]`.
    pub lines: Vec<Vec<[f64; 3]>>,
    /// α after the rounds, radians.
    pub slope: f64,
}

/// Grows ridgelines from `base` (their own slopes are replaced by each round's α, starting at
/// `slope`) on a `cols × rows` grid of `cell` metres.
pub fn grow(
    base: &[Skeleton],
    grid: (u32, u32, f64),
    filter: Filter,
    slope: f64,
    g: Growth,
) -> Result<Grown, RidgeError> {
    grow_from(base, base, grid, filter, slope, g)
}

/// As [`grow`], but the first round's drops fall from `first` only (the pen's click on one
/// ridgeline); the DTM of every round is still that of all of `base` and the grown lines.
pub fn grow_from(
    base: &[Skeleton],
    first: &[Skeleton],
    (cols, rows, cell): (u32, u32, f64),
    filter: Filter,
    slope: f64,
    g: Growth,
) -> Result<Grown, RidgeError> {
    let last = slope + g.slope_step * f64::from(g.rounds);
    super::check_slope(slope, "the slope")?;
    super::check_slope(last, "the slope after the last round")?;
    if !(g.spacing.is_finite() && g.spacing > 0.0) {
        return Err(RidgeError::Parameter {
            what: "the drop spacing".into(),
            value: g.spacing,
            expected: "it must be a positive number of metres",
        });
    }
    if !(g.spacing_factor > 0.0 && g.spacing_factor <= 1.0) {
        return Err(RidgeError::Parameter {
            what: "the spacing factor".into(),
            value: g.spacing_factor,
            expected: "it must be in (0, 1]",
        });
    }
    let mut rng = ChaCha8Rng::seed_from_u64(g.seed);
    let mut lines: Vec<Vec<[f64; 3]>> = Vec::new();
    // The lines drops fall from: the base, then each round's new lines.
    let mut sources: Vec<Skeleton> = first.to_vec();
    let (mut alpha, mut d) = (slope, g.spacing);
    for _ in 0..g.rounds {
        let mut all: Vec<Skeleton> = base
            .iter()
            .map(|s| Skeleton {
                slope: alpha,
                ..s.clone()
            })
            .collect();
        all.extend(lines.iter().map(|l| Skeleton::polyline(l, alpha)));
        let ids: Vec<(u32, &Skeleton)> = all.iter().enumerate().map(|(i, s)| (i as u32, s)).collect();
        let dtm = Dtm::build(cols, rows, cell, filter, &ids);
        let z = dtm.heights();
        let next = rain::directions(z, cols, rows, cell);
        // Cells a path of this round already follows: a later drop joins it there and stops,
        // so the new lines branch like a drainage network instead of doubling each other.
        let mut taken = vec![false; z.len()];
        let mut fresh = Vec::new();
        for s in &sources {
            // Drops every d along each segment, counted on from the previous segment.
            let mut at = d / 2.0;
            for &[a, b] in &s.edges {
                let (p, q) = (s.nodes[a as usize], s.nodes[b as usize]);
                let len = (q[0] - p[0]).hypot(q[1] - p[1]);
                let side = if rng.random::<bool>() { 1.0 } else { -1.0 };
                if len == 0.0 {
                    continue;
                }
                let n = [-(q[1] - p[1]) / len * side, (q[0] - p[0]) / len * side];
                while at < len {
                    let t = at / len;
                    let on = [
                        p[0] + t * (q[0] - p[0]),
                        p[1] + t * (q[1] - p[1]),
                        p[2] + t * (q[2] - p[2]),
                    ];
                    at += d;
                    let start = [on[0] + n[0] * 1.5 * cell, on[1] + n[1] * 1.5 * cell];
                    let (c, r) = ((start[0] / cell).floor(), (start[1] / cell).floor());
                    if c < 0.0 || r < 0.0 || c >= f64::from(cols) || r >= f64::from(rows) {
                        continue;
                    }
                    let mut path = rain::trace(&next, r as u32 * cols + c as u32);
                    if let Some(k) = path.iter().position(|&i| taken[i as usize]) {
                        path.truncate(k + 1);
                    }
                    if path.len() < 3 {
                        continue;
                    }
                    for &i in &path {
                        taken[i as usize] = true;
                    }
                    // Every few cells, and the last: enough for the line's shape.
                    let stride = ((d / cell / 2.0).round() as usize).clamp(1, 4);
                    let mut line = vec![on];
                    for (k, &i) in path.iter().enumerate() {
                        if k % stride == 0 || k + 1 == path.len() {
                            let (cc, rr) = (i % cols, i / cols);
                            line.push([
                                (f64::from(cc) + 0.5) * cell,
                                (f64::from(rr) + 0.5) * cell,
                                f64::from(z[i as usize]),
                            ]);
                        }
                    }
                    fresh.push(line);
                }
                at -= len;
            }
        }
        sources = fresh.iter().map(|l| Skeleton::polyline(l, alpha)).collect();
        lines.extend(fresh);
        alpha += g.slope_step;
        d *= g.spacing_factor;
    }
    Ok(Grown { lines, slope: alpha })
}
