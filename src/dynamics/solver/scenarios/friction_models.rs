//! Friction per patch ([`FrictionModel::Patch`]) on the scenes per-point friction is judged
//! by, and a box spun on the ground, whose stop both models must time as Coulomb's law does.

use super::*;

const PATCH: FrictionModel = FrictionModel::Patch;

/// A unit cube (half-size 0.5 m, 1 kg) on the ground, both with friction `mu`, solved with
/// `model`: the scene, the ground and the cube.
fn cube_on_the_ground(model: FrictionModel, mu: f32) -> (Scene, usize, usize) {
    let mut scene = Scene::default();
    scene.solver.settings.friction = model;
    let ground = scene.ground(Vec3::Z);
    let b = scene.add(
        Shape::cuboid(Vec3::splat(0.5)),
        Vec3::new(0.0, 0.0, 0.5),
        Quat::IDENTITY,
        1.0,
    );
    for body in [ground, b] {
        scene.bodies[body].friction = mu;
    }
    (scene, ground, b)
}

/// The angular speed of a unit cube spun at `spin` rad/s about the vertical on the ground after
/// `seconds`, with friction `mu` and `model`.
fn spun_box(model: FrictionModel, mu: f32, spin: f32, seconds: f32) -> f32 {
    let (mut scene, _, b) = cube_on_the_ground(model, mu);
    scene.run(0.5);
    scene.bodies[b].w = Vec3::new(0.0, 0.0, spin);
    scene.run(seconds);
    scene.bodies[b].w.z
}

#[test]
fn a_box_spun_on_the_ground_slows_as_coulomb_predicts_within_0_1_percent_per_point_and_per_patch() {
    // Each corner carries m g / 4 at √2 · 0.5 m from the axis and slides across its radius,
    // so friction's torque is μ m g √2 · 0.5 and the cube (I = m s² / 6 = m / 6) slows at
    // 6 μ g √2 · 0.5 rad/s² (20.8 at μ = 0.5) until it stops. Per point, each corner's two
    // friction rows have masses 2.7:1 apart once the box has turned 30°: solved apart and
    // clamped, they slowed it 1.3 % less than this (`Pair::solve_disc`). Above 30 rad/s (half
    // a radian a step) the turning-platform target, which fades out for a point slipping at
    // 2–4 times it, is no longer faded for a corner that slips at `ω r` against its `ω² r h/2`:
    // at 40 rad/s the cube slows 1.7 % less.
    for (mu, spin, t) in [
        (0.5f32, 20.0f32, 0.5f32),
        (0.2, 3.0, 0.25),
        (0.5, 30.0, 0.3),
    ] {
        let slowing = 6.0 * mu * 9.81 * 2f32.sqrt() * 0.5;
        let expected = spin - slowing * t;
        for model in [FrictionModel::PerPoint, PATCH] {
            let w = spun_box(model, mu, spin, t);
            eprintln!("{model:?}: {w} rad/s after {t} s, Coulomb predicts {expected}");
            assert!(
                ((spin - w) / (spin - expected) - 1.0).abs() < 1e-3,
                "{model:?}, mu {mu}, from {spin} rad/s: {w} rad/s, Coulomb predicts {expected}"
            );
        }
    }
    for model in [FrictionModel::PerPoint, PATCH] {
        // And it stops, not reverses.
        let stopped = spun_box(model, 0.5, 20.0, 1.5);
        assert!(stopped.abs() < 0.05, "{model:?}: still {stopped} rad/s");
    }
}

#[test]
fn a_box_on_an_incline_holds_iff_tan_theta_is_below_mu_within_1_degree_per_patch() {
    let mu = 0.5f32; // atan(0.5) = 26.57°
    for (degrees, holds) in [(25.5, true), (27.6, false)] {
        let (mut scene, b, downhill) = incline(degrees, Shape::cuboid(Vec3::splat(0.25)), mu);
        scene.solver.settings.friction = PATCH;
        let start = scene.bodies[b].center;
        scene.run(2.0);
        let slid = (scene.bodies[b].center - start).dot(downhill);
        assert_eq!(slid < 0.01, holds, "{degrees}°: slid {slid} m");
    }
}

#[test]
fn a_tall_box_pushed_at_its_top_tips_over_and_pushed_at_its_base_slides_per_patch() {
    tall_box_pushed(PATCH);
}

#[test]
fn a_stack_of_10_boxes_stands_10_s_with_drift_under_1_cm_per_patch() {
    let (drift, sag) = stack_drift(10, 10.0, PATCH);
    eprintln!("10 boxes, per patch: drift {drift} m, sag {sag} m");
    assert!(drift < 0.01, "drift {drift} m");
    assert!(sag < 0.01, "sag {sag} m");
}

/// The price of three rows instead of eight: a 20-box stack sways 2.0 cm in 10 s where per
/// point it sways 0.6 cm (measured), so per point stays the default.
#[test]
fn a_stack_of_20_boxes_stands_10_s_drifting_under_3_cm_per_patch() {
    let (drift, sag) = stack_drift(20, 10.0, PATCH);
    eprintln!("20 boxes, per patch: drift {drift} m, sag {sag} m");
    assert!(drift < 0.03, "drift {drift} m");
    assert!(sag < 0.04, "sag {sag} m");
}

#[test]
fn a_20_row_pyramid_of_210_boxes_stands_3_s_with_drift_under_1_cm_per_patch() {
    let drift = pyramid_drift(2, 3.0, PATCH);
    eprintln!("pyramid, per patch: drift {drift} m");
    assert!(drift < 0.01, "drift {drift} m");
}

/// A unit cube sliding on the ground slows at `μ g` (Coulomb) until it stops: its speed after
/// `t` is `v₀ − μ g t`, per point and per patch, also where its points slide 8–33 cm a step.
#[test]
fn a_box_sliding_at_5_to_20_m_s_slows_at_mu_g_within_0_1_percent_per_point_and_per_patch() {
    for model in [FrictionModel::PerPoint, PATCH] {
        for (mu, v0) in [(0.5f32, 5.0f32), (0.2, 10.0), (0.5, 20.0)] {
            let mut scene = Scene::default();
            scene.solver.settings.friction = model;
            let ground = scene.ground(Vec3::Z);
            let cube = Shape::cuboid(Vec3::splat(0.5));
            let b = scene.add(cube, Vec3::new(0.0, 0.0, 0.5), Quat::IDENTITY, 1.0);
            for body in [ground, b] {
                scene.bodies[body].friction = mu;
            }
            scene.run(0.5);
            scene.bodies[b].v = Vec3::new(v0, 0.0, 0.0);
            let t = 0.5;
            scene.run(t);
            let (v, expected) = (scene.bodies[b].v, v0 - mu * 9.81 * t);
            assert!(
                (v.x / expected - 1.0).abs() < 1e-3 && v.y.abs() < 1e-3,
                "{model:?}, mu {mu}, from {v0} m/s: {v} after {t} s, Coulomb predicts {expected}"
            );
        }
    }
}

/// A unit cube sliding at 5 m/s on the ground with friction 0.5 for 0.2 s, then with its
/// friction (and the ground's) set to 0: its speed 1 s later, with `model`.
fn slide_then_lose_friction(model: FrictionModel) -> (f32, f32) {
    let (mut scene, ground, b) = cube_on_the_ground(model, 0.5);
    scene.run(0.2);
    scene.bodies[b].v = Vec3::new(5.0, 0.0, 0.0);
    scene.run(0.2);
    let sliding = scene.bodies[b].v.x;
    for body in [ground, b] {
        scene.bodies[body].friction = 0.0;
    }
    scene.run(1.0);
    (sliding, scene.bodies[b].v.x)
}

#[test]
fn friction_set_to_0_while_sliding_leaves_the_speed_within_1e_4_per_point_and_per_patch() {
    // The rows of a contact without friction are not solved; the last step's friction
    // impulses, carried into the warm start, then pushed for ever: the box slowed, stopped and
    // accelerated backwards at μ g (−2.35 m/s 1 s later, by a probe through the ECS).
    for model in [FrictionModel::PerPoint, PATCH] {
        let (sliding, after) = slide_then_lose_friction(model);
        assert!(
            sliding > 3.0 && sliding < 4.5,
            "{model:?}: sliding at {sliding}"
        );
        assert!(
            (after - sliding).abs() < 1e-4,
            "{model:?}: {sliding} → {after} m/s"
        );
    }
}

/// How far `shape` (1 kg), its base `base` below its centre along its z axis, standing on a 30°
/// slope with friction 1 (1.7 tan θ) creeps in 10 s after settling for 0.5 s, with `model`.
fn held_on_a_slope(shape: Shape, base: f32, model: FrictionModel) -> f32 {
    let theta = 30f32.to_radians();
    let normal = Vec3::new(-theta.sin(), 0.0, theta.cos());
    let mut scene = Scene::default();
    scene.solver.settings.friction = model;
    let ground = scene.ground(normal);
    let tilt = Quat::from_rotation_y(-theta);
    let b = scene.add(shape, normal * base, tilt, 1.0);
    for body in [ground, b] {
        scene.bodies[body].friction = 1.0;
    }
    scene.run(0.5);
    let start = scene.bodies[b].center;
    scene.run(10.0);
    (scene.bodies[b].center - start).length()
}

#[test]
fn a_squat_cylinder_held_on_a_30_degree_slope_creeps_under_0_1_mm_in_10_s_per_point_and_per_patch()
{
    // Its cap's corners turned with the support direction's rounding, each step other points
    // of its rim, and per point it crept 28.5 mm (a user-style probe); they are fixed in its
    // frame when the cap meets the plane square on (`support.rs`, `FLAT_CAP_SINE`).
    for model in [FrictionModel::PerPoint, PATCH] {
        let crept = held_on_a_slope(Shape::cylinder(0.2, 0.5), 0.2, model);
        assert!(crept < 1e-4, "{model:?}: crept {crept} m");
    }
}

#[test]
fn a_cone_held_on_a_30_degree_slope_creeps_under_0_1_mm_in_10_s_per_point_and_per_patch() {
    // Its base rocks by about 0.07 mrad; its deepest corner passed between neighbours, and
    // the manifold switched between two squares of its eight corners, each switch losing the
    // friction's warm start: 84 mm per point (`manifold_reduction.rs`, `round_and_flat`).
    for model in [FrictionModel::PerPoint, PATCH] {
        let crept = held_on_a_slope(Shape::cone(0.5, 0.5), 0.5, model);
        assert!(crept < 1e-4, "{model:?}: crept {crept} m");
    }
}
