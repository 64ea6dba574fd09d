//! Section 2: tunnelling — fast balls shot at a thin wall through the full ECS plugin.
//!
//! The slides' warning: a discrete step finds contacts late, and a fast or thin object can be on
//! one side of a wall at one step and past it at the next. Their brute-force cure is substeps.
//! Each run shoots a grid of balls (one per lane, so they never meet) along +x at a static
//! `Collider::cuboid` wall; the start offsets follow a golden-ratio sequence over one step's
//! travel, so every crossing phase is sampled evenly (deterministically). A ball is counted through when it ends on the far side.
//!
//! A simple model predicts the fraction: the contact stops a ball only if a substep ends with its
//! centre in the band `[-(t/2 + r), 0)` before the wall's mid-plane (past the mid-plane the
//! nearest face is the far one, and the ball is pushed on through). With substep travel
//! `s = v·dt/n` the band is hit with probability `min(1, (t/2 + r)/s)`.
//!
//! The runs use the lecture's pipeline (detection in every substep), whose substeps this section
//! prices. The rigid-body solver, urto's default, detects once per step with speculative
//! contacts that look ahead by the body's own size, and sweeps faster bodies by CCD.

mod charts;
mod text;

use crate::common::legacy_app_with;
use crate::{Config, Context, SectionResult};
use bevy_ecs::world::EntityWorldMut;
use charts::{plot, record};
use std::time::Instant;
use text::section;
use urto::plugins::CcdSettings;
use urto::prelude::*;

/// Ball speeds (m/s).
const SPEEDS: [f32; 4] = [10.0, 30.0, 100.0, 300.0];

/// Wall thicknesses (m).
const THICKNESSES: [f32; 2] = [0.01, 0.05];

/// Substep counts tried.
const SUBSTEPS: [u32; 6] = [1, 2, 4, 8, 16, 32];

/// Ball radius (m).
const RADIUS: f32 = 0.05;

/// The step (s).
const DT: f32 = 1.0 / 60.0;

/// Distance between the wall and the nearest start (m).
const START: f32 = 1.0;

/// Lanes are this far apart in y and z (m), so balls never touch each other.
const LANE: f32 = 0.5;

/// Fewest steps a run lasts, so that its time per step is measurable.
const MIN_STEPS: u32 = 30;

/// One scene: a wall and a speed.
#[derive(Clone, Copy, Debug)]
struct Shot {
    thickness: f32,
    speed: f32,
}

impl Shot {
    /// Half-width of the band where a contact stops the ball (see the module doc).
    fn band(&self) -> f32 {
        self.thickness / 2.0 + RADIUS
    }

    /// The model's fraction of balls through with `n` substeps.
    fn model_pass(&self, n: u32) -> f64 {
        let travel = self.speed * DT / n as f32;
        (1.0 - self.band() / travel).max(0.0) as f64
    }

    /// The fewest substeps (a power of two) the model says stop every ball.
    fn model_substeps(&self) -> u32 {
        let needed = (self.speed * DT / self.band()).ceil().max(1.0) as u32;
        needed.next_power_of_two()
    }

    fn label(&self) -> String {
        format!("{} m/s", self.speed)
    }
}

/// What one run measured.
#[derive(Clone, Copy, Debug)]
pub struct TunnelRun {
    /// Balls that ended past the wall.
    passed: usize,
    /// Balls shot.
    balls: usize,
    /// Mean wall time of one step of the whole scene (µs).
    us_per_step: f64,
}

impl TunnelRun {
    fn pass_fraction(&self) -> f64 {
        self.passed as f64 / self.balls as f64
    }
}

/// All runs of one shot.
struct ShotResult {
    shot: Shot,
    /// One run per entry of [`SUBSTEPS`].
    substeps: Vec<TunnelRun>,
    /// The continuous-collision run, once it exists.
    ccd: Option<TunnelRun>,
}

fn balls(cfg: &Config) -> usize {
    cfg.pick(256, 16)
}

/// Units of progress: one per run, continuous collision included.
pub fn work_units(_cfg: &Config) -> u64 {
    (THICKNESSES.len() * SPEEDS.len() * (SUBSTEPS.len() + 1)) as u64
}

/// Runs the section.
pub fn run(ctx: &mut Context) -> SectionResult {
    let n = balls(&ctx.cfg);
    let mut results = Vec::new();
    for thickness in THICKNESSES {
        for speed in SPEEDS {
            let shot = Shot { thickness, speed };
            results.push(measure(ctx, shot, n));
        }
    }
    plot(ctx, &results)?;
    record(ctx, &results);
    Ok(section(&results, n))
}

fn measure(ctx: &Context, shot: Shot, balls: usize) -> ShotResult {
    let mut substeps = Vec::new();
    for n in SUBSTEPS {
        ctx.progress.task(format!(
            "tunnelling: wall {} m, {} m/s, {n} substeps",
            shot.thickness, shot.speed
        ));
        substeps.push(repeated(ctx.cfg.pick(3, 1), || {
            shoot(shot, n, balls, &|_| {})
        }));
        ctx.progress.tick();
    }
    ctx.progress.task("tunnelling: continuous collision");
    let ccd = ccd_run(shot, balls, ctx.cfg.pick(3, 1));
    ctx.progress.tick();
    ShotResult {
        shot,
        substeps,
        ccd,
    }
}

/// Runs `shoot` `times` times and keeps the smallest time (other processes only add time). The
/// runs are deterministic, so their outcomes must agree; a disagreement is reported, not hidden.
fn repeated(times: u32, shoot: impl Fn() -> TunnelRun) -> TunnelRun {
    let first = shoot();
    (1..times).fold(first, |best, _| {
        let run = shoot();
        if run.passed != first.passed {
            eprintln!(
                "tunnelling: a repeated run gave {} passes, not {}",
                run.passed, first.passed
            );
        }
        TunnelRun {
            us_per_step: best.us_per_step.min(run.us_per_step),
            ..best
        }
    })
}

/// The same shot with continuous collision (every ball marked [`Ccd`]) instead of substeps.
fn ccd_run(shot: Shot, balls: usize, times: u32) -> Option<TunnelRun> {
    Some(repeated(times, || {
        shoot(shot, 1, balls, &|ball| {
            ball.insert(Ccd);
        })
    }))
}

/// Shoots `balls` balls at the wall with `substeps` substeps; `decorate` may add components to
/// each ball (e.g. a continuous-collision marker).
fn shoot(
    shot: Shot,
    substeps: u32,
    balls: usize,
    decorate: &dyn Fn(&mut EntityWorldMut),
) -> TunnelRun {
    let mut app = legacy_app_with(DT, substeps);
    // Only marked balls are swept: the substep rows measure substeps alone.
    app.insert_resource(CcdSettings {
        auto_speed_ratio: None,
        ..Default::default()
    });
    let world = app.world_mut();
    let side = (balls as f32).sqrt().ceil() as usize;
    let half = side as f32 * LANE;
    world.spawn((Collider::cuboid(shot.thickness / 2.0, half, half), Static));
    let step_travel = shot.speed * DT;
    let ids: Vec<_> = (0..balls)
        .map(|i| {
            let (y, z) = lane(i, side);
            let x = -START - RADIUS - phase(i) * step_travel;
            let mut ball = world.spawn((
                Collider::sphere(RADIUS),
                Position::new(x, y, z),
                Velocity::new(shot.speed, 0.0, 0.0),
            ));
            decorate(&mut ball);
            ball.id()
        })
        .collect();
    let steps = steps_needed(shot);
    let start = Instant::now();
    // A world with UrtoPlugins always has the physics schedule.
    urto::step(world, steps).expect("the app has UrtoPlugins");
    let us_per_step = start.elapsed().as_secs_f64() * 1e6 / steps as f64;
    let passed = ids
        .iter()
        .filter(|&&e| world.get::<Position>(e).is_some_and(|p| p.0.x > 0.0))
        .count();
    TunnelRun {
        passed,
        balls,
        us_per_step,
    }
}

/// Start offset of ball `i` as a fraction of one step's travel: the golden-ratio (Weyl)
/// sequence. Its multiples `n·phase mod 1` are evenly spread too, so the crossing phase relative
/// to a substep is sampled evenly for every substep count `n` — where slices of the step's
/// travel would alias with the substep length (16 slices of a step are 2-substep multiples at
/// 32 substeps) and random offsets would add sampling noise.
fn phase(i: usize) -> f32 {
    const GOLDEN: f64 = 0.618_033_988_749_894_9;
    (0.5 + i as f64 * GOLDEN).fract() as f32
}

/// Centre of lane `i` in a `side × side` grid about the x axis.
fn lane(i: usize, side: usize) -> (f32, f32) {
    let c = (side as f32 - 1.0) / 2.0;
    ((i % side) as f32 - c, (i / side) as f32 - c)
}

/// Steps for every ball to reach the wall and travel a metre past it, at least [`MIN_STEPS`].
fn steps_needed(shot: Shot) -> u32 {
    let travel = shot.speed * DT;
    let span = START + RADIUS + travel + 1.0;
    ((span / travel).ceil() as u32 + 1).max(MIN_STEPS)
}

fn wall_label(thickness: f32) -> String {
    format!("{:.0} cm wall", thickness * 100.0)
}

/// `(substeps, mean µs per step over all shots)`.
fn mean_cost(results: &[ShotResult]) -> Vec<(f64, f64)> {
    SUBSTEPS
        .iter()
        .enumerate()
        .map(|(i, &n)| {
            let sum: f64 = results.iter().map(|r| r.substeps[i].us_per_step).sum();
            (n as f64, sum / results.len() as f64)
        })
        .collect()
}
