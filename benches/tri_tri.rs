//! Triangle–triangle tests: urto's exact Guigue–Devillers against parry's GJK-based
//! `intersection_test`, on the same random pairs (about a quarter of them intersecting), and the
//! brute-force mesh–mesh reference on two real meshes.
//!
//! Quick run: `cargo bench --bench tri_tri -- --warm-up-time 0.5 --measurement-time 1`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Quat, Vec3};
use parry3d::math::{Pose, Vector};
use parry3d::shape::Triangle as PTriangle;
use std::hint::black_box;
use std::path::Path;
use urto::geometry::{Isometry, Triangle, mesh_io, tri_tri_intersect, tri_tri_intersection};

fn random_pairs(count: usize) -> Vec<(Triangle, Triangle)> {
    let mut seed = 0x5eed_u64;
    let mut unit = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    };
    let mut v = move || Vec3::new(unit(), unit(), unit());
    (0..count)
        .map(|_| {
            let t1 = Triangle::new(v(), v(), v());
            let offset = v() * 0.4;
            let t2 = Triangle::new(v() + offset, v() + offset, v() + offset);
            (t1, t2)
        })
        .collect()
}

fn to_parry(t: &Triangle) -> PTriangle {
    let p = |v: Vec3| Vector::new(v.x, v.y, v.z);
    PTriangle::new(p(t.a), p(t.b), p(t.c))
}

fn triangle_pairs(c: &mut Criterion) {
    let pairs = random_pairs(1024);
    let parry_pairs: Vec<_> = pairs
        .iter()
        .map(|(a, b)| (to_parry(a), to_parry(b)))
        .collect();
    let mut group = c.benchmark_group("tri_tri_1024_pairs");
    group.bench_function("urto_exact_yes_no", |b| {
        b.iter(|| {
            pairs
                .iter()
                .filter(|(t1, t2)| tri_tri_intersect(black_box(t1), black_box(t2)))
                .count()
        })
    });
    group.bench_function("urto_exact_segment", |b| {
        b.iter(|| {
            pairs
                .iter()
                .filter(|(t1, t2)| tri_tri_intersection(black_box(t1), black_box(t2)).intersects())
                .count()
        })
    });
    group.bench_function("parry_gjk_intersection_test", |b| {
        b.iter(|| {
            parry_pairs
                .iter()
                .filter(|(t1, t2)| {
                    parry3d::query::intersection_test(
                        &Pose::IDENTITY,
                        black_box(t1),
                        &Pose::IDENTITY,
                        black_box(t2),
                    )
                    .is_ok_and(|r| r.intersecting)
                })
                .count()
        })
    });
    group.finish();
}

fn mesh_brute_force(c: &mut Criterion) {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let (Ok(ant), Ok(nut)) = (
        mesh_io::load(data.join("ant.ply")),
        mesh_io::load(data.join("nut.ply")),
    ) else {
        return;
    };
    // The nut's box centre on an ant vertex: the meshes cross.
    let pose = Isometry::new(
        ant.vertices()[100] - nut.local_aabb().center(),
        Quat::IDENTITY,
    );
    c.bench_function("brute_force_pairs_ant_912_nut_1046", |b| {
        b.iter(|| {
            ant.intersecting_pairs_brute_force(black_box(&nut), black_box(&pose))
                .len()
        })
    });
}

criterion_group!(benches, triangle_pairs, mesh_brute_force);
criterion_main!(benches);
