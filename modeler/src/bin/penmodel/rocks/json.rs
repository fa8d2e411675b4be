//! The JSON document of docs/rocks.md, streamed: each rock's arrays are written from the
//! scatter's own lists as they are reached. Built as a `serde_json::Value` first, a 72 MB
//! result held 1.44 GB (a boxed value per number; issue 47).

use std::cell::Cell;

use penmodel_terrain::rocks::{Amount, Recipe, Sampler, Scatter};
use serde::ser::{Serialize, Serializer};
use serde_json::{Value, json};

/// The document; its fields in the order they are written.
#[derive(serde::Serialize)]
struct Document<'a> {
    size: [u32; 2],
    seed: Value,
    sampler: Value,
    field_cells: usize,
    diagrams: Seq<Box<dyn Iterator<Item = Diagram<'a>> + 'a>>,
    rocks: Seq<Box<dyn Iterator<Item = Rock<'a>> + 'a>>,
    timing_ms: Value,
}

#[derive(serde::Serialize)]
struct Diagram<'a> {
    radius: f64,
    order: usize,
    goal: Value,
    shape: Value,
    seeds: &'a [[f64; 2]],
    cells_tried: usize,
    reached: bool,
    cells_kept: usize,
    area_cells: usize,
    fraction: f64,
    cells: Seq<Box<dyn Iterator<Item = Kept<'a>> + 'a>>,
}

#[derive(serde::Serialize)]
struct Kept<'a> {
    seed: u32,
    polygon: &'a [[f64; 2]],
}

#[derive(serde::Serialize)]
struct Rock<'a> {
    diagram: usize,
    seed: u32,
    polygon: &'a [[f64; 2]],
    added: &'a [[f64; 2]],
    moved: &'a [[f64; 3]],
    vertices: &'a [[f64; 3]],
    triangles: &'a [[u32; 3]],
}

/// A sequence written from an iterator, once.
struct Seq<I>(Cell<Option<I>>);

impl<I> Seq<I> {
    fn new(i: I) -> Seq<I> {
        Seq(Cell::new(Some(i)))
    }
}

impl<I: Iterator<Item = T>, T: Serialize> Serialize for Seq<I> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0.take() {
            Some(items) => s.collect_seq(items),
            None => Err(serde::ser::Error::custom("a streamed sequence is written once")),
        }
    }
}

/// Writes the document of `s` (made by `recipe`) to `w` as one line of JSON.
pub fn write(recipe: &Recipe, s: &Scatter, w: impl std::io::Write) -> serde_json::Result<()> {
    let diagrams = s.diagrams.iter().enumerate().map(move |(i, d)| {
        let layer = &recipe.layers[i];
        Diagram {
            radius: d.radius,
            order: d.order,
            goal: match layer.amount {
                Amount::Fraction(f) => json!({"fraction": f}),
                Amount::Count(c) => json!({"count": c}),
            },
            shape: json!({"widths": layer.shape.widths, "heights": layer.shape.heights}),
            seeds: &d.seeds,
            cells_tried: d.tried,
            reached: d.reached,
            cells_kept: d.cells.len(),
            area_cells: d.pixels,
            fraction: s.fraction(i),
            cells: Seq::new(Box::new(s.rocks.iter().filter(move |r| r.diagram == i).map(|r| Kept {
                seed: r.cell,
                polygon: r.polygon,
            }))),
        }
    });
    let rocks = s.rocks.iter().map(|r| Rock {
        diagram: r.diagram,
        seed: r.cell,
        polygon: r.polygon,
        added: r.mesh.added,
        moved: &r.mesh.vertices[r.polygon.len()..],
        vertices: r.mesh.vertices,
        triangles: r.mesh.triangles,
    });
    let t = s.timing;
    let doc = Document {
        size: [s.width, s.height],
        seed: json!(recipe.seed),
        sampler: match recipe.sampler {
            Sampler::Saturate => json!("saturate"),
            Sampler::Darts { fill } => json!({"darts": {"fill": fill}}),
        },
        field_cells: s.field_pixels,
        diagrams: Seq::new(Box::new(diagrams)),
        rocks: Seq::new(Box::new(rocks)),
        timing_ms: json!({
            "seeds_and_diagrams": t.seeds_and_diagrams,
            "seeds_cpu": t.seeds,
            "diagrams_cpu": t.diagrams,
            "selection": t.selection,
            "polygons": t.polygons,
            "meshes": t.meshes,
            "total": t.total,
        }),
    };
    let mut w = w;
    serde_json::to_writer(&mut w, &doc)?;
    w.write_all(b"\n").map_err(serde_json::Error::io)
}
