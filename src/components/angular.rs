//! The rotational state of a body: how fast it turns, what turns it, what it resists turning
//! with, and which axes it may not turn about (the angular counterparts of [`Velocity`](super::Velocity),
//! [`Force`](super::Force), [`Mass`](super::Mass) and drag).
//!
//! Every dynamic body turns by default, as in Avian and rapier: [`Velocity`](super::Velocity) brings an
//! [`AngularVelocity`] and an [`Inertia`] computed from the collider (scaled to the body's
//! [`ComputedMass`](super::ComputedMass)). [`LockedAxes::ROTATION_LOCKED`] keeps a body upright.

use super::point_sum::PointSum;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

/// Angular velocity in world axes (rad/s): the body turns about its centre of mass at this rate.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct AngularVelocity(pub Vec3);

impl AngularVelocity {
    /// An angular velocity from components.
    pub const fn new(x: f32, y: f32, z: f32) -> Self {
        Self(Vec3::new(x, y, z))
    }
}

/// Torque in world axes (N·m) applied during the next physics step, then cleared, like
/// [`Force`](super::Force).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct Torque(pub Vec3);

/// Forces applied at world points during the next physics step, then cleared. Each force both
/// pushes the body (as a [`Force`](super::Force)) and turns it about its centre of mass (`r × F`); forces at
/// many points accumulate exactly, whatever the centre of mass is when the step reads them.
///
/// ```
/// # use urto::prelude::*;
/// # use glam::Vec3;
/// let mut push = ForceAtPoint::default();
/// push.add(Vec3::X * 10.0, Vec3::new(0.0, 0.0, 1.0)); // 10 N along x, 1 m up
/// assert_eq!(push.force(), Vec3::X * 10.0);
/// assert_eq!(push.torque_about(Vec3::ZERO), Vec3::new(0.0, 10.0, 0.0));
/// ```
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct ForceAtPoint {
    /// The forces and their moment (about the first point, exact far from the origin).
    sum: PointSum,
}

impl ForceAtPoint {
    /// Adds `force` (N) acting at the world `point`.
    pub fn add(&mut self, force: Vec3, point: Vec3) {
        self.sum.add(force, point);
    }

    /// The sum of the forces.
    pub fn force(&self) -> Vec3 {
        self.sum.total()
    }

    /// Their torque about the world point `center`.
    pub fn torque_about(&self, center: Vec3) -> Vec3 {
        self.sum.moment_about(center)
    }

    /// True when nothing was added.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }
}

/// Angular drag rate `c` (1/s): without torque the angular velocity decays as `e^{−c t}`
/// (applied exactly, so any `c >= 0` is stable).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct AngularDrag(pub f32);

/// World axes a body may not turn about or move along (Avian's and rapier's `LockedAxes`):
/// its velocity along them stays zero, and no force, torque, contact, joint or impulse moves
/// it there. A 2.5D game locks translation along z and rotation about x and y.
///
/// The solver gives a locked body `1/m = 0` along each locked translation axis (a per-axis
/// effective mass, as Avian and rapier), so a contact pushing it there treats it as immovable
/// along that axis, not as a body whose motion is cut afterwards. Kinematic and static bodies
/// ignore the locks. On the lecture's pipeline (`SoftStepPlugin` disabled) only the rotation
/// locks and impulses honour them.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[component(summary_tick)]
pub struct LockedAxes(u8);

impl LockedAxes {
    /// The locks of a body that may have no `LockedAxes` (nothing locked then).
    pub fn of(locked: Option<&LockedAxes>) -> LockedAxes {
        locked.copied().unwrap_or_default()
    }

    /// Nothing locked.
    pub const NONE: Self = Self(0);
    /// Rotation locked about every axis: the body only translates.
    pub const ROTATION_LOCKED: Self = Self(0b000_111);
    /// Translation locked along every axis: the body only turns, about its centre of mass.
    pub const TRANSLATION_LOCKED: Self = Self(0b111_000);
    /// Everything locked: a dynamic body that neither moves nor turns.
    pub const ALL_LOCKED: Self = Self(0b111_111);

    /// Nothing locked (the same as [`Self::NONE`]), to chain `lock_*` calls on.
    pub const fn new() -> Self {
        Self::NONE
    }

    /// Also locks rotation about world x.
    #[must_use]
    pub const fn lock_rotation_x(self) -> Self {
        Self(self.0 | 1)
    }

    /// Also locks rotation about world y.
    #[must_use]
    pub const fn lock_rotation_y(self) -> Self {
        Self(self.0 | 2)
    }

    /// Also locks rotation about world z.
    #[must_use]
    pub const fn lock_rotation_z(self) -> Self {
        Self(self.0 | 4)
    }

    /// Also locks translation along world x.
    #[must_use]
    pub const fn lock_translation_x(self) -> Self {
        Self(self.0 | 8)
    }

    /// Also locks translation along world y.
    #[must_use]
    pub const fn lock_translation_y(self) -> Self {
        Self(self.0 | 16)
    }

    /// Also locks translation along world z.
    #[must_use]
    pub const fn lock_translation_z(self) -> Self {
        Self(self.0 | 32)
    }

    /// True when rotation about every axis is locked.
    pub const fn is_rotation_locked(self) -> bool {
        self.0 & 0b111 == 0b111
    }

    /// True when translation along every axis is locked.
    pub const fn is_translation_locked(self) -> bool {
        self.0 & 0b111_000 == 0b111_000
    }

    /// 1 for each world axis the body may turn about, 0 for a locked one.
    pub fn free_rotation_axes(self) -> Vec3 {
        self.free(0)
    }

    /// 1 for each world axis the body may move along, 0 for a locked one.
    pub fn free_translation_axes(self) -> Vec3 {
        self.free(3)
    }

    /// The three bits from `shift` as 1 (free) or 0 (locked).
    fn free(self, shift: u8) -> Vec3 {
        let free = |axis: u8| {
            if self.0 & (1 << (shift + axis)) == 0 {
                1.0
            } else {
                0.0
            }
        };
        Vec3::new(free(0), free(1), free(2))
    }
}

/// How a body resists turning: principal moments of inertia about its centre of mass, the
/// principal axes in the body's frame, and where the centre of mass lies in the body's frame.
///
/// Left at its default it is **computed** from the body's collider and those of its
/// [`ChildOf`](bevy_ecs::hierarchy::ChildOf) parts (the scene graph as a compound body, by the
/// parallel-axis theorem), at uniform density scaled to the body's
/// [`ComputedMass`](super::ComputedMass), and recomputed when the collider, mass or density
/// changes. [`Inertia::custom`] overrides it. A body without any collider
/// has infinite inertia: torques and contacts do not turn it, its angular velocity still does.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[component(summary_tick)]
pub struct Inertia {
    /// Principal moments (kg·m²); infinite where the body cannot be turned.
    pub principal: Vec3,
    /// Rotation from the principal axes to the body's frame.
    pub frame: Quat,
    /// The centre of mass in the body's frame: the body turns about it.
    pub local_center_of_mass: Vec3,
    /// Set by the game ([`Inertia::custom`]): the physics never recomputes it.
    pub custom: bool,
}

impl Default for Inertia {
    /// Computed by the physics (infinite until the first step computes it).
    fn default() -> Self {
        Self {
            principal: Vec3::INFINITY,
            frame: Quat::IDENTITY,
            local_center_of_mass: Vec3::ZERO,
            custom: false,
        }
    }
}

impl Inertia {
    /// A game-chosen inertia about the body's origin, which the physics keeps as given.
    pub fn custom(principal: Vec3, frame: Quat) -> Self {
        Self {
            principal,
            frame: if frame.length() > 0.0 {
                frame.normalize()
            } else {
                frame
            },
            local_center_of_mass: Vec3::ZERO,
            custom: true,
        }
    }

    /// The same inertia about a centre of mass elsewhere in the body's frame.
    #[must_use]
    pub fn with_center_of_mass(mut self, local_center_of_mass: Vec3) -> Self {
        self.local_center_of_mass = local_center_of_mass;
        self
    }

    /// `I⁻¹ v` in world axes for a body turned by `orientation`: `v` carried into the
    /// principal frame, divided by the moments (0 for infinite ones), carried back.
    pub fn inverse_world_times(&self, orientation: Quat, v: Vec3) -> Vec3 {
        let to_world = orientation * self.frame;
        to_world * (self.inverse_principal() * (to_world.inverse() * v))
    }

    /// `1/I` per principal axis, 0 for infinite moments.
    pub fn inverse_principal(&self) -> Vec3 {
        let inv = |i: f32| {
            if i.is_finite() && i > 0.0 {
                1.0 / i
            } else {
                0.0
            }
        };
        Vec3::new(
            inv(self.principal.x),
            inv(self.principal.y),
            inv(self.principal.z),
        )
    }

    /// True when the numbers describe a real inertia (moments `> 0` or infinite, a finite
    /// frame and centre).
    pub fn is_valid(&self) -> bool {
        self.principal.cmpgt(Vec3::ZERO).all()
            && !self.principal.is_nan()
            && self.frame.is_finite()
            && self.local_center_of_mass.is_finite()
    }
}
