//! Calibration against the simulated pen: the procedure recovers a known display pose.

use std::time::Duration;

use glam::{DQuat, DVec2, DVec3};
use pen_host::calibration::pivot::{fit_pivot, tip_offset};
use pen_host::calibration::procedure::{Prompt, attach, collect_pivot, collect_touches, prepare};
use pen_host::calibration::{Calibration, CalibrationError, DeviceId, DisplaySize, FitKind, SIMULATED_ID, fit};
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
    let scenario = pen_sim::scenarios::calibration(targets, None, rig);
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
    // The pen is shown as it goes: each taken touch is the mean of pressed positions just before
    // it, so the last pressed position told lies near it.
    let mut last_pressed = None;
    for s in &steps {
        match s {
            Prompt::Pen {
                position_mm, pressed, ..
            } if *pressed => last_pressed = Some(*position_mm),
            Prompt::Taken { touched_mm, .. } => {
                let p = last_pressed.take().expect("pressed positions before a taken touch");
                assert!(p.distance(*touched_mm) < 3.0, "{p} vs {touched_mm}");
            }
            _ => {}
        }
    }
    fit(targets, &touched, FitKind::Similarity, DisplaySize::REFERENCE).expect("fit")
}

/// The pivot after the touches measures the pen's emitter-to-tip vector, and with it taken out
/// a point carried by the calibration lands where it is: the fit alone puts it off by that
/// vector, as the tracked glasses' emitter was (issue 16).
#[test]
fn the_pivot_measures_the_vector_the_fit_took_in() {
    let display = DisplaySize::REFERENCE;
    let targets = display.targets(9);
    let at = display.pivot_target();
    let (rotation, translation) = misaligned();
    let rig = Rig::reference().with_display_pose(rotation, translation);
    let scenario = pen_sim::scenarios::calibration(&targets, Some(at), rig.clone());
    let mut device = Device::new(Source::Sim(SimOptions {
        scenario,
        seed: 3,
        speed: 0.0,
        plug: Default::default(),
    }));
    attach(&mut device, Duration::from_secs(2)).expect("attach");
    prepare(&mut device).expect("raw tracker frame");
    let touched = collect_touches(&mut device, &targets, Duration::from_secs(30), |_| {}).expect("touches");
    let mut prompts = Vec::new();
    let fixes = collect_pivot(&mut device, at, Duration::from_secs(30), |p| {
        if !matches!(p, Prompt::Pen { .. }) {
            prompts.push(p.clone())
        }
    })
    .expect("pivot");
    assert!(matches!(prompts.first(), Some(Prompt::Pivot { .. })), "{prompts:?}");
    assert!(matches!(prompts.last(), Some(Prompt::Pivoted { .. })), "{prompts:?}");
    let mut cal = fit(&targets, &touched, FitKind::Similarity, display).expect("fit");
    let pivot = fit_pivot(&fixes).expect("pivot fits");
    // The simulated pen's emitter is 8 mm up the pen from its tip.
    assert!((pivot.radius_mm - rig.emitter_offset_mm).abs() < 0.5, "{pivot:?}");
    // The tip is on the target: the pivot's centre in the true display frame.
    let true_tip = rig.display_to_tracker(at.extend(0.0));
    assert!(pivot.tip_mm.distance(true_tip) < 0.5, "{} vs {true_tip}", pivot.tip_mm);
    // The vector the touches' pen (leaning 35° towards the user) put into the translation:
    // from the emitter to the tip, −8 mm along the pen.
    let lean = pen_sim::hand::TILT_DEG.to_radians();
    let expected = -DVec3::new(0.0, -lean.sin(), lean.cos()) * rig.emitter_offset_mm;
    let offset = tip_offset(&cal, &pivot, at);
    println!("pivot {pivot:?}; offset {offset} against {expected}");
    assert!(offset.distance(expected) < 0.8, "{offset} vs {expected}");
    // A glasses' emitter 60 cm in front of the display: off by about 8 mm through the fit
    // alone, within a millimetre with the vector taken out.
    let glasses = DVec3::new(310.0, -250.0, 600.0);
    let tracker = rig.display_to_tracker(glasses);
    let at_display = |c: &Calibration| {
        let p = c.head_to_display(tracker, false);
        DVec3::new(p.u_mm, p.v_mm, p.h_mm)
    };
    assert!(at_display(&cal).distance(glasses) > 6.0);
    let pen_before = cal.to_display(tracker);
    cal.tip_offset_mm = Some(offset);
    assert!(
        at_display(&cal).distance(glasses) < 1.0,
        "{}",
        at_display(&cal) - glasses
    );
    // The pen's own positions are still the tip's: the vector stays in for them.
    assert_eq!(cal.to_display(tracker), pen_before);
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
    assert!(
        bad("width_mm = 600.0", "width_mm = -600.0")
            .contains("`display.width_mm` must be between 20 and 10000 mm, is -600")
    );
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
    let scenario = pen_sim::scenarios::calibration(&targets, None, rig);
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
        display: Some(cal.to_device()),
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

/// A calibration of base station A, applied to B: the pen's samples never become events.
#[test]
fn a_calibration_is_refused_for_another_base_station() {
    use pen_host::events::EventKind;
    use pen_host::pipeline::Pipeline;

    let scenario = pen_sim::scenarios::by_name("hold").expect("scenario");
    let source = |id: [u8; 12]| {
        Source::Sim(SimOptions {
            scenario: scenario.clone().with_unique_id(id),
            seed: 1,
            speed: 0.0,
            plug: Default::default(),
        })
    };
    let station_a = DeviceId(*b"station-A-id");
    let calibration = Calibration {
        device: Some(station_a),
        ..Calibration::identity(DisplaySize::REFERENCE)
    };
    let poll = |pipeline: &mut Pipeline, seconds: f64| {
        let mut events = Vec::new();
        let end = std::time::Instant::now() + Duration::from_secs_f64(seconds);
        while std::time::Instant::now() < end {
            pipeline.poll(Duration::from_millis(50), &mut events);
        }
        events
    };

    // Its own base station: attached, and the pen's events flow.
    let mut own = Pipeline::new(source(station_a.0), calibration.clone());
    let events = poll(&mut own, 0.5);
    assert!(matches!(
        events.first().map(|e| &e.kind),
        Some(EventKind::DeviceFound { .. })
    ));
    assert!(events.iter().any(|e| e.point.is_some()), "samples become events");
    assert_eq!(own.refused(), None);

    // Another: refused once with what to do, retried (another may be plugged in meanwhile)
    // without repeating it, and no sample becomes an event.
    let mut other = Pipeline::new(source(*b"station-B-id"), calibration.clone());
    let events = poll(&mut other, pen_host::pipeline::REFUSED_RETRY.as_secs_f64() + 0.5);
    let reasons: Vec<&str> = events
        .iter()
        .filter_map(|e| match &e.kind {
            EventKind::DeviceLost { reason } => Some(reason.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(reasons.len(), 1, "{events:?}");
    let b = DeviceId(*b"station-B-id");
    assert!(
        reasons[0].contains(&format!(
            "refused: the calibration is for base station {}, not for the one attached, {}",
            station_a.to_hex(),
            b.to_hex()
        )) && reasons[0].contains("penctl calibrate"),
        "{}",
        reasons[0]
    );
    assert_eq!(events.len(), 1, "nothing but the refusal: {events:?}");
    assert!(other.refused().is_some());

    // A device attached before the pipeline took it is checked all the same.
    let mut device = Device::new(source(*b"station-B-id"));
    attach(&mut device, Duration::from_secs(2)).expect("attach");
    let mut taken = Pipeline::with_device(device, calibration);
    let events = poll(&mut taken, 0.5);
    assert!(
        matches!(events.as_slice(), [e] if matches!(&e.kind, EventKind::DeviceLost { reason } if reason.contains("refused"))),
        "{events:?}"
    );

    // The check itself, and a device that does not say which it is.
    let info = |id: [u8; 12]| pen_protocol::DeviceInfo {
        protocol: pen_protocol::PROTOCOL_VERSION,
        firmware: pen_sim::sim::SIM_FIRMWARE,
        receiver_count: 4,
        max_receivers: 8,
        fix_rate_hz: 150,
        unique_id: id,
    };
    let cal = Calibration {
        device: Some(station_a),
        ..Calibration::identity(DisplaySize::REFERENCE)
    };
    assert_eq!(cal.check_device(Ok(&info(station_a.0))), Ok(()));
    assert_eq!(
        cal.check_device(Ok(&info(b.0))),
        Err(CalibrationError::WrongDevice {
            calibrated: station_a,
            attached: b
        })
    );
    assert!(matches!(
        cal.check_device(Err("no answer")),
        Err(CalibrationError::DeviceUnknown { .. })
    ));
    // One recording no device goes with any.
    assert_eq!(
        Calibration::identity(DisplaySize::REFERENCE).check_device(Ok(&info(b.0))),
        Ok(())
    );
    // The simulated pen's ID is the one pen-sim reports.
    assert_eq!(SIMULATED_ID.0, pen_sim::sim::SIM_UNIQUE_ID);
}

#[test]
fn the_file_records_the_device_and_version_1_is_read_with_a_warning() {
    let targets = DisplaySize::REFERENCE.targets(5);
    let (r, t) = misaligned();
    let touched: Vec<DVec3> = targets.iter().map(|p| r.inverse() * (p.extend(0.0) - t)).collect();
    let mut cal = fit(&targets, &touched, FitKind::Rigid, DisplaySize::REFERENCE).expect("fit");
    cal.device = Some(DeviceId(*b"station-A-id"));
    cal.tip_offset_mm = Some(DVec3::new(0.25, 4.5, -6.75));
    let text = cal.to_toml();
    assert!(text.contains("version = 3\n"), "{text}");
    assert!(
        text.contains("[device]\nunique_id = \"73746174696f6e2d412d6964\""),
        "{text}"
    );
    assert!(
        text.contains("[pen]\ntip_offset_mm = [\n    0.25,\n    4.5,\n    -6.75,\n]"),
        "{text}"
    );
    let back = Calibration::from_toml(&text, "cal.toml").expect("loads");
    assert_eq!(back, cal);
    assert_eq!(back.unbound_warning(std::path::Path::new("cal.toml")), None);

    let bad = |from: &str, to: &str| {
        Calibration::from_toml(&text.replacen(from, to, 1), "cal.toml")
            .unwrap_err()
            .to_string()
    };
    assert!(bad("[device]\nunique_id = \"73746174696f6e2d412d6964\"", "").contains("`device` is missing"));
    assert!(
        bad("unique_id = \"7374", "unique_id = \"zz")
            .contains("`device.unique_id` must be the base station's 24 hex digits")
    );
    assert!(bad("version = 3", "version = 1").contains("`device` is new in version 2"));
    assert!(bad("version = 3", "version = 2").contains("`pen` is new in version 3"));
    assert!(bad("version = 3", "version = 4").contains("`version` is 4; this program reads versions 1 to 3"));
    assert!(bad("    4.5,", "    450.0,").contains("`pen.tip_offset_mm` must be three finite numbers"));
    assert!(bad("    4.5,", "    nan,").contains("`pen.tip_offset_mm` must be three finite numbers"));

    // A file of version 2, written before the pivot: read, without the pen's vector.
    let pen = text.find("[pen]").expect("a [pen] table");
    let pen_end = text[pen..].find("]\n\n").map_or(text.len(), |i| pen + i + 3);
    let v2 = format!("{}{}", &text[..pen], &text[pen_end..]).replacen("version = 3", "version = 2", 1);
    let back = Calibration::from_toml(&v2, "v2.toml").expect("version 2 still loads");
    assert_eq!(back.tip_offset_mm, None);
    assert_eq!(back.device, cal.device);
    assert_eq!(back.transform, cal.transform);

    // A file of version 1, written before calibrations recorded their device: read, for any
    // base station, with a warning that says how to bind it.
    let old = v2.replacen("version = 2", "version = 1", 1).replacen(
        "[device]\nunique_id = \"73746174696f6e2d412d6964\"\n",
        "",
        1,
    );
    let v1 = Calibration::from_toml(&old, "old.toml").expect("version 1 still loads");
    assert_eq!(v1.device, None);
    assert_eq!(v1.transform, cal.transform);
    let warning = v1.unbound_warning(std::path::Path::new("old.toml")).expect("a warning");
    assert!(
        warning.contains("old.toml records no base station") && warning.contains("run `penctl calibrate`"),
        "{warning}"
    );
}

#[test]
fn display_sizes_are_checked_on_fit_and_load() {
    let targets = DisplaySize::REFERENCE.targets(4);
    let touched: Vec<DVec3> = targets.iter().map(|t| t.extend(5.0)).collect();
    let tiny = DisplaySize {
        width_mm: 1e-300,
        ..DisplaySize::REFERENCE
    };
    let e = fit(&targets, &touched, FitKind::Rigid, tiny).unwrap_err();
    assert_eq!(
        e.to_string(),
        "`display.width_mm` must be between 20 and 10000 mm, is 1e-300"
    );
    let huge_px = DisplaySize {
        height_px: 1_000_000,
        ..DisplaySize::REFERENCE
    };
    assert!(
        fit(&targets, &touched, FitKind::Rigid, huge_px)
            .unwrap_err()
            .to_string()
            .contains("`display.height_px` must be between 16 and 65536 pixels, is 1000000")
    );
    let text = fit(&targets, &touched, FitKind::Rigid, DisplaySize::REFERENCE)
        .expect("fit")
        .to_toml();
    let load = |from: &str, to: &str| {
        Calibration::from_toml(&text.replacen(from, to, 1), "cal.toml")
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        load("width_mm = 600.0", "width_mm = 1e-300"),
        "cal.toml: `display.width_mm` must be between 20 and 10000 mm, is 1e-300"
    );
    assert!(
        load("height_mm = 340.0", "height_mm = nan")
            .contains("`display.height_mm` must be between 20 and 10000 mm, is NaN")
    );
    assert!(
        load("height_mm = 340.0", "height_mm = 2e7")
            .contains("`display.height_mm` must be between 20 and 10000 mm, is 20000000")
    );
    assert!(
        load("width_px = 2560", "width_px = 1")
            .contains("`display.width_px` must be between 16 and 65536 pixels, is 1")
    );
    assert!(load("scale = 1.0", "scale = 1e300").contains("`transform.scale` must be between 0.5 and 2, is 1e300"));
}

/// Issue 47 item 11: a calibration without fit targets (the identity, a file with none) has an
/// RMS of +0, never -0 (an empty float `sum` is -0.0 in Rust, and pend printed "RMS -0.00 mm").
#[test]
fn a_calibration_without_targets_has_an_rms_of_plus_zero() {
    let identity = Calibration::identity(DisplaySize::REFERENCE);
    let loaded = Calibration::from_toml(&identity.to_toml(), "cal.toml").expect("loads");
    for c in [identity, loaded] {
        assert!(c.residuals.is_empty());
        assert!(c.rms_mm() == 0.0 && c.rms_mm().is_sign_positive(), "{}", c.rms_mm());
        assert_eq!(format!("{:.2}", c.rms_mm()), "0.00");
    }
}
