//! Sweep against a triangle (a two-sided surface): the centre's segment against the triangle
//! inflated by the radius, which is the union of
//!
//! 1. the **face prism**: the triangle moved by `±r` along its normal, entered through the face on
//!    the centre's side at a point whose projection lies in the triangle;
//! 2. three **edge cylinders** of radius `r` (their sides: see `swept_point.rs`);
//! 3. three **vertex balls** of radius `r`
//!
//! (Ericson 2005, §5.5.6 and §5.3.6). The earliest entry over these pieces, in this order, is the
//! impact; a face entry needs no comparison, since a segment entering through the face was
//! farther than `r` from the whole plane (so from every edge and vertex) until then. A zero-area
//! triangle has no face and collides as its edges.
//!
//! The face-inside test accepts points within the sweep's slack of the triangle, so that a ray
//! (radius 0, where the edge cylinders are lines) through an edge shared by two triangles of a
//! mesh hits one of them instead of slipping between.

use super::sweep::fallback_normal_for;
use super::swept_point::{Earliest, Piece, PieceHit, ball_entry, cylinder_entry, segment_in_box};
use super::{SphereSweep, Toi};
use crate::geometry::{ContactManifold, Sphere, Triangle, contact_triangle_sphere};
use glam::Vec3;

/// Time of impact of the sweep against the (static) triangle.
pub fn toi_sphere_triangle(sweep: &SphereSweep, tri: &Triangle) -> Option<Toi> {
    let centre = SweptCentre::of(sweep);
    if let Some(m) = centre.start_contact(tri) {
        return sweep.initial_contact(m.normal, m.points()[0].point);
    }
    let hit = centre.triangle_entry(tri, 1.0)?;
    Some(sweep.impact(hit.t, hit.normal))
}

/// What the piece tests need of a sweep, computed once per query (a mesh query reuses it for
/// every triangle).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SweptCentre {
    origin: Vec3,
    displacement: Vec3,
    radius: f32,
    slack: f32,
}

impl SweptCentre {
    pub(crate) fn of(sweep: &SphereSweep) -> Self {
        Self {
            origin: sweep.center(),
            displacement: sweep.displacement(),
            radius: sweep.radius(),
            slack: sweep.slack(),
        }
    }

    /// The static contact at the start (the triangle as shape A, so the normal runs from it to
    /// the sphere), skipping the closest-point computation when the start is clearly apart.
    pub(crate) fn start_contact(&self, tri: &Triangle) -> Option<ContactManifold> {
        let near = tri.aabb().expanded(self.radius + self.slack);
        if !near.contains_point(self.origin) {
            return None;
        }
        contact_triangle_sphere(
            tri,
            self.origin,
            &Sphere {
                radius: self.radius,
            },
        )
    }

    /// First entry into the inflated triangle at or before `t_max`, for a centre that starts
    /// outside it.
    pub(crate) fn triangle_entry(&self, tri: &Triangle, t_max: f32) -> Option<PieceHit> {
        let (o, d, r) = (self.origin, self.displacement, self.radius);
        // Cheap rejection: the segment misses the triangle's box grown by the radius.
        let reach = tri.aabb().expanded(r + self.slack);
        segment_in_box(o - reach.center(), d, reach.half_extents())?;
        let normal = tri.normal();
        if let Some(n) = normal {
            // A segment crosses the face's offset plane once, and before that it is farther
            // than r from the whole plane, hence from every edge and vertex: a face entry is
            // the first.
            if let Some(hit) = self.face_entry(tri, n) {
                return (hit.t <= t_max).then_some(hit);
            }
            // Never within r of the plane: never within r of the triangle.
            let (h0, h1) = (n.dot(o - tri.a), n.dot(o + d - tri.a));
            let band = r + self.slack;
            if (h0 > band && h1 > band) || (h0 < -band && h1 < -band) {
                return None;
            }
        }
        let mut earliest = Earliest::before(t_max);
        for (p, q) in [(tri.a, tri.b), (tri.b, tri.c), (tri.c, tri.a)] {
            let edge = q - p;
            if edge != Vec3::ZERO {
                let t = cylinder_entry(o - p, d, edge, r);
                earliest.consider(t, Piece::Edge { start: p, edge });
            }
        }
        for v in tri.vertices() {
            earliest.consider(ball_entry(o - v, d, r), Piece::Vertex(v));
        }
        earliest.hit(o, d, || fallback_normal_for(d))
    }

    /// Entry through the face on the centre's side, `n` the unit front normal.
    fn face_entry(&self, tri: &Triangle, n: Vec3) -> Option<PieceHit> {
        let (o, d, r) = (self.origin, self.displacement, self.radius);
        let height = n.dot(o - tri.a);
        let rate = n.dot(d);
        if height.abs() <= r {
            // Within the slab already: only rounding keeps the static test from calling it a
            // contact, so it is one if the centre is over the triangle and moving in.
            let side = if height != 0.0 {
                height.signum()
            } else {
                -rate.signum()
            };
            let inward = side * rate < 0.0;
            return (inward && self.over_triangle(tri, n, o)).then_some(PieceHit {
                t: 0.0,
                normal: n * side,
                on_face: true,
            });
        }
        let side = height.signum();
        let closing = -side * rate;
        if closing.is_nan() || closing <= 0.0 {
            return None;
        }
        let t = (height.abs() - r) / closing;
        if t.is_nan() || t > 1.0 {
            return None;
        }
        self.over_triangle(tri, n, o + d * t).then_some(PieceHit {
            t,
            normal: n * side,
            on_face: true,
        })
    }

    /// True when `p` projects into the triangle (closed, grown by the slack): on the inner side
    /// of each edge line within the plane.
    fn over_triangle(&self, tri: &Triangle, n: Vec3, p: Vec3) -> bool {
        [(tri.a, tri.b), (tri.b, tri.c), (tri.c, tri.a)]
            .into_iter()
            .all(|(s, e)| {
                let edge = e - s;
                n.dot(edge.cross(p - s)) >= -self.slack * edge.length()
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ccd::InitialOverlap;
    use crate::geometry::contacts::FALLBACK_NORMAL;

    fn unit() -> Triangle {
        Triangle::new(Vec3::ZERO, Vec3::X * 2.0, Vec3::Y * 2.0)
    }

    fn sweep(c: Vec3, r: f32, d: Vec3) -> SphereSweep {
        SphereSweep::new(c, r, d).unwrap()
    }

    #[test]
    fn face_from_both_sides_edge_and_vertex() {
        let top = toi_sphere_triangle(
            &sweep(Vec3::new(0.5, 0.5, 3.0), 0.5, -Vec3::Z * 5.0),
            &unit(),
        );
        let top = top.unwrap();
        assert!((top.t - 0.5).abs() < 1e-6 && top.normal == Vec3::Z);
        assert!((top.point - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
        let below = toi_sphere_triangle(
            &sweep(Vec3::new(0.5, 0.5, -3.0), 0.5, Vec3::Z * 5.0),
            &unit(),
        );
        let below = below.unwrap();
        assert!((below.t - 0.5).abs() < 1e-6 && below.normal == -Vec3::Z);
        // Edge: in the plane, toward the edge y = 0 from below.
        let edge = toi_sphere_triangle(
            &sweep(Vec3::new(1.0, -3.0, 0.0), 0.5, Vec3::Y * 5.0),
            &unit(),
        );
        let edge = edge.unwrap();
        assert!((edge.t - 0.5).abs() < 1e-6 && (edge.normal + Vec3::Y).length() < 1e-6);
        // Vertex: along the diagonal toward the corner at the origin.
        let dir = Vec3::new(1.0, 1.0, 1.0).normalize();
        let vertex = toi_sphere_triangle(&sweep(-dir * 3.0, 0.5, dir * 5.0), &unit()).unwrap();
        assert!((vertex.t - 0.5).abs() < 1e-6 && (vertex.normal + dir).length() < 1e-6);
    }

    #[test]
    fn grazing_parallel_and_starting_in_contact() {
        // Parallel to the face at exactly r: touches from where it first reaches the triangle's
        // edge x = 0 (the sphere centre over the triangle is at distance r).
        let graze = sweep(Vec3::new(-3.0, 0.5, 0.5), 0.5, Vec3::X * 4.0);
        let toi = toi_sphere_triangle(&graze, &unit()).unwrap();
        assert_eq!(toi.t, 0.75);
        assert_eq!(toi.normal, Vec3::Z);
        let above = sweep(Vec3::new(-3.0, 0.5, 0.5f32.next_up()), 0.5, Vec3::X * 4.0);
        assert!(toi_sphere_triangle(&above, &unit()).is_none());
        let resting = sweep(Vec3::new(0.5, 0.5, 0.5), 0.5, Vec3::X);
        let toi = toi_sphere_triangle(&resting, &unit()).unwrap();
        assert_eq!((toi.t, toi.normal), (0.0, Vec3::Z));
        let sliding = resting.with_initial_overlap(InitialOverlap::ApproachingOnly);
        assert!(toi_sphere_triangle(&sliding, &unit()).is_none());
    }

    #[test]
    fn a_ray_through_a_shared_edge_hits_one_of_the_two_triangles() {
        // The square [0, 2]² split along its diagonal; rays aimed exactly at diagonal points.
        let a = Triangle::new(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
        );
        let b = Triangle::new(
            Vec3::ZERO,
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        );
        for i in 1..100 {
            let s = i as f32 / 50.0;
            let start = Vec3::new(s, s, 0.0) + Vec3::new(0.3, -0.7, 1.0) * 3.0;
            let ray = sweep(start, 0.0, Vec3::new(0.3, -0.7, 1.0) * -4.0);
            let hit = toi_sphere_triangle(&ray, &a).or(toi_sphere_triangle(&ray, &b));
            assert!(hit.is_some_and(|h| (h.t - 0.75).abs() < 1e-5), "s = {s}");
        }
    }

    #[test]
    fn degenerate_triangles_collide_as_their_edges() {
        let segment = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        let toi = toi_sphere_triangle(
            &sweep(Vec3::new(1.0, 0.0, 3.0), 0.5, -Vec3::Z * 5.0),
            &segment,
        );
        let toi = toi.unwrap();
        assert!((toi.t - 0.5).abs() < 1e-6 && (toi.normal - Vec3::Z).length() < 1e-6);
        let point = Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE);
        let toi = toi_sphere_triangle(
            &sweep(Vec3::new(1.0, 1.0, 4.0), 1.0, -Vec3::Z * 4.0),
            &point,
        );
        assert!((toi.unwrap().t - 0.5).abs() < 1e-6);
        // A point-ray dead on a point-triangle: no surface normal, the fallback is used.
        let toi = toi_sphere_triangle(&sweep(Vec3::new(1.0, 1.0, 4.0), 0.0, Vec3::ZERO), &point);
        assert!(toi.is_none());
        let toi = toi_sphere_triangle(&sweep(Vec3::ONE, 0.0, Vec3::ZERO), &point).unwrap();
        assert_eq!((toi.t, toi.normal), (0.0, FALLBACK_NORMAL));
    }
}
