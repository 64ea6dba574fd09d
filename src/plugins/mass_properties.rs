//! Mass properties in the ECS: each body's [`ComputedMass`] and computed [`Inertia`] from its
//! colliders and every [`ChildOf`] part below it ([`MassProperties::compound`], the
//! parallel-axis theorem, Mirtich 1996 for meshes), at its [`Density`] (or
//! [`DEFAULT_DENSITY`]) unless a [`Mass`] is given, as Avian's mass-property plugin does. Only
//! bodies whose collider, mass, density or parts changed are recomputed, in the step's Prepare
//! stage: a scene that does not change its bodies pays a change-tick scan.
//!
//! Its own plugin, apart from rotation, so that a scene without turning still gets the masses
//! its game set. Without it a body weighs the [`Mass`] it was given (the insert hook writes it)
//! or the default 1 kg, and its inertia stays the default.

use crate::components::*;
use crate::geometry::{Isometry, MassProperties};
use crate::hierarchy::climb;
use crate::plugins::core::PrepareIndex;
use crate::plugins::required_resources::RequireResource;
use crate::plugins::settle::Unsettled;
use crate::schedule::PhysicsSchedule;
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::entity::{EntityHashMap, EntityHashSet};
use bevy_ecs::prelude::*;
use glam::Vec3;

/// Computes bodies' mass and inertia from their colliders.
#[derive(Debug, Clone, Default)]
pub struct MassPropertiesPlugin;

impl Plugin for MassPropertiesPlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<MassBuffers>().add_systems(
            PhysicsSchedule,
            compute_mass_properties
                .run_if(any_with_component::<Inertia>)
                .in_set(PrepareIndex),
        );
    }
}

/// Buffers reused from step to step.
#[derive(Resource, Default)]
struct MassBuffers {
    dirty: Vec<Entity>,
    /// The root of each part met this look (memo of [`root_of`]).
    roots: EntityHashMap<Entity>,
    path: Vec<Entity>,
    visited: EntityHashSet,
    stack: Vec<(Entity, Isometry)>,
    parts: PlacedParts,
    /// The [`Sensor`] parts met, which weigh only when the body has no other collider.
    sensor_parts: PlacedParts,
}

/// Colliders' unit-density mass properties, each placed in its body's frame.
type PlacedParts = Vec<(Isometry, MassProperties)>;

/// Sleeping roots are left out: a write to one wakes it first.
type ChangedRoot = (
    Without<ChildOf>,
    Without<Sleeping>,
    Unsettled,
    Or<(
        Changed<Collider>,
        Changed<Mass>,
        Changed<Density>,
        Added<Inertia>,
        Changed<Children>,
        Added<Sensor>,
    )>,
);
type ChangedPart = (
    With<ChildOf>,
    Unsettled,
    Or<(
        Changed<Collider>,
        Changed<ChildOf>,
        Changed<Children>,
        Changed<Position>,
        Changed<Rotation>,
        Added<Sensor>,
    )>,
);
type ChangedRoots<'w, 's> = Query<'w, 's, Entity, (ChangedRoot, With<Inertia>)>;
type Roots<'w, 's> = Query<
    'w,
    's,
    (
        &'static mut Inertia,
        &'static mut ComputedMass,
        Option<&'static Mass>,
        Option<&'static Density>,
    ),
    RootFilter,
>;
type RootFilter = (Without<ChildOf>, Without<Quarantined>);
type PartData<'a> = (
    Option<&'a Collider>,
    Option<&'a Children>,
    &'a Position,
    Option<&'a Rotation>,
    Has<Sensor>,
);

/// Recomputes the computed mass and inertia of bodies whose collider, mass, density or parts
/// changed (or whose [`Collider`], [`Mass`], [`Density`] or [`Quarantined`] marker was removed,
/// from the body or from a part).
#[allow(clippy::too_many_arguments)]
fn compute_mass_properties(
    mut root_queries: ParamSet<(ChangedRoots, Roots)>,
    changed_parts: Query<Entity, ChangedPart>,
    mut unset_mass: RemovedComponents<Mass>,
    mut unset_density: RemovedComponents<Density>,
    mut released: RemovedComponents<Quarantined>,
    (mut stripped, mut unsensed): (RemovedComponents<Collider>, RemovedComponents<Sensor>),
    parents: Query<&ChildOf>,
    parts: Query<PartData>,
    mut buffers: ResMut<MassBuffers>,
    mut stats: ResMut<PhysicsStats>,
) {
    let b = &mut *buffers;
    b.dirty.clear();
    b.dirty.extend(&root_queries.p0());
    // A body let out of quarantine may have been fixed while it was left out.
    let unset = unset_mass.read().chain(unset_density.read());
    b.dirty.extend(unset.chain(released.read()));
    // A collider removed from a body or a part changes its root's mass (a despawned part's
    // parent sees its `Children` change; a despawned body needs nothing).
    if !changed_parts.is_empty() || !stripped.is_empty() || !unsensed.is_empty() {
        b.roots.clear();
        let removed = stripped.read().chain(unsensed.read());
        for part in changed_parts.iter().chain(removed) {
            let root = root_of(part, &parents, &mut b.roots, &mut b.path);
            b.dirty.push(root);
        }
    }
    if b.dirty.is_empty() {
        return;
    }
    b.dirty.sort_unstable();
    b.dirty.dedup();
    let mut roots = root_queries.p1();
    stats.time(Stage::Prepare, "prepare/inertia", || {
        for &root in &b.dirty {
            let Ok((mut inertia, mut computed, mass, density)) = roots.get_mut(root) else {
                continue;
            };
            // A bad explicit mass quarantines the body (validation): nothing to derive.
            if mass.is_some_and(|m| !m.is_valid()) {
                continue;
            }
            let out = (&mut b.parts, &mut b.sensor_parts);
            gather_compound(root, &parts, &mut b.stack, &mut b.visited, out);
            let unit = MassProperties::compound(b.parts.drain(..));
            let (derived, density_report) =
                ComputedMass::derive(mass.copied(), density.copied(), unit.mass);
            if let Err(rho) = density_report {
                log::warn!(
                    "urto: {root}: density {rho} over a volume of {} m³ gives no usable mass; \
                     using the default density ({} kg)",
                    unit.mass,
                    derived.value()
                );
            }
            computed.set_if_neq(derived);
            if inertia.custom {
                continue;
            }
            inertia.set_if_neq(inertia_of(unit, derived));
        }
    });
}

/// The topmost ancestor of `e`. `roots` remembers the root of every node climbed through, and
/// a climb stops at the first remembered node ([`climb`]), so the parts of one deep chain cost
/// linear time together, not quadratic.
fn root_of(
    e: Entity,
    parents: &Query<&ChildOf>,
    roots: &mut EntityHashMap<Entity>,
    path: &mut Vec<Entity>,
) -> Entity {
    let parent = |x: Entity| parents.get(x).ok().map(|p| p.parent());
    let found = climb(Some(e), parent, |x| roots.get(&x).copied(), path);
    let root = found.or(path.last().copied()).unwrap_or(e);
    for &node in path.iter() {
        roots.insert(node, root);
    }
    root
}

/// Every collider at or below `root`, placed in `root`'s frame, at unit density, into `out`.
/// [`Sensor`]s weigh nothing, as in Avian, Godot and Unity (rapier weighs them): a pickup
/// radius or a detection zone attached to a character would otherwise outweigh it and move its
/// centre of mass. A body made of sensors alone weighs them, so that it still has a mass.
fn gather_compound(
    root: Entity,
    parts: &Query<PartData>,
    stack: &mut Vec<(Entity, Isometry)>,
    visited: &mut EntityHashSet,
    (out, sensors): (&mut PlacedParts, &mut PlacedParts),
) {
    stack.clear();
    visited.clear();
    out.clear();
    sensors.clear();
    stack.push((root, Isometry::default()));
    while let Some((e, pose)) = stack.pop() {
        if !visited.insert(e) {
            continue;
        }
        let Ok((collider, children, _, _, sensor)) = parts.get(e) else {
            continue;
        };
        // A part with an impossible shape is quarantined; its numbers reach no inertia.
        if let Some(c) = collider.filter(|c| c.shape.validate().is_ok()) {
            let to = if sensor { &mut *sensors } else { &mut *out };
            to.push((pose, c.shape.mass_properties(1.0)));
        }
        for &child in children.into_iter().flatten() {
            if let Ok((_, _, p, r, _)) = parts.get(child) {
                stack.push((child, pose * crate::components::pose(p, r)));
            }
        }
    }
    if out.is_empty() {
        out.append(sensors);
    }
}

/// Unit-density mass properties scaled to the body's mass, as a computed [`Inertia`]. Without
/// volume (no collider, zero-size shapes), with infinite mass or an unbounded shape the inertia
/// is infinite: torques and contacts cannot turn the body.
fn inertia_of(unit: MassProperties, mass: ComputedMass) -> Inertia {
    let turnable = unit.mass.is_finite() && unit.mass > 0.0 && mass.0.is_finite();
    if !turnable {
        return Inertia {
            local_center_of_mass: if unit.mass.is_finite() && unit.mass > 0.0 {
                unit.local_center_of_mass
            } else {
                Vec3::ZERO
            },
            ..Inertia::default()
        };
    }
    let scaled = unit.with_mass(mass.0);
    let (principal, frame) = scaled.principal();
    let positive = |i: f32| if i > 0.0 { i } else { f32::INFINITY };
    Inertia {
        principal: Vec3::new(
            positive(principal.x),
            positive(principal.y),
            positive(principal.z),
        ),
        // Rotating by a quaternion assumes unit length; an eigen-solver's frame is off by ulps,
        // and `I_w` then scales by `|q|⁴`, which the momentum path compounds every step.
        frame: frame.normalize(),
        local_center_of_mass: scaled.local_center_of_mass,
        custom: false,
    }
}
