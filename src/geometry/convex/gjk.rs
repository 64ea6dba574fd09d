//! GJK (Gilbert, Johnson & Keerthi 1988): the distance between two convex cores, found as the
//! distance from the origin to their Minkowski difference `A − B`, which GJK explores through
//! support points `w = s_A(d) − s_B(−d)` and a simplex of at most four of them.
//!
//! Each iteration finds the simplex's point `v` closest to the origin (Ericson 2005, §5.1: the
//! Voronoi regions of a triangle, and of a tetrahedron's faces), drops the vertices that do not
//! support it, and adds the support point along `−v`. It stops with van den Bergen's (2003)
//! relative test, `|v|² − v·w <= ε|v|²` (no support point gets meaningfully closer) or its
//! absolute twin at f32's resolution, when `v` stops shrinking (rounding: the previous simplex
//! is kept), or when the simplex encloses the origin or `v` is within a
//! tolerance of it: the cores overlap, and EPA (`epa.rs`) takes the simplex.
//!
//! A caller that only needs pairs within some distance (a contact's speculative margin) says
//! so, and GJK stops at the first support plane that puts `A − B` farther away: `v·w / |v|`
//! bounds the distance from below (every point `x` of `A − B` has `v·x >= v·w`), so a plane
//! beyond the limit separates the pair for good (the separating-axis early-out of Bullet's and
//! Jolt's GJK). Three of four triangles a hull's box reaches on a terrain, half of a
//! cylinder's, are apart, and converging on their distance was most of their cost.
//!
//! The support points come in f32, but the simplex arithmetic runs in f64: near a curved rim
//! GJK bunches support points a few micrometres apart, and an f32 tetrahedron of them cannot
//! tell inside from outside (a capsule 5 cm from a cylinder was reported 5 cm deep in it).

use super::support::ConvexPart;
use glam::{DVec3, Vec3};

/// Iterations GJK may take; polytopes converge in a handful, smooth shapes in tens.
const MAX_ITERATIONS: usize = 64;

/// Relative convergence of van den Bergen's test (`ε` above).
const RELATIVE_TOLERANCE: f64 = 1e-6;

/// A tetrahedron whose six-fold volume is below this fraction of its longest edge cubed is flat.
const FLAT_VOLUME_FRACTION: f64 = 1e-9;

/// Absolute convergence: a support point closer than this fraction of the pair's size to
/// improving the distance does not count (f32 support points are about this exact).
const ABSOLUTE_FRACTION: f64 = 1e-6;

/// The cores count as overlapping when `|v|` is below this fraction of the pair's size.
const OVERLAP_FRACTION: f64 = 1e-6;

/// A vertex of the Minkowski difference with the two support points that made it. The support
/// points stay in f32, as the shapes gave them (48 bytes, not 72: GJK and EPA copy these).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SupportPoint {
    /// `a − b`, in f64.
    pub w: DVec3,
    /// The support point of A.
    pub a: Vec3,
    /// The support point of B.
    pub b: Vec3,
}

/// The support point of `A − B` along `dir`.
#[inline]
pub(crate) fn support(a: &ConvexPart, b: &ConvexPart, dir: DVec3) -> SupportPoint {
    let d = dir.as_vec3();
    let (pa, pb) = (a.support(d), b.support(-d));
    SupportPoint {
        w: pa.as_dvec3() - pb.as_dvec3(),
        a: pa,
        b: pb,
    }
}

/// Which vertices of a simplex support its point closest to the origin, with that point's
/// barycentric weights: found without touching the simplex, applied by [`Simplex::reduce`].
#[derive(Clone, Copy, Debug)]
struct Reduction {
    ids: [usize; 3],
    weights: [f64; 3],
    len: usize,
}

impl Reduction {
    fn one(i: usize) -> Self {
        Self {
            ids: [i, 0, 0],
            weights: [1.0, 0.0, 0.0],
            len: 1,
        }
    }

    fn two([i, j]: [usize; 2], [wi, wj]: [f64; 2]) -> Self {
        Self {
            ids: [i, j, 0],
            weights: [wi, wj, 0.0],
            len: 2,
        }
    }
}

/// At most four support points, with the barycentric weights of the simplex's closest point.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Simplex {
    pub points: [SupportPoint; 4],
    pub weights: [f64; 4],
    pub len: usize,
}

impl Simplex {
    fn push(&mut self, p: SupportPoint) {
        self.points[self.len] = p;
        self.len += 1;
    }

    /// The point a reduction stands for: its vertices' weighted sum.
    fn point_of(&self, r: &Reduction) -> DVec3 {
        let mut v = DVec3::ZERO;
        for (&i, &w) in r.ids[..r.len].iter().zip(&r.weights) {
            v += self.points[i].w * w;
        }
        v
    }

    /// Keeps the reduction's vertices with its weights.
    fn reduce(&mut self, r: Reduction) {
        // Read before written: a kept vertex may move to a slot another one is read from.
        // (Spelled out per count: a gathered array of three went through `memcpy`.)
        let [i, j, k] = r.ids;
        match r.len {
            1 => self.points[0] = self.points[i],
            2 => [self.points[0], self.points[1]] = [self.points[i], self.points[j]],
            _ => {
                [self.points[0], self.points[1], self.points[2]] =
                    [self.points[i], self.points[j], self.points[k]]
            }
        }
        self.weights[..3].copy_from_slice(&r.weights);
        self.len = r.len;
    }

    /// The weighted sum of the vertices' A points and B points: the closest points' witnesses.
    pub fn witnesses(&self) -> (DVec3, DVec3) {
        let mut pa = DVec3::ZERO;
        let mut pb = DVec3::ZERO;
        for (p, &w) in self.points[..self.len].iter().zip(&self.weights) {
            pa += p.a.as_dvec3() * w;
            pb += p.b.as_dvec3() * w;
        }
        (pa, pb)
    }

    /// The simplex's point closest to the origin and the vertices supporting it (the simplex
    /// untouched: GJK keeps it as it is when the point makes no progress); `None` when a
    /// tetrahedron encloses the origin.
    fn closest(&self) -> Option<(Reduction, DVec3)> {
        let r = match self.len {
            1 => Reduction::one(0),
            2 => self.on_segment(0, 1),
            3 => self.on_triangle(0, 1, 2),
            _ => return self.on_tetrahedron(),
        };
        Some((r, self.point_of(&r)))
    }

    fn on_segment(&self, i: usize, j: usize) -> Reduction {
        let (a, b) = (self.points[i].w, self.points[j].w);
        let ab = b - a;
        let len2 = ab.length_squared();
        let t = if len2 > 0.0 { -a.dot(ab) / len2 } else { 0.0 };
        if t <= 0.0 {
            Reduction::one(i)
        } else if t >= 1.0 {
            Reduction::one(j)
        } else {
            Reduction::two([i, j], [1.0 - t, t])
        }
    }

    /// Ericson's `ClosestPtPointTriangle` for the origin, by Voronoi regions.
    fn on_triangle(&self, i: usize, j: usize, k: usize) -> Reduction {
        let (a, b, c) = (self.points[i].w, self.points[j].w, self.points[k].w);
        let (ab, ac) = (b - a, c - a);
        let (d1, d2) = (-ab.dot(a), -ac.dot(a));
        if d1 <= 0.0 && d2 <= 0.0 {
            return Reduction::one(i);
        }
        let (d3, d4) = (-ab.dot(b), -ac.dot(b));
        if d3 >= 0.0 && d4 <= d3 {
            return Reduction::one(j);
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            let t = d1 / (d1 - d3);
            return Reduction::two([i, j], [1.0 - t, t]);
        }
        let (d5, d6) = (-ab.dot(c), -ac.dot(c));
        if d6 >= 0.0 && d5 <= d6 {
            return Reduction::one(k);
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            let t = d2 / (d2 - d6);
            return Reduction::two([i, k], [1.0 - t, t]);
        }
        let va = d3 * d6 - d5 * d4;
        if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
            let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            return Reduction::two([j, k], [1.0 - t, t]);
        }
        let sum = va + vb + vc;
        if sum <= 0.0 || !sum.is_finite() {
            // A degenerate (flat) triangle: its first edge (GJK's next support point restores
            // the rest).
            return self.on_segment(i, j);
        }
        let (v, w) = (vb / sum, vc / sum);
        Reduction {
            ids: [i, j, k],
            weights: [1.0 - v - w, v, w],
            len: 3,
        }
    }

    /// The closest of the faces the origin lies beyond (of every face, when the tetrahedron is
    /// flat) and its closest point; `None` when the origin is inside all four.
    fn on_tetrahedron(&self) -> Option<(Reduction, DVec3)> {
        const FACES: [[usize; 4]; 4] = [[0, 1, 2, 3], [0, 3, 1, 2], [0, 2, 3, 1], [1, 3, 2, 0]];
        let w = self.points.map(|p| p.w);
        // A nearly flat tetrahedron (three support points bunched on a curved rim) cannot tell
        // inside from outside: it is searched face by face, as a flat one.
        let longest = (1..4)
            .map(|k| (w[k] - w[0]).length())
            .fold(0.0f64, f64::max);
        let volume6 = (w[1] - w[0]).cross(w[2] - w[0]).dot(w[3] - w[0]).abs();
        let flat = volume6 <= FLAT_VOLUME_FRACTION * longest * longest * longest;
        let mut best: Option<(f64, Reduction, DVec3)> = None;
        for [i, j, k, opposite] in FACES {
            let n = (w[j] - w[i]).cross(w[k] - w[i]);
            let origin_side = -n.dot(w[i]);
            let other_side = n.dot(w[opposite] - w[i]);
            // The origin is beyond this face when it is on the side away from the fourth
            // vertex; a flat tetrahedron (both zero) is searched face by face.
            if origin_side * other_side < 0.0 || other_side == 0.0 || flat {
                let face = self.on_triangle(i, j, k);
                let point = self.point_of(&face);
                let d2 = point.length_squared();
                if best.as_ref().is_none_or(|b| d2 < b.0) {
                    best = Some((d2, face, point));
                }
            }
        }
        best.map(|(_, face, point)| (face, point))
    }
}

/// What GJK found. The simplex is carried by value: boxing it would allocate per query.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)]
pub(crate) enum Gjk {
    /// The cores are apart: their closest points (on A's core, on B's core).
    Separated { on_a: Vec3, on_b: Vec3 },
    /// The cores overlap (or touch within the tolerance); the simplex goes to EPA.
    Overlapping(Simplex),
    /// The cores are farther apart than the limit [`gjk_within`] was given.
    Beyond,
}

/// Runs GJK on the cores of `a` and `b`, to convergence.
#[cfg(test)]
pub(crate) fn gjk(a: &ConvexPart, b: &ConvexPart) -> Gjk {
    gjk_within(a, b, f64::INFINITY)
}

/// Runs GJK on the cores of `a` and `b`, answering [`Gjk::Beyond`] as soon as a support plane
/// shows them more than `limit` apart (module notes; infinity: to convergence).
pub(crate) fn gjk_within(a: &ConvexPart, b: &ConvexPart, limit: f64) -> Gjk {
    let scale = f64::from(a.size() + b.size() + a.center().distance(b.center()));
    let overlap = (OVERLAP_FRACTION * scale).max(f64::MIN_POSITIVE);
    let resolution = ABSOLUTE_FRACTION * scale;
    let mut simplex = Simplex::default();
    let mut v = (a.center() - b.center()).as_dvec3();
    if v.length_squared() <= overlap * overlap {
        v = DVec3::X;
    }
    let mut last = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        let w = support(a, b, -v);
        let v2 = v.length_squared();
        // `v·w > limit |v|` with both sides positive, squared: no root.
        let ahead = v.dot(w.w);
        if ahead > 0.0 && ahead * ahead > limit * limit * v2 {
            return Gjk::Beyond;
        }
        if simplex.len > 0 {
            // How much closer to the origin the support plane along -v lies than v (times |v|):
            // converged when that is below the relative or the absolute resolution.
            let progress = v2 - ahead;
            let repeated = simplex.points[..simplex.len].iter().any(|p| p.w == w.w);
            if repeated || progress <= (RELATIVE_TOLERANCE * v2).max(v2.sqrt() * resolution) {
                break;
            }
        }
        simplex.push(w);
        let Some((reduction, closest)) = simplex.closest() else {
            return Gjk::Overlapping(simplex);
        };
        let v2 = closest.length_squared();
        if !v2.is_finite() || v2 >= last {
            // No progress (rounding in a nearly flat simplex): the previous answer stands,
            // without the new point.
            simplex.len -= 1;
            break;
        }
        simplex.reduce(reduction);
        v = closest;
        if v2 <= overlap * overlap {
            return Gjk::Overlapping(simplex);
        }
        last = v2;
    }
    let (on_a, on_b) = simplex.witnesses();
    Gjk::Separated {
        on_a: on_a.as_vec3(),
        on_b: on_b.as_vec3(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Isometry, Shape};
    use glam::Quat;

    fn part(shape: &Shape, at: Vec3, turn: Quat) -> ConvexPart<'_> {
        ConvexPart::of_shape(shape, Isometry::new(at, turn)).unwrap()
    }

    #[test]
    fn box_distance_is_the_face_gap_within_1e_6() {
        let cube = Shape::cuboid(Vec3::splat(0.5));
        let a = part(&cube, Vec3::ZERO, Quat::IDENTITY);
        let b = part(&cube, Vec3::new(0.3, 0.2, 1.75), Quat::IDENTITY);
        let Gjk::Separated { on_a, on_b } = gjk(&a, &b) else {
            panic!("apart")
        };
        assert!(((on_b - on_a).length() - 0.75).abs() < 1e-6);
        assert!((on_b - on_a).normalize().dot(Vec3::Z) > 1.0 - 1e-6);
    }

    #[test]
    fn overlapping_cores_are_reported_and_far_ones_are_not() {
        let cyl = Shape::cylinder(0.5, 0.4);
        let a = part(&cyl, Vec3::ZERO, Quat::IDENTITY);
        let b = part(&cyl, Vec3::new(0.5, 0.1, 0.2), Quat::from_rotation_x(1.0));
        assert!(matches!(gjk(&a, &b), Gjk::Overlapping(_)));
        let c = part(&cyl, Vec3::new(3.0, 0.1, 0.2), Quat::from_rotation_x(1.0));
        assert!(matches!(gjk(&a, &c), Gjk::Separated { .. }));
    }
}
