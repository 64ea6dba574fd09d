//! The Prepare stage: bad input is set aside before it can spread.
//!
//! A body whose state is unusable — a NaN or infinite position, velocity, force, rotation,
//! angular velocity or torque, a negative angular drag, an inertia that is not positive, a
//! zero, negative, subnormal or NaN mass, a non-finite impulse or gravity scale, a shape with
//! impossible numbers, a part of a compound body with a velocity of its own — gets a
//! [`Quarantined`] marker and a logged warning. Every other stage filters quarantined
//! entities out, so their NaN never reaches a neighbour through a contact or a spring. Only
//! added or changed components are checked, so a scene at rest costs nothing here.

use crate::components::*;
use crate::geometry::is_unit_rotation;
use crate::plugins::core::PrepareStart;
use crate::plugins::settle::Unsettled;
use crate::schedule::PhysicsSchedule;
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::entity::EntityHashSet;
use bevy_ecs::prelude::*;
use glam::Vec3;

/// Quarantines bodies with unusable state.
#[derive(Debug, Clone, Default)]
pub struct ValidationPlugin;

impl Plugin for ValidationPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PhysicsSchedule,
            (
                quarantine_invalid_bodies,
                quarantine_invalid_rotation,
                quarantine_invalid_pushes,
                quarantine_parent_cycles,
                quarantine_unplaced_bodies,
            )
                .in_set(PrepareStart),
        );
    }
}

type BodyData<'a> = (
    Entity,
    &'a Position,
    Option<&'a Velocity>,
    Option<&'a Mass>,
    Option<&'a Rotation>,
    Option<&'a Collider>,
    Option<&'a Force>,
    Has<ChildOf>,
);

/// Sleeping bodies are left out: a write to one wakes it first (`plugins/sleep.rs`).
type ChangedBody = (
    Without<Quarantined>,
    Without<Sleeping>,
    Unsettled,
    Or<(
        Changed<Position>,
        Changed<Velocity>,
        Changed<Mass>,
        Changed<Rotation>,
        Changed<Collider>,
        Changed<Force>,
        Changed<ChildOf>,
    )>,
);

fn quarantine_invalid_bodies(
    bodies: Query<BodyData, ChangedBody>,
    mut stats: ResMut<PhysicsStats>,
    mut commands: Commands,
) {
    stats.time(Stage::Prepare, "prepare/validate", || {
        for (entity, p, v, m, r, c, f, is_child) in &bodies {
            let reason = why_invalid(p, v, m, r, c, f).or_else(|| {
                (is_child && v.is_some()).then(|| {
                    "a part of a compound body cannot have its own Velocity: it moves with its \
                     root (remove the Velocity, or the ChildOf)"
                        .to_string()
                })
            });
            if let Some(reason) = reason {
                quarantine(&mut commands, entity, reason);
            }
        }
    });
}

type AngularData<'a> = (
    Entity,
    Option<&'a AngularVelocity>,
    Option<&'a Torque>,
    Option<&'a ForceAtPoint>,
    Option<&'a AngularDrag>,
    Option<&'a Inertia>,
);

type ChangedAngular = (
    Without<Quarantined>,
    Without<Sleeping>,
    Unsettled,
    Or<(
        Changed<AngularVelocity>,
        Changed<Torque>,
        Changed<ForceAtPoint>,
        Changed<AngularDrag>,
        Changed<Inertia>,
    )>,
);

/// The rotational state's share of the checks: finite spin and torques, a drag rate `>= 0`, a
/// real inertia.
fn quarantine_invalid_rotation(
    bodies: Query<AngularData, ChangedAngular>,
    mut stats: ResMut<PhysicsStats>,
    mut commands: Commands,
) {
    stats.time(Stage::Prepare, "prepare/validate_rotation", || {
        for (entity, w, t, at_point, drag, inertia) in &bodies {
            if let Some(reason) = why_invalid_rotation(w, t, at_point, drag, inertia) {
                quarantine(&mut commands, entity, reason);
            }
        }
    });
}

fn why_invalid_rotation(
    w: Option<&AngularVelocity>,
    t: Option<&Torque>,
    at_point: Option<&ForceAtPoint>,
    drag: Option<&AngularDrag>,
    inertia: Option<&Inertia>,
) -> Option<String> {
    let finite = |name: &str, x: Vec3| (!x.is_finite()).then(|| format!("{name} is {x}"));
    w.and_then(|w| finite("angular velocity", w.0))
        .or_else(|| t.and_then(|t| finite("torque", t.0)))
        .or_else(|| {
            at_point.and_then(|f| {
                finite("force at a point", f.force())
                    .or_else(|| finite("moment of a force at a point", f.torque_about(Vec3::ZERO)))
            })
        })
        .or_else(|| {
            drag.filter(|d| !(d.0.is_finite() && d.0 >= 0.0))
                .map(|d| format!("angular drag must be finite and >= 0, got {}", d.0))
        })
        .or_else(|| {
            inertia.filter(|i| !i.is_valid()).map(|i| {
                format!(
                    "inertia must have moments > 0 (or infinite) and a finite frame and \
                     centre, got {i:?}"
                )
            })
        })
}

type Pushes<'a> = (Entity, Option<&'a Impulse>, Option<&'a GravityScale>);
type ChangedPushes = (
    Without<Quarantined>,
    Without<Sleeping>,
    Or<(Changed<Impulse>, Changed<GravityScale>)>,
);

/// Impulses and gravity scales must be finite.
fn quarantine_invalid_pushes(
    bodies: Query<Pushes, ChangedPushes>,
    mut stats: ResMut<PhysicsStats>,
    mut commands: Commands,
) {
    stats.time(Stage::Prepare, "prepare/validate_pushes", || {
        for (entity, impulse, scale) in &bodies {
            let reason = if impulse.is_some_and(|i| !i.is_finite()) {
                Some(format!("impulse is not finite: {impulse:?}"))
            } else {
                scale
                    .filter(|s| !s.0.is_finite())
                    .map(|s| format!("gravity scale must be finite, got {}", s.0))
            };
            if let Some(reason) = reason {
                quarantine(&mut commands, entity, reason);
            }
        }
    });
}

/// Deepest `ChildOf` chain walked: the hierarchy's walks up a chain stop here, so a loop of
/// parents (two entities each other's `ChildOf`) cannot hang a step before it is quarantined.
pub(crate) const MAX_HIERARCHY_DEPTH: u32 = 1 << 16;

/// Quarantines every entity of a `ChildOf` loop (each is its own ancestor), checked for the
/// entities whose parent changed: a loop has no root, so no pose or volume reaches it, and the
/// walks up its chain would never end.
///
/// Every node met is settled once (it reaches a root, or a loop was found above it), and the
/// climbs stop at settled nodes, so a step costs time linear in the nodes met however deep the
/// chains (a 10,000-deep chain took seconds when each node climbed to its root).
fn quarantine_parent_cycles(
    changed: Query<Entity, (Changed<ChildOf>, Without<Quarantined>, Unsettled)>,
    parents: Query<&ChildOf>,
    mut settled: Local<EntityHashSet>,
    mut path: Local<EntityHashSet>,
    mut commands: Commands,
) {
    settled.clear();
    for e in &changed {
        path.clear();
        let mut up = e;
        loop {
            if settled.contains(&up) || path.len() as u32 >= MAX_HIERARCHY_DEPTH {
                break;
            }
            if path.contains(&up) {
                // Quarantine the whole loop, not only the link that closed it.
                let mut member = up;
                loop {
                    quarantine(
                        &mut commands,
                        member,
                        "its ChildOf chain loops back to it".into(),
                    );
                    member = parents.get(member).map_or(up, |p| p.parent());
                    if member == up {
                        break;
                    }
                }
                break;
            }
            path.insert(up);
            match parents.get(up) {
                Ok(p) => up = p.parent(),
                Err(_) => break,
            }
        }
        settled.extend(path.iter().copied());
    }
}

/// Bodies nothing can place: a moving body or a compound's root without a [`Position`] (game
/// code removed it; `Velocity` and `Static` bring one) is skipped by every stage, so it is
/// quarantined and the log says why, instead of silently never colliding. The filters are
/// archetype-level: a world without such bodies pays nothing per body.
#[allow(clippy::type_complexity)]
pub(crate) fn quarantine_unplaced_bodies(
    unplaced: Query<
        Entity,
        (
            Or<(With<Velocity>, With<Children>, With<Collider>)>,
            Without<Position>,
            Without<Quarantined>,
        ),
    >,
    mut commands: Commands,
) {
    for e in &unplaced {
        quarantine(
            &mut commands,
            e,
            "it has no Position (a body, a collider or a compound's root needs one)".into(),
        );
    }
}

/// Marks `entity` as quarantined and says why in the log.
pub(crate) fn quarantine(commands: &mut Commands, entity: Entity, reason: String) {
    log::warn!("urto: quarantined {entity}: {reason}");
    commands.entity(entity).insert(Quarantined { reason });
}

fn why_invalid(
    p: &Position,
    v: Option<&Velocity>,
    m: Option<&Mass>,
    r: Option<&Rotation>,
    c: Option<&Collider>,
    f: Option<&Force>,
) -> Option<String> {
    let finite = |name: &str, x: Vec3| (!x.is_finite()).then(|| format!("{name} is {x}"));
    finite("position", p.0)
        .or_else(|| v.and_then(|v| finite("velocity", v.0)))
        .or_else(|| f.and_then(|f| finite("force", f.0)))
        .or_else(|| {
            m.filter(|m| !m.is_valid())
                .map(|m| format!("mass must be > 0 (or Mass::INFINITE), got {}", m.0))
        })
        .or_else(|| {
            r.filter(|r| !is_unit_rotation(r.0))
                .map(|r| format!("rotation must be a unit quaternion, got {}", r.0))
        })
        .or_else(|| {
            c.and_then(|c| c.shape.validate().err())
                .map(|e| e.to_string())
        })
}
