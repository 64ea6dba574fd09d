//! The rigid-body solver in the ECS: contacts turn bodies.
//!
//! [`SoftStepPlugin`], in [`UrtoPlugins`](crate::UrtoPlugins) and on by default, hands
//! integration and contact response to the core [`Solver`] (soft-step substeps, contacts with
//! lever arms, friction, restitution, springs; see [`crate::dynamics::solver`]): the Integrate
//! stage and the legacy response stand aside (their systems run only without this plugin's
//! resource), the broad and narrow phases find the contacts once per step at the step's start,
//! looking ahead by each pair's speculative margin ([`SpeculativeMargin`]: the bodies' fixed
//! distances and how far the two can close in the step), and one system in
//! the Response set gathers the bodies, calls [`Solver::step`] and writes positions, rotations
//! and velocities back. Continuous collision sweeps the solver's motion afterwards; collision
//! messages, sleeping, hierarchies and validation work as before.
//!
//! Its settings are set in the group; disabling it brings back the lecture's pipeline (the
//! selected [`Integration`](crate::settings::Integration) method, bodies that contacts do not
//! turn):
//!
//! ```
//! # use bevy_app::App;
//! # use urto::prelude::*;
//! # use urto::dynamics::solver::SoftStepSettings;
//! let settings = SoftStepSettings { substeps: 8, ..Default::default() };
//! App::new().add_plugins(UrtoPlugins::default().set(SoftStepPlugin { settings }));
//! // The lecture's pipeline instead:
//! App::new().add_plugins(UrtoPlugins::default().build().disable::<SoftStepPlugin>());
//! ```
//!
//! Bodies sleep by islands (`plugins/sleep.rs`); a sleeping body is an immovable one to the
//! solver, and an awake one approaching it wakes its island. Not done yet: springs pull centres
//! of mass. Bodies are ordered by entity (`Entity`'s own order, fixed for a body's life) and
//! contacts by collider pair, never by archetype iteration.

mod contact_inputs;
mod joint_inputs;
mod lookahead;
mod slots;

pub use lookahead::SpeculativeMargin;

use contact_inputs::{KeyedContacts, Material, add_part_motion, gather_contacts, report_impulses};
use joint_inputs::JointParams;
pub(crate) use lookahead::{BodyMotion, Lookahead, LookaheadParams, Moves};
use slots::BodySlots;

use crate::components::*;
use crate::dynamics::forces::{
    MAX_SPRING_DAMPING_RATIO, MAX_SPRING_STIFFNESS_RATIO, Spring as CoreSpring, SpringEnd,
};
use crate::dynamics::solver::Solver;
use crate::dynamics::solver::{
    BodyInput, ContactInput, HeldLoad, JointInput, SoftStepSettings, SolverBodies,
};
use crate::plugins::forces::GatheredForces;
use crate::plugins::narrow_phase::Contacts;
use crate::plugins::required_resources::RequireResource;
use crate::plugins::sleep::{ContactSide, Waker, wakes};
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::settings::{
    ContactSettings, LengthUnit, PhysicsTimestep, RotationSettings, SleepSettings,
};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_ecs::query::{QueryItem, ROQueryItem};
use glam::{Quat, Vec3};
use std::time::Instant;

/// The soft-step rigid-body solver, in place of integration and the legacy response (in
/// [`UrtoPlugins`](crate::UrtoPlugins), on by default).
#[derive(Debug, Clone, Default)]
pub struct SoftStepPlugin {
    /// The solver's tunables (Box2D v3's defaults, stiffer contacts; see
    /// [`SoftStepSettings`]).
    pub settings: SoftStepSettings,
}

impl Plugin for SoftStepPlugin {
    fn build(&self, app: &mut App) {
        let settings = self.settings.validated().unwrap_or_else(|e| {
            log::warn!("urto: SoftStepPlugin settings refused ({e}); using the defaults");
            SoftStepSettings::default()
        });
        // Its presence is the switch: removed by game code, it comes back (a warning says so)
        // rather than the legacy stages taking over silently.
        app.insert_required(move || SoftStepSolver::new(settings))
            .init_required::<SpeculativeMargin>()
            .add_systems(
                SubstepSchedule,
                solve_soft_step
                    .run_if(any_with_component::<Velocity>)
                    .in_set(SolveBodies)
                    .in_set(SubstepSet::Response),
            );
    }
}

/// The solver's system, as a label: continuous collision sweeps after it and the collision
/// messages are reported after that.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SolveBodies;

/// The persistent solver and its buffers; its presence switches the legacy integration and
/// response off.
#[derive(Resource, Default)]
pub struct SoftStepSolver {
    /// The core solver (its settings and the impulses kept between steps).
    pub solver: Solver,
    /// The step's bodies by slot, and each entity's slot.
    slots: BodySlots,
    /// Each slot's input as the awake movers' pass found it (`None`: not an awake mover; the
    /// scatter's awake pass writes back exactly the slots that are `Some`).
    inputs: Vec<Option<(BodyInput, Vec3)>>,
    bodies: SolverBodies,
    contacts: Vec<ContactInput>,
    springs: Vec<CoreSpring>,
    joints: Vec<JointInput>,
    /// Each slot's centre of mass in its body frame (joint anchors are given from the origin).
    local_centers: Vec<Vec3>,
    waking: Vec<Entity>,
    keyed: KeyedContacts,
    sources: Vec<u32>,
    warned_stiff_springs: bool,
}

impl SoftStepSolver {
    /// How far body `e`'s centre of mass moved in the last step's solve (`None` for a body the
    /// solver did not move: static, asleep, or not in the step). What continuous collision
    /// sweeps a fast body against: the other body's real motion, which the solve may have
    /// changed midway (a ball struck in the step, then bounced), not its final velocity's.
    pub(crate) fn step_displacement(&self, e: Entity) -> Option<Vec3> {
        let slot = self.slots.slot(e)?;
        self.bodies.states.get(slot).map(|s| s.delta_position)
    }

    /// Each joint of the last step with what it held over the last substep.
    pub fn joint_loads(&self) -> impl Iterator<Item = (Entity, HeldLoad)> + '_ {
        self.solver
            .joint_loads()
            .map(|(key, load)| (Entity::from_bits(key), load))
    }

    /// A solver with these settings (unusable ones step with the defaults; see
    /// [`SoftStepSettings::validated`]); insert it to change the settings of a running app.
    pub fn new(settings: SoftStepSettings) -> Self {
        Self {
            solver: Solver::new(settings),
            ..Default::default()
        }
    }
}

/// Run condition of the stages the soft step replaces.
pub(crate) fn legacy_solver(solver: Option<Res<SoftStepSolver>>) -> bool {
    solver.is_none()
}

type Mover<'a> = (
    Entity,
    &'a mut Position,
    &'a mut Rotation,
    &'a mut Velocity,
    &'a mut AngularVelocity,
    &'a ComputedMass,
    &'a Inertia,
    Option<&'a LockedAxes>,
    Option<&'a AngularDrag>,
    Option<&'a LinearDrag>,
    Has<Sleeping>,
    Option<&'a mut SleepState>,
);
type MoverFilter = (Without<Static>, Without<Quarantined>, Without<ChildOf>);
/// The movers that are not asleep: the gather and the scatter iterate them in table order
/// (each looked up by entity cost about 470 instructions, the iteration a tenth of that).
type AwakeMoverFilter = (MoverFilter, Without<Sleeping>);
/// The awake movers, as entities only (a filter alone would match every entity of the world,
/// resources and observers included: the components a mover has are named).
type AwakeMover = (
    MoverFilter,
    Without<Sleeping>,
    With<Velocity>,
    With<AngularVelocity>,
    With<Inertia>,
);
#[allow(clippy::too_many_arguments)]
fn solve_soft_step(
    mut movers: ParamSet<(Query<Mover, MoverFilter>, Query<Mover, AwakeMoverFilter>)>,
    awake: Query<Entity, AwakeMover>,
    poses: Query<(&GlobalPose, Option<&StepStartPose>)>,
    materials: Query<Material>,
    mut contacts: ResMut<Contacts>,
    gathered: Res<GatheredForces>,
    settings: Res<ContactSettings>,
    sleep: Option<Res<SleepSettings>>,
    rotation: Option<Res<RotationSettings>>,
    timestep: Res<PhysicsTimestep>,
    mut soft: ResMut<SoftStepSolver>,
    mut stats: ResMut<PhysicsStats>,
    mut waker: Waker,
    joints: JointParams,
    sleepers: Query<(), With<Sleeping>>,
    length: Option<Res<LengthUnit>>,
) {
    let start = Instant::now();
    let s = &mut *soft;
    let unit = length.map_or_else(LengthUnit::default, |u| *u);
    s.solver.set_length_unit(unit);
    let gyroscopic = rotation.is_none_or(|r| r.gyroscopic);
    s.waking.clear();
    let jointed = joints.any();
    // Nothing asleep, nothing to wake: the joints' and the contacts' two lookups each saved
    // (a 10,000-ball net made 40,000 a step).
    let anyone_asleep = !sleepers.is_empty();
    if let Some(sleep) = sleep.filter(|s| s.enabled && anyone_asleep) {
        if jointed {
            joints.wake_partners(&movers.p0(), &mut s.waking);
        }
        wake_touched_sleepers(
            &mut movers.p0(),
            &contacts,
            sleep.speed * unit.get(),
            &mut s.waking,
            &mut waker,
        );
    }
    let held =
        |asleep: bool, e: Entity, waking: &[Entity]| asleep && waking.binary_search(&e).is_err();
    let awake = collect_entities(&awake, &contacts, s.slots.entities_mut());
    s.slots.index();
    if jointed {
        joints.add_bodies(&mut s.slots);
    }
    // The awake movers in table order, each into its slot; then the other slots (sleepers a
    // contact or joint names, statics) one by one.
    s.inputs.clear();
    s.inputs.resize(s.slots.len(), None);
    for m in movers.p1().iter() {
        if let Some(slot) = s.slots.slot(m.0) {
            s.inputs[slot] = Some(body_input(m, &gathered, gyroscopic));
        }
    }
    s.bodies.clear();
    s.local_centers.clear();
    let lone = movers.p0();
    for (&e, found) in s.slots.entities().iter().zip(&s.inputs) {
        // An awake mover's input is read where the pass above left it, not copied out.
        let local_center = match found {
            Some((input, local_center)) => {
                s.bodies.push_input(input);
                *local_center
            }
            None => {
                let (input, local_center) = match lone.get(e) {
                    Ok(m) if !held(m.10, e, &s.waking) => body_input(m, &gathered, gyroscopic),
                    _ => (immovable_input(poses.get(e).ok().map(|p| p.0)), Vec3::ZERO),
                };
                s.bodies.push_input(&input);
                local_center
            }
        };
        s.local_centers.push(local_center);
    }
    s.joints.clear();
    if jointed {
        let world = joints
            .any_to_world()
            .then(|| s.bodies.push(BodyInput::default()));
        joints.gather(&s.slots, &s.local_centers, world, &mut s.joints);
    }
    add_user_forces(&gathered, &s.slots, &mut s.bodies);
    gather_springs(&gathered, &s.slots, &s.bodies, &poses, &mut s.springs);

    gather_contacts(
        &contacts,
        &s.slots,
        &materials,
        &settings,
        &mut s.keyed,
        &mut s.contacts,
        &mut s.sources,
    );
    add_part_motion(
        &contacts,
        s.slots.entities(),
        &poses,
        timestep.substep_dt(),
        &s.sources,
        &mut s.contacts,
        &mut s.bodies,
    );
    s.solver.step(
        &mut s.bodies,
        &s.contacts,
        &s.springs,
        &s.joints,
        timestep.substep_dt(),
    );
    report_impulses(&s.solver, &s.sources, &mut contacts);
    let clamped = s.solver.clamped_springs();
    if clamped > 0 && !s.warned_stiff_springs {
        s.warned_stiff_springs = true;
        log::warn!(
            "urto: {clamped} spring(s) too stiff or too damped for the solver's substep are \
             lowered to k·w·h² = {MAX_SPRING_STIFFNESS_RATIO}, c·w·h = {MAX_SPRING_DAMPING_RATIO} \
             (w: the ends' summed inverse masses, h: the substep); more substeps allow \
             stiffer springs"
        );
    }
    stats.set_counter("soft_step/springs_clamped", clamped as f64);
    stats.set_counter("soft_step/bounded_joints", s.solver.bounded_joints() as f64);
    for m in movers.p1().iter_mut() {
        if let Some(slot) = s.slots.slot(m.0) {
            scatter(m, &s.bodies, slot);
        }
    }
    let mut lone = movers.p0();
    for (slot, &e) in s.slots.entities().iter().enumerate() {
        if s.inputs[slot].is_none()
            && let Ok(m) = lone.get_mut(e)
            && !held(m.10, e, &s.waking)
        {
            scatter(m, &s.bodies, slot);
        }
    }
    stats.set_counter("soft_step/bodies", s.slots.len() as f64);
    stats.set_counter("soft_step/awake_bodies", awake as f64);
    stats.set_counter("soft_step/contacts", s.contacts.len() as f64);
    stats.set_counter("soft_step/joints", s.joints.len() as f64);
    stats.add_time(Stage::Response, start.elapsed());
    stats.count_run("soft_step");
}

/// Wakes each sleeping body that an awake one approaches faster than `wake_speed` along their
/// contact's normal, or that a kinematic body touches (its parts may move on their own): the
/// sleeper then takes part in this step's solve.
fn wake_touched_sleepers(
    movers: &mut Query<Mover, MoverFilter>,
    contacts: &Contacts,
    wake_speed: f32,
    waking: &mut Vec<Entity>,
    waker: &mut Waker,
) {
    let state = |e: Entity| {
        movers.get(e).ok().map(|m| ContactSide {
            velocity: m.3.0,
            dynamic: m.5.inverse() > 0.0,
            asleep: m.10,
        })
    };
    for c in &contacts.pairs {
        let (Some(a), Some(b)) = (state(c.a), state(c.b)) else {
            continue;
        };
        let [wake_a, wake_b] = wakes(a, b, c.manifold.normal, wake_speed);
        if wake_a {
            waking.push(c.a);
        }
        if wake_b {
            waking.push(c.b);
        }
    }
    waking.sort_unstable();
    waking.dedup();
    for &e in waking.iter() {
        if let Ok(mut m) = movers.get_mut(e) {
            waker.wake(e, m.11.as_deref_mut());
        }
    }
}

/// Every awake moving body and every body a contact names, sorted by entity (`Entity`'s order:
/// generation, then index from the highest; fixed for a body's life, never archetype order),
/// each once; returns how many are awake moving bodies.
fn collect_entities(
    awake: &Query<Entity, AwakeMover>,
    contacts: &Contacts,
    out: &mut Vec<Entity>,
) -> usize {
    out.clear();
    out.extend(awake.iter());
    let awake = out.len();
    for pair in &contacts.pairs {
        out.push(pair.a);
        out.push(pair.b);
    }
    // `Entity`'s own order by a stable radix sort on the bits it compares (generation high,
    // the index stored inverted low; the bytes every entry shares, such as one generation,
    // are skipped): a comparison sort of the 7,000 entries of a 1,000-ball pile cost three
    // times as much.
    radsort::sort_by_key(out, |e| e.to_bits());
    out.dedup();
    awake
}

/// A body the solver does not move (static, sleeping, or named by a contact or joint only), at
/// its pose (the origin if it has none usable).
fn immovable_input(pose: Option<&GlobalPose>) -> BodyInput {
    let pose = pose
        .map(|p| p.0)
        .filter(|p| p.translation.is_finite() && p.rotation.is_finite());
    BodyInput {
        center: pose.map_or(Vec3::ZERO, |p| p.translation),
        orientation: pose.map_or(Quat::IDENTITY, |p| p.rotation.normalize()),
        ..Default::default()
    }
}

/// A moving body at the step's start: its centre of mass, inertia, gravity and damping, and its
/// centre of mass in its body frame (joint anchors are given from the origin).
fn body_input(
    m: ROQueryItem<'_, '_, Mover<'_>>,
    gathered: &GatheredForces,
    gyroscopic: bool,
) -> (BodyInput, Vec3) {
    let (_, p, r, v, w, mass, inertia, locked, angular_drag, drag, ..) = m;
    let inverse_mass = mass.inverse();
    let dynamic = inverse_mass > 0.0;
    // Without the component nothing is locked (`LockedAxes::default()`).
    let locks = LockedAxes::of(locked);
    let input = BodyInput {
        center: p.0 + r.0 * inertia.local_center_of_mass,
        orientation: r.0,
        linear_velocity: v.0,
        angular_velocity: w.0,
        inverse_mass,
        inverse_principal_inertia: if dynamic {
            inertia.inverse_principal()
        } else {
            Vec3::ZERO
        },
        inertia_frame: inertia.frame,
        linear_acceleration: gathered.gravity.unwrap_or(Vec3::ZERO),
        torque: Vec3::ZERO,
        linear_damping: drag.map_or(0.0, |d| d.0 * inverse_mass),
        angular_damping: angular_drag.map_or(0.0, |d| d.0),
        free_axes: locks.free_rotation_axes(),
        free_translation: locks.free_translation_axes(),
        gyroscopic,
    };
    (input, inertia.local_center_of_mass)
}

/// The step's forces and torques, each to its body's slot (bodies are sorted by entity).
fn add_user_forces(gathered: &GatheredForces, slots: &BodySlots, bodies: &mut SolverBodies) {
    for (e, f) in &gathered.forces {
        if let Some(slot) = slots.slot(*e) {
            let p = &mut bodies.params[slot];
            if p.dynamic {
                p.linear_acceleration += *f * p.inverse_mass;
            }
        }
    }
    for (e, t) in &gathered.torques {
        if let Some(slot) = slots.slot(*e) {
            let p = &mut bodies.params[slot];
            if p.dynamic {
                p.angular_acceleration += p.inverse_inertia * *t;
            }
        }
    }
}

/// The step's springs between solver slots. An end that is no solver body is an anchor at its
/// world position; an end with no finite position (quarantined, gone) drops the spring, so a
/// bad body never reaches a good one through it (the solver lowers springs too stiff for its
/// substep: [`CoreSpring::clamped_to_stability`]).
fn gather_springs(
    gathered: &GatheredForces,
    slots: &BodySlots,
    bodies: &SolverBodies,
    poses: &Query<(&GlobalPose, Option<&StepStartPose>)>,
    out: &mut Vec<CoreSpring>,
) {
    out.clear();
    for (owner, s) in &gathered.springs {
        let Some(body) = slots.slot(*owner) else {
            continue;
        };
        let other = match s.target {
            SpringTarget::Point(p) => SpringEnd::Anchor(p),
            SpringTarget::Entity(e) => match slots.slot(e) {
                Some(j) if bodies.params[j].dynamic => SpringEnd::Body(j),
                _ => match poses.get(e) {
                    Ok((p, _)) => SpringEnd::Anchor(p.0.translation),
                    Err(_) => continue,
                },
            },
        };
        if matches!(other, SpringEnd::Anchor(p) if !p.is_finite()) {
            continue;
        }
        let spring = CoreSpring {
            body,
            other,
            rest_length: s.rest_length,
            stiffness: s.stiffness,
            damping: s.damping,
        };
        out.push(spring);
    }
}

/// Writes a moving body's new pose and velocities.
fn scatter(m: QueryItem<'_, '_, Mover<'_>>, bodies: &SolverBodies, slot: usize) {
    let (_, mut p, mut r, mut v, mut w, _, inertia, ..) = m;
    let orientation: Quat = bodies.orientation(slot);
    let center = bodies.center(slot);
    p.set_if_neq(Position(
        center - orientation * inertia.local_center_of_mass,
    ));
    r.set_if_neq(Rotation(orientation));
    v.set_if_neq(Velocity(bodies.states[slot].linear_velocity));
    w.set_if_neq(AngularVelocity(bodies.states[slot].angular_velocity));
}
