//! What a live session shows: the terrain as the seed's display showed it — the display surface
//! is the ground, seen from the user's head with an off-axis projection, so a figure drawn at a
//! point of the display lies exactly there — with the document's figures, the highlight, the
//! figure being drawn or moved, the pen, the slope bar and the mode line.

use penmodel_render::{Camera, Overlay, Rgba, Scene, SlopeBar, Stereo, Style, Tracked};
use std::sync::Arc;

use penmodel_terrain::Heightmap;
use penmodel_terrain::address::{CurvePath, FigurePath};
use penmodel_terrain::document::{Document, Figure, FigureKind, Point};
use penmodel_terrain::export::Mesh;
use penmodel_terrain::trees::Standing;

use crate::feed::Calibrating;
use crate::interaction::rocks::{self, Tool};
use crate::interaction::{Interaction, View};
use crate::interaction::{ridge, river};
use crate::session::Session;

/// Colour of a rock field's outline.
pub const ROCK_FIELD_COLOUR: Rgba = [200, 170, 130, 255];
/// Colour of a river's control polygon and points.
pub const RIVER_COLOUR: Rgba = [90, 160, 255, 255];
/// Colour of the cells the next iteration erodes (the seed's red).
pub const EROSION_COLOUR: Rgba = [230, 40, 30, 255];
/// Colour of the cells the next iteration deposits (the seed's light blue).
pub const DEPOSITION_COLOUR: Rgba = [160, 215, 255, 255];
/// Colour of ridgelines and ridgeline trees.
pub const RIDGE_COLOUR: Rgba = [150, 110, 60, 255];
/// Colour of a grove's outline and a single tree's trunk, with the tree tool.
pub const GROVE_COLOUR: Rgba = [60, 150, 70, 255];
/// Colour of the palette button while the rock tool is on.
pub const PALETTE_ON_COLOUR: Rgba = [255, 200, 90, 255];
/// Colour of the palette button while figures are drawn.
pub const PALETTE_OFF_COLOUR: Rgba = [170, 170, 170, 255];
/// Colour of the figure being drawn.
pub const DRAWING_COLOUR: Rgba = [64, 224, 255, 255];
/// Colour of a figure or vertex being moved.
pub const MOVING_COLOUR: Rgba = [255, 160, 32, 255];
/// Colour of a figure that would be deleted where it is dropped.
pub const DELETING_COLOUR: Rgba = [120, 120, 120, 255];
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

/// A tool button's outline: bright and thick while its tool is on.
fn button(points: Vec<Point>, on: bool) -> Overlay {
    Overlay {
        points,
        closed: true,
        colour: if on { PALETTE_ON_COLOUR } else { PALETTE_OFF_COLOUR },
        width: if on { 5.0 } else { 2.0 },
        height: None,
    }
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
        let at = document_overlays_at(doc);
        let highlighted: Option<&CurvePath> = ui.grabbed().or(ui.hover().map(|h| &h.curve));
        let moving = ui.moving(doc);
        let mut selection = highlighted.and_then(|c| at.iter().position(|(p, _)| p == c));
        let mut overlays: Vec<Overlay> = at.into_iter().map(|(_, o)| o).collect();
        if let Some(m) = moving {
            // The figure where the pen is taking it, in place of where it was.
            if let Some(i) = selection.take() {
                overlays[i].points = m.points;
                overlays[i].colour = if m.deleting { DELETING_COLOUR } else { MOVING_COLOUR };
            }
        }
        // Rock fields' outlines (the held one where the pen takes it), the palette button.
        let moving_field = ui.field_moving(doc);
        for (i, f) in doc.rocks.iter().enumerate() {
            let (points, colour) = match &moving_field {
                Some((m, pts)) if *m == i && rocks::outside_every_region(doc, pts) => (pts.clone(), DELETING_COLOUR),
                Some((m, pts)) if *m == i => (pts.clone(), MOVING_COLOUR),
                _ => (f.outline_at(), ROCK_FIELD_COLOUR),
            };
            if ui.tool() == Tool::Rocks && ui.field_hover() == Some(i) {
                selection = Some(overlays.len());
            }
            overlays.push(Overlay {
                points,
                closed: true,
                colour,
                width: 2.0,
                height: None,
            });
        }
        overlays.push(button(rocks::palette_outline(view), ui.tool() == Tool::Rocks));
        // Rivers: each control polygon and its points (the held river as the pen makes it), the
        // next iteration's erosion and deposition while one is edited, the river button.
        let moving_river = ui.river_moving(doc);
        for (i, r) in doc.rivers.iter().enumerate() {
            let points = match &moving_river {
                Some((m, moved)) if *m == i => moved.points.clone(),
                _ => r.points.clone(),
            };
            let held = moving_river.as_ref().is_some_and(|(m, _)| *m == i);
            if ui.tool() == Tool::Rivers && ui.river_hover() == Some(i) && !held {
                selection = Some(overlays.len());
            }
            let colour = if held { MOVING_COLOUR } else { RIVER_COLOUR };
            overlays.push(Overlay {
                points: points.clone(),
                closed: false,
                colour,
                width: 1.0,
                height: None,
            });
            if ui.tool() == Tool::Rivers {
                overlays.extend(points.iter().map(|p| dot(*p, None, colour, 4.0)));
            }
        }
        if let Some((erosion, deposition)) = ui.river_preview() {
            overlays.extend(erosion.iter().map(|p| dot(*p, None, EROSION_COLOUR, 2.0)));
            overlays.extend(deposition.iter().map(|p| dot(*p, None, DEPOSITION_COLOUR, 2.0)));
        }
        overlays.push(button(river::palette_outline(view), ui.tool() == Tool::Rivers));
        // Ridgelines and trees (their nodes as dots with the ridge tool), the ridge stroke being
        // drawn (its air part at the pen's height), the ridge button.
        let ridges_on = ui.tool() == Tool::Ridges;
        let ridge_lines = doc.ridges.iter().flat_map(|r| {
            let lines = r.lines.iter().enumerate().map(|(i, l)| {
                let pts: Vec<Point> = l.points.iter().map(|p| [p[0], p[1]]).collect();
                (ridge::Part::Line(i), pts)
            });
            let trees = r.trees.iter().enumerate().flat_map(|(j, t)| {
                t.edges.iter().filter_map(move |&[a, b]| {
                    Some((
                        ridge::Part::Tree(j),
                        vec![*t.nodes.get(a as usize)?, *t.nodes.get(b as usize)?],
                    ))
                })
            });
            lines.chain(trees)
        });
        for (part, pts) in ridge_lines {
            if ridges_on && ui.ridge_hover() == Some(part) && selection.is_none() {
                selection = Some(overlays.len());
            }
            if ridges_on {
                overlays.extend(pts.iter().map(|p| dot(*p, None, RIDGE_COLOUR, 4.0)));
            }
            overlays.push(Overlay {
                points: pts,
                closed: false,
                colour: RIDGE_COLOUR,
                width: if ridges_on { 2.0 } else { 1.0 },
                height: None,
            });
        }
        if let Some(samples) = ui.ridge_drawing() {
            overlays.extend(samples.iter().map(|s| {
                let h = (s.h_mm > 0.0).then(|| view.height_at(s.h_mm));
                dot(s.at, h, DRAWING_COLOUR, 3.0)
            }));
        }
        overlays.push(button(ridge::palette_outline(view), ridges_on));
        // With the tree tool: the groves' outlines and the single trees' trunks (the held one where
        // the pen takes it, the one under the pen selected); the tree button.
        let trees_on = ui.tool() == Tool::Trees;
        if trees_on {
            use crate::interaction::trees::Held;
            let moving = ui.tree_moving();
            let shift = |held: Held, p: Point| match moving {
                Some((h, by)) if h == held => [p[0] + by[0], p[1] + by[1]],
                _ => p,
            };
            let colour = |held: Held| match moving {
                Some((h, _)) if h == held => MOVING_COLOUR,
                _ => GROVE_COLOUR,
            };
            for (i, g) in doc.groves.iter().enumerate() {
                let held = Held::Grove(i);
                if ui.tree_hover() == Some(held) && selection.is_none() {
                    selection = Some(overlays.len());
                }
                overlays.push(Overlay {
                    points: g.region.iter().map(|&p| shift(held, p)).collect(),
                    closed: true,
                    colour: colour(held),
                    width: 2.0,
                    height: None,
                });
            }
            for (i, t) in doc.trees.iter().enumerate() {
                let held = Held::Tree(i);
                if ui.tree_hover() == Some(held) && selection.is_none() {
                    selection = Some(overlays.len());
                }
                overlays.push(dot(shift(held, t.at), None, colour(held), 4.0));
            }
        }
        overlays.push(button(crate::interaction::trees::palette_outline(view), trees_on));
        if let Some(drawn) = ui.drawing() {
            overlays.push(Overlay {
                points: drawn.to_vec(),
                closed: false,
                colour: DRAWING_COLOUR,
                width: 3.0,
                height: None,
            });
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
        let slope_bar = ui.slope_bar(doc).map(|(value, min, max)| SlopeBar {
            value,
            min,
            max,
            label: "slope".into(),
        });
        Picture {
            overlays,
            selection,
            slope_bar,
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
                let h = h.or_else(|| penmodel_render::overlay::surface_height(terrain, g[0], g[1]))?;
                Some([g[0], h * f64::from(self.vertical_scale), g[1]])
            }),
            ..Scene::new(terrain, self.camera)
        }
    }
}

/// Colour of region boundaries in [`document_overlays`].
pub const REGION_COLOUR: Rgba = [245, 245, 245, 255];
/// Colour of control figures in [`document_overlays`].
pub const FIGURE_COLOUR: Rgba = [220, 40, 40, 255];

/// The document's region boundaries and figures as draped overlays, in document order: for
/// each region its boundary, then its figures depth first (a closed figure before the figures
/// nested in it).
pub fn document_overlays(doc: &Document) -> Vec<Overlay> {
    document_overlays_at(doc).into_iter().map(|(_, o)| o).collect()
}

/// [`document_overlays`], each with the curve it draws (to find a selection's index).
pub fn document_overlays_at(doc: &Document) -> Vec<(CurvePath, Overlay)> {
    fn figures(list: &[Figure], at: &dyn Fn(usize) -> FigurePath, out: &mut Vec<(CurvePath, Overlay)>) {
        for (i, f) in list.iter().enumerate() {
            let path = at(i);
            out.push((
                CurvePath::Figure(path.clone()),
                Overlay {
                    points: f.points.clone(),
                    closed: f.kind == FigureKind::Closed,
                    colour: FIGURE_COLOUR,
                    width: 3.0,
                    height: None,
                },
            ));
            figures(&f.figures, &|j| path.child(j), out);
        }
    }
    let mut out = Vec::new();
    for (r, region) in doc.regions.iter().enumerate() {
        out.push((
            CurvePath::Boundary(r),
            Overlay {
                points: region.boundary.clone(),
                closed: true,
                colour: REGION_COLOUR,
                width: 2.0,
                height: None,
            },
        ));
        figures(&region.figures, &|i| FigurePath::new(r, i), &mut out);
    }
    out
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
