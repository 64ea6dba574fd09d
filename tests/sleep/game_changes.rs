//! What a game does to a body's sleep: `SleepingDisabled` given and taken away, and a sleeper's
//! volume removed and put back.

use super::*;

/// `SleepingDisabled` keeps a body awake, and the ball resting against it too (its island),
/// while a ball alone beside them sleeps within 2 s; given to that sleeper, it wakes it at the
/// next step.
#[test]
fn a_body_with_sleeping_disabled_and_its_island_stay_awake_3s_and_the_marker_wakes_a_sleeper() {
    let mut app = sleepy_app();
    let sleepless = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    app.world_mut()
        .entity_mut(sleepless)
        .insert(SleepingDisabled);
    // Touching it: one island.
    let neighbour = common::ball(&mut app, Vec3::new(0.999, 0.0, 0.5));
    let alone = common::ball(&mut app, Vec3::new(10.0, 0.0, 0.5));
    let mut alone_slept = false;
    for _ in 0..180 {
        urto::step(app.world_mut(), 1).unwrap();
        assert!(!asleep(&app, sleepless) && !asleep(&app, neighbour));
        alone_slept |= asleep(&app, alone);
    }
    assert!(alone_slept && asleep(&app, alone), "the lone ball sleeps");
    let touching = app
        .world()
        .resource::<urto::plugins::Contacts>()
        .pairs
        .iter()
        .any(|p| [p.a, p.b] == [sleepless, neighbour] || [p.b, p.a] == [sleepless, neighbour]);
    assert!(touching, "the two balls still touch: one island");
    app.world_mut().entity_mut(alone).insert(SleepingDisabled);
    urto::step(app.world_mut(), 1).unwrap();
    assert!(!asleep(&app, alone), "the marker wakes a sleeper");
    urto::step(app.world_mut(), 120).unwrap();
    assert!(!asleep(&app, alone));
}

/// A body that loses `SleepingDisabled` counts its stillness from zero: a ball still for 0.4 s
/// before it got the marker is still awake 0.4 s after losing it (sleep time 0.5 s), and sleeps
/// within 1 s.
#[test]
fn a_body_that_loses_sleeping_disabled_sleeps_after_a_whole_sleep_time_not_sooner() {
    let mut app = sleepy_app();
    let time = app.world().resource::<SleepSettings>().time;
    assert!((time - 0.5).abs() < 1e-6, "the test assumes 0.5 s");
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    urto::step(app.world_mut(), 24).unwrap();
    assert!(!asleep(&app, ball));
    app.world_mut().entity_mut(ball).insert(SleepingDisabled);
    urto::step(app.world_mut(), 60).unwrap();
    app.world_mut()
        .entity_mut(ball)
        .remove::<SleepingDisabled>();
    urto::step(app.world_mut(), 24).unwrap();
    assert!(!asleep(&app, ball), "asleep 0.4 s after losing the marker");
    urto::step(app.world_mut(), 36).unwrap();
    assert!(asleep(&app, ball), "awake 1 s after losing the marker");
}

/// A sleeping ball whose `BoundingVolume` a game removes and puts back is indexed again as a
/// sleeper: asleep, it is paired with nothing (0 static pairs a step).
#[test]
fn a_sleeper_given_its_volume_back_stays_out_of_the_pairs() {
    let mut app = sleepy_app();
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    urto::step(app.world_mut(), 120).unwrap();
    assert!(asleep(&app, ball));
    assert_eq!(counter(&app, "broad_phase/static_pairs"), 0.0);
    common::put_volume_back(&mut app, ball);
    for _ in 0..10 {
        urto::step(app.world_mut(), 1).unwrap();
        assert!(asleep(&app, ball));
        assert_eq!(counter(&app, "broad_phase/static_pairs"), 0.0);
    }
}
