//! The multiplexed level-of-detail tree (seed 004, §4): every branch of the full tree as a
//! node with its transform, its descendants' extent and its own geometry, precomputed once per
//! species, so that drawing a tree at any roughness copies geometry instead of composing maps.
//!
//! Nodes are stored in depth-first (pre-)order: a node's descendants are the nodes after it up to
//! its [`Node::end`], so skipping a subtree is a jump. A node exists when its scale (the product
//! of its maps' scales) is at least [`STOP`] — its extent `|ω…ω(0, S_tree, 0)| = scale·S_tree`
//! at least 2 % of the tree's height; each map whose branch would fall below that gives the node
//! a rhombus leaf instead ([`super::shapes`]).

use glam::{DAffine3, DVec3};

use super::shapes::{self, Parts};
use super::species::Species;

/// Branches stop at 2 % of the tree's height (the seed's `S_min` of the full model).
pub const STOP: f64 = 0.02;

/// The most nodes a tree may have (`validate` refuses species beyond it).
pub const MAX_NODES: u64 = 100_000;

/// One branch of the full tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// The composition `ω_{i1}·…·ω_{ik}` mapping the tree's unit onto this branch's subtree.
    pub transform: DAffine3,
    /// The product of the maps' scales (1 for the trunk).
    pub scale: f64,
    /// The generation: 0 for the trunk, its branches 1, …
    pub depth: u16,
    /// Which of its parent's maps made it (0 for the trunk).
    pub map: u8,
    /// One past its last descendant in [`NodeTree::nodes`].
    pub end: u32,
    /// Its own geometry: vertices `[first, last)` of the tree's buffers.
    pub vertices: (u32, u32),
    /// Its own triangles: `[first, last)` indices of [`NodeTree::indices`], local to its vertices.
    pub triangles: (u32, u32),
    /// Its own polygons (the frustum's quads and its rhombus leaves).
    pub polygons: u32,
}

/// A species' full tree as nodes with their geometry, in the tree's unit (base at the origin,
/// +Y up).
#[derive(Debug, Clone)]
pub struct NodeTree {
    /// The species.
    pub species: Species,
    /// `S_tree`: the height of the full tree's top, in its unit.
    pub height: f64,
    /// The nodes in depth-first order; the trunk first.
    pub nodes: Vec<Node>,
    /// Every node's vertices, node after node.
    pub positions: Vec<[f32; 3]>,
    /// Their normals.
    pub normals: Vec<[f32; 3]>,
    /// Their colours (bark, leaf).
    pub colors: Vec<[f32; 3]>,
    /// Every node's triangles, indices local to the node's first vertex.
    pub indices: Vec<u32>,
}

/// How many nodes a species has when branches stop at `stop` (a scale), or `None` past `limit`:
/// the same recursion as the build, on scales alone.
pub fn count_nodes(species: &Species, stop: f64, limit: u64) -> Option<u64> {
    fn walk(species: &Species, scale: f64, stop: f64, limit: u64, n: &mut u64) -> bool {
        *n += 1;
        if *n > limit {
            return false;
        }
        species
            .maps
            .iter()
            .all(|m| scale * m.s.abs() < stop || walk(species, scale * m.s.abs(), stop, limit, n))
    }
    let mut n = 0;
    walk(species, 1.0, stop, limit, &mut n).then_some(n)
}

struct Build<'a> {
    species: &'a Species,
    maps: Vec<DAffine3>,
    trunk: f64,
    r0: f64,
    r1: f64,
    leaf: f64,
    stop: f64,
    tree: NodeTree,
    parts: Parts,
}

impl Build<'_> {
    fn node(&mut self, w: DAffine3, scale: f64, depth: u16, map: u8) {
        let at = self.tree.nodes.len();
        let v0 = self.parts.positions.len() as u32;
        let t0 = self.parts.indices.len() as u32;
        self.parts.branch(&w, self.trunk, self.r0, self.r1);
        let mut polygons = shapes::BRANCH_POLYGONS as u32;
        for (i, m) in self.species.maps.iter().enumerate() {
            if scale * m.s.abs() < self.stop {
                self.parts.leaf(&(w * self.maps[i]), self.leaf);
                polygons += shapes::LEAF_POLYGONS as u32;
            }
        }
        let v1 = self.parts.positions.len() as u32;
        // Local indices: a node's geometry is copied as a block.
        for i in &mut self.parts.indices[t0 as usize..] {
            *i -= v0;
        }
        self.tree.nodes.push(Node {
            transform: w,
            scale,
            depth,
            map,
            end: 0,
            vertices: (v0, v1),
            triangles: (t0, self.parts.indices.len() as u32),
            polygons,
        });
        for (i, m) in self.species.maps.iter().enumerate() {
            let s = scale * m.s.abs();
            if s >= self.stop {
                self.node(w * self.maps[i], s, depth + 1, i as u8);
            }
        }
        self.tree.nodes[at].end = self.tree.nodes.len() as u32;
    }
}

impl NodeTree {
    /// The full tree of `species` (valid: its maps contract and it has at most [`MAX_NODES`]
    /// nodes, which `crate::validate` checks). This is the seed's "fractal computation": every
    /// composition of maps down to [`STOP`].
    pub fn build(species: &Species) -> NodeTree {
        NodeTree::build_to(species, STOP)
    }

    /// The tree with branches down to `stop` (a scale in (0, 1)) instead of [`STOP`]: coarser
    /// trees, whose leaves stand for larger groups, for the silhouette fit.
    pub fn build_to(species: &Species, stop: f64) -> NodeTree {
        let trunk = species.trunk().max(1e-6);
        let r0 = shapes::TRUNK_RADIUS * trunk;
        let s_max = species.maps.iter().map(|m| m.s.abs()).fold(0.0, f64::max);
        let mut b = Build {
            species,
            maps: species.maps.iter().map(|m| m.affine()).collect(),
            trunk,
            r0,
            // Tapered to the radius of the largest branch's base, which continues it.
            r1: r0 * s_max,
            // A leaf stands for a branch's whole cut-off subtree: its length is a fraction of
            // the tree's reach in the branch's frame.
            leaf: shapes::LEAF_LENGTH * species.reach(),
            stop,
            tree: NodeTree {
                species: species.clone(),
                height: 0.0,
                nodes: Vec::new(),
                positions: Vec::new(),
                normals: Vec::new(),
                colors: Vec::new(),
                indices: Vec::new(),
            },
            parts: Parts::default(),
        };
        b.node(DAffine3::IDENTITY, 1.0, 0, 0);
        let Parts {
            positions,
            normals,
            colors,
            indices,
        } = b.parts;
        let mut tree = b.tree;
        tree.height = positions.iter().map(|p| f64::from(p[1])).fold(trunk, f64::max);
        tree.positions = positions;
        tree.normals = normals;
        tree.colors = colors;
        tree.indices = indices;
        tree
    }

    /// The box of the full tree in its unit: `(min, max)` corners.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.positions.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| {
                let p = DVec3::from(p.map(f64::from));
                (lo.min(p), hi.max(p))
            },
        )
    }

    /// The polygons of the full tree.
    pub fn polygons(&self) -> u64 {
        self.nodes.iter().map(|n| u64::from(n.polygons)).sum()
    }

    /// A node's extent `|ω…ω(0, S_tree, 0)|` in the tree's unit.
    pub fn extent(&self, node: usize) -> f64 {
        self.nodes[node].scale * self.height
    }

    /// The full geometry of `node`'s subtree in the node's own frame (the tree's unit, as if it
    /// were the trunk): what a simplified shape stands for, to render its textures from.
    pub fn subtree(&self, node: usize) -> crate::export::Mesh {
        let n = self.nodes[node];
        let inv = n.transform.inverse();
        let mut mesh = crate::export::Mesh::default();
        for k in node..n.end as usize {
            let m = &self.nodes[k];
            let base = mesh.positions.len() as u32;
            let (v0, v1) = (m.vertices.0 as usize, m.vertices.1 as usize);
            for v in v0..v1 {
                let p = inv.transform_point3(DVec3::from(self.positions[v].map(f64::from)));
                let q = inv.transform_vector3(DVec3::from(self.normals[v].map(f64::from)));
                mesh.positions.push(p.as_vec3().to_array());
                mesh.normals.push(q.normalize_or(DVec3::Y).as_vec3().to_array());
                mesh.colors.push(self.colors[v]);
            }
            let (t0, t1) = (m.triangles.0 as usize, m.triangles.1 as usize);
            mesh.indices.extend(self.indices[t0..t1].iter().map(|i| i + base));
        }
        mesh
    }
}
