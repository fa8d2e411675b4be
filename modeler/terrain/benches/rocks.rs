//! Rock field figures (issue 11, seed 001): the seed's fig. 1 recipe (r = 9, 3, 1 taking 20 %,
//! 24 % and 56 % of the area) on a 512 × 512 field, whole and stage by stage; single diagrams
//! r = 9, 3, 1 at A_s 0.5 as in the seed's table 1; and the Poisson-disk stage alone, the
//! maximal sampler beside the seed's darts (eq. 1, c_d 0.7).
//!
//! The seed took 5.57 s for fig. 1 and 0.21 / 1.88 / 4.53 s for the single diagrams on a Core 2
//! Duo 2.66 GHz. The peer (scipy's `qmc.PoissonDisk`) is timed by `scripts/rocks_peer.py`,
//! which runs this machine's `penmodel rocks` on the same radius and area in the same run.
//!
//! `reseat/fig1/512`: fig. 1's rocks stood again on a changed 512² terrain (the edit target:
//! one frame, ≤ 5 ms); `reseat-local/fig1/512`: the same for a change within 64 × 64 cells;
//! `reseat-move/fig1/512`: the same after each move of the field.
//!
//! Run: `cargo bench -p penmodel-terrain --bench rocks` (filter with e.g. `-- fig1`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use penmodel_terrain::Heightmap;
use penmodel_terrain::rocks::place::{self, Placement};
use penmodel_terrain::rocks::{self, Amount, Layer, Recipe, Sampler, Shape, poisson, scatter};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const SIDE: u32 = 512;

fn single(radius: f64) -> Recipe {
    Recipe {
        width: SIDE,
        height: SIDE,
        layers: vec![Layer {
            radius,
            amount: Amount::Fraction(0.5),
            shape: Shape::DEFAULT,
        }],
        seed: 1,
        sampler: Sampler::Saturate,
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("rocks");
    g.sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    let fig1 = Recipe::figure_1(SIDE, SIDE, 1);
    let once = scatter(&fig1, None).expect("fig. 1 is a valid recipe");
    // Stages of cold runs (each a fresh scatter): the fastest of each stage and the median total
    // (the machine is shared, so single runs vary). `ROCKS_COLD_RUNS=0` skips them (to count
    // one scatter's instructions under callgrind).
    let cold: usize = std::env::var("ROCKS_COLD_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(15);
    let runs: Vec<rocks::Timing> = (0..cold)
        .map(|_| scatter(&fig1, None).expect("fig. 1 is a valid recipe").timing)
        .collect();
    let least = |f: fn(&rocks::Timing) -> f64| runs.iter().map(f).fold(f64::INFINITY, f64::min);
    let mut totals: Vec<f64> = runs.iter().map(|t| t.total).collect();
    totals.sort_by(f64::total_cmp);
    let median = totals.get(totals.len() / 2).copied().unwrap_or(f64::NAN);
    eprintln!(
        "fig1/512: {} rocks, digest {:016x}; fastest of {} runs per stage (ms): seeds+diagrams {:.2} (seeds {:.2}, labels {:.2} CPU), selection {:.2}, polygons {:.2}, meshes {:.2}, total {:.2} (median {:.2})",
        once.rocks.len(),
        digest(&once),
        runs.len(),
        least(|t| t.seeds_and_diagrams),
        least(|t| t.seeds),
        least(|t| t.diagrams),
        least(|t| t.selection),
        least(|t| t.polygons),
        least(|t| t.meshes),
        least(|t| t.total),
        median,
    );
    // One thread's CPU time per scatter (see `thread_cpu_ns`): the fastest of five (none with
    // `ROCKS_COLD_RUNS=0`).
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool of one thread");
    let cpu = one.install(|| {
        (0..cold.min(5))
            .filter_map(|_| {
                let before = thread_cpu_ns()?;
                let s = scatter(&fig1, None).expect("fig. 1 is a valid recipe");
                drop(s);
                Some((thread_cpu_ns()? - before) as f64 / 1e6)
            })
            .fold(f64::INFINITY, f64::min)
    });
    eprintln!("fig1/512: one thread, CPU time {cpu:.1} ms a scatter (the fastest of 5, the drop included)");
    g.bench_function("fig1/512", |b| b.iter(|| scatter(black_box(&fig1), None)));
    for r in [9.0, 3.0, 1.0] {
        g.bench_with_input(BenchmarkId::new("single/512", r), &single(r), |b, recipe| {
            b.iter(|| scatter(black_box(recipe), None))
        });
        g.bench_with_input(BenchmarkId::new("seeds-saturate/512", r), &r, |b, &r| {
            let mut rng = ChaCha8Rng::seed_from_u64(1);
            b.iter(|| poisson::saturate(SIDE, SIDE, r, &mut rng))
        });
        g.bench_with_input(BenchmarkId::new("seeds-darts/512", r), &r, |b, &r| {
            let mut rng = ChaCha8Rng::seed_from_u64(1);
            let throws = poisson::seed_throws(SIDE, SIDE, r, 0.7);
            b.iter(|| poisson::darts(SIDE, SIDE, r, throws, &mut rng))
        });
    }
    // Re-seating: fig. 1's rocks stood again on a changed 512² terrain (what a pull under a
    // field, or moving it, costs; nothing is scattered).
    let heights: Vec<f32> = (0..SIDE * SIDE)
        .map(|i| {
            let (x, y) = (f64::from(i % SIDE), f64::from(i / SIDE));
            (20.0 * (x / 40.0).sin() * (y / 55.0).cos()) as f32
        })
        .collect();
    let map = Heightmap::from_heights(SIDE, SIDE, 1.0, heights).expect("512² heights");
    let at = Placement {
        origin: [0.0, 0.0],
        cell_size: 1.0,
    };
    let flat = place::Flat::of(&once);
    let ground = place::ground(&map);
    let mut seated = flat.seat(at, ground.surface());
    let mut samples = place::Samples::default();
    let t = std::time::Instant::now();
    flat.seat_on(at, &map, &mut samples, &mut seated);
    eprintln!(
        "reseat/fig1/512: {} vertices, {} triangles, once {:.2} ms",
        flat.vertices.len(),
        flat.indices.len() / 3,
        t.elapsed().as_secs_f64() * 1e3
    );
    // Moving the field: every re-seat at another place (a third of a cell apart, so every vertex
    // falls elsewhere in its heightmap square), finding every vertex's square again.
    let moves = [
        at,
        Placement {
            origin: [1.0 / 3.0, 2.0 / 3.0],
            ..at
        },
    ];
    // The seated meshes' bits (positions and normals) on each path of `seat_on`: a move, the
    // samples found, and a terrain change read through them — equal digests before and after a
    // change of the code mean the same meshes.
    {
        let mut m = penmodel_terrain::export::Mesh::default();
        let mut s = place::Samples::default();
        let mut digests = Vec::new();
        for place in [moves[1], at, at, at] {
            flat.seat_on(place, &map, &mut s, &mut m);
            digests.push(format!("{:016x}", mesh_digest(&m)));
        }
        eprintln!(
            "reseat/fig1/512: mesh digests (move, at, samples found, terrain change) {}",
            digests.join(" ")
        );
    }
    // CPU time of one thread per re-seat, which other processes on a loaded machine do not
    // inflate as they do wall time (Linux: the scheduler's count for the thread). 50 re-seats
    // of each kind (one with `ROCKS_COLD_RUNS=0`, to count their instructions).
    let reseats = if cold == 0 { 1 } else { 50 };
    let mut cpu_per = |moving: bool| {
        one.install(|| {
            if !moving {
                // Two seats at the place first: the second finds the samples.
                flat.seat_on(at, &map, &mut samples, &mut seated);
                flat.seat_on(at, &map, &mut samples, &mut seated);
            }
            let before = thread_cpu_ns()?;
            for step in 0..reseats {
                let at = if moving { moves[(step + 1) % 2] } else { at };
                flat.seat_on(at, &map, &mut samples, &mut seated);
            }
            Some((thread_cpu_ns()? - before) as f64 / reseats as f64 / 1e6)
        })
    };
    if let (Some(moving), Some(still)) = (cpu_per(true), cpu_per(false)) {
        eprintln!(
            "reseat/fig1/512: one thread, CPU time {still:.2} ms a re-seat after a terrain change, {moving:.2} ms after a move ({reseats} re-seats each)"
        );
    }
    // The terrain changed under the field (the same place: the heights are read again).
    flat.seat_on(at, &map, &mut samples, &mut seated);
    g.bench_function("reseat/fig1/512", |b| {
        b.iter(|| black_box(&flat).seat_on(at, &map, &mut samples, &mut seated))
    });
    // A change of the terrain within 64 × 64 cells under the field (a pull's reach): only the
    // blocks of rocks over it are stood again.
    g.bench_function("reseat-local/fig1/512", |b| {
        b.iter(|| {
            black_box(&flat).seat_on_within(at, &map, &mut samples, &mut seated, Some([224.0, 224.0, 288.0, 288.0]))
        })
    });
    let mut step = 0;
    g.bench_function("reseat-move/fig1/512", |b| {
        b.iter(|| {
            step += 1;
            black_box(&flat).seat_on(moves[step % 2], &map, &mut samples, &mut seated)
        })
    });
    // The rocks' triangulations alone: ours against delaunator on the same point sets.
    let sets: Vec<(Vec<[f64; 2]>, usize)> = once
        .rocks
        .iter()
        .map(|r| (r.polygon.iter().chain(r.mesh.added).copied().collect(), r.polygon.len()))
        .collect();
    g.bench_function("delaunay/fig1-rocks/ours", |b| {
        b.iter(|| {
            sets.iter()
                .map(|(p, k)| rocks::delaunay::triangulate(black_box(p), *k).len())
                .sum::<usize>()
        })
    });
    g.bench_function("delaunay/fig1-rocks/delaunator", |b| {
        b.iter(|| {
            sets.iter()
                .map(|(p, _)| {
                    let pts: Vec<delaunator::Point> =
                        p.iter().map(|q| delaunator::Point { x: q[0], y: q[1] }).collect();
                    delaunator::triangulate(black_box(&pts)).triangles.len()
                })
                .sum::<usize>()
        })
    });
    g.finish();
}

/// FNV-1a over every rock's diagram, cell, polygon, added points, vertices and triangles (the
/// bits of the coordinates): equal digests before and after a change of the code mean the same
/// rocks bit for bit.
fn digest(s: &rocks::Scatter) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |v: u64| {
        for b in v.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    for r in s.rocks.iter() {
        eat(r.diagram as u64);
        eat(u64::from(r.cell));
        r.polygon.iter().flatten().for_each(|c| eat(c.to_bits()));
        r.mesh.added.iter().flatten().for_each(|c| eat(c.to_bits()));
        r.mesh.vertices.iter().flatten().for_each(|c| eat(c.to_bits()));
        r.mesh.triangles.iter().flatten().for_each(|&i| eat(u64::from(i)));
    }
    h
}

/// FNV-1a over a mesh's positions and normals (their bits) and indices.
fn mesh_digest(m: &penmodel_terrain::export::Mesh) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |v: u32| {
        for b in v.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    m.positions
        .iter()
        .chain(&m.normals)
        .flatten()
        .for_each(|c| eat(c.to_bits()));
    m.indices.iter().for_each(|&i| eat(i));
    h
}

/// This thread's CPU time in nanoseconds, from `/proc/thread-self/schedstat` (None elsewhere).
fn thread_cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

criterion_group!(benches, bench);
criterion_main!(benches);
