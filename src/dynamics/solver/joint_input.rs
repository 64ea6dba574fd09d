//! What a caller says about a joint: its frames on the two bodies, its kind, limit and motor,
//! and the checks that refuse unusable values before they reach the solver
//! ([`joint`](super::joint) prepares and solves it).

use crate::geometry::is_unit_rotation;
use glam::{Quat, Vec3};

/// Where a joint holds a body: an anchor from its centre of mass and a basis whose x axis is
/// the joint's axis, both in the body's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointFrame {
    /// The anchor, from the centre of mass (body frame).
    pub anchor: Vec3,
    /// The joint's axes in the body frame (x: the joint's axis).
    pub basis: Quat,
}

impl JointFrame {
    /// A finite anchor and a finite unit basis.
    pub fn is_usable(&self) -> bool {
        self.anchor.is_finite() && is_unit_rotation(self.basis)
    }
}

impl Default for JointFrame {
    fn default() -> Self {
        Self {
            anchor: Vec3::ZERO,
            basis: Quat::IDENTITY,
        }
    }
}

/// Bounds on a joint's coordinate (rad for a hinge, m for a slider or a distance).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimit {
    /// Lowest value.
    pub min: f32,
    /// Highest value (equal to `min`: held there, as a rod holds its length).
    pub max: f32,
}

/// Drives a joint's coordinate: towards a speed, or towards a position as a spring, with at most
/// `max_force` (N, or N·m for a hinge).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointMotor {
    /// Speed the motor drives to (rad/s or m/s); with a target position, the speed at it.
    pub target_velocity: f32,
    /// Position the motor pulls to, as a spring of `hertz` and `damping_ratio` (none: a
    /// velocity motor).
    pub target_position: Option<f32>,
    /// The position spring's stiffness (Hz).
    pub hertz: f32,
    /// The position spring's damping ratio.
    pub damping_ratio: f32,
    /// Largest force (or torque) the motor applies.
    pub max_force: f32,
}

impl JointMotor {
    /// A motor that drives to `speed` with at most `max_force`.
    pub fn velocity(speed: f32, max_force: f32) -> Self {
        Self {
            target_velocity: speed,
            target_position: None,
            hertz: 0.0,
            damping_ratio: 0.0,
            max_force,
        }
    }

    /// A motor that pulls to `target` as a spring of `hertz` and `damping_ratio`, with at most
    /// `max_force`.
    pub fn position(target: f32, hertz: f32, damping_ratio: f32, max_force: f32) -> Self {
        Self {
            target_velocity: 0.0,
            target_position: Some(target),
            hertz,
            damping_ratio,
            max_force,
        }
    }
}

/// What a joint keeps (see the module doc's table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointKind {
    /// Welds the bodies together.
    Fixed,
    /// Keeps the anchors together; the bodies turn about them, B's axis within a cone of
    /// `swing` (rad) around A's, twisted about it within `twist` (a ragdoll's shoulder).
    Spherical {
        /// Largest angle between the two frames' axes (rad, in `(0, π)`).
        swing: Option<f32>,
        /// Bounds on the twist of B's frame about the axis (rad, in `(−π, π]`).
        twist: Option<JointLimit>,
    },
    /// Keeps the anchors together and the axes aligned; the bodies turn about the axis.
    Revolute {
        /// Bounds on the angle (rad, in `(−π, π]`).
        limit: Option<JointLimit>,
        /// Drives the angle.
        motor: Option<JointMotor>,
    },
    /// Keeps the frames aligned and the anchors on a line along the axis; B slides along it
    /// (the travel is B's anchor from A's: which body is named first does not matter otherwise).
    Prismatic {
        /// Bounds on the travel (m).
        limit: Option<JointLimit>,
        /// Drives the travel.
        motor: Option<JointMotor>,
    },
    /// Bounds the distance between the anchors: a rope (`0..=L`), a rod (`L..=L`), or with a
    /// position motor a spring.
    Distance {
        /// Bounds on the distance (m).
        limit: JointLimit,
        /// Drives the distance.
        motor: Option<JointMotor>,
    },
}

impl JointKind {
    /// The limit and the motor, where the kind has them.
    pub fn limit_and_motor(&self) -> (Option<JointLimit>, Option<JointMotor>) {
        match *self {
            Self::Revolute { limit, motor } | Self::Prismatic { limit, motor } => (limit, motor),
            Self::Distance { limit, motor } => (Some(limit), motor),
            Self::Spherical { twist, .. } => (twist, None),
            Self::Fixed => (None, None),
        }
    }

    /// Why the limit or motor is unusable, if one is: a limit with `min > max` or NaN (or below
    /// 0 for a distance), a motor with a negative or NaN force, a non-finite target or an
    /// unusable stiffness.
    pub fn problem(&self) -> Option<String> {
        let (limit, motor) = self.limit_and_motor();
        if let Some(l) = limit
            && (l.min.is_nan() || l.max.is_nan() || l.min > l.max)
        {
            return Some(format!("limit {}..={} is empty or NaN", l.min, l.max));
        }
        if matches!(self, Self::Distance { limit, .. } if limit.min < 0.0) {
            return Some("a distance limit below 0".into());
        }
        if let Self::Spherical {
            swing: Some(cone), ..
        } = self
            && !(*cone > 0.0 && *cone < std::f32::consts::PI)
        {
            return Some(format!("a swing cone of {cone} rad (must be in (0, π))"));
        }
        if let Some(m) = motor {
            let target_ok = m.target_position.is_none_or(f32::is_finite);
            let spring_ok = m.hertz.is_finite() && m.hertz >= 0.0 && m.damping_ratio >= 0.0;
            let force_ok = m.max_force >= 0.0;
            if !(force_ok && m.target_velocity.is_finite() && target_ok && spring_ok) {
                return Some(format!("motor {m:?} has an unusable value"));
            }
        }
        None
    }
}

/// A joint between two solver slots, as the caller describes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointInput {
    /// First body's slot.
    pub a: u32,
    /// Second body's slot.
    pub b: u32,
    /// Where the joint holds A.
    pub frame_a: JointFrame,
    /// Where the joint holds B.
    pub frame_b: JointFrame,
    /// What it keeps.
    pub kind: JointKind,
    /// A key stable from step to step (warm starting follows it).
    pub key: u64,
}
