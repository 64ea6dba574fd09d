//! Sleeping: bodies that have come to rest stop costing time until something wakes them (the
//! usual engine technique; Box2D, rapier and Jolt do the same).
//!
//! Bodies sleep by islands ([`crate::dynamics::islands`]): at the end of each step the awake
//! dynamic bodies are grouped by the step's contacts, and an island whose every body has been
//! still for [`SleepSettings::time`] falls asleep as a whole (still: within `speed × time` of
//! where its current window began, its centre and its surface as it turned, a net
//! displacement below [`SleepSettings::speed`] on average, and never faster than four times
//! it; Jolt's sleep test, see [`crate::dynamics::stillness`]): velocities and angular velocities
//! become exactly zero and each body gets the [`Sleeping`] marker. The marker moves it to
//! archetypes that every per-step query leaves out (`Without<Sleeping>`), and the broad phase
//! stops pairing it with scenery and other sleepers, so a sleeping island costs no pass over its
//! bodies; only the wake-up check (`wake_on_writes`) looks at them, through the summary ticks of
//! their tables (one comparison per column of a sleeping table, not per body). The contacts of a
//! sleeping island are kept (no collision ends by falling asleep). An island touching a moving
//! kinematic body or a body on a spring never sleeps; one that comes to rest against a sleeping
//! island joins it.
//!
//! A body wakes when an awake body's contact moves it faster than the sleep speed (see the
//! response and the solver), when game code moves or turns it, sets its velocity or angular
//! velocity, pushes it with a [`Force`], [`Torque`], [`ForceAtPoint`] or [`Impulse`], writes or
//! removes its [`Mass`], [`Density`] or [`GravityScale`], changes its collider or removes its
//! [`Sleeping`] marker, writes its [`Friction`] or [`Restitution`], when gravity changes,
//! when a contact of it ends (a body it touched moved away or disappeared), when a static body
//! it touches is moved, turned, reshaped, stripped of its collider, made a sensor or given new
//! layers, friction or restitution, or when it loses its collider or becomes a sensor
//! (`wake_on_scenery`), when a joint of it is added, written to, disabled, removed or loses a
//! body, or the static it hangs from is moved or loses its collider (`wake_on_joints`); its
//! whole island wakes with it (members are kept per island in [`SleepingIslands`], as Box2D
//! v3's `island.c` keeps them), before the next step simulates anything. The same changes made
//! to an awake body count its stillness from zero, so that it cannot fall asleep on the step
//! they are made; and an island pulled by gravity that touches nothing holding it never sleeps
//! ([`crate::dynamics::islands`]).

use crate::components::*;
use crate::dynamics::islands::{IslandBuilder, Stillness, islands_to_sleep};
use crate::dynamics::stillness::StillTest;
use crate::plugins::core::PrepareWake;
use crate::plugins::joints::ActiveJoint;
use crate::plugins::narrow_phase::Contacts;
use crate::plugins::required_resources::RequireResource;
use crate::plugins::wake_on_joints::wake_on_joint_changes;
use crate::plugins::wake_on_scenery::wake_on_scenery_changes;
use crate::plugins::wake_on_writes::wake_on_game_changes;
use crate::schedule::{PhysicsSchedule, PhysicsSet};
use crate::settings::{Gravity, LengthUnit, PhysicsTimestep, SleepSettings};
use crate::stats::PhysicsStats;
use bevy_app::prelude::*;
use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use bevy_ecs::system::entity_command;
use glam::Vec3;

/// Puts still bodies to sleep and wakes them when game code touches them.
#[derive(Debug, Clone, Default)]
pub struct SleepPlugin;

impl Plugin for SleepPlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<SleepSettings>()
            .init_required::<SleepingIslands>()
            .add_systems(
                PhysicsSchedule,
                (
                    wake_on_game_changes,
                    wake_on_scenery_changes,
                    wake_on_joint_changes,
                    wake_the_sleepless,
                    wake_islands,
                )
                    .chain()
                    .run_if(sleep_enabled)
                    .in_set(PrepareWake),
            )
            .add_systems(
                PhysicsSchedule,
                (wake_islands, fall_asleep)
                    .chain()
                    .run_if(sleep_enabled)
                    .in_set(PhysicsSet::Finish),
            )
            .add_systems(
                PhysicsSchedule,
                wake_everything.run_if(sleep_disabled).in_set(PrepareWake),
            );
    }
}

fn sleep_enabled(settings: Res<SleepSettings>) -> bool {
    settings.enabled
}

fn sleep_disabled(settings: Option<Res<SleepSettings>>) -> bool {
    settings.is_none_or(|s| !s.enabled)
}

/// Whether `e` takes part in no simulation this substep: static scenery or a sleeping body
/// (`(is static, is asleep)`, `None` for no body).
pub(crate) fn dormant(state: Option<(bool, bool)>) -> bool {
    state.is_some_and(|(is_static, asleep)| is_static || asleep)
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

/// Wakes sleeping bodies from any system: the marker goes when the system's commands apply, and
/// the body's island wakes with it at the next look at the woken islands.
#[derive(SystemParam)]
pub(crate) struct Waker<'w, 's> {
    commands: Commands<'w, 's>,
    islands: Option<ResMut<'w, SleepingIslands>>,
}

impl Waker<'_, '_> {
    /// Wakes `e`, whose sleep state is `state`.
    pub fn wake(&mut self, e: Entity, state: Option<&mut SleepState>) {
        unmark(&mut self.commands, e);
        if let Some(state) = state {
            if state.island != 0
                && let Some(islands) = self.islands.as_mut()
            {
                islands.woken.push(state.island);
            }
            state.restart();
        }
    }
}

/// Takes the [`Sleeping`] marker off `e` when the commands apply (nothing if `e` is gone by
/// then).
fn unmark(commands: &mut Commands, e: Entity) {
    if let Ok(mut entity) = commands.get_entity(e) {
        entity.queue_silenced(entity_command::remove::<Sleeping>());
    }
}

/// Wakes the islands of the bodies woken since the last look (by contacts, by game code, by a
/// removed [`Sleeping`] marker or a despawned member).
fn wake_islands(
    mut islands: ResMut<SleepingIslands>,
    mut states: Query<&mut SleepState>,
    mut commands: Commands,
) {
    let islands = &mut *islands;
    islands.woken.sort_unstable();
    islands.woken.dedup();
    for key in islands.woken.drain(..) {
        for e in islands.members.remove(&key).unwrap_or_default() {
            if let Ok(mut state) = states.get_mut(e) {
                state.restart();
            }
            unmark(&mut commands, e);
        }
    }
}

/// Sleeping bodies given [`SleepingDisabled`].
type SleepingSleepless = (With<Sleeping>, With<SleepingDisabled>);

/// A sleeping body given [`SleepingDisabled`] wakes, and its island with it (no archetype
/// matches while no sleeper has the marker: nothing to pay); a body that loses the marker
/// counts its stillness from zero (it was not counted while it had it).
fn wake_the_sleepless(
    mut sleepers: Query<(Entity, &mut SleepState), SleepingSleepless>,
    mut awake: Query<&mut SleepState, Without<Sleeping>>,
    mut freed: RemovedComponents<SleepingDisabled>,
    mut waker: Waker,
) {
    for (e, mut state) in &mut sleepers {
        waker.wake(e, Some(&mut state));
    }
    for e in freed.read() {
        if let Ok(mut state) = awake.get_mut(e) {
            state.restart();
        }
    }
}

/// With sleeping switched off, nothing stays asleep.
fn wake_everything(
    mut sleepers: Query<(Entity, &mut SleepState), With<Sleeping>>,
    islands: Option<ResMut<SleepingIslands>>,
    mut commands: Commands,
) {
    for (e, mut state) in &mut sleepers {
        state.restart();
        unmark(&mut commands, e);
    }
    if let Some(mut islands) = islands {
        islands.members.clear();
        islands.woken.clear();
    }
}

type Candidate<'a> = (
    Entity,
    &'a mut SleepState,
    (&'a Position, &'a Rotation),
    &'a mut Velocity,
    &'a ComputedMass,
    Option<&'a mut AngularVelocity>,
    &'a BoundingVolume,
    (Option<&'a GravityScale>, Option<&'a LockedAxes>),
);
type CandidateFilter = (
    Without<Sleeping>,
    Without<Static>,
    Without<Quarantined>,
    Without<ChildOf>,
    Without<Spring>,
    Without<SleepingDisabled>,
);

/// Awake bodies whose make-up game code wrote to since the last step: what wakes a sleeper
/// (`wake_on_writes`' `MadeOf`) counts their stillness from zero, so that a write on the step a
/// body would fall asleep is not slept through (a box given a gravity scale of −1 then stayed
/// on its floor, asleep). Read only for bodies still long enough to sleep.
type Remade = Or<(
    Changed<GravityScale>,
    Changed<Mass>,
    Changed<Density>,
    Changed<LockedAxes>,
    Changed<Collider>,
    Changed<CollisionLayers>,
    Changed<LinearDrag>,
    Changed<AngularDrag>,
    Changed<Friction>,
    Changed<Restitution>,
    Added<Sensor>,
)>;

/// Bodies that never sleep and keep what they touch awake: bodies on springs (their pull is not
/// in the contacts the islands are built from) and bodies with [`SleepingDisabled`].
type NeverSleeps = (Or<(With<Spring>, With<SleepingDisabled>)>, Without<Static>);

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
    /// The kinematic bodies and whether each moves.
    kinematic: Vec<(Entity, bool)>,
    stillness: Vec<Stillness>,
    /// Per awake body: the sleeping island it rests against (0: none).
    joins: Vec<u64>,
    asleep: Vec<bool>,
    /// Per island root: the key its bodies sleep with.
    keys: Vec<u64>,
}

/// Counts how long each awake dynamic body has been still and, once some body has been still
/// for [`SleepSettings::time`], groups the awake bodies into islands by the step's contacts
/// and joints and puts to sleep the islands still for that long.
#[allow(clippy::too_many_arguments)]
fn fall_asleep(
    mut bodies: Query<Candidate, CandidateFilter>,
    sleepers: Query<&SleepState, With<Sleeping>>,
    never_sleep: Query<(), NeverSleeps>,
    remade: Query<(), Remade>,
    contacts: Option<Res<Contacts>>,
    joints: Query<&Joint, ActiveJoint>,
    settings: Res<SleepSettings>,
    timestep: Res<PhysicsTimestep>,
    gravity: Option<Res<Gravity>>,
    mut islands: ResMut<SleepingIslands>,
    mut scratch: Local<IslandScratch>,
    mut stats: ResMut<PhysicsStats>,
    mut commands: Commands,
    length: Option<Res<LengthUnit>>,
) {
    let s = &mut *scratch;
    let gravity = gravity.map_or(Vec3::ZERO, |g| g.acceleration());
    // The sleep speed is set for metre-sized bodies.
    let settings = SleepSettings {
        speed: settings.speed * length.map_or(1.0, |u| u.get()),
        ..*settings
    };
    count_stillness(&mut bodies, &remade, &settings, (timestep.dt(), gravity), s);
    stats.set_counter("sleep/awake_bodies", s.awake.len() as f64);
    stats.set_counter("sleep/sleeping_islands", islands.members.len() as f64);
    if !s.stillness.iter().any(|b| b.still_for >= settings.time) {
        // An island sleeps once all its bodies have been still for the sleep time; while no
        // body has, none can, and the islands are not built (a scene in motion pays one pass
        // over its bodies here, not a lookup per contact and joint).
        return;
    }
    index_slots(s);
    s.islands.reset(s.awake.len());
    s.joins.clear();
    s.joins.resize(s.awake.len(), 0);
    if let Some(contacts) = contacts {
        for pair in &contacts.pairs {
            link_contact(s, (pair.a, pair.b), &sleepers, &never_sleep);
            link_contact(s, (pair.b, pair.a), &sleepers, &never_sleep);
        }
    }
    // Jointed bodies are one island: they fall asleep and wake together. A joint to the
    // world holds its body.
    for joint in &joints {
        if let Some(b) = joint.body_b_entity() {
            link_contact(s, (joint.body_a, b), &sleepers, &never_sleep);
            link_contact(s, (b, joint.body_a), &sleepers, &never_sleep);
        } else if let Some(&Slot::Awake(i)) = s.slots.get(&joint.body_a) {
            s.stillness[i].held = true;
        }
    }
    islands_to_sleep(&mut s.islands, &s.stillness, settings.time, &mut s.asleep);
    assign_island_keys(s, &mut islands.last_key);
    for (i, &e) in s.awake.iter().enumerate() {
        if !s.asleep[i] {
            continue;
        }
        let key = s.keys[s.islands.root(i)];
        if let Ok((_, mut sleep, (p, r), mut v, _, mut w, ..)) = bodies.get_mut(e) {
            sleep.at = p.0;
            sleep.orientation = r.0;
            sleep.island = key;
            islands.members.entry(key).or_default().push(e);
            commands.entity(e).insert(Sleeping);
            // Not a change by game code: the wake-up check compares values, not change ticks.
            v.bypass_change_detection().0 = Vec3::ZERO;
            if let Some(w) = w.as_mut() {
                w.bypass_change_detection().0 = Vec3::ZERO;
            }
        }
    }
    stats.set_counter("sleep/sleeping_islands", islands.members.len() as f64);
}

/// Every awake and kinematic body's slot, for the contacts and joints to find.
fn index_slots(s: &mut IslandScratch) {
    s.slots.clear();
    let awake = s.awake.iter().enumerate();
    s.slots.extend(awake.map(|(i, &e)| (e, Slot::Awake(i))));
    let kinematic = s.kinematic.iter();
    s.slots
        .extend(kinematic.map(|&(e, moving)| (e, Slot::Kinematic { moving })));
}

/// Lists the awake dynamic bodies with their stillness (counting it on, [`StillTest`]: within
/// `speed × time` of where the body's current window began, never faster than four times the
/// speed; from zero for a body still long enough to sleep but `remade`) and whether `gravity`
/// pulls them, and the kinematic ones.
fn count_stillness(
    bodies: &mut Query<Candidate, CandidateFilter>,
    remade: &Query<(), Remade>,
    settings: &SleepSettings,
    (dt, gravity): (f32, Vec3),
    s: &mut IslandScratch,
) {
    s.awake.clear();
    s.kinematic.clear();
    s.stillness.clear();
    let test = StillTest::new(settings.speed, settings.time);
    for (e, mut sleep, (p, r), v, m, w, volume, (scale, locks)) in bodies.iter_mut() {
        let spin = w.as_ref().map_or(0.0, |w| w.0.length());
        if m.inverse() == 0.0 {
            let moving = v.0 != Vec3::ZERO || spin != 0.0;
            s.kinematic.push((e, moving));
            continue;
        }
        let (start, reach) = ((sleep.at, sleep.orientation), volume.reach());
        // A turning body's surface moves at up to |ω| times its reach.
        let speed = v.0.length().max(spin * reach);
        let (mut still_for, restart) =
            test.step(sleep.still_for, (start, (p.0, r.0)), speed, reach, dt);
        if still_for >= settings.time && remade.contains(e) {
            still_for = 0.0;
        }
        let mut next = SleepState {
            still_for,
            ..*sleep
        };
        if restart {
            // Its window starts again here (`at` and `orientation` are where it began; asleep,
            // where the body fell asleep).
            (next.at, next.orientation) = (p.0, r.0);
        }
        sleep.set_if_neq(next);
        s.awake.push(e);
        let pull =
            gravity * scale.map_or(1.0, |g| g.0) * LockedAxes::of(locks).free_translation_axes();
        s.stillness.push(Stillness {
            still_for,
            pulled: pull != Vec3::ZERO,
            ..Stillness::default()
        });
    }
}

/// The contact of `body` with `other`, seen from `body`'s side: links two awake bodies, joins a
/// sleeping island, or makes `body` restless next to a body that never sleeps; a static,
/// kinematic or sleeping `other` holds `body`.
fn link_contact(
    s: &mut IslandScratch,
    (body, other): (Entity, Entity),
    sleepers: &Query<&SleepState, With<Sleeping>>,
    never_sleep: &Query<(), NeverSleeps>,
) {
    let Some(&Slot::Awake(i)) = s.slots.get(&body) else {
        return;
    };
    match s.slots.get(&other) {
        Some(&Slot::Awake(j)) => s.islands.link(i, j),
        Some(&Slot::Kinematic { moving }) => {
            s.stillness[i].restless |= moving;
            s.stillness[i].held = true;
        }
        None => {
            if let Ok(sleep) = sleepers.get(other) {
                if sleep.island != 0 {
                    s.joins[i] = sleep.island;
                }
                s.stillness[i].held = true;
            } else if never_sleep.contains(other) {
                s.stillness[i].restless = true;
            } else {
                // Static scenery (or a body out of the step: quarantined, a part).
                s.stillness[i].held = true;
            }
        }
    }
}

/// The key of each island about to sleep: the sleeping island it rests against, if any (it
/// joins it, so they wake together), else a new one.
fn assign_island_keys(s: &mut IslandScratch, last_key: &mut u64) {
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
            *last_key += 1;
            s.keys[r] = *last_key;
        }
    }
}
