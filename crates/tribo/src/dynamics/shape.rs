//! Shapes attached to bodies: definition (user input) and simulation record.

use super::material::Material;
use crate::geometry::Shape;
use crate::math::Aabb;
use crate::world::BodyId;

/// Collision filtering (Box2D's scheme). Two shapes collide when
/// `(a.category & b.mask) != 0 && (b.category & a.mask) != 0`, unless they share a
/// non-zero `group`: then a positive group always collides and a negative one never does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Filter {
    /// The categories this shape belongs to (bits).
    pub category: u64,
    /// The categories this shape collides with (bits).
    pub mask: u64,
    /// Group index: overrides category/mask between shapes of the same non-zero group.
    pub group: i32,
}

impl Default for Filter {
    fn default() -> Self {
        Filter {
            category: 1,
            mask: u64::MAX,
            group: 0,
        }
    }
}

impl Filter {
    /// Whether shapes with these two filters collide.
    pub fn should_collide(&self, other: &Filter) -> bool {
        if self.group == other.group && self.group != 0 {
            return self.group > 0;
        }
        (self.category & other.mask) != 0 && (other.category & self.mask) != 0
    }
}

/// Everything needed to attach a shape to a body, besides its geometry.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShapeDef {
    /// Surface and bulk properties.
    pub material: Material,
    /// Collision filtering.
    pub filter: Filter,
    /// Free for the user.
    pub user_data: u64,
}

impl ShapeDef {
    /// A shape definition with the given material and default filter.
    pub fn with_material(material: Material) -> ShapeDef {
        ShapeDef {
            material,
            ..ShapeDef::default()
        }
    }
}

/// The simulation record of a shape (internal).
#[derive(Clone, Debug)]
pub(crate) struct ShapeRecord {
    pub body: BodyId,
    pub geometry: Shape,
    pub material: Material,
    pub filter: Filter,
    pub user_data: u64,
    /// Proxy in the broad-phase tree of its body type.
    pub proxy: u32,
    /// Which tree holds the proxy (0 static, 1 moving).
    pub tree: u8,
    /// Fat box stored in the tree [m].
    pub fat_aabb: Aabb,
    /// The shape's box at its body's last pose, grown by the speculative distance and
    /// swept along the next step's motion beyond `sweep_free` [m] (inside `fat_aabb`;
    /// `crate::world::shape_box`): the narrow phase skips
    /// the manifold of a pair whose boxes are apart.
    pub aabb: Aabb,
    /// Room [m] between `aabb` and `fat_aabb` when the fat box is renewed
    /// ([`crate::collision::broad_phase::aabb_margin`]).
    pub margin: f32,
    /// How far [m] the shape may move in one step before its box is swept along the motion
    /// ([`crate::collision::broad_phase::sweep_free`]).
    pub sweep_free: f32,
    /// Set when the fat box was replaced this step (the broad phase looks for new pairs).
    pub moved: bool,
}
