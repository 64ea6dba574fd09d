//! The physics step as a schedule of chained, named system sets.
//!
//! One run of [`PhysicsSchedule`] is one fixed step `dt` (the slides' `simulate(dt)`):
//!
//! 1. [`PhysicsSet::Prepare`] — validate new or changed bodies (quarantine NaN, bad mass, bad
//!    shapes), compute the mass and inertia of changed bodies, propagate poses down body
//!    hierarchies.
//! 2. [`PhysicsSet::Forces`] — gather gravity (scaled per body), user forces, drag and springs
//!    into the step's force model (each only when the world has it), and apply impulses to
//!    velocities at once.
//! 3. [`PhysicsSet::Substeps`] — run [`SubstepSchedule`] `substeps` times with `dt / substeps`
//!    (the slides' brute-force cure for late contacts and tunnelling):
//!    1. [`SubstepSet::Integrate`] — advance positions and velocities, then orientations and
//!       angular velocities.
//!    2. [`SubstepSet::BroadPhase`] — propagate world poses down hierarchies, refit bounding
//!       volumes up them (only where something moved), update the broad-phase structures, list
//!       candidate pairs ([`BroadPhaseSystems`]).
//!    3. [`SubstepSet::NarrowPhase`] — exact tests on the candidates, producing contacts.
//!    4. [`SubstepSet::Response`] — impulses and position correction; collision messages.
//! 4. [`PhysicsSet::Finish`] — world poses and bounding volumes follow the positions the
//!    response left, so game code and debug output read a consistent state.
//! 5. [`PhysicsSet::Debug`] — consumers of the finished step (the rerun recording). Nothing
//!    after it reads what they write, so turning debug output off changes no result.
//!
//! In a Bevy `App` the schedule runs once per `FixedPostUpdate` (Bevy's fixed-timestep loop is
//! the accumulator); a standalone [`World`](bevy_ecs::world::World) is stepped with
//! [`step`](crate::step).

use bevy_ecs::schedule::{ScheduleLabel, SystemSet};

/// One fixed physics step.
#[derive(ScheduleLabel, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PhysicsSchedule;

/// One substep, run `substeps` times inside [`PhysicsSet::Substeps`].
#[derive(ScheduleLabel, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SubstepSchedule;

/// The sets of [`PhysicsSchedule`], chained in this order.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PhysicsSet {
    /// Validation and pose propagation.
    Prepare,
    /// Force gathering.
    Forces,
    /// The substep loop.
    Substeps,
    /// Derived state (world poses, bounding volumes) brought up to date with the final positions.
    Finish,
    /// Debug output (read-only consumers).
    Debug,
}

/// The steps of [`SubstepSet::BroadPhase`], chained in this order.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BroadPhaseSystems {
    /// World poses propagate down hierarchies.
    Poses,
    /// Bounding volumes refit up hierarchies, only along changed paths.
    Refit,
    /// The broad-phase structures follow the world (insert, move, remove).
    Index,
    /// Candidate pairs are listed.
    Pairs,
}

/// The sets of [`SubstepSchedule`], chained in this order.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SubstepSet {
    /// Time integration.
    Integrate,
    /// Bounding-volume refit and candidate pairs.
    BroadPhase,
    /// Contacts of the candidate pairs.
    NarrowPhase,
    /// Collision response.
    Response,
}
