//! urto in a game written the way Bevy games are: a real `App` run by `app.run()` under
//! `ScheduleRunnerPlugin`, frames at their own rate (50 per second by default) and physics at
//! urto's fixed 60 Hz, the game's logic in `FixedUpdate` systems. Recorded to
//! `game_integration.rrd`.
//!
//! - A player ball, spawned from a `Transform` with a `Density` (its mass follows its size),
//!   steers to a goal: a `FixedUpdate` system sets its `Force`, aiming with shape casts
//!   (`SpatialQuery::cast_sphere`) past the wall of crates between it and the goal.
//! - The goal is a static `Sensor` in a layer that only the player's ball can enter: crates and
//!   bullets pass through it untouched. An observer (`On<CollisionStart>` with
//!   `CollisionEventsEnabled`) scores, and the ball is sent back to the start by writing its
//!   `Transform` (a teleport the next step reads).
//! - A turret fires a bullet when a ray cast (`SpatialQuery::cast_ray`) sees the player; bullets
//!   are in a layer that ignores the other bullets, run with `Ccd`, and are despawned when they
//!   hit the player (an observer on the player, which also sums the hits' impact speeds and
//!   impulses from the event's `ContactData`) or after three seconds (entities removed while
//!   the game runs).
//! - The `CollisionStarted` messages are read once per frame (in `Last`, where a renderer draws); the player's drawn
//!   `Transform` is interpolated between fixed steps (`TransformInterpolation`).
//!
//! ```text
//! cargo run --release --example game_integration -- --help
//! rerun game_integration.rrd
//! ```

mod support;

use bevy_app::{App, AppExit, FixedUpdate, Last, ScheduleRunnerPlugin};
use bevy_ecs::prelude::*;
use bevy_time::{Fixed, Time, TimePlugin, TimeUpdateStrategy};
use bevy_transform::components::Transform;
use clap::Parser;
use glam::{Quat, Vec3};
use std::error::Error;
use std::time::{Duration, Instant};
use support::RecordingArgs;
use urto::debug::{DebugColor, RerunDebugPlugin};
use urto::plugins::SpatialQueryIndex;
use urto::prelude::*;

/// A player ball steering to a goal past crates and a turret, as a Bevy game runs it.
#[derive(Parser, Debug)]
struct Args {
    /// Seconds of game time to play.
    #[arg(long, default_value_t = 20.0)]
    seconds: f32,
    /// Rendered frames per second, 15 to 10,000 (physics steps at 60 Hz whatever this is: at
    /// most four steps a frame, so below 15 frames a second the game would fall behind).
    #[arg(long, default_value_t = 50.0)]
    fps: f32,
    /// Pace the frames by the wall clock, as a game with a window does (default: each frame
    /// advances the clocks by exactly 1/fps, as fast as the machine can, the same run every
    /// time).
    #[arg(long)]
    real_time: bool,
    #[command(flatten)]
    recording: RecordingArgs,
}

/// The scenery: ground, walls and the turret (the default layer).
const WORLD: LayerMask = LayerMask::DEFAULT;
const PLAYER: LayerMask = LayerMask(1 << 1);
const CRATES: LayerMask = LayerMask(1 << 2);
const BULLETS: LayerMask = LayerMask(1 << 3);
const GOAL: LayerMask = LayerMask(1 << 4);

const START: Vec3 = Vec3::new(-8.0, 0.0, PLAYER_RADIUS + 0.01);
const GOAL_AT: Vec3 = Vec3::new(8.0, 0.0, 0.5);
const TURRET_AT: Vec3 = Vec3::new(0.0, 5.0, 0.75);
const PLAYER_RADIUS: f32 = 0.4;
const BULLET_RADIUS: f32 = 0.1;
const BULLET_SPEED: f32 = 14.0;
const FIRE_EVERY: f32 = 0.8;
const BULLET_LIFE: f32 = 3.0;

#[derive(Component)]
struct Player {
    /// The side (+1 left, -1 right) it last turned to round an obstacle: it keeps to it, so
    /// that it does not dither in front of the wall.
    side: f32,
}

#[derive(Component)]
struct Goal;

#[derive(Component)]
struct Turret {
    reload: f32,
}

#[derive(Component)]
struct Bullet {
    age: f32,
}

/// Set by the goal's observer: the next fixed step sends the player back to the start.
#[derive(Component)]
struct Respawn;

/// What happened, for the summary.
#[derive(Resource, Default)]
struct Score {
    goals: u32,
    shots: u32,
    hits: u32,
    /// The hits' impact speeds (m/s) and their summed normal impulse (N·s), from the contact
    /// data each collision start carries.
    hit_speeds: Vec<f32>,
    hit_impulse: f32,
    expired: u32,
    collisions_started: u32,
    frames: u32,
    steps_in_frames: Vec<u32>,
    last_step: u64,
    /// Per frame, how far the player's ball moved over how far its speed carries it in a
    /// frame: as drawn (interpolated) and as stepped.
    drawn_pace: Vec<f32>,
    stepped_pace: Vec<f32>,
    /// The player's drawn and stepped positions at the last frame.
    last_seen: Option<(Vec3, Vec3)>,
}

/// When to stop, and what to print then.
#[derive(Resource)]
struct Run {
    seconds: f32,
    started: Instant,
    recording: std::path::PathBuf,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    if !(15.0..=10_000.0).contains(&args.fps) {
        return Err(format!("--fps must be within 15 to 10000, not {}", args.fps).into());
    }
    if !(args.seconds.is_finite() && args.seconds > 0.0) {
        return Err(format!("--seconds must be positive, not {}", args.seconds).into());
    }
    let frame = Duration::try_from_secs_f32(1.0 / args.fps)?;
    let mut app = App::new();
    app.add_plugins(TimePlugin)
        .add_plugins(UrtoPlugins::default())
        .add_plugins(RerunDebugPlugin::new(
            args.recording.config("game_integration", 1),
        )?)
        .insert_resource(Gravity::EARTH_Z_UP)
        .init_resource::<Score>()
        .insert_resource(Run {
            seconds: args.seconds,
            started: Instant::now(),
            recording: args.recording.path("game_integration"),
        });
    if args.real_time {
        app.add_plugins(ScheduleRunnerPlugin::run_loop(frame));
    } else {
        app.add_plugins(ScheduleRunnerPlugin::run_loop(Duration::ZERO))
            .insert_resource(TimeUpdateStrategy::ManualDuration(frame));
    }
    app.add_systems(
        FixedUpdate,
        (respawn, steer_player, fire_turret, age_bullets).chain(),
    )
    // Where a renderer would draw: after Bevy's `PostUpdate`, which interpolates the transforms.
    .add_systems(Last, (per_frame, end_after_playtime).chain());
    build_arena(app.world_mut());
    spawn_player(app.world_mut());
    match app.run() {
        AppExit::Success => Ok(()),
        AppExit::Error(code) => Err(format!("the game exited with code {code}").into()),
    }
}

/// Ground, four walls, a wall of crates across the way and the turret beside it.
fn build_arena(world: &mut World) {
    world.spawn((Collider::half_space(Vec3::Z), Static, Friction(0.6)));
    for (at, half) in [
        (Vec3::new(0.0, 6.5, 0.5), Vec3::new(10.5, 0.5, 0.5)),
        (Vec3::new(0.0, -6.5, 0.5), Vec3::new(10.5, 0.5, 0.5)),
        (Vec3::new(10.0, 0.0, 0.5), Vec3::new(0.5, 6.0, 0.5)),
        (Vec3::new(-10.0, 0.0, 0.5), Vec3::new(0.5, 6.0, 0.5)),
    ] {
        world.spawn((
            Collider::cuboid(half.x, half.y, half.z),
            Position(at),
            Static,
        ));
    }
    let crate_layers = CollisionLayers::new(CRATES, LayerMask::ALL);
    for row in 0..2 {
        for i in 0..6 {
            let y = -2.5 + i as f32 * 0.85 + row as f32 * 0.4;
            world.spawn((
                Collider::cuboid(0.4, 0.4, 0.4),
                Position::new(0.0, y, 0.4 + row as f32 * 0.8),
                Velocity::default(),
                Density(200.0),
                Friction(0.6),
                crate_layers,
            ));
        }
    }
    world.spawn((
        Collider::cuboid(0.5, 0.5, 0.75),
        Position(TURRET_AT),
        Static,
        Turret { reload: FIRE_EVERY },
        DebugColor([192, 57, 43]),
    ));
    let goal = world
        .spawn((
            Collider::cuboid(0.75, 1.5, 0.5),
            Position(GOAL_AT),
            Static,
            Sensor,
            CollisionLayers::new(GOAL, PLAYER),
            CollisionEventsEnabled,
            Goal,
            DebugColor([46, 204, 113]),
        ))
        .id();
    world.entity_mut(goal).observe(score_a_goal);
}

/// The player's ball, spawned the usual Bevy way: from a `Transform`.
fn spawn_player(world: &mut World) {
    let player = world
        .spawn((
            Transform::from_translation(START),
            Collider::sphere(PLAYER_RADIUS),
            Velocity::default(),
            Force::default(),
            Density(500.0),
            Friction(0.8),
            RollingResistance(0.01),
            CollisionLayers::new(PLAYER, LayerMask::ALL),
            CollisionEventsEnabled,
            TransformInterpolation,
            Player { side: 1.0 },
            DebugColor([52, 120, 219]),
        ))
        .id();
    world.entity_mut(player).observe(take_a_hit);
}

/// The goal's observer: the player's ball entered it.
fn score_a_goal(
    event: On<CollisionStart>,
    players: Query<(), With<Player>>,
    mut score: ResMut<Score>,
    mut commands: Commands,
) {
    if players.contains(event.other) {
        score.goals += 1;
        commands.entity(event.other).insert(Respawn);
    }
}

/// The player's observer: a bullet hit it (it pushed the ball, and now it is gone).
fn take_a_hit(
    event: On<CollisionStart>,
    bullets: Query<(), With<Bullet>>,
    mut score: ResMut<Score>,
    mut commands: Commands,
) {
    if bullets.contains(event.other) {
        score.hits += 1;
        if let Some(contact) = event.contact {
            score.hit_speeds.push(contact.impact_speed);
            score.hit_impulse += contact.normal_impulse;
        }
        commands.entity(event.other).try_despawn();
    }
}

/// Sends a scoring ball back to the start by writing its `Transform`, at rest.
fn respawn(
    mut players: Query<
        (Entity, &mut Transform, &mut Velocity, &mut AngularVelocity),
        With<Respawn>,
    >,
    mut commands: Commands,
) {
    for (entity, mut transform, mut v, mut w) in &mut players {
        *transform = Transform::from_translation(START);
        v.0 = Vec3::ZERO;
        w.0 = Vec3::ZERO;
        commands.entity(entity).remove::<Respawn>();
    }
}

/// Pushes the player toward the goal at a walking speed, turning aside (and keeping to that
/// side) where a cast of its own ball meets a crate or a wall within a few metres.
fn steer_player(
    mut players: Query<(
        Entity,
        &Position,
        &Velocity,
        &ComputedMass,
        &mut Force,
        &mut Player,
    )>,
    space: SpatialQuery,
) {
    const SPEED: f32 = 4.0;
    const LOOK_AHEAD: f32 = 3.0;
    for (entity, p, v, mass, mut force, mut player) in &mut players {
        let to_goal = (GOAL_AT - p.0).with_z(0.0);
        let Some(ahead) = to_goal.try_normalize() else {
            continue;
        };
        let filter =
            SpatialQueryFilter::from_mask(WORLD | CRATES | BULLETS).with_excluded([entity]);
        let clear = |dir: Vec3| {
            let reach = LOOK_AHEAD.min(to_goal.length());
            match space.cast_sphere(PLAYER_RADIUS * 0.9, p.0, dir, reach, &filter) {
                Ok(hit) => hit.is_none(),
                Err(_) => false,
            }
        };
        // Straight on, then ever wider turns to its side, and only then to the other.
        let turns = [0.0f32, 35.0, 70.0, 100.0];
        let side = player.side;
        let heading = turns
            .iter()
            .map(|&deg| deg * side)
            .chain(turns[1..].iter().map(|&deg| -deg * side))
            .map(|deg| Quat::from_rotation_z(deg.to_radians()) * ahead)
            .find(|&dir| clear(dir))
            .unwrap_or(ahead);
        let turn = ahead.cross(heading).z;
        if turn.abs() > 0.1 {
            player.side = turn.signum();
        }
        // A velocity controller in the ground plane: a = 3/s × (wanted − current).
        let push = (heading * SPEED - v.0.with_z(0.0)) * 3.0 * mass.value();
        force.0 += push;
    }
}

/// Fires a bullet at the player when the turret sees it (a ray from the muzzle hits the player
/// before anything else), led by the player's motion over the flight and aimed high by the
/// drop.
fn fire_turret(
    mut turrets: Query<(Entity, &Position, &mut Turret)>,
    players: Query<(Entity, &Position, &Velocity), With<Player>>,
    time: Res<Time>,
    gravity: Res<Gravity>,
    space: SpatialQuery,
    mut score: ResMut<Score>,
    mut commands: Commands,
) {
    let Ok((player, target, moving)) = players.single() else {
        return;
    };
    for (turret, at, mut state) in &mut turrets {
        state.reload -= time.delta_secs();
        if state.reload > 0.0 {
            continue;
        }
        let Some(dir) = (target.0 - at.0).try_normalize() else {
            continue;
        };
        let muzzle = at.0 + dir * 1.0;
        let filter = SpatialQueryFilter::from_mask(WORLD | CRATES | PLAYER).with_excluded([turret]);
        let seen = matches!(
            space.cast_ray(muzzle, dir, 30.0, &filter),
            Ok(Some(hit)) if hit.entity == player
        );
        if !seen {
            continue;
        }
        let flight = (target.0 - muzzle).length() / BULLET_SPEED;
        let lead = target.0 + moving.0.with_z(0.0) * flight;
        let Some(aim) = (lead - muzzle).try_normalize() else {
            continue;
        };
        let flight = (lead - muzzle).length() / BULLET_SPEED;
        let lift = -gravity.acceleration() * flight * 0.5;
        state.reload = FIRE_EVERY;
        commands.spawn((
            Collider::sphere(BULLET_RADIUS),
            Position(muzzle),
            Velocity(aim * BULLET_SPEED + lift),
            Density(2000.0),
            Ccd,
            CollisionLayers::new(BULLETS, PLAYER | CRATES | WORLD),
            Bullet { age: 0.0 },
            DebugColor([241, 196, 15]),
        ));
        score.shots += 1;
    }
}

/// Bullets that miss the player live three seconds (bouncing off walls and crates meanwhile).
fn age_bullets(
    mut bullets: Query<(Entity, &mut Bullet)>,
    time: Res<Time>,
    mut score: ResMut<Score>,
    mut commands: Commands,
) {
    for (entity, mut bullet) in &mut bullets {
        bullet.age += time.delta_secs();
        if bullet.age > BULLET_LIFE {
            score.expired += 1;
            commands.entity(entity).try_despawn();
        }
    }
}

/// Once a frame: the collisions that started since the last frame, how many fixed steps this
/// frame ran, and how evenly the player's ball moves on screen.
fn per_frame(
    mut started: MessageReader<CollisionStarted>,
    stats: Res<PhysicsStats>,
    time: Res<Time>,
    players: Query<(&Position, &Transform, &Velocity), With<Player>>,
    mut score: ResMut<Score>,
) {
    score.collisions_started += started.read().count() as u32;
    let steps = (stats.step - score.last_step) as u32;
    score.last_step = stats.step;
    score.frames += 1;
    score.steps_in_frames.push(steps);
    let Ok((p, drawn, v)) = players.single() else {
        return;
    };
    let now = (drawn.translation, p.0);
    if let Some((was_drawn, was_stepped)) = score.last_seen.replace(now) {
        let reach = v.0.length() * time.delta_secs();
        // Steady motion only: not the frame of a teleport, not a ball nearly at rest.
        if v.0.length() > 1.0 && reach > 0.0 && now.1.distance(was_stepped) < 1.0 {
            score.drawn_pace.push(now.0.distance(was_drawn) / reach);
            score.stepped_pace.push(now.1.distance(was_stepped) / reach);
        }
    }
}

/// Ends the game after its play time, printing what happened.
fn end_after_playtime(
    time: Res<Time>,
    fixed: Res<Time<Fixed>>,
    run: Res<Run>,
    score: Res<Score>,
    (stats, index): (Res<PhysicsStats>, Option<Res<SpatialQueryIndex>>),
    players: Query<&ComputedMass, With<Player>>,
    mut exit: MessageWriter<AppExit>,
) {
    if time.elapsed_secs() < run.seconds {
        return;
    }
    let frames = score.frames.max(1);
    let (fewest, most) = score
        .steps_in_frames
        .iter()
        .skip(1)
        .fold((u32::MAX, 0), |(lo, hi), &n| (lo.min(n), hi.max(n)));
    println!(
        "game_integration: {:.1} s of game time in {} frames and {} physics steps ({:.1} steps per second, {} to {} per frame)",
        time.elapsed_secs(),
        frames,
        stats.step,
        stats.step as f32 / time.elapsed_secs(),
        fewest.min(most),
        most,
    );
    println!(
        "  the physics clock: {:.3} s in steps of {:.2} ms",
        fixed.elapsed_secs(),
        fixed.timestep().as_secs_f64() * 1e3
    );
    if let Ok(mass) = players.single() {
        println!("  player ball: {:.0} kg from its density", mass.value());
    }
    println!(
        "  per frame the ball moved, over its speed × the frame time: drawn (interpolated) {}, stepped {}",
        spread(&score.drawn_pace),
        spread(&score.stepped_pace)
    );
    println!(
        "  goals: {}; turret shots: {}, hits on the player: {}, expired: {}, in flight: {}",
        score.goals,
        score.shots,
        score.hits,
        score.expired,
        score.shots.saturating_sub(score.hits + score.expired)
    );
    let (slowest, fastest) = (score.hit_speeds.iter())
        .fold((f32::INFINITY, 0.0f32), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if !score.hit_speeds.is_empty() {
        println!(
            "  the hits' contact data: impact speeds {slowest:.1} to {fastest:.1} m/s, normal impulses {:.1} N·s in all",
            score.hit_impulse
        );
    }
    println!(
        "  collisions started (messages read once a frame): {}",
        score.collisions_started
    );
    if let Some(index) = index {
        let r = index.refreshes();
        println!(
            "  the query index: refitted {} times, kept through spawns and despawns {}, rebuilt {}",
            r.refits, r.updates, r.rebuilds
        );
    }
    println!("  wall time: {:.2} s", run.started.elapsed().as_secs_f64());
    support::print_recording(&run.recording);
    exit.write(AppExit::Success);
}

/// The 5th to the 95th percentile of `values`.
fn spread(values: &[f32]) -> String {
    if values.is_empty() {
        return "(no steady frame)".into();
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f32::total_cmp);
    let at = |q: f32| sorted[((sorted.len() - 1) as f32 * q) as usize];
    format!("{:.2}–{:.2}", at(0.05), at(0.95))
}
