//! Tests of the convex hull: construction against brute-force convexity and parry3d, refused
//! and degenerate point clouds, the support function and the mass properties' volume.

use super::HullError::*;
use super::*;
use glam::Vec3Swizzles;
use std::collections::HashSet;

/// `n` seeded (splitmix64) points scaled by `h`: 0 in a cube, 1 on a sphere, 2 in a ball, 3 in
/// a box, in turn on a face, on an edge, at a corner (so repeated) and inside; 4 in a cube
/// 1e3 wide, 3e3 off the origin; 5 in a flat box (1e-3 thick); 6 a needle; 7 in a 1e-3 ball.
fn cloud(mut seed: u64, n: usize, kind: usize, h: Vec3) -> Vec<Vec3> {
    let mut next = || {
        seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let z = (seed ^ (seed >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    };
    let snap = [Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::ONE, Vec3::ZERO];
    let point = |i: usize| loop {
        let (p, m) = (Vec3::new(next(), next(), next()), snap[i % 4]);
        let m = [m, m.zxy(), m.yzx()][i / 4 % 3];
        match (kind, p.length_squared()) {
            (0, _) => return p * h,
            (1, r) if (0.01..1.0).contains(&r) => return p.normalize() * h,
            (2, r) if r < 1.0 => return p * h,
            (3, _) => return (p + (p.signum() - p) * m) * h,
            (4, _) => return (p + 3.0) * 1e3 * h,
            (5, _) => return p * Vec3::new(1.0, 1.0, 5e-4) * h,
            (6, _) => return p * Vec3::new(1.0, 1e-3, 1e-3) * h,
            (7, r) if r < 1.0 => return p * 1e-3 * h,
            _ => {}
        }
    };
    (0..n).map(point).collect()
}

/// Builds the hull and checks all it promises, within the input's tolerance (every `step`-th
/// point against every plane).
fn check(points: &[Vec3], step: usize) -> ConvexHull {
    let (h, tol) = (ConvexHull::from_points(points).unwrap(), tolerance(points));
    let bits = |p: &Vec3| p.to_array().map(f32::to_bits);
    let inputs: HashSet<_> = points.iter().map(bits).collect();
    assert!(h.vertices().iter().all(|v| inputs.contains(&bits(v))));
    let (mut edges, mut faces_at) = (HashSet::new(), vec![0; h.vertices().len()]);
    for (f, face) in h.faces().iter().enumerate() {
        let (ids, poly) = (h.face_vertices(f), h.face_polygon(f).collect::<Vec<_>>());
        let (m, n, mut turning) = (poly.len(), face.normal, 0.0);
        for i in 0..m {
            let (u, v, w) = (poly[(i + m - 1) % m], poly[i], poly[(i + 1) % m]);
            assert!(edges.insert((ids[i], ids[(i + 1) % m])), "an edge twice");
            faces_at[ids[i] as usize] += 1;
            let dent = n.cross(w - u).normalize().dot(v - u);
            assert!(dent <= tol, "face {f} has a dent of {dent} at {v}");
            assert!(face.offset - n.dot(v) <= 2.0 * tol, "face {f} not planar");
            turning += n.dot((v - u).cross(w - v)).atan2((v - u).dot(w - v));
        }
        let turns = turning / std::f32::consts::TAU;
        assert!((turns - 1.0).abs() < 1e-3, "face {f} turns {turns} times");
        assert!((n.length() - 1.0).abs() < 1e-6, "face {f}: normal {n}");
        for &q in points.iter().step_by(step) {
            let above = n.dot(q) - face.offset;
            assert!(
                above <= 2.0 * tol,
                "{q} above face {f} by {above}, tol {tol}"
            );
        }
    }
    let closed = edges.iter().all(|&(a, b)| edges.contains(&(b, a)));
    assert!(closed && faces_at.iter().all(|&n| n >= 3));
    let (v, e, f) = (h.vertices().len(), edges.len() / 2, h.faces().len());
    assert_eq!(v + f, e + 2, "Euler: V - E + F = 2");
    h
}

#[test]
fn random_clouds_are_convex_within_tolerance() {
    for (seed, kind) in (0..10).flat_map(|seed| (0..8).map(move |kind| (seed, kind))) {
        check(&cloud(seed, 1000, kind, Vec3::new(1.0, 0.5, 0.25)), 1);
    }
    check(&cloud(8, 200_000, 1, Vec3::ONE), 200); // dense: neighbours bulge by ~1e-5
}

#[test]
fn cube_cloud_has_exactly_8_vertices_and_6_quads() {
    let mut points = cloud(2, 1000, 3, Vec3::ONE);
    let grid = |i: usize| Vec3::new(2.0, (i % 5) as f32 - 2.0, (i / 5) as f32 - 2.0) / 2.0;
    let faces = |g: Vec3| [g, -g, g.zxy(), -g.zxy(), g.yzx(), -g.yzx()];
    points.extend((0..25).map(grid).flat_map(faces));
    let h = check(&points, 1);
    assert_eq!((h.vertices().len(), h.faces().len()), (8, 6));
    assert!((0..6).all(|f| h.face_vertices(f).len() == 4 && h.faces()[f].offset == 1.0));
    let down = h.faces()[h.best_face(Vec3::new(0.1, -0.9, 0.2))].normal;
    assert_eq!(down, Vec3::NEG_Y);
    assert_eq!(h.local_aabb(), Aabb::new(-Vec3::ONE, Vec3::ONE));
    assert!(h.bounding_radius() == 3f32.sqrt() && h.face_vertices(6).is_empty());
}

#[test]
fn too_few_flat_collinear_coincident_nan_and_huge_points_are_errors() {
    let (u, v) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(3.0, -1.0, 0.5));
    let err = |p: &[Vec3]| ConvexHull::from_points(p).err();
    let flat = (0..100).map(|i| (i as f32).sin() * u + (i as f32).cos() * v);
    let (flat, line): (Vec<_>, Vec<_>) = flat.map(|p| (p, p.x * v + u)).unzip();
    assert_eq!(err(&flat[..3]), Some(TooFewPoints(3)));
    for degenerate in [&flat[..], &line, &[v; 10]] {
        assert_eq!(err(degenerate), Some(Degenerate));
    }
    let mut bad = cloud(3, 10, 0, Vec3::ONE);
    bad[5].y = f32::NAN;
    assert!(matches!(err(&bad), Some(NonFinitePoint { index: 5, .. })));
    bad[5].y = -2e6;
    assert_eq!(err(&bad), Some(TooLarge(2e6)));
}

#[test]
fn million_points_in_a_ball_build_in_under_2s_in_release() {
    let points = cloud(4, 1_000_000, 2, Vec3::ONE);
    let start = std::time::Instant::now();
    let n = ConvexHull::from_points(&points).unwrap().vertices().len();
    let time = start.elapsed().as_secs_f32();
    println!("1e6 points in a ball: {time} s, {n} vertices");
    assert!(n > 100 && (cfg!(debug_assertions) || time < 2.0));
    check(&points, 100);
}

#[test]
fn support_is_the_brute_force_max_for_1000_directions() {
    let dirs = cloud(6, 1000, 0, Vec3::ONE);
    let (round, cube) = (cloud(5, 300, 1, Vec3::ONE), cloud(5, 1000, 3, Vec3::ONE));
    for h in [check(&round, 1), check(&cube, 1)] {
        assert!(h.vertices().len() > 16 || h.vertices().len() == 8);
        for &dir in &dirs {
            let best = h.vertices().iter().fold(f32::MIN, |m, v| m.max(v.dot(dir)));
            assert_eq!(h.support(dir).dot(dir), best, "along {dir}");
        }
    }
}

#[test]
fn volume_matches_parry3d_within_1e_4_relative() {
    let volume = |m: &TriMesh| {
        let v = |i: u32| m.vertices()[i as usize];
        let six = |&[a, b, c]: &[u32; 3]| v(a).dot(v(b).cross(v(c)));
        m.triangles().iter().map(six).sum::<f32>() / 6.0
    };
    for seed in 0..20 {
        let points = cloud(seed, 500, seed as usize % 2, Vec3::ONE);
        let (vertices, triangles) = parry3d::transformation::convex_hull(&points);
        let theirs = volume(&TriMesh::new(vertices, triangles).unwrap());
        let ours = volume(&check(&points, 1).to_trimesh().unwrap());
        assert!((ours - theirs).abs() <= 1e-4 * theirs, "{ours} vs {theirs}");
    }
}

/// The hull of a box's corners and its face centres (coplanar extras the hull must merge), a
/// hull shaped as the box `half` for tests that compare the two.
pub(crate) fn box_hull(half: glam::Vec3) -> crate::geometry::Shape {
    let mut points = Vec::new();
    for k in 0..8 {
        let s = |bit: usize| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
        points.push(half * glam::Vec3::new(s(0), s(1), s(2)));
    }
    for axis in [glam::Vec3::X, glam::Vec3::Y, glam::Vec3::Z] {
        points.push(half * axis);
        points.push(-half * axis);
    }
    crate::geometry::Shape::convex_hull(&points).unwrap()
}
