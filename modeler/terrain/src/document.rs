//! The document: the modeler's source of truth, plain data that serialises as versioned JSON.
//!
//! The format is specified in `docs/document.md`. This module only holds the types; reading and
//! writing them is [`crate::persist`]'s ([`Document::from_json`], [`Document::load`],
//! [`Document::save`]), which validates ([`crate::validate`]). A document built in code is
//! checked when it is handed to the [`TerrainEngine`](crate::TerrainEngine) or saved.

use serde::{Deserialize, Serialize};

/// The format version this build writes (and reads).
pub const VERSION: u32 = 6;

/// The oldest version this build reads: a version 1 to 3 document (no rock fields, no rivers, no
/// terrain settings) loads as the current version, with seed 000's taxicab distances.
pub const OLDEST_VERSION: u32 = 1;

/// A point in the ground plane, `[x, y]` in metres: x along columns, y along rows.
pub type Point = [f64; 2];

/// A terrain model: a grid and the generation regions drawn on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Document {
    /// Format version; [`VERSION`].
    pub version: u32,
    /// Free text about the document; generation ignores it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// The heightfield's grid.
    pub grid: Grid,
    /// The top-level generation regions, which never overlap.
    pub regions: Vec<Region>,
    /// Rock fields (seed 001) on the terrain; version 2 on.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rocks: Vec<RockField>,
    /// Rivers (seed 003) carved into the terrain; version 3 on.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rivers: Vec<River>,
    /// Ridgelines (seed 002), a height layer combined with the regions' terrain; version 3 on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ridges: Option<Ridges>,
    /// Trees (seed 004) standing on the terrain; version 4 on.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trees: Vec<Tree>,
    /// Groves of trees (seed 004) scattered in a region; version 4 on.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groves: Vec<Grove>,
    /// How the regions' terrain is made from the figures: the distance metric and the fractal
    /// detail; version 4 on. Left out, the defaults ([`TerrainSettings::default`]).
    #[serde(default, skip_serializing_if = "TerrainSettings::is_default")]
    pub terrain: TerrainSettings,
}

/// The distances eq. 1–3 read (`dp` from a figure, `df` from the region's edge).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// Seed 000's 4-neighbour path lengths, exactly: a point peak becomes a four-sided pyramid.
    /// What documents of versions 1 to 3 use.
    Taxicab,
    /// Exact Euclidean distances (`crate::edt`): a point peak becomes a cone. The default of
    /// new documents.
    #[default]
    Euclidean,
}

impl Metric {
    /// The name the document uses.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Taxicab => "taxicab",
            Metric::Euclidean => "euclidean",
        }
    }
}

/// Document-wide terrain settings (version 4).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerrainSettings {
    /// The distance metric of every region that does not choose its own ([`Region::metric`]).
    #[serde(default)]
    pub metric: Metric,
    /// Fractal detail added to the regions' terrain; none when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detail: Option<Detail>,
    /// Thermal erosion of the regions' terrain, after the detail; none when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub erosion: Option<Erosion>,
    /// A heightmap the sketch is added onto (version 6); none when left out: the sketch
    /// stands on 0 m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<Base>,
}

/// A heightmap under the sketch (`crate::import`): the regions' terrain (with its detail) is
/// added to its heights, and the erosion runs on the sum.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Base {
    /// The heightmap file, relative to the document's folder (or absolute): `.png` a 16-bit
    /// PNG, `.tif`/`.tiff` a float32 GeoTIFF, else raw float32 of the grid's size. Its size
    /// must be the grid's.
    pub path: String,
    /// The height of a 16-bit PNG's value 0, metres, instead of its `tEXt` chunk (with `max`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// The height of a 16-bit PNG's value 65535, metres (with `min`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// The heights read from `path` when the document was read from its file
    /// ([`crate::import::load_base`]); not part of the JSON.
    #[serde(skip)]
    pub heights: BaseHeights,
}

impl Base {
    /// A base naming `path`, its heights not loaded.
    pub fn new(path: impl Into<String>) -> Base {
        Base {
            path: path.into(),
            min: None,
            max: None,
            heights: BaseHeights::default(),
        }
    }
}

/// A base's heights, row-major over the grid, shared between copies of the document (an edit
/// copies the document; the heights stay one buffer). Equal when they are the same buffer or
/// hold the same heights.
#[derive(Clone, Default)]
pub struct BaseHeights(Option<std::sync::Arc<[f32]>>);

impl BaseHeights {
    /// Heights loaded.
    pub fn new(heights: Vec<f32>) -> BaseHeights {
        BaseHeights(Some(heights.into()))
    }

    /// The heights, if loaded.
    pub fn get(&self) -> Option<&[f32]> {
        self.0.as_deref()
    }

    /// The shared buffer, if loaded.
    pub fn shared(&self) -> Option<std::sync::Arc<[f32]>> {
        self.0.clone()
    }
}

impl PartialEq for BaseHeights {
    fn eq(&self, other: &BaseHeights) -> bool {
        match (&self.0, &other.0) {
            (Some(a), Some(b)) => std::sync::Arc::ptr_eq(a, b) || a[..] == b[..],
            (None, None) => true,
            _ => false,
        }
    }
}

impl std::fmt::Debug for BaseHeights {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            Some(h) => write!(f, "BaseHeights({} heights)", h.len()),
            None => f.write_str("BaseHeights(not loaded)"),
        }
    }
}

impl TerrainSettings {
    /// Whether these are the defaults (then the document leaves them out).
    pub fn is_default(&self) -> bool {
        *self == TerrainSettings::default()
    }
}

/// Fractal detail (`crate::detail`): seeded gradient-noise fBm added to the regions' terrain,
/// its amplitude following the ground — more on high and steep ground, none on the figures'
/// cells and at the regions' edges.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Detail {
    /// The amplitude as a fraction of the local relief (`docs/document.md`), 0 to 1.
    #[serde(default = "default_detail_amount")]
    pub amount: f64,
    /// The longest wavelength of the noise, metres (> 0).
    #[serde(default = "default_detail_scale")]
    pub scale: f64,
    /// Octaves of noise, each half the wavelength and half the amplitude of the last, 1 to 12.
    #[serde(default = "default_detail_octaves")]
    pub octaves: u32,
    /// The noise's seed: the same seed, the same detail.
    #[serde(default)]
    pub seed: u64,
}

fn default_detail_amount() -> f64 {
    0.12
}

fn default_detail_scale() -> f64 {
    400.0
}

fn default_detail_octaves() -> u32 {
    5
}

impl Default for Detail {
    fn default() -> Detail {
        Detail {
            amount: default_detail_amount(),
            scale: default_detail_scale(),
            octaves: default_detail_octaves(),
            seed: 0,
        }
    }
}

/// Thermal erosion (`crate::erosion`): material slides down between neighbouring cells where
/// the ground is steeper than the talus angle, a few steps, after the fractal detail.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Erosion {
    /// The talus angle, degrees (1 to 89): ground steeper than this sheds material.
    #[serde(default = "default_erosion_talus")]
    pub talus: f64,
    /// Steps, 0 to [`MAX_EROSION_ITERATIONS`](crate::validate::MAX_EROSION_ITERATIONS): material
    /// moves at most one cell per step; 0 is no thermal pass (the fluvial erosion alone).
    #[serde(default = "default_erosion_iterations")]
    pub iterations: u32,
    /// The share of the excess over the talus moved per step, 0 to 1.
    #[serde(default = "default_erosion_amount")]
    pub amount: f64,
    /// Fluvial erosion after the ridgelines join the terrain (version 5); none when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fluvial: Option<Fluvial>,
}

fn default_erosion_talus() -> f64 {
    33.0
}

fn default_erosion_iterations() -> u32 {
    16
}

fn default_erosion_amount() -> f64 {
    0.5
}

impl Default for Erosion {
    fn default() -> Erosion {
        Erosion {
            talus: default_erosion_talus(),
            iterations: default_erosion_iterations(),
            amount: default_erosion_amount(),
            fluvial: None,
        }
    }
}

/// Fluvial erosion (`crate::fluvial`, `docs/erosion.md`): the sketched land is the target a
/// landscape-evolution model raises the land toward while running water and soil creep wear
/// it. `{}` means on, with every default.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Fluvial {
    /// Steps, 1 to [`MAX_FLUVIAL_STEPS`](crate::validate::MAX_FLUVIAL_STEPS).
    pub steps: u32,
    /// Years per step (1 to 10⁶).
    pub dt: f64,
    /// Erodibility `K` of the stream-power law, m^(1−2m)/yr (0 to 1).
    pub k: f64,
    /// Drainage-area exponent `m` (0 to 2).
    pub m: f64,
    /// Slope exponent `n` (0.5 to 4).
    pub n: f64,
    /// Hillslope diffusivity `D`, m²/yr (0 to 100); left out,
    /// [`Fluvial::diffusivity`]'s default for the grid's cell size.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diffusion: Option<f64>,
    /// Response time `T`, years: how fast the land is raised back toward the sketch (at least
    /// `dt`); shorter keeps the sketch closer, longer lets water cut deeper.
    pub response: f64,
    /// Amplitude of the seeded noise added to the first surface, metres (0 to 100).
    pub noise: f64,
    /// The noise's seed.
    pub seed: u64,
}

impl Default for Fluvial {
    fn default() -> Fluvial {
        Fluvial {
            steps: 100,
            dt: 1000.0,
            k: 2.5e-4,
            m: 0.5,
            n: 1.0,
            diffusion: None,
            response: 10000.0,
            noise: 1.0,
            seed: 1,
        }
    }
}

/// The default hillslope diffusivity per square metre of cell, 1/yr: `D = 7.5·10⁻⁵ · dx²`
/// smooths a fifteenth of a cell's width per 1000-year step on any grid, so a 2 m grid and a
/// 12.5 m one look alike (3·10⁻⁴ and 0.0117 m²/yr).
pub const DIFFUSION_PER_CELL_AREA: f64 = 7.5e-5;

impl Fluvial {
    /// The hillslope diffusivity `D` on cells of `cell_size` metres, m²/yr: the document's, or
    /// [`DIFFUSION_PER_CELL_AREA`] times the cell's area.
    pub fn diffusivity(&self, cell_size: f64) -> f64 {
        self.diffusion
            .unwrap_or(DIFFUSION_PER_CELL_AREA * cell_size * cell_size)
    }
}

/// Ridgeline terrain (seed 002, `crate::ridge`): 3D ridgelines and 2D ridgeline trees whose
/// flanks, sloping down at `slope`, make a height layer. Where the layer is above the ground
/// (z > 0) a cell's height is the larger of it and the regions' terrain; elsewhere the regions'
/// terrain alone (`docs/ridgelines.md`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ridges {
    /// The flank slope α in degrees, strictly between 0 and 90.
    #[serde(default = "default_ridge_slope")]
    pub slope: f64,
    /// The low-pass filter: box half-width in cells.
    #[serde(default = "default_filter_radius")]
    pub filter_radius: u32,
    /// The low-pass filter: how many times the box is applied (0: the unfiltered maximum).
    #[serde(default = "default_filter_passes")]
    pub filter_passes: u32,
    /// 3D ridgelines, each a polyline of `[x, y, z]` points (metres), at least two.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lines: Vec<Ridgeline>,
    /// 2D ridgeline trees with automatic elevations.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trees: Vec<RidgeTree>,
}

fn default_ridge_slope() -> f64 {
    30.0
}

fn default_filter_radius() -> u32 {
    1
}

fn default_filter_passes() -> u32 {
    2
}

impl Default for Ridges {
    fn default() -> Ridges {
        Ridges {
            slope: default_ridge_slope(),
            filter_radius: default_filter_radius(),
            filter_passes: default_filter_passes(),
            lines: Vec::new(),
            trees: Vec::new(),
        }
    }
}

/// A 3D ridgeline: drawn in the air, its points carry their elevations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ridgeline {
    /// `[x, y, z]` in metres, at least two.
    pub points: Vec<[f64; 3]>,
}

/// A 2D ridgeline tree: nodes joined by segments, no cycle; each node's elevation is
/// `h_end + d·tan θ`, d its distance along the tree to the nearest end node (Alg. 2.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RidgeTree {
    /// The nodes `[x, y]`, metres.
    pub nodes: Vec<Point>,
    /// The segments, pairs of node indices.
    pub edges: Vec<[u32; 2]>,
    /// The characteristic slope θ in degrees, strictly between 0 and 90.
    #[serde(default = "default_theta")]
    pub theta: f64,
    /// The end nodes' elevation, metres.
    #[serde(default)]
    pub h_end: f64,
}

fn default_theta() -> f64 {
    20.0
}

/// A river (seed 003): a course drawn as a Bézier curve, shaped by `iterations` steps of
/// morphological erosion and deposition, then carved into the terrain. Its processed shape is
/// derived (`crate::river`), not stored: it regenerates from these fields in milliseconds, and
/// an entry that only holds what the user chose stays small and editable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct River {
    /// The control points of the course, metres; water flows from the first to the last. Every
    /// third point (0, 3, 6, …) is on the course, the two between are handles (a chain of cubic
    /// Bézier segments; a short last segment has a lower degree).
    pub points: Vec<Point>,
    /// The radius of the disc swept along the course, metres (the seed's width).
    pub width: f64,
    /// The water depth at the centre line, metres.
    pub depth: f64,
    /// The water amount (the seed's example: 60).
    #[serde(default = "default_water")]
    pub water: f64,
    /// The ground hardness, ≥ 1 harder (the seed's examples: 1 and 3).
    #[serde(default = "default_hardness")]
    pub hardness: f64,
    /// Years of change: erosion/deposition steps applied before carving.
    #[serde(default)]
    pub iterations: u32,
}

fn default_water() -> f64 {
    60.0
}

fn default_hardness() -> f64 {
    1.0
}

/// A rock field: rocks of mixed sizes scattered inside an outline (seed 001), standing on the
/// terrain. Its rocks are a pure function of everything here but `at`, so moving a field moves
/// the same rocks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RockField {
    /// Where the field is: the document point its outline is drawn from, metres.
    pub at: Point,
    /// The closed outline relative to `at` (last point repeats the first), metres.
    pub outline: Vec<Point>,
    /// Metres per cell of the field's image; radii and rock heights count these cells.
    pub cell_size: f64,
    /// The diagrams, one per radius.
    pub layers: Vec<RockLayer>,
    /// The random seed: the same seed, the same rocks.
    #[serde(default)]
    pub seed: u64,
}

/// One diagram of a rock field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RockLayer {
    /// The Poisson-disk radius in field cells (no two seeds within it).
    pub radius: f64,
    /// The area fraction `A_s` its rocks take (0 to 1); or give `count`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fraction: Option<f64>,
    /// The number of rocks, instead of `fraction`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    /// Eq. 2's `c_w1, c_w2, c_w3` (sideways move of the added points, × radius).
    #[serde(default)]
    pub widths: [f64; 3],
    /// Eq. 3's `c_h1, c_h2, c_h3` (their height, × radius), 0 to 10.
    #[serde(default = "default_heights")]
    pub heights: [f64; 3],
}

fn default_heights() -> [f64; 3] {
    [0.3, 0.0, 0.1]
}

impl RockField {
    /// The outline in document coordinates.
    pub fn outline_at(&self) -> Vec<Point> {
        self.outline
            .iter()
            .map(|p| [self.at[0] + p[0], self.at[1] + p[1]])
            .collect()
    }
}

/// The heightfield's grid. Cell `(c, r)` covers `[c·s, (c+1)·s) × [r·s, (r+1)·s)`, `s` the cell size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grid {
    /// Number of columns (cells along x).
    pub cols: u32,
    /// Number of rows (cells along y).
    pub rows: u32,
    /// Side of a cell in metres.
    pub cell_size: f64,
}

impl Grid {
    /// Number of cells.
    pub fn cells(&self) -> usize {
        self.cols as usize * self.rows as usize
    }

    /// Extent along x in metres.
    pub fn width(&self) -> f64 {
        f64::from(self.cols) * self.cell_size
    }

    /// Extent along y in metres.
    pub fn height(&self) -> f64 {
        f64::from(self.rows) * self.cell_size
    }
}

/// A generation region: a closed curve bounding the terrain its figures raise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// The closed boundary; its last point repeats its first.
    pub boundary: Vec<Point>,
    /// The control figures inside it.
    #[serde(default)]
    pub figures: Vec<Figure>,
    /// This region's distance metric (and its nested regions'), instead of the document's
    /// [`TerrainSettings::metric`]; version 4 on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub metric: Option<Metric>,
}

/// What a figure is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FigureKind {
    /// One point.
    Point,
    /// An open polyline of two or more points.
    Polyline,
    /// A closed curve (last point repeats the first); also the region of its nested figures.
    Closed,
}

impl FigureKind {
    /// The name the document uses.
    pub fn name(self) -> &'static str {
        match self {
            FigureKind::Point => "point",
            FigureKind::Polyline => "polyline",
            FigureKind::Closed => "closed",
        }
    }
}

/// A control figure: pulled to `height` with the slope coefficient `slope`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Figure {
    /// Point, polyline or closed curve.
    pub kind: FigureKind,
    /// The figure's points; a closed curve repeats its first point at the end.
    pub points: Vec<Point>,
    /// Absolute height in metres (negative for a depression).
    pub height: f64,
    /// Slope coefficient of eq. 2: 0 linear, < 0 sharp, > 0 bell-shaped.
    #[serde(default)]
    pub slope: f64,
    /// For a closed figure, the figures of the nested region it bounds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub figures: Vec<Figure>,
}

impl Figure {
    /// Moves the figure and everything nested in it by `by`.
    pub fn translate(&mut self, by: Point) {
        for p in &mut self.points {
            *p = [p[0] + by[0], p[1] + by[1]];
        }
        for f in &mut self.figures {
            f.translate(by);
        }
    }
}

impl Region {
    /// Moves the boundary and every figure by `by`.
    pub fn translate(&mut self, by: Point) {
        for p in &mut self.boundary {
            *p = [p[0] + by[0], p[1] + by[1]];
        }
        for f in &mut self.figures {
            f.translate(by);
        }
    }
}

impl Document {
    /// An empty document on `grid`.
    pub fn new(grid: Grid) -> Document {
        Document {
            version: VERSION,
            note: None,
            grid,
            regions: Vec::new(),
            rocks: Vec::new(),
            rivers: Vec::new(),
            ridges: None,
            trees: Vec::new(),
            groves: Vec::new(),
            terrain: TerrainSettings::default(),
        }
    }

    /// The metric region `r` uses: its own, or the document's.
    pub fn metric_of(&self, r: &Region) -> Metric {
        r.metric.unwrap_or(self.terrain.metric)
    }
}

/// One map of a tree's IFS (seed 004): `ω = Trans(0, y, 0)·Rot_y(θy)·Rot_z(−θz)·Scale(s)`, in
/// the tree's own unit (its trunk grows from the origin up +Y; `crate::trees::species`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IfsMap {
    /// Where the branch leaves the trunk, as a fraction of the tree's unit height.
    pub y: f64,
    /// The branch's scale, `0 < s < 1` (the IFS contracts).
    pub s: f64,
    /// The branch's lean from the vertical, degrees (`θz`).
    pub theta_z: f64,
    /// The branch's turn about the trunk, degrees (`θy`).
    pub theta_y: f64,
}

/// A tree (seed 004): an IFS tree standing on the terrain at `at`. Its shape is a preset's or
/// its own maps; its base height is the terrain's under `at`, so it follows the terrain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tree {
    /// Where the trunk meets the ground, metres.
    pub at: Point,
    /// The tree's height, metres (> 0).
    pub height: f64,
    /// A preset's name (`crate::trees::species::Preset`); `table-3.1` when neither this nor
    /// `maps` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// The tree's own IFS maps, instead of a preset.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub maps: Option<Vec<IfsMap>>,
    /// Turns the tree about its trunk (`seed`-derived angle), so that trees of one species differ.
    #[serde(default)]
    pub seed: u64,
    /// Sway in the wind; still when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<Wind>,
}

/// Wind sway (seed 004): branches of generation g lean `θ_g = A_g·sin(2π f_g t) + θ0_g` about
/// the horizontal axis across the wind, composed down the branch hierarchy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wind {
    /// The direction the wind blows towards, degrees from +x towards +y.
    #[serde(default)]
    pub direction: f64,
    /// Per generation (0 the trunk); the last entry holds for every deeper generation.
    pub generations: Vec<Sway>,
}

/// One generation's sway.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sway {
    /// The amplitude `A_g`, degrees.
    pub amplitude: f64,
    /// The frequency `f_g`, hertz.
    pub frequency: f64,
    /// The rest lean `θ0_g`, degrees (a steady wind's bend).
    #[serde(default)]
    pub rest: f64,
}

/// A grove (seed 004): trees scattered inside a region at a density (Poisson-disk spacing), each
/// a preset drawn from a weighted mix; a pure function of these fields.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grove {
    /// The closed outline (last point repeats the first), metres.
    pub region: Vec<Point>,
    /// Trees per hectare (10 000 m²), > 0.
    pub density: f64,
    /// The presets and their weights; `table-3.1` alone when empty.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mix: Vec<GroveSpecies>,
    /// The trees' mean height, metres; each tree varies by up to ±20 %.
    #[serde(default = "default_grove_height")]
    pub height: f64,
    /// The random seed: the same seed, the same grove.
    #[serde(default)]
    pub seed: u64,
    /// Sway in the wind for every tree of the grove; still when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<Wind>,
}

fn default_grove_height() -> f64 {
    10.0
}

/// One preset of a grove's mix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroveSpecies {
    /// The preset's name.
    pub preset: String,
    /// Its share, relative to the others' (> 0).
    #[serde(default = "default_weight")]
    pub weight: f64,
}

fn default_weight() -> f64 {
    1.0
}
