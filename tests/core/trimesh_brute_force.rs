//! The brute-force mesh–mesh reference: dropping degenerate triangles changes no result, the
//! box pre-check changes no result, and parry (GJK per triangle pair) agrees except within its
//! tolerance of touching.

use glam::{EulerRot, Quat, Vec3};
use parry3d::math::{Pose, Vector};
use parry3d::query;
use parry3d::shape::TriMesh as PTriMesh;
use std::path::Path;
use urto::geometry::mesh_io;
use urto::geometry::{Isometry, TriMesh, tri_tri_intersect};

fn load(name: &str) -> TriMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    mesh_io::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    }
}

/// Poses of `b` in `a`'s frame that put `b`'s box centre near a random vertex of `a` (within
/// `spread` times `b`'s half extents), with random rotations: meshes are surfaces, so this
/// gives a mix of crossing and apart pairs whatever their relative sizes.
fn poses(a: &TriMesh, b: &TriMesh, count: usize, spread: f32, seed: u64) -> Vec<Isometry> {
    let mut rng = Rng(seed);
    let reach = b.local_aabb().half_extents();
    (0..count)
        .map(|_| {
            let rotation = Quat::from_euler(
                EulerRot::XYZ,
                rng.unit() * 3.1,
                rng.unit() * 3.1,
                rng.unit() * 3.1,
            );
            let anchor = a.vertices()[rng.next() as usize % a.vertex_count()];
            let offset = Vec3::new(rng.unit(), rng.unit(), rng.unit()) * reach * spread;
            let translation = anchor + offset - rotation * b.local_aabb().center();
            Isometry::new(translation, rotation)
        })
        .collect()
}

#[test]
fn degenerate_triangles_change_no_collision_result() {
    let ant = load("ant.ply");
    let torus = TriMesh::torus(8.0, 3.0, 24, 12).unwrap();
    let mut vertices = ant.vertices().to_vec();
    let mut triangles = ant.triangles().to_vec();
    // Needles: zero-area triangles along long segments through the ant's box, which as
    // segments would cross the torus in many poses; and repeated-index triangles.
    let aabb = ant.local_aabb();
    let (lo, hi) = (aabb.min - aabb.extents(), aabb.max + aabb.extents());
    let base = vertices.len() as u32;
    vertices.extend([lo, (lo + hi) * 0.5, hi]);
    vertices.extend([Vec3::new(lo.x, hi.y, lo.z), Vec3::new(hi.x, lo.y, hi.z)]);
    let needles = [
        (0, [base, base + 1, base + 2]),
        (300, [base + 3, base + 4, base + 3]),
        (600, [5, 5, 9]),
        (triangles.len() + 3, [base + 2, base, base + 1]),
    ];
    for (at, t) in needles {
        triangles.insert(at, t);
    }
    let with_needles = TriMesh::new(vertices, triangles).unwrap();
    assert_eq!(
        with_needles.report().degenerate_triangles_dropped,
        needles.len()
    );
    assert_eq!(
        with_needles.triangles(),
        ant.triangles(),
        "same triangles, same order"
    );
    let mut meeting = 0;
    for pose in poses(&ant, &torus, 12, 1.0, 7) {
        let expected = ant.intersecting_pairs_brute_force(&torus, &pose);
        assert_eq!(
            with_needles.intersecting_pairs_brute_force(&torus, &pose),
            expected
        );
        let back = pose.inverse();
        let seen_from_torus = torus.intersecting_pairs_brute_force(&with_needles, &back);
        let mut swapped: Vec<_> = seen_from_torus.iter().map(|&(i, j)| (j, i)).collect();
        swapped.sort_unstable();
        assert_eq!(
            swapped.len(),
            expected.len(),
            "symmetric up to rounding of the pose"
        );
        meeting += !expected.is_empty() as usize;
    }
    assert!(meeting >= 3, "some poses collide: {meeting}");
}

#[test]
fn the_box_precheck_changes_no_result() {
    let ant = load("ant.ply");
    let nut = load("nut.ply");
    let mut meeting = 0;
    for pose in poses(&ant, &nut, 3, 1.0, 11) {
        let pairs = ant.intersecting_pairs_brute_force(&nut, &pose);
        meeting += !pairs.is_empty() as usize;
        let placed: Vec<_> = nut.iter_triangles().map(|t| t.transformed(&pose)).collect();
        let mut plain = Vec::new();
        for (i, a) in ant.iter_triangles().enumerate() {
            for (j, b) in placed.iter().enumerate() {
                if tri_tri_intersect(&a, b) {
                    plain.push((i as u32, j as u32));
                }
            }
        }
        assert_eq!(pairs, plain);
        assert_eq!(ant.intersects_brute_force(&nut, &pose), !pairs.is_empty());
    }
    assert!(meeting > 0, "at least one pose collides");
}

fn to_parry(m: &TriMesh) -> PTriMesh {
    let vertices = m
        .vertices()
        .iter()
        .map(|v| Vector::new(v.x, v.y, v.z))
        .collect();
    PTriMesh::new(vertices, m.triangles().to_vec()).expect("valid mesh")
}

fn to_parry_pose(p: &Isometry) -> Pose {
    let q = p.rotation;
    let t = p.translation;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        parry3d::math::Rotation::from_xyzw(q.x, q.y, q.z, q.w),
    )
}

#[test]
fn mesh_pairs_agree_with_parry_except_when_grazing() {
    let sphere = load("sphere.ply");
    let nut = load("nut.ply");
    let airplane = load("airplane.ply");
    let pairs = [(&sphere, &nut), (&nut, &airplane), (&sphere, &airplane)];
    let (mut hits, mut total) = (0, 0);
    for (k, (a, b)) in pairs.into_iter().enumerate() {
        let (pa, pb) = (to_parry(a), to_parry(b));
        for pose in poses(a, b, 10, 1.0, 100 + k as u64) {
            let ours = a.intersects_brute_force(b, &pose);
            let ppose = to_parry_pose(&pose);
            let theirs = query::intersection_test(&Pose::IDENTITY, &pa, &ppose, &pb)
                .expect("supported")
                .intersecting;
            total += 1;
            hits += ours as usize;
            if ours != theirs {
                let d = query::distance(&Pose::IDENTITY, &pa, &ppose, &pb).expect("supported");
                assert!(
                    d.distance < 1e-3,
                    "ours {ours}, parry {theirs}, distance {}",
                    d.distance
                );
            }
        }
    }
    println!("mesh pairs: {hits} of {total} poses intersect");
    assert!(hits > 5 && hits < total - 5, "{hits} of {total}");
}
