//! Bad input in the scene graph: `ChildOf` loops, compound roots without a pose, plain parents
//! with a NaN `Transform`, and chains deep enough to expose a quadratic walk.

use super::*;

/// A plain parent (only a `Transform`) whose translation is NaN, holding a collider: the
/// parent takes that NaN as its pose and is quarantined, and a ball falling past its child
/// stays finite and lands.
#[test]
fn a_plain_parent_with_a_nan_transform_is_quarantined() {
    use bevy_transform::components::Transform;
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let root = app
        .world_mut()
        .spawn(Transform::from_xyz(f32::NAN, 0.0, 1.0))
        .id();
    let part = (Collider::sphere(0.5), Transform::from_xyz(0.0, 0.0, 1.0));
    app.world_mut()
        .spawn((part, bevy_ecs::hierarchy::ChildOf(root)));
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 3.0));
    urto::step(app.world_mut(), 120).unwrap();
    assert!(quarantined(&app, root));
    let p = app.world().get::<Position>(ball).unwrap().0;
    assert!(p.is_finite() && (p.z - 0.5).abs() < 0.01, "ball at {p}");
}

/// Two entities that are each other's `ChildOf` (a loop with no root) are both quarantined, and
/// the step ends; a ball beside them falls as it would alone.
#[test]
fn a_childof_loop_is_quarantined_whole_and_the_step_ends() {
    use bevy_ecs::hierarchy::ChildOf;
    let mut app = common::legacy_app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let a = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::default(),
            Velocity::default(),
        ))
        .id();
    let b = app
        .world_mut()
        .spawn((Collider::sphere(0.5), Position::default(), ChildOf(a)))
        .id();
    app.world_mut().entity_mut(a).insert(ChildOf(b));
    let ball = common::ball(&mut app, Vec3::new(5.0, 0.0, 10.0));
    urto::step(app.world_mut(), 60).unwrap();
    assert!(quarantined(&app, a) && quarantined(&app, b));
    let z = app.world().get::<Position>(ball).unwrap().0.z;
    // One second of free fall under symplectic Euler: 10 − g (1 + 1/60) / 2.
    let expected = 10.0 - 9.8 * (1.0 + 1.0 / 60.0) / 2.0;
    assert!(
        (z - expected).abs() < 1e-3,
        "ball at {z}, expected {expected}"
    );
}

/// A compound whose root lost its `Position` was never collided and nothing said so: the root
/// is quarantined within one step, with the reason.
#[test]
fn a_compound_root_without_a_position_is_quarantined_within_one_step() {
    let mut app = common::app();
    let root = app.world_mut().spawn(Velocity::default()).id();
    app.world_mut().entity_mut(root).remove::<Position>();
    app.world_mut().spawn((
        Collider::sphere(0.5),
        Position::default(),
        bevy_ecs::prelude::ChildOf(root),
    ));
    urto::step(app.world_mut(), 1).unwrap();
    let why = &app
        .world()
        .get::<Quarantined>(root)
        .expect("refused")
        .reason;
    assert!(why.contains("no Position"), "{why}");
}

/// Every walk over a `ChildOf` chain is linear in its length: a 10,000-deep chain steps
/// (validation, poses, volumes, inertia) with each node met a bounded number of times. On the
/// first step every node is new, and each used to recompose its whole subtree (n²/2 = 5e7
/// poses); the hierarchy counters say how many nodes were recomposed and refit: at most twice
/// the chain, on the first step and after.
#[test]
fn a_10000_deep_chain_recomposes_and_refits_at_most_twice_its_nodes_per_step() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let mut parent = common::ball(&mut app, Vec3::new(0.0, 0.0, 5.0));
    let n = 10_000;
    for _ in 0..n {
        parent = app
            .world_mut()
            .spawn((
                Collider::sphere(0.1),
                Position::new(0.0, 0.0, 0.01),
                bevy_ecs::prelude::ChildOf(parent),
            ))
            .id();
    }
    for step in 0..3 {
        urto::step(app.world_mut(), 1).unwrap();
        let stats = app.world().resource::<PhysicsStats>();
        for name in ["hierarchy/poses", "hierarchy/refits"] {
            let c = stats.counter(name).unwrap_or(0.0);
            assert!(
                c > 0.0 && c <= 2.0 * (n + 1) as f64,
                "step {step}, {name}: {c}"
            );
        }
    }
    assert!(app.world().get::<Quarantined>(parent).is_none());
}
