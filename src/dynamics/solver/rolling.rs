//! Rolling resistance: a contact resists the rolling of one body over the other with a torque
//! of at most `b N`, the normal force times a lever arm `b` (metres; the "coefficient of rolling
//! friction" of engineering tables, a few millimetres for a hard ball on a hard floor). Box2D
//! v3 has the same row (`rollingResistance`, clamped by the contact's total normal impulse).
//!
//! The rows are angular only. For a tangent `t` of the contact plane, the constraint is
//! `C' = t·(ω_b − ω_a) = 0`, Jacobian `[0, −t, 0, t]`, effective mass
//! `K = t·(I_a⁻¹ + I_b⁻¹) t`. Each relax pass takes the impulse `λ = −K⁻¹ t·(ω_b − ω_a)` on both
//! tangents and clamps the accumulated pair to the disc `|λ| ≤ b Σλ_n`, as Coulomb friction
//! clamps the linear rows: a rolling ball decelerates at `(b/R) g / (1 + I/(m R²))`, and a ball
//! resting on the floor feels nothing. Spin about the normal (drilling) is not resisted.

use crate::geometry::length_or_zero;
use glam::{Mat3, Vec3};

/// The rolling rows of one contact, prepared once per step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RollingRows {
    /// Lever arm `b` of the resistance (m); 0: no rows.
    pub arm: f32,
    /// `I⁻¹ t` of A and B, per tangent.
    turn: [[Vec3; 2]; 2],
    /// `1 / K` per tangent.
    mass: [f32; 2],
    /// Accumulated angular impulses along the two tangents (N·m·s).
    pub impulse: [f32; 2],
}

impl RollingRows {
    /// Rows for lever arm `arm` (a non-finite or negative one is 0: none) in the plane of
    /// `tangents`, with the world inverse inertias of A and B.
    pub fn new(arm: f32, tangents: [Vec3; 2], inverse_inertia: [Mat3; 2]) -> Self {
        let arm = length_or_zero(arm);
        if arm == 0.0 {
            return Self::default();
        }
        let turn = tangents.map(|t| [inverse_inertia[0] * t, inverse_inertia[1] * t]);
        let mass = [0, 1].map(|k| {
            let k_eff = tangents[k].dot(turn[k][0] + turn[k][1]);
            if k_eff > 0.0 { 1.0 / k_eff } else { 0.0 }
        });
        Self {
            arm,
            turn,
            mass,
            impulse: [0.0; 2],
        }
    }

    /// Applies the accumulated impulses again at a substep's start (as the other rows are:
    /// an accumulated impulse is a substep's impulse).
    pub fn warm_start(&self, wa: &mut Vec3, wb: &mut Vec3) {
        for k in 0..2 {
            *wa -= self.turn[k][0] * self.impulse[k];
            *wb += self.turn[k][1] * self.impulse[k];
        }
    }

    /// One pass: resists the relative angular velocity `wb − wa` along the tangents, within
    /// `arm` times the contact's total normal impulse.
    pub fn solve(&mut self, wa: &mut Vec3, wb: &mut Vec3, tangents: [Vec3; 2], normal: f32) {
        let limit = self.arm * normal.max(0.0);
        let old = self.impulse;
        let rate = |k: usize, wa: Vec3, wb: Vec3| tangents[k].dot(wb - wa);
        let mut wanted = [0.0f32; 2];
        for (k, w) in wanted.iter_mut().enumerate() {
            *w = old[k] - self.mass[k] * rate(k, *wa, *wb);
        }
        let length = (wanted[0] * wanted[0] + wanted[1] * wanted[1]).sqrt();
        let scale = if length > limit && length > 0.0 {
            limit / length
        } else {
            1.0
        };
        for k in 0..2 {
            let new = wanted[k] * scale;
            let delta = new - old[k];
            *wa -= self.turn[k][0] * delta;
            *wb += self.turn[k][1] * delta;
            self.impulse[k] = new;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rolling_ball_on_a_fixed_floor_loses_at_most_the_clamped_angular_impulse() {
        // Ball B (I⁻¹ = 2.5 for a unit solid sphere) rolling about x on an immovable floor A.
        let t = [Vec3::X, Vec3::Y];
        let mut rows =
            RollingRows::new(0.01, t, [Mat3::ZERO, Mat3::from_diagonal(Vec3::splat(2.5))]);
        let (mut wa, mut wb) = (Vec3::ZERO, Vec3::new(3.0, 0.0, 0.0));
        rows.solve(&mut wa, &mut wb, t, 10.0);
        // At most b Σλ_n = 0.1 N·m·s of angular impulse: ω drops by 0.1 × 2.5.
        assert!((wb.x - (3.0 - 0.25)).abs() < 1e-6, "{wb}");
        assert_eq!(wa, Vec3::ZERO);
        // With a large normal impulse the row stops the rolling altogether, and no more.
        let mut rows =
            RollingRows::new(0.01, t, [Mat3::ZERO, Mat3::from_diagonal(Vec3::splat(2.5))]);
        let mut wb = Vec3::new(3.0, 0.0, 0.7);
        rows.solve(&mut wa, &mut wb, t, 1e6);
        assert!(wb.x.abs() < 1e-6 && (wb.z - 0.7).abs() < 1e-6, "{wb}");
    }

    #[test]
    fn bad_or_zero_arms_make_no_rows() {
        for arm in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(
                RollingRows::new(arm, [Vec3::X, Vec3::Y], [Mat3::IDENTITY; 2]).arm,
                0.0
            );
        }
    }
}
