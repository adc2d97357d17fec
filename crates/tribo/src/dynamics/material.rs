//! Surface materials and the rules that combine two materials at a contact.
//!
//! Pipeline stage: narrow phase (a contact's coefficients are mixed when it is created and
//! whenever a shape's material changes). Neighbours: [`crate::solver`] uses the mixed values.

use crate::error::{check_finite, check_non_negative, Error, Result};

/// How the coefficients of two touching materials are combined.
///
/// When the two materials choose different rules, the rule with the higher
/// [`CombineRule::precedence`] wins: `Average < GeometricMean < Min < Multiply < Max`
/// (the PhysX convention of "the larger enum wins", extended with the geometric mean).
/// A material that leaves its rule unset (`None`) defers to the other material's rule;
/// when both are unset the default applies (geometric mean for friction, max for
/// restitution, as in Box2D, so scenes port unchanged).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum CombineRule {
    /// (a + b) / 2
    Average,
    /// √(a·b)
    GeometricMean,
    /// min(a, b)
    Min,
    /// a·b
    Multiply,
    /// max(a, b)
    Max,
}

impl CombineRule {
    /// Rank used when two materials ask for different rules: the higher wins.
    pub fn precedence(self) -> u8 {
        self as u8
    }

    /// Applies the rule.
    pub fn combine(self, a: f32, b: f32) -> f32 {
        match self {
            CombineRule::Average => 0.5 * (a + b),
            CombineRule::GeometricMean => (a * b).sqrt(),
            CombineRule::Min => a.min(b),
            CombineRule::Multiply => a * b,
            CombineRule::Max => a.max(b),
        }
    }

    /// The rule that applies between two materials' choices, `default` when neither chose.
    pub fn resolve(a: Option<CombineRule>, b: Option<CombineRule>, default: CombineRule) -> CombineRule {
        match (a, b) {
            (None, None) => default,
            (Some(r), None) | (None, Some(r)) => r,
            (Some(ra), Some(rb)) => {
                if ra.precedence() >= rb.precedence() {
                    ra
                } else {
                    rb
                }
            }
        }
    }
}

/// The surface and bulk properties of a shape.
///
/// Defaults (Box2D's, so scenes port): density 1 kg/m², μs = μd = 0.6, restitution 0,
/// restitution threshold 1 m/s, no rolling resistance, no tangent speed, combine rules
/// unset (friction by geometric mean, restitution by max).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Density [kg/m²], ≥ 0. Zero gives a massless shape (a dynamic body needs some mass
    /// from at least one shape, or it gets 1 kg by default).
    pub density: f32,
    /// Static friction coefficient μs ≥ μd: a sticking contact holds while the friction
    /// impulse it needs is at most μs times its normal impulse.
    pub friction_static: f32,
    /// Dynamic (kinetic) friction coefficient μd ≥ 0: a sliding contact applies exactly μd
    /// times its normal impulse against the slip.
    pub friction_dynamic: f32,
    /// Coefficient of restitution e in [0, 1].
    pub restitution: f32,
    /// Approach speed [m/s] below which a contact does not bounce, usually 1 m/s.
    /// The smaller of the two materials' thresholds applies.
    pub restitution_threshold: f32,
    /// Rolling resistance (dimensionless, Box2D's definition): the resisting torque is at
    /// most `rolling_resistance × radius × normal force`. The larger of the two applies.
    pub rolling_resistance: f32,
    /// Surface speed [m/s] of this shape along its own surface, for conveyor belts:
    /// positive moves the surface clockwise around the shape (so on the top face of a
    /// ground box, bodies are carried towards +x). The two shapes' speeds add.
    pub tangent_speed: f32,
    /// Combine rule for friction (`None` = defer; see [`CombineRule`]).
    pub friction_combine: Option<CombineRule>,
    /// Combine rule for restitution (`None` = defer; see [`CombineRule`]).
    pub restitution_combine: Option<CombineRule>,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            density: 1.0,
            friction_static: 0.6,
            friction_dynamic: 0.6,
            restitution: 0.0,
            restitution_threshold: 1.0,
            rolling_resistance: 0.0,
            tangent_speed: 0.0,
            friction_combine: None,
            restitution_combine: None,
        }
    }
}

impl Material {
    /// A material with one friction coefficient used for both μs and μd (how a scene from
    /// a one-coefficient engine ports).
    pub fn with_friction(friction: f32) -> Material {
        Material {
            friction_static: friction,
            friction_dynamic: friction,
            ..Material::default()
        }
    }

    /// Sets both friction coefficients (builder style).
    pub fn friction(mut self, friction_static: f32, friction_dynamic: f32) -> Material {
        self.friction_static = friction_static;
        self.friction_dynamic = friction_dynamic;
        self
    }

    /// Sets the density [kg/m²] (builder style).
    pub fn density(mut self, density: f32) -> Material {
        self.density = density;
        self
    }

    /// Sets the restitution (builder style).
    pub fn restitution(mut self, restitution: f32) -> Material {
        self.restitution = restitution;
        self
    }

    /// Checks every field: finite, non-negative, μs ≥ μd, 0 ≤ e ≤ 1.
    pub fn validate(&self) -> Result<()> {
        check_non_negative("Material::density", self.density)?;
        check_non_negative("Material::friction_static", self.friction_static)?;
        check_non_negative("Material::friction_dynamic", self.friction_dynamic)?;
        if self.friction_static < self.friction_dynamic {
            return Err(Error::arg(
                "Material::friction_static",
                format!(
                    "static friction ({}) must be at least the dynamic friction ({})",
                    self.friction_static, self.friction_dynamic
                ),
            ));
        }
        check_non_negative("Material::restitution", self.restitution)?;
        if self.restitution > 1.0 {
            return Err(Error::arg(
                "Material::restitution",
                format!("must be in [0, 1] (got {})", self.restitution),
            ));
        }
        check_non_negative("Material::restitution_threshold", self.restitution_threshold)?;
        check_non_negative("Material::rolling_resistance", self.rolling_resistance)?;
        check_finite("Material::tangent_speed", self.tangent_speed)?;
        Ok(())
    }
}

/// The coefficients that act at one contact, mixed from the two materials.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MixedMaterial {
    /// Static friction μs.
    pub friction_static: f32,
    /// Dynamic friction μd (≤ μs).
    pub friction_dynamic: f32,
    /// Restitution e.
    pub restitution: f32,
    /// Restitution threshold [m/s].
    pub restitution_threshold: f32,
    /// Rolling resistance (dimensionless).
    pub rolling_resistance: f32,
    /// Relative surface speed [m/s] along the contact tangent.
    pub tangent_speed: f32,
}

impl MixedMaterial {
    /// All coefficients zero (the `Default`): a new contact's blank record.
    pub(crate) const BLANK: MixedMaterial = MixedMaterial {
        friction_static: 0.0,
        friction_dynamic: 0.0,
        restitution: 0.0,
        restitution_threshold: 0.0,
        rolling_resistance: 0.0,
        tangent_speed: 0.0,
    };
}

/// Mixes two materials by their combine rules. Both coefficients of friction use the same
/// rule; μs ≥ μd holds for the result because every rule is monotone in each argument.
///
/// Always inlined: called, it returned its result through memory, and the caller's wider
/// loads of its 4-byte stores could not be forwarded (`World::create_contact` waited on
/// them, see there).
#[inline(always)]
pub fn mix(a: &Material, b: &Material) -> MixedMaterial {
    let fr = CombineRule::resolve(a.friction_combine, b.friction_combine, CombineRule::GeometricMean);
    let rr = CombineRule::resolve(a.restitution_combine, b.restitution_combine, CombineRule::Max);
    let mu_s = fr.combine(a.friction_static, b.friction_static);
    let mu_d = fr.combine(a.friction_dynamic, b.friction_dynamic).min(mu_s);
    MixedMaterial {
        friction_static: mu_s,
        friction_dynamic: mu_d,
        restitution: rr.combine(a.restitution, b.restitution).clamp(0.0, 1.0),
        restitution_threshold: a.restitution_threshold.min(b.restitution_threshold),
        rolling_resistance: a.rolling_resistance.max(b.rolling_resistance),
        tangent_speed: a.tangent_speed + b.tangent_speed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precedence_and_defaults() {
        let a = Material::with_friction(0.4);
        let b = Material::with_friction(0.9);
        // default friction rule: geometric mean √(0.36) = 0.6
        assert!((mix(&a, &b).friction_static - 0.6).abs() < 1e-6);
        let a_min = Material {
            friction_combine: Some(CombineRule::Min),
            ..a
        };
        assert_eq!(mix(&a_min, &b).friction_static, 0.4);
        let b_max = Material {
            friction_combine: Some(CombineRule::Max),
            ..b
        };
        // Max outranks Min.
        assert_eq!(mix(&a_min, &b_max).friction_static, 0.9);
        assert_eq!(mix(&b_max, &a_min).friction_static, 0.9);
    }

    #[test]
    fn validation() {
        assert!(Material::default().validate().is_ok());
        assert!(Material::default().friction(0.3, 0.5).validate().is_err());
        assert!(Material::default().restitution(1.5).validate().is_err());
        assert!(Material::default().density(f32::NAN).validate().is_err());
        assert!(Material::default().density(-1.0).validate().is_err());
    }
}
