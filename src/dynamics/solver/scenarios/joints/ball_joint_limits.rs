//! A ball joint's swing cone and twist limit holding a kicked and a spun limb.

use super::*;

/// A 1 kg ball hanging 1 m below a fixed pivot on a ball joint of `kind` (both frames' axes
/// down), kicked with `v` and spun with `w`: the largest swing (angle of the bob's axis from
/// down) and the largest twist over 3 s.
fn kicked_ball_joint(kind: JointKind, v: Vec3, w: Vec3) -> (f32, f32) {
    let mut scene = Scene::default();
    let pivot = anchor(&mut scene, Vec3::ZERO);
    let bob = scene.add(
        Shape::cuboid(Vec3::splat(0.1)),
        Vec3::new(0.0, 0.0, -1.0),
        Quat::IDENTITY,
        1.0,
    );
    scene.bodies[bob].v = v;
    scene.bodies[bob].w = w;
    join(
        &mut scene,
        (pivot, bob),
        (Vec3::ZERO, Vec3::Z),
        Vec3::NEG_Z,
        kind,
    );
    let down = Quat::from_rotation_arc(Vec3::X, Vec3::NEG_Z);
    let (mut swing, mut twist) = (0.0f32, 0.0f32);
    for _ in 0..(3.0 / DT) as usize {
        scene.step();
        let frame = scene.bodies[bob].orientation * down;
        swing = swing.max((frame * Vec3::X).angle_between(Vec3::NEG_Z));
        twist = twist.max(twist_angle(down, frame).abs());
    }
    (swing, twist)
}

#[test]
fn a_swing_cone_of_30_degrees_holds_a_kicked_limb_within_half_a_degree() {
    let free = kicked_ball_joint(BALL, Vec3::X * 4.0, Vec3::ZERO);
    assert!(free.0 > 1.0, "unlimited, the kick swings it {} rad", free.0);
    let cone = JointKind::Spherical {
        swing: Some(30f32.to_radians()),
        twist: None,
    };
    let (swing, _) = kicked_ball_joint(cone, Vec3::X * 4.0, Vec3::ZERO);
    assert!(
        swing < 30.5f32.to_radians(),
        "swung {} degrees",
        swing.to_degrees()
    );
}

#[test]
fn a_twist_limit_of_half_a_radian_holds_a_spun_limb_within_half_a_degree() {
    let free = kicked_ball_joint(BALL, Vec3::ZERO, Vec3::Z * 10.0);
    assert!(free.1 > 1.0, "unlimited, the spin twists it {} rad", free.1);
    let limited = JointKind::Spherical {
        swing: None,
        twist: Some(JointLimit {
            min: -0.5,
            max: 0.5,
        }),
    };
    let (_, twist) = kicked_ball_joint(limited, Vec3::ZERO, Vec3::Z * 10.0);
    assert!(twist < 0.5 + 0.5f32.to_radians(), "twisted {twist} rad");
}
