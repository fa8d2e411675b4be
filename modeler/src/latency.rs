//! The tracked head's latency from emission to frame, on the device's clock (issue 16).
//!
//! A head report's timestamp is the device time of the glasses' burst (the emission); a frame
//! is produced at some later device time, read from the simulated device's clock
//! (`pen_host::transport::sim::DeviceClock`), so both ends are on one clock and no host–device
//! clock offset is estimated. Each frame drawn with a tracked pose records how old that pose's
//! burst is. The end of the sound's flight comes after the emission (up to 1.5 m / c, 4.4 ms),
//! so emission to frame bounds end of flight to frame from above. The pose was predicted
//! `prediction_ms` past its burst, and the host carries it on to the frame's expected end
//! ([`crate::head_prediction`]): the latency less both is what the prediction leaves uncovered
//! (negative: the pose is predicted past the frame). With a simulation that knows the head's
//! true path, each frame also measures how far the pose reported and the pose drawn are from
//! where the head was when the frame was done.

use serde_json::json;

use crate::interaction::stats::count;

/// The target: end of flight to frame, ms.
pub const TARGET_MS: f64 = 20.0;

/// Latencies of the frames drawn so far.
#[derive(Debug, Clone, Default)]
pub struct HeadLatency {
    /// Emission to frame per frame, µs.
    samples_us: Vec<u64>,
    /// Emission to the start of drawing the same frames, µs: the part before drawing.
    started_us: Vec<u64>,
    /// The prediction of the poses drawn, ms (the latest).
    prediction_ms: u8,
    /// How far the host carried each frame's pose on past the base station's prediction, µs
    /// (negative: back, for a frame done before the pose's own instant).
    leads_us: Vec<i64>,
    /// Per frame, emission to frame less both predictions, µs.
    uncovered_us: Vec<i64>,
    /// Per frame, with the head's true path: the pose reported and the pose drawn less the
    /// truth when the frame was done, and the pose reported less the truth at its own instant
    /// (burst + prediction: the tracking's and the base station's prediction's error alone), mm.
    errors_mm: Vec<[[f64; 3]; 3]>,
}

/// What [`HeadLatency::summary`] says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatencySummary {
    /// Frames drawn with a tracked pose.
    pub frames: usize,
    /// Emission to frame, ms: median, 95th percentile, most.
    pub p50_ms: f64,
    /// See [`p50_ms`](Self::p50_ms).
    pub p95_ms: f64,
    /// See [`p50_ms`](Self::p50_ms).
    pub max_ms: f64,
    /// How far past its burst each pose was predicted, ms.
    pub prediction_ms: u8,
    /// Emission to the start of drawing, ms: median and 95th percentile (the rest of the
    /// latency is the drawing).
    pub start_p50_ms: f64,
    /// See [`start_p50_ms`](Self::start_p50_ms).
    pub start_p95_ms: f64,
    /// How far the host carried the poses on past the base station's prediction, ms: median
    /// (negative: back, frames done before their poses' own instants).
    pub host_lead_p50_ms: f64,
    /// Emission to frame less the base station's and the host's prediction, ms: 95th
    /// percentile ([`uncovered_p95_ms`](Self::uncovered_p95_ms)).
    pub uncovered_p95: f64,
    /// With the head's true path: the poses as reported, mm from where the head was when their
    /// frames were done.
    pub reported_error: Option<ErrorSummary>,
    /// The same for the poses drawn (carried on by the host).
    pub drawn_error: Option<ErrorSummary>,
    /// The poses as reported, from where the head was at their own instant (burst + the base
    /// station's prediction): what no prediction by the host can remove.
    pub tracking_error: Option<ErrorSummary>,
    /// The mean of the poses reported less the truth at their own instant, mm: an offset
    /// between the calibrated display frame and the simulator's, the same for every pose and no
    /// matter of timing. It is in the three errors above: since the calibration's pivot takes
    /// the pen's emitter-to-tip vector out of the glasses' positions it is under half a
    /// millimetre (without the pivot, the 8 mm of that vector).
    pub bias_mm: [f64; 3],
}

/// Distances from the truth, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorSummary {
    /// Median.
    pub p50_mm: f64,
    /// 95th percentile.
    pub p95_mm: f64,
    /// Root mean square.
    pub rms_mm: f64,
}

impl ErrorSummary {
    fn of(mm: impl Iterator<Item = f64>) -> Option<ErrorSummary> {
        let mut v: Vec<f64> = mm.collect();
        if v.is_empty() {
            return None;
        }
        v.sort_unstable_by(f64::total_cmp);
        Some(ErrorSummary {
            p50_mm: nearest_rank(&v, 0.5),
            p95_mm: nearest_rank(&v, 0.95),
            rms_mm: (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt(),
        })
    }
}

impl LatencySummary {
    /// What prediction leaves uncovered, ms: the 95th percentile of each frame's emission to
    /// frame less the base station's and the host's prediction of its pose.
    pub fn uncovered_p95_ms(&self) -> f64 {
        self.uncovered_p95
    }

    /// Whether the 95th percentile meets [`TARGET_MS`].
    pub fn meets_target(&self) -> bool {
        self.p95_ms <= TARGET_MS
    }
}

impl HeadLatency {
    /// A frame showing the pose of the head burst at `burst_us`, predicted `prediction_ms`
    /// ahead by the base station and `lead_us` further by the host, was started at device time
    /// `started_us` and produced at `done_us`. A burst after the start (a clock restarted by a
    /// reattached device) is not a latency: skipped.
    pub fn frame(&mut self, started_us: u64, done_us: u64, burst_us: u64, prediction_ms: u8, lead_us: i64) {
        if let Some(start) = started_us.checked_sub(burst_us) {
            self.started_us.push(start);
            self.samples_us.push(done_us.saturating_sub(burst_us).max(start));
            self.prediction_ms = prediction_ms;
            self.leads_us.push(lead_us);
            let age = done_us.saturating_sub(burst_us).max(start) as i64;
            self.uncovered_us.push(age - i64::from(prediction_ms) * 1000 - lead_us);
        }
    }

    /// The last frame's pose as reported less where the head was when the frame was done was
    /// `reported_mm`, the pose drawn less it `drawn_mm`; the pose reported less where the head
    /// was at the pose's own instant `tracking_mm`.
    pub fn error(&mut self, reported_mm: [f64; 3], drawn_mm: [f64; 3], tracking_mm: [f64; 3]) {
        self.errors_mm.push([reported_mm, drawn_mm, tracking_mm]);
    }

    /// The mean of the tracking errors ([`LatencySummary::bias_mm`]).
    fn bias_mm(&self) -> [f64; 3] {
        let n = self.errors_mm.len().max(1) as f64;
        std::array::from_fn(|a| self.errors_mm.iter().map(|e| e[2][a]).sum::<f64>() / n)
    }

    /// The `k`th error of each frame, mm.
    fn errors(&self, k: usize) -> Option<ErrorSummary> {
        ErrorSummary::of(
            self.errors_mm
                .iter()
                .map(|e| (e[k][0].powi(2) + e[k][1].powi(2) + e[k][2].powi(2)).sqrt()),
        )
    }

    /// The figures, once a frame was recorded.
    pub fn summary(&self) -> Option<LatencySummary> {
        let (done, started) = (sorted(&self.samples_us), sorted(&self.started_us));
        (!done.is_empty()).then(|| LatencySummary {
            frames: done.len(),
            p50_ms: percentile_ms(&done, 0.5),
            p95_ms: percentile_ms(&done, 0.95),
            max_ms: percentile_ms(&done, 1.0),
            prediction_ms: self.prediction_ms,
            start_p50_ms: percentile_ms(&started, 0.5),
            start_p95_ms: percentile_ms(&started, 0.95),
            host_lead_p50_ms: signed_percentile_ms(&self.leads_us, 0.5),
            uncovered_p95: signed_percentile_ms(&self.uncovered_us, 0.95),
            reported_error: self.errors(0),
            drawn_error: self.errors(1),
            tracking_error: self.errors(2),
            bias_mm: self.bias_mm(),
        })
    }
}

fn sorted(v: &[u64]) -> Vec<u64> {
    let mut v = v.to_vec();
    v.sort_unstable();
    v
}

/// Nearest rank: the smallest of the `sorted` samples with at least `q` of them at or below it.
/// `sorted` is not empty.
pub fn nearest_rank<T: Copy>(sorted: &[T], q: f64) -> T {
    sorted[((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1]
}

/// [`nearest_rank`] of sorted µs, in ms.
fn percentile_ms(sorted: &[u64], q: f64) -> f64 {
    nearest_rank(sorted, q) as f64 * 1e-3
}

/// [`percentile_ms`] of µs that may be negative, not sorted; `v` is not empty.
fn signed_percentile_ms(v: &[i64], q: f64) -> f64 {
    let mut v = v.to_vec();
    v.sort_unstable();
    nearest_rank(&v, q) as f64 * 1e-3
}

/// How views moved to their poses compare with views drawn whole from the same poses.
/// A view moved to its pose against the view drawn whole from it.
#[derive(Debug, Clone, Copy)]
pub struct Check {
    /// Mean absolute difference per channel, 0–255.
    pub mean_abs: f64,
    /// The share of pixels that differ by more than [`VISIBLE_LEVELS`].
    pub visible: f64,
}

/// A pixel differs visibly by more than this many levels in a channel.
pub const VISIBLE_LEVELS: u8 = 8;

/// The tracked head's emission-to-frame latency `latency` (a session's) and the `checks` of its
/// reprojected views for the JSON summary (issue 16), or null
/// without a tracked head on a paced simulated device's clock (`--source sim --speed 1`).
pub fn head_json(latency: Option<LatencySummary>, checks: &[Check]) -> serde_json::Value {
    match latency {
        None => serde_json::Value::Null,
        Some(l) => json!({
            "reprojection": reprojection_json(checks),
            "frames": l.frames, "p50_ms": l.p50_ms, "p95_ms": l.p95_ms, "max_ms": l.max_ms,
            "prediction_ms": l.prediction_ms, "uncovered_p95_ms": l.uncovered_p95_ms(),
            "draw_start_p50_ms": l.start_p50_ms, "draw_start_p95_ms": l.start_p95_ms,
            "target_ms": TARGET_MS, "meets_target": l.meets_target(),
            "host_lead_p50_ms": l.host_lead_p50_ms,
            "reported_error_mm": error_json(l.reported_error), "drawn_error_mm": error_json(l.drawn_error),
            "tracking_error_mm": error_json(l.tracking_error), "bias_mm": l.bias_mm,
        }),
    }
}

/// How the views moved to their poses compare with views drawn whole from them
/// ([`crate::painter::Painter::check_reprojection`]), or null when none was moved.
fn reprojection_json(checks: &[Check]) -> serde_json::Value {
    match Reprojection::of(checks) {
        None => serde_json::Value::Null,
        Some(r) => json!({
            "frames": r.frames, "mean_abs_p50": r.mean_abs_p50, "mean_abs_max": r.mean_abs_max,
            "visibly_different_p50": r.visible_p50, "visibly_different_p95": r.visible_p95,
            "visible_levels": VISIBLE_LEVELS,
        }),
    }
}

/// [`Check`]s summed up.
struct Reprojection {
    frames: usize,
    mean_abs_p50: f64,
    mean_abs_max: f64,
    /// Shares of pixels, 0–1.
    visible_p50: f64,
    visible_p95: f64,
}

impl Reprojection {
    fn of(checks: &[Check]) -> Option<Reprojection> {
        let sorted = |f: fn(&Check) -> f64| {
            let mut v: Vec<f64> = checks.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let (mean_abs, visible) = (sorted(|c| c.mean_abs), sorted(|c| c.visible));
        (!checks.is_empty()).then(|| Reprojection {
            frames: checks.len(),
            mean_abs_p50: nearest_rank(&mean_abs, 0.5),
            mean_abs_max: nearest_rank(&mean_abs, 1.0),
            visible_p50: nearest_rank(&visible, 0.5),
            visible_p95: nearest_rank(&visible, 0.95),
        })
    }
}

/// Distances of the poses from the head's true path, or null without it.
fn error_json(e: Option<ErrorSummary>) -> serde_json::Value {
    e.map_or(
        serde_json::Value::Null,
        |e| json!({"p50": e.p50_mm, "p95": e.p95_mm, "rms": e.rms_mm}),
    )
}

/// [`head_json`] for a person: emission to frame against the 20 ms target, and what prediction
/// leaves uncovered.
pub fn head_line(latency: Option<LatencySummary>, checks: &[Check]) -> Option<String> {
    let l = latency?;
    let moved = Reprojection::of(checks).map_or(String::new(), |r| {
        format!(
            "; {} moved to their poses after the latch, against the same drawn whole: p50 {:.2}/255 \
             (most {:.2}), pixels differing visibly p50 {:.2} % / p95 {:.2} %",
            count(r.frames as u64, "view"),
            r.mean_abs_p50,
            r.mean_abs_max,
            r.visible_p50 * 100.0,
            r.visible_p95 * 100.0
        )
    });
    let truth = match (l.reported_error, l.drawn_error, l.tracking_error) {
        (Some(r), Some(d), Some(t)) => format!(
            "; from the true head when the frame was done: as reported p50 {:.1} / p95 {:.1} mm, as drawn p50 {:.1} / \
             p95 {:.1} mm (at the pose's own instant p50 {:.1} / p95 {:.1} mm)",
            r.p50_mm, r.p95_mm, d.p50_mm, d.p95_mm, t.p50_mm, t.p95_mm
        ),
        _ => String::new(),
    };
    Some(format!(
        "head: emission to frame on the device's clock p50 {:.1} ms, p95 {:.1} ms, max {:.1} ms over {} \
         (to the start of drawing p50 {:.1}, p95 {:.1}); target {} ms {}; predicted {} ms ahead, p95 uncovered {:.1} ms, \
         carried on by the host p50 {:.1} ms{truth}{moved}",
        l.p50_ms,
        l.p95_ms,
        l.max_ms,
        count(l.frames as u64, "frame"),
        l.start_p50_ms,
        l.start_p95_ms,
        TARGET_MS,
        if l.meets_target() { "met" } else { "missed" },
        l.prediction_ms,
        l.uncovered_p95_ms(),
        l.host_lead_p50_ms,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_by_nearest_rank() {
        let mut l = HeadLatency::default();
        assert_eq!(l.summary(), None);
        // Ages 1..=20 ms, given out of order, each drawn in 1 ms; one frame started before its
        // burst is skipped.
        for k in (1..=20u64).rev() {
            l.frame(
                100_000 + (k - 1) * 1000,
                100_000 + k * 1000,
                100_000,
                20,
                k as i64 * 100,
            );
        }
        l.frame(5_000, 6_000, 9_000, 20, 0);
        let s = l.summary().expect("frames");
        assert_eq!(s.frames, 20);
        // 10 of 20 at or below 10 ms; 19 of 20 at or below 19 ms.
        assert_eq!((s.p50_ms, s.p95_ms, s.max_ms), (10.0, 19.0, 20.0));
        // Started 1 ms earlier: 0..=19 ms.
        assert_eq!((s.start_p50_ms, s.start_p95_ms), (9.0, 18.0));
        assert!(s.meets_target());
        // Less the 20 ms and the host's k × 0.1 ms: k × 0.9 − 20 ms, rising with k, so the 19th.
        let mut uncovered: Vec<f64> = (1..=20).map(|k| f64::from(k) * 0.9 - 20.0).collect();
        uncovered.sort_by(f64::total_cmp);
        assert!(
            (s.uncovered_p95_ms() - uncovered[18]).abs() < 1e-9,
            "{}",
            s.uncovered_p95_ms()
        );
        // Leads of 0.1..=2 ms: 10 of 20 at or below 1 ms.
        assert_eq!(s.host_lead_p50_ms, 1.0);
        assert_eq!((s.reported_error, s.drawn_error, s.tracking_error), (None, None, None));
    }

    #[test]
    fn errors_by_nearest_rank_and_their_rms() {
        let mut l = HeadLatency::default();
        l.frame(0, 1_000, 0, 20, 0);
        // Reported 1..=20 mm off along y, drawn 3 mm off along z, tracked 3 or 7 mm off along x
        // (a bias of 5 mm along x, their mean, which stays in the errors).
        for k in 1..=20 {
            let tracked = if k % 2 == 0 { 3.0 } else { 7.0 };
            l.error([0.0, f64::from(k), 0.0], [0.0, 0.0, 3.0], [tracked, 0.0, 0.0]);
        }
        let s = l.summary().expect("a frame");
        let r = s.reported_error.expect("errors");
        assert_eq!((r.p50_mm, r.p95_mm), (10.0, 19.0));
        let mean_square = (1..=20).map(|k| f64::from(k * k)).sum::<f64>() / 20.0;
        assert!((r.rms_mm - mean_square.sqrt()).abs() < 1e-12);
        let d = s.drawn_error.expect("errors");
        assert_eq!((d.p50_mm, d.p95_mm, d.rms_mm), (3.0, 3.0, 3.0));
        assert_eq!(s.tracking_error.map(|t| (t.p50_mm, t.p95_mm)), Some((3.0, 7.0)));
        assert_eq!(s.bias_mm, [5.0, 0.0, 0.0]);
    }
}
