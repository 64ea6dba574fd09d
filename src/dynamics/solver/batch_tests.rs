//! Tests of `batch.rs`.

use super::*;
use crate::dynamics::solver::contact::on_moving;
use crate::dynamics::solver::{
    BodyInput, ContactInput, ContactPointInput, FrictionModel, RowSettings, Softness, SolverBodies,
};
use glam::Quat;

/// Six moving, turning bodies and three contacts between disjoint pairs, with 4, 2 and 1
/// points, some apart (speculative) and some penetrating, carrying impulses from a warm
/// start, with friction rows as `model` says.
fn scene(model: FrictionModel) -> (SolverBodies, Vec<ContactConstraint>) {
    scene_with(model, false)
}

/// [`scene`]; with `grounds`, bodies 1 and 3 (B of the first two contacts) are static and at
/// rest, and body 5 is kinematic (immovable, moving).
fn scene_with(model: FrictionModel, grounds: bool) -> (SolverBodies, Vec<ContactConstraint>) {
    let mut bodies = SolverBodies::default();
    let ground = |i: usize| grounds && i % 2 == 1;
    for i in 0..6 {
        let f = i as f32;
        let dynamic = BodyInput {
            center: Vec3::new(f, 0.3 * f, 0.0),
            orientation: Quat::from_rotation_y(0.2 * f),
            // Towards the grounds (along the normals), or as the scene always was.
            linear_velocity: Vec3::new(
                0.5 - f * 0.2,
                0.1 * f,
                if grounds { 1.0 } else { -1.0 + 0.3 * f },
            ),
            angular_velocity: Vec3::new(0.7, -0.2 * f, 0.4),
            inverse_mass: 1.0 / (1.0 + f),
            inverse_principal_inertia: Vec3::new(2.0, 3.0, 1.0 + f),
            ..Default::default()
        };
        bodies.push(match (ground(i), i) {
            (true, 5) => BodyInput {
                inverse_mass: 0.0,
                inverse_principal_inertia: Vec3::ZERO,
                ..dynamic
            },
            (true, _) => BodyInput {
                center: dynamic.center,
                ..Default::default()
            },
            _ => dynamic,
        });
    }
    for (i, s) in bodies.states.iter_mut().enumerate() {
        if ground(i) && i != 5 {
            continue;
        }
        s.delta_position = Vec3::new(0.01, -0.02, 0.003 * i as f32);
        s.delta_rotation = Quat::from_rotation_z(0.01 * i as f32);
    }
    let softness = Softness::new(60.0, 10.0, 1.0 / 240.0);
    let constraints = [(0u32, 1u32, 4u8), (2, 3, 2), (4, 5, 1)]
        .iter()
        .enumerate()
        .map(|(k, &(a, b, count))| {
            let mut input = ContactInput {
                a,
                b,
                normal: Vec3::new(0.1, 0.2 * k as f32, 1.0).normalize(),
                friction: 0.6,
                restitution: 0.0,
                rolling_resistance: 0.0,
                rounding: [0.0; 2],
                points: [ContactPointInput::default(); MAX_MANIFOLD_POINTS],
                count,
                key: k as u128,
            };
            for (j, p) in input.points.iter_mut().enumerate() {
                *p = ContactPointInput {
                    point: Vec3::new(a as f32 + 0.5, 0.2 * j as f32, 0.1 * k as f32),
                    separation: 0.01 * (j as f32 - 1.5),
                    ..Default::default()
                };
            }
            let mut c = ContactConstraint::prepare(
                &input,
                &bodies.centers,
                &bodies.states,
                &bodies.params,
                RowSettings {
                    softness,
                    friction: model,
                    step: 1.0 / 60.0,
                },
            );
            // Drift targets (`anchor_drift.rs`) on the first two contacts: their bodies
            // slide too fast for the targets preparation gives, and the rows solve them.
            c.turning = k < 2;
            let drift = if c.turning { 0.05 } else { 0.0 };
            for (j, p) in c.points.iter_mut().enumerate() {
                p.normal_impulse = 0.1 * j as f32;
                p.tangent_impulse = [0.02, -0.01 * j as f32];
                p.tangent_drift = [drift, -drift * j as f32];
            }
            if let Some(patch) = &mut c.patch {
                patch.tangent_impulse = [0.03, -0.02];
                patch.twist_impulse = 0.01 * k as f32;
                patch.tangent_drift = [drift, drift];
            }
            c
        })
        .collect();
    (bodies, constraints)
}

#[test]
fn a_batch_of_disjoint_contacts_solves_as_the_scalar_rows_do_within_1e_5_with_friction_per_point_and_per_patch()
 {
    for model in [FrictionModel::PerPoint, FrictionModel::Patch] {
        batch_against_scalar(model);
    }
}

fn batch_against_scalar(model: FrictionModel) {
    let (bodies, constraints) = scene(model);
    let (h, push) = (1.0 / 240.0, 3.0);
    let mut scalar_states = bodies.states.clone();
    let mut scalar = constraints.clone();
    for c in &mut scalar {
        c.flip = true;
        c.warm_start(&mut scalar_states);
        c.solve(&mut scalar_states, (1.0 / h, push), true, 1.0);
        c.solve(&mut scalar_states, (1.0 / h, push), false, 1.0);
    }
    let mut batch_states = bodies.states.clone();
    let mut batched = constraints.clone();
    let mut batch = packed(&[&[0, 1, 2]], &constraints);
    for refused in [&[][..], &[0, 1, 2, 0, 1], &[0, 7]] {
        assert!(!ContactBatches::default().pack([refused], &constraints));
    }
    batch.warm_start(&mut batch_states);
    batch.solve(&mut batch_states, (1.0 / h, push), true, true, 1.0);
    batch.solve(&mut batch_states, (1.0 / h, push), false, true, 1.0);
    batch.unpack(&mut batched);
    for (s, b) in scalar_states.iter().zip(&batch_states) {
        assert!(
            (s.linear_velocity - b.linear_velocity).length() < 1e-5,
            "{s:?} {b:?}"
        );
        assert!((s.angular_velocity - b.angular_velocity).length() < 1e-5);
    }
    for (s, b) in scalar.iter().zip(&batched) {
        for (ps, pb) in s.points().iter().zip(b.points()) {
            assert!(
                (ps.normal_impulse - pb.normal_impulse).abs() < 1e-5,
                "{ps:?} {pb:?}"
            );
            assert!((ps.tangent_impulse[0] - pb.tangent_impulse[0]).abs() < 1e-5);
            assert!((ps.tangent_impulse[1] - pb.tangent_impulse[1]).abs() < 1e-5);
            assert!((ps.relative_velocity - pb.relative_velocity).abs() < 1e-5);
            assert_eq!(ps.max_normal_impulse > 0.0, pb.max_normal_impulse > 0.0);
        }
        assert_eq!(s.patch.is_some(), model == FrictionModel::Patch);
        if let (Some(ps), Some(pb)) = (s.patch, b.patch) {
            for k in 0..2 {
                assert!((ps.tangent_impulse[k] - pb.tangent_impulse[k]).abs() < 1e-5);
            }
            assert!(
                (ps.twist_impulse - pb.twist_impulse).abs() < 1e-5,
                "{ps:?} {pb:?}"
            );
        }
    }
    // The friction rows acted: a patch's twist moved off its warm start where its points
    // pushed apart from the centre.
    if model == FrictionModel::Patch {
        let twists = batched
            .iter()
            .filter_map(|c| c.patch.map(|p| p.twist_impulse));
        assert!(twists.zip([0.0, 0.01]).any(|(t, start)| t != start));
    }
    // Something happened: the contacts pushed.
    assert!(
        batched
            .iter()
            .any(|c| c.points().iter().any(|p| p.normal_impulse > 0.0))
    );
    assert_ne!(batch_states, bodies.states);
}

#[test]
fn a_batch_repacked_over_a_fuller_one_solves_bit_for_bit_as_a_fresh_pack() {
    // The solver refills last step's batches in place: a batch whose lane 0 held four
    // points, refilled with contacts of two and one, must leave no trace of the old ones.
    let (bodies, constraints) = scene(FrictionModel::PerPoint);
    let solve = |batch: &mut ContactBatches| {
        let mut states = bodies.states.clone();
        batch.warm_start(&mut states);
        batch.solve(&mut states, (240.0, 3.0), true, false, 1.0);
        batch.solve(&mut states, (240.0, 3.0), false, true, 1.0);
        states
    };
    let mut reused = packed(&[&[0]], &constraints);
    assert!(reused.pack([&[1, 2][..]], &constraints));
    let mut fresh = packed(&[&[1, 2]], &constraints);
    assert_eq!(solve(&mut reused), solve(&mut fresh));
    let unpacked = |batch: &ContactBatches| {
        let mut out = constraints.clone();
        batch.unpack(&mut out);
        out
    };
    assert_eq!(unpacked(&reused), unpacked(&fresh));
    // Three lanes down to one: the lanes left over hold nothing of before.
    let mut shrunk = packed(&[&[0, 1, 2]], &constraints);
    assert!(shrunk.pack([&[2][..]], &constraints));
    let mut single = packed(&[&[2]], &constraints);
    assert_eq!(solve(&mut shrunk), solve(&mut single));
    assert_eq!(unpacked(&shrunk), unpacked(&single));
    // Two batches refilled over one, and one over two.
    let mut grown = packed(&[&[0, 1]], &constraints);
    assert!(grown.pack([&[2][..], &[0, 1]], &constraints));
    let mut two = packed(&[&[2], &[0, 1]], &constraints);
    assert_eq!(solve(&mut grown), solve(&mut two));
    assert_eq!(unpacked(&grown), unpacked(&two));
    assert!(two.pack([&[1][..]], &constraints));
    assert_eq!(solve(&mut two), solve(&mut packed(&[&[1]], &constraints)));
    // A refused pack says so, and keeps the groups before the refused one.
    assert!(!reused.pack([&[2][..], &[9]], &constraints));
    assert_eq!(reused.len(), 1);
}

/// `c` with the anchors of its still sides set to zero.
fn still_anchors_zeroed(c: &ContactConstraint) -> ContactConstraint {
    let mut c = *c;
    let [still_a, still_b] = c.still;
    for p in &mut c.points {
        p.anchor_a = on_moving(still_a, p.anchor_a);
        p.anchor_b = on_moving(still_b, p.anchor_b);
    }
    c
}

#[test]
fn a_still_ground_read_as_constants_gives_the_bits_of_gathering_it() {
    for model in [FrictionModel::PerPoint, FrictionModel::Patch] {
        let (bodies, constraints) = scene_with(model, true);
        let still: Vec<_> = constraints.iter().map(|c| c.still).collect();
        // Static at rest: still; kinematic and moving (body 5), or dynamic: not.
        assert_eq!(still, [[false, true], [false, true], [false, false]]);
        // A still side's anchors are read as zero in the separation (`on_moving`), by the
        // lanes as by the constraint: zeroed here too, the gathering copy reads the same.
        let constraints: Vec<_> = constraints.iter().map(still_anchors_zeroed).collect();
        let gathered: Vec<_> = constraints
            .iter()
            .map(|c| ContactConstraint {
                still: [false; 2],
                ..*c
            })
            .collect();
        for groups in [&[&[0u32, 1][..]][..], &[&[0, 1, 2]], &[&[1], &[2, 0]]] {
            let run = |constraints: &[ContactConstraint]| {
                let mut batch = packed(groups, constraints);
                let mut states = bodies.states.clone();
                batch.warm_start(&mut states);
                for flip in [false, true] {
                    batch.solve(&mut states, (240.0, 3.0), true, flip, 1.0);
                    batch.solve(&mut states, (240.0, 3.0), false, flip, 1.0);
                }
                let mut out = constraints.to_vec();
                batch.unpack(&mut out);
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                let velocities: Vec<_> = states
                    .iter()
                    .map(|s| (bits(s.linear_velocity), bits(s.angular_velocity)))
                    .collect();
                (velocities, out)
            };
            let (fast, slow) = (run(&constraints), run(&gathered));
            assert_eq!(fast.0, slow.0, "{model:?} {groups:?}");
            for (f, s) in fast.1.iter().zip(&slow.1) {
                assert_eq!(f.points(), s.points());
                assert_eq!(f.patch, s.patch);
            }
            // The grounds kept their rest state; the dynamic bodies were pushed.
            assert_eq!(fast.0[1], ([0; 3], [0; 3]));
            assert_ne!(fast.0[0].0, bits3(bodies.states[0].linear_velocity));
            assert!(fast.1[0].points().iter().any(|p| p.normal_impulse > 0.0));
        }
    }
}

fn bits3(v: Vec3) -> [u32; 3] {
    v.to_array().map(f32::to_bits)
}

/// The groups packed into fresh batches.
fn packed(groups: &[&[u32]], constraints: &[ContactConstraint]) -> ContactBatches {
    let mut batches = ContactBatches::default();
    assert!(batches.pack(groups.iter().copied(), constraints));
    batches
}
