//! Frames of a session: the display's view, with the overview (and a map) beside it or in a
//! corner, drawn with the trees held to the view's budget and, with a tracked head, latched to
//! its newest pose ([`crate::latch`]).

mod budget;

use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use penmodel_render::{Frame, RenderError, Renderer, Scene};
use penmodel_terrain::Heightmap;
use penmodel_terrain::revision::Revisions;

pub use budget::{TreeBudget, VIEW_BUDGET_MS};

use crate::feed::Feed;
use crate::latch::{HEAD_WAIT_US, latch_head};
use crate::latency::{Check, VISIBLE_LEVELS};
use crate::picture::{Look, Picture};
use crate::session::Session;

/// Where the overview goes.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Overview {
    /// Not drawn.
    Off,
    /// In the lower right corner, a quarter of each side (clear of the slope bar, which takes
    /// the middle 40 % of the bottom).
    Corner,
    /// In a column half as wide as the display's view, to its right: the overview above, a map
    /// from straight above below.
    Beside,
}

/// Draws frames: the display's view, and the overview.
pub struct Painter {
    frame: Frame,
    view: Frame,
    renderer: Renderer,
    overview: Overview,
    inset: Frame,
    inset_renderer: Renderer,
    /// The trees' detail in latched frames ([`TreeBudget`]).
    trees: TreeBudget,
    /// How long the last view drawn before the head's pose took, µs: how far ahead of now the
    /// next one is drawn ([`Session::head_ahead`]).
    held_view_us: u64,
    /// Whether the last frame's view was moved to its pose (`Renderer::reproject`).
    reprojected: bool,
    /// How the moved views compare with views drawn whole from the same poses
    /// ([`Painter::check_reprojection`]).
    checks: Vec<Check>,
    /// The renderer and frame of those whole views: apart, so that the session's renderer keeps
    /// its held eyes and caches as they were.
    checker: Option<(Renderer, Frame)>,
}

impl Painter {
    /// Where the overview goes.
    pub fn overview(&self) -> Overview {
        self.overview
    }

    /// The display's view as last drawn.
    pub fn view_frame(&self) -> &Frame {
        &self.view
    }

    /// How the views moved to their poses compared with views drawn whole from them.
    pub fn checks(&self) -> &[Check] {
        &self.checks
    }
}

impl Painter {
    /// Frames whose display view is `width × height`.
    pub fn new(width: u32, height: u32, overview: Overview) -> Result<Painter, RenderError> {
        let mut painter = Painter {
            frame: Frame::new(width, height)?,
            view: Frame::new(width, height)?,
            renderer: Renderer::new(),
            overview: Overview::Off,
            inset: Frame::new(1, 1)?,
            inset_renderer: Renderer::new(),
            trees: TreeBudget::new(),
            held_view_us: 0,
            reprojected: false,
            checks: Vec::new(),
            checker: None,
        };
        painter.set_overview(overview)?;
        Ok(painter)
    }

    /// Moves the overview (the frame's size follows).
    pub fn set_overview(&mut self, overview: Overview) -> Result<(), RenderError> {
        let (w, h) = (self.view.width(), self.view.height());
        let (frame_w, inset) = match overview {
            Overview::Off => (w, (1, 1)),
            Overview::Corner => (w, ((w / 4).max(1), (h / 4).max(1))),
            Overview::Beside => (w + (w / 2).max(1), ((w / 2).max(1), (h / 2).max(1))),
        };
        self.frame = Frame::new(frame_w, h)?;
        self.inset = Frame::new(inset.0, inset.1)?;
        self.overview = overview;
        Ok(())
    }

    /// `picture` with the overview; `revisions`, the terrain's history when `map` is an editor's,
    /// lets the land look recompute only what changed since the last frame.
    pub fn draw(
        &mut self,
        picture: &Picture,
        map: &Heightmap,
        revisions: Option<&Revisions>,
    ) -> Result<&Frame, RenderError> {
        self.insets(picture, map, revisions)?;
        self.view(picture, map, revisions)
    }

    /// Draws what does not follow the head: the overview (and beside it the map), so that a
    /// tracked frame can draw them before it takes the head's newest pose for its view (issue
    /// 16). [`view`](Self::view) completes the frame.
    pub fn insets(
        &mut self,
        picture: &Picture,
        map: &Heightmap,
        revisions: Option<&Revisions>,
    ) -> Result<(), RenderError> {
        if self.overview == Overview::Off {
            return Ok(());
        }
        let extent = [
            f64::from(map.cols()) * map.cell_size(),
            f64::from(map.rows()) * map.cell_size(),
        ];
        self.inset_renderer
            .render(&scene(&picture.overview(extent), map, revisions), &mut self.inset)?;
        if self.overview == Overview::Beside {
            // Its column is clear of the view: both go straight into the frame.
            let (w, h) = (self.view.width(), self.view.height());
            self.frame.blit(&self.inset, w, 0);
            self.inset_renderer
                .render(&scene(&picture.map(extent), map, revisions), &mut self.inset)?;
            self.frame.blit(&self.inset, w, h - self.inset.height());
        }
        Ok(())
    }

    /// The display's view of `picture` into the frame, with the insets [`insets`](Self::insets)
    /// drew: the frame complete.
    pub fn view(
        &mut self,
        picture: &Picture,
        map: &Heightmap,
        revisions: Option<&Revisions>,
    ) -> Result<&Frame, RenderError> {
        self.view_with(scene(picture, map, revisions))
    }

    /// [`view`](Self::view) of `scene`.
    pub fn view_with(&mut self, scene: Scene) -> Result<&Frame, RenderError> {
        self.renderer.render(&scene, &mut self.view)?;
        self.compose()
    }

    /// The frame from the view drawn and the insets.
    pub fn compose(&mut self) -> Result<&Frame, RenderError> {
        self.frame.blit(&self.view, 0, 0);
        if self.overview == Overview::Corner {
            // Over the view, so after it.
            let (w, h) = (self.view.width(), self.view.height());
            let margin = 8.min(w / 8).min(h / 8) + 1;
            // At least 1 from the edge, for the border; blit clips what does not fit.
            let x = w.saturating_sub(self.inset.width() + margin).max(1);
            let y = h.saturating_sub(self.inset.height() + margin).max(1);
            let mut border = Frame::new(self.inset.width() + 2, self.inset.height() + 2)?;
            border.pixels_mut().fill([255, 255, 255, 255]);
            self.frame.blit(&border, x - 1, y - 1);
            self.frame.blit(&self.inset, x, y);
        }
        Ok(&self.frame)
    }

    /// `picture` alone, at the display view's size.
    pub fn plain(&mut self, picture: &Picture, map: &Heightmap) -> Result<&Frame, RenderError> {
        self.renderer.render(&picture.scene(map), &mut self.view)?;
        Ok(&self.view)
    }

    /// A frame of what `session` shows now.
    pub fn session(&mut self, session: &Session, look: &Look) -> Result<&Frame, RenderError> {
        let picture = Picture::of(session, look);
        self.draw(&picture, session.editor.heightmap(), Some(session.editor.revisions()))
    }

    /// A frame of `session` in real time: the insets from what it shows now, then the feed
    /// [latched](latch_head) to the head's next pose, then the view from that pose. Returns
    /// the frame and whether the feed ended meanwhile. `advance`: the interaction's own clock
    /// is moved to the last event's time first (the window's); `said` takes what the feed said.
    ///
    /// With a tracked head the view is drawn *before* the latch, from the pose predicted for
    /// when the frame will be done, and after the latch only moved to the newest pose by its
    /// depth (`Renderer::reproject`): what stands between the head's report and the frame is
    /// then a pass over the pixels, not the view's drawing (17–25 ms at 640 × 360 on two
    /// cores). The view shows the pen's edits up to the view's start, as the insets do (at the
    /// frame, older than before by the latch's wait and the move); the slope bar and the mode
    /// line are drawn after the latch.
    pub fn session_latched(
        &mut self,
        rx: &Receiver<Feed>,
        session: &mut Session,
        look: &Look,
        advance: bool,
        said: &mut dyn FnMut(Vec<String>),
    ) -> Result<(&Frame, bool), RenderError> {
        let tracked = session.head_m().is_some();
        if tracked {
            session.head_ahead(self.held_view_us);
        }
        let revisions = Some(session.editor.revisions());
        let picture = Picture::of(session, look);
        self.insets(&picture, session.editor.heightmap(), revisions)?;
        if tracked {
            let before = self.trees.scene(&picture, session.editor.heightmap(), revisions);
            let started = Instant::now();
            self.renderer.render_held(&before, &mut self.view)?;
            self.held_view_us = started.elapsed().as_micros() as u64;
            self.trees.after(self.held_view_us as f64 * 1e-3);
        } else {
            // The terrain's changes taken in before the pose, not in the view after it: a frame
            // after a burst of edits spent up to 26 ms on them inside the latency window.
            let before = self.trees.scene(&picture, session.editor.heightmap(), revisions);
            self.renderer.prepare_terrain(&before);
            // The trees' new simplified shapes baked for the last pose, at the budget's detail,
            // not in the view.
            self.renderer
                .prepare_trees(&before, self.view.width(), self.view.height());
        }
        let ended = latch_head(rx, session, said, Duration::from_micros(HEAD_WAIT_US));
        if let Some(t) = session.last_event_us().filter(|_| advance) {
            session.interaction.advance(t);
        }
        session.frame_started();
        let picture = Picture::of(session, look);
        let latched = self
            .trees
            .scene(&picture, session.editor.heightmap(), Some(session.editor.revisions()));
        // Moved to the newest pose; drawn whole when the held view cannot be (the stereo mode
        // or the size changed, or no pose came before the view).
        self.reprojected = tracked && self.renderer.reproject(&latched, &mut self.view).is_ok();
        if !self.reprojected {
            let started = Instant::now();
            self.renderer.render(&latched, &mut self.view)?;
            self.trees.after(started.elapsed().as_secs_f64() * 1e3);
        }
        Ok((self.compose()?, ended))
    }
}

impl Painter {
    /// After a frame whose view was moved to its pose: the view drawn whole from the same pose
    /// and compared with it ([`Check`]), so the demo reports how near the moved views are.
    /// Outside the frame's latency (it is done); the headless demo's frames are 200 ms apart.
    pub fn check_reprojection(&mut self, session: &Session, look: &Look) -> Result<(), RenderError> {
        if !std::mem::take(&mut self.reprojected) {
            return Ok(());
        }
        let (renderer, whole) = match &mut self.checker {
            Some(c) if c.1.width() == self.view.width() && c.1.height() == self.view.height() => c,
            slot => slot.insert((Renderer::new(), Frame::new(self.view.width(), self.view.height())?)),
        };
        let picture = Picture::of(session, look);
        let map = session.editor.heightmap();
        renderer.render(
            &self.trees.scene(&picture, map, Some(session.editor.revisions())),
            whole,
        )?;
        if let (Some((mean_abs, _)), Some(visible)) = (
            self.view.difference(whole),
            self.view.visibly_different(whole, VISIBLE_LEVELS),
        ) {
            self.checks.push(Check { mean_abs, visible });
        }
        Ok(())
    }
}

/// `p`'s scene of `map`, with the terrain's history when known.
pub fn scene<'a>(p: &'a Picture, map: &'a Heightmap, revisions: Option<&'a Revisions>) -> Scene<'a> {
    Scene {
        revisions,
        ..p.scene(map)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interaction::{Tuning, View};
    use crate::latch::tests::head_at;
    use crate::session::blank_document;
    use penmodel_terrain::editor::Editor;

    #[test]
    fn a_tracked_frame_is_drawn_before_the_pose_and_moved_to_it() {
        use penmodel_terrain::{Figure, FigureKind, Region};
        // An 800 m hill in the middle of the blank map: 8 cm tall on the display at 1:10 000,
        // so an 80 mm move of the head shifts its top by about 6 pixels of 320.
        let mut doc = blank_document();
        let (w, h) = (480.0 * 12.5, 272.0 * 12.5);
        doc.regions.push(Region {
            boundary: vec![
                [100.0, 100.0],
                [w - 100.0, 100.0],
                [w - 100.0, h - 100.0],
                [100.0, h - 100.0],
                [100.0, 100.0],
            ],
            figures: vec![Figure {
                kind: FigureKind::Point,
                points: vec![[0.5 * w, 0.5 * h]],
                height: 800.0,
                slope: 0.0,
                figures: Vec::new(),
            }],
            metric: None,
        });
        let session_at = |poses: &[(f64, u64)]| {
            let mut session = Session::new(
                Editor::new(doc.clone()).expect("valid"),
                [600.0, 340.0],
                Tuning::default(),
            );
            for &(u, t) in poses {
                session.feed(head_at(Some(u), t));
            }
            session
        };
        let look = Look::default();
        let whole = |session: &Session| {
            let mut painter = Painter::new(320, 180, Overview::Off).expect("painter");
            painter.session(session, &look).expect("drawn").clone()
        };
        // The view is drawn from the pose in before the frame; the latch takes a newer one.
        let mut session = session_at(&[(250.0, 0)]);
        let before = whole(&session);
        let (tx, rx) = std::sync::mpsc::channel();
        tx.send(head_at(Some(330.0), 16_000)).expect("queued");
        let mut painter = Painter::new(320, 180, Overview::Off).expect("painter");
        let (shown, ended) = painter
            .session_latched(&rx, &mut session, &look, false, &mut |_| {})
            .expect("drawn");
        let shown = shown.clone();
        assert!(!ended && painter.reprojected, "the view was moved to the newest pose");
        let after = whole(&session);
        let visible = |a: &Frame, b: &Frame| a.visibly_different(b, VISIBLE_LEVELS).expect("same size");
        let (unmoved, moved) = (visible(&before, &after), visible(&shown, &after));
        // The move shows, and the frame is the newest pose's far more than the old one's.
        assert!(unmoved > 0.01, "{unmoved}");
        assert!(moved < 0.5 * unmoved, "{moved} vs {unmoved}");
        // The demo's check compares the same two.
        painter.check_reprojection(&session, &look).expect("checked");
        assert_eq!(painter.checks.len(), 1);
        assert!((painter.checks[0].visible - moved).abs() < 1e-12);
    }

    #[test]
    fn every_layout_draws_at_any_size() {
        let doc = blank_document();
        let map = penmodel_terrain::generate(&doc).expect("valid");
        let view = View::fit([600.0, 340.0], &doc.grid);
        let picture = Picture::document(&doc, &view, "test".into(), &Look::default());
        for (w, h) in [(1, 1), (8, 8), (33, 20), (320, 180)] {
            for (overview, width) in [
                (Overview::Off, w),
                (Overview::Corner, w),
                (Overview::Beside, w + (w / 2).max(1)),
            ] {
                let mut painter = Painter::new(w, h, overview).expect("painter");
                let frame = painter.draw(&picture, &map, None).expect("drawn");
                assert_eq!((frame.width(), frame.height()), (width, h));
            }
        }
    }
}
