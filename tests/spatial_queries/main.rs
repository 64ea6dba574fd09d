//! Spatial queries and collision layers: the index against brute force on random scenes,
//! parry3d's ray casts as an independent oracle, and the ECS face ([`SpatialQuery`], layers in
//! the step).

#[path = "../common/mod.rs"]
mod common;
mod ecs;
mod ecs_still;
mod nearest_and_casts;
mod shape_casts;
mod still_group;

use bevy_app::App;
use bevy_ecs::prelude::*;
use bevy_ecs::system::RunSystemOnce;
use common::rng::Rng;
use glam::Vec3;
use urto::bvh::QueryScratch;
use urto::geometry::contacts::contact;
use urto::geometry::{Isometry, MeshCollider, Shape, TriMesh};
use urto::prelude::*;
use urto::spatial::{
    CastHit, IndexUpdate, QueryError, QueryHit, Ray, SpatialIndex, StableIds, cast_sphere,
};

/// `n` colliders in a 40 m cube — balls, turned boxes, two meshes (a ball and a torus) — and
/// two half-spaces: a ground below everything and a tilted wall.
fn scene(rng: &mut Rng, n: usize) -> Vec<(Shape, Isometry)> {
    let ball = MeshCollider::new(TriMesh::uv_sphere(1.0, 12, 8).unwrap()).unwrap();
    let torus = MeshCollider::new(TriMesh::torus(1.2, 0.4, 16, 8).unwrap()).unwrap();
    let mut out: Vec<(Shape, Isometry)> = (0..n)
        .map(|_| {
            let pose = Isometry::new(rng.in_ball(20.0), rng.rotation());
            let shape = match rng.below(12) {
                0..4 => Shape::sphere(rng.range(0.2, 1.5)),
                10 | 11 => Shape::capsule(rng.range(0.0, 1.5), rng.range(0.1, 0.8)),
                4..8 => Shape::cuboid(Vec3::new(
                    rng.range(0.1, 1.2),
                    rng.range(0.1, 1.2),
                    rng.range(0.1, 1.2),
                )),
                8 => Shape::TriMesh(ball.clone()),
                _ => Shape::TriMesh(torus.clone()),
            };
            (shape, pose)
        })
        .collect();
    out.push((
        Shape::half_space(Vec3::Z),
        Isometry::from_translation(Vec3::new(0.0, 0.0, -25.0)),
    ));
    out.push((
        Shape::half_space(Vec3::new(-1.0, 0.2, 0.1)),
        Isometry::from_translation(Vec3::new(30.0, 0.0, 0.0)),
    ));
    out
}

fn indexed(colliders: &[(Shape, Isometry)]) -> SpatialIndex {
    let mut index = SpatialIndex::default();
    index.update(
        colliders
            .iter()
            .enumerate()
            .map(|(i, (s, p))| (i as u32, s, *p)),
    );
    index
}

/// A ray from somewhere in a 60 m cube, aimed at a point of the scene's cube.
fn random_ray(rng: &mut Rng) -> Ray {
    let origin = rng.in_ball(30.0);
    let target = rng.in_ball(20.0);
    Ray::new(origin, target - origin + rng.in_ball(0.5)).unwrap()
}

/// Every collider's own cast, sorted by distance then id: the brute-force answer.
fn brute_force_casts(
    colliders: &[(Shape, Isometry)],
    ray: &Ray,
    radius: f32,
    max: f32,
    keep: impl Fn(u32) -> bool,
) -> Vec<QueryHit> {
    let mut scratch = QueryScratch::new();
    let mut hits: Vec<QueryHit> = colliders
        .iter()
        .enumerate()
        .filter(|(i, _)| keep(*i as u32))
        .filter_map(|(i, (shape, pose))| {
            let aabb = shape.world_aabb(pose);
            let hit = cast_sphere(ray, radius, max, (shape, pose, &aabb), &mut scratch)?;
            Some(QueryHit { id: i as u32, hit })
        })
        .collect();
    hits.sort_by(|a, b| {
        a.hit
            .distance
            .total_cmp(&b.hit.distance)
            .then(a.id.cmp(&b.id))
    });
    hits
}

/// A target pose within 2 m of the origin, and a cast at it: a start within 6 m of it and the
/// unit direction from there to a point within 1.5 m of it (`None` where the two coincide).
fn random_target_and_cast(rng: &mut Rng) -> (Isometry, Option<(Vec3, Vec3)>) {
    let target = Isometry::new(rng.in_ball(2.0), rng.rotation());
    let start = target.translation + rng.in_ball(6.0);
    let aim = target.translation + rng.in_ball(1.5) - start;
    (
        target,
        aim.try_normalize().map(|direction| (start, direction)),
    )
}

/// The first hit of a cast over every collider by brute force (`cast` on each), ties to the
/// lower id: what the index's first-hit casts must answer.
fn brute_force_first(
    colliders: &[(Shape, Isometry)],
    mut cast: impl FnMut(&Shape, &Isometry) -> Option<CastHit>,
) -> Option<(u32, CastHit)> {
    colliders
        .iter()
        .enumerate()
        .filter_map(|(i, (s, p))| cast(s, p).map(|h| (i as u32, h)))
        .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance).then(a.0.cmp(&b.0)))
}

#[test]
fn first_and_all_ray_hits_equal_brute_force_on_1000_rays_over_402_colliders() {
    let mut rng = Rng::new(11);
    let colliders = scene(&mut rng, 400);
    let mut index = indexed(&colliders);
    let mut all = Vec::new();
    let (mut hits, mut filtered_differs) = (0, 0);
    for k in 0..1000 {
        let ray = random_ray(&mut rng);
        let max = if k % 3 == 0 { f32::INFINITY } else { 35.0 };
        let expected = brute_force_casts(&colliders, &ray, 0.0, max, |_| true);
        let first = index.cast_ray(&*colliders, &ray, max, |_| true).unwrap();
        assert_eq!(first, expected.first().copied(), "ray {k}: {ray:?}");
        index
            .cast_ray_all(&*colliders, &ray, max, |_| true, &mut all)
            .unwrap();
        assert_eq!(all, expected, "ray {k}");
        hits += usize::from(first.is_some());
        // A filter refusing odd ids: the first even hit.
        let even = index
            .cast_ray(&*colliders, &ray, max, |id| id % 2 == 0)
            .unwrap();
        let expected_even = brute_force_casts(&colliders, &ray, 0.0, max, |id| id % 2 == 0);
        assert_eq!(even, expected_even.first().copied());
        filtered_differs += usize::from(even != first);
    }
    // The scene is busy enough for the test to mean something.
    assert!(hits > 600, "{hits} of 1000 rays hit");
    assert!(filtered_differs > 200, "{filtered_differs}");
}

#[test]
fn sphere_casts_equal_brute_force_on_500_casts_of_radius_up_to_1_5() {
    let mut rng = Rng::new(12);
    let colliders = scene(&mut rng, 300);
    let mut index = indexed(&colliders);
    for k in 0..500 {
        let ray = random_ray(&mut rng);
        let radius = rng.range(0.0, 1.5);
        let expected = brute_force_casts(&colliders, &ray, radius, 40.0, |_| true);
        let first = index
            .cast_sphere(&*colliders, &ray, radius, 40.0, |_| true)
            .unwrap();
        assert_eq!(first, expected.first().copied(), "cast {k}");
    }
}

#[test]
fn box_and_capsule_casts_equal_brute_force_on_300_casts_over_302_colliders() {
    use urto::geometry::Capsule;
    use urto::spatial::{BoxCast, CapsuleCast, cast_box, cast_capsule};
    let mut rng = Rng::new(24);
    let colliders = scene(&mut rng, 300);
    let mut index = indexed(&colliders);
    let mut scratch = QueryScratch::new();
    let mut found = 0;
    for k in 0..300 {
        let ray = random_ray(&mut rng);
        let cast = BoxCast {
            pose: Isometry::new(ray.origin(), rng.rotation()),
            half_extents: Vec3::new(rng.range(0.0, 1.0), rng.range(0.0, 1.0), 0.4),
            direction: ray.direction(),
            max_distance: 40.0,
        };
        let expected = brute_force_first(&colliders, |s, p| cast_box(&cast, s, p, &mut scratch));
        let first = index.cast_box(&*colliders, &cast, |_| true).unwrap();
        assert_eq!(first.map(|h| (h.id, h.hit)), expected, "cast {k}");
        found += usize::from(first.is_some());
        let capsule = CapsuleCast {
            pose: cast.pose,
            capsule: Capsule {
                half_length: cast.half_extents.x,
                radius: cast.half_extents.y + 0.05,
            },
            direction: cast.direction,
            max_distance: 40.0,
        };
        let expected = brute_force_first(&colliders, |s, p| {
            cast_capsule(&capsule, s, p, &mut scratch)
        });
        let first = index.cast_capsule(&*colliders, &capsule, |_| true).unwrap();
        assert_eq!(first.map(|h| (h.id, h.hit)), expected, "capsule cast {k}");
        if k == 0 {
            // Unusable sizes are refused, not cast.
            let bad_box = BoxCast {
                half_extents: Vec3::new(0.5, f32::NAN, 0.5),
                ..cast
            };
            let refused = index.cast_box(&*colliders, &bad_box, |_| true);
            assert!(
                matches!(refused, Err(QueryError::BadSize(_))),
                "{refused:?}"
            );
            let bad_capsule = CapsuleCast {
                capsule: Capsule {
                    half_length: 0.5,
                    radius: -1.0,
                },
                ..capsule
            };
            let refused = index.cast_capsule(&*colliders, &bad_capsule, |_| true);
            assert!(
                matches!(refused, Err(QueryError::BadSize(_))),
                "{refused:?}"
            );
        }
    }
    assert!(found > 100, "{found}");
}

#[test]
fn overlaps_and_point_queries_equal_brute_force_on_400_queries() {
    let mut rng = Rng::new(13);
    let colliders = scene(&mut rng, 300);
    let mut index = indexed(&colliders);
    let mut found = Vec::new();
    let mut nonempty = 0;
    for k in 0..400 {
        let pose = Isometry::new(rng.in_ball(22.0), rng.rotation());
        let shape = if k % 2 == 0 {
            Shape::sphere(rng.range(0.0, 3.0))
        } else {
            Shape::cuboid(Vec3::new(rng.range(0.1, 3.0), 0.5, rng.range(0.1, 2.0)))
        };
        let expected: Vec<u32> = colliders
            .iter()
            .enumerate()
            .filter(|(_, (s, p))| contact(&shape, &pose, s, p).is_some())
            .map(|(i, _)| i as u32)
            .collect();
        index.overlapping(&*colliders, (&shape, &pose), |_| true, &mut found);
        assert_eq!(found, expected, "query {k}");
        nonempty += usize::from(!found.is_empty());
        let point = pose.translation;
        let expected: Vec<u32> = colliders
            .iter()
            .enumerate()
            .filter(|(_, (s, p))| {
                contact(
                    &Shape::sphere(0.0),
                    &Isometry::from_translation(point),
                    s,
                    p,
                )
                .is_some()
            })
            .map(|(i, _)| i as u32)
            .collect();
        index
            .containing(&*colliders, point, |_| true, &mut found)
            .unwrap();
        assert_eq!(found, expected, "point {k}");
    }
    assert!(nonempty > 100, "{nonempty}");
}

#[test]
fn a_refit_after_motion_answers_as_a_fresh_build_on_300_rays() {
    let mut rng = Rng::new(14);
    let mut colliders = scene(&mut rng, 200);
    let mut index = indexed(&colliders);
    for (_, pose) in colliders.iter_mut() {
        pose.translation += rng.in_ball(3.0);
        pose.rotation = rng.rotation() * pose.rotation;
    }
    let update = index.update(
        colliders
            .iter()
            .enumerate()
            .map(|(i, (s, p))| (i as u32, s, *p)),
    );
    assert_eq!(update, IndexUpdate::Refitted);
    let mut fresh = indexed(&colliders);
    for _ in 0..300 {
        let ray = random_ray(&mut rng);
        let a = index.cast_ray(&*colliders, &ray, 50.0, |_| true).unwrap();
        let b = fresh.cast_ray(&*colliders, &ray, 50.0, |_| true).unwrap();
        assert_eq!(a, b);
    }
}

#[test]
fn colliders_coming_and_going_for_60_rounds_answer_as_a_fresh_build_on_1200_rays_and_overlaps() {
    let mut rng = Rng::new(15);
    let pool = scene(&mut rng, 260);
    // Table order: (key, collider); a key is never reused, as an entity is not.
    let mut live: Vec<(u64, (Shape, Isometry))> =
        (0..200u64).map(|k| (k, pool[k as usize].clone())).collect();
    let mut next_key = 200u64;
    let (mut ids, mut index) = (StableIds::default(), SpatialIndex::default());
    let (mut kinds, mut a, mut b) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..60 {
        for _ in 0..rng.below(4) {
            let at = rng.below(live.len());
            live.swap_remove(at);
        }
        for _ in 0..rng.below(4) {
            let collider = pool[rng.below(pool.len())].clone();
            live.push((next_key, collider));
            next_key += 1;
        }
        for (_, (_, pose)) in live.iter_mut() {
            pose.translation += rng.in_ball(0.3);
        }
        // The colliders by their stable id (ids freed this round hold a stand-in never indexed).
        ids.begin();
        let given: Vec<u32> = live.iter().map(|(key, _)| ids.id(*key)).collect();
        ids.finish();
        let mut by_id = vec![
            (Shape::sphere(1.0), Isometry::IDENTITY);
            1 + *given.iter().max().unwrap() as usize
        ];
        for (id, (_, collider)) in given.iter().zip(&live) {
            by_id[*id as usize] = collider.clone();
        }
        let items = || {
            given
                .iter()
                .map(|&id| (id, &by_id[id as usize].0, by_id[id as usize].1))
        };
        kinds.push(index.update(items()));
        let mut fresh = SpatialIndex::default();
        fresh.update(items());
        for _ in 0..20 {
            let ray = random_ray(&mut rng);
            index
                .cast_ray_all(&*by_id, &ray, 60.0, |_| true, &mut a)
                .unwrap();
            fresh
                .cast_ray_all(&*by_id, &ray, 60.0, |_| true, &mut b)
                .unwrap();
            assert_eq!(a, b);
            let at = Isometry::from_translation(rng.in_ball(20.0));
            let (mut c, mut d) = (Vec::new(), Vec::new());
            index.overlapping(&*by_id, (&Shape::sphere(3.0), &at), |_| true, &mut c);
            fresh.overlapping(&*by_id, (&Shape::sphere(3.0), &at), |_| true, &mut d);
            assert_eq!(c, d);
        }
    }
    let kept = kinds.iter().filter(|k| **k == IndexUpdate::Updated).count();
    assert!(kept > 30, "{kept} of 60 rounds kept the tree: {kinds:?}");
}

/// The five shapes the parry3d oracles check, each with its parry twin and whether it is solid
/// (a mesh is a surface): a ball, a box, a capsule, a half-space and a torus mesh.
fn shapes_with_parry_twins() -> Vec<(Shape, Box<dyn parry3d::shape::Shape>, bool)> {
    let mesh = TriMesh::torus(1.5, 0.5, 24, 12).unwrap();
    let parry_mesh =
        parry3d::shape::TriMesh::new(mesh.vertices().to_vec(), mesh.triangles().to_vec()).unwrap();
    let half = Vec3::new(1.0, 0.4, 0.7);
    vec![
        (
            Shape::sphere(0.8),
            Box::new(parry3d::shape::Ball::new(0.8)),
            true,
        ),
        (
            Shape::cuboid(half),
            Box::new(parry3d::shape::Cuboid::new(half)),
            true,
        ),
        (
            Shape::capsule(0.9, 0.4),
            Box::new(parry3d::shape::Capsule::new_z(0.9, 0.4)),
            true,
        ),
        (
            Shape::half_space(Vec3::Z),
            Box::new(parry3d::shape::HalfSpace::new(Vec3::Z)),
            true,
        ),
        (
            Shape::TriMesh(MeshCollider::new(mesh).unwrap()),
            Box::new(parry_mesh),
            false,
        ),
    ]
}

/// parry3d's ray against one shape (`solid`: a ray starting inside hits at 0).
fn parry_ray(
    shape: &dyn parry3d::shape::Shape,
    pose: &Isometry,
    ray: &Ray,
    solid: bool,
) -> Option<(f32, Vec3)> {
    let at = parry3d::math::Pose::from_parts(pose.translation, pose.rotation);
    let r = parry3d::query::Ray::new(ray.origin(), ray.direction());
    shape
        .cast_ray_and_get_normal(&at, &r, 1.0e4, solid)
        .map(|hit| (hit.time_of_impact, hit.normal))
}

#[test]
fn ray_distances_agree_with_parry3d_within_1e_4_on_10000_rays_at_five_shapes() {
    let mut rng = Rng::new(15);
    let shapes = shapes_with_parry_twins();
    for (shape, parry_shape, solid) in &shapes {
        let (mut both, mut outside, mut normals_agree) = (0, 0, 0);
        for _ in 0..2000 {
            let pose = Isometry::new(rng.in_ball(5.0), rng.rotation());
            let origin = pose.translation + rng.in_ball(6.0);
            let ray = Ray::new(origin, pose.translation + rng.in_ball(1.5) - origin).unwrap();
            let aabb = shape.world_aabb(&pose);
            let ours = cast_sphere(
                &ray,
                0.0,
                1.0e4,
                (shape, &pose, &aabb),
                &mut QueryScratch::new(),
            );
            let theirs = parry_ray(parry_shape.as_ref(), &pose, &ray, *solid);
            match (ours, theirs) {
                (Some(h), Some((t, n))) => {
                    both += 1;
                    assert!(
                        (h.distance - t).abs() < 1e-4 * (1.0 + t),
                        "{shape:?} {ray:?}: {h:?} vs {t}"
                    );
                    if h.distance > 0.0 {
                        // Ours faces the caster; parry's mesh normal is the triangle's, on
                        // whichever side the ray came from.
                        assert!(h.normal.dot(ray.direction()) <= 1e-6, "{h:?}");
                        outside += 1;
                        normals_agree += usize::from(h.normal.dot(n).abs() > 0.999);
                    }
                }
                (None, None) => {}
                // A graze: one engine's tolerance takes it, the other's does not. The ray then
                // passes within 1e-3 of the surface.
                (ours, theirs) => {
                    let d = ours.map(|h| h.distance).or(theirs.map(|t| t.0)).unwrap();
                    let near = contact(
                        &Shape::sphere(1e-3),
                        &Isometry::from_translation(ray.at(d)),
                        shape,
                        &pose,
                    );
                    assert!(near.is_some(), "{shape:?} {ray:?}: {ours:?} vs {theirs:?}");
                }
            }
        }
        assert!(both > 300, "{shape:?}: {both} hits");
        // Rays starting inside a solid hit at 0 with no normal to compare; of the others, all
        // but edge and vertex hits share parry's normal.
        assert!(outside > 200, "{shape:?}: {outside} hits from outside");
        assert!(
            normals_agree * 100 > outside * 95,
            "{shape:?}: {normals_agree} of {outside}"
        );
    }
}

#[test]
fn bad_queries_are_refused_with_an_error() {
    assert!(Ray::new(Vec3::NAN, Vec3::X).is_err());
    assert!(Ray::new(Vec3::ZERO, Vec3::ZERO).is_err());
    let colliders = vec![(Shape::sphere(1.0), Isometry::default())];
    let mut index = indexed(&colliders);
    let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X).unwrap();
    assert!(
        index
            .cast_ray(&*colliders, &ray, f32::NAN, |_| true)
            .is_err()
    );
    assert!(index.cast_ray(&*colliders, &ray, -1.0, |_| true).is_err());
    assert!(
        index
            .cast_sphere(&*colliders, &ray, f32::INFINITY, 10.0, |_| true)
            .is_err()
    );
    assert!(
        index
            .containing(&*colliders, Vec3::NAN, |_| true, &mut Vec::new())
            .is_err()
    );
    let hit = index
        .cast_ray(&*colliders, &ray, 10.0, |_| true)
        .unwrap()
        .unwrap();
    assert!((hit.hit.distance - 4.0).abs() < 1e-5);
}
