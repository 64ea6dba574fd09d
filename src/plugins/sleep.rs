//! Sleeping: bodies that have come to rest stop costing time until something wakes them (the
//! usual engine technique; Box2D, rapier and Jolt do the same).
//!
//! Bodies sleep by islands ([`crate::dynamics::islands`]): at the end of each step the awake
//! dynamic bodies are grouped by the step's contacts, and an island whose every body has been
//! slower than [`SleepSettings::speed`] for [`SleepSettings::time`] (its centre, and its surface
//! turning at `|ω|` times its reach) falls asleep as a whole: velocities and angular velocities
//! become exactly zero, the solver skips its bodies, and the narrow phase skips their pairs with
//! static and other sleeping bodies (the contact is kept for the collision messages). An island
//! touching a moving kinematic body or a body on a spring never sleeps; one that comes to rest
//! against a sleeping island joins it.
//!
//! A body wakes when an awake body's contact moves it faster than the sleep speed (see the
//! response and the solver), when game code moves it, sets its velocity or angular velocity or
//! pushes it with a [`Force`], [`Torque`] or [`ForceAtPoint`], when gravity changes, or when a
//! contact of it ends (a body it touched moved away or disappeared); its whole island wakes with
//! it, before the next step simulates anything.

use crate::components::*;
use crate::dynamics::islands::{IslandBuilder, Stillness, islands_to_sleep};
use crate::plugins::core::PrepareStart;
use crate::plugins::narrow_phase::Contacts;
use crate::schedule::{PhysicsSchedule, PhysicsSet};
use crate::settings::{Gravity, PhysicsTimestep, SleepSettings};
use bevy_app::prelude::*;
use bevy_ecs::entity::EntityHashMap;
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
                (wake_on_game_changes, wake_islands)
                    .chain()
                    .run_if(sleep_enabled)
                    .in_set(PrepareStart),
            )
            .add_systems(
                PhysicsSchedule,
                (wake_islands, fall_asleep)
                    .chain()
                    .run_if(sleep_enabled)
                    .in_set(PhysicsSet::Finish),
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

/// Wakes every sleeping body whose island has an awake member (woken by a contact or by game
/// code since the last look), and forgets the island of the bodies so woken.
fn wake_islands(mut bodies: Query<&mut SleepState>, mut woken: Local<Vec<u64>>) {
    woken.clear();
    woken.extend(
        bodies
            .iter()
            .filter(|s| !s.asleep && s.island != 0)
            .map(|s| s.island),
    );
    if woken.is_empty() {
        return;
    }
    woken.sort_unstable();
    woken.dedup();
    for mut s in &mut bodies {
        if s.island != 0 && woken.binary_search(&s.island).is_ok() {
            s.wake();
            s.island = 0;
        }
    }
}

type Candidate<'a> = (
    Entity,
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

/// What a body in a contact is to the islands (sleeping bodies have no slot: they are looked
/// up only when a contact names them, so a sleeping island costs no work per step here).
#[derive(Clone, Copy, Debug)]
enum Slot {
    /// An awake dynamic body, at this index of the step's islands.
    Awake(usize),
    /// A kinematic body; moving ones keep what they touch awake.
    Kinematic { moving: bool },
}

/// The islands of the step and the buffers of [`fall_asleep`], kept from step to step.
#[derive(Default)]
struct IslandScratch {
    islands: IslandBuilder,
    slots: EntityHashMap<Slot>,
    awake: Vec<Entity>,
    stillness: Vec<Stillness>,
    /// Per awake body: the sleeping island it rests against (0: none).
    joins: Vec<u64>,
    asleep: Vec<bool>,
    /// Per island root: the key its bodies sleep with.
    keys: Vec<u64>,
    last_key: u64,
}

/// Counts how long each awake dynamic body has been still, groups the awake bodies into islands
/// by the step's contacts, and puts to sleep the islands still for [`SleepSettings::time`].
fn fall_asleep(
    mut bodies: Query<Candidate, CandidateFilter>,
    never_sleep: Query<(), (With<Spring>, Without<Static>)>,
    contacts: Option<Res<Contacts>>,
    settings: Res<SleepSettings>,
    timestep: Res<PhysicsTimestep>,
    mut scratch: Local<IslandScratch>,
) {
    let s = &mut *scratch;
    count_stillness(&mut bodies, settings.speed, timestep.dt(), s);
    s.islands.reset(s.awake.len());
    s.joins.clear();
    s.joins.resize(s.awake.len(), 0);
    if let Some(contacts) = contacts {
        for pair in &contacts.pairs {
            link_contact(s, (pair.a, pair.b), &bodies, &never_sleep);
            link_contact(s, (pair.b, pair.a), &bodies, &never_sleep);
        }
    }
    islands_to_sleep(&mut s.islands, &s.stillness, settings.time, &mut s.asleep);
    assign_island_keys(s);
    for (i, &e) in s.awake.iter().enumerate() {
        if !s.asleep[i] {
            continue;
        }
        let key = s.keys[s.islands.root(i)];
        if let Ok((_, mut sleep, p, mut v, _, mut w, _)) = bodies.get_mut(e) {
            sleep.asleep = true;
            sleep.at = p.0;
            sleep.island = key;
            // Not a change by game code: the wake-up check compares values, not change ticks.
            v.bypass_change_detection().0 = Vec3::ZERO;
            if let Some(w) = w.as_mut() {
                w.bypass_change_detection().0 = Vec3::ZERO;
            }
        }
    }
}

/// Lists the awake dynamic bodies with their stillness (counting it on) and every body's slot.
fn count_stillness(
    bodies: &mut Query<Candidate, CandidateFilter>,
    speed: f32,
    dt: f32,
    s: &mut IslandScratch,
) {
    s.slots.clear();
    s.awake.clear();
    s.stillness.clear();
    for (e, mut sleep, _, v, m, w, volume) in bodies.iter_mut() {
        let spin = w.as_ref().map_or(0.0, |w| w.0.length());
        if m.inverse() == 0.0 {
            let moving = v.0 != Vec3::ZERO || spin != 0.0;
            s.slots.insert(e, Slot::Kinematic { moving });
            continue;
        }
        if sleep.asleep {
            continue;
        }
        // A turning body's surface moves at up to |ω| times its reach (Box2D's sleep test).
        if v.0.length().max(spin * volume.reach()) >= speed {
            if sleep.still_for != 0.0 {
                sleep.still_for = 0.0;
            }
        } else {
            sleep.still_for += dt;
        }
        s.slots.insert(e, Slot::Awake(s.awake.len()));
        s.awake.push(e);
        s.stillness.push(Stillness {
            still_for: sleep.still_for,
            restless: false,
        });
    }
}

/// The contact of `body` with `other`, seen from `body`'s side: links two awake bodies, joins a
/// sleeping island, or makes `body` restless next to a body that never sleeps.
fn link_contact(
    s: &mut IslandScratch,
    (body, other): (Entity, Entity),
    bodies: &Query<Candidate, CandidateFilter>,
    never_sleep: &Query<(), (With<Spring>, Without<Static>)>,
) {
    let Some(&Slot::Awake(i)) = s.slots.get(&body) else {
        return;
    };
    match s.slots.get(&other) {
        Some(&Slot::Awake(j)) => s.islands.link(i, j),
        Some(&Slot::Kinematic { moving }) => s.stillness[i].restless |= moving,
        None => {
            if let Ok((_, sleep, ..)) = bodies.get(other) {
                if sleep.asleep && sleep.island != 0 {
                    s.joins[i] = sleep.island;
                }
            } else if never_sleep.contains(other) {
                s.stillness[i].restless = true;
            }
        }
    }
}

/// The key of each island about to sleep: the sleeping island it rests against, if any (it
/// joins it, so they wake together), else a new one.
fn assign_island_keys(s: &mut IslandScratch) {
    let n = s.awake.len();
    s.keys.clear();
    s.keys.resize(n, 0);
    for i in 0..n {
        if s.asleep[i] && s.joins[i] != 0 {
            let r = s.islands.root(i);
            s.keys[r] = s.joins[i];
        }
    }
    for i in 0..n {
        let r = s.islands.root(i);
        if s.asleep[i] && s.keys[r] == 0 {
            s.last_key += 1;
            s.keys[r] = s.last_key;
        }
    }
}
