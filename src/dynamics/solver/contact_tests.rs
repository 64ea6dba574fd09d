//! Tests of `contact.rs`.

use super::*;
use crate::dynamics::solver::{BodyInput, SolverBodies};
use glam::Quat;

/// A contact between bodies `a` and `b` with `count` points, its numbers drawn from `k`.
fn input(a: u32, b: u32, count: u8, k: f32) -> ContactInput {
    let mut points = [ContactPointInput::default(); MAX_MANIFOLD_POINTS];
    for (j, p) in points.iter_mut().enumerate() {
        *p = ContactPointInput {
            point: Vec3::new(k + 0.5, 0.2 * j as f32, -0.1 * k),
            separation: 0.01 * (j as f32 - k),
            ..Default::default()
        };
    }
    ContactInput {
        a,
        b,
        normal: Vec3::new(0.1 * k, 0.3, 1.0).normalize(),
        friction: 0.2 * k,
        restitution: 0.1 * k,
        rolling_resistance: 0.05 * (k - 1.0),
        rounding: [0.0; 2],
        points,
        count,
        key: k as u128,
    }
}

#[test]
fn a_constraint_refilled_over_a_fuller_one_equals_a_fresh_one_on_every_read_value() {
    let mut bodies = SolverBodies::default();
    for i in 0..4 {
        let f = i as f32;
        bodies.push(BodyInput {
            center: Vec3::new(f, 0.2 * f, 0.1),
            orientation: Quat::from_rotation_x(0.3 * f),
            linear_velocity: Vec3::new(0.4, -f, 0.2),
            angular_velocity: Vec3::new(-0.3, 0.5 * f, 1.0),
            inverse_mass: 1.0 / (1.0 + f),
            inverse_principal_inertia: Vec3::new(1.0 + f, 2.0, 3.0),
            ..Default::default()
        });
    }
    let (soft, stiff) = (
        Softness::new(30.0, 10.0, 1.0 / 240.0),
        Softness::new(60.0, 10.0, 1.0 / 240.0),
    );
    let prepare = |c: &ContactInput, s| {
        let model = FrictionModel::PerPoint;
        ContactConstraint::prepare(
            c,
            &bodies.centers,
            &bodies.states,
            &bodies.params,
            RowSettings {
                softness: s,
                friction: model,
                step: 1.0 / 60.0,
            },
        )
    };
    // Last step's constraint: four points with impulses, flipped, rolling.
    let mut reused = prepare(&input(0, 1, 4, 2.0), soft);
    for p in &mut reused.points {
        p.normal_impulse = 0.3;
        p.tangent_impulse = [0.1, -0.2];
        p.max_normal_impulse = 0.4;
    }
    reused.flip = true;
    let next = input(2, 3, 1, 1.0);
    reused.refill(
        &next,
        &bodies.centers,
        &bodies.states,
        &bodies.params,
        RowSettings {
            softness: stiff,
            friction: FrictionModel::PerPoint,
            step: 1.0 / 60.0,
        },
    );
    let fresh = prepare(&next, stiff);
    assert_eq!(reused.points(), fresh.points());
    // Everything but the unused points, which nothing reads.
    let mut unused_cleared = reused;
    unused_cleared.points[1..].copy_from_slice(&fresh.points[1..]);
    assert_eq!(unused_cleared, fresh);
}

#[test]
fn a_rounded_side_rolled_by_any_turn_keeps_its_separation_and_an_unturned_one_adds_exactly_zero() {
    // A ball of radius 0.5 on the ground (B, normal +z), its anchor straight down: rolled by
    // θ its anchor, as a material point, rises by R (1 − cos θ); `rolled` takes that back.
    let (n, radius) = (Vec3::Z, 0.5);
    let anchor = -n * radius;
    for angle in [0.01f32, 0.1, 0.5, 1.0] {
        // A turn about the normal itself (z) lifts nothing either.
        for axis in [
            Vec3::X,
            Vec3::new(0.6, 0.8, 0.0),
            Vec3::new(0.0, 0.6, 0.8),
            Vec3::Z,
        ] {
            let turned = Quat::from_axis_angle(axis, angle).inverse() * n;
            let lifted = anchor.dot(turned) - anchor.dot(n);
            let kept = lifted + normals::rolled([0.0, radius], n, [n, turned]);
            assert!(
                kept.abs() < 1e-6,
                "rolled {angle} rad about {axis}: {kept} m"
            );
        }
    }
    assert_eq!(
        normals::rolled([0.3, 0.5], n, [n, n]).to_bits(),
        0.0f32.to_bits()
    );
}

#[test]
fn a_rounding_that_is_not_a_finite_length_is_taken_as_none_and_the_other_side_kept() {
    let mut bodies = SolverBodies::default();
    for x in [0.0, 1.0] {
        bodies.push(BodyInput {
            center: Vec3::new(x, 0.0, 0.0),
            inverse_mass: 1.0,
            inverse_principal_inertia: Vec3::ONE,
            ..Default::default()
        });
    }
    let settings = RowSettings {
        softness: Softness::new(30.0, 10.0, 1.0 / 240.0),
        friction: FrictionModel::PerPoint,
        step: 1.0 / 60.0,
    };
    let cases = [
        ([f32::NAN, -1.0], [0.0, 0.0]),
        ([f32::INFINITY, 0.5], [0.0, 0.5]),
        ([0.25, f32::NEG_INFINITY], [0.25, 0.0]),
    ];
    for (given, kept) in cases {
        let mut c = input(0, 1, 2, 1.0);
        c.rounding = given;
        let (centers, states, params) = (&bodies.centers, &bodies.states, &bodies.params);
        let prepared = ContactConstraint::prepare(&c, centers, states, params, settings);
        assert_eq!(prepared.rounding, kept, "{given:?}");
    }
}
