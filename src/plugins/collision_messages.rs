//! Collision started / ended messages: each substep's touching pairs compared with the last
//! substep's, and likewise the overlaps of [`Sensor`]s (which the solver never sees). Two
//! bodies touch while any of their colliders touch or overlap through a sensor, so a body
//! touching another through several parts, sensors among them, starts and ends one collision
//! at a time. A start carries the [`ContactData`] of the pair's strongest collider contact
//! (`collision_data.rs`), none when a sensor's overlap began it.
//!
//! Pairs of sleeping or static bodies are not tested (nothing moved), so they are not in the
//! substep's contacts; they are kept aside, sorted, as the *dormant* pairs, and looked at again
//! only in a substep after a body woke, lost its [`Static`] marker or was despawned. A sleeping
//! pile therefore costs this stage nothing per step (Box2D v3 likewise keeps a sleeping
//! island's contacts in the island's solver set, out of the awake contact array), and falling
//! asleep ends no collision.

pub use super::collision_data::ContactData;
use crate::broad_phase::pair_diff::diff_sorted_by_key;
use crate::components::*;
use crate::plugins::narrow_phase::{ContactPair, Contacts, SensorOverlaps};
use crate::plugins::required_resources::RequireResource;
use crate::plugins::sleep::{Waker, dormant};
use crate::stats::PhysicsStats;
use bevy_app::prelude::*;
use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;

/// Two bodies started touching this step (`a < b`).
#[derive(Message, Debug, Clone, Copy, PartialEq)]
pub struct CollisionStarted {
    /// One body.
    pub a: Entity,
    /// The other.
    pub b: Entity,
    /// How they met, from `a` to `b` (of the pair's colliders, the contact the solver pushed
    /// hardest); `None` for a [`Sensor`]'s overlap, for which no contact is computed.
    pub contact: Option<ContactData>,
}

impl CollisionStarted {
    /// The contact seen from `entity` (normal towards the other body, `entity`'s collider
    /// first): as stored for `a`, flipped for `b`; `None` for a sensor's overlap or an entity
    /// that is not one of the pair.
    pub fn contact_from(&self, entity: Entity) -> Option<ContactData> {
        let c = self.contact?;
        match entity {
            e if e == self.a => Some(c),
            e if e == self.b => Some(c.flipped()),
            _ => None,
        }
    }
}

/// Two bodies stopped touching this step (`a < b`).
#[derive(Message, Debug, Clone, Copy, PartialEq, Eq)]
pub struct CollisionEnded {
    /// One body.
    pub a: Entity,
    /// The other.
    pub b: Entity,
}

/// Opt-in per entity: its collisions are also triggered on it as [`CollisionStart`] and
/// [`CollisionEnd`] events, for observers (Avian's `CollisionEventsEnabled`): a game reacts to
/// what hits *this* entity without filtering every pair's message. Entities without it pay
/// nothing.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CollisionEventsEnabled;

/// Triggered on an entity with [`CollisionEventsEnabled`] when it starts touching `other`
/// (after [`CollisionStarted`]; sensors' overlaps too).
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq)]
pub struct CollisionStart {
    /// The entity observed.
    #[event_target]
    pub entity: Entity,
    /// What it touches.
    pub other: Entity,
    /// How they met, seen from `entity` (normal towards `other`); `None` for a sensor's
    /// overlap.
    pub contact: Option<ContactData>,
}

/// Triggered on an entity with [`CollisionEventsEnabled`] when it stops touching `other`.
#[derive(EntityEvent, Clone, Copy, Debug, PartialEq, Eq)]
pub struct CollisionEnd {
    /// The entity observed.
    #[event_target]
    pub entity: Entity,
    /// What it touched.
    pub other: Entity,
}

/// The comparison of touching pairs that writes the collision messages, as a label: whatever
/// adds contacts after the solve (continuous collision) runs before it.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ReportCollisions;

/// A speculative contact (see [`crate::plugins::soft_step`]) counts as touching once a point is
/// this close (m), or once the solver pushed along it (a fast body stopped at the surface within
/// the step): Box2D's linear slop, so that a body resting a hair above its support under the
/// soft contact does not flicker between touching and not.
pub const TOUCHING_TOLERANCE: f32 = 0.005;

/// Registers the messages and the pairs they are computed from.
pub(crate) fn add_collision_messages(app: &mut App) {
    app.init_required::<TouchingPairs>()
        .add_message::<CollisionStarted>()
        .add_message::<CollisionEnded>();
}

type Pair = (Entity, Entity);

/// The touching pairs at the end of the previous substep, each list sorted.
#[derive(Resource, Default)]
pub(crate) struct TouchingPairs {
    /// Pairs with an awake body: tested every substep.
    active: Vec<Pair>,
    /// Pairs of sleeping or static bodies: untested, touching until one of them wakes or goes.
    dormant: Vec<Pair>,
    /// Pairs overlapping through a [`Sensor`] (the pairs of [`SensorOverlaps`]).
    sensing: Vec<Pair>,
}

impl TouchingPairs {
    /// The touching pairs of sleeping or static bodies (each `(a, b)` with `a < b`).
    pub(crate) fn dormant(&self) -> &[Pair] {
        &self.dormant
    }

    /// The pairs overlapping through a sensor (each `(a, b)` with `a < b`).
    pub(crate) fn sensing(&self) -> &[Pair] {
        &self.sensing
    }
}

/// Whether the bodies of a pair are both static or asleep.
use crate::plugins::narrow_phase::Dormancy;

/// The pairs found in only one of two substeps' sorted lists (scratch, kept between substeps
/// for its capacity): touching pairs that ended and that started (with their contact), and
/// sensor overlaps that ended and started.
#[derive(Default)]
pub(crate) struct Changes {
    gone: Vec<Pair>,
    came: Vec<Touch>,
    gone_sensing: Vec<Pair>,
    came_sensing: Vec<Pair>,
}

/// A pair touching in this substep, with the index of its strongest contact in [`Contacts`]
/// (of the pair's collider contacts, the one the solver pushed hardest; the first on a tie).
type Touch = (Pair, u32);

/// Compares this substep's touching pairs with the last one's; when a pair ends, a sleeping
/// body in it wakes (what it rested on moved away or vanished).
///
/// Two bodies touch while any collider of one touches or, through a [`Sensor`], overlaps any
/// of the other's: a body resting on the floor with a sensor part reaching into it starts one
/// collision, not two, and ends it when the last of the two lets go (the start carries the
/// contact when a collider contact begins it).
#[allow(clippy::too_many_arguments)]
pub(crate) fn report_collisions(
    contacts: Res<Contacts>,
    mut touching: ResMut<TouchingPairs>,
    mut bodies: Query<(Dormancy, Option<&mut SleepState>)>,
    mut woke: RemovedComponents<Sleeping>,
    mut unfixed: RemovedComponents<Static>,
    mut despawned: RemovedComponents<BoundingVolume>,
    overlaps: Option<Res<SensorOverlaps>>,
    mut fresh: Local<Vec<Touch>>,
    mut previous: Local<Vec<Pair>>,
    mut changes: Local<Changes>,
    mut sensed: Local<Vec<Pair>>,
    mut started: MessageWriter<CollisionStarted>,
    mut ended: MessageWriter<CollisionEnded>,
    mut waker: Waker,
    mut stats: ResMut<PhysicsStats>,
) {
    touching_now(&contacts, &mut fresh);
    let touching = &mut *touching;
    let is_dormant = |e: Entity, bodies: &Query<(Dormancy, Option<&mut SleepState>)>| {
        dormant(bodies.get(e).ok().map(|(d, _)| d))
    };
    // Dormant pairs come back into play only after something woke or went.
    let stirred = woke.read().count() + unfixed.read().count() + despawned.read().count() > 0;
    // The last substep's list is moved out, not copied: `active` is refilled below.
    std::mem::swap(&mut *previous, &mut touching.active);
    if stirred {
        let before = previous.len();
        touching.dormant.retain(|&(a, b)| {
            let still = is_dormant(a, &bodies) && is_dormant(b, &bodies);
            if !still {
                previous.push((a, b));
            }
            still
        });
        if previous.len() > before {
            previous.sort_unstable();
        }
    }
    let Changes {
        gone,
        came,
        gone_sensing,
        came_sensing,
    } = &mut *changes;
    // The sensors' overlaps first: a contact that ends while the bodies still overlap through
    // a sensor part ends nothing. Without the sensors' stage the last overlaps stay.
    gone_sensing.clear();
    came_sensing.clear();
    sensed.clear();
    if let Some(overlaps) = overlaps {
        sensed.extend(overlaps.pairs.iter().map(|p| (p.a.min(p.b), p.a.max(p.b))));
        let dormant_pair = |(a, b): Pair| is_dormant(a, &bodies) && is_dormant(b, &bodies);
        let lists = (&mut *gone_sensing, &mut *came_sensing);
        diff_sensing(&mut sensed, &touching.sensing, lists, dormant_pair);
        std::mem::swap(&mut *sensed, &mut touching.sensing);
    } else {
        sensed.clone_from(&touching.sensing);
    }
    // The last substep's overlaps.
    let sensed_before = &*sensed;
    let sensing_now = |p: &Pair| touching.sensing.binary_search(p).is_ok();
    // The pairs of only one of the two sorted lists, in one merge pass.
    gone.clear();
    came.clear();
    diff_sorted_by_key(&previous, &fresh, |p| *p, |t| t.0, came, gone);
    // Each pair touching before and not now is newly dormant (not tested now) or ended.
    let mut newly_dormant = false;
    for &(a, b) in gone.iter() {
        if is_dormant(a, &bodies) && is_dormant(b, &bodies) {
            touching.dormant.push((a, b));
            newly_dormant = true;
            continue;
        }
        if !sensing_now(&(a, b)) {
            ended.write(CollisionEnded { a, b });
        }
        for e in [a, b] {
            if let Ok(((_, true), state)) = bodies.get_mut(e) {
                waker.wake(e, state.map(Mut::into_inner));
            }
        }
    }
    if newly_dormant {
        touching.dormant.sort_unstable();
    }
    let mut resumed = false;
    // Each pair touching now and not before is a new collision, or a dormant pair tested again.
    for &(pair, contact) in came.iter() {
        if let Ok(at) = touching.dormant.binary_search(&pair) {
            // Tested again (a body of it woke): active from now on, not a new collision.
            touching.dormant[at].0 = Entity::PLACEHOLDER;
            resumed = true;
            continue;
        }
        if sensed_before.binary_search(&pair).is_ok() {
            // Already touching through a sensor part.
            continue;
        }
        let data = |c: &ContactPair| ContactData::of_pair(c, pair.0, TOUCHING_TOLERANCE);
        started.write(CollisionStarted {
            a: pair.0,
            b: pair.1,
            contact: contacts.pairs.get(contact as usize).map(data),
        });
    }
    if resumed {
        touching.dormant.retain(|p| p.0 != Entity::PLACEHOLDER);
    }
    touching.active.clear();
    touching.active.extend(fresh.iter().map(|t| t.0));
    // A sensor's overlap starts or ends a collision only if no collider contact holds the
    // pair now or held it last substep (a contact that ended with it has ended the pair).
    let found = |list: &[Pair], p: &Pair| list.binary_search(p).is_ok();
    let held = |p: &Pair| found(&touching.active, p) || found(&touching.dormant, p);
    for &(a, b) in gone_sensing.iter() {
        if !(held(&(a, b)) || found(&previous, &(a, b))) {
            ended.write(CollisionEnded { a, b });
        }
    }
    for &(a, b) in came_sensing.iter() {
        if !(held(&(a, b)) || found(&previous, &(a, b))) {
            let contact = None;
            started.write(CollisionStarted { a, b, contact });
        }
    }
    // Every pair touching now, tested this substep or at rest asleep.
    let all = touching.active.len() + touching.dormant.len();
    stats.set_counter("collisions/touching_pairs", all as f64);
}

/// This substep's touching body pairs (a contact within [`TOUCHING_TOLERANCE`], or one the
/// solver pushed along), each once with its strongest contact, sorted.
fn touching_now(contacts: &Contacts, fresh: &mut Vec<Touch>) {
    fresh.clear();
    fresh.extend(
        (contacts.pairs.iter().zip(0u32..))
            .filter(|(c, _)| c.normal_impulse > 0.0 || c.manifold.touching(TOUCHING_TOLERANCE))
            .map(|(c, i)| ((c.a.min(c.b), c.a.max(c.b)), i)),
    );
    // By pair, then by index (the list is in index order and the radix sort stable).
    radsort::sort_by_key(fresh, |((a, b), _)| {
        (u128::from(a.to_bits()) << 64) | u128::from(b.to_bits())
    });
    // The strongest push, then (ties, as without the rigid-body solver) the fastest approach.
    let strength = |i: u32| {
        let c = &contacts.pairs[i as usize];
        (c.normal_impulse, c.impact_speed)
    };
    fresh.dedup_by(|later, kept| {
        let same = later.0 == kept.0;
        if same && strength(later.1) > strength(kept.1) {
            kept.1 = later.1;
        }
        same
    });
}

/// The sensor overlaps' changes: `fresh` (this substep's pairs, sorted and deduplicated here)
/// against `before` (the last one's). A pair of two sleeping or static bodies is not tested,
/// so it keeps overlapping (it neither starts nor ends; it stays in `fresh`); a sensor's
/// overlap never wakes anything.
fn diff_sensing(
    fresh: &mut Vec<Pair>,
    before: &[Pair],
    (gone, came): (&mut Vec<Pair>, &mut Vec<Pair>),
    dormant: impl Fn(Pair) -> bool,
) {
    fresh.sort_unstable();
    fresh.dedup();
    diff_sorted_by_key(before, fresh, |p| *p, |p| *p, came, gone);
    let tested = fresh.len();
    gone.retain(|&p| {
        let kept = dormant(p);
        if kept {
            fresh.push(p);
        }
        !kept
    });
    if fresh.len() > tested {
        fresh.sort_unstable();
    }
}

/// Triggers this substep's collision messages as entity events on the bodies that asked for
/// them (both sides of a pair, each seeing the other).
pub(crate) fn trigger_collision_events(
    mut started: MessageReader<CollisionStarted>,
    mut ended: MessageReader<CollisionEnded>,
    enabled: Query<(), With<CollisionEventsEnabled>>,
    mut commands: Commands,
) {
    if enabled.is_empty() {
        started.clear();
        ended.clear();
        return;
    }
    let sides = |a: Entity, b: Entity| [(a, b), (b, a)];
    for m in started.read() {
        for (entity, other) in sides(m.a, m.b) {
            if enabled.contains(entity) {
                commands.trigger(CollisionStart {
                    entity,
                    other,
                    contact: m.contact_from(entity),
                });
            }
        }
    }
    for m in ended.read() {
        for (entity, other) in sides(m.a, m.b) {
            if enabled.contains(entity) {
                commands.trigger(CollisionEnd { entity, other });
            }
        }
    }
}

/// Advances the collision message buffers once per standalone step (an `App` does this itself
/// every frame), so unread messages live two steps, as Bevy's messages live two frames.
pub(crate) fn update_collision_messages(world: &mut World) {
    if let Some(mut m) = world.get_resource_mut::<Messages<CollisionStarted>>() {
        m.update();
    }
    if let Some(mut m) = world.get_resource_mut::<Messages<CollisionEnded>>() {
        m.update();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::*;
    use glam::Vec3;

    #[derive(Resource, Default)]
    struct Seen(Vec<(&'static str, Entity, Entity)>);

    #[test]
    fn a_pair_touching_through_several_colliders_is_listed_once_with_its_strongest_contact() {
        let e = |i| Entity::from_raw_u32(i).unwrap();
        let touching = crate::geometry::ContactManifold::single(Vec3::Z, Vec3::ZERO, 0.0);
        let contact = |a: u32, b: u32, normal_impulse: f32| ContactPair {
            a: e(a),
            b: e(b),
            collider_a: e(a + 10),
            collider_b: e(b + 10),
            manifold: touching,
            normal_impulse,
            impact_speed: 0.0,
            rounding: [0.0; 2],
        };
        let contacts = Contacts {
            // Pair (1, 2) through three collider pairs, listed both ways round.
            pairs: vec![
                contact(1, 2, 0.5),
                contact(3, 4, 0.0),
                contact(2, 1, 2.0),
                contact(1, 2, 1.0),
            ],
        };
        let mut fresh = Vec::new();
        touching_now(&contacts, &mut fresh);
        let pair = |a: u32, b: u32| (e(a).min(e(b)), e(a).max(e(b)));
        let mut expected = vec![(pair(1, 2), 2), (pair(3, 4), 1)];
        expected.sort_unstable();
        assert_eq!(fresh, expected);
    }

    #[test]
    fn an_entity_with_collision_events_sees_its_own_start_and_end_and_no_other_pair() {
        let mut app = App::new();
        app.add_plugins(UrtoPlugins::default())
            .insert_resource(Gravity::EARTH_Z_UP)
            .init_resource::<Seen>();
        let ground = app
            .world_mut()
            .spawn((Collider::half_space(Vec3::Z), Static))
            .id();
        let watched = app
            .world_mut()
            .spawn((
                Collider::sphere(0.5),
                Position::new(0.0, 0.0, 0.5),
                Velocity::default(),
                CollisionEventsEnabled,
            ))
            .id();
        // Another ball rests there too, unobserved.
        app.world_mut().spawn((
            Collider::sphere(0.5),
            Position::new(5.0, 0.0, 0.5),
            Velocity::default(),
        ));
        app.world_mut()
            .add_observer(|e: On<CollisionStart>, mut seen: ResMut<Seen>| {
                seen.0.push(("start", e.entity, e.other));
            });
        app.world_mut()
            .add_observer(|e: On<CollisionEnd>, mut seen: ResMut<Seen>| {
                seen.0.push(("end", e.entity, e.other));
            });
        crate::step(app.world_mut(), 60).unwrap();
        assert_eq!(
            app.world().resource::<Seen>().0,
            [("start", watched, ground)]
        );
        // Thrown up off the ground: the contact ends.
        app.world_mut().get_mut::<Velocity>(watched).unwrap().0 = Vec3::new(0.0, 0.0, 5.0);
        crate::step(app.world_mut(), 5).unwrap();
        let seen = &app.world().resource::<Seen>().0;
        assert_eq!(seen[1..], [("end", watched, ground)]);
    }
}
