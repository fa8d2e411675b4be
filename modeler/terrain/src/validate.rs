//! Validation of a document, with errors that name the element and the reason.
//!
//! A document is valid when:
//! - its version is [`VERSION`], the grid has at least one cell, a cell size within
//!   [[`MIN_CELL_SIZE`], [`MAX_CELL_SIZE`]] m and at most [`MAX_CELLS`] cells;
//! - every number is finite, every point lies on the grid (`0 ≤ x < cols·s`, `0 ≤ y < rows·s`),
//!   heights are within ±[`MAX_HEIGHT`] m and slopes within ±[`MAX_SLOPE`] — the ranges that make
//!   every intermediate term of eq. 1–4 and every `f32` height finite;
//! - figures are nested at most [`MAX_DEPTH`] deep (a figure path has at most that many figure
//!   indices), so that every document and journal line the editor writes parses back;
//! - the terrain engine's caches ([`engine_bytes`]) fit in [`MAX_ENGINE_BYTES`];
//! - a point figure has one point, a polyline at least two, and no point repeats the one before;
//! - region boundaries and closed figures are closed (last point equal to the first), have at
//!   least three distinct vertices and do not cross or touch themselves (polylines may cross
//!   themselves: a ridge that loops is still a ridge);
//! - every figure lies strictly inside its region (the region's boundary, or the closed figure it
//!   is nested in): its points are inside and its segments do not touch the region's edge;
//! - only closed figures hold nested figures;
//! - top-level regions do not overlap on the grid, and neither do the closed figures of one
//!   region (each is the region of its nested figures). Overlap is tested on the rasterised cells,
//!   so two curves closer than a cell that share a cell overlap.
//!
//! Errors stop at the first problem, in document order (the memory check comes last).
//!
//! The curve checks are linear in the number of vertices for drawn curves: a curve's segments go
//! into a grid of buckets about one segment long (`SegmentIndex`) and each segment is tested only
//! against those in its neighbouring buckets; points are located against their region's edge
//! through bands of rows (`Bands`).

use std::collections::HashMap;
use std::fmt;

use glam::DVec2;
use thiserror::Error;

use crate::cells::{self, Cell, Mask};
use crate::document::{Document, Figure, FigureKind, Grid, OLDEST_VERSION, Point, Region, VERSION};
use crate::geometry::{self, Side};

/// The most cells a grid may have: 4096 × 4096. The engine keeps about 16 bytes per cell per
/// figure of a region plus about 30 per cell, so a larger grid would not fit a workstation.
pub const MAX_CELLS: u64 = 1 << 24;

/// The smallest cell size, in metres. Below it mesh vertices `(c + ½)·s` would round together in
/// `f32` and their normals become undefined.
pub const MIN_CELL_SIZE: f64 = 1e-3;

/// The largest cell size, in metres: 100 km, so the grid's extent (≤ 4096 cells) stays far within
/// `f32` range with room for squared distances.
pub const MAX_CELL_SIZE: f64 = 1e5;

/// The largest absolute height, in metres (1000 km). A cell's height is the base plus a weighted
/// mean of reliefs (height − base, at most twice this), so every term stays a finite `f32`.
pub const MAX_HEIGHT: f64 = 1e6;

/// The largest absolute slope coefficient. Eq. 4 adds two slopes and multiplies by a weight;
/// eq. 2 raises a number in [0, 1] to `1 ± s`: within this range nothing overflows, and beyond a
/// few units the profile is already a step.
pub const MAX_SLOPE: f64 = 1e3;

/// The deepest a figure may be nested: a top-level figure is at depth 1, a figure in it at 2. The
/// JSON reader stops at 128 nested arrays and objects; a figure at depth d is 2d + 5 deep in the
/// document and 2d + 7 in a journal's `history` line, so 32 leaves room, and the editor refuses
/// the figure that would go deeper.
pub const MAX_DEPTH: usize = 32;

/// Bytes the terrain engine keeps per figure per cell of its region's bounding box: distances,
/// eq. 2 shape terms, their logarithms (a slope change is one `exp` per cell) and coefficients
/// (`f32` each).
pub const BYTES_PER_FIGURE_CELL: u64 = 16;

/// Bytes the terrain engine keeps, or allocates for a moment, per cell of a region's bounding
/// box whatever its figures: the mask, edge distances, eq. 3's normaliser (`f64`), a search
/// queue, a distance map being rebuilt and the cells it changed.
pub const BYTES_PER_REGION_CELL: u64 = 32;

/// The most memory the terrain engine may need for a document, in bytes (2 GiB): see
/// [`engine_bytes`]. 100 figures over 1024² cells need about 1.6 GB; 300 over 2048² would need
/// 20 GB, which aborted the process before this limit.
pub const MAX_ENGINE_BYTES: u64 = 2 << 30;

/// A number written compactly for a message: the shortest form that reads back, in exponent
/// notation when it is very large or very small (`1e308`, not 309 digits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let a = v.abs();
        if v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&a) {
            write!(f, "{v}")
        } else {
            write!(f, "{v:e}")
        }
    }
}

/// A byte count for a message, in the largest unit that keeps it ≥ 1 (`1.3 GB`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bytes(pub u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let b = self.0 as f64;
        match self.0 {
            0..1_000_000 => write!(f, "{:.1} kB", b / 1e3),
            1_000_000..1_000_000_000 => write!(f, "{:.1} MB", b / 1e6),
            _ => write!(f, "{:.1} GB", b / 1e9),
        }
    }
}

/// A document element that is not valid, and why.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{path}: {defect}")]
pub struct ValidationError {
    /// The element, e.g. `regions[1].figures[0].points[3]`.
    pub path: String,
    /// What is wrong with it.
    pub defect: Defect,
}

impl ValidationError {
    /// An error at `path`.
    pub fn new(path: impl Into<String>, defect: Defect) -> ValidationError {
        ValidationError {
            path: path.into(),
            defect,
        }
    }
}

/// What is wrong with an element.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Defect {
    /// The version is not one this build reads.
    #[error("unsupported document version {0} (this build reads versions {OLDEST_VERSION} to {VERSION})")]
    Version(String),
    /// The grid has no cells.
    #[error("the grid needs at least one column and one row")]
    EmptyGrid,
    /// The cell size is not within [[`MIN_CELL_SIZE`], [`MAX_CELL_SIZE`]] metres (or not finite).
    #[error("the cell size must be between {} and {} m, got {}", Num(MIN_CELL_SIZE), Num(MAX_CELL_SIZE), Num(*.0))]
    CellSize(f64),
    /// The grid has more cells than [`MAX_CELLS`].
    #[error("{cells} cells is more than the {max} this build can hold in memory")]
    GridTooLarge { cells: u64, max: u64 },
    /// A number is NaN or infinite.
    #[error("not a finite number")]
    NotFinite,
    /// A height beyond ±[`MAX_HEIGHT`] metres.
    #[error("a height must be within ±{} m, got {}", Num(MAX_HEIGHT), Num(*.0))]
    HeightRange(f64),
    /// A slope beyond ±[`MAX_SLOPE`].
    #[error("a slope must be within ±{}, got {}", Num(MAX_SLOPE), Num(*.0))]
    SlopeRange(f64),
    /// A figure nested deeper than [`MAX_DEPTH`].
    #[error("figures may be nested at most {MAX_DEPTH} deep; this one is at depth {0}")]
    TooDeep(usize),
    /// The terrain engine would need more than [`MAX_ENGINE_BYTES`].
    #[error(
        "the terrain would need about {} of memory ({figures} figures over {cells} cells of region bounding boxes), \
         more than the limit of {}: use fewer figures or a coarser grid",
        Bytes(*bytes),
        Bytes(*max)
    )]
    TooLarge {
        /// The estimate, [`engine_bytes`].
        bytes: u64,
        /// Figures in the document, at every depth.
        figures: u64,
        /// Cells of every region's and nested region's bounding box, summed.
        cells: u64,
        /// [`MAX_ENGINE_BYTES`].
        max: u64,
    },
    /// A point lies off the grid.
    #[error("({}, {}) lies outside the grid [0, {}) × [0, {}) m", Num(*x), Num(*y), Num(*width), Num(*height))]
    OutsideGrid {
        x: f64,
        y: f64,
        /// The grid's extent along x.
        width: f64,
        /// The grid's extent along y.
        height: f64,
    },
    /// A point figure without exactly one point.
    #[error("a point figure has exactly one point, found {0}")]
    PointCount(usize),
    /// A polyline with fewer than two points.
    #[error("a polyline needs at least two points, found {0}")]
    PolylineTooShort(usize),
    /// A closed curve with fewer than three distinct vertices.
    #[error("a closed curve needs at least three distinct points, found {0}")]
    CurveTooShort(usize),
    /// A point equal to the one before it.
    #[error("repeats the previous point")]
    RepeatedPoint,
    /// A closed curve whose last point is not its first.
    #[error("the curve is open: its last point ({}, {}) is not its first ({}, {})", Num(last[0]), Num(last[1]), Num(first[0]), Num(first[1]))]
    OpenCurve { first: Point, last: Point },
    /// A closed curve that crosses or touches itself.
    #[error("the curve crosses itself: the segment from this point meets the segment from points[{0}]")]
    SelfIntersecting(usize),
    /// A figure point outside its region.
    #[error("lies outside its region {0}")]
    OutsideRegion(String),
    /// A figure point on its region's edge.
    #[error("lies on the edge of its region {0}")]
    OnRegionEdge(String),
    /// A figure segment that leaves its region.
    #[error("the segment from the previous point to this one touches the edge of its region {0}")]
    CrossesRegionEdge(String),
    /// Nested figures in a figure that is not closed.
    #[error("a {0} figure cannot hold nested figures; only a closed figure bounds a region")]
    NestedInOpenFigure(&'static str),
    /// Two regions share grid cells.
    #[error("overlaps {other} on the grid (both cover cell ({}, {}))", cell.0, cell.1)]
    Overlap {
        /// The element it overlaps.
        other: String,
        /// The first shared cell, row by row.
        cell: Cell,
    },
    /// An element the document's version does not have.
    #[error("needs document version {0}")]
    NeedsVersion(u32),
    /// A rock field whose outline is in no top-level region.
    #[error("lies outside every region: draw the field inside a region")]
    OutsideEveryRegion,
    /// A rock field's image would be too large.
    #[error("the field would be {width} × {height} cells of its cell size, more than {max}: use a larger cell_size")]
    FieldTooLarge { width: f64, height: f64, max: u64 },
    /// A rock field without layers.
    #[error("a rock field needs at least one layer (a radius and a fraction or count)")]
    NoLayers,
    /// A radius that is not above 0.
    #[error("{} must be above 0", Num(*_0))]
    RadiusNotPositive(f64),
    /// A radius with no room for a rock in its field.
    #[error("{} cells leaves no room for one rock in the field's {width} × {height} cells", Num(*radius))]
    NoRoom { radius: f64, width: u32, height: u32 },
    /// A layer with both or neither of fraction and count.
    #[error("give either a fraction or a count")]
    FractionOrCount,
    /// A fraction outside [0, 1].
    #[error("{} must be from 0 to 1", Num(*_0))]
    FractionRange(f64),
    /// A field's fractions summing over 1.
    #[error("the fractions add up to {}, more than the whole field (1)", Num(*_0))]
    FractionsOverOne(f64),
    /// A shape coefficient out of range.
    #[error("{} must be from {} to {}", Num(*value), Num(*min), Num(*max))]
    Coefficient { value: f64, min: f64, max: f64 },
    /// A ridgeline, ridgeline tree or ridge parameter that cannot be used; the message names
    /// the element (`ridges.lines[2].points[1]`).
    #[error("{0}")]
    Ridge(String),
    /// A river course with fewer than two control points.
    #[error("a river's course needs at least two control points, found {0}")]
    CourseTooShort(usize),
    /// A river width, depth, water amount or hardness that is not above 0.
    #[error("{} must be above 0", Num(*_0))]
    NotPositive(f64),
    /// A river wider than [`crate::river::MAX_WIDTH_CELLS`] cells.
    #[error("{} m is more than the {} m ({} cells) a river may be wide", Num(*width), Num(*max), crate::river::MAX_WIDTH_CELLS)]
    RiverTooWide { width: f64, max: f64 },
    /// More river iterations than [`crate::river::MAX_ITERATIONS`].
    #[error("{0} iterations is more than the {max} a river may have", max = crate::river::MAX_ITERATIONS)]
    TooManyIterations(u32),
    /// A tree preset no build knows.
    #[error("unknown preset {_0:?}; the presets are {names}", names = crate::trees::Preset::names())]
    UnknownPreset(String),
    /// A tree with both a preset and its own maps.
    #[error("give either a preset or maps, not both")]
    PresetAndMaps,
    /// A tree with no maps or more than [`crate::trees::species::MAX_MAPS`].
    #[error("a tree needs 1 to {max} maps, found {_0}", max = crate::trees::species::MAX_MAPS)]
    MapCount(usize),
    /// An IFS map that does not contract.
    #[error("|s| = {} is not below 1: the IFS does not contract", Num(*_0))]
    NotContracting(f64),
    /// A species with more branches down to 2 % of its height than a tree may have.
    #[error(
        "the tree would have more than {} branches down to 2 % of its height: use smaller scales or fewer maps",
        crate::trees::nodes::MAX_NODES
    )]
    TooManyBranches,
    /// A tree height out of range.
    #[error("a tree's height must be above 0 and at most {} m, got {}", Num(crate::trees::MAX_HEIGHT), Num(*_0))]
    TreeHeight(f64),
    /// Wind without a generation.
    #[error("wind needs at least one generation (amplitude, frequency)")]
    NoGenerations,
    /// A grove whose expected trees are too many.
    #[error("{} trees per hectare over {} m² is about {} trees, more than the {} a grove may have", Num(*density), Num(*area), Num(*trees), Num(*max))]
    GroveTooDense {
        density: f64,
        area: f64,
        trees: f64,
        max: f64,
    },
    /// A grove whose sampling image would be too large.
    #[error(
        "the grove's sampling image would be {width} × {height} pixels, more than {max}: use a smaller region or a lower density"
    )]
    GroveTooLarge { width: u32, height: u32, max: u64 },
    /// A terrain setting (`terrain.detail`, `terrain.erosion`) out of its range.
    #[error("{what} must be {range}, got {}", Num(*value))]
    DetailRange {
        what: &'static str,
        range: String,
        value: f64,
    },
}

/// Checks the whole document.
pub fn document(doc: &Document) -> Result<(), ValidationError> {
    if doc.version != VERSION {
        return Err(ValidationError::new(
            "version",
            Defect::Version(doc.version.to_string()),
        ));
    }
    grid(&doc.grid)?;
    for (i, r) in doc.regions.iter().enumerate() {
        region(&doc.grid, r, i)?;
    }
    let masks: Vec<Mask> = doc
        .regions
        .iter()
        .map(|r| cells::closed_mask(&doc.grid, &r.boundary))
        .collect();
    for (i, m) in masks.iter().enumerate() {
        region_overlap(i, m, masks.iter().enumerate().take(i))?;
    }
    rock_fields(doc)?;
    rivers(doc)?;
    ridges(doc)?;
    trees(doc)?;
    groves(doc)?;
    terrain(doc)?;
    memory(doc)
}

/// The most octaves of fractal detail: the twelfth's wavelength is 1/2048 of the first's.
pub const MAX_DETAIL_OCTAVES: u32 = 12;

/// The most steps of thermal erosion: each moves material one cell, and a local change
/// recomputes a window grown by twice the steps.
pub const MAX_EROSION_ITERATIONS: u32 = 200;

/// Checks the terrain settings' fractal detail (`docs/document.md`): an amount from 0 to 1, a
/// scale (the longest wavelength) of at least two cells — a shorter one would alias on the grid
/// — and at most 10 000 km, and 1 to [`MAX_DETAIL_OCTAVES`] octaves; and the thermal erosion
/// ([`erosion`]). (The metric's names are checked when the text is read.)
pub fn terrain(doc: &Document) -> Result<(), ValidationError> {
    erosion(doc)?;
    let Some(d) = &doc.terrain.detail else { return Ok(()) };
    let range = |what: &'static str, range: String, value: f64| {
        Err(ValidationError::new(
            format!("terrain.detail.{}", what.rsplit(' ').next().unwrap_or(what)),
            Defect::DetailRange { what, range, value },
        ))
    };
    finite(d.amount, || "terrain.detail.amount".into())?;
    finite(d.scale, || "terrain.detail.scale".into())?;
    if !(0.0..=1.0).contains(&d.amount) {
        return range("the detail's amount", "from 0 to 1".into(), d.amount);
    }
    let min_scale = 2.0 * doc.grid.cell_size;
    if !(min_scale..=1e7).contains(&d.scale) {
        return range(
            "the detail's scale",
            format!("from {} m (two cells) to 10 000 km", Num(min_scale)),
            d.scale,
        );
    }
    if !(1..=MAX_DETAIL_OCTAVES).contains(&d.octaves) {
        return range(
            "the detail's octaves",
            format!("from 1 to {MAX_DETAIL_OCTAVES}"),
            f64::from(d.octaves),
        );
    }
    Ok(())
}

/// Checks the terrain settings' thermal erosion: a talus angle from 1° to 89°, 1 to
/// [`MAX_EROSION_ITERATIONS`] steps, an amount from 0 to 1.
pub fn erosion(doc: &Document) -> Result<(), ValidationError> {
    let Some(e) = &doc.terrain.erosion else { return Ok(()) };
    let range = |what: &'static str, range: String, value: f64| {
        Err(ValidationError::new(
            format!("terrain.erosion.{}", what.rsplit(' ').next().unwrap_or(what)),
            Defect::DetailRange { what, range, value },
        ))
    };
    finite(e.talus, || "terrain.erosion.talus".into())?;
    finite(e.amount, || "terrain.erosion.amount".into())?;
    if !(1.0..=89.0).contains(&e.talus) {
        return range("the erosion's talus", "from 1 to 89 degrees".into(), e.talus);
    }
    if !(1..=MAX_EROSION_ITERATIONS).contains(&e.iterations) {
        return range(
            "the erosion's iterations",
            format!("from 1 to {MAX_EROSION_ITERATIONS}"),
            f64::from(e.iterations),
        );
    }
    if !(0.0..=1.0).contains(&e.amount) {
        return range("the erosion's amount", "from 0 to 1".into(), e.amount);
    }
    Ok(())
}

/// Checks every rock field: its outline (a closed curve on the grid, relative to `at`), its cell
/// size and image size, its layers (the ranges of [`crate::rocks::Recipe::check`]), and that it
/// lies in a region (at least one of its vertices inside a top-level region).
pub fn rock_fields(doc: &Document) -> Result<(), ValidationError> {
    use crate::rocks::{self, RecipeError};
    for (i, f) in doc.rocks.iter().enumerate() {
        let path = format!("rocks[{i}]");
        finite(f.at[0], || format!("{path}.at"))?;
        finite(f.at[1], || format!("{path}.at"))?;
        if !(MIN_CELL_SIZE..=MAX_CELL_SIZE).contains(&f.cell_size) {
            return Err(ValidationError::new(
                format!("{path}.cell_size"),
                Defect::CellSize(f.cell_size),
            ));
        }
        let outline = f.outline_at();
        ring(
            &doc.grid,
            &outline,
            |k| format!("{path}.outline[{k}]"),
            &format!("{path}.outline"),
        )?;
        let (width, height, _) = rocks::field::extent(f);
        if width * height > rocks::MAX_PIXELS as f64 {
            let max = rocks::MAX_PIXELS;
            return Err(ValidationError::new(
                format!("{path}.cell_size"),
                Defect::FieldTooLarge { width, height, max },
            ));
        }
        if f.layers.is_empty() {
            return Err(ValidationError::new(format!("{path}.layers"), Defect::NoLayers));
        }
        for (k, l) in f.layers.iter().enumerate() {
            if l.fraction.is_some() == l.count.is_some() {
                return Err(ValidationError::new(
                    format!("{path}.layers[{k}]"),
                    Defect::FractionOrCount,
                ));
            }
        }
        let recipe = rocks::field::recipe(f, width as u32, height as u32);
        if let Err(e) = recipe.check() {
            let layer = |k: usize, what: &str| format!("{path}.layers[{k}].{what}");
            let (at, defect) = match e {
                RecipeError::FieldSize { .. } | RecipeError::Fill(_) => (
                    format!("{path}.cell_size"),
                    Defect::FieldTooLarge {
                        width,
                        height,
                        max: rocks::MAX_PIXELS,
                    },
                ),
                RecipeError::NoLayers => (format!("{path}.layers"), Defect::NoLayers),
                RecipeError::RadiusNotPositive { layer: k, radius } => {
                    (layer(k, "radius"), Defect::RadiusNotPositive(radius))
                }
                RecipeError::RadiusTooLarge {
                    layer: k,
                    radius,
                    width,
                    height,
                } => (layer(k, "radius"), Defect::NoRoom { radius, width, height }),
                RecipeError::FractionRange { layer: k, fraction } => {
                    (layer(k, "fraction"), Defect::FractionRange(fraction))
                }
                RecipeError::FractionsOverOne { sum } => (format!("{path}.layers"), Defect::FractionsOverOne(sum)),
                RecipeError::ShapeRange {
                    layer: k,
                    what,
                    value,
                    min,
                    max,
                } => {
                    let (list, n) = match what {
                        "c_w1" => ("widths", 0),
                        "c_w2" => ("widths", 1),
                        "c_w3" => ("widths", 2),
                        "c_h1" => ("heights", 0),
                        "c_h2" => ("heights", 1),
                        _ => ("heights", 2),
                    };
                    (
                        layer(k, &format!("{list}[{n}]")),
                        Defect::Coefficient { value, min, max },
                    )
                }
            };
            return Err(ValidationError::new(at, defect));
        }
        let in_a_region = doc.regions.iter().any(|r| {
            outline
                .iter()
                .any(|&p| geometry::locate(&r.boundary, p) == Side::Inside)
        });
        if !in_a_region {
            return Err(ValidationError::new(path, Defect::OutsideEveryRegion));
        }
    }
    Ok(())
}

/// The terrain engine's memory for `doc`, in bytes, an upper bound on what it keeps and
/// allocates while building and updating: per region (top-level, and the nested region of each
/// closed figure) its bounding box's cells × ([`BYTES_PER_FIGURE_CELL`] × its figures +
/// [`BYTES_PER_REGION_CELL`]), plus 4 bytes per grid cell for the heightmap. Returns the
/// estimate, the number of figures and the summed box cells. Linear in the document's points.
pub fn engine_bytes(doc: &Document) -> (u64, u64, u64) {
    fn box_cells(grid: &Grid, pts: &[Point]) -> u64 {
        // A closed curve's cells span exactly the cells of its extreme points (each segment's
        // walk stays between its end cells), so the box needs no rasterising.
        let Some(&first) = pts.first() else { return 0 };
        let (mut lo, mut hi) = (cells::point_cell(grid, first), cells::point_cell(grid, first));
        for &p in pts {
            let (c, r) = cells::point_cell(grid, p);
            lo = (lo.0.min(c), lo.1.min(r));
            hi = (hi.0.max(c), hi.1.max(r));
        }
        u64::from(hi.0 - lo.0 + 1) * u64::from(hi.1 - lo.1 + 1)
    }
    fn region(grid: &Grid, edge: &[Point], figs: &[Figure], acc: &mut (u64, u64, u64)) {
        let cells = box_cells(grid, edge);
        let n = figs.len() as u64;
        acc.0 = acc
            .0
            .saturating_add(cells.saturating_mul(BYTES_PER_FIGURE_CELL * n + BYTES_PER_REGION_CELL));
        acc.1 += n;
        acc.2 = acc.2.saturating_add(cells);
        for f in figs.iter().filter(|f| f.kind == FigureKind::Closed) {
            region(grid, &f.points, &f.figures, acc);
        }
    }
    // The heightmap, and with detail its noise, gates and the terrain before it; with erosion
    // the terrain before it and two f64 windows as large as the grid (a full rebuild's).
    let per_cell =
        if doc.terrain.detail.is_some() { 16 } else { 4 } + if doc.terrain.erosion.is_some() { 20 } else { 0 };
    let mut acc = (per_cell * doc.grid.cells() as u64, 0, 0);
    for r in &doc.regions {
        region(&doc.grid, &r.boundary, &r.figures, &mut acc);
    }
    acc
}

/// Checks that the terrain engine's memory for `doc` ([`engine_bytes`]) is within
/// [`MAX_ENGINE_BYTES`], before anything allocates it.
pub fn memory(doc: &Document) -> Result<(), ValidationError> {
    let (bytes, figures, cells) = engine_bytes(doc);
    if bytes > MAX_ENGINE_BYTES {
        return Err(ValidationError::new(
            "regions",
            Defect::TooLarge {
                bytes,
                figures,
                cells,
                max: MAX_ENGINE_BYTES,
            },
        ));
    }
    Ok(())
}

/// Checks a figure's height: finite and within ±[`MAX_HEIGHT`] metres.
pub fn height(v: f64, path: impl Fn() -> String) -> Result<(), ValidationError> {
    finite(v, &path)?;
    if v.abs() > MAX_HEIGHT {
        return Err(ValidationError::new(path(), Defect::HeightRange(v)));
    }
    Ok(())
}

/// Checks a figure's slope: finite and within ±[`MAX_SLOPE`].
pub fn slope(v: f64, path: impl Fn() -> String) -> Result<(), ValidationError> {
    finite(v, &path)?;
    if v.abs() > MAX_SLOPE {
        return Err(ValidationError::new(path(), Defect::SlopeRange(v)));
    }
    Ok(())
}

/// Checks the grid.
pub fn grid(g: &Grid) -> Result<(), ValidationError> {
    if g.cols == 0 || g.rows == 0 {
        return Err(ValidationError::new("grid", Defect::EmptyGrid));
    }
    if !(MIN_CELL_SIZE..=MAX_CELL_SIZE).contains(&g.cell_size) {
        return Err(ValidationError::new("grid.cell_size", Defect::CellSize(g.cell_size)));
    }
    let cells = u64::from(g.cols) * u64::from(g.rows);
    if cells > MAX_CELLS {
        return Err(ValidationError::new(
            "grid",
            Defect::GridTooLarge { cells, max: MAX_CELLS },
        ));
    }
    Ok(())
}

/// Checks top-level region `index` on its own: its boundary and every figure in it, at any depth.
/// Overlap with the other top-level regions is [`region_overlap`]'s.
pub fn region(grid: &Grid, region: &Region, index: usize) -> Result<(), ValidationError> {
    let path = format!("regions[{index}]");
    ring(
        grid,
        &region.boundary,
        |i| format!("{path}.boundary[{i}]"),
        &format!("{path}.boundary"),
    )?;
    figures(
        grid,
        &region.figures,
        &region.boundary,
        &format!("{path}.boundary"),
        &path,
        1,
    )
}

/// Checks that region `index`'s cells `mask` share no cell with the `others` (index, cells).
pub fn region_overlap<'a>(
    index: usize,
    mask: &Mask,
    others: impl IntoIterator<Item = (usize, &'a Mask)>,
) -> Result<(), ValidationError> {
    for (j, other) in others {
        if j == index {
            continue;
        }
        if let Some(cell) = mask.first_common(other) {
            return Err(ValidationError::new(
                format!("regions[{index}]"),
                Defect::Overlap {
                    other: format!("regions[{j}]"),
                    cell,
                },
            ));
        }
    }
    Ok(())
}

/// Checks the ridgelines and trees (`crate::ridge::layer::skeletons`): at least two points
/// each, finite numbers, trees without cycles and connected, slopes strictly between 0° and
/// 90°, filter parameters up to 64.
pub fn ridges(doc: &Document) -> Result<(), ValidationError> {
    match &doc.ridges {
        Some(r) => crate::ridge::layer::skeletons(r)
            .map(|_| ())
            .map_err(|e| ValidationError::new("ridges", Defect::Ridge(e.to_string()))),
        None => Ok(()),
    }
}

/// Checks every river: at least two control points, all on the grid (a Bézier course stays
/// within its control points' hull, so the course cannot leave the grid), a width, depth, water
/// amount and hardness above 0, a width of at most [`crate::river::MAX_WIDTH_CELLS`] cells (the
/// work per course sample grows with its square), and at most [`crate::river::MAX_ITERATIONS`]
/// iterations.
pub fn rivers(doc: &Document) -> Result<(), ValidationError> {
    for (i, r) in doc.rivers.iter().enumerate() {
        let path = format!("rivers[{i}]");
        if r.points.len() < 2 {
            return Err(ValidationError::new(
                format!("{path}.points"),
                Defect::CourseTooShort(r.points.len()),
            ));
        }
        points(&doc.grid, &r.points, &|k| format!("{path}.points[{k}]"))?;
        for (name, v) in [
            ("width", r.width),
            ("depth", r.depth),
            ("water", r.water),
            ("hardness", r.hardness),
        ] {
            finite(v, || format!("{path}.{name}"))?;
            if v <= 0.0 {
                return Err(ValidationError::new(format!("{path}.{name}"), Defect::NotPositive(v)));
            }
        }
        let max = crate::river::MAX_WIDTH_CELLS * doc.grid.cell_size;
        if r.width > max {
            return Err(ValidationError::new(
                format!("{path}.width"),
                Defect::RiverTooWide { width: r.width, max },
            ));
        }
        if r.iterations > crate::river::MAX_ITERATIONS {
            return Err(ValidationError::new(
                format!("{path}.iterations"),
                Defect::TooManyIterations(r.iterations),
            ));
        }
    }
    Ok(())
}

fn finite(v: f64, path: impl FnOnce() -> String) -> Result<(), ValidationError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ValidationError::new(path(), Defect::NotFinite))
    }
}

/// Every point finite, on the grid, and different from the one before.
fn points(grid: &Grid, pts: &[Point], path: &impl Fn(usize) -> String) -> Result<(), ValidationError> {
    for (i, p) in pts.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(ValidationError::new(path(i), Defect::NotFinite));
        }
        let (w, h) = (grid.width(), grid.height());
        if !(p[0] >= 0.0 && p[0] < w && p[1] >= 0.0 && p[1] < h) {
            let defect = Defect::OutsideGrid {
                x: p[0],
                y: p[1],
                width: w,
                height: h,
            };
            return Err(ValidationError::new(path(i), defect));
        }
        if i > 0 && pts[i - 1] == *p {
            return Err(ValidationError::new(path(i), Defect::RepeatedPoint));
        }
    }
    Ok(())
}

/// The segments `pts[i] pts[i + 1]` of a polyline in a grid of square buckets, for finding the
/// segments near another in time linear in the number of segments (for drawn curves, whose
/// segments are of similar length).
///
/// The bucket side `h` is the mean segment length. A segment is represented by sample points no
/// more than `h/3` apart, its ends included, each in the bucket holding it. A point common to two
/// segments lies within `h/6` of a sample of each, so those samples are at most `h/3` apart and
/// their buckets are equal or neighbours (also after rounding, which is far smaller than `h`):
/// looking up the 3 × 3 buckets around each sample of one segment finds every segment that can
/// touch it. A segment has at most `3·len/h + 2` samples, so the samples of a curve number at most
/// `5n`; a segment `k` times longer than the mean costs `k` times more, not `n`.
pub(crate) struct SegmentIndex<'a> {
    pts: &'a [Point],
    origin: DVec2,
    h: f64,
    buckets: HashMap<(i64, i64), Vec<u32>>,
    /// The query a segment was last found by, to report each candidate once.
    seen: Vec<u32>,
    query: u32,
}

impl<'a> SegmentIndex<'a> {
    pub(crate) fn new(pts: &'a [Point]) -> SegmentIndex<'a> {
        let n = pts.len().saturating_sub(1);
        let mut origin = DVec2::splat(f64::INFINITY);
        let mut total = 0.0;
        for (i, &p) in pts.iter().enumerate() {
            origin = origin.min(DVec2::from(p));
            if i > 0 {
                total += geometry::distance(pts[i - 1], p);
            }
        }
        let mean = total / n.max(1) as f64;
        // Points are on the grid, so finite; a curve of one repeated point has no length.
        let h = if mean.is_finite() && mean > 0.0 { mean } else { 1.0 };
        let mut index = SegmentIndex {
            pts,
            origin,
            h,
            buckets: HashMap::new(),
            seen: vec![0; n],
            query: 0,
        };
        let mut cells = Vec::new();
        for i in 0..n {
            cells.clear();
            index.samples(pts[i], pts[i + 1], &mut cells);
            for &cell in &cells {
                let list = index.buckets.entry(cell).or_default();
                if list.last() != Some(&(i as u32)) {
                    list.push(i as u32);
                }
            }
        }
        index
    }

    /// The buckets of the samples of segment `a b` (consecutive repeats removed).
    fn samples(&self, a: Point, b: Point, out: &mut Vec<(i64, i64)>) {
        let (a, b) = (DVec2::from(a), DVec2::from(b));
        let steps = (3.0 * a.distance(b) / self.h).ceil().clamp(1.0, 1e9) as u64;
        for k in 0..=steps {
            let p = a.lerp(b, k as f64 / steps as f64);
            let q = (p - self.origin) / self.h;
            // `as` saturates: a point far outside the curve's box lands in an edge bucket, which
            // only adds candidates.
            let cell = (q.x.floor() as i64, q.y.floor() as i64);
            if out.last() != Some(&cell) {
                out.push(cell);
            }
        }
    }

    /// Every indexed segment that may touch segment `a b`, in increasing order (a superset of
    /// those that do).
    pub(crate) fn near(&mut self, a: Point, b: Point, out: &mut Vec<usize>) {
        out.clear();
        self.query += 1;
        let mut cells = Vec::new();
        self.samples(a, b, &mut cells);
        for (x, y) in cells {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let key = (x.saturating_add(dx), y.saturating_add(dy));
                    let Some(list) = self.buckets.get(&key) else { continue };
                    for &i in list {
                        if self.seen[i as usize] != self.query {
                            self.seen[i as usize] = self.query;
                            out.push(i as usize);
                        }
                    }
                }
            }
        }
        out.sort_unstable();
    }

    /// Whether segment `a b` touches any indexed segment.
    fn touches(&mut self, a: Point, b: Point, scratch: &mut Vec<usize>) -> bool {
        self.near(a, b, scratch);
        let pts = self.pts;
        scratch
            .iter()
            .any(|&i| geometry::segments_touch(a, b, pts[i], pts[i + 1]))
    }
}

/// A closed curve's edges in horizontal bands, to locate points against it in time proportional
/// to the edges in the point's band rather than all of them. Each edge is in every band its
/// `y` range meets, so every edge that can hold the point or cross its horizontal ray is in the
/// point's band; [`Bands::locate`] gives exactly [`geometry::locate`]'s answer.
struct Bands<'a> {
    ring: &'a [Point],
    y0: f64,
    height: f64,
    bands: Vec<Vec<u32>>,
}

impl<'a> Bands<'a> {
    fn new(ring: &'a [Point]) -> Bands<'a> {
        let n = ring.len().saturating_sub(1);
        let (mut y0, mut y1, mut rise) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
        for (i, p) in ring.iter().enumerate() {
            y0 = y0.min(p[1]);
            y1 = y1.max(p[1]);
            if i > 0 {
                rise += (p[1] - ring[i - 1][1]).abs();
            }
        }
        // Bands at least as tall as an edge's mean rise, so the edges' band entries number at
        // most about 3n; and at most n + 1 bands.
        let span = (y1 - y0).max(0.0);
        let height = (rise / n.max(1) as f64).max(span / n.max(1) as f64);
        let height = if height.is_finite() && height > 0.0 {
            height
        } else {
            1.0
        };
        let count = ((span / height).floor() as usize).saturating_add(1).min(n + 1);
        let mut bands = Bands {
            ring,
            y0,
            height,
            bands: vec![Vec::new(); count.max(1)],
        };
        for i in 0..n {
            let (a, b) = (ring[i][1], ring[i + 1][1]);
            for band in bands.band(a.min(b))..=bands.band(a.max(b)) {
                bands.bands[band].push(i as u32);
            }
        }
        bands
    }

    /// The band of height `y` (monotonic in `y`, clamped to the bands).
    fn band(&self, y: f64) -> usize {
        let k = ((y - self.y0) / self.height).floor();
        // `as` saturates (NaN to 0), then the clamp keeps it in range.
        (k.max(0.0) as usize).min(self.bands.len() - 1)
    }

    /// [`geometry::locate`] of `p`, through the edges of its band only.
    fn locate(&self, p: Point) -> Side {
        let edges = &self.bands[self.band(p[1])];
        let mut inside = false;
        for &i in edges {
            let (a, b) = (self.ring[i as usize], self.ring[i as usize + 1]);
            if geometry::on_segment(a, b, p) {
                return Side::On;
            }
            // The same half-open test and crossing as geometry::locate, so the same bits.
            let (a, b, q) = (DVec2::from(a), DVec2::from(b), DVec2::from(p));
            if (a.y > q.y) != (b.y > q.y) {
                let x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if q.x < x {
                    inside = !inside;
                }
            }
        }
        if inside { Side::Inside } else { Side::Outside }
    }
}

/// A closed curve: valid points, closed, three or more vertices, not touching itself.
fn ring(grid: &Grid, pts: &[Point], path: impl Fn(usize) -> String, whole: &str) -> Result<(), ValidationError> {
    points(grid, pts, &path)?;
    let (Some(&first), Some(&last)) = (pts.first(), pts.last()) else {
        return Err(ValidationError::new(whole, Defect::CurveTooShort(0)));
    };
    if first != last {
        return Err(ValidationError::new(whole, Defect::OpenCurve { first, last }));
    }
    let n = pts.len() - 1; // segments, = distinct vertices
    if n < 3 {
        return Err(ValidationError::new(whole, Defect::CurveTooShort(n)));
    }
    let seg = |i: usize| (pts[i], pts[i + 1]);
    let mut index = SegmentIndex::new(pts);
    let mut near = Vec::new();
    // The first segment j meeting an earlier one, and the first such i: the order of checking
    // every pair, with only the pairs that can meet looked at.
    for j in 1..n {
        index.near(pts[j], pts[j + 1], &mut near);
        for &i in near.iter().take_while(|&&i| i < j) {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            let meets = if adjacent {
                // Adjacent segments share a vertex; they meet elsewhere only by doubling back.
                let (p, q, r) = if j == i + 1 {
                    (pts[i], pts[j], pts[j + 1])
                } else {
                    (pts[j], pts[0], pts[1])
                };
                let (p, q, r) = (DVec2::from(p), DVec2::from(q), DVec2::from(r));
                geometry::orient(p, q, r) == 0.0 && (p - q).dot(r - q) > 0.0
            } else {
                let ((a, b), (c, d)) = (seg(i), seg(j));
                geometry::segments_touch(a, b, c, d)
            };
            if meets {
                return Err(ValidationError::new(path(j), Defect::SelfIntersecting(i)));
            }
        }
    }
    Ok(())
}

/// A region's edge, indexed for the figures inside it.
struct Edge<'a> {
    path: &'a str,
    segments: SegmentIndex<'a>,
    bands: Bands<'a>,
}

/// The figures of one region, bounded by `edge` (named `edge_path`), with paths under `parent`,
/// at nesting `depth` (1 for a top-level region's figures).
fn figures(
    grid: &Grid,
    figs: &[Figure],
    edge: &[Point],
    edge_path: &str,
    parent: &str,
    depth: usize,
) -> Result<(), ValidationError> {
    if !figs.is_empty() && depth > MAX_DEPTH {
        return Err(ValidationError::new(
            format!("{parent}.figures[0]"),
            Defect::TooDeep(depth),
        ));
    }
    let mut edge = Edge {
        path: edge_path,
        segments: SegmentIndex::new(edge),
        bands: Bands::new(edge),
    };
    for (k, f) in figs.iter().enumerate() {
        figure(grid, f, &mut edge, &format!("{parent}.figures[{k}]"), depth)?;
    }
    // Sibling closed figures bound nested regions, which must not share cells.
    let closed: Vec<(usize, Mask)> = figs
        .iter()
        .enumerate()
        .filter(|(_, f)| f.kind == FigureKind::Closed)
        .map(|(k, f)| (k, cells::closed_mask(grid, &f.points)))
        .collect();
    for (a, (ka, ma)) in closed.iter().enumerate() {
        for (kb, mb) in &closed[..a] {
            if let Some(cell) = ma.first_common(mb) {
                return Err(ValidationError::new(
                    format!("{parent}.figures[{ka}]"),
                    Defect::Overlap {
                        other: format!("{parent}.figures[{kb}]"),
                        cell,
                    },
                ));
            }
        }
    }
    Ok(())
}

fn figure(grid: &Grid, f: &Figure, edge: &mut Edge<'_>, path: &str, depth: usize) -> Result<(), ValidationError> {
    height(f.height, || format!("{path}.height"))?;
    slope(f.slope, || format!("{path}.slope"))?;
    let point_path = |i: usize| format!("{path}.points[{i}]");
    match f.kind {
        FigureKind::Point => {
            points(grid, &f.points, &point_path)?;
            if f.points.len() != 1 {
                return Err(ValidationError::new(
                    format!("{path}.points"),
                    Defect::PointCount(f.points.len()),
                ));
            }
        }
        FigureKind::Polyline => {
            points(grid, &f.points, &point_path)?;
            if f.points.len() < 2 {
                let defect = Defect::PolylineTooShort(f.points.len());
                return Err(ValidationError::new(format!("{path}.points"), defect));
            }
        }
        FigureKind::Closed => ring(grid, &f.points, point_path, &format!("{path}.points"))?,
    }
    let mut scratch = Vec::new();
    for (i, &p) in f.points.iter().enumerate() {
        match edge.bands.locate(p) {
            Side::Inside => {}
            Side::On => {
                return Err(ValidationError::new(
                    point_path(i),
                    Defect::OnRegionEdge(edge.path.into()),
                ));
            }
            Side::Outside => {
                return Err(ValidationError::new(
                    point_path(i),
                    Defect::OutsideRegion(edge.path.into()),
                ));
            }
        }
        if i > 0 && edge.segments.touches(f.points[i - 1], p, &mut scratch) {
            return Err(ValidationError::new(
                point_path(i),
                Defect::CrossesRegionEdge(edge.path.into()),
            ));
        }
    }
    if !f.figures.is_empty() {
        if f.kind != FigureKind::Closed {
            return Err(ValidationError::new(
                format!("{path}.figures"),
                Defect::NestedInOpenFigure(f.kind.name()),
            ));
        }
        figures(grid, &f.figures, &f.points, &format!("{path}.points"), path, depth + 1)?;
    }
    Ok(())
}

/// Checks every tree: on the grid, a height in (0, [`crate::trees::MAX_HEIGHT`]] m, a known
/// preset or its own maps ([`species`]), and its wind (`wind`).
pub fn trees(doc: &Document) -> Result<(), ValidationError> {
    for (i, t) in doc.trees.iter().enumerate() {
        let path = format!("trees[{i}]");
        points(&doc.grid, &[t.at], &|_| format!("{path}.at"))?;
        tree_height(t.height, || format!("{path}.height"))?;
        match (&t.preset, &t.maps) {
            (Some(_), Some(_)) => return Err(ValidationError::new(path, Defect::PresetAndMaps)),
            (Some(p), None) => preset(p, || format!("{path}.preset"))?,
            (None, Some(maps)) => species(maps, &format!("{path}.maps"))?,
            (None, None) => {}
        }
        if let Some(w) = &t.wind {
            wind(w, &format!("{path}.wind"))?;
        }
    }
    Ok(())
}

/// Checks every grove: its region (a closed curve on the grid), a density above 0 with at most
/// [`crate::trees::grove::MAX_TREES`] expected trees and a sampling image of at most
/// [`crate::trees::grove::MAX_PIXELS`] pixels, known presets with weights above 0, a height in
/// (0, [`crate::trees::MAX_HEIGHT`]] m, and its wind.
pub fn groves(doc: &Document) -> Result<(), ValidationError> {
    use crate::trees::grove;
    for (i, g) in doc.groves.iter().enumerate() {
        let path = format!("groves[{i}]");
        ring(
            &doc.grid,
            &g.region,
            |k| format!("{path}.region[{k}]"),
            &format!("{path}.region"),
        )?;
        finite(g.density, || format!("{path}.density"))?;
        if g.density <= 0.0 {
            return Err(ValidationError::new(
                format!("{path}.density"),
                Defect::NotPositive(g.density),
            ));
        }
        let area = grove::area(&g.region);
        let expected = g.density / 10_000.0 * area;
        if expected > grove::MAX_TREES {
            let defect = Defect::GroveTooDense {
                density: g.density,
                area,
                trees: expected.round(),
                max: grove::MAX_TREES,
            };
            return Err(ValidationError::new(format!("{path}.density"), defect));
        }
        let (_, width, height) = grove::image(g);
        if u64::from(width) * u64::from(height) > grove::MAX_PIXELS {
            let defect = Defect::GroveTooLarge {
                width,
                height,
                max: grove::MAX_PIXELS,
            };
            return Err(ValidationError::new(format!("{path}.density"), defect));
        }
        for (k, m) in g.mix.iter().enumerate() {
            preset(&m.preset, || format!("{path}.mix[{k}].preset"))?;
            finite(m.weight, || format!("{path}.mix[{k}].weight"))?;
            if m.weight <= 0.0 {
                return Err(ValidationError::new(
                    format!("{path}.mix[{k}].weight"),
                    Defect::NotPositive(m.weight),
                ));
            }
        }
        tree_height(g.height, || format!("{path}.height"))?;
        if let Some(w) = &g.wind {
            wind(w, &format!("{path}.wind"))?;
        }
    }
    Ok(())
}

fn tree_height(h: f64, path: impl Fn() -> String) -> Result<(), ValidationError> {
    finite(h, &path)?;
    if h <= 0.0 || h > crate::trees::MAX_HEIGHT {
        return Err(ValidationError::new(path(), Defect::TreeHeight(h)));
    }
    Ok(())
}

fn preset(name: &str, path: impl Fn() -> String) -> Result<(), ValidationError> {
    match crate::trees::Preset::named(name) {
        Some(_) => Ok(()),
        None => Err(ValidationError::new(path(), Defect::UnknownPreset(name.to_owned()))),
    }
}

/// Checks a tree's own IFS maps (`path` names the list): 1 to
/// [`crate::trees::species::MAX_MAPS`] maps, finite numbers, `0 ≤ y ≤ 1`, `0 < s < 1` (a
/// contraction), and at most [`crate::trees::nodes::MAX_NODES`] branches down to 2 % of the
/// tree's height.
pub fn species(maps: &[crate::document::IfsMap], path: &str) -> Result<(), ValidationError> {
    use crate::trees::{Species, nodes, species::MAX_MAPS};
    if maps.is_empty() || maps.len() > MAX_MAPS {
        return Err(ValidationError::new(path, Defect::MapCount(maps.len())));
    }
    for (k, m) in maps.iter().enumerate() {
        for (name, v) in [("y", m.y), ("s", m.s), ("theta_z", m.theta_z), ("theta_y", m.theta_y)] {
            finite(v, || format!("{path}[{k}].{name}"))?;
        }
        if !(0.0..=1.0).contains(&m.y) {
            let defect = Defect::Coefficient {
                value: m.y,
                min: 0.0,
                max: 1.0,
            };
            return Err(ValidationError::new(format!("{path}[{k}].y"), defect));
        }
        if m.s.abs() >= 1.0 {
            return Err(ValidationError::new(
                format!("{path}[{k}].s"),
                Defect::NotContracting(m.s.abs()),
            ));
        }
        if m.s <= 0.0 {
            return Err(ValidationError::new(format!("{path}[{k}].s"), Defect::NotPositive(m.s)));
        }
    }
    let sp = Species { maps: maps.to_vec() };
    if nodes::count_nodes(&sp, nodes::STOP, nodes::MAX_NODES).is_none() {
        return Err(ValidationError::new(path, Defect::TooManyBranches));
    }
    Ok(())
}

/// Checks wind: a finite direction, at least one generation, amplitudes and rest leans within
/// ±[`crate::trees::wind::MAX_LEAN`]°, frequencies from 0 to [`crate::trees::wind::MAX_FREQUENCY`] Hz.
fn wind(w: &crate::document::Wind, path: &str) -> Result<(), ValidationError> {
    use crate::trees::wind::{MAX_FREQUENCY, MAX_LEAN};
    finite(w.direction, || format!("{path}.direction"))?;
    if w.generations.is_empty() {
        return Err(ValidationError::new(
            format!("{path}.generations"),
            Defect::NoGenerations,
        ));
    }
    for (g, s) in w.generations.iter().enumerate() {
        for (name, v, min, max) in [
            ("amplitude", s.amplitude, -MAX_LEAN, MAX_LEAN),
            ("rest", s.rest, -MAX_LEAN, MAX_LEAN),
            ("frequency", s.frequency, 0.0, MAX_FREQUENCY),
        ] {
            let at = || format!("{path}.generations[{g}].{name}");
            finite(v, at)?;
            if !(min..=max).contains(&v) {
                return Err(ValidationError::new(at(), Defect::Coefficient { value: v, min, max }));
            }
        }
    }
    Ok(())
}
