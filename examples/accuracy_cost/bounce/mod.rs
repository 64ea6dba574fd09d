//! Section 4: bounce accuracy — apex heights of a ball dropped on a plane through the ECS plugin,
//! against the analytic sequence `h_k = e^(2k) h_0`.
//!
//! A ball leaving the ground at speed `u` rises to `u²/2g`; a bounce with restitution `e` turns
//! an impact at `u` into a take-off at `e u`, so each apex is `e²` times the one before. The
//! discrete step finds the contact late (the ball is already inside the plane), reflects the
//! velocity it has then, and pushes the ball out by moving it: all three change the apex. The
//! solver also refuses to bounce approaches slower than `SolverSettings::restitution_threshold`,
//! which ends the sequence once an apex falls below `threshold² / 2g`.

mod charts;
mod text;

use crate::common::{app_with, legacy_app_with};
use crate::{Config, Context, SectionResult};
use charts::{plot, record};
use glam::Vec3;
use std::time::Instant;
use text::section;
use urto::dynamics::solver::SoftStepSettings;
use urto::plugins::SoftStepSolver;
use urto::prelude::*;

/// Drop height of the ball's bottom above the plane (m).
const H0: f64 = 2.0;

/// Ball radius (m).
const RADIUS: f32 = 0.1;

/// Restitution of ball and ground (the pair uses their mean).
const E: f32 = 0.8;

/// Simulated time of a run (s): enough for the bounces to die out.
const DURATION: f32 = 8.0;

/// Bounces tabulated.
const BOUNCES: usize = 12;

/// A local maximum counts as an apex only if the ball left the ground by this much (m).
const MIN_APEX: f64 = 1e-3;

/// The slides' gravity (m/s²).
const G: f64 = 9.8;

/// One configuration of the step.
#[derive(Clone, Copy, Debug)]
struct Setting {
    dt: f32,
    substeps: u32,
    integrator: Integrator,
    /// The rigid-body solver (`SoftStepPlugin`, its own 4 substeps) instead of the legacy
    /// response; `integrator` is then unused.
    soft_step: bool,
}

impl Setting {
    fn label(&self) -> String {
        if self.soft_step {
            return format!("soft-step solver, dt = 1/{:.0}", 1.0 / self.dt);
        }
        format!(
            "{}, dt = 1/{:.0}{}",
            self.integrator.name(),
            1.0 / self.dt,
            if self.substeps > 1 {
                format!(" × {} substeps", self.substeps)
            } else {
                String::new()
            }
        )
    }
}

/// The settings compared: the default, each integrator, smaller and larger steps, substeps, and
/// the rigid-body solver.
const SETTINGS: [Setting; 8] = [
    Setting {
        dt: 1.0 / 60.0,
        substeps: 1,
        integrator: Integrator::SymplecticEuler,
        soft_step: false,
    },
    Setting {
        dt: 1.0 / 60.0,
        substeps: 1,
        integrator: Integrator::ExplicitEuler,
        soft_step: false,
    },
    Setting {
        dt: 1.0 / 60.0,
        substeps: 1,
        integrator: Integrator::VelocityVerlet,
        soft_step: false,
    },
    Setting {
        dt: 1.0 / 60.0,
        substeps: 1,
        integrator: Integrator::Rk4,
        soft_step: false,
    },
    Setting {
        dt: 1.0 / 30.0,
        substeps: 1,
        integrator: Integrator::SymplecticEuler,
        soft_step: false,
    },
    Setting {
        dt: 1.0 / 60.0,
        substeps: 4,
        integrator: Integrator::SymplecticEuler,
        soft_step: false,
    },
    Setting {
        dt: 1.0 / 240.0,
        substeps: 1,
        integrator: Integrator::SymplecticEuler,
        soft_step: false,
    },
    Setting {
        dt: 1.0 / 60.0,
        substeps: 1,
        integrator: Integrator::SymplecticEuler,
        soft_step: true,
    },
];

/// What one run measured.
struct BounceRun {
    setting: Setting,
    /// Apex heights of the ball's bottom after each bounce (m).
    apexes: Vec<f64>,
    /// Mean wall time per step (µs).
    us_per_step: f64,
}

impl BounceRun {
    /// Relative error of apex `k` (1-based) against the analytic one; `None` if not reached.
    fn error(&self, k: usize) -> Option<f64> {
        self.apexes.get(k - 1).map(|h| h / analytic(k) - 1.0)
    }

    /// Mean absolute relative error over the first `n` bounces (as many as were reached).
    fn mean_error(&self, n: usize) -> f64 {
        let errs: Vec<f64> = (1..=n)
            .filter_map(|k| self.error(k))
            .map(f64::abs)
            .collect();
        errs.iter().sum::<f64>() / errs.len().max(1) as f64
    }
}

/// `h_k = e^(2k) h_0`.
fn analytic(k: usize) -> f64 {
    (E as f64).powi(2 * k as i32) * H0
}

/// Units of progress: one per setting.
pub fn work_units(_cfg: &Config) -> u64 {
    SETTINGS.len() as u64
}

/// Runs the section.
pub fn run(ctx: &mut Context) -> SectionResult {
    let threshold = ContactSettings::default().solver.restitution_threshold as f64;
    let runs: Vec<BounceRun> = SETTINGS
        .iter()
        .map(|s| {
            ctx.progress.task(format!("bounce: {}", s.label()));
            let r = drop_ball(*s);
            ctx.progress.tick();
            r
        })
        .collect();
    plot(ctx, &runs, threshold)?;
    record(ctx, &runs);
    Ok(section(&runs, threshold))
}

/// Drops the ball with `setting` and collects its apexes.
fn drop_ball(setting: Setting) -> BounceRun {
    let mut app = if setting.soft_step {
        app_with(setting.dt, setting.substeps)
    } else {
        legacy_app_with(setting.dt, setting.substeps)
    };
    app.insert_resource(Gravity::EARTH_Z_UP)
        .insert_resource(Integration(setting.integrator));
    if setting.soft_step {
        // The legacy response's bounce threshold, so that both end the sequence alike.
        let threshold = ContactSettings::default().solver.restitution_threshold;
        let settings = SoftStepSettings {
            restitution_threshold: threshold,
            ..Default::default()
        };
        app.insert_resource(SoftStepSolver::new(settings));
    }
    let world = app.world_mut();
    world.spawn((Collider::half_space(Vec3::Z), Static, Restitution(E)));
    let ball = world
        .spawn((
            Collider::sphere(RADIUS),
            Position::new(0.0, 0.0, H0 as f32 + RADIUS),
            Velocity::default(),
            Restitution(E),
        ))
        .id();
    let steps = (DURATION / setting.dt).round() as u32;
    let mut track = Vec::with_capacity(steps as usize);
    let start = Instant::now();
    for _ in 0..steps {
        // A world with UrtoPlugins always has the physics schedule.
        urto::step(world, 1).expect("the app has UrtoPlugins");
        let (p, v) = (world.get::<Position>(ball), world.get::<Velocity>(ball));
        if let (Some(p), Some(v)) = (p, v) {
            track.push(((p.0.z - RADIUS) as f64, v.0.z as f64));
        }
    }
    let us_per_step = start.elapsed().as_secs_f64() * 1e6 / steps as f64;
    BounceRun {
        setting,
        apexes: apexes(&track),
        us_per_step,
    }
}

/// Apexes of a sampled flight `(height, vertical velocity)`: where the velocity turns from up to
/// down, the higher of the two samples (off the true apex by at most `g dt²/8`).
fn apexes(track: &[(f64, f64)]) -> Vec<f64> {
    track
        .windows(2)
        .filter(|w| w[0].1 > 0.0 && w[1].1 <= 0.0)
        .map(|w| w[0].0.max(w[1].0))
        .filter(|h| *h > MIN_APEX)
        .collect()
}

/// Bounces the threshold allows: bounce `k` happens if the impact speed from apex `k-1`,
/// `sqrt(2 g h_(k-1))`, exceeds the threshold.
fn bounces_allowed(threshold: f64) -> usize {
    (1..=BOUNCES)
        .take_while(|&k| (2.0 * G * analytic(k - 1)).sqrt() > threshold)
        .count()
}

/// Relative tolerance under which two runs' apexes count as the same (the table's precision).
const SAME_APEX: f64 = 1e-3;

/// True when two runs reach the same bounces with apexes equal within [`SAME_APEX`].
fn same_apexes(a: &BounceRun, b: &BounceRun) -> bool {
    let (a, b) = (
        &a.apexes[..a.apexes.len().min(BOUNCES)],
        &b.apexes[..b.apexes.len().min(BOUNCES)],
    );
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x / y - 1.0).abs() <= SAME_APEX)
}
