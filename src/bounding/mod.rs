//! Bounding volumes: cheap primitives that contain an object, so that disjoint BVs prove
//! disjoint objects (the slides' "Bounding Volumes").
//!
//! Four kinds share one trait, [`Bv`], so that the hierarchy ([`crate::bvh`]) is written once:
//! [`BoundingSphere`], [`Aabb`] (axis-aligned in the object's own frame), [`Obb`] (oriented by the
//! covariance of the surface, Gottschalk, Lin and Manocha 1996) and [`Kdop`] (the slabs of k fixed
//! directions, Klosowski et al. 1998). They trade tightness against the cost of a test, the
//! `Cn`/`Nn` balance of the slides' cost model `Tc = Nv*Cv + Nn*Cn + Ns*Cs`.
//!
//! Every overlap test runs in A's frame with B placed by a [`RelativePose`] (or a kind-specific
//! precomputation of it, [`Bv::Relative`]) built once per query. Tests are conservative: they may
//! say "overlap" for disjoint contents, never "disjoint" for touching contents, including under
//! rounding (fits are padded by a few ulps of their coordinates' magnitude, and comparisons get a
//! slack proportional to the translation).

mod aabb;
mod aabb_bv;
mod box_sat;
mod covariance;
mod kdop;
mod obb;
mod relative_pose;
mod sphere;
mod surface;
pub(crate) mod symmetric_eigen;
mod wide_box;

pub use aabb::Aabb;
pub use kdop::{Kdop, Kdop14, Kdop18, Kdop26, KdopRelative};
pub use obb::Obb;
pub use relative_pose::{ABS_ROTATION_EPSILON, RELATIVE_SLACK, RelativePose};
pub use sphere::BoundingSphere;
pub use surface::{SurfaceMoments, TriangleSet};
pub(crate) use wide_box::WideBox;

use crate::geometry::Isometry;
use glam::Vec3;
use std::fmt::Debug;

/// A bounding-volume kind usable in a hierarchy.
///
/// Implementors promise containment (a BV fit to points or triangles holds them; a merge holds
/// both operands) and conservativeness (`overlaps` is true whenever the contents of the two BVs
/// could touch).
pub trait Bv: Copy + Debug + PartialEq + Send + Sync + 'static {
    /// What the overlap test needs of the relative pose, computed once per query by
    /// [`Bv::relative`] rather than once per node pair.
    type Relative: Copy + Debug;

    /// Prepares the pose of B's frame in A's frame (`pose_a.inv_mul(&pose_b)`).
    fn relative(pose_b_in_a: &Isometry) -> Self::Relative;

    /// A BV holding every point. An empty set gives a zero-size BV at the origin (a defined,
    /// finite value; the hierarchy never asks for it).
    fn fit_points<I>(points: I) -> Self
    where
        I: Iterator<Item = Vec3> + Clone;

    /// A BV holding the triangles of `set`.
    ///
    /// The default fits the corners; kinds that use the surface itself (the OBB's area-weighted
    /// covariance, the AABB's box of corners) take it from the set's summed moments.
    fn fit_triangles(set: &TriangleSet) -> Self {
        Self::fit_points(set.points())
    }

    /// A BV holding both, for refitting a hierarchy bottom-up.
    #[must_use]
    fn merged(&self, other: &Self) -> Self;

    /// A BV holding every point within `margin` (≥ 0) of this one: pair queries that look for
    /// triangles *near* each other (speculative contacts) test one side's BVs grown by it.
    #[must_use]
    fn grown(&self, margin: f32) -> Self;

    /// Conservative overlap test of `self` (in A's frame) and `other` (in B's frame).
    fn overlaps(&self, other: &Self, rel: &Self::Relative) -> bool;

    /// Like [`Bv::overlaps`] (`Some` exactly when it returns true), but on overlap also estimates
    /// how much: a number in `[0, 1]`,
    /// scale-free, larger for deeper overlap (the smallest, over the axes the test examines, of
    /// the projections' overlap divided by the sum of their lengths; 1 for concentric volumes).
    /// The priority traversal visits pairs with the larger estimate first.
    fn overlap_estimate(&self, other: &Self, rel: &Self::Relative) -> Option<f32>;

    /// A length measuring the BV, for the slides' rule "split the node with the larger BV".
    /// Comparable only between BVs of the same kind.
    fn size(&self) -> f32;

    /// The axis-aligned box of the BV in its own frame (for the SAH and for callers' predicates).
    fn local_aabb(&self) -> Aabb;

    /// True when `p` is in the BV, allowing `tolerance` of distance.
    fn contains_point(&self, p: Vec3, tolerance: f32) -> bool;
}

/// Relative padding of fitted BVs (16 ulps of the magnitude of their coordinates, about 2e-6):
/// enough that re-deriving a point's position inside the BV (a rotation and a subtraction) and
/// the transformed comparisons of [`Bv::overlaps`] never lose a point or a touching pair to
/// rounding, and far too small to matter for tightness.
pub const FIT_PAD_RELATIVE: f32 = 16.0 * f32::EPSILON;

/// The padding of a fitted BV whose coordinates reach `magnitude`.
#[inline]
pub(crate) fn rounding_pad(magnitude: f32) -> f32 {
    FIT_PAD_RELATIVE * magnitude
}

/// The overlap ratio of two projected intervals that the caller found overlapping, given their
/// radii and the distance between their centres (see [`Bv::overlap_estimate`]). Clamped to
/// `[0, 1]`, so rounding at the boundary cannot yield a negative rank.
#[inline]
pub(crate) fn overlap_ratio(radius_a: f32, radius_b: f32, distance: f32) -> f32 {
    let reach = radius_a + radius_b;
    if reach > 0.0 {
        ((reach - distance.abs()) / reach).clamp(0.0, 1.0)
    } else {
        1.0
    }
}
