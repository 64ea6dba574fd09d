//! The case continuous collision exists for: a fast ball against a wall 0.01 thick, at
//! 10–1000 m/s with a 60 Hz step, from any angle. A discrete step misses the wall (the ball is
//! on one side, then on the other, never overlapping it); the time of impact never does.

use crate::ccd_common;

use ccd_common::Rng;
use glam::{Quat, Vec3};
use urto::bounding::Aabb;
use urto::bvh::{BuildOptions, Bvh, QueryScratch};
use urto::ccd::{SphereSweep, Toi, toi_sphere_cuboid, toi_sphere_trimesh};
use urto::geometry::contacts::contact;
use urto::geometry::{Cuboid, Isometry, Shape, TriMesh};

const DT: f32 = 1.0 / 60.0;
const THICKNESS: f32 = 0.01;
/// Half the wall's width and height.
const SIDE: f32 = 5.0;

/// A fast ball crossing the wall's plane well inside its face, with the analytic time at which
/// it touches the face on its side.
struct Shot {
    sweep: SphereSweep,
    expected_t: f32,
    /// The wall's face normal on the ball's side.
    facing: Vec3,
}

/// A shot at the wall (`pose`, faces along local ±z) from a random side and angle: speed
/// 10–1000 m/s, incidence up to 85° from the normal, radius 0.005–0.5.
fn shot(rng: &mut Rng, pose: &Isometry, half_thickness: f32) -> Shot {
    let speed = 10f32.powf(rng.range(1.0, 3.0));
    let radius = 10f32.powf(rng.range(-2.3, -0.3));
    let side = if rng.unit() < 0.5 { 1.0 } else { -1.0 };
    let incidence = rng.range(0.0, 85f32.to_radians());
    let azimuth = rng.range(0.0, std::f32::consts::TAU);
    let (sin_i, cos_i) = incidence.sin_cos();
    let local_dir = Vec3::new(sin_i * azimuth.cos(), sin_i * azimuth.sin(), -side * cos_i);
    let displacement = local_dir * speed * DT;
    // Cross the plane where the surface is hit at a point well inside the face, at a random
    // fraction of the step.
    let hit_at = rng.range(0.05, 0.95);
    let touch = Vec3::new(
        rng.range(-3.0, 3.0),
        rng.range(-3.0, 3.0),
        side * (half_thickness + radius),
    );
    let start = touch - displacement * hit_at;
    let sweep = SphereSweep::new(
        pose.transform_point(start),
        radius,
        pose.transform_vector(displacement),
    );
    Shot {
        sweep: sweep.expect("finite shot"),
        expected_t: hit_at,
        facing: pose.transform_vector(Vec3::Z * side),
    }
}

fn assert_stopped_at_the_face(toi: Option<Toi>, shot: &Shot, what: &str) {
    let toi = toi.unwrap_or_else(|| panic!("{what}: tunnelled through {:?}", shot.sweep));
    // Off by at most the sweep's tolerance plus the rounding of coordinates about 10 m from the
    // origin, measured as distance from the face.
    let closing = shot.sweep.displacement().dot(shot.facing).abs();
    let miss = (toi.t - shot.expected_t).abs() * closing;
    let allowed = shot.sweep.tolerance() + 1e-5;
    assert!(
        miss <= allowed,
        "{what}: t = {} expected {}: {miss} from the face (allowed {allowed})",
        toi.t,
        shot.expected_t
    );
    assert!(
        (toi.normal - shot.facing).length() < 1e-4,
        "{what}: normal {} facing {} {toi:?} {:?} exp {}",
        toi.normal,
        shot.facing,
        shot.sweep,
        shot.expected_t
    );
}

fn wall_pose(rng: &mut Rng) -> Isometry {
    let axis = rng.direction();
    Isometry::new(
        rng.in_cube(10.0),
        Quat::from_axis_angle(axis, rng.range(0.0, 3.1)),
    )
}

#[test]
fn a_discrete_step_tunnels_through_the_thin_wall_and_the_toi_catches_it() {
    let wall = Shape::cuboid(Vec3::new(SIDE, SIDE, THICKNESS / 2.0));
    let pose = Isometry::IDENTITY;
    let ball = Shape::sphere(0.05);
    // 100 m/s straight at the wall: 1.67 m per step.
    let start = Vec3::new(0.0, 0.0, 0.8);
    let displacement = Vec3::new(0.0, 0.0, -100.0 * DT);
    let end = start + displacement;
    let at = |c: Vec3| contact(&ball, &Isometry::from_translation(c), &wall, &pose);
    assert!(
        at(start).is_none() && at(end).is_none(),
        "the discrete test sees nothing"
    );
    assert!(
        start.z > 0.0 && end.z < 0.0,
        "yet the ball crossed the wall"
    );
    let sweep = SphereSweep::new(start, 0.05, displacement).expect("finite");
    let toi = toi_sphere_cuboid(
        &sweep,
        &pose,
        &Cuboid {
            half_extents: Vec3::new(SIDE, SIDE, THICKNESS / 2.0),
        },
    );
    let toi = toi.expect("the TOI catches the wall");
    let expected = (0.8 - 0.005 - 0.05) / (100.0 * DT);
    assert!((toi.t - expected).abs() < 1e-6, "{toi:?}");
    assert_eq!(toi.normal, Vec3::Z);
    // Stopped there, the ball touches the wall instead of passing it.
    let stopped = at(sweep.position_at(toi.t) - Vec3::Z * 1e-5).expect("touching");
    assert!(stopped.max_depth() < 1e-4);
}

#[test]
fn box_wall_is_never_missed_from_any_angle_at_10_to_1000_m_per_s() {
    let mut rng = Rng::new(7);
    let cuboid = Cuboid {
        half_extents: Vec3::new(SIDE, SIDE, THICKNESS / 2.0),
    };
    for _ in 0..20 {
        let pose = wall_pose(&mut rng);
        for _ in 0..500 {
            let shot = shot(&mut rng, &pose, THICKNESS / 2.0);
            assert_stopped_at_the_face(
                toi_sphere_cuboid(&shot.sweep, &pose, &cuboid),
                &shot,
                "box",
            );
        }
    }
}

#[test]
fn mesh_walls_thin_box_and_zero_thickness_quad_are_never_missed() {
    let mut rng = Rng::new(8);
    let thin_box = TriMesh::cuboid(Vec3::new(SIDE, SIDE, THICKNESS / 2.0)).expect("mesh");
    let quad = TriMesh::grid_floor(2.0 * SIDE, 3).expect("mesh");
    let mut scratch = QueryScratch::new();
    for (mesh, half_thickness, what) in [
        (&thin_box, THICKNESS / 2.0, "thin box mesh"),
        (&quad, 0.0, "quad"),
    ] {
        let bvh = Bvh::<Aabb>::build(mesh.vertices(), mesh.triangles(), &BuildOptions::default());
        let bvh = bvh.expect("bvh");
        for _ in 0..10 {
            let pose = wall_pose(&mut rng);
            for _ in 0..500 {
                let shot = shot(&mut rng, &pose, half_thickness);
                let (toi, _) = toi_sphere_trimesh(&shot.sweep, mesh, &bvh, &pose, &mut scratch);
                assert_stopped_at_the_face(toi.map(|m| m.toi), &shot, what);
            }
        }
    }
}

#[test]
fn rays_are_never_missed_by_the_quad_either() {
    // Radius zero: the sweep is a ray, the quad has no thickness, and its two triangles share
    // a diagonal the ray may cross exactly.
    let mut rng = Rng::new(9);
    let quad = TriMesh::grid_floor(2.0 * SIDE, 1).expect("mesh");
    let bvh = Bvh::<Aabb>::build(quad.vertices(), quad.triangles(), &BuildOptions::default());
    let bvh = bvh.expect("bvh");
    let mut scratch = QueryScratch::new();
    for _ in 0..5000 {
        let pose = wall_pose(&mut rng);
        // Aim at the diagonal x = y half of the time.
        let u = rng.range(-4.0, 4.0);
        let v = if rng.unit() < 0.5 {
            u
        } else {
            rng.range(-4.0, 4.0)
        };
        let dir =
            Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), -1.0) * rng.range(0.2, 17.0);
        let hit_at = rng.range(0.05, 0.95);
        let start = Vec3::new(u, v, 0.0) - dir * hit_at;
        let ray = SphereSweep::new(pose.transform_point(start), 0.0, pose.transform_vector(dir));
        let (toi, _) = toi_sphere_trimesh(&ray.expect("finite"), &quad, &bvh, &pose, &mut scratch);
        let toi = toi.expect("the ray crosses the quad");
        assert!((toi.toi.t - hit_at).abs() < 1e-4, "{toi:?} vs {hit_at}");
    }
}
