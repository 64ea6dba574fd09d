//! Mesh colliders through the full plugin: mesh bodies (procedural and scanned) dropped on a mesh
//! floor come to rest on it — no NaN, no sinking beyond `SINK_TOLERANCE`, no flying off — and
//! the narrow phase reports the hierarchy's work as counters. Bad mesh input is an error at the
//! constructor, never a panic later.

mod common;

use bevy_ecs::prelude::*;
use glam::Vec3;
use urto::geometry::{MeshColliderError, MeshError, Shape, TriMesh};
use urto::prelude::*;

/// How far below the floor a resting body's lowest vertex may be: the solver's slop (2 mm) plus
/// one step of gravity (9.8 / 60² ≈ 2.7 mm) plus margin. A body that sank through a facet would
/// be tens of centimetres down.
const SINK_TOLERANCE: f32 = 0.01;

fn asset(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A scanned mesh centred on its box and scaled to about `radius`, as a collider.
fn scanned(name: &str, radius: f32) -> Collider {
    let mesh = urto::geometry::mesh_io::load(asset(name)).expect("test mesh loads");
    let c = mesh.local_aabb().center();
    let r = mesh
        .vertices()
        .iter()
        .fold(0.0f32, |m, v| m.max((*v - c).length()));
    let vertices = mesh
        .vertices()
        .iter()
        .map(|v| (*v - c) * (radius / r))
        .collect();
    let mesh = TriMesh::new(vertices, mesh.triangles().to_vec()).expect("still valid");
    Collider::trimesh(mesh).expect("collider builds")
}

/// The lowest vertex of a body's mesh in the world, at its pose (bodies turn).
fn lowest_point(world: &World, body: Entity) -> f32 {
    let c = world.get::<Collider>(body).unwrap();
    let pose = world.get::<GlobalPose>(body).unwrap().pose();
    match &c.shape {
        Shape::TriMesh(m) => m
            .mesh()
            .vertices()
            .iter()
            .map(|&v| pose.transform_point(v).z)
            .fold(f32::INFINITY, f32::min),
        _ => unreachable!("mesh bodies only"),
    }
}

#[test]
fn mesh_bodies_dropped_on_a_mesh_floor_come_to_rest_on_it() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    let floor = Collider::trimesh(TriMesh::grid_floor(12.0, 24).unwrap()).unwrap();
    world.spawn((floor, Static));
    let bodies = [
        Collider::trimesh(TriMesh::uv_sphere(0.4, 16, 8).unwrap()).unwrap(),
        Collider::trimesh(TriMesh::cuboid(Vec3::new(0.4, 0.3, 0.2)).unwrap()).unwrap(),
        Collider::trimesh(TriMesh::torus(0.4, 0.15, 24, 12).unwrap()).unwrap(),
        scanned("ant.ply", 0.5),
        scanned("nut.ply", 0.4),
    ];
    let spawned: Vec<Entity> = bodies
        .into_iter()
        .enumerate()
        .map(|(i, c)| {
            let x = -3.0 + 1.5 * i as f32;
            world
                .spawn((
                    c,
                    Position::new(x, 0.3, 1.0 + 0.3 * i as f32),
                    Velocity::default(),
                ))
                .id()
        })
        .collect();

    let names = [
        "narrow_phase/bvh_nodes_visited",
        "narrow_phase/bv_tests",
        "narrow_phase/triangle_tests",
        "narrow_phase/mesh_pairs",
    ];
    // The most work of any step (once the bodies sleep, a step does none).
    let mut most = [0.0f64; 4];
    for second in 0..5 {
        for _ in 0..60 {
            urto::step(app.world_mut(), 1).unwrap();
            let stats = app.world().resource::<PhysicsStats>();
            for (m, name) in most.iter_mut().zip(names) {
                *m = m.max(stats.counter(name).unwrap_or(0.0));
            }
        }
        for (i, &b) in spawned.iter().enumerate() {
            let low = lowest_point(app.world(), b);
            assert!(low.is_finite(), "NaN after {second} s");
            assert!(
                low > -SINK_TOLERANCE,
                "body {i} sank to {low} after {} s",
                second + 1
            );
        }
    }
    let world = app.world();
    for (i, &b) in spawned.iter().enumerate() {
        let p = world.get::<Position>(b).unwrap().0;
        let v = world.get::<Velocity>(b).unwrap().0;
        let low = lowest_point(world, b);
        assert!(low < 0.02, "body {i} floats at {low}");
        assert!(v.length() < 0.2, "body {i} still moving at {v}");
        // Bodies turn: the scanned ant lands on a leg, tumbles and rolls about 0.9 m.
        let start = Vec3::new(-3.0 + 1.5 * i as f32, 0.3, p.z);
        assert!(p.distance(start) < 1.2, "body {i} went off to {p}");
        assert!(world.get::<Quarantined>(b).is_none());
    }
    for (value, name) in most.into_iter().zip(names) {
        assert!(value > 0.0, "{name} = {value}");
    }
}

/// Two meshes stacked: the upper one rests on the lower one, which rests on the floor. The
/// slab tilts a little on the bumps and the faceted ball rolls downhill on it (about 0.5 m/s
/// after 3 s, which takes it to the edge near 4 s): while it is over the slab, it must touch the
/// slab's top face, and it must still be over it after 3 s.
#[test]
fn a_mesh_ball_rolling_on_a_mesh_slab_touches_its_top_within_the_sink_tolerance_for_3_s() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    let bumpy = TriMesh::height_field(8.0, 32, |x, y| 0.05 * (x * 2.0).sin() * (y * 1.5).cos());
    world.spawn((Collider::trimesh(bumpy.unwrap()).unwrap(), Static));
    let slab = TriMesh::cuboid(Vec3::new(0.8, 0.8, 0.1)).unwrap();
    let lower = world
        .spawn((
            Collider::trimesh(slab).unwrap(),
            Position::new(0.0, 0.0, 0.4),
            Velocity::default(),
        ))
        .id();
    let ball = TriMesh::uv_sphere(0.3, 16, 8).unwrap();
    let upper = world
        .spawn((
            Collider::trimesh(ball).unwrap(),
            Position::new(0.1, -0.1, 1.2),
            Velocity::default(),
        ))
        .id();
    // Settle for 1 s, then look every 1/3 s.
    urto::step(app.world_mut(), 60).unwrap();
    for step in (80..=240).step_by(20) {
        urto::step(app.world_mut(), 20).unwrap();
        let world = app.world();
        // Both turn: measure in the slab's frame, the ball's lowest vertex against the slab's
        // top face, and where it lies on it.
        let slab = world.get::<GlobalPose>(lower).unwrap().pose();
        let ball_pose = world.get::<GlobalPose>(upper).unwrap().pose();
        let Shape::TriMesh(ball_mesh) = &world.get::<Collider>(upper).unwrap().shape else {
            unreachable!("a mesh ball")
        };
        let above_top =
            |v: Vec3| slab.inverse_transform_point(ball_pose.transform_point(v)).z - 0.1;
        let gap = ball_mesh
            .mesh()
            .vertices()
            .iter()
            .map(|&v| above_top(v))
            .fold(f32::INFINITY, f32::min);
        let centre = slab.inverse_transform_point(ball_pose.translation);
        assert!(
            lowest_point(world, lower) > -0.05 - SINK_TOLERANCE,
            "slab sank by step {step}"
        );
        let over_slab = centre.x.abs() < 0.75 && centre.y.abs() < 0.75;
        if over_slab {
            assert!(
                gap.abs() < SINK_TOLERANCE,
                "ball {gap} from the slab's top at step {step}"
            );
        }
        assert!(
            over_slab || step > 180,
            "ball off the slab at {centre}, step {step}"
        );
    }
}

#[test]
fn bad_mesh_input_is_an_error() {
    // Not a mesh format.
    let readme = Collider::from_mesh_file(asset("README.md")).unwrap_err();
    assert!(matches!(readme, MeshColliderError::Load(_)), "{readme}");
    // A missing file.
    assert!(Collider::from_mesh_file(asset("no_such_mesh.obj")).is_err());
    let dir = std::env::temp_dir().join(format!("urto-mesh-ecs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A PLY file that does not parse.
    let corrupt = dir.join("corrupt.ply");
    std::fs::write(
        &corrupt,
        b"ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n",
    )
    .unwrap();
    let err = Collider::from_mesh_file(&corrupt).unwrap_err();
    assert!(err.to_string().contains("mesh"), "{err}");
    // An OBJ file with vertices but no faces: an empty mesh.
    let empty = dir.join("empty.obj");
    std::fs::write(&empty, b"v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    assert!(Collider::from_mesh_file(&empty).is_err());
    // Empty and degenerate arrays.
    assert_eq!(TriMesh::new(vec![], vec![]), Err(MeshError::NoVertices));
    let collinear = vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
    assert!(matches!(
        TriMesh::new(collinear, vec![[0, 1, 2]]),
        Err(MeshError::AllTrianglesDegenerate { count: 1 })
    ));
    std::fs::remove_dir_all(&dir).ok();
}
