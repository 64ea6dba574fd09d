//! Section 3: bounding volumes — which BV kind makes the cheapest hierarchy, and does the
//! slides' cost model `Tc = Nv*Cv + Nn*Cn + Ns*Cs` predict the measured time?
//!
//! Every kind (sphere, AABB, OBB, 14/18/26-DOP) builds a hierarchy (binned SAH, Wald 2007) over
//! the same mesh pairs; the enumerate-all query (depth-first, the collision response needs every
//! contact) runs over the same seeded placements with the crate's exact triangle–triangle test
//! (Guigue & Devillers 2003) as the leaf test. The counters give `Nv`, `Nn`, `Ns`;
//! `measure_unit_costs` replays the work of the busiest placements to time `Cv`, `Cn`, `Cs`; the
//! prediction is set against the query's measured time. The approach is `examples/bvh_costs.rs`'s
//! (shared through `tests/common`).

mod charts;
mod text;

use crate::common::meshes::{ply, torus_pair};
use crate::common::timing::min_of_means;
use crate::common::{Mesh, placements, posed_leaf_test_with};
use crate::{Config, Context, SectionResult};
use charts::{plot, record};
use glam::Vec3;
use std::time::Duration;
use text::section;
use urto::bounding::{Aabb, BoundingSphere, Bv, Kdop14, Kdop18, Kdop26, Obb};
use urto::bvh::{
    BuildOptions, Bvh, QueryScratch, QueryStats, TraversalOrder, UnitCosts, measure_unit_costs,
};
use urto::geometry::{Isometry, Triangle, tri_tri_intersect};

/// BV kinds, in the table's order.
const KINDS: [&str; 6] = ["sphere", "AABB", "OBB", "14-DOP", "18-DOP", "26-DOP"];

/// Placements whose work is replayed for the unit costs (the busiest ones).
const COST_SAMPLES: usize = 4;

/// Repeats of every timing; the smallest is kept (see `min_of_means`).
const REPEATS: u32 = 3;

/// The traversal measured (the cost model holds for any; one keeps the table readable).
const ORDER: TraversalOrder = TraversalOrder::DepthFirst;

/// A named pair of meshes and the placements of B near A.
struct MeshPair {
    name: String,
    a: Mesh,
    b: Mesh,
    poses: Vec<Isometry>,
}

/// Sizes of the run.
struct Sizes {
    torus_triangles: usize,
    placements: usize,
    min_time: Duration,
    unit_cost_budget: Duration,
}

fn sizes(cfg: &Config) -> Sizes {
    Sizes {
        torus_triangles: cfg.pick(20_000, 4_000),
        placements: cfg.pick(64, 16),
        min_time: cfg.pick(Duration::from_millis(150), Duration::from_millis(20)),
        unit_cost_budget: cfg.pick(Duration::from_millis(60), Duration::from_millis(15)),
    }
}

/// The pairs: procedural tori, and two real scanned meshes from `tests/data/`.
fn mesh_pairs(sz: &Sizes) -> Vec<MeshPair> {
    let (ta, tb) = torus_pair(sz.torus_triangles);
    let airplane = ply("airplane.ply").centred();
    let pairs = [
        ("two tori".to_string(), ta, tb),
        (
            "airplane × airplane".to_string(),
            airplane.clone(),
            airplane,
        ),
        (
            "ant × nut".to_string(),
            ply("ant.ply").centred(),
            ply("nut.ply").centred(),
        ),
    ];
    pairs
        .into_iter()
        .map(|(name, a, b)| {
            let poses = placements(&a, &b, sz.placements, 2024);
            MeshPair { name, a, b, poses }
        })
        .collect()
}

/// Units of progress: one per (pair, kind).
pub fn work_units(_cfg: &Config) -> u64 {
    3 * KINDS.len() as u64
}

/// What one (pair, kind) measured; counts and times are per placement.
struct KindRow {
    kind: &'static str,
    pair: String,
    triangles: (usize, usize),
    build_ms: f64,
    nodes: usize,
    stats: [f64; 3],
    costs: [f64; 3],
    predicted_us: f64,
    measured_us: f64,
    pairs_found: f64,
}

impl KindRow {
    /// How many values [`KindRow::named_values`] gives.
    const FIELDS: usize = 9;

    /// The row's numbers with entity-path names, for the recording.
    fn named_values(&self) -> [(&'static str, f64); Self::FIELDS] {
        [
            ("measured_us", self.measured_us),
            ("predicted_us", self.predicted_us),
            ("build_ms", self.build_ms),
            ("nv", self.stats[0]),
            ("nn", self.stats[1]),
            ("ns", self.stats[2]),
            ("cv_ns", self.costs[0]),
            ("cn_ns", self.costs[1]),
            ("cs_ns", self.costs[2]),
        ]
    }
}

/// Runs the section.
pub fn run(ctx: &mut Context) -> SectionResult {
    let sz = sizes(&ctx.cfg);
    ctx.progress.task("bounding volumes: loading meshes");
    let pairs = mesh_pairs(&sz);
    let mut rows = Vec::new();
    for pair in &pairs {
        rows.push(measure_kind::<BoundingSphere>(ctx, &sz, pair, KINDS[0]));
        rows.push(measure_kind::<Aabb>(ctx, &sz, pair, KINDS[1]));
        rows.push(measure_kind::<Obb>(ctx, &sz, pair, KINDS[2]));
        rows.push(measure_kind::<Kdop14>(ctx, &sz, pair, KINDS[3]));
        rows.push(measure_kind::<Kdop18>(ctx, &sz, pair, KINDS[4]));
        rows.push(measure_kind::<Kdop26>(ctx, &sz, pair, KINDS[5]));
    }
    plot(ctx, &rows, &pairs)?;
    record(ctx, &rows, &pairs);
    Ok(section(&rows, &sz))
}

/// The crate's exact triangle test on corner arrays.
fn exact_test(a: &[Vec3; 3], b: &[Vec3; 3]) -> bool {
    let t = |c: &[Vec3; 3]| Triangle {
        a: c[0],
        b: c[1],
        c: c[2],
    };
    tri_tri_intersect(&t(a), &t(b))
}

fn measure_kind<B: Bv>(ctx: &Context, sz: &Sizes, pair: &MeshPair, kind: &'static str) -> KindRow {
    ctx.progress
        .task(format!("bounding volumes: {kind} on {}", pair.name));
    let options = BuildOptions::default();
    // The meshes come from urto's own loaders and generators, which validate them.
    let build =
        || Bvh::<B>::build(&pair.a.vertices, &pair.a.triangles, &options).expect("valid mesh");
    let build_ms = min_of_means(REPEATS, sz.min_time, build).as_secs_f64() * 1e3;
    let ta = build();
    let tb = Bvh::<B>::build(&pair.b.vertices, &pair.b.triangles, &options).expect("valid mesh");
    let (per_pose, found) = query_stats(&ta, &tb, pair);
    let total = per_pose.iter().fold(QueryStats::default(), |s, p| s + *p);
    let (mut scratch, mut out) = (QueryScratch::new(), Vec::new());
    let measured = min_of_means(REPEATS, sz.min_time, || {
        query_all(&ta, &tb, pair, &mut scratch, &mut out)
    });
    let costs = unit_costs(&ta, &tb, pair, &per_pose, sz.unit_cost_budget);
    ctx.progress.tick();
    let n = pair.poses.len() as f64;
    KindRow {
        kind,
        pair: pair.name.clone(),
        triangles: (pair.a.triangles.len(), pair.b.triangles.len()),
        build_ms,
        nodes: ta.nodes().len(),
        stats: [total.nodes_visited, total.bv_tests, total.leaf_tests].map(|c| c as f64 / n),
        costs: [costs.visit_ns, costs.bv_test_ns, costs.leaf_test_ns],
        predicted_us: costs.predict_ns(&total) / n / 1e3,
        measured_us: measured.as_secs_f64() * 1e6 / n,
        pairs_found: found as f64 / n,
    }
}

/// The counters of each placement's query and the total number of intersecting pairs.
fn query_stats<B: Bv>(ta: &Bvh<B>, tb: &Bvh<B>, pair: &MeshPair) -> (Vec<QueryStats>, usize) {
    let mut scratch = QueryScratch::new();
    let mut out = Vec::new();
    let mut found = 0;
    let stats = pair
        .poses
        .iter()
        .map(|pose| {
            let leaf = posed_leaf_test_with(&pair.a, &pair.b, pose, exact_test);
            let s = ta.intersecting_pairs(tb, pose, ORDER, &mut scratch, leaf, &mut out);
            found += out.len();
            s
        })
        .collect();
    (stats, found)
}

/// One enumerate-all query per placement (the timed work); the number of pairs found.
fn query_all<B: Bv>(
    ta: &Bvh<B>,
    tb: &Bvh<B>,
    pair: &MeshPair,
    scratch: &mut QueryScratch,
    out: &mut Vec<[u32; 2]>,
) -> usize {
    pair.poses
        .iter()
        .map(|pose| {
            let leaf = posed_leaf_test_with(&pair.a, &pair.b, pose, exact_test);
            ta.intersecting_pairs(tb, pose, ORDER, scratch, leaf, out);
            out.len()
        })
        .sum()
}

/// Indices of the [`COST_SAMPLES`] placements with the most work (leaf tests, then BV tests).
fn busiest(stats: &[QueryStats]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..stats.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse((stats[i].leaf_tests, stats[i].bv_tests)));
    order.truncate(COST_SAMPLES);
    order
}

/// Unit costs measured on the busiest placements, each the smallest of [`REPEATS`]
/// measurements, combined as means weighted by each placement's counts (a placement's `Cs`
/// counts as much as it has leaf tests). Several placements, because one may be a pure
/// translation, whose BV tests take a cheaper rotation-free path.
fn unit_costs<B: Bv>(
    ta: &Bvh<B>,
    tb: &Bvh<B>,
    pair: &MeshPair,
    stats: &[QueryStats],
    budget: Duration,
) -> UnitCosts {
    let mut sum = [0.0f64; 3];
    let mut weight = [0.0f64; 3];
    for i in busiest(stats) {
        let pose = &pair.poses[i];
        let c = (0..REPEATS)
            .map(|_| {
                let leaf = posed_leaf_test_with(&pair.a, &pair.b, pose, exact_test);
                let c = measure_unit_costs(ta, tb, pose, ORDER, leaf, budget / REPEATS);
                [c.visit_ns, c.bv_test_ns, c.leaf_test_ns]
            })
            .fold([f64::INFINITY; 3], |m, c| {
                [m[0].min(c[0]), m[1].min(c[1]), m[2].min(c[2])]
            });
        let s = stats[i];
        let w = [s.nodes_visited, s.bv_tests, s.leaf_tests].map(|n| n.max(1) as f64);
        for k in 0..3 {
            sum[k] += c[k] * w[k];
            weight[k] += w[k];
        }
    }
    UnitCosts {
        visit_ns: sum[0] / weight[0],
        bv_test_ns: sum[1] / weight[1],
        leaf_test_ns: sum[2] / weight[2],
    }
}
