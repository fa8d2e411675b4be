//! The raw time-of-flight diagnostics report (ID 0x02): what each receiver heard in one cycle.
//! Sent after the pen report of the same cycle while the configuration's `stream_tof` flag is set.

use crate::ReportId;
use crate::codec::{Reader, Report, Writer};
use crate::error::DecodeError;
use crate::pen::MAX_RECEIVERS;

/// The time of flight of a receiver that heard nothing this cycle.
pub const NO_ARRIVAL: u32 = u32::MAX;

/// One measurement cycle as the receivers saw it, before any solving.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TofReport {
    /// The sequence number of the pen report of the same cycle.
    pub seq: u16,
    /// Device time of the burst in microseconds (wrapping like the pen report's).
    pub timestamp_us: u32,
    /// Receivers configured (slots beyond it hold [`NO_ARRIVAL`]).
    pub receiver_count: u8,
    /// Bit i set: receiver i's range was used in the fix (clear for rejected echoes and dropouts).
    pub used_mask: u8,
    /// Time of flight per receiver in nanoseconds, transducer delay already subtracted, or
    /// [`NO_ARRIVAL`].
    pub tof_ns: [u32; MAX_RECEIVERS],
    /// The speed of sound the cycle was solved with, m/s.
    pub speed_of_sound_m_s: f32,
}

impl Report for TofReport {
    const ID: ReportId = ReportId::Tof;
    const LEN: usize = 45;

    fn write_body(&self, w: &mut Writer<'_>) {
        w.u16(self.seq);
        w.u32(self.timestamp_us);
        w.u8(self.receiver_count);
        w.u8(self.used_mask);
        for t in self.tof_ns {
            w.u32(t);
        }
        w.f32(self.speed_of_sound_m_s);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let seq = r.u16()?;
        let timestamp_us = r.u32()?;
        let receiver_count = r.u8()?;
        if receiver_count as usize > MAX_RECEIVERS {
            return Err(DecodeError::OutOfRange {
                report: ReportId::Tof,
                field: "receiver_count",
            });
        }
        // Only configured receivers can have been used.
        let configured = ((1u16 << receiver_count) - 1) as u8;
        let used_mask = r.flags(configured)?;
        let mut tof_ns = [NO_ARRIVAL; MAX_RECEIVERS];
        for (i, t) in tof_ns.iter_mut().enumerate() {
            *t = r.u32()?;
            if i >= receiver_count as usize && *t != NO_ARRIVAL {
                return Err(DecodeError::OutOfRange {
                    report: ReportId::Tof,
                    field: "tof_ns beyond receiver_count",
                });
            }
        }
        if (0..MAX_RECEIVERS).any(|i| used_mask & (1 << i) != 0 && tof_ns[i] == NO_ARRIVAL) {
            return Err(DecodeError::OutOfRange {
                report: ReportId::Tof,
                field: "used_mask (a receiver without arrival)",
            });
        }
        let speed_of_sound_m_s = r.f32("speed_of_sound_m_s")?;
        Ok(TofReport {
            seq,
            timestamp_us,
            receiver_count,
            used_mask,
            tof_ns,
            speed_of_sound_m_s,
        })
    }
}
