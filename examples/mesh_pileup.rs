//! Triangle meshes and convex shapes piling up on a mesh floor: the ant and the nut loaded from
//! `examples/assets/` (PLY files from PyVista's example data, MIT licence, see
//! `examples/assets/LICENSE-pyvista.txt`) and a procedural torus as triangle meshes (none of
//! them convex), next to the convex shapes a game would use for props: the ant's convex hull, a
//! capsule and a box, dropped in columns onto a gently bumpy height-field floor. Mesh contacts
//! go through the meshes' OBB hierarchies (triangle pairs within the contact margin); convex
//! pairs through GJK and EPA or closed forms, and convex bodies meet the floor triangle by
//! triangle with its internal edges removed. The recording shows the bodies, the first levels
//! of each hierarchy, and the leaves through which meshes touch.
//!
//! ```text
//! cargo run --release --example mesh_pileup -- --help
//! rerun mesh_pileup.rrd
//! ```
//!
//! Bodies tumble and rub with the default friction; a 1 cm lever arm against rolling lets them
//! come to rest, and the floor is a shallow bowl so that nothing rolls off its edge.

use bevy_app::App;
use clap::Parser;
use std::error::Error;
use std::path::{Path, PathBuf};
use std::time::Instant;
use urto::debug::{RerunConfig, RerunDebugPlugin};
use urto::geometry::{MeshCollider, Shape, TriMesh};
use urto::prelude::*;

/// Meshes dropped on a mesh floor, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Number of falling bodies.
    #[arg(long, default_value_t = 27)]
    bodies: u32,
    /// Physics steps to simulate (60 per simulated second).
    #[arg(long, default_value_t = 480)]
    steps: u32,
    /// Where to write the recording.
    #[arg(long, default_value = "mesh_pileup.rrd")]
    out: PathBuf,
    /// Record every k-th step.
    #[arg(long, default_value_t = 1)]
    every: u64,
    /// Hierarchy levels drawn per mesh (0: none).
    #[arg(long, default_value_t = 4)]
    bvh_levels: u32,
    /// Open the viewer on the last recorded step (for screenshots).
    #[arg(long)]
    open_at_end: bool,
}

/// A mesh moved so its box is centred on the origin and scaled so its largest side is `size`.
fn normalized(mesh: TriMesh, size: f32) -> Result<TriMesh, Box<dyn Error>> {
    let b = mesh.local_aabb();
    let scale = size / b.extents().max_element();
    let vertices = mesh
        .vertices()
        .iter()
        .map(|v| (*v - b.center()) * scale)
        .collect();
    Ok(TriMesh::new(vertices, mesh.triangles().to_vec())?)
}

/// The shapes that fall, each built once and shared by all the bodies using it: three
/// triangle meshes, then three convex shapes.
fn body_shapes() -> Result<Vec<Collider>, Box<dyn Error>> {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assets");
    let load = |name: &str, size: f32| -> Result<MeshCollider, Box<dyn Error>> {
        let mesh = urto::geometry::mesh_io::load(assets.join(format!("{name}.ply")))?;
        Ok(MeshCollider::named(name, normalized(mesh, size)?)?)
    };
    let ant = load("ant", 0.9)?;
    let ant_hull = Collider::convex_hull(ant.mesh().vertices())?;
    Ok(vec![
        Collider::mesh(ant),
        Collider::mesh(load("nut", 0.7)?),
        Collider::mesh(MeshCollider::named(
            "torus",
            TriMesh::torus(0.35, 0.12, 32, 12)?,
        )?),
        ant_hull,
        Collider::capsule(0.25, 0.15),
        Collider::cuboid(0.4, 0.3, 0.2),
    ])
}

/// The floor's height: gentle bumps in a shallow bowl (the bowl keeps frictionless bodies from
/// sliding off the edge).
fn floor_height(x: f32, y: f32) -> f32 {
    0.08 * (0.9 * x).sin() * (0.7 * y).cos() + 0.012 * (x * x + y * y)
}

/// The floor mesh, static.
fn floor() -> Result<MeshCollider, Box<dyn Error>> {
    Ok(MeshCollider::named(
        "floor",
        TriMesh::height_field(14.0, 56, floor_height)?,
    )?)
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let recording = RerunDebugPlugin::new(RerunConfig {
        app_id: "urto mesh_pileup".into(),
        every_k_steps: args.every,
        bvh_levels: args.bvh_levels,
        overlapping_leaves: true,
        velocities: false,
        open_at_end: args.open_at_end,
        ..RerunConfig::file(&args.out)
    })?;

    let mut app = App::new();
    app.add_plugins(UrtoPlugins::default())
        .add_plugins(recording)
        .insert_resource(Gravity::EARTH_Z_UP)
        .insert_resource(ContactSettings {
            default_restitution: 0.2,
            ..Default::default()
        });
    let world = app.world_mut();
    let floor_body = world.spawn((Collider::mesh(floor()?), Static)).id();
    let shapes = body_shapes()?;
    // Columns on a 3 × 3 grid; each new body of a column falls from higher up, a little off the
    // column's axis so the pile does not stack perfectly.
    let mut bodies = Vec::new();
    for i in 0..args.bodies {
        let (column, level) = (i % 9, i / 9);
        let (cx, cy) = ((column % 3) as f32 - 1.0, (column / 3) as f32 - 1.0);
        let wobble = 0.15 * ((i * 7 % 5) as f32 - 2.0) / 2.0;
        let collider = shapes[i as usize % shapes.len()].clone();
        let position = Position::new(
            1.1 * cx + wobble,
            1.1 * cy - wobble,
            1.0 + 1.1 * level as f32 + 0.2 * column as f32,
        );
        bodies.push(
            world
                .spawn((
                    collider,
                    position,
                    Velocity::default(),
                    RollingResistance(0.01),
                ))
                .id(),
        );
    }

    let start = Instant::now();
    let (mut physics_time, mut contacts, mut work) = (0.0, 0.0, [0.0f64; 3]);
    let mut per_stage = [0.0f64; Stage::ALL.len()];
    for _ in 0..args.steps {
        urto::step(app.world_mut(), 1)?;
        let stats = app.world().resource::<PhysicsStats>();
        for (total, stage) in per_stage.iter_mut().zip(Stage::ALL) {
            *total += stats.stage_time(stage).as_secs_f64();
        }
        physics_time += Stage::ALL
            .iter()
            .filter(|s| **s != Stage::Debug)
            .map(|s| stats.stage_time(*s).as_secs_f64())
            .sum::<f64>();
        contacts += stats.counter("narrow_phase/contacts").unwrap_or(0.0);
        for (total, name) in work.iter_mut().zip([
            "narrow_phase/bvh_nodes_visited",
            "narrow_phase/bv_tests",
            "narrow_phase/triangle_tests",
        ]) {
            *total += stats.counter(name).unwrap_or(0.0);
        }
    }
    let wall = start.elapsed().as_secs_f64();

    let world = app.world();
    let stats = world.resource::<PhysicsStats>();
    let meshes: Vec<_> = shapes
        .iter()
        .filter_map(|c| match &c.shape {
            Shape::TriMesh(m) => Some(m.mesh().triangle_count()),
            _ => None,
        })
        .collect();
    println!(
        "mesh_pileup: {} bodies ({} distinct meshes of {} triangles, {} convex shapes) on a {}-triangle floor, {} steps ({:.1} s simulated)",
        args.bodies,
        meshes.len(),
        meshes.iter().sum::<usize>(),
        shapes.len() - meshes.len(),
        floor()?.mesh().triangle_count(),
        stats.step,
        stats.sim_time
    );
    println!(
        "  time per step: {:.1} µs physics, {:.1} µs with recording",
        physics_time / args.steps as f64 * 1e6,
        wall / args.steps as f64 * 1e6
    );
    let breakdown: Vec<String> = Stage::ALL
        .iter()
        .zip(per_stage)
        .filter(|(s, _)| **s != Stage::Debug)
        .map(|(s, t)| format!("{} {:.0}", s.name(), t / args.steps as f64 * 1e6))
        .collect();
    println!("  per stage (µs): {}", breakdown.join(", "));
    println!(
        "  contacts: {:.1} per step on average, {} in the last step",
        contacts / args.steps as f64,
        stats.counter("narrow_phase/contacts").unwrap_or(0.0)
    );
    println!(
        "  BVH work over the run: Nv {:.0} nodes visited, Nn {:.0} BV tests, Ns {:.0} triangle tests",
        work[0], work[1], work[2]
    );
    // Where the bodies ended: how far any vertex got below the floor surface, how fast the
    // fastest body still moves, and whether anything went NaN.
    let (mut sunk, mut fastest, mut bad, mut asleep) = (0.0f32, 0.0f32, 0, 0);
    for &b in &bodies {
        let (Some(p), Some(v), Some(c), Some(pose)) = (
            world.get::<Position>(b),
            world.get::<Velocity>(b),
            world.get::<Collider>(b),
            world.get::<GlobalPose>(b),
        ) else {
            continue;
        };
        if let Shape::TriMesh(m) = &c.shape {
            for v in m.mesh().vertices() {
                let w = pose.pose().transform_point(*v);
                sunk = sunk.max(floor_height(w.x, w.y) - w.z);
            }
        }
        fastest = fastest.max(v.0.length());
        asleep += usize::from(world.get::<Sleeping>(b).is_some());
        bad += usize::from(!p.0.is_finite() || world.get::<Quarantined>(b).is_some());
    }
    // Convex bodies: the deepest of their contacts with the floor in the last step.
    let floor_depth = world
        .resource::<urto::plugins::Contacts>()
        .pairs
        .iter()
        .filter(|c| c.a == floor_body || c.b == floor_body)
        .map(|c| c.manifold.max_depth())
        .fold(0.0f32, f32::max);
    println!(
        "  at the end: deepest mesh vertex {:.1} mm below the floor, deepest floor contact {:.1} mm, fastest body {fastest:.2} m/s, {asleep} of {} asleep, {bad} NaN or quarantined",
        sunk * 1e3,
        floor_depth * 1e3,
        bodies.len()
    );
    println!(
        "  recording: {}  (open it with `rerun {}`)",
        args.out.display(),
        args.out.display()
    );
    Ok(())
}
