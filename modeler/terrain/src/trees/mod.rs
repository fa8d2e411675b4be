//! Fractal trees with level of detail (seed 004, Kuwahara 1996): IFS trees drawn fast by
//! simplifying what the eye cannot resolve. `docs/trees.md` explains the method and constants.
//!
//! The public API, in the order a tree is made and drawn:
//!
//! - [`species`]: [`Species`] (IFS maps [`crate::document::IfsMap`]: `y`, `s`, `θz`, `θy`;
//!   `IfsMap::affine` is `Trans(0,y,0)·Rot_y(θy)·Rot_z(−θz)·Scale(s)`), [`Preset`]
//!   (`table-3.1`, `cypress`, `oak`, `fir`; `Preset::named`, `Preset::ALL`).
//! - [`nodes`]: [`NodeTree::build`] — the full tree as depth-first nodes (transform, scale,
//!   extent, own geometry: hexagonal frusta and rhombus leaves), branches stopping at
//!   [`nodes::STOP`] = 2 % of the height; `NodeTree::subtree(node)` is a node's full group in its
//!   own frame (to render a simplified shape's textures from).
//! - [`lod`]: `NodeTree::draw(q, place, pose, &mut Drawn)` — the depth-first walk at roughness
//!   `Q`: [`Drawn`] holds a coloured [`crate::export::Mesh`] (`colors`: bark and leaf, linear RGB)
//!   and the simplified shapes ([`Impostor`]: node, node frame → world, extent in metres);
//!   [`lod::law`] is the seed's data-volume law.
//! - [`roughness`]: [`Roughness`] — `Q` by distance (`by_distance`), by angle from the gaze
//!   (`by_gaze`, `acuity` = `R(θ)`), both (`choose`).
//! - [`wind`]: [`wind::pose`] — `θ_g = A_g·sin(2π f_g t) + θ0_g` per generation.
//! - [`grove`]: [`grove::trees`] — a grove's trees (Poisson-disk positions, presets, heights).
//! - [`planted`]: [`Forest`] — a document's trees and groves standing on its terrain
//!   (`Editor::trees`), each a [`Standing`] (`place()`: the tree's unit to the world in the
//!   exports' frame; `draw(q, t, &mut Drawn)`).
//! - [`silhouette`] and [`fit`]: orthographic coverage silhouettes (PNG in and out, framing,
//!   normalised cross-correlation) and [`fit::fit`], the seed's reconstruction of a species from
//!   a front and a side silhouette.

pub mod fit;
pub mod grove;
pub mod lod;
pub mod nodes;
pub mod planted;
pub mod roughness;
pub mod shapes;
pub mod silhouette;
pub mod species;
pub mod wind;

/// The tallest tree a document may hold, metres.
pub const MAX_HEIGHT: f64 = 1000.0;

pub use lod::{Drawn, Impostor};
pub use nodes::{Node, NodeTree};
pub use planted::{Forest, Source, Standing};
pub use roughness::Roughness;
pub use species::{Preset, Species};
