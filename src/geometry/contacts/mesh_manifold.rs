//! Merging the contacts of many triangles into one manifold.
//!
//! A mesh touches another shape through many triangles at once, each with its own normal (a
//! sphere in a crease, a box across a ridge of a terrain). urto's response works with one normal
//! per pair, so the triangle contacts (the *contributions*) are merged:
//! - **normal**: the depth-weighted average of the contributions' normals, so the deepest
//!   dominate and a body in a crease is pushed along the bisector. When every depth is zero
//!   (touching) the plain average; when the average cancels (normals from opposite sides, as for
//!   a thin plate squeezed from both faces) the normal of the deepest contribution.
//! - **one side**: in a mesh–mesh contact each triangle pair takes its normal from one of its
//!   two triangles (`trimesh_trimesh.rs`). The contributions of the side that carries most of
//!   the depth are kept, the others dropped: a body resting on a floor is pushed along the
//!   floor's normals, not along the normals of its own facets that happen to be the shorter way
//!   out for a few pairs (the floor triangles entering a leg of the body through its side).
//! - **outliers**: contributions whose normal deviates from the first average by more than
//!   [`MAX_DEVIATION_DEGREES`] are dropped and the average taken again. They come from triangles
//!   that cross a *side* of the other body: a floor triangle poking a little way into a box
//!   through its side face has a sideways least-penetration direction, although the floor as a
//!   whole pushes the box up. Left in, they tilt the normal, and a body resting on a finely
//!   tessellated floor would be pushed sideways on every step (the response has no friction to
//!   stop it).
//! - **points**: the points of the kept contributions are pooled, and at most
//!   [`MAX_MANIFOLD_POINTS`](crate::geometry::MAX_MANIFOLD_POINTS) kept: the deepest, then the
//!   ones spanning the widest area (`manifold_reduction.rs`). Each keeps its own depth, so the
//!   manifold's depth is the deepest kept contribution's.
//!
//! This is an approximation: a depth measured along one triangle's normal is kept as is under the
//! averaged normal. It is exact for a flat contact region and errs on the deep side in a crease
//! (the solver then corrects a little more than needed rather than less).

use super::manifold_reduction::spread_points;
use crate::geometry::{ContactManifold, ContactPoint, Isometry};
use glam::Vec3;

/// A weighted sum cancelling below this fraction of the summed weights counts as cancelled.
const CANCELLED_FRACTION: f32 = 1e-3;

/// Contributions further than this from the first average normal are dropped (see the module
/// notes). 60° keeps both faces of a right-angled corner (45° from their bisector) and drops
/// side faces under a body lying on a floor (90°).
pub(crate) const MAX_DEVIATION_DEGREES: f32 = 60.0;

/// One triangle's (or triangle pair's) contact: its unit normal, its depth, which shape's
/// triangle gave the normal, and its run of the pooled points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Contribution {
    pub normal: Vec3,
    pub depth: f32,
    /// Which side's triangle the normal belongs to (0: A, 1: B; mesh–primitive tests use 0).
    pub side: u8,
    /// First index of its points in the pool.
    pub first: u32,
    /// Number of its points.
    pub count: u32,
    /// Still apart (a speculative gap: every point of it has a negative depth).
    pub apart: bool,
}

/// The average normal of the module notes over `contributions`, or `None` when there is none.
fn average_normal<'a>(
    contributions: impl Iterator<Item = &'a Contribution> + Clone,
) -> Option<Vec3> {
    let (mut weighted, mut weight, mut plain, mut count) = (Vec3::ZERO, 0.0f32, Vec3::ZERO, 0u32);
    let mut deepest: Option<(f32, Vec3)> = None;
    for c in contributions {
        weighted += c.normal * c.depth;
        weight += c.depth;
        plain += c.normal;
        count += 1;
        if deepest.is_none_or(|(d, _)| c.depth > d) {
            deepest = Some((c.depth, c.normal));
        }
    }
    let (_, deepest) = deepest?;
    let (sum, total) = if weight > 0.0 {
        (weighted, weight)
    } else {
        (plain, count as f32)
    };
    if sum.length() > CANCELLED_FRACTION * total {
        sum.try_normalize().or(Some(deepest))
    } else {
        Some(deepest)
    }
}

/// The merged manifold of the module notes: `contributions` index into `points` (all in one local
/// frame); `kept` is a buffer for the points of the kept contributions. The result is carried to
/// the world by `pose`. `None` without contributions.
pub(crate) fn merge_contributions(
    contributions: &[Contribution],
    points: &[ContactPoint],
    kept: &mut Vec<ContactPoint>,
    pose: &Isometry,
) -> Option<ContactManifold> {
    // Where the shapes touch, the gaps still open around the contact do not steer the normal (a
    // box on a box sees its side faces' gaps to the lower box's sides, askew); their points are
    // kept when they agree with it. Only when everything is apart do the gaps decide.
    let touching = contributions.iter().any(|c| !c.apart);
    let steers = |c: &Contribution| !(touching && c.apart);
    let side = heavier_side(contributions.iter().filter(|c| steers(c)))?;
    let on_side = |c: &&Contribution| steers(c) && c.side == side;
    let first = average_normal(contributions.iter().filter(on_side))?;
    let min_cos = MAX_DEVIATION_DEGREES.to_radians().cos();
    let inlier = |c: &&Contribution| on_side(c) && c.normal.dot(first) >= min_cos;
    // The first average lies within the cone of the deepest contributions, so some usually
    // pass; if none does (normals spread evenly around), keep the whole side.
    let (normal, keep_side) = match average_normal(contributions.iter().filter(inlier)) {
        Some(n) => (n, false),
        None => (first, true),
    };
    kept.clear();
    for c in contributions {
        let agreeing_gap = !steers(c) && c.normal.dot(normal) >= min_cos;
        if (keep_side && on_side(&c)) || inlier(&c) || agreeing_gap {
            let run = c.first as usize..(c.first + c.count) as usize;
            kept.extend_from_slice(&points[run]);
        }
    }
    one_per_own_feature(kept);
    reduce_to_manifold(normal, kept, pose)
}

/// One point per feature of the shape that meets the mesh (`FeatureId::of_other_alone`): a
/// box's corner or a cylinder's end over a seam is reported by both triangles, and the one
/// whose own test ends at the seam may read it shallower (a lying cylinder's end read 0 against
/// 21 µm, and the reduction kept that reading); the deepest stands, where the first was.
fn one_per_own_feature(points: &mut Vec<ContactPoint>) {
    let mut i = 0;
    while i < points.len() {
        let p = points[i];
        let earlier = p
            .feature
            .is_other_alone()
            .then(|| points[..i].iter().position(|q| q.feature == p.feature));
        if let Some(Some(j)) = earlier {
            if p.depth > points[j].depth {
                points[j] = p;
            }
            points.remove(i);
        } else {
            i += 1;
        }
    }
}

/// The side carrying the larger summed depth (the larger count when every depth is zero); ties
/// go to the lower side. `None` without contributions.
fn heavier_side<'a>(contributions: impl Iterator<Item = &'a Contribution> + Clone) -> Option<u8> {
    let first = contributions.clone().next()?.side;
    if contributions.clone().all(|c| c.side == first) {
        return Some(first);
    }
    let mut depth = [0.0f32; 2];
    let mut count = [0u32; 2];
    for c in contributions {
        let s = usize::from(c.side.min(1));
        depth[s] += c.depth;
        count[s] += 1;
    }
    let heavier = if depth[0] + depth[1] > 0.0 {
        depth[1] > depth[0]
    } else {
        count[1] > count[0]
    };
    Some(u8::from(heavier))
}

/// The manifold of the merged `normal` and the pooled `points` (both in a local frame), reduced
/// to the deepest and widest few and carried to the world by `pose`. `None` without points.
pub(crate) fn reduce_to_manifold(
    normal: Vec3,
    points: &[ContactPoint],
    pose: &Isometry,
) -> Option<ContactManifold> {
    let (chosen, count) = spread_points(points, normal);
    if count == 0 {
        return None;
    }
    let mut manifold = ContactManifold::new(pose.transform_vector(normal));
    for &k in &chosen[..count] {
        let p = points[k];
        manifold.push(ContactPoint {
            point: pose.transform_point(p.point),
            ..p
        });
    }
    Some(manifold)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn single(normal: Vec3, depth: f32, index: u32) -> Contribution {
        Contribution {
            normal,
            depth,
            side: 0,
            first: index,
            count: 1,
            apart: false,
        }
    }

    fn point(x: f32, depth: f32) -> ContactPoint {
        ContactPoint::new(Vec3::new(x, 0.0, 0.0), depth)
    }

    #[test]
    fn deeper_normals_weigh_more_and_cancellation_falls_back_on_the_deepest() {
        assert!(average_normal([].iter()).is_none());
        let c = [single(Vec3::Z, 0.3, 0), single(Vec3::X, 0.1, 1)];
        let n = average_normal(c.iter()).unwrap();
        assert!((n - Vec3::new(0.1, 0.0, 0.3).normalize()).length() < 1e-6);
        let touching = [single(Vec3::Z, 0.0, 0), single(Vec3::Y, 0.0, 1)];
        let n = average_normal(touching.iter()).unwrap();
        assert!((n - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);
        let squeezed = [
            single(Vec3::Z, 0.2, 0),
            single(-Vec3::Z, 0.2, 1),
            single(-Vec3::Z, 0.1, 2),
            single(Vec3::Z, 0.1, 3),
        ];
        assert_eq!(
            average_normal(squeezed.iter()),
            Some(Vec3::Z),
            "first of the deepest"
        );
    }

    #[test]
    fn sideways_outliers_are_dropped_with_their_points() {
        // A body on a floor: most contributions point up, two come from its sides.
        let c = [
            single(Vec3::Z, 0.05, 0),
            single(Vec3::Z, 0.05, 1),
            single(Vec3::X, 0.04, 2),
            single(Vec3::Z, 0.05, 3),
            single(-Vec3::Y, 0.03, 4),
        ];
        let points: Vec<_> = (0..5).map(|i| point(i as f32, c[i].depth)).collect();
        let mut kept = Vec::new();
        let m = merge_contributions(&c, &points, &mut kept, &Isometry::IDENTITY).unwrap();
        assert_eq!(m.normal, Vec3::Z);
        assert_eq!(kept.len(), 3);
        assert!(
            m.points()
                .iter()
                .all(|p| p.point.x != 2.0 && p.point.x != 4.0)
        );
        // A right-angled corner keeps both faces: the bisector.
        let corner = [single(Vec3::Z, 0.05, 0), single(Vec3::X, 0.05, 1)];
        let m = merge_contributions(&corner, &points[..2], &mut kept, &Isometry::IDENTITY).unwrap();
        assert!((m.normal - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-6);
        assert!(merge_contributions(&[], &points, &mut kept, &Isometry::IDENTITY).is_none());
    }

    #[test]
    fn the_side_carrying_most_depth_wins() {
        let mut c = [
            single(Vec3::Z, 0.05, 0),
            single(Vec3::Z, 0.04, 1),
            single(Vec3::new(0.6, 0.0, 0.8), 0.03, 2),
        ];
        c[2].side = 1;
        let points: Vec<_> = (0..3).map(|i| point(i as f32, c[i].depth)).collect();
        let mut kept = Vec::new();
        let m = merge_contributions(&c, &points, &mut kept, &Isometry::IDENTITY).unwrap();
        assert_eq!(m.normal, Vec3::Z);
        assert_eq!(kept.len(), 2);
        c[2].depth = 0.1;
        let m = merge_contributions(&c, &points, &mut kept, &Isometry::IDENTITY).unwrap();
        assert!((m.normal - c[2].normal).length() < 1e-6);
        assert_eq!(heavier_side(c.iter()), Some(1));
    }
}
