//! The core plugin: schedules, settings, statistics, and the two ways a step is driven —
//! Bevy's fixed-timestep loop in an `App`, or [`step`] on a standalone world.

use crate::plugins::broad_phase::BroadPhasePairs;
use crate::plugins::ccd::CcdSettings;
use crate::plugins::forces::GatheredForces;
use crate::plugins::narrow_phase::{Contacts, HierarchyVisits, OverlappingLeaves, SensorOverlaps};
use crate::plugins::required_resources::{RequireResource, restore_required_resources};
use crate::plugins::settings_check::check_settings;
use crate::plugins::settle::{StillRevision, settle_statics, unsettle_written};
use crate::plugins::soft_step::SpeculativeMargin;
use crate::plugins::transform_sync::ReadGameTransforms;
use crate::schedule::{
    BroadPhaseSystems, PhysicsSchedule, PhysicsSet, SubstepSchedule, SubstepSet,
};
use crate::settings::SleepSettings;
use crate::settings::{ContactSettings, Integration, LengthUnit, PhysicsTimestep};
use crate::stats::PhysicsStats;
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::SingleThreadedExecutor;
use bevy_time::{Fixed, Time};
use std::fmt;
use std::time::Duration;

/// Builds the schedules and inserts the settings every other stage reads.
#[derive(Debug, Clone, Default)]
pub struct PhysicsCorePlugin {
    /// The fixed step; `None` keeps a [`PhysicsTimestep`] already in the world, else the default.
    pub timestep: Option<PhysicsTimestep>,
}

impl Plugin for PhysicsCorePlugin {
    fn build(&self, app: &mut App) {
        // Removed by game code, the timestep comes back as the plugin was built with it.
        let ts = self.timestep.unwrap_or_else(|| {
            app.world()
                .get_resource::<PhysicsTimestep>()
                .copied()
                .unwrap_or_default()
        });
        app.insert_required(move || ts)
            .init_required::<Integration>()
            .init_required::<ContactSettings>()
            .init_required::<LengthUnit>()
            .init_required::<PhysicsStats>()
            .insert_resource(CoreInstalled);
        // What one stage writes and another reads belongs to neither: any stage can be
        // disabled or replaced and the others still find their inputs (empty).
        app.init_required::<GatheredForces>()
            .init_required::<BroadPhasePairs>()
            .init_required::<Contacts>()
            .init_required::<SensorOverlaps>()
            .init_required::<OverlappingLeaves>()
            .init_required::<HierarchyVisits>()
            .init_required::<StillRevision>();

        // Single-threaded executors: the step is a strict chain, and one thread keeps runs
        // bit-for-bit reproducible whatever the machine's thread count.
        let mut physics = Schedule::new(PhysicsSchedule);
        physics.set_executor(SingleThreadedExecutor::new());
        physics.configure_sets(
            (
                PhysicsSet::Prepare,
                PhysicsSet::Forces,
                PhysicsSet::Substeps,
                PhysicsSet::Finish,
                PhysicsSet::Debug,
            )
                .chain(),
        );
        physics.add_systems((
            (
                restore_required_resources,
                begin_step,
                check_settings::<ContactSettings>,
                check_settings::<SleepSettings>,
                check_settings::<CcdSettings>,
                check_settings::<SpeculativeMargin>,
            )
                .chain()
                .in_set(PhysicsSet::Prepare)
                .before(PrepareWake),
            run_substeps.in_set(PhysicsSet::Substeps),
            // Before the game's `Transform`s are read: that scan leaves settled bodies out.
            unsettle_written
                .in_set(PhysicsSet::Prepare)
                .before(ReadGameTransforms)
                .before(PrepareWake),
            settle_statics.after(PhysicsSet::Debug),
        ));
        physics.configure_sets(
            (PrepareWake, PrepareStart, PrepareIndex)
                .chain()
                .in_set(PhysicsSet::Prepare),
        );
        app.add_schedule(physics);

        let mut substep = Schedule::new(SubstepSchedule);
        substep.set_executor(SingleThreadedExecutor::new());
        substep.configure_sets(
            (
                SubstepSet::Integrate,
                SubstepSet::BroadPhase,
                SubstepSet::NarrowPhase,
                SubstepSet::Response,
            )
                .chain(),
        );
        substep.configure_sets(
            (
                BroadPhaseSystems::Poses,
                BroadPhaseSystems::Refit,
                BroadPhaseSystems::Index,
                BroadPhaseSystems::Pairs,
            )
                .chain()
                .in_set(SubstepSet::BroadPhase),
        );
        app.add_schedule(substep);

        app.init_resource::<StepsThisFrame>()
            .add_systems(FixedFirst, cap_catch_up)
            .add_systems(FixedPostUpdate, run_physics_in_fixed_update)
            .add_systems(PreUpdate, set_fixed_clock);
    }

    fn finish(&self, app: &mut App) {
        if let Some(ts) = app.world().get_resource::<PhysicsTimestep>().copied() {
            set_clocks(app.world_mut(), &ts);
        }
    }
}

/// In an App, Bevy's fixed clock is the accumulator: give it our dt.
fn set_clocks(world: &mut World, ts: &PhysicsTimestep) {
    if let Some(mut fixed) = world.get_resource_mut::<Time<Fixed>>() {
        fixed.set_timestep(Duration::from_secs_f32(ts.dt()));
    }
}

/// The fixed steps run in this frame so far.
#[derive(Resource, Default)]
struct StepsThisFrame(u32);

/// At most [`PhysicsTimestep::max_steps_per_frame`] steps a frame: at the start of the last
/// step the cap allows, the whole steps still owed to the fixed clock are dropped, so Bevy's
/// fixed loop ends after it. The game's own clock is left alone: urto used to cap `Time<Virtual>`'s
/// `max_delta` at the cap instead, which slowed every `Update` system too (a 250 ms hitch
/// advanced the game's time by 67 ms; a user-style probe).
fn cap_catch_up(
    mut steps: ResMut<StepsThisFrame>,
    timestep: Option<Res<PhysicsTimestep>>,
    mut fixed: ResMut<Time<Fixed>>,
) {
    steps.0 += 1;
    let cap = timestep.map_or(u32::MAX, |ts| ts.max_steps_per_frame());
    if steps.0 >= cap {
        // Whole steps only: the fraction of a step left over is the next frame's, as it is
        // below the cap (and the interpolation's blend reads it).
        let (owed, step) = (
            fixed.overstep().as_nanos(),
            fixed.timestep().as_nanos().max(1),
        );
        let whole = owed - owed % step;
        fixed.discard_overstep(Duration::from_nanos(whole as u64));
    }
}

/// Before each frame's fixed loop: a [`PhysicsTimestep`] that is new or changed sets Bevy's
/// fixed clock. `finish()` does this too, but a hand-written `app.update()` loop never calls it,
/// and Bevy's default 64 Hz then ran the physics instead of the configured rate. Without
/// `Time<Fixed>` (no `TimePlugin`) the fixed loop never runs: a warning says so, once.
fn set_fixed_clock(world: &mut World, mut warned: Local<bool>) {
    if !world.contains_resource::<Time<Fixed>>() {
        if !*warned {
            *warned = true;
            log::warn!(
                "urto: no Time<Fixed> (add bevy_time's TimePlugin): Bevy's fixed loop never \
                 runs, so no physics step will; or step the world with urto::step"
            );
        }
        return;
    }
    let changed = world
        .get_resource_ref::<PhysicsTimestep>()
        .filter(|ts| ts.is_changed())
        .map(|ts| *ts);
    if let Some(ts) = changed {
        set_clocks(world, &ts);
    }
    if let Some(mut steps) = world.get_resource_mut::<StepsThisFrame>() {
        steps.0 = 0;
    }
}

/// Prepare's first part: sleeping bodies that game code touched wake, with their islands, so
/// that everything after sees them awake (their `Sleeping` marker gone).
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PrepareWake;

/// Anchor for Prepare's validation: it runs after the step's bookkeeping and the wake-ups.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PrepareStart;

/// Prepare's second half: poses, volumes and the broad-phase index follow what game code did
/// between steps (spawns, teleports), after validation set bad bodies aside.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PrepareIndex;

fn begin_step(mut stats: ResMut<PhysicsStats>) {
    stats.begin_step();
}

/// Runs the substep schedule `substeps` times and advances the step counters.
fn run_substeps(world: &mut World) {
    let ts = *world.resource::<PhysicsTimestep>();
    let _ = world.try_schedule_scope(SubstepSchedule, |world, schedule| {
        for _ in 0..ts.substeps() {
            schedule.run(world);
            world.resource_mut::<PhysicsStats>().sim_time += ts.substep_dt() as f64;
        }
    });
    world.resource_mut::<PhysicsStats>().step += 1;
}

/// In an `App`: one physics step per fixed tick, with dt taken from Bevy's fixed clock.
fn run_physics_in_fixed_update(world: &mut World) {
    let fixed_dt = world.resource::<Time>().delta_secs();
    // Removed by game code, the timestep is made again by the schedule's first system.
    let Some(mut ts) = world.get_resource_mut::<PhysicsTimestep>() else {
        world.run_schedule(PhysicsSchedule);
        return;
    };
    if (ts.dt() - fixed_dt).abs() > f32::EPSILON * ts.dt()
        && let Err(e) = ts.set_dt(fixed_dt)
    {
        log::warn!("urto: skipping a physics step: {e}");
        return;
    }
    world.run_schedule(PhysicsSchedule);
}

/// Marks a world built with [`PhysicsCorePlugin`]: [`step`] refuses a world without it (the
/// other stages' systems would find none of the resources they share).
#[derive(Resource)]
pub(crate) struct CoreInstalled;

/// Why [`step`] could not run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepError {
    /// The world has no physics schedule: add [`UrtoPlugins`](crate::UrtoPlugins) (with its
    /// [`PhysicsCorePlugin`]) to the app whose world is stepped.
    NoPhysicsSchedule,
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the world has no PhysicsSchedule: add UrtoPlugins to its App first")
    }
}

impl std::error::Error for StepError {}

/// Steps a world `n` times, outside any `App` loop (tests, examples, servers, offline runs).
///
/// ```
/// # use bevy_app::App;
/// # use urto::prelude::*;
/// let mut app = App::new();
/// app.add_plugins(UrtoPlugins::default());
/// app.world_mut().spawn((Collider::sphere(0.5), Position::new(0.0, 0.0, 2.0), Velocity::default()));
/// urto::step(app.world_mut(), 60).unwrap();
/// ```
pub fn step(world: &mut World, n: u32) -> Result<(), StepError> {
    if !world.contains_resource::<CoreInstalled>() {
        return Err(StepError::NoPhysicsSchedule);
    }
    for _ in 0..n {
        world
            .try_run_schedule(PhysicsSchedule)
            .map_err(|_| StepError::NoPhysicsSchedule)?;
        crate::plugins::collision_messages::update_collision_messages(world);
    }
    Ok(())
}
