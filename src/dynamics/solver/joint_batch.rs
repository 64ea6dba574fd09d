//! Four ball joints solved at once: the point rows of [`JointConstraint`] laid out one joint
//! per SIMD lane, as [`ContactBatch`](super::ContactBatch) lays out contacts (rapier's
//! `JointConstraint<SimdReal, 4>`, Box2D v3's wide solver).
//!
//! Only joints that are nothing but their point rows ride in lanes: free ball joints, the
//! joints of Box2D's `joint_grid`, of nets and of chains. The joints of a batch move no
//! common body ([`OrderedBatches`](super::ordered_batches::OrderedBatches), so the batches in
//! order give the scalar sweep over these joints in their order; the other joints are solved
//! one at a time after the batches), so no two lanes write the same velocities: a batch gathers its bodies' velocities, runs the scalar arithmetic of
//! [`point_rows`](super::point_rows) (`point_mass`, `inverse_mass`, `solve_point`) in every
//! lane, and scatters them back. Padding lanes hold zero masses and impulses: their `K⁻¹` is
//! zero and their impulses stay zero.

use super::body::BodyState;
use super::joint::JointConstraint;
use super::lanes::{LANES, Lanes, Mat3x4, PairVelocities, Quatx4, Slots, Vec3x4, lanes_of};
use super::softness::Softness;
use glam::{Mat3, Vec3};

/// Up to four free ball joints that move no common body.
#[derive(Clone, Debug, Default)]
pub(super) struct JointBatch {
    /// Which joint each lane holds (`None`: padding).
    joints: [Option<u32>; LANES],
    /// Body slots of A and B per lane (padding lanes repeat lane 0's).
    bodies: Slots,
    /// Whether the lane writes A's and B's velocities back (dynamic bodies of real lanes).
    writes: [[bool; LANES]; 2],
    /// `1/m` per world axis of A and B.
    inverse_mass: [Vec3x4; 2],
    /// World `I⁻¹` of A and B at the step's start.
    inverse_inertia: [Mat3x4; 2],
    /// The anchors from the centres of mass at the step's start (world).
    anchors: [Vec3x4; 2],
    /// `c_b − c_a` at the step's start.
    delta_center: Vec3x4,
    /// The anchors where the bodies are now.
    arms: [Vec3x4; 2],
    /// Anchor to anchor where the bodies are now.
    separation: Vec3x4,
    /// The point rows' `K⁻¹` where the bodies are now.
    k_inverse: Mat3x4,
    /// The accumulated impulse on B.
    impulse: Vec3x4,
}

impl JointBatch {
    /// Packs joints `indices` (1 to [`LANES`] free ball joints moving no common body) of
    /// `joints` into this batch, with their rows where the bodies are now; false (the batch
    /// left as it was) for no index, too many or one out of range.
    pub(super) fn repack(&mut self, indices: &[u32], joints: &[JointConstraint]) -> bool {
        let Some((lanes, first)) = lanes_of(indices, joints) else {
            return false;
        };
        // Slots are u32 (`SolverBodies::push`).
        let real = |l: usize| {
            let (a, b) = lanes[l].unwrap_or(first).slots();
            (a as u32, b as u32)
        };
        self.joints = std::array::from_fn(|l| indices.get(l).copied());
        self.bodies = [
            std::array::from_fn(|l| real(l).0),
            std::array::from_fn(|l| real(l).1),
        ];
        self.writes =
            [0, 1].map(|k| std::array::from_fn(|l| lanes[l].is_some_and(|j| j.masses.dynamic[k])));
        // Gathers through `fn` items the compiler inlines, not `&dyn Fn` readers per field and
        // lane: they cut the packing of a joint step by two thirds. They pass references, read
        // in place: copies of a `Mat3` through `Option`s and closures went through the stack
        // and stalled on their own stores.
        let vectors = |f: fn(&JointConstraint) -> &Vec3| {
            Vec3x4::gather_refs(in_lanes(&lanes, &Vec3::ZERO, f))
        };
        let matrices = |f: fn(&JointConstraint) -> &Mat3| {
            Mat3x4::gather_refs(in_lanes(&lanes, &Mat3::ZERO, f))
        };
        self.inverse_mass = [
            vectors(|j| &j.masses.inverse_mass[0]),
            vectors(|j| &j.masses.inverse_mass[1]),
        ];
        self.inverse_inertia = [
            matrices(|j| &j.masses.inverse_inertia[0]),
            matrices(|j| &j.masses.inverse_inertia[1]),
        ];
        self.anchors = [vectors(|j| &j.anchors[0]), vectors(|j| &j.anchors[1])];
        self.delta_center = vectors(|j| &j.delta_center);
        self.arms = [
            vectors(|j| &j.point.anchors.0),
            vectors(|j| &j.point.anchors.1),
        ];
        self.separation = vectors(|j| &j.point.separation);
        self.take_point_mass();
        self.impulse = vectors(|j| &j.impulses.point);
        true
    }

    /// Writes the impulses back into the joints the lanes came from.
    pub(super) fn unpack(&self, joints: &mut [JointConstraint]) {
        for (lane, index) in self.joints.iter().enumerate() {
            if let Some(i) = index {
                joints[*i as usize].impulses.point = self.impulse.lane(lane);
            }
        }
    }

    /// Applies the accumulated impulses.
    pub(super) fn warm_start(&self, states: &mut [BodyState]) {
        let mut pair = PairVelocities::load(&self.bodies, [false; 2], states);
        pair.push_point(self, self.impulse);
        pair.store(&self.bodies, &self.writes, states);
    }

    /// One pass: biased (`soft` closes the gaps) or relaxing (rigid), as
    /// [`JointConstraint::solve_point`] per lane.
    pub(super) fn solve(&mut self, states: &mut [BodyState], soft: Softness, use_bias: bool) {
        let mut pair = PairVelocities::load(&self.bodies, [false; 2], states);
        let [r_a, r_b] = self.arms;
        let cdot = pair.vb + pair.wb.cross(r_b) - pair.va - pair.wa.cross(r_a);
        let soft = if use_bias { soft } else { Softness::RIGID };
        let target = if use_bias {
            cdot + self.separation * Lanes::splat(soft.bias_rate)
        } else {
            cdot
        };
        let impulse = self.k_inverse.mul_vec(target) * Lanes::splat(-soft.mass_scale)
            - self.impulse * Lanes::splat(soft.impulse_scale);
        self.impulse = self.impulse + impulse;
        pair.push_point(self, impulse);
        pair.store(&self.bodies, &self.writes, states);
    }

    /// Takes the rows where the bodies are now, from their motion since the step's start (as
    /// [`JointConstraint::refresh`] per lane).
    pub(super) fn refresh(&mut self, states: &[BodyState]) {
        let [a, b] = self.bodies;
        let state = |i: u32| &states[i as usize];
        let turn = |slots: [u32; LANES]| Quatx4::gather(slots.map(|i| state(i).delta_rotation));
        let moved = |slots: [u32; LANES]| Vec3x4::gather(slots.map(|i| state(i).delta_position));
        let r_a = turn(a).rotate(self.anchors[0]);
        let r_b = turn(b).rotate(self.anchors[1]);
        self.arms = [r_a, r_b];
        self.separation = self.delta_center + moved(b) - moved(a) + r_b - r_a;
        self.take_point_mass();
    }

    /// The point rows' `K⁻¹` at the arms as they are (`point_mass` and `inverse_mass` of
    /// [`point_rows`](super::point_rows) in every lane).
    fn take_point_mass(&mut self) {
        let [r_a, r_b] = self.arms;
        let [ia, ib] = &self.inverse_inertia;
        let k = Mat3x4::diagonal(self.inverse_mass[0] + self.inverse_mass[1])
            .sub(&ia.skew_sandwich(r_a))
            .sub(&ib.skew_sandwich(r_b));
        self.k_inverse = k.inverse_mass();
    }
}

/// What the point rows add to their bodies' velocities.
impl PairVelocities {
    /// The impulse `p` on B at its anchor, `−p` on A.
    fn push_point(&mut self, batch: &JointBatch, p: Vec3x4) {
        let [ma, mb] = batch.inverse_mass;
        let [ia, ib] = &batch.inverse_inertia;
        let [r_a, r_b] = batch.arms;
        self.va = self.va - per_axis(p, ma);
        self.wa = self.wa - ia.mul_vec(r_a.cross(p));
        self.vb = self.vb + per_axis(p, mb);
        self.wb = self.wb + ib.mul_vec(r_b.cross(p));
    }
}

/// `p ⊙ w` per lane (an impulse over per-axis masses).
fn per_axis(p: Vec3x4, w: Vec3x4) -> Vec3x4 {
    Vec3x4 {
        x: p.x * w.x,
        y: p.y * w.y,
        z: p.z * w.z,
    }
}

/// Where `f` finds a value in each lane's joint (`zero` in padding lanes).
#[inline(always)]
fn in_lanes<'a, T>(
    lanes: &[Option<&'a JointConstraint>; LANES],
    zero: &'a T,
    f: impl Fn(&'a JointConstraint) -> &'a T,
) -> [&'a T; LANES] {
    lanes.map(|j| j.map_or(zero, &f))
}

#[cfg(test)]
mod tests {
    use super::super::joint_list::JointList;
    use super::*;
    use crate::dynamics::solver::{BodyInput, JointFrame, JointInput, JointKind, SolverBodies};
    use glam::Quat;

    /// Ten turning bodies (slot 0 static, slot 9 heavy and lopsided) and ball joints between
    /// random pairs with random anchors, carrying impulses.
    fn net(seed: u64) -> (SolverBodies, Vec<JointInput>) {
        let mut rng = crate::test_rng::TestRng::new(seed);
        let mut next = || rng.range(-1.0, 1.0);
        let mut bodies = SolverBodies::default();
        for i in 0..10 {
            let f = i as f32;
            let inverse_mass = match i {
                0 => 0.0,
                9 => 0.01,
                _ => 1.0 / (1.0 + f),
            };
            bodies.push(BodyInput {
                center: Vec3::new(f, next(), next()),
                orientation: Quat::from_rotation_z(next()) * Quat::from_rotation_x(next()),
                linear_velocity: Vec3::new(next(), next(), next()),
                angular_velocity: Vec3::new(next(), next(), next()) * 3.0,
                inverse_mass,
                inverse_principal_inertia: Vec3::new(2.0, 1.0 + next().abs(), 0.5) * inverse_mass,
                ..Default::default()
            });
        }
        let joints = (0..16u64)
            .map(|k| {
                let a = (next().abs() * 9.99) as u32;
                let b = (a + 1 + (next().abs() * 8.99) as u32) % 10;
                let frame = |anchor| JointFrame {
                    anchor,
                    basis: Quat::IDENTITY,
                };
                JointInput {
                    a,
                    b,
                    frame_a: frame(Vec3::new(next(), next(), next())),
                    frame_b: frame(Vec3::new(next(), next(), next())),
                    kind: JointKind::Spherical {
                        swing: None,
                        twist: None,
                    },
                    key: k,
                }
            })
            .collect();
        (bodies, joints)
    }

    /// The scalar path over `joints` in key order: warm start, a biased pass, the bodies
    /// moved, the rows refreshed, two relax passes.
    fn scalar_sweep(joints: &mut [JointConstraint], states: &mut [BodyState], moves: &[BodyState]) {
        let soft = Softness::new(60.0, 2.0, 1.0 / 240.0);
        for j in joints.iter() {
            j.apply_point_impulse(states, j.slots());
        }
        for j in joints.iter_mut() {
            j.solve_point(states, soft, true);
        }
        move_bodies(states, moves);
        for j in joints.iter_mut() {
            let (a, b) = j.slots();
            j.refresh(&states[a], &states[b]);
        }
        for _ in 0..2 {
            for j in joints.iter_mut() {
                j.solve_point(states, soft, false);
            }
        }
    }

    fn move_bodies(states: &mut [BodyState], moves: &[BodyState]) {
        for (s, m) in states.iter_mut().zip(moves) {
            s.delta_position = m.delta_position;
            s.delta_rotation = m.delta_rotation;
        }
    }

    #[test]
    fn a_rope_drops_an_impulse_kept_on_its_missing_lower_bound_at_the_first_pass() {
        let (bodies, mut inputs) = net(3);
        inputs.truncate(1);
        // A rope (no lower bound) whose kept impulses still hold a lower bound's, as after a
        // game turned a rod of 1 m into a rope.
        inputs[0].kind = JointKind::Distance {
            limit: crate::dynamics::solver::JointLimit { min: 0.0, max: 5.0 },
            motor: None,
        };
        let mut list = JointList::default();
        list.prepare(&bodies, &inputs, (f32::INFINITY, f32::INFINITY));
        list.impulses_mut(0).lower = 2.0;
        let mut states = bodies.states.clone();
        let soft = Softness::new(60.0, 2.0, 1.0 / 240.0);
        list.solve(&mut states, soft, 1.0 / 240.0, false);
        assert_eq!(list.joints()[0].impulses.lower, 0.0);
    }

    /// Every joint's point rows' `K⁻¹` is taken before the step's first pass: in the lanes for
    /// the batched free ball joints (within 1e-5 of the scalar formula), and the scalar one
    /// exactly for those solved one at a time (a limited ball joint, and a ball joint between
    /// two static bodies, whose `K⁻¹` is zero).
    #[test]
    fn every_point_mass_is_taken_at_prepare_in_lanes_within_1e_5_and_one_at_a_time_exactly() {
        let (mut bodies, mut inputs) = net(3);
        let second_static = bodies.len() as u32;
        bodies.push(BodyInput::default());
        let limited = JointInput {
            kind: JointKind::Spherical {
                swing: Some(0.5),
                twist: None,
            },
            key: 100,
            ..inputs[0]
        };
        let between_statics = JointInput {
            a: 0,
            b: second_static,
            key: 101,
            ..inputs[1]
        };
        inputs.extend([limited, between_statics]);
        let mut list = JointList::default();
        list.prepare(&bodies, &inputs, (f32::INFINITY, f32::INFINITY));
        let scalar = |j: &JointConstraint| {
            let mut j = *j;
            j.take_point_mass();
            j.point.inverse_mass
        };
        let (batches, one_by_one) = list.packing();
        assert_eq!(one_by_one.len(), 2);
        for &i in one_by_one {
            let j = &list.joints()[i as usize];
            assert_eq!(j.point.inverse_mass, scalar(j), "joint {i}");
        }
        let mut lanes = 0;
        for batch in batches {
            for (l, i) in batch.joints.iter().enumerate() {
                let Some(i) = i else { continue };
                let want = scalar(&list.joints()[*i as usize]);
                let [x, y, z] = batch.k_inverse.cols.map(|c| c.lane(l));
                let got = Mat3::from_cols(x, y, z);
                let size = want
                    .to_cols_array()
                    .iter()
                    .fold(1.0f32, |m, v| m.max(v.abs()));
                assert!(
                    got.abs_diff_eq(want, 1e-5 * size),
                    "joint {i}: {got} vs {want}"
                );
                lanes += 1;
            }
        }
        assert_eq!(lanes, inputs.len() - 2);
    }

    #[test]
    fn batched_ball_joints_equal_the_key_order_sweep_within_1e_4_on_20_nets() {
        let soft = Softness::new(60.0, 2.0, 1.0 / 240.0);
        let unbounded = (f32::INFINITY, f32::INFINITY);
        let mut filled = 0;
        for seed in 0..20 {
            let (bodies, inputs) = net(seed);
            let mut list = JointList::default();
            list.prepare(&bodies, &inputs, unbounded);
            list.set_impulses_all(|k| Vec3::new(0.3, -0.2, 0.1) * (k as f32 * 0.1 - 0.5));
            // The scalar reference takes its point rows' mass itself (the lanes take theirs).
            let mut scalar = list.joints().to_vec();
            scalar.iter_mut().for_each(JointConstraint::take_point_mass);
            filled += list.batch_lanes();
            let moves: Vec<BodyState> = (0..10)
                .map(|i| BodyState {
                    delta_position: Vec3::new(0.01, -0.02, 0.005) * i as f32,
                    delta_rotation: Quat::from_rotation_y(0.03 * i as f32),
                    ..Default::default()
                })
                .collect();
            let mut expected = bodies.states.clone();
            scalar_sweep(&mut scalar, &mut expected, &moves);
            let mut states = bodies.states.clone();
            list.warm_start(&mut states);
            list.solve(&mut states, soft, 1.0 / 240.0, true);
            move_bodies(&mut states, &moves);
            list.refresh(&states);
            for _ in 0..2 {
                list.solve(&mut states, soft, 1.0 / 240.0, false);
            }
            list.store();
            for (e, s) in expected.iter().zip(&states) {
                let scale = 1.0 + e.linear_velocity.length() + e.angular_velocity.length();
                assert!(
                    (e.linear_velocity - s.linear_velocity).length() < 1e-4 * scale,
                    "seed {seed}"
                );
                assert!(
                    (e.angular_velocity - s.angular_velocity).length() < 1e-4 * scale,
                    "seed {seed}"
                );
            }
            for (e, j) in scalar.iter().zip(list.joints()) {
                let scale = 1.0 + e.impulses.point.length();
                assert!((e.impulses.point - j.impulses.point).length() < 1e-4 * scale);
            }
            assert_ne!(states, bodies.states);
        }
        // The lanes did hold joints side by side.
        assert!(filled > 20 * 16 / 2, "{filled} joints in lanes of 320");
    }
}
