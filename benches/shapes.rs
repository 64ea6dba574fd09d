//! Issue 14's shape benchmarks against parry3d 0.31 on the same inputs: building a convex hull
//! from a point cloud, and convex shapes against a triangle mesh.
//!
//! - `hull_build`: urto's quickhull with coplanar faces merged (`Shape::convex_hull`) against
//!   parry's `ConvexPolyhedron::from_convex_hull` (its quickhull, then the polyhedron's faces
//!   and adjacency), for 16 points in a box (the hulls of the `contacts` bench), 100 and 1,000
//!   in a ball, 1,000 on a sphere (every point a corner) and 10,000 in a ball.
//! - `convex_mesh`: a ball, a box, a capsule, a cylinder and a 16-point hull, 256 poses each
//!   on and just above a bumpy terrain of 3,200 triangles (half of them touching it). urto's
//!   `contact_with_scratch` (the hierarchy's candidates, each triangle's contact with its
//!   internal edges removed, the points reduced to a manifold); parry's contact-manifold
//!   dispatcher on a `TriMesh` built with `FIX_INTERNAL_EDGES_TWO_SIDED` (the same work: ghost
//!   edges removed, the triangles two-sided as urto's), each call from an empty workspace as a new pair has. Neither engine's
//!   frame-to-frame cache is used (urto's pair cache sits in the narrow phase, above this call).
//!
//! - `ray_convex`: 256 rays at a cylinder, a cone, a 16-point hull and an ellipsoid (parry has
//!   none), first hit with its normal: urto's closed forms against parry's
//!   `cast_ray_and_get_normal`.
//!
//! Before timing, the pairs found touching (the rays hitting) are counted for both and printed.
//! A quick run: `cargo bench --bench shapes -- --quick`.

#[allow(dead_code)]
#[path = "../tests/common/rng.rs"]
mod rng;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use parry3d::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::{ConvexPolyhedron, SharedShape, TriMeshFlags};
use rng::Rng;
use std::hint::black_box;
use urto::geometry::contacts::{ContactScratch, contact_with_scratch};
use urto::geometry::{Isometry, MeshCollider, Shape, TriMesh};

/// The point clouds of `hull_build`: a name and the points.
fn clouds() -> Vec<(&'static str, Vec<Vec3>)> {
    let mut r = Rng::new(14);
    let in_ball = |r: &mut Rng, n: usize| (0..n).map(|_| r.in_ball(1.0)).collect::<Vec<_>>();
    let box16 = {
        let half = r.vec3(0.2, 1.0);
        (0..16).map(|_| r.vec3(-1.0, 1.0) * half).collect()
    };
    let ball100 = in_ball(&mut r, 100);
    let ball1k = in_ball(&mut r, 1_000);
    let sphere1k = (0..1_000).map(|_| r.direction()).collect();
    let ball10k = in_ball(&mut r, 10_000);
    vec![
        ("16 in a box", box16),
        ("100 in a ball", ball100),
        ("1000 in a ball", ball1k),
        ("1000 on a sphere", sphere1k),
        ("10000 in a ball", ball10k),
    ]
}

fn hull_build(c: &mut Criterion) {
    let mut group = c.benchmark_group("hull_build");
    for (name, points) in clouds() {
        let ours = Shape::convex_hull(&points).expect("a solid cloud");
        let theirs = ConvexPolyhedron::from_convex_hull(&points).expect("a solid cloud");
        let Shape::ConvexHull(hull) = &ours else {
            unreachable!()
        };
        eprintln!(
            "{name}: urto {} corners, {} faces; parry {} corners, {} faces",
            hull.vertices().len(),
            hull.faces().len(),
            theirs.points().len(),
            theirs.faces().len()
        );
        group.bench_function(format!("{name}: urto"), |b| {
            b.iter(|| Shape::convex_hull(black_box(&points)))
        });
        group.bench_function(format!("{name}: parry"), |b| {
            b.iter(|| ConvexPolyhedron::from_convex_hull(black_box(&points)))
        });
    }
    group.finish();
}

/// The terrain's height at `(x, y)`: bumps 0.3 m high, 6 m apart.
fn height(x: f32, y: f32) -> f32 {
    0.3 * x.sin() * y.cos()
}

/// A 20 m terrain of 40 × 40 cells (3,200 triangles), and the same for parry.
fn terrain() -> (Shape, SharedShape) {
    let mesh = TriMesh::height_field(20.0, 40, height).expect("a valid terrain");
    let theirs = parry3d::shape::TriMesh::with_flags(
        mesh.vertices().to_vec(),
        mesh.triangles().to_vec(),
        TriMeshFlags::FIX_INTERNAL_EDGES_TWO_SIDED,
    )
    .expect("a valid terrain");
    let ours = Shape::TriMesh(MeshCollider::new(mesh).expect("a valid terrain"));
    (ours, SharedShape::new(theirs))
}

/// The convex shapes of `convex_mesh`: a name, urto's shape and parry's.
fn convex_shapes() -> Vec<(&'static str, Shape, SharedShape)> {
    let mut r = Rng::new(41);
    let points: Vec<Vec3> = (0..16).map(|_| r.vec3(-0.5, 0.5)).collect();
    let hull_points: Vec<_> = match Shape::convex_hull(&points) {
        Ok(Shape::ConvexHull(h)) => h.vertices().to_vec(),
        _ => unreachable!("16 random points are a solid"),
    };
    let half = Vec3::new(0.5, 0.3, 0.4);
    vec![
        ("ball", Shape::sphere(0.5), SharedShape::ball(0.5)),
        (
            "box",
            Shape::cuboid(half),
            SharedShape::cuboid(half.x, half.y, half.z),
        ),
        (
            "capsule",
            Shape::capsule(0.5, 0.3),
            SharedShape::capsule_z(0.5, 0.3),
        ),
        (
            "cylinder",
            Shape::cylinder(0.4, 0.4),
            SharedShape::cylinder(0.4, 0.4),
        ),
        (
            "hull",
            Shape::convex_hull(&hull_points).expect("a solid"),
            SharedShape::convex_hull(&hull_points).expect("a solid"),
        ),
    ]
}

/// Poses over the terrain: anywhere on it, turned at random, the centre from 0.4 m below the
/// surface to 0.8 m above it (the shapes reach 0.5–0.8 m from their centres).
fn poses_over_terrain() -> Vec<Isometry> {
    let mut r = Rng::new(7);
    (0..256)
        .map(|_| {
            let (x, y) = (r.range(-9.0, 9.0), r.range(-9.0, 9.0));
            let z = height(x, y) + r.range(-0.4, 0.8);
            Isometry::new(Vec3::new(x, y, z), r.rotation())
        })
        .collect()
}

fn convex_mesh(c: &mut Criterion) {
    let (mesh, parry_mesh) = terrain();
    let poses = poses_over_terrain();
    let parry_poses: Vec<_> = poses
        .iter()
        .map(|p| parry3d::math::Pose::from_parts(p.translation, p.rotation))
        .collect();
    let dispatcher = DefaultQueryDispatcher;
    let mut group = c.benchmark_group("convex_mesh");
    for (name, shape, theirs) in convex_shapes() {
        let mut scratch = ContactScratch::new();
        let ours = |pose: &Isometry, scratch: &mut ContactScratch| {
            contact_with_scratch(&mesh, &Isometry::IDENTITY, &shape, pose, scratch)
        };
        let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
        let mut parry = |pose: &parry3d::math::Pose| {
            manifolds.clear();
            let mut workspace = None;
            let _ = dispatcher.contact_manifolds(
                pose,
                &*parry_mesh.0,
                &*theirs.0,
                0.0,
                &mut manifolds,
                &mut workspace,
            );
            manifolds.iter().any(|m| !m.points.is_empty())
        };
        let urto_touching = poses
            .iter()
            .filter(|p| ours(p, &mut scratch).is_some())
            .count();
        let parry_touching = parry_poses.iter().filter(|p| parry(p)).count();
        eprintln!(
            "{name} on the terrain: touching in {urto_touching} (urto) and {parry_touching} \
             (parry) of {} poses",
            poses.len()
        );
        group.bench_function(format!("{name}: urto"), |b| {
            b.iter(|| {
                for pose in &poses {
                    black_box(ours(pose, &mut scratch));
                }
            })
        });
        group.bench_function(format!("{name}: parry"), |b| {
            b.iter(|| {
                for pose in &parry_poses {
                    black_box(parry(pose));
                }
            })
        });
    }
    group.finish();
}

/// The shapes of `ray_convex`: a name, urto's shape and parry's (`None`: parry has none), and
/// the turn that puts parry's shape where urto's is (parry's cylinders and cones run along y).
fn ray_targets() -> Vec<(&'static str, Shape, Option<SharedShape>, glam::Quat)> {
    let mut r = Rng::new(43);
    let points: Vec<Vec3> = (0..16).map(|_| r.vec3(-0.5, 0.5)).collect();
    let along_z = glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    vec![
        (
            "cylinder",
            Shape::cylinder(0.4, 0.3),
            Some(SharedShape::cylinder(0.4, 0.3)),
            along_z,
        ),
        (
            "cone",
            Shape::cone(0.4, 0.3),
            Some(SharedShape::cone(0.4, 0.3)),
            along_z,
        ),
        (
            "hull",
            Shape::convex_hull(&points).expect("a solid"),
            SharedShape::convex_hull(&points),
            glam::Quat::IDENTITY,
        ),
        (
            "ellipsoid",
            Shape::ellipsoid(Vec3::new(0.5, 0.3, 0.2)),
            None,
            glam::Quat::IDENTITY,
        ),
    ]
}

/// Ray casts at convex shapes (first hit, distance and normal): 256 rays from 2–10 m away
/// aimed within 0.5 m of a turned shape's centre, urto's `cast_sphere` with radius 0 (closed
/// forms, `spatial/ray_convex.rs`) against parry's `cast_ray_and_get_normal` (solid).
fn ray_convex(c: &mut Criterion) {
    use parry3d::query::Ray as ParryRay;
    use urto::bvh::QueryScratch;
    use urto::spatial::{Ray, cast_sphere};
    let mut r = Rng::new(47);
    let pose = Isometry::new(Vec3::new(0.3, -0.2, 0.1), r.rotation());
    let rays: Vec<Ray> = (0..256)
        .map(|_| {
            let aim = pose.translation + r.vec3(-0.5, 0.5);
            let from = aim + r.direction() * r.range(2.0, 10.0);
            Ray::new(from, aim - from).expect("a direction")
        })
        .collect();
    let mut group = c.benchmark_group("ray_convex");
    for (name, shape, theirs, turn) in ray_targets() {
        let aabb = shape.world_aabb(&pose);
        let mut scratch = QueryScratch::new();
        let mut ours =
            |ray: &Ray| cast_sphere(ray, 0.0, 20.0, (&shape, &pose, &aabb), &mut scratch);
        let parry_pose = parry3d::math::Pose::from_parts(pose.translation, pose.rotation * turn);
        let parry_rays: Vec<_> = rays
            .iter()
            .map(|ray| ParryRay::new(ray.origin(), ray.direction()))
            .collect();
        let hits: Vec<_> = rays
            .iter()
            .map(|ray| ours(ray).map(|h| h.distance))
            .collect();
        if let Some(theirs) = &theirs {
            let parry =
                |ray: &ParryRay| theirs.cast_ray_and_get_normal(&parry_pose, ray, 20.0, true);
            let (mut same, mut worst) = (0, 0.0f32);
            for (ours, ray) in hits.iter().zip(&parry_rays) {
                let theirs = parry(ray).map(|h| h.time_of_impact);
                same += usize::from(ours.is_some() == theirs.is_some());
                if let (Some(a), Some(b)) = (ours, theirs) {
                    worst = worst.max((a - b).abs());
                }
            }
            eprintln!(
                "rays at a {name}: {} of {} hit (urto); urto and parry agree on hit or miss for \
                 {same}, distances within {worst:.1e} m",
                hits.iter().flatten().count(),
                rays.len()
            );
        }
        group.bench_function(format!("{name}: urto"), |b| {
            b.iter(|| {
                for ray in &rays {
                    black_box(ours(ray));
                }
            })
        });
        if let Some(theirs) = theirs {
            group.bench_function(format!("{name}: parry"), |b| {
                b.iter(|| {
                    for ray in &parry_rays {
                        black_box(theirs.cast_ray_and_get_normal(&parry_pose, ray, 20.0, true));
                    }
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, hull_build, convex_mesh, ray_convex);
criterion_main!(benches);
