//! The CPU rasteriser: a [`Scene`] in, a [`Frame`] out.
//!
//! One folder per stage, in pipeline order:
//!
//! 1. `scene/`: the input as plain data ([`Scene`], [`Style`]); the light per vertex its style
//!    calls for (`light`); what stands on the terrain — rocks, water and trees as meshes
//!    (`meshes`, a rock field's level of detail `rock_lod`), the trees' simplified shapes
//!    (`impostor`) and the trees chosen per frame (`forest`).
//! 2. `raster/`: eyes and screens (`camera`: an orbit camera or a tracked head in front of a
//!    display, the off-axis projection, stereo eyes, the ground plane's tilt); the grid's vertices
//!    projected and snapped once per eye, in chunks with screen bounds (`transform`); triangles and
//!    lines crossing the near plane or the guard band cut (`clip`); triangles into a depth buffer,
//!    fixed point, top-left rule (`rasterise`); triangles and quads binned by bands of rows
//!    (`binned`); textured, alpha-tested polygons (`textured`) and texture levels (`mips`).
//! 3. `lod/`: drawing less — the terrain's level-of-detail quadtree and its chosen nodes
//!    (`nodes`); an eye's picture moved to a newer pose by its depth (`reproject`).
//! 4. `shade/`: samples become colours — per-vertex light, the elevation ramp per pixel
//!    (`ramp`), the sky; or the land look's ground colours (`land`) and the sky, table and haze
//!    around them (`atmosphere`).
//! 5. `ui/`: figures and boundaries draped on the surface, depth-tested with a bias (`overlay`);
//!    the slope bar, the mode line and panels, in a built-in font (`text`).
//! 6. `output/`: the frame buffer ([`Frame`]), stereo's anaglyph and side-by-side (`stereo`), and
//!    where frames go: PNG, APNG, a window.
//!
//! `simd/` holds the lane code of every stage: the AVX2 copies' dispatch and the vector helpers.
//!
//! The stages are private to the crate: what callers use is re-exported here, flat, with
//! [`land`] (the land look's maps, palette and materials) and [`impostor`] (the trees' simplified
//! shapes) as namespaces, and [`output`] a module of its own.
//!
//! `tiles` runs stages 2, 4 and 5 per band of rows in parallel (rayon). A [`Renderer`] keeps its
//! buffers between frames, so a live session calls [`Renderer::render`] once per pen report
//! without allocating. `docs/renderer.md` gives the maths and the measured figures behind the
//! decisions.
//!
//! Input rules: a frame of zero size is refused ([`Frame::new`]); camera parameters that are not
//! finite, or a head behind the display, are refused ([`RenderError::Camera`]); a non-finite
//! height leaves a hole (the triangles touching it are skipped, and [`RenderStats`] counts such
//! vertices); a grid smaller than 2 × 2 has no triangles and shows only sky, overlays and UI.

mod lod;
pub mod output;
mod raster;
mod scene;
mod shade;
#[doc(hidden)]
pub mod simd;
mod tiles;
mod ui;

pub use lod::{Area, DEFAULT_PIXELS as DEFAULT_LOD_PIXELS, Pick, Pyramid};
pub use output::frame::{Frame, MAX_SIDE, RenderError, Rgba};
pub use output::stereo::luma;
pub use raster::camera::{Camera, Eye, Orbit, Projection, Tracked, View, Viewpoint, Viewport};
pub use raster::rasterise::{Bounds, Sample};
pub use raster::textured::{Quad, Texture};
pub use raster::transform::Affine;
pub use scene::forest::{TreeStats, eye_and_gaze};
pub use scene::meshes::{Paint, Projected as ProjectedMeshes};
pub use scene::{Look, Overlay, Scene, SlopeBar, Stereo, Style};
pub use ui::overlay::surface_height;
pub use ui::text::glyph;
pub use ui::{BarLayout, Place, panel};

/// The trees' simplified shapes (seed 004, §5.2.3): which side faces an eye, the quads and the
/// opaque part of a texture.
pub use scene::impostor;
/// The land look's maps, its palette and its materials.
pub use shade::land;

use lod::{nodes, reproject};
use output::{frame, stereo};
use raster::{rasterise, textured, transform};
use scene::{forest, light, meshes};
use shade::{atmosphere, ramp};
use ui::overlay;

use rasterise::{Capsule, Surface};
use transform::Projected;

/// What a render found in its input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RenderStats {
    /// Vertices whose height is not finite; their triangles were skipped.
    pub skipped_vertices: usize,
}

/// The textures the textured polygons name: the scene's, then the trees' simplified shapes' (the
/// order `EyeBuffers::project` offsets their indices by, and the tiles look them up in).
fn all_textures<'a>(scene: &'a Scene, trees: &'a forest::Trees) -> Vec<&'a textured::Texture> {
    scene.textures.iter().chain(trees.cache().textures()).collect()
}

/// The bounds of the whole frame.
fn whole(frame: &Frame) -> Bounds {
    Bounds {
        x0: 0,
        x1: frame.width() as i32,
        y0: 0,
        y1: frame.height() as i32,
    }
}

/// `held`, an eye of a frame drawn earlier, moved to `scene`'s `eye` in `out`: its viewport.
fn warp_held(held: Option<&reproject::Held>, scene: &Scene, eye: Eye, out: &mut Frame) -> Result<Bounds, RenderError> {
    let held = held
        .filter(|h| h.width == out.width() as usize && h.invw.len() == out.pixels().len())
        .ok_or(RenderError::NotHeld("no eye held at this frame's size"))?;
    let to = projection(scene, eye, held.bounds, out.width(), out.height());
    let motion = reproject::Motion::between(&held.projection, &to)
        .ok_or(RenderError::NotHeld("the held eye's projection is degenerate"))?;
    reproject::warp(held, &motion, out.pixels_mut());
    Ok(held.bounds)
}

/// The index of `eye`'s buffers: centre, left, right.
fn slot(eye: Eye) -> usize {
    match eye {
        Eye::Centre => 0,
        Eye::Left => 1,
        Eye::Right => 2,
    }
}

/// The projection of `scene`'s `eye` drawn into `viewport` of a `width × height` frame.
fn projection(scene: &Scene, eye: Eye, viewport: Bounds, width: u32, height: u32) -> Projection {
    let vp = scene.camera.viewpoint(eye, f64::from(width) / f64::from(height));
    Projection::new(
        &vp,
        scene.camera.tilt,
        Viewport {
            x: f64::from(viewport.x0),
            y: f64::from(viewport.y0),
            width: f64::from(viewport.x1 - viewport.x0),
            height: f64::from(viewport.y1 - viewport.y0),
        },
    )
}

/// Rows per tile unless set otherwise ([`Renderer::with_tile_rows`]). Taller tiles set up fewer
/// triangles twice (a 512² frame: 8 rows 343M instructions, 16 rows 303M, 32 rows 294M, 48 rows
/// 291M); 32 still gives 23 tiles to balance over two cores.
pub const TILE_ROWS: usize = 32;

/// Parts the meshes and the textured polygons are each projected in, on the pool's threads
/// (`EyeBuffers::project`). Each part is a run of the scene's order and the tiles draw the parts
/// in turn, so a tile draws the same triangles in the same order whatever the parts: the image
/// does not depend on them.
const PARTS: usize = 2;

/// `N` consecutive ranges of the items of `weights`, about equal in weight with `first` added to
/// the first range's (what that part projects besides the items).
fn split<const N: usize>(first: usize, weights: impl Iterator<Item = usize> + Clone) -> [std::ops::Range<usize>; N] {
    let total = first + weights.clone().sum::<usize>();
    let mut ends = [0usize; N];
    let (mut sum, mut n) = (first, 0);
    let mut k = 0;
    for w in weights {
        // Item n goes to the part whose share its middle falls in.
        while k + 1 < N && 2 * N * sum + N * w >= 2 * (k + 1) * total {
            ends[k] = n;
            k += 1;
        }
        sum += w;
        n += 1;
    }
    for end in &mut ends[k..] {
        *end = n;
    }
    std::array::from_fn(|i| if i == 0 { 0 } else { ends[i - 1] }..ends[i])
}

#[derive(Default)]
struct EyeBuffers {
    projected: Projected,
    capsules: Vec<Capsule>,
    /// Rocks, water and trees, in that order, in [`PARTS`] parts drawn one after the other.
    meshes: [meshes::Projected; PARTS],
    /// The scene's textured polygons and the trees' simplified shapes, in [`PARTS`] parts.
    textured: [textured::Projected; PARTS],
    /// The terrain's level-of-detail nodes, when [`Scene::terrain_lod`] is above 0.
    nodes: nodes::Projected,
    /// Whether the last projection drew the nodes rather than the full grid.
    lod: bool,
    /// Each pixel's `1/w` (0: no surface), kept while [`Renderer::render_held`] draws: the
    /// tiles' samples are their threads' ([`tiles::render`]).
    depths: Vec<f32>,
}

/// What the eyes of a frame share: the terrain's light and level-of-detail pyramid, the land
/// look's maps, the trees, the tile height.
struct Shared<'a> {
    light: &'a [f32],
    pyramid: &'a lod::Pyramid,
    land: &'a land::Land,
    trees: &'a forest::Trees,
    tile_rows: usize,
    /// Whether the eyes keep their depths ([`Renderer::render_held`]).
    hold: bool,
}

/// Renders scenes into frames, keeping its buffers from one frame to the next.
pub struct Renderer {
    tile_rows: usize,
    light: Vec<f32>,
    /// The land look's maps, kept while the terrain does not change.
    land: land::Land,
    /// What the classic light in `light` was made for — the terrain's revision, the vertical
    /// scale and the style — and the vertices it skipped: kept while they stay.
    classic: Option<(penmodel_terrain::revision::Mark, f32, Style, usize)>,
    /// The land look's background per eye (centre, left, right), kept while the camera stays.
    backdrops: [atmosphere::Backdrop; 3],
    /// The eyes' projections and depth buffers: the first for a mono frame's eye and the
    /// left one of an anaglyph, the second for its right eye (drawn side by side with the left).
    eyes: [EyeBuffers; 2],
    /// Which of `eyes` the last eye drew.
    last: usize,
    left: Option<Frame>,
    /// The trees drawn this frame and the simplified shapes' textures.
    trees: forest::Trees,
    /// The terrain's level-of-detail pyramid and the revision it was made for.
    pyramid: lod::Pyramid,
    pyramid_made: Option<penmodel_terrain::revision::Mark>,
    /// What [`Renderer::prepare_terrain`] prepared for — the terrain's revision, the vertical
    /// scale and the style — and what it found, for the frame that follows.
    prepared: Option<(penmodel_terrain::revision::Mark, f32, Style, RenderStats)>,
    /// Whether [`Renderer::render_held`] is drawing: each eye then keeps its picture.
    hold: bool,
    /// Each eye's picture and depth as last drawn by [`Renderer::render_held`] (centre, left,
    /// right), for [`Renderer::reproject`].
    held: [Option<reproject::Held>; 3],
    /// Held eyes' buffers from earlier frames, reused.
    spare: Vec<reproject::Held>,
}

impl Default for Renderer {
    fn default() -> Renderer {
        Renderer::new()
    }
}

impl Renderer {
    /// A renderer with [`TILE_ROWS`] rows per tile.
    pub fn new() -> Renderer {
        Renderer::with_tile_rows(TILE_ROWS)
    }

    /// A renderer with `rows` rows per tile (at least 1). The image does not depend on it.
    pub fn with_tile_rows(rows: usize) -> Renderer {
        Renderer {
            tile_rows: rows.max(1),
            light: Vec::new(),
            land: land::Land::default(),
            classic: None,
            backdrops: Default::default(),
            eyes: Default::default(),
            last: 0,
            left: None,
            trees: forest::Trees::default(),
            pyramid: lod::Pyramid::default(),
            pyramid_made: None,
            prepared: None,
            hold: false,
            held: Default::default(),
            spare: Vec::new(),
        }
    }

    /// Renders `scene` into `frame` (at the frame's size), mono or stereo as the scene asks.
    pub fn render(&mut self, scene: &Scene, frame: &mut Frame) -> Result<RenderStats, RenderError> {
        scene.camera.check()?;
        let stats = self.prepare_frame(scene);
        let full = whole(frame);
        self.trees
            .prepare(scene, f64::from(frame.width()) / f64::from(frame.height()));
        match scene.stereo {
            Stereo::None => {
                self.eye(scene, Eye::Centre, full, frame);
                self.ui(scene, full, frame);
            }
            Stereo::SideBySide => {
                let mid = full.x1 / 2;
                let halves = [
                    (Eye::Left, Bounds { x1: mid, ..full }),
                    (Eye::Right, Bounds { x0: mid, ..full }),
                ];
                for (eye, half) in halves {
                    if half.x1 > half.x0 {
                        self.eye(scene, eye, half, frame);
                        self.ui(scene, half, frame);
                    }
                }
            }
            Stereo::Anaglyph => {
                let mut left = match self.left.take() {
                    Some(f) if f.width() == frame.width() && f.height() == frame.height() => f,
                    _ => Frame::new(frame.width(), frame.height())?,
                };
                self.anaglyph_eyes(scene, full, &mut left, frame);
                stereo::anaglyph(&left, frame);
                self.left = Some(left);
                self.ui(scene, full, frame);
            }
        }
        Ok(stats)
    }

    /// Renders one eye of `scene` over the whole frame, with the UI, ignoring `scene.stereo`.
    pub fn render_eye(&mut self, scene: &Scene, eye: Eye, frame: &mut Frame) -> Result<RenderStats, RenderError> {
        scene.camera.check()?;
        let stats = self.prepare_frame(scene);
        let full = whole(frame);
        self.trees
            .prepare(scene, f64::from(frame.width()) / f64::from(frame.height()));
        self.eye(scene, eye, full, frame);
        self.ui(scene, full, frame);
        Ok(stats)
    }

    /// Renders `scene` into `frame` as [`render`](Self::render) does, and holds each eye's
    /// picture, depth and projection, so that [`reproject`](Self::reproject) can move them to a
    /// newer head pose (issue 16: the view drawn before the pose comes, only moved after it).
    pub fn render_held(&mut self, scene: &Scene, frame: &mut Frame) -> Result<RenderStats, RenderError> {
        // Last frame's eyes are stale: their buffers are reused.
        self.spare.extend(self.held.iter_mut().filter_map(Option::take));
        self.hold = true;
        let stats = self.render(scene, frame);
        self.hold = false;
        stats
    }

    /// The eyes the last [`render_held`](Self::render_held) drew, moved to `scene`'s camera by
    /// their depth ([`reproject`]), combined as `scene.stereo` asks, and `scene`'s UI over them:
    /// the frame. Only the eyes move: what the picture shows is what the held frame's scene
    /// showed. An eye not held at `frame`'s size, or a degenerate projection, is refused
    /// ([`RenderError::NotHeld`]).
    pub fn reproject(&mut self, scene: &Scene, frame: &mut Frame) -> Result<(), RenderError> {
        scene.camera.check()?;
        let full = whole(frame);
        let warp_eye = |held: &[Option<reproject::Held>; 3], eye: Eye, out: &mut Frame| {
            warp_held(held[slot(eye)].as_ref(), scene, eye, out)
        };
        match scene.stereo {
            Stereo::None => {
                warp_eye(&self.held, Eye::Centre, frame)?;
                self.ui(scene, full, frame);
            }
            Stereo::SideBySide => {
                for eye in [Eye::Left, Eye::Right] {
                    let half = warp_eye(&self.held, eye, frame)?;
                    self.ui(scene, half, frame);
                }
            }
            Stereo::Anaglyph => {
                let mut left = match self.left.take() {
                    Some(f) if f.width() == frame.width() && f.height() == frame.height() => f,
                    _ => Frame::new(frame.width(), frame.height())?,
                };
                let warped =
                    warp_eye(&self.held, Eye::Left, &mut left).and_then(|_| warp_eye(&self.held, Eye::Right, frame));
                if warped.is_ok() {
                    stereo::anaglyph(&left, frame);
                }
                self.left = Some(left);
                warped?;
                self.ui(scene, full, frame);
            }
        }
        Ok(())
    }

    /// How many of the terrain's triangles cover each pixel of a `width × height` frame seen by
    /// the centre eye (row-major, no depth test): a diagnostic for the fill rule.
    pub fn coverage(&mut self, scene: &Scene, width: u32, height: u32) -> Result<Vec<u16>, RenderError> {
        scene.camera.check()?;
        frame::check_size(width, height)?;
        self.prepare(scene);
        let full = Bounds {
            x0: 0,
            x1: width as i32,
            y0: 0,
            y1: height as i32,
        };
        self.last = 0;
        let (shared, [bufs, _], _) = self.parts();
        let (affine, near, _) = bufs.project(&shared, scene, Eye::Centre, full, width, height);
        let pass = tiles::EyePass {
            map: scene.terrain,
            light: shared.light,
            affine: &affine,
            projected: &bufs.projected,
            nodes: bufs.lod.then_some(&bufs.nodes),
            near,
            viewport: full,
        };
        let mut counts = vec![0u16; width as usize * height as usize];
        tiles::coverage(&pass, &mut counts, width as usize, shared.tile_rows);
        Ok(counts)
    }

    /// How many times the land look's maps were remade (they are kept while the terrain, the
    /// vertical scale, the style and the water stay the same).
    pub fn land_remakes(&self) -> u64 {
        self.land.remakes()
    }

    /// The level-of-detail pyramid, as of the last frame drawn with [`Scene::terrain_lod`] above 0.
    pub fn pyramid(&self) -> &lod::Pyramid {
        &self.pyramid
    }

    /// The nodes the last eye drew, each at its level ([`lod::Pick`]); empty at full detail.
    pub fn lod_picks(&self) -> &[lod::Pick] {
        let eye = &self.eyes[self.last];
        if eye.lod { &eye.nodes.picks } else { &[] }
    }

    /// How many nodes of each level the last eye drew (level 0 first); empty at full detail.
    pub fn lod_levels(&self) -> Vec<usize> {
        let eye = &self.eyes[self.last];
        if eye.lod { eye.nodes.per_level() } else { Vec::new() }
    }

    /// Brings the pyramid up to date: only the nodes over the cells changed since it was made
    /// when the scene has the terrain's revisions, all of it otherwise.
    fn sync_pyramid(&mut self, scene: &Scene) {
        let map = scene.terrain;
        let since = match (scene.revisions, self.pyramid_made) {
            (Some(r), Some(made)) if self.pyramid.fits(map) => r.since(made),
            _ => None,
        };
        match since {
            Some(rect) => self.pyramid.update(
                map,
                (
                    rect.c0 as usize,
                    (rect.c0 + rect.width) as usize,
                    rect.r0 as usize,
                    (rect.r0 + rect.height) as usize,
                ),
            ),
            None => self.pyramid.build(map),
        }
        self.pyramid_made = scene.revisions.map(|r| r.mark());
    }

    /// Brings up to date what `scene`'s frames share whatever the camera: the land look's maps
    /// and light, or the classic light, and the level-of-detail pyramid, for the terrain's
    /// changes since the last frame. [`render`](Self::render) does it anyway; a frame latched
    /// to the tracked head's newest pose (issue 16) does it first, before it waits for the
    /// pose, so that the view drawn after the pose is only what the camera decides.
    pub fn prepare_terrain(&mut self, scene: &Scene) {
        let stats = self.prepare(scene);
        self.prepared = scene
            .revisions
            .map(|r| (r.mark(), scene.vertical_scale, scene.style.clone(), stats));
    }

    /// Bakes the trees' simplified shapes that `scene` would draw into a `width × height` frame
    /// and are not baked yet. A frame latched to the tracked head (issue 16) calls it with the
    /// last pose before it waits for the next: the view drawn from that pose then finds nearly
    /// all of them baked (a grove just planted asked for 70 groups at once, 120 ms inside the
    /// latency window).
    pub fn prepare_trees(&mut self, scene: &Scene, width: u32, height: u32) {
        self.trees.prepare(scene, f64::from(width) / f64::from(height.max(1)));
    }

    /// The frame's [`prepare`](Self::prepare), unless [`prepare_terrain`](Self::prepare_terrain)
    /// did it for the same terrain and style: a second call would take the still terrain for
    /// one that stopped moving and remake the maps the land look lets lag a pull, inside the
    /// latency window.
    fn prepare_frame(&mut self, scene: &Scene) -> RenderStats {
        match self.prepared.take() {
            Some((mark, scale, style, stats))
                if scene.revisions.map(|r| r.mark()) == Some(mark)
                    && scale == scene.vertical_scale
                    && style == scene.style =>
            {
                stats
            }
            _ => self.prepare(scene),
        }
    }

    /// Per-frame work shared by both eyes: the light.
    fn prepare(&mut self, scene: &Scene) -> RenderStats {
        if scene.terrain_lod > 0.0 {
            self.sync_pyramid(scene);
        }
        if scene.style.look == scene::Look::Land {
            // The light buffer is about to hold the land look's light.
            self.classic = None;
            return RenderStats {
                skipped_vertices: self.land.prepare(scene, &mut self.light),
            };
        }
        // The light buffer is about to hold the classic light.
        self.land.forget();
        // A terrain whose revision has not moved, drawn the same way: the light is as it was.
        let map = scene.terrain;
        let cells = map.cols() as usize * map.rows() as usize;
        if let (Some(revisions), Some((made, scale, style, skipped)), None) =
            (scene.revisions, &self.classic, scene.light_map)
            && revisions.since(*made) == Some(penmodel_terrain::Rect::EMPTY)
            && *scale == scene.vertical_scale
            && *style == scene.style
            && self.light.len() == cells
        {
            return RenderStats {
                skipped_vertices: *skipped,
            };
        }
        let skipped = light::vertex_light(
            scene.terrain,
            scene.vertical_scale,
            &scene.style,
            scene.light_map,
            &mut self.light,
        );
        self.classic = match (scene.revisions, scene.light_map) {
            (Some(r), None) => Some((r.mark(), scene.vertical_scale, scene.style.clone(), skipped)),
            _ => None,
        };
        RenderStats {
            skipped_vertices: skipped,
        }
    }
}

impl EyeBuffers {
    /// Projects the grid for `eye` drawn into `viewport` of a `width × height` frame.
    fn project(
        &mut self,
        shared: &Shared,
        scene: &Scene,
        eye: Eye,
        viewport: Bounds,
        width: u32,
        height: u32,
    ) -> (Affine, f32, Projection) {
        let projection = projection(scene, eye, viewport, width, height);
        let affine = Affine::new(&projection, scene.terrain.cell_size(), f64::from(scene.vertical_scale));
        let near = projection.near as f32;
        let cell = scene.terrain.cell_size();
        let bands = (height as usize, shared.tile_rows);
        let (meshes, textured, trees) = (&mut self.meshes, &mut self.textured, shared.trees);
        let textures = all_textures(scene, trees);
        let textures = &textures;
        let all = 0..trees.len();
        let before =
            |m: &[(String, penmodel_terrain::export::Mesh)]| m.iter().map(|(_, m)| m.indices.len()).sum::<usize>();
        let solid = split::<PARTS>(
            before(scene.rocks) + before(scene.water),
            trees.meshes(all.clone()).map(|m| m.indices.len()),
        );
        let flat = split::<PARTS>(scene.polygons.len(), trees.quads(all).map(<[_]>::len));
        let affine_ref = &affine;
        // The meshes and the textured polygons in parts on the pool's threads, beside the
        // terrain's nodes and the overlays on this one: one of each on a thread was a serial part
        // of the trees' frames (the trees' 16,000 triangles and 6,000 polygons).
        rayon::scope(|s| {
            for (k, (part, range)) in meshes.iter_mut().zip(solid).enumerate() {
                s.spawn(move |_| {
                    part.clear(bands);
                    if k == 0 {
                        let rocks = scene.rocks.iter().map(|(_, m)| m);
                        part.add_rocks(rocks, scene.terrain_lod, affine_ref, cell, near, &scene.style);
                        let water = scene.water.iter().map(|(_, m)| m);
                        part.add(
                            water,
                            Paint::Whole(Surface::Water),
                            affine_ref,
                            cell,
                            near,
                            &scene.style,
                        );
                    }
                    let trees = trees.meshes(range);
                    part.add(trees, Paint::Tree, affine_ref, cell, near, &scene.style);
                });
            }
            for (k, (part, range)) in textured.iter_mut().zip(flat).enumerate() {
                s.spawn(move |_| {
                    part.clear(bands);
                    if k == 0 {
                        part.add(scene.polygons, 0, textures, affine_ref, cell, near);
                    }
                    let first = scene.textures.len() as u32;
                    for quads in trees.quads(range) {
                        part.add(quads, first, textures, affine_ref, cell, near);
                    }
                });
            }
            self.lod = scene.terrain_lod > 0.0;
            if self.lod {
                self.projected.chunks.clear();
                nodes::project(
                    shared.pyramid,
                    scene.terrain,
                    shared.light,
                    affine_ref,
                    near,
                    viewport,
                    scene.terrain_lod,
                    &mut self.nodes,
                );
            } else {
                transform::project_grid(
                    scene.terrain,
                    shared.light,
                    affine_ref,
                    near,
                    viewport,
                    &mut self.projected,
                );
            }
            overlay::capsules(scene, &projection, &mut self.capsules);
        });
        (affine, near, projection)
    }

    /// Projects and draws `eye` of `scene` into `viewport` of `frame`, the buffers' depth
    /// samples its depth buffer; returns its projection and what shows where no surface does
    /// (for [`Renderer::keep`]).
    fn draw(
        &mut self,
        shared: &Shared,
        backdrop: &mut atmosphere::Backdrop,
        scene: &Scene,
        eye: Eye,
        viewport: Bounds,
        frame: &mut Frame,
    ) -> (Projection, reproject::Background) {
        let (width, height) = (frame.width(), frame.height());
        let (affine, near, projection) = self.project(shared, scene, eye, viewport, width, height);
        let ramp = ramp::Ramp::new(&scene.style);
        let air = (scene.style.look == scene::Look::Land)
            .then(|| atmosphere::Atmosphere::new(&projection, scene.terrain, scene.vertical_scale, &scene.style));
        let columns = (viewport.x0 as usize, viewport.x1 as usize);
        let back = air
            .as_ref()
            .map(|a| backdrop.of(a, width as usize, height as usize, columns));
        let shading = shade::Shading {
            ramp: &ramp,
            land: air.as_ref().zip(back).map(|(a, b)| (shared.land, a, b)),
        };
        let pass = tiles::EyePass {
            map: scene.terrain,
            light: shared.light,
            affine: &affine,
            projected: &self.projected,
            nodes: self.lod.then_some(&self.nodes),
            near,
            viewport,
        };
        let textures = all_textures(scene, shared.trees);
        let depths = shared.hold.then(|| {
            self.depths.resize(width as usize * height as usize, 0.0);
            &mut self.depths[..]
        });
        tiles::render(
            &pass,
            &self.meshes,
            (&self.textured, &textures),
            &self.capsules,
            &shading,
            &scene.style,
            frame.pixels_mut(),
            depths,
            width as usize,
            shared.tile_rows,
        );
        let background = match &air {
            Some(air) => reproject::Background::Level(air.table_y()),
            None => reproject::Background::Screen(
                (1.0 / scene
                    .camera
                    .viewpoint(eye, f64::from(width) / f64::from(height))
                    .screen_distance()) as f32,
            ),
        };
        (projection, background)
    }
}

impl Renderer {
    /// What the eyes share, and the eyes' buffers and backgrounds to draw into.
    fn parts(&mut self) -> (Shared<'_>, &mut [EyeBuffers; 2], &mut [atmosphere::Backdrop; 3]) {
        let shared = Shared {
            light: &self.light,
            pyramid: &self.pyramid,
            land: &self.land,
            trees: &self.trees,
            tile_rows: self.tile_rows,
            hold: self.hold,
        };
        (shared, &mut self.eyes, &mut self.backdrops)
    }

    fn eye(&mut self, scene: &Scene, eye: Eye, viewport: Bounds, frame: &mut Frame) {
        self.last = 0;
        let (shared, [bufs, _], backdrops) = self.parts();
        let (projection, background) = bufs.draw(&shared, &mut backdrops[slot(eye)], scene, eye, viewport, frame);
        self.keep(0, eye, viewport, projection, background, frame);
    }

    /// Both eyes of an anaglyph over `viewport`, the left into `left` and the right into
    /// `right`, side by side on the pool's threads: drawn one after the other, each eye's
    /// projection and the last of its tiles left a thread idle.
    fn anaglyph_eyes(&mut self, scene: &Scene, viewport: Bounds, left: &mut Frame, right: &mut Frame) {
        self.last = 1;
        let (shared, [a, b], [_, back_left, back_right]) = self.parts();
        let ((pl, bl), (pr, br)) = rayon::join(
            || a.draw(&shared, back_left, scene, Eye::Left, viewport, left),
            || b.draw(&shared, back_right, scene, Eye::Right, viewport, right),
        );
        self.keep(0, Eye::Left, viewport, pl, bl, left);
        self.keep(1, Eye::Right, viewport, pr, br, right);
    }

    /// When [`Renderer::render_held`] is drawing, holds `eye`'s picture in `frame` and its depth
    /// (in the buffers `eyes[k]` that drew it) for [`Renderer::reproject`].
    fn keep(
        &mut self,
        k: usize,
        eye: Eye,
        viewport: Bounds,
        projection: Projection,
        background: reproject::Background,
        frame: &Frame,
    ) {
        if !self.hold {
            return;
        }
        // In an earlier frame's buffers (render_held emptied the slots, so one this frame did
        // not draw is refused by reproject).
        let mut held = self.spare.pop().unwrap_or_else(|| reproject::Held {
            pixels: Vec::new(),
            invw: Vec::new(),
            width: 0,
            bounds: viewport,
            projection,
        });
        held.pixels.clear();
        held.pixels.extend_from_slice(frame.pixels());
        let bufs = &self.eyes[k];
        let width = frame.width() as usize;
        let depths = bufs.depths.iter().copied();
        reproject::depths(depths, &projection, background, width, &mut held.invw);
        held.width = width;
        held.bounds = viewport;
        held.projection = projection;
        self.held[slot(eye)] = Some(held);
    }

    /// What the last frame's trees cost: polygons copied, simplified shapes drawn.
    pub fn tree_stats(&self) -> forest::TreeStats {
        self.trees.stats()
    }

    fn ui(&self, scene: &Scene, viewport: Bounds, frame: &mut Frame) {
        if let Some(bar) = &scene.slope_bar {
            ui::slope_bar(frame, &viewport, bar, &scene.style);
        }
        ui::mode_line(frame, &viewport, scene.mode, &scene.style);
    }
}
