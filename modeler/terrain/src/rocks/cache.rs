//! A document's rock fields, scattered once and stood on the terrain as often as it changes.
//!
//! A field's rocks depend on everything in it but `at` (its outline, cell size, layers, seed),
//! so [`Rocks::update`] scatters again only the fields whose recipe changed — an added field, a
//! new density or size — and keeps the others, wherever they moved. Standing them on the ground
//! ([`Rocks::seated`]) is the cheap part, done whenever the terrain or a position changes: each
//! vertex takes the terrain's height under it ([`super::place`]).

use std::sync::Arc;

use crate::document::{Document, RockField};
use crate::export::Mesh;
use crate::heightmap::Heightmap;

use super::field::{self, Image};
use super::place::{self, Flat, Placement};
use super::{Scatter, scatter};

/// One field's rocks.
#[derive(Debug, Clone)]
pub struct Field {
    /// The field as scattered (its `at` is where it was then; the rocks do not depend on it).
    pub field: RockField,
    /// Its image.
    pub image: Image,
    /// Its rocks in field coordinates (shared: scattering is the expensive part).
    pub scatter: Arc<Scatter>,
    /// The same, flattened for seating.
    pub flat: Arc<Flat>,
}

/// The rock fields of a document.
#[derive(Debug, Clone, Default)]
pub struct Rocks {
    fields: Vec<Field>,
}

fn same_recipe(a: &RockField, b: &RockField) -> bool {
    a.outline == b.outline && a.cell_size == b.cell_size && a.layers == b.layers && a.seed == b.seed
}

impl Rocks {
    /// The rocks of `doc` (valid: its fields have been checked).
    pub fn of(doc: &Document) -> Rocks {
        let mut r = Rocks::default();
        r.update(doc);
        r
    }

    /// Follows `doc`: scatters the fields whose recipe is new, keeps the rest. Returns how many
    /// fields were scattered.
    pub fn update(&mut self, doc: &Document) -> usize {
        let mut old: Vec<Option<Field>> = std::mem::take(&mut self.fields).into_iter().map(Some).collect();
        let mut scattered = 0;
        for f in &doc.rocks {
            let kept = old
                .iter_mut()
                .find(|o| o.as_ref().is_some_and(|o| same_recipe(&o.field, f)))
                .and_then(Option::take);
            let entry = match kept {
                Some(mut e) => {
                    e.field.at = f.at;
                    e
                }
                None => {
                    scattered += 1;
                    let image = field::image(f);
                    let recipe = field::recipe(f, image.width, image.height);
                    // A valid document's recipes are valid; an invalid one gives no rocks.
                    let s = scatter(&recipe, Some(&image.inside)).unwrap_or_else(|_| Scatter {
                        width: image.width,
                        height: image.height,
                        field_pixels: 0,
                        diagrams: Vec::new(),
                        rocks: Default::default(),
                        timing: Default::default(),
                    });
                    Field {
                        field: f.clone(),
                        image,
                        flat: Arc::new(Flat::of(&s)),
                        scatter: Arc::new(s),
                    }
                }
            };
            self.fields.push(entry);
        }
        scattered
    }

    /// The fields, in the document's order.
    pub fn fields(&self) -> &[Field] {
        &self.fields
    }

    /// Each field's rocks standing on `map`, as meshes named `rocks N` in the exports' frame.
    pub fn seated(&self, map: &Heightmap) -> Vec<(String, Mesh)> {
        let g = place::ground(map);
        let ground = g.surface();
        self.fields
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let at = Placement {
                    origin: [f.field.at[0] + f.image.origin[0], f.field.at[1] + f.image.origin[1]],
                    cell_size: f.field.cell_size,
                };
                (format!("rocks {i}"), f.flat.seat(at, &ground))
            })
            .collect()
    }
}

/// A document's rocks standing on its terrain, kept up to date edit by edit: the editor's
/// (`Editor::rocks`). After each change the fields whose recipe changed are scattered again and
/// every field is re-seated in place (the terrain may have changed under any of them).
#[derive(Debug, Clone, Default)]
pub struct Seated {
    rocks: Rocks,
    /// Per mesh, the rocks and the place it was seated with.
    seated_as: Vec<Option<(Arc<Flat>, Placement)>>,
    /// Per mesh, where its vertices read the heightmap (found again only when the field moves).
    samples: Vec<place::Samples>,
    /// Shared with the pictures being drawn; copied on write only while one holds it.
    meshes: Arc<Vec<(String, Mesh)>>,
}

impl Seated {
    /// The rocks of `doc` on `map`.
    pub fn of(doc: &Document, map: &Heightmap) -> Seated {
        let mut s = Seated::default();
        s.follow(doc, map, None);
        s
    }

    /// Brings the rocks up to date with `doc` and `map`, whose heights changed in `changed` (grid
    /// cells `(first column, first row, columns, rows)`, the engine's changed rectangle; `None`:
    /// anywhere). A field whose rocks and place are as they were and whose ground is outside
    /// `changed` is left as it is. (A plain tuple, not the engine's type: the engine's validation
    /// knows rock fields, so rocks do not import the engine.)
    pub fn follow(&mut self, doc: &Document, map: &Heightmap, changed: Option<(u32, u32, u32, u32)>) {
        if doc.rocks.is_empty() && self.meshes.is_empty() {
            return;
        }
        self.rocks.update(doc);
        let n = self.rocks.fields.len();
        self.seated_as.resize(n, None);
        self.samples.resize(n, place::Samples::default());
        let s = map.cell_size();
        let placements: Vec<Placement> = self
            .rocks
            .fields
            .iter()
            .map(|f| Placement {
                origin: [f.field.at[0] + f.image.origin[0], f.field.at[1] + f.image.origin[1]],
                cell_size: f.field.cell_size,
            })
            .collect();
        let due: Vec<bool> = self
            .rocks
            .fields
            .iter()
            .zip(&placements)
            .enumerate()
            .map(|(i, (f, at))| {
                let same = self.seated_as[i]
                    .as_ref()
                    .is_some_and(|(flat, was)| Arc::ptr_eq(flat, &f.flat) && was == at);
                // The grid cells whose heights the field's ground reads (one more each side
                // for the interpolation).
                let touched = changed.is_none_or(|(rc0, rr0, rw, rh)| {
                    let w = f64::from(f.image.width) * at.cell_size;
                    let h = f64::from(f.image.height) * at.cell_size;
                    let (c0, r0) = ((at.origin[0] / s).floor() - 1.0, (at.origin[1] / s).floor() - 1.0);
                    let (c1, r1) = (
                        ((at.origin[0] + w) / s).ceil() + 1.0,
                        ((at.origin[1] + h) / s).ceil() + 1.0,
                    );
                    rw > 0
                        && rh > 0
                        && c0 < f64::from(rc0 + rw)
                        && f64::from(rc0) < c1
                        && r0 < f64::from(rr0 + rh)
                        && f64::from(rr0) < r1
                });
                !same || touched || i >= self.meshes.len()
            })
            .collect();
        if due.iter().any(|&d| d) || self.meshes.len() > n {
            let meshes = Arc::make_mut(&mut self.meshes);
            meshes.truncate(n);
            for (i, f) in self.rocks.fields.iter().enumerate() {
                if !due[i] {
                    continue;
                }
                if i >= meshes.len() {
                    meshes.push((format!("rocks {i}"), Mesh::default()));
                }
                let mesh = &mut meshes[i].1;
                // The mesh holds this field's triangles when these rocks were seated into it
                // before (comparing the indices instead read 16 MB for fig. 1 at every edit).
                let same_rocks = self.seated_as[i]
                    .as_ref()
                    .is_some_and(|(flat, _)| Arc::ptr_eq(flat, &f.flat));
                if !same_rocks {
                    *mesh = Mesh::default();
                    self.samples[i].clear();
                }
                // Only the rocks over the changed cells, when only the terrain changed.
                // Beyond the grid's edge the ground is held at the outer cells' heights: a change
                // there reaches out without end.
                let within = changed.filter(|_| same_rocks).map(|cells| map.extent_of(cells));
                f.flat
                    .seat_on_within(placements[i], map, &mut self.samples[i], mesh, within);
                self.seated_as[i] = Some((Arc::clone(&f.flat), placements[i]));
            }
        }
        self.seated_as.truncate(n);
        self.samples.truncate(n);
    }

    /// Each field's rocks as a mesh named `rocks N`, in the exports' frame.
    pub fn meshes(&self) -> &[(String, Mesh)] {
        &self.meshes
    }

    /// The same, shared (for a picture that outlives the next edit).
    pub fn shared(&self) -> Arc<Vec<(String, Mesh)>> {
        Arc::clone(&self.meshes)
    }

    /// The fields as scattered.
    pub fn fields(&self) -> &[Field] {
        self.rocks.fields()
    }
}
