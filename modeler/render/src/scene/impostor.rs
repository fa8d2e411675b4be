//! Simplified shapes of trees (seed 004, §5.2.3): a branch group drawn as crossed polygons with
//! images of the group's full geometry.
//!
//! - **Baking** ([`bake`]): the group's full sub-model ([`NodeTree::subtree`], in the node's own
//!   frame) is rendered by this crate's rasteriser, in parallel projection, into four RGBA
//!   textures, one per side — front (seen from +Z), back (−Z), right (+X), left (−X) — lit
//!   like the meshes (two-sided Lambert with the style's light taken in the node's frame: one
//!   image serves every instance, whatever its turn) and transparent where nothing was drawn.
//!   The seed's "texture elements": the detailed shape projected in parallel onto the polygon.
//! - **Which polygon** ([`facing`]): of the two crossed polygons (through the group's box
//!   centre, one across Z, one across X), the one whose normal makes the smaller angle with the
//!   line to the eye, with the texture of the side the eye is on.
//! - **Cropped** ([`opaque`]): the polygon drawn spans only the texels its image covers (the
//!   smallest texel-aligned rectangle holding every opaque texel), not the whole box: the rest
//!   of the image is transparent, and its pixels were each a depth test, a division and a texel
//!   fetch for nothing. A side whose image is empty draws no polygon.
//! - **Cache** ([`Cache`]): a node's sub-model in its own frame depends only on its scale (the
//!   product of its maps' scales decides where its branches stop), so textures are kept per
//!   species and scale and baked the first time a group of that scale is drawn.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3};
use penmodel_terrain::export::Mesh;
use penmodel_terrain::trees::{Impostor, NodeTree};
use rayon::prelude::*;

use super::Style;
use super::meshes::srgb;
use crate::raster::rasterise::{self, Bounds, DepthSink, Sample, Surface, Vtx};
use crate::raster::textured::{Quad, Texture};

/// Texels across a side of a simplified shape's texture. A group drawn as one shape is at most
/// `Q·S_tree` across, tens of pixels at the distances where it replaces geometry.
pub const TEXELS: u32 = 64;

/// The side a simplified shape is seen from, in the node's frame (+Y up).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The eye on +Z.
    Front = 0,
    /// The eye on −Z.
    Back = 1,
    /// The eye on +X.
    Right = 2,
    /// The eye on −X.
    Left = 3,
}

impl Side {
    /// All four, in texture order.
    pub const ALL: [Side; 4] = [Side::Front, Side::Back, Side::Right, Side::Left];

    /// The image's right-hand direction and the direction towards the eye, node frame.
    fn basis(self) -> (Vec3, Vec3) {
        match self {
            Side::Front => (Vec3::X, Vec3::Z),
            Side::Back => (-Vec3::X, -Vec3::Z),
            Side::Right => (-Vec3::Z, Vec3::X),
            Side::Left => (Vec3::Z, -Vec3::X),
        }
    }
}

/// A group's four images and the box they span, node frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Baked {
    /// The box's lower and upper corners.
    pub bounds: [Vec3; 2],
    /// The images, in [`Side`] order.
    pub textures: [Texture; 4],
}

/// The range of `axis·c` over the corners of `bounds`.
fn span(bounds: &[Vec3; 2], axis: Vec3) -> (f32, f32) {
    let [lo, hi] = bounds;
    let a = axis.x * lo.x + axis.y * lo.y + axis.z * lo.z;
    let b = axis.x * hi.x + axis.y * hi.y + axis.z * hi.z;
    (a.min(b), a.max(b))
}

/// Renders `mesh` (node frame) into the four side images of `size × size` texels.
pub fn bake(mesh: &Mesh, style: &Style, size: u32) -> Baked {
    let size = size.max(1);
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in &mesh.positions {
        lo = lo.min(Vec3::from_array(*p));
        hi = hi.max(Vec3::from_array(*p));
    }
    if !(lo.is_finite() && hi.is_finite()) {
        (lo, hi) = (Vec3::ZERO, Vec3::ZERO);
    }
    // A flat group still gets a box with some depth, so every image has an extent.
    let pad = (hi - lo).max_element().max(1e-6) * 1e-3;
    let bounds = [lo - pad, hi + pad];
    let light = Vec3::from_array(super::light::world_light(style));
    let ambient = style.ambient.clamp(0.0, 1.0);
    let lit: Vec<f32> = mesh
        .normals
        .iter()
        .map(|n| ambient + (1.0 - ambient) * Vec3::from_array(*n).dot(light).abs())
        .collect();
    let colours: Vec<[u8; 3]> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            if mesh.colors.len() != mesh.positions.len() {
                return [style.rock_colour[0], style.rock_colour[1], style.rock_colour[2]];
            }
            let c = [0, 1, 2].map(|i| t.iter().map(|&k| mesh.colors[k as usize][i]).sum::<f32>() / 3.0);
            srgb(c)
        })
        .collect();
    let textures = Side::ALL.map(|side| image(mesh, &lit, &colours, &bounds, side, size));
    Baked { bounds, textures }
}

/// One side's image.
fn image(mesh: &Mesh, lit: &[f32], colours: &[[u8; 3]], bounds: &[Vec3; 2], side: Side, size: u32) -> Texture {
    let (right, toward) = side.basis();
    let (r0, r1) = span(bounds, right);
    let (t0, t1) = span(bounds, toward);
    let (y0, y1) = (bounds[0].y, bounds[1].y);
    let n = size as usize;
    let px = size as f32;
    let screen: Vec<Vtx> = mesh
        .positions
        .iter()
        .zip(lit)
        .map(|(p, &l)| {
            let p = Vec3::from_array(*p);
            // Parallel projection: depth is affine, so 1/w is any positive affine depth
            // (1 to 2, larger nearer the eye) and the light needs no division.
            let x = (p.dot(right) - r0) / (r1 - r0) * px;
            let y = (y1 - p.y) / (y1 - y0) * px;
            Vtx {
                x: rasterise::snap(x),
                y: rasterise::snap(y),
                invw: 1.0 + (p.dot(toward) - t0) / (t1 - t0),
                hw: 0.0,
                lw: l,
            }
        })
        .collect();
    let mut samples = vec![Sample::default(); n * n];
    let whole = Bounds {
        x0: 0,
        x1: size as i32,
        y0: 0,
        y1: size as i32,
    };
    let mut sink = DepthSink {
        samples: &mut samples,
        width: n,
        y0: 0,
        surface: Surface::Terrain,
    };
    for (t, c) in mesh.indices.chunks_exact(3).zip(colours) {
        let [a, b, cc] = [0, 1, 2].map(|k| &screen[t[k] as usize]);
        sink.surface = Surface::Colour(*c);
        rasterise::two_sided(a, b, cc, &whole, &mut sink);
    }
    let texels = samples
        .iter()
        .map(|s| match s.surface {
            Surface::Colour([r, g, b]) if s.invw > 0.0 => {
                let l = s.lw.clamp(0.0, 1.0);
                [
                    (f32::from(r) * l) as u8,
                    (f32::from(g) * l) as u8,
                    (f32::from(b) * l) as u8,
                    255,
                ]
            }
            _ => [0, 0, 0, 0],
        })
        .collect();
    Texture::new(size, size, texels).unwrap_or_default()
}

/// The side of a group's box an eye at `eye` (world) sees best, given the node's frame → world
/// `transform`: the crossed polygon whose normal is nearest the line from the box's centre to the
/// eye, and which of its faces.
pub fn facing(transform: &DAffine3, bounds: &[Vec3; 2], eye: DVec3) -> Side {
    let centre = (bounds[0] + bounds[1]).as_dvec3() * 0.5;
    let v = transform.inverse().transform_point3(eye) - centre;
    if v.z.abs() >= v.x.abs() {
        if v.z >= 0.0 { Side::Front } else { Side::Back }
    } else if v.x >= 0.0 {
        Side::Right
    } else {
        Side::Left
    }
}

/// The polygon of `side` through the box's centre, corners in the world (by `transform`) with
/// their texture coordinates, drawn with texture `texture`.
pub fn quad(transform: &DAffine3, bounds: &[Vec3; 2], side: Side, texture: u32) -> Quad {
    quad_within(transform, bounds, side, texture, WHOLE)
}

/// The whole texture, `[u0, v0, u1, v1]`.
pub const WHOLE: [f32; 4] = [0.0, 0.0, 1.0, 1.0];

/// [`quad`] cut to the texture rectangle `crop` (`[u0, v0, u1, v1]`, 0 to 1, v down): the part
/// of the polygon that shows those texels, with their coordinates.
pub fn quad_within(transform: &DAffine3, bounds: &[Vec3; 2], side: Side, texture: u32, crop: [f32; 4]) -> Quad {
    let (right, toward) = side.basis();
    let (r0, r1) = span(bounds, right);
    let (y0, y1) = (bounds[0].y, bounds[1].y);
    let axis = toward.abs();
    let middle = axis * axis.dot((bounds[0] + bounds[1]) * 0.5);
    // Weighted, so that 0 and 1 give the box's sides exactly.
    let across = |u: f32| r0 * (1.0 - u) + r1 * u;
    let down = |v: f32| y1 * (1.0 - v) + y0 * v;
    let at = |u: f32, v: f32| {
        let p = right * across(u) + middle + Vec3::Y * down(v);
        transform.transform_point3(p.as_dvec3()).as_vec3().to_array()
    };
    let [u0, v0, u1, v1] = crop;
    Quad {
        corners: [at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)],
        uv: [[u0, v0], [u1, v0], [u1, v1], [u0, v1]],
        texture,
    }
}

/// The smallest texel-aligned rectangle of `texture` holding every texel the alpha test keeps
/// (alpha ≥ 128), `[u0, v0, u1, v1]` from 0 to 1; `None` when it keeps none.
pub fn opaque(texture: &Texture) -> Option<[f32; 4]> {
    let (w, h) = (texture.width() as usize, texture.height() as usize);
    let (mut lo, mut hi) = ([usize::MAX; 2], [0usize; 2]);
    for (i, t) in texture.texels().iter().enumerate() {
        if t[3] >= 128 {
            let (x, y) = (i % w, i / w);
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x + 1), hi[1].max(y + 1)];
        }
    }
    (lo[0] != usize::MAX).then(|| {
        [
            lo[0] as f32 / w as f32,
            lo[1] as f32 / h as f32,
            hi[0] as f32 / w as f32,
            hi[1] as f32 / h as f32,
        ]
    })
}

/// Baked groups, per species and scale; their textures in one table, four per group.
#[derive(Debug, Default)]
pub struct Cache {
    /// `(node tree's address, scale's bits)` → group index. The trees are kept in `held`, so an
    /// address is not reused while it is a key.
    groups: HashMap<(usize, u64), u32>,
    held: Vec<Arc<NodeTree>>,
    bounds: Vec<[Vec3; 2]>,
    textures: Vec<Texture>,
    /// Each texture's [`opaque`] rectangle.
    crops: Vec<Option<[f32; 4]>>,
}

impl Cache {
    /// The group index of `impostor`'s node of `tree`, baked now if it is the first of its scale.
    pub fn group(&mut self, tree: &Arc<NodeTree>, node: u32, style: &Style) -> u32 {
        let key = key(tree, node);
        if let Some(&g) = self.groups.get(&key) {
            return g;
        }
        self.insert(key, tree, baked(tree, node, style))
    }

    /// The group index of `impostor`'s node of `tree` if it is baked: [`Cache::group`] without
    /// the bake, for the trees' walks on the pool's threads.
    pub fn find(&self, tree: &Arc<NodeTree>, node: u32) -> Option<u32> {
        self.groups.get(&key(tree, node)).copied()
    }

    /// Bakes the groups of `wanted` (node trees and nodes) not baked yet, on the pool's threads:
    /// a grove planted, or a head leaning in, asks for tens of new groups in one frame, and
    /// baking them one by one inside the view took up to 120 ms of a tracked frame (issue 16).
    pub fn bake_missing<'t>(&mut self, wanted: impl IntoIterator<Item = (&'t Arc<NodeTree>, u32)>, style: &Style) {
        // In the order first asked for, so the groups are numbered as `group` would number them.
        let mut missing: Vec<((usize, u64), &Arc<NodeTree>, u32)> = Vec::new();
        let mut seen = HashSet::new();
        for (tree, node) in wanted {
            let k = key(tree, node);
            if !self.groups.contains_key(&k) && seen.insert(k) {
                missing.push((k, tree, node));
            }
        }
        let made: Vec<Baked> = missing
            .par_iter()
            .map(|&(_, tree, node)| baked(tree, node, style))
            .collect();
        for ((k, tree, _), b) in missing.into_iter().zip(made) {
            self.insert(k, tree, b);
        }
    }

    /// Adds `baked` as the group of `key`; returns its index.
    fn insert(&mut self, key: (usize, u64), tree: &Arc<NodeTree>, baked: Baked) -> u32 {
        let g = self.bounds.len() as u32;
        self.bounds.push(baked.bounds);
        self.crops.extend(baked.textures.iter().map(opaque));
        self.textures.extend(baked.textures);
        if !self.held.iter().any(|t| Arc::ptr_eq(t, tree)) {
            self.held.push(Arc::clone(tree));
        }
        self.groups.insert(key, g);
        g
    }

    /// The quad facing `eye` for `impostor`, a group of [`Cache::group`], cut to its image's
    /// opaque texels; `None` when that image has none.
    pub fn quad(&self, group: u32, impostor: &Impostor, eye: DVec3) -> Option<Quad> {
        let bounds = &self.bounds[group as usize];
        let side = facing(&impostor.transform, bounds, eye);
        let texture = group * 4 + side as u32;
        let crop = self.crops[texture as usize]?;
        Some(quad_within(&impostor.transform, bounds, side, texture, crop))
    }

    /// Every baked texture, four per group in [`Side`] order.
    pub fn textures(&self) -> &[Texture] {
        &self.textures
    }

    /// How many groups were baked.
    pub fn groups(&self) -> usize {
        self.bounds.len()
    }
}

/// A group's key: its node tree's address and the node's scale (a tree's nodes of one scale
/// are the same shape).
fn key(tree: &Arc<NodeTree>, node: u32) -> (usize, u64) {
    let scale = tree.nodes.get(node as usize).map_or(1.0, |n| n.scale);
    (Arc::as_ptr(tree) as usize, scale.to_bits())
}

/// Node `node` of `tree` baked (an empty group for a node it does not have).
fn baked(tree: &NodeTree, node: u32, style: &Style) -> Baked {
    let mesh = if (node as usize) < tree.nodes.len() {
        tree.subtree(node as usize)
    } else {
        Mesh::default()
    };
    bake(&mesh, style, TEXELS)
}
