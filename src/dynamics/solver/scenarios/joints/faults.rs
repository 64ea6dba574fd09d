//! Joints the solver cannot use: skipped, and the bodies they name left to fall freely; a NaN
//! joint setting replaced by the defaults. Joints that are valid but violent (spawned metres
//! from their anchors, or fighting each other) held to the speed bound.

use super::*;
use crate::dynamics::solver::joint_list::JointList;

/// A 1 kg ball of radius 0.1 hanging 1 m below a fixed pivot, tied to it at `bob_anchor` by a
/// joint of `kind` (axis y).
fn bob_below_pivot(scene: &mut Scene, bob_anchor: Vec3, kind: JointKind) -> usize {
    let pivot = anchor(scene, Vec3::ZERO);
    let bob = scene.add(
        Shape::sphere(0.1),
        Vec3::new(0.0, 0.0, -1.0),
        Quat::IDENTITY,
        1.0,
    );
    join(scene, (pivot, bob), (Vec3::ZERO, bob_anchor), Vec3::Y, kind);
    bob
}

#[test]
fn an_unusable_joint_is_skipped_and_a_nan_joint_setting_steps_with_the_defaults() {
    // A NaN anchor, an empty limit and a negative motor force: the bob falls freely, finite.
    let bad_kinds = [
        (Vec3::NAN, BALL),
        (
            Vec3::Z,
            JointKind::Revolute {
                limit: Some(JointLimit {
                    min: 1.0,
                    max: -1.0,
                }),
                motor: None,
            },
        ),
        (
            Vec3::Z,
            JointKind::Revolute {
                limit: None,
                motor: Some(JointMotor::velocity(1.0, -5.0)),
            },
        ),
    ];
    for (bob_anchor, kind) in bad_kinds {
        let mut scene = Scene::default();
        let bob = bob_below_pivot(&mut scene, bob_anchor, kind);
        scene.run(0.5);
        let z = scene.bodies[bob].center.z;
        assert!(
            z.is_finite() && z < -1.0 - 0.5 * 9.81 * 0.25 * 0.9,
            "{kind:?}: z = {z}"
        );
        assert!(scene.solver.joints().is_empty(), "{kind:?} was solved");
    }
    // A NaN joint stiffness: the solver steps with its defaults and the joint holds.
    let mut scene = Scene::default();
    scene.solver.settings.joint_hertz = f32::NAN;
    let bob = bob_below_pivot(&mut scene, Vec3::Z, BALL);
    scene.run(0.5);
    assert_eq!(scene.solver.settings, SoftStepSettings::default());
    let z = scene.bodies[bob].center.z;
    assert!((z + 1.0).abs() < 0.01, "the joint let go: z = {z}");
}

/// A 10 g ball tied by a ball joint to a 10 t block 20 m away (valid but violent: the joint
/// closes the gap at once), stepped 30 times with `max_linear_speed`; the ball's top speed,
/// as its velocity or as the distance it moved in a step over the step (the relax passes take
/// the error-closing speed back out of the velocity a step hands out, not out of the motion).
fn snap_from_20_m(max_linear_speed: f32) -> f32 {
    let mut scene = Scene::default();
    scene.solver.settings.max_linear_speed = max_linear_speed;
    let block = scene.add(Shape::cuboid(Vec3::ONE), Vec3::ZERO, Quat::IDENTITY, 1e4);
    let far = Vec3::new(20.0, 0.0, 0.0);
    let ball = scene.add(Shape::sphere(0.05), far, Quat::IDENTITY, 0.01);
    join(
        &mut scene,
        (block, ball),
        (Vec3::ZERO, Vec3::ZERO),
        Vec3::Y,
        BALL,
    );
    let mut fastest = 0.0f32;
    for _ in 0..30 {
        let start = scene.bodies[ball].center;
        scene.step();
        let (v, moved) = (scene.bodies[ball].v, scene.bodies[ball].center - start);
        assert!(v.is_finite() && moved.is_finite(), "{v}, {moved}");
        fastest = fastest.max(v.length()).max(moved.length() / DT);
    }
    fastest
}

#[test]
fn a_joint_spawned_20_m_apart_on_a_10_g_ball_snaps_it_no_faster_than_the_400_m_per_s_bound() {
    let bound = SoftStepSettings::default().max_linear_speed;
    let fastest = snap_from_20_m(bound);
    assert!(fastest <= bound * (1.0 + 1e-6), "{fastest} m/s");
    // It was the bound that held it: unbounded, the same snap is faster.
    let unbounded = snap_from_20_m(1e9);
    assert!(unbounded > bound, "{unbounded} m/s");
}

#[test]
fn a_ball_welded_to_two_posts_it_cannot_reach_at_once_stays_finite_and_under_400_m_per_s_for_10_s()
{
    // Two rigid welds that disagree by metres, on a light ball with a small inertia, fight in
    // every relax pass; carried from step to step unbounded, their impulses grew until the
    // ball turned NaN (found by the scene fuzz).
    let mut scene = Scene::default();
    let posts = [Vec3::new(-2.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 0.5)];
    let post = posts.map(|at| anchor(&mut scene, at));
    let ball = scene.add(Shape::sphere(0.02), Vec3::ZERO, Quat::IDENTITY, 0.01);
    let offsets = [Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, -0.7, 0.3)];
    let axes = [Vec3::Y, Vec3::new(1.0, 0.0, 1.0)];
    for ((p, offset), axis) in post.into_iter().zip(offsets).zip(axes) {
        join(
            &mut scene,
            (p, ball),
            (Vec3::ZERO, offset),
            axis,
            JointKind::Fixed,
        );
    }
    let bound = SoftStepSettings::default().max_linear_speed;
    let mut steps_bounded = 0;
    for _ in 0..600 {
        scene.step();
        steps_bounded += usize::from(scene.solver.bounded_joints() > 0);
        let b = &scene.bodies[ball];
        assert!(
            b.center.is_finite() && b.orientation.is_finite(),
            "{}",
            b.center
        );
        assert!(
            b.v.length() <= bound * 1.001 && b.w.is_finite(),
            "{} {}",
            b.v,
            b.w
        );
    }
    // The bound is what holds them: the solver says so.
    assert!(steps_bounded > 0, "the warm-start bound never tripped");
}

#[test]
fn a_nan_carried_impulse_is_dropped_and_a_huge_one_scaled_until_the_spin_is_at_its_bound() {
    // A 1 kg ball of radius 0.1 (I = 0.004 kg m²) hung 1 m below a pivot.
    let mut scene = Scene::default();
    let bob = bob_below_pivot(&mut scene, Vec3::Z, BALL);
    scene.step();
    let mut list = JointList::default();
    let unbounded = (f32::INFINITY, f32::INFINITY);
    assert_eq!(list.prepare(&scene.arrays, &scene.joints, unbounded), 0);
    list.set_impulses(0, Vec3::new(f32::NAN, 0.0, 0.0));
    assert_eq!(list.bound_impulses(800.0, 100.0), 1);
    assert_eq!(list.joints()[0].impulses, JointImpulses::default());
    // 1e6 N s at the anchor, 1 m from the centre: the spin bound binds first (100 rad/s needs
    // only 100 · 0.004 / 1 = 0.4 N s), far before the speed bound (800 N s).
    list.set_impulses(0, Vec3::X * 1e6);
    assert_eq!(list.bound_impulses(800.0, 100.0), 1);
    let j = list.joints()[0].impulses.point.length();
    assert!((j / 0.4 - 1.0).abs() < 1e-3, "{j} N s");
    assert!(scene.bodies[bob].center.is_finite());
}

#[test]
fn a_sound_pendulum_swinging_at_3_m_per_s_never_trips_the_warm_start_bound_in_5_s() {
    let mut scene = Scene::default();
    let bob = bob_below_pivot(&mut scene, Vec3::Z, BALL);
    scene.bodies[bob].v = Vec3::X * 3.0;
    for _ in 0..300 {
        scene.step();
        assert_eq!(scene.solver.bounded_joints(), 0);
    }
}
