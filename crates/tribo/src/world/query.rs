//! World queries: ray casts and bounding-box overlaps against every shape.

use super::{BodyId, ShapeId, World};
use crate::error::{check_vec, Error, Result};
use crate::geometry::RayCastInput;
use crate::math::{Aabb, Vec2};

/// Which shapes a query sees: those whose category intersects `mask`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QueryFilter {
    /// Category bits of the query (tested against shapes' masks).
    pub category: u64,
    /// Categories the query sees.
    pub mask: u64,
}

impl Default for QueryFilter {
    fn default() -> Self {
        QueryFilter {
            category: 1,
            mask: u64::MAX,
        }
    }
}

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayResult {
    /// Shape hit.
    pub shape: ShapeId,
    /// Its body.
    pub body: BodyId,
    /// Hit point [m].
    pub point: Vec2,
    /// Surface normal at the hit.
    pub normal: Vec2,
    /// Fraction of the translation at the hit, in [0, 1].
    pub fraction: f32,
}

impl World {
    /// Casts the ray `origin + t·translation`, t ∈ [0, 1], and returns the closest hit.
    /// Rays that start inside a shape do not hit that shape.
    pub fn cast_ray_closest(&self, origin: Vec2, translation: Vec2, filter: QueryFilter) -> Result<Option<RayResult>> {
        check_vec("origin", origin)?;
        check_vec("translation", translation)?;
        let mut best: Option<RayResult> = None;
        for tree in &self.broad_phase.trees {
            let max = best.map_or(1.0, |b| b.fraction);
            tree.ray_cast(origin, translation, max, filter.mask, |input, _, data| {
                let si = data as u32;
                let Some(s) = self.shapes.at(si) else { return -1.0 };
                if (s.filter.mask & filter.category) == 0 {
                    return -1.0;
                }
                let Some(b) = self.bodies.at(s.body.index) else {
                    return -1.0;
                };
                let xf = b.xf;
                let local = RayCastInput {
                    origin: xf.inv_apply(input.origin),
                    translation: xf.q.inv_rotate(input.translation),
                    max_fraction: input.max_fraction,
                };
                match s.geometry.ray_cast(&local) {
                    Some(hit) => {
                        let better = best.map_or(true, |b| hit.fraction < b.fraction);
                        if better {
                            best = Some(RayResult {
                                shape: ShapeId {
                                    index: si,
                                    generation: self.shapes.generation(si),
                                },
                                body: s.body,
                                point: xf.apply(hit.point),
                                normal: xf.q.rotate(hit.normal),
                                fraction: hit.fraction,
                            });
                        }
                        hit.fraction
                    }
                    None => input.max_fraction,
                }
            });
        }
        Ok(best)
    }

    /// Shapes whose fat bounding box overlaps `aabb`, sorted by id (fat boxes are a little
    /// larger than the shapes; test the shapes' own boxes with [`World::shape_aabb`]).
    pub fn overlap_aabb(&self, aabb: Aabb, filter: QueryFilter) -> Result<Vec<ShapeId>> {
        if !aabb.is_valid() {
            return Err(Error::arg("aabb", "must be finite with min ≤ max"));
        }
        let mut out = Vec::new();
        for tree in &self.broad_phase.trees {
            tree.query(aabb, filter.mask, |_, data| {
                let si = data as u32;
                if let Some(s) = self.shapes.at(si) {
                    if (s.filter.mask & filter.category) != 0 {
                        out.push(ShapeId {
                            index: si,
                            generation: self.shapes.generation(si),
                        });
                    }
                }
                true
            });
        }
        out.sort_unstable();
        Ok(out)
    }
}
