//! Four-lane floats for the wide contact solver.
//!
//! `F4` is four `f32` lanes; every operation is lane-wise plain IEEE arithmetic (no fused
//! multiply-add, no approximate reciprocal), so a lane computes bit for bit what the same
//! scalar expression computes. On x86-64 every operation is one SSE instruction (safe
//! intrinsics of the baseline target; the lanes move in and out of registers with
//! `setr`/shuffles, which LLVM turns into plain vector loads and stores). Elsewhere the
//! lane loops are left to LLVM's vectorizer, which on x86-64 turned the selects of
//! compare results back into per-lane branches (Box2D's SIMD solver writes intrinsics for
//! the same reason). Masks are lanes of all-ones / all-zeros bits, like SIMD compare
//! results.

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

/// The SSE forms of the lane operations: x86-64's baseline SSE/SSE2 intrinsics, wrapped as
/// safe functions (the crate's third `unsafe` site).
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod sse {
    use super::{F4, M4};
    pub use core::arch::x86_64::{__m128, __m128i};

    /// Wraps intrinsics of the x86-64 baseline as safe functions.
    macro_rules! baseline {
        ($($name:ident($($a:ident: $t:ty),*) -> $r:ty;)*) => {$(
            #[inline(always)]
            pub fn $name($($a: $t),*) -> $r {
                // SAFETY: SSE and SSE2 are part of every x86-64 CPU (the target's baseline
                // features, always enabled); these intrinsics work on values only: they
                // read and write no memory.
                unsafe { core::arch::x86_64::$name($($a),*) }
            }
        )*};
    }

    baseline! {
        _mm_setr_ps(a: f32, b: f32, c: f32, d: f32) -> __m128;
        _mm_set1_ps(a: f32) -> __m128;
        _mm_setr_epi32(a: i32, b: i32, c: i32, d: i32) -> __m128i;
        _mm_set1_epi32(a: i32) -> __m128i;
        _mm_castsi128_ps(a: __m128i) -> __m128;
        _mm_cmpeq_epi32(a: __m128i, b: __m128i) -> __m128i;
        _mm_or_si128(a: __m128i, b: __m128i) -> __m128i;
        _mm_setzero_si128() -> __m128i;
        _mm_castps_si128(a: __m128) -> __m128i;
        _mm_cvtss_f32(a: __m128) -> f32;
        _mm_cvtsi128_si32(a: __m128i) -> i32;
        _mm_add_ps(a: __m128, b: __m128) -> __m128;
        _mm_sub_ps(a: __m128, b: __m128) -> __m128;
        _mm_mul_ps(a: __m128, b: __m128) -> __m128;
        _mm_div_ps(a: __m128, b: __m128) -> __m128;
        _mm_sqrt_ps(a: __m128) -> __m128;
        _mm_max_ps(a: __m128, b: __m128) -> __m128;
        _mm_min_ps(a: __m128, b: __m128) -> __m128;
        _mm_and_ps(a: __m128, b: __m128) -> __m128;
        _mm_andnot_ps(a: __m128, b: __m128) -> __m128;
        _mm_or_ps(a: __m128, b: __m128) -> __m128;
        _mm_xor_ps(a: __m128, b: __m128) -> __m128;
        _mm_cmpgt_ps(a: __m128, b: __m128) -> __m128;
        _mm_cmpge_ps(a: __m128, b: __m128) -> __m128;
        _mm_cmplt_ps(a: __m128, b: __m128) -> __m128;
        _mm_movemask_ps(a: __m128) -> i32;
        _mm_unpacklo_ps(a: __m128, b: __m128) -> __m128;
        _mm_unpackhi_ps(a: __m128, b: __m128) -> __m128;
        _mm_movelh_ps(a: __m128, b: __m128) -> __m128;
        _mm_movehl_ps(a: __m128, b: __m128) -> __m128;
    }

    /// Lane `L` of `v` moved to lane 0.
    #[inline(always)]
    fn lane<const L: i32>(v: __m128) -> __m128 {
        // SAFETY: as `baseline!`.
        unsafe { core::arch::x86_64::_mm_shuffle_ps::<L>(v, v) }
    }

    #[inline(always)]
    fn lane_i<const L: i32>(v: __m128i) -> __m128i {
        // SAFETY: as `baseline!`.
        unsafe { core::arch::x86_64::_mm_shuffle_epi32::<L>(v) }
    }

    #[inline(always)]
    pub fn f(x: F4) -> __m128 {
        _mm_setr_ps(x.0[0], x.0[1], x.0[2], x.0[3])
    }

    #[inline(always)]
    pub fn m(x: M4) -> __m128 {
        _mm_castsi128_ps(_mm_setr_epi32(
            x.0[0] as i32,
            x.0[1] as i32,
            x.0[2] as i32,
            x.0[3] as i32,
        ))
    }

    #[inline(always)]
    pub fn to_f(v: __m128) -> F4 {
        F4([
            _mm_cvtss_f32(v),
            _mm_cvtss_f32(lane::<0b01_01_01_01>(v)),
            _mm_cvtss_f32(lane::<0b10_10_10_10>(v)),
            _mm_cvtss_f32(lane::<0b11_11_11_11>(v)),
        ])
    }

    #[inline(always)]
    pub fn to_m(v: __m128) -> M4 {
        let i = _mm_castps_si128(v);
        M4([
            _mm_cvtsi128_si32(i) as u32,
            _mm_cvtsi128_si32(lane_i::<0b01_01_01_01>(i)) as u32,
            _mm_cvtsi128_si32(lane_i::<0b10_10_10_10>(i)) as u32,
            _mm_cvtsi128_si32(lane_i::<0b11_11_11_11>(i)) as u32,
        ])
    }
}

/// `$sse` (an expression over `core::arch::x86_64` and [`sse`]) on x86-64, else `$lanes`.
macro_rules! simd {
    ($sse:expr, $lanes:expr) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[allow(unused_imports)]
            use sse::*;
            $sse
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            $lanes
        }
    }};
}

#[cfg_attr(target_arch = "x86_64", allow(unused_macros))]
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
        simd!(
            sse::to_f(_mm_max_ps(sse::f(self), sse::f(o))),
            F4(lanes!(|i| if self.0[i] > o.0[i] { self.0[i] } else { o.0[i] }))
        )
    }

    /// Lane-wise minimum.
    #[inline(always)]
    pub fn min(self, o: F4) -> F4 {
        simd!(
            sse::to_f(_mm_min_ps(sse::f(self), sse::f(o))),
            F4(lanes!(|i| if self.0[i] < o.0[i] { self.0[i] } else { o.0[i] }))
        )
    }

    #[inline(always)]
    pub fn clamp(self, lo: F4, hi: F4) -> F4 {
        self.max(lo).min(hi)
    }

    /// Lane-wise square root (IEEE, as `f32::sqrt`).
    #[inline(always)]
    pub fn sqrt(self) -> F4 {
        simd!(sse::to_f(_mm_sqrt_ps(sse::f(self))), F4(lanes!(|i| self.0[i].sqrt())))
    }

    #[inline(always)]
    pub fn abs(self) -> F4 {
        simd!(
            sse::to_f(_mm_and_ps(sse::f(self), _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff)))),
            F4(lanes!(|i| f32::from_bits(self.0[i].to_bits() & 0x7fff_ffff)))
        )
    }

    #[inline(always)]
    pub fn gt(self, o: F4) -> M4 {
        simd!(
            sse::to_m(_mm_cmpgt_ps(sse::f(self), sse::f(o))),
            M4(lanes!(|i| mask(self.0[i] > o.0[i])))
        )
    }

    #[inline(always)]
    pub fn ge(self, o: F4) -> M4 {
        simd!(
            sse::to_m(_mm_cmpge_ps(sse::f(self), sse::f(o))),
            M4(lanes!(|i| mask(self.0[i] >= o.0[i])))
        )
    }

    #[inline(always)]
    pub fn lt(self, o: F4) -> M4 {
        simd!(
            sse::to_m(_mm_cmplt_ps(sse::f(self), sse::f(o))),
            M4(lanes!(|i| mask(self.0[i] < o.0[i])))
        )
    }
}

/// The 4×4 transpose: lane `j` of output `i` is lane `i` of input `j` (turns four bodies'
/// 16-byte rows into four lanes of each field and back; `_MM_TRANSPOSE4_PS`, eight
/// shuffles instead of sixteen single-lane moves).
#[inline(always)]
pub(crate) fn transpose(rows: [F4; LANES]) -> [F4; LANES] {
    simd!(
        {
            let [r0, r1, r2, r3] = rows.map(sse::f);
            let (t0, t1) = (_mm_unpacklo_ps(r0, r1), _mm_unpacklo_ps(r2, r3));
            let (t2, t3) = (_mm_unpackhi_ps(r0, r1), _mm_unpackhi_ps(r2, r3));
            [
                _mm_movelh_ps(t0, t1),
                _mm_movehl_ps(t1, t0),
                _mm_movelh_ps(t2, t3),
                _mm_movehl_ps(t3, t2),
            ]
            .map(sse::to_f)
        },
        core::array::from_fn(|i| F4(core::array::from_fn(|j| rows[j].0[i])))
    )
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

    /// A mask from four booleans.
    #[inline(always)]
    pub fn from_bools(b: [bool; LANES]) -> M4 {
        M4(b.map(mask))
    }

    /// The lanes where `a` or `b` is zero.
    #[inline(always)]
    pub fn either_zero(a: [u32; LANES], b: [u32; LANES]) -> M4 {
        simd!(
            {
                let v = |x: [u32; LANES]| _mm_setr_epi32(x[0] as i32, x[1] as i32, x[2] as i32, x[3] as i32);
                let z = _mm_setzero_si128();
                sse::to_m(_mm_castsi128_ps(_mm_or_si128(
                    _mm_cmpeq_epi32(v(a), z),
                    _mm_cmpeq_epi32(v(b), z),
                )))
            },
            M4(lanes!(|i| mask(a[i] == 0 || b[i] == 0)))
        )
    }

    /// Whether some lane is true.
    #[inline(always)]
    pub fn any(self) -> bool {
        simd!(
            _mm_movemask_ps(sse::m(self)) != 0,
            (self.0[0] | self.0[1] | self.0[2] | self.0[3]) != 0
        )
    }

    /// Whether every lane is true.
    #[inline(always)]
    pub fn all(self) -> bool {
        simd!(
            _mm_movemask_ps(sse::m(self)) == 0b1111,
            (self.0[0] & self.0[1] & self.0[2] & self.0[3]) == u32::MAX
        )
    }

    /// `self ? a : b` lane by lane.
    #[inline(always)]
    pub fn select(self, a: F4, b: F4) -> F4 {
        simd!(
            {
                let m = sse::m(self);
                sse::to_f(_mm_or_ps(_mm_and_ps(m, sse::f(a)), _mm_andnot_ps(m, sse::f(b))))
            },
            F4(lanes!(|i| f32::from_bits(
                (a.0[i].to_bits() & self.0[i]) | (b.0[i].to_bits() & !self.0[i])
            )))
        )
    }

    /// 1.0 where true, 0.0 where false.
    #[inline(always)]
    pub fn to_unit(self) -> F4 {
        simd!(
            sse::to_f(_mm_and_ps(sse::m(self), _mm_set1_ps(1.0))),
            F4(lanes!(|i| f32::from_bits(1.0f32.to_bits() & self.0[i])))
        )
    }
}

macro_rules! f4_binop {
    ($tr:ident, $f:ident, $op:tt, $sse:ident) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                simd!(sse::to_f($sse(sse::f(self), sse::f(o))), F4(lanes!(|i| self.0[i] $op o.0[i])))
            }
        }
    };
}
f4_binop!(Add, add, +, _mm_add_ps);
f4_binop!(Sub, sub, -, _mm_sub_ps);
f4_binop!(Mul, mul, *, _mm_mul_ps);
f4_binop!(Div, div, /, _mm_div_ps);

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
        simd!(
            sse::to_f(_mm_xor_ps(sse::f(self), _mm_set1_ps(-0.0))),
            F4(lanes!(|i| -self.0[i]))
        )
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
        simd!(
            sse::to_m(_mm_and_ps(sse::m(self), sse::m(o))),
            M4(lanes!(|i| self.0[i] & o.0[i]))
        )
    }
}

impl BitOr for M4 {
    type Output = M4;
    #[inline(always)]
    fn bitor(self, o: M4) -> M4 {
        simd!(
            sse::to_m(_mm_or_ps(sse::m(self), sse::m(o))),
            M4(lanes!(|i| self.0[i] | o.0[i]))
        )
    }
}

impl Not for M4 {
    type Output = M4;
    #[inline(always)]
    fn not(self) -> M4 {
        simd!(
            sse::to_m(_mm_xor_ps(sse::m(self), _mm_castsi128_ps(_mm_set1_epi32(-1)))),
            M4(lanes!(|i| !self.0[i]))
        )
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
        let rows = [a, b, a + b, a * b];
        let cols = transpose(rows);
        for (i, col) in cols.iter().enumerate() {
            assert_eq!(col.0, [a.0[i], b.0[i], (a + b).0[i], (a * b).0[i]]);
        }
        assert_eq!(transpose(cols), rows);
        // Body indices: 0 is the static body; u32::MAX must not read as a negative zero.
        let (ia, ib) = ([0, 7, 3, u32::MAX], [5, 0, 9, 1]);
        assert_eq!(M4::either_zero(ia, ib).0, [u32::MAX, u32::MAX, 0, 0]);
        assert_eq!(M4::either_zero([0; LANES], [0; LANES]).0, [u32::MAX; LANES]);
    }
}
