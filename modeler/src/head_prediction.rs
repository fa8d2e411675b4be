//! The host's prediction of the tracked head (issue 16): the pose a frame is drawn from,
//! extrapolated to when the frame will be done.
//!
//! The base station reports each pose predicted a fixed `prediction_ms` past its burst (20 ms,
//! pen-core's alpha-beta filter). A frame is done later than that when the draw takes longer
//! (burst to frame is ~25 ms on a quiet machine, more under load), so the host carries the
//! prediction on: from the pose's own instant (burst + `prediction_ms`) to the frame's expected
//! end — the device time the frame starts plus the median of the last frames' draw times —
//! at the velocity of a least-squares line through the poses of the last [`WINDOW_US`]. The
//! reports are already filtered, so a short line is smooth enough; a short one also follows the
//! head's lean (which eases in and out over about a second) with little lag.
//!
//! The device time "now" comes from the simulated device's clock when the feed has one;
//! otherwise from the host's clock through the smallest host-minus-device offset of the recent
//! events (the report with the least transport delay), so a real base station is predicted too.

use std::collections::VecDeque;

/// Poses this recent (device µs, before the newest) make the velocity's line: four or five at
/// the head's 64 reports/s.
pub const WINDOW_US: u64 = 70_000;
/// The furthest the host extrapolates past a pose's own instant, µs: as far as the IS-900,
/// the seed's anchor, predicts; beyond it the constant velocity is a guess.
pub const MAX_LEAD_US: u64 = 50_000;
/// Frames whose draw times make the expected one.
const DRAWS: usize = 9;
/// The host-minus-device offset is the least of the events within this long, µs: short enough
/// that the clocks' drift (tens of ppm) does not build up, long enough to hold a quick report.
const OFFSET_WINDOW_US: u64 = 2_000_000;

/// Recent poses and draw times.
#[derive(Debug, Clone, Default)]
pub struct HeadPredictor {
    /// The instant each pose is for (device µs: burst + the base station's prediction) and the
    /// pose (display frame, mm).
    poses: VecDeque<(u64, [f64; 3])>,
    /// The last frames' draw times, µs.
    draws: VecDeque<u64>,
    /// Host minus device time, µs: the least this window and the window before, with the
    /// device time the window began.
    offset: Option<(u64, i64, Option<i64>)>,
}

impl HeadPredictor {
    /// A tracked pose `mm` for device time `at_us`. A time before the newest (a device that
    /// restarted its clock) starts the history anew.
    pub fn pose(&mut self, at_us: u64, mm: [f64; 3]) {
        if self.poses.back().is_some_and(|&(t, _)| at_us <= t) {
            self.poses.clear();
        }
        self.poses.push_back((at_us, mm));
        while self.poses.front().is_some_and(|&(t, _)| at_us - t > WINDOW_US) {
            self.poses.pop_front();
        }
    }

    /// An event stamped `device_us` on the device's clock reached the host at `host_us` (µs
    /// since the Unix epoch): the clocks' offset.
    pub fn arrived(&mut self, device_us: u64, host_us: u64) {
        // Both stamps come from outside (the device's report, pend's line): a pair whose
        // difference does not fit is skipped, not wrapped.
        let Some(offset) = i64::try_from(host_us)
            .ok()
            .zip(i64::try_from(device_us).ok())
            .and_then(|(h, d)| h.checked_sub(d))
        else {
            return;
        };
        self.offset = match self.offset {
            Some((from, least, before)) if device_us >= from && device_us - from < OFFSET_WINDOW_US => {
                Some((from, least.min(offset), before))
            }
            // A new window, the last one kept; or a restarted clock: nothing before counts.
            Some((from, least, _)) if device_us >= from => Some((device_us, offset, Some(least))),
            _ => Some((device_us, offset, None)),
        };
    }

    /// The device time at host time `host_us`, from the events' offset.
    pub fn device_at(&self, host_us: u64) -> Option<u64> {
        let (_, least, before) = self.offset?;
        let offset = before.map_or(least, |b| b.min(least));
        u64::try_from(i64::try_from(host_us).ok()?.checked_sub(offset)?).ok()
    }

    /// A frame took `draw_us` to draw.
    pub fn drawn(&mut self, draw_us: u64) {
        if self.draws.len() == DRAWS {
            self.draws.pop_front();
        }
        self.draws.push_back(draw_us);
    }

    /// The median of the last frames' draw times, µs; 0 before the first.
    pub fn expected_draw_us(&self) -> u64 {
        let mut d: Vec<u64> = self.draws.iter().copied().collect();
        d.sort_unstable();
        d.get(d.len() / 2).copied().unwrap_or(0)
    }

    /// The velocity of the least-squares line through the poses, mm/µs, once two are known.
    pub fn velocity(&self) -> Option<[f64; 3]> {
        let n = self.poses.len();
        if n < 2 {
            return None;
        }
        let t0 = self.poses.front()?.0;
        let mean_t = self.poses.iter().map(|&(t, _)| (t - t0) as f64).sum::<f64>() / n as f64;
        let mut v = [0.0; 3];
        for (axis, v) in v.iter_mut().enumerate() {
            let mean = self.poses.iter().map(|(_, p)| p[axis]).sum::<f64>() / n as f64;
            let (mut st, mut tt) = (0.0, 0.0);
            for &(t, p) in &self.poses {
                let dt = (t - t0) as f64 - mean_t;
                st += dt * (p[axis] - mean);
                tt += dt * dt;
            }
            *v = if tt > 0.0 { st / tt } else { 0.0 };
        }
        Some(v)
    }

    /// The newest pose carried on to device time `to_us` (at most [`MAX_LEAD_US`] either way
    /// of the pose's own instant), and how far it was carried, µs. Back, when the frame is done
    /// before that instant: the base station predicts a fixed time past the burst, and a frame
    /// moved to the newest pose after the latch (`Renderer::reproject`) is done sooner.
    pub fn predict(&self, to_us: u64) -> Option<([f64; 3], i64)> {
        let &(at, p) = self.poses.back()?;
        let max = MAX_LEAD_US as i64;
        let lead = (to_us as i64).saturating_sub(at as i64).clamp(-max, max);
        let v = self.velocity().unwrap_or([0.0; 3]);
        let s = lead as f64;
        Some(([p[0] + v[0] * s, p[1] + v[1] * s, p[2] + v[2] * s], lead))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steady_motion_is_carried_on_exactly() {
        // 0.2 mm/ms right and 0.1 mm/ms in, a pose every 15.5 ms.
        let at = |t: u64| [100.0 + 2e-4 * t as f64, 170.0, 650.0 - 1e-4 * t as f64];
        let mut p = HeadPredictor::default();
        assert_eq!(p.predict(10_000), None);
        for k in 0..10u64 {
            p.pose(20_000 + k * 15_500, at(20_000 + k * 15_500));
        }
        let newest = 20_000 + 9 * 15_500;
        let (got, lead) = p.predict(newest + 12_000).expect("poses");
        assert_eq!(lead, 12_000);
        let want = at(newest + 12_000);
        for a in 0..3 {
            assert!((got[a] - want[a]).abs() < 1e-9, "{got:?} {want:?}");
        }
        // Back, for a frame done before the pose's instant, along the same line.
        let (got, lead) = p.predict(newest - 5_000).expect("poses");
        assert_eq!(lead, -5_000);
        let want = at(newest - 5_000);
        for a in 0..3 {
            assert!((got[a] - want[a]).abs() < 1e-9, "{got:?} {want:?}");
        }
        // Never past the limit either way.
        let max = MAX_LEAD_US as i64;
        assert_eq!(p.predict(newest + 1_000_000).map(|(_, l)| l), Some(max));
        assert_eq!(p.predict(0).map(|(_, l)| l), Some(-max));
    }

    #[test]
    fn a_restarted_clock_forgets_the_poses() {
        let mut p = HeadPredictor::default();
        p.pose(1_000_000, [0.0; 3]);
        p.pose(1_015_000, [1.5; 3]);
        assert!(p.velocity().is_some());
        p.pose(5_000, [9.0; 3]);
        assert_eq!(p.velocity(), None);
        assert_eq!(p.predict(20_000), Some(([9.0; 3], 15_000)));
    }

    #[test]
    fn the_expected_draw_is_the_median_of_the_last_frames() {
        let mut p = HeadPredictor::default();
        assert_eq!(p.expected_draw_us(), 0);
        // One slow frame among quick ones does not move it.
        for d in [20_000, 21_000, 150_000, 19_000, 22_000] {
            p.drawn(d);
        }
        assert_eq!(p.expected_draw_us(), 21_000);
        // Only the last DRAWS count.
        for _ in 0..DRAWS {
            p.drawn(40_000);
        }
        assert_eq!(p.expected_draw_us(), 40_000);
    }

    #[test]
    fn the_device_time_comes_from_the_quickest_event() {
        let mut p = HeadPredictor::default();
        assert_eq!(p.device_at(5), None);
        // Delays of 3, 1 and 2 ms between device and host: the 1 ms is the offset.
        let base = 1_700_000_000_000_000u64;
        for (device, delay) in [(10_000u64, 3_000u64), (20_000, 1_000), (30_000, 2_000)] {
            p.arrived(device, base + device + delay);
        }
        assert_eq!(p.device_at(base + 50_000), Some(49_000));
        // A later window keeps the earlier one's least until it ends.
        p.arrived(2_500_000, base + 2_500_000 + 4_000);
        assert_eq!(p.device_at(base + 2_600_000), Some(2_599_000));
    }

    #[test]
    fn stamps_whose_difference_does_not_fit_are_skipped() {
        let mut p = HeadPredictor::default();
        // A device stamp beyond i64 (a corrupt line) gives no offset and takes nothing.
        p.arrived(1 << 63, 1_700_000_000_000_000);
        assert_eq!(p.device_at(1_700_000_000_000_000), None);
        p.arrived(10_000, 11_000);
        assert_eq!(p.device_at(1 << 63), None, "a host time beyond i64 has no device time");
        assert_eq!(p.device_at(21_000), Some(20_000));
    }
}
