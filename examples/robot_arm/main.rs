//! The robot arm: an arm driven by motors (a turret on a hinge about the vertical, then a
//! shoulder, an elbow and a wrist on hinges about the horizontal) stands in the middle of a
//! workbench and sweeps round and round, clearing crates, balls and a tray of bottles off the
//! bench.
//!
//! **Nothing about the arm is scripted but its motors' targets.** The turret's velocity motor
//! turns it at a steady rate; the game reads how far it has turned, picks the reach for that
//! point of the sweep, and a little inverse kinematics turns the reach into target angles for
//! the shoulder's, elbow's and wrist's position motors (20 Hz springs with a torque
//! limit, Box2D's and Avian's motors). The links are dynamic bodies: gravity pulls on them, the
//! crates push back, and the motors' torques are what bats the crates away. A link that hits a
//! heavy crate trails its target and catches up.
//!
//! Each link is also a compound: a ball at its joint is the link's root, and its box, the
//! counterweight, the gripper's fingers and camera are children (bevy's `ChildOf`), rigid parts
//! of the link. The scene graph *is* the bounding-volume hierarchy (the slides' "Conclusioni"):
//! a link's volume bounds its parts, and the narrow phase descends it only where the other
//! side's volume overlaps, always splitting the larger of the two volumes first. A ball near the
//! gripper is tested against the finger it touches, not against every part of the gripper.
//!
//! The recording shows each joint's anchors and axis (orange, red past a limit), the motors'
//! torques as time series (`joints/<entity>/motor`), the volumes level by level (one tab per
//! depth of the scene graph) and, in the main view, which nodes the descent entered (yellow)
//! or pruned (grey) and the collider pairs it handed to the exact test (red segments).
//!
//! ```text
//! cargo run --release --example robot_arm -- --help
//! rerun robot_arm.rrd
//! ```

mod measures;
#[path = "../support/mod.rs"]
mod support;

use measures::{FirstTouches, Report, Tracking, Work, note_touches};

use bevy_app::App;
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;
use clap::Parser;
use glam::{Quat, Vec2, Vec3};
use std::collections::BTreeMap;
use std::error::Error;
use std::f32::consts::{PI, TAU};
use support::{Collisions, Lcg, StepTimer};
use urto::debug::{DebugColor, RerunConfig, RerunDebugPlugin};
use urto::geometry::Isometry;
use urto::prelude::*;

/// A motor-driven robot arm clearing a workbench, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Crates on the bench.
    #[arg(long, default_value_t = 8)]
    crates: u32,
    /// Balls on the bench.
    #[arg(long, default_value_t = 8)]
    balls: u32,
    /// Physics steps (60 per simulated second). The turret turns once every 10 s; by default
    /// the run stops during the third turn, as the arm sweeps the far end of the bench.
    #[arg(long, default_value_t = 1650)]
    steps: u32,
    /// Depths of the scene graph shown, one tab each.
    #[arg(long, default_value_t = 2)]
    levels: u32,
    #[command(flatten)]
    recording: support::RecordingArgs,
}

/// Height of the bench's top (m) and half its length and width.
const BENCH_TOP: f32 = 0.8;
const BENCH: Vec2 = Vec2::new(2.6, 0.65);
/// The shoulder's height above the bench, and the lengths of the upper arm and forearm (joint
/// to joint) and of the gripper's box.
const SHOULDER: f32 = 0.45;
const UPPER: f32 = 1.1;
const FORE: f32 = 1.0;
const GRIPPER: f32 = 0.22;
/// The wrist's height above the bench while sweeping: the gripper skims the obstacles' tops.
const SKIM: f32 = 0.18;
/// The turret's motor speed (rad/s), and the wrist's reach on successive turns.
const TURN_RATE: f32 = TAU / 10.0;
const REACHES: [f32; 3] = [0.95, 1.4, 1.85];
/// The pitch joints' position motors: stiffness (Hz), damping ratio, and the largest torque of
/// the shoulder, elbow and wrist (N·m).
const MOTOR_HERTZ: f32 = 20.0;
const MOTOR_DAMPING: f32 = 1.0;
const MAX_TORQUES: [f32; 3] = [900.0, 400.0, 80.0];

const ARM: [u8; 3] = [240, 243, 245];
const JOINT: [u8; 3] = [127, 140, 141];
const BALLS: [[u8; 3]; 3] = [[46, 204, 113], [231, 76, 60], [155, 89, 182]];

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let recording = RerunDebugPlugin::new(RerunConfig {
        velocities: false,
        bounding_volumes: false,
        scene_graph_levels: args.levels,
        hierarchy_visits: true,
        ..args.recording.config("robot_arm", 1)
    })?;
    let mut app = support::game_app(
        2,
        Gravity::EARTH_Z_UP,
        ContactSettings {
            default_restitution: 0.3,
            default_friction: 0.5,
            ..Default::default()
        },
    )?;
    app.add_plugins(recording);
    let obstacles = build_bench(&mut app, &args);
    let arm = spawn_arm(&mut app);
    let report = run(&mut app, &args, &arm, &obstacles)?;
    report.print(&app, &args, &arm, &obstacles);
    Ok(())
}

/// Spawns the floor, the bench (static) and the obstacles on it (dynamic: crates, balls and a
/// tray of bottles, itself a small compound); returns the obstacles' roots.
fn build_bench(app: &mut App, args: &Args) -> Vec<Entity> {
    let world = app.world_mut();
    // The floor is a slab rather than a half-space: an unbounded volume would overlap every
    // node of a link's hierarchy, and the descent could prune nothing against it. Its rolling
    // resistance (a workshop floor) stops the balls knocked off the bench.
    let floor = (Collider::cuboid(4.5, 3.5, 0.05), Position(Vec3::Z * -0.05));
    world.spawn((
        floor,
        Static,
        RollingResistance(0.01),
        DebugColor([210, 215, 218]),
    ));
    let mut slab = |half: Vec3, at: Vec3, color: [u8; 3]| {
        let body = (Collider::cuboid(half.x, half.y, half.z), Position(at));
        world.spawn((body, Static, DebugColor(color)));
    };
    let top = Vec3::Z * (BENCH_TOP - 0.04);
    slab(BENCH.extend(0.04), top, [93, 109, 126]);
    let legs = (BENCH - 0.1).extend((BENCH_TOP - 0.08) / 2.0);
    for (x, y) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (1.0, -1.0)] {
        let leg = legs * Vec3::new(x, y, 1.0);
        slab(Vec3::new(0.05, 0.05, legs.z), leg, [93, 109, 126]);
    }
    let mut rng = Lcg::new(7);
    let mut placed: Vec<(Vec2, f32)> = Vec::new();
    // Random spots within the arm's sweep and clear of each other; a spot not found in a few
    // hundred tries (a crowded bench) is skipped.
    let mut spot = |r: f32, rng: &mut Lcg| {
        (0..400).find_map(|_| {
            let at = Vec2::new(rng.range(-2.4, 2.4), rng.range(r - BENCH.y, BENCH.y - r));
            let reachable = (0.85..2.3).contains(&at.length());
            let free = reachable && placed.iter().all(|&(p, q)| p.distance(at) > r + q + 0.05);
            if free {
                placed.push((at, r));
            }
            free.then_some(at)
        })
    };
    let mut obstacles = Vec::new();
    let tray_at = spot(0.25, &mut rng).unwrap_or(Vec2::new(1.5, 0.0));
    obstacles.push(spawn_tray(world, tray_at));
    for i in 0..args.crates + args.balls {
        let size = rng.range(0.09, 0.13);
        let Some(at) = spot(size * 1.45, &mut rng) else {
            continue;
        };
        let (collider, color) = if i < args.crates {
            (Collider::cuboid(size, size, size), [194, 146, 92])
        } else {
            (Collider::sphere(size), BALLS[rng.below(BALLS.len())])
        };
        let body = (collider, Position(at.extend(BENCH_TOP + size)));
        let id = world.spawn((body, Velocity::default(), Mass(2.0), DebugColor(color)));
        obstacles.push(id.id());
    }
    obstacles
}

/// A tray with three bottles: a dynamic compound, so the arm meets it through two hierarchies
/// and the descent splits whichever of the two current volumes is larger.
fn spawn_tray(world: &mut World, at: Vec2) -> Entity {
    let tray = world
        .spawn((
            Collider::cuboid(0.22, 0.16, 0.02),
            Position(at.extend(BENCH_TOP + 0.02)),
            Velocity::default(),
            Mass(3.0),
            DebugColor([127, 140, 141]),
            Name::new("tray"),
        ))
        .id();
    for x in [-0.13, 0.0, 0.13] {
        let bottle = (
            Collider::cuboid(0.045, 0.045, 0.13),
            Position::new(x, 0.0, 0.15),
        );
        world.spawn((bottle, ChildOf(tray), DebugColor([22, 160, 133])));
    }
    tray
}

/// The arm's bodies and the joints the game drives.
struct Arm {
    /// Turret, upper arm, forearm, gripper.
    links: [Entity; 4],
    /// The turret's joint (velocity motor), then the shoulder's, elbow's and wrist's (position
    /// motors).
    joints: [Entity; 4],
    /// Colliders per link.
    colliders: [usize; 4],
}

/// A link's parts beyond its root ball: name, half extents of its box and position in the
/// link's frame (the joint at the origin, the link along x).
type Parts = &'static [(&'static str, [f32; 3], [f32; 3])];

const UPPER_PARTS: Parts = &[
    ("upper arm", [0.45, 0.08, 0.08], [UPPER / 2.0, 0.0, 0.0]),
    ("counterweight", [0.08, 0.11, 0.08], [-0.25, 0.0, 0.12]),
];
const FORE_PARTS: Parts = &[("forearm", [0.4, 0.065, 0.065], [FORE / 2.0, 0.0, 0.0])];
const GRIPPER_PARTS: Parts = &[
    (
        "gripper",
        [GRIPPER / 2.0, 0.12, 0.05],
        [GRIPPER / 2.0, 0.0, 0.0],
    ),
    ("camera", [0.05, 0.04, 0.03], [GRIPPER / 2.0, 0.0, 0.11]),
    (
        "finger L",
        [0.08, 0.02, 0.04],
        [GRIPPER / 2.0 + 0.15, 0.09, -0.02],
    ),
    (
        "finger R",
        [0.08, 0.02, 0.04],
        [GRIPPER / 2.0 + 0.15, -0.09, -0.02],
    ),
];

/// The base's half extents and the turret's half height and radius: the base bolted on the
/// bench, the turret on it, and the shoulder's ball above on a post of the turret.
const BASE: Vec3 = Vec3::new(0.15, 0.15, 0.1);
const TURRET: (f32, f32) = (0.05, 0.18);

/// A link: its root ball (`radius`, with the link's `mass`) placed at `pose`, and its parts as
/// children; returns the link and how many colliders it has.
fn spawn_link(
    world: &mut World,
    (name, radius, mass): (&str, f32, f32),
    pose: Isometry,
    parts: Parts,
) -> (Entity, usize) {
    let link = world
        .spawn((
            Collider::sphere(radius),
            Position(pose.translation),
            Rotation(pose.rotation),
            Velocity::default(),
            Mass(mass),
            DebugColor(JOINT),
            Name::new(name.to_string()),
        ))
        .id();
    for &(part, half, at) in parts {
        world.spawn((
            Collider::cuboid(half[0], half[1], half[2]),
            Position(Vec3::from(at)),
            ChildOf(link),
            DebugColor(ARM),
            Name::new(part),
        ));
    }
    (link, parts.len() + 1)
}

/// The arm, posed for the start of its sweep: a static base on the bench, the turret on a
/// motorised hinge about z, and three links on motorised hinges about their y axes.
fn spawn_arm(app: &mut App) -> Arm {
    let world = app.world_mut();
    let base_at = Vec3::new(0.0, 0.0, BENCH_TOP + BASE.z);
    let base = world
        .spawn((
            Collider::cuboid(BASE.x, BASE.y, BASE.z),
            Position(base_at),
            Static,
            DebugColor(JOINT),
            Name::new("base"),
        ))
        .id();
    let (yaw, reach) = (PI / 2.0, REACHES[0]);
    let turret_at = base_at + Vec3::Z * (BASE.z + TURRET.0);
    let turret = world
        .spawn((
            Collider::cylinder(TURRET.0, TURRET.1),
            Position(turret_at),
            Rotation(Quat::from_rotation_z(yaw)),
            Velocity::default(),
            Mass(10.0),
            DebugColor(JOINT),
            Name::new("turret"),
        ))
        .id();
    let shoulder_at = Vec3::new(0.0, 0.0, BENCH_TOP + SHOULDER);
    let [up, fore, grip] = link_poses(shoulder_at, yaw, joint_angles(reach));
    let (upper, n_upper) = spawn_link(world, ("shoulder", 0.1, 5.0), up, UPPER_PARTS);
    let (forearm, n_fore) = spawn_link(world, ("elbow", 0.09, 3.0), fore, FORE_PARTS);
    let (gripper, n_grip) = spawn_link(world, ("wrist", 0.07, 1.5), grip, GRIPPER_PARTS);
    // A hinge about −y turns a link's x axis upwards for a positive angle.
    let pitch = |a: Entity, b: Entity, anchor_a: Vec3, limits: (f32, f32), max: f32| {
        Joint::revolute(a, b)
            .with_axis(Vec3::NEG_Y)
            .with_anchors(anchor_a, Vec3::ZERO)
            .with_limits(limits.0, limits.1)
            .with_motor(JointMotor::position(0.0, MOTOR_HERTZ, MOTOR_DAMPING, max))
    };
    let joints = [
        Joint::revolute(base, turret)
            .with_axis(Vec3::Z)
            .with_anchors(Vec3::Z * BASE.z, Vec3::Z * -TURRET.0)
            .with_motor(JointMotor::velocity(TURN_RATE, 600.0)),
        pitch(
            turret,
            upper,
            shoulder_at - turret_at,
            (-0.5, 1.5),
            MAX_TORQUES[0],
        ),
        pitch(upper, forearm, Vec3::X * UPPER, (-2.8, 0.2), MAX_TORQUES[1]),
        pitch(
            forearm,
            gripper,
            Vec3::X * FORE,
            (-0.5, 2.0),
            MAX_TORQUES[2],
        ),
    ]
    .map(|joint| world.spawn(joint).id());
    Arm {
        links: [turret, upper, forearm, gripper],
        joints,
        colliders: [1, n_upper, n_fore, n_grip],
    }
}

/// Where the upper arm, forearm and gripper are for the turret turned to `yaw` and the pitch
/// joints at `angles` (forward kinematics; each link's origin at its joint).
fn link_poses(shoulder: Vec3, yaw: f32, angles: (f32, f32, f32)) -> [Isometry; 3] {
    // A rotation about local y by −a raises the link's x axis by a.
    let upper = Quat::from_rotation_z(yaw) * Quat::from_rotation_y(-angles.0);
    let fore = upper * Quat::from_rotation_y(-angles.1);
    let grip = fore * Quat::from_rotation_y(-angles.2);
    let elbow = shoulder + upper * Vec3::X * UPPER;
    let wrist = elbow + fore * Vec3::X * FORE;
    [
        Isometry::new(shoulder, upper),
        Isometry::new(elbow, fore),
        Isometry::new(wrist, grip),
    ]
}

/// The wrist's reach once the turret has turned `turned` rad from its start: it grows on each
/// turn, and changes while the arm points off the bench (the last tenth of a turn), so each
/// turn sweeps one ring of the bench clean.
fn reach(turned: f32) -> f32 {
    let turns = turned.max(0.0) / TAU;
    let (turn, into) = (turns as usize, turns.fract());
    let from = REACHES[turn.min(REACHES.len() - 1)];
    let to = REACHES[(turn + 1).min(REACHES.len() - 1)];
    let blend = ((into - 0.9) / 0.1).clamp(0.0, 1.0);
    from + (to - from) * blend * blend * (3.0 - 2.0 * blend)
}

/// Two-link inverse kinematics in the arm's vertical plane, elbow up: the shoulder's elevation
/// and the elbow's and wrist's bends that put the wrist `reach` out from the shoulder at the
/// skimming height, with the gripper level.
fn joint_angles(reach: f32) -> (f32, f32, f32) {
    let target = Vec2::new(reach, SKIM - SHOULDER);
    let d = target.length().clamp(0.2, UPPER + FORE - 1e-3);
    let bend = ((d * d - UPPER * UPPER - FORE * FORE) / (2.0 * UPPER * FORE)).clamp(-1.0, 1.0);
    let bend = bend.acos();
    let lift = target.y.atan2(target.x) + (FORE * bend.sin()).atan2(UPPER + FORE * bend.cos());
    (lift, -bend, bend - lift)
}

/// Runs the simulation: before each step the game reads the turret's turn and sets the pitch
/// motors' targets for it; after it, counts the arm's hits and how the motors followed.
fn run(
    app: &mut App,
    args: &Args,
    arm: &Arm,
    obstacles: &[Entity],
) -> Result<Report, Box<dyn Error>> {
    app.insert_resource(FirstTouches {
        links: arm.links.to_vec(),
        parts: BTreeMap::new(),
    })
    .add_systems(SubstepSchedule, note_touches.after(SubstepSet::NarrowPhase));
    let mut colliders = BTreeMap::from([(obstacles[0], 4)]);
    colliders.extend(
        arm.links
            .iter()
            .zip(arm.colliders)
            .map(|(&e, n)| (e, n as u64)),
    );
    colliders.retain(|_, n| *n > 1);
    let mut collisions = Collisions::new(app);
    let mut report = Report {
        hits: 0,
        starts: obstacles
            .iter()
            .map(|&e| pose(app, e).translation)
            .collect(),
        tracking: Tracking {
            last_yaw: yaw(app, arm.links[0]),
            ..Default::default()
        },
        work: Work::default(),
        timer: StepTimer::start(),
    };
    for step in 0..args.steps {
        let targets = steer(app, arm, &mut report.tracking);
        urto::step(app.world_mut(), 1)?;
        report.timer.add(app);
        let with_arm = |&(a, b): &(Entity, Entity)| {
            let (arm_a, arm_b) = (arm.links.contains(&a), arm.links.contains(&b));
            (arm_a && obstacles.contains(&b)) || (arm_b && obstacles.contains(&a))
        };
        report.hits += collisions.read(app).iter().filter(|p| with_arm(p)).count() as u32;
        report.work.add(app, &colliders);
        report.tracking.add(app, arm, targets, step >= 60);
    }
    Ok(report)
}

/// The game's only input: from how far the turret has turned, the reach, and from the reach
/// the pitch motors' target angles; returns the targets.
fn steer(app: &mut App, arm: &Arm, tracking: &mut Tracking) -> [f32; 3] {
    let now = yaw(app, arm.links[0]);
    let step = (now - tracking.last_yaw + PI).rem_euclid(TAU) - PI;
    tracking.turned += step;
    tracking.last_yaw = now;
    let (shoulder, elbow, wrist) = joint_angles(reach(tracking.turned));
    let targets = [shoulder, elbow, wrist];
    for (&joint, target) in arm.joints[1..].iter().zip(targets) {
        if let Some(mut joint) = app.world_mut().get_mut::<Joint>(joint)
            && let Some(motor) = joint.motor_mut()
        {
            motor.target_position = Some(target);
        }
    }
    targets
}

/// The turret's heading: the angle of its x axis about z.
fn yaw(app: &App, turret: Entity) -> f32 {
    let x = pose(app, turret).rotation * Vec3::X;
    x.y.atan2(x.x)
}

fn pose(app: &App, e: Entity) -> Isometry {
    let world = app.world();
    let at = world.get::<Position>(e).map_or(Vec3::NAN, |p| p.0);
    let rotation = world.get::<Rotation>(e).map_or(Quat::IDENTITY, |r| r.0);
    Isometry::new(at, rotation)
}
