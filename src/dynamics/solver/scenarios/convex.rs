//! Shapes that collide through GJK/EPA in the solver: a cylinder rolls down an incline at the
//! rate its axial inertia predicts, stands still on its cap on the ground, a box and a mesh
//! floor, and a cylinder rolling across a tessellated floor keeps its line, a log rolling down
//! a tessellated incline stays on it; hull boxes stack; a
//! hull gem dropped on the ground settles on a face; an ellipsoid rocks on the ground without
//! leaving it. Two bounds here are measured limits, not goals (see the tests).

use super::*;
use crate::geometry::{MeshCollider, TriMesh, box_hull as hull_box};

#[test]
fn a_cylinder_rolls_down_a_20_degree_incline_at_two_thirds_g_sin_theta_within_1_percent() {
    let theta = 20f32.to_radians();
    let (mut scene, c, downhill) = incline(20.0, Shape::cylinder(0.4, 0.3), 1.0);
    let start = scene.bodies[c].center;
    let t = 1.5;
    scene.run(t);
    // Rolling without slipping, I = m r²/2: a = g sin θ / (1 + 1/2).
    let expected = 0.5 * 9.81 * theta.sin() / 1.5 * t * t;
    let travelled = (scene.bodies[c].center - start).dot(downhill);
    assert!(
        (travelled / expected - 1.0).abs() < 0.01,
        "travelled {travelled} m, rolling predicts {expected} m"
    );
    assert!(axis(&scene.bodies[c]).dot(Vec3::Y).abs() > 0.999);
}

#[test]
fn a_standing_cylinder_rests_on_ground_within_0_2_mm_box_0_25_mm_and_mesh_0_5_mm_for_3_s() {
    let (half_height, radius) = (0.5, 0.3);
    let mut on_ground = Scene::default();
    on_ground.ground(Vec3::Z);
    let mut on_table = Scene::default();
    on_table.add(
        Shape::cuboid(Vec3::new(2.0, 2.0, 0.5)),
        Vec3::ZERO,
        Quat::IDENTITY,
        0.0,
    );
    let mut on_mesh = Scene::default();
    let floor = MeshCollider::new(TriMesh::grid_floor(6.0, 12).unwrap()).unwrap();
    on_mesh.add(Shape::TriMesh(floor), Vec3::ZERO, Quat::IDENTITY, 0.0);
    // On a mesh the cap's octagon is clipped triangle by triangle and the pieces merged
    // (`mesh_manifold.rs`): the merged points are not symmetric about the axis.
    // The drift is rounding at work, not a bias: two orderings of the same arithmetic (each
    // anchor turned by its body's rotation, or the normal turned back once per contact) gave
    // 0.027 and 0.018 mm on the ground, 0.067 and 0.160 mm on the box, 0.48 and 0.21 mm on
    // the mesh; a still body's anchor taken as zero in the separation (2026-12-06) 0.014 mm
    // on the ground and 0.202 mm on the box.
    for (name, mut scene, top, bound) in [
        ("ground", on_ground, 0.0, 2e-4),
        ("box", on_table, 0.5, 2.5e-4),
        ("mesh", on_mesh, 0.0, 5e-4),
    ] {
        let start = Vec3::new(0.3, -0.2, top + half_height + 0.001);
        let c = scene.add(
            Shape::cylinder(half_height, radius),
            start,
            Quat::from_rotation_z(0.4),
            3.0,
        );
        scene.run(3.0);
        let b = &scene.bodies[c];
        let drift = (b.center - start).truncate().length();
        let height = b.center.z - (top + half_height);
        assert!(drift < bound, "{name}: drifted {drift} m");
        assert!(height.abs() < 1e-4, "{name}: {height} m off its support");
        assert!(
            axis(b).z > 1.0 - 1e-6 && b.w.length() < 1e-3,
            "{name}: tilting"
        );
    }
}

#[test]
fn a_cylinder_rolling_across_a_tessellated_floor_keeps_its_line_within_2_mm_per_m_its_height_within_0_1_mm_and_99_5_percent_of_its_speed()
 {
    let radius = 0.3;
    let floor = MeshCollider::new(TriMesh::grid_floor(20.0, 40).unwrap()).unwrap();
    let mut scene = Scene::default();
    let f = scene.add(Shape::TriMesh(floor), Vec3::ZERO, Quat::IDENTITY, 0.0);
    scene.bodies[f].friction = 1.0;
    let lying = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let c = scene.add(
        Shape::cylinder(0.4, radius),
        Vec3::new(-6.0, 0.1, radius),
        lying,
        2.0,
    );
    scene.bodies[c].friction = 1.0;
    scene.bodies[c].v = Vec3::new(3.0, 0.0, 0.0);
    scene.bodies[c].w = Vec3::new(0.0, 3.0 / radius, 0.0);
    scene.run(2.0);
    let b = &scene.bodies[c];
    let travelled = b.center.x + 6.0;
    assert!(travelled > 5.0, "rolled only {travelled} m");
    // Across the seams: no hop, no veer, and its speed kept. Read as a material point (before
    // `Shape::rounding_along`), it sank 1.8 mm and hopped at the seams, keeping 2.87 m/s of 3;
    // before the seams handed a separated part beside them to the neighbour, 2.39.
    assert!((b.center.z - radius).abs() < 1e-4, "height {}", b.center.z);
    assert!(
        (b.center.y - 0.1).abs() < 2e-3 * travelled,
        "veered to y = {}",
        b.center.y
    );
    assert!(b.v.x > 0.995 * 3.0, "speed {}", b.v.x);
}

#[test]
fn a_log_rolling_down_a_20_degree_tessellated_incline_stays_on_it_within_0_5_mm_at_two_thirds_g_sin_theta_within_1_percent()
 {
    // A 2 m log of radius 0.1 m, its flat ends over the grid's seams: the triangles beyond them,
    // touched side-on by its ends, read it from underneath (a level normal's sign), 199 mm deep,
    // and it sank 14 mm into the incline as it rolled (a user-style probe). It then dipped by up
    // to 1.2 mm for a few steps after crossing some seams parallel to it, until its mesh points
    // were moved under its axis (`trimesh_convex::under_the_axis`): 0.23 mm now (on a
    // half-space 0.04 mm).
    let (theta, radius) = (20f32.to_radians(), 0.1);
    let tilt = Quat::from_rotation_y(-theta);
    let normal = tilt * Vec3::Z;
    let floor = MeshCollider::new(TriMesh::grid_floor(40.0, 80).unwrap()).unwrap();
    let mut scene = Scene::default();
    let f = scene.add(Shape::TriMesh(floor), Vec3::ZERO, tilt, 0.0);
    scene.bodies[f].friction = 1.0;
    let lying = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let start = normal * radius;
    let log = scene.add(Shape::cylinder(1.0, radius), start, tilt * lying, 1.0);
    scene.bodies[log].friction = 1.0;
    let mut off_plane = 0.0f32;
    for _ in 0..90 {
        scene.step();
        let height = (scene.bodies[log].center - start).dot(normal);
        off_plane = off_plane.max(height.abs());
    }
    assert!(off_plane < 5e-4, "{off_plane} m off the incline's plane");
    let downhill = -(tilt * Vec3::X);
    let travelled = (scene.bodies[log].center - start).dot(downhill);
    let expected = 0.5 * 9.81 * theta.sin() / 1.5 * 1.5 * 1.5;
    assert!(
        (travelled / expected - 1.0).abs() < 0.01,
        "travelled {travelled} m, rolling predicts {expected} m"
    );
}

#[test]
fn a_stack_of_6_hull_boxes_stands_5_s_with_drift_under_1_cm() {
    let half = Vec3::new(0.5, 0.4, 0.25);
    let mut scene = Scene::default();
    scene.ground(Vec3::Z);
    let boxes: Vec<usize> = (0..6)
        .map(|k| {
            let at = Vec3::new(0.0, 0.0, half.z * (2 * k + 1) as f32 + 0.001 * k as f32);
            scene.add(hull_box(half), at, Quat::IDENTITY, 1.0)
        })
        .collect();
    scene.run(5.0);
    for (k, &i) in boxes.iter().enumerate() {
        let b = &scene.bodies[i];
        let drift = b.center.truncate().length();
        assert!(drift < 0.01, "box {k} drifted {drift} m");
        assert!(axis(b).z > 0.999, "box {k} tilted");
        assert!(
            (b.center.z - half.z * (2 * k + 1) as f32).abs() < 0.01,
            "box {k} sagged"
        );
    }
}

#[test]
fn a_hull_gem_dropped_on_the_ground_settles_on_a_face_within_1_mm() {
    // An irregular octahedron-like gem, symmetric about the origin so that its centre of mass
    // is the local origin.
    let mut points = Vec::new();
    for p in [
        Vec3::new(0.5, 0.1, 0.05),
        Vec3::new(0.1, 0.4, -0.1),
        Vec3::new(0.05, -0.1, 0.35),
        Vec3::new(0.3, 0.3, 0.2),
        Vec3::new(-0.2, 0.35, 0.25),
    ] {
        points.push(p);
        points.push(-p);
    }
    let gem = Shape::convex_hull(&points).unwrap();
    let Shape::ConvexHull(hull) = &gem else {
        unreachable!()
    };
    let hull = hull.clone();
    let mut scene = Scene::default();
    scene.ground(Vec3::Z);
    let g = scene.add(
        gem,
        Vec3::new(0.0, 0.0, 1.0),
        Quat::from_rotation_x(0.3),
        1.0,
    );
    scene.run(4.0);
    let b = &scene.bodies[g];
    assert!(b.v.length() < 1e-3 && b.w.length() < 1e-2, "still moving");
    // Resting on a face: that face's normal points straight down, and the body's height is
    // the face's offset.
    let down = b.orientation.inverse() * -Vec3::Z;
    let face = hull.faces()[hull.best_face(down)];
    assert!(
        face.normal.dot(down) > 0.999,
        "not on a face: {}",
        face.normal.dot(down)
    );
    assert!(
        (b.center.z - face.offset).abs() < 1e-3,
        "height {}",
        b.center.z
    );
}

#[test]
fn an_ellipsoid_rocking_on_the_ground_stays_in_touch_within_3_mm_and_climbs_under_2_cm_in_6_s() {
    // Rolling without slipping on one point conserves energy: it should rock on and on, never
    // climbing above where it started. The solver keeps each contact point fixed on the body
    // for a step's substeps while the true point runs over the curved surface, which feeds
    // the rocking: 1.6 cm gained in 6 s (measured), a known limit the README states.
    let radii = Vec3::new(0.5, 0.35, 0.2);
    let shape = Shape::ellipsoid(radii);
    let mut scene = Scene::default();
    let ground = scene.ground(Vec3::Z);
    scene.bodies[ground].friction = 1.0;
    let tilt = Quat::from_rotation_x(0.3) * Quat::from_rotation_y(0.2);
    let resting = |q: Quat| shape.world_aabb(&Isometry::new(Vec3::ZERO, q)).max.z;
    let e = scene.add(shape.clone(), Vec3::new(0.0, 0.0, resting(tilt)), tilt, 1.0);
    scene.bodies[e].friction = 1.0;
    let start = scene.bodies[e].center.z;
    let (mut highest, mut worst_gap) = (start, 0.0f32);
    for _ in 0..(6.0 / DT) as usize {
        scene.step();
        let b = &scene.bodies[e];
        highest = highest.max(b.center.z);
        worst_gap = worst_gap.max((b.center.z - resting(b.orientation)).abs());
    }
    assert!(highest < start + 0.02, "climbed to {highest} from {start}");
    assert!(
        worst_gap < 3e-3,
        "left or sank into the ground by {worst_gap} m"
    );
}

/// Two 4 m wide faces of two triangles each, between `xs[0]`, `xs[1]` and `xs[2]` along x, at
/// the heights `surface(x)`: one fold along y at `xs[1]`.
fn folded_strip(xs: [f32; 3], surface: impl Fn(f32) -> f32) -> TriMesh {
    let vertices = xs
        .into_iter()
        .flat_map(|x| [-2.0, 2.0].map(|y| Vec3::new(x, y, surface(x))))
        .collect();
    let triangles = vec![[0, 2, 3], [0, 3, 1], [2, 4, 5], [2, 5, 3]];
    TriMesh::new(vertices, triangles).unwrap()
}

/// A mesh ridge folding by 4° (2° down each side, less than the 5° that makes its edge
/// inactive):
/// a shape resting on the ridge line is held by the seam itself, since neither triangle's
/// face holds its lowest point. The contact rule that drops a seam's contact when the part is
/// over the neighbour must not drop this one, even while the shape is still apart.
#[test]
fn an_ellipsoid_and_a_cylinder_on_a_4_degree_ridge_stay_on_its_surface_within_3_mm() {
    let slope = 2f32.to_radians().tan();
    let surface = |x: f32| -x.abs() * slope;
    let lying = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let shapes = [
        (Shape::ellipsoid(Vec3::splat(0.5)), Quat::IDENTITY),
        (Shape::cylinder(0.5, 0.5), lying),
    ];
    for (shape, orientation) in shapes {
        for x0 in [0.0f32, 0.01, 0.03] {
            let mesh = folded_strip([-2.0, 0.0, 2.0], surface);
            let mut scene = Scene::default();
            let floor = Shape::TriMesh(MeshCollider::new(mesh).unwrap());
            scene.add(floor, Vec3::ZERO, Quat::IDENTITY, 0.0);
            // Dropped at 6 m/s from 5 cm up: only the seam's speculative contact stops it
            // at the surface (10 cm a step).
            let c = scene.add(shape.clone(), Vec3::new(x0, 0.0, 0.55), orientation, 1.0);
            scene.bodies[c].v = Vec3::new(0.0, 0.0, -6.0);
            let mut lowest = f32::MAX;
            for _ in 0..60 {
                scene.step();
                let b = &scene.bodies[c];
                lowest = lowest.min(b.center.z - surface(b.center.x));
            }
            assert!(
                lowest > 0.497,
                "{shape:?} from x = {x0}: {lowest} m above the surface"
            );
        }
    }
}

/// A hull box sliding at 10 m/s, frictionless, from a level face across a 4° valley (an
/// inactive edge, not a flat one) onto the face rising beyond it. It must turn up at the
/// crease: measured 9.4 mm deep at worst, the soft contacts' answer to a 0.7 m/s rise met in
/// one step, and the same when a seam drops every separated contact beside it (so this bounds
/// the solver, not the seam rule).
#[test]
fn a_hull_box_sliding_at_10_m_s_into_a_4_degree_valley_sinks_less_than_12_mm() {
    let slope = 4f32.to_radians().tan();
    let surface = |x: f32| x.max(0.0) * slope;
    let mesh = folded_strip([-2.0, 0.0, 12.0], surface);
    let mut scene = Scene::default();
    let floor = scene.add(
        Shape::TriMesh(MeshCollider::new(mesh).unwrap()),
        Vec3::ZERO,
        Quat::IDENTITY,
        0.0,
    );
    scene.bodies[floor].friction = 0.0;
    let half = Vec3::new(0.3, 0.3, 0.2);
    let b = scene.add(
        hull_box(half),
        Vec3::new(-1.0, 0.0, half.z),
        Quat::IDENTITY,
        1.0,
    );
    scene.bodies[b].friction = 0.0;
    scene.bodies[b].v = Vec3::new(10.0, 0.0, 0.0);
    let mut deepest = 0.0f32;
    for _ in 0..60 {
        scene.step();
        let body = &scene.bodies[b];
        // The lowest corner's depth below the surface under it.
        for k in 0..8 {
            let s = |bit: usize| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
            let corner = body.center + body.orientation * (half * Vec3::new(s(0), s(1), s(2)));
            deepest = deepest.max(surface(corner.x) - corner.z);
        }
    }
    assert!(deepest < 12e-3, "sank {deepest} m into the rising face");
}
