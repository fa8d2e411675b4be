//! A node's own geometry: its branch as a hexagonal frustum and a rhombus leaf for each branch
//! cut off below 2 % of the tree's height, in the tree's unit.

use glam::{DAffine3, DVec3};

/// Sides of a branch's frustum.
pub const SIDES: usize = 6;

/// Polygons of a branch: its six side quads (no caps: the ground or the next branch covers them).
pub const BRANCH_POLYGONS: usize = SIDES;

/// Polygons of a leaf: one rhombus.
pub const LEAF_POLYGONS: usize = 1;

/// The trunk's radius at the ground as a fraction of the trunk's length.
pub const TRUNK_RADIUS: f64 = 0.09;

/// A leaf's length as a fraction of the height of the tree it stands for (in its branch's frame).
pub const LEAF_LENGTH: f64 = 0.7;

/// A leaf's half-width as a fraction of its length.
pub const LEAF_WIDTH: f64 = 0.3;

/// Bark colour, linear RGB.
pub const BARK: [f32; 3] = [0.30, 0.20, 0.12];

/// Leaf colour, linear RGB.
pub const LEAF: [f32; 3] = [0.18, 0.42, 0.12];

/// Vertices, normals, colours and triangles being built (indices local to what was pushed).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Parts {
    /// Positions.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals.
    pub normals: Vec<[f32; 3]>,
    /// Colours.
    pub colors: Vec<[f32; 3]>,
    /// Triangles, three indices each.
    pub indices: Vec<u32>,
}

fn f32x3(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

impl Parts {
    fn push(&mut self, p: DVec3, n: DVec3, c: [f32; 3]) -> u32 {
        let i = self.positions.len() as u32;
        self.positions.push(f32x3(p));
        self.normals.push(f32x3(n.normalize_or(DVec3::Y)));
        self.colors.push(c);
        i
    }

    /// The trunk `(0, 0, 0)–(0, length, 0)` of radii `r0` at the bottom and `r1` at the top,
    /// mapped by `w`: 12 vertices, 12 triangles.
    pub fn branch(&mut self, w: &DAffine3, length: f64, r0: f64, r1: f64) {
        let first = self.positions.len() as u32;
        for k in 0..SIDES {
            let a = std::f64::consts::TAU * k as f64 / SIDES as f64;
            let (s, c) = a.sin_cos();
            // The side's normal leans by the taper.
            let n = w.transform_vector3(DVec3::new(c * length, r0 - r1, s * length));
            self.push(w.transform_point3(DVec3::new(c * r0, 0.0, s * r0)), n, BARK);
            self.push(w.transform_point3(DVec3::new(c * r1, length, s * r1)), n, BARK);
        }
        let sides = SIDES as u32;
        for k in 0..sides {
            let (b0, t0) = (first + 2 * k, first + 2 * k + 1);
            let (b1, t1) = (first + 2 * ((k + 1) % sides), first + 2 * ((k + 1) % sides) + 1);
            self.indices.extend_from_slice(&[b0, t0, b1, b1, t0, t1]);
        }
    }

    /// A rhombus leaf along +Y of `w`'s frame, `length` long: 4 vertices, 2 triangles.
    pub fn leaf(&mut self, w: &DAffine3, length: f64) {
        let half = LEAF_WIDTH * length;
        let n = w.transform_vector3(DVec3::Z);
        let a = self.push(w.transform_point3(DVec3::ZERO), n, LEAF);
        let b = self.push(w.transform_point3(DVec3::new(half, 0.5 * length, 0.0)), n, LEAF);
        let c = self.push(w.transform_point3(DVec3::new(0.0, length, 0.0)), n, LEAF);
        let d = self.push(w.transform_point3(DVec3::new(-half, 0.5 * length, 0.0)), n, LEAF);
        self.indices.extend_from_slice(&[a, b, c, a, c, d]);
    }
}
