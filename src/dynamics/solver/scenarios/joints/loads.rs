//! What a joint reports it holds ([`Solver::joint_loads`], the ECS's `JointLoad`) against
//! statics: a level arm's weight and moment.

use super::*;

/// A 10 kg arm 1 m long held level at its end by a joint of `kind` to a fixed pivot, its
/// joint axis `axis` (both frames): the force and torque the joint reports after 2 s.
fn level_arm(kind: JointKind, axis: Vec3) -> (f32, f32) {
    let mut scene = Scene::default();
    let pivot = anchor(&mut scene, Vec3::new(0.0, 0.0, 5.0));
    let half = Vec3::new(0.5, 0.05, 0.05);
    let at = Vec3::new(0.5, 0.0, 5.0);
    let arm = scene.add(Shape::cuboid(half), at, Quat::IDENTITY, 10.0);
    join(
        &mut scene,
        (pivot, arm),
        (Vec3::ZERO, -Vec3::X * 0.5),
        axis,
        kind,
    );
    scene.run(2.0);
    let (_, load) = scene.solver.joint_loads().next().unwrap_or_default();
    (load.force, load.torque)
}

#[test]
fn a_level_arm_on_a_limited_hinge_or_a_swing_cone_reports_its_weight_and_moment_within_1_percent() {
    // The limit's and the cone's rows turn the arm about the joint's anchors, so the point
    // rows' answer rides in their impulse: the reported force, the point rows' alone, was
    // 24.7 N of 98.1 (a probe through the ECS; `breakable` held four times its threshold).
    let (weight, moment) = (10.0 * 9.81, 10.0 * 9.81 * 0.5);
    let hinge = JointKind::Revolute {
        limit: Some(JointLimit { min: 0.0, max: 0.0 }),
        motor: None,
    };
    let cone = JointKind::Spherical {
        swing: Some(0.01),
        twist: None,
    };
    for (name, kind, axis) in [("hinge", hinge, Vec3::Y), ("cone", cone, Vec3::X)] {
        let (force, torque) = level_arm(kind, axis);
        assert!((force / weight - 1.0).abs() < 0.01, "{name}: {force} N");
        assert!((torque / moment - 1.0).abs() < 0.01, "{name}: {torque} N m");
    }
}
