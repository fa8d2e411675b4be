//! The renderer's input: what to draw, as plain data.
//!
//! A [`Scene`] borrows the terrain and the overlays, so a live session builds one per frame at no
//! cost and hands it to [`Renderer::render`](super::Renderer::render).

pub(crate) mod forest;
pub mod impostor;
pub(crate) mod light;
pub(crate) mod meshes;
pub(crate) mod rock_lod;

use crate::output::frame::Rgba;
use crate::raster::camera::Camera;
use penmodel_terrain::Heightmap;
use penmodel_terrain::Point;
use penmodel_terrain::export::Mesh;
use penmodel_terrain::revision::Revisions;
use penmodel_terrain::trees::{Roughness, Standing};

use crate::raster::textured::{Quad, Texture};

/// How the two eyes' images are combined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stereo {
    /// One image from the centre eye.
    #[default]
    None,
    /// Red–cyan anaglyph: red from the left eye (its luminance), green and blue from the right.
    Anaglyph,
    /// The left eye's image in the left half, the right eye's in the right half, each squeezed to
    /// half width (the "half side-by-side" format 3D displays expand).
    SideBySide,
}

/// A line drawn on the terrain: a figure, a region boundary, or a figure being pulled.
#[allow(missing_docs)] // `colour` is the line's.
#[derive(Debug, Clone, PartialEq)]
pub struct Overlay {
    /// Points in the ground plane, `[x, y]` in metres (the document's coordinates). One point is
    /// drawn as a dot.
    pub points: Vec<Point>,
    /// Whether the last point joins the first.
    pub closed: bool,
    pub colour: Rgba,
    /// Line width in pixels.
    pub width: f32,
    /// `None`: draped on the terrain surface. `Some(h)`: at the fixed height `h` metres (a figure
    /// being pulled, drawn where the pen holds it).
    pub height: Option<f64>,
}

/// The slope bar: a value in a range, shown with its position (seed 000: "a scroll bar behind
/// the shape shows the value").
#[allow(missing_docs)] // fields named for what they hold.
#[derive(Debug, Clone, PartialEq)]
pub struct SlopeBar {
    pub value: f64,
    /// The value at the bar's left end.
    pub min: f64,
    /// The value at the bar's right end.
    pub max: f64,
    /// Text left of the value, e.g. `"slope"`.
    pub label: String,
}

impl SlopeBar {
    /// Where the value sits along the bar, 0 (left end) to 1 (right end), clamped; 0.5 for an
    /// empty or non-finite range or value.
    pub fn position(&self) -> f64 {
        let t = (self.value - self.min) / (self.max - self.min);
        if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.5 }
    }
}

/// How the terrain is coloured and lit ([`Style::look`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Look {
    /// The first renderer's look: one elevation ramp over `[−ramp_depth, ramp_top]`, Lambert plus
    /// ambient light, a screen-space sky gradient.
    #[default]
    Classic,
    /// Land (issue 20): colour by height in metres and by slope, cast shadows and sky light,
    /// sky, table and haze beyond the terrain ([`crate::shade::land`], [`crate::shade::atmosphere`]).
    Land,
}

/// Colours, widths and lighting: everything about the look that is not the scene's content.
#[derive(Debug, Clone, PartialEq)]
pub struct Style {
    /// Classic or land: [`Style::default`] is classic, [`Style::land`] the land look.
    pub look: Look,
    /// Land look: the snow line, metres of true height (not scaled by the vertical scale).
    pub snow_line: f32,
    /// Land look: the top of the beach band above sea level (height 0), metres, drawn when the
    /// scene has water (a height below 0, or rivers and lakes).
    pub beach_height: f32,
    /// Land look: slopes (degrees) from which grass gives way to rock, and where it is all rock.
    pub rock_slope: [f32; 2],
    /// Land look: azimuths of the sky-view factor (issue 12's horizons).
    pub sky_directions: u32,
    /// Land look: the shadows and sky light are computed on a grid of at most this many cells
    /// along its longer side (the heightmap averaged in blocks), and interpolated per vertex;
    /// 0 for the heightmap's own grid.
    pub light_cells: u32,
    /// Land look: while the terrain changes every frame, how many frames the shadows, sky light and
    /// colours may lag it (0: remade for every change); remade as soon as it stops.
    pub light_lag: u32,
    /// Land look: the distance over which the haze reaches 63 % of its strength, metres; 0 for
    /// three times the terrain's diagonal.
    pub haze_distance: f32,
    /// Land look: the haze's strength far away, 0 to 1.
    pub haze: f32,
    /// Land look: the display's table around the terrain, before light.
    pub table_colour: Rgba,
    /// Land look: the table's width around the terrain, as a fraction of its longer side.
    pub table_margin: f32,
    /// Heights at or above this many metres get the ramp's top colour (snow).
    pub ramp_top: f32,
    /// Heights at or below minus this many metres get the deepest water colour.
    pub ramp_depth: f32,
    /// Direction towards the light in the ground frame: `[x, y, up]` (need not be unit length).
    pub light: [f32; 3],
    /// Light that reaches every surface, 0 to 1; the rest is diffuse (Lambert).
    pub ambient: f32,
    /// Sky colour at the top of the frame.
    pub sky_top: Rgba,
    /// Sky colour at the bottom of the frame.
    pub sky_bottom: Rgba,
    /// Colour of the selected overlay.
    pub selection_colour: Rgba,
    /// Width of the selected overlay, pixels.
    pub selection_width: f32,
    /// An overlay passes the depth test where its depth is at most `1 + bias` times the
    /// terrain's: lines on the surface stay visible, lines behind a ridge are hidden.
    pub overlay_bias: f32,
    /// Text colour.
    pub text_colour: Rgba,
    /// Text size: pixels per font pixel.
    pub text_scale: u32,
    /// Colour of rocks, before light.
    pub rock_colour: Rgba,
    /// Colour of river and lake water, before light.
    pub water_colour: Rgba,
}

impl Style {
    /// The land look (issue 20) with its defaults; the rest as [`Style::default`].
    pub fn land() -> Style {
        Style {
            look: Look::Land,
            // A clear sky's zenith and its paler horizon: the land look's sky is a gradient by the
            // view ray's elevation, and the haze tends to the horizon's colour.
            sky_top: [82, 128, 196, 255],
            sky_bottom: [206, 220, 232, 255],
            ..Style::default()
        }
    }
}

impl Default for Style {
    fn default() -> Style {
        Style {
            look: Look::Classic,
            // Alpine snow lines are 1,500 to 3,000 m; the seed's terrains are true metres.
            snow_line: 1800.0,
            beach_height: 1.5,
            rock_slope: [32.0, 44.0],
            sky_directions: 16,
            light_cells: 160,
            light_lag: 2,
            haze_distance: 0.0,
            haze: 0.3,
            // Pale birch, the sand table's wooden frame.
            table_colour: [196, 178, 146, 255],
            table_margin: 0.06,
            ramp_top: 100.0,
            ramp_depth: 20.0,
            // From the south-west, 50° up: the default views look from the south, so the slopes
            // facing the viewer are lit and relief reads at a glance.
            light: [-1.0, 1.0, 1.7],
            ambient: 0.35,
            sky_top: [96, 136, 192, 255],
            sky_bottom: [200, 218, 235, 255],
            selection_colour: [255, 236, 64, 255],
            selection_width: 5.0,
            overlay_bias: 0.01,
            text_colour: [255, 255, 255, 255],
            text_scale: 2,
            // Weathered granite, a little warmer than the terrain's grey.
            rock_colour: [158, 148, 136, 255],
            water_colour: [52, 104, 168, 255],
        }
    }
}

/// Everything one frame shows.
#[allow(missing_docs)] // fields named for what they hold.
#[derive(Debug, Clone)]
pub struct Scene<'a> {
    pub terrain: &'a Heightmap,
    /// The terrain's history of changes (its editor's: `Editor::revisions`), when known: the
    /// land look then learns what changed since its last frame from it and recomputes only
    /// there; without it, it compares the heights with a copy ([`crate::shade::land`]).
    pub revisions: Option<&'a Revisions>,
    /// Vertical exaggeration: heights are drawn × this (1 = true scale).
    pub vertical_scale: f32,
    /// Lines on the terrain.
    pub overlays: &'a [Overlay],
    /// Meshes standing on the terrain (rock fields), in the exports' frame (X, Y up, Z; metres),
    /// drawn in [`Style::rock_colour`].
    pub rocks: &'a [(String, Mesh)],
    /// Water surfaces (rivers and lakes: flat meshes at their level, the same frame), drawn in
    /// [`Style::water_colour`].
    pub water: &'a [(String, Mesh)],
    /// The terrain's light per cell, 0 to 1, row-major like its heights — insolation from
    /// `penmodel_terrain::ridge::sun` (seed 002). When given and of the terrain's size, it
    /// replaces the style's Lambert light: a vertex's light is `ambient + (1 − ambient)·light`,
    /// so cells in a shadow get the ambient light alone.
    pub light_map: Option<&'a [f32]>,
    /// The index in `overlays` of the selected one, drawn in the selection colour and width.
    pub selection: Option<usize>,
    /// The slope bar, when shown.
    pub slope_bar: Option<SlopeBar>,
    /// One line of text for the mode, top left; empty for none.
    pub mode: &'a str,
    /// Where the eye is.
    pub camera: Camera,
    /// Mono or stereo.
    pub stereo: Stereo,
    /// Colours and lighting.
    pub style: Style,
    /// Trees standing on the terrain (a document's: `Editor::trees().trees()`), drawn with
    /// their own bark and leaf colours at the roughness [`Scene::tree_lod`] chooses
    /// (`crate::scene::forest`).
    pub trees: &'a [Standing],
    /// How trees choose their roughness `Q` by distance and gaze; `None` draws every tree in
    /// full (level of detail off).
    pub tree_lod: Option<Roughness>,
    /// The terrain's level of detail: the largest error, in pixels, a coarser level of the
    /// heightfield may make on screen ([`crate::lod`]); 0 draws every cell (full detail).
    pub terrain_lod: f32,
    /// The tracked head's view direction, world `[X, Y up, Z]`, when known; otherwise the gaze
    /// is the line from the centre eye through the screen's centre.
    pub gaze: Option<[f64; 3]>,
    /// The point the viewer looks at, world `[X, Y up, Z]`, when known (the pen's tip while
    /// modeling: seed 004's gaze is "the pen tip's direction from the head"); the gaze then runs
    /// from the centre eye to it. [`Scene::gaze`] takes precedence.
    pub looking_at: Option<[f64; 3]>,
    /// Seconds, for the trees' sway in the wind.
    pub time: f64,
    /// Textured, alpha-tested quads (the exports' frame), each naming a texture of
    /// [`Scene::textures`] (`crate::raster::textured`).
    pub polygons: &'a [Quad],
    /// The textures [`Scene::polygons`] name.
    pub textures: &'a [Texture],
}

impl<'a> Scene<'a> {
    /// The terrain alone, seen by `camera`, with the default style.
    pub fn new(terrain: &'a Heightmap, camera: Camera) -> Scene<'a> {
        Scene {
            terrain,
            revisions: None,
            vertical_scale: 1.0,
            overlays: &[],
            rocks: &[],
            water: &[],
            light_map: None,
            selection: None,
            slope_bar: None,
            mode: "",
            camera,
            stereo: Stereo::None,
            style: Style::default(),
            trees: &[],
            tree_lod: Some(Roughness::default()),
            terrain_lod: crate::lod::DEFAULT_PIXELS,
            gaze: None,
            looking_at: None,
            time: 0.0,
            polygons: &[],
            textures: &[],
        }
    }
}
