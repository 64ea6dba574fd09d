//! Mesh–mesh: the slides' "Uso della gerarchia". The two OBB hierarchies are traversed together
//! (a stack of node pairs from the two roots, the larger box split first, pairs tested by the
//! 15-axis box test) down to leaf pairs, whose triangles are tested exactly by Guigue and
//! Devillers' (2003) triangle–triangle test. Every intersecting pair then gives a contact
//! estimate, and the estimates are merged into one manifold as `mesh_manifold.rs` explains.
//!
//! # The per-pair estimate (an approximation)
//!
//! Two intersecting triangles say *that* the surfaces cross, not how deep one solid is inside the
//! other. The estimate uses the triangles' front normals (counter-clockwise corners, outward for
//! a closed mesh, up for a floor), in the manner of the triangle–triangle contact of Bullet's
//! GImpact (clip one triangle to the other's prism, measure what lies behind its plane):
//! - the part of A's triangle above or below B's triangle (A's triangle clipped by the three
//!   planes through B's edges, perpendicular to B) reaches `d_a` behind B's plane: B would move
//!   along `-n_b` by `d_a`;
//! - likewise B's triangle behind A's reaches `d_b`: B would move along `n_a` by `d_b`;
//! - the smaller wins (the shorter way out), ties going to A's normal. The point is the midpoint
//!   of the intersection segment (for coplanar or degenerate pairs, a point of both triangles).
//!
//! For a small triangle crossing a large one (a body's facets dipping into a floor) this is the
//! dip of the small triangle below the large one's plane, which is right; clipping keeps a large
//! triangle's far corners (behind the small one's plane only because the plane extends beyond
//! the triangle) out of the measure. The merge then drops pairs whose direction disagrees with
//! the rest (a floor triangle entering a box through its side: `mesh_manifold.rs`). It fails:
//! - on **open or thin meshes**, and on meshes whose triangles face inward or inconsistently:
//!   "behind" then is not "inside", and the normal can point the wrong way;
//! - when a triangle is pushed **further than its own size** through the other surface: it then
//!   leaves the intersection, the triangles still crossing are shallower, and the depth is
//!   underestimated (the normal stays right as long as some triangles cross); a body entirely
//!   inside a closed mesh touches nothing (urto collides surfaces, not volumes).
//!
//! The computation is symmetric: the meshes are put in a canonical order first, so
//! `contact(b, a)` is exactly `contact(a, b)` flipped.
//!
//! # Speculative contacts
//!
//! [`contact_trimesh_trimesh_within`] also reports triangles still apart by up to a margin, so
//! that a solver detecting once per step finds two meshes before they touch (Catto 2013; the
//! other shapes grow by the margin instead, `speculative.rs`). B's hierarchy boxes are grown by
//! the margin in the descent ([`Bvh::pairs_within`](crate::bvh::Bvh::pairs_within)), and a leaf
//! pair that does not intersect gives its gap (`triangle_distance.rs`): the normal along the
//! closest points, the depth minus the gap, the point midway, the side of the triangle whose
//! plane the gap is more nearly square to. In the merge a pair weighs its depth plus the margin
//! (what it would reach into the shapes grown by the margin), so crossing pairs weigh more than
//! near ones and near ones more than far ones.

use super::FALLBACK_NORMAL;
use super::mesh_scratch::{ContactScratch, push_contribution};
use super::polygon_clip::{ClipPolygon, FIRST_PLANE};
use super::triangle_distance::closest_points_triangle_triangle;
use crate::bvh::TraversalOrder;
use crate::geometry::{
    ContactManifold, ContactPoint, FeatureId, Isometry, MeshCollider, TriTriIntersection, Triangle,
    tri_tri_intersection,
};
use glam::Vec3;
use std::cmp::Ordering;

/// The unit normals of a pair's two triangles (`None` for a zero-area one).
type Normals = (Option<Vec3>, Option<Vec3>);

/// One intersecting triangle pair's estimate: normal from A to B, depth, point, and whose
/// triangle gave the normal (0: A's, 1: B's, 2: neither).
#[derive(Clone, Copy, Debug, PartialEq)]
struct PairContact {
    normal: Vec3,
    depth: f32,
    point: Vec3,
    side: u8,
}

/// Contact between a mesh at `pose_a` (shape A) and a mesh at `pose_b` (shape B).
///
/// `None` when no triangle of A meets a triangle of B (exactly decided). Otherwise the normal is
/// the depth-weighted average of the pair estimates of the module notes, and the points the
/// deepest and widest few intersection midpoints. Fills `scratch`'s hits with every intersecting
/// triangle pair and adds the hierarchy work to its counters.
pub fn contact_trimesh_trimesh(
    pose_a: &Isometry,
    a: &MeshCollider,
    pose_b: &Isometry,
    b: &MeshCollider,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    contact_trimesh_trimesh_within(pose_a, a, pose_b, b, 0.0, scratch)
}

/// [`contact_trimesh_trimesh`] that also finds the triangles up to `margin` apart (speculative
/// contacts, module notes): their points have negative depths (minus the gap). `None` when no
/// two triangles come within `margin`. A margin that is not a positive number counts as 0.
pub fn contact_trimesh_trimesh_within(
    pose_a: &Isometry,
    a: &MeshCollider,
    pose_b: &Isometry,
    b: &MeshCollider,
    margin: f32,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    let margin = if margin > 0.0 && margin.is_finite() {
        margin
    } else {
        0.0
    };
    if canonical_order(pose_a, a, pose_b, b) == Ordering::Less {
        let m = contact_in_order(pose_b, b, pose_a, a, margin, scratch);
        scratch.flip_hits();
        m.map(ContactManifold::flipped)
    } else {
        contact_in_order(pose_a, a, pose_b, b, margin, scratch)
    }
}

/// The estimate of the module notes for two triangles in one frame, as a one-point manifold
/// (normal from `ta` to `tb`), or `None` when they do not meet.
pub fn contact_triangle_triangle(ta: &Triangle, tb: &Triangle) -> Option<ContactManifold> {
    pair_contact(ta, tb, (ta.normal(), tb.normal()))
        .map(|c| ContactManifold::single(c.normal, c.point, c.depth))
}

/// `Greater` or `Equal` when `a` should play shape A: more triangles first, then the numbers of
/// the mesh's box and of the pose in a fixed total order.
fn canonical_order(
    pose_a: &Isometry,
    a: &MeshCollider,
    pose_b: &Isometry,
    b: &MeshCollider,
) -> Ordering {
    let key = |pose: &Isometry, m: &MeshCollider| {
        let (lo, hi) = (m.local_aabb().min, m.local_aabb().max);
        let (t, q) = (pose.translation, pose.rotation);
        [
            m.mesh().triangle_count() as f32,
            m.mesh().vertex_count() as f32,
            lo.x,
            lo.y,
            lo.z,
            hi.x,
            hi.y,
            hi.z,
            t.x,
            t.y,
            t.z,
            q.x,
            q.y,
            q.z,
            q.w,
        ]
    };
    let (ka, kb) = (key(pose_a, a), key(pose_b, b));
    super::total_order(&ka, &kb)
}

fn contact_in_order(
    pose_a: &Isometry,
    a: &MeshCollider,
    pose_b: &Isometry,
    b: &MeshCollider,
    margin: f32,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    scratch.begin_query();
    let b_in_a = pose_a.inv_mul(pose_b);
    let ContactScratch {
        query,
        hits,
        contributions,
        points,
        ..
    } = scratch;
    let stats = a.bvh().pairs_within(
        b.bvh(),
        &b_in_a,
        margin,
        TraversalOrder::DepthFirst,
        query,
        |ia, ib| {
            let (Some(ta), Some(tb)) = (
                a.mesh().triangle(ia as usize),
                b.mesh().triangle(ib as usize),
            ) else {
                return false;
            };
            // The same carrying as `TriMesh::intersecting_pairs_brute_force`, so both decide
            // on the same coordinates.
            let tb = tb.transformed(&b_in_a);
            // Exact on the same coordinates (min/max do not round), so it rejects no touching
            // pair, and it spares the exact test most of a leaf pair's triangle pairs.
            if !ta.aabb().expanded(margin).intersects(&tb.aabb()) {
                return false;
            }
            let normals = (ta.normal(), tb.normal());
            if beyond_plane(&tb, &ta, normals.0, margin)
                || beyond_plane(&ta, &tb, normals.1, margin)
            {
                return false;
            }
            let Some(c) =
                pair_contact(&ta, &tb, normals).or_else(|| gap_contact(&ta, &tb, normals, margin))
            else {
                return false;
            };
            // Named by the two triangles (one point per pair of them).
            let feature = FeatureId::single(1).of_part(ia).of_part(ib);
            let point = ContactPoint::new(c.point, c.depth).with_feature(feature);
            let weight = c.depth + margin;
            push_contribution(contributions, points, c.normal, weight, c.side, &[point]);
            true
        },
        hits,
    );
    scratch.count(stats);
    scratch.merge(pose_a)
}

/// The per-pair estimate of the module notes.
/// `normals` are the two triangles' unit normals (computed once per pair by the caller: each is
/// an `f64` normalisation).
fn pair_contact(ta: &Triangle, tb: &Triangle, normals: Normals) -> Option<PairContact> {
    let point = match tri_tri_intersection(ta, tb) {
        TriTriIntersection::Disjoint => return None,
        TriTriIntersection::Segment(p, q) => (p + q) * 0.5,
        TriTriIntersection::Coplanar | TriTriIntersection::Degenerate => shared_point(ta, tb),
    };
    let (na, nb) = normals;
    let a_behind_b = nb.map(|n| depth_behind(ta, tb, n));
    let b_behind_a = na.map(|n| depth_behind(tb, ta, n));
    let (normal, depth, side): (Vec3, f32, u8) = match (na, nb, a_behind_b, b_behind_a) {
        (Some(na), _, Some(da), Some(db)) if db <= da => (na, db, 0),
        (_, Some(nb), Some(da), _) => (-nb, da, 1),
        (Some(na), _, _, Some(db)) => (na, db, 0),
        // Two zero-area triangles (meshes drop them; a caller of the public test may not).
        _ => (
            (tb.centroid() - ta.centroid())
                .try_normalize()
                .unwrap_or(FALLBACK_NORMAL),
            0.0,
            2,
        ),
    };
    let (normal, depth, side) = match shallower_edge_axis(ta, tb) {
        Some((n, d)) if d < SLIVER_RATIO * depth => (n, d, squarer_side(normals, n)),
        _ => (normal, depth, side),
    };
    Some(PairContact {
        normal,
        depth,
        point,
        side,
    })
}

/// An edge axis replaces the face estimate only when it is this much shallower: the face
/// estimate knows inside from outside (the winding), the edge axis does not, so it is trusted
/// unless it is off by a factor, the mark of two faces crossing in a sliver (a factor of 355
/// for two stacked boxes; a body's facets dipping 10 cm into a floor come within 2).
const SLIVER_RATIO: f32 = 0.25;

/// The side (0: A's, 1: B's) whose triangle's plane `normal` is more nearly square to, ties to
/// A: how a normal that is neither triangle's is filed for the merge's choice of side.
fn squarer_side((na, nb): Normals, normal: Vec3) -> u8 {
    let squareness = |n: Option<Vec3>| n.map_or(0.0, |n| n.dot(normal).abs());
    u8::from(squareness(nb) > squareness(na))
}

/// The shallowest of the 9 edge–edge separating axes of two crossing triangles (`ea × eb`), as
/// a unit normal from `ta` to `tb` and the overlap along it, or `None` when every pair of edges
/// is parallel.
///
/// Why: the face estimate fails where two faces of two bodies cross in a sliver, as the side
/// faces of two stacked boxes do along the top edge of the lower one. Each face is then "behind"
/// the other by the whole width of the box (0.7 m for two 0.8 m boxes overlapping 2 mm), and
/// that depth, pointing sideways, outweighed every true contact and pushed the upper box off.
/// For two triangles as convex sets the least overlap over the 2 face normals and these 9 axes
/// is the exact penetration depth (the separating-axis theorem), so an edge axis shallower than
/// the face estimate is the shorter way out (2 mm, up).
fn shallower_edge_axis(ta: &Triangle, tb: &Triangle) -> Option<(Vec3, f32)> {
    let (ca, cb) = (ta.vertices(), tb.vertices());
    let edges = |c: [Vec3; 3]| [c[1] - c[0], c[2] - c[1], c[0] - c[2]];
    let span = |c: &[Vec3; 3], axis: Vec3| {
        c.iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
                let s = axis.dot(*p);
                (lo.min(s), hi.max(s))
            })
    };
    let mut best: Option<(Vec3, f32)> = None;
    for ea in edges(ca) {
        for eb in edges(cb) {
            let Some(axis) = ea.cross(eb).try_normalize() else {
                continue;
            };
            let ((a_lo, a_hi), (b_lo, b_hi)) = (span(&ca, axis), span(&cb, axis));
            // B moves up the axis by `up`, or down it by `down`, to clear A.
            let (up, down) = (a_hi - b_lo, b_hi - a_lo);
            let (normal, overlap) = if up <= down {
                (axis, up)
            } else {
                (-axis, down)
            };
            if overlap >= 0.0 && best.is_none_or(|(_, d)| overlap < d) {
                best = Some((normal, overlap));
            }
        }
    }
    best
}

/// True when every corner of `t` lies farther than `margin` on one side of `base`'s plane: the
/// triangles neither cross nor come within `margin` (a separating plane, six dot products, that
/// spares the exact tests the pairs the boxes let through on slanted surfaces). Exact for
/// `margin` 0 up to the rounding of the plane, so a touching pair is kept: corners on the plane
/// are not beyond it.
fn beyond_plane(t: &Triangle, base: &Triangle, base_normal: Option<Vec3>, margin: f32) -> bool {
    let Some(n) = base_normal else {
        return false;
    };
    let offset = n.dot(base.a);
    let s = t.vertices().map(|v| n.dot(v) - offset);
    // Rounding of the plane's offset at these coordinates, so no touching pair is lost.
    let slack = 4.0 * f32::EPSILON * (offset.abs() + s.iter().fold(0.0f32, |m, x| m.max(x.abs())));
    let reach = margin + slack;
    s.iter().all(|&d| d > reach) || s.iter().all(|&d| d < -reach)
}

/// The speculative estimate of two disjoint triangles at most `margin` apart (module notes), or
/// `None` when they are farther apart, or so close that the gap has no direction (the exact
/// test then calls them touching or apart; rounding alone separates the two).
fn gap_contact(ta: &Triangle, tb: &Triangle, normals: Normals, margin: f32) -> Option<PairContact> {
    if margin <= 0.0 {
        return None;
    }
    let (p, q) = closest_points_triangle_triangle(ta, tb);
    let gap = p.distance(q);
    if gap > margin {
        return None;
    }
    let normal = ((q - p) / gap).try_normalize()?;
    let side = squarer_side(normals, normal);
    Some(PairContact {
        normal,
        depth: -gap,
        point: (p + q) * 0.5,
        side,
    })
}

/// How far the part of `t` inside the prism of `base` (the infinite prism swept by `base` along
/// its unit normal `n`) reaches behind `base`'s plane; 0 when none of it is behind, or when
/// nothing is left after clipping (a pair meeting only at `base`'s border).
fn depth_behind(t: &Triangle, base: &Triangle, n: Vec3) -> f32 {
    let mut part = ClipPolygon::<6>::from_corners(&t.vertices());
    let corners = base.vertices();
    for k in 0..3 {
        let (a, b) = (corners[k], corners[(k + 1) % 3]);
        // Points outside the edge `a → b` (counter-clockwise about n) have `out·x > out·a`.
        let out = (b - a).cross(n);
        part = part.clipped(out, out.dot(a), FIRST_PLANE + k as u8);
    }
    part.vertices()
        .iter()
        .fold(0.0f32, |d, &v| d.max(0.0 - n.dot(v - base.a)))
}

/// A point of both (meeting) triangles, near their common region: the point of `tb` nearest to
/// `ta`'s centroid, brought back to `ta`, averaged.
fn shared_point(ta: &Triangle, tb: &Triangle) -> Vec3 {
    let on_b = tb.closest_point(ta.centroid());
    let on_a = ta.closest_point(on_b);
    (on_a + on_b) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_facet_dipping_into_a_floor_is_pushed_up_by_its_dip() {
        let floor = Triangle::new(
            Vec3::new(-10.0, -10.0, 0.0),
            Vec3::new(10.0, -10.0, 0.0),
            Vec3::new(0.0, 10.0, 0.0),
        );
        // A facet tilted 45°, its low corner 0.05 below the floor.
        let facet = Triangle::new(
            Vec3::new(0.0, 0.0, -0.05),
            Vec3::new(0.5, 0.0, 0.45),
            Vec3::new(0.0, 0.5, 0.45),
        );
        let m = contact_triangle_triangle(&floor, &facet).unwrap();
        assert_eq!(m.normal, Vec3::Z);
        assert!((m.max_depth() - 0.05).abs() < 1e-6);
        assert!(m.points()[0].point.z.abs() < 1e-6, "on the floor");
        let flipped = contact_triangle_triangle(&facet, &floor).unwrap();
        assert_eq!(flipped.normal, -Vec3::Z);
        assert_eq!(flipped.max_depth(), m.max_depth());
        let lifted = Triangle::from(facet.vertices().map(|v| v + Vec3::Z * 0.0501));
        assert!(contact_triangle_triangle(&floor, &lifted).is_none());
    }

    #[test]
    fn side_faces_crossing_in_a_2mm_sliver_push_up_by_2mm_not_sideways() {
        // The +y side of a lower box (its top edge at z = 0.4) and the -x side of a box resting
        // on it sunk 2 mm: they cross in a vertical sliver 2 mm high.
        let lower_side = Triangle::new(
            Vec3::new(-0.3, 0.47, 0.0),
            Vec3::new(0.5, 0.47, 0.4),
            Vec3::new(-0.3, 0.47, 0.4),
        );
        let upper_side = Triangle::new(
            Vec3::new(-0.19, -0.3, 0.398),
            Vec3::new(-0.19, 0.5, 0.398),
            Vec3::new(-0.19, 0.5, 0.798),
        );
        let m = contact_triangle_triangle(&lower_side, &upper_side).unwrap();
        assert!(m.normal.abs_diff_eq(Vec3::Z, 1e-5), "{}", m.normal);
        assert!(m.max_depth() <= 0.002 + 1e-6, "{}", m.max_depth());
    }

    #[test]
    fn coplanar_and_degenerate_pairs_give_finite_contacts() {
        let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let shifted = Triangle::from(t.vertices().map(|v| v + Vec3::new(0.3, 0.3, 0.0)));
        let m = contact_triangle_triangle(&t, &shifted).unwrap();
        assert_eq!(m.max_depth(), 0.0);
        assert!(m.normal.is_normalized() && m.points()[0].point.is_finite());
        let segment = Triangle::new(
            Vec3::new(0.2, 0.2, -1.0),
            Vec3::new(0.2, 0.2, 1.0),
            Vec3::new(0.2, 0.2, 0.0),
        );
        let m = contact_triangle_triangle(&t, &segment).unwrap();
        assert!(m.normal.is_normalized() && m.max_depth().is_finite());
        let m = contact_triangle_triangle(&segment, &segment).unwrap();
        assert_eq!(m.normal, FALLBACK_NORMAL);
    }
}
