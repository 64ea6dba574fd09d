//! Criterion benchmarks of the time-of-impact queries, one group per obstacle kind, each over the
//! same seeded set of sweeps (a mix of hits and misses, as `tests/ccd_common` makes them), and
//! parry3d's `cast_shapes` on the same sweeps as the rival for the box and the mesh.
//! Times are per query (criterion's throughput is one element per sweep).
//!
//! A quick smoke run: `cargo bench --bench ccd -- --quick --warm-up-time 0.2 --measurement-time 0.5`.

#[path = "../tests/ccd_common/mod.rs"]
mod ccd_common;

use ccd_common::{Rng, random_sweep};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{Quat, Vec3};
use std::hint::black_box;
use urto::bounding::{Aabb, Obb};
use urto::bvh::{BuildOptions, Bvh, QueryScratch};
use urto::ccd::{
    DEFAULT_MAX_ADVANCEMENT_ITERATIONS, SphereSweep, toi_sphere_by_advancement, toi_sphere_cuboid,
    toi_sphere_halfspace, toi_sphere_sphere, toi_sphere_triangle, toi_sphere_trimesh,
    toi_spheres_moving,
};
use urto::geometry::{Cuboid, HalfSpace, Isometry, Sphere, TriMesh, Triangle};

/// Sweeps per benchmark iteration.
const SWEEPS: usize = 256;

fn sweeps(seed: u64, size: f32, target: Vec3) -> Vec<SphereSweep> {
    let mut rng = Rng::new(seed);
    (0..SWEEPS)
        .map(|_| random_sweep(&mut rng, size, target, None))
        .collect()
}

fn bench_primitives(c: &mut Criterion) {
    let mut group = c.benchmark_group("toi");
    group.throughput(Throughput::Elements(SWEEPS as u64));
    let pose = Isometry::new(Vec3::new(0.1, -0.2, 0.3), Quat::from_rotation_z(0.4));
    let set = sweeps(1, 1.0, pose.translation);

    let ground = HalfSpace { normal: Vec3::Z };
    group.bench_function("half_space", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| toi_sphere_halfspace(s, &pose, &ground))
                .count()
        })
    });
    let ball = Sphere { radius: 0.8 };
    group.bench_function("sphere", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| toi_sphere_sphere(s, pose.translation, &ball))
                .count()
        })
    });
    let others = sweeps(2, 1.0, pose.translation);
    group.bench_function("moving_spheres", |b| {
        b.iter(|| {
            set.iter()
                .zip(&others)
                .filter_map(|(a, o)| toi_spheres_moving(a, o))
                .count()
        })
    });
    let cuboid = Cuboid {
        half_extents: Vec3::new(1.0, 0.6, 0.8),
    };
    group.bench_function("cuboid", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| toi_sphere_cuboid(s, &pose, &cuboid))
                .count()
        })
    });
    let closest = |p: Vec3| {
        let local = pose.inverse_transform_point(p);
        pose.transform_point(local.clamp(-cuboid.half_extents, cuboid.half_extents))
    };
    group.bench_function("cuboid_by_advancement", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| {
                    toi_sphere_by_advancement(s, closest, DEFAULT_MAX_ADVANCEMENT_ITERATIONS)
                })
                .count()
        })
    });
    let tri = Triangle::new(
        Vec3::new(-1.0, -0.8, 0.2),
        Vec3::new(1.2, -0.5, -0.1),
        Vec3::new(0.1, 1.1, 0.4),
    );
    group.bench_function("triangle", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| toi_sphere_triangle(s, &tri))
                .count()
        })
    });

    let parry_pose = parry3d::math::Pose::from_parts(pose.translation, pose.rotation);
    let parry_box = parry3d::shape::Cuboid::new(cuboid.half_extents);
    group.bench_function("cuboid_parry3d", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| parry_cast(s, &parry_pose, &parry_box))
                .count()
        })
    });
    group.finish();
}

/// parry3d's sweep of a ball against a static shape, with the same touching convention.
fn parry_cast(
    sweep: &SphereSweep,
    pose: &parry3d::math::Pose,
    shape: &dyn parry3d::shape::Shape,
) -> Option<f32> {
    let ball = parry3d::shape::Ball::new(sweep.radius());
    let at = parry3d::math::Pose::from_translation(sweep.center());
    let options = parry3d::query::ShapeCastOptions::with_max_time_of_impact(1.0);
    parry3d::query::cast_shapes(
        &at,
        sweep.displacement(),
        &ball,
        pose,
        Vec3::ZERO,
        shape,
        options,
    )
    .ok()
    .flatten()
    .map(|hit| hit.time_of_impact)
}

fn bench_mesh(c: &mut Criterion) {
    let mut group = c.benchmark_group("toi_trimesh");
    group.throughput(Throughput::Elements(SWEEPS as u64));
    // A ~1k-triangle sphere, placed off the origin and turned.
    let mesh = TriMesh::uv_sphere(1.0, 32, 16).expect("mesh");
    let pose = Isometry::new(Vec3::new(0.4, 0.1, -0.3), Quat::from_rotation_y(0.7));
    let set = sweeps(3, 1.0, pose.translation);
    let options = BuildOptions::default();
    let aabb_tree = Bvh::<Aabb>::build(mesh.vertices(), mesh.triangles(), &options).expect("bvh");
    let obb_tree = Bvh::<Obb>::build(mesh.vertices(), mesh.triangles(), &options).expect("bvh");
    let mut scratch = QueryScratch::new();
    group.bench_function("aabb_bvh", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| toi_sphere_trimesh(s, &mesh, &aabb_tree, &pose, &mut scratch).0)
                .count()
        })
    });
    group.bench_function("obb_bvh", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| toi_sphere_trimesh(s, &mesh, &obb_tree, &pose, &mut scratch).0)
                .count()
        })
    });
    let parry_mesh =
        parry3d::shape::TriMesh::new(mesh.vertices().to_vec(), mesh.triangles().to_vec())
            .expect("parry mesh");
    let parry_pose = parry3d::math::Pose::from_parts(pose.translation, pose.rotation);
    group.bench_function("parry3d", |b| {
        b.iter(|| {
            set.iter()
                .filter_map(|s| parry_cast(s, &parry_pose, &parry_mesh))
                .count()
        })
    });
    group.finish();
    black_box(&scratch);
}

criterion_group!(benches, bench_primitives, bench_mesh);
criterion_main!(benches);
