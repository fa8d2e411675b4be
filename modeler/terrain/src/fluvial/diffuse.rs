//! Linear hillslope diffusion, `∂h/∂t = D ∇²h`, implicit and split by direction: one implicit
//! step along the rows, then one along the columns, each a tridiagonal solve (Thomas'
//! algorithm), so any `D·dt` is stable and a step costs O(n). The grid's edge cells are held
//! (they are the base level).

use rayon::prelude::*;

/// Scratch rows for the solves, kept between steps.
pub struct Diffusion {
    cols: usize,
    rows: usize,
    /// Per row (or per column) the forward sweep's modified super-diagonal.
    cp: Vec<f64>,
    /// The column pass's modified super-diagonal and right-hand side, one per cell.
    col_cp: Vec<f64>,
    col_dp: Vec<f64>,
}

impl Diffusion {
    /// Scratch for a `cols × rows` grid.
    pub fn new(cols: usize, rows: usize) -> Diffusion {
        Diffusion {
            cols,
            rows,
            cp: vec![0.0; cols * rows],
            col_cp: vec![0.0; cols * rows],
            col_dp: vec![0.0; cols * rows],
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
        // Columns: every column at once, row after row, so memory is read in order.
        let (cp, dp) = (&mut self.col_cp, &mut self.col_dp);
        let b = 1.0 + 2.0 * r;
        // Row 0 is held: the sweep starts from its heights.
        for c in 1..cols - 1 {
            cp[c] = 0.0;
            dp[c] = h[c];
        }
        for y in 1..rows - 1 {
            let (prev, here) = ((y - 1) * cols, y * cols);
            let last = y + 2 == rows;
            for c in 1..cols - 1 {
                let mut rhs = h[here + c] + r * dp[prev + c];
                if last {
                    rhs += r * h[here + cols + c];
                }
                let denom = b - r * cp[prev + c];
                cp[here + c] = if last { 0.0 } else { r / denom };
                dp[here + c] = rhs / denom;
            }
        }
        for y in (1..rows - 1).rev() {
            let here = y * cols;
            for c in 1..cols - 1 {
                h[here + c] = dp[here + c] + cp[here + c] * h[here + cols + c];
            }
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
