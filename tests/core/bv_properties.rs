//! Properties every bounding-volume kind must have, checked on random and degenerate point sets
//! (duplicates, collinear, coplanar, tiny spread far from the origin):
//!
//! - containment: a BV fit to points or triangles holds them, a merge holds both operands'
//!   points — with zero tolerance (fits carry their own rounding pad);
//! - conservativeness: two point sets that share a point, placed by any rigid motion, have
//!   overlapping BVs (the shared point makes their contents intersect);
//! - the test is not trivially true: BVs whose bounding balls are far apart are reported apart;
//! - `overlap_estimate` is `Some` exactly when `overlaps` is true, and lies in `[0, 1]`.

use crate::common;

use common::rng::Rng;
use glam::Vec3;
use proptest::prelude::*;
use urto::bounding::{Aabb, BoundingSphere, Bv, Kdop14, Kdop18, Kdop26, Obb, TriangleSet};
use urto::geometry::Isometry;

/// A point set of one of several shapes, from a seed.
fn point_set(kind: u8, n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = Rng::new(seed);
    let offset = rng.in_ball(1.0) * [0.0, 1.0, 100.0, 5000.0][rng.below(4)];
    let p0 = rng.in_ball(3.0) + offset;
    let (u, v) = (rng.direction(), rng.direction());
    (0..n)
        .map(|_| match kind % 5 {
            0 => p0 + rng.in_ball(4.0),
            1 => p0,
            2 => p0 + u * rng.range(-5.0, 5.0),
            3 => p0 + u * rng.range(-5.0, 5.0) + v * rng.range(-2.0, 2.0),
            _ => p0 + rng.in_ball(1e-4),
        })
        .collect()
}

fn fit<B: Bv>(points: &[Vec3]) -> B {
    B::fit_points(points.iter().copied())
}

fn triangles_of(points: &[Vec3]) -> Vec<[u32; 3]> {
    let n = points.len() as u32;
    (0..n).map(|i| [i, (i + 1) % n, (i + 2) % n]).collect()
}

fn check_containment<B: Bv>(a: &[Vec3], b: &[Vec3]) -> Result<(), TestCaseError> {
    let bv: B = fit(a);
    for p in a {
        prop_assert!(bv.contains_point(*p, 0.0), "{bv:?} misses {p}");
    }
    let corners: Vec<[Vec3; 3]> = triangles_of(a)
        .iter()
        .map(|t| t.map(|i| a[i as usize]))
        .collect();
    let from_tris = B::fit_triangles(&TriangleSet::new(&corners));
    for p in a {
        prop_assert!(
            from_tris.contains_point(*p, 0.0),
            "{from_tris:?} misses {p}"
        );
    }
    let merged = bv.merged(&fit::<B>(b));
    for p in a.iter().chain(b) {
        prop_assert!(merged.contains_point(*p, 0.0), "{merged:?} misses {p}");
    }
    prop_assert!(bv.size().is_finite() && bv.size() >= 0.0);
    Ok(())
}

fn check_overlap<B: Bv>(
    a: &[Vec3],
    b: &[Vec3],
    pose: &Isometry,
    shared_a: Vec3,
) -> Result<(), TestCaseError> {
    // The shared point, in each set's own frame.
    let mut a = a.to_vec();
    let mut b = b.to_vec();
    a.push(shared_a);
    b.push(pose.inverse_transform_point(shared_a));
    let (ba, bb): (B, B) = (fit(&a), fit(&b));
    let rel = B::relative(pose);
    prop_assert!(ba.overlaps(&bb, &rel), "{ba:?} and {bb:?} share {shared_a}");
    let e = ba.overlap_estimate(&bb, &rel);
    prop_assert!(
        e.is_some_and(|e| (0.0..=1.0).contains(&e)),
        "estimate {e:?}"
    );
    Ok(())
}

/// Moves B far enough that the bounding balls of the two BVs' boxes are apart (by a factor
/// √3, which makes one of A's face slabs separate them): every kind must then say "apart".
fn check_far_apart<B: Bv>(
    a: &[Vec3],
    b: &[Vec3],
    pose: &Isometry,
    dir: Vec3,
) -> Result<(), TestCaseError> {
    let (ba, bb): (B, B) = (fit(a), fit(b));
    let (aa, ab) = (ba.local_aabb(), bb.local_aabb());
    // Plus a margin for rounding, relative to the coordinates' magnitude.
    let magnitude = pose.translation.length() + aa.center().length() + ab.center().length();
    let reach = 3f32.sqrt() * (aa.half_extents().length() + ab.half_extents().length()) * 1.01
        + 1e-5 * magnitude
        + 1e-3;
    // Place B's box centre at distance `reach` from A's along `dir`.
    let centre_b = pose.transform_point(ab.center());
    let shift = aa.center() + dir * reach - centre_b;
    let pose = Isometry::new(pose.translation + shift, pose.rotation);
    let rel = B::relative(&pose);
    prop_assert!(!ba.overlaps(&bb, &rel), "{ba:?} {bb:?} at {pose:?}");
    prop_assert!(ba.overlap_estimate(&bb, &rel).is_none());
    Ok(())
}

/// `overlaps` and `overlap_estimate` agree on arbitrary placements.
fn check_agreement<B: Bv>(a: &[Vec3], b: &[Vec3], pose: &Isometry) -> Result<(), TestCaseError> {
    let (ba, bb): (B, B) = (fit(a), fit(b));
    let rel = B::relative(pose);
    let e = ba.overlap_estimate(&bb, &rel);
    prop_assert_eq!(ba.overlaps(&bb, &rel), e.is_some());
    prop_assert!(e.is_none_or(|e| (0.0..=1.0).contains(&e)));
    Ok(())
}

fn pose_from(seed: u64, reach: f32) -> Isometry {
    Rng::new(seed).placement(reach)
}

macro_rules! bv_properties {
    ($module:ident, $bv:ty) => {
        mod $module {
            use super::*;

            proptest! {
                #![proptest_config(ProptestConfig::with_cases(256))]

                #[test]
                fn contains_what_it_was_fit_to(ka in 0u8..5, kb in 0u8..5, na in 1usize..40,
                                               nb in 1usize..40, seed in any::<u64>()) {
                    let a = point_set(ka, na, seed);
                    let b = point_set(kb, nb, seed ^ 0xABCD);
                    check_containment::<$bv>(&a, &b)?;
                }

                #[test]
                fn sets_sharing_a_point_overlap(ka in 0u8..5, kb in 0u8..5, na in 1usize..30,
                                                nb in 1usize..30, seed in any::<u64>()) {
                    let a = point_set(ka, na, seed);
                    let b = point_set(kb, nb, seed.rotate_left(17));
                    let pose = pose_from(seed ^ 0x1234, 50.0);
                    let shared = a[0] + Rng::new(seed ^ 0x77).in_ball(6.0);
                    check_overlap::<$bv>(&a, &b, &pose, shared)?;
                }

                #[test]
                fn far_apart_sets_do_not_overlap(ka in 0u8..5, kb in 0u8..5, na in 1usize..30,
                                                 nb in 1usize..30, seed in any::<u64>()) {
                    let a = point_set(ka, na, seed);
                    let b = point_set(kb, nb, seed.rotate_left(23));
                    let pose = pose_from(seed ^ 0x4321, 10.0);
                    let dir = Rng::new(seed ^ 0x99).direction();
                    check_far_apart::<$bv>(&a, &b, &pose, dir)?;
                }

                #[test]
                fn estimate_agrees_with_test(ka in 0u8..5, kb in 0u8..5, na in 1usize..30,
                                             nb in 1usize..30, seed in any::<u64>()) {
                    let a = point_set(ka, na, seed);
                    let b = point_set(kb, nb, seed.rotate_left(29));
                    let pose = pose_from(seed ^ 0x5555, 15.0);
                    check_agreement::<$bv>(&a, &b, &pose)?;
                }
            }
        }
    };
}

bv_properties!(sphere, BoundingSphere);
bv_properties!(aabb, Aabb);
bv_properties!(obb, Obb);
bv_properties!(kdop14, Kdop14);
bv_properties!(kdop18, Kdop18);
bv_properties!(kdop26, Kdop26);
