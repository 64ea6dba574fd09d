//! Pyramid peer benchmark: urto's soft-step solver (`SoftStepPlugin`) against rapier3d on the
//! same pyramid of boxes, rotations unlocked in both (issue 10's benchmark scene).
//!
//! The scene: `ROWS` rows of unit boxes (1 kg, 1 m, 1 cm apart in each row) on a static 1 m slab;
//! friction 0.6, no restitution, dt = 1/60, gravity 9.81 m/s² down Z. urto runs its soft-step
//! defaults (4 substeps, contacts at 60 Hz, 120 Hz against immovable bodies, sleeping by
//! islands), also with sleeping off; rapier runs its
//! defaults (4 solver iterations, TGS-soft, sleeping on, single-threaded). One criterion iteration
//! is the first `STEPS` steps of a fresh scene (the build is not timed): divide by `STEPS` for a
//! step.
//!
//! Quality, printed once per engine to stderr: the largest distance any box ends from where it
//! started after `STEPS` steps, the pyramid's sag (its top box's drop), and bodies asleep.
//!
//! Run (from `peers/`): `cargo bench --bench pyramid 2> pyramid_sanity.txt`;
//! `PEERS_PYRAMID_ROWS=40` for a larger one; `PEERS_PYRAMID_LAYERS=14` for the 3D
//! pyramid instead (a square pyramid of 14 layers, 14 × 14 boxes at the bottom and one at the
//! top: 1,015 boxes, 1 cm apart both ways).

use bevy_app::App;
use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use glam::{Quat, Vec3};
use rapier3d::prelude as rp;
use std::time::Duration;
use urto::dynamics::solver::{FrictionModel, SoftStepSettings};
use urto::prelude::*;

#[path = "common/fresh_runs.rs"]
mod fresh_runs;
use fresh_runs::timed;
#[path = "common/rapier_world.rs"]
mod rapier_world;
use rapier_world::{RapierWorld, rv};

const DT: f32 = 1.0 / 60.0;
const HALF: f32 = 0.5;
const STEPS: u32 = 300;
const FRICTION: f32 = 0.6;
/// rapier with its default sleeping, and with sleeping off (urto has no islands yet).
const RAPIER_VARIANTS: [(&str, bool); 2] = [("rapier", true), ("rapier_sleeping_off", false)];

/// urto's time per stage in the last step (µs).
fn stages_line(stats: &PhysicsStats) -> String {
    Stage::ALL
        .iter()
        .map(|s| {
            format!(
                "{} {:.0}",
                s.name(),
                stats.stage_time(*s).as_secs_f64() * 1e6
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn rows() -> u32 {
    positive_env("PEERS_PYRAMID_ROWS").unwrap_or(20)
}

/// The positive count in environment variable `name` (none for 0 or a value that is not a
/// number: an empty pyramid has no top to read the sag from).
fn positive_env(name: &str) -> Option<u32> {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|&n: &u32| n > 0)
}

/// The scene's name and where each box starts: the 3D pyramid of `PEERS_PYRAMID_LAYERS`
/// layers if set (to a positive number), else the 2D one of [`rows`] rows.
fn scene() -> (String, Vec<Vec3>) {
    match positive_env("PEERS_PYRAMID_LAYERS") {
        Some(layers) => (format!("pyramid3d_{layers}_layers"), boxes_3d(layers)),
        None => (format!("pyramid_{}_rows", rows()), boxes(rows())),
    }
}

/// A square pyramid of `layers` layers, each box 1 cm from its neighbours both ways; the top
/// box last (the sag is read from it).
fn boxes_3d(layers: u32) -> Vec<Vec3> {
    let mut out = Vec::new();
    for layer in 0..layers {
        let count = layers - layer;
        let at = |k: u32| (k as f32 - (count - 1) as f32 * 0.5) * 2.0 * HALF * 1.01;
        for i in 0..count {
            for k in 0..count {
                out.push(Vec3::new(at(i), at(k), HALF + 2.0 * HALF * layer as f32));
            }
        }
    }
    out
}

/// Where each box starts.
fn boxes(rows: u32) -> Vec<Vec3> {
    let mut out = Vec::new();
    for row in 0..rows {
        let count = rows - row;
        for k in 0..count {
            let y = (k as f32 - (count - 1) as f32 * 0.5) * 2.0 * HALF * 1.01;
            out.push(Vec3::new(0.0, y, HALF + 2.0 * HALF * row as f32));
        }
    }
    out
}

/// Largest displacement from the start, and the top box's drop.
fn quality(start: &[Vec3], end: &[Vec3]) -> (f32, f32) {
    let drift = start
        .iter()
        .zip(end)
        .map(|(s, e)| s.distance(*e))
        .fold(0.0f32, f32::max);
    let top = start.len() - 1;
    (drift, start[top].z - end[top].z)
}

struct Urto {
    app: App,
    bodies: Vec<bevy_ecs::entity::Entity>,
}

/// urto's defaults (sleeping by islands), the same awake, awake with one relax pass per
/// substep (Box2D's count) to show what the default's second pass costs, and awake with
/// friction per patch (rapier's friction model: three friction rows a contact instead of
/// eight), with two relax passes and with one (rapier's work per substep): `(label, relax
/// passes, sleeping, friction)`.
const URTO_VARIANTS: [(&str, u32, bool, FrictionModel); 5] = [
    ("urto", 2, true, FrictionModel::PerPoint),
    ("urto (no sleep)", 2, false, FrictionModel::PerPoint),
    (
        "urto (no sleep, relax 1)",
        1,
        false,
        FrictionModel::PerPoint,
    ),
    ("urto (no sleep, patch)", 2, false, FrictionModel::Patch),
    (
        "urto (no sleep, patch, relax 1)",
        1,
        false,
        FrictionModel::Patch,
    ),
];

impl Urto {
    fn new(
        start: &[Vec3],
        relax_iterations: u32,
        can_sleep: bool,
        friction: FrictionModel,
    ) -> Self {
        let settings = SoftStepSettings {
            relax_iterations,
            friction,
            ..Default::default()
        };
        let mut app = App::new();
        app.add_plugins(UrtoPlugins::default().set(SoftStepPlugin { settings }))
            .insert_resource(Gravity::new(Vec3::new(0.0, 0.0, -9.81)).expect("finite"))
            .insert_resource(SleepSettings {
                enabled: can_sleep,
                ..Default::default()
            });
        app.world_mut().spawn((
            Collider::cuboid(100.0, 100.0, 0.5),
            Position::new(0.0, 0.0, -0.5),
            Static,
            Friction(FRICTION),
            Restitution(0.0),
        ));
        let bodies = start
            .iter()
            .map(|&p| {
                app.world_mut()
                    .spawn((
                        Collider::cuboid(HALF, HALF, HALF),
                        Position(p),
                        Velocity::default(),
                        Mass(1.0),
                        Friction(FRICTION),
                        Restitution(0.0),
                    ))
                    .id()
            })
            .collect();
        Self { app, bodies }
    }

    fn step(&mut self, n: u32) {
        urto::step(self.app.world_mut(), n).expect("UrtoPlugins");
    }

    fn asleep(&self) -> usize {
        let w = self.app.world();
        self.bodies
            .iter()
            .filter(|&&b| w.get::<Sleeping>(b).is_some())
            .count()
    }

    fn positions(&self) -> Vec<Vec3> {
        let w = self.app.world();
        self.bodies
            .iter()
            .map(|&b| w.get::<Position>(b).expect("body").0)
            .collect()
    }
}

struct Rapier {
    world: RapierWorld,
    boxes: Vec<rp::RigidBodyHandle>,
}

impl Rapier {
    /// Rotations free (rapier's default); sleeping on (its default) or off.
    fn new(start: &[Vec3], can_sleep: bool) -> Self {
        let mut world = RapierWorld::new(rv(Vec3::new(0.0, 0.0, -9.81)), DT);
        let ground = rp::RigidBodyBuilder::fixed().translation(rv(Vec3::new(0.0, 0.0, -0.5)));
        let slab = rp::ColliderBuilder::cuboid(100.0, 100.0, 0.5)
            .friction(FRICTION)
            .restitution(0.0);
        world.add(ground, slab);
        let boxes = start
            .iter()
            .map(|&p| {
                let body = rp::RigidBodyBuilder::dynamic()
                    .translation(rv(p))
                    .can_sleep(can_sleep);
                let c = rp::ColliderBuilder::cuboid(HALF, HALF, HALF)
                    .mass(1.0)
                    .friction(FRICTION)
                    .restitution(0.0);
                world.add(body, c)
            })
            .collect();
        Self { world, boxes }
    }

    fn step(&mut self, n: u32) {
        self.world.step(n);
    }

    fn positions(&self) -> Vec<Vec3> {
        let poses = self.world.poses(&self.boxes);
        poses.into_iter().map(|(p, _)| p).collect()
    }

    fn asleep(&self) -> usize {
        self.boxes
            .iter()
            .filter(|h| self.world.bodies[**h].is_sleeping())
            .count()
    }
}

/// Runs `STEPS` steps one at a time; returns the step from which all `n` boxes stayed asleep
/// to the end of the run (`None` if some box was awake at the end).
fn run_watching_sleep<T>(
    engine: &mut T,
    step: impl Fn(&mut T),
    asleep: impl Fn(&T) -> usize,
    n: usize,
) -> Option<u32> {
    let mut since = None;
    for s in 1..=STEPS {
        step(engine);
        if asleep(engine) == n {
            since.get_or_insert(s);
        } else {
            since = None;
        }
    }
    since
}

/// The step from which every box slept, or "never" within the run.
fn step_or_never(step: Option<u32>) -> String {
    step.map_or_else(|| "never".to_string(), |s| s.to_string())
}

fn bench_pyramid(c: &mut Criterion) {
    let (name, start) = scene();
    let n = start.len();

    let mut default_run = None;
    for (label, relax, can_sleep, friction) in URTO_VARIANTS {
        let mut v = Urto::new(&start, relax, can_sleep, friction);
        let all_asleep_at = run_watching_sleep(&mut v, |u| u.step(1), Urto::asleep, n);
        let (drift, sag) = quality(&start, &v.positions());
        let turned = {
            let w = v.app.world();
            v.bodies
                .iter()
                .filter(|&&b| {
                    w.get::<Rotation>(b)
                        .expect("body")
                        .0
                        .angle_between(Quat::IDENTITY)
                        > 0.01
                })
                .count()
        };
        eprintln!(
            "[sanity] {name} ({n} boxes) {label} after {STEPS} steps: largest drift {:.1} mm, top sag {:.1} mm, boxes turned > 0.01 rad {turned}, asleep {}, all asleep from step {}",
            drift * 1e3,
            sag * 1e3,
            v.asleep(),
            step_or_never(all_asleep_at)
        );
        default_run.get_or_insert(v);
    }
    let u = default_run.expect("URTO_VARIANTS is not empty");
    for (label, can_sleep) in RAPIER_VARIANTS {
        let mut r = Rapier::new(&start, can_sleep);
        let all_asleep_at = run_watching_sleep(&mut r, |r| r.step(1), Rapier::asleep, n);
        let (drift, sag) = quality(&start, &r.positions());
        eprintln!(
            "[sanity] {name} ({n} boxes) {label} after {STEPS} steps: largest drift {:.1} mm, top sag {:.1} mm, asleep {}, all asleep from step {}",
            drift * 1e3,
            sag * 1e3,
            r.asleep(),
            step_or_never(all_asleep_at)
        );
    }
    let stages = u.app.world().resource::<PhysicsStats>();
    eprintln!("[urto stages] last step: {}", stages_line(stages));

    let mut group = c.benchmark_group(format!("{name}_{STEPS}_steps"));
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Elements(u64::from(STEPS)));
    for (label, relax, can_sleep, friction) in URTO_VARIANTS {
        group.bench_function(BenchmarkId::new(label, n), |b| {
            b.iter_custom(|iters| {
                timed(
                    iters,
                    || Urto::new(&start, relax, can_sleep, friction),
                    |u| u.step(STEPS),
                )
            })
        });
    }
    for (label, can_sleep) in RAPIER_VARIANTS {
        group.bench_function(BenchmarkId::new(label, n), |b| {
            b.iter_custom(|iters| {
                timed(iters, || Rapier::new(&start, can_sleep), |r| r.step(STEPS))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_pyramid);
criterion_main!(benches);
