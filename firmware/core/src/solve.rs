//! Multilateration: the emitter's position from its ranges to 3–8 receivers.
//!
//! 1. **Start.** With four or more receivers spread in three dimensions, the linearised least
//!    squares solution (range equations differenced against their mean, which cancels |x|²).
//!    Otherwise — three receivers, or receivers so nearly coplanar that the linear system is
//!    ill-conditioned — the point in front of the receivers' centroid at the distance the ranges
//!    imply (for the centroid c, mean |x − pᵢ|² = |x − c|² + mean |pᵢ − c|²).
//! 2. **Refine.** Gauss–Newton on the range residuals |x − pᵢ| − rᵢ with Levenberg–Marquardt
//!    damping, so that a nearly singular geometry takes short steps instead of wild ones.
//! 3. **Front.** Ranges alone cannot tell a point from its mirror image in the receivers' plane
//!    when the receivers are (nearly) coplanar; a solution behind the display is re-solved from
//!    its mirror image in that plane, and rejected if it stays behind. (Three receivers always
//!    lie in a plane: mount them in the display plane so that the mirror image is behind it.)
//! 4. **Reject.** The sum of squared residuals is tested against the χ² distribution of range
//!    noise of [`RANGE_SIGMA_MM`] with n − 3 degrees of freedom at 99.9 %. A fix that fails has
//!    a bad range (a late echo, a glitch). With five or more receivers it is redone without each
//!    receiver in turn and the best subset kept if that passes; with six or more and no single
//!    receiver to blame, without each pair (two echoes in one cycle still leave four ranges),
//!    where a receiver left out must be late, as an echo is, and subsets whose receivers stand
//!    in one plane other than the display's are skipped (their mirror images fit alike);
//!    otherwise the cycle has no fix.
//!    A single residual threshold would not do: least squares spreads one bad range over all
//!    residuals, most thinly where the geometry controls that receiver least. When more than
//!    one subset passes and their solutions disagree (four receivers leave one degree of
//!    freedom, and a bad range can fit a wrong point), the one nearest the caller's hint — the
//!    previous fix — wins; without a hint the cycle is ambiguous and has no fix.
//! 5. **Quality.** Receivers used, the RMS residual, and the position dilution of precision
//!    √trace((JᵀJ)⁻¹): the position error is about DOP × the range error.
//!
//! Every result is finite: a cycle that cannot be solved is [`NoFix`], never NaN.

use pen_protocol::MAX_RECEIVERS;

use crate::math::{Sym3, Vec3};

/// The range noise the consistency test assumes, mm: 2 µs of timing jitter at 343 m/s is
/// 0.69 mm; a little more allows for delay and temperature errors.
pub const RANGE_SIGMA_MM: f32 = 0.8;
/// The 99.9 % quantiles of χ² with 0…5 degrees of freedom (n − 3 for n = 3…8 receivers).
const CHI2_999: [f32; 6] = [0.0, 10.828, 13.816, 16.266, 18.467, 20.515];
/// How far behind the display a solution may lie before it is taken for the mirror image, mm.
pub const BEHIND_MARGIN_MM: f32 = 20.0;
/// Gauss–Newton iterations per solve at most: enough for the slow convergence along a poorly
/// observed direction (a pen near the plane of three receivers).
pub const MAX_ITERATIONS: usize = 12;
/// Iterations for each subset when leaving receivers out: a subset without the bad range
/// converges from its linear start in a few; one that has not by then keeps the bad range, and
/// more iterations would only cost time (up to 40 % of the cycle on the Cortex-M4F).
pub const SUBSET_ITERATIONS: usize = 6;
/// A step shorter than this ends the iteration, mm.
const CONVERGED_MM: f32 = 1e-3;
/// Damping increases tried per iteration before giving up.
const MAX_TRIES: usize = 5;
/// Reciprocal condition below which the linear start is not trusted.
const LINEAR_MIN_RCOND: f32 = 1e-4;
/// The dilution of precision reported for a geometry that does not determine the position in
/// some direction; far beyond what the pen report can carry (25.5), and finite.
pub const MAX_DOP: f32 = 1000.0;

/// Where the receivers are and which way the user is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry<'a> {
    /// Receiver positions, mm.
    pub receivers: &'a [Vec3],
    /// Unit vector pointing from the display towards the user.
    pub front: Vec3,
}

/// A position fix and how far to trust it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Fix {
    /// Emitter position in the tracker frame, mm.
    pub position: Vec3,
    /// Bit i set: receiver i's range was used.
    pub used_mask: u8,
    /// Receivers used.
    pub used: u8,
    /// RMS range residual of the receivers used, mm.
    pub residual_rms_mm: f32,
    /// Position dilution of precision, at most [`MAX_DOP`].
    pub dop: f32,
}

/// Why a cycle has no fix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NoFix {
    /// Fewer than three ranges.
    TooFewRanges,
    /// The ranges do not agree on a point, and no single receiver explains it.
    Inconsistent,
    /// The only consistent solution lies behind the display.
    Behind,
    /// The iteration failed (the emitter at a receiver, a singular geometry).
    Degenerate,
    /// Several receiver subsets fit different points and nothing tells which is right.
    Ambiguous,
    /// The fix jumped further from the previous one than a hand moves (the tracking gate).
    Jump,
    /// The first fix after a gap, held until the next one confirms it (the tracking gate).
    Acquiring,
    /// The receivers used place the pen too poorly to report it (dilution of precision above
    /// the engine's limit).
    PoorGeometry,
}

/// One least-squares problem: receivers with their ranges.
struct Problem<'a> {
    receivers: &'a [Vec3],
    ranges: &'a [Option<f32>; MAX_RECEIVERS],
}

/// A converged solution for one subset of receivers.
#[derive(Clone, Copy)]
struct Solution {
    x: Vec3,
    /// Sum of squared residuals, mm².
    sse: f32,
}

/// The largest sum of squared residuals, mm², that range noise explains for `n` receivers (see
/// the module docs). Three ranges have no redundancy, but spheres that do not meet still leave
/// a residual: they are held to the one-degree-of-freedom limit.
pub fn sse_limit(n: usize) -> f32 {
    let dof = n.saturating_sub(3).clamp(1, CHI2_999.len() - 1);
    CHI2_999[dof] * RANGE_SIGMA_MM * RANGE_SIGMA_MM
}

fn consistent(sse: f32, n: usize) -> bool {
    sse <= sse_limit(n)
}

impl Problem<'_> {
    fn used(&self, mask: u8) -> impl Iterator<Item = (Vec3, f32)> + '_ {
        self.receivers
            .iter()
            .zip(self.ranges.iter())
            .enumerate()
            .filter_map(move |(i, (&p, r))| match r {
                Some(r) if mask & (1 << i) != 0 => Some((p, *r)),
                _ => None,
            })
    }

    fn evaluate(&self, x: Vec3, mask: u8) -> Solution {
        let mut sse = 0.0;
        for (p, r) in self.used(mask) {
            let res = (x - p).length() - r;
            sse += res * res;
        }
        Solution { x, sse }
    }

    /// JᵀJ at `x` and the gradient Jᵀ·residuals; `None` when `x` sits on a receiver.
    fn normal_equations(&self, x: Vec3, mask: u8) -> Option<(Sym3, Vec3)> {
        let (mut h, mut g) = (Sym3::default(), Vec3::ZERO);
        for (p, r) in self.used(mask) {
            let d = x - p;
            let dist = d.length();
            if dist < 1.0 {
                return None;
            }
            let u = d * (1.0 / dist);
            h.add_outer(u, 1.0);
            g += u * (dist - r);
        }
        Some((h, g))
    }

    /// √trace((JᵀJ)⁻¹) at `x`, at most [`MAX_DOP`].
    fn dop(&self, x: Vec3, mask: u8) -> f32 {
        match self.normal_equations(x, mask).and_then(|(h, _)| h.inverse(1e-12)) {
            // `min` also turns a NaN into MAX_DOP.
            Some(inv) => crate::math::sqrt(inv.trace().max(0.0)).min(MAX_DOP),
            None => MAX_DOP,
        }
    }

    /// The linearised least-squares start, when the receivers span three dimensions well.
    fn linear_start(&self, mask: u8, n: usize) -> Option<Vec3> {
        let inv_n = 1.0 / n as f32;
        let mut centroid = Vec3::ZERO;
        for (p, _) in self.used(mask) {
            centroid += p;
        }
        let c = centroid * inv_n;
        // 2 qᵢ·y = kᵢ − mean k, with qᵢ = pᵢ − c, y = x − c, kᵢ = |qᵢ|² − rᵢ².
        let mut k_mean = 0.0;
        for (p, r) in self.used(mask) {
            k_mean += (p - c).length_squared() - r * r;
        }
        k_mean *= inv_n;
        let (mut m, mut b) = (Sym3::default(), Vec3::ZERO);
        for (p, r) in self.used(mask) {
            let q = p - c;
            m.add_outer(q, 1.0);
            b += q * (0.5 * (q.length_squared() - r * r - k_mean));
        }
        let y = m.inverse(LINEAR_MIN_RCOND)?.mul_vec(b);
        let x = y + c;
        x.is_finite().then_some(x)
    }

    /// The unit normal of the receivers' (best) plane, oriented to `front`: the largest cross
    /// product of two receivers' offsets from their centroid.
    fn plane(&self, mask: u8, front: Vec3) -> (Vec3, Vec3) {
        let (mut c, mut n) = (Vec3::ZERO, 0.0);
        for (p, _) in self.used(mask) {
            c += p;
            n += 1.0;
        }
        let c = c * (1.0 / n);
        let mut best = Vec3::ZERO;
        for (i, (a, _)) in self.used(mask).enumerate() {
            for (b, _) in self.used(mask).skip(i + 1) {
                let v = (a - c).cross(b - c);
                if v.length_squared() > best.length_squared() {
                    best = v;
                }
            }
        }
        let len = best.length();
        let normal = if len > 0.0 { best * (1.0 / len) } else { front };
        (c, if normal.dot(front) < 0.0 { -normal } else { normal })
    }

    /// The receivers in `mask` lie within [`COPLANAR_MM`] of a plane other than the display's:
    /// a point and its mirror image in that plane fit their ranges equally, both in front of
    /// the display, and nothing tells them apart. (In the display's plane the mirror image is
    /// behind it, and [`solve_subset`](Self::solve_subset) takes the one in front.)
    fn mirror_ambiguous(&self, mask: u8, front: Vec3, height: &dyn Fn(Vec3) -> f32) -> bool {
        let (c, normal) = self.plane(mask, front);
        let flat = self.used(mask).all(|(p, _)| (p - c).dot(normal).abs() < COPLANAR_MM);
        let display_plane = normal.dot(front) > 0.9 && height(c).abs() < COPLANAR_MM + BEHIND_MARGIN_MM;
        flat && !display_plane
    }

    /// In front of the receivers' centroid at the distance the ranges imply.
    fn centroid_start(&self, mask: u8, n: usize, front: Vec3) -> Vec3 {
        let inv_n = 1.0 / n as f32;
        let mut centroid = Vec3::ZERO;
        for (p, _) in self.used(mask) {
            centroid += p;
        }
        let c = centroid * inv_n;
        let (mut spread, mut r2) = (0.0, 0.0);
        for (p, r) in self.used(mask) {
            spread += (p - c).length_squared();
            r2 += r * r;
        }
        let d2 = (r2 - spread) * inv_n;
        // Ranges shorter than the spread allow no point: start just in front of the centroid.
        let d = if d2 > 1.0 { crate::math::sqrt(d2) } else { 1.0 };
        c + front * d
    }

    /// Levenberg–Marquardt from `start`.
    fn refine(&self, start: Vec3, mask: u8, iterations: usize) -> Option<Solution> {
        let mut best = self.evaluate(start, mask);
        let mut lambda = 1e-3f32;
        for _ in 0..iterations {
            let (h, g) = self.normal_equations(best.x, mask)?;
            let mut improved = false;
            // Raise the damping until a step lowers the cost, a few tries at most. A step too
            // short to matter ends the iteration whether or not it lowers the cost: at the
            // minimum, rounding decides that, and retrying would only burn time.
            for _ in 0..MAX_TRIES {
                let Some(inv) = h.damped(lambda).inverse(1e-12) else {
                    lambda *= 10.0;
                    continue;
                };
                let step = -inv.mul_vec(g);
                if step.length() < CONVERGED_MM {
                    break;
                }
                let trial = self.evaluate(best.x + step, mask);
                if trial.sse.is_finite() && trial.sse <= best.sse {
                    best = trial;
                    lambda = (lambda * 0.1).max(1e-7);
                    improved = true;
                    break;
                }
                lambda *= 10.0;
            }
            if !improved {
                break;
            }
        }
        best.x.is_finite().then_some(best)
    }

    /// Start, refine, and resolve the mirror ambiguity for the receivers in `mask`.
    fn solve_subset(
        &self,
        mask: u8,
        front: Vec3,
        behind: &dyn Fn(Vec3) -> f32,
        iterations: usize,
    ) -> Result<Solution, NoFix> {
        let n = mask.count_ones() as usize;
        let start = match n {
            4.. => self.linear_start(mask, n),
            _ => None,
        }
        .unwrap_or_else(|| self.centroid_start(mask, n, front));
        let mut sol = self.refine(start, mask, iterations).ok_or(NoFix::Degenerate)?;
        if behind(sol.x) < -BEHIND_MARGIN_MM {
            // Try the mirror image through the receivers' plane.
            let (c, normal) = self.plane(mask, front);
            let mirrored = sol.x - normal * (2.0 * (sol.x - c).dot(normal));
            match self.refine(mirrored, mask, iterations) {
                Some(m) if behind(m.x) >= -BEHIND_MARGIN_MM => sol = m,
                _ => return Err(NoFix::Behind),
            }
        }
        Ok(sol)
    }
}

/// A receiver left out must miss the subset's solution by this many standard deviations of the
/// range noise.
const OUTLIER_SIGMAS: f32 = 4.0;

/// Subset solutions closer together than this many standard deviations of the position error
/// (σ_range · DOP) are the same answer.
const SAME_POINT_SIGMAS: f32 = 6.0;

/// Receivers closer than this to a common plane cannot tell a point from its mirror image, mm.
const COPLANAR_MM: f32 = 20.0;

/// Most subsets tried at once: every pair left out of eight receivers.
const MAX_SUBSETS: usize = MAX_RECEIVERS * (MAX_RECEIVERS - 1) / 2;

/// Solves the subsets of `mask` without `k` (1 or 2) of its receivers and keeps those that
/// pass: the subset fits, and every receiver it leaves out misses its solution (otherwise the
/// subset fits only by chance and a bad range is among those it kept). When the passing subsets
/// disagree, the one nearest `hint` wins; without a hint the cycle is ambiguous.
fn leave_out(
    problem: &Problem<'_>,
    geometry: &Geometry<'_>,
    mask: u8,
    k: u32,
    height: &dyn Fn(Vec3) -> f32,
    hint: Option<Vec3>,
) -> Result<(u8, Solution), NoFix> {
    let n = mask.count_ones() as usize;
    let mut candidates: [Option<(u8, Solution)>; MAX_SUBSETS] = [None; MAX_SUBSETS];
    let mut count = 0;
    // Every `out` of `k` receivers of `mask`, in increasing order.
    for out in (1u16..256)
        .map(|o| o as u8)
        .filter(|&o| o & !mask == 0 && o.count_ones() == k)
    {
        let m = mask & !out;
        if problem.mirror_ambiguous(m, geometry.front, height) {
            continue;
        }
        let Ok(s) = problem.solve_subset(m, geometry.front, height, SUBSET_ITERATIONS) else {
            continue;
        };
        let misses = (0..MAX_RECEIVERS).filter(|i| out & (1 << i) != 0).all(|i| {
            problem.ranges[i].is_some_and(|r| {
                let excess = r - (s.x - geometry.receivers[i]).length();
                // With two left out, only late arrivals count: an echo's path is always longer,
                // and with one degree of freedom left a wrong subset often fits a point that
                // some good range misses from the short side.
                excess > OUTLIER_SIGMAS * RANGE_SIGMA_MM || (k == 1 && -excess > OUTLIER_SIGMAS * RANGE_SIGMA_MM)
            })
        });
        if consistent(s.sse, n - k as usize) && misses && count < MAX_SUBSETS {
            candidates[count] = Some((m, s));
            count += 1;
        }
    }
    let mut passing = candidates.iter().flatten();
    let Some(&first) = passing.next() else {
        return Err(NoFix::Inconsistent);
    };
    let lowest = passing.fold(first, |b, &c| if c.1.sse < b.1.sse { c } else { b });
    let same = SAME_POINT_SIGMAS * RANGE_SIGMA_MM * problem.dop(lowest.1.x, lowest.0);
    let agree = candidates
        .iter()
        .flatten()
        .all(|(_, s)| (s.x - lowest.1.x).length() <= same);
    if agree {
        return Ok(lowest);
    }
    let Some(h) = hint else {
        return Err(NoFix::Ambiguous);
    };
    let dist = |c: &(u8, Solution)| (c.1.x - h).length();
    Ok(candidates
        .iter()
        .flatten()
        .fold(first, |b, &c| if dist(&c) < dist(&b) { c } else { b }))
}

/// Solves one cycle. `ranges[i]` is receiver i's range in mm, `None` without an arrival;
/// `height` gives a point's signed distance in front of the display, mm; `hint` is where the
/// emitter probably is (the previous fix), used only to choose between ambiguous subsets.
pub fn solve(
    geometry: &Geometry<'_>,
    ranges: &[Option<f32>; MAX_RECEIVERS],
    height: &dyn Fn(Vec3) -> f32,
    hint: Option<Vec3>,
) -> Result<Fix, NoFix> {
    let problem = Problem {
        receivers: geometry.receivers,
        ranges,
    };
    let mut mask = 0u8;
    for (i, r) in ranges.iter().enumerate().take(geometry.receivers.len()) {
        if matches!(r, Some(r) if r.is_finite() && *r >= 0.0) {
            mask |= 1 << i;
        }
    }
    let n = mask.count_ones();
    if n < 3 {
        return Err(NoFix::TooFewRanges);
    }
    let mut best = problem.solve_subset(mask, geometry.front, height, MAX_ITERATIONS);
    if !matches!(best, Ok(s) if consistent(s.sse, n as usize)) {
        if n < 5 {
            return Err(match best {
                Ok(_) => NoFix::Inconsistent,
                Err(e) => e,
            });
        }
        // Leave each receiver out in turn; with six or more, then each pair (two echoes in one
        // cycle still leave four ranges, one more than a fix needs).
        let mut found = leave_out(&problem, geometry, mask, 1, height, hint);
        if matches!(found, Err(NoFix::Inconsistent)) && n >= 6 {
            // Every pair: trying only the latest arrivals' pairs (3 or 4 suspects) was cheaper
            // but fixed fewer echo cycles (150.7 and 151.2 a second against 152.0). The cost:
            // up to 285 000 instructions in a worst cycle (docs/firmware.md).
            found = leave_out(&problem, geometry, mask, 2, height, hint);
        }
        let (m, s) = found?;
        mask = m;
        best = Ok(s);
    }
    let sol = best?;
    let used = mask.count_ones() as u8;
    Ok(Fix {
        position: sol.x,
        used_mask: mask,
        used,
        residual_rms_mm: crate::math::sqrt(sol.sse / used as f32),
        dop: problem.dop(sol.x, mask),
    })
}
