//! Whole-step peer benchmark: urto against rapier3d on the same scenes, in the same run.
//!
//! Every scene is described once ([`Scene`]: balls with a position and a velocity, static planes,
//! gravity, friction, restitution) and built from that description in both engines, so both start
//! from the same state. Both step at dt = 1/60 with gravity 9.81 m/s² down Z where there is
//! gravity. urto runs its defaults (the rigid-body solver: one collision detection per step, 4
//! soft substeps; sleeping by islands); rapier runs its defaults (4 solver iterations, no
//! `parallel` feature: single-threaded like urto). Bodies turn in both engines (rotations
//! unlocked); friction and restitution are equal on every collider in both engines (the pair
//! values are then equal too, whatever the combine rule); every ball has a mass of 1 kg in both.
//!
//! Scenes (see `peers/README.md` for the numbers), each with its static planes built two ways in
//! both engines: `half_spaces` (urto `Collider::half_space`, rapier `SharedShape::halfspace`;
//! unbounded, so both engines pair every ball with every plane) and `slabs` (a 1 m thick box
//! behind each face: urto `Collider::cuboid`, rapier `SharedShape::cuboid`).
//! - `resting_*`: N = 1,000 and 10,000 balls on a ground, apart on a grid; time per step after
//!   120 settling steps. Each engine with and without sleeping (both on by default; off: urto
//!   `SleepSettings { enabled: false, .. }`, rapier `can_sleep(false)`).
//! - `falling_pile_*`: 1,000 balls dropped in a grid, with small random horizontal velocities,
//!   into an open box (a ground and four walls); one criterion iteration is the first 300 steps
//!   of a fresh scene (the build is not timed), so divide by 300 for a step. Each engine with and
//!   without sleeping.
//! - `sparse_movers_*`: 10,000 balls flying with random velocities, no gravity, elastic and
//!   frictionless, in a big closed box; time per step after 300 steps.
//!
//! Once per scene a sanity line per engine goes to stderr (mean height, deepest penetration,
//! centres through a plane, speeds, touching pairs, sleeping bodies), so that the reader sees that
//! both engines solved a comparable problem, and urto's own stage times.
//!
//! Run (from `peers/`, about 4 minutes after the build):
//! `cargo bench --bench whole_step 2> sanity.txt`
//! Filter with criterion's usual argument (`cargo bench --bench whole_step -- resting`) and the
//! wall kind with `PEERS_WALLS=half_spaces` or `PEERS_WALLS=slabs` (default: both).

use bevy_app::App;
use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use glam::Vec3;
use rapier3d::prelude as rp;
use std::time::Duration;
use urto::plugins::Contacts;
use urto::prelude::*;

#[path = "common/fresh_runs.rs"]
mod fresh_runs;
use fresh_runs::timed;
#[path = "common/rapier_world.rs"]
mod rapier_world;
use rapier_world::{RapierWorld, rv};

#[path = "common/whole_step_scenes.rs"]
mod whole_step_scenes;
use whole_step_scenes::*;

/// urto with `UrtoPlugins` defaults (60 Hz, the rigid-body solver), the scene's friction and
/// restitution as the contact defaults (every collider then has them), sleeping on (the
/// default) or off.
fn urto_app(scene: &Scene, can_sleep: bool) -> (App, Vec<bevy_ecs::entity::Entity>) {
    let mut app = App::new();
    let timestep = urto::PhysicsTimestep::new(DT, 1).expect("valid timestep");
    app.add_plugins(UrtoPlugins::with_timestep(timestep));
    app.insert_resource(SleepSettings {
        enabled: can_sleep,
        ..Default::default()
    });
    app.insert_resource(ContactSettings {
        default_restitution: scene.restitution,
        default_friction: scene.friction,
        ..Default::default()
    });
    if scene.gravity != Vec3::ZERO {
        app.insert_resource(Gravity::new(scene.gravity).expect("finite gravity"));
    }
    let world = app.world_mut();
    for p in &scene.planes {
        match scene.walls {
            Walls::HalfSpaces => {
                world.spawn((Collider::half_space(p.normal), Position(p.point), Static));
            }
            Walls::Slabs => {
                let (centre, half) = p.slab();
                world.spawn((
                    Collider::cuboid(half.x, half.y, half.z),
                    Position(centre),
                    Static,
                ));
            }
        }
    }
    let balls = scene
        .balls
        .iter()
        .map(|b| {
            world
                .spawn((
                    Collider::sphere(RADIUS),
                    Position(b.pos),
                    Velocity(b.vel),
                    Mass(1.0),
                ))
                .id()
        })
        .collect();
    (app, balls)
}

fn urto_step(app: &mut App, n: u32) {
    urto::step(app.world_mut(), n).expect("UrtoPlugins added");
}

/// Positions and velocities of the balls, and the touching pairs of the last step.
fn urto_state(app: &App, balls: &[bevy_ecs::entity::Entity]) -> (Vec<Ball>, usize, usize) {
    let world = app.world();
    let state = balls
        .iter()
        .map(|&e| Ball {
            pos: world.get::<Position>(e).expect("ball").0,
            vel: world.get::<Velocity>(e).expect("ball").0,
        })
        .collect();
    let sleeping = balls
        .iter()
        .filter(|&&e| world.get::<Sleeping>(e).is_some())
        .count();
    // Pairs touching, asleep ones included (sleeping pairs are not in `Contacts`: untested).
    let touching = world
        .resource::<PhysicsStats>()
        .counter("collisions/touching_pairs")
        .map_or(world.resource::<Contacts>().pairs.len(), |n| n as usize);
    (state, touching, sleeping)
}

/// Steps `n` times and returns urto's own per-stage times averaged over those steps (µs), for
/// the sanity line.
fn urto_step_staged(app: &mut App, n: u32) -> String {
    let stages: Vec<Stage> = Stage::ALL
        .into_iter()
        .filter(|s| *s != Stage::Debug)
        .collect();
    let mut sum = vec![0.0f64; stages.len()];
    for _ in 0..n {
        urto_step(app, 1);
        let stats = app.world().resource::<PhysicsStats>();
        for (acc, s) in sum.iter_mut().zip(&stages) {
            *acc += stats.stage_time(*s).as_secs_f64();
        }
    }
    stages
        .iter()
        .zip(&sum)
        .map(|(s, t)| format!("{} {:.0}", s.name(), t / f64::from(n.max(1)) * 1e6))
        .collect::<Vec<_>>()
        .join(", ")
}

// ---------------------------------------------------------------- rapier

fn gv(v: rp::Vector) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// rapier's usual structures, stepped with `PhysicsPipeline::step`.
struct Rapier {
    world: RapierWorld,
    balls: Vec<rp::RigidBodyHandle>,
}

impl Rapier {
    /// The scene with rapier's default parameters (dt = 1/60, 4 solver iterations); rotations
    /// free; `can_sleep` on (rapier's default) or off.
    fn new(scene: &Scene, can_sleep: bool) -> Self {
        let mut world = RapierWorld::new(rv(scene.gravity), DT);
        for p in &scene.planes {
            let (at, shape) = match scene.walls {
                Walls::HalfSpaces => (p.point, rp::SharedShape::halfspace(rv(p.normal))),
                Walls::Slabs => {
                    let (centre, half) = p.slab();
                    (centre, rp::SharedShape::cuboid(half.x, half.y, half.z))
                }
            };
            let c = rp::ColliderBuilder::new(shape)
                .friction(scene.friction)
                .restitution(scene.restitution);
            world.add(rp::RigidBodyBuilder::fixed().translation(rv(at)), c);
        }
        let balls = scene
            .balls
            .iter()
            .map(|b| {
                let body = rp::RigidBodyBuilder::dynamic()
                    .translation(rv(b.pos))
                    .linvel(rv(b.vel))
                    .can_sleep(can_sleep);
                let c = rp::ColliderBuilder::ball(RADIUS)
                    .mass(1.0)
                    .friction(scene.friction)
                    .restitution(scene.restitution);
                world.add(body, c)
            })
            .collect();
        Self { world, balls }
    }

    fn step(&mut self, n: u32) {
        self.world.step(n);
    }

    /// Positions and velocities, touching pairs (pairs with an active solver contact), sleeping
    /// balls.
    fn state(&self) -> (Vec<Ball>, usize, usize) {
        let mut sleeping = 0;
        let state = self
            .balls
            .iter()
            .map(|&h| {
                let b = &self.world.bodies[h];
                sleeping += usize::from(b.is_sleeping());
                Ball {
                    pos: gv(b.translation()),
                    vel: gv(b.linvel()),
                }
            })
            .collect();
        let touching = self
            .world
            .narrow_phase
            .contact_pairs()
            .filter(|p| p.has_any_active_contact())
            .count();
        (state, touching, sleeping)
    }
}

// ---------------------------------------------------------------- sanity

/// One line of what a state looks like: mean and lowest height, how deep the deepest ball sinks
/// into a plane, how many centres went through a plane, speeds, touching pairs, sleeping balls.
fn sanity(
    scene_name: &str,
    engine: &str,
    scene: &Scene,
    steps: u32,
    (balls, touching, sleeping): (Vec<Ball>, usize, usize),
) {
    let n = balls.len() as f32;
    let mean_z = balls.iter().map(|b| b.pos.z).sum::<f32>() / n;
    let min_z = balls.iter().map(|b| b.pos.z).fold(f32::INFINITY, f32::min);
    let mut deepest = 0.0f32;
    let mut through = 0;
    for b in &balls {
        let d = scene
            .planes
            .iter()
            .map(|p| (b.pos - p.point).dot(p.normal))
            .fold(f32::INFINITY, f32::min);
        deepest = deepest.max(RADIUS - d);
        through += usize::from(d < 0.0);
    }
    let mean_speed = balls.iter().map(|b| b.vel.length()).sum::<f32>() / n;
    let max_speed = balls.iter().map(|b| b.vel.length()).fold(0.0, f32::max);
    let moving = balls.iter().filter(|b| b.vel.length() > 0.05).count();
    eprintln!(
        "[sanity] {scene_name:<28} {engine:<17} after {steps:>3} steps: mean z {mean_z:7.3} m, \
         min z {min_z:6.3} m, deepest penetration {:6.1} mm, centres through a plane {through}, \
         mean speed {mean_speed:6.3} m/s, max speed {max_speed:6.3} m/s, moving > 5 cm/s \
         {moving}, touching pairs {touching}, sleeping {sleeping}",
        deepest * 1000.0
    );
}

fn initial_speed(scene: &Scene) -> f32 {
    scene.balls.iter().map(|b| b.vel.length()).sum::<f32>() / scene.balls.len() as f32
}

// ---------------------------------------------------------------- benches

/// The rapier variants of a scene: `(label, can_sleep)`.
const RAPIER_SLEEP_VARIANTS: [(&str, bool); 2] = [("rapier", true), ("rapier (no sleep)", false)];

/// The urto variants of a scene: `(label, can_sleep)`.
const URTO_SLEEP_VARIANTS: [(&str, bool); 2] = [("urto", true), ("urto (no sleep)", false)];

/// The wall kinds to run: `PEERS_WALLS` = `half_spaces`, `slabs` or `both` (default).
fn wall_kinds() -> Vec<Walls> {
    match std::env::var("PEERS_WALLS").as_deref() {
        Ok("half_spaces") => vec![Walls::HalfSpaces],
        Ok("slabs") => vec![Walls::Slabs],
        _ => vec![Walls::HalfSpaces, Walls::Slabs],
    }
}

fn walls_name(w: Walls) -> &'static str {
    match w {
        Walls::HalfSpaces => "half_spaces",
        Walls::Slabs => "slabs",
    }
}

fn bench_resting(c: &mut Criterion) {
    for walls in wall_kinds() {
        for n in [1000, 10_000] {
            let scene = resting(n, walls);
            let group_name = format!("resting_{}", walls_name(walls));
            let name = format!("{group_name}/{n}");
            let settle = 120;
            let mut group = c.benchmark_group(&group_name);
            group
                .sample_size(if n > 1000 { 10 } else { 30 })
                .throughput(Throughput::Elements(n as u64));

            for (label, can_sleep) in URTO_SLEEP_VARIANTS {
                let (mut app, balls) = urto_app(&scene, can_sleep);
                urto_step(&mut app, settle - 60);
                let stages = urto_step_staged(&mut app, 60);
                sanity(&name, label, &scene, settle, urto_state(&app, &balls));
                eprintln!("[urto stages] µs per step, mean of the last 60: {stages}");
                group.bench_function(BenchmarkId::new(label, n), |b| {
                    b.iter(|| urto_step(&mut app, 1))
                });
            }

            for (label, can_sleep) in RAPIER_SLEEP_VARIANTS {
                let mut r = Rapier::new(&scene, can_sleep);
                r.step(settle);
                sanity(&name, label, &scene, settle, r.state());
                group.bench_function(BenchmarkId::new(label, n), |b| b.iter(|| r.step(1)));
            }
            group.finish();
        }
    }
}

fn bench_falling_pile(c: &mut Criterion) {
    for walls in wall_kinds() {
        let scene = falling_pile(walls);
        let n = scene.balls.len();
        let group_name = format!("falling_pile_{}", walls_name(walls));
        let name = format!("{group_name}/{n}");

        // The sanity runs go on to PILE_CHECK_STEPS (not timed): has the pile come to rest?
        let more = PILE_CHECK_STEPS - PILE_STEPS;
        for (label, can_sleep) in URTO_SLEEP_VARIANTS {
            let (mut app, balls) = urto_app(&scene, can_sleep);
            let stages = urto_step_staged(&mut app, PILE_STEPS);
            sanity(&name, label, &scene, PILE_STEPS, urto_state(&app, &balls));
            eprintln!("[urto stages] µs per step, mean of {PILE_STEPS}: {stages}");
            urto_step(&mut app, more);
            sanity(
                &name,
                label,
                &scene,
                PILE_CHECK_STEPS,
                urto_state(&app, &balls),
            );
        }
        for (label, can_sleep) in RAPIER_SLEEP_VARIANTS {
            let mut r = Rapier::new(&scene, can_sleep);
            r.step(PILE_STEPS);
            sanity(&name, label, &scene, PILE_STEPS, r.state());
            r.step(more);
            sanity(&name, label, &scene, PILE_CHECK_STEPS, r.state());
        }

        // One iteration = the first PILE_STEPS steps of a fresh scene.
        let mut group = c.benchmark_group(format!("{group_name}_{PILE_STEPS}_steps"));
        group
            .sample_size(10)
            .sampling_mode(SamplingMode::Flat)
            .measurement_time(Duration::from_secs(8))
            .throughput(Throughput::Elements(u64::from(PILE_STEPS)));
        for (label, can_sleep) in URTO_SLEEP_VARIANTS {
            group.bench_function(BenchmarkId::new(label, n), |b| {
                b.iter_custom(|iters| {
                    timed(
                        iters,
                        || urto_app(&scene, can_sleep).0,
                        |app| urto_step(app, PILE_STEPS),
                    )
                })
            });
        }
        for (label, can_sleep) in RAPIER_SLEEP_VARIANTS {
            group.bench_function(BenchmarkId::new(label, n), |b| {
                b.iter_custom(|iters| {
                    timed(
                        iters,
                        || Rapier::new(&scene, can_sleep),
                        |r| r.step(PILE_STEPS),
                    )
                })
            });
        }
        group.finish();
    }
}

fn bench_sparse_movers(c: &mut Criterion) {
    for walls in wall_kinds() {
        let n = 10_000;
        let scene = sparse_movers(n, walls);
        let group_name = format!("sparse_movers_{}", walls_name(walls));
        let name = format!("{group_name}/{n}");
        let before = 300;
        eprintln!(
            "[sanity] {name:<28} initial mean speed {:.3} m/s (elastic, frictionless: it should stay)",
            initial_speed(&scene)
        );
        let mut group = c.benchmark_group(&group_name);
        group
            .sample_size(10)
            .throughput(Throughput::Elements(n as u64));

        let (mut app, balls) = urto_app(&scene, true);
        urto_step(&mut app, before - 60);
        let stages = urto_step_staged(&mut app, 60);
        sanity(&name, "urto", &scene, before, urto_state(&app, &balls));
        eprintln!("[urto stages] µs per step, mean of the last 60: {stages}");
        group.bench_function(BenchmarkId::new("urto", n), |b| {
            b.iter(|| urto_step(&mut app, 1))
        });
        drop(app);

        // Moving bodies never fall asleep: rapier's default (sleeping allowed) is the only variant.
        let mut r = Rapier::new(&scene, true);
        r.step(before);
        sanity(&name, "rapier", &scene, before, r.state());
        group.bench_function(BenchmarkId::new("rapier", n), |b| b.iter(|| r.step(1)));
        group.finish();
    }
}

fn config() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
}

criterion_group! {
    name = benches;
    config = config();
    targets = bench_resting, bench_falling_pile, bench_sparse_movers
}
criterion_main!(benches);
