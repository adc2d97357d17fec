//! Soft constraints: a constraint that behaves like a damped spring of a given frequency,
//! solved implicitly so it is stable at any stiffness.
//!
//! For a constraint row with effective mass m, frequency f [Hz] (ω = 2πf), damping ratio ζ
//! and substep h, the implicit spring-damper gives (Catto, "Solver2D" and Box2D v3 soft
//! step; see also Catto, "Soft Constraints", GDC 2011):
//!
//! ```text
//! bias_rate     = ω / (2ζ + hω)                    [1/s]
//! mass_scale    = hω(2ζ + hω) / (1 + hω(2ζ + hω))
//! impulse_scale = 1 / (1 + hω(2ζ + hω))
//! Δλ = −m · mass_scale · (v + bias_rate · C) − impulse_scale · λ
//! ```
//!
//! Under a steady load F the row settles at a static deflection C = F / (m ω²)
//! (set Δλ = 0 with v = 0 and λ = F h). The contact solver uses this to raise the frequency
//! of heavily loaded contacts (see `contact_solver`).

/// The three coefficients of a soft constraint row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Softness {
    /// Position error to velocity [1/s].
    pub bias_rate: f32,
    /// Fraction of the rigid impulse applied.
    pub mass_scale: f32,
    /// Fraction of the accumulated impulse relaxed each solve.
    pub impulse_scale: f32,
}

impl Default for Softness {
    fn default() -> Self {
        Softness::RIGID
    }
}

impl Softness {
    /// A rigid row (no softness, no bias).
    pub const RIGID: Softness = Softness {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    /// Softness of frequency `hertz` [Hz], damping ratio `zeta` and substep `h` [s].
    pub fn new(hertz: f32, zeta: f32, h: f32) -> Softness {
        if hertz <= 0.0 {
            return Softness::RIGID;
        }
        Softness::from_omega(2.0 * core::f32::consts::PI * hertz, zeta, h)
    }

    /// Softness of angular frequency `omega` [rad/s].
    pub fn from_omega(omega: f32, zeta: f32, h: f32) -> Softness {
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Softness {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit mass on a soft row under a constant force F settles at C = F/(m ω²).
    #[test]
    fn static_deflection_matches_spring() {
        let (hertz, zeta, h) = (30.0f32, 10.0f32, 1.0f32 / 240.0);
        let s = Softness::new(hertz, zeta, h);
        let omega = 2.0 * core::f32::consts::PI * hertz;
        let (m, f) = (1.0f32, 9.81f32);
        // simulate: v += h F/m (pushing into the constraint: C decreases), then solve.
        let (mut c, mut v, mut lambda) = (0.0f32, 0.0f32, 0.0f32);
        for _ in 0..20000 {
            v -= h * f / m;
            v += lambda / m; // warm start
            let dl = -m * s.mass_scale * (v + s.bias_rate * c) - s.impulse_scale * lambda;
            let new = (lambda + dl).max(0.0);
            v += (new - lambda) / m;
            lambda = new;
            c += h * v;
            // relax (rigid, no bias)
            let dl = -m * v;
            let new = (lambda + dl).max(0.0);
            v += (new - lambda) / m;
            lambda = new;
        }
        let expected = -f / (m * omega * omega);
        assert!(
            (c - expected).abs() < 0.02 * expected.abs(),
            "c = {c}, expected {expected}"
        );
    }
}
