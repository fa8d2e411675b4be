//! Rocks of mixed sizes scattered on the ground (seed 001, Sakurai & Miyata 2010).
//!
//! A rock field is an image of `width × height` cells (pixels). For each radius r of its
//! layers: Poisson-disk seeds no two within r ([`poisson`]), their Voronoi diagram
//! ([`voronoi`]); then the diagrams, largest mean cell first, give up cells at random, each kept
//! only if none of its pixels is taken yet, until the layer's area fraction or count
//! ([`select`]); and each kept cell becomes a rock mesh ([`shape`]). Gaps between cells of
//! different sizes stay, as in the seed (it rejected snapping them shut as unnatural).
//!
//! [`scatter`] is the whole method on a plain image (the `penmodel rocks` command); a document's
//! rock field passes the mask of its outline, so only cells wholly inside become rocks. The same
//! configuration and seed give the same rocks on any machine and any number of threads: every
//! random draw comes from a ChaCha8 stream named by the seed, the layer and the cell.
//!
//! Stages run on all cores where they are independent: the diagrams' seeds and pixel labels one
//! diagram per thread (the labels in bands of rows), the selected cells' polygons and meshes in
//! blocks of rocks ([`list`]). The selection is sequential by nature (each diagram sees what the
//! larger ones took), so the blocks of a diagram are made while the next is being selected.

pub mod cache;
pub mod delaunay;
pub mod field;
pub mod list;
pub mod place;
pub mod poisson;
mod predicates;
pub mod select;
pub mod shape;
pub mod top_view;
pub mod voronoi;

use std::sync::{Arc, Mutex};
use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use thiserror::Error;

pub use list::{Rock, RockList};
pub use select::Goal;
pub use shape::{RockMesh, Shape};

/// The largest field image, in pixels (as many as the largest terrain grid).
pub const MAX_PIXELS: u64 = 1 << 24;

/// How a layer's seeds are thrown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sampler {
    /// Every pixel tried once in random order: maximal (see [`poisson`]). The default.
    Saturate,
    /// The seed's darts: `A·fill / (π(0.5r)²)` throws (eq. 1; the seed's `fill` is 0.7).
    Darts {
        /// The disk filling rate `c_d`.
        fill: f64,
    },
}

/// When a layer's diagram stops giving up cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Amount {
    /// A fraction of the field's area `A_s` (0 to 1).
    Fraction(f64),
    /// A number of rocks.
    Count(u32),
}

/// One diagram: a radius, how much of it to keep, and its rocks' shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layer {
    /// The Poisson-disk radius r in cells (no two seeds within r).
    pub radius: f64,
    /// How much the diagram may take.
    pub amount: Amount,
    /// Eq. 2 and 3.
    pub shape: Shape,
}

/// A rock field's recipe.
#[derive(Debug, Clone, PartialEq)]
pub struct Recipe {
    /// Field image width in cells.
    pub width: u32,
    /// Field image height in cells.
    pub height: u32,
    /// The diagrams.
    pub layers: Vec<Layer>,
    /// The random seed.
    pub seed: u64,
    /// How seeds are thrown.
    pub sampler: Sampler,
}

impl Recipe {
    /// The seed's fig. 1 (table 1) on a `width × height` field: r = 9, 3, 1 taking 20 %, 24 %
    /// and 56 % of the area, with its per-diagram shape coefficients.
    pub fn figure_1(width: u32, height: u32, seed: u64) -> Recipe {
        let layer = |radius, fraction, widths, heights| Layer {
            radius,
            amount: Amount::Fraction(fraction),
            shape: Shape { widths, heights },
        };
        Recipe {
            width,
            height,
            layers: vec![
                layer(9.0, 0.2, [0.0, 0.3, 0.3], [0.3, 0.3, 0.1]),
                layer(3.0, 0.24, [0.0, 0.3, 0.1], [0.3, 0.3, 0.1]),
                layer(1.0, 0.56, [0.1, 0.1, 0.1], [0.3, 0.0, 0.1]),
            ],
            seed,
            sampler: Sampler::Saturate,
        }
    }
}

/// Why a recipe cannot be scattered. Each names the layer (`layers[i]`) or the field.
#[allow(missing_docs)] // fields named for what they hold.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RecipeError {
    #[error("the field is {width} × {height} cells; it needs at least 1 × 1 and at most {max} cells", max = MAX_PIXELS)]
    FieldSize { width: u32, height: u32 },
    #[error("there are no layers; give at least one radius")]
    NoLayers,
    #[error("layers[{layer}].radius: {radius} must be a number above 0")]
    RadiusNotPositive { layer: usize, radius: f64 },
    #[error("layers[{layer}].radius: {radius} is larger than the {width} × {height} field")]
    RadiusTooLarge {
        layer: usize,
        radius: f64,
        width: u32,
        height: u32,
    },
    #[error("layers[{layer}].fraction: {fraction} must be from 0 to 1")]
    FractionRange { layer: usize, fraction: f64 },
    #[error("the fractions add up to {sum}, more than 1")]
    FractionsOverOne { sum: f64 },
    #[error("layers[{layer}].shape.{what}: {value} must be from {min} to {max}")]
    ShapeRange {
        layer: usize,
        what: &'static str,
        value: f64,
        min: f64,
        max: f64,
    },
    #[error("darts fill rate {0} must be above 0 and at most 10")]
    Fill(f64),
}

/// The range of the eq. 2 coefficients (× r); eq. 3's are 0 to this (rocks stand up).
pub const MAX_COEFFICIENT: f64 = 10.0;

impl Recipe {
    /// Checks the recipe; errors name the layer and field.
    pub fn check(&self) -> Result<(), RecipeError> {
        let (width, height) = (self.width, self.height);
        if width == 0 || height == 0 || u64::from(width) * u64::from(height) > MAX_PIXELS {
            return Err(RecipeError::FieldSize { width, height });
        }
        if self.layers.is_empty() {
            return Err(RecipeError::NoLayers);
        }
        let mut sum = 0.0;
        for (layer, l) in self.layers.iter().enumerate() {
            let radius = l.radius;
            if !(radius > 0.0 && radius.is_finite()) {
                return Err(RecipeError::RadiusNotPositive { layer, radius });
            }
            if radius > f64::from(width.min(height)) {
                return Err(RecipeError::RadiusTooLarge {
                    layer,
                    radius,
                    width,
                    height,
                });
            }
            if let Amount::Fraction(fraction) = l.amount {
                if !(0.0..=1.0).contains(&fraction) {
                    return Err(RecipeError::FractionRange { layer, fraction });
                }
                sum += fraction;
            }
            let names = ["c_w1", "c_w2", "c_w3", "c_h1", "c_h2", "c_h3"];
            let values = l.shape.widths.iter().chain(&l.shape.heights);
            for (i, (&value, what)) in values.zip(names).enumerate() {
                let min = if i < 3 { -MAX_COEFFICIENT } else { 0.0 };
                if !(min..=MAX_COEFFICIENT).contains(&value) {
                    return Err(RecipeError::ShapeRange {
                        layer,
                        what,
                        value,
                        min,
                        max: MAX_COEFFICIENT,
                    });
                }
            }
        }
        // A little slack for decimal fractions such as 0.2 + 0.24 + 0.56.
        if sum > 1.0 + 1e-9 {
            return Err(RecipeError::FractionsOverOne { sum });
        }
        if let Sampler::Darts { fill } = self.sampler
            && !(fill > 0.0 && fill <= 10.0)
        {
            return Err(RecipeError::Fill(fill));
        }
        Ok(())
    }
}

/// One diagram's result.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagram {
    /// Its radius.
    pub radius: f64,
    /// The seeds, pixel centres in field coordinates (`x + ½, y + ½`).
    pub seeds: Vec<[f64; 2]>,
    /// Its place in the selection order (0 first: the largest mean cell).
    pub order: usize,
    /// The kept cells, as seed indices, in the order drawn.
    pub cells: Vec<u32>,
    /// Pixels its kept cells cover.
    pub pixels: usize,
    /// Cells drawn before it stopped.
    pub tried: usize,
    /// Whether it reached its amount (false when the cells ran out first).
    pub reached: bool,
}

/// Milliseconds per stage (summed over diagrams where they run one after another).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Timing {
    /// Poisson-disk seeds and pixel labels of all diagrams (in parallel).
    pub seeds_and_diagrams: f64,
    /// Of which the seeds alone, per diagram summed (CPU time across threads).
    pub seeds: f64,
    /// Of which the Voronoi labels and their grouping by cell, per diagram summed (CPU time
    /// across threads).
    pub diagrams: f64,
    /// Exclusive selection (one thread).
    pub selection: f64,
    /// Polygons of the kept cells, CPU time summed over the blocks of rocks (made in parallel,
    /// during and after the selection).
    pub polygons: f64,
    /// The rocks' meshes, CPU time summed over the blocks of rocks, as `polygons`.
    pub meshes: f64,
    /// Everything.
    pub total: f64,
}

/// A scattered field.
#[derive(Debug, Clone, PartialEq)]
pub struct Scatter {
    /// Field width in cells.
    pub width: u32,
    /// Field height in cells.
    pub height: u32,
    /// Pixels of the field (inside the mask), the area fractions' whole.
    pub field_pixels: usize,
    /// One per layer, in the recipe's order.
    pub diagrams: Vec<Diagram>,
    /// The rocks, diagram by diagram in selection order, each in the order drawn.
    pub rocks: RockList,
    /// Stage times.
    pub timing: Timing,
}

impl Scatter {
    /// The area fraction diagram `d` took.
    pub fn fraction(&self, d: usize) -> f64 {
        self.diagrams[d].pixels as f64 / self.field_pixels.max(1) as f64
    }
}

/// One diagram's seeds, pixels by cell and seed buckets, and what they took (ms).
struct Made {
    centres: Vec<[f64; 2]>,
    cells: voronoi::CellPixels,
    buckets: voronoi::Buckets,
    seeds_ms: f64,
    diagram_ms: f64,
}

/// A diagram's selection: what it took, whether it reached its goal, and its kept cells with
/// their places in the order drawn, sorted by cell.
type Selected = (select::Taken, bool, Arc<Vec<(u32, usize)>>);

/// A block of rocks and the time its polygons and meshes took (ms).
struct MadeBlock {
    block: list::Block,
    polygons_ms: f64,
    meshes_ms: f64,
}

/// The rocks of cells `part` (cell, order drawn) of diagram `i`: their polygons, then meshes.
fn make_block(recipe: &Recipe, made: &Made, i: usize, part: &[(u32, usize)]) -> MadeBlock {
    let (width, height) = (recipe.width, recipe.height);
    let t = Instant::now();
    let mut block = list::Block::with_rocks(part.len());
    for &(cell, _) in part {
        voronoi::cell_polygon(
            &made.centres,
            &made.buckets,
            width,
            height,
            cell as usize,
            &mut block.polygons,
        );
        block.end_polygon();
    }
    let polygons_ms = ms(t);
    let t = Instant::now();
    let corners = block.polygons.len();
    block.added.reserve(corners);
    block.vertices.reserve(2 * corners);
    block.triangles.reserve(3 * corners);
    let layer = &recipe.layers[i];
    // One generator for the block, set to each rock's stream in turn (a copy per rock cost a
    // copy of its buffer).
    let mut rng = ChaCha8Rng::seed_from_u64(recipe.seed);
    for (k, &(cell, _)) in part.iter().enumerate() {
        restream(&mut rng, SHAPE, i, u64::from(cell));
        let list::Block {
            polygons,
            polygon_starts,
            added,
            vertices,
            triangles,
            ..
        } = &mut block;
        let polygon = &polygons[polygon_starts[k] as usize..polygon_starts[k + 1] as usize];
        let out = shape::Out {
            added,
            vertices,
            triangles,
        };
        shape::rock_into(polygon, layer.radius, &layer.shape, &mut rng, out);
        block.end_mesh();
    }
    MadeBlock {
        block,
        polygons_ms,
        meshes_ms: ms(t),
    }
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// A random stream for `purpose` of `layer` (and `cell`) of a field with `seed`.
fn stream(seed: u64, purpose: u64, layer: usize, cell: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    restream(&mut rng, purpose, layer, cell);
    rng
}

/// Sets `rng` (seeded with the field's seed) to the start of the stream of [`stream`]: the same
/// generator as a fresh one, without expanding the seed again for each of tens of thousands of
/// rocks. Back at word 0 its buffer counts as used up, so the stream's first block is made on
/// the first draw, as a fresh generator's is.
fn restream(rng: &mut ChaCha8Rng, purpose: u64, layer: usize, cell: u64) {
    rng.set_word_pos(0);
    rng.set_stream(purpose << 56 | (layer as u64) << 40 | cell);
}

const SEEDS: u64 = 1;
const SELECT: u64 = 2;
const SHAPE: u64 = 3;

/// Runs the method on `recipe`. `inside`, if given, has one flag per pixel (row-major): cells
/// with a pixel outside are never kept, and fractions are of the inside pixels.
pub fn scatter(recipe: &Recipe, inside: Option<&[bool]>) -> Result<Scatter, RecipeError> {
    recipe.check()?;
    let start = Instant::now();
    let (width, height) = (recipe.width, recipe.height);
    let pixels = width as usize * height as usize;
    // The diagrams' seeds are sequential each; the smallest radius (the most seeds, and a
    // pixel order drawn to the end: see `poisson::saturate`) is started first, so that the
    // others run beside it rather than before it.
    let mut by_cost: Vec<usize> = (0..recipe.layers.len()).collect();
    by_cost.sort_by(|&a, &b| recipe.layers[a].radius.total_cmp(&recipe.layers[b].radius));
    let mut made: Vec<(usize, Made)> = by_cost
        .par_iter()
        .map(|&i| {
            let layer = &recipe.layers[i];
            let t = Instant::now();
            let mut rng = stream(recipe.seed, SEEDS, i, 0);
            let seeds = match recipe.sampler {
                Sampler::Saturate => poisson::saturate(width, height, layer.radius, &mut rng),
                Sampler::Darts { fill } => {
                    let throws = poisson::seed_throws(width, height, layer.radius, fill);
                    poisson::darts(width, height, layer.radius, throws, &mut rng)
                }
            };
            // Numbered in pixel order, so the stages after read the image and the seeds in step
            // (painting labels and cutting polygons in random order cost twice the time in
            // cache misses).
            let seeds = poisson::in_pixel_order(&seeds, pixels);
            let seeds_ms = ms(t);
            let t = Instant::now();
            let labels = voronoi::label(width, height, &seeds, layer.radius);
            // Grouped, and the seeds' buckets built, here on the diagram's own thread rather
            // than in the selection, which runs on one.
            let cells = voronoi::CellPixels::of(&labels, seeds.len());
            let centres: Vec<[f64; 2]> = seeds.iter().map(|&p| voronoi::centre(p, width)).collect();
            // Seeds are more than r apart: a bucket of side r holds a few.
            let buckets = voronoi::Buckets::new(&centres, width, height, layer.radius.max(1.0));
            (
                i,
                Made {
                    centres,
                    cells,
                    buckets,
                    seeds_ms,
                    diagram_ms: ms(t),
                },
            )
        })
        .collect();
    made.sort_by_key(|m| m.0);
    let made: Vec<Made> = made.into_iter().map(|m| m.1).collect();
    let mut timing = Timing {
        seeds_and_diagrams: ms(start),
        seeds: made.iter().map(|m| m.seeds_ms).sum(),
        diagrams: made.iter().map(|m| m.diagram_ms).sum(),
        ..Timing::default()
    };

    let mut taken: Vec<bool> = match inside {
        Some(mask) if mask.len() == pixels => mask.iter().map(|&i| !i).collect(),
        _ => vec![false; pixels],
    };
    let field_pixels = taken.iter().filter(|&&t| !t).count();
    // Largest mean cell first: the fewest seeds; ties keep the recipe's order.
    let mut order: Vec<usize> = (0..recipe.layers.len()).collect();
    order.sort_by_key(|&i| made[i].centres.len());
    // The selection runs on this thread, diagram after diagram; each diagram's kept cells are
    // handed to the other threads as soon as it is done, in blocks of whole rocks (a fixed
    // split: the same blocks on any number of threads), each block's polygons cut and then its
    // meshes made — so the rocks of the larger diagrams are made while the smaller ones are
    // still being selected. Within a diagram the cells are cut in seed order (pixel order:
    // neighbours near in memory), and listed in the order drawn at the end.
    let made_blocks: Vec<Mutex<Vec<(usize, MadeBlock)>>> = order.iter().map(|_| Mutex::default()).collect();
    let mut selected: Vec<Option<Selected>> = vec![None; recipe.layers.len()];
    let mut selection_ms = 0.0;
    {
        let (made, made_blocks) = (&made, &made_blocks);
        rayon::scope(|scope| {
            for (rank, &i) in order.iter().enumerate() {
                let t = Instant::now();
                let goal = match recipe.layers[i].amount {
                    Amount::Fraction(f) => Goal::Pixels((f * field_pixels as f64).ceil() as usize),
                    Amount::Count(c) => Goal::Cells(c as usize),
                };
                let mut rng = stream(recipe.seed, SELECT, i, 0);
                let got = select::select(&made[i].cells, &mut taken, goal, &mut rng);
                let reached = match goal {
                    Goal::Pixels(p) => got.pixels >= p,
                    Goal::Cells(c) => got.cells.len() >= c,
                };
                // By cell through a table of when each was drawn (kept cells are distinct),
                // rather than a sort.
                let mut drawn_at = vec![usize::MAX; made[i].centres.len()];
                for (k, &c) in got.cells.iter().enumerate() {
                    drawn_at[c as usize] = k;
                }
                let by_place: Vec<(u32, usize)> = (0..drawn_at.len() as u32)
                    .zip(drawn_at)
                    .filter(|m| m.1 != usize::MAX)
                    .collect();
                let by_place = Arc::new(by_place);
                selection_ms += ms(t);
                for b in 0..by_place.len().div_ceil(list::BLOCK) {
                    let by_place = Arc::clone(&by_place);
                    scope.spawn(move |_| {
                        let part = &by_place[b * list::BLOCK..((b + 1) * list::BLOCK).min(by_place.len())];
                        let block = make_block(recipe, &made[i], i, part);
                        if let Ok(mut done) = made_blocks[rank].lock() {
                            done.push((b, block));
                        }
                    });
                }
                selected[i] = Some((got, reached, by_place));
            }
        });
    }
    timing.selection = selection_ms;
    // The blocks in order, and the rocks listed in the order drawn.
    let mut blocks: Vec<list::Block> = Vec::new();
    let mut at: Vec<list::At> = Vec::new();
    for (rank, &i) in order.iter().enumerate() {
        let mut done = made_blocks[rank]
            .lock()
            .map(|mut d| std::mem::take(&mut *d))
            .unwrap_or_default();
        done.sort_unstable_by_key(|d| d.0);
        let Some((_, _, by_place)) = &selected[i] else {
            continue;
        };
        let (first_block, first_rock) = (blocks.len(), at.len());
        at.resize(first_rock + by_place.len(), list::At::default());
        for (j, &(cell, drawn)) in by_place.iter().enumerate() {
            at[first_rock + drawn] = list::At {
                diagram: i as u32,
                cell,
                block: (first_block + j / list::BLOCK) as u32,
                index: (j % list::BLOCK) as u32,
            };
        }
        for (_, d) in done {
            timing.polygons += d.polygons_ms;
            timing.meshes += d.meshes_ms;
            blocks.push(d.block);
        }
    }
    let rocks = RockList { at, blocks };
    let diagrams: Vec<Diagram> = made
        .into_iter()
        .zip(selected)
        .enumerate()
        .map(|(i, (m, sel))| {
            let (got, reached, _) = sel.unwrap_or_else(|| {
                (
                    select::Taken {
                        cells: Vec::new(),
                        pixels: 0,
                        tried: 0,
                    },
                    false,
                    Arc::default(),
                )
            });
            Diagram {
                radius: recipe.layers[i].radius,
                seeds: m.centres,
                order: order.iter().position(|&o| o == i).unwrap_or(i),
                cells: got.cells,
                pixels: got.pixels,
                tried: got.tried,
                reached,
            }
        })
        .collect();
    timing.total = ms(start);
    Ok(Scatter {
        width,
        height,
        field_pixels,
        diagrams,
        rocks,
        timing,
    })
}
