//! Terrain from ridgelines (seed 002, Yaegashi & Chiba), and the maps the seed reads off any
//! terrain: ridge and valley areas by rain, and insolation.
//!
//! - [`Skeleton`]: ridgelines as a graph of 3D nodes joined by straight segments, with one flank
//!   slope α. A 3D ridgeline (drawn in the air) is a chain; a 2D ridgeline tree gets its node
//!   elevations from [`tree`] (Alg. 2.4, a multi-source shortest path).
//! - [`polygon`]: Alg. 2.1's polygons — per segment its two flank quadrilaterals, per node the
//!   triangles that fill the gaps between its segments' flanks (and cap a ridgeline's ends).
//! - [`dtm`]: the polygons rasterised keeping the maximum, then low-pass filtered ([`filter`]);
//!   updated incrementally with the seed's per-cell winning-polygon array (Alg. 2.3), bit for bit
//!   equal to a full rebuild.
//! - [`grow`]: Alg. 2.5, drops traced down the flanks becoming new ridgelines, round by round.
//! - [`rain`]: uniform rain traced downhill along the Sobel gradient, a pass count per cell, and
//!   the ridge/valley classification.
//! - [`sun`]: per-direction horizon sweeps (Alg. 3.1), direct light (horizon test × Lambert),
//!   sky view over k azimuths, and their combination.
//!
//! Coordinates are the document's: metres in the ground plane, `x` along columns and `y` along
//! rows, cell `(c, r)` centred at `((c + ½)·s, (r + ½)·s)`. Elevations are metres.

pub mod dtm;
pub mod filter;
pub mod gradient;
pub mod grow;
pub mod layer;
mod packed;
pub mod polygon;
pub mod rain;
mod scratch;
mod sections;
pub mod sun;
pub mod tree;
mod walk;

use thiserror::Error;

pub use dtm::Dtm;
pub use filter::Filter;

/// Ridgelines as a graph: 3D nodes `[x, y, z]` (metres) joined by straight segments, all with
/// the flank slope `slope` (radians, in (0, π/2)).
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    /// The nodes, `[x, y, elevation]`.
    pub nodes: Vec<[f64; 3]>,
    /// The segments, as pairs of node indices.
    pub edges: Vec<[u32; 2]>,
    /// The flank slope α in radians.
    pub slope: f64,
}

impl Skeleton {
    /// A 3D ridgeline: a chain through `points`.
    pub fn polyline(points: &[[f64; 3]], slope: f64) -> Skeleton {
        let n = u32::try_from(points.len()).unwrap_or(u32::MAX);
        Skeleton {
            nodes: points.to_vec(),
            edges: (1..n).map(|i| [i - 1, i]).collect(),
            slope,
        }
    }

    /// Checks what the polygons need; `what` names the element in the message
    /// (`ridges.lines[2]`).
    pub fn check(&self, what: &str) -> Result<(), RidgeError> {
        check_slope(self.slope, what)?;
        check_graph(&self.nodes, &self.edges, what, "points")?;
        Ok(())
    }
}

/// Checks what the lines and the trees share: at least two nodes and an edge, every coordinate
/// finite (`{what}.{nodes_field}[i]` names one that is not), every edge joining two different
/// existing nodes.
fn check_graph<const D: usize>(
    nodes: &[[f64; D]],
    edges: &[[u32; 2]],
    what: &str,
    nodes_field: &str,
) -> Result<(), RidgeError> {
    if nodes.len() < 2 || edges.is_empty() {
        return Err(RidgeError::TooShort {
            what: what.to_string(),
            points: nodes.len(),
        });
    }
    for (i, p) in nodes.iter().enumerate() {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(RidgeError::NotFinite {
                what: format!("{what}.{nodes_field}[{i}]"),
            });
        }
    }
    for (i, e) in edges.iter().enumerate() {
        if e.iter().any(|&n| n as usize >= nodes.len()) || e[0] == e[1] {
            return Err(RidgeError::BadEdge {
                what: format!("{what}.edges[{i}]"),
                nodes: nodes.len(),
            });
        }
    }
    Ok(())
}

/// Checks a flank or tree slope in radians: strictly between 0° and 90°.
pub fn check_slope(slope: f64, what: &str) -> Result<(), RidgeError> {
    if slope.is_finite() && slope > 0.0 && slope < std::f64::consts::FRAC_PI_2 {
        Ok(())
    } else {
        Err(RidgeError::Slope {
            what: what.to_string(),
            degrees: slope.to_degrees(),
        })
    }
}

/// Why ridgelines, a tree or a sun cannot be used. Each names the element.
#[allow(missing_docs)] // fields named for what they hold.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RidgeError {
    #[error("{what} has {points} point(s); a ridgeline needs at least 2")]
    TooShort { what: String, points: usize },
    #[error("{what} is not a finite number (NaN or infinite)")]
    NotFinite { what: String },
    #[error("{what} must join two different nodes of the {nodes}")]
    BadEdge { what: String, nodes: usize },
    #[error("{what} is {degrees}°; it must be strictly between 0° and 90°")]
    Slope { what: String, degrees: f64 },
    #[error("{what} closes a cycle; a ridgeline tree must have none")]
    Cycle { what: String },
    #[error("{what} is not connected to the rest of the tree")]
    Disconnected { what: String },
    #[error("{what}: the sun's elevation {degrees}° is not above the horizon (it must be in (0°, 90°])")]
    SunBelowHorizon { what: String, degrees: f64 },
    #[error("{what} is {value}; {expected}")]
    Parameter {
        what: String,
        value: f64,
        expected: &'static str,
    },
}
