//! Choosing the roughness `Q` (seed 004, §5) by distance and by peripheral vision. Pure
//! functions; `Q` is kept in `(0, 1]`.
//!
//! - **Distance** `D` from the eye to the tree, `L0` the tree's size: `Q = Q0` while
//!   `D ≤ B = 2·L0`, beyond it `Q = −a·L0/D + b` with `b = Q0 + a/2`, so the two meet at `B`
//!   and `Q` rises towards `b` far away.
//! - **Peripheral vision**, `θ` the angle between the gaze and the tree: `Q = Q0 / R(θ)` with
//!   `R = 1` within 6° of the gaze and `R = exp(−(θ − 6°)/n)` beyond it (`n ≈ 5°`): acuity
//!   falls off outside the fovea, so detail there is wasted.
//! - Both: [`Roughness::choose`] divides the distance's `Q` by `R(θ)`.

/// The angle from the gaze within which acuity is full, degrees.
pub const FOVEA: f64 = 6.0;

/// The parameters of the choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roughness {
    /// `Q0`, the roughness near the viewer and at the gaze.
    pub q0: f64,
    /// `a`, how fast `Q` rises with distance beyond `B`.
    pub a: f64,
    /// `n`, the fall-off of acuity beyond the fovea, degrees.
    pub n: f64,
}

impl Default for Roughness {
    /// `Q0 = 0.02` (the full model), `a = 0.2` (so `b = 0.12`: the seed's subjects accepted
    /// `Q ≈ 0.10` for trees of 15° or less), `n = 5°`.
    fn default() -> Roughness {
        Roughness {
            q0: 0.02,
            a: 0.2,
            n: 5.0,
        }
    }
}

fn clamp(q: f64) -> f64 {
    if q.is_nan() {
        1.0
    } else {
        q.clamp(f64::MIN_POSITIVE, 1.0)
    }
}

impl Roughness {
    /// `B = 2·L0`, where the distance law starts.
    pub fn near(l0: f64) -> f64 {
        2.0 * l0
    }

    /// `b = Q0 + a/2`: the law's limit far away, which makes it continuous at `B`.
    pub fn b(&self) -> f64 {
        self.q0 + 0.5 * self.a
    }

    /// `Q` at distance `d` from a tree of size `l0` (same unit).
    pub fn by_distance(&self, d: f64, l0: f64) -> f64 {
        if d <= Roughness::near(l0) {
            clamp(self.q0)
        } else {
            clamp(-self.a * l0 / d + self.b())
        }
    }

    /// `R(θ)`: 1 within [`FOVEA`] degrees of the gaze, `exp(−(θ − 6°)/n)` beyond.
    pub fn acuity(&self, theta: f64) -> f64 {
        let theta = theta.abs();
        if theta <= FOVEA {
            1.0
        } else {
            (-(theta - FOVEA) / self.n).exp()
        }
    }

    /// `Q = Q0 / R(θ)` at `theta` degrees from the gaze.
    pub fn by_gaze(&self, theta: f64) -> f64 {
        clamp(self.q0 / self.acuity(theta))
    }

    /// Both: the distance's `Q` divided by `R(θ)`.
    pub fn choose(&self, d: f64, l0: f64, theta: f64) -> f64 {
        clamp(self.by_distance(d, l0) / self.acuity(theta))
    }
}
