//! Triangle–box contact: the separating axis theorem with penetration depths, the contact
//! counterpart of the 13-axis overlap test of Akenine-Möller (2001, "Fast 3D triangle-box
//! overlap testing") in the way `cuboid_cuboid.rs` extends the box–box test (Gottschalk, Lin
//! and Manocha 1996).
//!
//! 1. **Axes.** In the box's frame: the triangle's normal, the box's three face normals, and the
//!    nine cross products of a box axis with a triangle edge. On each, the overlap of the two
//!    projections is how far the box must move along it (one way or the other) to separate; the
//!    smallest over the axes is the penetration depth (for two convex polytopes the minimum over
//!    face normals and edge–edge cross products is the exact minimum translation distance).
//!    Edge axes from an edge parallel to a box axis are zero and skipped (the face normals cover
//!    them).
//! 2. **Face bias.** An edge axis is chosen only if clearly shallower than the best face axis,
//!    as for two boxes, so a box resting on a triangle does not flicker between near-equal axes;
//!    between face axes the triangle's normal wins ties.
//! 3. **Points.** The part of the triangle inside the box (the triangle clipped by the box's six
//!    face planes, Sutherland & Hodgman 1974), each vertex with its depth along the normal past
//!    the box face the normal most opposes (the reference face of box–box clipping: a box
//!    resting tilted on a triangle has its points at their own depths); and, when the normal
//!    is the triangle's, the box corners behind the triangle's plane whose projection falls
//!    inside the triangle. Along a box face or an edge axis the deepest point carries the
//!    separating depth of step 1 (a clipped point can fall short of it when the triangle's
//!    deepest corner lies outside the box's side); along the triangle's normal the points are
//!    exact, and that depth, the box's deepest point below the triangle's *plane*, may lie
//!    over another triangle.
//!
//! The triangle is a two-sided surface: the box leaves through whichever side needs the shorter
//! move, so a box pushed more than halfway through a triangle leaves through the far side.
//!
//! **Internal edges.** On a mesh, a box crossing onto a neighbouring triangle of a flat floor
//! overlaps it first at its edge, where a box face or an edge axis is shallower than the
//! triangle's normal: a sideways normal that makes a sliding box bump on the seam (a *ghost*
//! collision). When every edge of the triangle that reaches into the box is internal (see
//! [`active_edges`](crate::geometry::active_edges)), the triangle's normal is taken whatever the
//! other axes say (they still separate the pair when apart).

use super::manifold_reduction::deepest_corner;
use super::mesh_manifold::reduce_to_manifold;
use super::polygon_clip::{ClipPolygon, FIRST_PLANE, MAX_TRIANGLE_CLIP_VERTICES};
use crate::ccd::segment_in_box;
use crate::geometry::active_edges::ALL_EDGES_ACTIVE;
use crate::geometry::{ContactManifold, ContactPoint, Cuboid, FeatureId, Isometry, Triangle};
use glam::Vec3;

/// Candidate points of one triangle–box contact: the clipped triangle and the box's corners.
pub(crate) const MAX_TRIANGLE_BOX_POINTS: usize = MAX_TRIANGLE_CLIP_VERTICES + 8;

/// Edge axes with `|e_box × e_tri|² <= EDGE_AXIS_MIN_SIN2 |e_tri|²` are skipped (near-parallel).
const EDGE_AXIS_MIN_SIN2: f32 = 1e-12;

/// The best edge axis replaces the face axis only if its depth is below
/// `EDGE_SWITCH_REL × face depth - tolerance`.
const EDGE_SWITCH_REL: f32 = 0.95;

/// The absolute part of the switch tolerance, as a fraction of the box's largest half extent.
const SWITCH_ABS_FRACTION: f32 = 1e-3;

/// Lateral widening of the box's planes in clipping, as a fraction of the coordinates'
/// magnitude (about 80 ulps): keeps points of a triangle lying exactly on a face.
const CLIP_MARGIN_FRACTION: f32 = 1e-5;

/// Feature-id contexts: a vertex of the triangle clipped by the box (with its clip tag; a mesh
/// mixes in the triangle's number, `FeatureId::of_part`, unless two of the box's planes made
/// it), a box corner inside the triangle's outline or the last-resort deepest corner (with the
/// corner's number). The box's own features are named alike on every triangle they cross, so
/// a box sliding over a tessellated floor keeps its warm start from triangle to triangle.
const TRIANGLE_CLIPPED: u32 = 1 << 8;
const BOX_CORNER: u32 = 2 << 8;

/// A triangle–box contact in the box's frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriangleBoxContact {
    /// Unit normal from the triangle to the box.
    pub normal: Vec3,
    /// Penetration along it: the separating depth, or along the triangle's normal the
    /// deepest point's.
    pub depth: f32,
    points: [ContactPoint; MAX_TRIANGLE_BOX_POINTS],
    len: usize,
}

impl TriangleBoxContact {
    /// The candidate points (box frame, midway between the surfaces), the deepest at `depth`.
    pub fn points(&self) -> &[ContactPoint] {
        &self.points[..self.len]
    }

    /// Adds a point named `feature`, its depth clamped to `[0, self.depth]` (rounding can step
    /// out of it).
    fn push(&mut self, point: Vec3, depth: f32, feature: FeatureId) {
        if self.len < MAX_TRIANGLE_BOX_POINTS {
            self.points[self.len] = ContactPoint {
                point,
                // Not `clamp`, which panics on NaN (non-finite input must not panic).
                depth: depth.max(0.0).min(self.depth),
                feature,
            };
            self.len += 1;
        }
    }
}

impl super::mesh_scratch::TriangleContact for TriangleBoxContact {
    fn normal(&self) -> Vec3 {
        self.normal
    }

    fn depth(&self) -> f32 {
        self.depth
    }

    fn points(&self) -> &[ContactPoint] {
        TriangleBoxContact::points(self)
    }
}

/// Contact between a triangle (shape A) and a box at `pose` (shape B), or `None` when apart
/// (touching counts, with depth 0). At most four points, chosen as in the box–box test.
pub fn contact_triangle_cuboid(
    tri: &Triangle,
    pose: &Isometry,
    cuboid: &Cuboid,
) -> Option<ContactManifold> {
    contact_triangle_cuboid_with_edges(tri, ALL_EDGES_ACTIVE, pose, cuboid)
}

/// [`contact_triangle_cuboid`] for a triangle of a mesh whose `active` edges are known
/// ([`MeshCollider::active_edges`](crate::geometry::MeshCollider::active_edges)): see the
/// module notes on internal edges.
pub fn contact_triangle_cuboid_with_edges(
    tri: &Triangle,
    active: u8,
    pose: &Isometry,
    cuboid: &Cuboid,
) -> Option<ContactManifold> {
    let local = tri.vertices().map(|p| pose.inverse_transform_point(p));
    let contact = triangle_box_contact(local, active, cuboid.half_extents)?;
    reduce_to_manifold(contact.normal, contact.points(), pose)
}

/// One candidate axis: the unit normal (from the triangle to the box) and the depth along it.
#[derive(Clone, Copy, Debug)]
struct Axis {
    normal: Vec3,
    depth: f32,
}

/// The overlap of the triangle `v` and the box `[-h, h]` along the unit `axis`, oriented the
/// shorter way out; `None` when the projections are apart (a separating axis).
#[inline]
fn overlap_on(axis: Vec3, v: &[Vec3; 3], h: Vec3) -> Option<Axis> {
    let p = v.map(|x| axis.dot(x));
    let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
    let r = h.dot(axis.abs());
    if lo > r || hi < -r {
        return None;
    }
    // Moving the box along +axis clears the triangle after `hi + r`, along -axis after `r - lo`.
    let (up, down) = (hi + r, r - lo);
    Some(if up <= down {
        Axis {
            normal: axis,
            depth: up,
        }
    } else {
        Axis {
            normal: -axis,
            depth: down,
        }
    })
}

fn keep_shallower(best: &mut Option<Axis>, candidate: Axis) {
    if best.is_none_or(|b| candidate.depth < b.depth) {
        *best = Some(candidate);
    }
}

/// Step 1 and 2 of the module notes: the chosen axis, and whether it is the triangle's normal
/// (always, when `face_only` and the triangle has one: the internal-edge rule).
fn least_penetration_axis(v: &[Vec3; 3], h: Vec3, face_only: bool) -> Option<(Axis, bool)> {
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let on_triangle_normal = match edges[0].cross(edges[1]).try_normalize() {
        Some(n) => Some(overlap_on(n, v, h)?),
        None => None,
    };
    let mut face = on_triangle_normal;
    let mut is_triangle_normal = face.is_some();
    for axis in Vec3::AXES {
        let candidate = overlap_on(axis, v, h)?;
        if face.is_none_or(|b| candidate.depth < b.depth) {
            face = Some(candidate);
            is_triangle_normal = false;
        }
    }
    // Under the internal-edge rule the other axes only separate, never chosen: tested
    // unnormalised (a separating axis separates at any length), no root or division each.
    let separate_only = face_only && on_triangle_normal.is_some();
    let mut edge: Option<Axis> = None;
    for e in edges {
        for axis in Vec3::AXES {
            let cross = axis.cross(e);
            let len2 = cross.length_squared();
            if len2 <= EDGE_AXIS_MIN_SIN2 * e.length_squared() || len2 == 0.0 {
                continue;
            }
            if separate_only {
                overlap_on(cross, v, h)?;
            } else {
                keep_shallower(&mut edge, overlap_on(cross / len2.sqrt(), v, h)?);
            }
        }
    }
    // There is always a face axis: the box's three are never skipped.
    let face = face?;
    if let (true, Some(along)) = (face_only, on_triangle_normal) {
        return Some((along, true));
    }
    let tolerance = SWITCH_ABS_FRACTION * h.max_element();
    match edge {
        Some(e) if e.depth < EDGE_SWITCH_REL * face.depth - tolerance => Some((e, false)),
        _ => Some((face, is_triangle_normal)),
    }
}

/// The contact of triangle `v` with the box `[-h, h]`, both in the box's frame; `active` holds
/// the triangle's active edges (bit `k`: from corner `k` to `k + 1`).
pub(crate) fn triangle_box_contact(
    v: [Vec3; 3],
    active: u8,
    h: Vec3,
) -> Option<TriangleBoxContact> {
    let internal_only =
        (0..3).all(|k| active & (1 << k) == 0 || !edge_reaches(v[k], v[(k + 1) % 3], h));
    let (axis, along_triangle_normal) = least_penetration_axis(&v, h, internal_only)?;
    let n = axis.normal;
    // A clipped point's depth is measured along the normal to the box's face the normal most
    // opposes (the bottom of a box resting on the triangle), not to the box's support plane
    // along the normal (`p·n + h·|n|`): those agree only while that face is square to the
    // normal, and a box resting on a triangle tilted by θ read the deepest corner's depth at
    // every point (wrong by up to θ times its width). On a mesh floor such a box floated on one
    // corner, kept its tilt (no point told the solver which side was high), and rose while it
    // slid with friction.
    let face = n.abs().max_position();
    let (face_cos, face_sign) = (n[face].abs(), n[face].signum());
    let depth_of = |p: Vec3| (h[face] + face_sign * p[face]) / face_cos;
    let mut out = TriangleBoxContact {
        normal: n,
        depth: axis.depth,
        points: [ContactPoint::default(); MAX_TRIANGLE_BOX_POINTS],
        len: 0,
    };

    // The triangle inside the box, each point with its depth past the box's face.
    let scale = v[0].abs().max(v[1].abs()).max(v[2].abs()).max_element() + h.max_element();
    let margin = CLIP_MARGIN_FRACTION * scale;
    let mut polygon = ClipPolygon::<MAX_TRIANGLE_CLIP_VERTICES>::from_corners(&v);
    for (i, e) in Vec3::AXES.into_iter().enumerate() {
        let plane = FIRST_PLANE + 2 * i as u8;
        polygon = polygon
            .clipped(e, h[i] + margin, plane)
            .clipped(-e, h[i] + margin, plane + 1);
    }
    for (p, tag) in polygon.tagged() {
        let depth = depth_of(p);
        let feature = FeatureId::clipped(TRIANGLE_CLIPPED, tag.bits());
        // Where two of the box's planes cross the triangle's plane: the box's own edge.
        let feature = if tag.lines_from(FIRST_PLANE) {
            feature.of_other_alone()
        } else {
            feature
        };
        out.push(p - n * (0.5 * depth), depth, feature);
    }

    // Box corners behind the triangle's plane, inside its outline.
    let top = v.iter().fold(f32::NEG_INFINITY, |m, x| m.max(x.dot(n)));
    if along_triangle_normal {
        let area_normal = Triangle::from(v).scaled_normal();
        for (k, corner) in box_corners(h).into_iter().enumerate() {
            let depth = top - corner.dot(n);
            if depth >= 0.0 && inside_outline(&v, area_normal, corner) {
                let feature = FeatureId::single(BOX_CORNER + k as u32).of_other_alone();
                out.push(corner + n * (0.5 * depth), depth, feature);
            }
        }
    }

    if out.len == 0 {
        // Rounding left no point: the box's deepest corner along the normal.
        let (k, corner) = box_corners(h)
            .into_iter()
            .enumerate()
            .min_by(|a, b| a.1.dot(n).total_cmp(&b.1.dot(n)))
            .unwrap_or((0, Vec3::ZERO));
        let depth = top - corner.dot(n);
        let feature = FeatureId::single(BOX_CORNER + k as u32).of_other_alone();
        out.push(corner + n * (0.5 * depth), depth, feature);
    }
    // Along a box face or an edge axis, the deepest point (the one the merged manifold's
    // reduction takes first) carries the separating depth: a clipped point can fall short of
    // it when the triangle's deepest corner lies outside the box's side. Along the triangle's
    // normal the points are exact (the box's corners over the triangle and the triangle inside
    // the box, each at its own depth), and the separating depth is the box's deepest point
    // below the triangle's *plane*, wherever it is: handed on, a box lying tilted across a
    // floor gave it to a point of every triangle under it. There the triangle's share of the
    // contact (its weight in the mesh's merged normal) is its deepest point's depth.
    if along_triangle_normal {
        out.depth = out
            .points()
            .iter()
            .fold(f32::NEG_INFINITY, |d, p| d.max(p.depth));
    } else if let Some(deepest) = deepest_corner(out.points()) {
        out.points[deepest].depth = axis.depth;
    }
    Some(out)
}

/// True when the segment from `a` to `b` meets the box `[-h, h]` (slab clipping).
fn edge_reaches(a: Vec3, b: Vec3, h: Vec3) -> bool {
    segment_in_box(a, b - a, h).is_some()
}

fn box_corners(h: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|k| {
        let sign = |bit: usize| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
        h * Vec3::new(sign(0), sign(1), sign(2))
    })
}

/// True when `p` projects (along the triangle's normal) inside the closed triangle `v`, whose
/// area vector `(v1 − v0) × (v2 − v0)` is `normal`.
fn inside_outline(v: &[Vec3; 3], normal: Vec3, p: Vec3) -> bool {
    (0..3).all(|k| {
        let (a, b) = (v[k], v[(k + 1) % 3]);
        (b - a).cross(p - a).dot(normal) >= 0.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::intersects_triangle_cuboid;
    use glam::Quat;

    #[test]
    fn a_box_resting_on_a_big_triangle_gets_its_four_corners() {
        let tri = Triangle::new(
            Vec3::new(-10.0, -10.0, 0.0),
            Vec3::new(10.0, -10.0, 0.0),
            Vec3::new(0.0, 10.0, 0.0),
        );
        let cuboid = Cuboid {
            half_extents: Vec3::new(0.5, 0.4, 0.3),
        };
        let pose = Isometry::from_translation(Vec3::new(0.1, -0.2, 0.25));
        let m = contact_triangle_cuboid(&tri, &pose, &cuboid).unwrap();
        assert_eq!(m.normal, Vec3::Z);
        assert_eq!(m.len(), 4);
        assert!((m.max_depth() - 0.05).abs() < 1e-6);
        for p in m.points() {
            assert!((p.depth - 0.05).abs() < 1e-6);
            assert!((p.point.z + 0.025).abs() < 1e-6, "midway: {}", p.point);
        }
        // From below, the box leaves downwards (two-sided).
        let below = Isometry::from_translation(Vec3::new(0.1, -0.2, -0.25));
        let m = contact_triangle_cuboid(&tri, &below, &cuboid).unwrap();
        assert_eq!(m.normal, -Vec3::Z);
        let apart = Isometry::from_translation(Vec3::new(0.1, -0.2, 0.3001));
        assert!(contact_triangle_cuboid(&tri, &apart, &cuboid).is_none());
        let touching = Isometry::from_translation(Vec3::new(0.0, 0.0, 0.5));
        let cube = Cuboid {
            half_extents: Vec3::splat(0.5),
        };
        assert_eq!(
            contact_triangle_cuboid(&tri, &touching, &cube).map(|m| m.max_depth()),
            Some(0.0)
        );
    }

    #[test]
    fn a_spike_into_a_box_face_pushes_along_the_face() {
        // A thin vertical triangle whose tip enters the box's top face by 0.1.
        let tri = Triangle::new(
            Vec3::new(-0.05, 0.0, 2.0),
            Vec3::new(0.05, 0.0, 2.0),
            Vec3::new(0.0, 0.0, 0.9),
        );
        let cube = Cuboid {
            half_extents: Vec3::splat(1.0),
        };
        let m = contact_triangle_cuboid(&tri, &Isometry::IDENTITY, &cube).unwrap();
        assert_eq!(
            m.normal,
            -Vec3::Z,
            "the box moves down, away from the spike"
        );
        assert!((m.max_depth() - 0.1).abs() < 1e-6);
    }

    /// The contact exists exactly when the independent 13-axis overlap test says so, and its
    /// depth is the least overlap along the normal it reports: moving the box by the depth along
    /// the normal (plus a hair) separates them.
    #[test]
    fn agrees_with_the_overlap_test_and_its_depth_separates() {
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let cube = Cuboid {
            half_extents: Vec3::new(0.6, 0.4, 0.8),
        };
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..4000 {
            let tri = Triangle::new(
                Vec3::new(next(), next(), next()) * 1.5,
                Vec3::new(next(), next(), next()) * 1.5,
                Vec3::new(next(), next(), next()) * 1.5,
            );
            let q = Quat::from_xyzw(next(), next(), next(), next() + 1.5).normalize();
            let pose = Isometry::new(Vec3::new(next(), next(), next()), q);
            let contact = contact_triangle_cuboid(&tri, &pose, &cube);
            assert_eq!(
                contact.is_some(),
                intersects_triangle_cuboid(&tri, &pose, &cube)
            );
            let Some(m) = contact else {
                misses += 1;
                continue;
            };
            hits += 1;
            assert!(m.normal.is_normalized() && m.len() <= 4 && !m.is_empty());
            let d = m.max_depth();
            assert!(d >= 0.0 && d.is_finite());
            let moved = Isometry::new(pose.translation + m.normal * (d + 1e-4), q);
            assert!(
                !intersects_triangle_cuboid(&tri, &moved, &cube),
                "depth {d} along {} does not separate",
                m.normal
            );
        }
        assert!(hits > 500 && misses > 500, "{hits} / {misses}");
    }
}
