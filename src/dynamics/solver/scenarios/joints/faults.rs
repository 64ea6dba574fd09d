//! Joints the solver cannot use: skipped, and the bodies they name left to fall freely; a NaN
//! joint setting replaced by the defaults.

use super::*;

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
