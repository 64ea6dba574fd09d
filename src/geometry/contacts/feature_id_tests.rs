//! Feature ids (`FeatureId`): a body resting on its supports, moved and turned, keeps the
//! names of its contact points, each on the same feature of the body.

use super::contact;
use crate::geometry::{
    ContactManifold, FeatureId, Isometry, MeshCollider, Shape, TriMesh, box_hull as hull_box,
};
use glam::{Quat, Vec3};

/// Each point's feature id and its place in the body's frame, the ids checked to be named and
/// distinct.
fn named_points(m: &ContactManifold, body: &Isometry, what: &str) -> Vec<(FeatureId, Vec3)> {
    let named: Vec<_> = m
        .points()
        .iter()
        .map(|p| (p.feature, body.inverse_transform_point(p.point)))
        .collect();
    for (k, (id, _)) in named.iter().enumerate() {
        assert!(id.is_some(), "{what}: point {k} unnamed in {m:?}");
        assert!(
            named[..k].iter().all(|(other, _)| other != id),
            "{what}: id {id:?} twice in {m:?}"
        );
    }
    named
}

#[test]
fn a_box_resting_on_five_supports_keeps_its_points_names_within_1_mm_of_the_same_corner_as_it_slides_and_turns()
 {
    let slab = Vec3::new(20.0, 20.0, 0.5);
    let floor = MeshCollider::new(TriMesh::grid_floor(40.0, 40).unwrap()).unwrap();
    let supports = [
        ("ground", Shape::half_space(Vec3::Z), -0.0),
        ("box slab", Shape::cuboid(slab), -0.5),
        ("hull slab", hull_box(slab), -0.5),
        ("mesh floor", Shape::TriMesh(floor), 0.0),
        ("unit box", Shape::cuboid(Vec3::splat(0.5)), -0.5),
    ];
    let half = Vec3::new(0.3, 0.2, 0.2);
    let bodies = [("box", Shape::cuboid(half)), ("hull box", hull_box(half))];
    // Sunk 2 mm, across the seams of the floor's 1 m triangles; the second pose slid 11 cm and
    // turned 0.35 rad (its corners 13 cm, still on the unit box).
    let poses = [
        Isometry::new(Vec3::new(0.02, 0.03, 0.198), Quat::from_rotation_z(0.1)),
        Isometry::new(Vec3::new(0.06, -0.08, 0.198), Quat::from_rotation_z(0.45)),
    ];
    for (support_name, support, z) in &supports {
        let at = Isometry::new(Vec3::new(0.0, 0.0, *z), Quat::IDENTITY);
        for (body_name, body) in &bodies {
            let what = format!("{body_name} on the {support_name}");
            let [first, second] = poses.map(|pose| {
                let m = contact(support, &at, body, &pose).unwrap();
                let mut named = named_points(&m, &pose, &what);
                named.sort_by_key(|(id, _)| id.0);
                named
            });
            assert_eq!(first.len(), 4, "{what}: {first:?}");
            for ((id0, p0), (id1, p1)) in first.iter().zip(&second) {
                assert_eq!(id0, id1, "{what}: {first:?} then {second:?}");
                assert!(p0.distance(*p1) < 1e-3, "{what}: {id0:?} at {p0} then {p1}");
            }
        }
    }
}
