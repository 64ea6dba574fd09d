//! A kinematic body moved to a pose rather than at a velocity (rapier's position-based
//! kinematic bodies and `set_next_kinematic_position`): moving platforms and doors animated by
//! curves or tweens, whose riders must be carried. A game that instead wrote the platform's
//! `Position` every frame teleported it: contacts saw it standing still, and a box riding it
//! down at 1.2 m/s fell behind and bounced 0.45 m (a user-style probe).

use crate::geometry::is_unit_rotation;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

/// The pose a kinematic body (a [`Velocity`](super::Velocity) and
/// [`Mass::INFINITE`](super::Mass::INFINITE)) is to reach by the end of each step: at the
/// step's start its velocity and spin are set to carry it there in one step, so contacts push
/// and carry what touches it as a velocity-driven kinematic body would. It stays until removed:
/// a body at its target stands still. Dynamic bodies ignore it; a target that is not finite or
/// a rotation that is not a unit quaternion quarantines the body.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct KinematicTarget {
    /// The position to reach (the body's origin, in its parent's frame as its `Position`).
    pub position: Vec3,
    /// The rotation to reach.
    pub rotation: Quat,
}

impl KinematicTarget {
    /// A target at `position`, unturned.
    pub fn new(position: Vec3) -> Self {
        Self {
            position,
            rotation: Quat::IDENTITY,
        }
    }

    /// The same target turned to `rotation`.
    pub fn with_rotation(self, rotation: Quat) -> Self {
        Self { rotation, ..self }
    }

    /// The velocity and spin that carry a body from `position`, `rotation` to this target in
    /// `dt` seconds (the shorter way round); `None` for a target that is not finite or a
    /// rotation that is not a unit quaternion.
    pub fn motion_from(&self, (position, rotation): (Vec3, Quat), dt: f32) -> Option<(Vec3, Vec3)> {
        if !(self.position.is_finite() && is_unit_rotation(self.rotation)) {
            return None;
        }
        let mut turn = self.rotation.normalize() * rotation.inverse();
        if turn.w < 0.0 {
            turn = -turn;
        }
        let velocity = (self.position - position) / dt;
        let spin = turn.to_scaled_axis() / dt;
        (velocity.is_finite() && spin.is_finite()).then_some((velocity, spin))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A turn of 0.1 rad about z in a 1/60 s step is a spin of 6 rad/s about z (within 1e-4),
    /// whichever sign its quaternion has; the same rotation written as `-q` is no turn.
    #[test]
    fn a_target_turned_0_1_rad_spins_6_rad_s_either_sign_and_minus_q_is_no_turn() {
        let from = (Vec3::ZERO, Quat::from_rotation_x(0.3));
        let dt = 1.0 / 60.0;
        let turned = Quat::from_rotation_z(0.1) * from.1;
        for q in [turned, -turned] {
            let target = KinematicTarget::new(Vec3::X).with_rotation(q);
            let (v, w) = target.motion_from(from, dt).unwrap();
            assert!((v - Vec3::X * 60.0).length() < 1e-3, "{v}");
            assert!((w - Vec3::Z * 6.0).length() < 1e-4, "{w}");
        }
        let still = KinematicTarget::new(Vec3::ZERO).with_rotation(-from.1);
        let (_, w) = still.motion_from(from, dt).unwrap();
        assert!(w.length() < 1e-4, "{w}");
    }
}
