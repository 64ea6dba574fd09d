//! Capsules in the solver: a log rolls down an incline at the rate its axial inertia predicts,
//! lies still on the ground, on a box and on a triangle-mesh floor (two contact points, no
//! seesaw, and no roll from the floor's internal edges), and a standing capsule tipped by a few degrees falls and comes to rest lying.

use super::*;
use crate::geometry::{MeshCollider, TriMesh};

/// A capsule turned so that its axis (local z) runs along world y.
fn along_y() -> Quat {
    Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)
}

#[test]
fn a_log_rolls_down_a_20_degree_incline_as_its_axial_inertia_predicts_within_1_percent() {
    let (half_length, radius) = (0.6, 0.3);
    let theta = 20f32.to_radians();
    let shape = Shape::capsule(half_length, radius);
    let (mut scene, log, downhill) = incline(20.0, shape, 1.0);
    let start = scene.bodies[log].center;
    let t = 1.5;
    scene.run(t);
    // Rolling without slipping: a = g sin θ / (1 + I_axis / (m r²)).
    let mp = Shape::capsule(half_length, radius).mass_properties(1.0);
    let ratio = mp.inertia.z_axis.z / (mp.mass * radius * radius);
    let expected = 0.5 * 9.81 * theta.sin() / (1.0 + ratio) * t * t;
    let travelled = (scene.bodies[log].center - start).dot(downhill);
    assert!(
        (travelled / expected - 1.0).abs() < 0.01,
        "travelled {travelled} m, rolling predicts {expected} m"
    );
    // It rolls about its axis: the axis stays across the slope.
    assert!(axis(&scene.bodies[log]).dot(Vec3::Y).abs() > 0.999);
}

/// Drops nothing: starts a capsule lying at rest `gap` above its support and returns how far it
/// moved and how fast it turns after `seconds`.
fn lying_still(scene: &mut Scene, support_top: f32, seconds: f32) -> (f32, f32, f32) {
    let radius = 0.25;
    let c = scene.add(
        Shape::capsule(0.75, radius),
        Vec3::new(0.3, -0.2, support_top + radius + 0.001),
        Quat::from_rotation_z(0.4) * along_y(),
        3.0,
    );
    let start = scene.bodies[c].center;
    scene.run(seconds);
    let b = &scene.bodies[c];
    let drift = (b.center - start).truncate().length();
    let height = b.center.z - (support_top + radius);
    (drift, height, b.w.length() + axis(b).z.abs())
}

#[test]
fn a_capsule_lying_on_ground_box_and_mesh_stays_within_0_1_mm_and_level_for_3_s() {
    let mut on_ground = Scene::default();
    on_ground.ground(Vec3::Z);
    let mut on_table = Scene::default();
    let table = Shape::cuboid(Vec3::new(2.0, 2.0, 0.5));
    on_table.add(table, Vec3::ZERO, Quat::IDENTITY, 0.0);
    let mut on_mesh = Scene::default();
    let floor = MeshCollider::new(TriMesh::grid_floor(6.0, 12).unwrap()).unwrap();
    on_mesh.add(Shape::TriMesh(floor), Vec3::ZERO, Quat::IDENTITY, 0.0);
    for (name, mut scene, top) in [
        ("ground", on_ground, 0.0),
        ("box", on_table, 0.5),
        ("mesh", on_mesh, 0.0),
    ] {
        let (drift, height, turning) = lying_still(&mut scene, top, 3.0);
        assert!(drift < 1e-4, "{name}: drifted {drift} m");
        assert!(height.abs() < 1e-4, "{name}: {height} m off its support");
        assert!(turning < 1e-3, "{name}: turning or tilting {turning}");
    }
}

#[test]
fn a_standing_capsule_tipped_by_5_degrees_falls_and_rests_lying_within_1_cm() {
    let (half_length, radius) = (0.5, 0.2);
    let mut scene = Scene::default();
    scene.ground(Vec3::Z);
    let c = scene.add(
        Shape::capsule(half_length, radius),
        Vec3::new(0.0, 0.0, half_length + radius + 0.001),
        Quat::from_rotation_x(5f32.to_radians()),
        1.0,
    );
    scene.run(4.0);
    let b = &scene.bodies[c];
    assert!(axis(b).z.abs() < 0.01, "axis {}", axis(b));
    assert!((b.center.z - radius).abs() < 0.01, "height {}", b.center.z);
    assert!(b.v.length() < 0.05, "still moving at {}", b.v);
}
