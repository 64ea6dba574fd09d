//! The rerun recording: read back in Rust, it holds the expected entities and steps, and
//! recording changes no simulation result.
#![cfg(feature = "rerun")]

mod common;

use bevy_app::App;
use glam::Vec3;
use rerun::ChunkStore;
use std::collections::BTreeSet;
use urto::debug::{RerunConfig, RerunDebugPlugin};
use urto::prelude::*;

fn scene(app: &mut App) -> Vec<bevy_ecs::entity::Entity> {
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    // A capsule lying far from the balls, at rest on the ground.
    app.world_mut().spawn((
        Collider::capsule(0.6, 0.2),
        Position::new(-5.0, 0.0, 0.2),
        Rotation(glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)),
    ));
    // A cylinder standing and a hull lying far from the balls.
    app.world_mut()
        .spawn((Collider::cylinder(0.3, 0.2), Position::new(-5.0, 3.0, 0.3)));
    let tetra = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    app.world_mut().spawn((
        Collider::convex_hull(&tetra).expect("a tetrahedron"),
        Position::new(-5.0, -3.0, 0.0),
    ));
    (0..4)
        .map(|i| {
            let x = i as f32 * 1.5;
            app.world_mut()
                .spawn((
                    Collider::sphere(0.5),
                    Position::new(x, 0.0, 1.0 + x),
                    Velocity::new(0.3, 0.0, 0.0),
                ))
                .id()
        })
        .collect()
}

fn recorded_store(every_k: u64, steps: u32) -> (ChunkStore, Vec<Vec3>) {
    let (rec, storage) = rerun::RecordingStreamBuilder::new("urto_test")
        .memory()
        .expect("memory sink");
    let mut app = common::app();
    let config = RerunConfig {
        every_k_steps: every_k,
        ..RerunConfig::file("unused.rrd")
    };
    app.add_plugins(RerunDebugPlugin::from_stream(rec.clone(), config));
    let balls = scene(&mut app);
    urto::step(app.world_mut(), steps).unwrap();
    let positions = balls
        .iter()
        .map(|b| app.world().get::<Position>(*b).unwrap().0)
        .collect();
    let store = common::recording::read_back(&rec, &storage);
    (store, positions)
}

#[test]
fn recording_holds_the_scene_the_timelines_and_the_metrics() {
    let (store, _) = recorded_store(2, 20);
    let entities: BTreeSet<String> = store.all_entities().iter().map(|e| e.to_string()).collect();
    for expected in [
        "/world",
        "/world/bodies/spheres",
        "/world/bodies/capsules",
        "/world/bodies/cylinders",
        "/world/bodies/hulls",
        "/world/static/boxes",
        "/world/bounding_volumes",
        "/world/velocities",
        "/world/contacts",
        "/broad_phase/pairs",
        "/timing/integrate",
        "/timing/broad_phase",
        "/timing/debug",
        "/counters/narrow_phase/contacts",
    ] {
        assert!(
            entities.contains(expected),
            "missing {expected} in {entities:?}"
        );
    }
    // The moving bodies' count, from whichever stage moved them (legacy integration or the
    // rigid-body solver).
    assert!(
        ["/counters/integrate/bodies", "/counters/soft_step/bodies"]
            .iter()
            .any(|c| entities.contains(*c)),
        "no body counter in {entities:?}"
    );
    let steps = store.time_range(&"step".into()).expect("a step timeline");
    assert_eq!((steps.min().as_i64(), steps.max().as_i64()), (2, 20));
    assert!(store.time_range(&"sim_time".into()).is_some());
}

#[test]
fn logged_positions_are_the_simulated_positions_and_sampling_skips_steps() {
    let (store, positions) = recorded_store(3, 12);
    let centers = rerun::Ellipsoids3D::descriptor_centers().component;
    let mut last: Option<(i64, Vec<Vec3>)> = None;
    let mut logged_steps = BTreeSet::new();
    for chunk in store.iter_physical_chunks() {
        if chunk.entity_path().to_string() != "/world/bodies/spheres" {
            continue;
        }
        let rows = chunk.iter_indices(&"step".into());
        let values = chunk.iter_component::<rerun::components::Translation3D>(centers);
        for ((t, _), batch) in rows.zip(values) {
            let step = t.as_i64();
            logged_steps.insert(step);
            let pts: Vec<Vec3> = batch.iter().map(|c| Vec3::from_array(c.0.into())).collect();
            if last.as_ref().is_none_or(|(s, _)| step > *s) {
                last = Some((step, pts));
            }
        }
    }
    assert_eq!(logged_steps, BTreeSet::from([3, 6, 9, 12]));
    let (_, pts) = last.unwrap();
    assert_eq!(
        pts, positions,
        "the last logged centres are the simulated positions"
    );
}

#[test]
fn a_capsule_is_drawn_from_its_bottom_cap_along_its_axis_within_1_mm() {
    let (store, _) = recorded_store(1, 5);
    let translations = rerun::Capsules3D::descriptor_translations().component;
    let lengths = rerun::Capsules3D::descriptor_lengths().component;
    let mut seen = 0;
    for chunk in store.iter_physical_chunks() {
        if chunk.entity_path().to_string() != "/world/bodies/capsules" {
            continue;
        }
        let at = chunk.iter_component::<rerun::components::Translation3D>(translations);
        let length = chunk.iter_component::<rerun::components::Length>(lengths);
        for (a, l) in at.zip(length) {
            let bottom = Vec3::from_array(a.iter().next().unwrap().0.into());
            // Lying along y (z turned by 90° about x): the bottom cap's centre is 0.6 towards -y.
            assert!(
                (bottom - Vec3::new(-5.0, 0.6, 0.2)).length() < 1e-3,
                "{bottom}"
            );
            assert!((l.iter().next().unwrap().0.0 - 1.2).abs() < 1e-5);
            seen += 1;
        }
    }
    assert!(seen > 0, "no capsule logged");
}

#[test]
fn recording_changes_no_result() {
    let mut plain = common::app();
    let balls = scene(&mut plain);
    urto::step(plain.world_mut(), 90).unwrap();
    let without: Vec<Vec3> = balls
        .iter()
        .map(|b| plain.world().get::<Position>(*b).unwrap().0)
        .collect();
    let (_, with) = recorded_store(1, 90);
    assert_eq!(
        with, without,
        "bit-identical with and without the recording"
    );
}

#[test]
fn an_unwritable_path_is_an_error_at_start_up() {
    let dir = std::env::temp_dir().join("urto-no-such-dir").join("deeper");
    let err = RerunDebugPlugin::to_file(dir.join("x.rrd")).unwrap_err();
    assert!(err.to_string().contains("cannot open"), "{err}");
    let zero = RerunConfig {
        every_k_steps: 0,
        ..RerunConfig::file(std::env::temp_dir().join("urto-k0.rrd"))
    };
    assert!(RerunDebugPlugin::new(zero).is_err());
}
