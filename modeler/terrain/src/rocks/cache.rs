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
                        rocks: Vec::new(),
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
        let ground = place::ground(map);
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
