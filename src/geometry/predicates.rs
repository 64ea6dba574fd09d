//! Exact orientation predicates on `f32` points, and the small incidence tests built from them.
//!
//! The signs come from Shewchuk's adaptive-precision `orient2d`/`orient3d` (Shewchuk 1997,
//! "Adaptive precision floating-point arithmetic and fast robust geometric predicates", through
//! the `robust` crate). Every `f32` converts to `f64` exactly, and for `f32` inputs the
//! intermediate expansions can neither overflow (|values| stay below 2^400) nor underflow (every
//! bit involved is above 2^-450), so **every sign below is exact for every finite input**: a
//! point on a plane gives 0, never a rounding-dependent ±. The magnitudes are only approximate
//! and are used solely as interpolation weights.
//!
//! These are the building blocks of [`tri_tri`](crate::geometry::tri_tri) (Guigue & Devillers
//! 2003) and of the exact degeneracy test of triangles.

use glam::{DVec3, Vec3};
use robust::{Coord, Coord3D};

/// Sign of `x` as -1, 0 or 1 (NaN maps to 0: callers reject non-finite input beforehand).
#[inline]
pub(crate) fn sign(x: f64) -> i8 {
    (x > 0.0) as i8 - (x < 0.0) as i8
}

#[inline]
fn c3(p: Vec3) -> Coord3D<f32> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Guigue & Devillers' `[a, b, c, d]`: the determinant `(d - a) · ((b - a) × (c - a))`, positive
/// when `d` lies on the side of plane `abc` that its normal `(b - a) × (c - a)` points to (where
/// `a, b, c` are seen counter-clockwise). Sign exact; magnitude approximate (six times the
/// signed volume of the tetrahedron).
#[inline]
pub(crate) fn orient3d(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> f64 {
    // `robust` counts "below" as positive, the opposite of the paper's convention.
    -robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// The orientations of many points against one triangle's plane, sharing the work: the cross
/// product `(b - a) × (c - a)` is computed once, and each point costs one dot product.
///
/// This is the floating-point filter of Shewchuk's `orient3d` with the pivot at `a` instead of
/// `d`: the expression has the same shape (a difference vector times the 2×2 minors of two
/// others), so his bound `(7 + 56ε)ε · permanent` certifies the sign whenever the `f64` value
/// exceeds it, and only the rare uncertain cases go to the exact adaptive [`orient3d`].
pub(crate) struct PlaneOrientation {
    corners: [Vec3; 3],
    origin: DVec3,
    normal: DVec3,
    /// Per axis, `|u_j v_k| + |u_k v_j|`: the permanent's factors besides `|w_i|`.
    magnitudes: DVec3,
}

/// Shewchuk's `o3derrboundA`, with `ε = 2^-53`.
const ORIENT3D_ERROR_BOUND: f64 = (7.0 + 56.0 * f64::EPSILON / 2.0) * (f64::EPSILON / 2.0);

impl PlaneOrientation {
    pub(crate) fn new(corners: [Vec3; 3]) -> Self {
        // Element by element rather than `array::map`, which does not always inline.
        let (a, b, c) = (
            corners[0].as_dvec3(),
            corners[1].as_dvec3(),
            corners[2].as_dvec3(),
        );
        let (u, v) = (b - a, c - a);
        let magnitudes = DVec3::new(
            (u.y * v.z).abs() + (u.z * v.y).abs(),
            (u.z * v.x).abs() + (u.x * v.z).abs(),
            (u.x * v.y).abs() + (u.y * v.x).abs(),
        );
        Self {
            corners,
            origin: a,
            normal: u.cross(v),
            magnitudes,
        }
    }

    /// Same value sign as [`orient3d`]`(a, b, c, d)`, exact.
    #[inline]
    pub(crate) fn of(&self, d: Vec3) -> f64 {
        let w = d.as_dvec3() - self.origin;
        let det = w.dot(self.normal);
        let bound = ORIENT3D_ERROR_BOUND * w.abs().dot(self.magnitudes);
        if det > bound || -det > bound {
            det
        } else {
            let [a, b, c] = self.corners;
            orient3d(a, b, c, d)
        }
    }
}

/// The 2D point obtained by dropping coordinate `axis` and keeping the other two in cyclic order
/// (`axis` 0 keeps (y, z), 1 keeps (z, x), 2 keeps (x, y)). With the cyclic order, the 2D
/// orientation of a projected triangle equals the `axis` component of its 3D normal, sign
/// included.
#[inline]
pub(crate) fn project(p: Vec3, axis: usize) -> Coord<f32> {
    match axis {
        0 => Coord { x: p.y, y: p.z },
        1 => Coord { x: p.z, y: p.x },
        _ => Coord { x: p.x, y: p.y },
    }
}

/// `orient2d` of three points projected by dropping `axis`: positive when counter-clockwise.
#[inline]
pub(crate) fn orient2d(a: Coord<f32>, b: Coord<f32>, c: Coord<f32>) -> f64 {
    robust::orient2d(a, b, c)
}

/// The axis whose dropping keeps the triangle's area largest (the dominant component of its
/// normal), or `None` when the three points are exactly collinear (every component is zero).
///
/// Projecting along this axis maps the triangle's plane one-to-one onto 2D, so coplanar
/// questions can be asked in 2D, exactly.
pub(crate) fn projection_axis(a: Vec3, b: Vec3, c: Vec3) -> Option<usize> {
    let mut best = None;
    let mut best_abs = 0.0;
    for axis in 0..3 {
        let area = orient2d(project(a, axis), project(b, axis), project(c, axis)).abs();
        if area > best_abs {
            best_abs = area;
            best = Some(axis);
        }
    }
    best
}

/// True when `a`, `b`, `c` are exactly collinear (including repeated points): the triangle has
/// zero area.
pub(crate) fn collinear(a: Vec3, b: Vec3, c: Vec3) -> bool {
    projection_axis(a, b, c).is_none()
}

/// True when `p` lies in the axis-aligned box of `a` and `b` (used once collinearity is known).
#[inline]
fn in_box_2d(a: Coord<f32>, b: Coord<f32>, p: Coord<f32>) -> bool {
    a.x.min(b.x) <= p.x && p.x <= a.x.max(b.x) && a.y.min(b.y) <= p.y && p.y <= a.y.max(b.y)
}

/// Closed 2D segments `[a, b]` and `[c, d]` share a point. Either segment may be a single point;
/// collinear overlaps count.
pub(crate) fn segments_meet_2d(a: Coord<f32>, b: Coord<f32>, c: Coord<f32>, d: Coord<f32>) -> bool {
    let a_side = sign(orient2d(c, d, a));
    let b_side = sign(orient2d(c, d, b));
    let c_side = sign(orient2d(a, b, c));
    let d_side = sign(orient2d(a, b, d));
    if a_side * b_side < 0 && c_side * d_side < 0 {
        return true;
    }
    (a_side == 0 && in_box_2d(c, d, a))
        || (b_side == 0 && in_box_2d(c, d, b))
        || (c_side == 0 && in_box_2d(a, b, c))
        || (d_side == 0 && in_box_2d(a, b, d))
}

/// `p` lies in the closed 2D triangle `t`, whose orientation sign is `winding` (non-zero).
pub(crate) fn point_in_triangle_2d(p: Coord<f32>, t: [Coord<f32>; 3], winding: i8) -> bool {
    (0..3).all(|i| winding * sign(orient2d(t[i], t[(i + 1) % 3], p)) >= 0)
}

/// The closed segment `[s0, s1]` (possibly a single point) meets the closed, non-degenerate
/// triangle `t`.
pub(crate) fn segment_meets_triangle(s0: Vec3, s1: Vec3, t: [Vec3; 3]) -> bool {
    let [a, b, c] = t;
    let side0 = sign(orient3d(a, b, c, s0));
    let side1 = sign(orient3d(a, b, c, s1));
    if side0 == side1 && side0 != 0 {
        return false;
    }
    if side0 == 0 && side1 == 0 {
        return coplanar_segment_meets_triangle(s0, s1, t);
    }
    // The segment crosses the plane once, so its line is not parallel to it: the line passes
    // through the closed triangle iff it does not pass strictly on both sides of its edges.
    let edges = [
        sign(orient3d(s0, s1, a, b)),
        sign(orient3d(s0, s1, b, c)),
        sign(orient3d(s0, s1, c, a)),
    ];
    !(edges.contains(&1) && edges.contains(&-1))
}

/// A segment lying in the plane of a non-degenerate triangle meets it iff an end lies inside or
/// it meets an edge.
fn coplanar_segment_meets_triangle(s0: Vec3, s1: Vec3, t: [Vec3; 3]) -> bool {
    // A non-degenerate triangle always has an axis; 2 only guards the impossible case.
    let axis = projection_axis(t[0], t[1], t[2]).unwrap_or(2);
    let tri = t.map(|p| project(p, axis));
    let winding = sign(orient2d(tri[0], tri[1], tri[2]));
    let (p0, p1) = (project(s0, axis), project(s1, axis));
    point_in_triangle_2d(p0, tri, winding)
        || point_in_triangle_2d(p1, tri, winding)
        || (0..3).any(|i| segments_meet_2d(p0, p1, tri[i], tri[(i + 1) % 3]))
}

/// Closed 3D segments `[a0, a1]` and `[b0, b1]` share a point (either may be a single point).
pub(crate) fn segments_meet_3d(a0: Vec3, a1: Vec3, b0: Vec3, b1: Vec3) -> bool {
    if sign(orient3d(a0, a1, b0, b1)) != 0 {
        return false;
    }
    let axis = [(a0, a1, b0), (a0, a1, b1), (a0, b0, b1), (a1, b0, b1)]
        .into_iter()
        .find_map(|(p, q, r)| projection_axis(p, q, r))
        .or_else(|| line_projection_axis([a0, a1, b0, b1]));
    match axis {
        Some(axis) => segments_meet_2d(
            project(a0, axis),
            project(a1, axis),
            project(b0, axis),
            project(b1, axis),
        ),
        // All four points coincide.
        None => true,
    }
}

/// For collinear points not all equal, an axis whose dropping keeps the line a line (it drops a
/// coordinate other than one along which two of the points differ); `None` if all coincide.
fn line_projection_axis(points: [Vec3; 4]) -> Option<usize> {
    let first = points[0];
    let other = points.iter().find(|&&p| p != first)?;
    let d = (*other - first).abs();
    let varying = if d.x > 0.0 {
        0
    } else if d.y > 0.0 {
        1
    } else {
        2
    };
    Some((varying + 1) % 3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orient3d_follows_the_paper_convention() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        assert!(orient3d(a, b, c, Vec3::Z) > 0.0);
        assert!(orient3d(a, b, c, -Vec3::Z) < 0.0);
        assert_eq!(orient3d(a, b, c, Vec3::new(0.3, 7.0, 0.0)), 0.0);
    }

    /// Exact reference: integer coordinates below 2^24 (exact in f32) make the determinant an exact i128.
    fn exact_orient3d(p: [[i64; 3]; 4]) -> i128 {
        let d = |i: usize, k: usize| (p[i][k] - p[0][k]) as i128;
        let (b, c, e) = (1, 2, 3);
        let cross = [
            d(b, 1) * d(c, 2) - d(b, 2) * d(c, 1),
            d(b, 2) * d(c, 0) - d(b, 0) * d(c, 2),
            d(b, 0) * d(c, 1) - d(b, 1) * d(c, 0),
        ];
        d(e, 0) * cross[0] + d(e, 1) * cross[1] + d(e, 2) * cross[2]
    }

    #[test]
    fn signs_match_exact_integer_arithmetic_on_nearly_coplanar_points() {
        // Points on a plane through large coordinates, nudged by one unit: a naive f64
        // evaluation of these ~2^66 determinants cannot tell 0 from ±1.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |range: i64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % (2 * range as u64 + 1)) as i64 - range
        };
        let to_vec = |p: [i64; 3]| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        for _ in 0..2000 {
            let a = [next(1 << 21), next(1 << 21), next(1 << 21)];
            let u = [next(1 << 20), next(1 << 20), next(1 << 20)];
            let v = [next(1 << 20), next(1 << 20), next(1 << 20)];
            let b = [a[0] + u[0], a[1] + u[1], a[2] + u[2]];
            let c = [a[0] + v[0], a[1] + v[1], a[2] + v[2]];
            let (s, t, nudge) = (next(3), next(3), next(1));
            let d = [
                a[0] + s * u[0] + t * v[0],
                a[1] + s * u[1] + t * v[1],
                a[2] + s * u[2] + t * v[2] + nudge,
            ];
            let exact = exact_orient3d([a, b, c, d]).signum() as i8;
            let got = sign(orient3d(to_vec(a), to_vec(b), to_vec(c), to_vec(d)));
            assert_eq!(got, exact, "{a:?} {b:?} {c:?} {d:?}");
        }
    }

    #[test]
    fn the_shared_plane_filter_gives_the_exact_signs() {
        let mut seed = 0x0123_4567_89ab_cdefu64;
        let mut unit = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        };
        for i in 0..20_000 {
            let mut v = || Vec3::new(unit(), unit(), unit()) * 1000.0;
            let (a, b, c) = (v(), v(), v());
            // Half the points on the plane up to rounding, where the filter must defer.
            let d = if i % 2 == 0 {
                a + (b - a) * 0.37 + (c - a) * 0.21
            } else {
                v()
            };
            let plane = PlaneOrientation::new([a, b, c]);
            assert_eq!(
                sign(plane.of(d)),
                sign(orient3d(a, b, c, d)),
                "{a} {b} {c} {d}"
            );
            assert_eq!(sign(plane.of(a)), 0);
        }
    }

    #[test]
    fn collinearity_and_projection_axes() {
        assert!(collinear(Vec3::ZERO, Vec3::ONE, Vec3::splat(2.0)));
        assert!(collinear(Vec3::ONE, Vec3::ONE, Vec3::Z));
        assert!(!collinear(
            Vec3::ZERO,
            Vec3::ONE,
            Vec3::new(2.0, 2.0, 2.0f32.next_up())
        ));
        assert_eq!(projection_axis(Vec3::ZERO, Vec3::X, Vec3::Y), Some(2));
        assert_eq!(projection_axis(Vec3::ZERO, Vec3::Y, Vec3::Z), Some(0));
    }

    #[test]
    fn segments_in_3d_touching_crossing_collinear_and_points() {
        let o = Vec3::ZERO;
        assert!(segments_meet_3d(
            o,
            Vec3::X,
            Vec3::new(0.5, -1.0, 0.0),
            Vec3::new(0.5, 1.0, 0.0)
        ));
        assert!(!segments_meet_3d(
            o,
            Vec3::X,
            Vec3::new(0.5, -1.0, 0.1),
            Vec3::new(0.5, 1.0, 0.1)
        ));
        assert!(segments_meet_3d(
            o,
            Vec3::X,
            Vec3::X,
            Vec3::new(3.0, 0.0, 0.0)
        ));
        assert!(!segments_meet_3d(
            o,
            Vec3::X,
            Vec3::new(1.5, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0)
        ));
        assert!(segments_meet_3d(Vec3::Z, Vec3::Z, o, Vec3::Z * 2.0));
        assert!(!segments_meet_3d(Vec3::Z, Vec3::Z, Vec3::X, Vec3::X));
        assert!(segments_meet_3d(Vec3::Z, Vec3::Z, Vec3::Z, Vec3::Z));
    }

    #[test]
    fn segment_and_triangle() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let through = (Vec3::new(0.2, 0.2, -1.0), Vec3::new(0.2, 0.2, 1.0));
        assert!(segment_meets_triangle(through.0, through.1, t));
        assert!(segment_meets_triangle(
            Vec3::new(0.5, 0.5, -1.0),
            Vec3::new(0.5, 0.5, 1.0),
            t
        ));
        assert!(!segment_meets_triangle(
            Vec3::new(0.6, 0.5, -1.0),
            Vec3::new(0.6, 0.5, 1.0),
            t
        ));
        assert!(segment_meets_triangle(
            Vec3::new(-1.0, 0.5, 0.0),
            Vec3::new(2.0, 0.5, 0.0),
            t
        ));
        assert!(!segment_meets_triangle(
            Vec3::new(-1.0, 2.5, 0.0),
            Vec3::new(2.0, 2.5, 0.0),
            t
        ));
        assert!(segment_meets_triangle(
            Vec3::new(0.1, 0.1, 0.0),
            Vec3::new(0.1, 0.1, 0.0),
            t
        ));
    }
}
