//! Hard inputs for the time-of-impact queries: arbitrary magnitudes and degenerate shapes never
//! panic nor give NaN; exactly touching and one ulp apart follow the closed convention; and the
//! step loop the ECS layer will run (move to the impact, reflect, spend the rest of the step)
//! keeps a very fast ball between two thin walls.

use glam::{Quat, Vec3};
use proptest::prelude::*;
use urto::bounding::Aabb;
use urto::bvh::{BuildOptions, Bvh, QueryScratch};
use urto::ccd::{
    InitialOverlap, SphereSweep, Toi, toi_sphere_cuboid, toi_sphere_halfspace, toi_sphere_sphere,
    toi_sphere_triangle, toi_sphere_trimesh, toi_spheres_moving,
};
use urto::geometry::{Cuboid, HalfSpace, Isometry, Sphere, TriMesh, Triangle};

/// A float of any magnitude from 1e-30 to 1e12, either sign, or exactly zero.
fn wide() -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => Just(0.0f32),
        6 => (-30i32..12, 1.0f32..10.0, any::<bool>())
            .prop_map(|(e, m, neg)| if neg { -m * 10f32.powi(e) } else { m * 10f32.powi(e) }),
    ]
}

fn wide_vec() -> impl Strategy<Value = Vec3> {
    (wide(), wide(), wide()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn small_vec() -> impl Strategy<Value = Vec3> {
    (-3.0f32..3.0, -3.0f32..3.0, -3.0f32..3.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn well_formed(toi: Option<Toi>) -> Result<(), TestCaseError> {
    if let Some(toi) = toi {
        prop_assert!((0.0..=1.0).contains(&toi.t), "{toi:?}");
        prop_assert!(
            toi.normal.is_finite() && toi.normal.is_normalized(),
            "{toi:?}"
        );
        prop_assert!(toi.point.is_finite(), "{toi:?}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn any_magnitude_and_any_shape_gives_a_well_formed_answer(
        center in wide_vec(),
        radius in wide().prop_map(f32::abs),
        displacement in wide_vec(),
        other in wide_vec(),
        half in wide_vec().prop_map(Vec3::abs),
        corners in (small_vec(), small_vec(), small_vec()),
        degenerate in 0usize..3,
        angle in 0.0f32..6.3,
    ) {
        let Ok(sweep) = SphereSweep::new(center, radius, displacement) else {
            return Ok(());
        };
        let pose = Isometry::new(other, Quat::from_rotation_z(angle));
        well_formed(toi_sphere_halfspace(&sweep, &pose, &HalfSpace { normal: Vec3::Y }))?;
        well_formed(toi_sphere_sphere(&sweep, other, &Sphere { radius: half.x }))?;
        well_formed(toi_sphere_cuboid(&sweep, &pose, &Cuboid { half_extents: half }))?;
        let (a, b, c) = corners;
        let tri = match degenerate {
            0 => Triangle::new(a, b, c),
            1 => Triangle::new(a, b, a + (b - a) * 2.0),
            _ => Triangle::new(a, a, a),
        };
        well_formed(toi_sphere_triangle(&sweep, &tri))?;
        let still = SphereSweep::new(other, half.y.min(1e30), Vec3::ZERO);
        if let Ok(still) = still {
            well_formed(toi_spheres_moving(&sweep, &still))?;
        }
    }

    #[test]
    fn zero_displacement_reports_only_a_contact_at_the_start(
        center in small_vec(),
        radius in 0.0f32..1.0,
        corners in (small_vec(), small_vec(), small_vec()),
    ) {
        let still = SphereSweep::new(center, radius, Vec3::ZERO).unwrap();
        let (a, b, c) = corners;
        let tri = Triangle::new(a, b, c);
        let touching = tri.closest_point(center).distance(center) <= radius;
        let toi = toi_sphere_triangle(&still, &tri);
        prop_assert_eq!(toi.map(|t| t.t), touching.then_some(0.0));
        let cuboid = Cuboid { half_extents: a.abs() };
        let pose = Isometry::from_translation(b);
        let local = center - b;
        let box_touching = (local - local.clamp(-a.abs(), a.abs())).length() <= radius;
        let toi = toi_sphere_cuboid(&still, &pose, &cuboid);
        prop_assert_eq!(toi.map(|t| t.t), box_touching.then_some(0.0));
    }
}

#[test]
fn exactly_touching_counts_and_one_ulp_apart_does_not() {
    let up = Vec3::Z;
    // Every obstacle's surface passes through the origin with normal +z, and the sphere's
    // bottom sits exactly on it (all numbers exact in binary).
    let ground = HalfSpace { normal: up };
    let cuboid = Cuboid {
        half_extents: Vec3::new(2.0, 2.0, 1.0),
    };
    let box_pose = Isometry::from_translation(Vec3::new(0.0, 0.0, -1.0));
    let ball = Sphere { radius: 1.0 };
    let ball_centre = Vec3::new(0.0, 0.0, -1.0);
    let tri = Triangle::new(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(2.0, -1.0, 0.0),
        Vec3::new(-1.0, 2.0, 0.0),
    );
    // One ulp apart *as the obstacle's arithmetic sees it*: the box and the ball measure from
    // their centres one unit below, where the ulp is that of 1.5.
    let r = 0.5f32;
    let ulp_above_centre = 1.5f32.next_up() - 1.0;
    type Query<'a> = Box<dyn Fn(&SphereSweep) -> Option<Toi> + 'a>;
    let queries: [(&str, Query, f32); 4] = [
        (
            "half-space",
            Box::new(|s| toi_sphere_halfspace(s, &Isometry::IDENTITY, &ground)),
            r.next_up(),
        ),
        (
            "cuboid",
            Box::new(|s| toi_sphere_cuboid(s, &box_pose, &cuboid)),
            ulp_above_centre,
        ),
        (
            "sphere",
            Box::new(|s| toi_sphere_sphere(s, ball_centre, &ball)),
            ulp_above_centre,
        ),
        (
            "triangle",
            Box::new(|s| toi_sphere_triangle(s, &tri)),
            r.next_up(),
        ),
    ];
    for (name, query, apart_z) in &queries {
        let touching = Vec3::new(0.0, 0.0, r);
        let apart = Vec3::new(0.0, 0.0, *apart_z);
        for d in [Vec3::X, -up, up, Vec3::ZERO] {
            let at_start = query(&SphereSweep::new(touching, r, d).unwrap());
            let toi = at_start.unwrap_or_else(|| panic!("{name}: touching at the start, d = {d}"));
            assert_eq!(toi.t, 0.0, "{name}");
            assert!((toi.normal - up).length() < 1e-6, "{name}: {toi:?}");
            let gap = query(&SphereSweep::new(apart, r, d).unwrap());
            if d == -up {
                let toi = gap.unwrap_or_else(|| panic!("{name}: one ulp away and closing"));
                assert!(toi.t > 0.0 && toi.t < 1e-6, "{name}: {toi:?}");
            } else {
                assert!(gap.is_none(), "{name}: one ulp apart, d = {d}: {gap:?}");
            }
        }
        // With ApproachingOnly the touching start counts only when moving in.
        for (d, counts) in [
            (Vec3::X, false),
            (up, false),
            (-up, true),
            (Vec3::ZERO, false),
        ] {
            let s = SphereSweep::new(touching, r, d).unwrap();
            let toi = query(&s.with_initial_overlap(InitialOverlap::ApproachingOnly));
            assert_eq!(toi.is_some(), counts, "{name}, d = {d}");
        }
    }
}

/// The step loop the ECS layer will run, on the core alone: find the first impact over the
/// obstacles, move there, reflect the velocity about the normal, spend the rest of the step.
fn ccd_step(
    position: &mut Vec3,
    velocity: &mut Vec3,
    radius: f32,
    dt: f32,
    walls: &[(Isometry, Cuboid)],
) {
    let mut remaining = dt;
    for _ in 0..8 {
        let sweep = SphereSweep::new(*position, radius, *velocity * remaining)
            .expect("finite")
            .with_initial_overlap(InitialOverlap::ApproachingOnly);
        let first = walls
            .iter()
            .filter_map(|(pose, wall)| toi_sphere_cuboid(&sweep, pose, wall))
            .min_by(|a, b| a.t.total_cmp(&b.t));
        let Some(toi) = first else {
            *position = sweep.position_at(1.0);
            return;
        };
        *position = sweep.position_at(toi.t);
        *velocity -= 2.0 * velocity.dot(toi.normal) * toi.normal;
        remaining *= 1.0 - toi.t;
    }
}

#[test]
fn a_1000_m_per_s_ball_stays_between_two_thin_walls_for_ten_thousand_steps() {
    let wall = Cuboid {
        half_extents: Vec3::new(0.005, 1000.0, 1000.0),
    };
    let walls = [
        (Isometry::from_translation(Vec3::new(-1.0, 0.0, 0.0)), wall),
        (Isometry::from_translation(Vec3::new(1.0, 0.0, 0.0)), wall),
    ];
    let radius = 0.05;
    let mut position = Vec3::ZERO;
    let mut velocity = Vec3::new(1000.0, 3.0, -2.0);
    let inner = 1.0 - 0.005 - radius;
    for step in 0..10_000 {
        ccd_step(&mut position, &mut velocity, radius, 1.0 / 60.0, &walls);
        assert!(
            position.x.abs() <= inner + 1e-4,
            "step {step}: escaped to {position}"
        );
    }
    // Speed is kept by the reflections.
    assert!((velocity.length() - Vec3::new(1000.0, 3.0, -2.0).length()).abs() < 1e-2);
}

#[test]
fn mesh_queries_are_deterministic_whatever_the_scratch_held() {
    let mesh = TriMesh::uv_sphere(1.0, 16, 8).unwrap();
    let bvh =
        Bvh::<Aabb>::build(mesh.vertices(), mesh.triangles(), &BuildOptions::default()).unwrap();
    let sweep = SphereSweep::new(Vec3::new(-3.0, 0.2, 0.1), 0.3, Vec3::new(6.0, 0.0, 0.0)).unwrap();
    let mut fresh = QueryScratch::new();
    let first = toi_sphere_trimesh(&sweep, &mesh, &bvh, &Isometry::IDENTITY, &mut fresh);
    let mut used = QueryScratch::new();
    let other =
        SphereSweep::new(Vec3::new(0.0, 5.0, 0.0), 1.0, Vec3::new(0.0, -10.0, 0.0)).unwrap();
    let _ = toi_sphere_trimesh(&other, &mesh, &bvh, &Isometry::IDENTITY, &mut used);
    let again = toi_sphere_trimesh(&sweep, &mesh, &bvh, &Isometry::IDENTITY, &mut used);
    assert_eq!(first, again);
    let hit = first.0.expect("hit");
    assert_eq!(hit.toi.t.to_bits(), again.0.expect("hit").toi.t.to_bits());
}

#[test]
fn non_finite_obstacles_do_not_panic() {
    let sweep =
        SphereSweep::new(Vec3::new(0.1, -0.2, 3.0), 0.5, Vec3::new(0.2, 0.1, -6.0)).unwrap();
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let v = Vec3::new(bad, 0.0, 1.0);
        let pose = Isometry::from_translation(v);
        let turned = Isometry::new(Vec3::ZERO, Quat::from_xyzw(bad, 0.0, 0.0, 1.0));
        for p in [pose, turned] {
            let _ = toi_sphere_halfspace(&sweep, &p, &HalfSpace { normal: v });
            let _ = toi_sphere_cuboid(&sweep, &p, &Cuboid { half_extents: v });
            let _ = toi_sphere_cuboid(
                &sweep,
                &p,
                &Cuboid {
                    half_extents: Vec3::ONE,
                },
            );
        }
        let _ = toi_sphere_sphere(&sweep, v, &Sphere { radius: bad });
        let _ = toi_sphere_triangle(&sweep, &Triangle::new(v, Vec3::X, Vec3::Y));
    }
}
