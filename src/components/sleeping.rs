//! Sleeping bodies: the [`Sleeping`] marker and each body's [`SleepState`].
//!
//! A sleeping body carries the [`Sleeping`] marker, so it lives in archetypes of its own and
//! every per-step query of the physics filters it out with `Without<Sleeping>` at the archetype
//! level: a sleeping island is passed over without looking at its bodies one by one (Avian's
//! `Sleeping` component; Box2D v3 and rapier keep sleeping bodies out of their active sets for
//! the same reason). Only the wake-up check looks at them, through change detection.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;
use glam::{Quat, Vec3};
use std::collections::HashMap;

/// Marks a sleeping body (with [`SleepSettings`](crate::settings::SleepSettings) on, the
/// default): a dynamic body whose whole island has been still for the settings' time (see
/// [`crate::dynamics::stillness`]) falls asleep with it. It is then neither integrated nor tested against other
/// sleeping or static bodies, and costs no work per step. It wakes, with its island, when
/// something awake hits it, when a body it rests on goes, when the game moves or turns it, sets
/// its velocity or angular velocity, pushes it with a [`Force`](crate::components::Force),
/// [`Torque`](crate::components::Torque) or [`ForceAtPoint`](crate::components::ForceAtPoint),
/// changes its collider, or when gravity changes.
///
/// The physics inserts and removes it; game code reads it (`Has<Sleeping>`) and may remove it
/// to wake a body (its island wakes with it at the next step).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[component(on_add = note_fell_asleep, on_remove = note_woke)]
pub struct Sleeping;

/// Keeps a body awake: it never falls asleep, and neither do the awake bodies of its island (as
/// with a body on a spring). For a body that must not freeze at a slow turning point, a
/// player's body, or one moved by game code each step (Avian's `SleepingDisabled`, rapier's
/// `can_sleep(false)`). Given to a sleeping body, it wakes it and its island at the next step;
/// taken away, the body's stillness counts from zero. It goes on the root body (a compound's
/// parts have no sleep of their own). An island already asleep that it comes to rest against
/// wakes only as for any body: when it is approached faster than the wake speed.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SleepingDisabled;

/// A body's progress towards sleep and, asleep, what it slept with.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct SleepState {
    /// Seconds the body has been still (awake bodies): within the sleep speed times the sleep
    /// time of where each window began ([`SleepSettings`](crate::settings::SleepSettings)).
    pub still_for: f32,
    /// Awake, where its current still window began; asleep, where it fell asleep: moving it
    /// elsewhere wakes it.
    pub at: Vec3,
    /// Its orientation then: turning it wakes it (asleep).
    pub orientation: Quat,
    /// The island it fell asleep with (0: none): waking one body of it wakes all of them
    /// ([`crate::dynamics::islands`]).
    pub island: u64,
}

impl SleepState {
    /// Restarts the stillness count and leaves the island (the body is waking).
    pub fn restart(&mut self) {
        self.still_for = 0.0;
        self.island = 0;
    }
}

/// The sleeping islands: each one's members, so that waking one body wakes its island without
/// a pass over every sleeping body, and the islands woken since the last look.
#[derive(Resource, Default, Debug)]
pub struct SleepingIslands {
    pub(crate) members: HashMap<u64, Vec<Entity>>,
    pub(crate) woken: Vec<u64>,
    pub(crate) last_key: u64,
}

impl SleepingIslands {
    /// Number of sleeping islands.
    pub fn len(&self) -> usize {
        self.members.len()
    }

    /// True when nothing sleeps.
    pub fn is_empty(&self) -> bool {
        self.members.is_empty()
    }

    /// The bodies that fell asleep with island `key` (some may be gone since).
    pub fn members(&self, key: u64) -> &[Entity] {
        self.members.get(&key).map_or(&[], Vec::as_slice)
    }
}

/// Bodies that fell asleep (`true`) or woke (`false`) since the broad phase last looked, in the
/// order it happened: the broad phase stops and restarts pairing them from this list instead
/// of looking at every body each step.
#[derive(Resource, Default, Debug)]
pub(crate) struct SleepTransitions(pub Vec<(Entity, bool)>);

fn note_fell_asleep(world: DeferredWorld, context: HookContext) {
    note(world, context.entity, true);
}

/// A body woken by the physics has left its island already; one that game code woke (removing
/// the marker) or despawned takes its island with it, as destroying a body wakes its island in
/// Box2D.
fn note_woke(mut world: DeferredWorld, context: HookContext) {
    let island = world
        .get::<SleepState>(context.entity)
        .map_or(0, |s| s.island);
    if island != 0
        && let Some(mut islands) = world.get_resource_mut::<SleepingIslands>()
    {
        islands.woken.push(island);
    }
    note(world, context.entity, false);
}

fn note(mut world: DeferredWorld, e: Entity, asleep: bool) {
    if let Some(mut transitions) = world.get_resource_mut::<SleepTransitions>() {
        transitions.0.push((e, asleep));
    }
    crate::plugins::settle::note_sleeping_change(&mut world);
}
