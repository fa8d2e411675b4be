//! Automatic elevations for a 2D ridgeline tree (Alg. 2.4): a node's elevation is
//! `h_end + d·tan θ`, d the length of its shortest path along the tree to the nearest end node
//! (degree 1), θ a characteristic slope.
//!
//! The seed computes d by a leaves-up pass and a root-down pass; its text stops recursing early
//! and can leave nodes too high. The plain statement is a multi-source shortest path: Dijkstra
//! from every end node at once (in a tree the path between two nodes is unique, but the nearest
//! end is not known in advance), O(E log V).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::{RidgeError, Skeleton};

/// A 2D ridgeline tree.
#[derive(Debug, Clone, PartialEq)]
pub struct Tree {
    /// The nodes `[x, y]`, metres.
    pub nodes: Vec<[f64; 2]>,
    /// The segments, pairs of node indices.
    pub edges: Vec<[u32; 2]>,
    /// The characteristic slope θ, radians, in (0, π/2).
    pub theta: f64,
    /// The end nodes' elevation, metres.
    pub h_end: f64,
}

impl Tree {
    /// Checks the tree: at least two nodes, finite numbers, edges joining two different
    /// existing nodes, no cycle, connected, θ in (0°, 90°). `what` names it (`ridges.trees[0]`).
    pub fn check(&self, what: &str) -> Result<(), RidgeError> {
        super::check_slope(self.theta, &format!("{what}.theta"))?;
        if !self.h_end.is_finite() {
            return Err(RidgeError::NotFinite {
                what: format!("{what}.h_end"),
            });
        }
        super::check_graph(&self.nodes, &self.edges, what, "nodes")?;
        // Union-find: an edge joining two nodes already connected closes a cycle.
        let mut parent: Vec<usize> = (0..self.nodes.len()).collect();
        fn root(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for (i, e) in self.edges.iter().enumerate() {
            let (a, b) = (root(&mut parent, e[0] as usize), root(&mut parent, e[1] as usize));
            if a == b {
                return Err(RidgeError::Cycle {
                    what: format!("{what}.edges[{i}]"),
                });
            }
            parent[a] = b;
        }
        let r0 = root(&mut parent, 0);
        for i in 1..self.nodes.len() {
            if root(&mut parent, i) != r0 {
                return Err(RidgeError::Disconnected {
                    what: format!("{what}.nodes[{i}]"),
                });
            }
        }
        Ok(())
    }

    /// Each node's shortest path length to the nearest end node (degree 1), metres.
    pub fn distances(&self) -> Vec<f64> {
        let n = self.nodes.len();
        let mut adj: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for &[a, b] in &self.edges {
            let (a, b) = (a as usize, b as usize);
            let (p, q) = (self.nodes[a], self.nodes[b]);
            let len = (q[0] - p[0]).hypot(q[1] - p[1]);
            adj[a].push((b, len));
            adj[b].push((a, len));
        }
        let mut dist = vec![f64::INFINITY; n];
        // Lengths are finite and non-negative, so their bits order like the numbers.
        let mut heap = BinaryHeap::new();
        for (i, a) in adj.iter().enumerate() {
            if a.len() == 1 {
                dist[i] = 0.0;
                heap.push(Reverse((0.0f64.to_bits(), i)));
            }
        }
        while let Some(Reverse((d, i))) = heap.pop() {
            let d = f64::from_bits(d);
            if d > dist[i] {
                continue;
            }
            for &(j, len) in &adj[i] {
                let nd = d + len;
                if nd < dist[j] {
                    dist[j] = nd;
                    heap.push(Reverse((nd.to_bits(), j)));
                }
            }
        }
        dist
    }

    /// Each node's elevation, `h_end + d·tan θ`.
    pub fn elevations(&self) -> Vec<f64> {
        let t = self.theta.tan();
        self.distances().iter().map(|d| self.h_end + d * t).collect()
    }

    /// The tree with its elevations as a skeleton of flank slope `slope`.
    pub fn skeleton(&self, slope: f64) -> Skeleton {
        Skeleton {
            nodes: self
                .nodes
                .iter()
                .zip(self.elevations())
                .map(|(p, z)| [p[0], p[1], z])
                .collect(),
            edges: self.edges.clone(),
            slope,
        }
    }
}
