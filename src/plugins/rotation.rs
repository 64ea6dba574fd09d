//! Rotation in the ECS: the angular half of the Integrate stage of the lecture's pipeline (the
//! soft step turns bodies itself); the inertia it uses is computed in `mass_properties.rs`.
//!
//! - **Integrate** (each substep, after the linear integration): turning bodies are gathered
//!   into [`AngularBody`] values, [`integrate_rotations`] advances them, and their
//!   [`Rotation`] and [`AngularVelocity`] are written back. A body turns about its centre of
//!   mass, so when that is off its origin the origin moves with the turn. Bodies that neither
//!   spin nor feel a torque are skipped after one look; when nothing turned in the last
//!   substep, no torque acts and no angular velocity changed, the stage returns after that
//!   check alone (a change-tick scan), so a scene in which nothing turns pays almost nothing.

use crate::components::*;
use crate::dynamics::{AngularBody, integrate_rotations};
use crate::plugins::forces::GatheredForces;
use crate::plugins::integration::IntegrateBodies;
use crate::plugins::required_resources::RequireResource;
use crate::plugins::soft_step::legacy_solver;
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::settings::{Integration, PhysicsTimestep, RotationSettings};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use glam::Vec3;
use std::time::Instant;

/// Turns bodies that have an [`AngularVelocity`].
#[derive(Debug, Clone, Default)]
pub struct RotationPlugin;

impl Plugin for RotationPlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<RotationSettings>()
            .init_required::<RotationBuffers>()
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
            free_axes: LockedAxes::of(locked).free_rotation_axes(),
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
