//! Collision response: velocity impulses along contact normals and position correction.
//!
//! The slides' response is the reflection `v' = v - 2(v·N)N` of a velocity on a static surface.
//! Generalised with a coefficient of restitution `e` it becomes `v' = v - (1+e)(v·N)N`, and
//! between two movable bodies it becomes an impulse `j` along `N` shared by inverse mass, which
//! conserves momentum and, for `e = 1`, kinetic energy:
//!
//! `j = -(1+e) (v_b - v_a)·N / (1/m_a + 1/m_b)`, `v_a -= j N / m_a`, `v_b += j N / m_b`.
//!
//! With many simultaneous contacts (stacks, piles) single impulses fight each other, so contacts
//! are solved by sequential impulses with an accumulated, clamped impulse per contact (Catto,
//! "Iterative Dynamics with Temporal Coherence", GDC 2005): a few Gauss–Seidel sweeps converge to
//! the impulses that stop all approach at once. Penetration left by the discrete step is removed
//! by moving positions directly (no added velocity, so resting bodies neither sink nor jitter).
//! Response is linear: contacts push through the centre of mass (exact for spheres; boxes do not
//! spin from contacts).

use glam::Vec3;

/// The slides' reflection with restitution `e` about unit normal `n`: only the velocity
/// component *into* the surface (`v·n < 0`) is reflected and scaled by `e`.
pub fn reflect(v: Vec3, n: Vec3, e: f32) -> Vec3 {
    let vn = v.dot(n);
    if vn < 0.0 { v - (1.0 + e) * vn * n } else { v }
}

/// Tunables of the contact solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// Gauss–Seidel sweeps over the velocity constraints.
    pub velocity_iterations: u32,
    /// Sweeps of direct position correction.
    pub position_iterations: u32,
    /// Approach speeds below this (m/s) bounce with `e = 0`, so resting contact stays at rest
    /// instead of micro-bouncing on the velocity gravity adds every step.
    pub restitution_threshold: f32,
    /// Penetration tolerated without correction (m); keeps contacts alive between steps.
    pub slop: f32,
    /// Fraction of the remaining penetration removed per position sweep (0..=1).
    pub correction_fraction: f32,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            velocity_iterations: 8,
            position_iterations: 4,
            restitution_threshold: 0.5,
            slop: 0.002,
            correction_fraction: 0.8,
        }
    }
}

/// One contact between body `a` and body `b` (indices into the solver's arrays).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactConstraint {
    /// First body.
    pub a: usize,
    /// Second body.
    pub b: usize,
    /// Unit normal from `a` to `b`.
    pub normal: Vec3,
    /// Penetration depth at detection, `>= 0`.
    pub depth: f32,
    /// Coefficient of restitution of the pair.
    pub restitution: f32,
    /// Separation speed the solver aims for (from restitution), set by [`prepare`](Self::prepare).
    target_speed: f32,
    /// Impulse accumulated over the sweeps (`>= 0`: contacts push, never pull).
    accumulated: f32,
}

impl ContactConstraint {
    /// A contact from detection data.
    pub fn new(a: usize, b: usize, normal: Vec3, depth: f32, restitution: f32) -> Self {
        Self {
            a,
            b,
            normal,
            depth,
            restitution,
            target_speed: 0.0,
            accumulated: 0.0,
        }
    }

    /// Total normal impulse the solver applied (after [`solve_velocities`]).
    pub fn impulse(&self) -> f32 {
        self.accumulated
    }

    fn relative_speed(&self, v: &[Vec3]) -> f32 {
        (v[self.b] - v[self.a]).dot(self.normal)
    }

    fn prepare(&mut self, v: &[Vec3], settings: &SolverSettings) {
        let approach = -self.relative_speed(v);
        let e = if approach > settings.restitution_threshold {
            self.restitution
        } else {
            0.0
        };
        self.target_speed = e * approach.max(0.0);
        self.accumulated = 0.0;
    }
}

/// Solves the velocity constraints in place; `inverse_mass[i] == 0` marks immovable bodies.
pub fn solve_velocities(
    contacts: &mut [ContactConstraint],
    velocities: &mut [Vec3],
    inverse_mass: &[f32],
    settings: &SolverSettings,
) {
    for c in contacts.iter_mut() {
        c.prepare(velocities, settings);
    }
    for _ in 0..settings.velocity_iterations.max(1) {
        for c in contacts.iter_mut() {
            let (ia, ib) = (inverse_mass[c.a], inverse_mass[c.b]);
            let k = ia + ib;
            if k <= 0.0 {
                continue;
            }
            let error = c.target_speed - c.relative_speed(velocities);
            let new_total = (c.accumulated + error / k).max(0.0);
            let j = new_total - c.accumulated;
            c.accumulated = new_total;
            velocities[c.a] -= c.normal * (j * ia);
            velocities[c.b] += c.normal * (j * ib);
        }
    }
}

/// Pushes bodies apart along the contact normals until penetration is below `slop`, sharing
/// the motion by inverse mass. `positions` are moved in place.
pub fn correct_positions(
    contacts: &[ContactConstraint],
    positions: &mut [Vec3],
    inverse_mass: &[f32],
    settings: &SolverSettings,
    scratch: &mut Vec<Vec3>,
) {
    // Accumulated displacement per body, so later sweeps see the penetration that is left.
    scratch.clear();
    scratch.resize(positions.len(), Vec3::ZERO);
    for _ in 0..settings.position_iterations {
        for c in contacts {
            let (ia, ib) = (inverse_mass[c.a], inverse_mass[c.b]);
            let k = ia + ib;
            if k <= 0.0 {
                continue;
            }
            let depth = c.depth - (scratch[c.b] - scratch[c.a]).dot(c.normal);
            let push = settings.correction_fraction * (depth - settings.slop).max(0.0) / k;
            scratch[c.a] -= c.normal * (push * ia);
            scratch[c.b] += c.normal * (push * ib);
        }
    }
    for (p, d) in positions.iter_mut().zip(scratch.iter()) {
        *p += *d;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solve_one(va: Vec3, ma: f32, vb: Vec3, mb: f32, e: f32) -> [Vec3; 2] {
        let mut v = [va, vb];
        let im = [1.0 / ma, 1.0 / mb];
        let mut c = [ContactConstraint::new(0, 1, Vec3::X, 0.0, e)];
        let settings = SolverSettings {
            restitution_threshold: 0.0,
            ..Default::default()
        };
        solve_velocities(&mut c, &mut v, &im, &settings);
        v
    }

    #[test]
    fn reflection_is_the_slides_formula_for_e_one() {
        let v = Vec3::new(1.0, 0.0, -3.0);
        assert_eq!(reflect(v, Vec3::Z, 1.0), Vec3::new(1.0, 0.0, 3.0));
        assert_eq!(reflect(v, Vec3::Z, 0.5), Vec3::new(1.0, 0.0, 1.5));
        // Leaving the surface: untouched.
        assert_eq!(reflect(-v, Vec3::Z, 1.0), -v);
    }

    #[test]
    fn impulses_conserve_momentum_and_elastic_ones_conserve_energy() {
        let (va, vb, ma, mb) = (
            Vec3::new(2.0, 0.5, 0.0),
            Vec3::new(-1.0, 0.0, 0.3),
            1.0,
            3.0,
        );
        for e in [0.0, 0.3, 1.0] {
            let [wa, wb] = solve_one(va, ma, vb, mb, e);
            assert!(((va * ma + vb * mb) - (wa * ma + wb * mb)).length() < 1e-5);
            let closing_before = (va - vb).dot(Vec3::X);
            let separating_after = (wb - wa).dot(Vec3::X);
            assert!(
                (separating_after - e * closing_before).abs() < 1e-5,
                "e = {e}"
            );
            if e == 1.0 {
                let ke =
                    |a: Vec3, b: Vec3| 0.5 * (ma * a.length_squared() + mb * b.length_squared());
                assert!((ke(va, vb) - ke(wa, wb)).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn an_immovable_body_reflects_the_other() {
        let [wa, wb] = solve_one(
            Vec3::new(3.0, 1.0, 0.0),
            2.0,
            Vec3::ZERO,
            f32::INFINITY,
            1.0,
        );
        assert_eq!(wb, Vec3::ZERO);
        assert!((wa - reflect(Vec3::new(3.0, 1.0, 0.0), -Vec3::X, 1.0)).length() < 1e-6);
    }

    #[test]
    fn slow_approach_does_not_bounce_and_position_correction_respects_slop() {
        let settings = SolverSettings::default();
        let mut v = [Vec3::new(0.0, 0.0, -0.1), Vec3::ZERO];
        let im = [1.0, 0.0];
        let mut c = [ContactConstraint::new(0, 1, -Vec3::Z, 0.05, 1.0)];
        solve_velocities(&mut c, &mut v, &im, &settings);
        assert!(v[0].z.abs() < 1e-6, "resting contact bounced: {}", v[0]);
        let mut p = [Vec3::ZERO, Vec3::ZERO];
        correct_positions(&c, &mut p, &im, &settings, &mut Vec::new());
        let left = 0.05 - p[0].z;
        assert!(
            left > settings.slop - 1e-6 && left < settings.slop + 0.01,
            "{left}"
        );
    }
}
