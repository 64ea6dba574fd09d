//! The ECS face: `SpatialQuery` in a Bevy world (hits, filters, entities, nearest, box casts),
//! the index following steps and spawns, and layers in the step and in continuous collision.

use super::*;

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
fn the_query_index_refits_after_a_step_and_keeps_its_tree_through_a_spawn_and_a_despawn() {
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
        let r = app
            .world()
            .resource::<urto::plugins::SpatialQueryIndex>()
            .refreshes();
        (r.rebuilds, r.updates, r.refits)
    };
    assert_eq!(counts(&app), (1, 0, 0));
    // Two queries in one step refresh once.
    cast(&mut app);
    assert_eq!(counts(&app), (1, 0, 0));
    urto::step(app.world_mut(), 1).unwrap();
    cast(&mut app);
    assert_eq!(counts(&app), (1, 0, 1));
    // A ball spawned above: seen after the next step, the tree kept (an update).
    let high = common::ball(&mut app, Vec3::new(0.0, 0.0, 6.0));
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(cast(&mut app), Some(high));
    assert_eq!(counts(&app), (1, 1, 1));
    // Despawned: the ray reaches the resting ball again, still without a rebuild.
    app.world_mut().despawn(high);
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(cast(&mut app), Some(ball));
    assert_eq!(counts(&app), (1, 2, 1));
    // Spawned again (its id reused by another entity): hit as itself.
    let again = common::ball(&mut app, Vec3::new(0.0, 0.0, 7.0));
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(cast(&mut app), Some(again));
    // A quarantined collider is never hit.
    app.world_mut().entity_mut(again).insert(Quarantined {
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
    // A cylinder (radius 0.5, upright) cast along x above the ball meets the block's face at
    // x = 4, 3.5 m on; a mesh cannot be cast.
    let (cylinder, refused) = app
        .world_mut()
        .run_system_once(|q: SpatialQuery| {
            let all = SpatialQueryFilter::default();
            let at = Isometry::from_translation(Vec3::new(0.0, 0.0, 1.5));
            let cylinder = Shape::cylinder(0.4, 0.5);
            let hit = q.cast_shape(&cylinder, at, Vec3::X, 20.0, &all).unwrap();
            let cube = TriMesh::cuboid(Vec3::ONE).unwrap();
            let mesh = Shape::TriMesh(MeshCollider::new(cube).unwrap());
            let refused = q.cast_shape(&mesh, at, Vec3::X, 1.0, &all);
            (hit, refused)
        })
        .unwrap();
    let cylinder = cylinder.unwrap();
    assert_eq!(cylinder.entity, block);
    assert!((cylinder.distance - 3.5).abs() < 1e-3, "{cylinder:?}");
    assert_eq!(refused, Err(QueryError::NotCastable));
}

/// Bodies whose layers interact with none are left out of the broad phase, and each way back
/// in works within the step: layers written or removed, and a part below the root with layers
/// of its own. Balls dropped from 2 m rest on the ground (centre at 0.5 m) or fall through it.
#[test]
fn bodies_whose_layers_interact_with_none_leave_the_broad_phase_and_come_back_within_1_step() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let none = CollisionLayers::new(LayerMask::NONE, LayerMask::NONE);
    let unfiltered = CollisionLayers::new(LayerMask::ALL, LayerMask::NONE);
    let world = app.world_mut();
    world.spawn((Collider::half_space(Vec3::Z), Static));
    let mut ball = |x: f32, layers: Option<CollisionLayers>| {
        let mut e = world.spawn((
            Collider::sphere(0.5),
            Position::new(x, 0.0, 2.0),
            Velocity::default(),
        ));
        if let Some(l) = layers {
            e.insert(l);
        }
        e.id()
    };
    let ghost = ball(0.0, Some(none));
    let given = ball(3.0, Some(unfiltered));
    let unset = ball(6.0, Some(none));
    let solid = ball(9.0, None);
    let sleeper = ball(12.0, None);
    let compound = ball(15.0, Some(none));
    world.spawn((
        Collider::sphere(0.5),
        Position(Vec3::ZERO),
        ChildOf(compound),
    ));
    let moving = |app: &App| {
        let stats = app.world().resource::<PhysicsStats>();
        stats.counter("broad_phase/moving_bodies").unwrap_or(-1.0)
    };
    urto::step(app.world_mut(), 5).unwrap();
    assert_eq!(
        moving(&app),
        3.0,
        "the solid ball, the sleeper, the compound"
    );
    app.world_mut()
        .entity_mut(given)
        .insert(CollisionLayers::default());
    app.world_mut()
        .entity_mut(unset)
        .remove::<CollisionLayers>();
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(moving(&app), 5.0);
    urto::step(app.world_mut(), 150).unwrap();
    let z = |app: &App, e| app.world().get::<Position>(e).unwrap().0.z;
    for e in [given, unset, solid, sleeper, compound] {
        assert!(
            (z(&app, e) - 0.5).abs() < 0.01,
            "{e:?} rests: {}",
            z(&app, e)
        );
    }
    assert!(z(&app, ghost) < -1.0, "{}", z(&app, ghost));
    assert!(app.world().get::<Sleeping>(sleeper).is_some(), "asleep");
    // A sleeper made a ghost wakes, leaves the broad phase and falls through the ground.
    app.world_mut().entity_mut(sleeper).insert(none);
    urto::step(app.world_mut(), 60).unwrap();
    assert!(z(&app, sleeper) < -1.0, "{}", z(&app, sleeper));
    assert_eq!(moving(&app), 4.0);
}

/// Churn: 300 balls flying in zero gravity, a random third of them switched between layers
/// that interact with none, layers that do and no layers at all every step, some while they
/// sleep: the broad phase holds exactly the balls that can touch something after every step,
/// and no ball's state turns NaN.
#[test]
fn layers_switched_every_step_for_200_steps_leave_the_broad_phase_exact_and_no_nan() {
    let mut app = common::app();
    let mut rng = Rng::new(23);
    let none = CollisionLayers::new(LayerMask::NONE, LayerMask::ALL);
    let world = app.world_mut();
    let balls: Vec<Entity> = (0..300)
        .map(|_| {
            world
                .spawn((
                    Collider::sphere(0.3),
                    Position(rng.vec3(-10.0, 10.0)),
                    Velocity(rng.vec3(-3.0, 3.0) * (rng.below(2) as f32)),
                ))
                .id()
        })
        .collect();
    for step in 0..200 {
        for _ in 0..100 {
            let mut e = app.world_mut().entity_mut(balls[rng.below(balls.len())]);
            match rng.below(3) {
                0 => e.insert(none),
                1 => e.insert(CollisionLayers::default()),
                _ => e.remove::<CollisionLayers>(),
            };
        }
        urto::step(app.world_mut(), 1).unwrap();
        let world = app.world();
        let touching = balls
            .iter()
            .filter(|&&b| world.get::<CollisionLayers>(b).is_none_or(|l| *l != none))
            .count();
        let indexed = world
            .resource::<PhysicsStats>()
            .counter("broad_phase/moving_bodies");
        assert_eq!(indexed, Some(touching as f64), "step {step}");
        let finite = balls.iter().all(|&b| {
            let p = world.get::<Position>(b).unwrap().0;
            let v = world.get::<Velocity>(b).unwrap().0;
            p.is_finite() && v.is_finite()
        });
        assert!(finite, "step {step}");
    }
}

#[test]
fn a_compound_moved_by_the_game_is_hit_at_its_new_place_after_refresh_before_any_step() {
    // Its parts were read at their global poses, the last step's: after the game moved the
    // root and refreshed, a ray at the part's new place missed it and one at its old place hit
    // it, until the next step (a user-style probe).
    use bevy_ecs::hierarchy::ChildOf;
    use bevy_ecs::system::RunSystemOnce;
    let mut app = common::app();
    let root = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 10.0),
            Velocity::default(),
            GravityScale(0.0),
        ))
        .id();
    let part = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(3.0, 0.0, 0.0),
            ChildOf(root),
        ))
        .id();
    urto::step(app.world_mut(), 1).unwrap();
    // Moved 20 m along y and turned a quarter about z: the part's centre goes to (0, 23, 10).
    app.world_mut().entity_mut(root).insert((
        Position::new(0.0, 20.0, 10.0),
        Rotation(glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2)),
    ));
    let hits = app
        .world_mut()
        .run_system_once(|q: SpatialQuery| {
            q.refresh();
            let all = SpatialQueryFilter::default();
            let down = |x: f32, y: f32| {
                let hit = q.cast_ray(Vec3::new(x, y, 20.0), -Vec3::Z, 30.0, &all);
                hit.unwrap().map(|h| (h.entity, h.distance))
            };
            (down(0.0, 23.0), down(3.0, 0.0))
        })
        .unwrap();
    // The box's top at z = 10.5: 9.5 m down from z = 20.
    let (new_place, old_place) = hits;
    assert!(
        new_place.is_some_and(|(e, d)| e == part && (d - 9.5).abs() < 1e-4),
        "{new_place:?}"
    );
    assert_eq!(old_place, None);
}
