//! Small fixed-size linear algebra in `f32`, written out so that every operation happens in the
//! same order on the host and on the Cortex-M4F: their results are bit-identical.

/// The square root, correctly rounded as IEEE 754 requires, so every platform gives the same
/// bits. On a hard-float ARM core it is the FPU's VSQRT.F32 (14 cycles on the Cortex-M4F):
/// core has no `f32::sqrt`, and libm's portable routine costs over a hundred instructions,
/// which made square roots most of a fix's cost there.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
pub fn sqrt(x: f32) -> f32 {
    // SAFETY: `pen_vsqrtf` (below) takes and returns an f32 in s0 per the hard-float ABI,
    // touches nothing else, and the FPU it needs is part of every eabihf target.
    unsafe { pen_vsqrtf(x) }
}

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
unsafe extern "C" {
    fn pen_vsqrtf(x: f32) -> f32;
}

// A function in assembly rather than `asm!`: the inline form's FPU register operands need a
// target feature that stable Rust cannot enable on ARM.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
mod vsqrt {
    core::arch::global_asm!(
        ".section .text.pen_vsqrtf,\"ax\",%progbits",
        ".global pen_vsqrtf",
        ".type pen_vsqrtf,%function",
        ".thumb_func",
        ".fpu fpv4-sp-d16",
        "pen_vsqrtf:",
        "vsqrt.f32 s0, s0",
        "bx lr",
    );
}

/// The square root, correctly rounded (libm's, which uses the CPU's instruction where it has
/// one).
#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

use core::ops::{Add, AddAssign, Mul, Neg, Sub};

/// A 3-vector (mm, or a direction).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Vec3 {
    /// x.
    pub x: f32,
    /// y.
    pub y: f32,
    /// z.
    pub z: f32,
}

impl Vec3 {
    /// The zero vector.
    pub const ZERO: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    /// The z axis, the tracker frame's "out of the display, towards the user".
    pub const Z: Vec3 = Vec3::new(0.0, 0.0, 1.0);

    /// A vector from its components.
    pub const fn new(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3 { x, y, z }
    }

    /// From an array.
    pub const fn from_array(a: [f32; 3]) -> Vec3 {
        Vec3::new(a[0], a[1], a[2])
    }

    /// To an array.
    pub const fn to_array(self) -> [f32; 3] {
        [self.x, self.y, self.z]
    }

    /// Dot product.
    pub fn dot(self, o: Vec3) -> f32 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product.
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }

    /// Squared length.
    pub fn length_squared(self) -> f32 {
        self.dot(self)
    }

    /// Length.
    pub fn length(self) -> f32 {
        sqrt(self.length_squared())
    }

    /// Whether every component is finite.
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl AddAssign for Vec3 {
    fn add_assign(&mut self, o: Vec3) {
        *self = *self + o;
    }
}

impl Sub for Vec3 {
    type Output = Vec3;
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Mul<f32> for Vec3 {
    type Output = Vec3;
    fn mul(self, s: f32) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl Neg for Vec3 {
    type Output = Vec3;
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

/// A symmetric 3×3 matrix: normal equations and their inverses.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sym3 {
    /// Entries xx, xy, xz, yy, yz, zz.
    pub m: [f32; 6],
}

impl Sym3 {
    /// Adds `w · v vᵀ`.
    pub fn add_outer(&mut self, v: Vec3, w: f32) {
        let m = &mut self.m;
        m[0] += w * v.x * v.x;
        m[1] += w * v.x * v.y;
        m[2] += w * v.x * v.z;
        m[3] += w * v.y * v.y;
        m[4] += w * v.y * v.z;
        m[5] += w * v.z * v.z;
    }

    /// The trace.
    pub fn trace(&self) -> f32 {
        self.m[0] + self.m[3] + self.m[5]
    }

    /// The matrix with `(1 + lambda)` times its diagonal (Levenberg–Marquardt damping).
    pub fn damped(&self, lambda: f32) -> Sym3 {
        let mut d = *self;
        d.m[0] *= 1.0 + lambda;
        d.m[3] *= 1.0 + lambda;
        d.m[5] *= 1.0 + lambda;
        d
    }

    /// Matrix–vector product.
    pub fn mul_vec(&self, v: Vec3) -> Vec3 {
        let m = &self.m;
        Vec3::new(
            m[0] * v.x + m[1] * v.y + m[2] * v.z,
            m[1] * v.x + m[3] * v.y + m[4] * v.z,
            m[2] * v.x + m[4] * v.y + m[5] * v.z,
        )
    }

    /// The inverse, or `None` when the matrix is singular or so ill-conditioned that its
    /// reciprocal condition estimate falls below `min_rcond` (determinant against the cube of the
    /// mean diagonal, which is 1 for a multiple of the identity).
    pub fn inverse(&self, min_rcond: f32) -> Option<Sym3> {
        let [a, b, c, d, e, f] = self.m;
        // Cofactors of [[a b c] [b d e] [c e f]].
        let c00 = d * f - e * e;
        let c01 = c * e - b * f;
        let c02 = b * e - c * d;
        let c11 = a * f - c * c;
        let c12 = b * c - a * e;
        let c22 = a * d - b * b;
        let det = a * c00 + b * c01 + c * c02;
        let scale = self.trace() / 3.0;
        if !(det.is_finite() && scale > 0.0 && det > min_rcond * scale * scale * scale) {
            return None;
        }
        let inv = 1.0 / det;
        let out = Sym3 {
            m: [c00 * inv, c01 * inv, c02 * inv, c11 * inv, c12 * inv, c22 * inv],
        };
        out.m.iter().all(|v| v.is_finite()).then_some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_times_matrix_is_identity() {
        let mut s = Sym3::default();
        s.add_outer(Vec3::new(1.0, 2.0, 0.5), 1.0);
        s.add_outer(Vec3::new(-1.0, 0.5, 2.0), 2.0);
        s.add_outer(Vec3::new(0.3, -1.0, 1.0), 1.5);
        let inv = s.inverse(1e-6).expect("well conditioned");
        for (axis, unit) in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Z]
            .into_iter()
            .enumerate()
        {
            let back = s.mul_vec(inv.mul_vec(unit));
            assert!((back - unit).length() < 1e-5, "axis {axis}: {back:?}");
        }
    }

    #[test]
    fn singular_and_ill_conditioned_are_refused() {
        let mut s = Sym3::default();
        s.add_outer(Vec3::new(1.0, 0.0, 0.0), 1.0);
        s.add_outer(Vec3::new(0.0, 1.0, 0.0), 1.0);
        assert_eq!(s.inverse(1e-6), None, "rank 2");
        s.add_outer(Vec3::Z, 1e-5);
        assert_eq!(s.inverse(1e-3), None, "condition below the limit");
        assert!(s.inverse(1e-7).is_some());
        assert_eq!(Sym3::default().inverse(0.0), None);
    }
}
