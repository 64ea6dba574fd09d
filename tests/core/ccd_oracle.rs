//! Every time-of-impact query against two independent references, on thousands of seeded random
//! sweeps per obstacle kind:
//! - the brute-force reference: the sweep sampled finely with the existing static contact tests
//!   (`geometry::contacts`, `contact_triangle_sphere`), the first contact bisected;
//! - conservative advancement on the exact point–obstacle distance (which also covers rays,
//!   where the sampled depth test has nothing to measure).

use crate::ccd_common;

use ccd_common::{Rng, Tally, check_toi, random_sweep};
use glam::{Quat, Vec3};
use urto::bounding::{Aabb, Obb};
use urto::bvh::{BuildOptions, Bvh, QueryScratch};
use urto::ccd::{
    Advancement, SphereSweep, Toi, conservative_advancement, toi_sphere_cuboid,
    toi_sphere_halfspace, toi_sphere_sphere, toi_sphere_triangle, toi_sphere_trimesh,
    toi_spheres_moving,
};
use urto::geometry::contacts::{
    contact_sphere_cuboid, contact_sphere_halfspace, contact_sphere_sphere,
};
use urto::geometry::{
    Cuboid, HalfSpace, Isometry, Sphere, TriMesh, Triangle, contact_triangle_sphere,
};

const SAMPLES: usize = 1000;

/// Conservative advancement on the exact distance `|c − closest(c)| − r` must agree with the
/// exact query: never a contact the query misses beyond the tolerance, never a miss of one it
/// finds, and never later than it.
fn check_against_advancement(
    sweep: &SphereSweep,
    toi: Option<Toi>,
    closest: impl Fn(Vec3) -> Vec3,
) -> Result<(), String> {
    let r = sweep.radius();
    let distance = |t: f32| {
        let c = sweep.position_at(t);
        c.distance(closest(c)) - r
    };
    let tolerance = sweep.tolerance();
    let eps = ccd_common::position_tolerance(sweep);
    let speed = sweep.displacement().length();
    let late = |t_ca: f32, t_exact: f32| (t_ca - t_exact) * speed > eps;
    match (
        conservative_advancement(distance, speed, tolerance, 100_000),
        toi,
    ) {
        (Advancement::Contact { t, .. }, Some(toi)) if late(t, toi.t) => {
            Err(format!("advancement at {t} after the exact {toi:?}"))
        }
        (Advancement::Contact { t, .. }, None) if distance(t) > tolerance + eps => Err(format!(
            "advancement contact at {t} missed by the exact query"
        )),
        (Advancement::NoContact { .. }, Some(toi)) if toi.t > 0.0 || distance(0.0) > eps => {
            Err(format!("advancement finds nothing, exact query {toi:?}"))
        }
        (Advancement::Unresolved { t }, Some(toi)) if late(t, toi.t) => Err(format!(
            "advancement safe up to {t}, after the exact {toi:?}"
        )),
        _ => Ok(()),
    }
}

/// Runs `count` random sweeps made by `make` (which also runs the query) through both references:
/// `oracle` is the obstacle's static contact test (normal from the obstacle to the sphere) and
/// `closest` its closest-point function.
fn run(
    name: &str,
    (count, samples, seed): (usize, usize, u64),
    mut make: impl FnMut(&mut Rng) -> (SphereSweep, Option<Toi>),
    oracle: impl Fn(Vec3, f32) -> Option<Vec3>,
    closest: impl Fn(Vec3) -> Vec3,
) -> Tally {
    let mut rng = Rng::new(seed);
    let mut tally = Tally::default();
    for i in 0..count {
        let (sweep, toi) = make(&mut rng);
        let agreement = check_toi(&sweep, toi, &oracle, samples)
            .unwrap_or_else(|e| panic!("{name} #{i}: {e}\n{sweep:?}\n{toi:?}"));
        tally.add(agreement);
        check_against_advancement(&sweep, toi, &closest)
            .unwrap_or_else(|e| panic!("{name} #{i} (advancement): {e}\n{sweep:?}"));
    }
    println!("{name}: {tally:?}");
    assert!(
        tally.hits * 20 > tally.sweeps,
        "{name}: too few hits to test anything"
    );
    assert!(tally.hits * 10 < tally.sweeps * 9, "{name}: too few misses");
    assert!(tally.max_transversal_error < 1e-5, "{name}: {tally:?}");
    tally
}

/// Flips a static manifold (normal from the sphere, shape A, to the obstacle) to the TOI's
/// convention.
fn from_obstacle(normal_a_to_b: Vec3) -> Vec3 {
    -normal_a_to_b
}

fn random_pose(rng: &mut Rng) -> Isometry {
    let axis = rng.direction();
    Isometry::new(
        rng.in_cube(0.5),
        Quat::from_axis_angle(axis, rng.range(0.0, 3.1)),
    )
}

#[test]
fn half_space_against_the_references() {
    let pose = Isometry::new(Vec3::new(0.2, -0.1, 0.3), Quat::from_rotation_x(0.5));
    let h = HalfSpace { normal: Vec3::Z };
    let n = pose.transform_vector(Vec3::Z);
    run(
        "half-space",
        (3000, SAMPLES, 1),
        |rng| {
            let sweep = random_sweep(rng, 1.0, pose.translation + n * 2.0, Some(n));
            (sweep, toi_sphere_halfspace(&sweep, &pose, &h))
        },
        |c, r| {
            contact_sphere_halfspace(c, &Sphere { radius: r }, &pose, &h)
                .map(|m| from_obstacle(m.normal))
        },
        |c| c - n * n.dot(c - pose.translation).max(0.0),
    );
}

#[test]
fn sphere_against_the_references() {
    let centre = Vec3::new(0.3, -0.2, 0.1);
    let other = Sphere { radius: 0.8 };
    run(
        "sphere",
        (3000, SAMPLES, 2),
        |rng| {
            let sweep = random_sweep(rng, 1.0, centre, None);
            (sweep, toi_sphere_sphere(&sweep, centre, &other))
        },
        // The obstacle as shape A: the manifold's normal already points toward the sweep.
        |c, r| contact_sphere_sphere(centre, &other, c, &Sphere { radius: r }).map(|m| m.normal),
        |c| centre + (c - centre).clamp_length_max(other.radius),
    );
}

#[test]
fn cuboid_against_the_references() {
    let mut rng = Rng::new(3);
    // Several boxes, from cubes to thin plates and a flat one, each in a random pose.
    for (k, half) in [
        Vec3::ONE,
        Vec3::new(1.5, 0.4, 0.8),
        Vec3::new(1.0, 1.0, 0.005),
        Vec3::new(0.0, 0.5, 0.5),
    ]
    .into_iter()
    .enumerate()
    {
        let pose = random_pose(&mut rng);
        let cuboid = Cuboid { half_extents: half };
        run(
            &format!("cuboid {half}"),
            (1500, SAMPLES, 30 + k as u64),
            |rng| {
                let face = pose.transform_vector(Vec3::AXES[rng.pick(3)]);
                let sweep = random_sweep(rng, half.max_element(), pose.translation, Some(face));
                (sweep, toi_sphere_cuboid(&sweep, &pose, &cuboid))
            },
            |c, r| {
                contact_sphere_cuboid(c, &Sphere { radius: r }, &pose, &cuboid)
                    .map(|m| from_obstacle(m.normal))
            },
            |c| {
                let local = pose.inverse_transform_point(c);
                pose.transform_point(local.clamp(-half, half))
            },
        );
    }
}

#[test]
fn triangle_against_the_references() {
    let mut rng = Rng::new(4);
    for k in 0..6 {
        let tri = match k {
            // A sliver and a zero-area one among random triangles.
            4 => Triangle::new(
                Vec3::ZERO,
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(1.0, 1e-3, 0.1),
            ),
            5 => Triangle::new(
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(2.0, 2.0, 0.0),
            ),
            _ => Triangle::new(rng.in_cube(1.5), rng.in_cube(1.5), rng.in_cube(1.5)),
        };
        let size = tri.aabb().half_extents().max_element();
        run(
            &format!("triangle {k}"),
            (1000, SAMPLES, 40 + k),
            |rng| {
                let sweep = random_sweep(rng, size, tri.centroid(), tri.normal());
                (sweep, toi_sphere_triangle(&sweep, &tri))
            },
            // The triangle is shape A: the normal already points toward the sphere.
            |c, r| contact_triangle_sphere(&tri, c, &Sphere { radius: r }).map(|m| m.normal),
            |c| tri.closest_point(c),
        );
    }
}

/// Two sweeps that tend to meet: `b` is aimed near where `a` is at a random time `τ`, and gets
/// there at `τ`.
fn converging_pair(rng: &mut Rng) -> (SphereSweep, SphereSweep) {
    let a = random_sweep(rng, 1.0, Vec3::ZERO, None);
    let radius = rng.radius();
    let start = rng.in_cube(3.0);
    let tau = rng.range(0.2, 1.2);
    let meet = a.position_at(tau) + rng.in_cube(a.radius() + radius + 0.3);
    let b = SphereSweep::new(start, radius, (meet - start) / tau);
    (a, b.expect("finite sweep"))
}

#[test]
fn moving_spheres_equal_the_static_query_on_relative_motion_and_the_sampled_pair() {
    let mut rng = Rng::new(5);
    let mut hits = 0;
    let step = 1.0 / SAMPLES as f32;
    for i in 0..2000 {
        let (a, b) = converging_pair(&mut rng);
        let toi = toi_spheres_moving(&a, &b);
        let relative =
            SphereSweep::new(a.center(), a.radius(), a.displacement() - b.displacement());
        let b_sphere = Sphere { radius: b.radius() };
        let expected = toi_sphere_sphere(&relative.expect("finite"), b.center(), &b_sphere);
        assert_eq!(
            toi.map(|x| (x.t, x.normal)),
            expected.map(|x| (x.t, x.normal)),
            "#{i}"
        );
        // Sampled with both spheres moving.
        let a_sphere = Sphere { radius: a.radius() };
        let apart = |t: f32| {
            contact_sphere_sphere(b.position_at(t), &b_sphere, a.position_at(t), &a_sphere)
                .is_none()
        };
        let eps = 1e-4;
        match toi {
            Some(toi) => {
                hits += 1;
                let (pa, pb) = (a.position_at(toi.t), b.position_at(toi.t));
                let gap = pa.distance(pb) - a.radius() - b.radius();
                assert!(
                    gap.abs() < eps || (toi.t == 0.0 && gap <= 0.0),
                    "#{i}: gap {gap}"
                );
                if toi.t > 0.0 {
                    assert!((toi.point - (pb + toi.normal * b.radius())).length() < eps);
                }
                let mut before = (0..SAMPLES).map(|k| k as f32 * step);
                assert!(
                    before.all(|t| t >= toi.t - step || apart(t)),
                    "#{i}: in contact before {toi:?}"
                );
            }
            None => {
                let closest = (0..=SAMPLES).map(|k| {
                    let t = k as f32 * step;
                    a.position_at(t).distance(b.position_at(t)) - a.radius() - b.radius()
                });
                let closest = closest.fold(f32::INFINITY, f32::min);
                assert!(closest > -eps, "#{i}: missed, overlapping by {closest}");
            }
        }
    }
    assert!(hits > 400 && hits < 1800, "{hits}");
}

#[test]
fn mesh_through_its_bvh_against_the_references() {
    let mesh = TriMesh::uv_sphere(1.0, 8, 5).expect("mesh");
    let options = BuildOptions::default();
    let aabb_tree = Bvh::<Aabb>::build(mesh.vertices(), mesh.triangles(), &options);
    let obb_tree = Bvh::<Obb>::build(mesh.vertices(), mesh.triangles(), &options);
    let (aabb_tree, obb_tree) = (aabb_tree.expect("bvh"), obb_tree.expect("bvh"));
    let pose = Isometry::new(Vec3::new(0.4, 0.1, -0.3), Quat::from_rotation_z(1.1));
    let world: Vec<Triangle> = mesh
        .iter_triangles()
        .map(|t| t.transformed(&pose))
        .collect();
    let mut scratch = QueryScratch::new();
    run(
        "mesh",
        (500, 400, 6),
        |rng| {
            let sweep = random_sweep(rng, 1.0, pose.translation, None);
            let (toi, _) = toi_sphere_trimesh(&sweep, &mesh, &aabb_tree, &pose, &mut scratch);
            let (obb, _) = toi_sphere_trimesh(&sweep, &mesh, &obb_tree, &pose, &mut scratch);
            // The same hit up to the window in which a face wins a near-tie.
            let window = sweep.tolerance() / sweep.displacement().length().max(1e-30);
            match (toi, obb) {
                (Some(a), Some(b)) => assert!((a.toi.t - b.toi.t).abs() <= window),
                (a, b) => assert_eq!(a.is_some(), b.is_some()),
            }
            (sweep, toi.map(|m| m.toi))
        },
        // The mesh's static contact: its deepest triangle in contact.
        |c, r| {
            world
                .iter()
                .filter_map(|t| contact_triangle_sphere(t, c, &Sphere { radius: r }))
                .max_by(|a, b| a.max_depth().total_cmp(&b.max_depth()))
                .map(|m| m.normal)
        },
        |c| {
            world
                .iter()
                .map(|t| t.closest_point(c))
                .min_by(|a, b| a.distance_squared(c).total_cmp(&b.distance_squared(c)))
                .unwrap_or(c)
        },
    );
}
