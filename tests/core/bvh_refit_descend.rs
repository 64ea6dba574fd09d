//! Refit after the vertices move, and the single-volume descent (mesh against a sphere), both
//! checked against brute force.

use crate::common;

use common::meshes::{torus, uv_sphere};
use common::rng::Rng;
use common::{Mesh, brute_force_pairs, leaf_test};
use glam::{Quat, Vec3};
use std::ops::ControlFlow;
use urto::bounding::{Aabb, BoundingSphere, Bv, Kdop14, Kdop18, Kdop26, Obb};
use urto::bvh::{BuildOptions, Bvh, BvhError, QueryScratch, TraversalOrder};

/// A smooth deformation: twist about z, stretch, ripple.
fn deform(mesh: &Mesh, amount: f32) -> Mesh {
    let vertices = mesh
        .vertices
        .iter()
        .map(|v| {
            let twist = Quat::from_rotation_z(amount * v.z);
            let stretched = Vec3::new(v.x * (1.0 + amount), v.y, v.z * (1.0 - 0.5 * amount));
            twist * stretched + Vec3::Z * (amount * (3.0 * v.x).sin())
        })
        .collect();
    Mesh {
        vertices,
        triangles: mesh.triangles.clone(),
    }
}

fn check_refit<B: Bv>() {
    let a0 = torus(1.0, 0.3, 16, 8);
    let b = uv_sphere(0.7, 8, 12);
    let options = BuildOptions::default();
    let mut ta = Bvh::<B>::build(&a0.vertices, &a0.triangles, &options).unwrap();
    let tb = Bvh::<B>::build(&b.vertices, &b.triangles, &options).unwrap();
    let a = deform(&a0, 0.6);
    ta.refit(&a.vertices, &a.triangles).unwrap();
    // Every node holds its moved triangles.
    for node in ta.nodes() {
        let mut stack = vec![*node];
        while let Some(n) = stack.pop() {
            match n.children() {
                Some([l, r]) => stack.extend([ta.nodes()[l as usize], ta.nodes()[r as usize]]),
                None => {
                    for &t in ta.leaf_triangles(&n) {
                        for v in a.corners(t) {
                            assert!(node.bv.contains_point(v, 0.0));
                        }
                    }
                }
            }
        }
        assert_eq!(node.size, node.bv.size());
    }
    // And the refitted tree still finds exactly what brute force finds.
    let mut rng = Rng::new(21);
    let mut scratch = QueryScratch::new();
    let mut found = Vec::new();
    for _ in 0..60 {
        let pose = rng.placement(2.0);
        let b_in_a = b.transformed_vertices(&pose);
        let truth = brute_force_pairs(&a, &b, &b_in_a);
        ta.intersecting_pairs(
            &tb,
            &pose,
            TraversalOrder::DepthFirst,
            &mut scratch,
            leaf_test(&a, &b, &b_in_a),
            &mut found,
        );
        found.sort_unstable();
        assert_eq!(found, truth);
    }
    // A refit must name the same triangles.
    assert_eq!(
        ta.refit(&a.vertices, &a.triangles[1..]),
        Err(BvhError::TriangleCountChanged {
            built: a.triangles.len(),
            given: a.triangles.len() - 1
        })
    );
}

#[test]
fn refitted_trees_hold_moved_triangles_and_answer_queries() {
    check_refit::<BoundingSphere>();
    check_refit::<Aabb>();
    check_refit::<Obb>();
    check_refit::<Kdop14>();
    check_refit::<Kdop18>();
    check_refit::<Kdop26>();
}

/// Distance-based sphere–box test (Arvo 1990).
fn box_meets_sphere(b: &Aabb, centre: Vec3, radius: f32) -> bool {
    centre.clamp(b.min, b.max).distance_squared(centre) <= radius * radius
}

fn check_descend<B: Bv>() {
    let mesh = torus(1.0, 0.3, 24, 12);
    let bvh = Bvh::<B>::build(&mesh.vertices, &mesh.triangles, &BuildOptions::default()).unwrap();
    let mut rng = Rng::new(31);
    let mut scratch = QueryScratch::new();
    let mut hits = 0;
    for _ in 0..300 {
        let centre = rng.in_ball(1.8);
        let radius = rng.range(0.01, 0.6);
        let meets = |t: u32| box_meets_sphere(&Aabb::from_points(mesh.corners(t)), centre, radius);
        let truth: Vec<u32> = (0..mesh.triangles.len() as u32)
            .filter(|&t| meets(t))
            .collect();
        let mut found = Vec::new();
        let stats = bvh.descend(
            &mut scratch,
            |bv| box_meets_sphere(&bv.local_aabb(), centre, radius),
            |t| {
                if meets(t) {
                    found.push(t);
                }
                ControlFlow::Continue(())
            },
        );
        found.sort_unstable();
        assert_eq!(found, truth);
        assert!(stats.leaf_tests as usize >= truth.len());
        hits += usize::from(!truth.is_empty());
        // Stopping at the first hit hands over exactly one matching triangle.
        let mut first = Vec::new();
        bvh.descend(
            &mut scratch,
            |bv| box_meets_sphere(&bv.local_aabb(), centre, radius),
            |t| {
                if meets(t) {
                    first.push(t);
                    return ControlFlow::Break(());
                }
                ControlFlow::Continue(())
            },
        );
        assert_eq!(first.len(), usize::from(!truth.is_empty()));
    }
    assert!(
        hits > 30 && hits < 290,
        "the spheres must both hit and miss: {hits}"
    );
}

#[test]
fn descent_against_a_sphere_matches_brute_force() {
    check_descend::<BoundingSphere>();
    check_descend::<Aabb>();
    check_descend::<Obb>();
    check_descend::<Kdop14>();
    check_descend::<Kdop18>();
    check_descend::<Kdop26>();
}
