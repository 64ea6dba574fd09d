//! # urto — collision detection and rigid-body dynamics for Bevy-style ECS games
//!
//! urto implements the lecture *Scene dinamiche e Collision detection* (F. Ganovelli): a fixed
//! step with a choice of integrators, sweep-and-prune broad phase, bounding-volume hierarchies
//! in the narrow phase, reflection/impulse response, and debug recordings for the rerun viewer.
//!
//! Two layers, data flowing one way:
//! - the **algorithm core** — [`geometry`], [`bounding`], [`dynamics`], [`spatial`], [`clock`] — plain Rust
//!   and glam, no ECS: every algorithm is testable and benchmarkable alone;
//! - the **ECS layer** — `components`, `schedule`, `plugins`, `debug` (the `ecs` feature, on by
//!   default) — thin `bevy_ecs` systems that gather components, call the core, and write back.
//!
//! Features: `ecs` (the Bevy layer), `mesh-io` (OBJ, STL and PLY loading) and `rerun` (debug
//! recordings) are on by default; `default-features = false, features = ["core"]` builds the
//! algorithm core alone on glam (its types re-exported as [`math`]), as parry is used.
//!
//! The core alone, as a library (this runs the same with `features = ["core"]`):
//!
//! ```
//! use urto::geometry::{contacts::contact, Isometry, Shape};
//! use urto::math::{Quat, Vec3};
//!
//! let ball = Shape::sphere(0.5);
//! let crate_ = Shape::cuboid(Vec3::splat(0.5));
//! let tilted = Isometry::new(Vec3::new(0.0, 0.0, 0.9), Quat::from_rotation_x(0.3));
//! let touch = contact(&crate_, &Isometry::default(), &ball, &tilted).expect("they overlap");
//! assert!(touch.max_depth() > 0.0 && touch.normal.z > 0.9);
//! ```
#![cfg_attr(
    feature = "ecs",
    doc = r#"
The ECS layer (the `ecs` feature), a ball dropped on a floor:

```
use bevy_app::App;
use urto::prelude::*;

let mut app = App::new();
app.add_plugins(UrtoPlugins::default()).insert_resource(Gravity::EARTH_Z_UP);
app.world_mut().spawn((Collider::half_space(glam::Vec3::Z), Static));
let ball = app
    .world_mut()
    .spawn((Collider::sphere(0.5), Position::new(0.0, 0.0, 2.0), Velocity::default()))
    .id();
urto::step(app.world_mut(), 120).unwrap();
let z = app.world().get::<Position>(ball).unwrap().0.z;
assert!(z > 0.4 && z < 2.0);
```
"#
)]
// Every public item says what it is (the public-surface audit of issue 11); clippy's
// `-D warnings` in CI turns a missing doc into an error.
#![warn(missing_docs)]
// The core's docs point to its ECS face (`Collider`, `SpatialQuery`…), which a core-only build
// leaves out: those links cannot resolve there, and only there.
#![cfg_attr(not(feature = "ecs"), allow(rustdoc::broken_intra_doc_links))]

pub mod bounding;
pub mod broad_phase;
pub mod bvh;
pub mod ccd;
pub mod clock;
#[cfg(feature = "ecs")]
pub mod components;
#[cfg(feature = "ecs")]
pub mod debug;
pub mod dynamics;
pub mod geometry;
pub mod hierarchy;
mod pair_hash;
#[cfg(feature = "ecs")]
pub mod plugins;
#[cfg(feature = "ecs")]
pub mod schedule;
pub mod settings;
pub mod spatial;
#[cfg(feature = "ecs")]
pub mod stats;
#[cfg(test)]
mod test_rng;

#[cfg(feature = "ecs")]
pub use plugins::{UrtoPlugins, step, step_app};

/// The crates urto's API is made of, re-exported so a game uses the very versions urto was
/// built with (a second `glam` in the dependency tree makes `Vec3` two different types).
pub mod reexports {
    #[cfg(feature = "ecs")]
    pub use bevy_app;
    #[cfg(feature = "ecs")]
    pub use bevy_ecs;
    #[cfg(feature = "ecs")]
    pub use bevy_time;
    #[cfg(feature = "ecs")]
    pub use bevy_transform;
    pub use glam;
}

/// The vector, quaternion and matrix types of every core signature (glam's, re-exported), so a
/// program using the core alone names them as `urto::math::Vec3` without its own glam.
pub mod math {
    pub use glam::{Mat3, Quat, Vec2, Vec3, Vec3A, Vec4};
}
pub use settings::{
    ContactSettings, Gravity, Integration, LengthUnit, PhysicsTimestep, SettingsError,
};

/// What a game needs in scope.
#[cfg(feature = "ecs")]
pub mod prelude {
    pub use crate::components::*;
    pub use crate::dynamics::Integrator;
    pub use crate::dynamics::solver::{FrictionModel, SoftStepSettings};
    pub use crate::plugins::{
        CollisionEnd, CollisionEnded, CollisionEventsEnabled, CollisionStart, CollisionStarted,
        ContactData, PointProjection, RayHit, SoftStepPlugin, SpatialQuery, SpatialQueryFilter,
        TransformInterpolation, UrtoPlugins,
    };
    pub use crate::schedule::{PhysicsSchedule, PhysicsSet, SubstepSchedule, SubstepSet};
    pub use crate::settings::*;
    pub use crate::stats::{PhysicsStats, Stage};
    /// `UrtoPlugins::default().set(..)` and `.disable::<..>()` need the trait in scope.
    pub use bevy_app::PluginGroup;
}

/// The README's code blocks, compiled and run as doctests so that the README stays true.
#[cfg(all(doctest, feature = "rerun"))]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
