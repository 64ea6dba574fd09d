//! Removing a component is input too: a volume removed and put back between steps.

use super::*;

/// Removing a component is input too: a ground slab whose `BoundingVolume` a game removes and
/// puts back between steps is indexed again (both broad-phase syncs of a step read the removal;
/// the second once left it out for good), and the ball on it stays within 1 cm of rest.
#[test]
fn a_ground_whose_volume_is_removed_and_put_back_holds_its_ball_within_1cm_for_1s() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let ground = app
        .world_mut()
        .spawn((
            Collider::cuboid(5.0, 5.0, 0.5),
            Position(Vec3::new(0.0, 0.0, -0.5)),
            Static,
        ))
        .id();
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
