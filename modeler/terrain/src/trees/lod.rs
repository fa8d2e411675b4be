//! Drawing a tree at roughness `Q = S_min / S_tree` (seed 004, §4): a depth-first walk of the
//! [`NodeTree`] that copies each node's precomputed geometry, or, where a node's extent is at
//! most `Q·S_tree`, emits one simplified shape ([`Impostor`]) for it and skips its subtree.
//!
//! The data volume (nodes copied plus groups drawn as one shape) follows the seed's law
//! [`law`]` = (M/(M−1))·Q^(ln M / ln λ)` exactly when all maps share the scale λ and `Q` is a
//! power of it; with unequal scales its exponent is nearer `−D`, `D` the similarity dimension
//! ([`super::species::Species::dimension`]).

use glam::{Affine3A, DAffine3, DQuat, DVec3, Vec3A};

use super::nodes::NodeTree;
use super::wind::Pose;
use crate::export::Mesh;

/// The seed's data-volume law: `(M/(M−1))·Q^(ln M / ln λ)`.
pub fn law(m: usize, lambda: f64, q: f64) -> f64 {
    let m = m as f64;
    m / (m - 1.0) * q.powf(m.ln() / lambda.ln())
}

/// A branch group drawn as one simplified shape: the node it stands for, where, and how large.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impostor {
    /// The node of the tree's [`NodeTree`] (its subtree is the group: [`NodeTree::subtree`]).
    pub node: u32,
    /// The node's frame (the tree's unit, base at the origin, +Y up) to the world.
    pub transform: DAffine3,
    /// The group's extent `|ω…ω(0, S_tree, 0)|` in the world, metres.
    pub extent: f64,
}

/// What a walk drew: geometry for the copied nodes, and the simplified shapes.
#[derive(Debug, Clone, Default)]
pub struct Drawn {
    /// The copied branches and leaves, coloured (bark, leaf).
    pub mesh: Mesh,
    /// The simplified shapes.
    pub impostors: Vec<Impostor>,
    /// Nodes whose geometry was copied.
    pub nodes: u64,
    /// Polygons copied (frustum quads and rhombus leaves).
    pub polygons: u64,
    /// Rhombus leaves copied: the full model's own simplified shapes, each standing for a group
    /// below 2 % of the tree.
    pub leaves: u64,
}

impl Drawn {
    /// The data volume: nodes copied plus the groups drawn as one shape (simplified shapes and
    /// leaves). Every map of a copied node is one or the other, so this is `1 + M·nodes`.
    pub fn volume(&self) -> u64 {
        self.nodes + self.impostors.len() as u64 + self.leaves
    }
}

/// The simplified shapes as untextured crossed cards in the leaf colour, for exports: two
/// quads per shape through the centre of the tree's box in the node's frame, one across Z and
/// one across X, spanning the box (a group in its own frame is the tree cut sooner, inside the
/// tree's box). The renderer draws them textured instead (`penmodel-render`'s `impostor`).
pub fn cards(tree: &NodeTree, impostors: &[Impostor]) -> Mesh {
    let (lo, hi) = tree.bounds();
    let c = 0.5 * (lo + hi);
    let mut mesh = Mesh::default();
    for imp in impostors {
        let t = &imp.transform;
        for (corners, normal) in [
            (
                [
                    [lo.x, lo.y, c.z],
                    [hi.x, lo.y, c.z],
                    [hi.x, hi.y, c.z],
                    [lo.x, hi.y, c.z],
                ],
                DVec3::Z,
            ),
            (
                [
                    [c.x, lo.y, hi.z],
                    [c.x, lo.y, lo.z],
                    [c.x, hi.y, lo.z],
                    [c.x, hi.y, hi.z],
                ],
                DVec3::X,
            ),
        ] {
            let base = mesh.positions.len() as u32;
            let n = t.transform_vector3(normal).normalize_or(DVec3::Z).as_vec3().to_array();
            for p in corners {
                mesh.positions
                    .push(t.transform_point3(DVec3::from(p)).as_vec3().to_array());
                mesh.normals.push(n);
                mesh.colors.push(super::shapes::LEAF);
            }
            mesh.indices
                .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    mesh
}

fn f32_affine(a: &DAffine3) -> Affine3A {
    Affine3A::from_cols_array(&a.to_cols_array().map(|v| v as f32))
}

impl NodeTree {
    /// Draws the tree at roughness `q` (in (0, 1]; at or below [`super::nodes::STOP`] the full
    /// tree), placed by `place` (the tree's unit to the world), swaying as `pose` (still when
    /// `None`), appending to `out`.
    pub fn draw(&self, q: f64, place: &DAffine3, pose: Option<&Pose>, out: &mut Drawn) {
        let pose = pose.filter(|p| !p.is_still());
        // The sway's axis in the tree's unit (the placement turns and scales the tree).
        let axis = pose.map(|p| place.matrix3.inverse().mul_vec3(p.axis).normalize_or(DVec3::Z));
        let maps: Vec<DAffine3> = match pose {
            Some(_) => self.species.maps.iter().map(|m| m.affine()).collect(),
            None => Vec::new(),
        };
        let still = f32_affine(place);
        let mut swayed: Vec<DAffine3> = Vec::new();
        let mut i = 0;
        while i < self.nodes.len() {
            let n = &self.nodes[i];
            let d = usize::from(n.depth);
            let w = match (pose, axis) {
                (Some(pose), Some(axis)) => {
                    swayed.truncate(d);
                    let parent = swayed.last().copied().unwrap_or(DAffine3::IDENTITY);
                    // The lean about the branch's base, the axis seen from the parent's frame.
                    let y = if d == 0 {
                        0.0
                    } else {
                        self.species.maps[usize::from(n.map)].y
                    };
                    let a = parent.matrix3.inverse().mul_vec3(axis).normalize_or(DVec3::Z);
                    let base = DVec3::new(0.0, y, 0.0);
                    let lean = DAffine3::from_translation(base)
                        * DAffine3::from_quat(DQuat::from_axis_angle(a, pose.angle(d)))
                        * DAffine3::from_translation(-base);
                    let own = if d == 0 {
                        DAffine3::IDENTITY
                    } else {
                        maps[usize::from(n.map)]
                    };
                    let w = parent * lean * own;
                    swayed.push(w);
                    w
                }
                _ => n.transform,
            };
            if n.scale <= q {
                out.impostors.push(Impostor {
                    node: i as u32,
                    transform: *place * w,
                    extent: self.extent(i) * place.matrix3.x_axis.length(),
                });
                i = n.end as usize;
                continue;
            }
            let m = match pose {
                Some(_) => f32_affine(&(*place * w * n.transform.inverse())),
                None => still,
            };
            self.copy(i, &m, &mut out.mesh);
            out.nodes += 1;
            out.polygons += u64::from(n.polygons);
            out.leaves += u64::from(n.polygons) - super::shapes::BRANCH_POLYGONS as u64;
            i += 1;
        }
    }

    /// Appends node `i`'s own geometry mapped by `m` (a similarity) to `mesh`.
    fn copy(&self, i: usize, m: &Affine3A, mesh: &mut Mesh) {
        let n = &self.nodes[i];
        let base = mesh.positions.len() as u32;
        let (v0, v1) = (n.vertices.0 as usize, n.vertices.1 as usize);
        mesh.positions.extend(
            self.positions[v0..v1]
                .iter()
                .map(|p| m.transform_point3a(Vec3A::from_array(*p)).to_array()),
        );
        mesh.normals.extend(self.normals[v0..v1].iter().map(|q| {
            m.transform_vector3a(Vec3A::from_array(*q))
                .normalize_or_zero()
                .to_array()
        }));
        mesh.colors.extend_from_slice(&self.colors[v0..v1]);
        let (t0, t1) = (n.triangles.0 as usize, n.triangles.1 as usize);
        mesh.indices.extend(self.indices[t0..t1].iter().map(|k| k + base));
    }
}
