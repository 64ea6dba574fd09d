//! The Integrate stage: advances every moving body with the selected integrator.
//!
//! A thin adapter: it copies positions and velocities into flat arrays, maps the gathered forces
//! onto them as a [`ForceModel`], calls [`integrate`] (the core, no ECS), and writes back only
//! what changed, so bodies at rest do not trip change detection downstream.

use crate::components::*;
use crate::dynamics::forces::Spring as CoreSpring;
use crate::dynamics::{ForceModel, IntegratorScratch, SpringEnd, integrate};
use crate::plugins::forces::GatheredForces;
use crate::plugins::required_resources::RequireResource;
use crate::plugins::soft_step::legacy_solver;
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::settings::{Integration, PhysicsTimestep};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use glam::Vec3;
use std::time::Instant;

/// Moves bodies that have a [`Velocity`].
#[derive(Debug, Clone, Default)]
pub struct IntegrationPlugin;

impl Plugin for IntegrationPlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<IntegrationBuffers>().add_systems(
            SubstepSchedule,
            integrate_bodies
                .run_if(any_with_component::<Velocity>)
                .run_if(legacy_solver)
                .in_set(IntegrateBodies)
                .in_set(SubstepSet::Integrate),
        );
    }
}

/// The integration itself, as a label other stages can order against (continuous collision
/// records where bodies start before it and sweeps after it).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct IntegrateBodies;

/// Flat arrays reused from step to step.
#[derive(Resource, Default)]
struct IntegrationBuffers {
    positions: Vec<Vec3>,
    velocities: Vec<Vec3>,
    index: EntityHashMap<usize>,
    model: ForceModel,
    scratch: IntegratorScratch,
}

type Moving<'a> = (Entity, &'a mut Position, &'a mut Velocity, &'a ComputedMass);
/// Sleeping bodies are not integrated: their archetypes are left out.
type MovingFilter = (
    Without<Static>,
    Without<Quarantined>,
    Without<ChildOf>,
    Without<Sleeping>,
);

fn integrate_bodies(
    mut queries: ParamSet<(Query<Moving, MovingFilter>, Query<&Position>)>,
    gathered: Res<GatheredForces>,
    timestep: Res<PhysicsTimestep>,
    integration: Res<Integration>,
    mut buffers: ResMut<IntegrationBuffers>,
    mut stats: ResMut<PhysicsStats>,
) {
    let start = Instant::now();
    let b = &mut *buffers;
    gather_state(&queries.p0(), b, &gathered);
    if !gathered.springs.is_empty() {
        resolve_springs(&queries.p1(), b, &gathered);
    }
    integrate(
        integration.0,
        timestep.substep_dt(),
        &mut b.positions,
        &mut b.velocities,
        &b.model,
        &mut b.scratch,
    );
    let mut bodies = queries.p0();
    for (i, (_, mut p, mut v, _)) in bodies.iter_mut().enumerate() {
        p.set_if_neq(Position(b.positions[i]));
        v.set_if_neq(Velocity(b.velocities[i]));
    }
    stats.set_counter("integrate/bodies", b.positions.len() as f64);
    stats.add_time(Stage::Integrate, start.elapsed());
    stats.count_run("integrate");
}

/// Copies the moving bodies into the flat arrays and the model (query order = array order).
fn gather_state(
    bodies: &Query<Moving, MovingFilter>,
    b: &mut IntegrationBuffers,
    gathered: &GatheredForces,
) {
    b.positions.clear();
    b.velocities.clear();
    b.model.reset(0);
    b.model.gravity = gathered.gravity;
    let needs_index = !gathered.only_gravity();
    b.index.clear();
    for (i, (entity, p, v, m)) in bodies.iter().enumerate() {
        b.positions.push(p.0);
        b.velocities.push(v.0);
        b.model.inverse_mass.push(m.inverse());
        if needs_index {
            b.index.insert(entity, i);
        }
    }
    if !gathered.forces.is_empty() {
        b.model.constant_force.resize(b.positions.len(), Vec3::ZERO);
        for (e, f) in &gathered.forces {
            if let Some(&i) = b.index.get(e) {
                b.model.constant_force[i] += *f;
            }
        }
    }
    if !gathered.drag.is_empty() {
        b.model.linear_drag.resize(b.positions.len(), 0.0);
        for (e, d) in &gathered.drag {
            if let Some(&i) = b.index.get(e) {
                b.model.linear_drag[i] = *d;
            }
        }
    }
}

/// Maps springs to body indices; an end that is not a moving body becomes a fixed anchor at its
/// current position. Springs whose owner is not moving, or whose target is gone, are skipped.
fn resolve_springs(positions: &Query<&Position>, b: &mut IntegrationBuffers, g: &GatheredForces) {
    for (owner, s) in &g.springs {
        let Some(&body) = b.index.get(owner) else {
            continue;
        };
        let other = match s.target {
            SpringTarget::Point(p) => SpringEnd::Anchor(p),
            SpringTarget::Entity(e) => match b.index.get(&e) {
                Some(&j) => SpringEnd::Body(j),
                None => match positions.get(e) {
                    Ok(p) => SpringEnd::Anchor(p.0),
                    Err(_) => continue,
                },
            },
        };
        b.model.springs.push(CoreSpring {
            body,
            other,
            rest_length: s.rest_length,
            stiffness: s.stiffness,
            damping: s.damping,
        });
    }
}
