//! parry3d's shape cast (`cast_shapes`, a GJK-based time of impact) as an independent oracle for
//! the ball against a box and against a triangle mesh, on the same seeded sweeps.

use crate::ccd_common;

use ccd_common::{Rng, random_sweep};
use glam::{Quat, Vec3};
use urto::bounding::Aabb;
use urto::bvh::{BuildOptions, Bvh, QueryScratch};
use urto::ccd::{SphereSweep, toi_sphere_cuboid, toi_sphere_trimesh};
use urto::geometry::{Cuboid, Isometry, TriMesh, Triangle};

/// parry's time of impact of the sweep against a static shape, for sweeps not in contact at
/// the start.
fn parry_toi(
    sweep: &SphereSweep,
    pose: &Isometry,
    shape: &dyn parry3d::shape::Shape,
) -> Option<f32> {
    let ball = parry3d::shape::Ball::new(sweep.radius());
    let at = parry3d::math::Pose::from_translation(sweep.center());
    let obstacle = parry3d::math::Pose::from_parts(pose.translation, pose.rotation);
    let options = parry3d::query::ShapeCastOptions::with_max_time_of_impact(1.0);
    parry3d::query::cast_shapes(
        &at,
        sweep.displacement(),
        &ball,
        &obstacle,
        Vec3::ZERO,
        shape,
        options,
    )
    .expect("supported pair")
    .map(|hit| hit.time_of_impact)
}

/// Compares both on sweeps with a radius of at least 0.01 that start apart. When both hit, they
/// must agree within 1e-3 in distance travelled, or else ours must be the exact one: the exact
/// gap `gap(t)` (distance to the obstacle minus the radius) is zero at our time and still
/// positive at parry's (parry's cast stops within its own tolerance of the contact). Hit/miss
/// disagreements (grazes) must be rare.
fn compare(
    name: &str,
    seed: u64,
    pose: &Isometry,
    ours: impl Fn(&SphereSweep) -> Option<f32>,
    shape: &dyn parry3d::shape::Shape,
    closest: impl Fn(Vec3) -> Vec3,
) {
    let mut rng = Rng::new(seed);
    let (mut both, mut parry_early, mut disagreements) = (0, 0, 0);
    for i in 0..3000 {
        let sweep = random_sweep(&mut rng, 1.0, pose.translation, None);
        let speed = sweep.displacement().length();
        if sweep.radius() < 0.01 || speed < 1e-3 || ours(&sweep) == Some(0.0) {
            continue;
        }
        let gap = |t: f32| {
            let c = sweep.position_at(t);
            c.distance(closest(c)) - sweep.radius()
        };
        match (ours(&sweep), parry_toi(&sweep, pose, shape)) {
            (Some(a), Some(b)) => {
                both += 1;
                assert!(gap(a).abs() < 1e-4, "{name} #{i}: our {a} is not a contact");
                if (a - b).abs() * speed > 1e-3 {
                    assert!(b < a && gap(b) > 0.0, "{name} #{i}: ours {a}, parry {b}");
                    parry_early += 1;
                }
            }
            (None, None) => {}
            _ => disagreements += 1,
        }
    }
    println!(
        "{name}: {both} common hits ({parry_early} where parry stops early), \
         {disagreements} hit/miss disagreements"
    );
    assert!(both > 300, "{name}: {both}");
    assert!(
        disagreements * 100 < both,
        "{name}: {disagreements} disagreements"
    );
}

#[test]
fn ball_against_a_box_agrees_with_parry() {
    let pose = Isometry::new(Vec3::new(0.3, -0.2, 0.1), Quat::from_rotation_y(0.8));
    let cuboid = Cuboid {
        half_extents: Vec3::new(1.0, 0.5, 0.75),
    };
    let shape = parry3d::shape::Cuboid::new(cuboid.half_extents);
    compare(
        "box",
        11,
        &pose,
        |s| toi_sphere_cuboid(s, &pose, &cuboid).map(|t| t.t),
        &shape,
        |c| {
            let local = pose.inverse_transform_point(c);
            pose.transform_point(local.clamp(-cuboid.half_extents, cuboid.half_extents))
        },
    );
}

#[test]
fn ball_against_a_mesh_agrees_with_parry() {
    let mesh = TriMesh::uv_sphere(1.0, 16, 8).expect("mesh");
    let bvh = Bvh::<Aabb>::build(mesh.vertices(), mesh.triangles(), &BuildOptions::default());
    let bvh = bvh.expect("bvh");
    let pose = Isometry::new(Vec3::new(-0.2, 0.4, 0.1), Quat::from_rotation_x(0.5));
    let shape = parry3d::shape::TriMesh::new(mesh.vertices().to_vec(), mesh.triangles().to_vec());
    let shape = shape.expect("parry mesh");
    let world: Vec<Triangle> = mesh
        .iter_triangles()
        .map(|t| t.transformed(&pose))
        .collect();
    let scratch = std::cell::RefCell::new(QueryScratch::new());
    compare(
        "mesh",
        12,
        &pose,
        |s| {
            let mut scratch = scratch.borrow_mut();
            toi_sphere_trimesh(s, &mesh, &bvh, &pose, &mut scratch)
                .0
                .map(|m| m.toi.t)
        },
        &shape,
        |c| {
            world
                .iter()
                .map(|t| t.closest_point(c))
                .min_by(|a, b| a.distance_squared(c).total_cmp(&b.distance_squared(c)))
                .unwrap_or(c)
        },
    );
}
