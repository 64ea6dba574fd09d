//! Moving the bodies through a substep: velocities from gravity, forces and damping, then
//! positions and orientations from the velocities (Box2D v3's `b2IntegrateVelocitiesTask` and
//! `b2IntegratePositionsTask`), with the speed and spin bounds of [`SoftStepSettings`](super::SoftStepSettings)
//! (Box2D's `maximumLinearSpeed` and `B2_MAX_ROTATION`, Jolt's `mMaxLinearVelocity`).

use super::body::SolverBodies;
use crate::dynamics::free_rotation::FreeBody;
use glam::{Quat, Vec3};

/// Gravity, forces and torques for one substep, then damping by the exact decay `e^{−h c}`
/// (stable for any rate, and free drift decays as `e^{−c t}` whatever the substep; Box2D's
/// `1/(1 + h c)` is its first-order approximation). Kinematic and static bodies keep their
/// velocities.
pub(super) fn integrate_velocities(bodies: &mut SolverBodies, h: f32) {
    let decay = |c: f32| if c > 0.0 { (-h * c).exp() } else { 1.0 };
    for (state, p) in bodies.states.iter_mut().zip(&bodies.params) {
        if !p.dynamic {
            continue;
        }
        state.linear_velocity =
            (state.linear_velocity + p.linear_acceleration * h) * decay(p.linear_damping);
        state.angular_velocity =
            (state.angular_velocity + p.angular_acceleration * h) * decay(p.angular_damping);
    }
}

/// Moves every body by its velocity for one substep: `dp += h v` (a dynamic body's `v` at most
/// `max_speed`), and `dq` turned by `h ω` (the linearised quaternion update, renormalised, as
/// Box2D; at most `max_rotation` per substep, for every body). A gyroscopic body turning
/// noticeably instead follows the free rigid body's exact flow for `h` ([`FreeBody`]:
/// a splitting about a symmetric body, momentum exact), which also updates `ω`.
pub(super) fn integrate_positions(
    bodies: &mut SolverBodies,
    h: f32,
    max_rotation: f32,
    max_speed: f32,
) {
    for (i, state) in bodies.states.iter_mut().enumerate() {
        if bodies.params[i].dynamic {
            state.linear_velocity = capped(state.linear_velocity, max_speed);
        }
        state.delta_position += state.linear_velocity * h;
        let mut w = state.angular_velocity;
        if w == Vec3::ZERO {
            continue;
        }
        let turn = w.length() * h;
        if turn > max_rotation {
            w *= max_rotation / turn;
            state.angular_velocity = w;
        }
        let dq = state.delta_rotation;
        if let Some((frame, inverse_moments)) = bodies.params[i].gyroscopic
            && turn > GYROSCOPIC_MIN_TURN
        {
            let start = bodies.orientations[i];
            let mut free = FreeBody::new(dq * start, frame, inverse_moments, w);
            free.drift(f64::from(h));
            state.delta_rotation = (free.orientation(frame) * start.inverse()).normalize();
            state.angular_velocity = free.angular_velocity();
            continue;
        }
        let spin = Quat::from_xyzw(w.x, w.y, w.z, 0.0) * dq;
        state.delta_rotation = (dq + spin * (0.5 * h)).normalize();
    }
}

/// `v` shortened to `max` if it is longer (applied to dynamic bodies only). A length too large
/// to square is taken after scaling by the largest component, so a vector near `f32::MAX` is
/// shortened, not zeroed; a non-finite one is left for the step's guard to quarantine.
pub(super) fn capped(v: Vec3, max: f32) -> Vec3 {
    let squared = v.length_squared();
    if squared <= max * max || !v.is_finite() {
        return v;
    }
    let unit = if squared.is_finite() {
        v / squared.sqrt()
    } else {
        (v / v.abs().max_element()).normalize()
    };
    unit * max
}

/// Below this turn per substep (rad) the gyroscopic term changes `ω` by less than `turn²` of
/// itself per substep, far below the contacts' own error: the linearised update is used.
const GYROSCOPIC_MIN_TURN: f32 = 1e-4;

#[cfg(test)]
mod tests {
    use super::capped;
    use glam::Vec3;

    #[test]
    fn capped_shortens_to_the_bound_within_1e_6_keeps_shorter_and_non_finite_vectors() {
        for v in [
            Vec3::new(283.0, 293.0, -6.0),
            Vec3::new(f32::MAX, -f32::MAX, f32::MAX),
            Vec3::new(1e30, 0.0, 0.0),
        ] {
            let c = capped(v, 400.0);
            assert!((c.length() / 400.0 - 1.0).abs() < 1e-6, "{v} -> {c}");
            assert!(
                c.normalize()
                    .dot(v / v.abs().max_element())
                    .is_sign_positive()
            );
        }
        for v in [Vec3::new(230.0, 230.0, 230.0), Vec3::ZERO, Vec3::X * 400.0] {
            assert_eq!(capped(v, 400.0), v);
        }
        assert!(capped(Vec3::new(f32::NAN, 1.0, 0.0), 400.0).x.is_nan());
        assert!(capped(Vec3::INFINITY, 400.0).x.is_infinite());
    }
}
