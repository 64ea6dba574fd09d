//! Locked translation axes against the rigid-body answer with a per-axis inverse mass
//! `W = diag(1/m per axis)`: along a locked axis the body is immovable, so a contact's
//! effective mass is `1/K`, `K = n·W_a n + n·W_b n + (r×n)·I⁻¹(r×n)` terms.

use super::*;

/// Two balls of 1 kg and radius 0.5 at the same height, A moving at 2 m/s along x into B, whose
/// centre is offset by `(1, 1, 0)/√2`: the normal is `(1, 1, 0)/√2`. No friction, no bounce.
fn oblique_hit(b_free: Vec3) -> Scene {
    let mut scene = Scene::default();
    let d = Vec3::new(1.0, 1.0, 0.0).normalize() * 1.001;
    let a = scene.add(
        Shape::sphere(0.5),
        Vec3::new(-0.3, 0.0, 5.0),
        Quat::IDENTITY,
        1.0,
    );
    let b = scene.add(
        Shape::sphere(0.5),
        Vec3::new(-0.3, 0.0, 5.0) + d,
        Quat::IDENTITY,
        1.0,
    );
    scene.bodies[a].v = Vec3::new(2.0, 0.0, 0.0);
    for i in [a, b] {
        scene.bodies[i].friction = 0.0;
    }
    scene.bodies[b].free_translation = b_free;
    scene
}

#[test]
fn a_ball_locked_along_x_takes_an_oblique_hit_as_the_per_axis_mass_predicts_within_1_percent() {
    // K = n·W_a n + n·W_b n = 1 + ½ (B has no give along x); λ = √2 / K = 2√2/3. A leaves with
    // v_a − λ n = (4/3, −2/3, ·), B with W_b λ n = (0, 2/3, ·); B's x never changes.
    let mut scene = oblique_hit(Vec3::new(0.0, 1.0, 1.0));
    let x0 = scene.bodies[1].center.x;
    for _ in 0..30 {
        scene.step();
        assert_eq!(
            scene.bodies[1].center.x, x0,
            "B moved along its locked axis"
        );
        assert_eq!(scene.bodies[1].v.x, 0.0);
    }
    let (va, vb) = (scene.bodies[0].v, scene.bodies[1].v);
    let close = |got: f32, want: f32| (got - want).abs() <= 0.01 * 4.0 / 3.0;
    assert!(close(va.x, 4.0 / 3.0) && close(va.y, -2.0 / 3.0), "A: {va}");
    assert!(close(vb.y, 2.0 / 3.0), "B: {vb}");
    // Gravity still acts along the free z of both.
    assert!((va.z - vb.z).abs() < 1e-4 && va.z < -4.0, "{va} {vb}");
}

#[test]
fn without_the_lock_the_same_hit_shares_the_momentum_as_two_free_balls_within_1_percent() {
    // The control: equal free masses, e = 0 along n: both end with the same normal speed √2/2,
    // A keeps its tangential speed. A: (1.5, −0.5), B: (0.5, 0.5).
    let mut scene = oblique_hit(Vec3::ONE);
    scene.run(0.5);
    let (va, vb) = (scene.bodies[0].v, scene.bodies[1].v);
    let close = |got: Vec3, want: Vec3| (got.truncate() - want.truncate()).length() <= 0.015;
    assert!(close(va, Vec3::new(1.5, -0.5, 0.0)), "A: {va}");
    assert!(close(vb, Vec3::new(0.5, 0.5, 0.0)), "B: {vb}");
}

#[test]
fn a_box_locked_in_translation_hit_off_centre_only_spins_as_predicted_within_1_percent() {
    // A 1 kg ball at 3 m/s along y bounces (e = 1) off a 2 kg unit cube (translation locked,
    // turning about z only) 0.4 m off its centre. Along n = y: K = 1/m + r²/I with
    // I = m_box/6 = 1/3 and r×n = 0.4 z, so λ = (1 + e) 3/K and ω_z = 0.4 λ / I; the cube's
    // centre stays where it was.
    let mut scene = Scene::default();
    let cube = scene.add(
        Shape::cuboid(Vec3::splat(0.5)),
        Vec3::new(0.0, 0.0, 5.0),
        Quat::IDENTITY,
        2.0,
    );
    let ball = scene.add(
        Shape::sphere(0.1),
        Vec3::new(0.4, -0.7, 5.0),
        Quat::IDENTITY,
        1.0,
    );
    scene.bodies[ball].v = Vec3::new(0.0, 3.0, 0.0);
    for i in [cube, ball] {
        scene.bodies[i].friction = 0.0;
        scene.bodies[i].restitution = 1.0;
    }
    scene.bodies[cube].free_translation = Vec3::ZERO;
    scene.bodies[cube].free_rotation = Vec3::Z;
    let start = scene.bodies[cube].center;
    let (r, inertia) = (0.4, 2.0 / 6.0);
    let lambda = 2.0 * 3.0 / (1.0 + r * r / inertia);
    let want = r * lambda / inertia;
    // The ball is back off at 1.05 m/s before the turning cube's next corner comes round.
    scene.run(0.1);
    let (w, v) = (scene.bodies[cube].w, scene.bodies[ball].v);
    assert_eq!(scene.bodies[cube].center, start, "the locked centre moved");
    assert!((w.z - want).abs() <= 0.01 * want, "ω = {w}, want {want}");
    assert_eq!(w.truncate(), glam::Vec2::ZERO);
    assert!((v.y - (3.0 - lambda)).abs() <= 0.01 * 3.0, "ball {v}");
}

#[test]
fn a_pile_locked_to_the_xz_plane_stays_in_it_bit_for_bit_and_comes_to_rest_under_5_cm_per_s() {
    // A 2.5D pile (gravity along −z): boxes of three sizes locked along y and about x and z,
    // thrown with velocities out of the plane; every contact goes through the one-at-a-time
    // path.
    let mut scene = Scene::default();
    scene.ground(Vec3::Z);
    let mut movers = Vec::new();
    for i in 0..12 {
        let f = i as f32;
        let half = Vec3::new(0.2 + 0.1 * (f % 3.0), 0.3, 0.3 - 0.05 * (f % 2.0));
        let center = Vec3::new(0.2 * (f % 3.0), 0.05 * f, 0.4 + 0.7 * f);
        let k = scene.add(
            Shape::cuboid(half),
            center,
            Quat::from_rotation_y(0.1 * f),
            1.0 + 0.2 * f,
        );
        scene.bodies[k].v = Vec3::new(0.5 - 0.1 * f, 2.0 - 0.3 * f, 0.0);
        scene.bodies[k].w = Vec3::new(1.0, 0.5, -1.0);
        scene.bodies[k].free_translation = Vec3::new(1.0, 0.0, 1.0);
        scene.bodies[k].free_rotation = Vec3::Y;
        movers.push((k, center.y));
    }
    scene.run(6.0);
    for (k, y) in movers {
        let b = &scene.bodies[k];
        assert_eq!(b.center.y, y, "box {k} left its plane");
        assert!(
            b.v.y == 0.0 && b.w.x == 0.0 && b.w.z == 0.0,
            "{k}: {} {}",
            b.v,
            b.w
        );
        assert!(b.center.z > 0.0, "box {k} fell through: {}", b.center);
        assert!(b.v.length() < 0.05, "box {k} still moves: {}", b.v);
    }
}

/// A ball resting on a box: the box static, or dynamic and locked on every axis.
fn ball_on_box(locked_dynamic: bool) -> Scene {
    let mut scene = Scene::default();
    let mass = if locked_dynamic { 5.0 } else { 0.0 };
    let floor = scene.add(
        Shape::cuboid(Vec3::new(2.0, 2.0, 0.5)),
        Vec3::ZERO,
        Quat::IDENTITY,
        mass,
    );
    scene.bodies[floor].free_translation = Vec3::ZERO;
    scene.bodies[floor].free_rotation = Vec3::ZERO;
    scene.add(
        Shape::sphere(0.5),
        Vec3::new(0.0, 0.0, 1.0),
        Quat::IDENTITY,
        1.0,
    );
    scene
}

#[test]
fn a_dynamic_body_locked_on_every_axis_holds_a_ball_as_a_static_one_within_1e_6() {
    // The same immovable support gives the same (static) contact softness: the ball rests at
    // the same height. With the dynamic softness it sank further (a softer contact).
    let (mut fixed, mut locked) = (ball_on_box(false), ball_on_box(true));
    fixed.run(2.0);
    locked.run(2.0);
    let (zf, zl) = (fixed.bodies[1].center.z, locked.bodies[1].center.z);
    assert!((zf - zl).abs() < 1e-6, "static {zf}, locked dynamic {zl}");
    assert_eq!(locked.bodies[0].center, Vec3::ZERO);
}
