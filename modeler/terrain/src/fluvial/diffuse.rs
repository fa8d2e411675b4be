//! Linear hillslope diffusion, `∂h/∂t = D ∇²h`, implicit and split by direction: one implicit
//! step along the rows, then one along the columns, each a tridiagonal solve (Thomas'
//! algorithm), so any `D·dt` is stable and a step costs O(n). The grid's edge cells are held
//! (they are the base level).

use rayon::prelude::*;

/// Columns per strip of the column pass: each strip is solved by one thread, its rows read in
/// order (a strip's row is four cache lines of `f64`).
const STRIP: usize = 32;

/// Scratch rows for the solves, kept between steps.
pub struct Diffusion {
    cols: usize,
    rows: usize,
    /// Per row the forward sweep's modified super-diagonal.
    cp: Vec<f64>,
    /// Per strip of columns, the column pass's modified super-diagonal and its solution, a
    /// strip's row after row (`STRIP` wide, the last strip narrower).
    strips: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Diffusion {
    /// Scratch for a `cols × rows` grid.
    pub fn new(cols: usize, rows: usize) -> Diffusion {
        let inner = cols.saturating_sub(2);
        let strips = (0..inner.div_ceil(STRIP))
            .map(|s| {
                let w = STRIP.min(inner - s * STRIP);
                (vec![0.0; w * rows], vec![0.0; w * rows])
            })
            .collect();
        Diffusion {
            cols,
            rows,
            cp: vec![0.0; cols * rows],
            strips,
        }
    }

    /// One step on `h` with `r = D·dt/dx²`.
    pub fn step(&mut self, h: &mut [f64], r: f64) {
        let (cols, rows) = (self.cols, self.rows);
        if r <= 0.0 || cols < 3 || rows < 3 {
            return;
        }
        // Rows: each an independent system (−r, 1 + 2r, −r) over its inner cells.
        h.par_chunks_mut(cols)
            .zip(self.cp.par_chunks_mut(cols))
            .enumerate()
            .for_each(|(y, (line, cp))| {
                if y == 0 || y + 1 == rows {
                    return;
                }
                solve_line(line, cp, r);
            });
        // Columns: a strip of them per task, row after row so memory is read in order; the
        // solutions wait in the strips until every strip has read the heights.
        let land: &[f64] = h;
        self.strips.par_iter_mut().enumerate().for_each(|(s, (cp, x))| {
            solve_strip(land, cols, rows, 1 + s * STRIP, cp, x, r);
        });
        let strips = &self.strips;
        h.par_chunks_mut(cols).enumerate().for_each(|(y, line)| {
            if y == 0 || y + 1 == rows {
                return;
            }
            for (s, (_, x)) in strips.iter().enumerate() {
                let w = x.len() / rows;
                let from = 1 + s * STRIP;
                line[from..from + w].copy_from_slice(&x[y * w..(y + 1) * w]);
            }
        });
    }
}

/// The column pass over the columns `from..from + w` (`w = x.len() / rows`): every column's
/// system (−r, 1 + 2r, −r) over its inner rows, rows 0 and `rows − 1` held; the solution goes
/// to `x`, row-major in the strip (its first and last rows are not the solution's).
fn solve_strip(h: &[f64], cols: usize, rows: usize, from: usize, cp: &mut [f64], x: &mut [f64], r: f64) {
    let w = x.len() / rows;
    let b = 1.0 + 2.0 * r;
    // Row 0 is held: the sweep starts from its heights.
    for c in 0..w {
        cp[c] = 0.0;
        x[c] = h[from + c];
    }
    for y in 1..rows - 1 {
        let (prev, here) = ((y - 1) * w, y * w);
        let last = y + 2 == rows;
        for c in 0..w {
            let at = y * cols + from + c;
            let mut rhs = h[at] + r * x[prev + c];
            if last {
                rhs += r * h[at + cols];
            }
            let denom = b - r * cp[prev + c];
            cp[here + c] = if last { 0.0 } else { r / denom };
            x[here + c] = rhs / denom;
        }
    }
    for y in (1..rows - 1).rev() {
        let (here, below) = (y * w, (y + 1) * w);
        for c in 0..w {
            let next = if y + 2 == rows {
                h[(y + 1) * cols + from + c]
            } else {
                x[below + c]
            };
            x[here + c] += cp[here + c] * next;
        }
    }
}

/// Solves `−r·x[i−1] + (1 + 2r)·x[i] − r·x[i+1] = line[i]` for the inner cells of `line`, its
/// two ends held, in place.
fn solve_line(line: &mut [f64], cp: &mut [f64], r: f64) {
    let n = line.len();
    let b = 1.0 + 2.0 * r;
    // Forward sweep: `line` becomes the modified right-hand side.
    let mut prev_cp = 0.0;
    let mut prev_dp = line[0];
    for i in 1..n - 1 {
        let mut rhs = line[i] + r * prev_dp;
        if i + 2 == n {
            rhs += r * line[n - 1];
        }
        let denom = b - r * prev_cp;
        prev_cp = if i + 2 == n { 0.0 } else { r / denom };
        prev_dp = rhs / denom;
        cp[i] = prev_cp;
        line[i] = prev_dp;
    }
    for i in (1..n - 2).rev() {
        line[i] += cp[i] * line[i + 1];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The implicit step's defining equation holds: `x − r·∇²x = h` along a line.
    #[test]
    fn a_line_solve_satisfies_its_equation() {
        let h = [3.0, 7.0, 1.0, 4.0, 9.0, 2.0];
        let mut x = h;
        let mut cp = [0.0; 6];
        solve_line(&mut x, &mut cp, 0.7);
        for i in 1..5 {
            let lhs = x[i] - 0.7 * (x[i - 1] - 2.0 * x[i] + x[i + 1]);
            assert!((lhs - h[i]).abs() < 1e-12, "cell {i}: {lhs} against {}", h[i]);
        }
        assert_eq!((x[0], x[5]), (3.0, 2.0));
    }

    #[test]
    fn a_column_solve_satisfies_its_equation() {
        // A 3-column grid: only the middle column is inner; the row pass leaves it alone when
        // every row is constant, so the result is the column pass's.
        let col = [3.0, 7.0, 1.0, 4.0, 9.0, 2.0];
        let mut h: Vec<f64> = col.iter().flat_map(|&v| [v, v, v]).collect();
        Diffusion::new(3, 6).step(&mut h, 0.7);
        let x: Vec<f64> = (0..6).map(|y| h[y * 3 + 1]).collect();
        for i in 1..5 {
            let lhs = x[i] - 0.7 * (x[i - 1] - 2.0 * x[i] + x[i + 1]);
            assert!((lhs - col[i]).abs() < 1e-12, "row {i}: {lhs} against {}", col[i]);
        }
    }
}
