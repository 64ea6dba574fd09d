//! Sleeping: bodies that have come to rest stop costing time until something wakes them (the
//! usual engine technique; Box2D and rapier do the same with islands).
//!
//! At the end of each step a dynamic body slower than [`SleepSettings::speed`] for
//! [`SleepSettings::time`] (its centre, and its surface turning at `|ω|` times its reach) falls
//! asleep: its velocity and angular velocity become exactly zero, integration skips
//! it, and the narrow phase skips its pairs with static and other sleeping bodies (their contact
//! is kept for the collision messages). It wakes when an awake body's contact moves it faster
//! than the sleep speed (see the response), when game code moves it, sets its velocity or
//! angular velocity or pushes it with a [`Force`], [`Torque`] or [`ForceAtPoint`], when gravity changes, or when a body it touched disappears.
//! Without islands a body sleeps on its own stillness alone, which is enough for piles and
//! stacks: a body kept moving by its neighbours never stays still long enough.

use crate::components::*;
use crate::plugins::core::PrepareStart;
use crate::schedule::{PhysicsSchedule, PhysicsSet};
use crate::settings::{Gravity, PhysicsTimestep, SleepSettings};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use glam::Vec3;

/// Puts still bodies to sleep and wakes them when game code touches them.
#[derive(Debug, Clone, Default)]
pub struct SleepPlugin;

impl Plugin for SleepPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SleepSettings>()
            .add_systems(
                PhysicsSchedule,
                wake_on_game_changes
                    .run_if(sleep_enabled)
                    .in_set(PrepareStart),
            )
            .add_systems(
                PhysicsSchedule,
                fall_asleep.run_if(sleep_enabled).in_set(PhysicsSet::Finish),
            );
    }
}

fn sleep_enabled(settings: Res<SleepSettings>) -> bool {
    settings.enabled
}

/// Whether `e` takes part in no simulation this substep: static scenery or a sleeping body.
pub(crate) fn dormant(state: Option<(bool, Option<&SleepState>)>) -> bool {
    match state {
        Some((is_static, sleep)) => is_static || SleepState::is_asleep(sleep),
        None => false,
    }
}

/// How a body in a contact stands for the wake-up rule: its velocity, whether it is dynamic,
/// whether it sleeps.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ContactSide {
    pub velocity: Vec3,
    pub dynamic: bool,
    pub asleep: bool,
}

/// Which sides of a contact (normal `n` from A to B) wake: a sleeper whose awake partner
/// approaches it faster than `wake_speed` along the normal, or whose partner is kinematic
/// (its parts may move on their own). Gravity's pull on a body resting on a sleeper counts as
/// approach, so a stack wakes as a whole.
pub(crate) fn wakes(a: ContactSide, b: ContactSide, n: Vec3, wake_speed: f32) -> [bool; 2] {
    [
        a.asleep && !b.asleep && (!b.dynamic || -b.velocity.dot(n) > wake_speed),
        b.asleep && !a.asleep && (!a.dynamic || a.velocity.dot(n) > wake_speed),
    ]
}

type Sleeper<'a> = (
    &'a mut SleepState,
    &'a Position,
    &'a Velocity,
    Option<&'a Force>,
    Option<&'a AngularVelocity>,
    Option<&'a Torque>,
    Option<&'a ForceAtPoint>,
);

/// Wakes sleeping bodies that game code moved, set moving or pushed since the last step, and
/// every body when gravity changed.
fn wake_on_game_changes(mut bodies: Query<Sleeper>, gravity: Option<Res<Gravity>>) {
    let gravity_changed = gravity.is_some_and(|g| g.is_changed());
    for (mut sleep, p, v, force, w, torque, at_point) in &mut bodies {
        if !sleep.asleep {
            continue;
        }
        let pushed = force.is_some_and(|f| f.0 != Vec3::ZERO)
            || torque.is_some_and(|t| t.0 != Vec3::ZERO)
            || at_point.is_some_and(|f| !f.is_empty());
        let spun = w.is_some_and(|w| w.0 != Vec3::ZERO);
        if gravity_changed || pushed || spun || v.0 != Vec3::ZERO || p.0 != sleep.at {
            sleep.wake();
        }
    }
}

type Candidate<'a> = (
    &'a mut SleepState,
    &'a Position,
    &'a mut Velocity,
    &'a Mass,
    Option<&'a mut AngularVelocity>,
    &'a BoundingVolume,
);
type CandidateFilter = (
    Without<Static>,
    Without<Quarantined>,
    Without<ChildOf>,
    Without<Spring>,
);

/// Counts how long each awake dynamic body has been still, and puts it to sleep after
/// [`SleepSettings::time`] with its velocity set to exactly zero.
fn fall_asleep(
    mut bodies: Query<Candidate, CandidateFilter>,
    settings: Res<SleepSettings>,
    timestep: Res<PhysicsTimestep>,
) {
    let dt = timestep.dt();
    for (mut sleep, p, mut v, m, mut w, volume) in &mut bodies {
        if sleep.asleep || m.inverse() == 0.0 {
            continue;
        }
        // A turning body's surface moves at up to |ω| times its reach (Box2D's sleep test).
        let turning = w.as_ref().map_or(0.0, |w| w.0.length()) * volume.reach();
        if v.0.length().max(turning) >= settings.speed {
            if sleep.still_for != 0.0 {
                sleep.still_for = 0.0;
            }
            continue;
        }
        sleep.still_for += dt;
        if sleep.still_for >= settings.time {
            sleep.asleep = true;
            sleep.at = p.0;
            // Not a change by game code: the wake-up check compares values, not change ticks.
            v.bypass_change_detection().0 = Vec3::ZERO;
            if let Some(w) = w.as_mut() {
                w.bypass_change_detection().0 = Vec3::ZERO;
            }
        }
    }
}
