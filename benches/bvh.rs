//! Criterion benchmarks of the hierarchies: build (per BV kind × build rule) and pair queries
//! (per BV kind × build rule × traversal order, early-out and enumerate-all) on two tori of
//! about 1k, 20k and 200k triangles each, with parry3d's `TriMesh` build and
//! `intersection_test` on the same meshes and placements as the rival.
//!
//! Sizes: `URTO_BVH_BENCH_SIZES`, a comma-separated subset of `1k,20k,200k` (default: all).
//! A quick smoke run: `URTO_BVH_BENCH_SIZES=1k cargo bench --bench bvh -- --quick`
//! (criterion's `--quick`; a filter such as `query_early/obb` narrows further). The full set is
//! several hundred benchmarks: expect tens of minutes with the default criterion settings.

#[path = "../tests/common/mod.rs"]
mod common;

use common::meshes::torus_pair;
use common::{Mesh, placements, posed_leaf_test};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use urto::bounding::{Aabb, BoundingSphere, Bv, Kdop14, Kdop18, Kdop26, Obb};
use urto::bvh::{BuildOptions, BuildRule, Bvh, QueryScratch, TraversalOrder};
use urto::geometry::Isometry;

/// Placements per query benchmark iteration (the same seeded set for every contender).
const PLACEMENTS: usize = 16;

const RULES: [BuildRule; 2] = [BuildRule::Median, BuildRule::BinnedSah];
const ORDERS: [TraversalOrder; 3] = [
    TraversalOrder::DepthFirst,
    TraversalOrder::BreadthFirst,
    TraversalOrder::Priority,
];

/// A benchmark scene: two tori of about `n` triangles and placements of B near A.
struct Scene {
    label: &'static str,
    a: Mesh,
    b: Mesh,
    poses: Vec<Isometry>,
}

fn scene(label: &'static str, n: usize) -> Scene {
    let (a, b) = torus_pair(n);
    let poses = placements(&a, &b, PLACEMENTS, 2024);
    Scene { label, a, b, poses }
}

fn scenes() -> Vec<Scene> {
    let wanted = std::env::var("URTO_BVH_BENCH_SIZES").unwrap_or_else(|_| "1k,20k,200k".into());
    [("1k", 1_000), ("20k", 20_000), ("200k", 200_000)]
        .into_iter()
        .filter(|(label, _)| wanted.split(',').any(|w| w.trim() == *label))
        .map(|(label, n)| scene(label, n))
        .collect()
}

fn bench_kind<B: Bv>(c: &mut Criterion, kind: &str, s: &Scene) {
    for rule in RULES {
        let options = BuildOptions::with_rule(rule);
        c.bench_function(&format!("build/{kind}/{rule:?}/{}", s.label), |bench| {
            bench.iter(|| {
                Bvh::<B>::build(black_box(&s.a.vertices), &s.a.triangles, &options).unwrap()
            })
        });
        // The default build uses every core on large meshes; this is the caller's thread alone.
        let one_thread = BuildOptions {
            threads: 1,
            ..options
        };
        let id = format!("build/{kind}/{rule:?}-1-thread/{}", s.label);
        c.bench_function(&id, |bench| {
            bench.iter(|| {
                Bvh::<B>::build(black_box(&s.a.vertices), &s.a.triangles, &one_thread).unwrap()
            })
        });
        let ta = Bvh::<B>::build(&s.a.vertices, &s.a.triangles, &options).unwrap();
        let tb = Bvh::<B>::build(&s.b.vertices, &s.b.triangles, &options).unwrap();
        let mut scratch = QueryScratch::new();
        let mut out = Vec::new();
        for order in ORDERS {
            let id = BenchmarkId::new(format!("query_early/{kind}/{rule:?}/{order:?}"), s.label);
            c.bench_with_input(id, &s.poses, |bench, poses| {
                bench.iter(|| {
                    poses
                        .iter()
                        .filter(|pose| {
                            let test = posed_leaf_test(&s.a, &s.b, pose);
                            ta.first_intersecting_pair(&tb, pose, order, &mut scratch, test)
                                .0
                                .is_some()
                        })
                        .count()
                })
            });
            let id = BenchmarkId::new(format!("query_all/{kind}/{rule:?}/{order:?}"), s.label);
            c.bench_with_input(id, &s.poses, |bench, poses| {
                bench.iter(|| {
                    let mut pairs = 0;
                    for pose in poses {
                        let test = posed_leaf_test(&s.a, &s.b, pose);
                        ta.intersecting_pairs(&tb, pose, order, &mut scratch, test, &mut out);
                        pairs += out.len();
                    }
                    pairs
                })
            });
        }
    }
}

fn bench_parry(c: &mut Criterion, s: &Scene) {
    use parry3d::math::{Pose, Vector};
    use parry3d::query::intersection_test;
    use parry3d::shape::TriMesh;
    let vertices = |m: &Mesh| -> Vec<Vector> {
        m.vertices
            .iter()
            .map(|p| Vector::new(p.x, p.y, p.z))
            .collect()
    };
    let (va, vb) = (vertices(&s.a), vertices(&s.b));
    c.bench_function(&format!("build/parry/{}", s.label), |bench| {
        bench.iter(|| TriMesh::new(black_box(va.clone()), s.a.triangles.clone()).unwrap())
    });
    let ma = TriMesh::new(va, s.a.triangles.clone()).unwrap();
    let mb = TriMesh::new(vb, s.b.triangles.clone()).unwrap();
    let poses: Vec<Pose> = s
        .poses
        .iter()
        .map(|p| Pose::from_parts(p.translation, p.rotation))
        .collect();
    let id = BenchmarkId::new("query_early/parry", s.label);
    c.bench_with_input(id, &poses, |bench, poses| {
        bench.iter(|| {
            poses
                .iter()
                .filter(|p| {
                    intersection_test(&Pose::IDENTITY, &ma, p, &mb)
                        .unwrap()
                        .intersecting
                })
                .count()
        })
    });
}

fn benches(c: &mut Criterion) {
    for s in scenes() {
        bench_parry(c, &s);
        bench_kind::<BoundingSphere>(c, "sphere", &s);
        bench_kind::<Aabb>(c, "aabb", &s);
        bench_kind::<Obb>(c, "obb", &s);
        bench_kind::<Kdop14>(c, "kdop14", &s);
        bench_kind::<Kdop18>(c, "kdop18", &s);
        bench_kind::<Kdop26>(c, "kdop26", &s);
    }
}

criterion_group!(bvh, benches);
criterion_main!(bvh);
