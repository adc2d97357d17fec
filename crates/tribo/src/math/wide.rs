//! Four-lane floats: the lanes of the wide contact solver's four-lane build
//! (`solver::lanes4`; its eight-lane build takes `wide8`'s), and the few four-wide steps of
//! manifold recycling and polygon collision.
//!
//! `F4` is four `f32` lanes; every operation is lane-wise plain IEEE arithmetic (no fused
//! multiply-add, no approximate reciprocal), so a lane computes bit for bit what the same
//! scalar expression computes. On x86-64 a lane vector is an SSE register (`__m128`) and
//! every operation one SSE instruction (safe intrinsics of the baseline target); its lanes
//! are read and written as an array through `Deref` (the sixth `unsafe` site: a register's
//! bytes seen as four lanes). Elsewhere the
//! lane loops are left to LLVM's vectorizer, which on x86-64 turned the selects of
//! compare results back into per-lane branches (Box2D's SIMD solver writes intrinsics for
//! the same reason). Masks are lanes of all-ones / all-zeros bits, like SIMD compare
//! results.

use super::Vec2;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub, SubAssign};

/// Lanes of [`F4`].
pub(crate) const LANES4: usize = 4;

/// The register a lane vector lives in: an SSE register on x86-64 (so LLVM keeps it whole
/// where branches meet, instead of taking a four-`f32` array apart into scalars there and
/// packing it again: ~80 instructions per group of the biased solve pass, found with
/// llvm-mca), else an array.
#[cfg(target_arch = "x86_64")]
type Raw = core::arch::x86_64::__m128;
#[cfg(not(target_arch = "x86_64"))]
type RawF = [f32; LANES4];
#[cfg(not(target_arch = "x86_64"))]
type RawM = [u32; LANES4];
#[cfg(target_arch = "x86_64")]
type RawF = Raw;
#[cfg(target_arch = "x86_64")]
type RawM = Raw;

/// Four `f32` lanes (read and written as an array through `Deref`).
#[derive(Clone, Copy)]
#[repr(C, align(16))]
pub(crate) struct F4(RawF);

/// Four lane masks (each all ones = true or all zeros = false; read and written as an
/// array of `u32` through `Deref`).
#[derive(Clone, Copy)]
#[repr(C, align(16))]
pub(crate) struct M4(RawM);

const _: () = assert!(core::mem::size_of::<F4>() == 16 && core::mem::size_of::<M4>() == 16);

/// The `$n` lanes of `$t` as an array of `$e` through `Deref` (`$view`, `$view_mut`: the
/// register's bytes seen as the array), the comparison and debug print that read them, and
/// `Default` (all lanes zero). Also used by `wide8`.
macro_rules! lane_array {
    ($t:ident, $e:ty, $n:expr, $view:path, $view_mut:path) => {
        impl core::ops::Deref for $t {
            type Target = [$e; $n];
            #[inline(always)]
            fn deref(&self) -> &[$e; $n] {
                $view(&self.0)
            }
        }

        impl core::ops::DerefMut for $t {
            #[inline(always)]
            fn deref_mut(&mut self) -> &mut [$e; $n] {
                $view_mut(&mut self.0)
            }
        }

        impl PartialEq for $t {
            fn eq(&self, o: &$t) -> bool {
                **self == **o
            }
        }

        impl core::fmt::Debug for $t {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                write!(f, concat!(stringify!($t), "({:?})"), **self)
            }
        }

        impl Default for $t {
            fn default() -> $t {
                $t::new([Default::default(); $n])
            }
        }
    };
}
#[cfg(target_arch = "x86_64")]
pub(crate) use lane_array;
lane_array!(F4, f32, LANES4, as_lanes::f, as_lanes::f_mut);
lane_array!(M4, u32, LANES4, as_lanes::m, as_lanes::m_mut);

impl Eq for M4 {}

/// The lanes of a register as an array, in place.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod as_lanes {
    use super::{Raw, LANES4};

    #[inline(always)]
    pub fn f(r: &Raw) -> &[f32; LANES4] {
        // SAFETY: `__m128` is 16 bytes of four `f32` lanes in order (lane 0 first), aligned
        // to 16; every bit pattern is a valid `f32` and `u32`, and the borrow is the
        // register's.
        unsafe { &*(r as *const Raw as *const [f32; LANES4]) }
    }

    #[inline(always)]
    pub fn f_mut(r: &mut Raw) -> &mut [f32; LANES4] {
        // SAFETY: as `f`.
        unsafe { &mut *(r as *mut Raw as *mut [f32; LANES4]) }
    }

    #[inline(always)]
    pub fn m(r: &Raw) -> &[u32; LANES4] {
        // SAFETY: as `f`.
        unsafe { &*(r as *const Raw as *const [u32; LANES4]) }
    }

    #[inline(always)]
    pub fn m_mut(r: &mut Raw) -> &mut [u32; LANES4] {
        // SAFETY: as `f`.
        unsafe { &mut *(r as *mut Raw as *mut [u32; LANES4]) }
    }

    /// An array's lanes as a register (a constant expression).
    pub const fn from_f(a: [f32; LANES4]) -> Raw {
        // SAFETY: same size, every bit pattern valid (see `f`).
        unsafe { core::mem::transmute::<[f32; LANES4], Raw>(a) }
    }

    pub const fn from_m(a: [u32; LANES4]) -> Raw {
        // SAFETY: as `from_f`.
        unsafe { core::mem::transmute::<[u32; LANES4], Raw>(a) }
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod as_lanes {
    use super::LANES4;
    #[inline(always)]
    pub fn f(r: &[f32; LANES4]) -> &[f32; LANES4] {
        r
    }
    #[inline(always)]
    pub fn f_mut(r: &mut [f32; LANES4]) -> &mut [f32; LANES4] {
        r
    }
    #[inline(always)]
    pub fn m(r: &[u32; LANES4]) -> &[u32; LANES4] {
        r
    }
    #[inline(always)]
    pub fn m_mut(r: &mut [u32; LANES4]) -> &mut [u32; LANES4] {
        r
    }
    pub const fn from_f(a: [f32; LANES4]) -> [f32; LANES4] {
        a
    }
    pub const fn from_m(a: [u32; LANES4]) -> [u32; LANES4] {
        a
    }
}

impl F4 {
    /// Lanes from an array.
    #[inline(always)]
    pub const fn new(a: [f32; LANES4]) -> F4 {
        F4(as_lanes::from_f(a))
    }
}

impl M4 {
    /// Masks from an array.
    #[inline(always)]
    pub const fn new(a: [u32; LANES4]) -> M4 {
        M4(as_lanes::from_m(a))
    }
}

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
        _mm_set1_ps(a: f32) -> __m128;
        _mm_setr_epi32(a: i32, b: i32, c: i32, d: i32) -> __m128i;
        _mm_set1_epi32(a: i32) -> __m128i;
        _mm_castsi128_ps(a: __m128i) -> __m128;
        _mm_cmpeq_epi32(a: __m128i, b: __m128i) -> __m128i;
        _mm_cmpgt_epi32(a: __m128i, b: __m128i) -> __m128i;
        _mm_or_si128(a: __m128i, b: __m128i) -> __m128i;
        _mm_and_si128(a: __m128i, b: __m128i) -> __m128i;
        _mm_setzero_si128() -> __m128i;
        _mm_castps_si128(a: __m128) -> __m128i;
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
        _mm_cmpneq_ps(a: __m128, b: __m128) -> __m128;
        _mm_movemask_ps(a: __m128) -> i32;
        _mm_unpacklo_ps(a: __m128, b: __m128) -> __m128;
        _mm_unpackhi_ps(a: __m128, b: __m128) -> __m128;
        _mm_movelh_ps(a: __m128, b: __m128) -> __m128;
        _mm_movehl_ps(a: __m128, b: __m128) -> __m128;
    }

    #[inline(always)]
    pub fn f(x: F4) -> __m128 {
        x.0
    }

    #[inline(always)]
    pub fn m(x: M4) -> __m128 {
        x.0
    }

    #[inline(always)]
    pub fn to_f(v: __m128) -> F4 {
        F4(v)
    }

    #[inline(always)]
    pub fn to_m(v: __m128) -> M4 {
        M4(v)
    }
}

/// The SSE register of an `F4` (for the eight-lane type's row transposes).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn sse_register(x: F4) -> core::arch::x86_64::__m128 {
    x.0
}

/// An `F4` from its SSE register.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn from_sse_register(v: core::arch::x86_64::__m128) -> F4 {
    F4(v)
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
        let mut out = [Default::default(); LANES4];
        let mut $i = 0;
        while $i < LANES4 {
            out[$i] = $e;
            $i += 1;
        }
        out
    }};
}

impl F4 {
    pub const ZERO: F4 = F4::new([0.0; LANES4]);

    #[inline(always)]
    pub fn splat(x: f32) -> F4 {
        simd!(sse::to_f(_mm_set1_ps(x)), F4::new([x; LANES4]))
    }

    /// Lane-wise maximum (`a > b ? a : b`, SSE `maxps`).
    #[inline(always)]
    pub fn max(self, o: F4) -> F4 {
        simd!(
            sse::to_f(_mm_max_ps(sse::f(self), sse::f(o))),
            F4::new(lanes!(|i| if self[i] > o[i] { self[i] } else { o[i] }))
        )
    }

    /// Lane-wise minimum (`a < b ? a : b`, SSE `minps`: `b` where either is NaN).
    #[inline(always)]
    pub fn min(self, o: F4) -> F4 {
        simd!(
            sse::to_f(_mm_min_ps(sse::f(self), sse::f(o))),
            F4::new(lanes!(|i| if self[i] < o[i] { self[i] } else { o[i] }))
        )
    }

    #[inline(always)]
    pub fn clamp(self, lo: F4, hi: F4) -> F4 {
        self.max(lo).min(hi)
    }

    /// Lane-wise square root (IEEE, as `f32::sqrt`).
    #[inline(always)]
    pub fn sqrt(self) -> F4 {
        simd!(
            sse::to_f(_mm_sqrt_ps(sse::f(self))),
            F4::new(lanes!(|i| self[i].sqrt()))
        )
    }

    #[inline(always)]
    pub fn abs(self) -> F4 {
        simd!(
            sse::to_f(_mm_and_ps(sse::f(self), _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff)))),
            F4::new(lanes!(|i| f32::from_bits(self[i].to_bits() & 0x7fff_ffff)))
        )
    }

    #[inline(always)]
    pub fn gt(self, o: F4) -> M4 {
        simd!(
            sse::to_m(_mm_cmpgt_ps(sse::f(self), sse::f(o))),
            M4::new(lanes!(|i| mask(self[i] > o[i])))
        )
    }

    #[inline(always)]
    pub fn ge(self, o: F4) -> M4 {
        simd!(
            sse::to_m(_mm_cmpge_ps(sse::f(self), sse::f(o))),
            M4::new(lanes!(|i| mask(self[i] >= o[i])))
        )
    }

    #[inline(always)]
    pub fn lt(self, o: F4) -> M4 {
        simd!(
            sse::to_m(_mm_cmplt_ps(sse::f(self), sse::f(o))),
            M4::new(lanes!(|i| mask(self[i] < o[i])))
        )
    }

    /// Lane-wise `!=` (true where either lane is NaN, as the scalar `!=`).
    #[inline(always)]
    pub fn ne(self, o: F4) -> M4 {
        simd!(
            sse::to_m(_mm_cmpneq_ps(sse::f(self), sse::f(o))),
            M4::new(lanes!(|i| mask(self[i] != o[i])))
        )
    }

    /// The lanes whose bits (a word of flags carried as a float's bits, never used as a
    /// number) have every bit of `bits` set.
    #[inline(always)]
    pub fn bits_set(self, bits: u32) -> M4 {
        simd!(
            {
                let b = _mm_set1_epi32(bits as i32);
                sse::to_m(_mm_castsi128_ps(_mm_cmpeq_epi32(
                    _mm_and_si128(_mm_castps_si128(sse::f(self)), b),
                    b,
                )))
            },
            M4::new(lanes!(|i| mask(self[i].to_bits() & bits == bits)))
        )
    }
}

/// `core::array::from_fn`, always inlined. The wide solver's eight-lane build is compiled
/// for AVX2 function by function (`solver::lanes8`): a closure handed to `array::from_fn`
/// or `array::map` runs inside `core`'s code, which is not, so it stays a call per element
/// (and one not compiled for AVX2 at all leaves each AVX intrinsic out of line). Here the
/// loop is inlined into the caller, and the closure with it.
#[inline(always)]
pub(crate) fn array_of<T: Copy + Default, const N: usize>(mut f: impl FnMut(usize) -> T) -> [T; N] {
    let mut out = [T::default(); N];
    for (i, x) in out.iter_mut().enumerate() {
        *x = f(i);
    }
    out
}

/// [`array_of`] written out element by element, for `N` ≤ 8: no loop for the compiler to
/// unroll or not (the solver's gather, see `contact_wide::gather`).
#[inline(always)]
pub(crate) fn unrolled<T: Copy + Default, const N: usize>(mut f: impl FnMut(usize) -> T) -> [T; N] {
    const { assert!(N <= 8) };
    let mut out = [T::default(); N];
    macro_rules! each {
        ($($k:literal)*) => {
            $(if let Some(x) = out.get_mut($k) {
                *x = f($k);
            })*
        };
    }
    each!(0 1 2 3 4 5 6 7);
    out
}

/// The 4×4 transpose: lane `j` of output `i` is lane `i` of input `j` (turns four bodies'
/// 16-byte rows into four lanes of each field and back; `_MM_TRANSPOSE4_PS`, eight
/// shuffles instead of sixteen single-lane moves).
#[inline(always)]
pub(crate) fn transpose(rows: [F4; LANES4]) -> [F4; LANES4] {
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
        core::array::from_fn(|i| F4::new(core::array::from_fn(|j| rows[j][i])))
    )
}

/// Four 2D points as lanes of x and of y: `([p0.x, p1.x, p2.x, p3.x], [p0.y, …])` (four
/// shuffles of the points' coordinates).
#[inline(always)]
pub(crate) fn split_xy(p: [Vec2; LANES4]) -> (F4, F4) {
    let (a, b) = ([p[0].x, p[0].y, p[1].x, p[1].y], [p[2].x, p[2].y, p[3].x, p[3].y]);
    simd!(
        {
            let (a, b) = (sse::f(F4::new(a)), sse::f(F4::new(b)));
            let (t0, t1) = (_mm_unpacklo_ps(a, b), _mm_unpackhi_ps(a, b));
            (sse::to_f(_mm_unpacklo_ps(t0, t1)), sse::to_f(_mm_unpackhi_ps(t0, t1)))
        },
        (F4::new([a[0], a[2], b[0], b[2]]), F4::new([a[1], a[3], b[1], b[3]]))
    )
}

/// The inverse of [`split_xy`]: four points from lanes of x and of y (four shuffles).
#[inline(always)]
pub(crate) fn join_xy(x: F4, y: F4) -> [Vec2; LANES4] {
    let [a, b]: [[f32; LANES4]; 2] = simd!(
        {
            let (x, y) = (sse::f(x), sse::f(y));
            [*sse::to_f(_mm_unpacklo_ps(x, y)), *sse::to_f(_mm_unpackhi_ps(x, y))]
        },
        [[x[0], y[0], x[1], y[1]], [x[2], y[2], x[3], y[3]]]
    );
    [
        Vec2::new(a[0], a[1]),
        Vec2::new(a[2], a[3]),
        Vec2::new(b[0], b[1]),
        Vec2::new(b[2], b[3]),
    ]
}

/// `Transform::apply` lane by lane, its expression in its order, so every lane has the
/// scalar bits: `(c x − s y) + t.x`, `(s x + c y) + t.y` for the points `(x, y)`, each lane
/// with its own rotation `(c, s)` and translation `(t.x, t.y)`.
#[inline(always)]
pub(crate) fn apply_lanes((c, s): (F4, F4), (tx, ty): (F4, F4), (x, y): (F4, F4)) -> (F4, F4) {
    (c * x - s * y + tx, s * x + c * y + ty)
}

/// The bounds `(min, max)`, as `[x, y]`, of `4 GROUPS` points given as lanes of x and of y,
/// four points a group (`x[g][k]` is point 4g + k): the fold from point 0, `lo = p < lo ? p
/// : lo` and `hi = p > hi ? p : hi` for the points after it in order, so a tie keeps the
/// running value and with it the sign of a zero. That is bit for bit the scalar fold
/// `lo.min(p)`, `hi.max(p)` as `f32::min` and `f32::max` compile on x86-64 (they keep their
/// receiver on a tie; Rust leaves the choice open, and on aarch64 `fminnm` prefers −0).
/// Fewer points are padded with copies of point 0: a repeat of point 0 changes no bound,
/// not even on a tie (the running bound is never beyond it). With NaN lanes: where the
/// running value is NaN, `f32::min` takes the point and this keeps the NaN (a transform of
/// finite points by a normalised rotation gives none).
#[inline(always)]
pub(crate) fn bounds_of_points<const GROUPS: usize>(x: [F4; GROUPS], y: [F4; GROUPS]) -> ([f32; 2], [f32; 2]) {
    simd!(
        {
            // Each point as the pair (x, y) in lanes 0 and 1: [x0, y0, x1, y1] and
            // [x2, y2, x3, y3] per group, points 1 and 3 moved down to lanes 0 and 1.
            let first = _mm_unpacklo_ps(sse::f(x[0]), sse::f(y[0]));
            let (mut lo, mut hi) = (first, first);
            // `minps(p, acc)` is `p < acc ? p : acc`: the running value stays on a tie.
            let mut take = |p| {
                lo = _mm_min_ps(p, lo);
                hi = _mm_max_ps(p, hi);
            };
            for g in 0..GROUPS {
                let (x, y) = (sse::f(x[g]), sse::f(y[g]));
                let (p01, p23) = (_mm_unpacklo_ps(x, y), _mm_unpackhi_ps(x, y));
                if g > 0 {
                    take(p01);
                }
                take(_mm_movehl_ps(p01, p01));
                take(p23);
                take(_mm_movehl_ps(p23, p23));
            }
            let (lo, hi) = (sse::to_f(lo), sse::to_f(hi));
            ([lo[0], lo[1]], [hi[0], hi[1]])
        },
        {
            let lane = |v: &[F4; GROUPS], i: usize| v[i / LANES4][i % LANES4];
            let fold = |v: &[F4; GROUPS], less: fn(f32, f32) -> bool| {
                (1..LANES4 * GROUPS).fold(
                    lane(v, 0),
                    |acc, i| {
                        if less(lane(v, i), acc) {
                            lane(v, i)
                        } else {
                            acc
                        }
                    },
                )
            };
            let (lt, gt): (fn(f32, f32) -> bool, fn(f32, f32) -> bool) = (|a, b| a < b, |a, b| a > b);
            ([fold(&x, lt), fold(&y, lt)], [fold(&x, gt), fold(&y, gt)])
        }
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
        self[i] != 0
    }

    /// A mask from four booleans.
    #[inline(always)]
    pub fn from_bools(b: [bool; LANES4]) -> M4 {
        M4::new(b.map(mask))
    }

    /// [`M4::from_bools`] for four booleans stored side by side in a record: on x86-64 the
    /// four bytes loaded as one word into every lane, each lane testing its own byte (four
    /// instructions, where building the lanes one by one took about fifteen; booleans just
    /// computed are better made into lanes directly, by `from_bools`).
    #[inline(always)]
    pub fn from_stored_bools(b: [bool; LANES4]) -> M4 {
        simd!(
            {
                // Lane l holds bit 0 of byte l of the word (a bool's byte is 0 or 1).
                let word = i32::from_le_bytes(b.map(u8::from));
                let bits = _mm_setr_epi32(1, 1 << 8, 1 << 16, 1 << 24);
                sse::to_m(_mm_castsi128_ps(_mm_cmpeq_epi32(
                    _mm_and_si128(_mm_set1_epi32(word), bits),
                    bits,
                )))
            },
            M4::new(b.map(mask))
        )
    }

    /// The lanes whose byte in `b` is not zero (as [`M4::from_stored_bools`]: the same
    /// word, each lane's byte compared with zero and the result negated).
    #[inline(always)]
    pub fn from_nonzero_bytes(b: [u8; LANES4]) -> M4 {
        simd!(
            {
                let word = i32::from_le_bytes(b);
                let bytes = _mm_setr_epi32(0xFF, 0xFF << 8, 0xFF << 16, 0xFF << 24);
                let zero = _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(word), bytes), _mm_setzero_si128());
                !sse::to_m(_mm_castsi128_ps(zero))
            },
            M4::new(b.map(|x| mask(x != 0)))
        )
    }

    /// The lanes where `a` is zero.
    #[inline(always)]
    pub fn zero_lanes(a: [u32; LANES4]) -> M4 {
        simd!(
            sse::to_m(_mm_castsi128_ps(_mm_cmpeq_epi32(
                _mm_setr_epi32(a[0] as i32, a[1] as i32, a[2] as i32, a[3] as i32),
                _mm_setzero_si128(),
            ))),
            M4::new(lanes!(|i| mask(a[i] == 0)))
        )
    }

    /// The lanes where `a` is greater than `k` (unsigned: both offset by 2³¹ for the
    /// signed compare).
    #[inline(always)]
    pub fn above(a: [u32; LANES4], k: u32) -> M4 {
        simd!(
            {
                let flip = |x: u32| (x ^ 0x8000_0000) as i32;
                let v = _mm_setr_epi32(flip(a[0]), flip(a[1]), flip(a[2]), flip(a[3]));
                sse::to_m(_mm_castsi128_ps(_mm_cmpgt_epi32(v, _mm_set1_epi32(flip(k)))))
            },
            M4::new(lanes!(|i| mask(a[i] > k)))
        )
    }

    /// The lanes where `a` or `b` is zero.
    #[inline(always)]
    pub fn either_zero(a: [u32; LANES4], b: [u32; LANES4]) -> M4 {
        M4::zero_lanes(a) | M4::zero_lanes(b)
    }

    /// The four lanes of a mask (each lane all ones or all zeros) as booleans.
    #[inline(always)]
    pub fn to_bools(self) -> [bool; LANES4] {
        simd!(
            {
                let bits = _mm_movemask_ps(sse::m(self));
                [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0, bits & 8 != 0]
            },
            lanes!(|i| self[i] != 0)
        )
    }

    /// The lanes as the low four bits of a word (lane i: bit i).
    #[inline(always)]
    pub fn bits(self) -> u32 {
        simd!(
            _mm_movemask_ps(sse::m(self)) as u32,
            (0..LANES4).fold(0, |b, i| b | (((self[i] != 0) as u32) << i))
        )
    }

    /// Whether some lane is true.
    #[inline(always)]
    pub fn any(self) -> bool {
        simd!(
            _mm_movemask_ps(sse::m(self)) != 0,
            (self[0] | self[1] | self[2] | self[3]) != 0
        )
    }

    /// Whether every lane is true.
    #[inline(always)]
    pub fn all(self) -> bool {
        simd!(
            _mm_movemask_ps(sse::m(self)) == 0b1111,
            (self[0] & self[1] & self[2] & self[3]) == u32::MAX
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
            F4::new(lanes!(|i| f32::from_bits(
                (a[i].to_bits() & self[i]) | (b[i].to_bits() & !self[i])
            )))
        )
    }

    /// 1.0 where true, 0.0 where false.
    #[inline(always)]
    pub fn to_unit(self) -> F4 {
        simd!(
            sse::to_f(_mm_and_ps(sse::m(self), _mm_set1_ps(1.0))),
            F4::new(lanes!(|i| f32::from_bits(1.0f32.to_bits() & self[i])))
        )
    }
}

macro_rules! f4_binop {
    ($tr:ident, $f:ident, $op:tt, $sse:ident) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                simd!(sse::to_f($sse(sse::f(self), sse::f(o))), F4::new(lanes!(|i| self[i] $op o[i])))
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
            F4::new(lanes!(|i| -self[i]))
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
            M4::new(lanes!(|i| self[i] & o[i]))
        )
    }
}

impl BitOr for M4 {
    type Output = M4;
    #[inline(always)]
    fn bitor(self, o: M4) -> M4 {
        simd!(
            sse::to_m(_mm_or_ps(sse::m(self), sse::m(o))),
            M4::new(lanes!(|i| self[i] | o[i]))
        )
    }
}

impl Not for M4 {
    type Output = M4;
    #[inline(always)]
    fn not(self) -> M4 {
        simd!(
            sse::to_m(_mm_xor_ps(sse::m(self), _mm_castsi128_ps(_mm_set1_epi32(-1)))),
            M4::new(lanes!(|i| !self[i]))
        )
    }
}

/// A 2D vector of lanes `$v` over the lane type `$f` (x and y as lanes), with the few
/// operations the wide solver uses.
macro_rules! lane_vectors {
    ($v:ident, $f:ident, $doc:literal) => {
        #[doc = $doc]
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub(crate) struct $v {
            pub x: $f,
            pub y: $f,
        }

        impl $v {
            #[inline(always)]
            pub fn dot(self, o: $v) -> $f {
                self.x * o.x + self.y * o.y
            }

            /// z of the 3D cross product, lane by lane.
            #[inline(always)]
            pub fn cross(self, o: $v) -> $f {
                self.x * o.y - self.y * o.x
            }

            /// (y, −x): the vector turned clockwise (`Vec2::right_perp`; the tangent of a
            /// normal).
            #[inline(always)]
            pub fn right_perp(self) -> $v {
                $v {
                    x: self.y,
                    y: -self.x,
                }
            }

            #[inline(always)]
            pub fn scale(self, s: $f) -> $v {
                $v {
                    x: s * self.x,
                    y: s * self.y,
                }
            }
        }

        impl core::ops::Add for $v {
            type Output = $v;
            #[inline(always)]
            fn add(self, o: $v) -> $v {
                $v {
                    x: self.x + o.x,
                    y: self.y + o.y,
                }
            }
        }

        impl core::ops::Sub for $v {
            type Output = $v;
            #[inline(always)]
            fn sub(self, o: $v) -> $v {
                $v {
                    x: self.x - o.x,
                    y: self.y - o.y,
                }
            }
        }
    };
}
#[cfg(target_arch = "x86_64")]
pub(crate) use lane_vectors;

lane_vectors!(V4, F4, "Four 2D vectors, one per lane.");

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane of `from_stored_bools` (and `from_bools`) is set exactly where its boolean
    /// is true, for all sixteen patterns, and `from_nonzero_bytes` exactly where its byte is
    /// not zero (each byte value in each lane, so a bit of one byte cannot leak into another
    /// lane).
    #[test]
    fn masks_from_bytes_set_exactly_their_lanes() {
        let lanes = |m: M4| core::array::from_fn::<bool, LANES4, _>(|l| m.lane(l));
        for pattern in 0..16u32 {
            let b: [bool; LANES4] = core::array::from_fn(|l| pattern >> l & 1 == 1);
            let all = b.map(|x| if x { u32::MAX } else { 0 });
            assert_eq!(lanes(M4::from_stored_bools(b)), b, "{b:?}");
            assert_eq!((*M4::from_stored_bools(b), *M4::from_bools(b)), (all, all));
        }
        for x in 0..=255u8 {
            for l in 0..LANES4 {
                let mut bytes = [0u8; LANES4];
                bytes[l] = x;
                let expected: [bool; LANES4] = core::array::from_fn(|k| k == l && x != 0);
                assert_eq!(lanes(M4::from_nonzero_bytes(bytes)), expected, "{bytes:?}");
                // The other lanes full: only lane l depends on x.
                let others = bytes.map(|b| if b == 0 { 7 } else { b });
                let mut full = others;
                full[l] = x;
                let expected: [bool; LANES4] = core::array::from_fn(|k| k != l || x != 0);
                assert_eq!(lanes(M4::from_nonzero_bytes(full)), expected, "{full:?}");
            }
        }
    }

    /// `split_xy` gathers the x and the y of four points, in order, and `join_xy` puts
    /// them back.
    #[test]
    fn split_xy_gathers_the_coordinates_of_four_points() {
        let v = Vec2::new;
        let points = [v(1.0, 2.0), v(3.0, 4.0), v(5.0, 6.0), v(7.0, 8.0)];
        let (x, y) = split_xy(points);
        assert_eq!(*x, [1.0, 3.0, 5.0, 7.0]);
        assert_eq!(*y, [2.0, 4.0, 6.0, 8.0]);
        assert_eq!(join_xy(x, y), points);
    }

    #[test]
    fn lanes_match_scalar_arithmetic() {
        let a = F4::new([1.5, -2.0, 0.0, 3.25]);
        let b = F4::new([0.5, 4.0, -0.0, -1.0]);
        assert_eq!(*(a + b), [2.0, 2.0, 0.0, 2.25]);
        assert_eq!(*(a * b), [0.75, -8.0, -0.0, -3.25]);
        assert_eq!(*a.max(b), [1.5, 4.0, -0.0, 3.25]);
        assert_eq!(*a.min(b), [0.5, -2.0, -0.0, -1.0]);
        assert_eq!(*a.abs(), [1.5, 2.0, 0.0, 3.25]);
        let m = a.gt(b);
        assert_eq!(*m.select(a, b), [1.5, 4.0, -0.0, 3.25]);
        assert_eq!(*m.to_unit(), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(*(!m & a.ge(b)), [0, 0, u32::MAX, 0]);
        assert!(!m.all() && (m | !m).all());
        // A lane written through the array view is read back by the register operations.
        let mut c = a;
        c[2] = 5.0;
        assert_eq!(*(c + b), [2.0, 2.0, 5.0, 2.25]);
        let rows = [a, b, a + b, a * b];
        let cols = transpose(rows);
        for (i, col) in cols.iter().enumerate() {
            assert_eq!(**col, [a[i], b[i], (a + b)[i], (a * b)[i]]);
        }
        assert_eq!(transpose(cols), rows);
        // Body indices: 0 is the static body; u32::MAX must not read as a negative zero.
        let (ia, ib) = ([0, 7, 3, u32::MAX], [5, 0, 9, 1]);
        assert_eq!(*M4::either_zero(ia, ib), [u32::MAX, u32::MAX, 0, 0]);
        assert_eq!(*M4::either_zero([0; LANES4], [0; LANES4]), [u32::MAX; LANES4]);
        assert_eq!(*M4::zero_lanes([0, u32::MAX, 1, 0]), [u32::MAX, 0, 0, u32::MAX]);
        // `above` compares unsigned words (the signed compare's 2³¹ offset): the largest
        // word is above everything, and words either side of 2³¹ keep their order.
        let on = u32::MAX;
        assert_eq!(*M4::above([0, 1, 2, u32::MAX], 1), [0, 0, on, on]);
        assert_eq!(
            *M4::above([0x8000_0000, 0x7fff_ffff, 0, 0x8000_0001], 0x7fff_ffff),
            [on, 0, 0, on]
        );
        assert_eq!(*M4::above([0x8000_0000, u32::MAX, 5, 0], 0x8000_0000), [0, on, 0, 0]);
        // Flag words carried as float bits, never as numbers: a NaN's bits, a negative
        // zero's, all ones; every bit asked for must be set.
        let words = F4::new([0xffff_ffff, 0x8000_0002, 0x7fc0_0001, 0x0000_0001].map(f32::from_bits));
        assert_eq!(*words.bits_set(1), [on, 0, on, on]);
        assert_eq!(*words.bits_set(2), [on, on, 0, 0]);
        assert_eq!(*words.bits_set(3), [on, 0, 0, 0]);
        assert_eq!(m.to_bools(), [true, false, false, true]);
        assert_eq!((!m).to_bools(), [false, true, true, false]);
    }
}
