//! The soft step's contact inputs: the narrow phase's manifolds as solver contacts in a stable
//! order (collider pairs, never archetype order), the moving parts of kinematic compounds as
//! extra immovable solver bodies, and the solver's impulses reported back on the contacts.

use super::BodySlots;
use crate::components::*;
use crate::dynamics::solver::{BodyInput, ContactInput, ContactPointInput, Solver, SolverBodies};
use crate::plugins::narrow_phase::Contacts;
use crate::plugins::response::part_velocity;
use crate::settings::ContactSettings;
use bevy_ecs::prelude::*;
use glam::Vec3;

/// A body's contact material: restitution, friction and rolling resistance.
pub(super) type Material = (
    Option<&'static Restitution>,
    Option<&'static Friction>,
    Option<&'static RollingResistance>,
);

/// [`gather_contacts`]' scratch: the manifolds as the narrow phase listed them, their order by
/// key, and each slot's material. The keys are sorted with each manifold's place in the list
/// (an index, not the 128-byte contact: a thousand-ball pile sorts 3,000 manifolds a step,
/// and moving whole contacts through a stable sort was a tenth of its step), by a stable radix
/// sort on the 64-bit collider pair (two entity indices: the bytes all keys share are skipped),
/// which is the stable order by key; a comparison sort of the 128-bit keys was 3–6 % of a
/// pile's step. A body's material is read from the world once a step, not once per contact.
#[derive(Debug, Default)]
pub(super) struct KeyedContacts {
    found: Vec<(ContactInput, u32)>,
    order: Vec<(u64, u32)>,
    /// Per slot: restitution, friction, rolling resistance, once read.
    materials: Vec<Option<(f32, f32, f32)>>,
}

/// The narrow phase's manifolds as solver contacts, keyed by collider pair (sorted), each with
/// the index of the pair it came from (`sources`).
pub(super) fn gather_contacts(
    contacts: &Contacts,
    slots: &BodySlots,
    materials: &Query<Material>,
    settings: &ContactSettings,
    keyed: &mut KeyedContacts,
    out: &mut Vec<ContactInput>,
    sources: &mut Vec<u32>,
) {
    keyed.found.clear();
    keyed.materials.clear();
    keyed.materials.resize(slots.len(), None);
    let entities = slots.entities();
    let mut material = |slot: usize| {
        *keyed.materials[slot].get_or_insert_with(|| {
            let (r, f, rolling) = materials.get(entities[slot]).unwrap_or((None, None, None));
            (
                r.map_or(settings.default_restitution, |r| r.0),
                f.map_or(settings.default_friction, |f| f.0),
                rolling.map_or(0.0, |r| r.0),
            )
        })
    };
    for (source, pair) in contacts.pairs.iter().enumerate() {
        let (Some(a), Some(b)) = (slots.slot(pair.a), slots.slot(pair.b)) else {
            continue;
        };
        let ((ea, fa, ra), (eb, fb, rb)) = (material(a), material(b));
        // The lower slot first, whatever order the broad phase found the pair in (it follows
        // insertion, hence archetype, order).
        let [rounding_a, rounding_b] = pair.rounding;
        let (a, b, normal, rounding) = if a <= b {
            (a, b, pair.manifold.normal, [rounding_a, rounding_b])
        } else {
            (b, a, -pair.manifold.normal, [rounding_b, rounding_a])
        };
        let mut input = ContactInput {
            a: a as u32,
            b: b as u32,
            normal,
            friction: (fa * fb).max(0.0).sqrt(),
            restitution: 0.5 * (ea + eb),
            rolling_resistance: ra.max(rb),
            rounding,
            points: Default::default(),
            count: pair.manifold.len() as u8,
            key: pair_key(pair.collider_a, pair.collider_b) << 16,
        };
        for (p, cp) in input.points.iter_mut().zip(pair.manifold.points()) {
            *p = ContactPointInput {
                point: cp.point,
                separation: -cp.depth,
                feature: cp.feature,
            };
        }
        keyed.found.push((input, source as u32));
    }
    // Stable: the manifolds of one collider pair (meshes) keep the narrow phase's order, and
    // their rank among the pair's manifolds makes each key unique.
    let order = &mut keyed.order;
    order.clear();
    order.extend(
        keyed
            .found
            .iter()
            .enumerate()
            .map(|(i, (c, _))| ((c.key >> 16) as u64, i as u32)),
    );
    // Often in order already (a scene at rest keeps its pairs' order): checked first, as the
    // stable sort would leave it.
    if !order.is_sorted_by_key(|&(pair, _)| pair) {
        radsort::sort_by_key(order, |&(pair, _)| pair);
    }
    out.clear();
    sources.clear();
    let mut rank = 0u128;
    for (n, &(key, i)) in order.iter().enumerate() {
        let (mut input, source) = keyed.found[i as usize];
        rank = if n > 0 && key == order[n - 1].0 {
            rank + 1
        } else {
            0
        };
        input.key |= rank.min(0xffff);
        out.push(input);
        sources.push(source);
    }
}

/// The parts of kinematic and static compounds that the game moves (a robot's links) push with
/// their own motion: each such contact's side becomes an extra immovable solver body at the
/// contact, moving with the root's velocity at that point plus the part's own velocity
/// ([`part_velocity`]). Appended after the entities' slots, so no entity's slot changes.
pub(super) fn add_part_motion(
    contacts: &Contacts,
    entities: &[Entity],
    poses: &Query<(&GlobalPose, Option<&StepStartPose>)>,
    dt: f32,
    sources: &[u32],
    inputs: &mut [ContactInput],
    bodies: &mut SolverBodies,
) {
    for (input, &source) in inputs.iter_mut().zip(sources) {
        let pair = &contacts.pairs[source as usize];
        let points = &input.points[..input.count as usize];
        let at = points.iter().map(|p| p.point).sum::<Vec3>() / points.len().max(1) as f32;
        for slot in [&mut input.a, &mut input.b] {
            let i = *slot as usize;
            let (Some(&body), false) = (entities.get(i), bodies.params[i].dynamic) else {
                continue;
            };
            let part = if body == pair.a {
                pair.collider_a
            } else {
                pair.collider_b
            };
            if part == body {
                continue;
            }
            let Some(v) = part_velocity(body, part, at, poses, dt).filter(|v| *v != Vec3::ZERO)
            else {
                continue;
            };
            let state = bodies.states[i];
            let root = state.linear_velocity + state.angular_velocity.cross(at - bodies.centers[i]);
            *slot = bodies.push(BodyInput {
                center: at,
                linear_velocity: root + v,
                ..Default::default()
            });
        }
    }
}

/// Each contact's largest normal impulse of the step and its impact speed, back to the pair it
/// came from (the collision messages count a speculative contact that pushed as touching, and
/// report both).
pub(super) fn report_impulses(solver: &Solver, sources: &[u32], contacts: &mut Contacts) {
    for (c, &source) in solver.constraints().iter().zip(sources) {
        let pushed = || {
            c.points[..c.count as usize]
                .iter()
                .filter(|p| p.max_normal_impulse > 0.0)
        };
        let impulse = pushed().fold(0.0f32, |m, p| m.max(p.max_normal_impulse));
        // `relative_velocity` is the normal speed at first push, negative when closing.
        let speed = pushed().fold(0.0f32, |m, p| m.max(-p.relative_velocity));
        if let Some(pair) = contacts.pairs.get_mut(source as usize) {
            pair.normal_impulse = impulse;
            pair.impact_speed = speed;
        }
    }
}

/// A key for a pair of colliders, stable from step to step.
fn pair_key(a: Entity, b: Entity) -> u128 {
    let (lo, hi) = if a.index_u32() <= b.index_u32() {
        (a, b)
    } else {
        (b, a)
    };
    ((lo.index_u32() as u128) << 32) | hi.index_u32() as u128
}
