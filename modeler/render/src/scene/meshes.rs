//! Placed meshes — rock fields, water, trees — drawn into the terrain's depth buffer.
//!
//! Each eye projects every mesh vertex once (clip space from the same affine map as the terrain,
//! so a rock's rim vertex and the ground under it land on the same pixel and depth) and lights
//! it by its normal (`ambient + (1 − ambient)·|n·L|` with the terrain's light: two-sided, since
//! leaves and the undersides of branches are seen from both sides); triangles are binned by the
//! bands of rows the tiles draw, so a tile looks only at the triangles that reach it. Triangles
//! are drawn from both windings (rocks are closed on top and open underneath, where the ground
//! is; leaves are single quads).
//!
//! What a won sample shows is its [`Paint`]: a whole mesh in one of the style's colours (rocks in
//! [`Style::rock_colour`], water in [`Style::water_colour`]), or per triangle the mean of the
//! mesh's own vertex colours ([`Mesh::colors`], linear RGB, turned to sRGB here). Flat per
//! triangle rather than interpolated per pixel: the depth buffer's sample keeps one colour and
//! two interpolated values (height and light), and a tree's triangles are each bark or leaf.

use penmodel_terrain::export::Mesh;
use penmodel_terrain::trees::shapes::BARK;

use super::Style;
use super::rock_lod;
use crate::raster::binned::{Binned, Faces};
use crate::raster::clip::ClipVertex;
use crate::raster::rasterise::{Bounds, DepthSink, Sample, Surface};
use crate::raster::transform::Affine;

/// How a mesh is coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Paint {
    /// Every triangle shows this surface (rocks, water).
    Whole(Surface),
    /// Each triangle in the mean of its vertices' own colours ([`Mesh::colors`]); a mesh
    /// without colours falls back to the rock colour.
    Own,
    /// A tree's copied geometry ([`penmodel_terrain::trees::shapes`]): coloured as [`Paint::Own`],
    /// and a triangle whose three vertices are in the bark colour is a side of a branch's
    /// frustum, a closed tube, drawn from its front only ([`Faces::Front`]): its back faces
    /// lie behind the front ones, and drawing them was two fifths of the copied branches'
    /// triangles for nothing. (Only the open end of a branch shows the difference: seen
    /// through, 156 of the 30-tree scene's 921,600 pixels.) Leaves stay two-sided.
    Tree,
}

/// sRGB byte of linear intensity `i / (LINEAR_STEPS − 1)`: a table, so that colouring a tree's
/// 10⁵ triangles per frame costs no `powf`.
const LINEAR_STEPS: usize = 1024;

fn srgb_table() -> &'static [u8; LINEAR_STEPS] {
    static TABLE: std::sync::OnceLock<[u8; LINEAR_STEPS]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|i| {
            let c = i as f32 / (LINEAR_STEPS - 1) as f32;
            let s = if c <= 0.003_130_8 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0).round().clamp(0.0, 255.0) as u8
        })
    })
}

/// Linear RGB (0 to 1) → sRGB bytes.
pub(crate) fn srgb(linear: [f32; 3]) -> [u8; 3] {
    let table = srgb_table();
    let last = (LINEAR_STEPS - 1) as f32;
    linear.map(|c| {
        let c = if c.is_finite() { c.clamp(0.0, 1.0) } else { 0.0 };
        table[(c * last + 0.5) as usize]
    })
}

/// One eye's projected meshes.
#[derive(Debug, Default)]
pub struct Projected(Binned<(Surface, Faces)>, PartsCache, RockScratch);

/// [`Projected::add_rocks`]'s per-frame lists, kept so that a frame allocates nothing.
#[derive(Debug, Default)]
struct RockScratch {
    choices: Vec<rock_lod::Choice>,
    /// The whole rocks' vertices, packed: `source[i]` is the mesh's vertex of the i-th.
    source: Vec<u32>,
    triangles: Vec<([u32; 3], Surface)>,
}

/// The last frames' rock meshes' [`rock_lod::parts`], by their indices: a field's triangles stay
/// the same while it follows the terrain (only its positions change), and finding its parts
/// again each frame cost more than comparing the indices.
#[derive(Debug, Default)]
struct PartsCache(Vec<(Vec<u32>, usize, Option<Vec<rock_lod::Part>>)>);

impl PartsCache {
    /// The parts of the `k`-th rock mesh of a frame.
    fn of(&mut self, k: usize, indices: &[u32], vertices: usize) -> Option<&[rock_lod::Part]> {
        if self.0.len() <= k {
            self.0.resize_with(k + 1, Default::default);
        }
        let entry = &mut self.0[k];
        if entry.0 != indices || entry.1 != vertices {
            *entry = (indices.to_vec(), vertices, rock_lod::parts(indices, vertices));
        }
        entry.2.as_deref()
    }
}

impl Projected {
    /// Forgets the last frame's meshes, for a frame `frame_height` rows tall drawn in bands of
    /// `band_rows` rows; then [`Projected::add`] the meshes.
    pub fn clear(&mut self, bands: (usize, usize)) {
        self.0.clear(bands);
    }

    /// Projects `meshes` (the exports' frame: X, Y up, Z, metres) for one eye, painted `paint`,
    /// and bins their triangles. Meshes added later win ties of depth against earlier ones.
    pub fn add<'m>(
        &mut self,
        meshes: impl IntoIterator<Item = &'m Mesh>,
        paint: Paint,
        affine: &Affine,
        cell_size: f64,
        near: f32,
        style: &Style,
    ) {
        add(&mut self.0, meshes, paint, affine, cell_size, near, style);
    }

    /// Projects and bins rock fields like [`Projected::add`] with [`Paint::Whole`]`(`[`Surface::Rock`]`)`,
    /// each rock whose bounding sphere projects within `pixels` of its centre as one quad
    /// ([`super::rock_lod`]); `pixels` 0 draws every rock whole.
    pub fn add_rocks<'m>(
        &mut self,
        meshes: impl IntoIterator<Item = &'m Mesh>,
        pixels: f32,
        affine: &Affine,
        cell_size: f64,
        near: f32,
        style: &Style,
    ) {
        let Projected(binned, cache, scratch) = self;
        let light = super::light::world_light(style);
        let ambient = style.ambient.clamp(0.0, 1.0);
        let s = cell_size as f32;
        for (k, mesh) in meshes.into_iter().enumerate() {
            let n = mesh.positions.len().min(mesh.normals.len());
            let parts = if pixels > 0.0 {
                cache.of(k, &mesh.indices, n)
            } else {
                None
            };
            let Some(parts) = parts else {
                add(
                    binned,
                    [mesh],
                    Paint::Whole(Surface::Rock),
                    affine,
                    cell_size,
                    near,
                    style,
                );
                continue;
            };
            let RockScratch {
                choices,
                source,
                triangles,
            } = scratch;
            rock_lod::choose(mesh, parts, affine, s, near, pixels, (light, ambient), choices);
            source.clear();
            for (part, choice) in parts.iter().zip(choices.iter()) {
                if *choice == rock_lod::Choice::Whole {
                    source.extend(part.vertices.clone().map(|v| v as u32));
                }
            }
            let first = binned.triangles();
            let base = binned.vertices_from(source.len(), near, |i| {
                lit(mesh, source[i] as usize, (light, ambient), affine, s)
            });
            triangles.clear();
            let mut packed = base;
            for (part, choice) in parts.iter().zip(choices.iter()) {
                match choice {
                    rock_lod::Choice::Whole => {
                        // The part's vertex v is packed at `packed + (v − start)`.
                        let shift = packed as i64 - part.vertices.start as i64;
                        let at = |v: u32| (i64::from(v) + shift) as u32;
                        let tris = &mesh.indices[3 * part.triangles.start..3 * part.triangles.end];
                        triangles.extend(
                            tris.chunks_exact(3)
                                .map(|t| ([at(t[0]), at(t[1]), at(t[2])], Surface::Rock)),
                        );
                        packed += part.vertices.len() as u32;
                    }
                    rock_lod::Choice::Quad(corners) => {
                        let [a, b, c, d] = corners.map(|v| binned.vertex(v, near));
                        triangles.push(([a, b, c], Surface::Rock));
                        triangles.push(([a, c, d], Surface::Rock));
                    }
                }
            }
            binned.extend(triangles.drain(..).map(|(t, s)| (t, (s, Faces::Both))));
            binned.bin(first);
        }
    }

    /// How many triangles were added this frame.
    pub fn triangles(&self) -> usize {
        self.0.triangles()
    }

    /// Draws the triangles that reach the tile `bounds` (its first row starts a band) into its
    /// samples.
    pub fn draw(&self, bounds: &Bounds, samples: &mut [Sample], width: usize, near: f32) {
        let mut sink = DepthSink {
            samples,
            width,
            y0: bounds.y0,
            surface: Surface::Rock,
        };
        self.0.draw(bounds, near, &mut sink, |sink, (surface, faces)| {
            sink.surface = surface;
            Some(faces)
        });
    }
}

/// What a triangle shows and which of its faces are drawn.
type Look = (Surface, Faces);

/// [`Projected::add`] into `binned`.
fn add<'m>(
    binned: &mut Binned<(Surface, Faces)>,
    meshes: impl IntoIterator<Item = &'m Mesh>,
    paint: Paint,
    affine: &Affine,
    cell_size: f64,
    near: f32,
    style: &Style,
) {
    let light = super::light::world_light(style);
    let ambient = style.ambient.clamp(0.0, 1.0);
    let s = cell_size as f32;
    let first = binned.triangles();
    for mesh in meshes {
        let n = mesh.positions.len().min(mesh.normals.len());
        let base = binned.vertices_from(n, near, |i| lit(mesh, i, (light, ambient), affine, s));
        let own = matches!(paint, Paint::Own | Paint::Tree);
        let coloured = own && mesh.colors.len() == mesh.positions.len();
        // The last triangle's vertex colours and what they made: a tree's triangles come in
        // long runs of one colour (bark, leaf), and the mean and its sRGB bytes for each were
        // most of the copied polygons' projection (0.7 of 1.4 ms a frame).
        let mut last: Option<([[f32; 3]; 3], Look)> = None;
        binned.extend(mesh.indices.chunks_exact(3).map(|t| {
            let (surface, faces) = match paint {
                Paint::Whole(s) => (s, Faces::Both),
                _ if coloured => {
                    let corners = [0, 1, 2].map(|k| mesh.colors[t[k] as usize]);
                    match last {
                        Some((seen, look)) if seen == corners => look,
                        _ => {
                            let [a, b, c] = corners;
                            let third = 1.0 / 3.0;
                            let colour = Surface::Colour(srgb([0, 1, 2].map(|i| (a[i] + b[i] + c[i]) * third)));
                            let bark = paint == Paint::Tree && corners.iter().all(|&c| c == BARK);
                            let look = (colour, if bark { Faces::Front } else { Faces::Both });
                            last = Some((corners, look));
                            look
                        }
                    }
                }
                _ => (Surface::Rock, Faces::Both),
            };
            ([t[0] + base, t[1] + base, t[2] + base], (surface, faces))
        }));
    }
    binned.bin(first);
}

/// Vertex `i` of `mesh` in clip space (grid cells of `s` metres), lit two-sided:
/// `ambient + (1 − ambient)·|n·L|`.
#[inline]
fn lit(mesh: &Mesh, i: usize, (light, ambient): ([f32; 3], f32), affine: &Affine, s: f32) -> ClipVertex {
    let p = mesh.positions[i];
    let l = super::light::two_sided(mesh.normals[i], light, ambient);
    affine.clip_point(p[0] / s - 0.5, p[2] / s - 0.5, p[1], l)
}
