//! Problems with closed-form solutions, and the runs measured on them.

use super::*;
use crate::common::timing::min_of_means;
use glam::Vec3;
use urto::dynamics::{ForceModel, Integrator, IntegratorScratch, Spring, SpringEnd, integrate};

/// Advances `steps` steps of `dt`.
pub(super) fn advance(
    method: Integrator,
    dt: f32,
    steps: usize,
    state: (&mut [Vec3], &mut [Vec3]),
    field: &impl urto::dynamics::AccelerationField,
) {
    let mut scratch = IntegratorScratch::default();
    for _ in 0..steps {
        integrate(method, dt, state.0, state.1, field, &mut scratch);
    }
}

/// Whole steps of `dt` in `t_end` and the time they actually cover (in f64).
pub(super) fn steps_for(t_end: f32, dt: f32) -> (usize, f64) {
    let steps = (t_end / dt).round() as usize;
    (steps, steps as f64 * dt as f64)
}

/// Distance at `t_end` between the integrated and the analytic projectile.
pub(super) fn projectile_error(method: Integrator, dt: f32) -> f64 {
    let (mut p, mut v) = ([Vec3::ZERO], [LAUNCH]);
    let (steps, t) = steps_for(PROJECTILE_T_END, dt);
    advance(method, dt, steps, (&mut p, &mut v), &GRAVITY);
    let exact = LAUNCH.as_dvec3() * t + 0.5 * GRAVITY.as_dvec3() * t * t;
    (p[0].as_dvec3() - exact).length()
}

/// `n` bodies, each on its own anchored spring (see [`ANCHOR_X`]), in rows 3 m apart in y.
pub(super) fn spring_model(n: usize) -> ForceModel {
    let mut model = ForceModel::default();
    model.reset(n);
    model.inverse_mass.fill(1.0);
    for body in 0..n {
        model.springs.push(Spring {
            body,
            other: SpringEnd::Anchor(Vec3::new(ANCHOR_X, 3.0 * body as f32, 0.0)),
            rest_length: REST_LENGTH,
            stiffness: 1.0,
            damping: 0.0,
        });
    }
    model
}

/// The released state of [`spring_model`]'s bodies.
pub(super) fn spring_start(n: usize) -> (Vec<Vec3>, Vec<Vec3>) {
    let p = (0..n)
        .map(|i| Vec3::new(0.0, 3.0 * i as f32, 0.0))
        .collect();
    (p, vec![Vec3::ZERO; n])
}

/// Phase-space error at `t_end` of the spring against `x = x_eq + A cos t`, `v = -A sin t`:
/// `sqrt(dx² + (dv/ω)²)`, so that amplitude and phase errors both count (the position alone
/// can look accurate at a zero crossing of a grown oscillation).
pub(super) fn spring_error(method: Integrator, dt: f32) -> f64 {
    let model = spring_model(1);
    let (mut p, mut v) = spring_start(1);
    let (steps, t) = steps_for(SPRING_T_END, dt);
    advance(method, dt, steps, (&mut p, &mut v), &model);
    let dx = p[0].x as f64 - (EQUILIBRIUM_X + AMPLITUDE * t.cos());
    let dv = v[0].x as f64 + AMPLITUDE * t.sin();
    dx.hypot(dv)
}

/// The envelope of `|E/E0 - 1|` over a long spring run: the largest value over each period of
/// the oscillation, at the period's end (the energy error of the symplectic methods oscillates
/// within a period; sampling single steps would alias it).
pub(super) fn energy_drift(method: Integrator, steps: usize) -> Vec<(f64, f64)> {
    let model = spring_model(1);
    let (mut p, mut v) = spring_start(1);
    let energy =
        |p: &[Vec3], v: &[Vec3]| model.kinetic_energy(v) as f64 + model.potential_energy(p) as f64;
    let e0 = energy(&p, &v);
    let window = ((std::f64::consts::TAU / DRIFT_DT as f64).round() as usize).max(1);
    let mut scratch = IntegratorScratch::default();
    let mut out = Vec::with_capacity(steps / window + 1);
    let mut peak = 0.0f64;
    for i in 1..=steps {
        integrate(method, DRIFT_DT, &mut p, &mut v, &model, &mut scratch);
        peak = peak.max((energy(&p, &v) / e0 - 1.0).abs());
        if i % window == 0 {
            out.push((i as f64 * DRIFT_DT as f64, peak));
            peak = 0.0;
        }
    }
    out
}

/// Wall time of one step per body, `sz.bodies` bodies in `field`.
pub(super) fn ns_per_body_step(
    method: Integrator,
    sz: &Sizes,
    field: &impl urto::dynamics::AccelerationField,
) -> f64 {
    let (mut p, mut v) = spring_start(sz.bodies);
    let mut scratch = IntegratorScratch::default();
    let t = min_of_means(3, sz.min_time, || {
        integrate(method, GAME_DT, &mut p, &mut v, field, &mut scratch);
    });
    t.as_secs_f64() * 1e9 / sz.bodies as f64
}
