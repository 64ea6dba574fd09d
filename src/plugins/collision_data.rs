//! What a collision looked like when it started, carried by [`CollisionStarted`] messages and
//! [`CollisionStart`] events: which parts met, the normal and points where they touch, how fast
//! they met and how hard the solver pushed (what a game scales a hit sound, a spark or damage by).
//!
//! The peers hand this out differently: Avian keeps it in its `Collisions` parameter (a game looks
//! the pair up after the event), rapier sends a separate `ContactForceEvent` above a force
//! threshold. Here the message of the start carries it, so a game reacting to a hit needs no
//! second lookup; the full per-step contacts stay in [`Contacts`](super::Contacts).
//!
//! [`CollisionStarted`]: super::CollisionStarted
//! [`CollisionStart`]: super::CollisionStart

use crate::geometry::ContactManifold;
use crate::plugins::narrow_phase::ContactPair;
use bevy_ecs::entity::Entity;

/// The contact of a collision that started, oriented from the first body to the second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactData {
    /// The first body's collider that touched (the body itself, or a part of its hierarchy).
    pub collider: Entity,
    /// The second body's collider that touched.
    pub other_collider: Entity,
    /// Unit normal from the first body to the second, and the points (world space, midway
    /// between the surfaces) where they touch, as detected at the start of the step. A fast
    /// body the solver stopped at the surface keeps its speculative points (still apart by up
    /// to the step's motion at detection, negative depth): they are where it met the surface.
    pub manifold: ContactManifold,
    /// The largest normal impulse (N·s) the rigid-body solver applied at one point in one
    /// substep of the step: 0 for a contact that only touched (a graze, or continuous
    /// collision's impacts). On the lecture's pipeline (`SoftStepPlugin` disabled), its
    /// response's total normal impulse in the substep.
    pub normal_impulse: f32,
    /// The speed (m/s) at which the bodies met along the normal (≥ 0), from the rigid-body
    /// solver or a continuous-collision impact; on the lecture's pipeline, the approach speed
    /// before its response.
    pub impact_speed: f32,
}

impl ContactData {
    /// The contact of `pair` seen from body `first` (one of the pair's bodies): points that
    /// touch only, unless none does.
    pub(crate) fn of_pair(pair: &ContactPair, first: Entity, tolerance: f32) -> Self {
        let data = Self {
            collider: pair.collider_a,
            other_collider: pair.collider_b,
            manifold: pair.manifold.touching_points(tolerance),
            normal_impulse: pair.normal_impulse,
            impact_speed: pair.impact_speed,
        };
        if pair.a == first {
            data
        } else {
            data.flipped()
        }
    }

    /// The same contact seen from the second body: colliders swapped, normal reversed.
    #[must_use]
    pub fn flipped(self) -> Self {
        Self {
            collider: self.other_collider,
            other_collider: self.collider,
            manifold: self.manifold.flipped(),
            ..self
        }
    }
}
