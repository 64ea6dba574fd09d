//! urto inside a real `bevy_app::App`, driven by Bevy's fixed-timestep loop.

use bevy_app::App;
use bevy_time::{TimePlugin, TimeUpdateStrategy};
use glam::Vec3;
use std::time::Duration;
use urto::prelude::*;

fn app(frame: Duration) -> App {
    let mut app = App::new();
    app.add_plugins(TimePlugin)
        .add_plugins(UrtoPlugins::with_timestep(
            PhysicsTimestep::new(1.0 / 50.0, 1)
                .unwrap()
                .with_max_steps_per_frame(3)
                .unwrap(),
        ));
    app.insert_resource(TimeUpdateStrategy::ManualDuration(frame))
        .insert_resource(Gravity::EARTH_Z_UP);
    app.finish();
    app.cleanup();
    app
}

#[test]
fn app_update_steps_physics_by_elapsed_time() {
    let mut app = app(Duration::from_millis(10));
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let ball = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 3.0),
            Velocity::default(),
        ))
        .id();
    for _ in 0..101 {
        app.update();
    }
    // 100 frames of 10 ms after the first = 1 s = 50 steps of 20 ms.
    let stats = app.world().resource::<PhysicsStats>();
    assert_eq!(stats.step, 50);
    let z = app.world().get::<Position>(ball).unwrap().0.z;
    assert!(
        z > 0.0 && z < 2.0,
        "after 1 s of gravity the ball must have fallen: {z}"
    );
}

/// A frame of a second (250 ms once Bevy's own `max_delta` caps it) runs 3 steps, the cap, and
/// leaves the game's clock alone: `Time<Virtual>` advances the 250 ms (it advanced 60 ms when
/// urto capped its `max_delta` instead, slowing every `Update` system after a hitch).
#[test]
fn a_slow_frame_runs_at_most_the_catch_up_cap_and_the_game_clock_keeps_its_time() {
    let mut app = app(Duration::from_secs(1));
    app.world_mut().spawn(Velocity::default());
    app.update(); // the first frame has no elapsed time
    app.update();
    assert_eq!(app.world().resource::<PhysicsStats>().step, 3);
    let game = app
        .world()
        .resource::<bevy_time::Time<bevy_time::Virtual>>();
    assert_eq!(game.elapsed(), Duration::from_millis(250));
    // The next frame runs 3 more, no backlog carried.
    app.update();
    assert_eq!(app.world().resource::<PhysicsStats>().step, 6);
}

/// Frames of 70 ms at 50 Hz with a cap of 3 steps: each frame owes 3.5 steps, runs 3 and
/// drops whole steps only, so the half step left over joins the next frame's: after 10
/// frames (the first has no elapsed time), 9 × 3 steps ran and half a step is owed.
#[test]
fn the_catch_up_cap_drops_whole_steps_and_keeps_the_fraction_within_1_us() {
    let mut app = app(Duration::from_millis(70));
    app.world_mut().spawn(Velocity::default());
    for _ in 0..10 {
        app.update();
    }
    assert_eq!(app.world().resource::<PhysicsStats>().step, 27);
    let fixed = app.world().resource::<bevy_time::Time<bevy_time::Fixed>>();
    let owed = fixed.overstep().as_secs_f64();
    assert!((owed - 0.01).abs() < 1e-6, "owed {owed} s");
}

#[test]
fn a_hand_written_update_loop_without_finish_steps_at_exactly_the_configured_60_hz() {
    // The README's loop: plugins added, then app.update() in a loop, never app.finish().
    let mut app = App::new();
    app.add_plugins((TimePlugin, UrtoPlugins::default()))
        .insert_resource(TimeUpdateStrategy::ManualDuration(
            Duration::from_secs(1) / 60,
        ));
    app.world_mut().spawn(Velocity::default());
    for _ in 0..121 {
        app.update();
    }
    let fixed = app.world().resource::<bevy_time::Time<bevy_time::Fixed>>();
    assert_eq!(fixed.timestep(), Duration::from_secs_f32(1.0 / 60.0));
    // 120 frames of 1/60 s after the first: 120 steps, give or take the rounding of the two
    // clocks' nanoseconds at the boundary.
    let steps = app.world().resource::<PhysicsStats>().step;
    assert!((119..=120).contains(&steps), "{steps} steps");
    let dt = app.world().resource::<PhysicsTimestep>().dt();
    assert!((dt - 1.0 / 60.0).abs() < 1e-7, "{dt}");
}

#[test]
fn an_interpolated_body_renders_smoothly_at_twice_the_step_rate_within_10_percent_of_its_speed() {
    use bevy_transform::components::Transform;
    let mut app = App::new();
    app.add_plugins((TimePlugin, UrtoPlugins::default()))
        .insert_resource(TimeUpdateStrategy::ManualDuration(
            Duration::from_secs(1) / 120,
        ));
    let body = app
        .world_mut()
        .spawn((
            Velocity::new(6.0, 0.0, 0.0),
            Transform::default(),
            TransformInterpolation,
        ))
        .id();
    let plain = app
        .world_mut()
        .spawn((Velocity::new(6.0, 0.0, 0.0), Transform::default()))
        .id();
    let x = |app: &App, e| app.world().get::<Transform>(e).unwrap().translation.x;
    let (mut drawn, mut jumpy) = (Vec::new(), Vec::new());
    for _ in 0..40 {
        app.update();
        drawn.push(x(&app, body));
        jumpy.push(x(&app, plain));
    }
    // Frames of 1/120 s: 6 m/s moves 5 cm a frame. Uninterpolated, the pose moves 10 cm every
    // other frame; interpolated, 5 cm every frame.
    let steps = |xs: &[f32]| {
        xs.windows(2)
            .skip(10)
            .map(|w| w[1] - w[0])
            .collect::<Vec<_>>()
    };
    assert!(
        steps(&jumpy).iter().any(|d| d.abs() < 1e-6),
        "the plain body should jump"
    );
    for d in steps(&drawn) {
        assert!(
            (d - 0.05).abs() < 0.005,
            "an interpolated frame moved {d} m"
        );
    }
    // The physics itself is not blended: the Position is the stepped one.
    let p = app.world().get::<Position>(body).unwrap().0.x;
    assert!((p - x(&app, plain)).abs() < 1e-6);
}

#[test]
fn app_run_under_schedule_runner_steps_at_60_hz_from_50_hz_frames_within_one_step() {
    // A game's loop: `app.run()` under `ScheduleRunnerPlugin`, frames of 20 ms (each advances
    // the clock by exactly that), an `Update` system that ends the game after 150 frames, and
    // a `FixedUpdate` system of the game's own. The runner owns the app, so the exit system
    // reports what it saw through shared counters.
    use bevy_app::{AppExit, FixedUpdate, ScheduleRunnerPlugin, Update};
    use bevy_ecs::prelude::*;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

    let (steps, fixed_runs) = (Arc::new(AtomicU64::new(0)), Arc::new(AtomicU64::new(0)));
    let mut app = App::new();
    app.add_plugins((
        TimePlugin,
        UrtoPlugins::default(),
        ScheduleRunnerPlugin::run_loop(Duration::ZERO),
    ))
    .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_millis(
        20,
    )));
    let body = app.world_mut().spawn(Velocity::new(1.0, 0.0, 0.0)).id();
    let counted = fixed_runs.clone();
    app.add_systems(FixedUpdate, move || {
        counted.fetch_add(1, Ordering::Relaxed);
    });
    let (seen, travelled) = (steps.clone(), Arc::new(AtomicU32::new(0)));
    let moved = travelled.clone();
    let mut frames = 0u32;
    app.add_systems(
        Update,
        move |stats: Res<PhysicsStats>,
              bodies: Query<&Position>,
              mut exit: MessageWriter<AppExit>| {
            frames += 1;
            if frames == 151 {
                seen.store(stats.step, Ordering::Relaxed);
                let x = bodies.get(body).map_or(f32::NAN, |p| p.0.x);
                moved.store(x.to_bits(), Ordering::Relaxed);
                exit.write(AppExit::Success);
            }
        },
    );
    assert_eq!(app.run(), AppExit::Success);
    // 150 frames of 20 ms after the first = 3 s: 180 steps of 1/60 s, or 179 where the f32
    // step (a hair over 1/60 s) puts the 180th just past 3 s.
    let steps = steps.load(Ordering::Relaxed);
    assert!((179..=180).contains(&steps), "{steps} steps");
    assert_eq!(fixed_runs.load(Ordering::Relaxed), steps);
    // And the steps moved the body: 1 m/s for `steps` steps.
    let x = f32::from_bits(travelled.load(Ordering::Relaxed));
    let expected = steps as f32 / 60.0;
    assert!((x - expected).abs() < 1e-3, "x = {x}, expected {expected}");
}
