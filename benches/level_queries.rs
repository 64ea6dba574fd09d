//! Spatial queries in a level of static scenery, through the ECS: `URTO_BENCH_STATICS` static
//! boxes (default 100,000, on a lattice over a ground) and 1,000 balls drifting above them in
//! zero gravity. One iteration is one physics step, alone (`step`) or followed by one ray cast
//! (`step_and_ray`): the first query after a step refreshes the query index, so the difference
//! between the two is what the queries cost a step. Settled statics sit in the index's still
//! group and are not read again while none changes; before they were, every collider's box
//! was computed again at each step's first query.
//!
//! A second scene, `sleeping_debris`, holds `URTO_BENCH_SLEEPERS` boxes (default 10,000)
//! asleep on a ground instead of the statics, with the same drifting balls: sleeping bodies
//! sit in the index's sleeping group, read again only when a body falls asleep or wakes; before
//! they were read at every step's first query, as moving bodies are.
//!
//! Quick run: `URTO_BENCH_STATICS=10000 cargo bench --bench level_queries -- --quick`.

use bevy_app::App;
use bevy_ecs::bundle::Bundle;
use bevy_ecs::system::SystemId;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::Vec3;
use std::hint::black_box;
use urto::plugins::SpatialQueryIndex;
use urto::prelude::*;

const BALLS: usize = 1_000;

/// A lattice of `statics` unit boxes 3 m apart on a ground, and the drifting balls.
fn level(statics: usize) -> App {
    lattice(statics, |at| (Position(at), Static), 5)
}

/// `sleepers` unit boxes at rest 3 m apart on a ground, asleep, and the drifting balls.
fn sleeping_debris(sleepers: usize) -> App {
    let mut app = lattice(sleepers, |at| (Position(at), Velocity::default()), 60);
    let world = app.world_mut();
    let asleep = world.query::<&Sleeping>().iter(world).count();
    // The debris, and the few balls drifting slower than the sleep speed.
    assert!(asleep >= sleepers, "the debris sleeps: {asleep} asleep");
    app
}

/// A ground, `boxes` unit boxes 3 m apart on it (each a collider and `body(centre)`) and the
/// drifting balls, stepped `steps` times.
fn lattice<B: Bundle>(boxes: usize, body: impl Fn(Vec3) -> B, steps: u32) -> App {
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::default());
    let world = app.world_mut();
    world.spawn((Collider::half_space(Vec3::Z), Static));
    let side = (boxes as f64).sqrt().ceil() as usize;
    for i in 0..boxes {
        let at = Vec3::new((i % side) as f32 * 3.0, (i / side) as f32 * 3.0, 0.5);
        world.spawn((Collider::cuboid(0.5, 0.5, 0.5), body(at)));
    }
    spawn_balls(world, side as f32 * 3.0);
    urto::step(app.world_mut(), steps).expect("the scene steps");
    app
}

/// The balls drifting over a square of `extent` metres.
fn spawn_balls(world: &mut bevy_ecs::world::World, extent: f32) {
    for i in 0..BALLS {
        let t = i as f32 / BALLS as f32;
        let at = Vec3::new(t * extent, (t * 97.0).fract() * extent, 10.0 + 5.0 * t);
        let v = Vec3::new((t * 13.0).fract() - 0.5, (t * 29.0).fract() - 0.5, 0.0);
        world.spawn((Collider::sphere(0.4), Position(at), Velocity(v)));
    }
}

/// A ray down onto a box in the middle of a lattice of `boxes` (its top 29 m below).
fn ray_system(app: &mut App, boxes: usize) -> SystemId<(), Option<f32>> {
    let middle = ((boxes as f64).sqrt().ceil() as usize / 2) as f32 * 3.0;
    let from = Vec3::new(middle + 0.1, middle + 0.2, 30.0);
    app.world_mut().register_system(move |q: SpatialQuery| {
        let all = SpatialQueryFilter::default();
        let hit = q.cast_ray(from, -Vec3::Z, 100.0, &all);
        hit.ok().flatten().map(|h| h.distance)
    })
}

fn bench(c: &mut Criterion) {
    let sizes = |var: &str, default: &str| {
        let sizes = std::env::var(var).unwrap_or_else(|_| default.into());
        let sizes = sizes.split(',').filter_map(|s| s.trim().parse().ok());
        sizes.collect::<Vec<usize>>()
    };
    for statics in sizes("URTO_BENCH_STATICS", "100000") {
        bench_scene(c, "level_queries", statics, level(statics));
    }
    for sleepers in sizes("URTO_BENCH_SLEEPERS", "10000") {
        bench_scene(c, "sleeping_debris", sleepers, sleeping_debris(sleepers));
    }
}

/// A step alone and a step with one ray, in the scene `app` of `boxes` boxes on a lattice.
fn bench_scene(c: &mut Criterion, name: &str, boxes: usize, mut app: App) {
    let ray = ray_system(&mut app, boxes);
    let hit = app.world_mut().run_system(ray).expect("the ray runs");
    let mut group = c.benchmark_group(format!("{name}/{boxes}"));
    group.bench_function(BenchmarkId::new("step", boxes), |b| {
        b.iter(|| urto::step(app.world_mut(), 1).expect("steps"))
    });
    group.bench_function(BenchmarkId::new("step_and_ray", boxes), |b| {
        b.iter(|| {
            urto::step(app.world_mut(), 1).expect("steps");
            black_box(app.world_mut().run_system(ray).expect("the ray runs"))
        })
    });
    group.finish();
    let refreshes = app.world().resource::<SpatialQueryIndex>().refreshes();
    println!("{name}/{boxes}: the ray hit at {hit:?} m; index refreshes {refreshes:?}");
}

criterion_group!(benches, bench);
criterion_main!(benches);
