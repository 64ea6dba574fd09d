//! The rerun recording of mesh bodies, read back in Rust: each mesh's triangles are logged once
//! and its pose on every recorded step (a static mesh's pose once); hierarchy levels and the
//! overlapping leaves appear only when asked for; the narrow phase's BVH counters are recorded;
//! and none of it changes a simulation result.
#![cfg(feature = "rerun")]

mod common;

use bevy_app::App;
use bevy_ecs::entity::Entity;
use glam::Vec3;
use rerun::ChunkStore;
use std::collections::BTreeSet;
use urto::debug::{RerunConfig, RerunDebugPlugin};
use urto::geometry::TriMesh;
use urto::plugins::narrow_phase::OverlappingLeaves;
use urto::prelude::*;

const STEPS: u32 = 40;

/// A mesh floor, a mesh ball just above it and a mesh box falling onto the ball's side.
fn scene(app: &mut App) -> (Entity, Vec<Entity>) {
    app.insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    let floor = TriMesh::grid_floor(6.0, 12).unwrap();
    let floor = world
        .spawn((Collider::trimesh(floor).unwrap(), Static))
        .id();
    let ball = TriMesh::uv_sphere(0.5, 16, 8).unwrap();
    let cube = TriMesh::cuboid(Vec3::splat(0.3)).unwrap();
    let bodies = vec![
        world
            .spawn((
                Collider::trimesh(ball).unwrap(),
                Position::new(0.0, 0.0, 0.55),
                Velocity::default(),
                // Kept awake, so its leaves touch the floor's at the last step: asleep, it
                // leaves the narrow phase (the cube, bouncing, may be in the air by then).
                SleepingDisabled,
            ))
            .id(),
        world
            .spawn((
                Collider::trimesh(cube).unwrap(),
                Position::new(1.5, 0.2, 1.0),
                Velocity::default(),
            ))
            .id(),
    ];
    (floor, bodies)
}

/// Runs the scene with the recording into memory; returns the store and the final positions.
fn recorded(config: RerunConfig) -> (ChunkStore, Vec<Vec3>, App, Entity, Vec<Entity>) {
    let (rec, storage) = rerun::RecordingStreamBuilder::new("urto_mesh_test")
        .memory()
        .expect("memory sink");
    let mut app = common::app();
    app.add_plugins(RerunDebugPlugin::from_stream(rec.clone(), config));
    let (floor, bodies) = scene(&mut app);
    urto::step(app.world_mut(), STEPS).unwrap();
    let positions = bodies
        .iter()
        .map(|b| app.world().get::<Position>(*b).unwrap().0)
        .collect();
    let store = common::recording::read_back(&rec, &storage);
    (store, positions, app, floor, bodies)
}

fn entities(store: &ChunkStore) -> BTreeSet<String> {
    store.all_entities().iter().map(|e| e.to_string()).collect()
}

/// The rows (step, values) of one component of one entity.
fn rows<C: rerun::Component>(
    store: &ChunkStore,
    entity: &str,
    component: rerun::ComponentIdentifier,
) -> Vec<(i64, Vec<C>)> {
    let mut out = Vec::new();
    for chunk in store.iter_physical_chunks() {
        if chunk.entity_path().to_string() != entity {
            continue;
        }
        let indices = chunk.iter_indices(&"step".into());
        for ((t, _), batch) in indices.zip(chunk.iter_component::<C>(component)) {
            out.push((t.as_i64(), batch.to_vec()));
        }
    }
    out.sort_by_key(|(t, _)| *t);
    out
}

fn debug_config() -> RerunConfig {
    RerunConfig {
        bvh_levels: 3,
        overlapping_leaves: true,
        ..RerunConfig::file("unused.rrd")
    }
}

#[test]
fn meshes_are_logged_once_and_posed_every_step() {
    let (store, positions, _, floor, bodies) = recorded(debug_config());
    let names = entities(&store);
    let ball = format!("/world/meshes/mesh_{}", bodies[0]);
    let floor = format!("/world/meshes/mesh_{floor}");
    for expected in [
        &ball,
        &floor,
        "/hierarchy/level_0/static",
        "/hierarchy/level_2/moving",
        "/narrow_phase/overlapping_leaves",
        "/narrow_phase/overlapping_leaf_boxes",
        "/counters/narrow_phase/bvh_nodes_visited",
        "/counters/narrow_phase/bv_tests",
        "/counters/narrow_phase/triangle_tests",
    ] {
        assert!(names.contains(expected), "missing {expected} in {names:?}");
    }
    assert!(
        !names.iter().any(|n| n.contains("level_3")),
        "only 3 levels"
    );

    let vertices = rerun::Mesh3D::descriptor_vertex_positions().component;
    let meshes = rows::<rerun::components::Position3D>(&store, &ball, vertices);
    assert_eq!(meshes.len(), 1, "the triangles are logged once");
    assert_eq!(
        meshes[0].1.len(),
        2 + 16 * 7,
        "every vertex of the UV sphere"
    );

    let translation = rerun::Transform3D::descriptor_translation().component;
    let poses = rows::<rerun::components::Translation3D>(&store, &ball, translation);
    assert_eq!(poses.len(), STEPS as usize, "a pose per recorded step");
    let last = Vec3::from_array(poses.last().unwrap().1[0].0.into());
    assert_eq!(
        last, positions[0],
        "the last pose is the simulated position"
    );
    let floor_poses = rows::<rerun::components::Translation3D>(&store, &floor, translation);
    assert_eq!(floor_poses.len(), 1, "a static mesh is posed once");

    let strips = rerun::LineStrips3D::descriptor_strips().component;
    let leaves =
        rows::<rerun::components::LineStrip3D>(&store, "/narrow_phase/overlapping_leaves", strips);
    assert_eq!(leaves.len(), STEPS as usize);
    assert!(
        leaves.iter().any(|(_, s)| !s.is_empty()),
        "the ball rests on the floor: some leaves overlap"
    );
}

#[test]
fn without_the_options_there_are_no_hierarchies_and_the_narrow_phase_records_nothing() {
    let (store, _, app, _, _) = recorded(RerunConfig::file("unused.rrd"));
    let names = entities(&store);
    assert!(names.iter().any(|n| n.starts_with("/world/meshes/")));
    assert!(
        !names.iter().any(|n| n.starts_with("/hierarchy")),
        "{names:?}"
    );
    assert!(!names.contains("/narrow_phase/overlapping_leaves"));
    let leaves = app.world().resource::<OverlappingLeaves>();
    assert!(!leaves.enabled && leaves.pairs.is_empty());
}

#[test]
fn recording_meshes_changes_no_result() {
    let mut plain = common::app();
    let (_, bodies) = scene(&mut plain);
    urto::step(plain.world_mut(), STEPS).unwrap();
    let without: Vec<Vec3> = bodies
        .iter()
        .map(|b| plain.world().get::<Position>(*b).unwrap().0)
        .collect();
    let (_, with, app, _, _) = recorded(debug_config());
    assert_eq!(
        with, without,
        "bit-identical with and without the recording"
    );
    let leaves = app.world().resource::<OverlappingLeaves>();
    assert!(leaves.enabled);
    assert!(!leaves.pairs.is_empty(), "the ball touches the floor");
    for pair in &leaves.pairs {
        assert!(!pair.leaves.is_empty());
        assert!(
            pair.leaves.windows(2).all(|w| w[0] < w[1]),
            "sorted, each once"
        );
    }
}
