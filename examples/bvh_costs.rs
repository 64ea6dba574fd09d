//! Quick measurement of the hierarchies on a ~20k-triangle mesh pair: build time per BV kind and
//! rule, query time per traversal order and mode with the cost counters `Nv`, `Nn`, `Ns`, the
//! cost model's prediction `Nv*Cv + Nn*Cn + Ns*Cs` from measured unit costs, and the same
//! early-out query done by parry3d.
//!
//! `cargo run --release --example bvh_costs` (about 20 s). Environment: `URTO_BVH_TRIANGLES`, the
//! approximate triangle count of each mesh (default 20000); `URTO_BVH_LEAF_SIZE` (default 4);
//! `URTO_BVH_KINDS`, a comma-separated subset of `sphere,aabb,obb,kdop14,kdop18,kdop26,parry`;
//! `URTO_BVH_MESH`, an OBJ, STL or PLY file of your own to measure instead of the tori (two
//! copies of it, centred, placed at random against each other): what
//! `MeshCollider::with_hierarchy`'s choices cost for that mesh.

#[path = "../tests/common/mod.rs"]
mod common;

use common::meshes::torus_pair;
use common::timing::mean_time;
use common::{Mesh, placements, posed_leaf_test};
use std::time::Duration;
use urto::bounding::{Aabb, BoundingSphere, Bv, Kdop14, Kdop18, Kdop26, Obb};
use urto::bvh::{
    BuildOptions, BuildRule, Bvh, QueryScratch, QueryStats, TraversalOrder, measure_unit_costs,
};
use urto::geometry::Isometry;

const PLACEMENTS: usize = 64;
const MIN_TIME: Duration = Duration::from_millis(40);

/// Mean time of one call of `f` over at least MIN_TIME.
fn time<R>(f: impl FnMut() -> R) -> Duration {
    mean_time(MIN_TIME, f)
}

fn per_placement(total: Duration) -> f64 {
    total.as_secs_f64() * 1e6 / PLACEMENTS as f64
}

fn run_kind<B: Bv>(name: &str, a: &Mesh, b: &Mesh, poses: &[Isometry]) {
    for rule in [BuildRule::Median, BuildRule::BinnedSah] {
        let options = BuildOptions {
            leaf_size: env_or("URTO_BVH_LEAF_SIZE", 4),
            ..BuildOptions::with_rule(rule)
        };
        let build = time(|| Bvh::<B>::build(&a.vertices, &a.triangles, &options).unwrap());
        let ta = Bvh::<B>::build(&a.vertices, &a.triangles, &options).unwrap();
        let tb = Bvh::<B>::build(&b.vertices, &b.triangles, &options).unwrap();
        // The nodes and the leaves' triangle indices.
        let bytes = std::mem::size_of_val(ta.nodes()) + 4 * a.triangles.len();
        println!(
            "{name:7} {rule:9?} build {:8.2} ms  nodes {:6} depth {:3}  memory {:8.1} KiB",
            build.as_secs_f64() * 1e3,
            ta.nodes().len(),
            ta.depth(),
            bytes as f64 / 1024.0
        );
        let mut scratch = QueryScratch::new();
        let mut out = Vec::new();
        for order in [
            TraversalOrder::DepthFirst,
            TraversalOrder::BreadthFirst,
            TraversalOrder::Priority,
        ] {
            let mut early_stats = QueryStats::default();
            let mut hits = 0;
            let early = time(|| {
                early_stats = QueryStats::default();
                hits = 0;
                for pose in poses {
                    let (found, s) = ta.first_intersecting_pair(
                        &tb,
                        pose,
                        order,
                        &mut scratch,
                        posed_leaf_test(a, b, pose),
                    );
                    early_stats += s;
                    hits += usize::from(found.is_some());
                }
            });
            let mut all_stats = QueryStats::default();
            let mut pairs = 0;
            let all = time(|| {
                all_stats = QueryStats::default();
                pairs = 0;
                for pose in poses {
                    all_stats += ta.intersecting_pairs(
                        &tb,
                        pose,
                        order,
                        &mut scratch,
                        posed_leaf_test(a, b, pose),
                        &mut out,
                    );
                    pairs += out.len();
                }
            });
            let costs = measure_unit_costs(
                &ta,
                &tb,
                &poses[0],
                order,
                posed_leaf_test(a, b, &poses[0]),
                Duration::from_millis(30),
            );
            let n = PLACEMENTS as f64;
            let mean = |s: &QueryStats| {
                format!(
                    "Nv {:7.0} Nn {:7.0} Ns {:7.0}",
                    s.nodes_visited as f64 / n,
                    s.bv_tests as f64 / n,
                    s.leaf_tests as f64 / n
                )
            };
            println!(
                "    {order:12?} early-out {:8.1} µs [{}] model {:8.1} µs | all {:8.1} µs [{}] model {:8.1} µs | hits {hits}/{PLACEMENTS} pairs {:.0} | Cv {:.1} Cn {:.1} Cs {:.1} ns",
                per_placement(early),
                mean(&early_stats),
                costs.predict_ns(&early_stats) / n / 1e3,
                per_placement(all),
                mean(&all_stats),
                costs.predict_ns(&all_stats) / n / 1e3,
                pairs as f64 / n,
                costs.visit_ns,
                costs.bv_test_ns,
                costs.leaf_test_ns,
            );
        }
    }
}

fn run_parry(a: &Mesh, b: &Mesh, poses: &[Isometry]) {
    use parry3d::math::{Pose, Vector};
    use parry3d::query::intersection_test;
    use parry3d::shape::TriMesh;
    let to_parry = |m: &Mesh| {
        let v: Vec<Vector> = m
            .vertices
            .iter()
            .map(|p| Vector::new(p.x, p.y, p.z))
            .collect();
        (v, m.triangles.clone())
    };
    let (va, ia) = to_parry(a);
    let (vb, ib) = to_parry(b);
    let build = time(|| TriMesh::new(va.clone(), ia.clone()).unwrap());
    let ma = TriMesh::new(va, ia).unwrap();
    let mb = TriMesh::new(vb, ib).unwrap();
    let ident = Pose::IDENTITY;
    let parry_poses: Vec<Pose> = poses
        .iter()
        .map(|p| Pose::from_parts(p.translation, p.rotation))
        .collect();
    let mut hits = 0;
    let query = time(|| {
        hits = 0;
        for p in &parry_poses {
            hits += usize::from(intersection_test(&ident, &ma, p, &mb).unwrap().intersecting);
        }
    });
    println!(
        "parry3d TriMesh build {:8.2} ms | intersection_test {:8.1} µs | hits {hits}/{PLACEMENTS}",
        build.as_secs_f64() * 1e3,
        per_placement(query)
    );
}

/// The mesh in `path`, centred on its bounding box (the placements are about the origin).
fn own_mesh(path: &str) -> Result<Mesh, urto::geometry::mesh_io::MeshLoadError> {
    let mesh = urto::geometry::mesh_io::load(path)?;
    let own = Mesh {
        vertices: mesh.vertices().to_vec(),
        triangles: mesh.triangles().to_vec(),
    };
    Ok(own.centred())
}

fn env_or(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let n = env_or("URTO_BVH_TRIANGLES", 20_000);
    let kinds = std::env::var("URTO_BVH_KINDS")
        .unwrap_or_else(|_| "parry,sphere,aabb,obb,kdop14,kdop18,kdop26".into());
    let wanted = |k: &str| kinds.split(',').any(|w| w.trim() == k);
    let (a, b) = match std::env::var("URTO_BVH_MESH") {
        Ok(path) => match own_mesh(&path) {
            Ok(mesh) => (mesh.clone(), mesh),
            Err(e) => {
                eprintln!("cannot measure {path}: {e}");
                std::process::exit(1);
            }
        },
        Err(_) => torus_pair(n),
    };
    let poses = placements(&a, &b, PLACEMENTS, 2024);
    println!(
        "A: {} triangles, B: {} triangles, {PLACEMENTS} placements; times per placement",
        a.triangles.len(),
        b.triangles.len()
    );
    if wanted("parry") {
        run_parry(&a, &b, &poses);
    }
    if wanted("sphere") {
        run_kind::<BoundingSphere>("sphere", &a, &b, &poses);
    }
    if wanted("aabb") {
        run_kind::<Aabb>("aabb", &a, &b, &poses);
    }
    if wanted("obb") {
        run_kind::<Obb>("obb", &a, &b, &poses);
    }
    if wanted("kdop14") {
        run_kind::<Kdop14>("kdop14", &a, &b, &poses);
    }
    if wanted("kdop18") {
        run_kind::<Kdop18>("kdop18", &a, &b, &poses);
    }
    if wanted("kdop26") {
        run_kind::<Kdop26>("kdop26", &a, &b, &poses);
    }
}
