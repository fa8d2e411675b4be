//! Reprojection (issue 16): a frame drawn from one head pose and moved to another by its depth
//! equals the frame drawn from it where nothing moves, and is much nearer the frame drawn from
//! the new pose than the old frame is.

use penmodel_render::{Camera, Frame, Renderer, Scene, Stereo, Style, Tracked, View};

/// A terrain of hills and a ridge, 160 m square, and a tracked camera over it on a 0.6 × 0.34 m
/// display with the head at `head_mm` (display frame, mm from its centre).
fn camera(head_mm: [f64; 3]) -> Camera {
    Camera {
        view: View::Tracked(Tracked {
            head: head_mm.map(|v| v * 1e-3),
            ..Tracked::fit([0.6, 0.34], [160.0, 160.0], 0.45)
        }),
        tilt: 0.0,
    }
}

fn hills() -> penmodel_terrain::Heightmap {
    crate::common::terrain(160, |x, y| {
        let bump = |cx: f64, cy: f64, r: f64, h: f64| h * (-((x - cx).powi(2) + (y - cy).powi(2)) / (r * r)).exp();
        bump(50.0, 60.0, 25.0, 40.0)
            + bump(110.0, 100.0, 18.0, 30.0)
            + 12.0 * ((x * 0.11).sin() * (y * 0.07).cos())
            + if (78.0..82.0).contains(&x) { 25.0 } else { 0.0 }
    })
}

fn scene(map: &penmodel_terrain::Heightmap, head_mm: [f64; 3], stereo: Stereo) -> Scene<'_> {
    let mut s = Scene::new(map, camera(head_mm));
    s.style = Style::land();
    s.stereo = stereo;
    s
}

/// The share of pixels of `a` whose colour differs from `b`'s by more than 8 levels in some
/// channel: visibly, where the frames' smooth shading differs by a level or two between poses.
fn visibly_different(a: &Frame, b: &Frame) -> f64 {
    a.visibly_different(b, 8).expect("same size")
}

#[test]
fn a_held_frame_moved_to_a_new_pose_is_near_the_frame_drawn_from_it() {
    let map = hills();
    let from = [0.0, -250.0, 450.0];
    // Moves of 30–40 mm, a head's over a few tenths of a second: the hills' tops move by
    // several pixels (a frame's residual motion is a few mm).
    let cases = [
        (Stereo::None, [30.0, -230.0, 430.0]),
        (Stereo::None, [-40.0, -280.0, 470.0]),
        (Stereo::Anaglyph, [30.0, -230.0, 430.0]),
        (Stereo::SideBySide, [30.0, -230.0, 430.0]),
    ];
    for (stereo, to) in cases {
        let mut renderer = Renderer::new();
        let (mut held, mut moved) = (
            Frame::new(320, 180).expect("frame"),
            Frame::new(320, 180).expect("frame"),
        );
        renderer
            .render_held(&scene(&map, from, stereo), &mut held)
            .expect("render");
        // Moved nowhere: the frame as drawn, to the byte.
        renderer
            .reproject(&scene(&map, from, stereo), &mut moved)
            .expect("reproject");
        assert!(
            moved.pixels() == held.pixels(),
            "{stereo:?}: the identity changed the frame"
        );
        renderer
            .reproject(&scene(&map, to, stereo), &mut moved)
            .expect("reproject");
        let mut drawn = Frame::new(320, 180).expect("frame");
        Renderer::new()
            .render(&scene(&map, to, stereo), &mut drawn)
            .expect("render");
        let (stale, warped) = (visibly_different(&held, &drawn), visibly_different(&moved, &drawn));
        eprintln!(
            "{stereo:?} to {to:?}: {:.2} % of the pixels differ visibly, moved {:.2} %",
            stale * 100.0,
            warped * 100.0
        );
        // The motion shows (the test is not of a still picture), and the warp takes most of it
        // away: what is left is what the new pose uncovers (a steep ridge's far side) and the
        // shading's own dependence on the eye, and edges placed to the nearest pixel where a
        // draw places them to the sub-pixel (measured 2.0–2.9 % against 6.3–9.4 %; side by
        // side, whose pixels are twice as wide, 4.9 % against 7.2 % for the −40 mm move).
        assert!(stale > 0.04, "{stereo:?}: {stale}");
        assert!(warped < 0.5 * stale, "{stereo:?}: {warped} vs {stale}");
    }
}

#[test]
fn reprojecting_needs_a_held_frame_of_the_same_size() {
    let map = hills();
    let mut renderer = Renderer::new();
    let mut frame = Frame::new(64, 36).expect("frame");
    let s = scene(&map, [0.0, -250.0, 450.0], Stereo::None);
    assert!(renderer.reproject(&s, &mut frame).is_err(), "nothing held");
    renderer.render_held(&s, &mut frame).expect("render");
    assert!(
        renderer.reproject(&s, &mut Frame::new(65, 36).expect("frame")).is_err(),
        "another size"
    );
    // A plain render holds nothing.
    renderer.render(&s, &mut frame).expect("render");
    assert!(
        renderer.reproject(&s, &mut frame).is_ok(),
        "the held frame is kept until the next held one"
    );
    let anaglyph = scene(&map, [0.0, -250.0, 450.0], Stereo::Anaglyph);
    assert!(
        renderer.reproject(&anaglyph, &mut frame).is_err(),
        "the held frame has no left eye"
    );
}
