//! What the narrow phase hands on: the substep's [`Contacts`] (for the solver, the messages and
//! the game), the [`SensorOverlaps`] kept apart from them, and, while enabled, the debug list of
//! [`OverlappingLeaves`] of each mesh contact.

use crate::geometry::ContactManifold;
use bevy_ecs::prelude::*;

/// A contact between two bodies; the manifold's normal points from `a` to `b`.
///
/// `a` and `b` are the root bodies that respond (a compound body moves as a whole);
/// `collider_a` and `collider_b` are the parts that touched (the wheel, the house) — the roots
/// themselves for bodies without parts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPair {
    /// First body (a moving one).
    pub a: Entity,
    /// Second body.
    pub b: Entity,
    /// The collider of `a`'s hierarchy that touched.
    pub collider_a: Entity,
    /// The collider of `b`'s hierarchy that touched.
    pub collider_b: Entity,
    /// Where and how deep they touch (with the rigid-body solver, also points still up to the
    /// speculative margin apart, with negative depths).
    pub manifold: ContactManifold,
    /// The largest normal impulse the rigid-body solver applied to this contact in one substep
    /// of the step (N·s), or the lecture's response's in its substep; 0 until it has solved.
    pub normal_impulse: f32,
    /// The speed (m/s) at which the two bodies met along the normal: the fastest approach of
    /// the points the rigid-body solver pushed this step, taken when each first pushed (a
    /// speculative point's speed carried on to the surface). What a game scales a hit sound or
    /// damage by; about 0 for a resting contact, 0 until it has solved. The lecture's response
    /// gives the approach speed before it solved.
    pub impact_speed: f32,
    /// The rounding of `collider_a`'s and `collider_b`'s shapes ([`Shape::rounding`]: a
    /// ball's or capsule's radius, else 0): the solver follows a rounded body's contact as it
    /// rolls.
    ///
    /// [`Shape::rounding`]: crate::geometry::Shape::rounding
    pub rounding: [f32; 2],
}

/// A sensor's overlap: `a` and `b` are the root bodies, `collider_a` and `collider_b` the parts
/// that overlap (at least one of them a [`Sensor`](crate::components::Sensor)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SensorPair {
    /// First body (a moving one).
    pub a: Entity,
    /// Second body.
    pub b: Entity,
    /// The collider of `a`'s hierarchy that overlaps.
    pub collider_a: Entity,
    /// The collider of `b`'s hierarchy that overlaps.
    pub collider_b: Entity,
}

/// The overlaps involving a [`Sensor`](crate::components::Sensor) in this substep, in the
/// broad phase's pair order: kept out of [`Contacts`], so nothing responds to them.
#[derive(Resource, Debug, Default, Clone)]
pub struct SensorOverlaps {
    /// The overlapping pairs.
    pub pairs: Vec<SensorPair>,
}

/// The contacts of this substep, in the broad phase's pair order.
#[derive(Resource, Debug, Default, Clone)]
pub struct Contacts {
    /// The touching pairs.
    pub pairs: Vec<ContactPair>,
}

/// Stands for "no leaf" in [`LeafOverlap::leaves`], on the side of a primitive shape.
pub const NO_LEAF: u32 = u32::MAX;

/// The hierarchy leaves through which two bodies touched in the last substep.
#[derive(Debug, Clone, PartialEq)]
pub struct LeafOverlap {
    /// First body.
    pub a: Entity,
    /// Second body.
    pub b: Entity,
    /// Pairs `[leaf of a, leaf of b]` (node indices in each body's
    /// [`MeshCollider::bvh`](crate::geometry::MeshCollider::bvh), [`NO_LEAF`] for a primitive),
    /// sorted, each once: the leaf pairs holding at least one pair of touching triangles.
    pub leaves: Vec<[u32; 2]>,
}

/// Debug output of the narrow phase: the leaves of each mesh contact. Empty unless `enabled`.
#[derive(Resource, Debug, Default, Clone)]
pub struct OverlappingLeaves {
    /// Fill [`pairs`](Self::pairs) (costs a little per mesh contact).
    pub enabled: bool,
    /// One entry per mesh pair in contact in the last substep, in the contacts' order.
    pub pairs: Vec<LeafOverlap>,
}
