//! Section 5: the rigid-body solver — what substeps and relax passes buy on a stack of 20 unit
//! boxes standing for 10 s, and what they cost per step.
//!
//! The soft step (`SoftStepPlugin`, Box2D v3's scheme) detects contacts once per step and then
//! runs `substeps` rounds of integrate → solve (biased) → integrate positions → relax. More
//! substeps make the contacts stiffer relative to the step (less sag, less sway); more relax
//! passes converge the velocities further within a substep (less sway). A tall stack is the
//! classic test of both: its top box shows every error of the contacts below it.

mod text;

use crate::recording::Time;
use crate::{Config, Context, SectionResult};
use bevy_app::App;
use glam::Vec3;
use std::time::Instant;
use text::section;
use urto::dynamics::solver::SoftStepSettings;
use urto::plugins::SoftStepPlugin;
use urto::prelude::*;

/// Boxes in the stack (unit cubes, 1 kg, resting on each other at the start).
const BOXES: usize = 20;

/// Simulated time (s).
const DURATION: f32 = 10.0;

/// The fixed step (s).
const DT: f32 = 1.0 / 60.0;

/// Substeps compared.
const SUBSTEPS: [u32; 4] = [1, 2, 4, 8];

/// Relax passes per substep compared.
const RELAX: [u32; 3] = [1, 2, 3];

/// What one run measured.
struct StackRun {
    substeps: u32,
    relax: u32,
    /// Largest distance of any box from where it rested after the first second (its sag
    /// done), over the rest of the run (m): the stack's sway.
    drift: f64,
    /// Largest overlap of two neighbours (or of the bottom box with the ground) over the run (m).
    penetration: f64,
    /// The top box's drop at the end (m).
    sag: f64,
    /// Mean wall time per step (µs).
    us_per_step: f64,
}

impl StackRun {
    /// Passes over the contacts per step: each substep solves once and relaxes `relax` times.
    fn passes(&self) -> u32 {
        self.substeps * (1 + self.relax)
    }
}

/// Units of progress: one per run.
pub fn work_units(_cfg: &Config) -> u64 {
    (SUBSTEPS.len() * RELAX.len()) as u64
}

/// Runs the section.
pub fn run(ctx: &mut Context) -> SectionResult {
    let seconds = ctx.cfg.pick(DURATION, 2.0);
    let mut runs = Vec::new();
    for substeps in SUBSTEPS {
        for relax in RELAX {
            ctx.progress
                .task(format!("solver: {substeps} substeps × {relax} relax"));
            runs.push(stack(substeps, relax, seconds));
            ctx.progress.tick();
        }
    }
    record(ctx, &runs);
    Ok(section(&runs, seconds))
}

/// Stands the stack with these settings for `seconds` and measures it.
fn stack(substeps: u32, relax: u32, seconds: f32) -> StackRun {
    let settings = SoftStepSettings {
        substeps,
        relax_iterations: relax,
        ..Default::default()
    };
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::default().set(SoftStepPlugin { settings }))
        .insert_resource(Gravity::EARTH_Z_UP)
        // The stack must stay awake: asleep, it would neither drift nor cost what is measured.
        .insert_resource(SleepSettings {
            enabled: false,
            ..Default::default()
        });
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Friction(0.6)));
    let start: Vec<Vec3> = (0..BOXES)
        .map(|i| Vec3::new(0.0, 0.0, 0.5 + i as f32))
        .collect();
    let boxes: Vec<_> = start
        .iter()
        .map(|&p| {
            app.world_mut()
                .spawn((
                    Collider::cuboid(0.5, 0.5, 0.5),
                    Position(p),
                    Velocity::default(),
                    Friction(0.6),
                    Restitution(0.0),
                ))
                .id()
        })
        .collect();
    let steps = (seconds / DT).round() as u32;
    let settle_steps = (1.0 / DT).round() as u32;
    let (mut drift, mut penetration) = (0.0f64, 0.0f64);
    let mut elapsed = 0.0f64;
    let mut heights = vec![0.0f32; BOXES];
    let mut settled = start.clone();
    for step in 1..=steps {
        let t = Instant::now();
        urto::step(app.world_mut(), 1).expect("the app has UrtoPlugins");
        elapsed += t.elapsed().as_secs_f64();
        for (i, &b) in boxes.iter().enumerate() {
            let p = app.world().get::<Position>(b).map_or(settled[i], |p| p.0);
            if step == settle_steps {
                settled[i] = p;
            } else if step > settle_steps {
                drift = drift.max(p.distance(settled[i]) as f64);
            }
            heights[i] = p.z;
        }
        // The ground's top, then each box's top: how far the next box's bottom is below it.
        let mut below = 0.0f32;
        for &z in &heights {
            penetration = penetration.max((below - (z - 0.5)) as f64);
            below = z + 0.5;
        }
    }
    let sag = (start[BOXES - 1].z - heights[BOXES - 1]) as f64;
    StackRun {
        substeps,
        relax,
        drift,
        penetration: penetration.max(0.0),
        sag,
        us_per_step: elapsed * 1e6 / steps as f64,
    }
}

/// The series in the recording: drift and time per step against the substep count, one line
/// per relax count.
fn record(ctx: &mut Context, runs: &[StackRun]) {
    for relax in RELAX {
        let mine = || runs.iter().filter(move |r| r.relax == relax);
        let at = |r: &StackRun| Time::Sequence(i64::from(r.substeps));
        let base = format!("solver/relax_{relax}");
        ctx.rec.series(
            "solver_substeps",
            &format!("{base}/drift_mm"),
            mine().map(|r| (at(r), r.drift * 1e3)),
        );
        ctx.rec.series(
            "solver_substeps",
            &format!("{base}/us_per_step"),
            mine().map(|r| (at(r), r.us_per_step)),
        );
    }
}
