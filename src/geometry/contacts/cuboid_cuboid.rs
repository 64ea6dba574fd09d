//! Cuboid–cuboid: the separating axis theorem for two oriented boxes (Gottschalk, Lin & Manocha
//! 1996, "OBBTree"), extended from a yes/no test to a contact manifold the way ODE's `dBoxBox`,
//! Bullet's `btBoxBoxDetector` and Box2D's `b2CollidePolygons` (Catto) do.
//!
//! 1. **Axes.** Two convex polyhedra are disjoint iff their projections are disjoint on some
//!    face normal of either or on some cross product of an edge of each; for boxes that is 3 + 3
//!    face normals and 3 × 3 edge pairs. The overlap of the projections on an axis is the
//!    penetration along it, and the smallest over the 15 axes is the penetration depth.
//!    Everything runs in A's frame, where A's axes are the coordinate axes.
//! 2. **Near-parallel edges.** The cross product of two nearly parallel edges is a tiny vector
//!    whose direction is mostly rounding noise; it is skipped below a threshold, which is safe
//!    because parallel edges are covered by the face normals (Gottschalk et al.'s argument).
//! 3. **Face bias.** An edge axis is chosen only if clearly shallower than the best face axis,
//!    and B's face only if clearly shallower than A's, so that a box resting on another does not
//!    flicker between nearly equal axes from one step to the next (ODE's 5% "fudge factor",
//!    Box2D's relative/absolute tolerances).
//! 4. **Face contact.** The *reference* face (on the chosen axis) meets the *incident* face of
//!    the other box (the one most anti-parallel to it). The incident face is clipped against the
//!    side planes of the reference face (Sutherland & Hodgman 1974), the points below the
//!    reference face are kept, and at most four spread-out ones survive.
//! 5. **Edge contact.** The closest points of the two edges that span the axis.
//! 6. **Feature ids.** A face contact's point is named by the two faces (whose is the reference)
//!    and its clip tag (`polygon_clip.rs`: the incident edges and reference sides it lies on);
//!    an edge contact's by the two edge directions.

use super::FALLBACK_NORMAL;
use super::closest_segment_points::{Segment, closest_segment_points};
use super::cuboid_axes::{Axis, BestAxes, Feature, FramedBox, choose_axis, least_penetration_axes};
use super::manifold_reduction::spread_points;
use super::polygon_clip::{ClipPolygon, FIRST_PLANE, MAX_CLIP_VERTICES};
use crate::geometry::{ContactManifold, ContactPoint, Cuboid, FeatureId, Isometry};
use glam::{Mat3, Vec3};
use std::cmp::Ordering;

/// Lateral widening of the reference face's side planes in face clipping, as a fraction of the
/// magnitude of the coordinates (about 80 ulps): see `face_contact`.
const CLIP_MARGIN_FRACTION: f32 = 1e-5;

/// Feature-id contexts: a face contact (with its faces in the low bits), an edge contact (with
/// its two edge directions), the last-resort deepest vertex.
const FACE_CONTACT: u32 = 1 << 8;
const EDGE_CONTACT: u32 = 2 << 8;
const DEEPEST_VERTEX: u32 = 3 << 8;

/// Contact between a box at `pose_a` (shape A) and a box at `pose_b` (shape B).
///
/// The normal is the separating axis of least penetration (with the face bias of the module
/// docs), oriented from A to B; when B's centre lies exactly on the plane through A's centre
/// normal to it, the orientation closer to [`FALLBACK_NORMAL`] is taken, and so are ties between
/// equally deep axes (two coincident boxes separate along the axis closest to world up).
///
/// The computation is symmetric: the two boxes are put in a canonical order first (larger
/// volume first, then a fixed comparison of their numbers), so `contact(b, a)` is exactly
/// `contact(a, b)` flipped.
pub fn contact_cuboid_cuboid(
    pose_a: &Isometry,
    a: &Cuboid,
    pose_b: &Isometry,
    b: &Cuboid,
) -> Option<ContactManifold> {
    if canonical_order(pose_a, a, pose_b, b) == Ordering::Less {
        contact_in_order(pose_b, b, pose_a, a).map(ContactManifold::flipped)
    } else {
        contact_in_order(pose_a, a, pose_b, b)
    }
}

/// `Greater` or `Equal` when `a` should play shape A: larger volume first (the bigger box's face
/// is the natural reference for a smaller one resting on it), then the numbers of the shape and
/// the pose compared in a fixed total order.
fn canonical_order(pose_a: &Isometry, a: &Cuboid, pose_b: &Isometry, b: &Cuboid) -> Ordering {
    let key = |pose: &Isometry, c: &Cuboid| {
        let h = c.half_extents;
        let (t, q) = (pose.translation, pose.rotation);
        [
            h.x * h.y * h.z,
            h.x,
            h.y,
            h.z,
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

/// [`contact_cuboid_cuboid`] once the order is fixed: the separating axis test in A's frame,
/// then the contact points on the chosen axis, reduced and put back in world space.
fn contact_in_order(
    pose_a: &Isometry,
    a: &Cuboid,
    pose_b: &Isometry,
    b: &Cuboid,
) -> Option<ContactManifold> {
    let to_a = pose_a.rotation.inverse();
    let box_a = FramedBox {
        center: Vec3::ZERO,
        axes: Mat3::IDENTITY,
        half: a.half_extents,
    };
    let box_b = FramedBox {
        center: to_a * (pose_b.translation - pose_a.translation),
        axes: Mat3::from_quat(to_a * pose_b.rotation),
        half: b.half_extents,
    };
    let up = to_a * FALLBACK_NORMAL;
    let best = least_penetration_axes(&box_a, &box_b, up)?;
    let axis = choose_axis(&best, a.half_extents, b.half_extents);

    let mut candidates = [ContactPoint::default(); MAX_CLIP_VERTICES];
    let (axis, len) = contact_points(&box_a, &box_b, &best, axis, &mut candidates);
    let mut manifold = ContactManifold::new(pose_a.transform_vector(axis.normal));
    let (chosen, count) = spread_points(&candidates[..len], axis.normal);
    for &k in &chosen[..count] {
        let c = candidates[k];
        manifold.push(ContactPoint {
            point: pose_a.transform_point(c.point),
            ..c
        });
    }
    Some(manifold)
}

/// The candidate contact points (A's frame) for the chosen `axis`, written into `out`; returns
/// the axis they belong to and how many there are.
///
/// A face axis whose clipped incident face leaves no point below the reference face (the face
/// bias kept a face axis while the boxes really meet edge to edge, or the incident box hangs
/// over the reference face's border) falls back on the best edge axis if it overlaps no more,
/// else on the incident box's deepest vertex paired with its closest point on the reference
/// box.
fn contact_points(
    box_a: &FramedBox,
    box_b: &FramedBox,
    best: &BestAxes,
    axis: Axis,
    out: &mut [ContactPoint; MAX_CLIP_VERTICES],
) -> (Axis, usize) {
    let (reference, face, ref_normal, incident, of_b) = match axis.feature {
        Feature::FaceOfA(i) => (box_a, i, axis.normal, box_b, false),
        Feature::FaceOfB(j) => (box_b, j, -axis.normal, box_a, true),
        Feature::Edges(i, j) => {
            out[0] = edge_contact(box_a, i, box_b, j, axis.normal, axis.depth);
            return (axis, 1);
        }
    };
    let len = face_contact((reference, face, of_b), ref_normal, incident, out);
    if len > 0 {
        return (axis, len);
    }
    // The edge axis only where it overlaps no more than the face axis: the boxes' depth is
    // their least overlap, and a deeper edge axis (a corner touching a face, its clip lost
    // to rounding) read 21 mm for a touch of 1e-7.
    if let Some(edge) = best.edge.filter(|e| e.depth <= axis.depth)
        && let Feature::Edges(i, j) = edge.feature
    {
        out[0] = edge_contact(box_a, i, box_b, j, edge.normal, edge.depth);
        return (edge, 1);
    }
    out[0] = deepest_vertex_contact(reference, ref_normal, incident, axis.depth);
    (axis, 1)
}

/// Face contact: `reference`'s face along its local axis `axis` (B's when `of_b`), of outward
/// unit normal `ref_normal`, against the face of `incident` most anti-parallel to it. Writes
/// the candidate points (A's frame, midway between the faces, named by the faces and their clip
/// tags) into `out` and returns how many (possibly none).
///
/// The side planes are widened by a margin of [`CLIP_MARGIN_FRACTION`] of the coordinates'
/// magnitude: clipping interpolates, and without the margin a reference face of zero width (a
/// box with a zero half extent) would lose every interpolated point to rounding.
fn face_contact(
    (reference, axis, of_b): (&FramedBox, usize, bool),
    ref_normal: Vec3,
    incident: &FramedBox,
    out: &mut [ContactPoint; MAX_CLIP_VERTICES],
) -> usize {
    let scale = reference
        .center
        .abs()
        .max_element()
        .max(incident.center.abs().max_element())
        + reference.half.max_element()
        + incident.half.max_element();
    let margin = CLIP_MARGIN_FRACTION * scale;
    let (corners, incident_id) = incident_face(incident, ref_normal);
    let mut polygon = ClipPolygon::<MAX_CLIP_VERTICES>::from_quad(corners);
    for (n, k) in [(axis + 1) % 3, (axis + 2) % 3].into_iter().enumerate() {
        let side = reference.axes.col(k);
        let centre = reference.center.dot(side);
        let reach = reference.half[k] + margin;
        let plane = FIRST_PLANE + 2 * n as u8;
        polygon =
            polygon
                .clipped(side, centre + reach, plane)
                .clipped(-side, reach - centre, plane + 1);
    }
    let outward = reference.axes.col(axis).dot(ref_normal) > 0.0;
    let faces = FACE_CONTACT | u32::from(of_b) << 6 | face_id(axis, outward) << 3 | incident_id;

    let face_offset = reference.center.dot(ref_normal) + reference.half[axis];
    let mut len = 0;
    for (p, tag) in polygon.tagged() {
        let separation = p.dot(ref_normal) - face_offset;
        if separation <= 0.0 {
            out[len] = ContactPoint {
                point: p - ref_normal * (separation * 0.5),
                // `0 - x` rather than `-x`: touching gives +0, not -0.
                depth: 0.0 - separation,
                feature: FeatureId::clipped(faces, tag.bits()),
            };
            len += 1;
        }
    }
    len
}

/// Last-resort contact for a face axis: the vertex of `incident` deepest along `-ref_normal`,
/// paired with its closest point on `reference`, at the axis overlap `depth`.
fn deepest_vertex_contact(
    reference: &FramedBox,
    ref_normal: Vec3,
    incident: &FramedBox,
    depth: f32,
) -> ContactPoint {
    let vertex = support_point(incident, -ref_normal);
    let local = reference.axes.transpose() * (vertex - reference.center);
    let clamped = local.max(-reference.half).min(reference.half);
    let on_reference = reference.center + reference.axes * clamped;
    ContactPoint::new((vertex + on_reference) * 0.5, depth.max(0.0))
        .with_feature(FeatureId::single(DEEPEST_VERTEX))
}

/// A box face's number (0..6) from its axis and side.
fn face_id(axis: usize, outward: bool) -> u32 {
    axis as u32 * 2 + u32::from(outward)
}

/// The face of `b` whose outward normal is most anti-parallel to `direction`, as four corners
/// in order around it, and its number ([`face_id`]).
fn incident_face(b: &FramedBox, direction: Vec3) -> ([Vec3; 4], u32) {
    let dots = Vec3::new(
        b.axes.x_axis.dot(direction),
        b.axes.y_axis.dot(direction),
        b.axes.z_axis.dot(direction),
    );
    let abs = dots.abs();
    let j = if abs.x >= abs.y && abs.x >= abs.z {
        0
    } else if abs.y >= abs.z {
        1
    } else {
        2
    };
    let outward = if dots[j] > 0.0 { -1.0 } else { 1.0 };
    let centre = b.center + b.axes.col(j) * (outward * b.half[j]);
    let u = b.axes.col((j + 1) % 3) * b.half[(j + 1) % 3];
    let v = b.axes.col((j + 2) % 3) * b.half[(j + 2) % 3];
    let corners = [
        centre + u + v,
        centre - u + v,
        centre - u - v,
        centre + u - v,
    ];
    (corners, face_id(j, outward > 0.0))
}

/// The vertex of `b` farthest along `direction` (ties: the `+` vertex).
fn support_point(b: &FramedBox, direction: Vec3) -> Vec3 {
    (0..3).fold(b.center, |p, k| {
        let axis = b.axes.col(k);
        p + axis * (edge_sign(axis, direction) * b.half[k])
    })
}

/// Edge contact on the axis `normal` (A to B, A's frame) spanned by `a`'s edge along its local
/// axis `i` and `b`'s edge along its local axis `j`: the midpoint of the two edges' closest
/// points, with the axis overlap as depth.
fn edge_contact(
    a: &FramedBox,
    i: usize,
    b: &FramedBox,
    j: usize,
    normal: Vec3,
    depth: f32,
) -> ContactPoint {
    let on_a = closest_segment_points(
        supporting_edge(a, i, normal),
        supporting_edge(b, j, -normal),
    );
    let edges = EDGE_CONTACT | (i * 3 + j) as u32;
    ContactPoint::new((on_a.0 + on_a.1) * 0.5, depth.max(0.0))
        .with_feature(FeatureId::single(edges))
}

/// The edge of `b` parallel to its local axis `k` that lies farthest along `direction`
/// (ties: the `+` side).
fn supporting_edge(b: &FramedBox, k: usize, direction: Vec3) -> Segment {
    let axis = b.axes.col(k);
    // The support vertex with its `k` coordinate brought back to the middle of the edge.
    let mid = support_point(b, direction) - axis * (edge_sign(axis, direction) * b.half[k]);
    let half = axis * b.half[k];
    Segment {
        start: mid - half,
        end: mid + half,
    }
}

/// The side (`±1`) of a box's axis that lies farther along `direction` (ties: `+`).
fn edge_sign(axis: Vec3, direction: Vec3) -> f32 {
    if axis.dot(direction) < 0.0 { -1.0 } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;
    use std::f32::consts::FRAC_PI_4;

    fn cuboid(x: f32, y: f32, z: f32) -> Cuboid {
        Cuboid {
            half_extents: Vec3::new(x, y, z),
        }
    }

    /// Asserts that `m`'s points are, in some order, `expected` (within `tol`), all at `depth`.
    fn assert_points(m: &ContactManifold, expected: &[Vec3], depth: f32, tol: f32) {
        assert_eq!(m.len(), expected.len(), "{m:?}");
        for e in expected {
            let p = m.points().iter().find(|p| (p.point - *e).length() <= tol);
            let p = p.unwrap_or_else(|| panic!("no point near {e} in {m:?}"));
            assert!((p.depth - depth).abs() <= tol, "{m:?}");
        }
    }

    fn square_corners(centre: Vec3, rot: Quat, hx: f32, hy: f32) -> Vec<Vec3> {
        [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)]
            .iter()
            .map(|&(x, y)| centre + rot * Vec3::new(x * hx, y * hy, 0.0))
            .collect()
    }

    #[test]
    fn stacked_boxes_overlapping_touching_and_one_ulp_apart() {
        let (a, b) = (cuboid(1.0, 1.0, 1.0), cuboid(0.5, 0.5, 0.5));
        let pa = Isometry::IDENTITY;
        let sunk = Isometry::from_translation(Vec3::new(0.0, 0.0, 1.4));
        let m = contact_cuboid_cuboid(&pa, &a, &sunk, &b).unwrap();
        assert_eq!(m.normal, Vec3::Z);
        let corners = square_corners(Vec3::new(0.0, 0.0, 0.95), Quat::IDENTITY, 0.5, 0.5);
        assert_points(&m, &corners, 0.1, 1e-5);

        let touching = Isometry::from_translation(Vec3::new(0.0, 0.0, 1.5));
        let m = contact_cuboid_cuboid(&pa, &a, &touching, &b).unwrap();
        let corners = square_corners(Vec3::new(0.0, 0.0, 1.0), Quat::IDENTITY, 0.5, 0.5);
        assert_points(&m, &corners, 0.0, 0.0);

        let gap = Isometry::from_translation(Vec3::new(0.0, 0.0, 1.5f32.next_up()));
        assert!(contact_cuboid_cuboid(&pa, &a, &gap, &b).is_none());
        // Side by side along x, touching with coplanar faces of equal size.
        let beside = Isometry::from_translation(Vec3::new(2.0, 0.0, 0.0));
        let m = contact_cuboid_cuboid(&pa, &a, &beside, &a).unwrap();
        assert_eq!((m.normal, m.len(), m.max_depth()), (Vec3::X, 4, 0.0));
        let gap = Isometry::from_translation(Vec3::new(2.0f32.next_up(), 0.0, 0.0));
        assert!(contact_cuboid_cuboid(&pa, &a, &gap, &a).is_none());
    }

    #[test]
    fn a_turned_box_resting_on_a_bigger_box_gives_its_four_bottom_corners() {
        let ground = cuboid(5.0, 5.0, 1.0);
        let small = cuboid(1.0, 0.5, 0.5);
        let pg = Isometry::new(Vec3::new(1.0, 2.0, 3.0), Quat::from_rotation_x(0.2));
        let turn = Quat::from_rotation_z(0.3);
        let local = Isometry::new(Vec3::new(0.5, -1.0, 1.5 - 0.01), turn);
        let ps = pg * local;
        let bottom = square_corners(Vec3::new(0.5, -1.0, 1.0 - 0.005), turn, 1.0, 0.5);
        let bottom: Vec<Vec3> = bottom.into_iter().map(|p| pg.transform_point(p)).collect();
        let up = pg.transform_vector(Vec3::Z);
        for (m, normal) in [
            (
                contact_cuboid_cuboid(&pg, &ground, &ps, &small).unwrap(),
                up,
            ),
            (
                contact_cuboid_cuboid(&ps, &small, &pg, &ground).unwrap(),
                -up,
            ),
        ] {
            assert!((m.normal - normal).length() < 1e-5, "{m:?}");
            assert_points(&m, &bottom, 0.01, 1e-4);
        }
    }

    #[test]
    fn an_aligned_stack_keeps_the_face_normal_and_four_points_under_rounding_wobble() {
        // A box resting on an equal one: the face axes of both and the edge axes such as
        // A.x × B.y all give the same depth, up to rounding, as the upper box wobbles by
        // rounding-sized angles. Without the face bias the choice would follow the rounding
        // and flicker between a 4-point face manifold and a 1-point edge one.
        let cube = cuboid(0.5, 0.5, 0.5);
        let below = Isometry::from_translation(Vec3::new(1.0, 2.0, 0.5));
        for step in 0..400 {
            let wobble = (step as f32 - 200.0) * 1e-9;
            let tilt = Quat::from_rotation_x(wobble) * Quat::from_rotation_y(-0.7 * wobble);
            let above = Isometry::new(Vec3::new(1.0, 2.0, 1.5 - 1e-3), tilt);
            let m = contact_cuboid_cuboid(&below, &cube, &above, &cube).unwrap();
            assert!((m.normal - Vec3::Z).length() < 1e-6, "step {step}: {m:?}");
            assert_eq!(m.len(), 4, "step {step}: {m:?}");
            assert!((m.max_depth() - 1e-3).abs() < 1e-5, "step {step}: {m:?}");
        }
    }

    #[test]
    fn a_box_balanced_on_an_edge_gives_two_points() {
        let ground = cuboid(5.0, 5.0, 1.0);
        let cube = cuboid(1.0, 1.0, 1.0);
        let rolled = Quat::from_rotation_x(FRAC_PI_4);
        let pose = Isometry::new(Vec3::new(0.0, 0.0, 1.0 + 2f32.sqrt() - 0.02), rolled);
        let m = contact_cuboid_cuboid(&Isometry::IDENTITY, &ground, &pose, &cube).unwrap();
        assert!((m.normal - Vec3::Z).length() < 1e-6);
        let ends = [Vec3::new(1.0, 0.0, 0.99), Vec3::new(-1.0, 0.0, 0.99)];
        assert_points(&m, &ends, 0.02, 1e-4);
    }

    #[test]
    fn crossed_edges_touch_at_the_midpoint_of_their_closest_points() {
        let cube = cuboid(1.0, 1.0, 1.0);
        let r2 = 2f32.sqrt();
        // A's top edge runs along x at height sqrt(2) over y = 0; B's bottom edge runs along y
        // over x = 0.1: their closest points are above (0.1, 0).
        let pa = Isometry::new(Vec3::ZERO, Quat::from_rotation_x(FRAC_PI_4));
        let pb = Isometry::new(
            Vec3::new(0.1, -0.2, 2.0 * r2 - 0.05),
            Quat::from_rotation_y(FRAC_PI_4),
        );
        let m = contact_cuboid_cuboid(&pa, &cube, &pb, &cube).unwrap();
        assert!((m.normal - Vec3::Z).length() < 1e-5, "{m:?}");
        assert_eq!(m.len(), 1);
        assert!((m.max_depth() - 0.05).abs() < 1e-5);
        let expected = Vec3::new(0.1, 0.0, r2 - 0.025);
        assert!((m.points()[0].point - expected).length() < 1e-5, "{m:?}");
    }

    #[test]
    fn coincident_boxes_separate_along_world_up() {
        let a = cuboid(1.0, 1.0, 1.0);
        let pose = Isometry::from_translation(Vec3::new(4.0, 5.0, 6.0));
        let m = contact_cuboid_cuboid(&pose, &a, &pose, &a).unwrap();
        assert_eq!(m.normal, FALLBACK_NORMAL);
        let corners = square_corners(pose.translation, Quat::IDENTITY, 1.0, 1.0);
        assert_points(&m, &corners, 2.0, 1e-5);
        // Unequal extents: the thinnest axis is the least penetration; with the centres
        // coincident, an axis normal to up keeps its + orientation.
        let slab = cuboid(1.0, 2.0, 3.0);
        let m = contact_cuboid_cuboid(&pose, &slab, &pose, &slab).unwrap();
        assert_eq!((m.normal, m.max_depth()), (Vec3::X, 2.0));
        // Turned about x by a little: the face closest to up still wins every tie.
        let tilted = Isometry::new(pose.translation, Quat::from_rotation_x(0.1));
        let m = contact_cuboid_cuboid(&tilted, &a, &tilted, &a).unwrap();
        assert!((m.normal - tilted.transform_vector(Vec3::Z)).length() < 1e-6);
    }

    #[test]
    fn zero_size_boxes_give_finite_deduplicated_contacts() {
        let cube = cuboid(1.0, 1.0, 1.0);
        let point = cuboid(0.0, 0.0, 0.0);
        let inside = Isometry::from_translation(Vec3::new(0.2, 0.3, 0.9));
        // The point leaves through the cube's +z face: the cube lies along -z from it.
        let m = contact_cuboid_cuboid(&inside, &point, &Isometry::IDENTITY, &cube).unwrap();
        assert_eq!(m.normal, -Vec3::Z);
        assert_points(&m, &[Vec3::new(0.2, 0.3, 0.95)], 0.1, 1e-6);
        // Two points at the same place: depth 0, a finite normal, one point.
        let m = contact_cuboid_cuboid(&inside, &point, &inside, &point).unwrap();
        assert!(m.normal.is_normalized() && m.len() == 1 && m.max_depth() == 0.0);
        // A zero-thickness plate lying on the cube's top face, turned: its four corners.
        let plate = cuboid(0.5, 0.25, 0.0);
        let turn = Quat::from_rotation_z(0.7);
        let on_top = Isometry::new(Vec3::new(0.1, 0.0, 1.0), turn);
        let m = contact_cuboid_cuboid(&Isometry::IDENTITY, &cube, &on_top, &plate).unwrap();
        let corners = square_corners(on_top.translation, turn, 0.5, 0.25);
        assert_points(&m, &corners, 0.0, 1e-5);
    }

    #[test]
    fn parallel_edges_are_skipped_without_losing_separation() {
        // Two axis-aligned boxes, corner to corner along the xy diagonal, just apart: every
        // edge pair along z is parallel, and the face axes alone must see the gap.
        let cube = cuboid(1.0, 1.0, 1.0);
        let apart = Isometry::from_translation(Vec3::new(2.001, 2.001, 0.5));
        assert!(contact_cuboid_cuboid(&Isometry::IDENTITY, &cube, &apart, &cube).is_none());
        // Turned by far less than the threshold's angle: still apart, still no NaN.
        let tiny = Isometry::new(apart.translation, Quat::from_rotation_z(1e-7));
        assert!(contact_cuboid_cuboid(&Isometry::IDENTITY, &cube, &tiny, &cube).is_none());
        let overlapping = Isometry::new(Vec3::new(1.9, 1.9, 0.5), Quat::from_rotation_z(1e-7));
        let m = contact_cuboid_cuboid(&Isometry::IDENTITY, &cube, &overlapping, &cube).unwrap();
        assert!(
            m.normal.is_normalized() && (m.max_depth() - 0.1).abs() < 1e-4,
            "{m:?}"
        );
    }

    /// The least overlap of the 15 axes: the true penetration depth of two boxes.
    fn least_overlap(pose_a: &Isometry, a: &Cuboid, pose_b: &Isometry, b: &Cuboid) -> f32 {
        let to_a = pose_a.rotation.inverse();
        let framed = |center, axes, half| FramedBox { center, axes, half };
        let box_a = framed(Vec3::ZERO, Mat3::IDENTITY, a.half_extents);
        let box_b = framed(
            to_a * (pose_b.translation - pose_a.translation),
            Mat3::from_quat(to_a * pose_b.rotation),
            b.half_extents,
        );
        let best = least_penetration_axes(&box_a, &box_b, Vec3::Z).map_or(0.0, |best| {
            let edge = best.edge.map_or(f32::MAX, |e| e.depth);
            best.face_a.depth.min(best.face_b.depth).min(edge)
        });
        best.max(0.0)
    }

    /// Boxes barely touching, at random turns, and the pose a gliding sweep stopped at: no
    /// point reads deeper than the boxes' least overlap, beyond the face bias (`0.95`, and
    /// `1e-3` of the size). A face clip that kept no point fell back on the best edge axis
    /// whatever its overlap: a corner touching a face by 1e-7 read 21 mm deep along an edge
    /// axis, and continuous collision, which checks where it stops, stopped 0.43 m early.
    #[test]
    fn touching_boxes_never_read_deeper_than_their_least_overlap_beyond_the_face_bias() {
        let slab = cuboid(0.6, 0.2, 0.3);
        let glide = Isometry::new(
            Vec3::new(-0.9985566, -0.011991546, -0.7726321),
            Quat::from_xyzw(0.4491324, -0.54958344, 0.33515057, 0.6196065),
        );
        let mut cases = vec![(slab, glide, slab, Isometry::IDENTITY)];
        let mut rng = crate::test_rng::TestRng::new(41);
        while cases.len() < 20_000 {
            let size = |v: Vec3| cuboid(v.x, v.y, v.z);
            let (a, b) = (size(rng.vec3(0.05, 0.6)), size(rng.vec3(0.05, 0.6)));
            let pose_b = Isometry::new(Vec3::ZERO, rng.rotation());
            let turn = rng.rotation();
            // Along a random direction, just inside touching (found by bisection).
            let d = rng.vec3(-1.0, 1.0).normalize_or(Vec3::X);
            let (mut lo, mut hi) = (0.0f32, 3.0f32);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                let pose_a = Isometry::new(d * mid, turn);
                if contact_cuboid_cuboid(&pose_a, &a, &pose_b, &b).is_some() {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            let pose_a = Isometry::new(d * lo, turn);
            cases.push((a, pose_a, b, pose_b));
        }
        for (k, (a, pose_a, b, pose_b)) in cases.into_iter().enumerate() {
            let Some(m) = contact_cuboid_cuboid(&pose_a, &a, &pose_b, &b) else {
                continue;
            };
            let least = least_overlap(&pose_a, &a, &pose_b, &b);
            let size = a
                .half_extents
                .max_element()
                .min(b.half_extents.max_element());
            let bound = (least + 1e-3 * size) / 0.95 + 1e-6;
            assert!(m.max_depth() <= bound, "{k}: {} > {bound}", m.max_depth());
        }
    }
}
