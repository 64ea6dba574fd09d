//! Stepping a whole `App` by fixed steps, the game's fixed-update systems included.
//!
//! [`step`](super::step) runs only the physics schedule: enough for tests and offline runs, but
//! a game whose `FixedUpdate` systems push bodies, spawn them or read collisions would not see
//! them run. [`step_app`] runs Bevy's whole `FixedMain` schedule once per step — `FixedFirst`,
//! `FixedPreUpdate`, `FixedUpdate`, `FixedPostUpdate` (where the physics step is), `FixedLast` —
//! with `Res<Time>` set to the fixed clock advanced by exactly one [`PhysicsTimestep`], as
//! Bevy's own fixed loop (`run_fixed_main_schedule`) does, but without waiting for wall-clock
//! time: a server, a replay or a test runs the game's fixed logic at the configured rate, as
//! fast as it can.

use super::collision_messages::update_collision_messages;
use super::core::{CoreInstalled, StepError};
use crate::settings::PhysicsTimestep;
use bevy_app::{App, FixedMain};
use bevy_time::{Fixed, Time};
use std::time::Duration;

/// Runs `n` fixed steps of `app`: each one Bevy's `FixedMain` schedule with the fixed clock
/// advanced by one timestep (see the module notes). The frame schedules (`Update`, rendering)
/// do not run. Errors if the app has no [`UrtoPlugins`](crate::UrtoPlugins).
///
/// ```
/// # use bevy_app::{App, FixedUpdate};
/// # use bevy_ecs::prelude::*;
/// # use urto::prelude::*;
/// let mut app = App::new();
/// app.add_plugins(UrtoPlugins::default());
/// app.add_systems(FixedUpdate, |mut q: Query<&mut Velocity>| {
///     for mut v in &mut q {
///         v.0.x = 2.0; // the game's own fixed-rate logic
///     }
/// });
/// let ball = app.world_mut().spawn((Collider::sphere(0.5), Velocity::default())).id();
/// urto::step_app(&mut app, 60).unwrap();
/// let x = app.world().get::<Position>(ball).unwrap().0.x;
/// assert!((x - 2.0).abs() < 1e-4); // 1 s at 2 m/s
/// ```
pub fn step_app(app: &mut App, n: u32) -> Result<(), StepError> {
    let world = app.world_mut();
    if !world.contains_resource::<CoreInstalled>() {
        return Err(StepError::NoPhysicsSchedule);
    }
    let dt = world
        .get_resource::<PhysicsTimestep>()
        .map_or(PhysicsTimestep::default().dt(), |t| t.dt());
    let step = Duration::from_secs_f32(dt);
    if !world.contains_resource::<Time<Fixed>>() {
        world.insert_resource(Time::<Fixed>::from_duration(step));
    }
    let outer = world.get_resource::<Time>().copied();
    for _ in 0..n {
        let fixed = {
            let mut fixed = world.resource_mut::<Time<Fixed>>();
            fixed.set_timestep(step);
            fixed.advance_by(step);
            fixed.as_generic()
        };
        world.insert_resource(fixed);
        world.run_schedule(FixedMain);
        update_collision_messages(world);
    }
    match outer {
        Some(time) => world.insert_resource(time),
        None => {
            world.remove_resource::<Time>();
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::prelude::*;
    use bevy_app::{App, FixedUpdate};
    use bevy_ecs::prelude::*;
    use bevy_time::Time;

    #[derive(Resource, Default)]
    struct Seen(Vec<f32>);

    #[test]
    fn the_games_fixed_systems_run_once_per_step_with_the_physics_dt() {
        let mut app = App::new();
        app.add_plugins(UrtoPlugins::default())
            .insert_resource(PhysicsTimestep::new(1.0 / 50.0, 1).unwrap())
            .init_resource::<Seen>()
            .add_systems(FixedUpdate, |time: Res<Time>, mut seen: ResMut<Seen>| {
                seen.0.push(time.delta_secs());
            });
        crate::step_app(&mut app, 25).unwrap();
        let seen = &app.world().resource::<Seen>().0;
        assert_eq!(seen.len(), 25);
        assert!(seen.iter().all(|dt| (dt - 0.02).abs() < 1e-6), "{seen:?}");
        let stats = app.world().resource::<PhysicsStats>();
        assert_eq!(stats.step, 25);
        assert!((stats.sim_time - 0.5).abs() < 1e-6, "{}", stats.sim_time);
    }

    #[test]
    fn an_app_without_urto_is_refused() {
        assert!(crate::step_app(&mut App::new(), 1).is_err());
    }
}
