//! The torque-free motion of a rigid body by splitting (McLachlan 1993, "Explicit Lie–Poisson
//! integration and the Euler equations"; Dullweber, Leimkuhler & McLachlan 1997, "Symplectic
//! splitting methods for rigid body molecular dynamics").
//!
//! In the principal frame the kinetic energy `H = Σ Πᵢ²/(2Iᵢ)` of the body momentum `Π` is a
//! sum of three terms, and the flow of each one alone is a plain rotation: under
//! `Hᵢ = Πᵢ²/(2Iᵢ)` the body turns about its principal axis `eᵢ` by `θ = h Πᵢ / Iᵢ` and `Π` turns
//! the opposite way, so the world momentum `L = R Π` does not change at all. Composing the
//! three flows symmetrically (Strang: `1(h/2) 2(h/2) 3(h) 2(h/2) 1(h/2)`) gives a second-order,
//! symplectic and time-reversible step that
//! - conserves the angular momentum exactly (only rotations are applied to it), and
//! - keeps the kinetic energy within a bounded error forever (no drift),
//!
//! where the explicit momentum update drifts towards spinning about the axis of least inertia
//! (energy grows) and the implicit one of Catto (GDC 2015) towards the axis of most inertia
//! (energy and momentum decay). The flip of a body spun about its intermediate axis (the
//! Dzhanibekov effect) then keeps its analytic period. It runs in f64 with renormalised
//! quaternions: the ulps by which an f32 unit quaternion is off would otherwise scale the
//! momentum every step (about 2e-7 a step for a tumbling box).

use glam::{DQuat, DVec3, Quat, Vec3};

/// A body in free rotation: principal-to-world rotation and the world angular momentum.
#[derive(Clone, Copy, Debug)]
pub struct FreeBody {
    /// Rotation from the principal axes to the world.
    principal_to_world: DQuat,
    /// Principal moments of inertia (finite, `> 0`).
    moments: DVec3,
    /// Angular momentum in world axes.
    momentum: DVec3,
}

impl FreeBody {
    /// A body at orientation `orientation` whose principal axes sit at `inertia_frame` in its
    /// own frame, with `1/I` per principal axis (all `> 0`) and world angular velocity `w`.
    pub fn new(orientation: Quat, inertia_frame: Quat, inverse_moments: Vec3, w: Vec3) -> Self {
        let principal_to_world = (orientation.as_dquat() * inertia_frame.as_dquat()).normalize();
        let moments = DVec3::ONE / inverse_moments.as_dvec3();
        let local = principal_to_world.inverse() * w.as_dvec3();
        Self {
            principal_to_world,
            moments,
            momentum: principal_to_world * (local * moments),
        }
    }

    /// Adds an angular impulse (world N·m·s): a torque kick.
    pub fn kick(&mut self, impulse: Vec3) {
        self.momentum += impulse.as_dvec3();
    }

    /// Lets the body turn freely for `h` seconds (the Strang composition of the module doc).
    pub fn drift(&mut self, h: f64) {
        let mut pi = self.principal_to_world.inverse() * self.momentum;
        let mut r = self.principal_to_world;
        for (axis, fraction) in [(0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)] {
            let theta = fraction * h * pi[axis] / self.moments[axis];
            let turn = AxisTurn::new(theta);
            pi = turn.rotate_back(axis, pi);
            r *= turn.quat(axis);
        }
        self.principal_to_world = r.normalize();
    }

    /// The body's orientation, given its principal axes' place in its frame.
    pub fn orientation(&self, inertia_frame: Quat) -> Quat {
        (self.principal_to_world * inertia_frame.as_dquat().inverse())
            .normalize()
            .as_quat()
    }

    /// World angular velocity `R I⁻¹ Rᵀ L`.
    pub fn angular_velocity(&self) -> Vec3 {
        let r = self.principal_to_world;
        (r * ((r.inverse() * self.momentum) / self.moments)).as_vec3()
    }
}

/// A turn by `φ` about a principal axis, as the quaternion `(sin(φ/2) e, cos(φ/2))` and the
/// matching 2D rotation. The half angle's sine and cosine are taken in f32 (half the cost of
/// f64's, and the angle need be no better than the state it turns) and renormalised in f64, so
/// the turn is an exact rotation: `Π` and the body turn by the same `φ`, which is all the exact
/// conservation of momentum needs.
struct AxisTurn {
    /// `cos φ`, `sin φ`.
    cos: f64,
    sin: f64,
    /// `sin(φ/2)`, `cos(φ/2)`.
    half_sin: f64,
    half_cos: f64,
}

impl AxisTurn {
    fn new(phi: f64) -> Self {
        let (s, c) = ((0.5 * phi) as f32).sin_cos();
        let (s, c) = (s as f64, c as f64);
        let norm = 1.0 / (s * s + c * c).sqrt();
        let (half_sin, half_cos) = (s * norm, c * norm);
        Self {
            cos: half_cos * half_cos - half_sin * half_sin,
            sin: 2.0 * half_sin * half_cos,
            half_sin,
            half_cos,
        }
    }

    /// `v` turned by `−φ` about coordinate axis `axis`.
    fn rotate_back(&self, axis: usize, v: DVec3) -> DVec3 {
        let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut out = v;
        out[j] = self.cos * v[j] + self.sin * v[k];
        out[k] = -self.sin * v[j] + self.cos * v[k];
        out
    }

    /// The turn by `+φ` about coordinate axis `axis`, as a quaternion.
    fn quat(&self, axis: usize) -> DQuat {
        let mut xyz = DVec3::ZERO;
        xyz[axis] = self.half_sin;
        DQuat::from_xyzw(xyz.x, xyz.y, xyz.z, self.half_cos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn energy(b: &FreeBody) -> f64 {
        let pi = b.principal_to_world.inverse() * b.momentum;
        0.5 * (pi * pi / b.moments).element_sum()
    }

    #[test]
    fn free_flow_keeps_momentum_to_1e_12_and_energy_within_1e_3_over_100_000_steps() {
        let mut b = FreeBody::new(
            Quat::from_rotation_x(0.4),
            Quat::IDENTITY,
            Vec3::new(1.0, 0.5, 0.25),
            Vec3::new(0.3, 4.0, 0.2),
        );
        let (l0, e0) = (b.momentum, energy(&b));
        let mut worst = 0.0f64;
        for _ in 0..100_000 {
            b.drift(1.0 / 60.0);
            worst = worst.max((energy(&b) / e0 - 1.0).abs());
        }
        assert!((b.momentum - l0).length() / l0.length() < 1e-12);
        assert!(worst < 1e-3, "energy error {worst}");
    }

    #[test]
    fn an_axis_turn_matches_the_quaternion_it_composes_with() {
        for theta in [-1.3, -0.1, 0.0, 0.02, 0.7] {
            let turn = AxisTurn::new(theta);
            for axis in 0..3 {
                let v = DVec3::new(0.3, -1.2, 2.0);
                let by_quat = turn.quat(axis).inverse() * v;
                assert!((turn.rotate_back(axis, v) - by_quat).length() < 1e-12);
            }
        }
    }

    #[test]
    fn a_spin_about_a_principal_axis_stays_put() {
        let mut b = FreeBody::new(
            Quat::IDENTITY,
            Quat::IDENTITY,
            Vec3::new(1.0, 0.5, 0.25),
            Vec3::Z,
        );
        b.drift(1.0);
        assert!((b.angular_velocity() - Vec3::Z).length() < 1e-6);
        assert!(
            b.orientation(Quat::IDENTITY)
                .angle_between(Quat::from_rotation_z(1.0))
                < 1e-3
        );
    }
}
