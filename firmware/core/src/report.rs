//! The engine: one measurement cycle in, pen reports out, configuration requests answered.
//!
//! It holds no hardware and does no waiting. The station (`station.rs`) feeds it capture times
//! and switch samples at the times the hardware (or the simulated pen) provides, and sends what
//! it reports.

use pen_protocol::{
    Command, Config, DeviceInfo, Filter, FirmwareVersion, GetFeature, HeadReport, MAX_PREDICTION_MS, MAX_RECEIVERS,
    Message, NO_ARRIVAL, OsPenReport, PROTOCOL_VERSION, PenReport, Position, Quality, Report, ReportId, ResetRecord,
    Status, StatusCode, TofReport, os_extent,
};

use crate::debounce::Debouncer;
use crate::filter::{OneEuroParams, Smoother};
use crate::head::{
    Emitter, HEAD_MAX_SPEED_MM_PER_US, HEAD_TRACK_TIMEOUT_US, HeadFilter, HeadSettings, MUX_GUARD_US, mux_listen_us,
};
use crate::math::Vec3;
use crate::ranging::{range_mm, time_of_flight_ns};
use crate::settings::{Settings, default_config};
use crate::solve::{self, Fix, Geometry, NoFix};
use crate::store::{ConfigStore, Saved};
use crate::track::Track;

/// The shortest measurement cycle, µs: the listening window plus time for the echoes of the
/// previous burst to die away. 6.5 ms is 153.8 fixes per second.
pub const MIN_CYCLE_US: u64 = 6_500;
/// How long after the burst the receivers are listened to, µs: 1.5 m of flight even at
/// 300 m/s (−40 °C).
pub const LISTEN_US: u64 = 5_000;
/// How often switches are sampled and reports polled, µs.
pub const TICK_US: u64 = 500;
/// Fixes with a larger dilution of precision are not reported: at 2 µs of timing jitter their
/// expected error exceeds 7 mm. The reference build stays below 3.7 with all receivers; only a
/// fix from a poorly placed subset (three receivers left, say) comes near it.
pub const MAX_REPORTED_DOP: f32 = 10.0;
/// How long the pen stays in range after its last reported fix, µs. A cycle without a fix (an
/// echo-spoiled or gated one) is common and short; ending proximity for it would make an OS end
/// the stroke (Windows lifts the contact, libinput drops a tip outside proximity). 100 ms is 15
/// cycles: long enough to ride out a run of bad cycles, short enough that a pen taken away is
/// out of range before a user notices.
pub const IN_RANGE_HOLD_US: u64 = 100_000;
/// How far beyond the display's edges the OS's pen stays in range (at the edge), mm: a stroke
/// drawn to the edge does not break on the last millimetre's noise.
pub const OS_EDGE_MARGIN_MM: f32 = 20.0;

/// One measurement cycle as the receivers heard it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cycle {
    /// Device time of the burst, µs.
    pub t0_us: u64,
    /// Capture time of each receiver's first arrival after the burst, ns; `None` for no arrival
    /// within the listening window.
    pub arrival_ns: [Option<u32>; MAX_RECEIVERS],
}

/// What a cycle produced, for diagnostics and the simulator's traces.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CycleResult {
    /// The accepted fix before smoothing (solved and through the tracking gate), or why there
    /// was none.
    pub fix: Result<Fix, NoFix>,
    /// The reported position in mm (smoothed, constrained, in the reporting frame) when in range.
    pub reported_mm: Option<Vec3>,
}

/// Something the firmware must do outside the engine after a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Action {
    /// Restart into the ROM DFU bootloader (after the status has been sent).
    EnterBootloader,
    /// Restart the firmware (after the status has been sent): the saved configuration's display
    /// size differs from the one the USB descriptor was built for, and the OS must enumerate the
    /// device again to map its pen onto the new display.
    Restart,
}

/// Counters since start-up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// Measurement cycles.
    pub cycles: u32,
    /// Cycles with a fix.
    pub fixes: u32,
    /// Fixes that left one receiver out as inconsistent.
    pub rejected_receivers: u32,
    /// Cycles without a fix because the ranges disagreed, were ambiguous, pointed behind the
    /// display or placed the pen too poorly.
    pub inconsistent: u32,
    /// Fixes held back by the tracking gate (a jump, or the first fix after a gap).
    pub gated: u32,
    /// Cycles with fewer than three arrivals.
    pub too_few: u32,
    /// Pen reports produced.
    pub reports: u32,
}

/// One slot of the measurement loop: which emitter fires, how long the slot lasts and how long
/// after the burst the receivers are listened to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Slot {
    /// The emitter fired.
    pub emitter: Emitter,
    /// From this burst to the next, µs.
    pub period_us: u64,
    /// From the burst to the collection of the arrivals, µs (less than the period).
    pub listen_us: u64,
}

/// Head counters since head tracking started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeadCounters {
    /// Head slots.
    pub slots: u32,
    /// Head slots with a fix through the head's tracking gate.
    pub fixes: u32,
    /// Head reports produced.
    pub reports: u32,
}

/// The tracked head's state.
struct HeadState {
    settings: HeadSettings,
    track: Track,
    filter: HeadFilter,
    /// The last reported position (held while no fix comes).
    position: Position,
    pending: Option<HeadReport>,
    seq: u16,
    /// The slot within the schedule's pattern.
    slot: u32,
    counters: HeadCounters,
}

impl HeadState {
    fn new(settings: HeadSettings) -> HeadState {
        HeadState {
            settings: HeadSettings {
                prediction_ms: settings.prediction_ms.min(MAX_PREDICTION_MS),
                ..settings
            },
            track: Track::with_limits(HEAD_TRACK_TIMEOUT_US, HEAD_MAX_SPEED_MM_PER_US),
            filter: HeadFilter::new(),
            position: Position::default(),
            pending: None,
            seq: 0,
            slot: 0,
            counters: HeadCounters::default(),
        }
    }
}

/// The switch transitions not yet reported, so that a click between two reports is never lost.
#[derive(Debug, Clone, Copy, Default)]
struct SwitchLatch {
    reported: [bool; 3],
    pending: [u8; 3],
}

impl SwitchLatch {
    fn any_pending(&self) -> bool {
        self.pending.iter().any(|&p| p > 0)
    }

    /// The levels to report now: each pending transition is reported once, in order.
    fn take(&mut self, current: [bool; 3]) -> [bool; 3] {
        for ((reported, pending), current) in self.reported.iter_mut().zip(&mut self.pending).zip(current) {
            match *pending {
                0 => *reported = current,
                n => {
                    *reported = !*reported;
                    *pending = n - 1;
                }
            }
        }
        self.reported
    }
}

/// The state of the base station.
pub struct Engine {
    settings: Settings,
    smoother: Smoother,
    track: Track,
    debouncer: Debouncer,
    latch: SwitchLatch,
    firmware: FirmwareVersion,
    unique_id: [u8; 12],
    /// The OS pen's extent the USB descriptor was built with, at start-up (0.1 mm).
    os_extent: Option<[u16; 2]>,
    status: Status,
    // The latest cycle.
    /// The latest reportable fix, smoothed, tracker frame.
    smoothed: Option<Vec3>,
    /// The position of the last report (held while no fix comes).
    position: Position,
    /// Device time of the last reported fix: the pen is in range for [`IN_RANGE_HOLD_US`] after
    /// it, or while the tip is pressed.
    last_fix_us: Option<u64>,
    /// The latest cycle fixed: its position is fresh.
    fixed: bool,
    quality: Quality,
    timestamp_us: u32,
    tof: TofReport,
    last_result: Option<CycleResult>,
    // Reporting.
    fresh: bool,
    seq: u16,
    last_report_us: Option<u64>,
    counters: Counters,
    /// Head tracking, while it runs.
    head: Option<HeadState>,
    /// The glasses' emitter is wired to this base station: the HeadOn command may start it.
    head_fitted: bool,
    /// Why the previous run ended, when a panic or a fault ended it (the reset record, 0x09).
    last_reset: ResetRecord,
}

/// The OS pen's extent for a configuration's display, if its size is known.
fn display_extent(config: &Config) -> Option<[u16; 2]> {
    config.display.and_then(|d| os_extent(d.size_mm))
}

fn smoother_for(filter: Filter) -> Smoother {
    Smoother::new(match filter {
        Filter::Off => None,
        Filter::OneEuro {
            min_cutoff_hz,
            beta,
            d_cutoff_hz,
        } => Some(OneEuroParams {
            min_cutoff_hz,
            beta,
            d_cutoff_hz,
        }),
    })
}

impl Engine {
    /// An engine running `config`, or the defaults when `config` is `None` or invalid.
    pub fn new(config: Option<Config>, firmware: FirmwareVersion, unique_id: [u8; 12]) -> Engine {
        let settings = config
            .and_then(|c| Settings::new(c).ok())
            .or_else(|| Settings::new(default_config()).ok())
            .unwrap_or_else(|| unreachable!("the default configuration is valid (tested)"));
        let os_extent = display_extent(&settings.config);
        Engine {
            smoother: smoother_for(settings.config.filter),
            os_extent,
            settings,
            track: Track::new(),
            debouncer: Debouncer::new(),
            latch: SwitchLatch::default(),
            firmware,
            unique_id,
            status: Status::ok(0),
            smoothed: None,
            position: Position::default(),
            last_fix_us: None,
            fixed: false,
            quality: Quality::NONE,
            timestamp_us: 0,
            tof: TofReport {
                seq: 0,
                timestamp_us: 0,
                receiver_count: 0,
                used_mask: 0,
                tof_ns: [NO_ARRIVAL; MAX_RECEIVERS],
                speed_of_sound_m_s: 0.0,
            },
            last_result: None,
            fresh: false,
            seq: 0,
            last_report_us: None,
            counters: Counters::default(),
            head: None,
            head_fitted: false,
            last_reset: ResetRecord::NONE,
        }
    }

    /// The running configuration.
    pub fn config(&self) -> &Config {
        &self.settings.config
    }

    /// The derived settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Counters since start-up.
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// What the latest cycle produced.
    pub fn last_result(&self) -> Option<CycleResult> {
        self.last_result
    }

    /// The debounced switches.
    pub fn switches(&self) -> [bool; 3] {
        self.debouncer.state()
    }

    /// The measurement cycle's period, µs: the report interval, but never shorter than
    /// [`MIN_CYCLE_US`]; faster report rates repeat the latest fix between cycles. With the head
    /// tracked, every slot's: 1.5 m of flight at the running speed of sound and a guard
    /// ([`crate::head`]), whatever the report rate.
    pub fn cycle_period_us(&self) -> u64 {
        match self.head {
            Some(_) => self.mux_listen_us() + MUX_GUARD_US,
            None => self.settings.report_interval_us.unwrap_or(0).max(MIN_CYCLE_US),
        }
    }

    /// How long after a burst its arrivals are listened to, µs: the pen's [`LISTEN_US`], or
    /// with the head tracked every slot's window.
    pub fn listen_us(&self) -> u64 {
        match self.head {
            Some(_) => self.mux_listen_us(),
            None => LISTEN_US,
        }
    }

    fn mux_listen_us(&self) -> u64 {
        let s = &self.settings;
        let max_delay = s.delays_ns[..s.count].iter().copied().max().unwrap_or(0);
        mux_listen_us(s.speed_m_s, max_delay)
    }

    /// Starts tracking the head (the glasses' emitter is fitted) with `settings`, or stops it
    /// (`None`): the pen then has every cycle again.
    pub fn set_head(&mut self, settings: Option<HeadSettings>) {
        self.head = settings.map(HeadState::new);
    }

    /// Says whether the glasses' emitter is wired to this base station (the board knows; the
    /// simulator fits it with a viewer). Without it the HeadOn command is answered *not
    /// supported*.
    pub fn set_head_emitter_fitted(&mut self, fitted: bool) {
        self.head_fitted = fitted;
        if !fitted {
            self.head = None;
        }
    }

    /// Starts head tracking as it was saved (a SaveConfig while it ran, [`Saved::head`]), where
    /// the glasses' emitter is fitted: call after
    /// [`set_head_emitter_fitted`](Self::set_head_emitter_fitted). Returns whether it runs.
    pub fn resume_head(&mut self, saved_on: bool) -> bool {
        if saved_on && self.head_fitted && self.head.is_none() {
            self.set_head(Some(HeadSettings::default()));
        }
        self.head.is_some()
    }

    /// The head's settings, while it is tracked.
    pub fn head_settings(&self) -> Option<HeadSettings> {
        self.head.as_ref().map(|h| h.settings)
    }

    /// Head counters, while the head is tracked.
    pub fn head_counters(&self) -> Option<HeadCounters> {
        self.head.as_ref().map(|h| h.counters)
    }

    /// The next slot of the measurement loop (and the schedule moves on): every one the pen's
    /// without the head, else the schedule's pattern.
    pub fn next_slot(&mut self) -> Slot {
        let (period_us, listen_us) = (self.cycle_period_us(), self.listen_us());
        let Some(head) = self.head.as_mut() else {
            return Slot {
                emitter: Emitter::Pen,
                period_us,
                listen_us,
            };
        };
        let schedule = head.settings.schedule;
        let emitter = schedule.emitter(head.slot);
        head.slot = (head.slot + 1) % schedule.slots().max(1);
        Slot {
            emitter,
            period_us,
            listen_us,
        }
    }

    /// Pen fixes per second the schedule allows.
    fn pen_rate_hz(&self) -> u16 {
        let period = self.cycle_period_us();
        let (pen, slots) = self.head.as_ref().map_or((1, 1), |h| {
            (h.settings.schedule.pen as u64, h.settings.schedule.slots() as u64)
        });
        let per_frame = period * slots.max(1);
        ((1_000_000 * pen + per_frame / 2) / per_frame) as u16
    }

    /// The device information report.
    pub fn device_info(&self) -> DeviceInfo {
        DeviceInfo {
            protocol: PROTOCOL_VERSION,
            firmware: self.firmware,
            receiver_count: self.settings.config.receiver_count,
            max_receivers: MAX_RECEIVERS as u8,
            fix_rate_hz: self.pen_rate_hz(),
            unique_id: self.unique_id,
        }
    }

    /// Takes a sample of the raw switch levels (true = pressed).
    pub fn on_switches(&mut self, now_us: u64, raw: [bool; 3]) {
        let changed = self.debouncer.sample(now_us, raw, self.settings.debounce_us);
        for (pending, changed) in self.latch.pending.iter_mut().zip(changed) {
            *pending = pending.saturating_add(changed as u8);
        }
    }

    /// Solves a measurement cycle and updates the position the next report carries.
    pub fn on_cycle(&mut self, cycle: &Cycle) -> CycleResult {
        let (ranges, tof_ns) = self.ranges(cycle);
        let hint = self.track.hint(cycle.t0_us);
        let raw = self
            .solve(&ranges, hint)
            .and_then(|fix| self.track.gate(cycle.t0_us, fix.position).map(|()| fix));
        self.counters.cycles += 1;
        let reported = match raw {
            Ok(fix) => {
                self.counters.fixes += 1;
                if (fix.used as usize) < ranges.iter().filter(|r| r.is_some()).count() {
                    self.counters.rejected_receivers += 1;
                }
                self.report_position(cycle.t0_us, fix)
            }
            Err(e) => {
                match e {
                    NoFix::TooFewRanges => self.counters.too_few += 1,
                    NoFix::Jump | NoFix::Acquiring => self.counters.gated += 1,
                    _ => self.counters.inconsistent += 1,
                }
                None
            }
        };
        self.fixed = reported.is_some();
        if self.fixed {
            self.last_fix_us = Some(cycle.t0_us);
        }
        self.quality = match raw {
            Ok(fix) if self.fixed => Quality::new(fix.used, fix.residual_rms_mm, fix.dop),
            _ => Quality::NONE,
        };
        // The device clock wraps in the report, as the protocol defines.
        self.timestamp_us = cycle.t0_us as u32;
        self.tof = TofReport {
            seq: self.seq,
            timestamp_us: self.timestamp_us,
            receiver_count: self.settings.count as u8,
            used_mask: raw.map_or(0, |f| f.used_mask),
            tof_ns,
            speed_of_sound_m_s: self.settings.speed_m_s,
        };
        self.fresh = true;
        let result = CycleResult {
            fix: raw,
            reported_mm: reported,
        };
        self.last_result = Some(result);
        result
    }

    /// Each configured receiver's range (mm) and time of flight (ns) in `cycle`. An arrival
    /// after the listening window is none: the station collects them when the window closes,
    /// but a replay or a faulty capture may still carry one, and a consistent set of ranges
    /// beyond the workspace would solve to a fix far outside it. So every fix lies within the
    /// window's flight of the receivers it used (the fuzz property checks it).
    fn ranges(&self, cycle: &Cycle) -> ([Option<f32>; MAX_RECEIVERS], [u32; MAX_RECEIVERS]) {
        let s = &self.settings;
        let window_ns = self.listen_us() * 1000;
        let mut ranges = [None; MAX_RECEIVERS];
        let mut tof_ns = [NO_ARRIVAL; MAX_RECEIVERS];
        for i in 0..s.count {
            let arrival = cycle.arrival_ns[i].filter(|&a| u64::from(a) <= window_ns);
            if let Some(t) = arrival.and_then(|a| time_of_flight_ns(a, s.delays_ns[i])) {
                tof_ns[i] = t;
                ranges[i] = Some(range_mm(t, s.speed_m_s));
            }
        }
        (ranges, tof_ns)
    }

    /// Multilateration of one burst, with fixes placed too poorly refused.
    fn solve(&self, ranges: &[Option<f32>; MAX_RECEIVERS], hint: Option<Vec3>) -> Result<Fix, NoFix> {
        let s = &self.settings;
        let geometry = Geometry {
            receivers: &s.receivers[..s.count],
            front: s.front(),
        };
        solve::solve(&geometry, ranges, &|p| s.height(p), hint).and_then(|fix| {
            if fix.dop > MAX_REPORTED_DOP {
                Err(NoFix::PoorGeometry)
            } else {
                Ok(fix)
            }
        })
    }

    /// Solves a head slot (the glasses' burst): through the head's own tracking gate and
    /// alpha-beta filter, predicted ahead, into the head report [`poll_head`](Self::poll_head)
    /// returns. A slot without a fix holds the last position with `no_fix` set. Without head
    /// tracking the slot is ignored.
    pub fn on_head_cycle(&mut self, cycle: &Cycle) -> CycleResult {
        let (ranges, _) = self.ranges(cycle);
        let hint = self.head.as_ref().and_then(|h| h.track.hint(cycle.t0_us));
        let solved = self.solve(&ranges, hint);
        let display = self
            .settings
            .display
            .filter(|_| self.settings.config.report_display_frame);
        let Some(head) = self.head.as_mut() else {
            return CycleResult {
                fix: Err(NoFix::TooFewRanges),
                reported_mm: None,
            };
        };
        head.counters.slots += 1;
        let raw = solved.and_then(|fix| head.track.gate(cycle.t0_us, fix.position).map(|()| fix));
        let mut reported = None;
        let mut quality = Quality::NONE;
        if let Ok(fix) = raw {
            head.counters.fixes += 1;
            head.filter.update(cycle.t0_us, fix.position);
            let ahead_us = head.settings.prediction_ms as u64 * 1000;
            if let Some(predicted) = head.filter.predict(ahead_us) {
                let p = display.map_or(predicted, |d| d.to_display(predicted));
                if let Some(position) = Position::from_mm(p.to_array()) {
                    head.position = position;
                    reported = Some(p);
                    quality = Quality::new(fix.used, fix.residual_rms_mm, fix.dop);
                }
            }
        }
        head.pending = Some(HeadReport {
            no_fix: reported.is_none(),
            display_frame: display.is_some(),
            position: head.position,
            prediction_ms: head.settings.prediction_ms,
            seq: head.seq,
            timestamp_us: cycle.t0_us as u32,
            quality,
        });
        head.seq = head.seq.wrapping_add(1);
        CycleResult {
            fix: raw,
            reported_mm: reported,
        }
    }

    /// The head report of the latest head slot, once.
    pub fn poll_head(&mut self) -> Option<HeadReport> {
        let head = self.head.as_mut()?;
        let report = head.pending.take()?;
        head.counters.reports += 1;
        Some(report)
    }

    /// Smooths, constrains and transforms a fix; `None` if it cannot be reported.
    fn report_position(&mut self, t_us: u64, fix: Fix) -> Option<Vec3> {
        let smoothed = self.smoother.filter(t_us, fix.position);
        let p = self.presented(smoothed);
        // A fix that cannot be carried (beyond ±3.27 m) is not reported.
        Position::from_mm(p.to_array())?;
        self.smoothed = Some(smoothed);
        Some(p)
    }

    /// A smoothed fix as reported now: on the display surface while the tip switch is pressed
    /// (so a tip_down already lies on it, though its fix came before the press), in the display
    /// frame if the configuration asks for it.
    fn presented(&self, smoothed: Vec3) -> Vec3 {
        let s = &self.settings;
        let mut p = smoothed;
        if let Some(display) = &s.display {
            if self.debouncer.state()[0] {
                p = display.onto_surface(p);
            }
            if s.config.report_display_frame {
                p = display.to_display(p);
            }
        }
        p
    }

    /// The next pen report, if one is due at `now_us`: after each cycle, after a switch
    /// transition, and between cycles at the report rate when it exceeds the cycle rate.
    pub fn poll_report(&mut self, now_us: u64) -> Option<PenReport> {
        let period = self.cycle_period_us();
        let between_cycles = self.settings.report_interval_us.is_some_and(|interval| {
            interval < period
                && self
                    .last_report_us
                    .is_some_and(|t| now_us.saturating_sub(t) >= interval)
        });
        if !(self.fresh || self.latch.any_pending() || between_cycles) {
            return None;
        }
        self.fresh = false;
        self.last_report_us = Some(now_us);
        if self.fixed
            && let Some(p) = self
                .smoothed
                .and_then(|p| Position::from_mm(self.presented(p).to_array()))
        {
            self.position = p;
        }
        let [sw1, sw2, sw3] = self.latch.take(self.debouncer.state());
        let report = PenReport {
            sw1,
            sw2,
            sw3,
            in_range: self.in_range(now_us, sw1),
            display_frame: self.settings.config.report_display_frame,
            position: self.position,
            seq: self.seq,
            timestamp_us: self.timestamp_us,
            quality: self.quality,
        };
        self.seq = self.seq.wrapping_add(1);
        self.counters.reports += 1;
        Some(report)
    }

    /// In range at `now_us` with the tip at `tip`: a fix within [`IN_RANGE_HOLD_US`], or the tip
    /// pressed (the pen is on the display, where it was last seen). Never before the first fix:
    /// there is no position to hold.
    fn in_range(&self, now_us: u64, tip: bool) -> bool {
        self.last_fix_us
            .is_some_and(|t| tip || now_us.saturating_sub(t) <= IN_RANGE_HOLD_US)
    }

    /// The OS pen's extent (0.1 mm) the USB descriptor is to be built with: the display size of
    /// the configuration the engine started with; `None` before a calibration gave one.
    pub fn os_extent(&self) -> Option<[u16; 2]> {
        self.os_extent
    }

    /// The operating system's pen report that goes with `pen` (just polled): the pen's point on
    /// the display — X = u from the left edge, Y = height − v down from the top edge, 0.1 mm —
    /// in range while `pen` is and
    /// the point lies over the display (within [`OS_EDGE_MARGIN_MM`], clamped to the edge). Out
    /// of range without a display size, or when the running display size differs from the one
    /// the descriptor was built with (until the restart that follows saving it).
    pub fn os_report(&self, pen: &PenReport) -> OsPenReport {
        let out = OsPenReport {
            barrel: pen.sw2,
            secondary_barrel: pen.sw3,
            ..OsPenReport::default()
        };
        let (Some(extent), Some(display), Some(p)) = (self.os_extent, &self.settings.display, self.smoothed) else {
            return out;
        };
        if !pen.in_range || display_extent(&self.settings.config) != Some(extent) {
            return out;
        }
        let on = if pen.sw1 { display.onto_surface(p) } else { p };
        let q = display.to_display(on);
        let margin = OS_EDGE_MARGIN_MM * 10.0;
        let axis = |mm: f32, max: u16| {
            let t = mm * 10.0;
            (t >= -margin && t <= max as f32 + margin).then(|| t.clamp(0.0, max as f32) as u16)
        };
        // The display frame's v runs up from the bottom edge; the OS's Y runs down from the top.
        let down_mm = extent[1] as f32 / 10.0 - q.y;
        match (axis(q.x, extent[0]), axis(down_mm, extent[1])) {
            (Some(x), Some(y)) => OsPenReport {
                tip: pen.sw1,
                in_range: true,
                x,
                y,
                ..out
            },
            _ => out,
        }
    }

    /// The time-of-flight report of the latest cycle, when the configuration streams them.
    pub fn tof_report(&self) -> Option<TofReport> {
        self.settings.config.stream_tof.then_some(self.tof)
    }

    /// Answers a feature-report read (HID GET_REPORT); returns the bytes written to `out`.
    pub fn get_feature(&self, id: u8, out: &mut [u8]) -> Option<usize> {
        match ReportId::from_u8(id)? {
            ReportId::DeviceInfo => self.device_info().encode(out).ok(),
            ReportId::Config => self.settings.config.encode(out).ok(),
            ReportId::Status => self.status.encode(out).ok(),
            ReportId::ResetRecord => self.last_reset.encode(out).ok(),
            _ => None,
        }
    }

    /// Sets what the reset record (0x09) answers: the panic or fault that ended the previous
    /// run, as the board found it in RAM at start-up.
    pub fn set_last_reset(&mut self, record: ResetRecord) {
        self.last_reset = record;
    }

    /// The status of the last request.
    pub fn status(&self) -> Status {
        self.status
    }

    /// Applies a feature-report write (HID SET_REPORT, or a report sent over the serial link).
    /// The outcome is also what the status report says next.
    pub fn set_feature(&mut self, bytes: &[u8], store: &mut impl ConfigStore) -> (Status, Option<Action>) {
        let request = bytes.first().copied().unwrap_or(0);
        let (status, action) = match Message::decode(bytes) {
            Ok(Message::Config(config)) => (self.apply_config(config), None),
            Ok(Message::Command(command)) => self.command(command, store),
            Ok(Message::DeviceInfo(_) | Message::Status(_) | Message::ResetRecord(_)) => {
                (Status::failed(request, StatusCode::ReadOnly), None)
            }
            Ok(_) => (Status::failed(request, StatusCode::UnknownReport), None),
            Err(pen_protocol::DecodeError::UnknownReportId(_)) => {
                (Status::failed(request, StatusCode::UnknownReport), None)
            }
            Err(_) => (Status::failed(request, StatusCode::Malformed), None),
        };
        self.status = status;
        (status, action)
    }

    fn apply_config(&mut self, config: Config) -> Status {
        let request = ReportId::Config as u8;
        match Settings::new(config) {
            Ok(settings) => {
                // A held position belongs to the old geometry or frame: out of range until the
                // next fix.
                self.last_fix_us = None;
                self.fixed = false;
                if let Some(head) = self.head.as_mut() {
                    // The head's history belongs to the old geometry too; its count goes on.
                    let seq = head.seq;
                    *head = HeadState::new(head.settings);
                    head.seq = seq;
                }
                let filter_changed = settings.config.filter != self.settings.config.filter;
                self.settings = settings;
                if filter_changed {
                    self.smoother = smoother_for(config.filter);
                } else {
                    // New geometry or frame: old history would drag fixes from the old frame.
                    self.smoother.reset();
                }
                Status::ok(request)
            }
            Err(e) => Status::from_config_error(request, e),
        }
    }

    fn command(&mut self, command: Command, store: &mut impl ConfigStore) -> (Status, Option<Action>) {
        let request = ReportId::Command as u8;
        match command {
            // The head mode is saved with the configuration, so a power cycle keeps it.
            Command::SaveConfig => match store.save(&Saved {
                config: self.settings.config,
                head: self.head.is_some(),
            }) {
                // A new display size takes a new USB descriptor: restart to enumerate again.
                Ok(()) if display_extent(&self.settings.config) != self.os_extent => {
                    (Status::ok(request), Some(Action::Restart))
                }
                Ok(()) => (Status::ok(request), None),
                Err(_) => (Status::failed(request, StatusCode::StorageFailed), None),
            },
            Command::LoadDefaults => {
                let status = self.apply_config(default_config());
                (Status { request, ..status }, None)
            }
            Command::EnterBootloader => (Status::ok(request), Some(Action::EnterBootloader)),
            Command::HeadOn if !self.head_fitted => (Status::failed(request, StatusCode::Unsupported), None),
            Command::HeadOn => {
                if self.head.is_none() {
                    self.set_head(Some(HeadSettings::default()));
                }
                (Status::ok(request), None)
            }
            Command::HeadOff => {
                self.set_head(None);
                (Status::ok(request), None)
            }
        }
    }

    /// Answers a request that arrived over the serial link: a get-feature request gets the
    /// feature report, a configuration or command gets the status report. Returns the length of
    /// the answer written to `out` (a report, to be framed) and any action to take.
    pub fn handle_request(
        &mut self,
        payload: &[u8],
        out: &mut [u8],
        store: &mut impl ConfigStore,
    ) -> (Option<usize>, Option<Action>) {
        if let Ok(get) = GetFeature::decode(payload) {
            return (self.get_feature(get.report as u8, out), None);
        }
        let (status, action) = if payload.first() == Some(&(ReportId::GetFeature as u8)) {
            // A get-feature request for something that is not a readable feature report.
            let status = Status::failed(ReportId::GetFeature as u8, StatusCode::UnknownReport);
            self.status = status;
            (status, None)
        } else {
            self.set_feature(payload, store)
        };
        (status.encode(out).ok(), action)
    }
}
