//! Four-lane floats for the wide contact solver.
//!
//! `F4` is four `f32` lanes; every operation is lane-wise plain IEEE arithmetic (no fused
//! multiply-add, no approximate reciprocal), so a lane computes bit for bit what the same
//! scalar expression computes. The lane loops are written so that LLVM turns them into
//! single SSE2 / NEON instructions (the crate forbids `unsafe`, so no intrinsics); masks
//! are lanes of all-ones / all-zeros bits, like SIMD compare results.

use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub, SubAssign};

/// Lanes per wide constraint.
pub(crate) const LANES: usize = 4;

/// Four `f32` lanes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(16))]
pub(crate) struct F4(pub [f32; LANES]);

/// Four lane masks (each all ones = true or all zeros = false).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C, align(16))]
pub(crate) struct M4(pub [u32; LANES]);

macro_rules! lanes {
    (|$i:ident| $e:expr) => {{
        let mut out = [Default::default(); LANES];
        let mut $i = 0;
        while $i < LANES {
            out[$i] = $e;
            $i += 1;
        }
        out
    }};
}

impl F4 {
    pub const ZERO: F4 = F4([0.0; LANES]);

    #[inline(always)]
    pub fn splat(x: f32) -> F4 {
        F4([x; LANES])
    }

    /// Lane-wise maximum (`a > b ? a : b`, like SSE `maxps` with the operands swapped).
    #[inline(always)]
    pub fn max(self, o: F4) -> F4 {
        F4(lanes!(|i| if self.0[i] > o.0[i] { self.0[i] } else { o.0[i] }))
    }

    /// Lane-wise minimum.
    #[inline(always)]
    pub fn min(self, o: F4) -> F4 {
        F4(lanes!(|i| if self.0[i] < o.0[i] { self.0[i] } else { o.0[i] }))
    }

    #[inline(always)]
    pub fn clamp(self, lo: F4, hi: F4) -> F4 {
        self.max(lo).min(hi)
    }

    /// Lane-wise square root (IEEE, as `f32::sqrt`).
    #[inline(always)]
    pub fn sqrt(self) -> F4 {
        F4(lanes!(|i| self.0[i].sqrt()))
    }

    #[inline(always)]
    pub fn abs(self) -> F4 {
        F4(lanes!(|i| f32::from_bits(self.0[i].to_bits() & 0x7fff_ffff)))
    }

    #[inline(always)]
    pub fn gt(self, o: F4) -> M4 {
        M4(lanes!(|i| mask(self.0[i] > o.0[i])))
    }

    #[inline(always)]
    pub fn ge(self, o: F4) -> M4 {
        M4(lanes!(|i| mask(self.0[i] >= o.0[i])))
    }

    #[inline(always)]
    pub fn lt(self, o: F4) -> M4 {
        M4(lanes!(|i| mask(self.0[i] < o.0[i])))
    }
}

#[inline(always)]
fn mask(b: bool) -> u32 {
    if b {
        u32::MAX
    } else {
        0
    }
}

impl M4 {
    #[inline(always)]
    pub fn lane(self, i: usize) -> bool {
        self.0[i] != 0
    }

    /// Whether some lane is true.
    #[inline(always)]
    pub fn any(self) -> bool {
        (self.0[0] | self.0[1] | self.0[2] | self.0[3]) != 0
    }

    /// Whether every lane is true.
    #[inline(always)]
    pub fn all(self) -> bool {
        (self.0[0] & self.0[1] & self.0[2] & self.0[3]) == u32::MAX
    }

    /// `self ? a : b` lane by lane.
    #[inline(always)]
    pub fn select(self, a: F4, b: F4) -> F4 {
        F4(lanes!(|i| f32::from_bits(
            (a.0[i].to_bits() & self.0[i]) | (b.0[i].to_bits() & !self.0[i])
        )))
    }

    /// 1.0 where true, 0.0 where false.
    #[inline(always)]
    pub fn to_unit(self) -> F4 {
        F4(lanes!(|i| f32::from_bits(1.0f32.to_bits() & self.0[i])))
    }
}

macro_rules! f4_binop {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                F4(lanes!(|i| self.0[i] $op o.0[i]))
            }
        }
    };
}
f4_binop!(Add, add, +);
f4_binop!(Sub, sub, -);
f4_binop!(Mul, mul, *);
f4_binop!(Div, div, /);

impl Mul<F4> for f32 {
    type Output = F4;
    #[inline(always)]
    fn mul(self, o: F4) -> F4 {
        F4::splat(self) * o
    }
}

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        F4(lanes!(|i| -self.0[i]))
    }
}

impl AddAssign for F4 {
    #[inline(always)]
    fn add_assign(&mut self, o: F4) {
        *self = *self + o;
    }
}

impl SubAssign for F4 {
    #[inline(always)]
    fn sub_assign(&mut self, o: F4) {
        *self = *self - o;
    }
}

impl BitAnd for M4 {
    type Output = M4;
    #[inline(always)]
    fn bitand(self, o: M4) -> M4 {
        M4(lanes!(|i| self.0[i] & o.0[i]))
    }
}

impl BitOr for M4 {
    type Output = M4;
    #[inline(always)]
    fn bitor(self, o: M4) -> M4 {
        M4(lanes!(|i| self.0[i] | o.0[i]))
    }
}

impl Not for M4 {
    type Output = M4;
    #[inline(always)]
    fn not(self) -> M4 {
        M4(lanes!(|i| !self.0[i]))
    }
}

/// Four 2D vectors, one per lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct V4 {
    pub x: F4,
    pub y: F4,
}

impl V4 {
    #[inline(always)]
    pub fn dot(self, o: V4) -> F4 {
        self.x * o.x + self.y * o.y
    }

    /// z of the 3D cross product, lane by lane.
    #[inline(always)]
    pub fn cross(self, o: V4) -> F4 {
        self.x * o.y - self.y * o.x
    }

    /// (−y, x): the vector turned counter-clockwise.
    #[inline(always)]
    pub fn left_perp(self) -> V4 {
        V4 { x: -self.y, y: self.x }
    }

    #[inline(always)]
    pub fn scale(self, s: F4) -> V4 {
        V4 {
            x: s * self.x,
            y: s * self.y,
        }
    }
}

impl Add for V4 {
    type Output = V4;
    #[inline(always)]
    fn add(self, o: V4) -> V4 {
        V4 {
            x: self.x + o.x,
            y: self.y + o.y,
        }
    }
}

impl Sub for V4 {
    type Output = V4;
    #[inline(always)]
    fn sub(self, o: V4) -> V4 {
        V4 {
            x: self.x - o.x,
            y: self.y - o.y,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_match_scalar_arithmetic() {
        let a = F4([1.5, -2.0, 0.0, 3.25]);
        let b = F4([0.5, 4.0, -0.0, -1.0]);
        assert_eq!((a + b).0, [2.0, 2.0, 0.0, 2.25]);
        assert_eq!((a * b).0, [0.75, -8.0, -0.0, -3.25]);
        assert_eq!(a.max(b).0, [1.5, 4.0, -0.0, 3.25]);
        assert_eq!(a.min(b).0, [0.5, -2.0, -0.0, -1.0]);
        assert_eq!(a.abs().0, [1.5, 2.0, 0.0, 3.25]);
        let m = a.gt(b);
        assert_eq!(m.select(a, b).0, [1.5, 4.0, -0.0, 3.25]);
        assert_eq!(m.to_unit().0, [1.0, 0.0, 0.0, 1.0]);
        assert_eq!((!m & a.ge(b)).0, [0, 0, u32::MAX, 0]);
        assert!(!m.all() && (m | !m).all());
    }
}
