//! Soft constraints: a constraint that behaves as a critically tuned spring-damper instead of
//! a rigid rod, parameterised by a stiffness in hertz and a damping ratio (Catto, "Solver2D",
//! 2024, and Box2D v3's `b2MakeSoft`; Avian and rapier's TGS-soft use the same numbers).
//!
//! For a constraint `C` with effective mass `m`, the spring-damper `m C'' = −k C − c C'` with
//! `ω = √(k/m)` (`k = m ω²`, `c = 2 ζ m ω`) integrated by implicit Euler over a substep `h`
//! (`C₂ = C₁ + h C'₂`) gives, for the constraint's velocity `v = C'₂`,
//!
//! `m (v − v₁) = −h k (C₁ + h v) − h c v`
//!
//! whose impulse `λ = m (v − v₁)`, once `v` is solved for and written against the rigid
//! solution `λ_rigid = −m v₁`, is
//!
//! `λ = −m · mass_scale · (v₁ + bias_rate · C₁) − impulse_scale · λ_accumulated`
//!
//! with `bias_rate = ω / (2ζ + hω)`, `mass_scale = hω(2ζ + hω) / (1 + hω(2ζ + hω))` and
//! `impulse_scale = 1 / (1 + hω(2ζ + hω))`. The stiffness is thereby independent of the masses
//! and of the substep: a contact at 30 Hz pushes out of penetration over about 1/30 s whatever
//! it holds, which is what keeps stacks from fighting and piles from exploding.

/// The three coefficients of a soft constraint for one substep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Softness {
    /// Fraction of the position error turned into a velocity bias, per second (1/s).
    pub bias_rate: f32,
    /// Scale of the rigid impulse (0..1).
    pub mass_scale: f32,
    /// Scale of the accumulated impulse taken back each iteration (0..1).
    pub impulse_scale: f32,
}

impl Softness {
    /// A rigid constraint: no bias, full impulse.
    pub const RIGID: Self = Self {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    /// A constraint of stiffness `hertz` and `damping_ratio` over substeps of `h` seconds;
    /// `hertz <= 0` (or non-finite input) is rigid.
    pub fn new(hertz: f32, damping_ratio: f32, h: f32) -> Self {
        if !(hertz > 0.0 && hertz.is_finite() && h > 0.0 && damping_ratio >= 0.0) {
            return Self::RIGID;
        }
        let omega = 2.0 * std::f32::consts::PI * hertz;
        let a1 = 2.0 * damping_ratio + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit mass on a soft constraint `C = x` solved once per substep: the response of the
    /// implicit spring-damper.
    fn settle(hertz: f32, zeta: f32, h: f32, steps: usize) -> Vec<f32> {
        let soft = Softness::new(hertz, zeta, h);
        let (mut x, mut v) = (1.0f32, 0.0f32);
        let mut xs = Vec::new();
        for _ in 0..steps {
            // λ from zero accumulated impulse, unit effective mass.
            let lambda = -soft.mass_scale * (v + soft.bias_rate * x);
            v += lambda;
            x += h * v;
            xs.push(x);
        }
        xs
    }

    #[test]
    fn a_critically_damped_constraint_closes_its_error_without_overshoot() {
        let xs = settle(30.0, 1.0, 1.0 / 240.0, 240);
        assert!(
            xs.iter().all(|x| *x > -1e-3),
            "overshoot: {:?}",
            xs.iter().cloned().fold(0.0, f32::min)
        );
        // After a period at 30 Hz (1/30 s = 8 substeps) most of the error is gone.
        assert!(xs[16] < 0.2, "{}", xs[16]);
        assert!(xs[239].abs() < 1e-3);
    }

    #[test]
    fn stiffness_does_not_depend_on_the_substep_within_5_percent() {
        // The error left after 0.05 s at two substep sizes.
        let a = settle(10.0, 1.0, 1.0 / 240.0, 12)[11];
        let b = settle(10.0, 1.0, 1.0 / 480.0, 24)[23];
        assert!((a - b).abs() < 0.05, "{a} vs {b}");
    }

    #[test]
    fn zero_hertz_is_rigid() {
        assert_eq!(Softness::new(0.0, 1.0, 0.01), Softness::RIGID);
        assert_eq!(Softness::new(f32::NAN, 1.0, 0.01), Softness::RIGID);
    }
}
