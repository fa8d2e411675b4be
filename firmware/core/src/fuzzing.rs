//! The properties the fuzz target (`firmware/core/fuzz/`) checks, in one place so that the
//! stable test that replays its corpus (`tests/fuzz_corpus.rs`) checks exactly the same thing.
//! Not part of the core's API: hidden, and free to change with the target.

use pen_protocol::{FirmwareVersion, MAX_RECEIVERS, Position};

use crate::replay::{self, CycleHead};
use crate::{Cycle, CycleResult, Emitter, Engine, Vec3, ranging, solve};

/// Switch samples a cycle may carry here: pen-qemu's buffer.
const MAX_SAMPLES: usize = 4096;

/// Any bytes as a replay file (`crate::replay`, either version): never a panic; the header and
/// every cycle that reads are in canonical form (written again, they are the bytes read); and the
/// cycles' capture
/// times, whatever they are, through the engine give no fix that is not a finite position, and
/// no report but from a fix, within what a report carries (±3.2767 m), and no fix outside the
/// tracker's volume: within the listening window's flight of every receiver it used (its range
/// at most that, the fix within the consistency limit's residual of its range). The same values
/// are also taken as raw capture ticks
/// (receivers 0–3 on the fast 32-bit timer, 4–7 on the slow 16-bit one, converted as the board
/// converts them, `ranging::ticks_to_ns`) through a second engine, with the same expectations:
/// any sequence of ticks, no panic, no fix that is not a position.
pub fn replay(bytes: &[u8]) {
    let mut src = bytes;
    let Ok(header) = replay::read_header(&mut src) else {
        return;
    };
    let mut written = [0u8; replay::HEADER_LEN];
    let mut n = 0;
    replay::write_header(&header, &mut |b: &[u8]| {
        written[n..n + b.len()].copy_from_slice(b);
        n += b.len();
    });
    assert_eq!(
        &written[..n],
        &bytes[..header.encoded_len()],
        "the header is not canonical"
    );
    let new_engine = || {
        let mut e = Engine::new(
            Some(header.config),
            FirmwareVersion {
                major: 0,
                minor: 1,
                patch: 0,
            },
            *b"penscape-fuz",
        );
        e.set_head_emitter_fitted(header.head.is_some());
        e.set_head(header.head);
        e
    };
    let (mut engine, mut from_ticks) = (new_engine(), new_engine());
    let mut samples = [0u8; MAX_SAMPLES];
    loop {
        let before = src;
        let head = match replay::read_cycle(&mut src, &header, &mut samples) {
            Ok(Some(head)) => head,
            Ok(None) | Err(_) => return,
        };
        let consumed = &before[..before.len() - src.len()];
        check_cycle(&header, &head, &samples[..head.samples as usize], consumed);
        for (engine, arrival_ns) in [
            (&mut engine, head.arrival_ns),
            (&mut from_ticks, as_ticks(&head.arrival_ns)),
        ] {
            let cycle = Cycle {
                t0_us: head.t0_us,
                arrival_ns,
            };
            let result = match head.emitter {
                Emitter::Pen => engine.on_cycle(&cycle),
                Emitter::Head => engine.on_head_cycle(&cycle),
            };
            check_result(&result, engine);
        }
    }
}

/// The arrivals read as capture-timer ticks, in ns as the board converts them.
fn as_ticks(values: &[Option<u32>; MAX_RECEIVERS]) -> [Option<u32>; MAX_RECEIVERS] {
    let (fast, slow) = (
        ranging::ns_per_tick(ranging::FAST_TIMER_HZ),
        ranging::ns_per_tick(ranging::SLOW_TIMER_HZ),
    );
    let mut out = [None; MAX_RECEIVERS];
    for (i, (o, v)) in out.iter_mut().zip(values).enumerate() {
        // The slow timer is 16 bits wide: its captures never exceed 65535.
        *o = v.map(|t| {
            if i < 4 {
                ranging::ticks_to_ns(t, fast)
            } else {
                ranging::ticks_to_ns(t & 0xFFFF, slow)
            }
        });
    }
    out
}

fn check_result(result: &CycleResult, engine: &Engine) {
    if let Ok(fix) = result.fix {
        assert!(finite(fix.position), "a fix at {:?}", fix.position);
        // The tracker's volume: a range is at most the window's flight (arrivals after it are
        // none), and a consistent fix is within the residuals' limit of each range; 1 mm for
        // single precision.
        let s = engine.settings();
        let reach_mm = ranging::range_mm((engine.listen_us() * 1000) as u32, s.speed_m_s);
        let slack_mm = crate::math::sqrt(solve::sse_limit(fix.used as usize)) + 1.0;
        for (i, r) in s.receivers[..s.count].iter().enumerate() {
            if fix.used_mask & (1 << i) != 0 {
                let d = (fix.position - *r).length();
                assert!(
                    d <= reach_mm + slack_mm,
                    "a fix at {:?}, {d} mm from receiver {i}, beyond the {reach_mm} mm it can hear",
                    fix.position
                );
            }
        }
    }
    if let Some(p) = result.reported_mm {
        // Reported only from an accepted fix, and only where the report can carry it: a
        // position that would saturate the report's ±3.2767 m is not a position.
        assert!(result.fix.is_ok(), "a report at {p:?} without a fix");
        let carried = Position::from_mm([p.x, p.y, p.z]);
        assert!(carried.is_some(), "a report at {p:?}, beyond what a report carries");
    }
}

fn check_cycle(header: &replay::Header, head: &CycleHead, samples: &[u8], consumed: &[u8]) {
    let mut written = [0u8; replay::CYCLE_HEAD_LEN + MAX_SAMPLES];
    let mut n = 0;
    let mut push = |b: &[u8]| {
        written[n..n + b.len()].copy_from_slice(b);
        n += b.len();
    };
    replay::write_cycle(header, head.emitter, head.t0_us, &head.arrival_ns, samples, &mut push);
    assert_eq!(&written[..n], consumed, "a cycle is not canonical: {head:?}");
}

fn finite(p: Vec3) -> bool {
    p.x.is_finite() && p.y.is_finite() && p.z.is_finite()
}
