//! Bullets peer benchmark: fast small bodies fired into free bodies, urto's continuous collision
//! between moving bodies against rapier3d's CCD, on the same scene in the same run.
//!
//! The scene: a 10 × 10 × 10 block of free boxes (half size 0.2 m, 1 kg, 1 m apart, x from 10 to
//! 19 m), no gravity, and 100 bullets (balls of 2 cm, 50 g) fired along +x at 300 m/s from
//! x = 8, each down a row of boxes (5 m a step at dt = 1/60: a box is 0.4 m thick); friction
//! 0.5 and no restitution on every collider in both engines (rapier's defaults). urto runs
//! its defaults (automatic CCD for bodies moving more than their size in a substep, 4 soft
//! substeps); rapier its defaults with `ccd_enabled(true)` on the bullets (its CCD solver clamps
//! them at their first time of impact against any body). Also urto with CCD off, for what it
//! saves and what it lets through. One criterion iteration is the first `STEPS` steps of a fresh
//! scene (the build is not timed): divide by `STEPS` for a step.
//!
//! Quality, printed once per engine to stderr: bullets past the block's far side (through ten
//! boxes: tunnelled), boxes set moving (faster than 1 mm/s), and the bullets' total momentum
//! handed to the boxes.
//!
//! Run (from `peers/`): `cargo bench --bench bullets 2> bullets_sanity.txt`.

use bevy_app::App;
use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use glam::Vec3;
use rapier3d::prelude as rp;
use std::time::Duration;
use urto::plugins::CcdSettings;
use urto::prelude::*;

#[path = "common/fresh_runs.rs"]
mod fresh_runs;
use fresh_runs::timed;
#[path = "common/rapier_world.rs"]
mod rapier_world;
use rapier_world::{RapierWorld, rv};

const DT: f32 = 1.0 / 60.0;
const STEPS: u32 = 30;
const SIDE: usize = 10;
const BOX_HALF: f32 = 0.2;
const BOX_MASS: f32 = 1.0;
const BULLET_RADIUS: f32 = 0.02;
const BULLET_MASS: f32 = 0.05;
const BULLET_SPEED: f32 = 300.0;
/// rapier's default friction and restitution, on every collider in both engines.
const FRICTION: f32 = 0.5;
const RESTITUTION: f32 = 0.0;
/// The block's far side: a bullet beyond it went through ten boxes.
const FAR_SIDE: f32 = 10.0 + (SIDE as f32 - 1.0) + BOX_HALF;

/// The boxes' centres, then the bullets' starts (one down each row, off its axis by up to
/// 0.1 m so that some hit near an edge).
fn scene() -> (Vec<Vec3>, Vec<Vec3>) {
    let mut boxes = Vec::new();
    for i in 0..SIDE {
        for j in 0..SIDE {
            for k in 0..SIDE {
                boxes.push(Vec3::new(10.0 + i as f32, j as f32, k as f32));
            }
        }
    }
    let bullets = (0..SIDE * SIDE)
        .map(|r| {
            let (j, k) = ((r % SIDE) as f32, (r / SIDE) as f32);
            let off = 0.1 * ((r * 7 % 11) as f32 / 10.0 - 0.5);
            Vec3::new(8.0, j + off, k - off)
        })
        .collect();
    (boxes, bullets)
}

/// What the sanity line reports: bullets through the block, boxes moving, momentum in boxes.
fn quality(boxes: &[(Vec3, Vec3)], bullets: &[(Vec3, Vec3)]) -> String {
    let through = bullets.iter().filter(|(p, _)| p.x > FAR_SIDE).count();
    let moving = boxes.iter().filter(|(_, v)| v.length() > 1e-3).count();
    let handed: f32 = boxes.iter().map(|(_, v)| v.x * BOX_MASS).sum();
    let fired = BULLET_MASS * BULLET_SPEED * bullets.len() as f32;
    format!(
        "bullets through the block {through} of {}, boxes moving {moving}, momentum in the boxes {:.1} % of the bullets'",
        bullets.len(),
        100.0 * handed / fired
    )
}

struct Urto {
    app: App,
    boxes: Vec<bevy_ecs::entity::Entity>,
    bullets: Vec<bevy_ecs::entity::Entity>,
}

impl Urto {
    fn new(ccd: bool) -> Self {
        let (boxes, bullets) = scene();
        let mut app = App::new();
        let timestep = urto::PhysicsTimestep::new(DT, 1).expect("valid timestep");
        app.add_plugins(UrtoPlugins::with_timestep(timestep));
        app.insert_resource(Gravity::new(Vec3::ZERO).expect("finite gravity"));
        // rapier's defaults, so that both engines solve the same collisions.
        app.insert_resource(ContactSettings {
            default_restitution: RESTITUTION,
            default_friction: FRICTION,
            ..Default::default()
        });
        if !ccd {
            app.insert_resource(CcdSettings {
                auto_speed_ratio: None,
                ..Default::default()
            });
        }
        let world = app.world_mut();
        let boxes = boxes
            .iter()
            .map(|&p| {
                let collider = Collider::cuboid(BOX_HALF, BOX_HALF, BOX_HALF);
                let body = (collider, Position(p), Velocity::default(), Mass(BOX_MASS));
                world.spawn(body).id()
            })
            .collect();
        let bullets = bullets
            .iter()
            .map(|&p| {
                let v = Velocity(Vec3::X * BULLET_SPEED);
                let body = (Collider::sphere(BULLET_RADIUS), Position(p), v);
                world.spawn((body, Mass(BULLET_MASS))).id()
            })
            .collect();
        Self {
            app,
            boxes,
            bullets,
        }
    }

    fn step(&mut self, n: u32) {
        urto::step(self.app.world_mut(), n).expect("UrtoPlugins added");
    }

    fn states(&self, of: &[bevy_ecs::entity::Entity]) -> Vec<(Vec3, Vec3)> {
        let w = self.app.world();
        of.iter()
            .map(|&e| {
                let p = w.get::<Position>(e).expect("body").0;
                (p, w.get::<Velocity>(e).expect("body").0)
            })
            .collect()
    }
}

fn material(collider: rp::ColliderBuilder) -> rp::ColliderBuilder {
    collider.friction(FRICTION).restitution(RESTITUTION)
}

struct Rapier {
    world: RapierWorld,
    boxes: Vec<rp::RigidBodyHandle>,
    bullets: Vec<rp::RigidBodyHandle>,
}

impl Rapier {
    fn new() -> Self {
        let (boxes, bullets) = scene();
        let mut world = RapierWorld::new(rp::Vector::ZERO, DT);
        let boxes = boxes
            .iter()
            .map(|&p| {
                let body = rp::RigidBodyBuilder::dynamic().translation(rv(p));
                let collider = rp::ColliderBuilder::cuboid(BOX_HALF, BOX_HALF, BOX_HALF);
                world.add(body, material(collider).mass(BOX_MASS))
            })
            .collect();
        let bullets = bullets
            .iter()
            .map(|&p| {
                let body = rp::RigidBodyBuilder::dynamic()
                    .translation(rv(p))
                    .linvel(rv(Vec3::X * BULLET_SPEED))
                    .ccd_enabled(true);
                let collider = material(rp::ColliderBuilder::ball(BULLET_RADIUS)).mass(BULLET_MASS);
                world.add(body, collider)
            })
            .collect();
        Self {
            world,
            boxes,
            bullets,
        }
    }

    fn step(&mut self, n: u32) {
        self.world.step(n);
    }

    fn states(&self, of: &[rp::RigidBodyHandle]) -> Vec<(Vec3, Vec3)> {
        of.iter()
            .map(|h| {
                let b = &self.world.bodies[*h];
                let (p, v) = (b.translation(), b.linvel());
                (Vec3::new(p.x, p.y, p.z), Vec3::new(v.x, v.y, v.z))
            })
            .collect()
    }
}

const URTO_VARIANTS: [(&str, bool); 2] = [("urto", true), ("urto_ccd_off", false)];

fn bench_bullets(c: &mut Criterion) {
    for (label, ccd) in URTO_VARIANTS {
        let mut u = Urto::new(ccd);
        u.step(STEPS);
        let line = quality(&u.states(&u.boxes), &u.states(&u.bullets));
        eprintln!("[sanity] bullets {label} after {STEPS} steps: {line}");
    }
    let mut r = Rapier::new();
    r.step(STEPS);
    let line = quality(&r.states(&r.boxes), &r.states(&r.bullets));
    eprintln!("[sanity] bullets rapier (ccd on the bullets) after {STEPS} steps: {line}");

    let mut group = c.benchmark_group(format!("bullets_{STEPS}_steps"));
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Elements(u64::from(STEPS)));
    let n = SIDE * SIDE * SIDE;
    for (label, ccd) in URTO_VARIANTS {
        group.bench_function(BenchmarkId::new(label, n), |b| {
            b.iter_custom(|iters| timed(iters, || Urto::new(ccd), |u| u.step(STEPS)))
        });
    }
    group.bench_function(BenchmarkId::new("rapier", n), |b| {
        b.iter_custom(|iters| timed(iters, Rapier::new, |r| r.step(STEPS)))
    });
    group.finish();
}

criterion_group!(benches, bench_bullets);
criterion_main!(benches);
