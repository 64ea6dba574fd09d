//! A joint gallery, recorded to `joints.rrd`:
//!
//! - a **motor-driven arm**: a turret on a hinge about the vertical, driven by a velocity motor,
//!   a boom held level by a position motor, and a forearm whose position motor the game swings
//!   back and forth, batting the crates and balls around it with the torques its motors apply
//!   (nothing about the arm is scripted but the motors' targets);
//! - a **rope bridge** of 30 planks, each tied to the next by two ball joints at its corners and
//!   the ends tied to the world, crossed by a rolling ball;
//! - a **wrecking ball**: a 50 kg ball at the end of a 12-link chain, released sideways into a
//!   stack of boxes;
//! - a **door** on a limited hinge closed by a spring (a position motor), hit by a thrown ball;
//! - a **ragdoll** of capsules with a ball for a head (ball joints with swing cones and twist limits at the neck,
//!   shoulders and hips, limited hinges at the elbows and knees) pushed down a flight of stairs.
//!
//! The recording shows each joint's anchors and axis (orange, red past a limit) and what the
//! first joints hold as time series (`joints/<entity>/force`).
//!
//! ```text
//! cargo run --release --example joints -- --help
//! rerun joints.rrd
//! ```

mod support;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use clap::Parser;
use glam::Vec3;
use std::error::Error;
use support::{RecordingArgs, StepTimer};
use urto::debug::RerunDebugPlugin;
use urto::prelude::*;

/// A joint gallery (motor arm, rope bridge, wrecking ball, door), recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Seconds simulated.
    #[arg(long, default_value_t = 12.0)]
    seconds: f32,
    /// Planks of the rope bridge.
    #[arg(long, default_value_t = 30)]
    planks: u32,
    #[command(flatten)]
    recording: RecordingArgs,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::default())
        .add_plugins(RerunDebugPlugin::new(args.recording.config("joints", 1))?)
        .insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Friction(0.6)));
    let arm = build_arm(&mut app);
    let props = scatter_props(&mut app);
    let (bridge, ball_start) = build_bridge(&mut app, args.planks);
    let wrecking = build_wrecking_ball(&mut app);
    let door = build_door(&mut app);
    let ragdoll = build_ragdoll(&mut app);

    let mut timer = StepTimer::start();
    let steps = (args.seconds * 60.0) as u32;
    let start: Vec<Vec3> = props.iter().map(|&e| position(&app, e)).collect();
    let (mut sag, mut door_swing, mut turret_speed) = (0.0f32, 0.0f32, Vec::new());
    let mut worst_limit = 0.0f32;
    let mut hanging_sag = 0.0;
    let deck_low = |app: &App| {
        let deck = bridge.iter().map(|&p| position(app, p).z);
        BRIDGE_HEIGHT - deck.fold(f32::INFINITY, f32::min)
    };
    for step in 0..steps {
        // The bridge hangs for 4 s, then a 6 kg ball lands on it, rolling across.
        if step == 240 {
            hanging_sag = deck_low(&app);
            let ball = dynamic(&mut app, Collider::sphere(0.25), ball_start, 6.0);
            app.world_mut()
                .entity_mut(ball)
                .insert(Velocity::new(4.5, 0.0, 0.0));
        }
        // The game's only input: the forearm's target swings ±0.9 rad every 3 s.
        let t = step as f32 / 60.0;
        if let Some(mut joint) = app.world_mut().get_mut::<Joint>(arm.forearm_joint)
            && let Some(motor) = joint.motor_mut()
        {
            motor.target_position = Some(0.9 * (t * std::f32::consts::TAU / 3.0).sin());
        }
        urto::step(app.world_mut(), 1)?;
        timer.add(&app);
        if step >= 240 {
            sag = sag.max(deck_low(&app));
        }
        door_swing = door_swing.max(angle_about_z(&app, door).abs());
        worst_limit = worst_limit.max(past_limits(&mut app, &ragdoll.joints));
        if t > 3.0 {
            turret_speed.push(angular_speed_z(&app, arm.turret));
        }
    }

    let batted = props
        .iter()
        .zip(&start)
        .filter(|(e, s)| position(&app, **e).distance(**s) > 0.5)
        .count();
    let mean_speed = turret_speed.iter().sum::<f32>() / turret_speed.len().max(1) as f32;
    let joints = app.world_mut().query::<&Joint>().iter(app.world()).count();
    println!(
        "joints: {joints} joints, {} steps ({:.1} s simulated)",
        app.world().resource::<PhysicsStats>().step,
        args.seconds
    );
    println!(
        "  arm: turret at {mean_speed:.3} rad/s (motor target {TURRET_SPEED}), {batted} of {} props batted more than 0.5 m",
        props.len()
    );
    println!(
        "  bridge: {} planks hanging {:.2} m deep, {:.2} m under the ball",
        args.planks, hanging_sag, sag
    );
    println!(
        "  wrecking ball: chain stretched {:.2} % at the end, {} of {} boxes knocked over",
        chain_stretch(&app, &wrecking) * 100.0,
        knocked(&app, &wrecking.stack),
        wrecking.stack.len()
    );
    println!(
        "  door: swung open {:.0} degrees (limit 100), back to {:.1} degrees",
        door_swing.to_degrees(),
        angle_about_z(&app, door).to_degrees()
    );
    let pelvis = position(&app, ragdoll.torso);
    println!(
        "  ragdoll: {} bodies, {} joints, fell {:.1} m down the stairs; its joints at most {:.1} degrees past a limit",
        ragdoll.bodies,
        ragdoll.joints.len(),
        STAIRS_TOP - pelvis.z,
        worst_limit.to_degrees()
    );
    println!("  {}", timer.summary());
    support::print_recording(&args.recording.path("joints"));
    Ok(())
}

const TURRET_SPEED: f32 = 0.8;
const BRIDGE_HEIGHT: f32 = 2.0;

struct Arm {
    turret: Entity,
    forearm_joint: Entity,
}

fn dynamic(app: &mut App, collider: Collider, at: Vec3, mass: f32) -> Entity {
    app.world_mut()
        .spawn((collider, Position(at), Velocity::default(), Mass(mass)))
        .id()
}

/// Base post → turret (velocity motor about z) → boom (position motor about y, level) →
/// forearm (position motor about z, swung by the game).
fn build_arm(app: &mut App) -> Arm {
    let world = app.world_mut();
    let base = world
        .spawn((
            Collider::cuboid(0.2, 0.2, 0.15),
            Position::new(0.0, 0.0, 0.15),
            Static,
        ))
        .id();
    let turret = dynamic(
        app,
        Collider::cuboid(0.3, 0.3, 0.1),
        Vec3::new(0.0, 0.0, 0.4),
        20.0,
    );
    let boom = dynamic(
        app,
        Collider::cuboid(0.8, 0.08, 0.08),
        Vec3::new(1.1, 0.0, 0.4),
        4.0,
    );
    let forearm = dynamic(
        app,
        Collider::cuboid(0.6, 0.06, 0.12),
        Vec3::new(2.5, 0.0, 0.25),
        3.0,
    );
    let world = app.world_mut();
    world.spawn(
        Joint::revolute(base, turret)
            .with_axis(Vec3::Z)
            .with_anchors(Vec3::new(0.0, 0.0, 0.15), Vec3::new(0.0, 0.0, -0.1))
            .with_motor(JointMotor::velocity(TURRET_SPEED, 4000.0)),
    );
    world.spawn(
        Joint::revolute(turret, boom)
            .with_axis(Vec3::Y)
            .with_anchors(Vec3::new(0.3, 0.0, 0.0), Vec3::new(-0.8, 0.0, 0.0))
            .with_limits(-0.3, 0.3)
            .with_motor(JointMotor::position(0.0, 5.0, 1.0, 2000.0)),
    );
    let forearm_joint = world
        .spawn(
            Joint::revolute(boom, forearm)
                .with_axis(Vec3::Z)
                .with_anchors(Vec3::new(0.8, 0.0, -0.05), Vec3::new(-0.6, 0.0, 0.1))
                .with_limits(-1.2, 1.2)
                .with_motor(JointMotor::position(0.0, 3.0, 1.0, 600.0)),
        )
        .id();
    Arm {
        turret,
        forearm_joint,
    }
}

/// Crates and balls in a ring the arm sweeps through.
fn scatter_props(app: &mut App) -> Vec<Entity> {
    (0..10)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / 10.0 + 0.3;
            let r = 2.3 + 0.5 * (i % 2) as f32;
            let at = Vec3::new(r * a.cos(), r * a.sin(), 0.25);
            let collider = if i % 3 == 0 {
                Collider::sphere(0.25)
            } else {
                Collider::cuboid(0.25, 0.25, 0.25)
            };
            let e = dynamic(app, collider, at, 1.0);
            app.world_mut().entity_mut(e).insert(Friction(0.5));
            e
        })
        .collect()
}

/// Planks along x at y = 8, each tied to the next by ball joints at both corners, the ends tied
/// to the world 8 % closer than the deck is long (a rope bridge hangs slack); returns the deck
/// and where the ball is dropped onto it.
fn build_bridge(app: &mut App, planks: u32) -> (Vec<Entity>, Vec3) {
    let (half, width, gap) = (0.1f32, 0.5f32, 0.02f32);
    let pitch = 2.0 * half + gap;
    let span = pitch * planks as f32;
    let x0 = -0.5 * span + 0.5 * pitch;
    let y = 8.0;
    let mut deck = Vec::new();
    for i in 0..planks {
        let at = Vec3::new(x0 + pitch * i as f32, y, BRIDGE_HEIGHT);
        deck.push(dynamic(app, Collider::cuboid(half, width, 0.03), at, 2.0));
    }
    let corner = |x: f32, side: f32| Vec3::new(x, side * (width - 0.05), 0.0);
    let world = app.world_mut();
    for side in [-1.0, 1.0] {
        for pair in deck.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            world.spawn(Joint::spherical(a, b).with_anchors(
                corner(half + 0.5 * gap, side),
                corner(-half - 0.5 * gap, side),
            ));
        }
        let ends = [
            (deck[0], -half - 0.5 * gap, -0.46 * span),
            (deck[deck.len() - 1], half + 0.5 * gap, 0.46 * span),
        ];
        for (plank, local_x, world_x) in ends {
            let fixed = Vec3::new(world_x, y + side * (width - 0.05), BRIDGE_HEIGHT);
            world.spawn(
                Joint::spherical(plank, JointEnd::World).with_anchors(corner(local_x, side), fixed),
            );
        }
    }
    (deck, Vec3::new(-0.4 * span, y, BRIDGE_HEIGHT + 0.3))
}

struct Wrecking {
    ball: Entity,
    top: Vec3,
    rest: f32,
    stack: Vec<(Entity, Vec3)>,
}

/// A 50 kg ball at the end of 12 chain links hung from the world at y = −6, released from the
/// side into a stack of boxes.
fn build_wrecking_ball(app: &mut App) -> Wrecking {
    let (half, gap, n) = (0.15f32, 0.02f32, 12);
    let pitch = 2.0 * half + gap;
    let top = Vec3::new(0.0, -6.0, 6.0);
    let direction = Vec3::new(-1.0, 0.0, 0.0);
    let rotation = glam::Quat::from_rotation_arc(Vec3::NEG_Z, direction);
    let mut previous = (JointEnd::World, top);
    let end = Vec3::new(0.0, 0.0, half + 0.5 * gap);
    for i in 0..n {
        let at = top + direction * pitch * (i as f32 + 0.5);
        let link = dynamic(app, Collider::cuboid(0.04, 0.04, half), at, 1.0);
        app.world_mut().entity_mut(link).insert(Rotation(rotation));
        app.world_mut()
            .spawn(Joint::spherical(link, previous.0).with_anchors(end, previous.1));
        previous = (JointEnd::Body(link), -end);
    }
    let ball_at = top + direction * (pitch * n as f32 + 0.5);
    let ball = dynamic(app, Collider::sphere(0.5), ball_at, 50.0);
    app.world_mut().spawn(
        Joint::spherical(ball, previous.0).with_anchors(Vec3::new(0.5, 0.0, 0.0), previous.1),
    );
    let mut stack = Vec::new();
    for level in 0..3 {
        for k in 0..(3 - level) {
            let at = Vec3::new(
                0.6,
                -6.0 + (k as f32 - 0.5 * (2 - level) as f32) * 0.62,
                0.3 + 0.6 * level as f32,
            );
            stack.push((dynamic(app, Collider::cuboid(0.3, 0.3, 0.3), at, 3.0), at));
        }
    }
    let rest = pitch * n as f32;
    Wrecking {
        ball,
        top,
        rest,
        stack,
    }
}

/// A door hinged about z at its left edge, limited to ±100°, closed by a spring, and a ball
/// thrown at its free end.
fn build_door(app: &mut App) -> Entity {
    let frame = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.05, 0.05, 1.0),
            Position::new(-6.0, 3.0, 1.0),
            Static,
        ))
        .id();
    let door = dynamic(
        app,
        Collider::cuboid(0.5, 0.04, 0.9),
        Vec3::new(-5.45, 3.0, 1.0),
        8.0,
    );
    app.world_mut().spawn(
        Joint::revolute(frame, door)
            .with_axis(Vec3::Z)
            .with_anchors(Vec3::new(0.05, 0.0, 0.0), Vec3::new(-0.5, 0.0, 0.0))
            .with_limits(-1.75, 1.75)
            .with_motor(JointMotor::position(0.0, 1.0, 0.7, 200.0)),
    );
    let ball = dynamic(app, Collider::sphere(0.2), Vec3::new(-5.1, 6.0, 1.0), 3.0);
    app.world_mut()
        .entity_mut(ball)
        .insert(Velocity::new(0.0, -8.0, 2.0));
    door
}

fn position(app: &App, e: Entity) -> Vec3 {
    app.world().get::<Position>(e).map_or(Vec3::ZERO, |p| p.0)
}

fn angle_about_z(app: &App, e: Entity) -> f32 {
    let r = app
        .world()
        .get::<Rotation>(e)
        .map_or(glam::Quat::IDENTITY, |r| r.0);
    let x = r * Vec3::X;
    x.y.atan2(x.x)
}

fn angular_speed_z(app: &App, e: Entity) -> f32 {
    app.world().get::<AngularVelocity>(e).map_or(0.0, |w| w.0.z)
}

/// How much longer than its links the chain hangs, from its top to the ball's anchor (the
/// chain is straight under the ball's weight).
fn chain_stretch(app: &App, w: &Wrecking) -> f32 {
    let ball = w.ball;
    let r = app
        .world()
        .get::<Rotation>(ball)
        .map_or(glam::Quat::IDENTITY, |r| r.0);
    let anchor = position(app, ball) + r * Vec3::new(0.5, 0.0, 0.0);
    (anchor - w.top).length() / w.rest - 1.0
}

fn knocked(app: &App, stack: &[(Entity, Vec3)]) -> usize {
    stack
        .iter()
        .filter(|(e, at)| position(app, *e).distance(*at) > 0.3)
        .count()
}

const STAIRS_TOP: f32 = 2.4;

struct Ragdoll {
    torso: Entity,
    bodies: usize,
    joints: Vec<Entity>,
}

/// Eight steps 0.3 m high and 0.5 m deep going down along +x at y = −12, and a ragdoll of
/// capsules (a ball for a head) standing at the top, pushed forward.
fn build_ragdoll(app: &mut App) -> Ragdoll {
    let y = -12.0;
    for k in 0..8 {
        let top = STAIRS_TOP - 0.3 * k as f32;
        let at = Vec3::new(8.0 + 0.5 * k as f32, y, 0.5 * top);
        app.world_mut().spawn((
            Collider::cuboid(0.25, 1.0, 0.5 * top),
            Position(at),
            Static,
            Friction(0.6),
        ));
    }
    let z = STAIRS_TOP + 0.02;
    let x = 8.15;
    let mut part = |collider: Collider, at: Vec3, mass: f32| {
        let e = dynamic(app, collider, at, mass);
        app.world_mut().entity_mut(e).insert(Friction(0.6));
        e
    };
    // A limb standing along z, `half` tall from its centre, as a capsule.
    let limb = |half: f32, radius: f32| Collider::capsule(half - radius, radius);
    // Standing: shins, thighs, torso, head; arms hanging at the sides.
    let torso = part(limb(0.25, 0.15), Vec3::new(x, y, z + 1.05), 15.0);
    let head = part(Collider::sphere(0.11), Vec3::new(x, y, z + 1.45), 4.0);
    let mut limbs = Vec::new();
    for side in [-1.0f32, 1.0] {
        let upper_arm = part(
            limb(0.15, 0.05),
            Vec3::new(x, y + side * 0.25, z + 1.13),
            2.0,
        );
        let forearm = part(
            limb(0.14, 0.045),
            Vec3::new(x, y + side * 0.25, z + 0.83),
            1.5,
        );
        let thigh = part(limb(0.2, 0.07), Vec3::new(x, y + side * 0.1, z + 0.6), 6.0);
        let shin = part(
            limb(0.19, 0.06),
            Vec3::new(x, y + side * 0.1, z + 0.19),
            4.0,
        );
        limbs.push((side, upper_arm, forearm, thigh, shin));
    }
    let down = Vec3::NEG_Z;
    let world = app.world_mut();
    let mut joints = vec![
        world
            .spawn(
                Joint::spherical(torso, head)
                    .with_axis(Vec3::Z)
                    .with_anchors(Vec3::new(0.0, 0.0, 0.27), Vec3::new(0.0, 0.0, -0.13))
                    .with_swing_limit(0.6)
                    .with_limits(-0.6, 0.6),
            )
            .id(),
    ];
    for (side, upper_arm, forearm, thigh, shin) in limbs {
        let shoulder = Joint::spherical(torso, upper_arm)
            .with_axis(down)
            .with_anchors(Vec3::new(0.0, side * 0.25, 0.23), Vec3::new(0.0, 0.0, 0.15))
            .with_swing_limit(1.5)
            .with_limits(-0.8, 0.8);
        let elbow = Joint::revolute(upper_arm, forearm)
            .with_axis(Vec3::Y)
            .with_anchors(Vec3::new(0.0, 0.0, -0.16), Vec3::new(0.0, 0.0, 0.15))
            .with_limits(-2.4, 0.0);
        let hip = Joint::spherical(torso, thigh)
            .with_axis(down)
            .with_anchors(Vec3::new(0.0, side * 0.1, -0.26), Vec3::new(0.0, 0.0, 0.2))
            .with_swing_limit(1.2)
            .with_limits(-0.5, 0.5);
        let knee = Joint::revolute(thigh, shin)
            .with_axis(Vec3::Y)
            .with_anchors(Vec3::new(0.0, 0.0, -0.205), Vec3::new(0.0, 0.0, 0.195))
            .with_limits(0.0, 2.4);
        for joint in [shoulder, elbow, hip, knee] {
            joints.push(world.spawn(joint).id());
        }
    }
    world.entity_mut(torso).insert(Velocity::new(4.0, 0.0, 0.0));
    Ragdoll {
        torso,
        bodies: 10,
        joints,
    }
}

/// The worst of `joints`' distances past their limits (rad or m).
fn past_limits(app: &mut App, joints: &[Entity]) -> f32 {
    let pose = |app: &App, e: Entity| {
        let p = position(app, e);
        let r = app
            .world()
            .get::<Rotation>(e)
            .map_or(glam::Quat::IDENTITY, |r| r.0);
        urto::geometry::Isometry::new(p, r)
    };
    joints
        .iter()
        .filter_map(|&j| app.world().get::<Joint>(j).copied())
        .map(|joint| {
            let b = joint.body_b_entity().map(|b| pose(app, b));
            let (a, b) = joint.world_frames(pose(app, joint.body_a), b);
            joint.past_limit(&a, &b)
        })
        .fold(0.0, f32::max)
}
