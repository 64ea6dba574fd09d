//! Joints as entities: a [`Joint`] names two bodies (or a body and the world) and what the joint
//! keeps between them (Avian's and bevy_rapier's way: a joint is an entity of its own, so a body
//! can have any number of them, and despawning the joint removes it).
//!
//! ```
//! # use bevy_ecs::prelude::*;
//! # use urto::prelude::*;
//! # use glam::Vec3;
//! # let mut world = World::new();
//! let door_frame = world.spawn((Collider::cuboid(0.1, 0.1, 0.1), Static)).id();
//! let door = world
//!     .spawn((Collider::cuboid(0.5, 0.05, 1.0), Position::new(0.6, 0.0, 0.0), Velocity::default()))
//!     .id();
//! // A hinge along z at the door's left edge, swinging up to 100 degrees either way, closed by a
//! // spring of 2 Hz.
//! world.spawn(
//!     Joint::revolute(door_frame, door)
//!         .with_axis(Vec3::Z)
//!         .with_anchors(Vec3::new(0.1, 0.0, 0.0), Vec3::new(-0.5, 0.0, 0.0))
//!         .with_limits(-1.75, 1.75)
//!         .with_motor(JointMotor::position(0.0, 2.0, 1.0, 50.0)),
//! );
//! // A lamp hanging from a point in the world on a 2 m rope.
//! let lamp = world.spawn((Collider::sphere(0.2), Position::new(0.0, 0.0, 3.0), Velocity::default())).id();
//! world.spawn(Joint::rope(lamp, JointEnd::World, 2.0).with_anchors(Vec3::ZERO, Vec3::new(0.0, 0.0, 5.0)));
//! ```
//!
//! The bodies of a joint do not collide with each other unless the joint says
//! [`with_collisions`](Joint::with_collisions) (Box2D's `collideConnected`, off by default: a
//! ragdoll's limbs overlap at their joints). Jointed bodies fall asleep and wake together.
//!
//! Why not a joint on a [`ChildOf`](bevy_ecs::hierarchy::ChildOf) link? In urto a child with a
//! collider is a rigid *part* of its parent's body (the scene graph is the compound's bounding
//! volume hierarchy), so a jointed limb is a body of its own, with its own `Position`; a joint
//! naming a part is refused with a warning.

use crate::dynamics::solver::JointFrame;
use crate::dynamics::solver::joint::twist_angle;
pub use crate::dynamics::solver::{JointKind, JointLimit, JointMotor};
use crate::geometry::Isometry;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

/// The second end of a joint: a body, or a fixed frame in the world.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointEnd {
    /// A body (its anchor and basis in the body's frame).
    Body(Entity),
    /// The world (its anchor and basis in world coordinates).
    World,
}

impl From<Entity> for JointEnd {
    fn from(e: Entity) -> Self {
        Self::Body(e)
    }
}

/// A joint between `body_a` and `body_b` (see the module doc and
/// [`JointKind`] for what each kind keeps). Anchors are in each body's frame from its origin
/// ([`Position`](super::Position)); the joint's axis is its bases' x axis.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    /// The first body.
    pub body_a: Entity,
    /// The second body, or the world.
    pub body_b: JointEnd,
    /// Where the joint holds A, in A's frame.
    pub anchor_a: Vec3,
    /// Where it holds B, in B's frame (world coordinates for [`JointEnd::World`]).
    pub anchor_b: Vec3,
    /// The joint's axes in A's frame (x: the hinge's or slider's axis).
    pub basis_a: Quat,
    /// The joint's axes in B's frame.
    pub basis_b: Quat,
    /// What the joint keeps, with its limit and motor.
    pub kind: JointKind,
    /// Whether the two bodies still collide with each other (default: no).
    pub collide_connected: bool,
    /// Force (N) above which the joint breaks (default: never).
    pub break_force: f32,
    /// Torque (N·m) above which the joint breaks (default: never).
    pub break_torque: f32,
}

impl Joint {
    /// A joint of `kind` between `a` and `b`, anchored at both origins, axis x.
    pub fn new(a: Entity, b: impl Into<JointEnd>, kind: JointKind) -> Self {
        Self {
            body_a: a,
            body_b: b.into(),
            anchor_a: Vec3::ZERO,
            anchor_b: Vec3::ZERO,
            basis_a: Quat::IDENTITY,
            basis_b: Quat::IDENTITY,
            kind,
            collide_connected: false,
            break_force: f32::INFINITY,
            break_torque: f32::INFINITY,
        }
    }

    /// Welds the two bodies in their poses at the anchors.
    pub fn fixed(a: Entity, b: impl Into<JointEnd>) -> Self {
        Self::new(a, b, JointKind::Fixed)
    }

    /// A ball joint: the anchors stay together, the bodies turn freely about them.
    pub fn spherical(a: Entity, b: impl Into<JointEnd>) -> Self {
        let kind = JointKind::Spherical {
            swing: None,
            twist: None,
        };
        Self::new(a, b, kind)
    }

    /// A hinge about the joint's axis ([`with_axis`](Self::with_axis)).
    pub fn revolute(a: Entity, b: impl Into<JointEnd>) -> Self {
        let kind = JointKind::Revolute {
            limit: None,
            motor: None,
        };
        Self::new(a, b, kind)
    }

    /// A slider along the joint's axis ([`with_axis`](Self::with_axis)).
    pub fn prismatic(a: Entity, b: impl Into<JointEnd>) -> Self {
        let kind = JointKind::Prismatic {
            limit: None,
            motor: None,
        };
        Self::new(a, b, kind)
    }

    /// Keeps the anchors between `min` and `max` apart.
    pub fn distance(a: Entity, b: impl Into<JointEnd>, min: f32, max: f32) -> Self {
        let kind = JointKind::Distance {
            limit: JointLimit { min, max },
            motor: None,
        };
        Self::new(a, b, kind)
    }

    /// A rope of `length`: slack when shorter, taut at it.
    pub fn rope(a: Entity, b: impl Into<JointEnd>, length: f32) -> Self {
        Self::distance(a, b, 0.0, length)
    }

    /// A rod holding the anchors exactly `length` apart.
    pub fn rod(a: Entity, b: impl Into<JointEnd>, length: f32) -> Self {
        Self::distance(a, b, length, length)
    }

    /// The anchors, in each body's frame from its origin.
    pub fn with_anchors(mut self, a: Vec3, b: Vec3) -> Self {
        self.anchor_a = a;
        self.anchor_b = b;
        self
    }

    /// The joint's axis, the same in both bodies' frames (a hinge's axis, a slider's
    /// direction).
    pub fn with_axis(self, axis: Vec3) -> Self {
        self.with_axes(axis, axis)
    }

    /// The joint's axis in A's frame and in B's.
    pub fn with_axes(mut self, a: Vec3, b: Vec3) -> Self {
        self.basis_a = basis_along(a);
        self.basis_b = basis_along(b);
        self
    }

    /// Bounds on the joint's coordinate (rad for a hinge, m for a slider or a distance, the
    /// twist about the axis for a ball joint); no effect on fixed joints.
    pub fn with_limits(mut self, min: f32, max: f32) -> Self {
        let new = JointLimit { min, max };
        match &mut self.kind {
            JointKind::Revolute { limit, .. }
            | JointKind::Prismatic { limit, .. }
            | JointKind::Spherical { twist: limit, .. } => *limit = Some(new),
            JointKind::Distance { limit, .. } => *limit = new,
            _ => {}
        }
        self
    }

    /// Keeps a ball joint's B axis within `angle` (rad) of A's (a cone); no effect on other
    /// kinds.
    pub fn with_swing_limit(mut self, angle: f32) -> Self {
        if let JointKind::Spherical { swing, .. } = &mut self.kind {
            *swing = Some(angle);
        }
        self
    }

    /// A motor on the joint's coordinate; no effect on fixed and spherical joints.
    pub fn with_motor(mut self, new: JointMotor) -> Self {
        match &mut self.kind {
            JointKind::Revolute { motor, .. }
            | JointKind::Prismatic { motor, .. }
            | JointKind::Distance { motor, .. } => *motor = Some(new),
            _ => {}
        }
        self
    }

    /// The motor, to change its target while the game runs (none on fixed and spherical
    /// joints, or before [`with_motor`](Self::with_motor)).
    pub fn motor_mut(&mut self) -> Option<&mut JointMotor> {
        match &mut self.kind {
            JointKind::Revolute { motor, .. }
            | JointKind::Prismatic { motor, .. }
            | JointKind::Distance { motor, .. } => motor.as_mut(),
            _ => None,
        }
    }

    /// Lets the two bodies collide with each other.
    pub fn with_collisions(mut self) -> Self {
        self.collide_connected = true;
        self
    }

    /// Breaks the joint (a [`JointBroken`] message, a [`JointDisabled`] marker) when it holds
    /// more than `force` (N) or `torque` (N·m).
    pub fn breakable(mut self, force: f32, torque: f32) -> Self {
        self.break_force = force;
        self.break_torque = torque;
        self
    }

    /// The body at the second end, if it is one.
    pub fn body_b_entity(&self) -> Option<Entity> {
        match self.body_b {
            JointEnd::Body(e) => Some(e),
            JointEnd::World => None,
        }
    }

    /// The joint's frame on each end in world coordinates (anchor and basis), for A at `pose_a`
    /// and B at `pose_b` (`None` for the world).
    pub fn world_frames(&self, pose_a: Isometry, pose_b: Option<Isometry>) -> (Isometry, Isometry) {
        let frame = |pose: Isometry, anchor: Vec3, basis| {
            Isometry::new(pose.transform_point(anchor), pose.rotation * basis)
        };
        (
            frame(pose_a, self.anchor_a, self.basis_a),
            frame(pose_b.unwrap_or_default(), self.anchor_b, self.basis_b),
        )
    }

    /// How far the joint is past its limits (rad or m; 0 within them or without any), its
    /// frames in world coordinates being `a` and `b` ([`world_frames`](Self::world_frames)):
    /// a ball joint's swing past its cone, its twist, a hinge's angle, a slider's travel, a
    /// distance, each past its bounds.
    pub fn past_limit(&self, a: &Isometry, b: &Isometry) -> f32 {
        let swing = match self.kind {
            JointKind::Spherical {
                swing: Some(cone), ..
            } => {
                let (x_a, x_b) = (a.rotation * Vec3::X, b.rotation * Vec3::X);
                (x_a.angle_between(x_b) - cone).max(0.0)
            }
            _ => 0.0,
        };
        let (Some(limit), _) = self.kind.limit_and_motor() else {
            return swing;
        };
        let coordinate = self.coordinate(a, b);
        (limit.min - coordinate)
            .max(coordinate - limit.max)
            .max(swing)
            .max(0.0)
    }

    /// The joint's coordinate, what its limits bound and its motor drives, its frames in world
    /// coordinates being `a` and `b` ([`world_frames`](Self::world_frames)): a hinge's angle or
    /// a ball joint's twist about the axis (rad, in `(−π, π]`), a slider's travel along its axis
    /// or the distance between the anchors (m); 0 for a fixed joint.
    pub fn coordinate(&self, a: &Isometry, b: &Isometry) -> f32 {
        match self.kind {
            JointKind::Revolute { .. } | JointKind::Spherical { .. } => {
                twist_angle(a.rotation, b.rotation)
            }
            JointKind::Prismatic { .. } => {
                (a.rotation * Vec3::X).dot(b.translation - a.translation)
            }
            JointKind::Distance { .. } => a.translation.distance(b.translation),
            JointKind::Fixed => 0.0,
        }
    }

    /// Why the joint cannot be solved, if it cannot: non-finite or non-unit frames, a body
    /// twice, a limit with `min > max` or NaN, a motor with a negative or NaN force or an
    /// unusable stiffness.
    pub fn problem(&self) -> Option<String> {
        if self.body_b == JointEnd::Body(self.body_a) {
            return Some("joins a body to itself".into());
        }
        for (anchor, basis) in [(self.anchor_a, self.basis_a), (self.anchor_b, self.basis_b)] {
            let frame = JointFrame { anchor, basis };
            if !frame.is_usable() {
                return Some(format!("frame {frame:?} is not finite or not unit"));
            }
        }
        if let Some(problem) = self.kind.problem() {
            return Some(problem);
        }
        if self.break_force.is_nan() || self.break_torque.is_nan() {
            return Some("a NaN break threshold".into());
        }
        None
    }
}

/// A basis whose x axis is `axis` (the shortest turn from x; a zero axis keeps x).
fn basis_along(axis: Vec3) -> Quat {
    let axis = axis.normalize_or_zero();
    if axis == Vec3::ZERO {
        return Quat::IDENTITY;
    }
    Quat::from_rotation_arc(Vec3::X, axis)
}

/// Switches a joint off: the solver skips it (broken joints get it; remove it to mend one).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct JointDisabled;

/// A joint broke: it held more than its [`Joint::break_force`] or [`Joint::break_torque`].
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct JointBroken {
    /// The joint's entity (it now has [`JointDisabled`]).
    pub joint: Entity,
    /// The force it held (N).
    pub force: f32,
    /// The torque it held (N·m).
    pub torque: f32,
}

/// What a joint held over the last substep of the last step (written for every solved joint).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct JointLoad {
    /// Force (N).
    pub force: f32,
    /// Torque (N·m).
    pub torque: f32,
    /// What the motor applied, signed along the joint's coordinate (N·m on a hinge, N on a
    /// slider or a distance joint; 0 without a motor): the effort a game reads off its motor.
    pub motor: f32,
}

impl From<crate::dynamics::solver::HeldLoad> for JointLoad {
    fn from(held: crate::dynamics::solver::HeldLoad) -> Self {
        Self {
            force: held.force,
            torque: held.torque,
            motor: held.motor,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_joint_with_unusable_values_names_the_problem_and_a_good_one_has_none() {
        let (a, b) = (
            Entity::from_raw_u32(1).unwrap(),
            Entity::from_raw_u32(2).unwrap(),
        );
        assert_eq!(Joint::revolute(a, b).with_limits(-1.0, 1.0).problem(), None);
        let bad = [
            Joint::spherical(a, a),
            Joint::spherical(a, b).with_anchors(Vec3::NAN, Vec3::ZERO),
            Joint::revolute(a, b).with_limits(1.0, -1.0),
            Joint::prismatic(a, b).with_limits(f32::NAN, 1.0),
            Joint::rope(a, b, -1.0),
            Joint::revolute(a, b).with_motor(JointMotor::velocity(1.0, -5.0)),
            Joint::revolute(a, b).with_motor(JointMotor::position(f32::INFINITY, 1.0, 1.0, 1.0)),
            Joint::fixed(a, b).breakable(f32::NAN, 1.0),
        ];
        for joint in bad {
            assert!(joint.problem().is_some(), "{joint:?}");
        }
    }

    #[test]
    fn the_coordinate_reads_a_hinge_angle_a_slider_travel_and_a_distance_within_1e_5() {
        let (a, b) = (
            Entity::from_raw_u32(1).unwrap(),
            Entity::from_raw_u32(2).unwrap(),
        );
        let at = |x: f32, turn: Quat| Isometry::new(Vec3::new(x, 0.0, 0.0), turn);
        // A hinge about −y, B's frame turned by 0.7 rad about −y (its x axis raised).
        let hinge = Joint::revolute(a, b).with_axis(Vec3::NEG_Y);
        let pose_b = at(0.0, Quat::from_rotation_y(-0.7));
        let (fa, fb) = hinge.world_frames(Isometry::default(), Some(pose_b));
        assert!((hinge.coordinate(&fa, &fb) - 0.7).abs() < 1e-5);
        let slider = Joint::prismatic(a, b).with_axis(Vec3::X);
        let (fa, fb) = slider.world_frames(at(1.0, Quat::IDENTITY), Some(at(1.25, Quat::IDENTITY)));
        assert!((slider.coordinate(&fa, &fb) - 0.25).abs() < 1e-5);
        let rope = Joint::rope(a, b, 2.0);
        let (fa, fb) = rope.world_frames(at(0.0, Quat::IDENTITY), Some(at(-1.5, Quat::IDENTITY)));
        assert!((rope.coordinate(&fa, &fb) - 1.5).abs() < 1e-5);
        assert_eq!(Joint::fixed(a, b).coordinate(&fa, &fb), 0.0);
    }

    #[test]
    fn a_zero_axis_keeps_x_and_an_axis_turns_x_onto_it() {
        assert_eq!(basis_along(Vec3::ZERO), Quat::IDENTITY);
        let q = basis_along(Vec3::new(0.0, 0.0, 2.0));
        assert!((q * Vec3::X - Vec3::Z).length() < 1e-6);
    }
}
