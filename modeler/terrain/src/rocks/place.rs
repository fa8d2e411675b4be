//! Rocks set on the ground: a field's rock meshes moved into the document's frame and stood on a
//! surface, as one mesh for the exports and the renderer.
//!
//! Every vertex keeps its height above the ground (0 for a cell's own vertices, eq. 3's `t_z`
//! for the added points) and takes the ground's height under it, so a rock follows the terrain
//! when the terrain changes and nothing else about it is recomputed.

use rayon::prelude::*;

use crate::export::Mesh;
use crate::heightmap::Heightmap;

use super::Scatter;

/// Where a field lies: field cell `(x, y)` is at `origin + (x, y)·cell_size` metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// The field image's corner `(0, 0)` in the document, metres.
    pub origin: [f64; 2],
    /// Metres per field cell (heights above the ground scale the same).
    pub cell_size: f64,
}

/// All rocks of `scatter` as one mesh in the exports' frame (`X = x`, `Y` up, `Z = y`, metres),
/// on the ground `ground(x, y)`; normals averaged over each vertex's triangles, by area.
pub fn mesh(scatter: &Scatter, at: Placement, ground: impl Fn(f64, f64) -> f64 + Sync) -> Mesh {
    Flat::of(scatter).seat(at, ground)
}

/// A field's rocks as flat lists in field coordinates, ready to stand on any ground: made once
/// per scatter, seated at every change of the terrain or the field's place.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Flat {
    /// `[x, y, height above the ground]` per vertex, field cells; `f32` like the meshes made
    /// from it (half the memory to read at every re-seat).
    pub vertices: Vec<[f32; 3]>,
    /// Three vertex indices per triangle.
    pub indices: Vec<u32>,
    /// The rocks in the order of these lists, as indices into the scatter's rocks: in bands of
    /// [`BAND`] cells by their seed's row, along the band by column, so that standing them on the
    /// ground reads the heightmap in step (in the scatter's order, random, the height reads
    /// missed the cache and took most of the time).
    pub order: Vec<u32>,
    /// Blocks of whole rocks, about [`BLOCK`] vertices each: `(first vertex, first rock)` in
    /// [`Flat::order`], with the ends last. Blocks are seated on all cores.
    blocks: Vec<(usize, usize)>,
    /// Per block (each window of [`Flat::blocks`]), the box of its vertices in field cells:
    /// `[min x, min y, max x, max y]` (a change of the terrain elsewhere leaves it as it is).
    boxes: Vec<[f32; 4]>,
    /// Per rock in [`Flat::order`]: its first vertex and its first triangle in `local`; then
    /// the ends.
    starts: Vec<(u32, u32)>,
    /// Per rock in [`Flat::order`], the box of its vertices in field cells, `[min x, min y, max
    /// x, max y]`: a rock within the terrain's squares is seated without holding each vertex in.
    bounds: Vec<[f32; 4]>,
    /// The triangles again, with indices into their own rock's vertices. Seating walks the
    /// rocks one by one, each rock's vertices and normals a few hundred bytes in L1: half the
    /// memory of `indices` to read at every re-seat, and no index beyond the rock to check.
    local: Vec<[u16; 3]>,
    /// Per vertex, the sum of its triangles' upward components `u_y·w_x − u_x·w_y` (field cells²):
    /// the same at every seat, so a normal's other two components are all a seat sums.
    up: Vec<f32>,
}

/// Vertices per block of rocks for the parallel normals.
pub const BLOCK: usize = 8192;

/// Rows of field cells per band of [`Flat::order`].
pub const BAND: f64 = 16.0;

impl Flat {
    /// The rocks of `scatter`, flattened.
    pub fn of(scatter: &Scatter) -> Flat {
        let n: usize = scatter.rocks.iter().map(|r| r.mesh.vertices.len()).sum();
        let t: usize = scatter.rocks.iter().map(|r| r.mesh.triangles.len()).sum();
        let mut order: Vec<u32> = (0..scatter.rocks.len() as u32).collect();
        let seed = |i: u32| {
            let at = &scatter.rocks.at[i as usize];
            scatter.diagrams[at.diagram as usize].seeds[at.cell as usize]
        };
        order.sort_by(|&a, &b| {
            let (p, q) = (seed(a), seed(b));
            ((p[1] / BAND).floor(), p[0])
                .partial_cmp(&((q[1] / BAND).floor(), q[0]))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let mut f = Flat {
            vertices: Vec::with_capacity(n),
            indices: Vec::with_capacity(3 * t),
            order,
            blocks: vec![(0, 0)],
            boxes: Vec::new(),
            starts: Vec::with_capacity(scatter.rocks.len() + 1),
            bounds: Vec::with_capacity(scatter.rocks.len()),
            local: Vec::with_capacity(t),
            up: Vec::with_capacity(n),
        };
        // One rock's upward sums, in f64 (memory reused from rock to rock).
        let mut up: Vec<f64> = Vec::new();
        for (k, &i) in f.order.iter().enumerate() {
            let Some(rock) = scatter.rocks.get(i as usize) else {
                continue;
            };
            let start = f.blocks.last().map_or(0, |b| b.0);
            if f.vertices.len() - start >= BLOCK {
                f.blocks.push((f.vertices.len(), k));
            }
            let base = f.vertices.len() as u32;
            f.starts.push((base, f.local.len() as u32));
            f.vertices
                .extend(rock.mesh.vertices.iter().map(|v| v.map(|c| c as f32)));
            f.indices.extend(rock.mesh.triangles.iter().flatten().map(|i| base + i));
            // A cell has a vertex per cutting neighbour, seeds more than r ≥ 1 pixel apart
            // around it within the field (at most 2²⁴ pixels): far below 2¹⁵ vertices.
            f.local.extend(
                rock.mesh
                    .triangles
                    .iter()
                    .map(|t| t.map(|i| u16::try_from(i).expect("a rock has fewer than 65 536 vertices"))),
            );
            let verts = &f.vertices[base as usize..];
            f.bounds.push(bounds(verts));
            up.clear();
            up.resize(verts.len(), 0.0);
            for t in rock.mesh.triangles.iter() {
                let [a, b, c] = t.map(|i| verts[i as usize]);
                let (u, w) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
                let n = f64::from(u[1]) * f64::from(w[0]) - f64::from(u[0]) * f64::from(w[1]);
                for &i in t {
                    up[i as usize] += n;
                }
            }
            f.up.extend(up.iter().map(|&n| n as f32));
        }
        f.starts.push((f.vertices.len() as u32, f.local.len() as u32));
        if f.blocks.last() != Some(&(f.vertices.len(), f.order.len())) {
            f.blocks.push((f.vertices.len(), f.order.len()));
        }
        f.boxes = f
            .blocks
            .windows(2)
            .map(|w| bounds(&f.vertices[w[0].0..w[1].0]))
            .collect();
        f
    }

    /// The rocks standing on `ground` at `at`.
    pub fn seat(&self, at: Placement, ground: impl Fn(f64, f64) -> f64 + Sync) -> Mesh {
        let mut mesh = Mesh {
            positions: Vec::new(),
            normals: Vec::new(),
            indices: self.indices.clone(),
            colors: Vec::new(),
        };
        self.seat_into(at, ground, &mut mesh);
        mesh
    }

    /// Stands the rocks on `ground` at `at` in `mesh`, reusing its memory: its positions and
    /// normals are rewritten (re-seating a field after the terrain changed allocates nothing).
    /// `mesh` is one this `Flat` seated before, or empty: its indices are taken as they are when
    /// their count matches.
    pub fn seat_into(&self, at: Placement, ground: impl Fn(f64, f64) -> f64 + Sync, mesh: &mut Mesh) {
        if mesh.indices.len() != self.indices.len() {
            mesh.indices.clone_from(&self.indices);
        }
        mesh.positions.resize(self.vertices.len(), [0.0; 3]);
        mesh.normals.resize(self.vertices.len(), [0.0; 3]);
        // Disjoint slices of the outputs, one per block of whole rocks.
        let mut parts = Vec::with_capacity(self.blocks.len());
        let (mut positions, mut normals) = (&mut mesh.positions[..], &mut mesh.normals[..]);
        for w in self.blocks.windows(2) {
            let len = w[1].0 - w[0].0;
            let (p, rest_p) = std::mem::take(&mut positions).split_at_mut(len);
            let (n, rest_n) = std::mem::take(&mut normals).split_at_mut(len);
            (positions, normals) = (rest_p, rest_n);
            parts.push((w[0], w[1], p, n));
        }
        parts.into_par_iter().for_each(|((v0, k0), (_, k1), out, norms)| {
            let mut scratch = Scratch::new();
            for w in self.starts[k0..=k1].windows(2) {
                let ((a, t0), (b, t1)) = (w[0], w[1]);
                let (a, b) = (a as usize - v0, b as usize - v0);
                let verts = &self.vertices[a + v0..b + v0];
                seat_rock(
                    at,
                    &ground,
                    verts,
                    self.faces(a + v0..b + v0, t0 as usize..t1 as usize),
                    &mut out[a..b],
                    &mut norms[a..b],
                    &mut scratch,
                );
            }
        });
    }
}

impl Flat {
    /// One rock's triangles, its vertices and their upward sums, for [`normals_of`].
    #[inline(always)]
    fn faces(&self, verts: std::ops::Range<usize>, tris: std::ops::Range<usize>) -> Faces<'_> {
        Faces {
            tris: &self.local[tris],
            verts: &self.vertices[verts.clone()],
            up: &self.up[verts],
        }
    }
}

/// A rock's part of a [`Flat`] for its normals: triangles with indices into its own vertices.
#[derive(Clone, Copy)]
struct Faces<'a> {
    tris: &'a [[u16; 3]],
    /// In field cells: a seat moves every vertex of a field by the same step across the ground
    /// and changes only heights, so a face's edges across the ground are the same at every seat.
    verts: &'a [[f32; 3]],
    up: &'a [f32],
}

impl Flat {
    /// Stands the rocks on heightmap `map` at `at` in `mesh`, as [`Flat::seat_into`] with
    /// [`ground`], and keeps in `samples` where each vertex reads the heightmap. When the place
    /// and the grid are those of the last call with the same `samples` and `mesh`, only the
    /// heights are read again: a change of the terrain under a field leaves every vertex's
    /// square of the heightmap, its weights and its x and z as they were (finding them was
    /// about half of a re-seat). The samples are written on the second seat at a place, not
    /// while the field moves. `samples` belongs to `mesh` (clear it when the mesh is reset).
    pub fn seat_on(&self, at: Placement, map: &Heightmap, samples: &mut Samples, mesh: &mut Mesh) {
        self.seat_on_within(at, map, samples, mesh, None);
    }

    /// [`Flat::seat_on`] after a change of the terrain only within `changed` (metres, `[x0, y0,
    /// x1, y1]`; `None`: anywhere): when only the heights are read again, the blocks of rocks
    /// whose vertices all lie outside it (and a cell beyond, whose heights they blend) keep
    /// their positions and normals. Each rock's normals are its own, so the mesh is the same bit
    /// for bit as a whole re-seat's.
    pub fn seat_on_within(
        &self,
        at: Placement,
        map: &Heightmap,
        samples: &mut Samples,
        mesh: &mut Mesh,
        changed: Option<[f64; 4]>,
    ) {
        let g = ground(map);
        let key = Some((at, map.cols(), map.rows(), map.cell_size().to_bits()));
        let n = self.vertices.len();
        let again = samples.key == key
            && samples.at.len() == n
            && mesh.positions.len() == n
            && mesh.normals.len() == n
            && mesh.indices.len() == self.indices.len()
            && g.wide;
        // The samples are found on the second seat at one place: while a field is being moved
        // every seat is at a new place, and writing them would only slow those seats down.
        let find = !again && samples.last == key;
        samples.last = key;
        samples.key = None;
        if find {
            samples.at.resize(n, Sample::default());
        }
        if mesh.indices.len() != self.indices.len() {
            mesh.indices.clone_from(&self.indices);
        }
        mesh.positions.resize(n, [0.0; 3]);
        mesh.normals.resize(n, [0.0; 3]);
        let mut parts = Vec::with_capacity(self.blocks.len());
        // A moving field keeps no samples: its blocks get none.
        let (mut positions, mut normals, mut sampled) = (
            &mut mesh.positions[..],
            &mut mesh.normals[..],
            if again || find {
                &mut samples.at[..]
            } else {
                &mut [][..]
            },
        );
        for w in self.blocks.windows(2) {
            let len = w[1].0 - w[0].0;
            let (p, rest_p) = std::mem::take(&mut positions).split_at_mut(len);
            let (q, rest_q) = std::mem::take(&mut normals).split_at_mut(len);
            let kept = len.min(sampled.len());
            let (r, rest_r) = std::mem::take(&mut sampled).split_at_mut(kept);
            (positions, normals, sampled) = (rest_p, rest_q, rest_r);
            parts.push((w[0], w[1], p, q, r));
        }
        let cell = at.cell_size;
        // The changed rectangle in field cells, a terrain cell wider each way.
        let within = changed.filter(|_| again).map(|r| {
            let m = map.cell_size();
            [
                ((r[0] - m - at.origin[0]) / cell) as f32,
                ((r[1] - m - at.origin[1]) / cell) as f32,
                ((r[2] + m - at.origin[0]) / cell) as f32,
                ((r[3] + m - at.origin[1]) / cell) as f32,
            ]
        });
        let parts: Vec<_> = parts
            .into_iter()
            .zip(&self.boxes)
            .filter(|(_, b)| within.is_none_or(|r| b[0] <= r[2] && r[0] <= b[2] && b[1] <= r[3] && r[1] <= b[3]))
            .map(|(p, _)| p)
            .collect();
        parts
            .into_par_iter()
            .for_each(|((v0, k0), (_, k1), out, norms, sampled)| {
                // The ground and the place as this block's own values, not read through the
                // closure's references: the compiler could not tell that the writes to the mesh
                // leave them unchanged, and loaded their fields again at every vertex.
                let (g, at, cell) = (g, at, cell);
                let mut scratch = Scratch::new();
                for (w, bounds) in self.starts[k0..=k1].windows(2).zip(&self.bounds[k0..k1]) {
                    let ((a, t0), (b, t1)) = (w[0], w[1]);
                    let (a, b) = (a as usize - v0, b as usize - v0);
                    let out = &mut out[a..b];
                    let verts = &self.vertices[a + v0..b + v0];
                    if again {
                        // The sample holds the vertex's height above the ground too, so the
                        // vertices need not be read at all.
                        for (o, q) in out.iter_mut().zip(&sampled[a..b]) {
                            o[1] = (g.at(*q) + f64::from(q.lift) * cell) as f32;
                        }
                    } else if find {
                        for ((o, v), q) in out.iter_mut().zip(verts).zip(&mut sampled[a..b]) {
                            let (x, y) = place(at, *v);
                            *q = Sample {
                                lift: v[2],
                                ..g.sample(x, y)
                            };
                            *o = [x as f32, (g.at(*q) + f64::from(v[2]) * cell) as f32, y as f32];
                        }
                    } else {
                        // Moving: [`Flat::seat_into`]'s heights, with the ground's code inlined
                        // here rather than called through a closure at every vertex (the call
                        // was a fifth of a move's re-seat).
                        if g.holds(at, *bounds) {
                            for (o, v) in out.iter_mut().zip(verts) {
                                let (x, y) = place(at, *v);
                                *o = [
                                    x as f32,
                                    (g.height_inside(x, y) + f64::from(v[2]) * cell) as f32,
                                    y as f32,
                                ];
                            }
                        } else {
                            for (o, v) in out.iter_mut().zip(verts) {
                                let (x, y) = place(at, *v);
                                *o = [x as f32, (g.height(x, y) + f64::from(v[2]) * cell) as f32, y as f32];
                            }
                        }
                    }
                    normals_of(
                        out,
                        self.faces(a + v0..b + v0, t0 as usize..t1 as usize),
                        cell,
                        &mut norms[a..b],
                        &mut scratch,
                    );
                }
            });
        if again || find {
            samples.key = key;
        }
    }
}

/// Where the vertices of a [`Flat`] read a heightmap, for [`Flat::seat_on`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Samples {
    /// The place and the grid (columns, rows, cell size's bits) they were found for.
    key: Option<(Placement, u32, u32, u64)>,
    /// The same for the last seat, with or without samples.
    last: Option<(Placement, u32, u32, u64)>,
    at: Vec<Sample>,
}

impl Samples {
    /// Forgets them (the next seat finds them again).
    pub fn clear(&mut self) {
        self.key = None;
        self.last = None;
        self.at.clear();
    }
}

/// A point's square of the heightmap and its place in it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sample {
    /// The square's upper left centre, `row · columns + column`.
    corner: u32,
    /// For a rock vertex in [`Samples`], its height above the ground in field cells (the
    /// vertex's third coordinate; 0 from [`Ground::sample`]). Kept here, in what would be
    /// padding, so a re-seat after a change of the terrain reads 24 bytes a vertex, not 36.
    lift: f32,
    /// Along the columns and the rows, 0 to 1 (as computed, so that a height read again is the
    /// one [`Ground::height`] gives).
    u: f64,
    v: f64,
}

/// The box of `vertices` across the ground, `[min x, min y, max x, max y]`.
fn bounds(vertices: &[[f32; 3]]) -> [f32; 4] {
    vertices.iter().fold(
        [f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY],
        |b, v| [b[0].min(v[0]), b[1].min(v[1]), b[2].max(v[0]), b[3].max(v[1])],
    )
}

/// Vertex `v`'s `(x, y)` in metres at `at`.
#[inline]
fn place(at: Placement, v: [f32; 3]) -> (f64, f64) {
    (
        at.origin[0] + f64::from(v[0]) * at.cell_size,
        at.origin[1] + f64::from(v[1]) * at.cell_size,
    )
}

/// Stands one rock: its vertices on `ground`, then its normals ([`normals_of`]).
#[inline]
fn seat_rock(
    at: Placement,
    ground: &impl Fn(f64, f64) -> f64,
    verts: &[[f32; 3]],
    faces: Faces<'_>,
    out: &mut [[f32; 3]],
    norms: &mut [[f32; 3]],
    scratch: &mut Scratch,
) {
    for (o, v) in out.iter_mut().zip(verts) {
        let (x, y) = place(at, *v);
        *o = [
            x as f32,
            (ground(x, y) + f64::from(v[2]) * at.cell_size) as f32,
            y as f32,
        ];
    }
    normals_of(out, faces, at.cell_size, norms, scratch);
}

/// Vertices a rock may have for [`normals_of`]'s fixed arrays (more take the general way).
const SCRATCH: usize = 256;

/// [`normals_of`]'s working memory, one per block of rocks: fixed arrays, so that a triangle's
/// indices taken as bytes need no range checks (they were a fifth of the normals' instructions).
struct Scratch {
    heights: [f32; SCRATCH],
    /// The vertices' `(x, y)`, field cells.
    across: [[f32; 2]; SCRATCH],
    sums: [[f32; 2]; SCRATCH],
}

impl Scratch {
    fn new() -> Scratch {
        Scratch {
            heights: [0.0; SCRATCH],
            across: [[0.0; 2]; SCRATCH],
            sums: [[0.0; 2]; SCRATCH],
        }
    }
}

/// A rock's normals from its heights (`out[k][1]`, metres) and its faces at `cell` metres a
/// field cell: each triangle's normal `(b − a) × (c − a)` divided by `cell`, summed in triangle
/// order and normalised. Its upward part is the precomputed [`Faces::up`]; the other two are
/// linear in the heights over the faces' edges across the ground (every access within
/// the rock's few hundred bytes).
#[inline(always)]
fn normals_of(out: &[[f32; 3]], faces: Faces<'_>, cell: f64, norms: &mut [[f32; 3]], scratch: &mut Scratch) {
    let n = out.len();
    if n <= SCRATCH {
        for (((h, xy), o), v) in scratch
            .heights
            .iter_mut()
            .zip(&mut scratch.across)
            .zip(out)
            .zip(faces.verts)
        {
            *h = o[1];
            *xy = [v[0], v[1]];
        }
        let sums = &mut scratch.sums[..n];
        sums.fill([0.0; 2]);
        // Below `SCRATCH` vertices an index is its low byte.
        sum_faces(&scratch.heights, &scratch.across, &mut scratch.sums, faces.tris, |i| {
            usize::from(i as u8)
        });
    } else {
        let heights: Vec<f32> = out.iter().map(|o| o[1]).collect();
        let across: Vec<[f32; 2]> = faces.verts.iter().map(|v| [v[0], v[1]]).collect();
        let mut sums = vec![[0.0; 2]; n];
        sum_faces(&heights, &across, &mut sums, faces.tris, usize::from);
        return finish_normals(&sums, faces.up, cell, norms);
    }
    finish_normals(&scratch.sums[..n], faces.up, cell, norms);
}

/// The sums of [`normals_of`] across the ground, each face's added to its three vertices.
#[inline(always)]
fn sum_faces(
    heights: &[f32],
    across: &[[f32; 2]],
    sums: &mut [[f32; 2]],
    tris: &[[u16; 3]],
    index: impl Fn(u16) -> usize,
) {
    for t in tris {
        let (a, b, c) = (index(t[0]), index(t[1]), index(t[2]));
        let ha = heights[a];
        let (du, dw) = (heights[b] - ha, heights[c] - ha);
        let (pa, pb, pc) = (across[a], across[b], across[c]);
        let e = [pb[0] - pa[0], pb[1] - pa[1], pc[0] - pa[0], pc[1] - pa[1]];
        // `u × w` with `u = (e0·cell, du, e1·cell)`, `w = (e2·cell, dw, e3·cell)`, over `cell`.
        let (nx, nz) = (du * e[3] - e[1] * dw, e[0] * dw - du * e[2]);
        for k in [a, b, c] {
            let s = &mut sums[k];
            *s = [s[0] + nx, s[1] + nz];
        }
    }
}

/// [`normals_of`]'s normals from the sums across the ground and the upward ones, normalised.
#[inline(always)]
fn finish_normals(sums: &[[f32; 2]], up: &[f32], cell: f64, norms: &mut [[f32; 3]]) {
    let cell = cell as f32;
    for ((s, &up), o) in sums.iter().zip(up).zip(norms) {
        let s = [s[0], up * cell, s[1]];
        let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        *o = if len > 0.0 {
            // One division, not three (a re-seat waits on them).
            let inv = 1.0 / len;
            [s[0] * inv, s[1] * inv, s[2] * inv]
        } else {
            [0.0, 1.0, 0.0]
        };
    }
}

/// The terrain's surface, its height at `(x, y)` metres the one its mesh draws: heights at cell
/// centres, two triangles per square of four centres split along the diagonal from the upper
/// right to the lower left centre (as [`crate::export::Mesh`]); held flat beyond the outer
/// centres.
pub fn ground(map: &Heightmap) -> Ground<'_> {
    let (cols, rows) = (map.cols(), map.rows());
    Ground {
        h: map.heights(),
        cols,
        rows,
        last: [f64::from(cols - 1), f64::from(rows - 1)],
        max: [cols.saturating_sub(2), rows.saturating_sub(2)],
        // With two or more columns and rows, the square's four corners are in the grid as they
        // are (`c ≤ cols − 2`); only a grid one cell wide needs its indices held in.
        wide: cols >= 2 && rows >= 2,
        // Multiplied, not divided: two divisions per rock vertex were a tenth of a re-seat.
        per_metre: 1.0 / map.cell_size(),
    }
}

/// A heightmap's surface ([`ground`]): [`Ground::height`], or a point's [`Sample`] found once
/// and its height read at each change of the terrain ([`Ground::at`]).
#[derive(Debug, Clone, Copy)]
pub struct Ground<'a> {
    h: &'a [f32],
    cols: u32,
    rows: u32,
    last: [f64; 2],
    max: [u32; 2],
    wide: bool,
    per_metre: f64,
}

impl<'a> Ground<'a> {
    /// The height at `(x, y)` metres.
    #[inline(always)]
    pub fn height(&self, x: f64, y: f64) -> f64 {
        self.at(self.sample(x, y))
    }

    /// Where `(x, y)` metres reads the heightmap.
    #[inline(always)]
    pub fn sample(&self, x: f64, y: f64) -> Sample {
        // `clamp` without its check that the bounds are in order (they are: `last` ≥ 0), which
        // it made at every rock vertex; the same value, NaN included.
        let hold = |f: f64, last: f64| {
            if f < 0.0 {
                0.0
            } else if f > last {
                last
            } else {
                f
            }
        };
        let fx = hold(x * self.per_metre - 0.5, self.last[0]);
        let fy = hold(y * self.per_metre - 0.5, self.last[1]);
        let (c, r) = ((fx as u32).min(self.max[0]), (fy as u32).min(self.max[1]));
        Sample {
            corner: r * self.cols + c,
            lift: 0.0,
            u: fx - f64::from(c),
            v: fy - f64::from(r),
        }
    }

    /// Whether every point of the box `b` (`[min x, min y, max x, max y]`, field cells) at `at`
    /// falls in the grid's squares, not beyond its outer centres: there [`Ground::height_inside`]
    /// gives [`Ground::height`]'s value. Each step from field cells to the heightmap's
    /// coordinates is a rounded sum or product with a positive factor, so it keeps the order of
    /// the points, and the box's corners bound its vertices' coordinates as computed.
    #[inline]
    pub fn holds(&self, at: Placement, b: [f32; 4]) -> bool {
        let f = |v: f32, o: f64| (o + f64::from(v) * at.cell_size) * self.per_metre - 0.5;
        self.wide
            && at.cell_size > 0.0
            && self.per_metre > 0.0
            && f(b[0], at.origin[0]) >= 0.0
            && f(b[1], at.origin[1]) >= 0.0
            && f(b[2], at.origin[0]) < self.last[0]
            && f(b[3], at.origin[1]) < self.last[1]
    }

    /// [`Ground::height`] at a point [`Ground::holds`] found in the grid's squares: nothing to
    /// hold in (about a fifth of a moving field's seat went into holding every vertex in).
    #[inline(always)]
    pub fn height_inside(&self, x: f64, y: f64) -> f64 {
        let (fx, fy) = (x * self.per_metre - 0.5, y * self.per_metre - 0.5);
        let (c, r) = (fx as u32, fy as u32);
        let (a, b, d, e) = self.corners(r * self.cols + c);
        blend(a, b, d, e, fx - f64::from(c), fy - f64::from(r))
    }

    /// The heights at the four centres about corner `i` of a grid two or more cells wide.
    #[inline(always)]
    fn corners(&self, i: u32) -> (f32, f32, f32, f32) {
        let i = i as usize;
        let stride = self.cols as usize;
        // One range check for the square's four corners.
        match self.h.get(i..i + stride + 2) {
            Some(s) => (s[0], s[1], s[stride], s[stride + 1]),
            None => (0.0, 0.0, 0.0, 0.0),
        }
    }

    /// The height at sample `q`.
    // Inlined into the seating loops (called, it took a third of a re-seat, reloading the
    // ground's fields at every vertex).
    #[inline(always)]
    pub fn at(&self, q: Sample) -> f64 {
        let h = self.h;
        let (a, b, d, e) = if self.wide {
            self.corners(q.corner)
        } else {
            let (cols, rows) = (self.cols, self.rows);
            let (c, r) = (q.corner % cols, q.corner / cols);
            let at = |c: u32, r: u32| h[(r.min(rows - 1) * cols + c.min(cols - 1)) as usize];
            (at(c, r), at(c + 1, r), at(c, r + 1), at(c + 1, r + 1))
        };
        blend(a, b, d, e, q.u, q.v)
    }

    /// The same as a function of `(x, y)`, for [`Flat::seat_into`] and [`mesh`].
    pub fn surface(self) -> impl Fn(f64, f64) -> f64 + Sync + 'a {
        move |x, y| self.height(x, y)
    }
}

/// The height at `(u, v)` in a square of the ground with corner heights `a` (upper left), `b`
/// (right of it), `d` (below it) and `e` (diagonal).
#[inline(always)]
fn blend(a: f32, b: f32, d: f32, e: f32, u: f64, v: f64) -> f64 {
    let (a, b, d, e) = (f64::from(a), f64::from(b), f64::from(d), f64::from(e));
    // The lower triangle `a + u·(b − a) + v·(d − a)` or the upper one, `e + (1 − u)·(d − e)
    // + (1 − v)·(b − e)` = `(b + d − e) + u·(e − d) + v·(e − b)`, blended by a 0 or 1
    // rather than branched on: which half a rock vertex falls in is random, and the
    // mispredicted branch was a tenth of a re-seat.
    let upper = f64::from(u8::from(u + v > 1.0));
    let base = a + upper * (b + d - e - a);
    let along_u = (b - a) + upper * (e - d - (b - a));
    let along_v = (d - a) + upper * (e - b - (d - a));
    base + u * along_u + v * along_v
}

/// Area-weighted vertex normals of a triangle list (counter-clockwise seen from +Y).
pub fn normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut sum = vec![[0.0f64; 3]; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize].map(f64::from));
        let (u, v) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        for &i in t {
            let s = &mut sum[i as usize];
            s[0] += n[0];
            s[1] += n[1];
            s[2] += n[2];
        }
    }
    sum.into_iter()
        .map(|n| {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 {
                [(n[0] / len) as f32, (n[1] / len) as f32, (n[2] / len) as f32]
            } else {
                [0.0, 1.0, 0.0]
            }
        })
        .collect()
}
