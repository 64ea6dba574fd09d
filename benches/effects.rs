//! "Simulate only the effects a scene calls for", measured: the same 10,000 bodies stepped
//! with more and more effects switched on. Each row adds one effect to the previous one; a
//! scene pays for an effect only from the row where it appears.
//!
//! Rows: bodies with a velocity only (integration), then gravity, then a user force on every
//! body, then drag, then colliders (spheres, spread out: broad phase, no contacts), then a ground
//! (every body in contact: narrow phase and response), then continuous collision on every body.
//!
//! A second group, `rotation/N`, measures what turning costs on the same bodies without
//! colliders: no rotation stage at all (the floor), rotation locked on every body, every body free to turn but none
//! turning (what a scene that never spins pays: one look per body), and every body tumbling
//! with and without the gyroscopic term.
//!
//! A third group, `sleeping/N`, is the ground-contact scene (row 6) once every body has fallen
//! asleep: what a sleeping scene costs per step (rapier's sleeping step is the yardstick; see
//! `peers/`), next to the same scene awake.
//!
//! Sizes: `URTO_BENCH_BODIES` (default `10000`). Quick run:
//! `URTO_BENCH_BODIES=1000 cargo bench --bench effects -- --quick`.

use bevy_app::App;
use bevy_app::PluginGroup;
use bevy_ecs::prelude::With;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use urto::plugins::{CcdSettings, RotationPlugin};
use urto::prelude::*;

/// The effects, cumulative.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Effects {
    Integration,
    Gravity,
    UserForces,
    Drag,
    Colliders,
    Contacts,
    Ccd,
}

const ALL: [Effects; 7] = [
    Effects::Integration,
    Effects::Gravity,
    Effects::UserForces,
    Effects::Drag,
    Effects::Colliders,
    Effects::Contacts,
    Effects::Ccd,
];

fn name(e: Effects) -> &'static str {
    match e {
        Effects::Integration => "1 integration only",
        Effects::Gravity => "2 + gravity",
        Effects::UserForces => "3 + user forces",
        Effects::Drag => "4 + drag",
        Effects::Colliders => "5 + colliders, apart",
        Effects::Contacts => "6 + ground contact",
        Effects::Ccd => "7 + CCD on every body",
    }
}

/// `n` bodies on a square lattice 2 m apart; with `e` and everything before it.
fn scene(n: usize, e: Effects) -> App {
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::default());
    app.insert_resource(CcdSettings {
        auto_speed_ratio: None,
        ..Default::default()
    });
    // Every row measures the work of its effects; asleep, resting bodies would do none (the
    // peers bench measures sleeping).
    app.insert_resource(SleepSettings {
        enabled: false,
        ..Default::default()
    });
    if e >= Effects::Gravity {
        app.insert_resource(Gravity::EARTH_Z_UP);
    }
    if e >= Effects::Contacts {
        app.world_mut()
            .spawn((Collider::half_space(Vec3::Z), Static));
    }
    let side = (n as f32).sqrt().ceil() as usize;
    for i in 0..n {
        let at = Vec3::new((i % side) as f32 * 2.0, (i / side) as f32 * 2.0, 0.5);
        let mut body = app
            .world_mut()
            .spawn((Position(at), Velocity::new(0.0, 0.0, 0.0)));
        if e >= Effects::UserForces {
            body.insert(Force(Vec3::X));
        }
        if e >= Effects::Drag {
            body.insert(LinearDrag(0.1));
        }
        if e >= Effects::Colliders {
            body.insert(Collider::sphere(0.5));
        }
        if e >= Effects::Ccd {
            body.insert(Ccd);
        }
    }
    // Warm up: first-step registration and bulk inserts are not what a step costs.
    urto::step(app.world_mut(), 3).expect("UrtoPlugins");
    app
}

/// Re-arms the one-step user forces so every measured step has them.
fn rearm_forces(app: &mut App) {
    let mut q = app.world_mut().query::<&mut Force>();
    for mut f in q.iter_mut(app.world_mut()) {
        f.0 = Vec3::X;
    }
}

fn bench_effects(c: &mut Criterion) {
    let sizes: Vec<usize> = std::env::var("URTO_BENCH_BODIES")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![10_000]);
    for n in sizes {
        let mut group = c.benchmark_group(format!("effects/{n}"));
        group.throughput(Throughput::Elements(n as u64));
        for e in ALL {
            let mut app = scene(n, e);
            let stats = app.world().resource::<PhysicsStats>();
            let ran: Vec<&str> = [
                "forces/gravity",
                "forces/user",
                "forces/drag",
                "integrate",
                "broad_phase",
                "narrow_phase",
                "response",
                "ccd",
            ]
            .into_iter()
            .filter(|s| stats.runs(s) > 0)
            .collect();
            eprintln!("[effects] {n} bodies, {}: runs {ran:?}", name(e));
            group.bench_function(BenchmarkId::new(name(e), n), |b| {
                b.iter(|| {
                    if e >= Effects::UserForces {
                        rearm_forces(&mut app);
                    }
                    urto::step(app.world_mut(), 1).expect("UrtoPlugins")
                })
            });
        }
        group.finish();
    }
}

/// How the bodies of the rotation group turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Turning {
    PluginOff,
    Locked,
    FreeButStill,
    Tumbling { gyroscopic: bool },
}

const TURNING: [(Turning, &str); 5] = [
    (
        Turning::PluginOff,
        "0 no rotation stage (RotationPlugin disabled)",
    ),
    (Turning::Locked, "a rotation locked"),
    (Turning::FreeButStill, "b free to turn, none turning"),
    (
        Turning::Tumbling { gyroscopic: false },
        "c all tumbling, no gyroscopic term",
    ),
    (
        Turning::Tumbling { gyroscopic: true },
        "d all tumbling, gyroscopic",
    ),
];

/// `n` bodies drifting apart (integration only), turning as `t` says.
fn turning_scene(n: usize, t: Turning) -> App {
    let mut app = App::new();
    if t == Turning::PluginOff {
        app.add_plugins(UrtoPlugins::default().build().disable::<RotationPlugin>());
    } else {
        app.add_plugins(UrtoPlugins::default());
    }
    if let Turning::Tumbling { gyroscopic } = t {
        app.insert_resource(RotationSettings { gyroscopic });
    }
    for i in 0..n {
        let mut body = app.world_mut().spawn((
            Position(Vec3::new(i as f32 * 2.0, 0.0, 0.0)),
            Velocity::new(0.0, 0.0, 0.1),
            Inertia::custom(Vec3::new(1.0, 2.0, 3.0), glam::Quat::IDENTITY),
        ));
        match t {
            Turning::Locked => {
                body.insert(LockedAxes::ROTATION_LOCKED);
            }
            Turning::PluginOff | Turning::FreeButStill => {}
            Turning::Tumbling { .. } => {
                body.insert(AngularVelocity::new(1.0, 2.0, 0.5));
            }
        }
    }
    urto::step(app.world_mut(), 3).expect("UrtoPlugins");
    app
}

fn bench_rotation(c: &mut Criterion) {
    let sizes: Vec<usize> = std::env::var("URTO_BENCH_BODIES")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![10_000]);
    for n in sizes {
        let mut group = c.benchmark_group(format!("rotation/{n}"));
        group.throughput(Throughput::Elements(n as u64));
        for (t, label) in TURNING {
            let mut app = scene_turning_checked(n, t);
            group.bench_function(BenchmarkId::new(label, n), |b| {
                b.iter(|| urto::step(app.world_mut(), 1).expect("UrtoPlugins"))
            });
        }
        group.finish();
    }
}

/// The scene, with the number of bodies the rotation stage turned printed as a check.
fn scene_turning_checked(n: usize, t: Turning) -> App {
    let app = turning_scene(n, t);
    let turned = app
        .world()
        .resource::<PhysicsStats>()
        .counter("integrate/turning")
        .unwrap_or(0.0);
    eprintln!("[rotation] {n} bodies, {t:?}: {turned} turned per step");
    app
}

/// The ground-contact scene with sleeping on, stepped until every body sleeps (checked).
fn sleeping_scene(n: usize) -> App {
    let mut app = scene(n, Effects::Contacts);
    app.insert_resource(SleepSettings::default());
    urto::step(app.world_mut(), 120).expect("UrtoPlugins");
    let world = app.world_mut();
    let asleep = world
        .query_filtered::<(), With<Sleeping>>()
        .iter(world)
        .count();
    eprintln!("[sleeping] {n} bodies: {asleep} asleep");
    assert_eq!(asleep, n, "the scene must sleep to measure sleeping");
    app
}

fn bench_sleeping(c: &mut Criterion) {
    let sizes: Vec<usize> = std::env::var("URTO_BENCH_BODIES")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![10_000]);
    for n in sizes {
        let mut group = c.benchmark_group(format!("sleeping/{n}"));
        group.throughput(Throughput::Elements(n as u64));
        let mut asleep = sleeping_scene(n);
        group.bench_function(BenchmarkId::new("all asleep", n), |b| {
            b.iter(|| urto::step(asleep.world_mut(), 1).expect("UrtoPlugins"))
        });
        let mut awake = scene(n, Effects::Contacts);
        group.bench_function(BenchmarkId::new("awake (sleeping off)", n), |b| {
            b.iter(|| urto::step(awake.world_mut(), 1).expect("UrtoPlugins"))
        });
        group.finish();
    }
}

criterion_group!(benches, bench_effects, bench_rotation, bench_sleeping);
criterion_main!(benches);
