//! The seed-like modeling session, as numbers: the figures (display mm), the pulls (pen height,
//! mm) and the slope gestures (sideways pen travel, mm) that the `modeling-session` scenario's
//! hand performs. The modeler's tests build the same document from these numbers directly and
//! compare it with what the pen made through the whole chain.

use glam::DVec2;

use crate::script::{SW1, SW3, Script, Timeline};

/// What to do with a figure once drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pull {
    /// Where the hand grabs it, display mm.
    pub grab: DVec2,
    /// The pen's height when it lets go, mm.
    pub height_mm: f64,
    /// Sideways travel with SW3 held while pulled, mm (negative: left, sharper); 0 for none.
    pub slope_mm: f64,
}

/// A figure of the session.
#[derive(Debug, Clone, PartialEq)]
pub enum Drawn {
    /// A point at the position.
    Point(DVec2),
    /// A polyline through the positions.
    Polyline(Vec<DVec2>),
    /// A closed curve through the positions, back to the first.
    Closed(Vec<DVec2>),
}

/// One step of the modeling session: a figure drawn, maybe pulled and sloped, maybe undone.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelingStep {
    /// The figure drawn; a closed curve outside every region becomes a generation region.
    pub drawn: Drawn,
    /// Its pull, if it is pulled.
    pub pull: Option<Pull>,
    /// SW3 clicks (undos) after the step.
    pub undos: usize,
}

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// The session, in order: a region; two peaks; a ridge; a plateau with a peak on it; and a hill
/// drawn and pulled by mistake, then undone (pull and figure: two SW3 clicks).
pub fn steps() -> Vec<ModelingStep> {
    let pulled = |drawn, grab, height_mm, slope_mm| ModelingStep {
        drawn,
        pull: Some(Pull {
            grab,
            height_mm,
            slope_mm,
        }),
        undos: 0,
    };
    let ridge = vec![v(250.0, 90.0), v(340.0, 130.0), v(430.0, 110.0)];
    vec![
        ModelingStep {
            drawn: Drawn::Closed(vec![
                v(60.0, 40.0),
                v(540.0, 40.0),
                v(560.0, 300.0),
                v(300.0, 320.0),
                v(50.0, 290.0),
            ]),
            pull: None,
            undos: 0,
        },
        pulled(Drawn::Point(v(150.0, 200.0)), v(150.0, 200.0), 90.0, -40.0),
        pulled(Drawn::Point(v(230.0, 260.0)), v(230.0, 260.0), 50.0, 0.0),
        pulled(Drawn::Polyline(ridge.clone()), ridge[1], 60.0, 50.0),
        pulled(
            Drawn::Closed(vec![v(380.0, 190.0), v(480.0, 195.0), v(470.0, 270.0), v(390.0, 265.0)]),
            v(430.0, 230.0),
            40.0,
            0.0,
        ),
        pulled(Drawn::Point(v(430.0, 230.0)), v(430.0, 230.0), 110.0, -25.0),
        ModelingStep {
            undos: 2,
            ..pulled(Drawn::Point(v(500.0, 80.0)), v(500.0, 80.0), 70.0, 0.0)
        },
    ]
}

/// The session's rock field (issue 11): the palette button tapped (the rock tool), an outline
/// drawn on the flank of the first peak, the field grabbed and slid along, and the palette
/// tapped again (back to figures).
#[derive(Debug, Clone, PartialEq)]
pub struct RockStep {
    /// The palette button's centre, display mm (the modeler's button is the square from 8 to 28
    /// mm in the display's corner).
    pub palette: DVec2,
    /// The field's outline, display mm (closed back to the first point).
    pub outline: Vec<DVec2>,
    /// Where the field is grabbed, and how far it is slid, mm.
    pub grab: DVec2,
    /// The slide.
    pub slide: DVec2,
}

/// The rock field of the demo's session, after [`steps`].
pub fn rock_step() -> RockStep {
    RockStep {
        palette: v(18.0, 18.0),
        outline: vec![
            v(90.0, 95.0),
            v(200.0, 85.0),
            v(215.0, 150.0),
            v(160.0, 175.0),
            v(95.0, 160.0),
        ],
        grab: v(150.0, 130.0),
        slide: v(15.0, 10.0),
    }
}

/// The session's river (issue 13): the river button tapped (the river tool), a meandering course
/// drawn through the terrain — from the ridge's southern foot down the valley between the second
/// peak and the plateau to the region's lower edge — two SW3 clicks over it (two years: its bends
/// migrate), and the button tapped again (back to figures).
#[derive(Debug, Clone, PartialEq)]
pub struct RiverStep {
    /// The river button's centre, display mm (the modeler's button is the square from 8 to 28
    /// mm across and 32 to 52 mm down).
    pub button: DVec2,
    /// The course as drawn, display mm, source first.
    pub course: Vec<DVec2>,
    /// Where the hand clicks SW3 for each year: on the course.
    pub over: DVec2,
    /// Years committed.
    pub years: u32,
}

/// The river of the demo's session, after the rock field.
pub fn river_step() -> RiverStep {
    let course = vec![
        v(320.0, 145.0),
        v(342.0, 180.0),
        v(310.0, 215.0),
        v(342.0, 250.0),
        v(310.0, 282.0),
        v(326.0, 312.0),
    ];
    RiverStep {
        button: v(18.0, 42.0),
        over: course[2],
        course,
        years: 2,
    }
}

/// The session's ridgeline (issue 12): the ridge button tapped (the ridgeline tool), a touch where
/// the ridge starts, the pen lifted and carried through the air (its height the ridge's
/// elevation), SW3 in the air to end it; then an SW3 click over it grows one round of valleys
/// (Alg. 2.5), and the button is tapped again (back to figures).
#[derive(Debug, Clone, PartialEq)]
pub struct RidgeStep {
    /// The ridge button's centre, display mm (the modeler's button is the 20 mm square 8 mm
    /// from the display's top right corner: 572 to 592 mm across on the 600 mm display).
    pub button: DVec2,
    /// The ridge as drawn: display mm and the pen's height, mm; the first is the touch (0 mm).
    pub path: Vec<glam::DVec3>,
    /// Where the hand clicks SW3 to grow valleys: over the ridge.
    pub over: DVec2,
}

/// The ridgeline of the demo's session, after the river: across the lower left of the region.
pub fn ridge_step() -> RidgeStep {
    let p = glam::DVec3::new;
    RidgeStep {
        button: v(582.0, 18.0),
        path: vec![
            p(80.0, 270.0, 0.0),
            p(80.0, 270.0, 25.0),
            p(170.0, 300.0, 45.0),
            p(280.0, 290.0, 30.0),
        ],
        over: v(170.0, 300.0),
    }
}

/// Taps on the tree button that take the tool from the second preset back to figures: one per
/// remaining preset of the modeler's `Preset::ALL` (cypress, oak, fir) and one more. The demo's
/// test checks it against the modeler's list.
pub const TREE_TAPS_TO_FIGURES: usize = 4;

/// The session's trees (issue 14): the tree button tapped (the tree tool, `table-3.1`), a tap
/// planting a tree, the button again (sample-3.2: the seed's two species), a tap planting a second; the first grabbed (SW2)
/// and pulled up, taller; an outline drawn back to its start and the tip lifted plants a grove;
/// a tap on the button for each remaining preset (cypress, oak, fir) and one more, back to figures. Every planted tree sways in the
/// tool's breeze, so the demo's frames move.
#[derive(Debug, Clone, PartialEq)]
pub struct TreeStep {
    /// The tree button's centre, display mm (the modeler's button is the square from 8 to 28 mm
    /// across and 56 to 76 mm down).
    pub button: DVec2,
    /// Where the two single trees are tapped, display mm: a table-3.1, then a sample-3.2.
    pub taps: [DVec2; 2],
    /// The pen's height when it lets go of the first tree, pulled: its top, mm.
    pub pull_mm: f64,
    /// The grove's outline, display mm (closed back to the first point).
    pub outline: Vec<DVec2>,
}

/// The trees of the demo's session, after the ridgeline: two on the saddle between the second
/// peak and the ridge's start, a grove on the slope right of the ridge's end.
pub fn tree_step() -> TreeStep {
    TreeStep {
        button: v(18.0, 66.0),
        taps: [v(255.0, 175.0), v(275.0, 195.0)],
        pull_mm: 25.0,
        outline: vec![v(460.0, 135.0), v(515.0, 130.0), v(520.0, 170.0), v(465.0, 175.0)],
    }
}

/// The hand's timeline for `steps`, from and back to `home`.
pub fn timeline(steps: &[ModelingStep], home: glam::DVec3) -> Timeline {
    let mut s = Script::new(home);
    for step in steps {
        match &step.drawn {
            Drawn::Point(p) => s.draw_point(*p),
            Drawn::Polyline(points) => s.draw_polyline(points),
            Drawn::Closed(points) => s.draw_closed(points),
        };
        if let Some(pull) = step.pull {
            s.grab(pull.grab).pull_to(pull.height_mm);
            if pull.slope_mm != 0.0 {
                s.slope(pull.slope_mm);
            }
            // The user looks at the result before letting go.
            s.hold(0.3).let_go();
        }
        for _ in 0..step.undos {
            // A click, then a pause so the next one is a click of its own.
            s.click(SW3).hold(0.3);
        }
    }
    let rock = rock_step();
    // The rock tool: tap the palette, draw the field, slide it, tap the palette again.
    s.hover(rock.palette).touch().lift(8.0);
    s.draw_closed(&rock.outline);
    s.grab(rock.grab)
        .drag_to(rock.grab + rock.slide)
        .hold(0.3)
        .lift(8.0)
        .let_go();
    s.hover(rock.palette).touch().lift(8.0);
    let river = river_step();
    // The river tool: tap its button, draw the course, two years, tap the button again.
    s.hover(river.button).touch().lift(8.0);
    s.draw_polyline(&river.course);
    for _ in 0..river.years {
        s.hover(river.over).click(SW3).hold(0.3);
    }
    s.hover(river.button).touch().lift(8.0);
    let ridge = ridge_step();
    // The ridgeline tool: tap its button, touch, lift and draw in the air, SW3 there; a click
    // over it grows valleys; tap the button again.
    s.hover(ridge.button).touch().lift(8.0);
    if let Some((first, rest)) = ridge.path.split_first() {
        s.hover(first.truncate()).touch();
        s.release(SW1);
        for p in rest {
            s.move_to(*p);
        }
        s.hold(0.2).click(SW3);
    }
    s.hover(ridge.over).click(SW3).hold(0.3);
    s.hover(ridge.button).touch().lift(8.0);
    let trees = tree_step();
    // The tree tool: its button, a tap (a tree), the button (next preset), a tap; the first tree
    // pulled taller; a grove's outline ended by lifting the tip; the button once per remaining
    // preset and once more (back to figures).
    s.hover(trees.button).touch().lift(8.0);
    s.hover(trees.taps[0]).touch().lift(8.0);
    s.hover(trees.button).touch().lift(8.0);
    s.hover(trees.taps[1]).touch().lift(8.0);
    s.grab(trees.taps[0]).pull_to(trees.pull_mm).hold(0.3).let_go();
    if let Some(first) = trees.outline.first() {
        s.hover(*first).touch();
        for p in trees.outline.iter().skip(1).chain(Some(first)) {
            s.drag_to(*p);
        }
        s.lift(8.0);
    }
    for _ in 0..TREE_TAPS_TO_FIGURES {
        s.hover(trees.button).touch().lift(8.0);
    }
    s.move_to(home);
    s.build()
}

/// How long before the session's end the viewer switches the glasses on in [`watched`], s.
pub const WATCHED_S: f64 = 12.0;

/// The seed's session watched by a seated viewer wearing the tracked glasses (issue 16): for its
/// last [`WATCHED_S`] seconds the glasses are on (a HeadOn, as the host sends it), the head
/// swaying and leaning in to look closely ([`crate::viewer::Viewer::seated`]), the glasses'
/// emitter multiplexed with the pen's 5:2 and predicted 20 ms ahead. The modeler's demo plays
/// it, so those frames, drawn from the tracked head, show the parallax of a person moving in
/// front of the display. Why not the whole session: a camera that moves changes nearly every
/// pixel of every frame, and the demo's animation, stored as deltas between frames, grew from
/// 25 MB to 83 MB with the head tracked throughout.
pub fn watched(scenario: crate::sim::Scenario) -> crate::sim::Scenario {
    let from_s = (scenario.timeline.duration_s() - WATCHED_S).max(0.0);
    scenario.with_head_from(pen_core::HeadSettings::default(), from_s)
}
