//! A triangle in space and its primitive queries: closest point (Ericson 2005, "Real-Time
//! Collision Detection" §5.1.5), contact with a sphere, overlap with an oriented box (the
//! 13-axis separating-axis test of Akenine-Möller 2001, "Fast 3D triangle-box overlap testing")
//! and contact with a half-space.
//!
//! Triangles are **two-sided surfaces**, as the meshes they come from (we collide surfaces, not
//! volumes): contact normals point from the triangle towards the other shape on whichever side
//! it is. Where the geometry defines no direction (a sphere centre exactly on the triangle) the
//! triangle's front normal is used, and for a zero-area triangle
//! [`FALLBACK_NORMAL`](crate::geometry::contacts::FALLBACK_NORMAL): never NaN.
//!
//! Triangle–triangle intersection lives in [`tri_tri`](crate::geometry::tri_tri).

use crate::bounding::Aabb;
use crate::geometry::active_edges::{ALL_EDGES_ACTIVE, face_normal_at_inactive_edge};
use crate::geometry::contacts::FALLBACK_NORMAL;
use crate::geometry::predicates::collinear;
use crate::geometry::{
    ContactManifold, ContactPoint, Cuboid, FeatureId, HalfSpace, Isometry, Sphere,
};
use glam::{DVec3, Vec3};

/// A triangle given by its three corners; `a, b, c` counter-clockwise seen from the front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// First corner.
    pub a: Vec3,
    /// Second corner.
    pub b: Vec3,
    /// Third corner.
    pub c: Vec3,
}

impl From<[Vec3; 3]> for Triangle {
    fn from([a, b, c]: [Vec3; 3]) -> Self {
        Self { a, b, c }
    }
}

impl Triangle {
    /// A triangle from its corners.
    pub const fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        Self { a, b, c }
    }

    /// The corners as an array.
    pub fn vertices(&self) -> [Vec3; 3] {
        [self.a, self.b, self.c]
    }

    /// `(b - a) × (c - a)`: front-facing, twice the area long, zero for degenerate triangles.
    pub fn scaled_normal(&self) -> Vec3 {
        (self.b - self.a).cross(self.c - self.a)
    }

    /// The unit front normal, or `None` when the triangle has no usable normal (zero area, or a
    /// normal too small or too large to normalise in `f32`).
    pub fn normal(&self) -> Option<Vec3> {
        let [a, b, c] = self.vertices().map(Vec3::as_dvec3);
        (b - a).cross(c - a).try_normalize().map(DVec3::as_vec3)
    }

    /// Area, computed in `f64` so that no finite input overflows.
    pub fn area(&self) -> f32 {
        let [a, b, c] = self.vertices().map(Vec3::as_dvec3);
        (0.5 * (b - a).cross(c - a).length()) as f32
    }

    /// The mean of the corners.
    pub fn centroid(&self) -> Vec3 {
        (self.a + self.b + self.c) / 3.0
    }

    /// The smallest box holding the triangle.
    pub fn aabb(&self) -> Aabb {
        Aabb::new(
            self.a.min(self.b).min(self.c),
            self.a.max(self.b).max(self.c),
        )
    }

    /// True when no coordinate is NaN or infinite.
    pub fn is_finite(&self) -> bool {
        self.a.is_finite() && self.b.is_finite() && self.c.is_finite()
    }

    /// True when the corners are exactly collinear (repeated corners included): the triangle has
    /// zero area and is really a segment or a point. Decided with exact predicates, so a thin
    /// but genuine sliver is *not* degenerate.
    pub fn is_degenerate(&self) -> bool {
        collinear(self.a, self.b, self.c)
    }

    /// The triangle moved by `pose`. Written out, not `vertices().map(..)`: in the mesh
    /// queries' per-triangle closures the array map's closure may stay out of line (a box on a
    /// terrain spent 8 % of its query calling it).
    #[must_use]
    #[inline]
    pub fn transformed(&self, pose: &Isometry) -> Triangle {
        Triangle {
            a: pose.transform_point(self.a),
            b: pose.transform_point(self.b),
            c: pose.transform_point(self.c),
        }
    }

    /// The point of the (closed) triangle nearest to `p` (Ericson 2005, §5.1.5: find the Voronoi
    /// region of `p` — a corner, an edge or the face — with dot products, then project).
    ///
    /// Computed in `f64`, so no finite input overflows; a degenerate triangle gives the nearest
    /// point of its edges.
    pub fn closest_point(&self, p: Vec3) -> Vec3 {
        let [a, b, c] = self.vertices().map(Vec3::as_dvec3);
        closest_point_f64(a, b, c, p.as_dvec3()).as_vec3()
    }
}

/// `num / den` clamped to `[0, 1]`, and 0 when `den` is not positive (a zero-length edge).
#[inline]
fn ratio(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        (num / den).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Ericson's region walk (variable names follow the book: `d1..d6` are the dot products of the
/// edges with the vectors to `p`, `va, vb, vc` the unnormalised barycentrics).
fn closest_point_f64(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> DVec3 {
    let (ab, ac) = (b - a, c - a);
    let ap = p - a;
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * ratio(d1, d1 - d3);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * ratio(d2, d2 - d6);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ratio(d4 - d3, (d4 - d3) + (d5 - d6));
    }
    let sum = va + vb + vc;
    if sum > 0.0 {
        return a + ab * (vb / sum) + ac * (vc / sum);
    }
    // Only a zero-area triangle gets here (the sum is |ab × ac|²): it is its edges.
    [(a, b), (b, c), (c, a)]
        .map(|(s, t)| closest_on_segment(s, t, p))
        .into_iter()
        .min_by(|x, y| {
            (*x - p)
                .length_squared()
                .total_cmp(&(*y - p).length_squared())
        })
        .unwrap_or(a)
}

fn closest_on_segment(s: DVec3, t: DVec3, p: DVec3) -> DVec3 {
    let d = t - s;
    s + d * ratio((p - s).dot(d), d.length_squared())
}

/// Contact between a triangle (shape A) and a sphere centred at `center` (shape B).
///
/// The normal points from the closest point of the triangle to the centre, `depth = r - dist`;
/// with the centre exactly on the triangle it is the front normal (see the module notes).
pub fn contact_triangle_sphere(
    tri: &Triangle,
    center: Vec3,
    sphere: &Sphere,
) -> Option<ContactManifold> {
    contact_triangle_sphere_with_edges(tri, ALL_EDGES_ACTIVE, center, sphere)
}

/// [`contact_triangle_sphere`] for a triangle of a mesh whose `active` edges are known
/// ([`MeshCollider::active_edges`](crate::geometry::MeshCollider::active_edges)): a closest
/// point only on inactive edges takes the face normal, and the depth is measured along it (see
/// [`active_edges`](crate::geometry::active_edges)).
pub fn contact_triangle_sphere_with_edges(
    tri: &Triangle,
    active: u8,
    center: Vec3,
    sphere: &Sphere,
) -> Option<ContactManifold> {
    let closest = tri.closest_point(center);
    let offset = center - closest;
    let dist2 = offset.length_squared();
    if dist2.is_nan() || dist2 > sphere.radius * sphere.radius {
        return None;
    }
    let normal = offset
        .try_normalize()
        .or_else(|| tri.normal())
        .unwrap_or(FALLBACK_NORMAL);
    let (normal, closest) = match face_normal_at_inactive_edge(tri, active, closest, normal) {
        // The flat surface continues past the inactive edge: it supports the ball right under
        // its centre, not at the edge (a point off to the side would roll the ball).
        Some(face) => (face, center - face * offset.dot(face)),
        None => (normal, closest),
    };
    let on_sphere = center - normal * sphere.radius;
    Some(ContactManifold::single(
        normal,
        (closest + on_sphere) * 0.5,
        (sphere.radius - offset.dot(normal)).max(0.0),
    ))
}

/// True when the triangle and the box of `cuboid` placed at `pose` share a point (touching
/// counts). The triangle is brought into the box frame and tested by [`triangle_box_overlap`].
pub fn intersects_triangle_cuboid(tri: &Triangle, pose: &Isometry, cuboid: &Cuboid) -> bool {
    let local = tri.vertices().map(|p| pose.inverse_transform_point(p));
    triangle_box_overlap(local, cuboid.half_extents)
}

/// True when the triangle and the axis-aligned box share a point (touching counts): the same
/// test with an unrotated box, as BVH leaves and grid cells need it.
pub fn intersects_triangle_aabb(tri: &Triangle, aabb: &Aabb) -> bool {
    let center = aabb.center();
    triangle_box_overlap(tri.vertices().map(|p| p - center), aabb.half_extents())
}

/// Separating-axis test of a triangle against the box `[-h, h]` (Akenine-Möller 2001): the
/// convex sets are disjoint iff their projections are disjoint on one of 13 axes — the 3 box
/// face normals, the triangle normal, and the 9 cross products of a box axis with a triangle
/// edge. Zero axes (a degenerate edge, an edge parallel to a box axis) project everything to 0
/// and never separate, so degenerate triangles are tested as the segment or point they are.
pub fn triangle_box_overlap(v: [Vec3; 3], h: Vec3) -> bool {
    // Box faces: the triangle's bounding box against the box.
    let (lo, hi) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
    if lo.cmpgt(h).any() || hi.cmplt(-h).any() {
        return false;
    }
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let normal = edges[0].cross(edges[1]);
    if separates(normal, v, h) {
        return false;
    }
    for edge in edges {
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            if separates(axis.cross(edge), v, h) {
                return false;
            }
        }
    }
    true
}

/// The projections of the triangle and of the box `[-h, h]` on `axis` are disjoint.
#[inline]
fn separates(axis: Vec3, v: [Vec3; 3], h: Vec3) -> bool {
    let p = v.map(|x| axis.dot(x));
    let radius = h.dot(axis.abs());
    p[0].min(p[1]).min(p[2]) > radius || p[0].max(p[1]).max(p[2]) < -radius
}

/// Contact between a triangle (shape A) and the half-space `h` placed at `pose` (shape B).
///
/// Every corner on or below the plane becomes a contact point (up to 3) with its own depth, so a
/// triangle lying on the ground rests on all its corners; the manifold's
/// [`max_depth`](ContactManifold::max_depth) is the depth of the deepest corner. The normal is
/// the plane's inward normal, as in the sphere–half-space test.
pub fn contact_triangle_halfspace(
    tri: &Triangle,
    pose: &Isometry,
    h: &HalfSpace,
) -> Option<ContactManifold> {
    let n = pose.transform_vector(h.normal);
    let mut manifold = ContactManifold::new(-n);
    for (k, corner) in tri.vertices().into_iter().enumerate() {
        let signed_distance = n.dot(corner - pose.translation);
        if signed_distance <= 0.0 {
            manifold.push(ContactPoint {
                point: corner - n * (0.5 * signed_distance),
                depth: -signed_distance,
                feature: FeatureId::single(1 + k as u32),
            });
        }
    }
    (!manifold.is_empty()).then_some(manifold)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn unit() -> Triangle {
        Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)
    }

    #[test]
    fn closest_point_in_every_region() {
        let t = unit();
        let cases = [
            (Vec3::new(-1.0, -1.0, 3.0), Vec3::ZERO),
            (Vec3::new(2.0, -0.5, 1.0), Vec3::X),
            (Vec3::new(-0.2, 5.0, 0.0), Vec3::Y),
            (Vec3::new(0.5, -2.0, 1.0), Vec3::new(0.5, 0.0, 0.0)),
            (Vec3::new(-3.0, 0.25, 1.0), Vec3::new(0.0, 0.25, 0.0)),
            (Vec3::new(1.0, 1.0, -2.0), Vec3::new(0.5, 0.5, 0.0)),
            (Vec3::new(0.2, 0.3, -7.0), Vec3::new(0.2, 0.3, 0.0)),
        ];
        for (p, expected) in cases {
            assert!((t.closest_point(p) - expected).length() < 1e-6, "{p}");
        }
    }

    #[test]
    fn degenerate_triangles_give_finite_closest_points() {
        let segment = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        assert!((segment.closest_point(Vec3::new(1.5, 1.0, 0.0)) - Vec3::X * 1.5).length() < 1e-6);
        let point = Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE);
        assert_eq!(point.closest_point(Vec3::ZERO), Vec3::ONE);
        assert!(point.normal().is_none() && point.is_degenerate());
        let huge = Triangle::new(
            Vec3::splat(-3e38),
            Vec3::new(3e38, -3e38, 0.0),
            Vec3::splat(3e38),
        );
        assert!(huge.closest_point(Vec3::new(1e38, 0.0, 5e37)).is_finite());
    }

    #[test]
    fn sphere_contact_on_the_face_the_edge_and_exactly_on_the_surface() {
        let t = unit();
        let s = Sphere { radius: 0.5 };
        let m = contact_triangle_sphere(&t, Vec3::new(0.2, 0.2, 0.3), &s).unwrap();
        assert!((m.normal - Vec3::Z).length() < 1e-6);
        assert!((m.max_depth() - 0.2).abs() < 1e-6);
        let below = contact_triangle_sphere(&t, Vec3::new(0.2, 0.2, -0.3), &s).unwrap();
        assert!((below.normal + Vec3::Z).length() < 1e-6, "two-sided");
        let edge = contact_triangle_sphere(&t, Vec3::new(0.5, -0.4, 0.0), &s).unwrap();
        assert!((edge.normal + Vec3::Y).length() < 1e-6);
        assert!((edge.points()[0].point - Vec3::new(0.5, 0.05, 0.0)).length() < 1e-6);
        let on = contact_triangle_sphere(&t, Vec3::new(0.1, 0.1, 0.0), &s).unwrap();
        assert_eq!(on.normal, Vec3::Z);
        assert_eq!(on.max_depth(), 0.5);
        assert!(contact_triangle_sphere(&t, Vec3::new(0.2, 0.2, 0.51), &s).is_none());
        let touching = contact_triangle_sphere(&t, Vec3::new(0.25, 0.25, 0.5), &s).unwrap();
        assert_eq!(touching.max_depth(), 0.0);
        let point = Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE);
        let m = contact_triangle_sphere(&point, Vec3::ONE, &s).unwrap();
        assert_eq!(m.normal, FALLBACK_NORMAL);
    }

    #[test]
    fn box_overlap_needs_the_edge_axes() {
        let h = Vec3::splat(1.0);
        // The triangle rises away from the box's vertical edge at x = y = 1, its lower edge
        // running along x + y = 2.1: the face axes and the triangle normal all overlap, only the
        // axis z × edge = (-1, -1, 0) separates.
        let t = [
            Vec3::new(2.6, -0.5, 0.0),
            Vec3::new(-0.5, 2.6, 0.0),
            Vec3::new(3.0, 3.0, 5.0),
        ];
        let pushed_in = t.map(|p| p - Vec3::new(0.2, 0.2, 0.0));
        assert!(!triangle_box_overlap(t, h));
        assert!(triangle_box_overlap(pushed_in, h));
        let n = Triangle::from(t).scaled_normal();
        assert!(!separates(n, t, h), "the normal alone does not separate");
        let touching_face = [
            Vec3::new(1.0, -5.0, -5.0),
            Vec3::new(1.0, 5.0, -5.0),
            Vec3::new(1.0, 0.0, 5.0),
        ];
        assert!(triangle_box_overlap(touching_face, h));
        let beyond = touching_face.map(|p| p + Vec3::X * 1e-6);
        assert!(!triangle_box_overlap(beyond, h));
    }

    #[test]
    fn oriented_box_and_aabb_agree_on_an_axis_aligned_pose() {
        let t = Triangle::new(
            Vec3::new(2.2, 0.0, 0.0),
            Vec3::new(2.2, 1.0, 0.0),
            Vec3::new(3.0, 0.0, 1.0),
        );
        let cuboid = Cuboid {
            half_extents: Vec3::ONE,
        };
        let near = Isometry::from_translation(Vec3::new(1.5, 0.0, 0.0));
        let far = Isometry::from_translation(Vec3::new(1.1, 0.0, 0.0));
        assert!(intersects_triangle_cuboid(&t, &near, &cuboid));
        assert!(!intersects_triangle_cuboid(&t, &far, &cuboid));
        let aabb = Aabb::from_center_half_extents(Vec3::new(1.5, 0.0, 0.0), Vec3::ONE);
        assert!(intersects_triangle_aabb(&t, &aabb));
        // Turning the far box by 45° about z brings its corner to x = 1.1 + √2 > 2.2.
        let turned = Isometry::new(
            far.translation,
            Quat::from_rotation_z(std::f32::consts::FRAC_PI_4),
        );
        assert!(intersects_triangle_cuboid(&t, &turned, &cuboid));
    }

    #[test]
    fn half_space_reports_every_corner_below() {
        let ground = HalfSpace { normal: Vec3::Z };
        let t = Triangle::new(
            Vec3::new(0.0, 0.0, -0.2),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.3),
        );
        let m = contact_triangle_halfspace(&t, &Isometry::IDENTITY, &ground).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m.normal, -Vec3::Z);
        assert!((m.max_depth() - 0.2).abs() < 1e-6);
        assert!((m.points()[0].point - Vec3::new(0.0, 0.0, -0.1)).length() < 1e-6);
        let lifted = Isometry::from_translation(Vec3::new(0.0, 0.0, -0.25));
        assert!(contact_triangle_halfspace(&t, &lifted, &ground).is_none());
    }

    #[test]
    fn area_normal_and_degeneracy() {
        let t = Triangle::new(Vec3::ZERO, Vec3::X * 2.0, Vec3::Y * 3.0);
        assert!((t.area() - 3.0).abs() < 1e-6);
        assert_eq!(t.normal(), Some(Vec3::Z));
        let sliver = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::new(0.5, 1e-30, 0.0));
        assert!(!sliver.is_degenerate());
        assert!(Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 7.0).is_degenerate());
    }
}
