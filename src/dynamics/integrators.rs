//! Time integrators: advance positions and velocities of many bodies by one step `dt`.
//!
//! The slides' step is explicit Euler (`p += dt*v; v += dt*a`, the old velocity moves the
//! position). It is the cheapest and the least accurate, and it pumps energy into oscillators.
//! The alternatives trade evaluations of the acceleration for accuracy:
//!
//! | method | order | acceleration evaluations / step | energy on a spring |
//! |---|---|---|---|
//! | explicit Euler | 1 | 1 | grows by `(1 + ω²dt²)` per step |
//! | semi-implicit (symplectic) Euler | 1 | 1 | bounded (symplectic) |
//! | velocity Verlet | 2 | 2 | bounded (symplectic, time-reversible) |
//! | classic Runge–Kutta (RK4) | 4 | 4 | slowly decays |
//!
//! (Hairer, Lubich, Wanner, *Geometric Numerical Integration*, 2006.) The acceleration is not a
//! per-body number but a field over the whole state ([`AccelerationField`]), so that
//! position-dependent forces (springs) and velocity-dependent ones (drag) are re-evaluated at the
//! intermediate states the higher-order methods need; with a precomputed acceleration they would
//! all collapse to first order.

use glam::Vec3;

/// Which method advances the state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Integrator {
    /// The slides' step: position moves with the old velocity.
    ExplicitEuler,
    /// Velocity first, then position with the new velocity (symplectic; the game default).
    #[default]
    SymplecticEuler,
    /// Störmer–Verlet in velocity form, second order and symplectic.
    VelocityVerlet,
    /// Classic fourth-order Runge–Kutta.
    Rk4,
}

impl Integrator {
    /// Every method, in order of increasing cost.
    pub const ALL: [Integrator; 4] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::VelocityVerlet,
        Integrator::Rk4,
    ];

    /// Order of global accuracy: halving `dt` divides the error by about `2^order`.
    pub fn order(self) -> u32 {
        match self {
            Self::ExplicitEuler | Self::SymplecticEuler => 1,
            Self::VelocityVerlet => 2,
            Self::Rk4 => 4,
        }
    }

    /// How many times one step evaluates the acceleration field.
    pub fn evaluations_per_step(self) -> u32 {
        match self {
            Self::ExplicitEuler | Self::SymplecticEuler => 1,
            Self::VelocityVerlet => 2,
            Self::Rk4 => 4,
        }
    }

    /// A short human name, for tables and plots.
    pub fn name(self) -> &'static str {
        match self {
            Self::ExplicitEuler => "explicit Euler",
            Self::SymplecticEuler => "symplectic Euler",
            Self::VelocityVerlet => "velocity Verlet",
            Self::Rk4 => "RK4",
        }
    }
}

/// The accelerations of all bodies as a function of the whole state.
pub trait AccelerationField {
    /// Writes into `out[i]` the acceleration of body `i` at time `t` (relative to the step's
    /// start) in the state (`positions`, `velocities`).
    fn accelerations(&self, t: f32, positions: &[Vec3], velocities: &[Vec3], out: &mut [Vec3]);
}

/// A uniform acceleration, e.g. gravity alone.
impl AccelerationField for Vec3 {
    fn accelerations(&self, _t: f32, _p: &[Vec3], _v: &[Vec3], out: &mut [Vec3]) {
        out.fill(*self);
    }
}

/// Any closure with the field's signature is a field (handy in tests and reports).
impl<F> AccelerationField for F
where
    F: Fn(f32, &[Vec3], &[Vec3], &mut [Vec3]),
{
    fn accelerations(&self, t: f32, p: &[Vec3], v: &[Vec3], out: &mut [Vec3]) {
        self(t, p, v, out)
    }
}

/// Reusable buffers for the intermediate states, so a step allocates nothing once warm.
#[derive(Default, Debug)]
pub struct IntegratorScratch {
    k: [Vec<Vec3>; 4],
    l: [Vec<Vec3>; 4],
    tmp_p: Vec<Vec3>,
    tmp_v: Vec<Vec3>,
}

impl IntegratorScratch {
    fn resize(&mut self, n: usize) {
        for b in self.k.iter_mut().chain(self.l.iter_mut()) {
            b.resize(n, Vec3::ZERO);
        }
        self.tmp_p.resize(n, Vec3::ZERO);
        self.tmp_v.resize(n, Vec3::ZERO);
    }
}

/// Advances every body by `dt` with `method`. `positions` and `velocities` have one entry per
/// body and the same length.
pub fn integrate(
    method: Integrator,
    dt: f32,
    positions: &mut [Vec3],
    velocities: &mut [Vec3],
    field: &impl AccelerationField,
    scratch: &mut IntegratorScratch,
) {
    debug_assert_eq!(positions.len(), velocities.len());
    scratch.resize(positions.len());
    match method {
        Integrator::ExplicitEuler => euler(dt, positions, velocities, field, scratch, false),
        Integrator::SymplecticEuler => euler(dt, positions, velocities, field, scratch, true),
        Integrator::VelocityVerlet => velocity_verlet(dt, positions, velocities, field, scratch),
        Integrator::Rk4 => rk4(dt, positions, velocities, field, scratch),
    }
}

/// Explicit (the slides') or symplectic Euler: one field evaluation, then the same two updates
/// in the opposite order. Updating the velocity first makes the position step use the new
/// velocity, which is all that separates energy growth from bounded energy error.
fn euler(
    dt: f32,
    p: &mut [Vec3],
    v: &mut [Vec3],
    field: &impl AccelerationField,
    s: &mut IntegratorScratch,
    velocity_first: bool,
) {
    let a = &mut s.k[0];
    field.accelerations(0.0, p, v, a);
    for ((p, v), a) in p.iter_mut().zip(v.iter_mut()).zip(a.iter()) {
        if velocity_first {
            *v += *a * dt;
            *p += *v * dt;
        } else {
            *p += *v * dt;
            *v += *a * dt;
        }
    }
}

/// Velocity Verlet. With velocity-dependent forces the end-of-step acceleration is evaluated at
/// the half-step velocity `v + a0*dt/2`, the usual explicit choice (it keeps second order).
fn velocity_verlet(
    dt: f32,
    p: &mut [Vec3],
    v: &mut [Vec3],
    field: &impl AccelerationField,
    s: &mut IntegratorScratch,
) {
    let [a0, a1, ..] = &mut s.k;
    field.accelerations(0.0, p, v, a0);
    for i in 0..p.len() {
        p[i] += v[i] * dt + a0[i] * (0.5 * dt * dt);
        s.tmp_v[i] = v[i] + a0[i] * (0.5 * dt);
    }
    field.accelerations(dt, p, &s.tmp_v, a1);
    for i in 0..p.len() {
        v[i] += (a0[i] + a1[i]) * (0.5 * dt);
    }
}

/// Classic RK4 on the first-order system `p' = v, v' = a(p, v)`.
fn rk4(
    dt: f32,
    p: &mut [Vec3],
    v: &mut [Vec3],
    field: &impl AccelerationField,
    s: &mut IntegratorScratch,
) {
    let n = p.len();
    let IntegratorScratch { k, l, tmp_p, tmp_v } = s;
    // Stage j: k[j] = velocity slope, l[j] = acceleration slope.
    let weights = [0.0, 0.5, 0.5, 1.0];
    for stage in 0..4 {
        let h = weights[stage] * dt;
        for i in 0..n {
            let (dp, dv) = if stage == 0 {
                (Vec3::ZERO, Vec3::ZERO)
            } else {
                (k[stage - 1][i] * h, l[stage - 1][i] * h)
            };
            tmp_p[i] = p[i] + dp;
            tmp_v[i] = v[i] + dv;
            k[stage][i] = tmp_v[i];
        }
        field.accelerations(h, tmp_p, tmp_v, &mut l[stage]);
    }
    for i in 0..n {
        p[i] += (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]) * (dt / 6.0);
        v[i] += (l[0][i] + 2.0 * l[1][i] + 2.0 * l[2][i] + l[3][i]) * (dt / 6.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: Vec3 = Vec3::new(0.0, 0.0, -9.8);

    /// Error at `t_end` of a projectile launched from the origin.
    fn projectile_error(method: Integrator, dt: f32, t_end: f32) -> f32 {
        let v0 = Vec3::new(3.0, 0.0, 12.0);
        let (mut p, mut v) = ([Vec3::ZERO], [v0]);
        let mut s = IntegratorScratch::default();
        let steps = (t_end / dt).round() as usize;
        for _ in 0..steps {
            integrate(method, dt, &mut p, &mut v, &G, &mut s);
        }
        let t = steps as f32 * dt;
        (p[0] - (v0 * t + 0.5 * G * t * t)).length()
    }

    /// Position error at `t_end` of an undamped unit spring `x'' = -ω² x` started at x = 1.
    fn spring_error(method: Integrator, dt: f32, t_end: f32, omega: f32) -> f32 {
        let field = move |_t: f32, p: &[Vec3], _v: &[Vec3], out: &mut [Vec3]| {
            for (o, p) in out.iter_mut().zip(p) {
                *o = -omega * omega * *p;
            }
        };
        let (mut p, mut v) = ([Vec3::X], [Vec3::ZERO]);
        let mut s = IntegratorScratch::default();
        let steps = (t_end / dt).round() as usize;
        for _ in 0..steps {
            integrate(method, dt, &mut p, &mut v, &field, &mut s);
        }
        let t = steps as f64 * dt as f64;
        let exact = (omega as f64 * t).cos() as f32;
        (p[0].x - exact).abs()
    }

    /// log2 of the error ratio when dt halves: the observed order of convergence.
    fn observed_order(error: impl Fn(f32) -> f32, dt: f32) -> f32 {
        (error(dt) / error(dt / 2.0)).log2()
    }

    #[test]
    fn every_integrator_converges_at_its_order_on_the_spring() {
        for method in Integrator::ALL {
            // dt chosen so errors sit well above f32 rounding yet in the asymptotic regime.
            let dt = match method.order() {
                4 => 0.2,
                2 => 0.02,
                _ => 0.002,
            };
            let order = observed_order(|dt| spring_error(method, dt, 4.0, 1.0), dt);
            assert!(
                (order - method.order() as f32).abs() < 0.3,
                "{}: observed order {order}, expected {}",
                method.name(),
                method.order()
            );
        }
    }

    #[test]
    fn euler_methods_converge_at_first_order_on_the_projectile() {
        for method in [Integrator::ExplicitEuler, Integrator::SymplecticEuler] {
            let order = observed_order(|dt| projectile_error(method, dt, 2.0), 0.01);
            assert!((order - 1.0).abs() < 0.1, "{}: {order}", method.name());
        }
    }

    #[test]
    fn second_and_fourth_order_methods_are_exact_on_the_projectile() {
        // Constant acceleration: the position is a quadratic, which Verlet and RK4 reproduce.
        for method in [Integrator::VelocityVerlet, Integrator::Rk4] {
            let err = projectile_error(method, 1.0 / 60.0, 2.0);
            assert!(err < 1e-4, "{}: error {err}", method.name());
        }
    }

    #[test]
    fn explicit_euler_energy_grows_as_theory_predicts() {
        // For x'' = -x, one explicit Euler step multiplies the energy by exactly (1 + dt²).
        let dt = 0.01f32;
        let field = |_t: f32, p: &[Vec3], _v: &[Vec3], out: &mut [Vec3]| out[0] = -p[0];
        let (mut p, mut v) = ([Vec3::X], [Vec3::ZERO]);
        let mut s = IntegratorScratch::default();
        let steps = 1000;
        for _ in 0..steps {
            integrate(
                Integrator::ExplicitEuler,
                dt,
                &mut p,
                &mut v,
                &field,
                &mut s,
            );
        }
        let energy = 0.5 * (p[0].length_squared() + v[0].length_squared());
        let predicted = 0.5 * (1.0 + dt * dt).powi(steps);
        assert!(
            (energy / predicted - 1.0).abs() < 1e-3,
            "{energy} vs {predicted}"
        );
    }
}
