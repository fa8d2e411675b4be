//! Trees in the scene (seed 004): each frame, every standing tree is drawn at the roughness `Q`
//! its distance and its angle from the gaze call for, once for both eyes; the copied branches
//! go to the meshes, the simplified shapes to the textured polygons.
//!
//! - **Distance** `D`: from the centre eye to the middle of the tree's height; `L0` is the
//!   tree's height. **Angle** `θ`: between the gaze and the line to that point. `Q` is
//!   [`Roughness::choose`]`(D, L0, θ)`.
//! - **The gaze** is [`Scene::gaze`] when a view direction is given; else the line from the
//!   centre eye to [`Scene::looking_at`], the pen's tip while modeling (the seed: "the pen tip's
//!   direction from the head"); else the line from the centre eye through the screen's centre.
//!   The tracker gives the head's position, not where it faces, so with the tracked head and no
//!   pen the gaze is the line from the real eyes through the display's centre.
//! - **LOD off** ([`Scene::tree_lod`] `None`) draws every tree at [`STOP`], the full model.
//! - Both eyes see the same `Q` per tree, so a stereo pair never shows a group as geometry in one
//!   eye and as a shape in the other.
//! - The trees are walked in parallel, each into its own buffers (kept from frame to frame), and
//!   handed on in the scene's order, so the frame is the same as from one walk: the walk was a
//!   serial part of the 30-tree frame. Each tree's walk also looks up its simplified shapes'
//!   groups and makes their polygons, when every group it needs is baked (nearly every frame);
//!   only the trees that need a group baked wait for the bake, on one thread, in the scene's
//!   order (so the groups are numbered as before). Looking the 6,000 shapes of the 30-tree scene
//!   up on one thread after the walk was most of `prepare`'s wall time.

use glam::{DMat3, DVec3};
use penmodel_terrain::trees::nodes::STOP;
use penmodel_terrain::trees::{Drawn, Roughness};
use rayon::prelude::*;

use super::Scene;
use super::impostor::Cache;
use crate::raster::camera::Eye;
use crate::raster::textured::Quad;

/// What the trees of the last frame cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TreeStats {
    /// Trees drawn.
    pub trees: usize,
    /// Polygons of copied geometry (frustum quads and rhombus leaves).
    pub polygons: u64,
    /// Simplified shapes drawn (one polygon each).
    pub impostors: usize,
    /// Groups baked into textures so far.
    pub baked: usize,
}

impl TreeStats {
    /// Polygons drawn in all: the copied ones and one per simplified shape.
    pub fn total_polygons(&self) -> u64 {
        self.polygons + self.impostors as u64
    }
}

/// The trees' per-frame buffers and the simplified shapes' textures.
#[derive(Debug, Default)]
pub(crate) struct Trees {
    /// Per tree of the scene, in its order, what it drew this frame.
    drawn: Vec<Walked>,
    cache: Cache,
    stats: TreeStats,
}

/// One tree's frame: what its walk drew and its simplified shapes' polygons.
#[derive(Debug, Default)]
struct Walked {
    drawn: Drawn,
    quads: Vec<Quad>,
    /// Whether `quads` were made: every group the walk drew was baked already.
    made: bool,
}

/// The centre eye and the gaze of `scene` in the terrain's frame (the tilt undone), for a frame
/// of `aspect` = width / height.
pub fn eye_and_gaze(scene: &Scene, aspect: f64) -> (DVec3, DVec3) {
    let vp = scene.camera.viewpoint(Eye::Centre, aspect);
    // The terrain turns by −tilt about the axis through the pivot; the eye, seen from the
    // terrain, turns the other way.
    let back = DMat3::from_axis_angle(vp.axis, -scene.camera.tilt).transpose();
    let eye = back * (vp.eye - vp.pivot) + vp.pivot;
    let centre = 0.5 * (vp.lower_right + vp.upper_left);
    let axis = back * (centre - vp.eye);
    let usable = |g: &DVec3| g.is_finite() && g.length() > 0.0;
    let gaze = scene
        .gaze
        .map(DVec3::from_array)
        .filter(usable)
        .or_else(|| scene.looking_at.map(|p| DVec3::from_array(p) - eye).filter(usable))
        .unwrap_or(axis);
    (eye, gaze.normalize_or(DVec3::NEG_Y))
}

/// The roughness for a tree whose middle is at `middle`, `height` tall, seen from `eye` with
/// `gaze` (unit).
pub(crate) fn roughness(lod: &Roughness, eye: DVec3, gaze: DVec3, middle: DVec3, height: f64) -> f64 {
    let to = middle - eye;
    let d = to.length();
    let theta = if d > 0.0 {
        (to.dot(gaze) / d).clamp(-1.0, 1.0).acos().to_degrees()
    } else {
        0.0
    };
    lod.choose(d, height, theta)
}

impl Trees {
    /// Draws `scene`'s trees for this frame (both eyes), seen from a frame of `aspect`.
    pub(crate) fn prepare(&mut self, scene: &Scene, aspect: f64) {
        self.drawn.resize_with(scene.trees.len(), Walked::default);
        if scene.trees.is_empty() {
            self.stats = TreeStats {
                baked: self.cache.groups(),
                ..TreeStats::default()
            };
            return;
        }
        let (eye, gaze) = eye_and_gaze(scene, aspect);
        let cache = &self.cache;
        scene
            .trees
            .par_iter()
            .zip(self.drawn.par_iter_mut())
            .for_each(|(tree, walked)| {
                let d = &mut walked.drawn;
                d.mesh.positions.clear();
                d.mesh.normals.clear();
                d.mesh.colors.clear();
                d.mesh.indices.clear();
                d.impostors.clear();
                (d.nodes, d.polygons, d.leaves) = (0, 0, 0);
                let q = match &scene.tree_lod {
                    None => STOP,
                    Some(lod) => {
                        let middle = DVec3::new(tree.at[0], tree.base + 0.5 * tree.height, tree.at[1]);
                        roughness(lod, eye, gaze, middle, tree.height)
                    }
                };
                tree.draw(q, scene.time, d);
                walked.quads.clear();
                walked.made = true;
                for imp in &d.impostors {
                    let Some(group) = cache.find(&tree.nodes, imp.node) else {
                        walked.made = false;
                        break;
                    };
                    walked.quads.extend(cache.quad(group, imp, eye));
                }
            });
        if self.drawn.iter().any(|w| !w.made) {
            // Only trees with a group not baked yet ask: the others' groups are all in the cache,
            // so the new groups are numbered in the order the scene first asks for them.
            let unmade = || scene.trees.iter().zip(&self.drawn).filter(|(_, w)| !w.made);
            let wanted =
                unmade().flat_map(|(tree, w)| w.drawn.impostors.iter().map(move |imp| (&tree.nodes, imp.node)));
            self.cache.bake_missing(wanted, &scene.style);
            for (tree, walked) in scene.trees.iter().zip(&mut self.drawn).filter(|(_, w)| !w.made) {
                walked.quads.clear();
                for imp in &walked.drawn.impostors {
                    let group = self.cache.group(&tree.nodes, imp.node, &scene.style);
                    walked.quads.extend(self.cache.quad(group, imp, eye));
                }
                walked.made = true;
            }
        }
        self.stats = TreeStats {
            trees: scene.trees.len(),
            polygons: self.drawn.iter().map(|w| w.drawn.polygons).sum(),
            impostors: self.drawn.iter().map(|w| w.drawn.impostors.len()).sum(),
            baked: self.cache.groups(),
        };
    }

    /// How many trees the last frame drew.
    pub(crate) fn len(&self) -> usize {
        self.drawn.len()
    }

    /// The copied branches and leaves of trees `range` (of the scene's, in its order), coloured:
    /// a mesh per tree.
    pub(crate) fn meshes(
        &self,
        range: std::ops::Range<usize>,
    ) -> impl Iterator<Item = &penmodel_terrain::export::Mesh> + Clone {
        self.drawn[range].iter().map(|w| &w.drawn.mesh)
    }

    /// The simplified shapes' polygons of trees `range`, per tree in the scene's order.
    pub(crate) fn quads(&self, range: std::ops::Range<usize>) -> impl Iterator<Item = &[Quad]> + Clone {
        self.drawn[range].iter().map(|w| &w.quads[..])
    }

    /// The simplified shapes' textures.
    pub(crate) fn cache(&self) -> &Cache {
        &self.cache
    }

    /// What the last frame's trees cost.
    pub(crate) fn stats(&self) -> TreeStats {
        self.stats
    }
}
