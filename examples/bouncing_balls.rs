//! The main example: balls under gravity dropped on a ground plane, bouncing with restitution
//! off it and off each other, recorded to `bouncing_balls.rrd`. Contacts turn them (the
//! rigid-body solver, urto's default): friction sets a sliding ball rolling, and a 1 cm
//! rolling resistance brings it to rest, as it would a real ball.
//!
//! ```text
//! cargo run --release --example bouncing_balls -- --help
//! rerun bouncing_balls.rrd
//! ```

mod support;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use clap::Parser;
use glam::Vec3;
use std::error::Error;
use std::path::PathBuf;
use support::{Collisions, Lcg, StepTimer};
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
    let ground = world
        .spawn((Collider::half_space(Vec3::Z), Static, Restitution(0.9)))
        .id();
    let mut rng = Lcg::new(7);
    let side = (args.balls as f32).sqrt().ceil() as u32;
    let mut balls = Vec::new();
    for i in 0..args.balls {
        let (gx, gy) = ((i % side) as f32, (i / side) as f32);
        let radius = 0.2 + 0.25 * rng.next();
        balls.push(
            world
                .spawn((
                    Collider::sphere(radius),
                    Position::new(
                        gx * 1.1 - side as f32 * 0.5,
                        gy * 1.1 - side as f32 * 0.5,
                        1.0 + 4.0 * rng.next(),
                    ),
                    Velocity::new(rng.next() - 0.5, rng.next() - 0.5, 0.0),
                    Density(1000.0), // water: the mass follows the size
                    Restitution(0.5 + 0.45 * rng.next()),
                    RollingResistance(0.01),
                ))
                .id(),
        );
    }

    let mut timer = StepTimer::start();
    let mut collisions = Collisions::new(&app);
    let (mut bounces, mut ball_hits) = (0, 0);
    for _ in 0..args.steps {
        urto::step(app.world_mut(), 1)?;
        timer.add(&app);
        for (a, b) in collisions.read(&app) {
            if a == ground || b == ground {
                bounces += 1;
            } else {
                ball_hits += 1;
            }
        }
    }
    let stats = app.world().resource::<PhysicsStats>();
    println!(
        "bouncing_balls: {} balls, {} steps ({:.1} s simulated)",
        args.balls, stats.step, stats.sim_time
    );
    println!("  bounces on the ground: {bounces}; collisions between two balls: {ball_hits}");
    let (resting, deepest) = at_rest(&app, &balls);
    println!(
        "  at the end {resting} of {} balls rest on the ground (speed < 5 cm/s); deepest below the surface: {:.1} mm",
        balls.len(),
        deepest * 1e3
    );
    println!("  {}", timer.summary());
    support::print_recording(&args.out);
    Ok(())
}

/// How many balls rest on the ground (slow, touching it) and how deep the deepest sinks (m).
fn at_rest(app: &App, balls: &[Entity]) -> (usize, f32) {
    let world = app.world();
    let mut resting = 0;
    let mut deepest = 0.0f32;
    for &ball in balls {
        let (Some(p), Some(v), Some(c)) = (
            world.get::<Position>(ball),
            world.get::<Velocity>(ball),
            world.get::<Collider>(ball),
        ) else {
            continue;
        };
        let gap = p.0.z - c.shape.bounding_radius();
        deepest = deepest.max(-gap);
        if v.0.length() < 0.05 && gap < 0.01 {
            resting += 1;
        }
    }
    (resting, deepest)
}
