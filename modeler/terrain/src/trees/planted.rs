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
use crate::export::{Instance, Mesh};
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
    /// Its sway, if any (shared by a grove's trees).
    pub wind: Option<Arc<Wind>>,
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
        let pose = self.wind.as_deref().map(|w| wind::pose(w, t));
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

/// A tree standing at `at` on `ground`.
fn stand(
    source: Source,
    at: Point,
    ground: &crate::rocks::place::Ground<'_>,
    height: f64,
    seed: u64,
    nodes: Arc<NodeTree>,
    wind: Option<Arc<Wind>>,
) -> Standing {
    Standing {
        source,
        at,
        base: ground.height(at[0], at[1]),
        height,
        turn: turn(seed),
        nodes,
        wind,
    }
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
    groves: Vec<Scattered>,
    /// The document's own trees as they were stood.
    planted: Vec<Tree>,
    /// Shared with the pictures drawn from it, so that a frame takes them without a copy.
    trees: Arc<Vec<Standing>>,
    /// The standing trees by square of the ground: a change of the terrain finds those over it.
    index: Buckets,
    /// The grid they stand on: columns, rows, cell size's bits.
    grid: Option<(u32, u32, u64)>,
}

/// A grove as its trees were scattered, and its wind, shared by them.
#[derive(Debug, Clone)]
struct Scattered {
    grove: Grove,
    trees: Arc<Vec<GroveTree>>,
    wind: Option<Arc<Wind>>,
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

/// Terrain cells per side of a `Buckets` square: a local change of the terrain looks at a few
/// squares, and a grid of 512² has 1024 of them.
pub const BUCKET_CELLS: f64 = 16.0;

/// Indices of points in squares of the ground, `side` metres, row by row; points beyond the
/// grid in the squares at its edge.
#[derive(Debug, Clone, Default)]
struct Buckets {
    side: f64,
    cols: usize,
    rows: usize,
    cells: Vec<Vec<u32>>,
}

impl Buckets {
    /// Empty squares over `map`.
    fn over(map: &Heightmap) -> Buckets {
        let side = BUCKET_CELLS * map.cell_size();
        let count = |cells: u32| (f64::from(cells) / BUCKET_CELLS).ceil().max(1.0) as usize;
        let (cols, rows) = (count(map.cols()), count(map.rows()));
        Buckets {
            side,
            cols,
            rows,
            cells: vec![Vec::new(); cols * rows],
        }
    }

    /// The square column (or row) of coordinate `x` along an axis of `n` squares.
    fn along(&self, x: f64, n: usize) -> usize {
        // NaN and negatives to 0 (the cast saturates), the far side to the last.
        ((x / self.side).floor() as usize).min(n - 1)
    }

    fn of(&self, p: Point) -> usize {
        self.along(p[1], self.rows) * self.cols + self.along(p[0], self.cols)
    }

    fn insert(&mut self, i: usize, p: Point) {
        let b = self.of(p);
        self.cells[b].push(i as u32);
    }

    /// Moves point `i` from `from` to `to`.
    fn relocate(&mut self, i: usize, from: Point, to: Point) {
        let (a, b) = (self.of(from), self.of(to));
        if a != b {
            self.cells[a].retain(|&k| k as usize != i);
            self.cells[b].push(i as u32);
        }
    }

    /// The points in the squares that `r` (metres `[x0, y0, x1, y1]`, ends maybe infinite)
    /// overlaps: every point inside `r`, and some beside it.
    fn near(&self, r: [f64; 4]) -> impl Iterator<Item = usize> + '_ {
        let (c0, c1) = (self.along(r[0], self.cols), self.along(r[2], self.cols));
        let (r0, r1) = (self.along(r[1], self.rows), self.along(r[3], self.rows));
        (r0..=r1).flat_map(move |row| {
            self.cells[row * self.cols + c0..=row * self.cols + c1]
                .iter()
                .flatten()
                .map(|&k| k as usize)
        })
    }
}

impl Forest {
    /// The trees of `doc` (valid) on `map`.
    pub fn of(doc: &Document, map: &Heightmap) -> Forest {
        let mut f = Forest::default();
        f.follow(doc, map, None);
        f
    }

    /// The node tree of `species`, built once.
    pub fn nodes(&mut self, species: &Species) -> Arc<NodeTree> {
        nodes_of(&mut self.species, species)
    }

    /// Brings the trees up to date with `doc` and its terrain `map`, whose heights changed only
    /// in the cells `changed` (`(c0, r0, width, height)`; `None`: anywhere). Groves that changed
    /// are scattered again and then every tree stood again; else the document's own trees that
    /// changed are stood again, and the trees over the changed cells (and a cell beyond, whose
    /// heights their ground blends) read their base again — the same bits as standing all.
    pub fn follow(&mut self, doc: &Document, map: &Heightmap, changed: Option<(u32, u32, u32, u32)>) {
        if doc.trees.is_empty() && doc.groves.is_empty() && self.trees.is_empty() {
            return;
        }
        let grid = (map.cols(), map.rows(), map.cell_size().to_bits());
        let groves_same =
            self.groves.len() == doc.groves.len() && self.groves.iter().zip(&doc.groves).all(|(o, g)| o.grove == *g);
        let Some(changed) =
            changed.filter(|_| groves_same && self.grid == Some(grid) && self.planted.len() == doc.trees.len())
        else {
            return self.stand_all(doc, map);
        };
        let ground = crate::rocks::place::ground(map);
        let redo: Vec<usize> = (0..doc.trees.len())
            .filter(|&i| self.planted[i] != doc.trees[i])
            .collect();
        let over: Vec<usize> = if changed.2 > 0 && changed.3 > 0 {
            let r = map.extent_of(changed);
            let m = map.cell_size();
            let r = [r[0] - m, r[1] - m, r[2] + m, r[3] + m];
            self.index
                .near(r)
                .filter(|&k| {
                    let at = self.trees[k].at;
                    (r[0]..=r[2]).contains(&at[0]) && (r[1]..=r[3]).contains(&at[1])
                })
                .collect()
        } else {
            Vec::new()
        };
        if redo.is_empty() && over.is_empty() {
            return;
        }
        let trees = Arc::make_mut(&mut self.trees);
        for i in redo {
            let t = &doc.trees[i];
            let nodes = nodes_of(&mut self.species, &Species::of_tree(t));
            self.index.relocate(i, trees[i].at, t.at);
            trees[i] = stand(
                Source::Tree(i),
                t.at,
                &ground,
                t.height,
                t.seed,
                nodes,
                t.wind.clone().map(Arc::new),
            );
            self.planted[i].clone_from(t);
        }
        for k in over {
            let at = trees[k].at;
            trees[k].base = ground.height(at[0], at[1]);
        }
    }

    /// Scatters the groves that changed again and stands every tree.
    fn stand_all(&mut self, doc: &Document, map: &Heightmap) {
        let mut old = std::mem::take(&mut self.groves);
        for g in &doc.groves {
            let kept = old.iter().position(|o| o.grove == *g).map(|k| old.swap_remove(k));
            let entry = kept.unwrap_or_else(|| Scattered {
                grove: g.clone(),
                trees: Arc::new(grove::trees(g)),
                wind: g.wind.clone().map(Arc::new),
            });
            self.groves.push(entry);
        }
        let ground = crate::rocks::place::ground(map);
        let mut trees = Vec::new();
        for (i, t) in doc.trees.iter().enumerate() {
            let nodes = nodes_of(&mut self.species, &Species::of_tree(t));
            let wind = t.wind.clone().map(Arc::new);
            trees.push(stand(Source::Tree(i), t.at, &ground, t.height, t.seed, nodes, wind));
        }
        for (i, Scattered { trees: list, wind, .. }) in self.groves.iter().enumerate() {
            for (k, t) in list.iter().enumerate() {
                let nodes = nodes_of(&mut self.species, &Species::preset(t.preset));
                trees.push(stand(
                    Source::Grove(i, k),
                    t.at,
                    &ground,
                    t.height,
                    t.seed,
                    nodes,
                    wind.clone(),
                ));
            }
        }
        self.index = Buckets::over(map);
        for (k, t) in trees.iter().enumerate() {
            self.index.insert(k, t.at);
        }
        self.planted.clone_from(&doc.trees);
        self.grid = Some((map.cols(), map.rows(), map.cell_size().to_bits()));
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

    /// The trees as instances of shared meshes, for exports: one [`Shared`] per species
    /// (trees of the same maps share a node tree) drawn once at roughness `q` at rest, in the
    /// tree's unit, with each of its trees' place ([`Standing::place`]). In order of the
    /// species' first tree.
    pub fn instanced(&self, q: f64) -> Vec<Shared> {
        let mut shared: Vec<(*const NodeTree, Shared)> = Vec::new();
        for tree in self.trees.iter() {
            let key = Arc::as_ptr(&tree.nodes);
            let k = match shared.iter().position(|(p, _)| *p == key) {
                Some(k) => k,
                None => {
                    let mut drawn = Drawn::default();
                    tree.nodes.draw(q, &DAffine3::IDENTITY, None, &mut drawn);
                    let cards = super::lod::cards(&tree.nodes, &drawn.impostors);
                    let (bark, mut leaves) = bark_and_leaves(&drawn.mesh);
                    append(&mut leaves, &cards);
                    let name = format!("trees {}", shared.len());
                    shared.push((
                        key,
                        Shared {
                            name,
                            bark,
                            leaves,
                            instances: Vec::new(),
                        },
                    ));
                    shared.len() - 1
                }
            };
            let (turn, scale) = (tree.turn, tree.height / tree.nodes.height);
            shared[k].1.instances.push(Instance {
                translation: [tree.at[0] as f32, tree.base as f32, tree.at[1] as f32],
                rotation: [0.0, (0.5 * turn).sin() as f32, 0.0, (0.5 * turn).cos() as f32],
                scale: [scale as f32; 3],
            });
        }
        shared.into_iter().map(|(_, s)| s).collect()
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

/// One species' tree at one detail, in the tree's unit (base at the origin, +Y up), and where
/// each tree of it stands: what an export writes once and draws at every place.
#[derive(Debug, Clone)]
pub struct Shared {
    /// Its name in the export.
    pub name: String,
    /// The branches, without colours (the export's material is the bark's).
    pub bark: Mesh,
    /// The leaves and the simplified shapes' cards, without colours.
    pub leaves: Mesh,
    /// Where each tree of it stands ([`Standing::place`] as translation, rotation and scale).
    pub instances: Vec<Instance>,
}

/// A drawn tree's triangles split by colour: the bark's and the rest (leaves), each with its
/// own vertices and no colours.
pub fn bark_and_leaves(mesh: &Mesh) -> (Mesh, Mesh) {
    let (mut bark, mut leaves) = (Mesh::default(), Mesh::default());
    // Per vertex of `mesh`: which part it went to and its index there.
    let mut moved: Vec<Option<(bool, u32)>> = vec![None; mesh.positions.len()];
    for t in mesh.indices.chunks_exact(3) {
        let Some(&first) = t.first() else { continue };
        let is_bark = mesh.colors.get(first as usize) == Some(&super::shapes::BARK);
        let out = if is_bark { &mut bark } else { &mut leaves };
        for &v in t {
            let v = v as usize;
            let i = match moved.get(v).copied().flatten() {
                Some((b, i)) if b == is_bark => i,
                _ => {
                    let i = out.positions.len() as u32;
                    out.positions.push(mesh.positions.get(v).copied().unwrap_or_default());
                    out.normals
                        .push(mesh.normals.get(v).copied().unwrap_or([0.0, 1.0, 0.0]));
                    if let Some(m) = moved.get_mut(v) {
                        *m = Some((is_bark, i));
                    }
                    i
                }
            };
            out.indices.push(i);
        }
    }
    (bark, leaves)
}

/// Appends `more` to `mesh`, dropping its colours.
fn append(mesh: &mut Mesh, more: &Mesh) {
    let base = mesh.positions.len() as u32;
    mesh.positions.extend_from_slice(&more.positions);
    mesh.normals.extend_from_slice(&more.normals);
    mesh.indices.extend(more.indices.iter().map(|i| i + base));
}
