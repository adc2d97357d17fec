//! Eight-lane floats for the wide contact solver's eight-lane builds (`solver::lanes8`,
//! compiled for AVX2, and `solver::lanes8_avx512`, for AVX2 with AVX-512F/VL, chosen at
//! run time on a CPU that has them): the same operations as
//! [`super::wide::F4`] and [`super::wide::M4`], each one AVX instruction on a 256-bit
//! register. Every operation is lane-wise plain IEEE arithmetic (no fused multiply-add, no
//! approximate reciprocal), so a lane computes bit for bit what the same scalar expression
//! computes, as with four lanes.
//!
//! Used only through `solver::lanes8::wide::{FL, ML, VL}`, in functions compiled for AVX2
//! (or for AVX2 with AVX-512F/VL):
//! the operations here are `#[inline(always)]` and take the AVX instructions only once
//! inlined there (out of line, each intrinsic would be a call).

use super::wide::F4;
use core::arch::x86_64::{__m256, __m256i};
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub, SubAssign};

/// Lanes of [`F8`].
pub(crate) const LANES8: usize = 8;

/// Eight `f32` lanes (read and written as an array through `Deref`).
#[derive(Clone, Copy)]
#[repr(C, align(32))]
pub(crate) struct F8(__m256);

/// Eight lane masks (each all ones = true or all zeros = false).
#[derive(Clone, Copy)]
#[repr(C, align(32))]
pub(crate) struct M8(__m256);

const _: () = assert!(core::mem::size_of::<F8>() == 32 && core::mem::size_of::<M8>() == 32);

/// The AVX and AVX2 intrinsics used here, wrapped as safe functions, and a register's
/// lanes seen as an array.
#[allow(unsafe_code)]
mod avx {
    pub use core::arch::x86_64::{__m128, __m128i, __m256, __m256i};
    pub use core::arch::x86_64::{_CMP_GE_OQ, _CMP_GT_OQ, _CMP_LT_OQ, _CMP_NEQ_UQ};

    /// Wraps intrinsics as safe functions.
    macro_rules! avx2 {
        ($($name:ident $(<$c:ident>)? ($($a:ident: $t:ty),*) -> $r:ty;)*) => {$(
            #[inline(always)]
            pub fn $name$(<const $c: i32>)?($($a: $t),*) -> $r {
                // SAFETY: the CPU has AVX and AVX2 wherever an eight-lane value exists:
                // they are made and used only in `solver::lanes8` and
                // `solver::lanes8_avx512`, whose solvers the world takes only after
                // `is_x86_feature_detected!("avx2")` (`solver::Contacts`),
                // or in a crate compiled for AVX2 as a whole, or in this module's tests,
                // which return first on a CPU without it. These intrinsics work on
                // values only: they read and write no memory.
                unsafe { core::arch::x86_64::$name$(::<$c>)?($($a),*) }
            }
        )*};
    }

    avx2! {
        _mm256_set1_ps(a: f32) -> __m256;
        _mm256_set1_epi32(a: i32) -> __m256i;
        _mm256_setzero_si256() -> __m256i;
        _mm256_castsi256_ps(a: __m256i) -> __m256;
        _mm256_castps_si256(a: __m256) -> __m256i;
        _mm256_cmpeq_epi32(a: __m256i, b: __m256i) -> __m256i;
        _mm256_cmpgt_epi32(a: __m256i, b: __m256i) -> __m256i;
        _mm256_and_si256(a: __m256i, b: __m256i) -> __m256i;
        _mm256_cvtepu8_epi32(a: __m128i) -> __m256i;
        _mm_cvtsi64_si128(a: i64) -> __m128i;
        _mm256_add_ps(a: __m256, b: __m256) -> __m256;
        _mm256_sub_ps(a: __m256, b: __m256) -> __m256;
        _mm256_mul_ps(a: __m256, b: __m256) -> __m256;
        _mm256_div_ps(a: __m256, b: __m256) -> __m256;
        _mm256_sqrt_ps(a: __m256) -> __m256;
        _mm256_max_ps(a: __m256, b: __m256) -> __m256;
        _mm256_min_ps(a: __m256, b: __m256) -> __m256;
        _mm256_and_ps(a: __m256, b: __m256) -> __m256;
        _mm256_andnot_ps(a: __m256, b: __m256) -> __m256;
        _mm256_or_ps(a: __m256, b: __m256) -> __m256;
        _mm256_xor_ps(a: __m256, b: __m256) -> __m256;
        _mm256_cmp_ps<P>(a: __m256, b: __m256) -> __m256;
        _mm256_movemask_ps(a: __m256) -> i32;
        _mm256_unpacklo_ps(a: __m256, b: __m256) -> __m256;
        _mm256_unpackhi_ps(a: __m256, b: __m256) -> __m256;
        _mm256_shuffle_ps<P>(a: __m256, b: __m256) -> __m256;
        _mm256_set_m128(hi: __m128, lo: __m128) -> __m256;
        _mm256_castps256_ps128(a: __m256) -> __m128;
        _mm256_extractf128_ps<P>(a: __m256) -> __m128;
    }

    #[inline(always)]
    pub fn f(r: &__m256) -> &[f32; 8] {
        // SAFETY: `__m256` is 32 bytes of eight `f32` lanes in order (lane 0 first),
        // aligned to 32; every bit pattern is a valid `f32` and `u32`, and the borrow is
        // the register's.
        unsafe { &*(r as *const __m256 as *const [f32; 8]) }
    }

    #[inline(always)]
    pub fn f_mut(r: &mut __m256) -> &mut [f32; 8] {
        // SAFETY: as `f`.
        unsafe { &mut *(r as *mut __m256 as *mut [f32; 8]) }
    }

    #[inline(always)]
    pub fn m(r: &__m256) -> &[u32; 8] {
        // SAFETY: as `f`.
        unsafe { &*(r as *const __m256 as *const [u32; 8]) }
    }

    #[inline(always)]
    pub fn m_mut(r: &mut __m256) -> &mut [u32; 8] {
        // SAFETY: as `f`.
        unsafe { &mut *(r as *mut __m256 as *mut [u32; 8]) }
    }

    /// An array's lanes as a register (a constant expression).
    pub const fn from_f(a: [f32; 8]) -> __m256 {
        // SAFETY: same size, every bit pattern valid (see `f`).
        unsafe { core::mem::transmute::<[f32; 8], __m256>(a) }
    }

    pub const fn from_m(a: [u32; 8]) -> __m256 {
        // SAFETY: as `from_f`.
        unsafe { core::mem::transmute::<[u32; 8], __m256>(a) }
    }

    /// Eight words as a register.
    #[inline(always)]
    pub fn words(a: [u32; 8]) -> __m256i {
        _mm256_castps_si256(from_m(a))
    }
}

use avx::*;

crate::math::wide::lane_array!(F8, f32, LANES8, avx::f, avx::f_mut);
crate::math::wide::lane_array!(M8, u32, LANES8, avx::m, avx::m_mut);

impl Eq for M8 {}

impl F8 {
    pub const ZERO: F8 = F8::new([0.0; LANES8]);

    /// Lanes from an array.
    #[inline(always)]
    pub const fn new(a: [f32; LANES8]) -> F8 {
        F8(from_f(a))
    }

    #[inline(always)]
    pub fn splat(x: f32) -> F8 {
        F8(_mm256_set1_ps(x))
    }

    /// Lane-wise maximum (`a > b ? a : b`, SSE's and AVX's `maxps`, as `F4::max`).
    #[inline(always)]
    pub fn max(self, o: F8) -> F8 {
        F8(_mm256_max_ps(self.0, o.0))
    }

    /// Lane-wise minimum (`a < b ? a : b`, as `F4::min`).
    #[inline(always)]
    pub fn min(self, o: F8) -> F8 {
        F8(_mm256_min_ps(self.0, o.0))
    }

    #[inline(always)]
    pub fn clamp(self, lo: F8, hi: F8) -> F8 {
        self.max(lo).min(hi)
    }

    /// Lane-wise square root (IEEE, as `f32::sqrt`).
    #[inline(always)]
    pub fn sqrt(self) -> F8 {
        F8(_mm256_sqrt_ps(self.0))
    }

    #[inline(always)]
    pub fn abs(self) -> F8 {
        F8(_mm256_and_ps(
            self.0,
            _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff)),
        ))
    }

    /// `>` (false where either lane is NaN, as SSE's `cmpgtps`).
    #[inline(always)]
    pub fn gt(self, o: F8) -> M8 {
        M8(_mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0))
    }

    #[inline(always)]
    pub fn ge(self, o: F8) -> M8 {
        M8(_mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0))
    }

    #[inline(always)]
    pub fn lt(self, o: F8) -> M8 {
        M8(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0))
    }

    /// Lane-wise `!=` (true where either lane is NaN, as the scalar `!=`).
    #[inline(always)]
    pub fn ne(self, o: F8) -> M8 {
        M8(_mm256_cmp_ps::<_CMP_NEQ_UQ>(self.0, o.0))
    }

    /// The lanes whose bits (a word of flags carried as a float's bits) have every bit of
    /// `bits` set.
    #[inline(always)]
    pub fn bits_set(self, bits: u32) -> M8 {
        let b = _mm256_set1_epi32(bits as i32);
        M8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
            _mm256_and_si256(_mm256_castps_si256(self.0), b),
            b,
        )))
    }
}

/// Eight 16-byte rows (one per lane: a body's state row, a contact's input row) as four
/// vectors of eight lanes: lane `l` of output `i` is element `i` of row `l`. Rows `l` and
/// `l + 4` share a register, and each 128-bit half is transposed as `_MM_TRANSPOSE4_PS`
/// does (eight shuffles for the eight rows, as for four rows with four lanes).
#[inline(always)]
pub(crate) fn rows_to_lanes8(rows: [F4; LANES8]) -> [F8; 4] {
    use crate::math::wide::sse_register as sse;
    // Spelled out, without closures or `array::from_fn` / `map`: this is inlined into code
    // compiled for AVX2, and a closure here would not be (`wide::array_of`).
    let [t0, t1, t2, t3] = transpose_halves([
        _mm256_set_m128(sse(rows[4]), sse(rows[0])),
        _mm256_set_m128(sse(rows[5]), sse(rows[1])),
        _mm256_set_m128(sse(rows[6]), sse(rows[2])),
        _mm256_set_m128(sse(rows[7]), sse(rows[3])),
    ]);
    [F8(t0), F8(t1), F8(t2), F8(t3)]
}

/// The inverse of [`rows_to_lanes8`]: four vectors of eight lanes as eight 16-byte rows.
#[inline(always)]
pub(crate) fn lanes_to_rows8(cols: [F8; 4]) -> [F4; LANES8] {
    use crate::math::wide::from_sse_register as f4;
    let [t0, t1, t2, t3] = transpose_halves([cols[0].0, cols[1].0, cols[2].0, cols[3].0]);
    [
        f4(_mm256_castps256_ps128(t0)),
        f4(_mm256_castps256_ps128(t1)),
        f4(_mm256_castps256_ps128(t2)),
        f4(_mm256_castps256_ps128(t3)),
        f4(_mm256_extractf128_ps::<1>(t0)),
        f4(_mm256_extractf128_ps::<1>(t1)),
        f4(_mm256_extractf128_ps::<1>(t2)),
        f4(_mm256_extractf128_ps::<1>(t3)),
    ]
}

/// The 4×4 transpose of each 128-bit half of four registers.
#[inline(always)]
fn transpose_halves([v0, v1, v2, v3]: [__m256; 4]) -> [__m256; 4] {
    let (t0, t1) = (_mm256_unpacklo_ps(v0, v1), _mm256_unpacklo_ps(v2, v3));
    let (t2, t3) = (_mm256_unpackhi_ps(v0, v1), _mm256_unpackhi_ps(v2, v3));
    // (0x44: elements 0, 1 of the first and 0, 1 of the second; 0xEE: 2, 3 and 2, 3.)
    [
        _mm256_shuffle_ps::<0x44>(t0, t1),
        _mm256_shuffle_ps::<0xEE>(t0, t1),
        _mm256_shuffle_ps::<0x44>(t2, t3),
        _mm256_shuffle_ps::<0xEE>(t2, t3),
    ]
}

/// Eight bytes as eight lanes of 32-bit words (zero-extended).
#[inline(always)]
fn byte_lanes(b: [u8; LANES8]) -> __m256i {
    _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(i64::from_le_bytes(b)))
}

impl M8 {
    /// Masks from an array.
    #[inline(always)]
    pub const fn new(a: [u32; LANES8]) -> M8 {
        M8(from_m(a))
    }

    #[inline(always)]
    pub fn lane(self, i: usize) -> bool {
        self[i] != 0
    }

    /// A mask from eight booleans.
    #[inline(always)]
    pub fn from_bools(b: [bool; LANES8]) -> M8 {
        M8::new(b.map(|x| if x { u32::MAX } else { 0 }))
    }

    /// [`M8::from_bools`] for eight booleans stored side by side in a record (one load and
    /// a zero extension of each byte into its lane).
    #[inline(always)]
    pub fn from_stored_bools(b: [bool; LANES8]) -> M8 {
        let lanes = byte_lanes(b.map(u8::from));
        M8(_mm256_castsi256_ps(_mm256_cmpgt_epi32(lanes, _mm256_setzero_si256())))
    }

    /// The lanes whose byte in `b` is not zero.
    #[inline(always)]
    pub fn from_nonzero_bytes(b: [u8; LANES8]) -> M8 {
        let zero = _mm256_cmpeq_epi32(byte_lanes(b), _mm256_setzero_si256());
        !M8(_mm256_castsi256_ps(zero))
    }

    /// The lanes where `a` is zero.
    #[inline(always)]
    pub fn zero_lanes(a: [u32; LANES8]) -> M8 {
        M8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
            words(a),
            _mm256_setzero_si256(),
        )))
    }

    /// The lanes where `a` is greater than `k` (unsigned: both offset by 2³¹ for the
    /// signed compare).
    #[inline(always)]
    pub fn above(a: [u32; LANES8], k: u32) -> M8 {
        let flip = |x: u32| x ^ 0x8000_0000;
        let v = words(a.map(flip));
        M8(_mm256_castsi256_ps(_mm256_cmpgt_epi32(
            v,
            _mm256_set1_epi32(flip(k) as i32),
        )))
    }

    /// The lanes where `a` or `b` is zero.
    #[inline(always)]
    pub fn either_zero(a: [u32; LANES8], b: [u32; LANES8]) -> M8 {
        M8::zero_lanes(a) | M8::zero_lanes(b)
    }

    /// The eight lanes of a mask as booleans.
    #[inline(always)]
    pub fn to_bools(self) -> [bool; LANES8] {
        let bits = _mm256_movemask_ps(self.0);
        core::array::from_fn(|i| bits >> i & 1 != 0)
    }

    /// Whether some lane is true.
    #[inline(always)]
    pub fn any(self) -> bool {
        _mm256_movemask_ps(self.0) != 0
    }

    /// Whether every lane is true.
    #[inline(always)]
    pub fn all(self) -> bool {
        _mm256_movemask_ps(self.0) == 0xFF
    }

    /// `self ? a : b` lane by lane.
    #[inline(always)]
    pub fn select(self, a: F8, b: F8) -> F8 {
        F8(_mm256_or_ps(_mm256_and_ps(self.0, a.0), _mm256_andnot_ps(self.0, b.0)))
    }

    /// 1.0 where true, 0.0 where false.
    #[inline(always)]
    pub fn to_unit(self) -> F8 {
        F8(_mm256_and_ps(self.0, _mm256_set1_ps(1.0)))
    }
}

macro_rules! f8_binop {
    ($tr:ident, $f:ident, $avx:ident) => {
        impl $tr for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                F8($avx(self.0, o.0))
            }
        }
    };
}
f8_binop!(Add, add, _mm256_add_ps);
f8_binop!(Sub, sub, _mm256_sub_ps);
f8_binop!(Mul, mul, _mm256_mul_ps);
f8_binop!(Div, div, _mm256_div_ps);

impl Mul<F8> for f32 {
    type Output = F8;
    #[inline(always)]
    fn mul(self, o: F8) -> F8 {
        F8::splat(self) * o
    }
}

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        F8(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)))
    }
}

impl AddAssign for F8 {
    #[inline(always)]
    fn add_assign(&mut self, o: F8) {
        *self = *self + o;
    }
}

impl SubAssign for F8 {
    #[inline(always)]
    fn sub_assign(&mut self, o: F8) {
        *self = *self - o;
    }
}

impl BitAnd for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitand(self, o: M8) -> M8 {
        M8(_mm256_and_ps(self.0, o.0))
    }
}

impl BitOr for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitor(self, o: M8) -> M8 {
        M8(_mm256_or_ps(self.0, o.0))
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8(_mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))))
    }
}

crate::math::wide::lane_vectors!(V8, F8, "Eight 2D vectors, one per lane.");

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether this CPU can run the eight-lane operations: the tests return at once on one
    /// that cannot (the library never runs them there; `solver::Contacts`).
    fn avx2() -> bool {
        let yes = std::is_x86_feature_detected!("avx2");
        if !yes {
            eprintln!("no AVX2 on this CPU: eight-lane operations not tested");
        }
        yes
    }

    fn f8(f: impl Fn(usize) -> f32) -> F8 {
        F8::new(core::array::from_fn(f))
    }

    /// Every operation gives each lane what the scalar expression gives, NaN and signed
    /// zeros included (the same rules as the four-lane operations). A NaN that an operation
    /// makes from numbers (0 / −0, the square root of −2) is only required to be NaN: the
    /// instruction makes it negative, a scalar reference the compiler folds positive (the
    /// test profile is optimised).
    #[test]
    fn eight_lanes_match_scalar_arithmetic() {
        if !avx2() {
            return;
        }
        let xs = [1.5, -2.0, 0.0, 3.25, f32::NAN, -0.0, 1e-30, 7.0];
        let ys = [0.5, 4.0, -0.0, -1.0, 1.0, 0.0, f32::NAN, 7.0];
        let (a, b) = (F8::new(xs), F8::new(ys));
        let same = |v: F8, f: &dyn Fn(f32, f32) -> f32| {
            for l in 0..LANES8 {
                assert_eq!(v[l].to_bits(), f(xs[l], ys[l]).to_bits(), "lane {l}");
            }
        };
        // Exact bits, but any NaN where the scalar gives one made from two numbers.
        let made = |v: F8, f: &dyn Fn(f32, f32) -> f32| {
            for l in 0..LANES8 {
                let want = f(xs[l], ys[l]);
                if want.is_nan() && !xs[l].is_nan() && !ys[l].is_nan() {
                    assert!(v[l].is_nan(), "lane {l}: {} for NaN", v[l]);
                } else {
                    assert_eq!(v[l].to_bits(), want.to_bits(), "lane {l}");
                }
            }
        };
        same(a + b, &|x, y| x + y);
        same(a - b, &|x, y| x - y);
        same(a * b, &|x, y| x * y);
        made(a / b, &|x, y| x / y);
        same(-a, &|x, _| -x);
        same(a.abs(), &|x, _| f32::from_bits(x.to_bits() & 0x7fff_ffff));
        made(a.sqrt(), &|x, _| x.sqrt());
        same(a.max(b), &|x, y| if x > y { x } else { y });
        same(a.min(b), &|x, y| if x < y { x } else { y });
        let mask = |m: M8, f: &dyn Fn(f32, f32) -> bool| {
            assert_eq!(m.to_bools(), core::array::from_fn(|l| f(xs[l], ys[l])));
        };
        mask(a.gt(b), &|x, y| x > y);
        mask(a.ge(b), &|x, y| x >= y);
        mask(a.lt(b), &|x, y| x < y);
        mask(a.ne(b), &|x, y| x != y);
        let m = a.gt(b);
        same(m.select(a, b), &|x, y| if x > y { x } else { y });
        same(m.to_unit(), &|x, y| if x > y { 1.0 } else { 0.0 });
        assert!(m.any() && !m.all() && (m | !m).all() && !(m & !m).any());
    }

    /// Masks from stored booleans, bytes and words set exactly their own lanes.
    #[test]
    fn eight_lane_masks_set_exactly_their_lanes() {
        if !avx2() {
            return;
        }
        for l in 0..LANES8 {
            for x in [1u8, 2, 0x80, 0xFF] {
                let mut bytes = [0u8; LANES8];
                bytes[l] = x;
                let one: [bool; LANES8] = core::array::from_fn(|k| k == l);
                assert_eq!(M8::from_nonzero_bytes(bytes).to_bools(), one);
                assert_eq!(M8::from_stored_bools(one).to_bools(), one);
                assert_eq!(M8::from_bools(one).to_bools(), one);
                let mut words = [5u32; LANES8];
                words[l] = 0;
                assert_eq!(M8::zero_lanes(words).to_bools(), one);
                let mut big = [1u32; LANES8];
                big[l] = 0x8000_0001;
                assert_eq!(M8::above(big, 0x8000_0000).to_bools(), one);
            }
        }
        let words = f8(|l| f32::from_bits([0xffff_ffff, 0x8000_0002, 0x7fc0_0001, 1, 3, 0, 2, 7][l]));
        assert_eq!(
            words.bits_set(3).to_bools(),
            [true, false, false, false, true, false, false, true]
        );
    }

    /// Rows to lanes and back: lane `l` of vector `i` is element `i` of row `l`.
    #[test]
    fn rows_and_lanes_are_transposes() {
        if !avx2() {
            return;
        }
        let rows: [F4; LANES8] = core::array::from_fn(|l| F4::new(core::array::from_fn(|i| (10 * l + i) as f32)));
        let cols = rows_to_lanes8(rows);
        for (i, c) in cols.iter().enumerate() {
            assert_eq!(**c, core::array::from_fn(|l| (10 * l + i) as f32));
        }
        assert_eq!(lanes_to_rows8(cols), rows);
    }
}
