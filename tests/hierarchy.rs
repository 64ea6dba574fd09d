//! The scene graph as the BV hierarchy: volumes bound their subtrees, refits touch only what
//! changed, and re-parenting or despawning keeps the broad phase consistent.

mod common;

use bevy_app::App;
use bevy_ecs::prelude::*;
use bevy_transform::components::Transform;
use glam::{Quat, Vec3};
use urto::bounding::Aabb;
use urto::plugins::BroadPhasePairs;
use urto::prelude::*;

fn refits(app: &App) -> f64 {
    let stats = app.world().resource::<PhysicsStats>();
    stats.counter("hierarchy/refits").unwrap_or(0.0)
}

fn bv(app: &App, e: Entity) -> Aabb {
    app.world().get::<BoundingVolume>(e).unwrap().0
}

/// A static block of `n` houses in a row under one root with no collider of its own.
fn town_block(app: &mut App, n: usize, at: Vec3) -> (Entity, Vec<Entity>) {
    let root = app.world_mut().spawn((Position(at), Static)).id();
    let houses = (0..n)
        .map(|i| {
            app.world_mut()
                .spawn((
                    Collider::cuboid(0.4, 0.4, 0.5),
                    Position::new(i as f32, 0.0, 0.5),
                    Static,
                    ChildOf(root),
                ))
                .id()
        })
        .collect();
    (root, houses)
}

/// A car: a box chassis with four sphere wheels, moving along +x.
fn car(app: &mut App, at: Vec3) -> (Entity, Vec<Entity>) {
    let chassis = app
        .world_mut()
        .spawn((
            Collider::cuboid(1.0, 0.5, 0.25),
            Position(at),
            Velocity::new(2.0, 0.0, 0.0),
        ))
        .id();
    let wheels = [(-0.7, -0.6), (-0.7, 0.6), (0.7, -0.6), (0.7, 0.6)]
        .map(|(x, y)| {
            app.world_mut()
                .spawn((
                    Collider::sphere(0.3),
                    Position::new(x, y, -0.25),
                    ChildOf(chassis),
                ))
                .id()
        })
        .to_vec();
    (chassis, wheels)
}

#[test]
fn refits_touch_only_changed_branches() {
    let mut app = common::app();
    let (block, houses) = town_block(&mut app, 200, Vec3::new(0.0, 10.0, 0.0));
    let (chassis, wheels) = car(&mut app, Vec3::ZERO);
    urto::step(app.world_mut(), 2).unwrap();
    // Steady state: the car (chassis + 4 wheels) refits every step, the town never.
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(refits(&app), 5.0);
    // One house is moved by game code: that house and its block root, nothing else.
    app.world_mut()
        .entity_mut(chassis)
        .insert(Velocity::default());
    app.world_mut().get_mut::<Position>(houses[17]).unwrap().0.z = 3.0;
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(refits(&app), 2.0);
    assert!(
        bv(&app, block).max.z >= 3.5 - 1e-6,
        "the block grew with its house"
    );
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(refits(&app), 0.0, "nothing moved");
    // A wheel turns (local rotation): the wheel and the chassis.
    app.world_mut().get_mut::<Rotation>(wheels[0]).unwrap().0 = Quat::from_rotation_y(0.5);
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(refits(&app), 2.0);
}

fn assert_bounds_subtree(app: &mut App, root: Entity) {
    let mut stack = vec![root];
    while let Some(e) = stack.pop() {
        let node = bv(app, e);
        let world = app.world();
        if let (Some(c), Some(g)) = (world.get::<Collider>(e), world.get::<GlobalPose>(e)) {
            let own = c.shape.world_aabb(&g.pose());
            assert!(
                node.expanded(1e-4).contains(&own),
                "{e}: own collider outside its volume"
            );
        }
        if let Some(children) = world.get::<Children>(e) {
            for c in children.iter() {
                assert!(
                    node.expanded(1e-4).contains(&bv(app, c)),
                    "{e}: child {c} outside"
                );
                stack.push(c);
            }
        }
    }
}

#[test]
fn deep_and_wide_hierarchies_bound_their_descendants_as_they_move() {
    let mut app = common::app();
    // Depth 8: an arm of links, each turned and offset from its parent.
    let base = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.2),
            Position::default(),
            Velocity::new(0.0, 1.0, 0.5),
        ))
        .id();
    let mut parent = base;
    for depth in 1..=8 {
        parent = app
            .world_mut()
            .spawn((
                Collider::cuboid(0.1, 0.1, 0.4),
                Position::new(0.0, 0.0, 0.8),
                Rotation(Quat::from_rotation_x(0.3 * depth as f32)),
                ChildOf(parent),
            ))
            .id();
    }
    // Width 1000: a block of houses.
    let (block, _) = town_block(&mut app, 1000, Vec3::new(5.0, 0.0, 0.0));
    for _ in 0..30 {
        urto::step(app.world_mut(), 1).unwrap();
        assert_bounds_subtree(&mut app, base);
    }
    assert_bounds_subtree(&mut app, block);
    let tip = app
        .world()
        .get::<GlobalPose>(parent)
        .unwrap()
        .pose()
        .translation;
    assert!(bv(&app, base).contains_point(tip));
    assert!(bv(&app, block).extents().x > 999.0);
}

fn pairs(app: &App) -> Vec<(Entity, Entity)> {
    let mut p: Vec<_> = app
        .world()
        .resource::<BroadPhasePairs>()
        .pairs
        .iter()
        .map(|&(a, b)| (a.min(b), a.max(b)))
        .collect();
    p.sort_unstable();
    p
}

#[test]
fn reparenting_and_despawning_a_subtree_keep_the_broad_phase_consistent() {
    let mut app = common::app();
    let (block_a, houses_a) = town_block(&mut app, 10, Vec3::ZERO);
    let (block_b, _) = town_block(&mut app, 10, Vec3::new(0.0, 50.0, 0.0));
    let (chassis, _) = car(&mut app, Vec3::new(4.0, 50.0, 0.5));
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(
        pairs(&app),
        vec![(block_b.min(chassis), block_b.max(chassis))]
    );

    // Move house 3 of block A next to the car: block B's volume does not change, block A's
    // shrinks back once the house leaves; the car now meets block A through that house.
    app.world_mut()
        .entity_mut(houses_a[3])
        .insert(ChildOf(block_b));
    app.world_mut().get_mut::<Position>(houses_a[3]).unwrap().0 = Vec3::new(4.0, 0.0, 0.5);
    urto::step(app.world_mut(), 1).unwrap();
    assert_bounds_subtree(&mut app, block_a);
    assert_bounds_subtree(&mut app, block_b);
    assert!(bv(&app, block_b).contains_point(Vec3::new(4.0, 50.0, 0.5)));

    // A house becomes a root of its own: the broad phase sees it.
    app.world_mut().entity_mut(houses_a[5]).remove::<ChildOf>();
    urto::step(app.world_mut(), 1).unwrap();
    let moving_pairs_with_house = pairs(&app)
        .iter()
        .any(|p| p.0 == houses_a[5] || p.1 == houses_a[5]);
    assert!(
        !moving_pairs_with_house,
        "a static house far from the car has no pair"
    );
    // Despawning block B (and its houses, by bevy's linked despawn) removes every pair with it.
    app.world_mut().entity_mut(block_b).despawn();
    urto::step(app.world_mut(), 1).unwrap();
    assert!(pairs(&app).iter().all(|p| p.0 != block_b && p.1 != block_b));
    assert!(
        app.world().get_entity(houses_a[3]).is_err(),
        "the moved house went with block B"
    );
    assert_bounds_subtree(&mut app, block_a);
}

#[test]
fn a_part_with_its_own_velocity_is_quarantined() {
    let mut app = common::app();
    let (chassis, wheels) = car(&mut app, Vec3::ZERO);
    app.world_mut()
        .entity_mut(wheels[1])
        .insert(Velocity::new(1.0, 0.0, 0.0));
    urto::step(app.world_mut(), 1).unwrap();
    let q = app
        .world()
        .get::<Quarantined>(wheels[1])
        .expect("quarantined");
    assert!(q.reason.contains("compound"), "{}", q.reason);
    assert!(app.world().get::<Quarantined>(chassis).is_none());
}

/// A level as Bevy scenes spawn it: a plain root with only a `Transform` (10, 0, 2), turned a
/// quarter about z, a plain group under it at (0, 1, 0), and static balls under the group with
/// only their `Transform`s. The plain entities take their poses from their `Transform`s, so
/// each ball collides where it is drawn: a ball dropped on each rests on it within 1 cm. Before,
/// the balls collided at their local positions near the origin and the root was quarantined.
/// A dynamic body under the root is a part with a velocity, quarantined.
#[test]
fn colliders_under_plain_transform_parents_collide_where_they_are_drawn_within_1_cm() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let turn = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let world = app.world_mut();
    let root = world
        .spawn(Transform::from_xyz(10.0, 0.0, 2.0).with_rotation(turn))
        .id();
    let group = world
        .spawn((Transform::from_xyz(0.0, 1.0, 0.0), ChildOf(root)))
        .id();
    let locals = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 1.0)];
    for at in locals {
        world.spawn((
            Collider::sphere(0.5),
            Transform::from_translation(at),
            ChildOf(group),
        ));
    }
    let mover = world
        .spawn((
            Collider::sphere(0.2),
            Transform::from_xyz(0.0, 0.0, 5.0),
            Velocity::default(),
            ChildOf(root),
        ))
        .id();
    // Where the balls are drawn: the root's pose composed with the group's and their own.
    let drawn = locals.map(|at| Vec3::new(10.0, 0.0, 2.0) + turn * (Vec3::Y + at));
    let dropped = drawn.map(|at| {
        let ball = (
            Collider::sphere(0.5),
            Position(at + Vec3::Z * 3.0),
            Velocity::default(),
        );
        app.world_mut().spawn(ball).id()
    });
    urto::step(app.world_mut(), 120).unwrap();
    for (ball, at) in dropped.iter().zip(drawn) {
        let rest = app.world().get::<Position>(*ball).unwrap().0;
        let on_top = at + Vec3::Z;
        assert!(rest.distance(on_top) < 0.01, "{rest} on {on_top}");
    }
    for plain in [root, group] {
        assert!(app.world().get::<Quarantined>(plain).is_none());
    }
    let q = app.world().get::<Quarantined>(mover).expect("quarantined");
    assert!(q.reason.contains("Velocity"), "{}", q.reason);
}

/// A kinematic arm whose joint the game turns at 3 rad/s bats a ball at the speed of the point
/// that hits it (1.5 m from the joint: 4.5 m/s), sending it off faster than that along the
/// link's motion; without the part's own velocity it would only be pushed aside.
#[test]
fn a_turning_kinematic_link_bats_a_ball_at_its_own_speed() {
    bats_a_ball_at_its_own_speed(common::legacy_app());
}

/// The same with the rigid-body solver, where the link's contact becomes an immovable solver
/// body moving at the link's velocity there.
#[test]
fn with_the_soft_step_a_turning_kinematic_link_bats_a_ball_at_its_own_speed() {
    bats_a_ball_at_its_own_speed(common::app());
}

fn bats_a_ball_at_its_own_speed(mut app: App) {
    let base = app
        .world_mut()
        .spawn((
            Collider::sphere(0.1),
            Position::default(),
            Velocity::default(),
            Mass::INFINITE,
        ))
        .id();
    let joint = app
        .world_mut()
        .spawn((Position::default(), ChildOf(base)))
        .id();
    app.world_mut().spawn((
        Collider::cuboid(0.9, 0.1, 0.1),
        Position::new(1.0, 0.0, 0.0),
        ChildOf(joint),
    ));
    let ball = app
        .world_mut()
        .spawn((
            Collider::sphere(0.1),
            Position::new(1.5, 0.35, 0.0),
            Velocity::default(),
        ))
        .id();
    let (omega, dt) = (3.0, 1.0 / 60.0);
    for step in 1..=20 {
        app.world_mut().get_mut::<Rotation>(joint).unwrap().0 =
            Quat::from_rotation_z(omega * step as f32 * dt);
        urto::step(app.world_mut(), 1).unwrap();
    }
    let v = app.world().get::<Velocity>(ball).unwrap().0;
    let tip_speed = omega * 1.5;
    assert!(
        v.length() > tip_speed,
        "batted at {v} (point speed {tip_speed})"
    );
    assert!(v.y > 0.8 * v.length(), "along the link's motion: {v}");
}
