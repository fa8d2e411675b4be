//! The named scenarios: the accuracy benchmarks, the seed's operations, and the trouble a real
//! room makes.

use glam::{DVec2, DVec3};

use crate::acoustics::{Acoustics, Air};
use crate::rig::Rig;
use crate::script::{HOVER_MM, SW1, SW2, SW3, Script};
use crate::sim::Scenario;

/// Every scenario name with a line about it.
pub const NAMES: &[(&str, &str)] = &[
    (
        "static-grid",
        "holds at 36 points spread over the workspace, SW2 clicked at each; no echoes",
    ),
    (
        "hand-sweep",
        "a hand sweeping the workspace, touching the surface and clicking; no echoes",
    ),
    (
        "echoes",
        "the hand sweep with six receivers, 5 % late echoes and 2 % dropouts",
    ),
    (
        "draw-figures",
        "draws a point, a polyline and a closed curve, each ended with SW3",
    ),
    (
        "modeling-session",
        "the seed's session: a region with two peaks, a ridge, a plateau with a peak, pulled and sloped; a mistake undone",
    ),
    (
        "hold",
        "the pen held still 40 mm above the middle of the display for 10 s",
    ),
    (
        "dead-receiver",
        "the hand sweep with receiver 2's cable cut, five receivers",
    ),
    (
        "echo-burst",
        "the hand sweep with half of all arrivals late echoes for one second",
    ),
    (
        "viewer",
        "the hand sweep with a seated viewer's tracked glasses (sway, leaning in) multiplexed 5:2",
    ),
    (
        "temperature-step",
        "the hand sweep while the air warms by 5 °C at 3 s and the device is not told",
    ),
];

/// The scenario called `name`.
pub fn by_name(name: &str) -> Option<Scenario> {
    let scenario = match name {
        "static-grid" => Scenario::new(name, Rig::reference(), Acoustics::clean(), static_grid()),
        "hand-sweep" => Scenario::new(name, Rig::reference(), Acoustics::clean(), hand_sweep()),
        "viewer" => Scenario::new(name, Rig::reference(), Acoustics::clean(), hand_sweep())
            .with_head(pen_core::HeadSettings::default()),
        "echoes" => Scenario::new(
            name,
            Rig::reference_six(),
            Acoustics::with_echoes(0.05, 0.02),
            hand_sweep(),
        ),
        "draw-figures" => Scenario::new(name, Rig::reference(), Acoustics::clean(), draw_figures()),
        "modeling-session" => Scenario::new(
            name,
            Rig::reference(),
            Acoustics::clean(),
            crate::session::timeline(&crate::session::steps(), home()),
        ),
        "hold" => {
            let mut s = Script::new(home());
            s.hold(10.0);
            Scenario::new(name, Rig::reference(), Acoustics::clean(), s.build())
        }
        "dead-receiver" => {
            let acoustics = Acoustics {
                dead_mask: 1 << 2,
                ..Acoustics::clean()
            };
            Scenario::new(name, Rig::reference_five(), acoustics, hand_sweep())
        }
        "echo-burst" => {
            let acoustics = Acoustics {
                echo_burst: Some((4.0, 5.0, 0.5)),
                ..Acoustics::clean()
            };
            Scenario::new(name, Rig::reference_five(), acoustics, hand_sweep())
        }
        "temperature-step" => {
            let acoustics = Acoustics {
                air: Air {
                    step: Some((3.0, 5.0)),
                    ..Air::room()
                },
                ..Acoustics::clean()
            };
            Scenario::new(name, Rig::reference(), acoustics, hand_sweep())
        }
        _ => return None,
    };
    Some(scenario)
}

/// A calibration session: the pen touches each target (display mm) for 0.6 s, lifting in
/// between; then, with `pivot_mm`, it touches there and tilts about its tip for
/// [`PIVOT_S`] with SW1 held (the host learns from it where the tip is from the emitter).
/// `rig` says where the display really is.
pub fn calibration(targets_mm: &[DVec2], pivot_mm: Option<DVec2>, rig: Rig) -> Scenario {
    let mut s = Script::new(home());
    for t in targets_mm {
        s.hover(*t).touch().hold(0.6).lift(HOVER_MM);
    }
    if let Some(p) = pivot_mm {
        s.hover(p).touch().pivot(PIVOT_S).lift(HOVER_MM);
    }
    s.move_to(home());
    Scenario::new("calibration", rig, Acoustics::clean(), s.build())
}

/// How long the calibration's pivot lasts, s: the top of the pen circles once.
pub const PIVOT_S: f64 = 3.0;

/// The transducer-delay procedure (`penctl delays --sim`): the hand holds the pen still with its
/// emitter at each of `points_mm` (tracker frame; the reference rig, whose display frame is the
/// tracker frame), pressing SW1 for 0.8 s at each. The device starts uncalibrated, with the
/// firmware's default delays of 0 µs, so the rig's true delays are what the procedure must find.
pub fn transducer_delays(points_mm: &[DVec3]) -> Scenario {
    let rig = Rig::reference();
    // The tip sits below the emitter along the pen's nominal lean (the hand's slow wobble moves
    // the emitter by up to 0.5 mm about it).
    let lean = crate::hand::TILT_DEG.to_radians();
    let axis = DVec3::new(0.0, -lean.sin(), lean.cos());
    let mut s = Script::new(home());
    for p in points_mm {
        let tip = *p - axis * rig.emitter_offset_mm;
        s.move_to(tip).hold(0.3).press(SW1).hold(0.8).release(SW1).hold(0.2);
    }
    s.move_to(home());
    let mut scenario = Scenario::new("transducer-delays", rig, Acoustics::clean(), s.build());
    scenario.config.transducer_delay_us = [0.0; pen_protocol::MAX_RECEIVERS];
    scenario
}

/// Where every scenario starts and ends: hovering over the middle of the display.
pub fn home() -> DVec3 {
    DVec3::new(300.0, 170.0, HOVER_MM)
}

fn static_grid() -> crate::script::Timeline {
    let mut s = Script::new(home());
    for z in [20.0, 120.0, 300.0] {
        for y in [40.0, 170.0, 300.0] {
            for x in [50.0, 217.0, 383.0, 550.0] {
                s.move_to(DVec3::new(x, y, z)).hold(0.4).click(SW2).hold(0.3);
            }
        }
    }
    s.move_to(home());
    s.build()
}

fn hand_sweep() -> crate::script::Timeline {
    let mut s = Script::new(home());
    // Sweeps across the workspace at several heights, with strokes on the surface in between.
    let sweeps = [
        DVec3::new(40.0, 40.0, 250.0),
        DVec3::new(560.0, 60.0, 180.0),
        DVec3::new(520.0, 300.0, 60.0),
        DVec3::new(80.0, 280.0, 120.0),
        DVec3::new(300.0, 170.0, 15.0),
        DVec3::new(450.0, 100.0, 350.0),
        DVec3::new(150.0, 220.0, 30.0),
    ];
    for (i, p) in sweeps.iter().enumerate() {
        s.move_to(*p);
        if i % 2 == 1 {
            s.click(SW3);
        }
        if i % 3 == 2 {
            let xy = p.truncate();
            s.hover(xy)
                .touch()
                .drag_to(xy + DVec2::new(80.0, 40.0))
                .drag_to(xy + DVec2::new(-40.0, 60.0));
            s.lift(HOVER_MM);
        }
    }
    s.move_to(home());
    s.build()
}

fn draw_figures() -> crate::script::Timeline {
    let mut s = Script::new(home());
    s.draw_point(DVec2::new(150.0, 250.0));
    s.draw_polyline(&[
        DVec2::new(200.0, 80.0),
        DVec2::new(300.0, 120.0),
        DVec2::new(420.0, 100.0),
    ]);
    s.draw_closed(&[
        DVec2::new(380.0, 200.0),
        DVec2::new(500.0, 210.0),
        DVec2::new(480.0, 300.0),
        DVec2::new(390.0, 290.0),
    ]);
    s.move_to(home());
    s.build()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scenario_builds_and_returns_home() {
        for (name, _) in NAMES {
            let s = by_name(name).unwrap_or_else(|| panic!("{name}"));
            let t = &s.timeline;
            assert!(t.duration_s() > 5.0, "{name} is {} s", t.duration_s());
            assert_eq!(t.tip(0.0), home(), "{name} starts at home");
            assert_eq!(t.tip(t.duration_s()), home(), "{name} ends at home, so it can loop");
            assert_eq!(
                t.switches(t.duration_s()),
                [false; 3],
                "{name} ends with every switch released"
            );
            assert!(s.config.validate().is_ok());
        }
        assert!(by_name("no-such").is_none());
    }
}
