//! [`WideBox`]: an axis-aligned box in 16-byte SIMD lanes (`Vec3A`), for the loops that handle
//! many boxes or points: the query tree's slab and overlap tests (`spatial/tree.rs`), the
//! hierarchy build's SAH bins (`bvh/binned_sah.rs`) and the OBB fit's projections
//! (`bounding/obb.rs`). A union is one `minps`/`maxps` pair, where the
//! scalar [`Aabb`]'s NaN-aware `min` costs four instructions a coordinate. Callers keep NaN
//! out or mark it (SIMD `min` forgets it at the next finite value).

use super::Aabb;
use glam::Vec3A;

/// An axis-aligned box in SIMD lanes; `EMPTY` holds nothing.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WideBox {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl WideBox {
    pub const EMPTY: Self = Self {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    #[inline]
    pub fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    #[inline]
    pub fn including(&self, p: Vec3A) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    #[inline(always)]
    pub fn intersects(&self, other: &Self) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// The squared distance from `p` to the box (0 inside).
    #[inline(always)]
    pub fn distance_squared(&self, p: Vec3A) -> f32 {
        let outside = (self.min - p).max(p - self.max).max(Vec3A::ZERO);
        outside.length_squared()
    }

    /// Surface area (0 when empty or flat).
    #[inline]
    pub fn surface_area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

impl From<Aabb> for WideBox {
    fn from(b: Aabb) -> Self {
        Self {
            min: b.min.into(),
            max: b.max.into(),
        }
    }
}

impl From<WideBox> for Aabb {
    fn from(b: WideBox) -> Self {
        Aabb::new(b.min.into(), b.max.into())
    }
}
