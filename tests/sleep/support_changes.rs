//! What a game does to what sleepers rest on: a static floor moved, tilted, made dynamic,
//! stripped of its collider or made a sensor, and a sleeper in a stack stripped of its
//! collider, wake the sleepers it held (`src/plugins/wake_on_scenery.rs`).

use super::*;

/// A unit box asleep on a static 10 × 10 × 1 m slab (top at z = 0), both with `friction`;
/// `slab` and `box` entities.
fn box_asleep_on_a_slab(friction: f32) -> (App, Entity, Entity) {
    let (mut app, slab, b) = box_on_a_slab(friction);
    urto::step(app.world_mut(), 90).unwrap();
    assert!(asleep(&app, b), "the box sleeps on the slab");
    (app, slab, b)
}

#[test]
fn a_box_asleep_on_a_slab_moved_down_1_m_falls_and_rests_on_it_within_1_cm_in_2_5_s() {
    let (mut app, slab, b) = box_asleep_on_a_slab(0.5);
    app.world_mut().get_mut::<Position>(slab).unwrap().0.z -= 1.0;
    urto::step(app.world_mut(), 150).unwrap();
    // It lands after 0.45 s and bounces (the default restitution). Before: it hung at z = 0.5,
    // asleep.
    assert!((z(&app, b) + 0.5).abs() < 0.01, "z = {}", z(&app, b));
}

#[test]
fn a_box_asleep_on_a_slab_tilted_30_degrees_with_friction_0_2_slides_over_1_m_in_1_s() {
    let (mut app, slab, b) = box_asleep_on_a_slab(0.2);
    let start = position(&app, b);
    *app.world_mut().get_mut::<Rotation>(slab).unwrap() =
        Rotation(Quat::from_rotation_y(30f32.to_radians()));
    urto::step(app.world_mut(), 60).unwrap();
    // Down a 30° slope at g (sin 30° − 0.2 cos 30°) = 3.2 m/s²: 1.6 m in 1 s.
    let slid = (position(&app, b) - start).length();
    assert!(slid > 1.0, "slid {slid} m");
}

#[test]
fn a_box_asleep_on_a_slab_that_loses_its_collider_or_becomes_a_sensor_falls_through_it() {
    for sensor in [false, true] {
        let (mut app, slab, b) = box_asleep_on_a_slab(0.5);
        let mut entity = app.world_mut().entity_mut(slab);
        if sensor {
            entity.insert(Sensor);
        } else {
            entity.remove::<Collider>();
        }
        urto::step(app.world_mut(), 60).unwrap();
        // Free fall for 1 s: 4.9 m.
        assert!(z(&app, b) < -4.0, "sensor {sensor}: z = {}", z(&app, b));
    }
}

#[test]
fn a_box_asleep_on_a_slab_whose_friction_drops_from_2_to_0_2_on_a_30_degree_slope_slides() {
    let (mut app, slab, b) = box_asleep_on_a_slab(2.0);
    *app.world_mut().get_mut::<Rotation>(slab).unwrap() =
        Rotation(Quat::from_rotation_y(30f32.to_radians()));
    urto::step(app.world_mut(), 120).unwrap();
    assert!(
        asleep(&app, b),
        "held by friction 2 on the slope, it sleeps again"
    );
    let start = position(&app, b);
    app.world_mut().get_mut::<Friction>(slab).unwrap().0 = 0.2;
    app.world_mut().get_mut::<Friction>(b).unwrap().0 = 0.2;
    urto::step(app.world_mut(), 60).unwrap();
    let slid = (position(&app, b) - start).length();
    assert!(slid > 1.0, "slid {slid} m");
}

#[test]
fn the_middle_box_of_a_sleeping_stack_losing_its_collider_lets_the_top_one_fall_onto_the_bottom_within_1_cm()
 {
    let mut app = sleepy_app();
    let boxes: Vec<Entity> = [0.5, 1.5, 2.5]
        .iter()
        .map(|&z| common::crate_box(&mut app, z))
        .collect();
    urto::step(app.world_mut(), 120).unwrap();
    assert!(boxes.iter().all(|&b| asleep(&app, b)));
    app.world_mut().entity_mut(boxes[1]).remove::<Collider>();
    urto::step(app.world_mut(), 90).unwrap();
    // Before: the top box hung at 2.5, the middle one at 1.5.
    let top = z(&app, boxes[2]);
    assert!((top - 1.5).abs() < 0.01, "top box at z = {top}");
    assert!(z(&app, boxes[1]) < -1.0, "the middle one falls through");
}

/// The slab under a sleeping box made a dynamic body by the game (its `Static` taken off, a
/// `Velocity` and a `Mass` given): both fall, the box on it. Before (a user-style probe), the
/// box slept on in the air for two steps while the slab fell away, and met it again 28 cm
/// later, at 5.5 m/s.
#[test]
fn a_box_asleep_on_a_slab_made_dynamic_falls_with_it_within_1_mm_for_1_s() {
    let (mut app, slab, b) = box_asleep_on_a_slab(0.5);
    app.world_mut()
        .entity_mut(slab)
        .remove::<Static>()
        .insert((Velocity::default(), Mass(100.0)));
    let rest = z(&app, b) - z(&app, slab);
    for step in 1..=60 {
        urto::step(app.world_mut(), 1).unwrap();
        let gap = z(&app, b) - z(&app, slab) - rest;
        assert!(gap.abs() < 1e-3, "step {step}: gap {gap}");
    }
    assert!(z(&app, slab) < -4.0, "the slab fell");
}
