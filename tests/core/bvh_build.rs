//! Construction: structural invariants (every triangle in exactly one leaf, leaf sizes, every
//! node's BV holding its subtree, children after parents), determinism, errors on bad input,
//! degenerate input, and the SAH beating the median on its own cost measure.

use crate::common;

use common::Mesh;
use common::meshes::{ply, soup, torus, uv_sphere};
use common::rng::Rng;
use glam::Vec3;
use urto::bounding::{Aabb, BoundingSphere, Bv, Kdop14, Kdop18, Kdop26, Obb};
use urto::bvh::{BuildOptions, BuildRule, Bvh, BvhError};

/// The triangles under `node`, gathered by walking the tree.
fn subtree_triangles<B: Bv>(bvh: &Bvh<B>, node: u32, out: &mut Vec<u32>) {
    let n = &bvh.nodes()[node as usize];
    match n.children() {
        Some([l, r]) => {
            subtree_triangles(bvh, l, out);
            subtree_triangles(bvh, r, out);
        }
        None => out.extend_from_slice(bvh.leaf_triangles(n)),
    }
}

fn check_structure<B: Bv>(bvh: &Bvh<B>, mesh: &Mesh, leaf_size: usize) {
    let n = mesh.triangles.len();
    let mut order = bvh.triangle_order().to_vec();
    order.sort_unstable();
    assert_eq!(
        order,
        (0..n as u32).collect::<Vec<_>>(),
        "order is a permutation"
    );
    let mut reached = vec![0u32; bvh.nodes().len()];
    reached[0] = 1;
    let mut leaf_cover = vec![0u32; n];
    for (i, node) in bvh.nodes().iter().enumerate() {
        assert_eq!(node.size, node.bv.size());
        match node.children() {
            Some([l, r]) => {
                assert!(l as usize > i && r == l + 1, "children follow their parent");
                reached[l as usize] += 1;
                reached[r as usize] += 1;
            }
            None => {
                let range = node.triangle_range().unwrap();
                assert!(
                    (1..=leaf_size).contains(&range.len()),
                    "leaf of {}",
                    range.len()
                );
                for k in range {
                    leaf_cover[k] += 1;
                }
            }
        }
        let mut tris = Vec::new();
        subtree_triangles(bvh, i as u32, &mut tris);
        for t in tris {
            for v in mesh.corners(t) {
                assert!(
                    node.bv.contains_point(v, 0.0),
                    "node {i} {:?} misses {v}",
                    node.bv
                );
            }
        }
    }
    assert!(
        reached.iter().all(|&r| r == 1),
        "every node has exactly one parent"
    );
    assert!(
        leaf_cover.iter().all(|&c| c == 1),
        "leaves partition the order"
    );
}

fn check_kind<B: Bv>(mesh: &Mesh) {
    for rule in [BuildRule::Median, BuildRule::BinnedSah] {
        for leaf_size in [1, 4, 7] {
            let options = BuildOptions {
                rule,
                leaf_size,
                ..BuildOptions::default()
            };
            let bvh = Bvh::<B>::build(&mesh.vertices, &mesh.triangles, &options).unwrap();
            check_structure(&bvh, mesh, leaf_size);
            let again = Bvh::<B>::build(&mesh.vertices, &mesh.triangles, &options).unwrap();
            assert_eq!(bvh, again, "deterministic");
            if rule == BuildRule::Median {
                // Halving runs: depth is ⌈log₂ ⌈n / leaf⌉⌉ + 1 at most.
                let leaves = mesh.triangles.len().div_ceil(leaf_size);
                let bound = (leaves as f64).log2().ceil() as usize + 1;
                assert!(
                    bvh.depth() <= bound,
                    "median depth {} > {bound}",
                    bvh.depth()
                );
            }
        }
    }
}

fn check_all_kinds(mesh: &Mesh) {
    check_kind::<BoundingSphere>(mesh);
    check_kind::<Aabb>(mesh);
    check_kind::<Obb>(mesh);
    check_kind::<Kdop14>(mesh);
    check_kind::<Kdop18>(mesh);
    check_kind::<Kdop26>(mesh);
}

#[test]
fn procedural_and_scanned_meshes_build_valid_trees() {
    let mut rng = Rng::new(11);
    check_all_kinds(&uv_sphere(1.0, 8, 12));
    check_all_kinds(&torus(2.0, 0.5, 12, 6));
    check_all_kinds(&soup(150, 3.0, 0.4, &mut rng));
    check_all_kinds(&ply("ant.ply"));
}

/// The build splits and fits large meshes on several threads; the tree must not depend on how
/// many (12,800 triangles, past the size below which it stays on one thread; a torus, the same
/// torus scaled to 1e-2 and moved 100 away, and a soup of random triangles; leaves of 4 and of
/// 5,000, which the threads must not split either; counts up to `usize::MAX`, capped at the
/// machine's cores).
#[test]
fn any_thread_count_builds_the_same_tree_bit_for_bit() {
    let mut rng = Rng::new(5);
    let big_torus = torus(2.0, 0.5, 160, 40);
    let far_small = Mesh {
        vertices: big_torus
            .vertices
            .iter()
            .map(|v| *v * 1e-2 + Vec3::new(100.0, -100.0, 50.0))
            .collect(),
        triangles: big_torus.triangles.clone(),
    };
    let meshes = [big_torus, far_small, soup(9000, 10.0, 0.3, &mut rng)];
    for mesh in &meshes {
        assert!(mesh.triangles.len() > 8192);
        for (rule, leaf_size) in [
            (BuildRule::Median, 4),
            (BuildRule::BinnedSah, 4),
            (BuildRule::BinnedSah, 5000),
        ] {
            let with = |threads| BuildOptions {
                threads,
                leaf_size,
                ..BuildOptions::with_rule(rule)
            };
            let one = Bvh::<Obb>::build(&mesh.vertices, &mesh.triangles, &with(1)).unwrap();
            check_structure(&one, mesh, leaf_size);
            let one_aabb = Bvh::<Aabb>::build(&mesh.vertices, &mesh.triangles, &with(1)).unwrap();
            for threads in [0, 2, 3, 8, usize::MAX] {
                let many = Bvh::<Obb>::build(&mesh.vertices, &mesh.triangles, &with(threads));
                assert!(many.unwrap() == one, "{threads} threads, {rule:?}");
                let aabb = Bvh::<Aabb>::build(&mesh.vertices, &mesh.triangles, &with(threads));
                assert!(
                    aabb.unwrap() == one_aabb,
                    "AABB, {threads} threads, {rule:?}"
                );
            }
        }
    }
}

#[test]
fn degenerate_meshes_build_valid_trees() {
    let p = Vec3::new(3.0, -1.0, 2.0);
    // One triangle: the root is a leaf.
    let single = Mesh {
        vertices: vec![p, p + Vec3::X, p + Vec3::Y],
        triangles: vec![[0, 1, 2]],
    };
    check_all_kinds(&single);
    let bvh = Bvh::<Obb>::build(
        &single.vertices,
        &single.triangles,
        &BuildOptions::default(),
    )
    .unwrap();
    assert!(bvh.root().is_leaf() && bvh.nodes().len() == 1);
    // Fifty copies of the same triangle: every centroid coincides, the SAH must fall back.
    let copies = Mesh {
        vertices: vec![p, p + Vec3::X, p + Vec3::Y],
        triangles: vec![[0, 1, 2]; 50],
    };
    check_all_kinds(&copies);
    // Points (all corners equal) and needles (collinear corners) along a line.
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..40u32 {
        let a = p + Vec3::new(i as f32 * 0.25, 0.0, 0.0);
        vertices.extend([a, a + Vec3::X * 0.1 * (i % 2) as f32, a + Vec3::X * 0.2]);
        triangles.push([3 * i, 3 * i + 1, 3 * i + if i % 3 == 0 { 0 } else { 2 }]);
    }
    check_all_kinds(&Mesh {
        vertices,
        triangles,
    });
    // Same centroid, growing sizes (a nest of triangles).
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..30u32 {
        let s = 1.0 + i as f32;
        vertices.extend([
            p + Vec3::new(-s, -s, 0.0),
            p + Vec3::new(2.0 * s, -s, 0.0),
            p + Vec3::new(-s, 2.0 * s, 0.0),
        ]);
        triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    check_all_kinds(&Mesh {
        vertices,
        triangles,
    });
}

#[test]
fn bad_input_is_refused_with_a_clear_error() {
    let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let ok = BuildOptions::default();
    assert_eq!(
        Bvh::<Aabb>::build(&v, &[], &ok).unwrap_err(),
        BvhError::EmptyMesh
    );
    let mut nan = v.clone();
    nan[1].y = f32::NAN;
    assert_eq!(
        Bvh::<Obb>::build(&nan, &[[0, 1, 2]], &ok).unwrap_err(),
        BvhError::NonFiniteVertex { vertex: 1 }
    );
    let mut inf = v.clone();
    inf[2].z = f32::INFINITY;
    assert!(matches!(
        Bvh::<Kdop14>::build(&inf, &[[0, 1, 2]], &ok),
        Err(BvhError::NonFiniteVertex { vertex: 2 })
    ));
    assert_eq!(
        Bvh::<BoundingSphere>::build(&v, &[[0, 1, 2], [0, 3, 1]], &ok).unwrap_err(),
        BvhError::IndexOutOfRange {
            triangle: 1,
            index: 3,
            vertex_count: 3
        }
    );
    let zero_leaf = BuildOptions { leaf_size: 0, ..ok };
    assert_eq!(
        Bvh::<Aabb>::build(&v, &[[0, 1, 2]], &zero_leaf).unwrap_err(),
        BvhError::BadLeafSize(0)
    );
    for bins in [0, 1, 65] {
        let bad = BuildOptions {
            sah_bins: bins,
            ..ok
        };
        assert_eq!(
            Bvh::<Aabb>::build(&v, &[[0, 1, 2]], &bad).unwrap_err(),
            BvhError::BadBinCount(bins)
        );
    }
    // Every error prints a sentence.
    assert!(
        BvhError::EmptyMesh
            .to_string()
            .contains("without triangles")
    );
}

/// The SAH cost of a tree measured on the triangles' boxes: Σ over nodes of
/// `area(node)/area(root)`, times the triangle count for leaves.
fn sah_cost(bvh: &Bvh<Aabb>) -> f32 {
    let root = bvh.root().bv.surface_area();
    bvh.nodes()
        .iter()
        .map(|n| {
            let weight = n.triangle_range().map_or(1, |r| r.len()) as f32;
            n.bv.surface_area() / root * weight
        })
        .sum()
}

#[test]
fn sah_trees_cost_less_than_median_trees_by_the_sah() {
    let mut rng = Rng::new(12);
    // Clustered soup: a dense blob and a sparse halo, where the median cuts badly.
    let mut clustered = soup(400, 0.5, 0.05, &mut rng);
    let halo = soup(100, 20.0, 0.5, &mut rng);
    let base = clustered.vertices.len() as u32;
    clustered.vertices.extend(halo.vertices);
    clustered
        .triangles
        .extend(halo.triangles.iter().map(|t| t.map(|i| i + base)));
    for mesh in [clustered, ply("ant.ply"), ply("airplane.ply")] {
        let median = Bvh::<Aabb>::build(
            &mesh.vertices,
            &mesh.triangles,
            &BuildOptions::with_rule(BuildRule::Median),
        )
        .unwrap();
        let sah = Bvh::<Aabb>::build(
            &mesh.vertices,
            &mesh.triangles,
            &BuildOptions::with_rule(BuildRule::BinnedSah),
        )
        .unwrap();
        let (cm, cs) = (sah_cost(&median), sah_cost(&sah));
        assert!(cs < cm, "SAH {cs} vs median {cm}");
    }
}
