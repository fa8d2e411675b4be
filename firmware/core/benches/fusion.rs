//! The cost of one fix on the host: the solver alone (four receivers; five with a late echo,
//! which takes the leave-one-out path) and a whole engine cycle (ranges, solve, gate, filter,
//! report). `cargo bench -p pen-core --bench fusion`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use pen_core::solve::{Geometry, solve};
use pen_core::{Cycle, Engine, Vec3, default_config};
use pen_protocol::{FirmwareVersion, MAX_RECEIVERS};

fn ranges(receivers: &[Vec3], p: Vec3) -> [Option<f32>; MAX_RECEIVERS] {
    let mut r = [None; MAX_RECEIVERS];
    for (slot, q) in r.iter_mut().zip(receivers) {
        *slot = Some((p - *q).length());
    }
    r
}

fn bench(c: &mut Criterion) {
    let engine = Engine::new(
        None,
        FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        [0; 12],
    );
    let s = *engine.settings();
    let four = &s.receivers[..4];
    let five: Vec<Vec3> = [four, &[Vec3::new(640.0, -40.0, 300.0)]].concat();
    let p = Vec3::new(260.0, 140.0, 90.0);
    let height = |q: Vec3| q.z;

    let r4 = ranges(four, p);
    c.bench_function("solve/4 receivers", |b| {
        b.iter(|| {
            solve(
                &Geometry {
                    receivers: four,
                    front: Vec3::Z,
                },
                black_box(&r4),
                &height,
                None,
            )
        })
    });

    let mut r5 = ranges(&five, p);
    r5[2] = r5[2].map(|r| r + 60.0);
    let hint = Some(p);
    c.bench_function("solve/5 receivers, one late echo", |b| {
        b.iter(|| {
            solve(
                &Geometry {
                    receivers: &five,
                    front: Vec3::Z,
                },
                black_box(&r5),
                &height,
                hint,
            )
        })
    });

    let mut engine = Engine::new(
        Some(default_config()),
        FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        [0; 12],
    );
    let mut arrival_ns = [None; MAX_RECEIVERS];
    for (slot, r) in arrival_ns.iter_mut().zip(r4) {
        *slot = r.map(|r| (r / (s.speed_m_s * 1e-6)) as u32);
    }
    let mut t0 = 0;
    c.bench_function("engine/cycle and report", |b| {
        b.iter(|| {
            t0 += 6_500;
            let result = engine.on_cycle(&Cycle {
                t0_us: t0,
                arrival_ns: black_box(arrival_ns),
            });
            (result, engine.poll_report(t0 + 5_000))
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
