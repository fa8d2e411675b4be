//! From the eye to the samples: the camera and its projection, the grid's vertices projected
//! and cut into chunks, clipping, rasterisation into a tile's depth buffer, the triangles and
//! quads binned by bands of rows, textured polygons and their texture levels.

pub(crate) mod binned;
pub(crate) mod camera;
pub(crate) mod clip;
pub(crate) mod mips;
pub(crate) mod rasterise;
pub(crate) mod textured;
pub(crate) mod transform;
