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
    /// Each cell's place in the stack (`u32::MAX` while it is not in it).
    pub pos: Vec<u32>,
    /// By place in the stack: the receiver's place.
    pub receiver_pos: Vec<u32>,
    /// By place in the stack: the drainage area.
    pub stack_area: Vec<f64>,
    /// Places in the stack where runs of whole edge basins start, then where the basins end
    /// (the flooded cells follow): no cell in one run drains through another, so the runs can
    /// be worked on at once.
    runs: Vec<usize>,
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
            pos: vec![u32::MAX; n],
            receiver_pos: vec![0; n],
            stack_area: vec![0.0; n],
            runs: Vec::new(),
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
        self.runs.clear();
        self.runs.push(0);
        // Runs of a few thousand cells at least, so a thread's task outweighs its hand-over.
        let run = (cols * rows / 64).max(4096);
        for root in 0..cols * rows {
            if self.receiver[root] as usize != root {
                continue;
            }
            let (c, r) = (root % cols, root / cols);
            let edge = c == 0 || r == 0 || c + 1 == cols || r + 1 == rows;
            if edge && self.stack.len() - self.runs[self.runs.len() - 1] >= run {
                self.runs.push(self.stack.len());
            }
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
        if self.stack.len() > self.runs[self.runs.len() - 1] {
            self.runs.push(self.stack.len());
        }
        self.pos.iter_mut().for_each(|p| *p = u32::MAX);
        for (p, &i) in self.stack.iter().enumerate() {
            self.pos[i as usize] = p as u32;
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
                if self.pos[n] != u32::MAX && self.fill_at[n] != u32::MAX {
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
                if self.pos[n] != u32::MAX {
                    continue;
                }
                self.pos[n] = self.stack.len() as u32;
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

    /// Places in the stack where runs of whole edge basins start, then where the last ends:
    /// a cell's receiver is in its own run; the flooded cells (which may drain into any run)
    /// come after the last.
    pub fn runs(&self) -> &[usize] {
        &self.runs
    }

    /// Where the flooded cells start in the stack.
    pub fn flooded_from(&self) -> usize {
        self.runs[self.runs.len() - 1]
    }

    /// Drainage areas, summed down the stack in its place order (each cell's donors come
    /// after it): the flooded cells first, then every run of basins on its own thread, and
    /// always in the stack's reverse order, so the sums are the same bits on any number of
    /// threads.
    fn accumulate(&mut self) {
        let (stack, pos, receiver) = (&self.stack, &self.pos, &self.receiver);
        self.receiver_pos
            .par_iter_mut()
            .zip(stack.par_iter())
            .for_each(|(rp, &i)| *rp = pos[receiver[i as usize] as usize]);
        let rpos = &self.receiver_pos;
        let areas = &mut self.stack_area;
        areas.iter_mut().for_each(|a| *a = 1.0);
        let flooded = self.runs[self.runs.len() - 1];
        for p in (flooded..stack.len()).rev() {
            let q = rpos[p] as usize;
            if q != p {
                areas[q] += areas[p];
            }
        }
        split_runs(&mut areas[..flooded], &self.runs)
            .into_par_iter()
            .for_each(|(start, run)| {
                for k in (0..run.len()).rev() {
                    let q = rpos[start + k] as usize;
                    if q != start + k {
                        run[q - start] += run[k];
                    }
                }
            });
        let areas = &self.stack_area;
        self.area
            .par_iter_mut()
            .zip(pos.par_iter())
            .for_each(|(a, &p)| *a = areas[p as usize]);
    }
}

/// `values` (by place in the stack, up to the flooded cells) cut at `runs`' places: each run
/// with the place it starts at.
pub fn split_runs<'a, T>(mut values: &'a mut [T], runs: &[usize]) -> Vec<(usize, &'a mut [T])> {
    let mut out = Vec::with_capacity(runs.len());
    for w in runs.windows(2) {
        let (run, rest) = values.split_at_mut(w[1] - w[0]);
        out.push((w[0], run));
        values = rest;
    }
    out
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

    /// The runs the stream-power step solves in parallel hold whole basins: every cell's
    /// receiver is in its own run, or the cell is flooded and comes after every run; the areas
    /// summed on the runs are the stack's.
    #[test]
    fn every_run_holds_its_cells_receivers() {
        let (cols, rows) = (200, 180);
        // A cone with noise: it drains to every side.
        let mut h: Vec<f64> = (0..cols * rows)
            .map(|i| {
                let (x, y) = ((i % cols) as f64 - 100.0, (i / cols) as f64 - 90.0);
                let noise = (super::super::mix(7, i as u64) % 1000) as f64 / 1000.0;
                200.0 - (x * x + y * y).sqrt() + 0.8 * noise
            })
            .collect();
        // And two pits dug into its flanks.
        h[50 * cols + 60] -= 10.0;
        h[130 * cols + 150] -= 4.0;
        let mut w = Routing::new(cols, rows);
        w.route(&h);
        assert!(w.runs().len() > 3, "several runs: {:?}", w.runs());
        assert!(w.flooded_from() < w.stack.len(), "some cells are flooded");
        for run in w.runs().windows(2) {
            for p in run[0]..run[1] {
                let q = w.receiver_pos[p] as usize;
                assert!(
                    (run[0]..=p).contains(&q),
                    "place {p}'s receiver at {q}, outside {run:?}"
                );
            }
        }
        for p in w.flooded_from()..w.stack.len() {
            assert!((w.receiver_pos[p] as usize) < p, "flooded place {p}");
        }
        let mut area = vec![1.0; cols * rows];
        for &i in w.stack.iter().rev() {
            let r = w.receiver[i as usize] as usize;
            if r != i as usize {
                area[r] += area[i as usize];
            }
        }
        assert_eq!(area, w.area);
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
