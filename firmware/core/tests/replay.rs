//! The replay format: what the harness writes, the QEMU image reads back exactly; damage is named;
//! a replay written before the tracked head (version 2) still reads.

use pen_core::replay::{self, CycleHead, Header, ReplayError};
use pen_core::{Emitter, HeadSettings, Schedule, default_config};
use pen_protocol::{Config, MAX_RECEIVERS, Report};

fn heard() -> [Option<u32>; MAX_RECEIVERS] {
    let mut heard = [None; MAX_RECEIVERS];
    heard[0] = Some(1_234_567);
    heard[3] = Some(0);
    heard
}

fn head_settings() -> HeadSettings {
    HeadSettings {
        schedule: Schedule { pen: 5, head: 2 },
        prediction_ms: 20,
    }
}

/// Two cycles of the pen alone, or with the head a pen cycle then a head cycle.
fn recorded(head: Option<HeadSettings>) -> Vec<u8> {
    let mut out = Vec::new();
    let mut push = |b: &[u8]| out.extend_from_slice(b);
    let header = Header::new(default_config(), head);
    replay::write_header(&header, &mut push);
    replay::write_cycle(&header, Emitter::Pen, 6_500, &heard(), &[1, 0, 5], &mut push);
    let second = if head.is_some() { Emitter::Head } else { Emitter::Pen };
    replay::write_cycle(&header, second, 13_000, &[None; MAX_RECEIVERS], &[], &mut push);
    out
}

#[test]
fn cycles_read_back_as_written() {
    for head in [None, Some(head_settings())] {
        let bytes = recorded(head);
        assert_eq!(bytes.len(), replay::HEADER_LEN + 2 * replay::CYCLE_HEAD_LEN + 3);
        let mut src = bytes.as_slice();
        let header = replay::read_header(&mut src).expect("a header");
        assert_eq!(header, Header::new(default_config(), head));
        let mut samples = [0u8; 8];
        let first = replay::read_cycle(&mut src, &header, &mut samples)
            .expect("a cycle")
            .expect("not the end");
        assert_eq!(
            first,
            CycleHead {
                emitter: Emitter::Pen,
                t0_us: 6_500,
                arrival_ns: heard(),
                samples: 3
            }
        );
        assert_eq!(&samples[..3], &[1, 0, 5]);
        let second = replay::read_cycle(&mut src, &header, &mut samples)
            .expect("a cycle")
            .expect("not the end");
        assert_eq!((second.t0_us, second.samples), (13_000, 0));
        assert_eq!(second.emitter == Emitter::Head, head.is_some());
        assert_eq!(second.arrival_ns, [None; MAX_RECEIVERS]);
        assert_eq!(
            replay::read_cycle(&mut src, &header, &mut samples),
            Ok(None),
            "a clean end"
        );
    }
}

/// A version 2 replay, built here byte by byte from its layout (docs/simulator.md): magic,
/// version 2, the configuration report, then cycles of burst time, eight captures, the sample
/// count and the samples, with no head bytes and no emitter byte.
fn version_2() -> Vec<u8> {
    let mut out = b"PRPL".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    let mut c = [0u8; Config::LEN];
    default_config().encode(&mut c).expect("fits");
    out.extend_from_slice(&c);
    out.extend_from_slice(&6_500u64.to_le_bytes());
    for a in heard() {
        out.extend_from_slice(&a.unwrap_or(u32::MAX).to_le_bytes());
    }
    out.extend_from_slice(&3u16.to_le_bytes());
    out.extend_from_slice(&[1, 0, 5]);
    out
}

#[test]
fn a_version_2_replay_reads_as_the_pen_alone_and_writes_back_the_same() {
    let bytes = version_2();
    let mut src = bytes.as_slice();
    let header = replay::read_header(&mut src).expect("a header");
    assert_eq!((header.version, header.head), (2, None));
    assert_eq!(header.config, default_config());
    assert_eq!(header.encoded_len(), replay::HEADER_LEN_2);
    let mut samples = [0u8; 8];
    let cycle = replay::read_cycle(&mut src, &header, &mut samples)
        .expect("a cycle")
        .expect("not the end");
    assert_eq!(
        cycle,
        CycleHead {
            emitter: Emitter::Pen,
            t0_us: 6_500,
            arrival_ns: heard(),
            samples: 3
        }
    );
    assert_eq!(replay::read_cycle(&mut src, &header, &mut samples), Ok(None));
    let mut again = Vec::new();
    let mut push = |b: &[u8]| again.extend_from_slice(b);
    replay::write_header(&header, &mut push);
    replay::write_cycle(
        &header,
        cycle.emitter,
        cycle.t0_us,
        &cycle.arrival_ns,
        &samples[..3],
        &mut push,
    );
    assert_eq!(again, bytes);
}

#[test]
fn damaged_replays_are_named() {
    let bytes = recorded(Some(head_settings()));
    let mut samples = [0u8; 8];

    let mut wrong_magic = bytes.clone();
    wrong_magic[0] = b'X';
    assert_eq!(
        replay::read_header(&mut wrong_magic.as_slice()),
        Err(ReplayError::NotAReplay)
    );

    // Version 1 held protocol 1's shorter configuration.
    let mut version_1 = bytes.clone();
    version_1[4] = 1;
    assert_eq!(
        replay::read_header(&mut version_1.as_slice()),
        Err(ReplayError::Version(1))
    );

    let mut bad_config = bytes.clone();
    bad_config[8] = 0xEE; // the configuration report's ID
    assert_eq!(
        replay::read_header(&mut bad_config.as_slice()),
        Err(ReplayError::BadConfig)
    );

    // The head bytes: a schedule without head slots, or a prediction beyond 50 ms.
    let at = 8 + Config::LEN;
    for (k, v) in [(1, 0u8), (2, 51)] {
        let mut bad_head = bytes.clone();
        bad_head[at + k] = v;
        assert_eq!(replay::read_header(&mut bad_head.as_slice()), Err(ReplayError::BadHead));
    }

    assert_eq!(
        replay::read_header(&mut &bytes[..replay::HEADER_LEN - 1]),
        Err(ReplayError::Truncated)
    );

    // Cut inside the first cycle's samples, and right after a cycle's emitter byte.
    for len in [replay::HEADER_LEN + replay::CYCLE_HEAD_LEN + 1, replay::HEADER_LEN + 1] {
        let mut cut = &bytes[..len];
        let header = replay::read_header(&mut cut).expect("the header is whole");
        assert_eq!(
            replay::read_cycle(&mut cut, &header, &mut samples),
            Err(ReplayError::Truncated),
            "{len} bytes"
        );
    }

    // An emitter byte that is neither; a head cycle in a run of the pen alone.
    let mut bad_emitter = bytes.clone();
    bad_emitter[replay::HEADER_LEN] = 7;
    let mut src = bad_emitter.as_slice();
    let header = replay::read_header(&mut src).expect("the header is whole");
    assert_eq!(
        replay::read_cycle(&mut src, &header, &mut samples),
        Err(ReplayError::BadEmitter(7))
    );
    let mut pen_only = recorded(None);
    pen_only[replay::HEADER_LEN] = 1;
    let mut src = pen_only.as_slice();
    let header = replay::read_header(&mut src).expect("the header is whole");
    assert_eq!(
        replay::read_cycle(&mut src, &header, &mut samples),
        Err(ReplayError::BadEmitter(1))
    );

    // More samples than the reader holds.
    let mut src = bytes.as_slice();
    let header = replay::read_header(&mut src).expect("the header is whole");
    let mut two = [0u8; 2];
    assert_eq!(
        replay::read_cycle(&mut src, &header, &mut two),
        Err(ReplayError::TooManySamples(3))
    );
}
