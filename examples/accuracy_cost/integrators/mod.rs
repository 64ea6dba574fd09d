//! Section 1: integrators × `dt` — accuracy against analytic solutions, energy drift, wall time.
//!
//! The core's four methods (`urto::dynamics::Integrator`) run on two problems with closed-form
//! solutions: the slides' projectile under constant gravity (`p = v0 t + g t²/2`) and an undamped
//! spring through the crate's own `ForceModel` (`x = x_eq + A cos ωt`). The error at `t_end`
//! over `dt = 2^-k` gives the observed order (the slope on a log–log plot); a long spring run
//! gives the energy drift; 10,000 bodies give a measurable wall time per body and step; error
//! against time per simulated second gives the Pareto front (Hairer, Lubich & Wanner, *Geometric
//! Numerical Integration*, 2006, for the theory the numbers are set against).

mod analysis;
mod charts;
mod problems;
mod text;

use crate::{Config, Context, SectionResult};
use charts::{plot, record};
use glam::Vec3;
use problems::*;
use std::time::Duration;
use text::section;
use urto::dynamics::Integrator;

/// The slides' gravity, z up.
const GRAVITY: Vec3 = Vec3::new(0.0, 0.0, -9.8);

/// Launch velocity of the projectile (m/s).
const LAUNCH: Vec3 = Vec3::new(3.0, 0.0, 12.0);

/// Simulated time of the projectile runs (s); a multiple of every `dt = 2^-k`.
const PROJECTILE_T_END: f32 = 2.0;

/// Simulated time of the spring accuracy runs (s).
const SPRING_T_END: f32 = 8.0;

/// The spring: 1 N/m on 1 kg (ω = 1 rad/s), rest length 2 from an anchor at x = -3, released at
/// x = 0: it oscillates about x = -1 with amplitude 1 and never comes near the anchor, where a
/// spring's axis is undefined.
const ANCHOR_X: f32 = -3.0;

const REST_LENGTH: f32 = 2.0;

const EQUILIBRIUM_X: f64 = -1.0;

const AMPLITUDE: f64 = 1.0;

/// Step of the energy-drift run (ω·dt = 0.01).
const DRIFT_DT: f32 = 0.01;

/// The game's step, reported on its own.
const GAME_DT: f32 = 1.0 / 60.0;

/// Largest error fitted for the observed order: above it a method is not yet in its asymptotic
/// regime (or has diverged).
const FIT_MAX: f64 = 1e-1;

/// How far above the rounding estimate ([`Problem::rounding_floor`]) an error must be to be fitted.
const ROUNDING_MARGIN: f64 = 1.0;

/// Successive halvings of `dt` must shrink the error by at least this factor to count as the
/// asymptotic regime (a first-order method gives 2, rounding noise gives about 1 or less).
const MIN_SHRINK: f64 = 1.5;

/// Error targets for the "cheapest way to reach it" conclusions.
const TARGETS: [f64; 3] = [1e-2, 1e-4, 1e-6];

/// A test problem with a closed-form solution.
#[derive(Clone, Copy)]
struct Problem {
    /// Simulated time (s).
    t_end: f32,
    /// Size of the largest coordinate the run handles (m), for the rounding estimate.
    scale: f64,
}

impl Problem {
    /// A pessimistic estimate of the f32 rounding accumulated over a run with step `dt`: half
    /// an ulp of the largest coordinate per step, all of the same sign (as for the projectile,
    /// whose increments never change sign). Errors not well above it are not fitted for the
    /// order, since they no longer follow `dt`.
    fn rounding_floor(&self, dt: f64) -> f64 {
        let steps = (self.t_end as f64 / dt).round();
        0.5 * f32::EPSILON as f64 * self.scale * steps
    }
}

/// The projectile: coordinates stay below 8 m (apex 7.35 m, range 6 m).
const PROJECTILE: Problem = Problem {
    t_end: PROJECTILE_T_END,
    scale: 8.0,
};

/// The spring: coordinates (and the spring length) stay below 3 m.
const SPRING: Problem = Problem {
    t_end: SPRING_T_END,
    scale: 3.0,
};

/// Sizes of the run.
struct Sizes {
    /// `dt = 2^-k` for `k` in this range.
    log2_inv_dt: std::ops::RangeInclusive<i32>,
    /// Steps of the energy-drift run.
    drift_steps: usize,
    /// Bodies in the timing runs.
    bodies: usize,
    /// Minimum wall time of one timing measurement.
    min_time: Duration,
}

fn sizes(cfg: &Config) -> Sizes {
    Sizes {
        log2_inv_dt: cfg.pick(1..=14, 1..=10),
        drift_steps: cfg.pick(100_000, 10_000),
        bodies: cfg.pick(10_000, 2_000),
        min_time: cfg.pick(Duration::from_millis(300), Duration::from_millis(30)),
    }
}

/// Units of progress this section reports: per method, the dt sweep, the drift run, two timings.
pub fn work_units(_cfg: &Config) -> u64 {
    4 * Integrator::ALL.len() as u64
}

/// What one method measured.
struct MethodResult {
    method: Integrator,
    /// `(dt, error at t_end)` on the projectile.
    projectile: Vec<(f64, f64)>,
    /// `(dt, error at t_end)` on the spring.
    spring: Vec<(f64, f64)>,
    /// `(t, |E/E0 - 1|)` samples of the drift run.
    drift: Vec<(f64, f64)>,
    /// Nanoseconds per body and step under uniform gravity.
    ns_gravity: f64,
    /// Nanoseconds per body and step with a spring per body (the `ForceModel` path).
    ns_spring: f64,
}

impl MethodResult {
    /// `(ns of wall time per body per simulated second, spring error)` for each dt.
    fn pareto_points(&self) -> Vec<(f64, f64)> {
        self.spring
            .iter()
            .map(|&(dt, err)| (self.ns_spring / dt, err))
            .collect()
    }
}

/// Runs the section.
pub fn run(ctx: &mut Context) -> SectionResult {
    let sz = sizes(&ctx.cfg);
    let results: Vec<MethodResult> = Integrator::ALL
        .iter()
        .map(|&m| measure(ctx, &sz, m))
        .collect();
    plot(ctx, &results)?;
    record(ctx, &results);
    Ok(section(&results, &sz))
}

fn measure(ctx: &Context, sz: &Sizes, method: Integrator) -> MethodResult {
    let p = &ctx.progress;
    p.task(format!("integrators: {} dt sweep", method.name()));
    let dts: Vec<f32> = sz.log2_inv_dt.clone().map(|k| 2f32.powi(-k)).collect();
    let projectile = dts
        .iter()
        .map(|&dt| (dt as f64, projectile_error(method, dt)))
        .collect();
    let spring = dts
        .iter()
        .map(|&dt| (dt as f64, spring_error(method, dt)))
        .collect();
    p.tick();
    p.task(format!("integrators: {} energy drift", method.name()));
    let drift = energy_drift(method, sz.drift_steps);
    p.tick();
    p.task(format!("integrators: {} timing", method.name()));
    let ns_gravity = ns_per_body_step(method, sz, &GRAVITY);
    p.tick();
    let ns_spring = ns_per_body_step(method, sz, &spring_model(sz.bodies));
    p.tick();
    MethodResult {
        method,
        projectile,
        spring,
        drift,
        ns_gravity,
        ns_spring,
    }
}
