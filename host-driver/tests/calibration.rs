//! Calibration against the simulated pen: the procedure recovers a known display pose.

use std::time::Duration;

use glam::{DQuat, DVec2, DVec3};
use pen_host::calibration::procedure::{Prompt, attach, collect_touches, prepare};
use pen_host::calibration::{Calibration, CalibrationError, DisplaySize, FitKind, fit};
use pen_host::device::Device;
use pen_host::source::Source;
use pen_host::transport::sim::SimOptions;
use pen_sim::rig::Rig;

/// The simulated display: rotated 1.5° about a tilted axis and shifted from the tracker frame.
fn misaligned() -> (DQuat, DVec3) {
    (
        DQuat::from_axis_angle(DVec3::new(0.3, -0.2, 1.0).normalize(), 1.5f64.to_radians()),
        DVec3::new(12.0, -7.0, 3.0),
    )
}

fn run(targets: &[DVec2], seed: u64) -> Calibration {
    let (rotation, translation) = misaligned();
    let rig = Rig::reference().with_display_pose(rotation, translation);
    let scenario = pen_sim::scenarios::calibration(targets, rig);
    let mut device = Device::new(Source::Sim(SimOptions {
        scenario,
        seed,
        speed: 0.0,
        plug: Default::default(),
    }));
    attach(&mut device, Duration::from_secs(2)).expect("attach");
    prepare(&mut device).expect("raw tracker frame");
    let mut steps = Vec::new();
    let touched = collect_touches(&mut device, targets, Duration::from_secs(30), |s| steps.push(s.clone()))
        .expect("every target touched");
    assert_eq!(
        steps.iter().filter(|s| matches!(s, Prompt::Taken { .. })).count(),
        targets.len()
    );
    fit(targets, &touched, FitKind::Similarity, DisplaySize::REFERENCE).expect("fit")
}

#[test]
fn calibration_recovers_the_display_pose() {
    let targets = DisplaySize::REFERENCE.targets(9);
    let cal = run(&targets, 3);
    // At the targets: ≤ 0.5 mm RMS at 2 µs of timing jitter.
    assert!(cal.rms_mm() <= 0.5, "RMS {:.3} mm at the targets", cal.rms_mm());
    // The rotation is the display's.
    let (rotation, translation) = misaligned();
    let angle = cal.transform.rotation.angle_between(rotation).to_degrees();
    assert!(angle < 0.1, "rotation off by {angle:.3}°");
    assert!(
        (cal.transform.scale - 1.0).abs() < 0.002,
        "scale {}",
        cal.transform.scale
    );
    // The translation is the display's, plus the emitter's offset from the tip (8 mm along a pen
    // leaning 35° towards the user), which the fit takes in: calibrated points are the tip's.
    let lean = 35f64.to_radians();
    let emitter = DVec3::new(0.0, -lean.sin(), lean.cos()) * 8.0;
    let expected = translation - emitter;
    assert!(
        cal.transform.translation_mm.distance(expected) < 0.7,
        "{:?} vs {expected:?}",
        cal.transform.translation_mm
    );
}

#[test]
fn degenerate_touches_are_refused() {
    let display = DisplaySize::REFERENCE;
    let targets = display.targets(4);
    let touched: Vec<DVec3> = targets.iter().map(|t| t.extend(5.0)).collect();
    assert!(fit(&targets, &touched, FitKind::Rigid, display).is_ok());
    assert_eq!(
        fit(&targets[..3], &touched[..3], FitKind::Rigid, display),
        Err(CalibrationError::TooFewPoints(3))
    );
    let mut nan = touched.clone();
    nan[2].y = f64::NAN;
    assert_eq!(
        fit(&targets, &nan, FitKind::Rigid, display),
        Err(CalibrationError::NotFinite { index: 2 })
    );
    // The pen never moved: every touch at one point.
    let same = vec![DVec3::new(1.0, 2.0, 3.0); 4];
    assert!(matches!(
        fit(&targets, &same, FitKind::Rigid, display),
        Err(CalibrationError::Collinear { which: "touched", .. })
    ));
    // Targets on one line.
    let line: Vec<DVec2> = (0..4).map(|i| DVec2::new(100.0 * i as f64, 50.0)).collect();
    assert!(matches!(
        fit(&line, &touched, FitKind::Rigid, display),
        Err(CalibrationError::Collinear { which: "target", .. })
    ));
}

#[test]
fn the_file_round_trips_and_bad_values_are_named() {
    let targets = DisplaySize::REFERENCE.targets(5);
    let (r, t) = misaligned();
    let touched: Vec<DVec3> = targets.iter().map(|p| r.inverse() * (p.extend(0.0) - t)).collect();
    let cal = fit(&targets, &touched, FitKind::Rigid, DisplaySize::REFERENCE).expect("fit");
    assert!(cal.rms_mm() < 1e-9);
    let text = cal.to_toml();
    let back = Calibration::from_toml(&text, "cal.toml").expect("loads");
    assert_eq!(back.transform, cal.transform);
    assert_eq!(back.residuals.len(), 5);

    let bad = |from: &str, to: &str| {
        Calibration::from_toml(&text.replacen(from, to, 1), "cal.toml")
            .unwrap_err()
            .to_string()
    };
    assert!(bad("scale = 1.0", "scale = 7.0").contains("`transform.scale` must be between 0.5 and 2, is 7"));
    assert!(bad("width_mm = 600.0", "width_mm = -600.0").contains("`display.width_mm` must be a positive number"));
    assert!(bad("version = 1", "version = 9").contains("`version` is 9"));
    assert!(bad("rotation_wxyz = [", "rotation_wxyz = [2.0, ").contains("rotation_wxyz"));
    assert!(bad("width_px = 2560", "").contains("`display.width_px` is missing"));
    assert!(bad("[display]", "[display]\ncolour = 3").contains("colour"));
}

#[test]
fn a_calibration_written_to_the_device_makes_it_report_display_coordinates() {
    let targets = DisplaySize::REFERENCE.targets(5);
    let (rotation, translation) = misaligned();
    let rig = Rig::reference().with_display_pose(rotation, translation);
    let scenario = pen_sim::scenarios::calibration(&targets, rig);
    let timeline = scenario.timeline.clone();
    let mut device = Device::new(Source::Sim(SimOptions {
        scenario,
        seed: 5,
        speed: 0.0,
        plug: Default::default(),
    }));
    attach(&mut device, Duration::from_secs(2)).expect("attach");
    let original = prepare(&mut device).expect("raw");
    let touched = collect_touches(&mut device, &targets, Duration::from_secs(30), |_| {}).expect("touches");
    let cal = fit(&targets, &touched, FitKind::Similarity, DisplaySize::REFERENCE).expect("fit");
    let config = pen_protocol::Config {
        display: Some(cal.transform.to_device()),
        report_display_frame: true,
        ..original
    };
    let t = device.transport().expect("attached");
    assert_eq!(
        t.set_feature(&pen_protocol::Message::Config(config))
            .expect("status")
            .code,
        pen_protocol::StatusCode::Ok
    );
    // The session loops: the pen touches the first target again. The device now reports u, v on
    // the surface, h = 0 while the tip is down, with no host calibration at all.
    let mut checked = 0;
    let end = std::time::Instant::now() + Duration::from_secs(30);
    while checked < 20 && std::time::Instant::now() < end {
        let Some(pen_host::device::DeviceEvent::Sample(s, _)) = device.next(Duration::from_millis(100)) else {
            continue;
        };
        let t_s = (s.device_us as f64 * 1e-6) % timeline.duration_s();
        if s.in_range && s.sw[0] && timeline.switches(t_s)[0] {
            assert!(s.display_frame);
            let tip = timeline.tip(t_s);
            let off = DVec2::new(s.position_mm.x - tip.x, s.position_mm.y - tip.y).length();
            assert!(
                off < 1.5,
                "reported ({:.1}, {:.1}) for the tip at ({:.1}, {:.1})",
                s.position_mm.x,
                s.position_mm.y,
                tip.x,
                tip.y
            );
            assert_eq!(s.position_mm.z, 0.0);
            checked += 1;
        }
    }
    assert_eq!(checked, 20, "touches seen after the calibration was written");
}
