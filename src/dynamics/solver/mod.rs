//! The rigid-body solver: soft-step substeps over dense body arrays, contacts found once per
//! step (Box2D v3's `solver.c` "soft step", Catto's "Solver2D" 2024; rapier's and Avian's
//! TGS-soft are the same scheme).
//!
//! One [`Solver::step`] takes the bodies at the step's start and the step's contacts and runs,
//! with `h = dt / substeps`:
//!
//! 1. **prepare** — contact rows with lever arms ([`ContactConstraint::prepare`]), seeded with
//!    last step's impulses ([`WarmStartCache`]), then packed up to four at a time into
//!    batches ([`ContactBatches`]) of contacts that share no moving body ([`ordered_batches`]); joints
//!    seeded with theirs, held to what the speed and spin bounds allow
//!    (`joint_list.rs`, `JointList::bound_impulses`), the free ball joints packed four at a
//!    time the same way (`joint_batch.rs`);
//! 2. `substeps` times:
//!    1. **integrate velocities** — springs, then gravity, forces, torques and damping, all
//!       evaluated at the substep's starting state (so a stiff spring is as stable as the
//!       substep is short, and a dashpot never resists gravity's kick);
//!    2. **warm start** — apply the accumulated impulses, joints' then contacts' (each
//!       contact's points are swept in the opposite order from the last substep, so
//!       Gauss–Seidel favours none of them);
//!    3. **solve** — one biased pass, joints before contacts (Box2D's order: the contacts, last,
//!       win a conflict): penetration pushed out softly, speculative points closed, joint
//!       errors closed at [`SoftStepSettings::joint_hertz`]; an impact's points are swept
//!       until they agree, in this pass and the relax passes (`contact_normals.rs`);
//!    4. **integrate positions** — each body's motion since the step's start (`dp`, `dq`),
//!       a dynamic body's speed at most [`SoftStepSettings::max_linear_speed`] and every
//!       body's turn at most [`SoftStepSettings::max_rotation_per_substep`]; the joints' rows
//!       are taken again where the bodies now are;
//!    5. **relax** — passes without bias, friction (per point, or per patch:
//!       [`FrictionModel`]) and rolling resistance included (two over
//!       the contacts and one over the joints by default, see
//!       [`SoftStepSettings::relax_iterations`] and
//!       [`SoftStepSettings::joint_relax_iterations`]);
//! 3. **restitution** — bounces from the approach speeds at the step's start, then the speed
//!    and spin bounds once more on what the step hands out;
//! 4. **store impulses** — for the next step's warm start.
//!
//! Substeps share one collision detection: the separation of each contact point follows the
//! bodies' motion within the step (see [`contact`]), so detection runs once per step while the
//! solver converges as if it ran `substeps` times. The defaults are Box2D v3's and rapier's
//! (4 substeps, damping ratio 10, twice as stiff against immovable bodies,
//! push-out at most 3 m/s, bounces above 1 m/s); see [`SoftStepSettings`].
//!
//! # Four contacts at once
//! The passes run batch by batch, each batch's contacts side by side in the lanes of
//! `wide::f32x4` ([`batch`], as Box2D v3's wide contact solver): a batch gathers its bodies'
//! velocities, runs the scalar rows' arithmetic in every lane and scatters them back. The
//! batches hold contacts that move no common body, packed without reordering dependent ones
//! ([`ordered_batches`]), so the passes compute exactly the key-order Gauss–Seidel sweep of
//! the scalar rows, four contacts at a time where the contact graph allows it (a 210-box
//! pyramid: 590 contacts in 169 batches). Contacts with rolling resistance are solved one at a
//! time after the batches.
//!
//! Free ball joints (the point rows alone: nets, chains) ride in lanes the same way
//! (`joint_batch.rs`), exactly their key-order sweep; the joints of other kinds (limits,
//! hinges, welds, sliders, distances) are solved one at a time after the batches, in the order
//! given. In a scene mixing both, the ball joints therefore go first in each pass, where the
//! scalar sweep would have interleaved them by key: another Gauss–Seidel order, as
//! deterministic.
//!
//! Bodies are in the caller's slot order and contacts in the caller's key order, and the
//! batches follow the key order, so the result depends on nothing else (no hashing, no
//! archetype or thread order).

mod anchor_drift;
pub mod batch;
mod batch_rows;
pub mod body;
pub mod contact;
mod contact_pair;
mod integrate;
pub mod joint;
mod joint_batch;
mod joint_extra;
pub mod joint_input;
mod joint_list;
pub mod joint_rows;
pub mod lanes;
pub mod ordered_batches;
pub mod patch_friction;
pub mod point_rows;
pub mod rolling;
pub mod row;
pub mod softness;
mod turned_rows;
pub mod warm_start;

#[cfg(test)]
mod scenarios;

pub use batch::ContactBatches;
pub use body::{BodyInput, BodyParams, BodyState, SolverBodies};
pub use contact::{
    ConstraintPoint, ContactConstraint, ContactInput, ContactPointInput, RowSettings,
};
pub use joint::{
    HeldLoad, JointConstraint, JointFrame, JointImpulses, JointInput, JointKind, JointLimit,
    JointMotor,
};
pub use patch_friction::FrictionModel;
pub use rolling::RollingRows;
pub use softness::Softness;
pub use warm_start::WarmStartCache;

use crate::dynamics::forces::{ForceModel, Spring, SpringEnd};
use crate::settings::{LengthUnit, MAX_SUBSTEPS, SettingsError};
use anchor_drift::drift_share;
use glam::Vec3;
use integrate::{capped, integrate_positions, integrate_velocities};
use joint_list::JointList;
use ordered_batches::OrderedBatches;
use turned_rows::TurnedRows;

/// How many times the speed and spin bounds a joint's carried impulses may change a body's
/// velocity by: a sound joint's impulse reverses at most a body's whole velocity (from `+v` to
/// `−v`, twice the bound), so anything above that is a fight between joints, not a load.
const WARM_START_BOUND: f32 = 2.0;

/// Most relax passes per substep a setting may ask for (more is a hang, not accuracy).
pub const MAX_RELAX_ITERATIONS: u32 = 64;

/// The solver's tunables (defaults as in Box2D v3 and rapier 0.36).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftStepSettings {
    /// Substeps per step (each integrates, solves once and relaxes).
    pub substeps: u32,
    /// Relax passes per substep over the contacts (Box2D v3 makes one). Two halve a tall stack's sway: measured in
    /// `scenarios.rs` over 10 s, 10 boxes drift 1.07 → 0.31 cm and 20 boxes 2.06 → 0.59 cm, for
    /// one more pass over the contacts per substep (a second *biased* pass instead gave 0.52 and
    /// 0.84 cm, three relax passes 0.10 and 1.18 cm).
    pub relax_iterations: u32,
    /// Relax passes per substep over the joints (Box2D v3 makes one): the first this many of
    /// the relax passes include the joints, and if this is the larger, the last passes relax
    /// the joints alone (after the contacts, so that those passes let the joints win a
    /// conflict). A second pass, which steadies stacks, buys joints nothing: measured on
    /// the joint grid (`peers/benches/joint_grid.rs`, 60 steps), the worst joint gap of a
    /// 20 × 20 net is 14.6 mm with one pass and 19.6 mm with two, of a 100 × 100 net 369.5 and
    /// 374.0 mm, for a third more joint work.
    pub joint_relax_iterations: u32,
    /// Contact stiffness between two movable bodies (Hz). Box2D and rapier take 30 Hz; here a
    /// stack of 20 unit boxes at 30 Hz sags 11 cm under its own weight (a soft contact yields
    /// `load / (m_eff ω²)`) and slowly topples, at 60 Hz it sags 3 cm and stands (measured in
    /// `scenarios.rs`), and 60 Hz is still within Box2D's bound of a quarter of the substep rate
    /// at 4 substeps of a 60 Hz step.
    pub contact_hertz: f32,
    /// Contact stiffness against a static or kinematic body (Hz).
    pub static_contact_hertz: f32,
    /// Damping ratio of the contact springs.
    pub damping_ratio: f32,
    /// Fastest push out of penetration (m/s). This, the restitution threshold, the warm-start
    /// distance and the speed bound are read times the solver's [`LengthUnit`]
    /// ([`Solver::set_length_unit`]; 1 unless the game sets one).
    pub max_push_out: f32,
    /// Approach speeds below this do not bounce (m/s).
    pub restitution_threshold: f32,
    /// A contact point takes last step's impulses from the nearest old point within this (m).
    pub warm_start_distance: f32,
    /// Fastest turn per substep (rad): keeps a wildly spinning body's linearised rotation sane.
    /// It also bounds the spin a dynamic body leaves the step with (`max / h`), and, with the
    /// speed bound, the impulses a joint carries into a step.
    pub max_rotation_per_substep: f32,
    /// Fastest a body moves (m/s; Box2D v3's `maximumLinearSpeed`, 400 m/s, "faster than the
    /// speed of sound"; Jolt's is 500). Valid but violent input (a joint spawned with its
    /// anchors metres apart on a 10 g body, a stiff spring stretched far) would otherwise fling
    /// a body at kilometres per second; this bounds it, and a game with faster bodies raises it.
    pub max_linear_speed: f32,
    /// Stiffness with which joints close their position errors in the biased pass (Hz; 0:
    /// rigid). Box2D v3 takes twice its contact stiffness, 60 Hz.
    pub joint_hertz: f32,
    /// Damping ratio of the joints' error correction (Box2D v3: 2).
    pub joint_damping_ratio: f32,
    /// Friction rows per contact point or per contact patch ([`FrictionModel`]).
    pub friction: FrictionModel,
}

impl Default for SoftStepSettings {
    fn default() -> Self {
        Self {
            substeps: 4,
            relax_iterations: 2,
            joint_relax_iterations: 1,
            contact_hertz: 60.0,
            static_contact_hertz: 120.0,
            damping_ratio: 10.0,
            max_push_out: 3.0,
            restitution_threshold: 1.0,
            warm_start_distance: 0.05,
            max_rotation_per_substep: 0.25 * std::f32::consts::PI,
            max_linear_speed: 400.0,
            joint_hertz: 60.0,
            joint_damping_ratio: 2.0,
            friction: FrictionModel::default(),
        }
    }
}

impl SoftStepSettings {
    /// These settings, or the defaults where they are unusable: what [`Solver::step`] steps
    /// with (the lookahead reads the substep count from here too).
    pub fn usable(self) -> Self {
        self.validated().unwrap_or_default()
    }

    /// The settings if every number is usable: `1..=MAX_SUBSTEPS` substeps,
    /// `1..=MAX_RELAX_ITERATIONS` relax passes (contacts and joints), stiffnesses,
    /// damping ratio, restitution threshold and warm-start distance finite and `>= 0`, push-out
    /// speed, rotation bound and speed bound finite and `> 0`.
    pub fn validated(self) -> Result<Self, SettingsError> {
        if !(1..=MAX_SUBSTEPS).contains(&self.substeps) {
            return Err(SettingsError::BadSubsteps(self.substeps));
        }
        for (name, passes) in [
            ("relax_iterations", self.relax_iterations),
            ("joint_relax_iterations", self.joint_relax_iterations),
        ] {
            if !(1..=MAX_RELAX_ITERATIONS).contains(&passes) {
                return Err(SettingsError::BadCoefficient(name, passes as f32));
            }
        }
        let at_least_zero = [
            ("contact_hertz", self.contact_hertz),
            ("static_contact_hertz", self.static_contact_hertz),
            ("damping_ratio", self.damping_ratio),
            ("restitution_threshold", self.restitution_threshold),
            ("warm_start_distance", self.warm_start_distance),
            ("joint_hertz", self.joint_hertz),
            ("joint_damping_ratio", self.joint_damping_ratio),
        ];
        let above_zero = [
            ("max_push_out", self.max_push_out),
            ("max_rotation_per_substep", self.max_rotation_per_substep),
            ("max_linear_speed", self.max_linear_speed),
        ];
        for (name, v) in at_least_zero {
            if !(v.is_finite() && v >= 0.0) {
                return Err(SettingsError::BadCoefficient(name, v));
            }
        }
        for (name, v) in above_zero {
            if !(v.is_finite() && v > 0.0) {
                return Err(SettingsError::BadCoefficient(name, v));
            }
        }
        Ok(self)
    }
}

/// The persistent solver: its constraint buffer and the impulses kept between steps.
#[derive(Clone, Debug, Default)]
pub struct Solver {
    /// The tunables.
    pub settings: SoftStepSettings,
    /// The size of the scene's bodies, which the settings' lengths and speeds are read in.
    length_unit: LengthUnit,
    /// The settings this step runs with: usable, and in the length unit.
    stepping: SoftStepSettings,
    constraints: Vec<ContactConstraint>,
    /// The constraints in batches that keep the key order's result.
    batching: OrderedBatches,
    /// The batched constraints, [`lanes::LANES`] at a time.
    batches: ContactBatches,
    cache: WarmStartCache,
    /// Centres and velocities of the substep, for the springs.
    spring_state: (Vec<Vec3>, Vec<Vec3>),
    /// The step's springs, each within the stable range of the substep.
    stable_springs: Vec<Spring>,
    /// How many springs of the last step were lowered to that range.
    clamped_springs: usize,
    /// How many joints of the last step carried impulses past the warm-start bound.
    bounded_joints: usize,
    /// The step's joints, with their impulses (and last step's, for the warm start).
    joints: JointList,
    /// The last step's substep (s).
    substep: f32,
    /// The rows of bodies that turn within the step, rebuilt as they turn.
    turned_rows: TurnedRows,
}

impl Solver {
    /// A solver with the given settings.
    pub fn new(settings: SoftStepSettings) -> Self {
        Self {
            settings,
            ..Default::default()
        }
    }

    /// Reads the settings' lengths and speeds in `unit` from the next step on.
    pub fn set_length_unit(&mut self, unit: LengthUnit) {
        self.length_unit = unit;
    }

    /// The constraints of the last step, with their impulses (for contact reports and debug
    /// output).
    pub fn constraints(&self) -> &[ContactConstraint] {
        &self.constraints
    }

    /// The joints of the last step, with their impulses (in the order given; see
    /// [`Self::joint_loads`] for the force each applied).
    pub fn joints(&self) -> &[JointConstraint] {
        self.joints.joints()
    }

    /// What each joint of the last step applied over its last substep, by the joint's key.
    pub fn joint_loads(&self) -> impl Iterator<Item = (u64, HeldLoad)> + '_ {
        self.joints.loads(self.substep)
    }

    /// The last step's substep (s).
    pub fn substep(&self) -> f32 {
        self.substep
    }

    /// Advances `bodies` by `dt` under `contacts` (sorted by key; see the module doc),
    /// `springs` (their `body` and `other` are slots; each pulls its bodies' centres of mass)
    /// and `joints` (a joint naming a slot past the bodies or one body twice, or with unusable
    /// frames, limit or motor, is skipped: see [`JointKind::problem`]).
    pub fn step(
        &mut self,
        bodies: &mut SolverBodies,
        contacts: &[ContactInput],
        springs: &[Spring],
        joints: &[JointInput],
        dt: f32,
    ) {
        // The settings are public: unusable ones (a NaN stiffness, u32::MAX substeps) step with
        // the defaults rather than hang or spread NaN.
        self.settings = self.settings.usable();
        let s = self.length_unit.solver_settings(self.settings);
        self.stepping = s;
        // A step that returns early bounds nothing.
        self.bounded_joints = 0;
        let substeps = s.substeps.max(1);
        let h = dt / substeps as f32;
        if !(h > 0.0 && h.is_finite()) {
            return;
        }
        let inv_h = 1.0 / h;
        self.substep = h;
        self.prepare(bodies, contacts, (h, dt));
        self.turned_rows.begin(bodies);
        self.prepare_joints(bodies, joints, inv_h);
        let joint_soft = Softness::new(s.joint_hertz, s.joint_damping_ratio, h);
        self.stabilise_springs(bodies, springs, h);
        let springs = std::mem::take(&mut self.stable_springs);
        let mut flip = false;
        for k in 0..substeps {
            let share = drift_share(k, substeps);
            // Springs read the substep's starting state, as gravity and the forces do: read
            // after gravity's kick, a dashpot resisted it and a hanging body sagged (1 − c·h)
            // times its g/k (half of it at the damping bound).
            if !springs.is_empty() {
                self.apply_springs(bodies, &springs, h);
            }
            integrate_velocities(bodies, h);
            flip = !flip;
            // Joints before contacts, as Box2D: the contacts, solved last, win a conflict.
            self.joints.warm_start(&mut bodies.states);
            self.warm_start(bodies, flip);
            self.solve_joints(bodies, joint_soft, h, true);
            self.solve_contacts(bodies, inv_h, true, (flip, share));
            integrate_positions(bodies, h, s.max_rotation_per_substep, s.max_linear_speed);
            let (constraints, batches) = (&mut self.constraints, &mut self.batches);
            if self.turned_rows.refresh(bodies, constraints, batches) {
                let turned = self.turned_rows.turned();
                self.joints.take_turned_inertia(&bodies.params, turned);
            }
            self.joints.refresh(&bodies.states);
            for pass in 0..s.relax_iterations.max(s.joint_relax_iterations) {
                if pass < s.joint_relax_iterations {
                    self.solve_joints(bodies, joint_soft, h, false);
                }
                if pass < s.relax_iterations {
                    self.solve_contacts(bodies, inv_h, false, (flip, share));
                }
            }
        }
        self.joints.store();
        self.batches.unpack(&mut self.constraints);
        for c in &mut self.constraints {
            c.restitute(&mut bodies.states, s.restitution_threshold);
        }
        self.cap_velocities(bodies, inv_h);
        let orientations = &bodies.orientations;
        self.cache
            .store(&self.constraints, |a| orientations[a as usize], h);
        self.stable_springs = springs;
    }

    /// Prepares the step's joints, holding the impulses each carries into the step to what
    /// could change a body's velocity by [`WARM_START_BOUND`] times the speed and spin bounds
    /// (see `JointList::bound_impulses`).
    fn prepare_joints(&mut self, bodies: &SolverBodies, joints: &[JointInput], inv_h: f32) {
        let s = &self.stepping;
        let max_speed = WARM_START_BOUND * s.max_linear_speed;
        let max_spin = WARM_START_BOUND * s.max_rotation_per_substep * inv_h;
        self.bounded_joints = self.joints.prepare(bodies, joints, (max_speed, max_spin));
    }

    /// The relax passes and the bounces after the last move can still speed a dynamic body
    /// up: the step hands out no speed or spin above the bounds either (a spin above
    /// `max_rotation_per_substep / h` could not be followed by the next step anyway).
    fn cap_velocities(&self, bodies: &mut SolverBodies, inv_h: f32) {
        let s = &self.stepping;
        let max_spin = s.max_rotation_per_substep * inv_h;
        for (state, p) in bodies.states.iter_mut().zip(&bodies.params) {
            if p.dynamic {
                state.linear_velocity = capped(state.linear_velocity, s.max_linear_speed);
                state.angular_velocity = capped(state.angular_velocity, max_spin);
            }
        }
    }

    /// One pass over the joints, biased or relaxing.
    fn solve_joints(&mut self, bodies: &mut SolverBodies, soft: Softness, h: f32, bias: bool) {
        self.joints.solve(&mut bodies.states, soft, h, bias);
    }

    /// How many springs of the last step were too stiff or too damped for the substep and were
    /// lowered to the stable bound ([`Spring::clamped_to_stability`]).
    pub fn clamped_springs(&self) -> usize {
        self.clamped_springs
    }

    /// How many joints carried impulses into the last step that were not finite or could have
    /// changed a body's velocity by more than twice the speed or spin bound, and were dropped
    /// or scaled down (`joint_list.rs`, `JointList::bound_impulses`). Joints that keep tripping
    /// it fight each other or carry far more than their bodies can take.
    pub fn bounded_joints(&self) -> usize {
        self.bounded_joints
    }

    /// Copies `springs` into the step's list, each lowered into the range a substep `h` can
    /// follow given its ends' inverse masses: past it a spring does not get stiffer, it
    /// diverges, and flings what it holds into its neighbours.
    fn stabilise_springs(&mut self, bodies: &SolverBodies, springs: &[Spring], h: f32) {
        self.stable_springs.clear();
        self.clamped_springs = 0;
        let n = bodies.params.len();
        // The largest `1/m` of any free axis: the bound is the stiffest the spring may be
        // along any direction it can pull.
        let inverse_mass = |i: usize| (i < n).then(|| bodies.params[i].inverse_mass.max_element());
        for spring in springs {
            let other = match spring.other {
                SpringEnd::Body(j) => inverse_mass(j),
                SpringEnd::Anchor(_) => Some(0.0),
            };
            let w = inverse_mass(spring.body)
                .zip(other)
                .map_or(0.0, |(a, b)| a + b);
            self.stable_springs
                .push(match spring.clamped_to_stability(w, h) {
                    Some(stable) => {
                        self.clamped_springs += 1;
                        stable
                    }
                    None => *spring,
                });
        }
    }

    /// Each spring's impulse for one substep, from the bodies' state now; an end past the
    /// bodies (a bad slot) is skipped.
    fn apply_springs(&mut self, bodies: &mut SolverBodies, springs: &[Spring], h: f32) {
        let (centers, velocities) = &mut self.spring_state;
        centers.clear();
        velocities.clear();
        for (i, state) in bodies.states.iter().enumerate() {
            centers.push(bodies.centers[i] + state.delta_position);
            velocities.push(state.linear_velocity);
        }
        let n = centers.len();
        for spring in springs {
            let other = match spring.other {
                SpringEnd::Body(j) => Some(j),
                SpringEnd::Anchor(_) => None,
            };
            if spring.body >= n || other.is_some_and(|j| j >= n) {
                continue;
            }
            let f = ForceModel::spring_force(spring, centers, velocities) * h;
            push(bodies, spring.body, f);
            if let Some(j) = other {
                push(bodies, j, -f);
            }
        }
    }

    /// The batches of the last step and the contacts they hold (at most four each): how well
    /// the lanes were filled.
    pub fn batch_fill(&self) -> (usize, usize) {
        let contacts = self.constraints.len() - self.batching.one_by_one().len();
        (self.batches.len(), contacts)
    }

    /// Applies every contact's accumulated impulses: the batches, then the rest.
    fn warm_start(&mut self, bodies: &mut SolverBodies, flip: bool) {
        self.batches.warm_start(&mut bodies.states);
        for &i in self.batching.one_by_one() {
            let c = &mut self.constraints[i as usize];
            c.flip = flip;
            c.warm_start(&mut bodies.states);
        }
    }

    /// One pass over every contact, batch by batch and then the rest one at a time: biased
    /// (push-out) or relaxing (no bias, friction aiming at `share` of its drift targets);
    /// `flip` visits each contact's points backwards.
    fn solve_contacts(
        &mut self,
        bodies: &mut SolverBodies,
        inv_h: f32,
        use_bias: bool,
        (flip, share): (bool, f32),
    ) {
        let push = (inv_h, self.stepping.max_push_out);
        let states = &mut bodies.states;
        self.batches.solve(states, push, use_bias, flip, share);
        for &i in self.batching.one_by_one() {
            self.constraints[i as usize].solve(states, push, use_bias, share);
        }
    }

    /// Builds this step's constraints (a step of `dt` in substeps of `h`) and seeds them from
    /// the cache.
    fn prepare(&mut self, bodies: &SolverBodies, contacts: &[ContactInput], (h, dt): (f32, f32)) {
        let s = self.stepping;
        let soft = Softness::new(s.contact_hertz, s.damping_ratio, h);
        let static_soft = Softness::new(s.static_contact_hertz, s.damping_ratio, h);
        // A dynamic body locked on every axis is as immovable as a static one, and its
        // contacts as stiff.
        let softness = |c: &ContactInput| {
            let immovable = |i: u32| bodies.params[i as usize].is_immovable();
            RowSettings {
                softness: if immovable(c.a) || immovable(c.b) {
                    static_soft
                } else {
                    soft
                },
                friction: s.friction,
                step: dt,
            }
        };
        let (centers, states, params) = (&bodies.centers, &bodies.states, &bodies.params);
        // Last step's constraints are refilled in place; only new places are built.
        let reused = self.constraints.len().min(contacts.len());
        self.constraints.truncate(reused);
        for (c, input) in self.constraints.iter_mut().zip(contacts) {
            c.refill(input, centers, states, params, softness(input));
        }
        self.constraints.extend(
            contacts[reused..]
                .iter()
                .map(|c| ContactConstraint::prepare(c, centers, states, params, softness(c))),
        );
        let orientations = &bodies.orientations;
        self.cache.seed(
            &mut self.constraints,
            |a| orientations[a as usize],
            h,
            s.warm_start_distance,
        );
        self.batching.pack(&self.constraints, bodies.len());
        let constraints = &self.constraints;
        let packed = self.batches.pack(self.batching.batches(), constraints);
        debug_assert!(packed, "the packing hands out 1 to 4 valid indices");
    }
}

/// Adds `impulse` to body `i`'s momentum, if it is dynamic.
fn push(bodies: &mut SolverBodies, i: usize, impulse: Vec3) {
    let p = &bodies.params[i];
    if p.dynamic {
        bodies.states[i].linear_velocity += impulse * p.inverse_mass;
    }
}
