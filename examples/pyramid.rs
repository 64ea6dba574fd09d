//! A pyramid of boxes, then a heavy ball thrown into it: the soft-step rigid-body solver
//! (`SoftStepPlugin`) stacks boxes that stand still, and topples them so they tumble, roll and
//! come to rest on their faces. Recorded to `pyramid.rrd`.
//!
//! ```text
//! cargo run --release --example pyramid -- --help
//! rerun pyramid.rrd
//! ```

mod support;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use clap::Parser;
use glam::{Quat, Vec3};
use std::error::Error;
use support::{RecordingArgs, StepTimer};
use urto::debug::RerunDebugPlugin;
use urto::prelude::*;

/// A pyramid of boxes struck by a ball, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Rows of the pyramid (rows × (rows + 1) / 2 boxes).
    #[arg(long, default_value_t = 12)]
    rows: u32,
    /// Seconds the pyramid stands before the ball is thrown.
    #[arg(long, default_value_t = 2.0)]
    stand: f32,
    /// Seconds simulated in all.
    #[arg(long, default_value_t = 8.0)]
    seconds: f32,
    #[command(flatten)]
    recording: RecordingArgs,
}

const HALF: f32 = 0.25;

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::default())
        .add_plugins(RerunDebugPlugin::new(args.recording.config("pyramid", 1))?)
        .insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Friction(0.6)));
    let boxes = build_pyramid(&mut app, args.rows);
    let start: Vec<Vec3> = boxes.iter().map(|&b| position(&app, b)).collect();

    let mut timer = StepTimer::start();
    let stand_steps = (args.stand * 60.0) as u32;
    for _ in 0..stand_steps {
        urto::step(app.world_mut(), 1)?;
        timer.add(&app);
    }
    let drift = boxes
        .iter()
        .zip(&start)
        .map(|(&b, s)| position(&app, b).distance(*s))
        .fold(0.0f32, f32::max);

    let height = args.rows as f32 * HALF;
    app.world_mut().spawn((
        Collider::sphere(0.4),
        Position::new(-8.0, 0.0, height),
        Velocity::new(14.0, 0.0, 1.5),
        Mass(40.0),
        Friction(0.6),
    ));
    let mut fastest_spin = 0.0f32;
    for _ in stand_steps..(args.seconds * 60.0) as u32 {
        urto::step(app.world_mut(), 1)?;
        timer.add(&app);
        for &b in &boxes {
            let w = app
                .world()
                .get::<AngularVelocity>(b)
                .map_or(0.0, |w| w.0.length());
            fastest_spin = fastest_spin.max(w);
        }
    }

    let toppled = boxes
        .iter()
        .zip(&start)
        .filter(|(b, s)| position(&app, **b).distance(**s) > HALF)
        .count();
    let flat = boxes.iter().filter(|&&b| lies_on_a_face(&app, b)).count();
    println!(
        "pyramid: {} rows, {} boxes, soft-step solver ({} steps, {:.1} s simulated)",
        args.rows,
        boxes.len(),
        app.world().resource::<PhysicsStats>().step,
        args.seconds
    );
    println!(
        "  standing for {:.1} s: the farthest box moved {:.1} mm",
        args.stand,
        drift * 1e3
    );
    println!(
        "  after the ball: {toppled} boxes knocked out of place, fastest spin {fastest_spin:.1} rad/s, {flat} of {} lying flat on a face at the end",
        boxes.len()
    );
    println!("  {}", timer.summary());
    support::print_recording(&args.recording.path("pyramid"));
    Ok(())
}

/// Rows of boxes, each row centred over the one below and 1 % apart.
fn build_pyramid(app: &mut App, rows: u32) -> Vec<Entity> {
    let mut boxes = Vec::new();
    for row in 0..rows {
        let count = rows - row;
        for k in 0..count {
            let y = (k as f32 - (count - 1) as f32 * 0.5) * 2.0 * HALF * 1.01;
            let z = HALF + 2.0 * HALF * row as f32;
            let id = app
                .world_mut()
                .spawn((
                    Collider::cuboid(HALF, HALF, HALF),
                    Position::new(0.0, y, z),
                    Velocity::default(),
                    Mass(2.0),
                    Friction(0.6),
                ))
                .id();
            boxes.push(id);
        }
    }
    boxes
}

fn position(app: &App, e: Entity) -> Vec3 {
    app.world().get::<Position>(e).map_or(Vec3::ZERO, |p| p.0)
}

/// True when one of the box's axes is vertical within 2°: it lies on a face.
fn lies_on_a_face(app: &App, e: Entity) -> bool {
    let r = app
        .world()
        .get::<Rotation>(e)
        .map_or(Quat::IDENTITY, |r| r.0);
    Vec3::AXES
        .iter()
        .any(|&a| (r * a).z.abs() > 2f32.to_radians().cos())
}
