//! The Response stage: impulses (restitution, Coulomb friction, warm-started from the previous
//! substep's impulses of the same contact) and position correction for the contacts (the
//! lecture's pipeline; the soft step replaces it by default), and the collision started / ended
//! messages game code listens to (`collision_messages.rs`).

pub use super::collision_messages::{
    CollisionEnd, CollisionEnded, CollisionEventsEnabled, CollisionStart, CollisionStarted,
    ContactData, ReportCollisions,
};
use super::collision_messages::{
    add_collision_messages, report_collisions, trigger_collision_events,
};
use crate::components::*;
use crate::dynamics::response::{
    ContactConstraint, SupportGraph, correct_positions, resting_displacements, solve_velocities,
};
use crate::geometry::ContactManifold;
use crate::plugins::narrow_phase::{ContactPair, Contacts};
use crate::plugins::required_resources::RequireResource;
use crate::plugins::sleep::{ContactSide, Waker, wakes};
use crate::plugins::soft_step::legacy_solver;
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::settings::{ContactSettings, LengthUnit, PhysicsTimestep, SleepSettings};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use glam::Vec3;
use std::collections::HashMap;
use std::time::Instant;

/// Resolves contacts and reports collisions.
#[derive(Debug, Clone, Default)]
pub struct ResponsePlugin;

impl Plugin for ResponsePlugin {
    fn build(&self, app: &mut App) {
        add_collision_messages(app);
        app.init_required::<ResponseBuffers>().add_systems(
            SubstepSchedule,
            (
                resolve_contacts.run_if(legacy_solver),
                report_collisions.in_set(ReportCollisions),
                trigger_collision_events,
            )
                .chain()
                .run_if(any_with_component::<Collider>)
                .in_set(SubstepSet::Response),
        );
    }
}

/// Solver arrays reused from step to step. Index 0 is the shared immovable body (all statics).
#[derive(Resource, Default)]
struct ResponseBuffers {
    index: EntityHashMap<usize>,
    /// Sleeping bodies an awake body approaches fast enough to wake them this substep.
    waking: Vec<Entity>,
    entities: Vec<Entity>,
    positions: Vec<Vec3>,
    velocities: Vec<Vec3>,
    inverse_mass: Vec<f32>,
    constraints: Vec<ContactConstraint>,
    displacement: Vec<Vec3>,
    velocities_before: Vec<Vec3>,
    settle_scale: Vec<f32>,
    /// Contacts ordered from the ground up (shock propagation).
    support: SupportGraph,
    /// Each constraint's key (indexed by the constraint's tag): the pair of colliders that
    /// touched and the manifold's rank among that pair's manifolds.
    keys: Vec<ContactKey>,
    /// Last substep's impulses (normal, friction) per contact, for warm starting; looked up,
    /// never iterated, so its hashing order reaches no result.
    warm: HashMap<ContactKey, (f32, Vec3)>,
}

type ContactKey = (Entity, Entity, u16);

type Movable<'a> = (
    &'a mut Position,
    &'a mut Velocity,
    &'a ComputedMass,
    Has<Sleeping>,
    Option<&'a mut SleepState>,
);
type MovableFilter = (Without<Static>, Without<Quarantined>);

#[allow(clippy::too_many_arguments)]
fn resolve_contacts(
    mut contacts: ResMut<Contacts>,
    mut bodies: Query<Movable, MovableFilter>,
    restitution: Query<&Restitution>,
    friction: Query<&Friction>,
    poses: Query<(&GlobalPose, Option<&StepStartPose>)>,
    settings: Res<ContactSettings>,
    sleep: Option<Res<SleepSettings>>,
    timestep: Res<PhysicsTimestep>,
    mut buffers: ResMut<ResponseBuffers>,
    mut stats: ResMut<PhysicsStats>,
    mut waker: Waker,
    length: Option<Res<LengthUnit>>,
) {
    if contacts.pairs.is_empty() {
        buffers.warm.clear();
        return;
    }
    let start = Instant::now();
    let step_dt = timestep.dt();
    let b = &mut *buffers;
    b.clear();
    let e_of = |e: Entity| {
        restitution
            .get(e)
            .map_or(settings.default_restitution, |r| r.0)
    };
    let mu_of = |e: Entity| friction.get(e).map_or(settings.default_friction, |f| f.0);
    b.waking.clear();
    if let Some(sleep) = sleep.filter(|s| s.enabled) {
        let unit = length.map_or(1.0, |u| u.get());
        b.find_waking(&contacts.pairs, &bodies, sleep.speed * unit);
    }
    let mut rank = 0u16;
    for (i, c) in contacts.pairs.iter().enumerate() {
        // The k-th manifold of a pair in this list is the same contact as last substep's k-th.
        let touching = |c: &ContactPair| (c.collider_a, c.collider_b);
        let previous = i.checked_sub(1).map(|j| touching(&contacts.pairs[j]));
        rank = if previous == Some(touching(c)) {
            rank + 1
        } else {
            0
        };
        let key = (c.collider_a, c.collider_b, rank);
        let m = &c.manifold;
        let (ia, ib) = (b.slot(c.a, &bodies), b.slot(c.b, &bodies));
        let ia = b.moving_part_slot(ia, (c.a, c.collider_a), m, &poses, step_dt);
        let ib = b.moving_part_slot(ib, (c.b, c.collider_b), m, &poses, step_dt);
        let mu = (mu_of(c.a).max(0.0) * mu_of(c.b).max(0.0)).sqrt();
        let e = 0.5 * (e_of(c.a) + e_of(c.b));
        let (jn, jt) = b.warm.get(&key).copied().unwrap_or_default();
        b.constraints.push(
            ContactConstraint::new(ia, ib, m.normal, m.max_depth(), e)
                .with_friction(mu)
                .with_warm_start(jn, jt)
                .with_tag(b.keys.len() as u32),
        );
        b.keys.push(key);
    }
    b.support.order(&mut b.constraints, &b.inverse_mass);
    b.velocities_before.clone_from(&b.velocities);
    solve_velocities(
        &mut b.constraints,
        &mut b.velocities,
        &b.inverse_mass,
        Some(b.support.levels()),
        &settings.solver,
    );
    resting_displacements(
        &b.constraints,
        &b.velocities_before,
        &b.velocities,
        timestep.substep_dt(),
        &mut b.displacement,
        &mut b.settle_scale,
    );
    correct_positions(
        &b.constraints,
        &mut b.positions,
        &b.inverse_mass,
        Some(b.support.levels()),
        &settings.solver,
        &mut b.displacement,
    );
    b.remember_impulses();
    b.report_impulses(&mut contacts.pairs);
    for i in 1..b.entities.len() {
        if b.inverse_mass[i] > 0.0
            && let Ok((mut p, mut v, _, asleep, mut state)) = bodies.get_mut(b.entities[i])
        {
            if asleep {
                // One of `waking`: the others were held immovable.
                waker.wake(b.entities[i], state.as_deref_mut());
            }
            p.set_if_neq(Position(b.positions[i]));
            v.set_if_neq(Velocity(b.velocities[i]));
        }
    }
    stats.add_time(Stage::Response, start.elapsed());
    stats.count_run("response");
}

impl ResponseBuffers {
    fn clear(&mut self) {
        self.index.clear();
        self.constraints.clear();
        self.keys.clear();
        self.entities.clear();
        self.positions.clear();
        self.velocities.clear();
        self.inverse_mass.clear();
        // Slot 0: every static body (immovable, at rest).
        self.entities.push(Entity::PLACEHOLDER);
        self.positions.push(Vec3::ZERO);
        self.velocities.push(Vec3::ZERO);
        self.inverse_mass.push(0.0);
    }

    /// Each contact's normal impulse and approach speed along its normal before the solve,
    /// for the collision messages' contact data (what the rigid-body solver reports too). A
    /// continuous-collision impact, added before the solve with its speed and already
    /// separating, keeps the larger.
    fn report_impulses(&self, pairs: &mut [ContactPair]) {
        for c in &self.constraints {
            if let Some(pair) = pairs.get_mut(c.tag as usize) {
                let (va, vb) = (self.velocities_before[c.a], self.velocities_before[c.b]);
                pair.normal_impulse = pair.normal_impulse.max(c.impulse());
                pair.impact_speed = pair.impact_speed.max((va - vb).dot(c.normal));
            }
        }
    }

    /// Keeps this substep's impulses for the next one; contacts that ended are forgotten.
    fn remember_impulses(&mut self) {
        self.warm.clear();
        for c in &self.constraints {
            let key = self.keys[c.tag as usize];
            self.warm.insert(key, (c.impulse(), c.tangent_impulse()));
        }
    }

    /// The slot for a contact on `part` of `body`'s hierarchy: `slot` itself, unless the body is
    /// immovable and the game moved the part relative to it this step (a robot's joint turned):
    /// then a slot of its own, immovable, moving at the velocity of the manifold's centre, so
    /// the part bats what it hits instead of only pushing it aside.
    fn moving_part_slot(
        &mut self,
        slot: usize,
        (body, part): (Entity, Entity),
        manifold: &ContactManifold,
        poses: &Query<(&GlobalPose, Option<&StepStartPose>)>,
        step_dt: f32,
    ) -> usize {
        if part == body || self.inverse_mass[slot] > 0.0 {
            return slot;
        }
        let points = manifold.points();
        let at = points.iter().map(|p| p.point).sum::<Vec3>() / points.len().max(1) as f32;
        let Some(v) = part_velocity(body, part, at, poses, step_dt) else {
            return slot;
        };
        if v == Vec3::ZERO {
            return slot;
        }
        self.entities.push(Entity::PLACEHOLDER);
        self.positions.push(at);
        self.velocities.push(self.velocities[slot] + v);
        self.inverse_mass.push(0.0);
        self.entities.len() - 1
    }

    /// The sleeping bodies of `contacts` that an awake body approaches faster than `wake_speed`
    /// (gravity's pull on a body resting on a sleeper counts: a stack sleeps as a whole, as with
    /// islands). The others are held immovable, so a pile's awake bodies rest on its sleeping
    /// ones as on the ground.
    fn find_waking(
        &mut self,
        contacts: &[ContactPair],
        bodies: &Query<Movable, MovableFilter>,
        wake_speed: f32,
    ) {
        let state = |e: Entity| {
            bodies.get(e).ok().map(|(_, v, m, asleep, _)| ContactSide {
                velocity: v.0,
                dynamic: m.inverse() > 0.0,
                asleep,
            })
        };
        for c in contacts {
            let (Some(a), Some(b)) = (state(c.a), state(c.b)) else {
                continue;
            };
            let [wake_a, wake_b] = wakes(a, b, c.manifold.normal, wake_speed);
            if wake_a {
                self.waking.push(c.a);
            }
            if wake_b {
                self.waking.push(c.b);
            }
        }
        self.waking.sort_unstable();
        self.waking.dedup();
    }

    /// The solver index of `e`, adding it on first sight; statics share slot 0.
    fn slot(&mut self, e: Entity, bodies: &Query<Movable, MovableFilter>) -> usize {
        if let Some(&i) = self.index.get(&e) {
            return i;
        }
        let Ok((p, v, m, asleep, _)) = bodies.get(e) else {
            return 0;
        };
        // A sleeping body holds still like scenery unless it is being woken.
        let held = asleep && self.waking.binary_search(&e).is_err();
        let i = self.entities.len();
        self.index.insert(e, i);
        self.entities.push(e);
        self.positions.push(p.0);
        self.velocities.push(v.0);
        self.inverse_mass.push(if held { 0.0 } else { m.inverse() });
        i
    }
}

/// The velocity of the point `at` of `part` relative to its root `body`, from how the part moved
/// in the root's frame since the step began; `None` until both have a [`StepStartPose`].
pub(crate) fn part_velocity(
    body: Entity,
    part: Entity,
    at: Vec3,
    poses: &Query<(&GlobalPose, Option<&StepStartPose>)>,
    step_dt: f32,
) -> Option<Vec3> {
    let pose = |e: Entity| {
        let (now, start) = poses.get(e).ok()?;
        Some((now.0, start?.0))
    };
    let (root_now, root_start) = pose(body)?;
    let (part_now, part_start) = pose(part)?;
    let local = part_now.inverse_transform_point(at);
    let in_root_now = root_now.inv_mul(&part_now).transform_point(local);
    let in_root_start = root_start.inv_mul(&part_start).transform_point(local);
    let v = root_now.transform_vector(in_root_now - in_root_start) / step_dt;
    v.is_finite().then_some(v)
}
