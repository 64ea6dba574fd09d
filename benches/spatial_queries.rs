//! Criterion benchmarks of the spatial queries against parry3d's BVH (the tree under rapier's
//! query pipeline) on the same scene: 10,000 balls and turned boxes in a 100 m cube.
//!
//! - `ray_first_hit`: 1,000 rays, each the nearest hit (urto's box tree and exact casts; parry's
//!   `Bvh::cast_ray` with each shape's `cast_ray` as the leaf test);
//! - `sphere_overlap`: 1,000 balls of radius 2 m, each every collider it touches (urto's
//!   `overlapping`; parry's `intersect_aabb` and `intersection_test`);
//! - `build` and `refit` of the tree over the 10,000 boxes (parry's refit is its leaf updates
//!   and `refit`, as rapier does each step);
//! - `churn_10k`: the same with one collider despawned and one spawned each step (urto keeps
//!   its tree: the new one in a small tree, the gone one retired; parry removes and inserts).
//!
//! Before timing, the answers are compared and printed: the same first hits, the same overlaps.
//! (Hits more than 1 mm apart are rays grazing a ball 40–90 m away, where the chord is nearly
//! zero and the 5e-8 by which an f32 unit direction misses length 1 moves the hit by
//! millimetres in either engine.)
//! A quick run: `cargo bench --bench spatial_queries -- --quick`.

#[allow(dead_code)]
#[path = "../tests/common/rng.rs"]
mod rng;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use parry3d::bounding_volume::Aabb as ParryAabb;
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};
use parry3d::shape::{Ball, Cuboid, SharedShape};
use rng::Rng;
use std::hint::black_box;
use urto::geometry::{Isometry, Shape};
use urto::spatial::{Ray, SpatialIndex, StableIds};

const COLLIDERS: usize = 10_000;
const QUERIES: usize = 1_000;

struct Scene {
    ours: Vec<(Shape, Isometry)>,
    theirs: Vec<(SharedShape, parry3d::math::Pose)>,
}

fn scene() -> Scene {
    let mut rng = Rng::new(7);
    let mut scene = Scene {
        ours: Vec::new(),
        theirs: Vec::new(),
    };
    for i in 0..COLLIDERS {
        let pose = Isometry::new(rng.in_ball(50.0), rng.rotation());
        let at = parry3d::math::Pose::from_parts(pose.translation, pose.rotation);
        if i % 2 == 0 {
            let r = rng.range(0.2, 1.0);
            scene.ours.push((Shape::sphere(r), pose));
            scene.theirs.push((SharedShape::new(Ball::new(r)), at));
        } else {
            let h = Vec3::new(
                rng.range(0.1, 1.0),
                rng.range(0.1, 1.0),
                rng.range(0.1, 1.0),
            );
            scene.ours.push((Shape::cuboid(h), pose));
            scene.theirs.push((SharedShape::new(Cuboid::new(h)), at));
        }
    }
    scene
}

fn rays() -> Vec<Ray> {
    let mut rng = Rng::new(8);
    (0..QUERIES)
        .map(|_| {
            let origin = rng.in_ball(60.0);
            Ray::new(origin, rng.in_ball(40.0) - origin).unwrap()
        })
        .collect()
}

fn ours_indexed(scene: &Scene) -> SpatialIndex {
    let mut index = SpatialIndex::default();
    index.update(
        scene
            .ours
            .iter()
            .enumerate()
            .map(|(i, (s, p))| (i as u32, s, *p)),
    );
    index
}

fn parry_aabbs(scene: &Scene) -> Vec<ParryAabb> {
    scene
        .theirs
        .iter()
        .map(|(s, p)| s.compute_aabb(p))
        .collect()
}

fn parry_first_hit(bvh: &Bvh, scene: &Scene, ray: &Ray) -> Option<(u32, f32)> {
    let r = parry3d::query::Ray::new(ray.origin(), ray.direction());
    bvh.cast_ray(&r, 1.0e3, |i, best| {
        let (shape, pose) = &scene.theirs[i as usize];
        shape.cast_ray(pose, &r, best, true)
    })
}

fn parry_overlaps(bvh: &Bvh, scene: &Scene, centre: Vec3, out: &mut Vec<u32>) {
    out.clear();
    let ball = Ball::new(2.0);
    let at = parry3d::math::Pose::from_translation(centre);
    let aabb = ParryAabb::new(centre - Vec3::splat(2.0), centre + Vec3::splat(2.0));
    for i in bvh.intersect_aabb(&aabb) {
        let (shape, pose) = &scene.theirs[i as usize];
        if parry3d::query::intersection_test(&at, &ball, pose, shape.as_ref())
            .is_ok_and(|hit| hit.intersecting)
        {
            out.push(i);
        }
    }
    out.sort_unstable();
}

/// Prints how often both engines agree, so the timings compare the same work.
fn check(scene: &Scene, rays: &[Ray]) {
    let mut ours = ours_indexed(scene);
    let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &parry_aabbs(scene));
    let (mut same, mut same_collider, mut hits) = (0, 0, 0);
    for ray in rays {
        let a = ours.cast_ray(&*scene.ours, ray, 1.0e3, |_| true).unwrap();
        let b = parry_first_hit(&bvh, scene, ray);
        hits += usize::from(a.is_some());
        let (collider, distance) = match (a, b) {
            (Some(a), Some((id, t))) => (a.id == id, (a.hit.distance - t).abs() < 1e-3),
            (None, None) => (true, true),
            _ => (false, false),
        };
        same_collider += usize::from(collider);
        same += usize::from(collider && distance);
    }
    let (mut same_sets, mut found) = (0, 0);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for ray in rays {
        let centre = ray.origin() * 0.5;
        let ball = Shape::sphere(2.0);
        ours.overlapping(
            &*scene.ours,
            (&ball, &Isometry::from_translation(centre)),
            |_| true,
            &mut a,
        );
        parry_overlaps(&bvh, scene, centre, &mut b);
        same_sets += usize::from(a == b);
        found += a.len();
    }
    println!(
        "spatial_queries check: first hits on the same collider for {same_collider} of {} rays \
         ({hits} hit), within 1 mm for {same}; overlap sets agree on {same_sets} of {} balls \
         ({found} colliders found)",
        rays.len(),
        rays.len()
    );
}

fn bench(c: &mut Criterion) {
    let scene = scene();
    let rays = rays();
    check(&scene, &rays);
    let mut ours = ours_indexed(&scene);
    let aabbs = parry_aabbs(&scene);
    let mut bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);

    let mut group = c.benchmark_group("ray_first_hit");
    group.throughput(Throughput::Elements(QUERIES as u64));
    group.bench_function("urto", |b| {
        b.iter(|| {
            for ray in &rays {
                black_box(ours.cast_ray(&*scene.ours, ray, 1.0e3, |_| true).unwrap());
            }
        })
    });
    group.bench_function("parry3d", |b| {
        b.iter(|| {
            for ray in &rays {
                black_box(parry_first_hit(&bvh, &scene, ray));
            }
        })
    });
    group.finish();

    let mut group = c.benchmark_group("sphere_overlap");
    group.throughput(Throughput::Elements(QUERIES as u64));
    let mut out = Vec::new();
    let ball = Shape::sphere(2.0);
    group.bench_function("urto", |b| {
        b.iter(|| {
            for ray in &rays {
                let at = Isometry::from_translation(ray.origin() * 0.5);
                ours.overlapping(&*scene.ours, (&ball, &at), |_| true, &mut out);
                black_box(&out);
            }
        })
    });
    group.bench_function("parry3d", |b| {
        b.iter(|| {
            for ray in &rays {
                parry_overlaps(&bvh, &scene, ray.origin() * 0.5, &mut out);
                black_box(&out);
            }
        })
    });
    group.finish();

    let mut group = c.benchmark_group("tree_10k");
    let items = || {
        scene
            .ours
            .iter()
            .enumerate()
            .map(|(i, (s, p))| (i as u32, s, *p))
    };
    group.bench_function("urto_build", |b| {
        b.iter(|| {
            let mut fresh = SpatialIndex::default();
            black_box(fresh.update(items()));
        })
    });
    group.bench_function("parry3d_build", |b| {
        b.iter(|| black_box(Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs)))
    });
    group.bench_function("urto_refit", |b| b.iter(|| black_box(ours.update(items()))));
    let mut workspace = BvhWorkspace::default();
    group.bench_function("parry3d_refit", |b| {
        b.iter(|| {
            for (i, (shape, pose)) in scene.theirs.iter().enumerate() {
                bvh.insert_or_update_partially(shape.compute_aabb(pose), i as u32, 0.0);
            }
            bvh.refit(&mut workspace);
        })
    });
    group.finish();
    churn(c, &scene, &aabbs);
}

/// A step of a game that despawns one collider and spawns one elsewhere (a bullet): the
/// index takes every box again in the order an ECS table gives after a swap-remove and a
/// spawn, with ids from [`StableIds`] as the ECS gives them (the new collider a new key).
/// parry's tree as rapier's broad phase keeps it: leaves updated, one removed, one inserted
/// (its index reused), refitted. The rebuild this replaces is `tree_10k/urto_build`.
fn churn(c: &mut Criterion, scene: &Scene, aabbs: &[ParryAabb]) {
    let mut group = c.benchmark_group("churn_10k");
    let mut rng = Rng::new(9);
    let spawns: Vec<Isometry> = (0..997)
        .map(|_| Isometry::new(rng.in_ball(50.0), rng.rotation()))
        .collect();
    // Scene slots in table order, each slot's current key and pose.
    let mut order: Vec<usize> = (0..COLLIDERS).collect();
    let mut keys: Vec<u64> = (0..COLLIDERS as u64).collect();
    let mut poses: Vec<Isometry> = scene.ours.iter().map(|(_, p)| *p).collect();
    let (mut ids, mut ours) = (StableIds::default(), SpatialIndex::default());
    let mut step = 0usize;
    group.bench_function("urto_one_replaced", |b| {
        b.iter(|| {
            step += 1;
            let slot = order.swap_remove((step * 7919) % COLLIDERS);
            order.push(slot);
            keys[slot] = (COLLIDERS + step) as u64;
            poses[slot] = spawns[step % spawns.len()];
            ids.begin();
            let items = order
                .iter()
                .map(|&i| (ids.id(keys[i]), &scene.ours[i].0, poses[i]));
            black_box(ours.update(items));
            ids.finish();
        })
    });
    let mut bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, aabbs);
    let mut workspace = BvhWorkspace::default();
    let mut poses: Vec<_> = scene.theirs.iter().map(|(_, p)| *p).collect();
    group.bench_function("parry3d_one_replaced", |b| {
        b.iter(|| {
            step += 1;
            let slot = (step * 7919) % COLLIDERS;
            bvh.remove(slot as u32);
            let at = spawns[step % spawns.len()];
            poses[slot] = parry3d::math::Pose::from_parts(at.translation, at.rotation);
            for (i, ((shape, _), pose)) in scene.theirs.iter().zip(&poses).enumerate() {
                bvh.insert_or_update_partially(shape.compute_aabb(pose), i as u32, 0.0);
            }
            bvh.refit(&mut workspace);
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
