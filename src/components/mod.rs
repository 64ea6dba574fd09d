//! The state urto reads and writes, as ECS components (the slides' "Lo stato": position,
//! velocity, then mass and force).
//!
//! Spawning a body is one line thanks to `#[require]`:
//!
//! ```
//! # use bevy_ecs::prelude::*;
//! # use urto::prelude::*;
//! # let mut world = World::new();
//! // A dynamic ball: Velocity, ComputedMass (from its volume at 1 kg/m³), Rotation,
//! // AngularVelocity, Inertia and BoundingVolume come by default.
//! world.spawn((Collider::sphere(0.5), Position::new(0.0, 0.0, 3.0), Velocity::default()));
//! // Static scenery: never moves, collides as infinitely heavy.
//! world.spawn((Collider::half_space(glam::Vec3::Z), Static));
//! ```
//!
//! # Kinds of body
//! - **dynamic**: has [`Velocity`] and a finite mass (from its colliders' volume at its
//!   [`Density`], or a [`Mass`] it is given); forces and contacts move it.
//! - **kinematic**: has [`Velocity`] and [`Mass::INFINITE`]; it moves at its velocity, pushes
//!   dynamic bodies and is never pushed back.
//! - **static**: has the [`Static`] marker (or no [`Velocity`]); never moves, collides as
//!   infinitely heavy. Unbounded shapes (half-spaces) are always static.
//!
//! Bodies whose numbers are unusable (NaN, zero or negative mass, a bad shape) are set aside with
//! a [`Quarantined`] marker and a logged warning: they stop taking part, and nothing they hold can
//! spread to their neighbours.

mod angular;
mod impulse;
mod joint;
mod kinematic_target;
mod mass;
mod point_sum;
mod sleeping;

pub use angular::{AngularDrag, AngularVelocity, ForceAtPoint, Inertia, LockedAxes, Torque};
pub use impulse::{GravityScale, Impulse};
pub use joint::{
    Joint, JointBroken, JointDisabled, JointEnd, JointKind, JointLimit, JointLoad, JointMotor,
};
pub use kinematic_target::KinematicTarget;
pub use mass::{ComputedMass, DEFAULT_DENSITY, Density, Mass};
pub(crate) use sleeping::SleepTransitions;
pub use sleeping::{SleepState, Sleeping, SleepingDisabled, SleepingIslands};

use crate::bounding::Aabb;
#[cfg(feature = "mesh-io")]
use crate::geometry::convex::HullFileError;
use crate::geometry::{HullError, Isometry, MeshCollider, MeshColliderError, Shape, TriMesh};
pub use crate::spatial::{LayerMask, Layers};
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

/// Where a body is: the position of its origin (centre of mass) in its parent's frame — the
/// world for a body without [`ChildOf`], the parent body for a
/// part of a compound (a wheel of a car, a link of an arm).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[require(Rotation, GlobalPose, BoundingVolume)]
#[component(summary_tick)]
pub struct Position(pub Vec3);

impl Position {
    /// A position from coordinates.
    pub const fn new(x: f32, y: f32, z: f32) -> Self {
        Self(Vec3::new(x, y, z))
    }
}

/// Orientation of a body in its parent's frame (see [`Position`]); identity when absent. A
/// dynamic body turns with its [`AngularVelocity`] (and the torques that change it); set it to
/// place boxes and planes. Contacts still act through the centre of mass: they do not yet turn
/// bodies (the rigid-body solver of issue 10, stage 4).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct Rotation(pub Quat);

impl Rotation {
    /// The orientation of a body that may have no `Rotation` (the identity then).
    pub fn of(rotation: Option<&Rotation>) -> Quat {
        rotation.map_or(Quat::IDENTITY, |r| r.0)
    }
}

/// Linear velocity of the centre of mass (m/s). Brings what a dynamic body needs, including an
/// [`AngularVelocity`] and a computed [`Inertia`]: dynamic bodies turn by default.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[require(Position, Rotation, ComputedMass, SleepState, AngularVelocity, Inertia)]
#[component(summary_tick)]
pub struct Velocity(pub Vec3);

impl Velocity {
    /// A velocity from components.
    pub const fn new(x: f32, y: f32, z: f32) -> Self {
        Self(Vec3::new(x, y, z))
    }
}

/// Force (N) applied during the next physics step, then cleared: game code adds to it, the step
/// consumes it. Bodies without it cost the force stage nothing.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct Force(pub Vec3);

/// Linear drag coefficient `b` (N·s/m): the force `-b v`.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct LinearDrag(pub f32);

/// What the far end of a [`Spring`] holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpringTarget {
    /// Another body.
    Entity(Entity),
    /// A fixed point in the world.
    Point(Vec3),
}

/// A damped spring from this body to a target.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// The far end.
    pub target: SpringTarget,
    /// Length at which it exerts no force (m).
    pub rest_length: f32,
    /// Stiffness (N/m).
    pub stiffness: f32,
    /// Damping along the spring's axis (N·s/m).
    pub damping: f32,
}

/// How much of the approach speed a contact gives back (0 = dead stop, 1 = perfect bounce).
/// The pair uses the average of its two bodies' values; absent means
/// [`ContactSettings::default_restitution`](crate::ContactSettings).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[component(summary_tick)]
pub struct Restitution(pub f32);

/// Coulomb friction coefficient (0 = ice). The pair uses the geometric mean of its two bodies'
/// values, so ice on anything slides; absent means
/// [`ContactSettings::default_friction`](crate::ContactSettings).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[component(summary_tick)]
pub struct Friction(pub f32);

/// Rolling resistance (m): the lever arm `b` of the torque, at most `b` times the normal force,
/// with which a contact resists rolling (a few millimetres for a hard ball on a hard floor;
/// see [`crate::dynamics::solver::rolling`]). The pair uses the larger of its two bodies'
/// values (as Box2D); absent means 0. Applied by the rigid-body solver
/// ([`SoftStepPlugin`](crate::plugins::SoftStepPlugin)); a negative or non-finite value counts
/// as 0.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct RollingResistance(pub f32);

/// The shape a body collides with, in the body's frame.
#[derive(Component, Clone, Debug, PartialEq)]
#[require(Position)]
#[component(summary_tick)]
pub struct Collider {
    /// The shape.
    pub shape: Shape,
}

impl Collider {
    /// A ball of `radius`.
    pub fn sphere(radius: f32) -> Self {
        Self {
            shape: Shape::sphere(radius),
        }
    }

    /// A box of the given half extents.
    pub fn cuboid(hx: f32, hy: f32, hz: f32) -> Self {
        Self {
            shape: Shape::cuboid(Vec3::new(hx, hy, hz)),
        }
    }

    /// A capsule along the body's local z axis (standing up when unrotated): `half_length` from
    /// the centre to each cap's centre, and `radius`. Characters and limbs are capsules.
    pub fn capsule(half_length: f32, radius: f32) -> Self {
        Self {
            shape: Shape::capsule(half_length, radius),
        }
    }

    /// A solid cylinder along the body's local z axis (standing when unrotated): caps
    /// `half_height` from the centre, and `radius`. Wheels, barrels, pillars.
    pub fn cylinder(half_height: f32, radius: f32) -> Self {
        Self {
            shape: Shape::cylinder(half_height, radius),
        }
    }

    /// A solid cone along the body's local z axis (apex up when unrotated): its base of `radius`
    /// `half_height` below the body's origin, its apex `half_height` above; the centre of mass
    /// is a quarter of the height above the base. Traffic cones, spikes, lamp shades.
    pub fn cone(half_height: f32, radius: f32) -> Self {
        Self {
            shape: Shape::cone(half_height, radius),
        }
    }

    /// A solid ellipsoid of semi-axes `rx`, `ry`, `rz` along the body's local axes.
    pub fn ellipsoid(rx: f32, ry: f32, rz: f32) -> Self {
        Self {
            shape: Shape::ellipsoid(Vec3::new(rx, ry, rz)),
        }
    }

    /// The convex hull of `points` (in the body's frame), built once here by quickhull. Errors:
    /// fewer than 4 points, non-finite or oversized ones, or all of them (nearly) coplanar.
    pub fn convex_hull(points: &[Vec3]) -> Result<Self, HullError> {
        Shape::convex_hull(points).map(|shape| Self { shape })
    }

    /// The convex hull of the vertices of an OBJ, STL or PLY file (chosen by extension): the
    /// usual way to give a detailed prop a cheap dynamic collider.
    #[cfg(feature = "mesh-io")]
    pub fn convex_hull_from_file(path: impl AsRef<std::path::Path>) -> Result<Self, HullFileError> {
        let hull = crate::geometry::convex::hull_from_file(path)?;
        Ok(Self {
            shape: Shape::ConvexHull(std::sync::Arc::new(hull)),
        })
    }

    /// The solid below a plane through the body's position with outward `normal` (a ground).
    pub fn half_space(normal: Vec3) -> Self {
        Self {
            shape: Shape::half_space(normal),
        }
    }

    /// A triangle mesh (validated by [`TriMesh::new`]) with its hierarchy, built here once.
    /// Errors only if the hierarchy cannot be built (more than `u32::MAX` triangles).
    pub fn trimesh(mesh: TriMesh) -> Result<Self, MeshColliderError> {
        MeshCollider::new(mesh).map(Self::mesh)
    }

    /// A mesh loaded from an OBJ, STL or PLY file (chosen by extension). Errors: unreadable
    /// file, unknown extension, content that does not parse, or geometry that is not a valid
    /// mesh (no triangles, non-finite coordinates, every triangle degenerate).
    #[cfg(feature = "mesh-io")]
    pub fn from_mesh_file(path: impl AsRef<std::path::Path>) -> Result<Self, MeshColliderError> {
        MeshCollider::from_file(path).map(Self::mesh)
    }

    /// A mesh collider built beforehand: cheap, so many bodies can share one mesh.
    pub fn mesh(collider: MeshCollider) -> Self {
        Self {
            shape: Shape::TriMesh(collider),
        }
    }
}

/// The world-space AABB the broad phase reads, kept up to date by the physics step. In a
/// hierarchy it bounds the node's own collider *and* all its descendants (the scene graph is the
/// BV hierarchy); empty for a body with no collider at or below it.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct BoundingVolume(pub Aabb);

impl BoundingVolume {
    /// Half the diagonal (0 when empty or unbounded): how far the body reaches from the
    /// volume's centre, for the speed of its turning surface (`|ω|` times this).
    pub fn reach(&self) -> f32 {
        let half = self.0.half_extents();
        if half.is_finite() && half.cmpge(glam::Vec3::ZERO).all() {
            half.length()
        } else {
            0.0
        }
    }
}

/// The world pose of a body, derived each substep from [`Position`] and [`Rotation`]: a root's
/// own, or its parent's world pose composed with its local one. Read-only to games (its field is
/// the crate's): [`GlobalPose::pose`] reads it, and a game moves a body through its
/// [`Position`] and [`Rotation`], which the next propagation turns into this
/// ([`GlobalPose::propagated`] is for a stage that replaces the propagation).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct GlobalPose(pub(crate) Isometry);

impl GlobalPose {
    /// The body's pose in the world, as of the last propagation.
    pub fn pose(&self) -> Isometry {
        self.0
    }

    /// A world pose as the propagation writes it: only for a stage that replaces
    /// [`HierarchyPlugin`](crate::plugins::HierarchyPlugin)'s (game code moves bodies through
    /// [`Position`] and [`Rotation`]; a pose written here by anything else is overwritten at
    /// the next propagation). `None` for a pose with a NaN or an infinity, which no stage may
    /// hand to the narrow phase (validation quarantines the bodies whose own pose is bad).
    ///
    /// ```
    /// # use urto::prelude::*;
    /// # use urto::geometry::Isometry;
    /// assert!(GlobalPose::propagated(Isometry::IDENTITY).is_some());
    /// let bad = Isometry::from_translation(glam::Vec3::new(f32::NAN, 0.0, 0.0));
    /// assert!(GlobalPose::propagated(bad).is_none());
    /// ```
    pub fn propagated(pose: Isometry) -> Option<Self> {
        pose.is_finite().then_some(Self(pose))
    }
}

/// Where a node of a compound body was at the start of the step (its [`GlobalPose`] then). A
/// game turns a robot's joints by setting the parts' local poses; how a part moved relative to
/// its root this step, divided by the step, is the velocity with which it pushes what it
/// touches when its root is immovable. Kept by the physics for every node of a hierarchy and
/// read-only to games ([`StepStartPose::pose`]).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStartPose(pub(crate) Isometry);

impl StepStartPose {
    /// The node's world pose when the step began.
    pub fn pose(&self) -> Isometry {
        self.0
    }
}

/// Continuous collision for a fast body: instead of testing only where the step ends (where a
/// bullet may already be past a thin wall: tunnelling), the body's motion during the step is
/// swept against static scenery and it stops at the first impact, then spends the rest of the
/// step from there. Costs one sweep per step; bodies without it pay nothing.
///
/// The sweep uses the body's bounding sphere (exact for balls), and a body of convex colliders
/// (one, or the parts of a compound) is then brought on to where the first of them meets the
/// obstacle ([`toi_parts_from`](crate::ccd::toi_parts_from)); a body with a mesh among its
/// colliders stops where its sphere does (early, never tunnelling).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ccd;

/// A collider that detects overlaps without pushing: a trigger volume (a goal, a pickup, a
/// damage zone). Its overlaps start and end
/// [`CollisionStarted`](crate::plugins::CollisionStarted) and
/// [`CollisionEnded`](crate::plugins::CollisionEnded) messages as contacts do, and are listed in
/// [`SensorOverlaps`](crate::plugins::narrow_phase::SensorOverlaps), but the solver never sees
/// them: no push, no island (a body resting in a sensor sleeps as it would outside it, and a
/// sleeping body keeps overlapping), and continuous collision passes through sensors. Works on
/// static, kinematic and dynamic bodies, and on one part of a compound.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sensor;

/// Which collision layers a collider is in and which it interacts with (see
/// [`crate::spatial::layers`]): two colliders touch only when each is a member of a layer the
/// other filters, and a [`SpatialQuery`](crate::plugins::SpatialQuery) sees colliders whose
/// memberships meet its mask. Without it a collider is in the first layer and interacts with
/// every layer (Avian's default). A body without parts whose layers interact with none (no
/// membership or no filter) is kept out of the broad phase, at no cost there; writing its
/// layers wakes it if it sleeps.
///
/// ```
/// # use urto::prelude::*;
/// const PLAYER: LayerMask = LayerMask(1 << 1);
/// const GHOST: LayerMask = LayerMask(1 << 2);
/// // A ghost in its own layer that passes through players.
/// let ghost = CollisionLayers::new(GHOST, !PLAYER);
/// let player = CollisionLayers::new(PLAYER, LayerMask::ALL);
/// assert!(!ghost.interacts_with(&player));
/// assert!(ghost.interacts_with(&CollisionLayers::default()));
/// ```
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[component(summary_tick)]
pub struct CollisionLayers(pub Layers);

impl CollisionLayers {
    /// Members of `memberships`, interacting with `filters`.
    pub const fn new(memberships: LayerMask, filters: LayerMask) -> Self {
        Self(Layers::new(memberships, filters))
    }

    /// Whether colliders with these layers and `other`'s may touch.
    pub const fn interacts_with(&self, other: &Self) -> bool {
        self.0.interacts_with(&other.0)
    }
}

/// The layers of a collider that may have none (the default's).
pub(crate) fn layers_of(layers: Option<&CollisionLayers>) -> CollisionLayers {
    layers.copied().unwrap_or_default()
}

/// Marks scenery that never moves.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[require(Position, Rotation)]
pub struct Static;

/// Set aside: this entity's physical state was unusable, so physics ignores it until the marker
/// is removed (after fixing the state).
#[derive(Component, Clone, Debug, PartialEq, Eq)]
pub struct Quarantined {
    /// Why, in words.
    pub reason: String,
}

/// The pose of a body as an [`Isometry`].
pub fn pose(position: &Position, rotation: Option<&Rotation>) -> Isometry {
    Isometry::new(position.0, Rotation::of(rotation))
}

/// Where a body's centre of mass is in its parent's frame: its [`Inertia`]'s centre carried by
/// its pose (the body's origin without an `Inertia`).
pub fn center_of_mass(
    position: &Position,
    rotation: Option<&Rotation>,
    inertia: Option<&Inertia>,
) -> Vec3 {
    let local = inertia.map_or(Vec3::ZERO, |i| i.local_center_of_mass);
    position.0 + Rotation::of(rotation) * local
}
