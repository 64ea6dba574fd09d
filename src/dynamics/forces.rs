//! The forces of a step, gathered into one acceleration field.
//!
//! The slides' state grows from `(p, v)` to mass `m` and force `f` (`a = f/m`). Forces here are
//! kept as a *model* rather than summed into a number per body, because springs depend on
//! positions and drag on velocities: the integrator re-evaluates them at every intermediate
//! state it visits (see [`crate::dynamics::integrators`]). Each kind of force is stored only when
//! the scene has it, so a scene without springs pays nothing for springs.

use crate::dynamics::AccelerationField;
use glam::Vec3;

/// The far end of a spring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpringEnd {
    /// Another body, by its index in the step's body arrays.
    Body(usize),
    /// A fixed point in the world.
    Anchor(Vec3),
}

/// A damped linear spring (Hooke's law plus a dashpot along the spring's axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// The body the spring pulls, by index.
    pub body: usize,
    /// What the other end holds on to.
    pub other: SpringEnd,
    /// Length at which the spring exerts no force.
    pub rest_length: f32,
    /// Stiffness `k` (N/m).
    pub stiffness: f32,
    /// Damping `c` along the axis (N·s/m).
    pub damping: f32,
}

/// Largest `k·w·h²` (stiffness × the ends' summed inverse masses × step²) a spring may have:
/// an explicit spring step is stable while `ω·h < 2`, i.e. `k·w·h² < 4`; a sixteenth of that
/// keeps `ω·h = 1/2`, where the step still follows the oscillation (at `ω·h = 1` with the
/// damping bound below, a ball on such a spring next to contacts locked into a cycle).
pub const MAX_SPRING_STIFFNESS_RATIO: f32 = 0.25;

/// Largest `c·w·h` (damping × summed inverse masses × step) a spring may have: an explicit
/// dashpot overshoots and then diverges once `c·w·h > 2`; a quarter of that damps without
/// reversing the relative velocity.
pub const MAX_SPRING_DAMPING_RATIO: f32 = 0.5;

impl Spring {
    /// This spring with its stiffness and damping lowered into the range an explicit step `h`
    /// can follow, given the summed inverse masses `w` of its ends (see
    /// [`MAX_SPRING_STIFFNESS_RATIO`], [`MAX_SPRING_DAMPING_RATIO`]); `None` if it already was
    /// in range. Stiffer is not more rigid past that bound: it only diverges (a spring of
    /// 1e12 N/m at 60 Hz flings what it holds to 1e20 m/s).
    pub fn clamped_to_stability(&self, w: f32, h: f32) -> Option<Spring> {
        if !(w > 0.0 && h > 0.0) {
            return None;
        }
        let k_max = MAX_SPRING_STIFFNESS_RATIO / (w * h * h);
        let c_max = MAX_SPRING_DAMPING_RATIO / (w * h);
        (self.stiffness > k_max || self.damping > c_max).then(|| Spring {
            stiffness: self.stiffness.min(k_max),
            damping: self.damping.min(c_max),
            ..*self
        })
    }
}

/// All forces acting during one step, over bodies indexed `0..n`.
#[derive(Clone, Debug, Default)]
pub struct ForceModel {
    /// Uniform acceleration of every body with finite mass; `None` when the world has none.
    pub gravity: Option<Vec3>,
    /// `1/m` per body; 0 for infinite mass (no force moves it).
    pub inverse_mass: Vec<f32>,
    /// Constant force per body over the step; empty when no body has one.
    pub constant_force: Vec<Vec3>,
    /// Linear drag coefficient `b` per body (`f = -b v`); empty when no body has drag.
    pub linear_drag: Vec<f32>,
    /// Springs between bodies or to anchors.
    pub springs: Vec<Spring>,
}

impl ForceModel {
    /// Empties the model for a new step over `n` bodies, keeping allocations.
    pub fn reset(&mut self, n: usize) {
        self.gravity = None;
        self.inverse_mass.clear();
        self.inverse_mass.resize(n, 0.0);
        self.constant_force.clear();
        self.linear_drag.clear();
        self.springs.clear();
    }

    /// Number of bodies the model covers.
    pub fn len(&self) -> usize {
        self.inverse_mass.len()
    }

    /// True when the model covers no body.
    pub fn is_empty(&self) -> bool {
        self.inverse_mass.is_empty()
    }

    /// Force of `spring` on its body in the given state (the other end gets the opposite).
    pub fn spring_force(spring: &Spring, positions: &[Vec3], velocities: &[Vec3]) -> Vec3 {
        let (p, v) = (positions[spring.body], velocities[spring.body]);
        let (q, w) = match spring.other {
            SpringEnd::Body(j) => (positions[j], velocities[j]),
            SpringEnd::Anchor(a) => (a, Vec3::ZERO),
        };
        let d = q - p;
        let len = d.length();
        if len <= f32::EPSILON {
            // Both ends coincide: the axis is undefined, so the spring exerts no force.
            return Vec3::ZERO;
        }
        let axis = d / len;
        let stretch = len - spring.rest_length;
        let closing_speed = (w - v).dot(axis);
        axis * (spring.stiffness * stretch + spring.damping * closing_speed)
    }

    /// Potential energy of gravity and springs (for energy-drift measurements).
    pub fn potential_energy(&self, positions: &[Vec3]) -> f32 {
        let gravity: f32 = match self.gravity {
            Some(g) => positions
                .iter()
                .zip(&self.inverse_mass)
                .filter(|(_, im)| **im > 0.0)
                .map(|(p, im)| -g.dot(*p) / im)
                .sum(),
            None => 0.0,
        };
        let springs: f32 = self
            .springs
            .iter()
            .map(|s| {
                let q = match s.other {
                    SpringEnd::Body(j) => positions[j],
                    SpringEnd::Anchor(a) => a,
                };
                let stretch = (q - positions[s.body]).length() - s.rest_length;
                0.5 * s.stiffness * stretch * stretch
            })
            .sum();
        gravity + springs
    }

    /// Kinetic energy `Σ ½ m v²` over bodies of finite mass.
    pub fn kinetic_energy(&self, velocities: &[Vec3]) -> f32 {
        velocities
            .iter()
            .zip(&self.inverse_mass)
            .filter(|(_, im)| **im > 0.0)
            .map(|(v, im)| 0.5 * v.length_squared() / im)
            .sum()
    }
}

impl AccelerationField for ForceModel {
    fn accelerations(&self, _t: f32, positions: &[Vec3], velocities: &[Vec3], out: &mut [Vec3]) {
        let gravity = self.gravity.unwrap_or(Vec3::ZERO);
        for (a, im) in out.iter_mut().zip(&self.inverse_mass) {
            *a = if *im > 0.0 { gravity } else { Vec3::ZERO };
        }
        for ((a, f), im) in out
            .iter_mut()
            .zip(&self.constant_force)
            .zip(&self.inverse_mass)
        {
            *a += *f * *im;
        }
        for (i, b) in self.linear_drag.iter().enumerate() {
            out[i] -= velocities[i] * (*b * self.inverse_mass[i]);
        }
        for s in &self.springs {
            let f = Self::spring_force(s, positions, velocities);
            out[s.body] += f * self.inverse_mass[s.body];
            if let SpringEnd::Body(j) = s.other {
                out[j] -= f * self.inverse_mass[j];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{Integrator, IntegratorScratch, integrate};

    fn two_body_spring() -> ForceModel {
        let mut m = ForceModel::default();
        m.reset(2);
        m.inverse_mass = vec![1.0, 0.5];
        m.springs.push(Spring {
            body: 0,
            other: SpringEnd::Body(1),
            rest_length: 1.0,
            stiffness: 10.0,
            damping: 0.0,
        });
        m
    }

    #[test]
    fn spring_between_bodies_conserves_momentum_and_bounds_energy() {
        let model = two_body_spring();
        let mut p = [Vec3::ZERO, Vec3::new(1.5, 0.0, 0.0)];
        let mut v = [Vec3::new(0.0, 0.3, 0.0), Vec3::ZERO];
        let momentum = |v: &[Vec3]| v[0] * 1.0 + v[1] * 2.0;
        let energy = |p: &[Vec3], v: &[Vec3]| model.kinetic_energy(v) + model.potential_energy(p);
        let (m0, e0) = (momentum(&v), energy(&p, &v));
        let mut s = IntegratorScratch::default();
        for _ in 0..10_000 {
            integrate(
                Integrator::VelocityVerlet,
                0.01,
                &mut p,
                &mut v,
                &model,
                &mut s,
            );
        }
        assert!((momentum(&v) - m0).length() < 1e-4);
        assert!((energy(&p, &v) / e0 - 1.0).abs() < 1e-2);
    }

    #[test]
    fn drag_decays_velocity_exponentially() {
        let mut model = ForceModel::default();
        model.reset(1);
        model.inverse_mass[0] = 0.5;
        model.linear_drag.push(1.0); // v' = -(b/m) v = -0.5 v
        let (mut p, mut v) = ([Vec3::ZERO], [Vec3::X]);
        let mut s = IntegratorScratch::default();
        for _ in 0..100 {
            integrate(Integrator::Rk4, 0.02, &mut p, &mut v, &model, &mut s);
        }
        assert!((v[0].x - (-0.5f32 * 2.0).exp()).abs() < 1e-5);
    }

    #[test]
    fn infinite_mass_bodies_feel_no_force_and_coincident_spring_ends_are_inert() {
        let mut model = two_body_spring();
        model.inverse_mass[1] = 0.0;
        model.gravity = Some(Vec3::new(0.0, 0.0, -9.8));
        let mut out = [Vec3::ZERO; 2];
        model.accelerations(0.0, &[Vec3::ZERO, Vec3::ZERO], &[Vec3::ZERO; 2], &mut out);
        assert_eq!(out[1], Vec3::ZERO);
        assert_eq!(out[0], Vec3::new(0.0, 0.0, -9.8));
    }
}
