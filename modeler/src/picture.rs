//! What a live session shows: the terrain as the seed's display showed it — the display surface
//! is the ground, seen from the user's head with an off-axis projection, so a figure drawn at a
//! point of the display lies exactly there — with the document's figures, the highlight, the
//! figure being drawn or moved, the pen, the slope bar and the mode line.

use penmodel_render::{Camera, Overlay, Rgba, Scene, SlopeBar, Stereo, Style, Tracked};
use std::sync::Arc;

use penmodel_terrain::Heightmap;
use penmodel_terrain::document::{Document, Point};
use penmodel_terrain::export::Mesh;
use penmodel_terrain::trees::Standing;

use crate::feed::Calibrating;
use crate::interaction::{Interaction, Layers, View};
use crate::session::Session;

pub use crate::interaction::figures::{FIGURE_COLOUR, REGION_COLOUR};
pub use crate::interaction::tool::{
    DELETING_COLOUR, DRAWING_COLOUR, MOVING_COLOUR, PALETTE_OFF_COLOUR, PALETTE_ON_COLOUR,
};
/// Colour of the pen's tip and its foot on the ground.
pub const PEN_COLOUR: Rgba = [255, 255, 255, 255];
/// Colour of the calibration target to touch next.
pub const TARGET_NEXT_COLOUR: Rgba = [255, 220, 0, 255];
/// Colour of a calibration target already taken.
pub const TARGET_TAKEN_COLOUR: Rgba = [80, 220, 120, 255];
/// Colour of a calibration target still to come.
pub const TARGET_LATER_COLOUR: Rgba = [150, 150, 150, 255];
/// Radius of a calibration target's ring on the display, mm.
pub const TARGET_RADIUS_MM: f64 = 8.0;

/// How the session is looked at.
#[derive(Debug, Clone, PartialEq)]
pub struct Look {
    /// The viewer's head in the display's frame, metres: x right, y up the display, z out of it.
    /// The default sits 70 cm from a desk-sized display, in front of its near half.
    pub head_m: [f64; 3],
    /// The distance between the eyes, metres (stereo places each eye half of it from the head
    /// point, along the display's x).
    pub eye_separation_m: f64,
    /// Mono or stereo.
    pub stereo: Stereo,
    /// Colours and light.
    pub style: Style,
}

impl Default for Look {
    fn default() -> Look {
        Look {
            head_m: [0.0, -0.35, 0.7],
            eye_separation_m: 0.063,
            stereo: Stereo::None,
            // The land look (issue 20); the classic ramp's top kept for `Look::Classic`: terrain
            // of hundreds of metres, snow from 900 m.
            style: Style {
                ramp_top: 900.0,
                ..Style::land()
            },
        }
    }
}

/// The camera of a view: the display is the screen, the head looks through it.
pub fn camera(view: &View, head_m: [f64; 3], eye_separation_m: f64) -> Camera {
    Camera {
        view: penmodel_render::View::Tracked(Tracked {
            display: [view.display_mm[0] * 1e-3, view.display_mm[1] * 1e-3],
            head: head_m,
            eye_separation: eye_separation_m,
            centre: view.centre,
            scale: view.scale * 1e-3,
        }),
        tilt: view.tilt,
    }
}

/// One frame's content, owned; [`Picture::scene`] lends it to the renderer.
#[derive(Debug, Clone)]
pub struct Picture {
    overlays: Vec<Overlay>,
    selection: Option<usize>,
    slope_bar: Option<SlopeBar>,
    mode: String,
    camera: Camera,
    vertical_scale: f32,
    look: Look,
    /// The rock fields standing on the terrain.
    rocks: Arc<Vec<(String, Mesh)>>,
    /// The rivers' and lakes' water surface.
    water: Arc<Vec<(String, Mesh)>>,
    /// The trees and groves' trees standing on the terrain.
    trees: Arc<Vec<Standing>>,
    /// Seconds, for the trees' sway.
    time: f64,
    /// The pen's tip while it is over the display: its ground point and, in the air, its height
    /// (metres); on the surface, the terrain's. The trees' gaze turns to it (seed 004).
    pen_tip: Option<(Point, Option<f64>)>,
}

fn dot(at: Point, height: Option<f64>, colour: Rgba, width: f32) -> Overlay {
    Overlay {
        points: vec![at],
        closed: false,
        colour,
        width,
        height,
    }
}

impl Picture {
    /// What `session` shows now.
    pub fn of(session: &Session, look: &Look) -> Picture {
        // The tracked head, once it reports, places the eyes (issue 16); until then the look's.
        let tracked;
        let look = match session.head_m() {
            Some(head_m) => {
                tracked = Look { head_m, ..look.clone() };
                &tracked
            }
            None => look,
        };
        let ui = &session.interaction;
        let doc = session.editor.document();
        if let (Some(c), crate::session::State::Running) = (session.calibrating(), session.state()) {
            return Picture::calibrating(c, ui.view(), look);
        }
        let mode = match session.state() {
            crate::session::State::Ended(why) => format!("{why} | Esc closes"),
            crate::session::State::Failed(why) => format!("the pen failed: {why} | Esc closes"),
            crate::session::State::Running if session.events() == 0 && !session.status().is_empty() => {
                session.status().to_string()
            }
            crate::session::State::Running => ui.status(doc),
        };
        let water = session
            .editor
            .water()
            .filter(|w| w.any())
            .map_or_else(Vec::new, |w| vec![("water".to_string(), w.mesh(doc.grid.cell_size))]);
        Picture::from_parts(ui, doc, mode, look)
            .with_rocks(session.editor.rocks().shared())
            .with_water(Arc::new(water))
            .with_trees(session.editor.trees().shared())
            // The pen's clock drives the sway, so a replayed session sways the same.
            .with_time(session.last_event_us().map_or(0.0, |us| us as f64 * 1e-6))
    }

    /// The picture with the trees `trees` (an editor's, `Editor::trees().trees()`), drawn with
    /// level of detail.
    pub fn with_trees(mut self, trees: Arc<Vec<Standing>>) -> Picture {
        self.trees = trees;
        self
    }

    /// The picture at `seconds`, for the trees' sway in the wind.
    pub fn with_time(mut self, seconds: f64) -> Picture {
        self.time = seconds;
        self
    }

    /// The picture with the water surface `water` (from [`penmodel_terrain::Editor::water`]).
    pub fn with_water(mut self, water: Arc<Vec<(String, Mesh)>>) -> Picture {
        self.water = water;
        self
    }

    /// The picture with the rock fields `rocks` (an editor's, [`penmodel_terrain::Editor::rocks`]).
    pub fn with_rocks(mut self, rocks: Arc<Vec<(String, Mesh)>>) -> Picture {
        self.rocks = rocks;
        self
    }

    /// The calibration procedure: its targets on the display as rings (taken green, the next
    /// yellow with a dot at its centre, the rest grey), the pen's tip, and what to do.
    pub fn calibrating(c: &Calibrating, view: &View, look: &Look) -> Picture {
        let ring = |centre: [f64; 2], radius_mm: f64| -> Vec<Point> {
            (0..24)
                .map(|i| {
                    let a = std::f64::consts::TAU * f64::from(i) / 24.0;
                    view.to_ground(centre[0] + radius_mm * a.cos(), centre[1] + radius_mm * a.sin())
                })
                .collect()
        };
        let mut overlays = Vec::new();
        for (i, t) in c.targets.iter().enumerate() {
            let (colour, width) = match i.cmp(&c.taken) {
                std::cmp::Ordering::Less => (TARGET_TAKEN_COLOUR, 3.0),
                std::cmp::Ordering::Equal => (TARGET_NEXT_COLOUR, 5.0),
                std::cmp::Ordering::Greater => (TARGET_LATER_COLOUR, 2.0),
            };
            overlays.push(Overlay {
                points: ring(*t, TARGET_RADIUS_MM),
                closed: true,
                colour,
                width,
                height: None,
            });
            if i == c.taken {
                overlays.push(dot(view.to_ground(t[0], t[1]), None, colour, 5.0));
            }
        }
        if let Some(p) = c.pen_mm {
            let colour = if c.pressed { DRAWING_COLOUR } else { PEN_COLOUR };
            overlays.push(dot(view.to_ground(p[0], p[1]), None, colour, 7.0));
        }
        let count = c.targets.len();
        let mode = if c.taken < count {
            format!(
                "calibrating: touch the yellow target ({} of {count}) with the tip, hold it still a moment, lift",
                c.taken + 1
            )
        } else {
            format!("calibrating: all {count} targets taken, fitting")
        };
        Picture::plain(overlays, view, mode, look)
    }

    /// The document alone through `view`: no pen, no highlight, `mode` as the text line.
    pub fn document(doc: &Document, view: &View, mode: String, look: &Look) -> Picture {
        Picture::plain(document_overlays(doc), view, mode, look)
    }

    /// `overlays` through `view`, nothing selected, no slope bar.
    fn plain(overlays: Vec<Overlay>, view: &View, mode: String, look: &Look) -> Picture {
        Picture {
            overlays,
            selection: None,
            slope_bar: None,
            mode,
            camera: camera(view, look.head_m, look.eye_separation_m),
            vertical_scale: view.exaggeration as f32,
            look: look.clone(),
            rocks: Arc::default(),
            water: Arc::default(),
            trees: Arc::default(),
            time: 0.0,
            pen_tip: None,
        }
    }

    fn from_parts(ui: &Interaction, doc: &Document, mode: String, look: &Look) -> Picture {
        let view = ui.view();
        let Layers {
            mut overlays,
            selection,
        } = ui.layers(doc);
        if let Some(drawn) = ui.drawing() {
            overlays.push(Layers::line(drawn.to_vec(), false, DRAWING_COLOUR, 3.0));
        }
        let pen_tip = ui.pen().map(|p| {
            (
                view.to_ground(p.u_mm, p.v_mm),
                (p.h_mm > 1.0).then(|| view.height_at(p.h_mm)),
            )
        });
        if let Some(p) = ui.pen() {
            let ground = view.to_ground(p.u_mm, p.v_mm);
            overlays.push(dot(ground, None, PEN_COLOUR, 4.0));
            if p.h_mm > 1.0 {
                overlays.push(dot(ground, Some(view.height_at(p.h_mm)), PEN_COLOUR, 7.0));
            }
        }
        Picture {
            overlays,
            selection,
            slope_bar: ui.gauge(doc),
            mode,
            camera: camera(view, look.head_m, look.eye_separation_m),
            vertical_scale: view.exaggeration as f32,
            look: look.clone(),
            rocks: Arc::default(),
            water: Arc::default(),
            trees: Arc::default(),
            time: 0.0,
            pen_tip,
        }
    }

    /// The same content seen from an orbit camera over the whole grid (`extent`, metres), without
    /// the text and the slope bar: the overview shown beside the display's view, where heights
    /// read at a glance.
    pub fn overview(&self, extent: [f64; 2]) -> Picture {
        self.orbit(Camera::overview(extent, 30f64.to_radians(), 35f64.to_radians()))
    }

    /// The same content from straight above, north up: a map.
    pub fn map(&self, extent: [f64; 2]) -> Picture {
        self.orbit(Camera::overview(extent, 0.0, 89f64.to_radians()))
    }

    fn orbit(&self, camera: Camera) -> Picture {
        Picture {
            mode: String::new(),
            slope_bar: None,
            camera,
            look: Look {
                stereo: Stereo::None,
                ..self.look.clone()
            },
            // Nobody's eyes are at an orbit camera: its trees are chosen along its view axis.
            pen_tip: None,
            ..self.clone()
        }
    }

    /// The lines drawn on the terrain: the document's figures and boundaries in document order,
    /// then the stroke being drawn and the pen's dots.
    pub fn overlays(&self) -> &[Overlay] {
        &self.overlays
    }

    /// The text line shown at the top.
    pub fn mode(&self) -> &str {
        &self.mode
    }

    /// The highlighted overlay's index.
    pub fn selection(&self) -> Option<usize> {
        self.selection
    }

    /// The scene of `terrain` with this picture's content.
    pub fn scene<'a>(&'a self, terrain: &'a Heightmap) -> Scene<'a> {
        Scene {
            terrain,
            vertical_scale: self.vertical_scale,
            overlays: &self.overlays,
            rocks: &self.rocks,
            water: &self.water,
            light_map: None,
            selection: self.selection,
            slope_bar: self.slope_bar.clone(),
            mode: &self.mode,
            camera: self.camera,
            stereo: self.look.stereo,
            style: self.look.style.clone(),
            trees: &self.trees,
            time: self.time,
            looking_at: self.pen_tip.and_then(|(g, h)| {
                let h = h.or_else(|| penmodel_render::surface_height(terrain, g[0], g[1]))?;
                Some([g[0], h * f64::from(self.vertical_scale), g[1]])
            }),
            ..Scene::new(terrain, self.camera)
        }
    }
}

/// The document's region boundaries and figures as draped overlays, in document order: for
/// each region its boundary, then its figures depth first (a closed figure before the figures
/// nested in it).
pub fn document_overlays(doc: &Document) -> Vec<Overlay> {
    crate::interaction::figures::document_overlays(doc)
        .into_iter()
        .map(|(_, o)| o)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::blank_document;
    use penmodel_render::{Frame, Renderer};

    fn calibrating(taken: usize) -> Calibrating {
        Calibrating {
            targets: vec![[60.0, 34.0], [300.0, 170.0], [540.0, 306.0]],
            taken,
            pen_mm: Some([310.0, 160.0]),
            pressed: false,
        }
    }

    #[test]
    fn calibration_shows_each_target_where_it_is_and_the_pen() {
        let doc = blank_document();
        let view = View::fit([600.0, 340.0], &doc.grid);
        let c = calibrating(1);
        let picture = Picture::calibrating(&c, &view, &Look::default());
        let rings: Vec<&Overlay> = picture.overlays().iter().filter(|o| o.closed).collect();
        assert_eq!(rings.len(), 3);
        for (ring, target) in rings.iter().zip(&c.targets) {
            // Every point of the ring is TARGET_RADIUS_MM from its target on the display.
            for p in &ring.points {
                let d = view.to_display(*p);
                let r = ((d[0] - target[0]).powi(2) + (d[1] - target[1]).powi(2)).sqrt();
                assert!((r - TARGET_RADIUS_MM).abs() < 1e-6, "{r}");
            }
        }
        let colours: Vec<Rgba> = rings.iter().map(|o| o.colour).collect();
        assert_eq!(colours, [TARGET_TAKEN_COLOUR, TARGET_NEXT_COLOUR, TARGET_LATER_COLOUR]);
        let pen = picture.overlays().last().expect("the pen");
        assert_eq!(pen.colour, PEN_COLOUR);
        let at = view.to_display(pen.points[0]);
        assert!((at[0] - 310.0).abs() < 1e-9 && (at[1] - 160.0).abs() < 1e-9);
        assert!(picture.mode().contains("2 of 3"), "{}", picture.mode());
    }

    #[test]
    fn the_targets_are_drawn() {
        let doc = blank_document();
        let map = penmodel_terrain::generate(&doc).expect("valid");
        let view = View::fit([600.0, 340.0], &doc.grid);
        let mut frame = Frame::new(480, 272).expect("frame");
        let mut renderer = Renderer::new();
        let count = |frame: &Frame, colour: Rgba| frame.pixels().iter().filter(|p| **p == colour).count();
        let picture = Picture::calibrating(&calibrating(1), &view, &Look::default());
        renderer.render(&picture.scene(&map), &mut frame).expect("render");
        assert!(count(&frame, TARGET_NEXT_COLOUR) > 20);
        assert!(count(&frame, TARGET_TAKEN_COLOUR) > 20);
        // Once all are taken, none is yellow.
        let picture = Picture::calibrating(&calibrating(3), &view, &Look::default());
        renderer.render(&picture.scene(&map), &mut frame).expect("render");
        assert_eq!(count(&frame, TARGET_NEXT_COLOUR), 0);
    }
}
