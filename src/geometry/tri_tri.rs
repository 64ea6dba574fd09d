//! Triangle–triangle intersection (Guigue & Devillers 2003, "Fast and robust triangle-triangle
//! overlap test using orientation predicates"), decided with exact predicates.
//!
//! The slides' narrow phase ends in polygon-pair tests (`Ns * Cs` in the cost model): this is that
//! test for triangle meshes. Guigue & Devillers use nothing but the signs of 3×3 determinants
//! (orientations), which urto's internal `predicates` module evaluates **exactly** for
//! any finite `f32` input. So shared vertices, shared edges, a vertex on a face, crossing edges,
//! coplanar overlaps and one-ulp gaps are all decided exactly on the given coordinates.
//!
//! The algorithm:
//! 1. If the corners of one triangle lie strictly on one side of the other's plane, they are
//!    disjoint (two tests of three orientations each).
//! 2. Otherwise each triangle is rotated (a circular permutation keeps its orientation) so that
//!    its first corner is alone on its side of the other plane, and the other triangle is
//!    mirrored (two corners swapped) if needed to make that side the positive one.
//! 3. Both triangles then cut the line `L` where the planes meet in intervals, and those overlap
//!    iff two more orientations are `<= 0`. Two further orientations order the interval ends,
//!    which gives the intersection segment.
//! 4. Coplanar triangles are projected onto the coordinate plane their normal is dominant in and
//!    tested there: two disjoint convex polygons are always separated by the line through an
//!    edge of one of them (an edge of their Minkowski difference), so they intersect iff no edge
//!    has the other triangle's three corners strictly outside — 18 exact 2D orientations. (The
//!    paper's own 2D test is a faster decision tree of the same predicates; coplanar pairs are
//!    rare enough that the shorter criterion wins on clarity.)
//!
//! Conventions: triangles are **closed** sets, so touching counts as intersecting, as everywhere
//! in urto. A **degenerate** triangle (exactly collinear or repeated corners: zero area) is
//! treated as the segment or point it is, and tested exactly as such; meshes drop such triangles
//! anyway (see [`TriMesh`](crate::geometry::TriMesh)). A triangle with a NaN or infinite
//! coordinate intersects nothing.

use crate::geometry::Triangle;
use crate::geometry::predicates::{
    PlaneOrientation, collinear, orient2d, orient3d, project, projection_axis,
    segment_meets_triangle, segments_meet_3d, sign,
};
use glam::{DVec3, Vec3};

/// How two closed triangles meet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TriTriIntersection {
    /// They share no point.
    Disjoint,
    /// Non-coplanar triangles meeting along the segment from the first point to the second
    /// (both equal when they touch at a single point). The points are rounded to `f32`.
    Segment(Vec3, Vec3),
    /// They meet and lie in one plane: the intersection may be a polygon; no segment is given.
    Coplanar,
    /// They meet, but one of them has zero area (it is a segment or a point); no segment is
    /// given.
    Degenerate,
}

impl TriTriIntersection {
    /// True for every case but [`Disjoint`](Self::Disjoint).
    pub fn intersects(&self) -> bool {
        !matches!(self, Self::Disjoint)
    }
}

/// True when the closed triangles share at least one point (exact; see the module notes).
pub fn tri_tri_intersect(t1: &Triangle, t2: &Triangle) -> bool {
    match prepare(t1, t2) {
        Stage::Decided(result) => result.intersects(),
        Stage::Crossing(c) => c.intervals_overlap(),
    }
}

/// How the closed triangles meet, with the intersection segment of non-coplanar pairs (for
/// contact generation). The decision is exact; the segment ends are interpolated in `f64` from
/// the exact-sign orientations and rounded to `f32`.
pub fn tri_tri_intersection(t1: &Triangle, t2: &Triangle) -> TriTriIntersection {
    match prepare(t1, t2) {
        Stage::Decided(result) => result,
        Stage::Crossing(c) if c.intervals_overlap() => c.segment(),
        Stage::Crossing(_) => TriTriIntersection::Disjoint,
    }
}

/// Where step 1 leaves a pair: decided, or two proper non-coplanar triangles whose planes both
/// separate the other's corners (steps 2–3 remain).
enum Stage {
    Decided(TriTriIntersection),
    Crossing(Canonical),
}

/// Step 1, the coplanar and degenerate cases, and step 2.
fn prepare(t1: &Triangle, t2: &Triangle) -> Stage {
    if !(t1.is_finite() && t2.is_finite()) {
        return Stage::Decided(TriTriIntersection::Disjoint);
    }
    let (v1, v2) = (t1.vertices(), t2.vertices());
    // Element by element rather than `array::map`, which does not always inline (this is
    // the hot path of every mesh–mesh query).
    let plane2 = PlaneOrientation::new(v2);
    let d1 = [plane2.of(v1[0]), plane2.of(v1[1]), plane2.of(v1[2])];
    if strictly_one_side(d1) {
        return Stage::Decided(TriTriIntersection::Disjoint);
    }
    let plane1 = PlaneOrientation::new(v1);
    let d2 = [plane1.of(v2[0]), plane1.of(v2[1]), plane1.of(v2[2])];
    if strictly_one_side(d2) {
        return Stage::Decided(TriTriIntersection::Disjoint);
    }
    // A degenerate triangle has no plane: every orientation against it is zero. So past this
    // test both triangles are proper and not coplanar.
    if d1.iter().all(|&d| d == 0.0) || d2.iter().all(|&d| d == 0.0) {
        return Stage::Decided(coplanar_or_degenerate(v1, v2));
    }
    Stage::Crossing(Canonical::new(v1, d1, v2, d2))
}

/// All three orientations are non-zero with one sign.
#[inline]
fn strictly_one_side(d: [f64; 3]) -> bool {
    (d[0] > 0.0 && d[1] > 0.0 && d[2] > 0.0) || (d[0] < 0.0 && d[1] < 0.0 && d[2] < 0.0)
}

/// Both triangles after step 2: `p1` alone on the positive side of plane 2, `p2` alone on the
/// positive side of plane 1, with the orientations `d1` (of triangle 1's corners against plane
/// 2) and `d2` permuted along with the corners.
struct Canonical {
    t1: [Vec3; 3],
    d1: [f64; 3],
    t2: [Vec3; 3],
    d2: [f64; 3],
}

impl Canonical {
    fn new(t1: [Vec3; 3], d1: [f64; 3], t2: [Vec3; 3], d2: [f64; 3]) -> Self {
        let (mut t1, mut d1, mirror2) = lone_corner_first(t1, d1);
        let (mut t2, mut d2) = (t2, d2);
        if mirror2 {
            // Flipping plane 2 puts p1 on its positive side; triangle 1's signs change but
            // not their ratios, which is all the segment needs.
            t2.swap(1, 2);
            d2.swap(1, 2);
        }
        let (t2, d2, mirror1) = lone_corner_first(t2, d2);
        if mirror1 {
            t1.swap(1, 2);
            d1.swap(1, 2);
        }
        Self { t1, d1, t2, d2 }
    }

    /// Step 3: triangle 1 cuts `L` in `[i, j]` (on edges `p1q1`, `p1r1`) and triangle 2 in
    /// `[l, k]` (on `p2r2`, `p2q2`), in that order along `L`; they overlap iff `l <= j` and
    /// `i <= k`, i.e. `[p1,r1,r2,p2] <= 0` and `[p1,q1,p2,q2] <= 0`.
    fn intervals_overlap(&self) -> bool {
        let ([p1, q1, r1], [p2, q2, r2]) = (self.t1, self.t2);
        orient3d(p1, q1, p2, q2) <= 0.0 && orient3d(p1, r1, r2, p2) <= 0.0
    }

    /// The overlap `[max(i, l), min(j, k)]`: plane `(p1, q1, r2)` holds `i` and has `l` on the side
    /// of `p2`, so `[p1,q1,r2,p2] > 0` means `l` comes after `i`; likewise `[p1,r1,q2,p2] > 0`
    /// means `k` comes after `j`.
    fn segment(&self) -> TriTriIntersection {
        let ([p1, q1, r1], [p2, q2, r2]) = (self.t1, self.t2);
        let start = if orient3d(p1, q1, r2, p2) > 0.0 {
            crossing(p2, r2, self.d2[0], self.d2[2])
        } else {
            crossing(p1, q1, self.d1[0], self.d1[1])
        };
        let end = if orient3d(p1, r1, q2, p2) > 0.0 {
            crossing(p1, r1, self.d1[0], self.d1[2])
        } else {
            crossing(p2, q2, self.d2[0], self.d2[1])
        };
        TriTriIntersection::Segment(start, end)
    }
}

/// Where segment `[p, q]` meets the plane its ends have orientations `dp`, `dq` against. After
/// step 2 these have opposite signs or one is zero, never both, so the weight is in `[0, 1]`.
fn crossing(p: Vec3, q: Vec3, dp: f64, dq: f64) -> Vec3 {
    let denominator = dp - dq;
    let t = if denominator != 0.0 {
        (dp / denominator).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (p, q) = (p.as_dvec3(), q.as_dvec3());
    DVec3::lerp(p, q, t).as_vec3()
}

/// Step 2 for one triangle: the circular rotation that puts first the corner alone on its side
/// of the other plane, and whether that side is the negative one (the other triangle must then
/// be mirrored). Zeros join whichever side makes the first corner alone:
/// one positive corner → it, positive; else one negative → it, negative; else the zero corner,
/// opposite to the two strict ones. Needs: not all on one strict side, not all zero.
fn lone_corner_first(t: [Vec3; 3], d: [f64; 3]) -> ([Vec3; 3], [f64; 3], bool) {
    let s = [sign(d[0]), sign(d[1]), sign(d[2])];
    let count = |v: i8| (s[0] == v) as u8 + (s[1] == v) as u8 + (s[2] == v) as u8;
    let index_of = |v: i8| {
        if s[0] == v {
            0
        } else if s[1] == v {
            1
        } else {
            2
        }
    };
    let (lone, negative) = match (count(1), count(-1)) {
        (1, _) => (index_of(1), false),
        (_, 1) => (index_of(-1), true),
        (2, _) => (index_of(0), true),
        _ => (index_of(0), false),
    };
    match lone {
        0 => (t, d, negative),
        1 => ([t[1], t[2], t[0]], [d[1], d[2], d[0]], negative),
        _ => ([t[2], t[0], t[1]], [d[2], d[0], d[1]], negative),
    }
}

/// Step 4 and the degenerate cases.
fn coplanar_or_degenerate(v1: [Vec3; 3], v2: [Vec3; 3]) -> TriTriIntersection {
    let (s1, s2) = (Simplex::of(v1), Simplex::of(v2));
    let meet = match (s1, s2) {
        (Simplex::Triangle(a), Simplex::Triangle(b)) => {
            return if coplanar_triangles_meet(a, b) {
                TriTriIntersection::Coplanar
            } else {
                TriTriIntersection::Disjoint
            };
        }
        (Simplex::Triangle(t), Simplex::Segment(p, q))
        | (Simplex::Segment(p, q), Simplex::Triangle(t)) => segment_meets_triangle(p, q, t),
        (Simplex::Segment(p, q), Simplex::Segment(r, s)) => segments_meet_3d(p, q, r, s),
    };
    if meet {
        TriTriIntersection::Degenerate
    } else {
        TriTriIntersection::Disjoint
    }
}

/// What a triangle really is: a proper triangle, or (when degenerate) the segment between its
/// two extreme corners, a point being a segment of length zero.
#[derive(Clone, Copy)]
enum Simplex {
    Triangle([Vec3; 3]),
    Segment(Vec3, Vec3),
}

impl Simplex {
    fn of(t: [Vec3; 3]) -> Self {
        if !collinear(t[0], t[1], t[2]) {
            return Self::Triangle(t);
        }
        // Along a line, lexicographic order of (x, y, z) is the order along the line, so the
        // lexicographic extremes are the segment's ends.
        let lex = |a: &&Vec3, b: &&Vec3| a.to_array().partial_cmp(&b.to_array());
        let lo = t
            .iter()
            .min_by(|a, b| lex(a, b).unwrap_or(std::cmp::Ordering::Equal));
        let hi = t
            .iter()
            .max_by(|a, b| lex(a, b).unwrap_or(std::cmp::Ordering::Equal));
        Self::Segment(*lo.unwrap_or(&t[0]), *hi.unwrap_or(&t[0]))
    }
}

/// Two proper coplanar triangles meet iff no edge of either has all three corners of the other
/// strictly outside (see step 4 in the module notes).
fn coplanar_triangles_meet(a: [Vec3; 3], b: [Vec3; 3]) -> bool {
    // A proper triangle always has an axis; 2 only guards the impossible case.
    let axis = projection_axis(a[0], a[1], a[2]).unwrap_or(2);
    let (a, b) = (a.map(|p| project(p, axis)), b.map(|p| project(p, axis)));
    let winding = |t: &[robust::Coord<f32>; 3]| sign(orient2d(t[0], t[1], t[2]));
    let separated_by_an_edge_of = |t: &[robust::Coord<f32>; 3], other: &[robust::Coord<f32>; 3]| {
        let w = winding(t);
        (0..3).any(|i| {
            other
                .iter()
                .all(|&p| w * sign(orient2d(t[i], t[(i + 1) % 3], p)) < 0)
        })
    };
    !(separated_by_an_edge_of(&a, &b) || separated_by_an_edge_of(&b, &a))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Triangle {
        Triangle::new(Vec3::from(a), Vec3::from(b), Vec3::from(c))
    }

    fn both_orders(t1: &Triangle, t2: &Triangle) -> bool {
        let r = tri_tri_intersect(t1, t2);
        assert_eq!(r, tri_tri_intersect(t2, t1), "symmetry");
        r
    }

    #[test]
    fn crossing_and_separated() {
        let t1 = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        let crossing = tri([0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [3.0, 3.0, 0.0]);
        assert!(both_orders(&t1, &crossing));
        let above = tri([0.5, 0.5, 0.1], [0.5, 0.5, 1.0], [3.0, 3.0, 0.5]);
        assert!(!both_orders(&t1, &above));
    }

    #[test]
    fn touching_configurations_intersect_and_one_ulp_gaps_do_not() {
        let t1 = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let shared_vertex = tri([0.0, 0.0, 0.0], [-1.0, 0.0, 1.0], [0.0, -1.0, 1.0]);
        let shared_edge = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.0, 1.0]);
        let vertex_on_face = tri([0.25, 0.25, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]);
        for t2 in [shared_vertex, shared_edge, vertex_on_face] {
            assert!(both_orders(&t1, &t2), "{t2:?}");
        }
        let lift =
            |t: Triangle| Triangle::from(t.vertices().map(|p| Vec3::new(p.x, p.y, p.z.next_up())));
        assert!(!both_orders(&t1, &lift(vertex_on_face)));
        assert!(!both_orders(&t1, &lift(shared_vertex)));
    }

    #[test]
    fn coplanar_cases() {
        let t1 = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let overlapping = tri([0.2, 0.2, 0.0], [2.0, 0.2, 0.0], [0.2, 2.0, 0.0]);
        let inside = tri([0.1, 0.1, 0.0], [0.3, 0.1, 0.0], [0.1, 0.3, 0.0]);
        let touching_edge = tri([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]);
        let disjoint = tri([0.6, 0.6, 0.0], [2.0, 0.6, 0.0], [0.6, 2.0, 0.0]);
        assert_eq!(
            tri_tri_intersection(&t1, &overlapping),
            TriTriIntersection::Coplanar
        );
        assert!(both_orders(&t1, &inside) && both_orders(&inside, &t1));
        assert!(both_orders(&t1, &touching_edge));
        assert!(!both_orders(&t1, &disjoint));
    }

    #[test]
    fn segment_of_a_crossing_pair() {
        let t1 = tri([0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]);
        let t2 = tri([1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [1.0, 5.0, 1.0]);
        // t2 lies in x = 1 and crosses z = 0 on y ∈ [1, 3]; t1 ends at y = 3 there.
        let TriTriIntersection::Segment(a, b) = tri_tri_intersection(&t1, &t2) else {
            panic!("expected a segment");
        };
        let (lo, hi) = if a.y < b.y { (a, b) } else { (b, a) };
        assert!((lo - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6, "{lo}");
        assert!((hi - Vec3::new(1.0, 3.0, 0.0)).length() < 1e-6, "{hi}");
    }

    #[test]
    fn degenerate_triangles_act_as_segments_and_points() {
        let t1 = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let needle = tri([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [0.2, 0.2, 0.5]);
        let missing_needle = tri([0.7, 0.7, -1.0], [0.7, 0.7, 1.0], [0.7, 0.7, 0.0]);
        let point_on = tri([0.3, 0.3, 0.0], [0.3, 0.3, 0.0], [0.3, 0.3, 0.0]);
        let point_off = tri([0.3, 0.3, 1.0], [0.3, 0.3, 1.0], [0.3, 0.3, 1.0]);
        assert_eq!(
            tri_tri_intersection(&t1, &needle),
            TriTriIntersection::Degenerate
        );
        assert!(!both_orders(&t1, &missing_needle));
        assert!(both_orders(&t1, &point_on));
        assert!(!both_orders(&t1, &point_off));
        assert!(!both_orders(&needle, &point_off));
        let crossing_needle = tri([0.2, -1.0, 0.5], [0.2, 1.0, 0.5], [0.2, 0.0, 0.5]);
        let along = tri([0.2, 0.2, 0.5], [0.2, 0.2, 0.5], [0.2, 0.2, 0.5]);
        assert!(both_orders(&needle, &crossing_needle));
        assert!(both_orders(&needle, &along));
    }

    /// Independent exact criterion for proper triangles: closed triangles meet iff an edge of
    /// one meets the other (the ends of their common part lie on edges), tested with the
    /// segment–triangle predicate rather than the Guigue–Devillers path.
    fn edge_oracle(t1: &Triangle, t2: &Triangle) -> bool {
        let edges_meet = |a: &Triangle, b: &Triangle| {
            let v = a.vertices();
            (0..3).any(|i| segment_meets_triangle(v[i], v[(i + 1) % 3], b.vertices()))
        };
        edges_meet(t1, t2) || edges_meet(t2, t1)
    }

    /// The 6 orderings of a triangle's corners (3 rotations, each also mirrored).
    fn orderings(t: &Triangle) -> [Triangle; 6] {
        let [a, b, c] = t.vertices();
        [
            [a, b, c],
            [b, c, a],
            [c, a, b],
            [a, c, b],
            [c, b, a],
            [b, a, c],
        ]
        .map(Triangle::from)
    }

    fn xorshift(seed: &mut u64) -> u64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        *seed
    }

    #[test]
    fn agrees_with_the_edge_oracle_on_grid_triangles_in_every_vertex_order() {
        // Corners on a 5×5×5 integer grid: shared corners, shared edges, corners on faces and
        // coplanar pairs are everywhere, and every one of them must be decided exactly.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let corner = |seed: &mut u64| {
            let r = xorshift(seed);
            Vec3::new(
                (r % 5) as f32 - 2.0,
                ((r >> 8) % 5) as f32 - 2.0,
                ((r >> 16) % 5) as f32 - 2.0,
            )
        };
        let (mut tested, mut meeting, mut coplanar) = (0, 0, 0);
        while tested < 4000 {
            let t1 = Triangle::new(corner(&mut seed), corner(&mut seed), corner(&mut seed));
            let mut t2 = Triangle::new(corner(&mut seed), corner(&mut seed), corner(&mut seed));
            if tested % 3 == 0 {
                // Every third pair coplanar: integer combinations of t1's edges.
                let in_plane = |seed: &mut u64| {
                    let r = xorshift(seed);
                    let (i, j) = ((r % 4) as f32 - 1.0, ((r >> 8) % 4) as f32 - 1.0);
                    t1.a + (t1.b - t1.a) * i + (t1.c - t1.a) * j
                };
                t2 = Triangle::new(
                    in_plane(&mut seed),
                    in_plane(&mut seed),
                    in_plane(&mut seed),
                );
            }
            if t1.is_degenerate() || t2.is_degenerate() {
                continue;
            }
            tested += 1;
            let expected = edge_oracle(&t1, &t2);
            meeting += expected as usize;
            coplanar += (tri_tri_intersection(&t1, &t2) == TriTriIntersection::Coplanar) as usize;
            for a in orderings(&t1) {
                for b in orderings(&t2) {
                    assert_eq!(tri_tri_intersect(&a, &b), expected, "{a:?} {b:?}");
                    assert_eq!(tri_tri_intersect(&b, &a), expected, "{b:?} {a:?}");
                }
            }
        }
        assert!(
            meeting > 500 && tested - meeting > 500,
            "both outcomes exercised: {meeting}"
        );
        assert!(coplanar > 500, "coplanar pairs exercised: {coplanar}");
    }

    #[test]
    fn agrees_with_the_edge_oracle_on_nearly_touching_float_triangles() {
        // t2 shares a corner, or has a corner on t1's plane nudged by a few ulps.
        let mut seed = 0x1234_5678_9abc_def1u64;
        let unit = |seed: &mut u64| (xorshift(seed) % 2_000_001) as f32 / 1_000_000.0 - 1.0;
        let v = |seed: &mut u64| Vec3::new(unit(seed), unit(seed), unit(seed));
        for _ in 0..3000 {
            let t1 = Triangle::new(v(&mut seed), v(&mut seed), v(&mut seed));
            let on_plane = t1.a + (t1.b - t1.a) * 0.3 + (t1.c - t1.a) * 0.3;
            let nudge = (xorshift(&mut seed) % 7) as i32 - 3;
            let mut z = on_plane.z;
            for _ in 0..nudge.abs() {
                z = if nudge > 0 {
                    z.next_up()
                } else {
                    z.next_down()
                };
            }
            let t2 = Triangle::new(
                Vec3::new(on_plane.x, on_plane.y, z),
                v(&mut seed),
                v(&mut seed),
            );
            if t1.is_degenerate() || t2.is_degenerate() {
                continue;
            }
            assert_eq!(
                tri_tri_intersect(&t1, &t2),
                edge_oracle(&t1, &t2),
                "{t1:?} {t2:?}"
            );
            assert_eq!(tri_tri_intersect(&t2, &t1), edge_oracle(&t1, &t2));
        }
    }

    #[test]
    fn non_finite_input_intersects_nothing() {
        let t1 = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let bad = tri([f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert!(!both_orders(&t1, &bad));
        let inf = tri([f32::INFINITY, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(
            tri_tri_intersection(&inf, &t1),
            TriTriIntersection::Disjoint
        );
    }
}
