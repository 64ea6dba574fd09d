//! Removing a component is input too: a volume removed and put back between steps.

use super::*;

/// A static 10 × 10 × 1 m slab, its top at z = 0.
fn slab(app: &mut bevy_app::App) -> bevy_ecs::entity::Entity {
    let shape = Collider::cuboid(5.0, 5.0, 0.5);
    let at = Position(Vec3::new(0.0, 0.0, -0.5));
    app.world_mut().spawn((shape, at, Static)).id()
}

/// Removing a component is input too: a ground slab whose `BoundingVolume` a game removes and
/// puts back between steps is indexed again (both broad-phase syncs of a step read the removal;
/// the second once left it out for good), and the ball on it stays within 1 cm of rest.
#[test]
fn a_ground_whose_volume_is_removed_and_put_back_holds_its_ball_within_1cm_for_1s() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let ground = slab(&mut app);
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    // Awake: a sleeping ball would rest on nothing.
    app.insert_resource(SleepSettings {
        enabled: false,
        ..Default::default()
    });
    urto::step(app.world_mut(), 30).unwrap();
    let rest = app.world().get::<Position>(ball).unwrap().0;
    common::put_volume_back(&mut app, ground);
    for step in 0..60 {
        urto::step(app.world_mut(), 1).unwrap();
        let now = app.world().get::<Position>(ball).unwrap().0;
        assert!((now - rest).length() < 0.01, "step {step}: {rest} -> {now}");
    }
}

/// A game removing the state urto keeps (a body's `BoundingVolume` or `GlobalPose`) without
/// putting it back: urto puts it back with a warning, and nothing falls. Before, the bodies
/// were out of the broad phase for good and a resting stack fell through its slab (a
/// user-style probe: z ≈ −19 m in 2 s).
#[test]
fn a_stack_whose_volumes_and_poses_are_removed_stays_within_1cm_for_2s() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.insert_resource(SleepSettings {
        enabled: false,
        ..Default::default()
    });
    let slab = slab(&mut app);
    let stack: Vec<_> = (0..3)
        .map(|k| common::crate_box(&mut app, 0.5 + k as f32))
        .collect();
    urto::step(app.world_mut(), 30).unwrap();
    let rest: Vec<Vec3> = stack
        .iter()
        .map(|&e| app.world().get::<Position>(e).unwrap().0)
        .collect();
    let world = app.world_mut();
    for &e in stack.iter().chain([&slab]) {
        world.entity_mut(e).remove::<BoundingVolume>();
    }
    world.entity_mut(stack[2]).remove::<GlobalPose>();
    urto::step(app.world_mut(), 120).unwrap();
    for (&e, was) in stack.iter().zip(&rest) {
        let now = app.world().get::<Position>(e).unwrap().0;
        assert!((now - *was).length() < 0.01, "{e}: {was} -> {now}");
        assert!(app.world().get::<BoundingVolume>(e).is_some());
    }
    assert!(app.world().get::<GlobalPose>(stack[2]).is_some());
}
