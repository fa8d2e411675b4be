//! The tracked head end to end: the simulated base station's head reports (the exact device
//! bytes) through pend's real socket as `head` events, in the display frame; a head behind the
//! display refused with the reason and a count, the last pose kept; a report without a fix
//! keeping the last pose and saying so; `head` lines only to clients that ask (events version 4).

use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::process::Command;
use std::time::Instant;

use crate::common::{GUARD, start_pend};

use glam::{DQuat, DVec3};
use pen_host::calibration::{Calibration, DisplaySize};
use pen_host::client::{Client, Line, parse_line};
use pen_host::events::{DisplayPoint, EventKind};
use pen_host::head::{HeadPose, HeadSampler, HeadStatus, HeadTracker};
use pen_host::wire::EVENTS_VERSION;
use pen_protocol::{HeadReport, Message, Position, Quality};

/// What a client writes to ask for `head` lines, as docs/events.md shows it.
const ASK_FOR_HEAD: &[u8] = b"{\"type\": \"subscribe\", \"lines\": [\"head\"]}\n";

/// The first `n` head events a client of pend that asked for them reads, with their report's
/// device time, and the greeting's events version.
fn head_events(calibration: Calibration, n: usize) -> (u32, Vec<(u64, HeadPose)>) {
    let dir = tempfile::tempdir().expect("tempdir");
    let (socket, file) = (dir.path().join("pend.sock"), dir.path().join("calibration.toml"));
    calibration.save(&file).expect("calibration saved");
    let calibration = file.to_str().expect("a UTF-8 temporary path");
    let _pend = start_pend(
        &socket,
        &["--source", "sim:viewer", "--speed", "0", "--calibration", calibration],
    );
    let stream = UnixStream::connect(&socket).expect("connects");
    stream.set_read_timeout(Some(GUARD)).expect("timeout");
    (&stream).write_all(ASK_FOR_HEAD).expect("asks");
    let mut reader = BufReader::new(stream);
    let mut line = String::new();
    reader.read_line(&mut line).expect("greeting");
    let greeting: serde_json::Value = serde_json::from_str(&line).expect("JSON");
    let version = greeting["events"].as_u64().expect("events version") as u32;
    let mut out = Vec::new();
    let end = Instant::now() + GUARD;
    while out.len() < n && Instant::now() < end {
        line.clear();
        assert!(reader.read_line(&mut line).expect("reads") > 0, "pend closed");
        if let Line::Event(e) = parse_line(line.trim_end()).expect("a good line")
            && let EventKind::Head(h) = e.kind
        {
            assert_eq!(e.point, None, "a head event is not the pen's");
            let (_, device_us) = e.seq.expect("a head event comes from a report");
            out.push((device_us, h));
        }
    }
    (version, out)
}

#[test]
fn pend_publishes_the_head_in_the_display_frame() {
    let display = DisplaySize::REFERENCE;
    let (version, events) = head_events(Calibration::identity(display), 300);
    assert_eq!(version, EVENTS_VERSION);
    assert_eq!(events.len(), 300);
    // At least 60 a second of device time.
    let span_s = (events[events.len() - 1].0 - events[0].0) as f64 * 1e-6;
    assert!(
        (events.len() - 1) as f64 / span_s >= 60.0,
        "{} in {span_s} s",
        events.len()
    );
    let mut last_good: Option<DisplayPoint> = None;
    let mut tracked = 0;
    for (_, h) in &events {
        match h.status {
            HeadStatus::Tracked => {
                tracked += 1;
                let p = h.at.expect("a tracked pose");
                // The seated viewer (650 mm away, leaning in up to 220 mm, the emitter 95 mm in
                // front of the head): in front of the display, over it give or take the sway.
                assert!((250.0..700.0).contains(&p.h_mm), "{p:?}");
                assert!((-100.0..display.width_mm + 100.0).contains(&p.u_mm), "{p:?}");
                assert!(h.reason.is_none());
                last_good = Some(p);
            }
            HeadStatus::Held => {
                assert_eq!(h.at, last_good, "a report without a fix keeps the last pose");
                assert!(h.reason.as_deref().is_some_and(|r| r.contains("keeping the last pose")));
            }
            HeadStatus::Refused => panic!("nothing is behind the display here: {h:?}"),
        }
        assert_eq!(h.refused, 0);
    }
    assert!(tracked >= 280, "{tracked} of 300 tracked");
}

/// The host's pipeline on the seeded `viewer` scenario (the simulated glasses), unpaced.
fn viewer_pipeline(calibration: Calibration) -> pen_host::pipeline::Pipeline {
    let scenario = pen_sim::scenarios::by_name("viewer").expect("the viewer scenario");
    let source = pen_host::source::Source::Sim(pen_host::transport::sim::SimOptions {
        scenario,
        seed: 1,
        speed: 0.0,
        plug: Default::default(),
    });
    pen_host::pipeline::Pipeline::new(source, calibration)
}

/// The head events a pipeline on the seeded `viewer` scenario makes with `calibration`, each
/// with its report's device time: the same scenario and seed give the same reports, from the
/// start, whatever the calibration.
fn pipeline_heads(calibration: Calibration, n: usize) -> Vec<(u64, HeadPose)> {
    let mut pipeline = viewer_pipeline(calibration);
    let (mut events, mut out) = (Vec::new(), Vec::new());
    let end = Instant::now() + GUARD;
    while out.len() < n && Instant::now() < end {
        pipeline.poll(std::time::Duration::from_millis(50), &mut events);
        for e in events.drain(..) {
            if let (EventKind::Head(h), Some((_, device_us))) = (e.kind, e.seq) {
                out.push((device_us, h));
            }
        }
    }
    out
}

/// The pivot's vector (`Calibration::tip_offset_mm`, the file's `[pen] tip_offset_mm`) is taken
/// out of the glasses' positions: the same device reports come out moved by exactly minus it.
#[test]
fn the_pens_vector_is_taken_out_of_the_glasses() {
    let bound = Calibration {
        device: Some(pen_host::calibration::SIMULATED_ID),
        ..Calibration::identity(DisplaySize::REFERENCE)
    };
    let offset = DVec3::new(0.5, 4.5, -6.5);
    let with_pen = Calibration {
        tip_offset_mm: Some(offset),
        ..bound.clone()
    };
    let plain = pipeline_heads(bound, 60);
    let moved = pipeline_heads(with_pen, 60);
    let mut compared = 0;
    for (t, h) in &moved {
        let (Some(m), Some((_, p))) = (h.at, plain.iter().find(|(u, _)| u == t)) else {
            continue;
        };
        let Some(p) = p.at else { continue };
        let d = DVec3::new(m.u_mm - p.u_mm, m.v_mm - p.v_mm, m.h_mm - p.h_mm);
        assert!(d.distance(-offset) < 1e-9, "moved by {d}, not by {}", -offset);
        compared += 1;
    }
    assert!(compared >= 30, "{compared} poses at the same device times");
}

/// A fitted calibration without the pivot's vector says so once, when the glasses first report;
/// one with it, or the identity (nothing fitted, nothing taken in), says nothing.
#[test]
fn a_calibration_without_the_pens_vector_says_so_once_for_the_glasses() {
    use pen_host::calibration::{SIMULATED_ID, TargetResidual};
    let fitted = Calibration {
        device: Some(SIMULATED_ID),
        residuals: vec![TargetResidual {
            target_mm: glam::DVec2::new(60.0, 34.0),
            touched_mm: DVec3::new(60.0, 34.0, 0.0),
            residual_mm: 0.0,
        }],
        ..Calibration::identity(DisplaySize::REFERENCE)
    };
    let notices = |calibration: Calibration| {
        let mut pipeline = viewer_pipeline(calibration);
        let (mut events, mut heads, mut said) = (Vec::new(), 0, Vec::new());
        let end = Instant::now() + GUARD;
        while heads < 100 && Instant::now() < end {
            pipeline.poll(std::time::Duration::from_millis(50), &mut events);
            heads += events
                .drain(..)
                .filter(|e| matches!(e.kind, EventKind::Head(_)))
                .count();
            said.extend(pipeline.take_notice());
        }
        assert!(heads >= 100, "{heads} head events");
        said
    };
    let said = notices(fitted.clone());
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(
        said[0].contains("no pen vector") && said[0].contains("penctl calibrate"),
        "{}",
        said[0]
    );
    let with_pen = Calibration {
        tip_offset_mm: Some(DVec3::new(0.0, 4.6, -6.6)),
        ..fitted
    };
    assert_eq!(notices(with_pen), Vec::<String>::new());
    let identity = Calibration {
        device: Some(SIMULATED_ID),
        ..Calibration::identity(DisplaySize::REFERENCE)
    };
    assert_eq!(notices(identity), Vec::<String>::new());
}

#[test]
fn a_head_behind_the_display_is_refused_and_counted() {
    // A calibration turned over (180° about the display's u axis): every head comes out behind
    // the surface, as a mirrored solution or a wrong calibration would put it.
    let mut flipped = Calibration::identity(DisplaySize::REFERENCE);
    flipped.transform.rotation = DQuat::from_rotation_x(std::f64::consts::PI);
    let (_, events) = head_events(flipped, 40);
    // The client joins a running pend: the count goes up by one per refusal from where it was.
    let (mut refused, mut count) = (0, None);
    for (_, h) in &events {
        if h.status == HeadStatus::Refused {
            refused += 1;
            if let Some(before) = count {
                assert_eq!(h.refused, before + 1, "the count goes up by one per refusal");
            }
            count = Some(h.refused);
            assert_eq!(h.at, None, "no good pose to keep");
            let reason = h.reason.as_deref().expect("a reason");
            assert!(
                reason.contains("behind the display") && reason.contains("refused"),
                "{reason}"
            );
        }
    }
    assert!(refused >= 30, "{refused} of 40 refused");
}

#[test]
fn head_lines_go_only_to_clients_that_ask() {
    let dir = tempfile::tempdir().expect("tempdir");
    let socket = dir.path().join("pend.sock");
    let _pend = start_pend(&socket, &["--source", "sim:viewer", "--speed", "1"]);
    // A client built for version 2 only reads; it joins first, so every head line the others
    // read was offered to it too.
    let quiet = UnixStream::connect(&socket).expect("connects");
    let asking = UnixStream::connect(&socket).expect("connects");
    (&asking).write_all(ASK_FOR_HEAD).expect("asks");
    asking.set_read_timeout(Some(GUARD)).expect("timeout");
    // The library's client asks by itself.
    let mut library = Client::connect(&socket).expect("connects");
    let mut asking = BufReader::new(asking);
    let (mut line, mut heads) = (String::new(), 0);
    let end = Instant::now() + GUARD;
    while heads < 30 && Instant::now() < end {
        line.clear();
        assert!(asking.read_line(&mut line).expect("reads") > 0, "pend closed");
        let v: serde_json::Value = serde_json::from_str(&line).expect("JSON");
        heads += usize::from(v["type"] == "head");
    }
    assert_eq!(heads, 30, "the client that asked reads head lines");
    let mut library_heads = 0;
    while library_heads < 30 && Instant::now() < end {
        match library.next_line().expect("pend open").expect("a good line") {
            Line::Event(e) if matches!(e.kind, EventKind::Head(_)) => library_heads += 1,
            _ => {}
        }
    }
    assert_eq!(library_heads, 30, "pen_host's client asks for head lines");
    // What the quiet client was sent meanwhile: every line of a kind version 2 knows.
    quiet
        .set_read_timeout(Some(std::time::Duration::from_millis(500)))
        .expect("timeout");
    let version_2 = [
        "hello",
        "refused",
        "proximity_in",
        "proximity_out",
        "tip_down",
        "tip_up",
        "button_down",
        "button_up",
        "motion",
        "device_lost",
        "device_found",
        "missed",
    ];
    let mut quiet = BufReader::new(quiet);
    let mut read = 0;
    // Its lines since it joined are waiting in its socket; the pen goes on moving, so a second
    // more reads them all and then some.
    let quiet_end = Instant::now() + std::time::Duration::from_secs(1);
    while Instant::now() < quiet_end {
        line.clear();
        match quiet.read_line(&mut line) {
            Ok(n) if n > 0 => {}
            // Nothing more within the timeout (or pend closed): all it was sent is read.
            _ => break,
        }
        read += 1;
        let v: serde_json::Value = serde_json::from_str(&line).expect("JSON");
        let kind = v["type"].as_str().expect("a type");
        assert!(version_2.contains(&kind), "a client that did not ask read {line}");
        if read == 1 {
            assert_eq!(kind, "hello");
            assert_eq!(v["events"], EVENTS_VERSION);
        }
    }
    assert!(read >= 1, "the quiet client was greeted");
}

#[test]
fn head_bytes_through_the_sampler_and_tracker() {
    // The device's bytes for a good pose, then no fix, then a pose behind the display.
    let report = |no_fix: bool, z: i16, seq: u16| HeadReport {
        no_fix,
        display_frame: true,
        position: Position { x: 3000, y: 1700, z },
        prediction_ms: 20,
        seq,
        timestamp_us: (u32::MAX - 5).wrapping_add(seq as u32),
        quality: if no_fix {
            Quality::NONE
        } else {
            Quality {
                receivers_used: 4,
                residual: 3,
                dop: 19,
            }
        },
    };
    let calibration = Calibration::identity(DisplaySize::REFERENCE);
    let (mut sampler, mut tracker) = (HeadSampler::new(), HeadTracker::new());
    let mut run = |r: HeadReport| {
        let Ok(Message::Head(r)) = Message::decode(&r.to_bytes()) else {
            panic!("the head report decodes");
        };
        let s = sampler.sample(&r, 0);
        let e = tracker.on_sample(&s, calibration.point(s.position_mm), 0);
        match e.kind {
            EventKind::Head(h) => (s, h),
            other => panic!("{other:?}"),
        }
    };
    let (s, good) = run(report(false, 6500, 0));
    assert_eq!(good.status, HeadStatus::Tracked);
    assert_eq!(s.position_mm, DVec3::new(300.0, 170.0, 650.0));
    let (_, held) = run(report(true, 6500, 1));
    assert_eq!((held.status, held.at), (HeadStatus::Held, good.at));
    let (s, behind) = run(report(false, -420, 10));
    assert_eq!(
        (behind.status, behind.at, behind.refused),
        (HeadStatus::Refused, good.at, 1)
    );
    assert!(
        behind.reason.as_deref().is_some_and(|r| r.contains("42.0 mm behind")),
        "{behind:?}"
    );
    // The device clock wrapped between the first and the last report: unwrapped, it went on.
    assert_eq!(s.device_us, (u32::MAX as u64 - 5) + 10);
}

#[test]
fn penctl_head_on_needs_the_glasses() {
    let penctl = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_penctl"))
            .args(args)
            .output()
            .expect("penctl runs")
    };
    // The hand sweep's base station has no glasses' emitter: refused, with the device's word.
    let out = penctl(&["head", "on", "--source", "sim:hand-sweep"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("not supported"), "{err}");
    // The viewer's has them.
    for state in ["on", "off"] {
        let out = penctl(&["head", state, "--source", "sim:viewer"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    let out = penctl(&["head", "sideways", "--source", "sim:viewer"]);
    assert_eq!(out.status.code(), Some(2), "a usage error");
}
