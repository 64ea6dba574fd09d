//! Solver bodies: the dense per-body arrays the solver stages sweep (Box2D v3's `b2BodyState`
//! and Avian's `SolverBody`). Each body sits in a stable slot given by the caller's order; the
//! stages touch only [`BodyState`] (velocities and the motion since the step began), so the
//! poses at the step's start stay fixed and contact anchors can be kept relative to them.

use glam::{Mat3, Quat, Vec3};

/// What the substeps change: velocities and the motion since the step's start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    /// Velocity of the centre of mass (m/s).
    pub linear_velocity: Vec3,
    /// Angular velocity in world axes (rad/s).
    pub angular_velocity: Vec3,
    /// How far the centre of mass moved since the step's start.
    pub delta_position: Vec3,
    /// How the body turned since the step's start (world frame, applied on the left).
    pub delta_rotation: Quat,
}

impl Default for BodyState {
    fn default() -> Self {
        Self {
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            delta_position: Vec3::ZERO,
            delta_rotation: Quat::IDENTITY,
        }
    }
}

/// What stays fixed over a step: masses, the world inverse inertia at the step's start, and the
/// accelerations of the step's external forces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyParams {
    /// `1/m` along each world axis: 0 for static and kinematic bodies and along a locked
    /// translation axis (Avian's and rapier's per-axis effective inverse mass), so no impulse
    /// moves the body there.
    pub inverse_mass: Vec3,
    /// World inverse inertia `R I⁻¹ Rᵀ` at the step's start, locked axes zeroed.
    pub inverse_inertia: Mat3,
    /// Gravity plus force over mass (m/s²).
    pub linear_acceleration: Vec3,
    /// `I⁻¹ τ` (rad/s²).
    pub angular_acceleration: Vec3,
    /// Linear damping rate (1/s).
    pub linear_damping: f32,
    /// Angular damping rate (1/s).
    pub angular_damping: f32,
    /// True for bodies the solver may move (dynamic); kinematic and static bodies keep their
    /// velocities.
    pub dynamic: bool,
    /// For a body turning with the gyroscopic term: its principal frame (in the body frame) and
    /// `1/I` per principal axis.
    pub gyroscopic: Option<(Quat, Vec3)>,
}

impl BodyParams {
    /// Whether no impulse can move or turn the body: static, kinematic, or dynamic and locked
    /// on every axis (its contacts then take the static softness).
    pub fn is_immovable(&self) -> bool {
        !self.dynamic || (self.inverse_mass == Vec3::ZERO && self.inverse_inertia == Mat3::ZERO)
    }
}

/// One body as the caller describes it at the step's start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyInput {
    /// World position of the centre of mass.
    pub center: Vec3,
    /// World orientation.
    pub orientation: Quat,
    /// Velocity of the centre of mass.
    pub linear_velocity: Vec3,
    /// Angular velocity in world axes.
    pub angular_velocity: Vec3,
    /// `1/m` (0: immovable).
    pub inverse_mass: f32,
    /// `1/I` per principal axis (0: infinite about it).
    pub inverse_principal_inertia: Vec3,
    /// Rotation from principal axes to the body frame.
    pub inertia_frame: Quat,
    /// Gravity plus force over mass.
    pub linear_acceleration: Vec3,
    /// Torque (N·m, world).
    pub torque: Vec3,
    /// Linear damping rate (1/s).
    pub linear_damping: f32,
    /// Angular damping rate (1/s).
    pub angular_damping: f32,
    /// 1 per world axis the body may turn about, 0 where locked.
    pub free_axes: Vec3,
    /// 1 per world axis the body may move along, 0 where locked.
    pub free_translation: Vec3,
    /// Turn with the gyroscopic term `−ω × Iω` (Dzhanibekov's flip, a spinning top's
    /// precession); honoured for dynamic bodies with every axis free and finite inertia.
    pub gyroscopic: bool,
}

impl Default for BodyInput {
    /// A static body at the origin.
    fn default() -> Self {
        Self {
            center: Vec3::ZERO,
            orientation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            inverse_mass: 0.0,
            inverse_principal_inertia: Vec3::ZERO,
            inertia_frame: Quat::IDENTITY,
            linear_acceleration: Vec3::ZERO,
            torque: Vec3::ZERO,
            linear_damping: 0.0,
            angular_damping: 0.0,
            free_axes: Vec3::ONE,
            free_translation: Vec3::ONE,
            gyroscopic: false,
        }
    }
}

/// Whether a per-axis `1/m` is one number on every axis (no translation lock): then the rows
/// take their one-number form, bit for bit what they were before locks existed.
pub fn same_on_every_axis(inverse_mass: Vec3) -> bool {
    inverse_mass.min_element() == inverse_mass.max_element()
}

/// The solver's bodies, one slot each, in the caller's (stable) order.
#[derive(Clone, Debug, Default)]
pub struct SolverBodies {
    /// Per-substep state.
    pub states: Vec<BodyState>,
    /// Per-step parameters.
    pub params: Vec<BodyParams>,
    /// Centres of mass at the step's start.
    pub centers: Vec<Vec3>,
    /// Orientations at the step's start.
    pub orientations: Vec<Quat>,
    /// The slots of the bodies that turn with the gyroscopic term ([`BodyParams::gyroscopic`]),
    /// whose inertia turns with them (`turned_rows.rs`).
    pub gyroscopic: Vec<u32>,
}

/// Whether the three principal moments are equal (a ball, a cube): then `ω × Iω = 0` and the
/// gyroscopic term vanishes; the linearised update then turns the body by `2 atan(|ω| h / 2)`
/// instead of `|ω| h` (0.08 % short at 0.1 rad per substep), for a fraction of the exact
/// flow's cost.
fn isotropic(inverse_moments: Vec3) -> bool {
    inverse_moments.max_element() - inverse_moments.min_element()
        <= 1e-6 * inverse_moments.max_element()
}

/// A body's inverse inertia in world axes with its locked axes zeroed: `L R D Rᵀ L`, `R` the
/// principal frame in world axes, `D` the inverse principal moments, `L` the free axes on the
/// diagonal. Written out as column scalings around one product (`(R D) Rᵀ`, then entry `(i, j)`
/// times `fᵢ fⱼ`): the same numbers as the four matrix products for 0/1 locks (a zeroed entry
/// may differ in the sign of its zero), at a third of
/// the instructions (every awake body's gather computes it once a step).
fn world_inverse_inertia(b: &BodyInput) -> Mat3 {
    let m = free_inverse_inertia(b.orientation, b.inertia_frame, b.inverse_principal_inertia);
    let f = b.free_axes;
    Mat3::from_cols(m.x_axis * f * f.x, m.y_axis * f * f.y, m.z_axis * f * f.z)
}

/// The world inverse inertia `R D Rᵀ` of a body free to turn about every axis, at
/// `orientation`, its principal axes at `frame` in its frame with inverse moments `d`.
pub(super) fn free_inverse_inertia(orientation: Quat, frame: Quat, d: Vec3) -> Mat3 {
    let r = Mat3::from_quat(orientation * frame);
    let rd = Mat3::from_cols(r.x_axis * d.x, r.y_axis * d.y, r.z_axis * d.z);
    rd * r.transpose()
}

impl SolverBodies {
    /// Empties the arrays (keeping their memory).
    pub fn clear(&mut self) {
        self.states.clear();
        self.params.clear();
        self.centers.clear();
        self.orientations.clear();
        self.gyroscopic.clear();
    }

    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.states.len()
    }

    /// True when there is none.
    pub fn is_empty(&self) -> bool {
        self.states.is_empty()
    }

    /// Adds a body; returns its slot.
    pub fn push(&mut self, b: BodyInput) -> u32 {
        self.push_input(&b)
    }

    /// [`Self::push`] reading the input where it lies: a `BodyInput` (about 170 bytes) handed
    /// over by value is copied first, and the copy's wide loads wait on the narrower stores
    /// that just wrote it (the ECS gather's inputs were copied twice a body, a step).
    pub fn push_input(&mut self, b: &BodyInput) -> u32 {
        let slot = self.states.len() as u32;
        let dynamic = b.inverse_mass > 0.0;
        let inverse_inertia = if dynamic {
            world_inverse_inertia(b)
        } else {
            Mat3::ZERO
        };
        let linear_mask = if dynamic {
            b.free_translation
        } else {
            Vec3::ONE
        };
        self.states.push(BodyState {
            linear_velocity: b.linear_velocity * linear_mask,
            angular_velocity: b.angular_velocity * b.free_axes,
            ..Default::default()
        });
        self.params.push(BodyParams {
            inverse_mass: Vec3::splat(b.inverse_mass) * b.free_translation,
            inverse_inertia,
            linear_acceleration: if dynamic {
                b.linear_acceleration * b.free_translation
            } else {
                Vec3::ZERO
            },
            angular_acceleration: if dynamic {
                inverse_inertia * b.torque
            } else {
                Vec3::ZERO
            },
            linear_damping: b.linear_damping,
            angular_damping: b.angular_damping,
            dynamic,
            gyroscopic: (b.gyroscopic
                && dynamic
                && b.free_axes == Vec3::ONE
                && b.inverse_principal_inertia.cmpgt(Vec3::ZERO).all()
                && b.inverse_principal_inertia.is_finite()
                && !isotropic(b.inverse_principal_inertia))
            .then_some((b.inertia_frame, b.inverse_principal_inertia)),
        });
        if self.params[slot as usize].gyroscopic.is_some() {
            self.gyroscopic.push(slot);
        }
        self.centers.push(b.center);
        self.orientations.push(b.orientation);
        slot
    }

    /// Where body `i`'s centre of mass is now.
    pub fn center(&self, i: usize) -> Vec3 {
        self.centers[i] + self.states[i].delta_position
    }

    /// Body `i`'s orientation now.
    pub fn orientation(&self, i: usize) -> Quat {
        (self.states[i].delta_rotation * self.orientations[i]).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    /// The written-out product gives the four matrix products' numbers exactly, on random
    /// frames, moments and locks.
    #[test]
    fn world_inverse_inertia_equals_the_four_products_exactly_on_2000_random_bodies() {
        let mut rng = TestRng::new(7);
        for _ in 0..2000 {
            let bit = |rng: &mut TestRng| if rng.below(3) == 0 { 0.0 } else { 1.0 };
            let b = BodyInput {
                orientation: rng.rotation(),
                inertia_frame: rng.rotation(),
                inverse_principal_inertia: rng.vec3(0.01, 50.0),
                free_axes: Vec3::new(bit(&mut rng), bit(&mut rng), bit(&mut rng)),
                inverse_mass: 1.0,
                ..Default::default()
            };
            let r = Mat3::from_quat(b.orientation * b.inertia_frame);
            let lock = Mat3::from_diagonal(b.free_axes);
            let four =
                lock * r * Mat3::from_diagonal(b.inverse_principal_inertia) * r.transpose() * lock;
            assert_eq!(world_inverse_inertia(&b), four);
        }
    }
}
