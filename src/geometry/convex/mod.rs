//! Convex shapes through their support functions: GJK for the distance between two convex
//! cores (`gjk.rs`), EPA for their penetration when they overlap (`epa.rs`), and the supporting
//! features the contact manifold is clipped from (`support.rs`). Cylinders, ellipsoids and hulls
//! collide only this way; spheres, capsules and boxes take it when paired with one of them
//! (their own pairs keep the closed forms, which are faster and exact).
//!
//! [`signed_distance`] is the public face: the signed distance between two convex
//! shapes with the closest (or deepest) points, as parry's `query::distance` and
//! `query::contact` report.

mod epa;
mod gjk;
pub(crate) mod support;

use crate::geometry::mesh_io::MeshLoadError;
use crate::geometry::{HullError, Isometry, Shape};
pub(crate) use epa::epa;
pub(crate) use gjk::{Gjk, gjk_within};
use glam::Vec3;
use std::fmt;
use support::ConvexPart;

/// The signed distance between two convex shapes and where it is attained.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SignedDistance {
    /// Distance between the surfaces; negative when they overlap (minus the penetration depth).
    pub distance: f32,
    /// Unit direction from A to B: moving B along it by `-distance` makes them touch.
    pub normal: Vec3,
    /// A's surface point nearest B (deepest in B when overlapping).
    pub on_a: Vec3,
    /// B's surface point nearest A (deepest in A when overlapping).
    pub on_b: Vec3,
}

/// The signed distance between convex shapes `a` at `pose_a` and `b` at `pose_b` by GJK (apart)
/// or EPA (overlapping), or `None` when either is not convex (a half-space, a mesh) or the pair
/// has no defined direction (two flat shapes in one plane).
pub fn signed_distance(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
) -> Option<SignedDistance> {
    // In A's frame: the numbers stay near the pair, not near the world origin.
    let pa = ConvexPart::of_shape(a, Isometry::IDENTITY)?;
    let pb = ConvexPart::of_shape(b, pose_a.inv_mul(pose_b))?;
    let d = core_distance(&pa, &pb)?;
    Some(SignedDistance {
        distance: d.distance,
        normal: pose_a.transform_vector(d.normal),
        on_a: pose_a.transform_point(d.on_a),
        on_b: pose_a.transform_point(d.on_b),
    })
}

/// [`SignedDistance`] of two parts in one frame, their roundings included.
pub(crate) fn core_distance(a: &ConvexPart, b: &ConvexPart) -> Option<SignedDistance> {
    core_distance_within(a, b, f32::INFINITY)
}

/// [`core_distance`] for a caller that needs only pairs within `limit` of each other: `None`
/// as soon as GJK shows the surfaces farther apart (a pair within it gets its exact answer).
pub(crate) fn core_distance_within(
    a: &ConvexPart,
    b: &ConvexPart,
    limit: f32,
) -> Option<SignedDistance> {
    // The cores' limit, with a hair of slack: the bound is exact, its arithmetic is not.
    let slack = 1e-6 * f64::from(a.size() + b.size());
    let core_limit = f64::from(limit) + f64::from(a.rounding + b.rounding) + slack;
    let (core, on_a, on_b, normal) = match gjk_within(a, b, core_limit) {
        Gjk::Beyond => return None,
        Gjk::Separated { on_a, on_b } => {
            let gap = on_b - on_a;
            let len = gap.length();
            match gap.try_normalize() {
                Some(n) => (len, on_a, on_b, n),
                // Exactly touching cores without a GJK overlap: no direction; ask EPA.
                None => return penetrating(a, b, &gjk_simplex_of(a, b)),
            }
        }
        Gjk::Overlapping(s) => return penetrating(a, b, &s),
    };
    Some(rounded(a, b, core, on_a, on_b, normal))
}

fn gjk_simplex_of(a: &ConvexPart, b: &ConvexPart) -> gjk::Simplex {
    let mut s = gjk::Simplex::default();
    s.points[0] = gjk::support(a, b, glam::DVec3::Z);
    s.weights[0] = 1.0;
    s.len = 1;
    s
}

fn penetrating(a: &ConvexPart, b: &ConvexPart, s: &gjk::Simplex) -> Option<SignedDistance> {
    let p = epa(a, b, s)?;
    Some(rounded(a, b, -p.depth, p.on_a, p.on_b, p.normal))
}

/// The surfaces' distance and points from the cores': each rounding moves its surface out
/// along the normal.
fn rounded(
    a: &ConvexPart,
    b: &ConvexPart,
    core: f32,
    on_a: Vec3,
    on_b: Vec3,
    normal: Vec3,
) -> SignedDistance {
    SignedDistance {
        distance: core - a.rounding - b.rounding,
        normal,
        on_a: on_a + normal * a.rounding,
        on_b: on_b - normal * b.rounding,
    }
}

/// Why a convex hull could not be made from a mesh file.
#[derive(Debug)]
pub enum HullFileError {
    /// The file could not be read or parsed (see [`MeshLoadError`]).
    Load(MeshLoadError),
    /// Its vertices make no hull (see [`HullError`]).
    Hull(HullError),
}

impl fmt::Display for HullFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Load(e) => write!(f, "cannot load the hull's mesh: {e}"),
            Self::Hull(e) => write!(f, "the mesh's vertices make no hull: {e}"),
        }
    }
}

impl std::error::Error for HullFileError {}

impl From<MeshLoadError> for HullFileError {
    fn from(e: MeshLoadError) -> Self {
        Self::Load(e)
    }
}

impl From<HullError> for HullFileError {
    fn from(e: HullError) -> Self {
        Self::Hull(e)
    }
}

/// The convex hull of the vertices of an OBJ, STL or PLY file (by extension, as
/// [`load`](crate::geometry::mesh_io::load)).
#[cfg(feature = "mesh-io")]
pub fn hull_from_file(
    path: impl AsRef<std::path::Path>,
) -> Result<crate::geometry::ConvexHull, HullFileError> {
    let mesh = crate::geometry::mesh_io::load(path)?;
    Ok(crate::geometry::ConvexHull::from_points(mesh.vertices())?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    /// Stopping at a limit drops only pairs beyond it: a pair within the limit gets the full
    /// query's answer bit for bit, over every kind of convex part (rounded ones included) at
    /// gaps from 30 cm deep to 1 m apart.
    #[test]
    fn gjk_stopping_at_a_limit_keeps_every_pair_within_it_bit_for_bit_on_20_000_random_pairs() {
        let mut rng = TestRng::new(77);
        let hull_points: Vec<Vec3> = (0..16).map(|_| rng.vec3(-0.5, 0.5)).collect();
        let shapes = [
            Shape::sphere(0.4),
            Shape::cuboid(Vec3::new(0.5, 0.3, 0.2)),
            Shape::capsule(0.4, 0.2),
            Shape::cylinder(0.4, 0.3),
            Shape::cone(0.4, 0.3),
            Shape::ellipsoid(Vec3::new(0.5, 0.3, 0.2)),
            Shape::convex_hull(&hull_points).unwrap(),
        ];
        let (mut within, mut beyond) = (0, 0);
        for k in 0..20_000 {
            let (sa, sb) = (&shapes[k % 7], &shapes[(k / 7) % 7]);
            let a = ConvexPart::of_shape(sa, Isometry::new(Vec3::ZERO, rng.rotation())).unwrap();
            let at = rng.vec3(-1.0, 1.0).normalize_or_zero() * rng.range(0.0, 1.8);
            let b = ConvexPart::of_shape(sb, Isometry::new(at, rng.rotation())).unwrap();
            let limit = rng.range(0.0, 0.5);
            let (Some(full), stopped) =
                (core_distance(&a, &b), core_distance_within(&a, &b, limit))
            else {
                continue;
            };
            if full.distance <= limit {
                within += 1;
                assert_eq!(stopped, Some(full), "{k}: {sa:?} {sb:?}");
            } else {
                beyond += 1;
                assert!(stopped.is_none_or(|d| d.distance > limit), "{k}");
            }
        }
        assert!(within > 5_000 && beyond > 5_000, "{within} / {beyond}");
    }

    /// Bad limits lose nothing: a NaN or infinite one gives the full answer, a negative one
    /// drops only pairs farther apart than its magnitude (which every caller drops anyway).
    #[test]
    fn a_nan_infinite_or_negative_limit_gives_the_full_answer_or_drops_only_far_pairs() {
        let cube = Shape::cuboid(Vec3::splat(0.5));
        let a = ConvexPart::of_shape(&cube, Isometry::IDENTITY).unwrap();
        for gap in [-0.2, 0.1, 0.7] {
            let at = Isometry::from_translation(Vec3::new(0.0, 0.0, 1.0 + gap));
            let b = ConvexPart::of_shape(&cube, at).unwrap();
            let full = core_distance(&a, &b).unwrap();
            assert!((full.distance - gap).abs() < 1e-5, "{gap}: {full:?}");
            for limit in [f32::NAN, f32::INFINITY] {
                assert_eq!(core_distance_within(&a, &b, limit), Some(full), "{limit}");
            }
            let negative = core_distance_within(&a, &b, -0.5);
            if gap <= 0.5 {
                assert_eq!(negative, Some(full), "{gap}");
            } else {
                assert!(negative.is_none_or(|d| d.distance > -0.5), "{gap}");
            }
        }
    }
}
