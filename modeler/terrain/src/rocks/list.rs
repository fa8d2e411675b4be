//! A scatter's rocks, stored flat: the polygons, added points, vertices and triangles of a block
//! of rocks each in one list, a rock being ranges in them.
//!
//! Why: a rock owning four vectors made fig. 1 allocate and free about 194 000 of them, some
//! 15 % of a scatter's time. Blocks of `BLOCK` rocks in the order they are made (a fixed
//! split, so the same on any number of threads) are filled on all cores without sharing.

use super::shape::RockMesh;

/// Rocks per block.
pub(crate) const BLOCK: usize = 256;

/// A rock: a kept cell and its mesh, borrowed from its scatter's lists.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rock<'a> {
    /// The diagram (layer index) it came from.
    pub diagram: usize,
    /// The cell (seed index in its diagram).
    pub cell: u32,
    /// The cell's polygon, counter-clockwise in (x, y) (positive area), no repeated vertex.
    pub polygon: &'a [[f64; 2]],
    /// The mesh.
    pub mesh: RockMesh<'a>,
}

/// Where a rock is: its diagram and cell, its block and its index there.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct At {
    pub(crate) diagram: u32,
    pub(crate) cell: u32,
    pub(crate) block: u32,
    pub(crate) index: u32,
}

/// Some rocks' lists; per rock, where its ranges start (one entry more at the end).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Block {
    pub(crate) polygons: Vec<[f64; 2]>,
    pub(crate) polygon_starts: Vec<u32>,
    pub(crate) added: Vec<[f64; 2]>,
    pub(crate) vertices: Vec<[f64; 3]>,
    pub(crate) triangles: Vec<[u32; 3]>,
    /// Starts in `added`, `vertices`, `triangles`.
    pub(crate) mesh_starts: Vec<[u32; 3]>,
}

fn range(starts: &[u32], i: usize) -> std::ops::Range<usize> {
    starts[i] as usize..starts[i + 1] as usize
}

impl Block {
    /// An empty block for `rocks` rocks.
    pub(crate) fn with_rocks(rocks: usize) -> Block {
        let mut b = Block {
            polygon_starts: Vec::with_capacity(rocks + 1),
            mesh_starts: Vec::with_capacity(rocks + 1),
            ..Block::default()
        };
        b.polygon_starts.push(0);
        b.mesh_starts.push([0; 3]);
        b
    }

    /// Closes the polygon pushed onto `polygons` since the last one.
    pub(crate) fn end_polygon(&mut self) {
        self.polygon_starts.push(self.polygons.len() as u32);
    }

    /// Closes the mesh pushed since the last one.
    pub(crate) fn end_mesh(&mut self) {
        self.mesh_starts.push([
            self.added.len() as u32,
            self.vertices.len() as u32,
            self.triangles.len() as u32,
        ]);
    }

    /// Rock `i`'s polygon.
    pub(crate) fn polygon(&self, i: usize) -> &[[f64; 2]] {
        &self.polygons[range(&self.polygon_starts, i)]
    }

    fn mesh(&self, i: usize) -> RockMesh<'_> {
        let (a, b) = (self.mesh_starts[i], self.mesh_starts[i + 1]);
        RockMesh {
            added: &self.added[a[0] as usize..b[0] as usize],
            vertices: &self.vertices[a[1] as usize..b[1] as usize],
            triangles: &self.triangles[a[2] as usize..b[2] as usize],
        }
    }
}

/// A scatter's rocks, diagram by diagram in selection order, each in the order drawn.
#[derive(Debug, Clone, Default)]
pub struct RockList {
    pub(crate) at: Vec<At>,
    pub(crate) blocks: Vec<Block>,
}

impl RockList {
    /// How many.
    pub fn len(&self) -> usize {
        self.at.len()
    }

    /// None.
    pub fn is_empty(&self) -> bool {
        self.at.is_empty()
    }

    /// Rock `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<Rock<'_>> {
        let at = self.at.get(i)?;
        let block = &self.blocks[at.block as usize];
        let k = at.index as usize;
        Some(Rock {
            diagram: at.diagram as usize,
            cell: at.cell,
            polygon: block.polygon(k),
            mesh: block.mesh(k),
        })
    }

    /// The rocks in order.
    pub fn iter(&self) -> Iter<'_> {
        Iter { list: self, next: 0 }
    }
}

/// The rocks of a [`RockList`] in order.
#[derive(Debug, Clone)]
pub struct Iter<'a> {
    list: &'a RockList,
    next: usize,
}

impl<'a> Iterator for Iter<'a> {
    type Item = Rock<'a>;

    fn next(&mut self) -> Option<Rock<'a>> {
        let rock = self.list.get(self.next)?;
        self.next += 1;
        Some(rock)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.list.len() - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for Iter<'_> {}

/// Equal when the rocks are, however they are stored.
impl PartialEq for RockList {
    fn eq(&self, other: &RockList) -> bool {
        self.len() == other.len() && (0..self.len()).all(|i| self.get(i) == other.get(i))
    }
}

impl<'a> IntoIterator for &'a RockList {
    type Item = Rock<'a>;
    type IntoIter = Iter<'a>;

    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}
