//! The main example: balls under gravity dropped on a ground plane, bouncing by the slides'
//! reflection rule (with restitution) and off each other, recorded to `bouncing_balls.rrd`.
//!
//! ```text
//! cargo run --release --example bouncing_balls -- --help
//! rerun bouncing_balls.rrd
//! ```

use bevy_app::App;
use clap::Parser;
use glam::Vec3;
use std::error::Error;
use std::path::PathBuf;
use std::time::Instant;
use urto::debug::{RerunConfig, RerunDebugPlugin};
use urto::prelude::*;

/// Balls dropped on a ground plane, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Number of balls.
    #[arg(long, default_value_t = 24)]
    balls: u32,
    /// Physics steps to simulate (60 per simulated second).
    #[arg(long, default_value_t = 600)]
    steps: u32,
    /// Where to write the recording.
    #[arg(long, default_value = "bouncing_balls.rrd")]
    out: PathBuf,
    /// Record every k-th step.
    #[arg(long, default_value_t = 1)]
    every: u64,
    /// Open the viewer on the last recorded step (for screenshots).
    #[arg(long)]
    open_at_end: bool,
}

/// A small deterministic generator (same scene on every run, no extra dependency).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let recording = RerunDebugPlugin::new(RerunConfig {
        app_id: "urto bouncing_balls".into(),
        every_k_steps: args.every,
        open_at_end: args.open_at_end,
        ..RerunConfig::file(&args.out)
    })?;

    let mut app = App::new();
    app.add_plugins(UrtoPlugins::default())
        .add_plugins(recording)
        .insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    world.spawn((Collider::half_space(Vec3::Z), Static, Restitution(0.9)));
    let mut rng = Lcg(7);
    let side = (args.balls as f32).sqrt().ceil() as u32;
    for i in 0..args.balls {
        let (gx, gy) = ((i % side) as f32, (i / side) as f32);
        let radius = 0.2 + 0.25 * rng.next();
        world.spawn((
            Collider::sphere(radius),
            Position::new(
                gx * 1.1 - side as f32 * 0.5,
                gy * 1.1 - side as f32 * 0.5,
                1.0 + 4.0 * rng.next(),
            ),
            Velocity::new(rng.next() - 0.5, rng.next() - 0.5, 0.0),
            Mass(radius.powi(3) * 4.19 * 1000.0),
            Restitution(0.5 + 0.45 * rng.next()),
        ));
    }

    let start = Instant::now();
    let mut physics_time = 0.0;
    for _ in 0..args.steps {
        urto::step(app.world_mut(), 1)?;
        let stats = app.world().resource::<PhysicsStats>();
        physics_time += Stage::ALL
            .iter()
            .filter(|s| **s != Stage::Debug)
            .map(|s| stats.stage_time(*s).as_secs_f64())
            .sum::<f64>();
    }
    let wall = start.elapsed().as_secs_f64();
    let stats = app.world().resource::<PhysicsStats>();
    println!(
        "bouncing_balls: {} balls, {} steps ({:.1} s simulated)",
        args.balls, stats.step, stats.sim_time
    );
    println!(
        "  time per step: {:.1} µs physics, {:.1} µs with recording",
        physics_time / args.steps as f64 * 1e6,
        wall / args.steps as f64 * 1e6
    );
    println!(
        "  recording: {}  (open it with `rerun {}`)",
        args.out.display(),
        args.out.display()
    );
    Ok(())
}
