//! Spatial queries and collision layers: the index against brute force on random scenes,
//! parry3d's ray casts as an independent oracle, and the ECS face ([`SpatialQuery`], layers in
//! the step).

mod common;

use bevy_app::App;
use bevy_ecs::prelude::*;
use bevy_ecs::system::RunSystemOnce;
use common::rng::Rng;
use glam::Vec3;
use urto::bvh::QueryScratch;
use urto::geometry::contacts::contact;
use urto::geometry::{Isometry, MeshCollider, Shape, TriMesh};
use urto::prelude::*;
use urto::spatial::{QueryError, QueryHit, Ray, SpatialIndex, cast_sphere};

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
        let expected = colliders
            .iter()
            .enumerate()
            .filter_map(|(i, (s, p))| cast_box(&cast, s, p, &mut scratch).map(|h| (i as u32, h)))
            .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance).then(a.0.cmp(&b.0)));
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
        let expected = colliders
            .iter()
            .enumerate()
            .filter_map(|(i, (s, p))| {
                cast_capsule(&capsule, s, p, &mut scratch).map(|h| (i as u32, h))
            })
            .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance).then(a.0.cmp(&b.0)));
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
    assert_eq!(update, urto::spatial::IndexUpdate::Refitted);
    let mut fresh = indexed(&colliders);
    for _ in 0..300 {
        let ray = random_ray(&mut rng);
        let a = index.cast_ray(&*colliders, &ray, 50.0, |_| true).unwrap();
        let b = fresh.cast_ray(&*colliders, &ray, 50.0, |_| true).unwrap();
        assert_eq!(a, b);
    }
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

const BALLS: LayerMask = LayerMask(1 << 1);

/// Ground, a static box at x = 5 and a ball in layer [`BALLS`] resting at the origin.
fn ecs_scene() -> (App, [Entity; 3]) {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    let ground = world.spawn((Collider::half_space(Vec3::Z), Static)).id();
    let block = world
        .spawn((
            Collider::cuboid(1.0, 1.0, 1.0),
            Position::new(5.0, 0.0, 1.0),
            Static,
        ))
        .id();
    let ball = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 0.5),
            Velocity::default(),
            CollisionLayers::new(BALLS, LayerMask::ALL),
        ))
        .id();
    urto::step(app.world_mut(), 1).unwrap();
    (app, [ground, block, ball])
}

#[test]
fn spatial_query_hits_filters_and_lists_entities_in_a_bevy_world() {
    let (mut app, [ground, block, ball]) = ecs_scene();
    let world = app.world_mut();
    let top = Vec3::new(0.0, 0.0, 10.0);
    let results = world
        .run_system_once(move |q: SpatialQuery| {
            let all = SpatialQueryFilter::default();
            let first = q
                .cast_ray(top, -Vec3::Z, f32::INFINITY, &all)
                .unwrap()
                .unwrap();
            let no_balls = SpatialQueryFilter::from_mask(!BALLS);
            let past_ball = q
                .cast_ray(top, -Vec3::Z, 100.0, &no_balls)
                .unwrap()
                .unwrap();
            let excluded = all.clone().with_excluded([first.entity]);
            let excluding = q
                .cast_ray(top, -Vec3::Z, 100.0, &excluded)
                .unwrap()
                .unwrap();
            let every = q.cast_ray_all(top, -Vec3::Z, 100.0, &all).unwrap();
            let side = q
                .cast_sphere(0.5, Vec3::new(0.0, 0.0, 1.0), Vec3::X, 20.0, &all)
                .unwrap()
                .unwrap();
            let inside = q.containing_point(Vec3::new(5.2, 0.3, 1.5), &all).unwrap();
            let around = q
                .overlapping(
                    &Shape::sphere(1.0),
                    Isometry::from_translation(Vec3::new(0.0, 0.0, 0.9)),
                    &all,
                )
                .unwrap();
            let refused = q.cast_ray(Vec3::NAN, Vec3::X, 1.0, &all).is_err()
                && q.cast_box(Vec3::ONE, Isometry::IDENTITY, Vec3::ZERO, 1.0, &all)
                    .is_err();
            (
                first, past_ball, excluding, every, side, inside, around, refused,
            )
        })
        .unwrap();
    let (first, past_ball, excluding, every, side, inside, around, refused) = results;
    assert_eq!(first.entity, ball);
    // The ball rests with its top at 1 m: the ray travels 9 m.
    assert!((first.distance - 9.0).abs() < 0.02, "{first:?}");
    assert!((first.normal - Vec3::Z).length() < 1e-3);
    assert_eq!(past_ball.entity, ground);
    assert!((past_ball.distance - 10.0).abs() < 1e-4);
    assert_eq!(excluding.entity, ground);
    assert_eq!(
        every.iter().map(|h| h.entity).collect::<Vec<_>>(),
        [ball, ground]
    );
    // A ball of 0.5 m cast along x from the resting ball's place meets the box's face at 4 m,
    // 3.5 m on; starting inside the resting ball it hits that at once.
    assert_eq!(side.entity, ball);
    assert_eq!(side.distance, 0.0);
    assert_eq!(inside, [block]);
    assert!(around.contains(&ball) && around.contains(&ground) && !around.contains(&block));
    assert!(refused);
}

#[test]
fn the_query_index_refits_after_a_step_and_rebuilds_after_a_spawn() {
    let (mut app, [.., ball]) = ecs_scene();
    let cast = |app: &mut App| {
        app.world_mut()
            .run_system_once(|q: SpatialQuery| {
                let all = SpatialQueryFilter::default();
                q.cast_ray(Vec3::new(0.0, 0.0, 10.0), -Vec3::Z, 100.0, &all)
                    .unwrap()
                    .map(|h| h.entity)
            })
            .unwrap()
    };
    assert_eq!(cast(&mut app), Some(ball));
    let counts = |app: &App| {
        app.world()
            .resource::<urto::plugins::SpatialQueryIndex>()
            .refreshes()
    };
    assert_eq!(counts(&app), (1, 0));
    // Two queries in one step refresh once.
    cast(&mut app);
    assert_eq!(counts(&app), (1, 0));
    urto::step(app.world_mut(), 1).unwrap();
    cast(&mut app);
    assert_eq!(counts(&app), (1, 1));
    // A ball spawned above: seen after the next step (a rebuild).
    let high = common::ball(&mut app, Vec3::new(0.0, 0.0, 6.0));
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(cast(&mut app), Some(high));
    assert_eq!(counts(&app), (2, 1));
    // A quarantined collider is never hit.
    app.world_mut().entity_mut(high).insert(Quarantined {
        reason: "test".into(),
    });
    assert_eq!(cast(&mut app), Some(ball));
}

#[test]
fn layers_that_do_not_interact_let_bodies_pass_through_the_ground_and_each_other() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    world.spawn((Collider::half_space(Vec3::Z), Static));
    let resting = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(-3.0, 0.0, 2.0),
            Velocity::default(),
        ))
        .id();
    // Filters out the ground's layer (the default one).
    let ghost = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(3.0, 0.0, 2.0),
            Velocity::default(),
            CollisionLayers::new(BALLS, BALLS),
        ))
        .id();
    // Two balls thrown at each other, one of which refuses the other's layer.
    let left = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(-2.0, 10.0, 50.0),
            Velocity(Vec3::new(4.0, 0.0, 0.0)),
            CollisionLayers::new(BALLS, !BALLS),
        ))
        .id();
    let right = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(2.0, 10.0, 50.0),
            Velocity(Vec3::new(-4.0, 0.0, 0.0)),
            CollisionLayers::new(BALLS, LayerMask::ALL),
        ))
        .id();
    urto::step(app.world_mut(), 120).unwrap();
    let z = |app: &App, e| app.world().get::<Position>(e).unwrap().0;
    assert!(
        (z(&app, resting).z - 0.5).abs() < 0.02,
        "{}",
        z(&app, resting)
    );
    assert!(z(&app, ghost).z < -1.0, "{}", z(&app, ghost));
    // Each kept its x velocity: they crossed.
    assert!(z(&app, left).x > 1.5 && z(&app, right).x < -1.5);
}

#[test]
fn ccd_lets_a_fast_ball_through_a_thin_wall_its_layers_ignore() {
    let mut app = common::app();
    let world = app.world_mut();
    world.spawn((
        Collider::cuboid(0.05, 5.0, 5.0),
        Position::new(0.0, 0.0, 0.0),
        Static,
    ));
    let fast = |world: &mut World, y: f32, layers: CollisionLayers| {
        world
            .spawn((
                Collider::sphere(0.1),
                Position::new(-2.0, y, 0.0),
                Velocity(Vec3::new(300.0, 0.0, 0.0)),
                Ccd,
                layers,
            ))
            .id()
    };
    let stopped = fast(world, -2.0, CollisionLayers::default());
    let ghost = fast(world, 2.0, CollisionLayers::new(BALLS, BALLS));
    urto::step(app.world_mut(), 1).unwrap();
    let x = |e| app.world().get::<Position>(e).unwrap().0.x;
    assert!(x(stopped) < 0.0, "{}", x(stopped));
    assert!(x(ghost) > 2.5, "{}", x(ghost));
}

#[test]
fn nearest_distances_agree_with_parrys_projections_within_1e_5_on_2500_points_at_five_shapes() {
    use urto::spatial::nearest_point;
    let mut rng = Rng::new(21);
    let shapes = shapes_with_parry_twins();
    let mut scratch = QueryScratch::new();
    for (shape, parry_shape, solid) in &shapes {
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..500 {
            let pose = Isometry::new(rng.in_ball(3.0), rng.rotation());
            let p = pose.translation + rng.in_ball(1.6);
            let ours = nearest_point(shape, &pose, p, &mut scratch);
            let at = parry3d::math::Pose::from_parts(pose.translation, pose.rotation);
            let theirs = parry_shape.project_point(&at, p, *solid);
            let point = Vec3::from_array(theirs.point.to_array());
            assert_eq!(
                ours.inside, theirs.is_inside,
                "{shape:?} {p}: {ours:?} vs {theirs:?}"
            );
            // The distances agree tightly; the points a little less where the nearest point
            // slides along a nearly flat stretch of a mesh (the distance is flat there).
            let context = format!("{shape:?} {p}: {ours:?} vs {point}");
            assert!(
                (ours.distance - p.distance(point)).abs() < 1e-5 * (1.0 + ours.distance),
                "{context}"
            );
            assert!((ours.point - point).length() < 1e-3, "{context}");
            assert!((ours.distance - p.distance(ours.point)).abs() < 1e-5);
            if ours.inside {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        assert!(outside > 100, "{shape:?}: {outside} outside");
        assert!(!solid || inside > 20, "{shape:?}: {inside} inside");
    }
}

#[test]
fn nearest_colliders_equal_brute_force_on_500_points_over_402_colliders() {
    use urto::spatial::nearest_point;
    let mut rng = Rng::new(22);
    let colliders = scene(&mut rng, 400);
    let mut index = indexed(&colliders);
    let mut scratch = QueryScratch::new();
    let mut limited = 0;
    for k in 0..500 {
        let p = rng.in_ball(28.0);
        let max = if k % 5 == 0 { 1.0 } else { f32::INFINITY };
        let brute = colliders
            .iter()
            .enumerate()
            .map(|(i, (s, pose))| (i as u32, nearest_point(s, pose, p, &mut scratch)))
            .filter(|(_, h)| h.distance <= max)
            .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance).then(a.0.cmp(&b.0)));
        let ours = index.nearest(&*colliders, p, max, |_| true).unwrap();
        assert_eq!(ours.map(|o| o.0), brute.map(|b| b.0), "point {k} {p}");
        if let (Some(o), Some(b)) = (ours, brute) {
            assert_eq!(o.1, b.1);
        }
        limited += usize::from(max < 1e3 && ours.is_none());
    }
    assert!(limited > 10, "{limited} queries found nothing within 1 m");
    assert!(
        index
            .nearest(&*colliders, Vec3::NAN, 1.0, |_| true)
            .is_err()
    );
    assert!(
        index
            .nearest(&*colliders, Vec3::ZERO, -1.0, |_| true)
            .is_err()
    );
}

#[test]
fn spatial_query_finds_the_nearest_collider_and_casts_a_box_with_a_filter() {
    let (mut app, [ground, block, ball]) = ecs_scene();
    let world = app.world_mut();
    let (near_ball, past_ball, inside) = world
        .run_system_once(|q: SpatialQuery| {
            let all = SpatialQueryFilter::default();
            let above = Vec3::new(0.0, 0.0, 3.0);
            let near_ball = q.nearest_point(above, f32::INFINITY, &all).unwrap();
            let no_balls = SpatialQueryFilter::from_mask(!BALLS);
            let past_ball = q.nearest_point(above, f32::INFINITY, &no_balls).unwrap();
            let inside = q
                .nearest_point(Vec3::new(5.2, 0.3, 1.5), 10.0, &all)
                .unwrap();
            (near_ball, past_ball, inside)
        })
        .unwrap();
    let near_ball = near_ball.unwrap();
    assert_eq!(near_ball.entity, ball);
    // The ball rests with its top at 1 m.
    assert!((near_ball.distance - 2.0).abs() < 0.02, "{near_ball:?}");
    let past_ball = past_ball.unwrap();
    assert_eq!(past_ball.entity, ground);
    assert!((past_ball.distance - 3.0).abs() < 1e-5, "{past_ball:?}");
    let inside = inside.unwrap();
    assert_eq!(
        (inside.entity, inside.inside, inside.distance),
        (block, true, 0.0)
    );
}

/// parry3d's first hit of `caster` at `pose` moved along the unit `direction` for at most 12 m
/// against `target` at `at`, stopping at penetration (as our casts do).
fn parry_cast(
    (caster, pose): (&dyn parry3d::shape::Shape, &Isometry),
    direction: Vec3,
    (target, at): (&dyn parry3d::shape::Shape, &Isometry),
) -> Option<parry3d::query::ShapeCastHit> {
    use parry3d::math::{Pose, Vector};
    let pose_of = |p: &Isometry| Pose::from_parts(p.translation, p.rotation);
    let options = parry3d::query::ShapeCastOptions {
        max_time_of_impact: 12.0,
        stop_at_penetration: true,
        ..Default::default()
    };
    parry3d::query::cast_shapes(
        &pose_of(pose),
        Vector::from_array(direction.to_array()),
        caster,
        &pose_of(at),
        Vector::ZERO,
        target,
        options,
    )
    .expect("supported")
}

#[test]
fn box_casts_touch_within_1e_4_and_agree_with_parry3d_within_1e_3_on_2500_casts_at_five_shapes() {
    use urto::spatial::{BoxCast, cast_box};
    let mut rng = Rng::new(23);
    let shapes = shapes_with_parry_twins();
    let mut scratch = QueryScratch::new();
    for (shape, parry_shape, _) in &shapes {
        let (mut hits, mut misses, mut worst) = (0, 0, 0.0f32);
        for _ in 0..500 {
            let target = Isometry::new(rng.in_ball(2.0), rng.rotation());
            let start = target.translation + rng.in_ball(6.0);
            let aim = target.translation + rng.in_ball(1.5) - start;
            let Some(direction) = aim.try_normalize() else {
                continue;
            };
            let cast = BoxCast {
                pose: Isometry::new(start, rng.rotation()),
                half_extents: Vec3::new(rng.range(0.1, 0.6), rng.range(0.1, 0.6), 0.3),
                direction,
                max_distance: 12.0,
            };
            let ours = cast_box(&cast, shape, &target, &mut scratch);
            let caster = parry3d::shape::Cuboid::new(cast.half_extents);
            let theirs = parry_cast(
                (&caster, &cast.pose),
                direction,
                (parry_shape.as_ref(), &target),
            );
            let context = format!("{shape:?} {cast:?} {target:?}: {ours:?} vs {theirs:?}");
            match (ours, theirs) {
                (Some(h), Some(t)) => {
                    let error = (h.distance - t.time_of_impact).abs();
                    assert!(error < 1e-3, "{context}");
                    worst = worst.max(error);
                    // Independently of parry: touching at our distance, apart 1e-4 before it.
                    let box_at = |d: f32, grow: f32| {
                        let at = Isometry::new(
                            cast.pose.translation + direction * d,
                            cast.pose.rotation,
                        );
                        let s = Shape::cuboid(cast.half_extents + Vec3::splat(grow));
                        contact(&s, &at, shape, &target).is_some()
                    };
                    assert!(box_at(h.distance, 1e-4), "not touching: {context}");
                    if h.distance > 1e-3 {
                        assert!(
                            !box_at(h.distance - 1e-4, 0.0),
                            "already touching: {context}"
                        );
                    }
                    assert!(h.normal.is_normalized(), "{context}");
                    hits += 1;
                }
                (None, None) => misses += 1,
                // A graze: the two engines' tolerances decide differently; the box then passes
                // within a hair of the target.
                (ours, theirs) => {
                    let d = ours
                        .map(|h| h.distance)
                        .or(theirs.map(|t| t.time_of_impact));
                    let at = Isometry::new(
                        cast.pose.translation + direction * d.unwrap(),
                        cast.pose.rotation,
                    );
                    let grown = Shape::cuboid(cast.half_extents + Vec3::splat(1e-3));
                    assert!(contact(&grown, &at, shape, &target).is_some(), "{context}");
                }
            }
        }
        eprintln!("box cast at {shape:?}: {hits} hits, {misses} misses, worst {worst}");
        assert!(
            hits > 200 && misses > 10,
            "{shape:?}: {hits} hits, {misses} misses"
        );
    }
}

/// parry3d's capsule casts run up to 5e-3 from the contact (its rounded-segment GJK tolerance),
/// so each of ours is also checked independently: touching within 1e-4, apart 1e-4 before.
#[test]
fn capsule_casts_touch_within_1e_4_and_agree_with_parry3d_within_1e_2_on_2500_casts() {
    use urto::geometry::Capsule;
    use urto::spatial::{CapsuleCast, cast_capsule};
    let mut rng = Rng::new(25);
    let mut scratch = QueryScratch::new();
    for (shape, parry_shape, _) in &shapes_with_parry_twins() {
        let (mut hits, mut misses, mut worst) = (0, 0, 0.0f32);
        for _ in 0..500 {
            let target = Isometry::new(rng.in_ball(2.0), rng.rotation());
            let start = target.translation + rng.in_ball(6.0);
            let aim = target.translation + rng.in_ball(1.5) - start;
            let Some(direction) = aim.try_normalize() else {
                continue;
            };
            let capsule = Capsule {
                half_length: rng.range(0.0, 0.7),
                radius: rng.range(0.1, 0.5),
            };
            let cast = CapsuleCast {
                pose: Isometry::new(start, rng.rotation()),
                capsule,
                direction,
                max_distance: 12.0,
            };
            let ours = cast_capsule(&cast, shape, &target, &mut scratch);
            let caster = parry3d::shape::Capsule::new_z(capsule.half_length, capsule.radius);
            let theirs = parry_cast(
                (&caster, &cast.pose),
                direction,
                (parry_shape.as_ref(), &target),
            );
            let context = format!("{shape:?} {cast:?} {target:?}: {ours:?} vs {theirs:?}");
            let capsule_at = |d: f32, grow: f32| {
                let at = Isometry::new(cast.pose.translation + direction * d, cast.pose.rotation);
                let s = Shape::capsule(capsule.half_length, capsule.radius + grow);
                contact(&s, &at, shape, &target).is_some()
            };
            match (ours, theirs) {
                (Some(h), Some(t)) => {
                    assert!(h.normal.is_normalized(), "{context}");
                    // Independently of parry: touching at our distance, apart 1e-4 before it.
                    assert!(capsule_at(h.distance, 1e-4), "not touching: {context}");
                    if h.distance > 1e-3 {
                        assert!(!capsule_at(h.distance - 1e-4, 0.0), "already: {context}");
                    }
                    let error = (h.distance - t.time_of_impact).abs();
                    assert!(error < 1e-2, "{context}");
                    worst = worst.max(error);
                    hits += 1;
                }
                (None, None) => misses += 1,
                // A graze: the capsule passes within a hair of the target.
                (ours, theirs) => {
                    let d = ours
                        .map(|h| h.distance)
                        .or(theirs.map(|t| t.time_of_impact));
                    assert!(capsule_at(d.unwrap(), 1e-3), "{context}");
                }
            }
        }
        eprintln!("capsule cast at {shape:?}: {hits} hits, {misses} misses, worst {worst}");
        assert!(
            hits > 200 && misses > 5,
            "{shape:?}: {hits} hits, {misses} misses"
        );
    }
}
