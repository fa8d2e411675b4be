//! Projected triangles (or quads) binned by bands of rows, shared by the meshes
//! ([`crate::scene::meshes`]: triangles) and the textured quads ([`super::textured`]: quads): vertices
//! projected once per eye, each polygon listed in the bands of rows its screen extent reaches
//! (every band when it crosses the near plane), and drawn per tile — straight when it lies
//! wholly in front of the near plane (a quad in one pass, [`rasterise::quad_two_sided`]),
//! clipped otherwise (a quad as its two triangles) — from both windings (the rasteriser fills
//! one; rocks are open underneath and leaves and quads are single-sided surfaces), or from the
//! front only for the sides of closed shapes ([`Faces::Front`]).

use super::clip::{self, ClipVertex};
use super::rasterise::{self, Bounds, Sink, Vtx};
use super::transform;

/// Vertices from which a mesh is projected on the pool's threads ([`Binned::vertices_from`]):
/// fewer, and a tree's few hundred cost more to hand out than to project.
const PARALLEL_VERTICES: usize = 4096;

/// Which sides of a triangle are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Faces {
    /// Both: a surface seen from either side (a leaf, a textured quad, a rock open underneath).
    Both,
    /// The front only: a side of a closed shape, whose back faces lie behind its front faces
    /// (a branch's frustum). Its vertices run counter-clockwise seen from the front (the
    /// exports' winding, glTF's); seen through the camera on rows growing downward a front
    /// face is counter-clockwise on screen, and [`rasterise::triangle`] fills clockwise ones, so
    /// it is drawn as `(a, c, b)`.
    Front,
}

/// One eye's projected polygons of `N` corners (3: triangles; 4: quads, corners in order round
/// them), each tagged with a `T` (what it shows).
#[derive(Debug)]
pub(crate) struct Binned<T, const N: usize = 3> {
    clip: Vec<ClipVertex>,
    screen: Vec<Vtx>,
    /// Whether each vertex is in front of the near plane.
    direct: Vec<bool>,
    /// Polygons (indices into `clip`) and their tags.
    triangles: Vec<([u32; N], T)>,
    /// Polygon indices per band of `band_rows` rows.
    bins: Vec<Vec<u32>>,
    band_rows: usize,
    frame_height: usize,
}

impl<T, const N: usize> Default for Binned<T, N> {
    fn default() -> Self {
        Binned {
            clip: Vec::new(),
            screen: Vec::new(),
            direct: Vec::new(),
            triangles: Vec::new(),
            bins: Vec::new(),
            band_rows: 1,
            frame_height: 0,
        }
    }
}

impl<T: Copy, const N: usize> Binned<T, N> {
    /// Forgets the last frame's polygons, for a frame `frame_height` rows tall drawn in bands
    /// of `band_rows` rows.
    pub(crate) fn clear(&mut self, (frame_height, band_rows): (usize, usize)) {
        self.clip.clear();
        self.screen.clear();
        self.direct.clear();
        self.triangles.clear();
        self.band_rows = band_rows.max(1);
        self.frame_height = frame_height;
        let bands = frame_height.div_ceil(self.band_rows);
        self.bins.resize_with(bands, Vec::new);
        self.bins.iter_mut().for_each(Vec::clear);
    }

    /// Adds a vertex; returns its index.
    #[inline]
    pub(crate) fn vertex(&mut self, v: ClipVertex, near: f32) -> u32 {
        let i = self.clip.len() as u32;
        self.direct.push(v.inside(near));
        self.screen.push(transform::project(&v));
        self.clip.push(v);
        i
    }

    /// Adds the `n` vertices `vertex(0)`, …, `vertex(n − 1)`; returns the first one's index.
    /// A large mesh's (a rock field's 10⁵ triangles) are projected on the pool's threads: it was
    /// one side of the eye's join, alone, while the textured polygons took the other.
    pub(crate) fn vertices_from(&mut self, n: usize, near: f32, vertex: impl Fn(usize) -> ClipVertex + Sync) -> u32 {
        use rayon::prelude::*;
        let first = self.clip.len();
        let unset = ClipVertex {
            x: 0.0,
            y: 0.0,
            w: 1.0,
            h: 0.0,
            l: 0.0,
        };
        self.clip.resize(first + n, unset);
        self.screen.resize(first + n, Vtx::default());
        self.direct.resize(first + n, false);
        let fill = |(i, ((c, s), d)): (usize, ((&mut ClipVertex, &mut Vtx), &mut bool))| {
            let v = vertex(i);
            *d = v.inside(near);
            *s = transform::project(&v);
            *c = v;
        };
        let (clip, screen, direct) = (
            &mut self.clip[first..],
            &mut self.screen[first..],
            &mut self.direct[first..],
        );
        if n >= PARALLEL_VERTICES {
            clip.par_iter_mut()
                .zip(screen.par_iter_mut())
                .zip(direct.par_iter_mut())
                .with_min_len(PARALLEL_VERTICES / 4)
                .enumerate()
                .for_each(fill);
        } else {
            clip.iter_mut()
                .zip(screen.iter_mut())
                .zip(direct.iter_mut())
                .enumerate()
                .for_each(fill);
        }
        first as u32
    }

    /// How many vertices were added this frame.
    pub(crate) fn vertices(&self) -> u32 {
        self.clip.len() as u32
    }

    /// Adds polygons (indices of added vertices) with their tags; bin them with
    /// [`Binned::bin`].
    pub(crate) fn extend(&mut self, triangles: impl IntoIterator<Item = ([u32; N], T)>) {
        self.triangles.extend(triangles);
    }

    /// How many polygons (triangles, or quads) were added this frame.
    pub(crate) fn triangles(&self) -> usize {
        self.triangles.len()
    }

    /// Bins the polygons from index `first` on.
    pub(crate) fn bin(&mut self, first: usize) {
        let bands = self.bins.len();
        let one = (1 << rasterise::SUBPIXEL) as f32;
        for (i, (t, _)) in self.triangles.iter().enumerate().skip(first) {
            let (lo, hi) = if t.iter().all(|&k| self.direct[k as usize]) {
                let ys = t.map(|k| self.screen[k as usize].y as f32 / one);
                ys[1..]
                    .iter()
                    .fold((ys[0], ys[0]), |(lo, hi), &y| (lo.min(y), hi.max(y)))
            } else if t.iter().any(|&k| self.direct[k as usize]) {
                // Crosses the near plane: every band may see it.
                (0.0, self.frame_height as f32)
            } else {
                continue;
            };
            let first = (lo.max(0.0) as usize) / self.band_rows;
            let last = ((hi.max(0.0) as usize) / self.band_rows).min(bands.saturating_sub(1));
            for bin in self.bins.iter_mut().take(last + 1).skip(first) {
                bin.push(i as u32);
            }
        }
    }

    /// Draws the polygons that reach the tile `bounds` (its first row starts a band) into
    /// `sink`, after `prepare(sink, tag)` set it up for each and said which faces to draw; a
    /// polygon whose `prepare` returns `None` is skipped.
    pub(crate) fn draw<S: Sink>(
        &self,
        bounds: &Bounds,
        near: f32,
        sink: &mut S,
        mut prepare: impl FnMut(&mut S, T) -> Option<Faces>,
    ) {
        let Some(bin) = self.bins.get(bounds.y0.max(0) as usize / self.band_rows.max(1)) else {
            return;
        };
        for &i in bin {
            let (t, tag) = self.triangles[i as usize];
            let Some(faces) = prepare(sink, tag) else {
                continue;
            };
            let draw = |a: &Vtx, b: &Vtx, c: &Vtx, sink: &mut S| match faces {
                Faces::Both => rasterise::two_sided(a, b, c, bounds, sink),
                Faces::Front => rasterise::triangle(a, c, b, bounds, sink),
            };
            if t.iter().all(|&k| self.direct[k as usize]) {
                let v = t.map(|k| &self.screen[k as usize]);
                if N == 4 && faces == Faces::Both {
                    rasterise::quad_two_sided([v[0], v[1], v[2], v[3]], bounds, sink);
                } else {
                    // A polygon's fan: a triangle is its one triangle.
                    for k in 1..N - 1 {
                        draw(v[0], v[k], v[k + 1], sink);
                    }
                }
                continue;
            }
            // A polygon's fan, each triangle clipped.
            for k in 1..N - 1 {
                // Clipping keeps the winding: the fan's triangles turn as the triangle did.
                let poly = clip::triangle([t[0], t[k], t[k + 1]].map(|i| self.clip[i as usize]), near);
                if poly.len < 3 {
                    continue;
                }
                let v: Vec<Vtx> = poly.vertices[..poly.len].iter().map(transform::project).collect();
                for k in 1..poly.len - 1 {
                    draw(&v[0], &v[k], &v[k + 1], sink);
                }
            }
        }
    }
}
