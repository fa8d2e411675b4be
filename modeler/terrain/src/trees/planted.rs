//! A document's trees and groves standing on its terrain: each tree's base is the terrain's
//! height under its trunk ([`crate::rocks::place::ground`], the surface the terrain mesh draws),
//! read again whenever the terrain changes, so trees follow the ground and never change it.
//!
//! The expensive parts are kept across edits: a species' [`NodeTree`] is built once and shared
//! by every tree of it, and a grove's trees are scattered again only when the grove changed.

use std::sync::Arc;

use glam::{DAffine3, DVec3};

use super::grove::{self, GroveTree};
use super::lod::Drawn;
use super::nodes::NodeTree;
use super::species::{Preset, Species};
use super::wind;
use crate::document::{Document, Grove, IfsMap, Point, Tree, Wind};
use crate::heightmap::Heightmap;

/// Where a standing tree comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// `trees[i]`.
    Tree(usize),
    /// Tree `k` of `groves[i]`.
    Grove(usize, usize),
}

/// A tree standing on the terrain.
#[derive(Debug, Clone)]
pub struct Standing {
    /// Which document element it is.
    pub source: Source,
    /// Where its trunk meets the ground, metres.
    pub at: Point,
    /// The ground's height there, metres.
    pub base: f64,
    /// Its height, metres.
    pub height: f64,
    /// Its turn about the trunk, radians (from its seed).
    pub turn: f64,
    /// Its species' full tree (shared).
    pub nodes: Arc<NodeTree>,
    /// Its sway, if any.
    pub wind: Option<Wind>,
}

impl Standing {
    /// The tree's unit to the world (the exports' frame: X = x, Y up, Z = y, metres).
    pub fn place(&self) -> DAffine3 {
        DAffine3::from_translation(DVec3::new(self.at[0], self.base, self.at[1]))
            * DAffine3::from_rotation_y(self.turn)
            * DAffine3::from_scale(DVec3::splat(self.height / self.nodes.height))
    }

    /// Draws the tree at roughness `q` and time `t` seconds (the sway's), appending to `out`.
    pub fn draw(&self, q: f64, t: f64, out: &mut Drawn) {
        let pose = self.wind.as_ref().map(|w| wind::pose(w, t));
        self.nodes.draw(q, &self.place(), pose.as_ref(), out);
    }
}

/// A seed's turn about the trunk, radians in `[0, 2π)` (SplitMix64's finaliser spreads
/// neighbouring seeds).
pub fn turn(seed: u64) -> f64 {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU
}

impl Species {
    /// A document tree's species: its maps, or its preset's (`table-3.1` when it names none or
    /// an unknown one, which validation refuses).
    pub fn of_tree(tree: &Tree) -> Species {
        match &tree.maps {
            Some(maps) => Species { maps: maps.clone() },
            None => Species::preset(
                tree.preset
                    .as_deref()
                    .and_then(Preset::named)
                    .unwrap_or(Preset::Table31),
            ),
        }
    }
}

/// The trees of a document on its terrain, kept up to date edit by edit (the editor's).
#[derive(Debug, Clone, Default)]
pub struct Forest {
    species: Vec<(Vec<IfsMap>, Arc<NodeTree>)>,
    groves: Vec<(Grove, Arc<Vec<GroveTree>>)>,
    /// Shared with the pictures drawn from it, so that a frame takes them without a copy.
    trees: Arc<Vec<Standing>>,
}

/// The node tree of `species` from `built`, building and keeping it the first time.
fn nodes_of(built: &mut Vec<(Vec<IfsMap>, Arc<NodeTree>)>, species: &Species) -> Arc<NodeTree> {
    if let Some((_, n)) = built.iter().find(|(m, _)| *m == species.maps) {
        return Arc::clone(n);
    }
    let n = Arc::new(NodeTree::build(species));
    built.push((species.maps.clone(), Arc::clone(&n)));
    n
}

impl Forest {
    /// The trees of `doc` (valid) on `map`.
    pub fn of(doc: &Document, map: &Heightmap) -> Forest {
        let mut f = Forest::default();
        f.follow(doc, map);
        f
    }

    /// The node tree of `species`, built once.
    pub fn nodes(&mut self, species: &Species) -> Arc<NodeTree> {
        nodes_of(&mut self.species, species)
    }

    /// Brings the trees up to date with `doc` and its terrain `map`: groves that changed are
    /// scattered again, every base height is read again.
    pub fn follow(&mut self, doc: &Document, map: &Heightmap) {
        if doc.trees.is_empty() && doc.groves.is_empty() && self.trees.is_empty() {
            return;
        }
        let mut old = std::mem::take(&mut self.groves);
        for g in &doc.groves {
            let kept = old.iter().position(|(o, _)| o == g).map(|k| old.swap_remove(k));
            let entry = kept.unwrap_or_else(|| (g.clone(), Arc::new(grove::trees(g))));
            self.groves.push(entry);
        }
        let ground = crate::rocks::place::ground(map);
        let mut trees = Vec::new();
        for (i, t) in doc.trees.iter().enumerate() {
            let nodes = self.nodes(&Species::of_tree(t));
            trees.push(Standing {
                source: Source::Tree(i),
                at: t.at,
                base: ground.height(t.at[0], t.at[1]),
                height: t.height,
                turn: turn(t.seed),
                nodes,
                wind: t.wind.clone(),
            });
        }
        for (i, (g, list)) in self.groves.iter().enumerate() {
            for (k, t) in list.iter().enumerate() {
                let nodes = nodes_of(&mut self.species, &Species::preset(t.preset));
                trees.push(Standing {
                    source: Source::Grove(i, k),
                    at: t.at,
                    base: ground.height(t.at[0], t.at[1]),
                    height: t.height,
                    turn: turn(t.seed),
                    nodes,
                    wind: g.wind.clone(),
                });
            }
        }
        self.trees = Arc::new(trees);
    }

    /// Every standing tree: the document's trees in order, then each grove's.
    pub fn trees(&self) -> &[Standing] {
        &self.trees
    }

    /// The same trees, shared: what a picture keeps for its frame.
    pub fn shared(&self) -> Arc<Vec<Standing>> {
        Arc::clone(&self.trees)
    }

    /// Draws every tree at the roughness `q(tree)` gives and time `t` seconds.
    pub fn draw(&self, q: impl Fn(&Standing) -> f64, t: f64) -> Drawn {
        let mut out = Drawn::default();
        for tree in self.trees.iter() {
            tree.draw(q(tree), t, &mut out);
        }
        out
    }
}
