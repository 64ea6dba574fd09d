//! The hierarchy finds exactly the triangle pairs that brute force finds, for every BV kind ×
//! build rule × traversal order, on thousands of seeded random rigid placements of procedural and
//! scanned meshes; early-out agrees on yes/no and returns a pair brute force also finds.
//!
//! Placements: set `URTO_BVH_PLACEMENTS_SCALE` (default 1.0) to scale their number.

use crate::common;

use common::meshes::{ply, soup, torus, uv_sphere};
use common::rng::Rng;
use common::{Mesh, brute_force_pairs, leaf_test};
use glam::Vec3;
use urto::bounding::{Aabb, BoundingSphere, Bv, Kdop14, Kdop18, Kdop26, Obb};
use urto::bvh::{BuildOptions, BuildRule, Bvh, QueryScratch, TraversalOrder};
use urto::geometry::Isometry;

const RULES: [BuildRule; 2] = [BuildRule::Median, BuildRule::BinnedSah];
const ORDERS: [TraversalOrder; 3] = [
    TraversalOrder::DepthFirst,
    TraversalOrder::BreadthFirst,
    TraversalOrder::Priority,
];

/// One placement with its ground truth.
struct Placement {
    pose: Isometry,
    b_in_a: Vec<Vec3>,
    truth: Vec<[u32; 2]>,
}

fn placements(
    a: &Mesh,
    b: &Mesh,
    count: usize,
    seed: u64,
    pose_of: impl Fn(&mut Rng) -> Isometry,
) -> Vec<Placement> {
    let scale: f64 = std::env::var("URTO_BVH_PLACEMENTS_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let count = ((count as f64 * scale).ceil() as usize).max(1);
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let pose = pose_of(&mut rng);
            let b_in_a = b.transformed_vertices(&pose);
            let truth = brute_force_pairs(a, b, &b_in_a);
            Placement {
                pose,
                b_in_a,
                truth,
            }
        })
        .collect()
}

/// Checks one BV kind, all rules and orders, against the placements' truth. Returns the total
/// leaf tests of the enumerate queries (to show the pruning).
fn check_kind<B: Bv>(name: &str, a: &Mesh, b: &Mesh, cases: &[Placement]) -> u64 {
    let mut scratch = QueryScratch::new();
    let mut found = Vec::new();
    let mut leaf_tests = 0;
    for rule in RULES {
        let options = BuildOptions::with_rule(rule);
        let ta = Bvh::<B>::build(&a.vertices, &a.triangles, &options).unwrap();
        let tb = Bvh::<B>::build(&b.vertices, &b.triangles, &options).unwrap();
        let mut stats_per_order = Vec::new();
        for order in ORDERS {
            let mut order_stats = Vec::with_capacity(cases.len());
            for (k, case) in cases.iter().enumerate() {
                let what = format!("{name} {rule:?} {order:?} placement {k} {:?}", case.pose);
                let stats = ta.intersecting_pairs(
                    &tb,
                    &case.pose,
                    order,
                    &mut scratch,
                    leaf_test(a, b, &case.b_in_a),
                    &mut found,
                );
                leaf_tests += stats.leaf_tests;
                order_stats.push(stats);
                let mut sorted = found.clone();
                sorted.sort_unstable();
                assert_eq!(sorted.len(), found.len(), "{what}: duplicate pairs");
                sorted.dedup();
                assert_eq!(sorted, case.truth, "{what}");
                let (first, early) = ta.first_intersecting_pair(
                    &tb,
                    &case.pose,
                    order,
                    &mut scratch,
                    leaf_test(a, b, &case.b_in_a),
                );
                assert_eq!(first.is_some(), !case.truth.is_empty(), "{what}: early-out");
                if let Some(pair) = first {
                    assert!(case.truth.binary_search(&pair).is_ok(), "{what}: {pair:?}");
                    assert!(
                        early.leaf_tests <= stats.leaf_tests,
                        "{what}: early-out did more"
                    );
                } else {
                    assert_eq!(
                        early, stats,
                        "{what}: a fruitless early-out does all the work"
                    );
                }
            }
            stats_per_order.push(order_stats);
        }
        // Enumerating visits the same overlapping pairs whatever the order: only the order of
        // the visits changes, so the counters must agree exactly.
        for other in &stats_per_order[1..] {
            assert_eq!(
                &stats_per_order[0], other,
                "{name} {rule:?}: counters depend on the order"
            );
        }
    }
    leaf_tests
}

fn check_all_kinds(a: &Mesh, b: &Mesh, cases: &[Placement]) {
    let hits = cases.iter().filter(|c| !c.truth.is_empty()).count();
    assert!(
        hits > 0 && hits < cases.len(),
        "placements must both hit and miss: {hits}/{}",
        cases.len()
    );
    let all_pairs =
        (a.triangles.len() * b.triangles.len() * cases.len() * RULES.len() * ORDERS.len()) as f64;
    for (name, tests) in [
        (
            "sphere",
            check_kind::<BoundingSphere>("sphere", a, b, cases),
        ),
        ("aabb", check_kind::<Aabb>("aabb", a, b, cases)),
        ("obb", check_kind::<Obb>("obb", a, b, cases)),
        ("kdop14", check_kind::<Kdop14>("kdop14", a, b, cases)),
        ("kdop18", check_kind::<Kdop18>("kdop18", a, b, cases)),
        ("kdop26", check_kind::<Kdop26>("kdop26", a, b, cases)),
    ] {
        let fraction = tests as f64 / all_pairs;
        eprintln!(
            "{name}: leaf tests = {:.4} of all pairs ({hits}/{} placements hit)",
            fraction,
            cases.len()
        );
        // The hierarchy must actually prune.
        assert!(fraction < 0.2, "{name} tested {fraction} of all pairs");
    }
}

/// Random placement within `reach` of A's origin.
fn near(reach: f32) -> impl Fn(&mut Rng) -> Isometry {
    move |rng| rng.placement(reach)
}

#[test]
fn sphere_against_torus() {
    let a = uv_sphere(1.0, 10, 16);
    let b = torus(1.2, 0.35, 16, 8);
    let cases = placements(&a, &b, 400, 1, near(1.15 * (a.radius() + b.radius())));
    check_all_kinds(&a, &b, &cases);
}

#[test]
fn torus_against_torus() {
    let a = torus(1.0, 0.3, 16, 8);
    let b = torus(0.8, 0.25, 14, 8);
    let cases = placements(&a, &b, 400, 2, near(1.15 * (a.radius() + b.radius())));
    check_all_kinds(&a, &b, &cases);
}

#[test]
fn soup_against_sphere() {
    let mut rng = Rng::new(3);
    let a = soup(200, 1.5, 0.3, &mut rng);
    let b = uv_sphere(0.8, 8, 12);
    let cases = placements(&a, &b, 250, 4, near(1.15 * (a.radius() + b.radius())));
    check_all_kinds(&a, &b, &cases);
}

#[test]
fn scanned_ant_against_nut() {
    let a = ply("ant.ply").centred();
    let b = ply("nut.ply").centred();
    let reach = 0.9 * (a.radius() + b.radius());
    let cases = placements(&a, &b, 20, 5, near(reach));
    check_all_kinds(&a, &b, &cases);
}

/// Large coordinates: the airplane sits ~900 units from its origin; B is a copy turned about the
/// airplane's centre and nudged, so the contacts happen far from the origin (rounding slack).
#[test]
fn airplane_far_from_origin_against_itself() {
    let a = ply("airplane.ply");
    let centre = Aabb::from_points(a.vertices.iter().copied()).center();
    let radius = a
        .vertices
        .iter()
        .fold(0.0f32, |r, v| r.max(v.distance(centre)));
    let cases = placements(&a, &a, 8, 6, move |rng| {
        let turn = Isometry::new(Vec3::ZERO, rng.rotation());
        let about_centre =
            Isometry::from_translation(centre) * turn * Isometry::from_translation(-centre);
        Isometry::from_translation(rng.direction() * rng.range(0.0, 2.2 * radius)) * about_centre
    });
    check_all_kinds(&a, &a, &cases);
}
