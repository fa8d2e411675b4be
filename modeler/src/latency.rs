//! The tracked head's latency from emission to frame, on the device's clock (issue 16).
//!
//! A head report's timestamp is the device time of the glasses' burst (the emission); a frame
//! is produced at some later device time, read from the simulated device's clock
//! (`pen_host::transport::sim::DeviceClock`), so both ends are on one clock and no host–device
//! clock offset is estimated. Each frame drawn with a tracked pose records how old that pose's
//! burst is. The end of the sound's flight comes after the emission (up to 1.5 m / c, 4.4 ms),
//! so emission to frame bounds end of flight to frame from above. The pose was predicted
//! `prediction_ms` past its burst: the latency less the prediction is what the prediction leaves
//! uncovered (negative: the pose is predicted past the frame).

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
}

impl LatencySummary {
    /// The 95th percentile less the prediction: what prediction leaves uncovered, ms.
    pub fn uncovered_p95_ms(&self) -> f64 {
        self.p95_ms - f64::from(self.prediction_ms)
    }

    /// Whether the 95th percentile meets [`TARGET_MS`].
    pub fn meets_target(&self) -> bool {
        self.p95_ms <= TARGET_MS
    }
}

impl HeadLatency {
    /// A frame showing the pose of the head burst at `burst_us`, predicted `prediction_ms`
    /// ahead, was started at device time `started_us` and produced at `done_us`. A burst after
    /// the start (a clock restarted by a reattached device) is not a latency: skipped.
    pub fn frame(&mut self, started_us: u64, done_us: u64, burst_us: u64, prediction_ms: u8) {
        if let Some(start) = started_us.checked_sub(burst_us) {
            self.started_us.push(start);
            self.samples_us.push(done_us.saturating_sub(burst_us).max(start));
            self.prediction_ms = prediction_ms;
        }
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
        })
    }
}

fn sorted(v: &[u64]) -> Vec<u64> {
    let mut v = v.to_vec();
    v.sort_unstable();
    v
}

/// Nearest rank: the smallest sample with at least `q` of them at or below it, ms. `sorted` is
/// not empty.
fn percentile_ms(sorted: &[u64], q: f64) -> f64 {
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1] as f64 * 1e-3
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
            l.frame(100_000 + (k - 1) * 1000, 100_000 + k * 1000, 100_000, 20);
        }
        l.frame(5_000, 6_000, 9_000, 20);
        let s = l.summary().expect("frames");
        assert_eq!(s.frames, 20);
        // 10 of 20 at or below 10 ms; 19 of 20 at or below 19 ms.
        assert_eq!((s.p50_ms, s.p95_ms, s.max_ms), (10.0, 19.0, 20.0));
        // Started 1 ms earlier: 0..=19 ms.
        assert_eq!((s.start_p50_ms, s.start_p95_ms), (9.0, 18.0));
        assert!(s.meets_target());
        assert_eq!(s.uncovered_p95_ms(), -1.0);
    }
}
