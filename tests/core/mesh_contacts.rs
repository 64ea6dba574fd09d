//! Mesh contacts against brute force: on seeded random rigid placements of procedural and scanned
//! meshes, the hierarchy-accelerated tests (mesh–sphere, mesh–half-space, mesh–box, mesh–mesh)
//! agree with the same per-triangle tests run over *every* triangle (or triangle pair) and merged
//! by hand:
//! - intersect / not-intersect, and the exact set of triangles in contact (the hierarchy must
//!   miss none and invent none);
//! - the deepest depth and the merged normal (the side carrying most depth, the depth-weighted
//!   average of its triangle normals, then again without those more than 60° off);
//! - mesh–mesh: intersect / not equals `TriMesh::intersects_brute_force`, the intersecting pairs
//!   equal `TriMesh::intersecting_pairs_brute_force`;
//! - conventions: unit normal, `0 <= depth`, at most four points, no NaN, and swapping the pair
//!   flips the normal exactly;
//!
//! Where the test and the library compute in different frames (half-space and box: the brute
//! force works in world space), triangles within `BAND` of touching are not classified.

use crate::common;

use common::rng::Rng;
use glam::Vec3;
use urto::geometry::active_edges::ALL_EDGES_ACTIVE;
use urto::geometry::contacts::{
    ContactScratch, NO_TRIANGLE, contact, contact_triangle_capsule,
    contact_triangle_cuboid_with_edges, contact_triangle_triangle, contact_with_scratch,
};
use urto::geometry::mesh_io::load_ply;
use urto::geometry::{
    Capsule, ContactManifold, Cuboid, HalfSpace, Isometry, MeshCollider, Shape, TriMesh, Triangle,
    contact_triangle_sphere_with_edges, intersects_triangle_cuboid,
};

/// Rounding band around touching where world-space and local-space computations may disagree.
const BAND: f32 = 1e-4;

/// A scanned mesh from `tests/data`, centred on its box and scaled to radius ~`radius`.
fn scanned(name: &str, radius: f32) -> TriMesh {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    let mesh = load_ply(path).expect("test mesh loads");
    let c = mesh.local_aabb().center();
    let r = mesh
        .vertices()
        .iter()
        .fold(0.0f32, |m, v| m.max((*v - c).length()));
    let vertices = mesh
        .vertices()
        .iter()
        .map(|v| (*v - c) * (radius / r))
        .collect();
    TriMesh::new(vertices, mesh.triangles().to_vec()).expect("still valid")
}

fn collider(mesh: TriMesh) -> MeshCollider {
    MeshCollider::new(mesh).expect("valid collider")
}

/// The meshes the tests run on, with distinct triangle counts (see `mesh_mesh_*`).
fn meshes() -> Vec<(&'static str, MeshCollider)> {
    vec![
        ("ant", collider(scanned("ant.ply", 1.0))),
        ("torus", collider(TriMesh::torus(0.8, 0.3, 24, 12).unwrap())),
        ("sphere", collider(TriMesh::uv_sphere(0.9, 16, 8).unwrap())),
        (
            "floor",
            collider(
                TriMesh::height_field(3.0, 14, |x, y| 0.2 * (1.3 * x).sin() * (0.9 * y).cos())
                    .unwrap(),
            ),
        ),
    ]
}

/// The checks every manifold must pass.
fn assert_well_formed(m: &ContactManifold, what: &str) {
    assert!(
        m.normal.is_finite() && m.normal.is_normalized(),
        "{what}: normal {}",
        m.normal
    );
    assert!(!m.is_empty() && m.len() <= 4, "{what}: {} points", m.len());
    for p in m.points() {
        assert!(p.point.is_finite(), "{what}: point {}", p.point);
        assert!(
            p.depth >= 0.0 && p.depth.is_finite(),
            "{what}: depth {}",
            p.depth
        );
    }
}

/// Depth-weighted average of normals (plain average when all depths are zero).
fn average(contributions: &[(Vec3, f32)]) -> Vec3 {
    let weighted: Vec3 = contributions.iter().map(|(n, d)| *n * *d).sum();
    if contributions.iter().any(|(_, d)| *d > 0.0) {
        weighted.normalize()
    } else {
        contributions
            .iter()
            .map(|(n, _)| *n)
            .sum::<Vec3>()
            .normalize()
    }
}

/// The merge: the side (whose triangle gave the normal) carrying the most depth, then the
/// average over it, then the average of its contributions within 60° of that (all of the side
/// if none is); returns that normal and the deepest kept depth.
fn merged(contributions: &[(Vec3, f32, u8)]) -> (Vec3, f32) {
    let side_depth =
        |s: u8| -> f32 { contributions.iter().filter(|c| c.2 == s).map(|c| c.1).sum() };
    let side_count = |s: u8| contributions.iter().filter(|c| c.2 == s).count();
    let side = if side_count(1) == 0 {
        0
    } else if side_count(0) == 0 {
        1
    } else if side_depth(0) + side_depth(1) > 0.0 {
        u8::from(side_depth(1) > side_depth(0))
    } else {
        u8::from(side_count(1) > side_count(0))
    };
    let on_side: Vec<(Vec3, f32)> = contributions
        .iter()
        .filter(|c| c.2 == side)
        .map(|c| (c.0, c.1))
        .collect();
    let first = average(&on_side);
    let inliers: Vec<(Vec3, f32)> = on_side
        .iter()
        .copied()
        .filter(|(n, _)| n.dot(first) >= 0.5)
        .collect();
    let kept = if inliers.is_empty() {
        &on_side[..]
    } else {
        &inliers[..]
    };
    let deepest = kept.iter().fold(0.0f32, |d, c| d.max(c.1));
    (average(kept), deepest)
}

fn assert_normal_close(got: Vec3, want: Vec3, what: &str) {
    assert!(
        got.dot(want) > 1.0 - 1e-4,
        "{what}: normal {got} vs brute force {want}"
    );
}

fn sorted_mesh_hits(scratch: &ContactScratch) -> Vec<u32> {
    let mut hits: Vec<u32> = scratch.hits().iter().map(|h| h[0]).collect();
    hits.sort_unstable();
    hits
}

/// The hierarchy-accelerated mesh–primitive contact against `brute`, the triangle test run on
/// every triangle (in the mesh's frame: the triangle, its active edges, the body, the body's pose
/// in that frame), for 300 bodies `draw` places near each mesh (from the mesh and its pose).
fn matches_every_triangle(
    seed: u64,
    mut draw: impl FnMut(&mut Rng, &MeshCollider, &Isometry) -> (Shape, Isometry),
    brute: impl Fn(&Triangle, u8, &Shape, &Isometry) -> Option<ContactManifold>,
) {
    let mut rng = Rng::new(seed);
    let mut scratch = ContactScratch::new();
    scratch.set_record_hits(true);
    let (mut touching, mut apart) = (0, 0);
    for (name, mesh) in meshes() {
        let shape = Shape::TriMesh(mesh.clone());
        for _ in 0..300 {
            let pose = rng.placement(0.5);
            let (body, at) = draw(&mut rng, &mesh, &pose);
            let got = contact_with_scratch(&shape, &pose, &body, &at, &mut scratch);
            let local = pose.inv_mul(&at);
            let brute: Vec<(u32, Vec3, f32)> = mesh
                .mesh()
                .iter_triangles()
                .enumerate()
                .filter_map(|(t, tri)| {
                    brute(&tri, mesh.active_edges(t as u32), &body, &local)
                        .map(|m| (t as u32, pose.transform_vector(m.normal), m.max_depth()))
                })
                .collect();
            assert_eq!(got.is_some(), !brute.is_empty(), "{name}");
            let Some(m) = got else {
                apart += 1;
                continue;
            };
            touching += 1;
            assert_well_formed(&m, name);
            let expected: Vec<u32> = brute.iter().map(|b| b.0).collect();
            assert_eq!(sorted_mesh_hits(&scratch), expected, "{name}: triangles");
            let pairs: Vec<(Vec3, f32, u8)> = brute.iter().map(|b| (b.1, b.2, 0)).collect();
            let (normal, deepest) = merged(&pairs);
            assert!(
                (m.max_depth() - deepest).abs() < 1e-6,
                "{name}: {} vs {deepest}",
                m.max_depth()
            );
            assert_normal_close(m.normal, normal, name);
            let flipped = contact(&body, &at, &shape, &pose).expect("symmetric");
            assert_eq!(flipped, m.flipped(), "{name}: swapping flips the normal");
        }
    }
    assert!(touching > 300 && apart > 100, "{touching} / {apart}");
}

#[test]
fn mesh_sphere_matches_every_triangle_tested() {
    matches_every_triangle(
        11,
        |rng, mesh, pose| {
            let radius = rng.range(0.05, 0.7);
            let center = pose.transform_point(rng.in_ball(mesh.bounding_radius() + radius));
            (Shape::sphere(radius), Isometry::from_translation(center))
        },
        |tri, active, body, local| {
            let Shape::Sphere(s) = body else {
                unreachable!()
            };
            contact_triangle_sphere_with_edges(tri, active, local.translation, s)
        },
    );
}

#[test]
fn mesh_capsule_matches_every_triangle_tested() {
    matches_every_triangle(
        16,
        |rng, mesh, pose| {
            let capsule = Capsule {
                half_length: rng.range(0.0, 0.6),
                radius: rng.range(0.05, 0.5),
            };
            let reach = mesh.bounding_radius() + capsule.radius + capsule.half_length;
            let at = Isometry::new(pose.transform_point(rng.in_ball(reach)), rng.rotation());
            (Shape::Capsule(capsule), at)
        },
        |tri, active, body, local| {
            let Shape::Capsule(c) = body else {
                unreachable!()
            };
            let (p0, p1) = c.segment(local);
            contact_triangle_capsule(tri, active, p0, p1, c.radius)
        },
    );
}

#[test]
fn triangle_capsule_depth_agrees_with_parrys_segment_distance_within_1e_4() {
    use parry3d::math::{Pose, Vector};
    let v = |x: Vec3| Vector::from_array(x.to_array());
    let mut rng = Rng::new(17);
    let (mut apart, mut touching, mut pierced) = (0, 0, 0);
    for _ in 0..5000 {
        let tri =
            urto::geometry::Triangle::new(rng.in_ball(1.2), rng.in_ball(1.2), rng.in_ball(1.2));
        let (p0, p1) = (rng.in_ball(1.5), rng.in_ball(1.5));
        let radius = rng.range(0.0, 0.5);
        let ours = contact_triangle_capsule(&tri, ALL_EDGES_ACTIVE, p0, p1, radius);
        let pt = parry3d::shape::Triangle::new(v(tri.a), v(tri.b), v(tri.c));
        let ps = parry3d::shape::Segment::new(v(p0), v(p1));
        let gap = parry3d::query::distance(&Pose::IDENTITY, &pt, &Pose::IDENTITY, &ps)
            .expect("supported")
            .distance;
        if (gap - radius).abs() < BAND {
            continue;
        }
        if gap > 1e-5 {
            assert_eq!(
                ours.is_some(),
                gap < radius,
                "{tri:?} {p0} {p1} {radius}: {gap}"
            );
            if let Some(m) = ours {
                assert!(
                    (m.max_depth() - (radius - gap)).abs() < 1e-4,
                    "{m:?} vs {gap}"
                );
                touching += 1;
            } else {
                apart += 1;
            }
        } else if tri.normal().is_some() {
            // The segment crosses the triangle: pushed out at least the radius.
            let m = ours.expect("a crossing segment touches");
            assert!(m.max_depth() >= radius - 1e-5, "{m:?}");
            pierced += 1;
        }
    }
    println!("triangle-capsule vs parry: {touching} touching, {apart} apart, {pierced} pierced");
    assert!(
        touching > 300 && apart > 300 && pierced > 100,
        "{touching} {apart} {pierced}"
    );
}

#[test]
fn mesh_half_space_matches_every_vertex_tested() {
    let mut rng = Rng::new(12);
    let mut scratch = ContactScratch::new();
    scratch.set_record_hits(true);
    let (mut touching, mut apart) = (0, 0);
    for (name, mesh) in meshes() {
        let shape = Shape::TriMesh(mesh.clone());
        for _ in 0..300 {
            let pose = rng.placement(0.5);
            let h = HalfSpace {
                normal: rng.direction(),
            };
            let ground = Shape::HalfSpace(h);
            let at = Isometry::new(
                pose.translation + rng.in_ball(1.5 * mesh.bounding_radius()),
                rng.rotation(),
            );
            let got = contact_with_scratch(&shape, &pose, &ground, &at, &mut scratch);
            let n = at.transform_vector(h.normal);
            let height = |v: Vec3| n.dot(pose.transform_point(v) - at.translation);
            let heights: Vec<f32> = mesh.mesh().vertices().iter().map(|&v| height(v)).collect();
            let lowest = heights.iter().fold(f32::INFINITY, |m, &x| m.min(x));
            if lowest.abs() < BAND {
                continue;
            }
            assert_eq!(got.is_some(), lowest < 0.0, "{name}: lowest {lowest}");
            let Some(m) = got else {
                apart += 1;
                continue;
            };
            touching += 1;
            assert_well_formed(&m, name);
            assert_eq!(m.normal, -n, "{name}");
            assert!(
                (m.max_depth() + lowest).abs() < BAND,
                "{name}: {} vs {}",
                m.max_depth(),
                -lowest
            );
            // Every triangle with a corner clearly below is reported, and only triangles with a
            // corner (nearly) below.
            let hits = sorted_mesh_hits(&scratch);
            for (t, corners) in mesh.mesh().triangles().iter().enumerate() {
                let low = corners
                    .iter()
                    .fold(f32::INFINITY, |m, &i| m.min(heights[i as usize]));
                let reported = hits.binary_search(&(t as u32)).is_ok();
                assert!(low >= -BAND || reported, "{name}: triangle {t} missed");
                assert!(!reported || low < BAND, "{name}: triangle {t} invented");
            }
            let flipped = contact(&ground, &at, &shape, &pose).expect("symmetric");
            assert_eq!(flipped, m.flipped(), "{name}");
        }
    }
    assert!(touching > 300 && apart > 100, "{touching} / {apart}");
}

#[test]
fn mesh_box_matches_every_triangle_tested() {
    let mut rng = Rng::new(13);
    let mut scratch = ContactScratch::new();
    scratch.set_record_hits(true);
    let (mut touching, mut apart) = (0, 0);
    for (name, mesh) in meshes() {
        let shape = Shape::TriMesh(mesh.clone());
        for _ in 0..200 {
            let pose = rng.placement(0.5);
            let cuboid = Cuboid {
                half_extents: Vec3::new(
                    rng.range(0.05, 0.6),
                    rng.range(0.05, 0.6),
                    rng.range(0.05, 0.6),
                ),
            };
            let boxed = Shape::Cuboid(cuboid);
            let at = Isometry::new(
                pose.translation + rng.in_ball(mesh.bounding_radius() + 0.5),
                rng.rotation(),
            );
            let got = contact_with_scratch(&shape, &pose, &boxed, &at, &mut scratch);
            let world: Vec<_> = mesh
                .mesh()
                .iter_triangles()
                .map(|t| t.transformed(&pose))
                .collect();
            let brute: Vec<(u32, ContactManifold)> = world
                .iter()
                .enumerate()
                .filter_map(|(t, tri)| {
                    let active = mesh.active_edges(t as u32);
                    contact_triangle_cuboid_with_edges(tri, active, &at, &cuboid)
                        .map(|m| (t as u32, m))
                })
                .collect();
            let grown = Cuboid {
                half_extents: cuboid.half_extents + Vec3::splat(BAND),
            };
            let shrunk = Cuboid {
                half_extents: cuboid.half_extents - Vec3::splat(BAND),
            };
            let surely = |t: usize| intersects_triangle_cuboid(&world[t], &at, &shrunk);
            let maybe = |t: usize| intersects_triangle_cuboid(&world[t], &at, &grown);
            let hits = if got.is_some() {
                sorted_mesh_hits(&scratch)
            } else {
                vec![]
            };
            for t in 0..world.len() {
                let reported = hits.binary_search(&(t as u32)).is_ok();
                assert!(!surely(t) || reported, "{name}: triangle {t} missed");
                assert!(!reported || maybe(t), "{name}: triangle {t} invented");
            }
            let Some(m) = got else {
                apart += 1;
                continue;
            };
            touching += 1;
            assert_well_formed(&m, name);
            let clear: Vec<&(u32, ContactManifold)> =
                brute.iter().filter(|(_, c)| c.max_depth() > BAND).collect();
            if clear.len() == brute.len() && !brute.is_empty() {
                let pairs: Vec<(Vec3, f32, u8)> = brute
                    .iter()
                    .map(|(_, c)| (c.normal, c.max_depth(), 0))
                    .collect();
                let (normal, deepest) = merged(&pairs);
                assert!(
                    (m.max_depth() - deepest).abs() < BAND,
                    "{name}: {} vs {deepest}",
                    m.max_depth()
                );
                assert!(m.normal.dot(normal) > 0.999, "{name}");
            }
            let flipped = contact(&boxed, &at, &shape, &pose).expect("symmetric");
            assert_eq!(flipped, m.flipped(), "{name}");
        }
    }
    assert!(touching > 200 && apart > 50, "{touching} / {apart}");
}

/// Mesh pairs with A having more triangles than B: the library then keeps the given order (its
/// canonical order puts the larger mesh first) and carries B's triangles exactly as
/// `TriMesh::intersecting_pairs_brute_force` does, so the pair sets must be identical.
#[test]
fn mesh_mesh_matches_brute_force_pairs() {
    let mut rng = Rng::new(14);
    let mut scratch = ContactScratch::new();
    let all = meshes();
    let (mut touching, mut apart) = (0, 0);
    for (i, (name_a, a)) in all.iter().enumerate() {
        for (name_b, b) in &all[i + 1..] {
            let (a, b, what) = if a.mesh().triangle_count() >= b.mesh().triangle_count() {
                (a, b, format!("{name_a}-{name_b}"))
            } else {
                (b, a, format!("{name_b}-{name_a}"))
            };
            let (sa, sb) = (Shape::TriMesh(a.clone()), Shape::TriMesh(b.clone()));
            let reach = a.bounding_radius() + b.bounding_radius();
            for _ in 0..60 {
                let pose_a = Isometry::new(rng.in_ball(2.0), rng.rotation());
                let pose_b = pose_a * rng.placement(0.95 * reach);
                let got = contact_with_scratch(&sa, &pose_a, &sb, &pose_b, &mut scratch);
                let rel = pose_a.inv_mul(&pose_b);
                let truth = a.mesh().intersecting_pairs_brute_force(b.mesh(), &rel);
                assert_eq!(
                    got.is_some(),
                    a.mesh().intersects_brute_force(b.mesh(), &rel),
                    "{what}"
                );
                let mut hits: Vec<(u32, u32)> =
                    scratch.hits().iter().map(|h| (h[0], h[1])).collect();
                hits.sort_unstable();
                assert_eq!(hits, truth, "{what}: intersecting pairs");
                let Some(m) = got else {
                    apart += 1;
                    continue;
                };
                touching += 1;
                assert_well_formed(&m, &what);
                // Brute-force merge of the per-pair estimates, in world space.
                let estimates: Vec<(Vec3, f32, u8)> = truth
                    .iter()
                    .map(|&(ta, tb)| {
                        let ta = a.mesh().triangle(ta as usize).unwrap();
                        let tb = b.mesh().triangle(tb as usize).unwrap().transformed(&rel);
                        let c = contact_triangle_triangle(&ta, &tb).expect("they intersect");
                        // The normal is A's triangle's (side 0), B's reversed (side 1), or an
                        // edge axis filed with the triangle whose plane it is squarer to.
                        let square = |n: Option<Vec3>| n.map_or(0.0, |n| n.dot(c.normal).abs());
                        let side = if Some(c.normal) == ta.normal() {
                            0
                        } else if Some(-c.normal) == tb.normal() {
                            1
                        } else {
                            u8::from(square(tb.normal()) > square(ta.normal()))
                        };
                        (pose_a.transform_vector(c.normal), c.max_depth(), side)
                    })
                    .collect();
                let (normal, deepest) = merged(&estimates);
                assert!(
                    (m.max_depth() - deepest).abs() < 1e-6,
                    "{what}: {} vs {deepest}",
                    m.max_depth()
                );
                assert_normal_close(m.normal, normal, &what);
                // Swapping the pair flips the normal exactly and swaps the hits.
                let flipped = contact_with_scratch(&sb, &pose_b, &sa, &pose_a, &mut scratch)
                    .expect("symmetric");
                assert_eq!(flipped, m.flipped(), "{what}");
                assert!(
                    scratch
                        .hits()
                        .iter()
                        .all(|h| h[0] != NO_TRIANGLE && h[1] != NO_TRIANGLE)
                );
                let mut swapped: Vec<(u32, u32)> =
                    scratch.hits().iter().map(|h| (h[1], h[0])).collect();
                swapped.sort_unstable();
                assert_eq!(swapped, truth, "{what}: swapped hits");
            }
        }
    }
    assert!(touching > 100 && apart > 50, "{touching} / {apart}");
}

/// A closed mesh sunk into a floor by less than its facets' height: the normal points up (from
/// the floor to the body) and the depth is the sinking, for each of the test meshes (whose
/// triangles face outwards). Sunk deeper, the crossing facets are higher up the body and the
/// depth is underestimated (a documented limit of the estimate), but the normal still points up.
#[test]
fn a_mesh_sunk_into_a_floor_is_pushed_up_by_its_sinking() {
    let floor = collider(TriMesh::grid_floor(8.0, 16).unwrap());
    let ground = Shape::TriMesh(floor);
    for (name, mesh) in meshes().into_iter().filter(|(n, _)| *n != "floor") {
        let lowest = mesh.local_aabb().min.z;
        for sink in [0.002f32, 0.005, 0.01, 0.1] {
            let pose = Isometry::from_translation(Vec3::new(0.1, -0.2, -lowest - sink));
            let body = Shape::TriMesh(mesh.clone());
            let m = contact(&ground, &Isometry::IDENTITY, &body, &pose)
                .unwrap_or_else(|| panic!("{name} sunk by {sink} touches"));
            assert!(
                m.normal.dot(Vec3::Z) > 0.99,
                "{name} {sink}: normal {}",
                m.normal
            );
            let depth = m.max_depth();
            if sink <= 0.01 {
                assert!(
                    (depth - sink).abs() < 0.2 * sink,
                    "{name} {sink}: depth {depth}"
                );
            } else {
                assert!(
                    depth > 0.0 && depth <= 1.01 * sink,
                    "{name} {sink}: depth {depth}"
                );
            }
        }
    }
}

/// The test and example meshes are closed with outward triangles (what the mesh–mesh estimate
/// assumes): their signed volumes are positive.
#[test]
fn test_meshes_face_outwards() {
    let nut = ("nut", collider(scanned("nut.ply", 1.0)));
    let closed = meshes().into_iter().filter(|(n, _)| *n != "floor");
    for (name, mesh) in closed.chain([nut]) {
        let volume: f64 = mesh
            .mesh()
            .iter_triangles()
            .map(|t| {
                let [a, b, c] = t.vertices().map(Vec3::as_dvec3);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        assert!(volume > 0.0, "{name}: signed volume {volume}");
    }
}
