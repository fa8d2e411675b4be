//! The host's cost per report: decode the bytes, make the sample, calibrate it, derive its
//! events, encode them as JSON and publish them to 32 connected clients.
//! `cargo bench -p pen-host --bench host`.

use std::io::Read;
use std::os::unix::net::UnixStream;
use std::sync::Arc;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DQuat, DVec3};
use pen_host::calibration::{Calibration, DisplaySize, FitKind, Transform};
use pen_host::daemon::Hub;
use pen_host::events::EventDetector;
use pen_host::sample::Sampler;
use pen_protocol::{Message, PenReport, Position, Quality};

fn bench(c: &mut Criterion) {
    let calibration = Calibration {
        transform: Transform {
            rotation: DQuat::from_rotation_z(0.02),
            translation_mm: DVec3::new(10.0, -5.0, 2.0),
            scale: 1.0003,
        },
        kind: FitKind::Similarity,
        display: DisplaySize::REFERENCE,
        residuals: Vec::new(),
        device: None,
        tip_offset_mm: None,
    };
    let report = |seq: u16| PenReport {
        sw1: seq % 64 < 32,
        sw2: false,
        sw3: false,
        in_range: true,
        display_frame: false,
        position: Position {
            x: 3000 + (seq % 100) as i16,
            y: 1700,
            z: 400,
        },
        seq,
        timestamp_us: seq as u32 * 6500,
        quality: Quality {
            receivers_used: 4,
            residual: 5,
            dop: 18,
        },
    };
    let frames: Vec<[u8; 17]> = (0..256).map(|s| report(s).to_bytes()).collect();

    let mut sampler = Sampler::new();
    let mut detector = EventDetector::new();
    let mut events = Vec::new();
    let mut i = 0usize;
    c.bench_function("report → events (decode, sample, calibrate, detect)", |b| {
        b.iter(|| {
            i += 1;
            let Ok(Message::Pen(r)) = Message::decode(&frames[i % frames.len()]) else {
                unreachable!()
            };
            let (s, _) = sampler.sample(&r, 1_000_000 + i as u64);
            events.clear();
            detector.on_sample(&s, calibration.to_display(s.position_mm), &mut events);
            events.len()
        })
    });

    let motion = {
        let Ok(Message::Pen(r)) = Message::decode(&frames[1]) else {
            unreachable!()
        };
        let (s, _) = Sampler::new().sample(&r, 5);
        let mut out = Vec::new();
        EventDetector::new().on_sample(&s, calibration.to_display(s.position_mm), &mut out);
        out.pop().expect("a motion event")
    };
    c.bench_function("event → JSON line", |b| b.iter(|| pen_host::wire::line(&motion)));

    // 32 clients connected through socket pairs, each drained by a thread: at this rate the
    // writers cannot keep up, so this is the saturated throughput, not the per-report cost.
    let hub = Arc::new(Hub::default());
    for _ in 0..32 {
        let (ours, mut theirs) = UnixStream::pair().expect("socket pair");
        std::thread::spawn(move || {
            let mut buf = [0u8; 65536];
            while matches!(theirs.read(&mut buf), Ok(n) if n > 0) {}
        });
        hub_add(&hub, ours);
    }
    let mut k = 0usize;
    c.bench_function("report → events → JSON → 32 clients", |b| {
        b.iter(|| {
            k += 1;
            let Ok(Message::Pen(r)) = Message::decode(&frames[k % frames.len()]) else {
                unreachable!()
            };
            let (s, _) = sampler.sample(&r, 2_000_000 + k as u64);
            events.clear();
            detector.on_sample(&s, calibration.to_display(s.position_mm), &mut events);
            for e in &events {
                hub.publish(e);
            }
        })
    });
}

fn hub_add(hub: &Hub, stream: UnixStream) {
    hub.connect(stream, pen_host::daemon::DEFAULT_QUEUE);
}

criterion_group!(benches, bench);
criterion_main!(benches);
