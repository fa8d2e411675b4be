//! The solver against known geometry.

use crate::common;

use common::*;
use pen_core::Vec3;
use pen_core::solve::{Geometry, MAX_DOP, NoFix, solve, sse_limit};
use pen_core::track::Track;
use pen_protocol::MAX_RECEIVERS;
use proptest::prelude::*;

/// Height above the plane z = 0 (the reference build's display surface).
fn height(p: Vec3) -> f32 {
    p.z
}

fn geometry(receivers: &[Vec3]) -> Geometry<'_> {
    Geometry {
        receivers,
        front: Vec3::Z,
    }
}

/// √trace((JᵀJ)⁻¹) in f64, computed independently of the solver.
fn dop_f64(receivers: &[Vec3], p: Vec3) -> f64 {
    let mut m = [[0f64; 3]; 3];
    for q in receivers {
        let d = [(p.x - q.x) as f64, (p.y - q.y) as f64, (p.z - q.z) as f64];
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let u = [d[0] / n, d[1] / n, d[2] / n];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += u[i] * u[j];
            }
        }
    }
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let trace_inv = ((m[1][1] * m[2][2] - m[1][2] * m[2][1])
        + (m[0][0] * m[2][2] - m[0][2] * m[2][0])
        + (m[0][0] * m[1][1] - m[0][1] * m[1][0]))
        / det;
    trace_inv.sqrt()
}

fn workspace_points() -> Vec<Vec3> {
    let mut pts = Vec::new();
    for x in [0.0, 150.0, 300.0, 450.0, 600.0] {
        for y in [0.0, 170.0, 340.0] {
            for z in [5.0, 60.0, 200.0, 400.0] {
                pts.push(Vec3::new(x, y, z));
            }
        }
    }
    pts
}

/// The reference build with a fifth receiver at the top of a 300 mm bottom-right post.
fn five_receivers() -> Vec<Vec3> {
    [reference_receivers(), vec![Vec3::new(640.0, -40.0, 300.0)]].concat()
}

#[test]
fn exact_ranges_give_the_exact_position() {
    let configs: Vec<Vec<Vec3>> = vec![
        reference_receivers(),
        // Five: a fifth receiver raised at the middle of the bottom edge.
        five_receivers(),
        // Eight around the display, alternating heights.
        (0..8)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / 8.0;
                Vec3::new(
                    300.0 + 420.0 * a.cos(),
                    170.0 + 300.0 * a.sin(),
                    if i % 2 == 0 { 0.0 } else { 150.0 },
                )
            })
            .collect(),
        // Three receivers in the display plane: the mirror image is behind it.
        vec![
            Vec3::new(-40.0, -40.0, 0.0),
            Vec3::new(640.0, -40.0, 0.0),
            Vec3::new(300.0, 400.0, 0.0),
        ],
    ];
    for receivers in &configs {
        for p in workspace_points() {
            let fix = solve(&geometry(receivers), &exact_ranges(receivers, p), &height, None)
                .unwrap_or_else(|e| panic!("{} receivers, {p:?}: {e:?}", receivers.len()));
            assert!(
                distance(fix.position, p) < 0.01,
                "{} receivers: {:?} for {p:?}",
                receivers.len(),
                fix.position
            );
            assert_eq!(fix.used as usize, receivers.len());
            assert!(fix.residual_rms_mm < 0.01);
        }
    }
}

#[test]
fn coplanar_receivers_pick_the_point_in_front() {
    // All four on the display surface: every point has a mirror image behind it.
    let receivers = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(600.0, 0.0, 0.0),
        Vec3::new(0.0, 340.0, 0.0),
        Vec3::new(600.0, 340.0, 0.0),
    ];
    for p in [
        Vec3::new(300.0, 170.0, 250.0),
        Vec3::new(50.0, 300.0, 40.0),
        Vec3::new(550.0, 20.0, 120.0),
    ] {
        let fix = solve(&geometry(&receivers), &exact_ranges(&receivers, p), &height, None).expect("fix");
        assert!(distance(fix.position, p) < 0.05, "{:?} for {p:?}", fix.position);
    }
}

/// With range noise σ, the position error's RMS is σ·DOP (the Cramér–Rao bound of this
/// least-squares problem, to first order), and no error exceeds 5 σ·DOP.
#[test]
fn noisy_ranges_stay_within_the_geometric_bound() {
    let receivers = five_receivers();
    let sigma = 0.69; // 2 µs of timing jitter at 343 m/s
    let mut rng = common::Rng::new(7);
    for p in [
        Vec3::new(300.0, 170.0, 100.0),
        Vec3::new(50.0, 20.0, 10.0),
        Vec3::new(580.0, 320.0, 300.0),
    ] {
        let dop = dop_f64(&receivers, p);
        let (mut sum_sq, mut worst, mut dop_sum, trials) = (0.0f64, 0.0f64, 0.0f64, 2000);
        let (mut fixes, mut subsets) = (0, 0);
        for _ in 0..trials {
            let mut ranges = exact_ranges(&receivers, p);
            for r in ranges.iter_mut().flatten() {
                *r += (sigma * rng.normal()) as f32;
            }
            // The consistency test rejects noise alone in about 0.1 % of cycles (its 99.9 %
            // quantile, at a σ a little above the noise): those cycles drop a receiver or, when
            // the subsets disagree, have no fix.
            let Ok(fix) = solve(&geometry(&receivers), &ranges, &height, None) else {
                continue;
            };
            fixes += 1;
            if (fix.used as usize) < receivers.len() {
                subsets += 1;
                continue;
            }
            let e = distance(fix.position, p) as f64;
            sum_sq += e * e;
            worst = worst.max(e);
            // The solver evaluates DOP at its noisy estimate, not at the truth.
            assert!(
                (fix.dop as f64 / dop - 1.0).abs() < 0.1,
                "reported DOP {} vs {dop}",
                fix.dop
            );
            dop_sum += fix.dop as f64;
        }
        assert!(
            fixes as f64 >= 0.995 * trials as f64,
            "{p:?}: {fixes} fixes in {trials} cycles"
        );
        assert!(
            subsets as f64 <= 0.005 * trials as f64,
            "{p:?}: {subsets} false rejections"
        );
        let full = (fixes - subsets) as f64;
        assert!((dop_sum / full / dop - 1.0).abs() < 0.02, "mean reported DOP vs {dop}");
        let rmse = (sum_sq / full).sqrt();
        let bound = sigma * dop;
        assert!(
            (rmse / bound - 1.0).abs() < 0.1,
            "{p:?}: RMSE {rmse:.3} mm vs σ·DOP {bound:.3} mm"
        );
        assert!(
            worst < 5.0 * bound,
            "{p:?}: worst {worst:.3} mm vs 5σ·DOP {:.3} mm",
            5.0 * bound
        );
    }
}

#[test]
fn one_corrupted_range_among_five_is_rejected() {
    let receivers = five_receivers();
    let p = Vec3::new(260.0, 140.0, 90.0);
    // Where the previous cycle put the pen, 6.5 ms ago.
    let previous = p + Vec3::new(3.0, -2.0, 1.0);
    for bad in 0..5 {
        for extra in [15.0, 40.0, 300.0] {
            let mut ranges = exact_ranges(&receivers, p);
            // A late echo: the first arrival took a longer path.
            ranges[bad] = ranges[bad].map(|r| r + extra);
            let fix = solve(&geometry(&receivers), &ranges, &height, Some(previous)).expect("fix without the echo");
            assert_eq!(fix.used, 4);
            assert_eq!(fix.used_mask, 0b11111 & !(1 << bad), "receiver {bad} +{extra} mm");
            assert!(distance(fix.position, p) < 0.05);
            // Without a previous fix two subsets may fit; the solver then gives no fix, never
            // a wrong one.
            match solve(&geometry(&receivers), &ranges, &height, None) {
                Ok(fix) => assert!(distance(fix.position, p) < 0.05, "receiver {bad} +{extra}: {fix:?}"),
                Err(e) => assert_eq!(e, NoFix::Ambiguous),
            }
        }
    }
}

/// The four receivers other than `a` and `b` lie in one plane (within 1 mm).
fn coplanar_rest(receivers: &[Vec3], a: usize, b: usize) -> bool {
    let rest: Vec<Vec3> = (0..receivers.len())
        .filter(|&i| i != a && i != b)
        .map(|i| receivers[i])
        .collect();
    let n = (rest[1] - rest[0]).cross(rest[2] - rest[0]);
    (rest[3] - rest[0]).dot(n).abs() / n.length() < 1.0
}

#[test]
fn two_echoes_among_six_leave_four_good_ranges_and_a_fix() {
    // The reference six (pen-sim's `echoes` rig): the five and one more raised receiver.
    let receivers = [five_receivers(), vec![Vec3::new(-40.0, 380.0, 300.0)]].concat();
    let p = Vec3::new(260.0, 140.0, 90.0);
    // The previous fix, one cycle (6.5 ms) ago.
    let previous = p + Vec3::new(3.0, -2.0, 1.0);
    let (mut right, mut degenerate) = (0, 0);
    for a in 0..6 {
        for b in a + 1..6 {
            for (ea, eb) in [(30.0, 150.0), (300.0, 45.0), (80.0, 80.0)] {
                let mut ranges = exact_ranges(&receivers, p);
                ranges[a] = ranges[a].map(|r| r + ea);
                ranges[b] = ranges[b].map(|r| r + eb);
                let what = format!("receivers {a} +{ea} mm and {b} +{eb} mm");
                let got = solve(&geometry(&receivers), &ranges, &height, Some(previous));
                if coplanar_rest(&receivers, a, b) {
                    // The four good receivers stand in one plane: the pen and its
                    // mirror image fit them alike, and a wrong subset may fit some point. Such
                    // a fix must then be one the tracking gate holds back.
                    degenerate += 1;
                    if let Ok(fix) = got
                        && passes_gate(previous, fix.position)
                    {
                        assert!(distance(fix.position, p) < 0.05, "{what}: {fix:?}");
                    }
                    continue;
                }
                let fix = got.unwrap_or_else(|e| panic!("{what}: {e:?}"));
                assert_eq!(fix.used_mask, 0b111111 & !(1 << a) & !(1 << b), "{what}");
                assert!(distance(fix.position, p) < 0.05, "{what}: {fix:?}");
                right += 1;
                // Without a previous fix: the right point or none, never a wrong one.
                if let Ok(fix) = solve(&geometry(&receivers), &ranges, &height, None) {
                    assert!(distance(fix.position, p) < 0.05, "{what}: {fix:?}");
                }
            }
        }
    }
    // Two pairs leave four coplanar receivers: 0 and 3 (the rest in a vertical plane), 1 and 2
    // (the rest at z = 300 mm, parallel to the display).
    assert_eq!((right, degenerate), (13 * 3, 2 * 3));
    // Three echoes among six leave three good ranges, which cannot be checked: a subset with an
    // echo may fit some point (here 159 mm away), which the gate holds back; nothing wrong is
    // reported.
    let mut ranges = exact_ranges(&receivers, p);
    for (i, extra) in [(0, 40.0), (2, 90.0), (4, 200.0)] {
        ranges[i] = ranges[i].map(|r| r + extra);
    }
    if let Ok(fix) = solve(&geometry(&receivers), &ranges, &height, Some(previous)) {
        assert!(
            passes_gate(previous, fix.position) == (distance(fix.position, p) < 0.05),
            "{fix:?}"
        );
    }
}

/// The tracking gate, with a fix at `previous` one cycle ago, lets `p` through.
fn passes_gate(previous: Vec3, p: Vec3) -> bool {
    let mut track = Track::new();
    assert_eq!(track.gate(0, previous), Err(NoFix::Acquiring));
    assert_eq!(track.gate(6_500, previous), Ok(()));
    track.gate(13_000, p).is_ok()
}

#[test]
fn a_corrupted_range_among_four_gives_no_fix_rather_than_a_wrong_one() {
    let receivers = reference_receivers();
    let p = Vec3::new(260.0, 140.0, 90.0);
    let mut ranges = exact_ranges(&receivers, p);
    ranges[2] = ranges[2].map(|r| r + 40.0);
    match solve(&geometry(&receivers), &ranges, &height, None) {
        Err(NoFix::Inconsistent) | Err(NoFix::Behind) => {}
        other => panic!("expected no fix, got {other:?}"),
    }
    // A small error within the limit is not detectable and gives a usable fix.
    let mut ranges = exact_ranges(&receivers, p);
    ranges[2] = ranges[2].map(|r| r + 1.0);
    let fix = solve(&geometry(&receivers), &ranges, &height, None).expect("fix");
    assert!(fix.residual_rms_mm < 1.0);
}

#[test]
fn dropouts_leave_the_rest() {
    let receivers = five_receivers();
    let p = Vec3::new(100.0, 300.0, 50.0);
    let mut ranges = exact_ranges(&receivers, p);
    ranges[1] = None;
    let fix = solve(&geometry(&receivers), &ranges, &height, None).expect("fix from four");
    assert_eq!((fix.used, fix.used_mask), (4, 0b11101));
    assert!(distance(fix.position, p) < 0.01);
    ranges[3] = None;
    ranges[0] = None;
    assert_eq!(
        solve(&geometry(&receivers), &ranges, &height, None),
        Err(NoFix::TooFewRanges)
    );
}

#[test]
fn pen_in_the_plane_of_nearly_coplanar_receivers_shows_in_the_quality() {
    // Receivers raised only 5 mm out of one plane; the pen in that plane.
    let flat = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(600.0, 0.0, 5.0),
        Vec3::new(0.0, 340.0, 5.0),
        Vec3::new(600.0, 340.0, 0.0),
    ];
    let in_plane = Vec3::new(300.0, 170.0, 2.0);
    let fix = solve(&geometry(&flat), &exact_ranges(&flat, in_plane), &height, None).expect("a fix");
    // The same pen above the reference build's raised receivers.
    let good = solve(
        &geometry(&reference_receivers()),
        &exact_ranges(&reference_receivers(), in_plane),
        &height,
        None,
    )
    .expect("fix");
    assert!(good.dop < 5.0, "reference build DOP {}", good.dop);
    assert!(
        fix.dop > 25.5,
        "coplanar DOP {} should saturate the report's quality byte",
        fix.dop
    );
    assert!(fix.dop <= MAX_DOP);
    assert!(fix.position.is_finite());
}

proptest! {
    /// Whatever the ranges — garbage, zero, enormous, missing — the result is a finite fix or
    /// no fix.
    #[test]
    fn never_nan_or_infinite(ranges in proptest::collection::vec(proptest::option::of(-10.0f32..5000.0), 5)) {
        let receivers = five_receivers();
        let mut r = [None; MAX_RECEIVERS];
        r[..5].copy_from_slice(&ranges);
        if let Ok(fix) = solve(&geometry(&receivers), &r, &height, None) {
            prop_assert!(fix.position.is_finite());
            prop_assert!(fix.residual_rms_mm.is_finite() && fix.dop.is_finite());
            let sse = fix.residual_rms_mm * fix.residual_rms_mm * fix.used as f32;
            prop_assert!(sse <= sse_limit(fix.used as usize) * 1.0001);
        }
    }

    /// Random points of the workspace with exact ranges are found.
    #[test]
    fn random_points_are_found(x in -100.0f32..700.0, y in -100.0f32..450.0, z in 1.0f32..800.0) {
        let receivers = reference_receivers();
        let p = Vec3::new(x, y, z);
        let fix = solve(&geometry(&receivers), &exact_ranges(&receivers, p), &height, None);
        prop_assert!(matches!(fix, Ok(f) if distance(f.position, p) < 0.05), "{:?} for {:?}", fix, p);
    }
}
