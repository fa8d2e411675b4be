//! The exact Euclidean distance transform of a binary image (Felzenszwalb & Huttenlocher's
//! separable lower envelope of parabolas: columns, then rows; linear in the cells).
//!
//! Why beside [`super::morph::distance`]: the banks blend into the ground by the distance to the
//! water, and the city-block distance's contours are diamonds, so every bank stepped like the
//! diamonds that shaped the water; the Euclidean distance's contours are round.

/// The squared distance no cell reaches (no target in the image).
const FAR: f64 = f64::INFINITY;

/// Euclidean distance (cells) from every cell of a `width × height` image to the nearest cell
/// whose value is not 0; infinite when there is none. Cells beyond the image are not targets.
pub fn euclidean(image: &[u8], width: usize, height: usize) -> Vec<f32> {
    let mut d2: Vec<f64> = image.iter().map(|&v| if v != 0 { 0.0 } else { FAR }).collect();
    let n = width.max(height);
    let mut work = Envelope {
        f: vec![0.0; n],
        out: vec![0.0; n],
        v: vec![0; n],
        z: vec![0.0; n + 1],
    };
    for c in 0..width {
        for r in 0..height {
            work.f[r] = d2[r * width + c];
        }
        work.run(height);
        for r in 0..height {
            d2[r * width + c] = work.out[r];
        }
    }
    for row in d2.chunks_mut(width.max(1)) {
        work.f[..row.len()].copy_from_slice(row);
        work.run(row.len());
        row.copy_from_slice(&work.out[..row.len()]);
    }
    d2.iter().map(|&s| s.sqrt() as f32).collect()
}

/// One line's transform: `out[q] = min_p (q − p)² + f[p]`.
struct Envelope {
    f: Vec<f64>,
    out: Vec<f64>,
    /// The parabolas of the lower envelope (their apexes)…
    v: Vec<usize>,
    /// …and where each takes over.
    z: Vec<f64>,
}

impl Envelope {
    fn run(&mut self, n: usize) {
        let Envelope { f, out, v, z } = self;
        // Only finite parabolas enter the envelope (an infinite one is never the lowest).
        let mut k: Option<usize> = None;
        for q in 0..n {
            if f[q] == FAR {
                continue;
            }
            let Some(mut top) = k else {
                v[0] = q;
                z[0] = f64::NEG_INFINITY;
                z[1] = f64::INFINITY;
                k = Some(0);
                continue;
            };
            let qf = q as f64;
            // Drop the parabolas the new one hides (z[0] is −∞, so the first is never dropped).
            let s = loop {
                let pf = v[top] as f64;
                let s = ((f[q] + qf * qf) - (f[v[top]] + pf * pf)) / (2.0 * (qf - pf));
                if s <= z[top] {
                    top -= 1;
                } else {
                    break s;
                }
            };
            top += 1;
            v[top] = q;
            z[top] = s;
            z[top + 1] = f64::INFINITY;
            k = Some(top);
        }
        if k.is_none() {
            out[..n].fill(FAR);
            return;
        }
        let mut j = 0;
        for (q, o) in out[..n].iter_mut().enumerate() {
            let qf = q as f64;
            while z[j + 1] < qf {
                j += 1;
            }
            let p = v[j] as f64;
            *o = (qf - p) * (qf - p) + f[v[j]];
        }
    }
}
