//! Same scene, same result: bit-identical state after many steps, run after run and thread
//! after thread (the physics schedules run single-threaded, and no result depends on a hash
//! order), and whichever moving-body broad phase is plugged in (the pairs reach the solver in
//! key order, not in the broad phase's own order).

mod common;

use bevy_app::{App, PluginGroup};
use bevy_ecs::prelude::*;
use common::rng::Rng;
use glam::Vec3;
use std::hash::{DefaultHasher, Hash, Hasher};
use urto::broad_phase::{RegionSweep, SortAndSweep};
use urto::geometry::TriMesh;
use urto::plugins::{BroadPhaseFactory, BroadPhasePlugin};
use urto::prelude::*;

/// Spheres, boxes, a compound body, a mesh, springs, drag, a fast bullet (CCD) and a wall,
/// stepped 300 times; the hash of every body's position and velocity bits.
fn run_scene() -> u64 {
    run_scene_in(common::app_with(1.0 / 60.0, 2))
}

/// The scene of [`run_scene`] with another moving-body broad phase.
fn run_scene_with(moving: BroadPhaseFactory) -> u64 {
    let mut app = App::new();
    let timestep = PhysicsTimestep::new(1.0 / 60.0, 2).expect("valid test timestep");
    app.add_plugins(
        UrtoPlugins::with_timestep(timestep)
            .build()
            .set(BroadPhasePlugin {
                moving,
                ..Default::default()
            }),
    );
    run_scene_in(app)
}

fn run_scene_in(mut app: App) -> u64 {
    app.insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    world.spawn((Collider::half_space(Vec3::Z), Static));
    world.spawn((
        Collider::cuboid(0.05, 5.0, 3.0),
        Position::new(6.0, 0.0, 3.0),
        Static,
    ));
    let mut rng = Rng::new(99);
    for i in 0..80 {
        let at = Vec3::new(
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(0.5, 8.0),
        );
        let shape = if i % 3 == 0 {
            Collider::cuboid(0.3, 0.2, 0.25)
        } else {
            Collider::sphere(rng.range(0.15, 0.4))
        };
        world.spawn((
            shape,
            Position(at),
            Velocity(rng.in_ball(2.0)),
            Mass(rng.range(0.5, 3.0)),
        ));
    }
    let car = world
        .spawn((
            Collider::cuboid(0.8, 0.4, 0.2),
            Position::new(0.0, 4.0, 1.0),
            Velocity::new(1.0, 0.0, 0.0),
        ))
        .id();
    for x in [-0.6, 0.6] {
        world.spawn((
            Collider::sphere(0.25),
            Position::new(x, 0.0, -0.2),
            ChildOf(car),
        ));
    }
    let torus = Collider::trimesh(TriMesh::torus(0.6, 0.2, 24, 12).unwrap()).unwrap();
    let ring = world
        .spawn((
            torus,
            Position::new(-2.0, -4.0, 3.0),
            Velocity::default(),
            LinearDrag(0.2),
        ))
        .id();
    world.spawn((
        Collider::sphere(0.2),
        Position::new(-2.0, -4.0, 5.0),
        Velocity::default(),
        Spring {
            target: SpringTarget::Entity(ring),
            rest_length: 1.0,
            stiffness: 40.0,
            damping: 1.0,
        },
    ));
    world.spawn((
        Collider::sphere(0.05),
        Position::new(0.0, -1.0, 2.0),
        Velocity::new(400.0, 0.0, 0.0),
        Ccd,
    ));
    urto::step(app.world_mut(), 300).unwrap();
    let mut q = app
        .world_mut()
        .query::<(Entity, &Position, Option<&Velocity>)>();
    let mut state: Vec<_> = q
        .iter(app.world())
        .map(|(e, p, v)| {
            (
                e,
                p.0.to_array().map(f32::to_bits),
                v.map(|v| v.0.to_array().map(f32::to_bits)),
            )
        })
        .collect();
    state.sort_unstable_by_key(|s| s.0);
    let mut h = DefaultHasher::new();
    state.iter().for_each(|s| (s.1, s.2).hash(&mut h));
    h.finish()
}

#[test]
fn the_same_scene_gives_bit_identical_state_in_every_run_and_thread() {
    let first = run_scene();
    assert_eq!(first, run_scene(), "a second run in the same thread");
    let threads: Vec<u64> = (0..3)
        .map(|_| std::thread::spawn(run_scene))
        .collect::<Vec<_>>()
        .into_iter()
        .map(|t| t.join().expect("the scene runs"))
        .collect();
    assert!(
        threads.iter().all(|h| *h == first),
        "runs on concurrent threads"
    );
}

#[test]
fn the_segmented_and_the_from_scratch_broad_phases_give_the_default_state_bit_for_bit() {
    let default = run_scene();
    assert_eq!(
        run_scene_with(|| Box::new(RegionSweep::new())),
        default,
        "regions"
    );
    assert_eq!(
        run_scene_with(|| Box::new(SortAndSweep::new())),
        default,
        "sort and sweep"
    );
}
