//! Where water goes: depressions resolved by priority flood, D8 receivers, the stack (cells in
//! an order where every cell comes after its receiver) and drainage area.
//!
//! The grid's edge cells are the outlets. Steepest descent (D8) gives each cell its lowest
//! neighbour as receiver; the receivers form a forest, and the stack is that forest walked from
//! its roots (Braun & Willett 2013), O(n). Cells whose tree ends in a pit (an inner cell with no
//! lower neighbour) are resolved by **Priority-Flood+ε** (Barnes, Lehman & Mulla 2014, alg. 3)
//! started from the drained cells around them: lowest first, a cell not higher than the one that
//! reached it is raised to the next `f64` above it (and taken from a plain queue before the heap,
//! so a flat or a lake costs no heap operations). The filled surface has no flat and no pit.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use rayon::prelude::*;

/// The 8 neighbours as `(dc, dr)`, in a fixed order (ties go to the first).
pub const D8: [(i32, i32); 8] = [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1)];

/// A total order of `f64` as `u64` (negative values below positive ones).
fn key(z: f64) -> u64 {
    let b = z.to_bits();
    if b >> 63 == 1 { !b } else { b | (1 << 63) }
}

/// The next `f64` above `z` (finite `z`).
fn next_up(z: f64) -> f64 {
    if z == 0.0 {
        return f64::from_bits(1);
    }
    let b = z.to_bits();
    f64::from_bits(if z > 0.0 { b + 1 } else { b - 1 })
}

/// The drainage of one surface: reused between steps, so a step allocates nothing.
pub struct Routing {
    cols: usize,
    rows: usize,
    /// The surface with depressions filled (ε above their spill).
    pub filled: Vec<f64>,
    /// Each cell's receiver (itself at the edge).
    pub receiver: Vec<u32>,
    /// The distance to the receiver in cells (1 or √2; 1 at the edge).
    pub dist: Vec<f64>,
    /// Cells, every one after its receiver.
    pub stack: Vec<u32>,
    /// Drainage area in cells (the cell itself included).
    pub area: Vec<f64>,
    /// Whether a cell is in the stack already (drained, or reached by the flood).
    closed: Vec<bool>,
    heap: BinaryHeap<Reverse<(u64, u32)>>,
    pit: VecDeque<u32>,
    donors: Vec<u32>,
    first: Vec<u32>,
    fill_at: Vec<u32>,
    /// Inner cells with no lower neighbour, and the cells that drain into them.
    sinks: Vec<u32>,
}

impl Routing {
    /// Buffers for a `cols × rows` grid.
    pub fn new(cols: usize, rows: usize) -> Routing {
        let n = cols * rows;
        Routing {
            cols,
            rows,
            filled: vec![0.0; n],
            receiver: vec![0; n],
            dist: vec![1.0; n],
            stack: Vec::with_capacity(n),
            area: vec![0.0; n],
            closed: vec![false; n],
            heap: BinaryHeap::new(),
            pit: VecDeque::new(),
            donors: vec![0; n],
            first: vec![0; n + 1],
            fill_at: vec![0; n + 1],
            sinks: Vec::new(),
        }
    }

    /// Routes water over `h` (finite heights, row-major): receivers, stack, fill and area.
    ///
    /// Steepest descent on `h` itself drains most cells of eroded land to the edge; only the
    /// cells that drain into a pit (an inner cell with no lower neighbour) are flooded, from the
    /// drained cells around them, by Priority-Flood+ε: each takes the cell that reached it as
    /// its receiver and the flood's order as its place in the stack. Every cell's filled height
    /// and receiver are what a flood of the whole grid from its edge would give, except that a
    /// flooded cell drains to the neighbour the flood came from rather than the steepest.
    pub fn route(&mut self, h: &[f64]) {
        self.receivers(h);
        self.flats(h);
        self.donors();
        self.drained();
        if !self.sinks.is_empty() {
            self.flood(h);
        }
        self.accumulate();
    }

    fn receivers(&mut self, h: &[f64]) {
        let (cols, rows) = (self.cols, self.rows);
        self.receiver
            .par_chunks_mut(cols)
            .zip(self.dist.par_chunks_mut(cols))
            .enumerate()
            .for_each(|(r, (rcv, dist))| {
                for c in 0..cols {
                    let i = r * cols + c;
                    rcv[c] = i as u32;
                    dist[c] = 1.0;
                    if c == 0 || r == 0 || c + 1 == cols || r + 1 == rows {
                        continue;
                    }
                    let mut best = 0.0;
                    for (k, (dc, dr)) in D8.into_iter().enumerate() {
                        let n = (r as i32 + dr) as usize * cols + (c as i32 + dc) as usize;
                        let d = if k < 4 { 1.0 } else { std::f64::consts::SQRT_2 };
                        let s = (h[i] - h[n]) / d;
                        if s > best {
                            best = s;
                            rcv[c] = n as u32;
                            dist[c] = d;
                        }
                    }
                }
            });
        self.filled.copy_from_slice(h);
    }

    /// Gives the cells of a flat a way out across it: breadth-first from the flat's cells that
    /// have a lower neighbour (or are on the edge), each cell of the flat drains to the one the
    /// search came from, so a plain drains to its rim in O(its cells) instead of being flooded.
    fn flats(&mut self, h: &[f64]) {
        let (cols, rows) = (self.cols as i32, self.rows as i32);
        let inner = |i: usize| {
            let (c, r) = ((i % cols as usize) as i32, (i / cols as usize) as i32);
            c > 0 && r > 0 && c + 1 < cols && r + 1 < rows
        };
        let mut queue = std::mem::take(&mut self.pit);
        queue.clear();
        // A cell takes, as receiver, a neighbour of its height that already drains: one
        // that drained before this pass or was given a way out earlier in it, so the
        // receivers stay a forest.
        let settle = |rcv: &mut [u32], dist: &mut [f64], i: usize, queue: &mut VecDeque<u32>| {
            let (c, r) = ((i % cols as usize) as i32, (i / cols as usize) as i32);
            for (k, (dc, dr)) in D8.into_iter().enumerate() {
                let n = (r + dr) as usize * cols as usize + (c + dc) as usize;
                if h[n] == h[i] && (rcv[n] as usize != n || !inner(n)) {
                    rcv[i] = n as u32;
                    dist[i] = if k < 4 { 1.0 } else { std::f64::consts::SQRT_2 };
                    queue.push_back(i as u32);
                    return;
                }
            }
        };
        for i in 0..(cols * rows) as usize {
            if inner(i) && self.receiver[i] as usize == i {
                settle(&mut self.receiver, &mut self.dist, i, &mut queue);
            }
        }
        // Then across each flat, breadth-first from those cells.
        while let Some(p) = queue.pop_front() {
            let p = p as usize;
            let (c, r) = ((p % cols as usize) as i32, (p / cols as usize) as i32);
            for (k, (dc, dr)) in D8.into_iter().enumerate() {
                let n = (r + dr) as usize * cols as usize + (c + dc) as usize;
                if inner(n) && self.receiver[n] as usize == n && h[n] == h[p] {
                    self.receiver[n] = p as u32;
                    self.dist[n] = if k < 4 { 1.0 } else { std::f64::consts::SQRT_2 };
                    queue.push_back(n as u32);
                }
            }
        }
        self.pit = queue;
    }

    /// Donors laid out per receiver (a counting sort).
    fn donors(&mut self) {
        let n = self.cols * self.rows;
        self.first.iter_mut().for_each(|f| *f = 0);
        for i in 0..n {
            let r = self.receiver[i] as usize;
            if r != i {
                self.first[r + 1] += 1;
            }
        }
        for i in 0..n {
            self.first[i + 1] += self.first[i];
        }
        self.fill_at.copy_from_slice(&self.first);
        for i in 0..n {
            let r = self.receiver[i] as usize;
            if r != i {
                self.donors[self.fill_at[r] as usize] = i as u32;
                self.fill_at[r] += 1;
            }
        }
    }

    /// The stack of the cells that drain to the edge, breadth-first from each edge cell (a
    /// cell's receiver is always pushed before it); the cells that drain to pits in `sinks`.
    fn drained(&mut self) {
        let (cols, rows) = (self.cols, self.rows);
        self.stack.clear();
        self.sinks.clear();
        self.closed.iter_mut().for_each(|c| *c = false);
        for root in 0..cols * rows {
            if self.receiver[root] as usize != root {
                continue;
            }
            let (c, r) = (root % cols, root / cols);
            let edge = c == 0 || r == 0 || c + 1 == cols || r + 1 == rows;
            let list = if edge { &mut self.stack } else { &mut self.sinks };
            let start = list.len();
            list.push(root as u32);
            let mut k = start;
            while k < list.len() {
                let x = list[k] as usize;
                let (a, b) = (self.first[x] as usize, self.first[x + 1] as usize);
                list.extend_from_slice(&self.donors[a..b]);
                k += 1;
            }
        }
        for &i in &self.stack {
            self.closed[i as usize] = true;
        }
    }

    /// Priority-Flood+ε over the cells in `sinks`, from the drained cells beside them.
    fn flood(&mut self, h: &[f64]) {
        let (cols, rows) = (self.cols as i32, self.rows as i32);
        self.heap.clear();
        self.pit.clear();
        let neighbours = |i: usize| {
            let (c, r) = ((i % cols as usize) as i32, (i / cols as usize) as i32);
            D8.into_iter().enumerate().filter_map(move |(k, (dc, dr))| {
                let (nc, nr) = (c + dc, r + dr);
                (nc >= 0 && nr >= 0 && nc < cols && nr < rows).then(|| (k, nr as usize * cols as usize + nc as usize))
            })
        };
        // Seeds: drained cells next to a flooded one, each once (`fill_at`, free after
        // `donors`, marks them).
        for &s in &self.sinks {
            for (_, n) in neighbours(s as usize) {
                if self.closed[n] && self.fill_at[n] != u32::MAX {
                    self.fill_at[n] = u32::MAX;
                    self.heap.push(Reverse((key(h[n]), n as u32)));
                }
            }
        }
        loop {
            let c = match self.pit.pop_front() {
                Some(c) => c as usize,
                None => match self.heap.pop() {
                    Some(Reverse((_, c))) => c as usize,
                    None => break,
                },
            };
            let spill = next_up(self.filled[c]);
            for (k, n) in neighbours(c) {
                if self.closed[n] {
                    continue;
                }
                self.closed[n] = true;
                self.receiver[n] = c as u32;
                self.dist[n] = if k < 4 { 1.0 } else { std::f64::consts::SQRT_2 };
                self.stack.push(n as u32);
                if h[n] <= spill {
                    self.filled[n] = spill;
                    self.pit.push_back(n as u32);
                } else {
                    self.filled[n] = h[n];
                    self.heap.push(Reverse((key(h[n]), n as u32)));
                }
            }
        }
    }

    fn accumulate(&mut self) {
        self.area.iter_mut().for_each(|a| *a = 1.0);
        for &i in self.stack.iter().rev() {
            let r = self.receiver[i as usize] as usize;
            if r != i as usize {
                self.area[r] += self.area[i as usize];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pit_drains_through_its_spill_and_every_cell_reaches_the_edge() {
        // A 5 × 5 bowl: the middle is a pit below its rim, the rim's lowest cell is (4, 2).
        let mut h = vec![10.0; 25];
        for r in 1..4 {
            for c in 1..4 {
                h[r * 5 + c] = 5.0;
            }
        }
        h[2 * 5 + 2] = 1.0;
        h[2 * 5 + 4] = 2.0;
        let mut w = Routing::new(5, 5);
        w.route(&h);
        assert_eq!(w.stack.len(), 25);
        let mut seen = [false; 25];
        for &i in &w.stack {
            let r = w.receiver[i as usize] as usize;
            assert!(r == i as usize || seen[r], "cell {i} before its receiver {r}");
            seen[i as usize] = true;
        }
        // The pit's water leaves by the low rim cell: its area is every inner cell and itself.
        assert_eq!(w.area[2 * 5 + 4], 10.0);
        // The pit fills to just above the plateau around it.
        assert!(w.filled[2 * 5 + 2] > 5.0 && w.filled[2 * 5 + 2] < 5.0 + 1e-9);
    }

    #[test]
    fn a_flat_drains_to_the_edge() {
        let mut w = Routing::new(6, 4);
        w.route(&[0.0; 24]);
        let total: f64 = (0..24)
            .filter(|&i| w.receiver[i] as usize == i)
            .map(|i| w.area[i])
            .sum();
        assert_eq!(total, 24.0);
    }
}
