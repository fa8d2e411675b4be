//! The replay format: what the harness writes, the QEMU image reads back exactly; damage is named.

use pen_core::default_config;
use pen_core::replay::{self, CycleHead, ReplayError};
use pen_protocol::MAX_RECEIVERS;

fn recorded() -> Vec<u8> {
    let mut out = Vec::new();
    let mut push = |b: &[u8]| out.extend_from_slice(b);
    replay::write_header(&default_config(), &mut push);
    let mut heard = [None; MAX_RECEIVERS];
    heard[0] = Some(1_234_567);
    heard[3] = Some(0);
    replay::write_cycle(6_500, &heard, &[1, 0, 5], &mut push);
    replay::write_cycle(13_000, &[None; MAX_RECEIVERS], &[], &mut push);
    out
}

#[test]
fn cycles_read_back_as_written() {
    let bytes = recorded();
    assert_eq!(bytes.len(), replay::HEADER_LEN + 2 * replay::CYCLE_HEAD_LEN + 3);
    let mut src = bytes.as_slice();
    assert_eq!(replay::read_header(&mut src), Ok(default_config()));
    let mut samples = [0u8; 8];
    let first = replay::read_cycle(&mut src, &mut samples)
        .expect("a cycle")
        .expect("not the end");
    let mut heard = [None; MAX_RECEIVERS];
    heard[0] = Some(1_234_567);
    heard[3] = Some(0);
    assert_eq!(
        first,
        CycleHead {
            t0_us: 6_500,
            arrival_ns: heard,
            samples: 3
        }
    );
    assert_eq!(&samples[..3], &[1, 0, 5]);
    let second = replay::read_cycle(&mut src, &mut samples)
        .expect("a cycle")
        .expect("not the end");
    assert_eq!((second.t0_us, second.samples), (13_000, 0));
    assert_eq!(second.arrival_ns, [None; MAX_RECEIVERS]);
    assert_eq!(replay::read_cycle(&mut src, &mut samples), Ok(None), "a clean end");
}

#[test]
fn damaged_replays_are_named() {
    let bytes = recorded();
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

    assert_eq!(
        replay::read_header(&mut &bytes[..replay::HEADER_LEN - 1]),
        Err(ReplayError::Truncated)
    );

    // Cut inside the first cycle's samples.
    let mut cut = &bytes[..replay::HEADER_LEN + replay::CYCLE_HEAD_LEN + 1];
    replay::read_header(&mut cut).expect("the header is whole");
    assert_eq!(replay::read_cycle(&mut cut, &mut samples), Err(ReplayError::Truncated));

    // More samples than the reader holds.
    let mut src = bytes.as_slice();
    replay::read_header(&mut src).expect("the header is whole");
    let mut two = [0u8; 2];
    assert_eq!(
        replay::read_cycle(&mut src, &mut two),
        Err(ReplayError::TooManySamples(3))
    );
}
