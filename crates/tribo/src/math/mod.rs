//! Math: 2D vectors, rotations stored as (cos, sin), rigid transforms and axis-aligned boxes.
//!
//! Pipeline stage: none (used everywhere). Neighbours: [`crate::geometry`] builds on this
//! module only.
//!
//! All arithmetic is plain `f32` with no fused multiply-add, so a given build produces
//! bit-identical results run after run.

pub(crate) mod wide;
#[cfg(target_arch = "x86_64")]
pub(crate) mod wide8;

use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A 2D vector or point [m] (or [m/s], [N], ... by context).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec2 {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
}

impl Vec2 {
    /// The zero vector.
    pub const ZERO: Vec2 = Vec2 { x: 0.0, y: 0.0 };
    /// The unit x axis.
    pub const X: Vec2 = Vec2 { x: 1.0, y: 0.0 };
    /// The unit y axis.
    pub const Y: Vec2 = Vec2 { x: 0.0, y: 1.0 };

    /// Makes a vector from its components.
    #[inline]
    pub const fn new(x: f32, y: f32) -> Vec2 {
        Vec2 { x, y }
    }

    /// Dot product.
    #[inline]
    pub fn dot(self, o: Vec2) -> f32 {
        self.x * o.x + self.y * o.y
    }

    /// 2D cross product (the z component of the 3D cross product).
    #[inline]
    pub fn cross(self, o: Vec2) -> f32 {
        self.x * o.y - self.y * o.x
    }

    /// Cross product of a scalar (z axis) with this vector: `s × v = (-s·v.y, s·v.x)`.
    /// Used for the velocity of a point: `v + ω × r`.
    #[inline]
    pub fn cross_sv(s: f32, v: Vec2) -> Vec2 {
        Vec2::new(-s * v.y, s * v.x)
    }

    /// Cross product of this vector with a scalar (z axis): `v × s = (s·v.y, -s·v.x)`.
    #[inline]
    pub fn cross_vs(self, s: f32) -> Vec2 {
        Vec2::new(s * self.y, -s * self.x)
    }

    /// Counter-clockwise perpendicular `(-y, x)`.
    #[inline]
    pub fn left_perp(self) -> Vec2 {
        Vec2::new(-self.y, self.x)
    }

    /// Clockwise perpendicular `(y, -x)`.
    #[inline]
    pub fn right_perp(self) -> Vec2 {
        Vec2::new(self.y, -self.x)
    }

    /// Euclidean length.
    #[inline]
    pub fn length(self) -> f32 {
        (self.x * self.x + self.y * self.y).sqrt()
    }

    /// Squared length.
    #[inline]
    pub fn length_squared(self) -> f32 {
        self.x * self.x + self.y * self.y
    }

    /// Distance between two points.
    #[inline]
    pub fn distance(self, o: Vec2) -> f32 {
        (o - self).length()
    }

    /// Unit vector in the same direction, or `None` when the length is below `f32::EPSILON`.
    #[inline]
    pub fn try_normalize(self) -> Option<Vec2> {
        let len = self.length();
        if len < f32::EPSILON {
            None
        } else {
            Some(self * (1.0 / len))
        }
    }

    /// Unit vector in the same direction, or zero for a (near) zero vector.
    #[inline]
    pub fn normalize_or_zero(self) -> Vec2 {
        self.try_normalize().unwrap_or(Vec2::ZERO)
    }

    /// Returns the length and the unit vector (zero vector when the length is tiny).
    #[inline]
    pub fn length_and_normalize(self) -> (f32, Vec2) {
        let len = self.length();
        if len < f32::EPSILON {
            (0.0, Vec2::ZERO)
        } else {
            (len, self * (1.0 / len))
        }
    }

    /// Component-wise minimum.
    #[inline]
    pub fn min(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x.min(o.x), self.y.min(o.y))
    }

    /// Component-wise maximum.
    #[inline]
    pub fn max(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x.max(o.x), self.y.max(o.y))
    }

    /// Component-wise absolute value.
    #[inline]
    pub fn abs(self) -> Vec2 {
        Vec2::new(self.x.abs(), self.y.abs())
    }

    /// Linear interpolation `self + t (o - self)`.
    #[inline]
    pub fn lerp(self, o: Vec2, t: f32) -> Vec2 {
        Vec2::new(self.x + t * (o.x - self.x), self.y + t * (o.y - self.y))
    }

    /// True when both components are finite (not NaN, not infinite).
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

impl Add for Vec2 {
    type Output = Vec2;
    #[inline]
    fn add(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x + o.x, self.y + o.y)
    }
}
impl Sub for Vec2 {
    type Output = Vec2;
    #[inline]
    fn sub(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x - o.x, self.y - o.y)
    }
}
impl Neg for Vec2 {
    type Output = Vec2;
    #[inline]
    fn neg(self) -> Vec2 {
        Vec2::new(-self.x, -self.y)
    }
}
impl Mul<f32> for Vec2 {
    type Output = Vec2;
    #[inline]
    fn mul(self, s: f32) -> Vec2 {
        Vec2::new(self.x * s, self.y * s)
    }
}
impl Mul<Vec2> for f32 {
    type Output = Vec2;
    #[inline]
    fn mul(self, v: Vec2) -> Vec2 {
        Vec2::new(self * v.x, self * v.y)
    }
}
impl Div<f32> for Vec2 {
    type Output = Vec2;
    #[inline]
    fn div(self, s: f32) -> Vec2 {
        Vec2::new(self.x / s, self.y / s)
    }
}
impl AddAssign for Vec2 {
    #[inline]
    fn add_assign(&mut self, o: Vec2) {
        self.x += o.x;
        self.y += o.y;
    }
}
impl SubAssign for Vec2 {
    #[inline]
    fn sub_assign(&mut self, o: Vec2) {
        self.x -= o.x;
        self.y -= o.y;
    }
}
impl MulAssign<f32> for Vec2 {
    #[inline]
    fn mul_assign(&mut self, s: f32) {
        self.x *= s;
        self.y *= s;
    }
}

/// A rotation stored as cosine and sine of the angle (counter-clockwise positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rot {
    /// Cosine of the angle.
    pub c: f32,
    /// Sine of the angle.
    pub s: f32,
}

impl Default for Rot {
    fn default() -> Self {
        Rot::IDENTITY
    }
}

impl Rot {
    /// No rotation.
    pub const IDENTITY: Rot = Rot { c: 1.0, s: 0.0 };

    /// Rotation by `angle` [rad], counter-clockwise.
    #[inline]
    pub fn from_angle(angle: f32) -> Rot {
        let (s, c) = angle.sin_cos();
        Rot { c, s }
    }

    /// The angle [rad] in (-π, π].
    #[inline]
    pub fn angle(self) -> f32 {
        self.s.atan2(self.c)
    }

    /// The angle [rad] in [−π, π] to within 3·10⁻⁷ rad ([`atan2_fast`]): for the solver's
    /// passes, which read joint angles many times a step.
    #[inline]
    pub(crate) fn angle_fast(self) -> f32 {
        atan2_fast(self.s, self.c)
    }

    /// Rotates a vector.
    #[inline]
    pub fn rotate(self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x - self.s * v.y, self.s * v.x + self.c * v.y)
    }

    /// Rotates a vector by the inverse rotation.
    #[inline]
    pub fn inv_rotate(self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x + self.s * v.y, -self.s * v.x + self.c * v.y)
    }

    /// Composition `self * o` (apply `o` first, then `self`).
    #[inline]
    pub fn mul(self, o: Rot) -> Rot {
        Rot {
            c: self.c * o.c - self.s * o.s,
            s: self.s * o.c + self.c * o.s,
        }
    }

    /// `self⁻¹ * o`: the rotation from `self` to `o`.
    #[inline]
    pub fn inv_mul(self, o: Rot) -> Rot {
        Rot {
            c: self.c * o.c + self.s * o.s,
            s: self.c * o.s - self.s * o.c,
        }
    }

    /// Advances the rotation by a small angle `da` [rad] with the first-order update
    /// `q + da·(−s, c)` and renormalises (Box2D v3 `b2IntegrateRotation`; exact for the
    /// direction, error O(da³) in the angle).
    #[inline]
    pub fn integrate(self, da: f32) -> Rot {
        let c = self.c - da * self.s;
        let s = self.s + da * self.c;
        let mag = (c * c + s * s).sqrt();
        let inv = if mag > 0.0 { 1.0 / mag } else { 0.0 };
        Rot { c: c * inv, s: s * inv }
    }

    /// Unit x axis of the rotated frame.
    #[inline]
    pub fn x_axis(self) -> Vec2 {
        Vec2::new(self.c, self.s)
    }
}

/// A rigid transform: rotation then translation. `apply(v) = q·v + p`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Transform {
    /// Translation [m].
    pub p: Vec2,
    /// Rotation.
    pub q: Rot,
}

impl Transform {
    /// The identity transform.
    pub const IDENTITY: Transform = Transform {
        p: Vec2::ZERO,
        q: Rot::IDENTITY,
    };

    /// Makes a transform from a position [m] and an angle [rad].
    #[inline]
    pub fn new(p: Vec2, angle: f32) -> Transform {
        Transform {
            p,
            q: Rot::from_angle(angle),
        }
    }

    /// Maps a local point to the parent frame.
    #[inline]
    pub fn apply(self, v: Vec2) -> Vec2 {
        self.q.rotate(v) + self.p
    }

    /// Maps a parent-frame point to the local frame.
    #[inline]
    pub fn inv_apply(self, v: Vec2) -> Vec2 {
        self.q.inv_rotate(v - self.p)
    }

    /// Composition `self * o` (apply `o` first).
    #[inline]
    pub fn mul(self, o: Transform) -> Transform {
        Transform {
            p: self.q.rotate(o.p) + self.p,
            q: self.q.mul(o.q),
        }
    }

    /// `self⁻¹ * o`: `o` expressed in the frame of `self`.
    #[inline]
    pub fn inv_mul(self, o: Transform) -> Transform {
        Transform {
            p: self.q.inv_rotate(o.p - self.p),
            q: self.q.inv_mul(o.q),
        }
    }
}

/// Axis-aligned bounding box [m].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec2,
    /// Upper corner.
    pub max: Vec2,
}

impl Aabb {
    /// Makes a box from its corners.
    #[inline]
    pub const fn new(min: Vec2, max: Vec2) -> Aabb {
        Aabb { min, max }
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb::new(self.min.min(o.min), self.max.max(o.max))
    }

    /// True when `o` lies inside `self` (boundaries included).
    #[inline]
    pub fn contains(self, o: Aabb) -> bool {
        self.min.x <= o.min.x && self.min.y <= o.min.y && o.max.x <= self.max.x && o.max.y <= self.max.y
    }

    /// True when the boxes overlap (touching counts).
    #[inline]
    pub fn overlaps(self, o: Aabb) -> bool {
        // Bitwise, not short-circuit: one branch on the answer, not up to four.
        !((o.min.x > self.max.x) | (o.min.y > self.max.y) | (self.min.x > o.max.x) | (self.min.y > o.max.y))
    }

    /// True when both boxes have the same corners: IEEE `==` on each coordinate (±0.0 equal,
    /// NaN unequal), as the derived `==`, without its short-circuit branches.
    #[inline]
    pub(crate) fn same(self, o: Aabb) -> bool {
        (self.min.x == o.min.x) & (self.min.y == o.min.y) & (self.max.x == o.max.x) & (self.max.y == o.max.y)
    }

    /// Perimeter [m], the surface-area heuristic's cost in 2D.
    #[inline]
    pub fn perimeter(self) -> f32 {
        2.0 * ((self.max.x - self.min.x) + (self.max.y - self.min.y))
    }

    /// Centre point.
    #[inline]
    pub fn center(self) -> Vec2 {
        Vec2::new(0.5 * (self.min.x + self.max.x), 0.5 * (self.min.y + self.max.y))
    }

    /// Half extents.
    #[inline]
    pub fn extents(self) -> Vec2 {
        Vec2::new(0.5 * (self.max.x - self.min.x), 0.5 * (self.max.y - self.min.y))
    }

    /// Grows the box by `margin` [m] on every side.
    #[inline]
    pub fn expand(self, margin: f32) -> Aabb {
        let m = Vec2::new(margin, margin);
        Aabb::new(self.min - m, self.max + m)
    }

    /// True when min ≤ max and every coordinate is finite.
    #[inline]
    pub fn is_valid(self) -> bool {
        self.min.is_finite() && self.max.is_finite() && self.min.x <= self.max.x && self.min.y <= self.max.y
    }
}

/// Coefficients of atan(a) ≈ a (c₀ + c₁ a² + … + c₇ a¹⁴) on a ∈ [0, 1]: our own
/// least-squares fit at 400 Chebyshev nodes, reweighted by the error (Lawson's iteration)
/// towards the minimax fit; largest error of the f32 evaluation 3·10⁻⁷ rad.
const ATAN_COEFFS: [f32; 8] = [
    0.999_999_34,
    -0.333_298_53,
    0.199_464_9,
    -0.139_082_67,
    0.096_413_11,
    -0.055_900_738,
    0.021_855_235,
    -0.004_052_509_6,
];

/// atan2(y, x) [rad] in [−π, π] to within 3·10⁻⁷ rad (libm's `atan2f`: about 10⁻⁷) for
/// finite arguments (±0 and ±π for zeros as `atan2f`), at a fraction of its cost: the ratio a = min/max of
/// |x| and |y| in [0, 1], the polynomial [`ATAN_COEFFS`], then the octant
/// (π/2 − r, π − r, −r). A revolute joint's limit and spring rows read its angle in every
/// pass, and `atan2f` was 4.5 % of rain's step; Box2D v3 reads its joint angles through
/// an approximate atan2 of its own as well (`b2Atan2`).
#[inline]
pub(crate) fn atan2_fast(y: f32, x: f32) -> f32 {
    let poly = |a: f32| {
        let s = a * a;
        let mut r = ATAN_COEFFS[7];
        for &c in ATAN_COEFFS[..7].iter().rev() {
            r = r * s + c;
        }
        r * a
    };
    if x > y.abs() {
        // |angle| < π/4 (a joint's turn within a step, nearly always): the odd polynomial
        // of y/x carries the sign itself, bit for bit the general path's result.
        return poly(y / x);
    }
    let (ax, ay) = (x.abs(), y.abs());
    let (hi, lo) = (ax.max(ay), ax.min(ay));
    // (0, 0): 0 / tiny = 0.
    let mut r = poly(lo / hi.max(f32::MIN_POSITIVE));
    // The octant by bit masks, not branches: a float select compiles to a branch on the
    // x86-64 baseline, and the signs of a small relative turn are a coin toss (this
    // function in branches made rain's joint pass slower than `atan2f`).
    let pick = |take: bool, if_true: f32, if_false: f32| {
        let m = 0u32.wrapping_sub(take as u32);
        f32::from_bits((if_true.to_bits() & m) | (if_false.to_bits() & !m))
    };
    r = pick(ay > ax, core::f32::consts::FRAC_PI_2 - r, r);
    r = pick(x.is_sign_negative(), core::f32::consts::PI - r, r);
    // r ≥ 0 here: y's sign.
    f32::from_bits(r.to_bits() | (y.to_bits() & 0x8000_0000))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast atan2 is within 3.5·10⁻⁷ rad of the exact angle (atan2 in f64 of the same
    /// f32 arguments) all around the circle and at any scale: its fit's 3·10⁻⁷ plus the
    /// f32 rounding of the octant's π − r (half an ulp of π, 1.2·10⁻⁷). Exact on the axes.
    #[test]
    fn fast_atan2_is_within_its_bound() {
        let mut worst = 0.0f64;
        for k in 0..=100_000 {
            let t = -std::f64::consts::PI + 2.0 * std::f64::consts::PI * k as f64 / 100_000.0;
            for scale in [1e-6f64, 1.0, 3.7e5] {
                let (y, x) = ((t.sin() * scale) as f32, (t.cos() * scale) as f32);
                let exact = (y as f64).atan2(x as f64);
                worst = worst.max((atan2_fast(y, x) as f64 - exact).abs());
            }
        }
        assert!(worst < 3.5e-7, "largest error {worst:e} rad");
        assert_eq!(atan2_fast(0.0, 1.0), 0.0);
        assert_eq!(atan2_fast(1.0, 0.0), core::f32::consts::FRAC_PI_2);
        assert_eq!(atan2_fast(-1.0, 0.0), -core::f32::consts::FRAC_PI_2);
        assert_eq!(atan2_fast(0.0, -1.0), core::f32::consts::PI);
        assert_eq!(atan2_fast(0.0, 0.0), 0.0);
        assert!((Rot::from_angle(2.5).angle_fast() - 2.5).abs() < 5e-7);
    }

    #[test]
    fn rotation_round_trip() {
        let q = Rot::from_angle(0.7);
        let v = Vec2::new(1.5, -2.0);
        let w = q.inv_rotate(q.rotate(v));
        assert!((w - v).length() < 1e-6);
        assert!((q.angle() - 0.7).abs() < 1e-6);
    }

    #[test]
    fn transform_inverse() {
        let a = Transform::new(Vec2::new(1.0, 2.0), 0.3);
        let b = Transform::new(Vec2::new(-3.0, 0.5), -1.1);
        let rel = a.inv_mul(b);
        let p = Vec2::new(0.25, 0.75);
        assert!((a.apply(rel.apply(p)) - b.apply(p)).length() < 1e-5);
        assert!((a.inv_apply(a.apply(p)) - p).length() < 1e-6);
    }

    #[test]
    fn integrate_rotation_matches_angle() {
        // Small steps of da add up to the angle within O(da²) per step.
        let mut q = Rot::IDENTITY;
        for _ in 0..100 {
            q = q.integrate(0.01);
        }
        assert!((q.angle() - 1.0).abs() < 1e-3, "{}", q.angle());
    }

    #[test]
    fn aabb_ops() {
        let a = Aabb::new(Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0));
        let b = Aabb::new(Vec2::new(0.5, 0.5), Vec2::new(2.0, 2.0));
        assert!(a.overlaps(b));
        assert!(a.union(b).contains(a));
        assert_eq!(a.perimeter(), 4.0);
        assert!(!a.overlaps(Aabb::new(Vec2::new(1.1, 0.0), Vec2::new(2.0, 1.0))));
    }
}
