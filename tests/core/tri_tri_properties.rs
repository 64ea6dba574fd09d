//! Property tests of the exact triangle–triangle test: the answer cannot change under motions
//! that are exact in floating point (permuting or negating axes, scaling by a power of two,
//! translating a grid by whole numbers), nor under reordering corners or swapping the
//! triangles. Corners on a small half-integer grid make touching, coplanar and degenerate pairs
//! common — exactly where a rounding-based test would flip its answer under such motions.

use glam::Vec3;
use proptest::prelude::*;
use urto::geometry::{TriTriIntersection, Triangle, tri_tri_intersect, tri_tri_intersection};

fn grid_corner() -> impl Strategy<Value = Vec3> {
    (-4i32..=4, -4i32..=4, -4i32..=4)
        .prop_map(|(x, y, z)| Vec3::new(x as f32, y as f32, z as f32) * 0.5)
}

fn grid_triangle() -> impl Strategy<Value = Triangle> {
    (grid_corner(), grid_corner(), grid_corner()).prop_map(|(a, b, c)| Triangle::new(a, b, c))
}

/// An exact motion: axis permutation, axis sign flips, a power-of-two scale, a whole-number
/// translation.
#[derive(Clone, Debug)]
struct ExactMotion {
    permutation: [usize; 3],
    flips: [bool; 3],
    scale_exponent: i32,
    shift: [i32; 3],
}

impl ExactMotion {
    fn apply(&self, t: &Triangle) -> Triangle {
        let f = |p: Vec3| {
            let a = p.to_array();
            let mut q = [0.0f32; 3];
            for i in 0..3 {
                let v = a[self.permutation[i]];
                q[i] = if self.flips[i] { -v } else { v } + self.shift[i] as f32;
            }
            Vec3::from(q) * 2f32.powi(self.scale_exponent)
        };
        Triangle::new(f(t.a), f(t.b), f(t.c))
    }
}

fn exact_motion() -> impl Strategy<Value = ExactMotion> {
    let permutations = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    (
        0usize..6,
        any::<[bool; 3]>(),
        -20i32..20,
        (-50i32..50, -50i32..50, -50i32..50),
    )
        .prop_map(move |(p, flips, scale_exponent, (x, y, z))| ExactMotion {
            permutation: permutations[p],
            flips,
            scale_exponent,
            shift: [x, y, z],
        })
}

fn rotate(t: &Triangle, k: usize) -> Triangle {
    let v = t.vertices();
    Triangle::new(v[k % 3], v[(k + 1) % 3], v[(k + 2) % 3])
}

fn mirror(t: &Triangle) -> Triangle {
    Triangle::new(t.a, t.c, t.b)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn exact_motions_and_reorderings_keep_the_answer(
        t1 in grid_triangle(),
        t2 in grid_triangle(),
        motion in exact_motion(),
        k1 in 0usize..3,
        k2 in 0usize..3,
        mirror1 in any::<bool>(),
    ) {
        let expected = tri_tri_intersect(&t1, &t2);
        let (m1, m2) = (motion.apply(&t1), motion.apply(&t2));
        prop_assert_eq!(tri_tri_intersect(&m1, &m2), expected);
        let r1 = if mirror1 { mirror(&rotate(&t1, k1)) } else { rotate(&t1, k1) };
        let r2 = rotate(&t2, k2);
        prop_assert_eq!(tri_tri_intersect(&r1, &r2), expected);
        prop_assert_eq!(tri_tri_intersect(&r2, &r1), expected);
        // The detailed variant decides the same way, and its kind does not depend on order.
        let kind = tri_tri_intersection(&t1, &t2);
        prop_assert_eq!(kind.intersects(), expected);
        let swapped = tri_tri_intersection(&t2, &t1);
        prop_assert_eq!(
            std::mem::discriminant(&swapped),
            std::mem::discriminant(&kind)
        );
    }

    #[test]
    fn segments_lie_on_both_triangles(t1 in grid_triangle(), t2 in grid_triangle()) {
        if let TriTriIntersection::Segment(a, b) = tri_tri_intersection(&t1, &t2) {
            for p in [a, b] {
                prop_assert!((t1.closest_point(p) - p).length() < 1e-5, "{} off {:?}", p, t1);
                prop_assert!((t2.closest_point(p) - p).length() < 1e-5, "{} off {:?}", p, t2);
            }
        }
    }
}
