//! Ridgeline terrain figures (issue 12, seed 002):
//!
//! - `move_segment/512`, `add_delete_segment/512`: one segment moved (a pen drag), or added and
//!   deleted again, on a 512² grid holding 60 other segments — the terrain update alone, target
//!   ≤ 2 ms per update.
//! - `full_dtm/200seg/1024`: the DTM of 200 segments on 1024², target ≤ 50 ms on 2 cores.
//! - `sky32/1024`, `direct/1024`, `insolation32/1024`: horizons in 32 azimuths (sky view), one
//!   sun direction (direct), both combined; target ≤ 100 ms for 32 directions. Beside it, printed
//!   before the runs: the brute-force ray march (`sun::ray_march`) over a sample of cells in the
//!   same 32 azimuths, its time per cell scaled to the whole grid, the ratio, and the largest and
//!   mean difference in horizon angle over the sample.
//! - `rain/1024`: rain pass counts on the 1024² DTM (the valley map's peer, a D8 flow
//!   accumulation, is timed by `scripts/ridge_peer.py` in the same run as `penmodel analyze`).
//!
//! Printed before the runs as well: each figure's CPU time per call over all threads and on the
//! busiest thread alone — the work a call shares among the cores ends no sooner than its
//! busiest thread, so on idle cores that is about the wall time, and other processes on the
//! machine stretch it much less than the wall time.
//!
//! Run: `cargo bench -p penmodel-terrain --bench ridge` (filter with e.g. `-- sky32`).
//! `RIDGE_SKY_CALLS=N` runs only N `sky_view(.., 32)` calls on the 1024² DTM and exits, no
//! criterion: a short run for `valgrind --tool=callgrind` (instruction counts do not depend on
//! the machine's load); `RIDGE_DIRECT_CALLS=N` the same for N `direct` calls (the bench's sun).

use std::f64::consts::TAU;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group};
use penmodel_terrain::ridge::polygon::{self, Polygon};
use penmodel_terrain::ridge::sun::{self, Field, Sun};
use penmodel_terrain::ridge::{Dtm, Filter, Skeleton, rain};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `lines` random-walk ridgelines of `segs` segments each over a `side`² grid of 1 m cells,
/// elevations between `lo` and `hi` metres.
fn scene(side: u32, lines: usize, segs: usize, lo: f64, hi: f64, seed: u64) -> Vec<Skeleton> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let s = f64::from(side);
    (0..lines)
        .map(|_| {
            let mut p = [rng.random_range(0.1 * s..0.9 * s), rng.random_range(0.1 * s..0.9 * s)];
            let mut heading: f64 = rng.random_range(0.0..TAU);
            let pts: Vec<[f64; 3]> = (0..=segs)
                .map(|_| {
                    let q = [p[0], p[1], rng.random_range(lo..hi)];
                    heading += rng.random_range(-0.6..0.6);
                    let step = rng.random_range(0.02 * s..0.04 * s);
                    p = [
                        (p[0] + step * heading.cos()).clamp(0.0, s),
                        (p[1] + step * heading.sin()).clamp(0.0, s),
                    ];
                    q
                })
                .collect();
            Skeleton::polyline(&pts, 30f64.to_radians())
        })
        .collect()
}

fn ids(s: &[Skeleton]) -> Vec<(u32, &Skeleton)> {
    s.iter().enumerate().map(|(i, s)| (i as u32, s)).collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("ridge");
    g.sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));

    // A pen drag on 512²: 12 lines of 5 segments, one more 1-segment line moved back and forth.
    let small = scene(512, 12, 5, 20.0, 60.0, 1);
    let mut dtm = Dtm::build(512, 512, 1.0, Filter::DEFAULT, &ids(&small));
    let seg = |dx: f64| {
        Skeleton::polyline(
            &[[200.0 + dx, 250.0, 45.0], [230.0 + dx, 262.0, 50.0]],
            30f64.to_radians(),
        )
    };
    let (a, b) = (seg(0.0), seg(3.0));
    let extra = small.len() as u32;
    dtm.set(extra, Some(&a));
    let mut flip = false;
    g.bench_function("move_segment/512", |bch| {
        bch.iter(|| {
            flip = !flip;
            black_box(dtm.set(extra, Some(if flip { &b } else { &a })))
        })
    });
    g.bench_function("add_delete_segment/512", |bch| {
        bch.iter(|| {
            dtm.set(extra + 1, Some(&a));
            black_box(dtm.set(extra + 1, None))
        })
    });

    let big = big_scene();
    let full = Dtm::build(1024, 1024, 1.0, Filter::DEFAULT, &ids(&big));
    eprintln!("full_dtm/200seg/1024: {} polygons", full.polygon_count());
    g.bench_function("full_dtm/200seg/1024", |bch| {
        bch.iter(|| Dtm::build(1024, 1024, 1.0, Filter::DEFAULT, black_box(&ids(&big))))
    });

    // Alg. 2.2 on the drag scene: the same one-segment move.
    {
        let mut lists = Lists::new(512, 512);
        let mut id = 0u32;
        for sk in &small {
            for (_, poly) in polygon::polygons(sk) {
                lists.insert(id, &poly);
                id += 1;
            }
        }
        let pa: Vec<Polygon> = polygon::polygons(&a).into_iter().map(|(_, p)| p).collect();
        let pb: Vec<Polygon> = polygon::polygons(&b).into_iter().map(|(_, p)| p).collect();
        for (k, p) in pa.iter().enumerate() {
            lists.insert(id + k as u32, p);
        }
        let mut flip = false;
        let per_move = cpu_per_call(400, || {
            flip = !flip;
            let (from, to) = if flip { (&pa, &pb) } else { (&pb, &pa) };
            for (k, p) in from.iter().enumerate() {
                lists.remove(id + k as u32, p);
            }
            for (k, p) in to.iter().enumerate() {
                lists.insert(id + k as u32, p);
            }
        });
        // Alg. 2.3 likewise without the filter, for the same work.
        let mut d = Dtm::build(512, 512, 1.0, Filter::NONE, &ids(&small));
        d.set(extra, Some(&a));
        let mut flip = false;
        let per_move_23 = cpu_per_call(2000, || {
            flip = !flip;
            d.set(extra, Some(if flip { &b } else { &a }));
        });
        eprintln!(
            "move_segment/512 raster only, CPU ms: Alg. 2.3 (winner array) {per_move_23:.3}, Alg. 2.2 (sorted per-cell lists, one thread) {per_move:.3}; Alg. 2.2 holds {} entries ({:.1} per cell, {:.1} MB at 8 bytes), Alg. 2.3 4 bytes per cell (1.0 MB)",
            lists.entries(),
            lists.entries() as f64 / (512.0 * 512.0),
            lists.entries() as f64 * 8.0 / 1e6
        );
    }
    let z = full.heights().to_vec();
    {
        let field = Field {
            z: &z,
            cols: 1024,
            rows: 1024,
            cell: 1.0,
        };
        let sun = Sun::degrees(135.0, 25.0, "sun").expect("a sun above the horizon");
        let mut d = Dtm::build(512, 512, 1.0, Filter::DEFAULT, &ids(&small));
        let mut flip = false;
        let [mv, full, sky, direct, rain] = [
            cpu_and_busiest(2000, || {
                flip = !flip;
                d.set(small.len() as u32, Some(if flip { &b } else { &a }));
            }),
            cpu_and_busiest(20, || drop(Dtm::build(1024, 1024, 1.0, Filter::DEFAULT, &ids(&big)))),
            cpu_and_busiest(10, || drop(sun::sky_view(field, 32))),
            cpu_and_busiest(20, || drop(sun::direct(field, sun))),
            cpu_and_busiest(20, || drop(rain::counts(&z, 1024, 1024, 1.0))),
        ];
        eprintln!(
            "CPU time per call (all threads / busiest thread), ms: move_segment/512 {:.3} / {:.3}, full_dtm/200seg/1024 {:.1} / {:.1}, sky32/1024 {:.0} / {:.0}, direct/1024 {:.1} / {:.1}, rain/1024 {:.1} / {:.1}",
            mv.0, mv.1, full.0, full.1, sky.0, sky.1, direct.0, direct.1, rain.0, rain.1
        );
    }
    let field = Field {
        z: &z,
        cols: 1024,
        rows: 1024,
        cell: 1.0,
    };
    peer_ray_march(field, 32);
    sky_against_ray_march(field, 32);
    let sun = Sun::degrees(135.0, 25.0, "sun").expect("a sun above the horizon");
    g.bench_function("sky32/1024", |bch| bch.iter(|| sun::sky_view(black_box(field), 32)));
    g.bench_function("direct/1024", |bch| bch.iter(|| sun::direct(black_box(field), sun)));
    g.bench_function("insolation32/1024", |bch| {
        bch.iter(|| {
            let d = sun::direct(black_box(field), sun);
            let s = sun::sky_view(field, 32);
            sun::insolation(&d, &s)
        })
    });
    g.bench_function("rain/1024", |bch| {
        bch.iter(|| rain::counts(black_box(&z), 1024, 1024, 1.0))
    });
    g.finish();
}

/// Alg. 2.2 for comparison: per cell a list of (elevation, polygon id), highest first; a
/// polygon's removal deletes its entries from the lists of its cells, an insertion puts them in
/// order; a cell's value is its list's head. Only the raster layer (no filter), one thread.
struct Lists {
    cols: u32,
    rows: u32,
    lists: Vec<Vec<(f32, u32)>>,
}

impl Lists {
    fn new(cols: u32, rows: u32) -> Lists {
        Lists {
            cols,
            rows,
            lists: vec![Vec::new(); cols as usize * rows as usize],
        }
    }

    /// Visits the cells of `poly` with their elevation.
    fn cells(&self, poly: &Polygon, mut f: impl FnMut(usize, f32)) {
        let (prepared, outlines) = (poly.prepare(), poly.outlines());
        let rect = poly.cells(self.cols, self.rows, 1.0);
        for r in rect.r0..rect.r0 + rect.height {
            let y = f64::from(r) + 0.5;
            let Some((x0, x1)) = polygon::span(&outlines, y) else {
                continue;
            };
            let c0 = (x0 - 1.5).ceil().max(f64::from(rect.c0)) as u32;
            let c1 = ((x1 + 0.5).floor().min(f64::from(rect.c0 + rect.width) - 1.0)).max(-1.0) as i64;
            for c in c0..(c1 + 1).max(i64::from(c0)) as u32 {
                if let Some(v) = prepared.value([f64::from(c) + 0.5, y]) {
                    f(r as usize * self.cols as usize + c as usize, v as f32);
                }
            }
        }
    }

    fn insert(&mut self, id: u32, poly: &Polygon) {
        let mut hits = Vec::new();
        self.cells(poly, |i, v| hits.push((i, v)));
        for (i, v) in hits {
            let l = &mut self.lists[i];
            let at = l.partition_point(|e| e.0 >= v);
            l.insert(at, (v, id));
        }
    }

    fn remove(&mut self, id: u32, poly: &Polygon) {
        let mut hits = Vec::new();
        self.cells(poly, |i, _| hits.push(i));
        for i in hits {
            self.lists[i].retain(|e| e.1 != id);
        }
    }

    fn entries(&self) -> usize {
        self.lists.iter().map(Vec::len).sum()
    }
}

/// CPU time (user + system) this process has used, ms, from `/proc/self/stat` (Linux; 0
/// elsewhere). Other builds on the machine stretch wall times, much less the CPU time a run
/// needs; half of it is what two idle cores would take at best.
fn cpu_ms() -> f64 {
    std::fs::read_to_string("/proc/self/stat").map_or(0.0, |s| stat_ms(&s))
}

/// User + system ms of a `/proc/.../stat` line.
fn stat_ms(stat: &str) -> f64 {
    // Fields after the command's closing parenthesis; utime and stime are the 14th and 15th.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse().ok())
        .collect();
    // Clock ticks of 10 ms (USER_HZ is 100 on Linux).
    f.iter().sum::<f64>() * 10.0
}

/// Each thread's CPU ms by thread id, from `/proc/self/task/*/stat` (empty elsewhere).
fn thread_ms() -> std::collections::HashMap<String, f64> {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return Default::default();
    };
    dir.filter_map(Result::ok)
        .filter_map(|e| {
            let stat = std::fs::read_to_string(e.path().join("stat")).ok()?;
            Some((e.file_name().to_string_lossy().into_owned(), stat_ms(&stat)))
        })
        .collect()
}

/// CPU ms per call of `f`, over `n` calls.
fn cpu_per_call(n: u32, f: impl FnMut()) -> f64 {
    cpu_and_busiest(n, f).0
}

/// CPU ms per call of `f` over `n` calls, all threads and the busiest thread's. The work a
/// call shares among the cores finishes no sooner than its busiest thread: on idle cores the
/// second figure is about the wall time, and a loaded machine stretches it much less.
fn cpu_and_busiest(n: u32, mut f: impl FnMut()) -> (f64, f64) {
    let (t, before) = (cpu_ms(), thread_ms());
    for _ in 0..n {
        f();
    }
    let after = thread_ms();
    let busiest = after
        .iter()
        .map(|(id, ms)| ms - before.get(id).copied().unwrap_or(0.0))
        .fold(0.0, f64::max);
    ((cpu_ms() - t) / f64::from(n), busiest / f64::from(n))
}

/// The brute force beside the sweep, on every 16th cell of every 16th row in `k` azimuths.
fn peer_ray_march(field: Field<'_>, k: u32) {
    let t = Instant::now();
    let mut sweep = Vec::with_capacity(k as usize);
    for d in 0..k {
        let mut h = vec![0.0; field.z.len()];
        sun::horizons(field, TAU * f64::from(d) / f64::from(k), |i, t| h[i] = t);
        sweep.push(h);
    }
    let sweep_ms = t.elapsed().as_secs_f64() * 1e3;
    let (mut worst, mut sum, mut n) = (0.0f64, 0.0f64, 0usize);
    let t = Instant::now();
    let mut cells = 0usize;
    for r in (0..field.rows).step_by(16) {
        for c in (0..field.cols).step_by(16) {
            cells += 1;
            for (d, h) in sweep.iter().enumerate() {
                let a = sun::ray_march(field, TAU * d as f64 / f64::from(k), c, r);
                let b = h[(r * field.cols + c) as usize];
                if a.is_finite() && b.is_finite() {
                    let diff = (a.atan() - b.atan()).abs().to_degrees();
                    worst = worst.max(diff);
                    sum += diff;
                    n += 1;
                }
            }
        }
    }
    let brute_ms = t.elapsed().as_secs_f64() * 1e3 * field.z.len() as f64 / cells as f64;
    eprintln!(
        "horizons {k} azimuths on {}x{}: sweep {sweep_ms:.1} ms (one thread, all cells); ray march {brute_ms:.0} ms (one thread, scaled from {cells} cells); ratio {:.0}; horizon angle difference largest {worst:.2} deg, mean {:.3} deg over {n} cell-azimuths",
        field.cols,
        field.rows,
        brute_ms / sweep_ms,
        sum / n.max(1) as f64
    );
}

/// The sky view beside the one the ray march gives on every 16th cell of every 16th row:
/// `1 − (1/k)·Σ sin² max(0, H_i)` with the ray march's horizons, the mean and largest difference.
fn sky_against_ray_march(field: Field<'_>, k: u32) {
    let sky = sun::sky_view(field, k);
    let (mut worst, mut sum, mut n) = (0.0f64, 0.0f64, 0usize);
    for r in (0..field.rows).step_by(16) {
        for c in (0..field.cols).step_by(16) {
            let sin2: f64 = (0..k)
                .map(|d| {
                    let t = sun::ray_march(field, TAU * f64::from(d) / f64::from(k), c, r).max(0.0);
                    t * t / (1.0 + t * t)
                })
                .sum();
            let diff = (1.0 - sin2 / f64::from(k) - f64::from(sky[(r * field.cols + c) as usize])).abs();
            worst = worst.max(diff);
            sum += diff;
            n += 1;
        }
    }
    eprintln!(
        "sky view {k} azimuths against the ray march's: |difference| mean {:.5}, largest {worst:.4} over {n} cells",
        sum / n.max(1) as f64
    );
}

/// The bench's 200 segments on 1024²: 20 lines of 10.
fn big_scene() -> Vec<Skeleton> {
    scene(1024, 20, 10, 40.0, 150.0, 2)
}

criterion_group!(benches, bench);

fn main() {
    let calls = |name: &str| std::env::var(name).ok().and_then(|v| v.parse::<u32>().ok());
    let (sky, direct) = (calls("RIDGE_SKY_CALLS"), calls("RIDGE_DIRECT_CALLS"));
    if sky.is_some() || direct.is_some() {
        let z = Dtm::build(1024, 1024, 1.0, Filter::DEFAULT, &ids(&big_scene()))
            .heights()
            .to_vec();
        let field = Field {
            z: &z,
            cols: 1024,
            rows: 1024,
            cell: 1.0,
        };
        let (n, what) = match (sky, direct) {
            (Some(n), _) => (n, "sky_view"),
            (_, n) => (n.unwrap_or(0), "direct"),
        };
        let sun = Sun::degrees(135.0, 25.0, "sun").expect("a sun above the horizon");
        let (mut total, mut bits) = (0.0f64, 0xcbf2_9ce4_8422_2325u64);
        for _ in 0..n {
            let map = if sky.is_some() {
                sun::sky_view(black_box(field), 32)
            } else {
                sun::direct(black_box(field), sun)
            };
            total += map.iter().map(|&v| f64::from(v)).sum::<f64>();
            // The map's bits, to compare versions that should agree exactly.
            bits = map
                .iter()
                .fold(bits, |h, v| (h ^ u64::from(v.to_bits())).wrapping_mul(0x100_0000_01b3));
        }
        eprintln!(
            "{n} {what} calls, mean value {:.6}, bits {bits:016x}",
            total / (f64::from(n.max(1)) * 1024.0 * 1024.0)
        );
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
