//! The ECS layer: one plugin per stage of the step, gathered in [`UrtoPlugins`].
//!
//! Each plugin is a thin adapter: its systems gather components into plain arrays, call the
//! algorithm core, and write the results back. Any stage can be disabled or replaced:
//!
//! ```
//! # use bevy_app::{App, PluginGroup};
//! # use urto::prelude::*;
//! # use urto::plugins::ResponsePlugin;
//! let mut app = App::new();
//! // Detect contacts, but let game code respond to them.
//! app.add_plugins(UrtoPlugins::default().build().disable::<ResponsePlugin>());
//! ```

pub mod broad_phase;
pub mod ccd;
mod collision_data;
mod collision_messages;
pub mod core;
pub mod forces;
pub mod hierarchy;
pub mod integration;
pub mod interpolation;
pub mod joints;
pub mod mass_properties;
pub mod narrow_phase;
mod plain_parents;
mod proxy_table;
mod required_resources;
pub mod response;
mod restored_state;
pub mod rotation;
mod settings_check;
pub(crate) mod settle;
pub mod sleep;
pub mod soft_step;
pub mod spatial_query;
mod step_app;
mod table_ticks;
pub mod transform_sync;
pub mod validation;
mod wake_on_joints;
mod wake_on_scenery;
mod wake_on_writes;

pub use broad_phase::{BroadPhaseFactory, BroadPhaseIndex, BroadPhasePairs, BroadPhasePlugin};
pub use ccd::{CcdImpacts, CcdPlugin, CcdSettings};
pub use core::{PhysicsCorePlugin, StepError, step};
pub use forces::{ForcesPlugin, GatheredForces};
pub use hierarchy::HierarchyPlugin;
pub use integration::IntegrationPlugin;
pub use interpolation::{InterpolationPlugin, PreviousPose, TransformInterpolation};
pub use joints::{JointPlugin, JointedPairs};
pub use mass_properties::MassPropertiesPlugin;
pub use narrow_phase::{ContactHooks, ContactPair, Contacts, NarrowPhasePlugin};
pub use response::{
    CollisionEnd, CollisionEnded, CollisionEventsEnabled, CollisionStart, CollisionStarted,
    ContactData, ReportCollisions, ResponsePlugin,
};
pub use rotation::RotationPlugin;
pub use sleep::SleepPlugin;
pub use soft_step::{SoftStepPlugin, SoftStepSolver, SolveBodies, SpeculativeMargin};
pub use spatial_query::{
    IndexRefreshes, PointProjection, RayHit, SpatialQuery, SpatialQueryFilter, SpatialQueryIndex,
    SpatialQueryPlugin,
};
pub use step_app::step_app;
pub use transform_sync::TransformSyncPlugin;
pub use validation::ValidationPlugin;

use crate::settings::PhysicsTimestep;
use bevy_app::{PluginGroup, PluginGroupBuilder};

/// Every stage of urto in schedule order; `app.add_plugins(UrtoPlugins::default())`.
///
/// [`SoftStepPlugin`] (the rigid-body solver: contacts that turn bodies) is in the group and on.
/// Change its settings with `UrtoPlugins::default().set(SoftStepPlugin { settings })`; the
/// lecture's pipeline (integration and impulse response in every substep, bodies that contacts
/// do not turn) runs with `UrtoPlugins::default().build().disable::<SoftStepPlugin>()`.
///
/// The rerun recording is not in the group because it needs a destination that can fail to
/// open: add `urto::debug::RerunDebugPlugin` (the `rerun` feature) separately.
#[derive(Debug, Clone, Default)]
pub struct UrtoPlugins {
    /// The fixed step (default 60 Hz, one substep).
    pub timestep: Option<PhysicsTimestep>,
}

impl UrtoPlugins {
    /// The group with a given fixed step.
    pub fn with_timestep(timestep: PhysicsTimestep) -> Self {
        Self {
            timestep: Some(timestep),
        }
    }
}

impl PluginGroup for UrtoPlugins {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>()
            .add(PhysicsCorePlugin {
                timestep: self.timestep,
            })
            .add(ValidationPlugin)
            .add(ForcesPlugin)
            .add(IntegrationPlugin)
            .add(MassPropertiesPlugin)
            .add(RotationPlugin)
            .add(HierarchyPlugin)
            .add(BroadPhasePlugin::default())
            .add(CcdPlugin)
            .add(NarrowPhasePlugin)
            .add(SoftStepPlugin::default())
            .add(JointPlugin)
            .add(ResponsePlugin)
            .add(SleepPlugin)
            .add(TransformSyncPlugin)
            .add(InterpolationPlugin)
            .add(SpatialQueryPlugin)
    }
}
