//! Billiards: a break shot into a triangle rack. Many balls, mass-weighted impacts, cushions;
//! the recording shows the sweep-and-prune pairs (segments), the contacts (arrows), and per-step
//! pair and swap counts as time series.
//!
//! ```text
//! cargo run --release --example billiards
//! rerun billiards.rrd
//! ```

use bevy_app::App;
use bevy_ecs::bundle::Bundle;
use bevy_ecs::message::Messages;
use clap::Parser;
use glam::Vec3;
use std::error::Error;
use std::path::PathBuf;
use std::time::Instant;
use urto::debug::{RerunConfig, RerunDebugPlugin};
use urto::prelude::*;

/// A break shot on a billiard table, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Rows of the triangle rack (rows·(rows+1)/2 balls).
    #[arg(long, default_value_t = 7)]
    rows: u32,
    /// Speed of the cue ball (m/s).
    #[arg(long, default_value_t = 6.0)]
    speed: f32,
    /// Physics steps (120 per simulated second).
    #[arg(long, default_value_t = 720)]
    steps: u32,
    /// Where to write the recording.
    #[arg(long, default_value = "billiards.rrd")]
    out: PathBuf,
    /// Open the viewer on the last recorded step (for screenshots).
    #[arg(long)]
    open_at_end: bool,
}

const RADIUS: f32 = 0.0286;
const BALL_MASS: f32 = 0.17;
const DRAG: f32 = 0.03;
/// A step shortly after the break, before any ball can reach a cushion.
const BREAK_CHECK_STEP: u32 = 25;
const TABLE: Vec3 = Vec3::new(1.27, 0.635, 0.02); // half extents of the playing surface

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let recording = RerunDebugPlugin::new(RerunConfig {
        app_id: "urto billiards".into(),
        velocities: false,
        bounding_volumes: false,
        plane_half_size: 2.0,
        open_at_end: args.open_at_end,
        ..RerunConfig::file(&args.out)
    })?;
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::with_timestep(PhysicsTimestep::new(
        1.0 / 120.0,
        1,
    )?))
    .add_plugins(recording)
    .insert_resource(Gravity::EARTH_Z_UP);
    build_table(&mut app);
    let balls = rack(&mut app, args.rows);
    let cue = app
        .world_mut()
        .spawn(ball(
            Vec3::new(-0.6, 0.0, RADIUS),
            Vec3::new(args.speed, 0.013, 0.0),
        ))
        .id();

    let momentum_before = total_momentum(&app, &balls, cue);
    let start = Instant::now();
    let (mut collisions, mut max_pairs, mut swaps) = (0usize, 0.0f64, 0.0f64);
    let mut cursor = app
        .world()
        .resource::<Messages<CollisionStarted>>()
        .get_cursor();
    let mut momentum_after_break = None;
    for step in 0..args.steps {
        urto::step(app.world_mut(), 1)?;
        let world = app.world();
        collisions += cursor
            .read(world.resource::<Messages<CollisionStarted>>())
            .count();
        let stats = world.resource::<PhysicsStats>();
        max_pairs = max_pairs.max(stats.counter("broad_phase/pairs").unwrap_or(0.0));
        swaps += stats.counter("broad_phase/sap_swaps").unwrap_or(0.0);
        if step == BREAK_CHECK_STEP {
            momentum_after_break = Some(total_momentum(&app, &balls, cue));
        }
    }
    let wall = start.elapsed().as_secs_f64();
    let moving = balls
        .iter()
        .chain([&cue])
        .filter(|e| app.world().get::<Velocity>(**e).unwrap().0.length() > 0.05)
        .count();
    println!("billiards: {} balls, {} steps", balls.len() + 1, args.steps);
    println!("  collisions started: {collisions}, most ball pairs in one step: {max_pairs}");
    println!(
        "  sweep-and-prune swaps per step: {:.1}",
        swaps / args.steps as f64
    );
    if let Some(p) = momentum_after_break {
        // Ball–ball impulses conserve momentum; only drag (the same b/m for every ball) removes
        // it, by (1 - b/m dt) per step under symplectic Euler.
        let decay = (1.0 - DRAG / BALL_MASS / 120.0).powi(BREAK_CHECK_STEP as i32 + 1);
        let expected = momentum_before.truncate() * decay;
        let error = (p.truncate() - expected).length() / expected.length();
        println!(
            "  horizontal momentum after the break: {:.5} kg·m/s, drag alone predicts {:.5} (relative error {error:.1e})",
            p.truncate().length(),
            expected.length()
        );
    }
    println!("  balls still rolling at the end: {moving}");
    println!(
        "  time per step: {:.1} µs (with recording)",
        wall / args.steps as f64 * 1e6
    );
    println!(
        "  recording: {}  (open it with `rerun {}`)",
        args.out.display(),
        args.out.display()
    );
    Ok(())
}

fn ball(at: Vec3, v: Vec3) -> impl Bundle {
    (
        Collider::sphere(RADIUS),
        Position(at),
        Velocity(v),
        Mass(BALL_MASS),
        Restitution(0.95),
        LinearDrag(DRAG),
        // Balls roll rather than slide; urto's bodies do not spin, so rolling resistance is
        // modelled by the drag and sliding friction is off.
        Friction(0.0),
    )
}

/// The playing surface (its top at z = 0) and four cushions.
fn build_table(app: &mut App) {
    let world = app.world_mut();
    world.spawn((
        Collider::cuboid(TABLE.x, TABLE.y, TABLE.z),
        Position::new(0.0, 0.0, -TABLE.z),
        Static,
        Restitution(0.0),
    ));
    let h = 0.025;
    let (w, l) = (0.05, TABLE.x + 0.1);
    for (pos, half) in [
        (Vec3::new(0.0, TABLE.y + w, h), Vec3::new(l, w, h)),
        (Vec3::new(0.0, -TABLE.y - w, h), Vec3::new(l, w, h)),
        (Vec3::new(TABLE.x + w, 0.0, h), Vec3::new(w, TABLE.y, h)),
        (Vec3::new(-TABLE.x - w, 0.0, h), Vec3::new(w, TABLE.y, h)),
    ] {
        world.spawn((
            Collider::cuboid(half.x, half.y, half.z),
            Position(pos),
            Static,
            Restitution(0.75),
        ));
    }
}

/// A triangle rack pointing at the cue ball, apex at x = 0.4.
fn rack(app: &mut App, rows: u32) -> Vec<bevy_ecs::entity::Entity> {
    let gap = 2.0 * RADIUS * 1.001;
    let mut balls = Vec::new();
    for row in 0..rows {
        for k in 0..=row {
            let x = 0.4 + row as f32 * gap * 0.866;
            let y = (k as f32 - row as f32 / 2.0) * gap;
            balls.push(
                app.world_mut()
                    .spawn(ball(Vec3::new(x, y, RADIUS), Vec3::ZERO))
                    .id(),
            );
        }
    }
    balls
}

fn total_momentum(
    app: &App,
    balls: &[bevy_ecs::entity::Entity],
    cue: bevy_ecs::entity::Entity,
) -> Vec3 {
    balls
        .iter()
        .chain([&cue])
        .map(|e| app.world().get::<Velocity>(*e).unwrap().0 * BALL_MASS)
        .sum()
}
