//! The robot arm: an articulated arm (base → shoulder → upper arm → elbow → forearm → wrist →
//! gripper → two fingers, with a counterweight and a camera on the side) stands in the middle
//! of a workbench and sweeps round and round, clearing crates, balls and a tray of bottles off
//! the bench.
//!
//! The arm is one compound body: every link is a child (bevy's `ChildOf`) of the link it hangs
//! from, with a collider and a local `Position`/`Rotation`, and the game moves it only by turning
//! the joints' local rotations (a scripted sweep with a little inverse kinematics). The scene
//! graph *is* the bounding-volume hierarchy (the slides' "Conclusioni"): each link's volume
//! bounds its own collider and everything further down the arm, so the broad phase sees one box
//! for the whole arm, and the narrow phase descends it only where the other side's volume
//! overlaps, always splitting the larger of the two volumes first. A ball near the gripper is
//! tested against the gripper, not against the eleven colliders of the arm.
//!
//! The recording shows the volumes level by level (one tab per depth of the scene graph) and, in
//! the main view, which nodes the descent entered (yellow) or pruned (grey) and the collider
//! pairs it handed to the exact test (red segments).
//!
//! The base is kinematic (`Mass::INFINITE`): contacts push the obstacles, never the arm. A link
//! hits with the velocity its turning joints give the point of contact (how the link moved
//! relative to the base this step, `StepStartPose`), so it bats what it meets; bodies only
//! translate (urto has no angular dynamics), and what leaves the bench's edge falls to the floor.
//! A crate pushed along keeps bumping into the link that chases it, so hits count every bump.
//!
//! ```text
//! cargo run --release --example robot_arm -- --help
//! rerun robot_arm.rrd
//! ```

mod support;

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
use urto::plugins::narrow_phase::HierarchyVisits;
use urto::plugins::{BroadPhasePairs, Contacts};
use urto::prelude::*;

/// A robot arm clearing a workbench, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Crates on the bench.
    #[arg(long, default_value_t = 8)]
    crates: u32,
    /// Balls on the bench.
    #[arg(long, default_value_t = 8)]
    balls: u32,
    /// Physics steps (60 per simulated second). The arm turns once every 10 s; by default the
    /// run stops during the third turn, as the arm sweeps the far end of the bench.
    #[arg(long, default_value_t = 1650)]
    steps: u32,
    /// Depths of the scene graph shown, one tab each.
    #[arg(long, default_value_t = 6)]
    levels: u32,
    #[command(flatten)]
    recording: support::RecordingArgs,
}

/// Height of the bench's top (m) and half its length and width.
const BENCH_TOP: f32 = 0.8;
const BENCH: Vec2 = Vec2::new(2.6, 0.65);
/// Shoulder height above the bench, and the lengths of the upper arm and forearm.
const SHOULDER: f32 = 0.45;
const UPPER: f32 = 1.1;
const FORE: f32 = 1.0;
const GRIPPER: f32 = 0.22;
/// The wrist's height above the bench while sweeping: the gripper skims the obstacles' tops.
const SKIM: f32 = 0.18;
/// Radians per second of the sweep, and the wrist's reach on successive turns.
const TURN_RATE: f32 = TAU / 10.0;
const REACHES: [f32; 3] = [0.95, 1.4, 1.85];

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
    let mut slab = |half: Vec3, at: Vec3, color: [u8; 3]| {
        let body = (Collider::cuboid(half.x, half.y, half.z), Position(at));
        world.spawn((body, Static, DebugColor(color)));
    };
    // The floor is a slab rather than a half-space: an unbounded volume overlaps every node of
    // the arm, and the descent could prune nothing against it.
    slab(Vec3::new(3.4, 2.4, 0.05), Vec3::Z * -0.05, [210, 215, 218]);
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

/// The arm's root and the joints the game turns (shoulder, elbow, wrist).
struct Arm {
    base: Entity,
    joints: [Entity; 3],
    colliders: usize,
    /// Depths of its scene graph.
    levels: usize,
}

/// Indices of the shoulder, elbow and wrist in [`PARTS`].
const JOINTS: [usize; 3] = [1, 4, 6];

/// The links below the base: name, parent (index in this list, the base being 0), half extents
/// of its box (one number: radius of a ball) and position in the parent's frame. A link box is
/// centred half its length from its joint (a collider sits at its entity's origin), and the next
/// joint half a length further on. The counterweight and the camera are side branches, which the
/// descent prunes when the trouble is at the gripper.
const PARTS: [(&str, usize, &[f32], [f32; 3]); 10] = [
    ("shoulder", 0, &[0.16], [0.0, 0.0, SHOULDER - 0.16]),
    ("upper arm", 1, &[0.45, 0.08, 0.08], [UPPER / 2.0, 0.0, 0.0]),
    ("counterweight", 1, &[0.1, 0.13, 0.1], [-0.3, 0.0, 0.0]),
    ("elbow", 2, &[0.11], [UPPER / 2.0, 0.0, 0.0]),
    ("forearm", 4, &[0.4, 0.065, 0.065], [FORE / 2.0, 0.0, 0.0]),
    ("wrist", 5, &[0.08], [FORE / 2.0, 0.0, 0.0]),
    ("gripper", 6, &[0.07, 0.12, 0.05], [GRIPPER / 2.0, 0.0, 0.0]),
    ("camera", 6, &[0.05, 0.04, 0.03], [0.0, 0.0, 0.11]),
    ("finger L", 7, &[0.08, 0.02, 0.04], [0.15, 0.09, -0.02]),
    ("finger R", 7, &[0.08, 0.02, 0.04], [0.15, -0.09, -0.02]),
];

/// The arm: a kinematic base bolted (1 cm clear) on the bench, and its links, each a child of
/// the one it hangs from.
fn spawn_arm(app: &mut App) -> Arm {
    let world = app.world_mut();
    let base = world
        .spawn((
            Collider::cuboid(0.3, 0.3, 0.16),
            Position::new(0.0, 0.0, BENCH_TOP + 0.17),
            Velocity::default(),
            Mass::INFINITE,
            DebugColor(JOINT),
            Name::new("base"),
        ))
        .id();
    let (mut entities, mut depth) = (vec![base], vec![0]);
    for (name, parent, size, at) in PARTS {
        let (collider, color) = match size {
            &[r] => (Collider::sphere(r), JOINT),
            _ => (Collider::cuboid(size[0], size[1], size[2]), ARM),
        };
        let part = (
            collider,
            Position(Vec3::from(at)),
            ChildOf(entities[parent]),
        );
        entities.push(world.spawn((part, DebugColor(color), Name::new(name))).id());
        depth.push(depth[parent] + 1);
    }
    Arm {
        base,
        joints: JOINTS.map(|j| entities[j]),
        colliders: entities.len(),
        levels: depth.iter().max().map_or(1, |d| d + 1),
    }
}

/// Where the script wants the wrist at time `t`: the arm turns steadily, starting pointed off
/// the bench's side (+y), and reaches further on each turn; the reach changes while the arm
/// points off the bench, so each turn sweeps one ring of it clean.
fn script(t: f32) -> (f32, f32) {
    let turned = TURN_RATE * t;
    let turn = (turned / TAU) as usize;
    let into = turned / TAU - turn as f32;
    let from = REACHES[turn.min(REACHES.len() - 1)];
    let to = REACHES[(turn + 1).min(REACHES.len() - 1)];
    let blend = ((into - 0.9) / 0.1).clamp(0.0, 1.0);
    let reach = from + (to - from) * blend * blend * (3.0 - 2.0 * blend);
    (PI / 2.0 + turned, reach)
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

/// Sets the joints' local rotations for time `t` (the only thing the game moves).
fn pose_arm(app: &mut App, arm: &Arm, t: f32) {
    let (yaw, reach) = script(t);
    let (shoulder, elbow, wrist) = joint_angles(reach);
    // A rotation about local y by -a raises the link's x axis by a.
    let pitch = |a: f32| Quat::from_rotation_y(-a);
    let world = app.world_mut();
    let rotations = [
        Quat::from_rotation_z(yaw) * pitch(shoulder),
        pitch(elbow),
        pitch(wrist),
    ];
    for (joint, r) in arm.joints.into_iter().zip(rotations) {
        if let Some(mut rotation) = world.get_mut::<Rotation>(joint) {
            rotation.0 = r;
        }
    }
}

/// The descent's work, summed over steps (each measured in the step's last substep, which the
/// visits and the broad-phase pairs describe).
#[derive(Default)]
struct Work {
    /// Broad-phase pairs involving a compound (the arm or the tray).
    compound_pairs: u64,
    entered: u64,
    pruned: u64,
    collider_pairs: u64,
    /// What testing every collider of one side against every collider of the other would cost.
    all_pairs: u64,
    peak_collider_pairs: usize,
    /// Per step over both substeps, from the physics counters.
    bv_tests: f64,
    steps: u64,
}

impl Work {
    fn add(&mut self, app: &App, colliders: &BTreeMap<Entity, u64>) {
        let world = app.world();
        let visits = world.resource::<HierarchyVisits>();
        let count = |e: &Entity| colliders.get(e).copied();
        for (a, b) in &world.resource::<BroadPhasePairs>().pairs {
            if count(a).is_some() || count(b).is_some() {
                self.compound_pairs += 1;
                self.all_pairs += count(a).unwrap_or(1) * count(b).unwrap_or(1);
            }
        }
        self.entered += visits.entered.len() as u64;
        self.pruned += visits.pruned.len() as u64;
        self.collider_pairs += visits.collider_pairs.len() as u64;
        self.peak_collider_pairs = self.peak_collider_pairs.max(visits.collider_pairs.len());
        let stats = world.resource::<PhysicsStats>();
        self.bv_tests += stats.counter("hierarchy/bv_tests").unwrap_or(0.0);
        self.steps += 1;
    }

    fn per_step(&self, total: u64) -> f64 {
        total as f64 / self.steps.max(1) as f64
    }
}

/// The link of the arm that first touched each body, noted in every substep (a graze can
/// begin and end within one step).
#[derive(Resource)]
struct FirstTouches {
    arm: Entity,
    links: BTreeMap<Entity, Entity>,
}

/// Notes, from this substep's contacts, which link touched what (game code in the substep
/// schedule, after the narrow phase).
fn note_touches(contacts: Res<Contacts>, mut touches: ResMut<FirstTouches>) {
    for c in &contacts.pairs {
        let (other, link) = match (c.a, c.b) {
            (a, b) if a == touches.arm => (b, c.collider_a),
            (a, b) if b == touches.arm => (a, c.collider_b),
            _ => continue,
        };
        touches.links.entry(other).or_insert(link);
    }
}

/// What happened during the run.
struct Report {
    /// Times an obstacle started touching the arm.
    hits: u32,
    /// Where the obstacles and the arm's base started.
    starts: Vec<Vec3>,
    base_start: Vec3,
    work: Work,
    timer: StepTimer,
}

/// Runs the simulation, posing the arm before each step and counting the arm's hits.
fn run(
    app: &mut App,
    args: &Args,
    arm: &Arm,
    obstacles: &[Entity],
) -> Result<Report, Box<dyn Error>> {
    app.insert_resource(FirstTouches {
        arm: arm.base,
        links: BTreeMap::new(),
    })
    .add_systems(SubstepSchedule, note_touches.after(SubstepSet::NarrowPhase));
    let colliders = BTreeMap::from([(arm.base, arm.colliders as u64), (obstacles[0], 4)]);
    let mut collisions = Collisions::new(app);
    let mut report = Report {
        hits: 0,
        starts: obstacles.iter().map(|&e| position(app, e)).collect(),
        base_start: position(app, arm.base),
        work: Work::default(),
        timer: StepTimer::start(),
    };
    for step in 0..args.steps {
        pose_arm(app, arm, step as f32 / 60.0);
        urto::step(app.world_mut(), 1)?;
        report.timer.add(app);
        let with_arm = |&(a, b): &(Entity, Entity)| {
            (a == arm.base && obstacles.contains(&b)) || (b == arm.base && obstacles.contains(&a))
        };
        report.hits += collisions.read(app).iter().filter(|p| with_arm(p)).count() as u32;
        report.work.add(app, &colliders);
    }
    Ok(report)
}

fn position(app: &App, e: Entity) -> Vec3 {
    app.world().get::<Position>(e).map_or(Vec3::NAN, |p| p.0)
}

impl Report {
    fn print(&self, app: &App, args: &Args, arm: &Arm, obstacles: &[Entity]) {
        let world = app.world();
        let stats = world.resource::<PhysicsStats>();
        println!(
            "robot_arm: an arm of {} colliders (scene graph {} levels deep) clearing a bench of {} obstacles (crates, balls, a tray of 3 bottles); {} steps ({:.0} s simulated, {:.1} turns)",
            arm.colliders,
            arm.levels,
            obstacles.len(),
            stats.step,
            stats.sim_time,
            TURN_RATE * stats.sim_time as f32 / TAU
        );
        let ends: Vec<Vec3> = obstacles.iter().map(|&e| position(app, e)).collect();
        let off = ends.iter().filter(|p| p.z < BENCH_TOP - 0.05).count();
        let moved = ends.iter().zip(&self.starts);
        let pushed = moved
            .filter(|(p, s)| p.z >= BENCH_TOP - 0.05 && p.distance(**s) > 0.1)
            .count();
        let links = &world.resource::<FirstTouches>().links;
        let (touched, scenery): (Vec<_>, Vec<_>) =
            links.iter().partition(|(o, _)| obstacles.contains(o));
        let mut by_link: BTreeMap<&str, u32> = BTreeMap::new();
        for &(_, &link) in &touched {
            let name = world.get::<Name>(link).map_or("?", |n| n.as_str());
            *by_link.entry(name).or_default() += 1;
        }
        let by_link: Vec<String> = by_link.iter().map(|(l, n)| format!("{l} {n}")).collect();
        println!(
            "  the arm touched {} of {} obstacles ({} hits; first touched by: {}); {off} knocked off the bench, {pushed} pushed along it, {} left in place",
            touched.len(),
            obstacles.len(),
            self.hits,
            by_link.join(", "),
            obstacles.len() - off - pushed,
        );
        println!(
            "  the kinematic base moved {:.4} m (contacts push the obstacles, never the arm); the arm touched {} pieces of bench or floor",
            position(app, arm.base).distance(self.base_start),
            scenery.len()
        );
        let w = &self.work;
        println!(
            "  scene-graph descent, per step (its last substep): {:.1} broad-phase pairs with a compound; entered {:.1} nodes, pruned {:.1}, {:.2} collider pairs to the exact test (peak {}) instead of {:.1} for every collider against every collider; {:.1} volume tests per step (both substeps)",
            w.per_step(w.compound_pairs),
            w.per_step(w.entered),
            w.per_step(w.pruned),
            w.per_step(w.collider_pairs),
            w.peak_collider_pairs,
            w.per_step(w.all_pairs),
            w.bv_tests / w.steps.max(1) as f64,
        );
        println!("  {}", self.timer.summary());
        support::print_recording(&args.recording.path("robot_arm"));
    }
}
