//! The Forces stage: gathers the step's forces and torques, one system per kind of force, each running only
//! when the world has that kind (no `Gravity` resource: no gravity system; no `Force`
//! component anywhere: no force system). What they gather is evaluated by the integrator at every
//! intermediate state it needs. [`Impulse`]s change velocities here at once, before anything
//! integrates; a [`GravityScale`] adds the force `(s − 1) m g`.

use crate::components::*;
use crate::plugins::validation::quarantine;
use crate::schedule::{PhysicsSchedule, PhysicsSet};
use crate::settings::{Gravity, PhysicsTimestep};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use glam::Vec3;

/// Gathers gravity, user forces, drag and springs.
#[derive(Debug, Clone, Default)]
pub struct ForcesPlugin;

/// The forces gathered for the current step, keyed by entity (the integrator maps them to its
/// body arrays).
#[derive(Resource, Debug, Default, Clone)]
pub struct GatheredForces {
    /// Gravity, when the world has it.
    pub gravity: Option<Vec3>,
    /// User forces consumed from [`Force`] components this step.
    pub forces: Vec<(Entity, Vec3)>,
    /// Drag coefficients.
    pub drag: Vec<(Entity, f32)>,
    /// Springs, by the entity that carries them.
    pub springs: Vec<(Entity, Spring)>,
    /// Torques (N·m, world axes) consumed from [`Torque`] and [`ForceAtPoint`] this step.
    pub torques: Vec<(Entity, Vec3)>,
}

impl GatheredForces {
    /// True when nothing but (possibly) gravity acts.
    pub fn only_gravity(&self) -> bool {
        self.forces.is_empty() && self.drag.is_empty() && self.springs.is_empty()
    }
}

impl Plugin for ForcesPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PhysicsSchedule,
            (
                clear_gathered_forces,
                gather_gravity.run_if(resource_exists::<Gravity>),
                gather_user_forces.run_if(any_with_component::<Force>),
                gather_drag.run_if(any_with_component::<LinearDrag>),
                gather_springs.run_if(any_with_component::<Spring>),
                gather_torques.run_if(any_with_component::<Torque>),
                gather_point_forces.run_if(any_with_component::<ForceAtPoint>),
                scale_gravity
                    .run_if(resource_exists::<Gravity>)
                    .run_if(any_with_component::<GravityScale>),
                apply_impulses.run_if(any_with_component::<Impulse>),
                follow_kinematic_targets.run_if(any_with_component::<KinematicTarget>),
            )
                .chain()
                .in_set(PhysicsSet::Forces),
        );
    }
}

fn clear_gathered_forces(mut gathered: ResMut<GatheredForces>) {
    let g = &mut *gathered;
    g.gravity = None;
    g.forces.clear();
    g.drag.clear();
    g.springs.clear();
    g.torques.clear();
}

fn gather_gravity(
    gravity: Res<Gravity>,
    mut gathered: ResMut<GatheredForces>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::Forces, "forces/gravity", || {
        gathered.gravity = Some(gravity.acceleration());
    });
}

/// Bodies whose forces count: not quarantined, not asleep (a force on a sleeper wakes it
/// first, `plugins/sleep.rs`).
type Active = (Without<Quarantined>, Without<Sleeping>);

/// Consumes every [`Force`]: it acts for this step, then reads zero until game code adds more.
fn gather_user_forces(
    mut bodies: Query<(Entity, &mut Force), Active>,
    mut gathered: ResMut<GatheredForces>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::Forces, "forces/user", || {
        for (entity, mut force) in &mut bodies {
            if force.0 != Vec3::ZERO {
                gathered.forces.push((entity, force.0));
                force.0 = Vec3::ZERO;
            }
        }
    });
}

fn gather_drag(
    bodies: Query<(Entity, &LinearDrag), Active>,
    mut gathered: ResMut<GatheredForces>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::Forces, "forces/drag", || {
        gathered.drag.extend(
            bodies
                .iter()
                .filter(|(_, d)| d.0 != 0.0)
                .map(|(e, d)| (e, d.0)),
        );
    });
}

fn gather_springs(
    bodies: Query<(Entity, &Spring), Active>,
    mut gathered: ResMut<GatheredForces>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::Forces, "forces/springs", || {
        gathered.springs.extend(bodies.iter().map(|(e, s)| (e, *s)));
    });
}

/// Consumes every [`Torque`], as [`gather_user_forces`] does forces.
fn gather_torques(
    mut bodies: Query<(Entity, &mut Torque), Active>,
    mut gathered: ResMut<GatheredForces>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::Forces, "forces/torques", || {
        for (entity, mut torque) in &mut bodies {
            if torque.0 != Vec3::ZERO {
                gathered.torques.push((entity, torque.0));
                torque.0 = Vec3::ZERO;
            }
        }
    });
}

type PointForced<'a> = (
    Entity,
    &'a mut ForceAtPoint,
    &'a Position,
    Option<&'a Rotation>,
    Option<&'a Inertia>,
);

/// Consumes every [`ForceAtPoint`]: its sum pushes the body, its moment about the body's centre
/// of mass (where it is at the step's start) turns it.
fn gather_point_forces(
    mut bodies: Query<PointForced, Active>,
    mut gathered: ResMut<GatheredForces>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::Forces, "forces/at_point", || {
        for (entity, mut at_point, p, r, inertia) in &mut bodies {
            if at_point.is_empty() {
                continue;
            }
            let center = center_of_mass(p, r, inertia);
            gathered.forces.push((entity, at_point.force()));
            gathered
                .torques
                .push((entity, at_point.torque_about(center)));
            *at_point = ForceAtPoint::default();
        }
    });
}

/// Bodies with their own share of gravity: the force `(s − 1) m g` on top of the world's
/// gravity, through the user-force path every integrator and solver reads (so the integrators
/// and both solvers need no per-body gravity; the speculative lookahead reads the scale
/// itself). Kinematic bodies ignore it.
fn scale_gravity(
    bodies: Query<(Entity, &GravityScale, &ComputedMass), Active>,
    gravity: Res<Gravity>,
    mut gathered: ResMut<GatheredForces>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::Forces, "forces/gravity_scale", || {
        let g = gravity.acceleration();
        for (entity, scale, mass) in &bodies {
            let m = mass.value();
            if scale.0 != 1.0 && m.is_finite() {
                gathered.forces.push((entity, g * ((scale.0 - 1.0) * m)));
            }
        }
    });
}

type Kicked<'a> = (
    &'a mut Impulse,
    &'a mut Velocity,
    Option<&'a mut AngularVelocity>,
    &'a ComputedMass,
    (&'a Position, Option<&'a Rotation>),
    Option<&'a Inertia>,
    Option<&'a LockedAxes>,
);

/// Consumes every [`Impulse`]: `Δv = J / m`, `Δω = I⁻¹ L` about the centre of mass (in world
/// axes, locked axes, translation and rotation, left alone), before the step integrates. Kinematic bodies ignore it.
fn apply_impulses(
    mut bodies: Query<Kicked, (Active, Changed<Impulse>)>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::Forces, "forces/impulses", || {
        for (mut impulse, mut v, w, mass, (p, r), inertia, locked) in &mut bodies {
            if impulse.is_empty() {
                continue;
            }
            let inverse_mass = mass.inverse();
            if inverse_mass > 0.0 {
                let locks = LockedAxes::of(locked);
                let free = locks.free_translation_axes();
                v.0 += impulse.linear() * inverse_mass * free;
                if let (Some(mut w), Some(inertia)) = (w, inertia) {
                    let center = center_of_mass(p, r, Some(inertia));
                    let moment = impulse.angular_about(center);
                    let spin = inertia.inverse_world_times(Rotation::of(r), moment);
                    let spin = spin * locks.free_rotation_axes();
                    if spin != Vec3::ZERO {
                        w.0 += spin;
                    }
                }
            }
            *impulse = Impulse::default();
        }
    });
}

type Targeted<'a> = (
    Entity,
    &'a KinematicTarget,
    (&'a Position, Option<&'a Rotation>),
    &'a mut Velocity,
    Option<&'a mut AngularVelocity>,
    &'a ComputedMass,
);

/// Sets each kinematic body's velocity and spin to reach its [`KinematicTarget`] by the end of
/// the step (a body without an `AngularVelocity` only translates); a target that cannot be
/// followed quarantines its body.
fn follow_kinematic_targets(
    mut bodies: Query<Targeted, Without<Quarantined>>,
    timestep: Res<PhysicsTimestep>,
    mut commands: Commands,
) {
    for (e, target, (p, r), mut v, w, mass) in &mut bodies {
        if mass.inverse() != 0.0 {
            continue;
        }
        let Some((velocity, spin)) = target.motion_from((p.0, Rotation::of(r)), timestep.dt())
        else {
            let reason = format!("its KinematicTarget cannot be followed: {target:?}");
            quarantine(&mut commands, e, reason);
            continue;
        };
        v.set_if_neq(Velocity(velocity));
        if let Some(mut w) = w {
            w.set_if_neq(AngularVelocity(spin));
        }
    }
}
