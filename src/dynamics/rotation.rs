//! Rotation: orientations and angular velocities of rigid bodies advanced by one step `dt`.
//!
//! A rigid body turns by Euler's equations in the world frame,
//!
//! `q' = ½ [ω, 0] ⊗ q`, `d(I_w ω)/dt = τ`, so `ω' = I_w⁻¹ (τ − ω × I_w ω)`,
//!
//! with `I_w = R diag(I) Rᵀ` the inertia tensor turned into the world by the body's orientation
//! times its principal frame (`R = q · frame`). The last term is the *gyroscopic* one: without
//! it a free body keeps its angular velocity, which is only right for bodies with a spherical
//! inertia; with it the angular **momentum** `L = I_w ω` is what stays, and a box spun about its
//! intermediate axis flips over and over (the Dzhanibekov effect).
//!
//! How each [`Integrator`] treats rotation:
//! - with the gyroscopic term, the **Euler methods and velocity Verlet** split the step into
//!   torque kicks (`L += τ dt`) and the torque-free flow of [`FreeBody`](super::free_rotation)
//!   (a splitting about a symmetric body: exact angular momentum, bounded energy error): drift
//!   then kick (explicit), kick then drift (symplectic), half kick, drift, half kick (Verlet).
//!   The plain explicit update of `ω × Iω` gains energy until the body spins about its axis of
//!   least inertia, and the implicit one (Catto, "Numerical Methods", GDC 2015) loses
//!   momentum: both fail a free tumbling box;
//! - without it (or with an axis locked or of infinite inertia) the Euler methods update `ω` by
//!   the torque alone and turn by the old (explicit) or new (symplectic) one, and velocity
//!   Verlet takes the explicit midpoint rule on `(q, ω)`;
//! - **RK4** takes classic Runge–Kutta on `(q, ω)` (the quaternion as a 4-vector), gyroscopic
//!   term included when asked.
//!
//! Every method renormalises the quaternion at the end of the step. The orientation update
//! `exp(dt ω) q` is exact for a constant `ω` (a kinematic body turns at exactly its rate).
//! Angular drag is the exact decay `ω ← e^{−c dt} ω` applied after the step (operator
//! splitting): unconditionally stable, whatever `c dt`. Locked axes zero the world components
//! of the angular velocity and of the inverse inertia (as Avian and rapier lock world axes).
//! A body whose inertia is infinite about some axis (kinematic bodies, user overrides) takes no
//! gyroscopic term: it turns at its angular velocity plus what torques the finite axes allow.

use crate::dynamics::Integrator;
use crate::dynamics::free_rotation::FreeBody;
use glam::{Quat, Vec3, Vec4};

/// The rotational state of one body and what acts on it for the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngularBody {
    /// Orientation of the body's frame in the world (unit).
    pub orientation: Quat,
    /// Angular velocity in world axes (rad/s).
    pub angular_velocity: Vec3,
    /// `1/I` about each principal axis (kg⁻¹m⁻²); 0 = infinite inertia about that axis.
    pub inverse_principal_inertia: Vec3,
    /// Rotation from the principal axes to the body's frame.
    pub inertia_frame: Quat,
    /// Torque in world axes (N·m), constant over the step.
    pub torque: Vec3,
    /// Angular drag rate `c` (1/s): without torque `ω` decays as `e^{−c t}`.
    pub drag: f32,
    /// 1 where rotation about the world axis is free, 0 where it is locked.
    pub free_axes: Vec3,
}

impl Default for AngularBody {
    fn default() -> Self {
        Self {
            orientation: Quat::IDENTITY,
            angular_velocity: Vec3::ZERO,
            inverse_principal_inertia: Vec3::ZERO,
            inertia_frame: Quat::IDENTITY,
            torque: Vec3::ZERO,
            drag: 0.0,
            free_axes: Vec3::ONE,
        }
    }
}

impl AngularBody {
    /// Rotation from principal axes to the world at orientation `q`.
    fn principal_to_world(&self, q: Quat) -> Quat {
        q * self.inertia_frame
    }

    /// `I_w⁻¹ x` at orientation `q`, restricted to the free axes (`P I_w⁻¹ P`).
    pub fn apply_inverse_inertia(&self, q: Quat, x: Vec3) -> Vec3 {
        let r = self.principal_to_world(q);
        let local = r.inverse() * (x * self.free_axes);
        (r * (local * self.inverse_principal_inertia)) * self.free_axes
    }

    /// `I_w x` at orientation `q`; only meaningful when the inertia is finite on every axis.
    pub fn apply_inertia(&self, q: Quat, x: Vec3) -> Vec3 {
        let r = self.principal_to_world(q);
        r * ((r.inverse() * x) / self.inverse_principal_inertia)
    }

    /// True when every principal moment is finite (then `L = I_w ω` exists).
    pub fn has_finite_inertia(&self) -> bool {
        self.inverse_principal_inertia.cmpgt(Vec3::ZERO).all()
    }

    /// Angular momentum `I_w ω` about the centre of mass (infinite inertia: not defined, zero).
    pub fn angular_momentum(&self) -> Vec3 {
        if self.has_finite_inertia() {
            self.apply_inertia(self.orientation, self.angular_velocity)
        } else {
            Vec3::ZERO
        }
    }

    /// Rotational kinetic energy `½ ω·I_w ω` (0 when some inertia is infinite).
    pub fn kinetic_energy(&self) -> f32 {
        0.5 * self.angular_velocity.dot(self.angular_momentum())
    }

    /// `ω'` at state `(q, ω)`: torque, and the gyroscopic term when asked and defined.
    fn angular_acceleration(&self, q: Quat, w: Vec3, gyroscopic: bool) -> Vec3 {
        let mut tau = self.torque;
        if gyroscopic && self.has_finite_inertia() {
            tau -= w.cross(self.apply_inertia(q, w));
        }
        self.apply_inverse_inertia(q, tau)
    }

    /// True when the step would change nothing (no spin, no torque): such bodies are skipped.
    pub fn is_still(&self) -> bool {
        self.angular_velocity == Vec3::ZERO
            && (self.torque == Vec3::ZERO || self.inverse_principal_inertia == Vec3::ZERO)
    }
}

/// How rotation is integrated, beyond the method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RotationOptions {
    /// Include the gyroscopic term (conserve angular momentum rather than angular velocity).
    pub gyroscopic: bool,
}

impl Default for RotationOptions {
    fn default() -> Self {
        Self { gyroscopic: true }
    }
}

/// `exp(dt ω) q`: `q` turned by the constant angular velocity `ω` for `dt`.
pub fn turn(q: Quat, w: Vec3, dt: f32) -> Quat {
    (Quat::from_scaled_axis(w * dt) * q).normalize()
}

/// Advances every body by `dt` with `method`. Bodies that neither spin nor feel a torque are
/// left untouched (bit for bit).
pub fn integrate_rotations(
    method: Integrator,
    dt: f32,
    options: RotationOptions,
    bodies: &mut [AngularBody],
) {
    for body in bodies.iter_mut().filter(|b| !b.is_still()) {
        body.angular_velocity *= body.free_axes;
        let (q, w) = step_body(body, method, dt, options.gyroscopic);
        body.orientation = q.normalize();
        body.angular_velocity = w * (-body.drag * dt).exp() * body.free_axes;
    }
}

/// One method's step for one body.
fn step_body(b: &AngularBody, method: Integrator, dt: f32, gyroscopic: bool) -> (Quat, Vec3) {
    let splittable = b.has_finite_inertia() && b.free_axes == Vec3::ONE;
    match method {
        Integrator::Rk4 => rk4(b, dt, gyroscopic),
        _ if gyroscopic && splittable => split(b, method, dt),
        Integrator::ExplicitEuler => euler(b, dt, false),
        Integrator::SymplecticEuler => euler(b, dt, true),
        Integrator::VelocityVerlet => midpoint(b, dt, gyroscopic),
    }
}

/// Torque kicks around the exact-momentum free flow of [`FreeBody`]: drift then kick
/// (explicit Euler), kick then drift (symplectic Euler), or half kick, drift, half kick
/// (velocity Verlet, second order).
fn split(b: &AngularBody, method: Integrator, dt: f32) -> (Quat, Vec3) {
    let mut free = FreeBody::new(
        b.orientation,
        b.inertia_frame,
        b.inverse_principal_inertia,
        b.angular_velocity,
    );
    let impulse = b.torque * dt;
    match method {
        Integrator::ExplicitEuler => {
            free.drift(dt as f64);
            free.kick(impulse);
        }
        Integrator::VelocityVerlet => {
            free.kick(impulse * 0.5);
            free.drift(dt as f64);
            free.kick(impulse * 0.5);
        }
        _ => {
            free.kick(impulse);
            free.drift(dt as f64);
        }
    }
    (free.orientation(b.inertia_frame), free.angular_velocity())
}

/// Explicit or symplectic Euler without the gyroscopic term: the angular velocity changes only
/// by the torque, and the orientation turns by the old or the new one.
fn euler(b: &AngularBody, dt: f32, velocity_first: bool) -> (Quat, Vec3) {
    let (q0, w0) = (b.orientation, b.angular_velocity);
    let w1 = w0 + dt * b.angular_acceleration(q0, w0, false);
    let w_turn = if velocity_first { w1 } else { w0 };
    (turn(q0, w_turn, dt), w1)
}

/// The explicit midpoint rule: slopes at the start, then at the half step.
fn midpoint(b: &AngularBody, dt: f32, gyroscopic: bool) -> (Quat, Vec3) {
    let (q0, w0) = (b.orientation, b.angular_velocity);
    let a0 = b.angular_acceleration(q0, w0, gyroscopic);
    let q_half = turn(q0, w0, 0.5 * dt);
    let w_half = w0 + 0.5 * dt * a0;
    let a_half = b.angular_acceleration(q_half, w_half, gyroscopic);
    (turn(q0, w_half, dt), w0 + dt * a_half)
}

/// `q'` as a 4-vector: `½ [ω, 0] ⊗ q`.
fn quat_rate(q: Vec4, w: Vec3) -> Vec4 {
    Vec4::from(Quat::from_xyzw(w.x, w.y, w.z, 0.0) * Quat::from_vec4(q)) * 0.5
}

/// Classic RK4 on `(q, ω)`.
fn rk4(b: &AngularBody, dt: f32, gyroscopic: bool) -> (Quat, Vec3) {
    let (q0, w0) = (Vec4::from(b.orientation), b.angular_velocity);
    let slope = |q: Vec4, w: Vec3| {
        let unit = Quat::from_vec4(q).normalize();
        (quat_rate(q, w), b.angular_acceleration(unit, w, gyroscopic))
    };
    let (kq1, kw1) = slope(q0, w0);
    let (kq2, kw2) = slope(q0 + kq1 * (0.5 * dt), w0 + kw1 * (0.5 * dt));
    let (kq3, kw3) = slope(q0 + kq2 * (0.5 * dt), w0 + kw2 * (0.5 * dt));
    let (kq4, kw4) = slope(q0 + kq3 * dt, w0 + kw3 * dt);
    let q1 = q0 + (kq1 + 2.0 * kq2 + 2.0 * kq3 + kq4) * (dt / 6.0);
    let w1 = w0 + (kw1 + 2.0 * kw2 + 2.0 * kw3 + kw4) * (dt / 6.0);
    (Quat::from_vec4(q1).normalize(), w1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box-like body with distinct principal moments 1, 2, 3 turned off the world axes.
    fn tumbling(w: Vec3) -> AngularBody {
        AngularBody {
            orientation: Quat::from_rotation_x(0.3) * Quat::from_rotation_z(0.7),
            angular_velocity: w,
            inverse_principal_inertia: Vec3::new(1.0, 0.5, 1.0 / 3.0),
            ..Default::default()
        }
    }

    fn run(mut body: AngularBody, method: Integrator, dt: f32, steps: usize) -> AngularBody {
        let options = RotationOptions::default();
        for _ in 0..steps {
            integrate_rotations(method, dt, options, std::slice::from_mut(&mut body));
        }
        body
    }

    #[test]
    fn a_constant_spin_turns_by_exactly_its_angle_within_1e_5_rad() {
        let spin = AngularBody {
            angular_velocity: Vec3::new(0.0, 0.0, 2.0),
            ..Default::default()
        };
        for method in Integrator::ALL {
            let end = run(spin, method, 0.01, 100);
            let expected = Quat::from_rotation_z(2.0);
            // |q − q'| ≈ half the angle between them (acos loses precision this close to 1).
            let gap = (end.orientation - expected)
                .length()
                .min((end.orientation + expected).length());
            assert!(2.0 * gap < 1e-5, "{method:?}: {gap}");
        }
    }

    #[test]
    fn euler_methods_conserve_a_free_bodys_angular_momentum_within_1e_5() {
        let body = tumbling(Vec3::new(1.0, 2.0, -0.5));
        let l0 = body.angular_momentum();
        for method in [Integrator::ExplicitEuler, Integrator::SymplecticEuler] {
            let end = run(body, method, 1.0 / 60.0, 600);
            let drift = (end.angular_momentum() - l0).length() / l0.length();
            assert!(drift < 1e-5, "{method:?}: {drift}");
        }
    }

    #[test]
    fn higher_order_methods_conserve_energy_and_momentum_within_1e_3() {
        let body = tumbling(Vec3::new(1.0, 2.0, -0.5));
        let (l0, e0) = (body.angular_momentum(), body.kinetic_energy());
        for method in [Integrator::VelocityVerlet, Integrator::Rk4] {
            let end = run(body, method, 1.0 / 240.0, 2400);
            let dl = (end.angular_momentum() - l0).length() / l0.length();
            let de = (end.kinetic_energy() - e0).abs() / e0;
            assert!(dl < 1e-3 && de < 1e-3, "{method:?}: {dl} {de}");
        }
    }

    #[test]
    fn torque_about_a_principal_axis_gives_alpha_equal_tau_over_i_within_1e_4() {
        let mut body = tumbling(Vec3::ZERO);
        body.orientation = Quat::IDENTITY;
        body.torque = Vec3::new(0.0, 3.0, 0.0);
        for method in Integrator::ALL {
            let end = run(body, method, 0.01, 100);
            // I_y = 2: α = 1.5 rad/s², ω(1 s) = 1.5.
            assert!((end.angular_velocity - Vec3::new(0.0, 1.5, 0.0)).length() < 1e-4);
        }
    }

    #[test]
    fn locked_axes_keep_their_components_at_exactly_zero() {
        let mut body = tumbling(Vec3::new(1.0, 2.0, -0.5));
        body.free_axes = Vec3::new(0.0, 0.0, 1.0);
        body.torque = Vec3::new(5.0, 5.0, 5.0);
        for method in Integrator::ALL {
            let end = run(body, method, 1.0 / 60.0, 120);
            assert_eq!(end.angular_velocity.x, 0.0);
            assert_eq!(end.angular_velocity.y, 0.0);
            assert!(end.angular_velocity.z.abs() > 0.1);
        }
    }

    #[test]
    fn drag_decays_as_the_exponential_even_when_c_dt_is_huge() {
        let mut body = tumbling(Vec3::new(0.0, 0.0, 4.0));
        body.drag = 1e6;
        let end = run(body, Integrator::SymplecticEuler, 1.0 / 60.0, 1);
        assert!(end.angular_velocity.is_finite());
        assert!(end.angular_velocity.length() < 1e-6);
        body.drag = 0.5;
        let end = run(body, Integrator::Rk4, 0.01, 100);
        let expected = 4.0 * (-0.5f32).exp();
        assert!((end.angular_velocity.length() / expected - 1.0).abs() < 0.05);
    }

    #[test]
    fn a_still_body_is_left_bit_identical() {
        let body = tumbling(Vec3::ZERO);
        let end = run(body, Integrator::Rk4, 0.1, 10);
        assert_eq!(end, body);
    }

    #[test]
    fn infinite_inertia_ignores_torque_and_spins_at_its_rate() {
        let body = AngularBody {
            angular_velocity: Vec3::new(0.0, 1.0, 0.0),
            torque: Vec3::splat(100.0),
            ..Default::default()
        };
        for method in Integrator::ALL {
            let end = run(body, method, 0.01, 50);
            assert_eq!(end.angular_velocity, body.angular_velocity);
            assert!(end.orientation.is_finite());
        }
    }
}
