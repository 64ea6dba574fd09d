//! Rotation in the ECS: inertia computed from colliders (and compound bodies over the scene
//! graph), and the angular half of the Integrate stage.
//!
//! Two thin adapters over the core:
//! - **Prepare**: a body whose [`Inertia`] is not custom gets the mass properties of its collider
//!   and of every [`ChildOf`] part below it ([`MassProperties::compound`], the parallel-axis
//!   theorem), at uniform density scaled to its [`Mass`]; only bodies whose collider, mass or
//!   parts changed are recomputed.
//! - **Integrate** (each substep, after the linear integration): turning bodies are gathered
//!   into [`AngularBody`] values, [`integrate_rotations`] advances them, and their
//!   [`Rotation`] and [`AngularVelocity`] are written back. A body turns about its centre of
//!   mass, so when that is off its origin the origin moves with the turn. Bodies that neither
//!   spin nor feel a torque are skipped after one look; when nothing turned in the last
//!   substep, no torque acts and no angular velocity changed, the stage returns after that
//!   check alone (a change-tick scan), so a scene in which nothing turns pays almost nothing.

use crate::components::*;
use crate::dynamics::{AngularBody, integrate_rotations};
use crate::geometry::{Isometry, MassProperties};
use crate::hierarchy::climb;
use crate::plugins::core::PrepareIndex;
use crate::plugins::forces::GatheredForces;
use crate::plugins::integration::IntegrateBodies;
use crate::plugins::required_resources::RequireResource;
use crate::plugins::soft_step::legacy_solver;
use crate::schedule::{PhysicsSchedule, SubstepSchedule, SubstepSet};
use crate::settings::{Integration, PhysicsTimestep, RotationSettings};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::entity::{EntityHashMap, EntityHashSet};
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use std::time::Instant;

/// Turns bodies that have an [`AngularVelocity`].
#[derive(Debug, Clone, Default)]
pub struct RotationPlugin;

impl Plugin for RotationPlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<RotationSettings>()
            .init_required::<RotationBuffers>()
            .add_systems(
                PhysicsSchedule,
                compute_inertia
                    .run_if(any_with_component::<Inertia>)
                    .in_set(PrepareIndex),
            )
            .add_systems(
                SubstepSchedule,
                integrate_turning_bodies
                    .run_if(any_with_component::<AngularVelocity>)
                    .run_if(legacy_solver)
                    .after(IntegrateBodies)
                    .in_set(SubstepSet::Integrate),
            );
    }
}

/// Buffers reused from substep to substep.
#[derive(Resource, Default)]
struct RotationBuffers {
    /// Each gathered body's place in the turning query's order.
    slots: Vec<u32>,
    bodies: Vec<AngularBody>,
    /// Each gathered body's centre of mass in its own frame.
    centers: Vec<Vec3>,
    torques: EntityHashMap<Vec3>,
    dirty: Vec<Entity>,
    /// The root of each part met this look (memo of [`root_of`]).
    roots: EntityHashMap<Entity>,
    path: Vec<Entity>,
    visited: EntityHashSet,
    stack: Vec<(Entity, Isometry)>,
    parts: Vec<(Isometry, MassProperties)>,
}

/// Sleeping roots are left out: a write to one wakes it first.
type ChangedRoot = (
    Without<ChildOf>,
    Without<Sleeping>,
    Or<(
        Changed<Collider>,
        Changed<Mass>,
        Changed<Density>,
        Added<Inertia>,
        Changed<Children>,
    )>,
);
type ChangedPart = (
    With<ChildOf>,
    Or<(
        Changed<Collider>,
        Changed<ChildOf>,
        Changed<Children>,
        Changed<Position>,
        Changed<Rotation>,
    )>,
);
type ChangedRoots<'w, 's> = Query<'w, 's, Entity, (ChangedRoot, With<Inertia>)>;
type Roots<'w, 's> = Query<
    'w,
    's,
    (
        &'static mut Inertia,
        &'static mut Mass,
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
);

/// Recomputes the computed inertia of bodies whose collider, mass or parts changed.
fn compute_inertia(
    mut root_queries: ParamSet<(ChangedRoots, Roots)>,
    changed_parts: Query<Entity, ChangedPart>,
    parents: Query<&ChildOf>,
    parts: Query<PartData>,
    mut buffers: ResMut<RotationBuffers>,
    mut stats: ResMut<PhysicsStats>,
) {
    let b = &mut *buffers;
    b.dirty.clear();
    b.dirty.extend(&root_queries.p0());
    if !changed_parts.is_empty() {
        b.roots.clear();
        for part in &changed_parts {
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
            let Ok((mut inertia, mut mass, density)) = roots.get_mut(root) else {
                continue;
            };
            gather_compound(root, &parts, &mut b.stack, &mut b.visited, &mut b.parts);
            let unit = MassProperties::compound(b.parts.drain(..));
            // A kinematic body (infinite mass) stays kinematic whatever its density.
            if let Some(&Density(rho)) = density.filter(|_| mass.0.is_finite()) {
                let from_density = rho * unit.mass;
                if from_density.is_normal() && from_density > 0.0 {
                    mass.set_if_neq(Mass(from_density));
                } else {
                    log::warn!(
                        "urto: {root}: density {rho} over a volume of {} m³ gives no usable \
                         mass; keeping {} kg",
                        unit.mass,
                        mass.0
                    );
                }
            }
            if inertia.custom {
                continue;
            }
            inertia.set_if_neq(inertia_of(unit, *mass));
        }
    });
}

/// The topmost ancestor of `e`, at most `longest_chain` steps up.
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

/// Every collider at or below `root`, placed in `root`'s frame, at unit density.
fn gather_compound(
    root: Entity,
    parts: &Query<PartData>,
    stack: &mut Vec<(Entity, Isometry)>,
    visited: &mut EntityHashSet,
    out: &mut Vec<(Isometry, MassProperties)>,
) {
    stack.clear();
    visited.clear();
    out.clear();
    stack.push((root, Isometry::default()));
    while let Some((e, pose)) = stack.pop() {
        if !visited.insert(e) {
            continue;
        }
        let Ok((collider, children, ..)) = parts.get(e) else {
            continue;
        };
        // A part with an impossible shape is quarantined; its numbers reach no inertia.
        if let Some(c) = collider.filter(|c| c.shape.validate().is_ok()) {
            out.push((pose, c.shape.mass_properties(1.0)));
        }
        for &child in children.into_iter().flatten() {
            if let Ok((_, _, p, r)) = parts.get(child) {
                stack.push((child, pose * pose_of(p, r)));
            }
        }
    }
}

/// The local pose of a part.
fn pose_of(p: &Position, r: Option<&Rotation>) -> Isometry {
    Isometry::new(p.0, r.map_or(Quat::IDENTITY, |r| r.0))
}

/// Unit-density mass properties scaled to the body's mass, as a computed [`Inertia`]. Without
/// volume (no collider, zero-size shapes), with infinite mass or an unbounded shape the inertia
/// is infinite: torques and contacts cannot turn the body.
fn inertia_of(unit: MassProperties, mass: Mass) -> Inertia {
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

type Turning<'a> = (
    Entity,
    &'a mut Position,
    &'a mut Rotation,
    &'a mut AngularVelocity,
    &'a Inertia,
    Option<&'a AngularDrag>,
    Option<&'a LockedAxes>,
);
/// Sleeping bodies do not turn: their archetypes are left out.
type TurningFilter = (
    Without<Static>,
    Without<Quarantined>,
    Without<ChildOf>,
    Without<Sleeping>,
);
/// Bodies whose angular velocity was written since the stage last ran.
type Spun<'w, 's> = Query<'w, 's, (), (Changed<AngularVelocity>, TurningFilter)>;

#[allow(clippy::too_many_arguments)]
fn integrate_turning_bodies(
    mut queries: ParamSet<(Query<Turning, TurningFilter>, Spun)>,
    gathered: Res<GatheredForces>,
    timestep: Res<PhysicsTimestep>,
    integration: Res<Integration>,
    settings: Res<RotationSettings>,
    mut buffers: ResMut<RotationBuffers>,
    mut stats: ResMut<PhysicsStats>,
) {
    let start = Instant::now();
    let b = &mut *buffers;
    // Nothing turned last substep, no torque acts and no angular velocity was written since:
    // nothing can turn now either, and a scene that never spins pays this check alone.
    if b.bodies.is_empty() && gathered.torques.is_empty() && queries.p1().is_empty() {
        stats.set_counter("integrate/turning", 0.0);
        return;
    }
    b.torques.clear();
    for (e, t) in &gathered.torques {
        *b.torques.entry(*e).or_default() += *t;
    }
    let mut bodies = queries.p0();
    gather_turning(&bodies, b);
    let options = crate::dynamics::RotationOptions {
        gyroscopic: settings.gyroscopic,
    };
    integrate_rotations(integration.0, timestep.substep_dt(), options, &mut b.bodies);
    scatter_turning(&mut bodies, b);
    stats.set_counter("integrate/turning", b.bodies.len() as f64);
    stats.add_time(Stage::Integrate, start.elapsed());
}

/// The awake bodies that spin or feel a torque, each with its place in the query's order
/// (the scatter walks the same query in the same order).
fn gather_turning(bodies: &Query<Turning, TurningFilter>, b: &mut RotationBuffers) {
    b.slots.clear();
    b.bodies.clear();
    b.centers.clear();
    for (slot, (e, _, r, w, inertia, drag, locked)) in bodies.iter().enumerate() {
        let torque = if b.torques.is_empty() {
            Vec3::ZERO
        } else {
            b.torques.get(&e).copied().unwrap_or(Vec3::ZERO)
        };
        let body = AngularBody {
            orientation: r.0,
            angular_velocity: w.0,
            inverse_principal_inertia: inertia.inverse_principal(),
            inertia_frame: inertia.frame,
            torque,
            drag: drag.map_or(0.0, |d| d.0),
            free_axes: locked.map_or(Vec3::ONE, |l| l.free_rotation_axes()),
        };
        if !body.is_still() {
            b.slots.push(slot as u32);
            b.bodies.push(body);
            b.centers.push(inertia.local_center_of_mass);
        }
    }
}

/// Writes the turned state back; the origin follows a turn about an off-origin centre of mass.
fn scatter_turning(bodies: &mut Query<Turning, TurningFilter>, b: &RotationBuffers) {
    let mut next = 0;
    for (slot, (_, mut p, mut r, mut w, ..)) in bodies.iter_mut().enumerate() {
        if next == b.slots.len() {
            break;
        }
        if b.slots[next] as usize != slot {
            continue;
        }
        let (body, com) = (&b.bodies[next], b.centers[next]);
        next += 1;
        if com != Vec3::ZERO {
            p.0 += r.0 * com - body.orientation * com;
        }
        r.set_if_neq(Rotation(body.orientation));
        w.set_if_neq(AngularVelocity(body.angular_velocity));
    }
}
