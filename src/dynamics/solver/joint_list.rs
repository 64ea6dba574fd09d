//! The step's joints as the solver keeps them: every joint's [`JointConstraint`] in one dense
//! array, the extra rows of the kinds that have them in another ([`JointExtra`]), and last
//! step's impulses by key for the warm start (Box2D v3's joint arrays and its
//! `b2WarmStartJoint` / `b2SolveJoint` passes).
//!
//! The free ball joints ride four at a time in [`JointBatch`]es, packed by the contacts'
//! [`OrderedBatches`] so that the batches in order solve them as the sweep in the order given
//! would; the other joints are solved one at a time after the batches, in the order given
//! (the ECS gives them by key).

use super::body::{BodyParams, BodyState, SolverBodies};
use super::joint::{HeldLoad, JointConstraint, JointImpulses, JointInput};
use super::joint_batch::JointBatch;
use super::joint_extra::{JointExtra, Pass};
use super::ordered_batches::OrderedBatches;
use super::softness::Softness;
use glam::Vec3;

/// The step's joints (see the module doc).
#[derive(Clone, Debug, Default)]
pub(super) struct JointList {
    joints: Vec<JointConstraint>,
    extras: Vec<JointExtra>,
    /// Last step's impulses by key, sorted.
    cache: Vec<(u64, JointImpulses)>,
    /// Which joints ride in which batch, and which are solved one at a time.
    batching: OrderedBatches,
    /// The batches of the step (refilled in place each step).
    batches: Vec<JointBatch>,
}

impl JointList {
    /// The step's joints, with their impulses.
    pub(super) fn joints(&self) -> &[JointConstraint] {
        &self.joints
    }

    /// What each joint applied over the last substep `h`, by its key: its rows' impulses with
    /// the linear share of its rows held at the anchors.
    pub(super) fn loads(&self, h: f32) -> impl Iterator<Item = (u64, HeldLoad)> + '_ {
        self.joints.iter().map(move |j| {
            let extra = j.extra.and_then(|e| self.extras.get(e as usize));
            let pivoted = extra.map_or(Vec3::ZERO, |e| e.pivoted_impulse(&j.impulses));
            (j.key, j.load(h, pivoted))
        })
    }

    /// Prepares the step's joints over `bodies`, each seeded with its impulses of the last
    /// step held to `(max_speed, max_spin)` ([`Self::bound_impulses`]), and packs the free
    /// ball joints into batches; returns how many joints the bound changed. A joint naming a
    /// slot past the bodies or one body twice, or with unusable frames, limit or motor, is
    /// skipped (see [`JointKind::problem`](super::JointKind::problem)).
    pub(super) fn prepare(
        &mut self,
        bodies: &SolverBodies,
        inputs: &[JointInput],
        (max_speed, max_spin): (f32, f32),
    ) -> usize {
        self.gather(bodies, inputs);
        let bounded = self.bound(max_speed, max_spin);
        self.pack(bodies.len());
        bounded
    }

    /// The usable joints of `inputs`, seeded with their impulses of the last step.
    fn gather(&mut self, bodies: &SolverBodies, inputs: &[JointInput]) {
        let n = bodies.len() as u32;
        self.extras.clear();
        // Last step's joints are refilled in place; only new places are built.
        let mut count = 0;
        // Where the next joint's kept impulses should be: the joints come in key order, as
        // the cache is kept, so each is found in one read (a binary search otherwise).
        let mut next_kept = 0;
        for joint in inputs {
            let usable = joint.frame_a.is_usable()
                && joint.frame_b.is_usable()
                && joint.kind.problem().is_none();
            if joint.a >= n || joint.b >= n || joint.a == joint.b || !usable {
                continue;
            }
            if let Some(slot) = self.joints.get_mut(count) {
                slot.refill(joint, bodies);
            } else {
                self.joints.push(JointConstraint::prepare(joint, bodies));
            }
            let c = &mut self.joints[count];
            count += 1;
            let kept = match self.cache.get(next_kept) {
                Some(e) if e.0 == joint.key => Ok(next_kept),
                _ => self.cache.binary_search_by_key(&joint.key, |e| e.0),
            };
            if let Ok(i) = kept {
                c.impulses = self.cache[i].1;
                c.impulses.keep_rows_of(&joint.kind);
                next_kept = i + 1;
            }
            let turns = (
                bodies.orientations[joint.a as usize],
                bodies.orientations[joint.b as usize],
            );
            if let Some(mut extra) = JointExtra::prepare(joint, &c.masses, turns) {
                // The extra rows are held at the point rows' mass.
                c.take_point_mass();
                let start = BodyState::default();
                extra.refresh(&c.masses, (&start, &start), &c.point, &c.impulses);
                c.extra = Some(self.extras.len() as u32);
                self.extras.push(extra);
            }
        }
        self.joints.truncate(count);
    }

    /// Holds the impulses each joint carries into the step to what could change a body's
    /// velocity by at most `max_speed` and its spin by at most `max_spin`, and drops them if
    /// they are not finite. A joint fighting another one that holds the same body somewhere
    /// else (two joints to static bodies at places the body cannot reach at once) otherwise
    /// grows its rigid passes' impulses step after step until they overflow. The bound is per
    /// joint: a sound joint can reach it too where a light, thin body carries a heavy one (a
    /// 0.2 kg rod holding 10 kg 10 cm off its axis), and is then held to it. Returns how many
    /// joints it changed. Runs before the packing, which copies the impulses into the batches.
    fn bound(&mut self, max_speed: f32, max_spin: f32) -> usize {
        let mut bounded = 0;
        for i in 0..self.joints.len() {
            if self.joints[i].impulses == JointImpulses::default() {
                continue;
            }
            let mut effect = [BodyState::default(); 2];
            self.apply_impulses(i, &mut effect, (0, 1));
            let joint = &mut self.joints[i];
            let finite = effect
                .iter()
                .all(|s| s.linear_velocity.is_finite() && s.angular_velocity.is_finite());
            if !finite {
                joint.impulses = JointImpulses::default();
                bounded += 1;
                continue;
            }
            let over = effect
                .iter()
                .map(|s| {
                    let speed = s.linear_velocity.length_squared() / (max_speed * max_speed);
                    let spin = s.angular_velocity.length_squared() / (max_spin * max_spin);
                    speed.max(spin)
                })
                .fold(0.0f32, f32::max);
            if over > 1.0 {
                joint.impulses.scale(1.0 / over.sqrt());
                bounded += 1;
            }
        }
        bounded
    }

    /// Packs the free ball joints into batches over `bodies` slots (after the carried impulses
    /// are bounded: the batches take them as they are), each batch taking its point rows' mass
    /// in its lanes. A free ball joint left to be solved one at a time moves no dynamic body:
    /// its `K⁻¹` is the zero it starts with.
    fn pack(&mut self, bodies: usize) {
        let joints = &self.joints;
        self.batching.pack_by(joints.len(), bodies, |i| {
            let j = &joints[i];
            let (a, b) = j.slots();
            let moved = [(a, j.masses.dynamic[0]), (b, j.masses.dynamic[1])];
            j.is_free_ball()
                .then(|| moved.map(|(slot, dynamic)| dynamic.then_some(slot)))
        });
        self.batching
            .refill(&mut self.batches, |b, members| b.repack(members, joints));
    }

    /// Applies joint `i`'s accumulated impulses to the bodies in `states` at slots `ab`.
    fn apply_impulses(&self, i: usize, states: &mut [BodyState], ab: (usize, usize)) {
        let joint = &self.joints[i];
        joint.apply_point_impulse(states, ab);
        if let Some(x) = joint.extra {
            let extra = &self.extras[x as usize];
            extra.apply_impulses(&joint.masses, states, ab, &joint.impulses);
        }
    }

    /// Applies every joint's accumulated impulses.
    pub(super) fn warm_start(&self, states: &mut [BodyState]) {
        for batch in &self.batches {
            batch.warm_start(states);
        }
        for &i in self.batching.one_by_one() {
            let i = i as usize;
            self.apply_impulses(i, states, self.joints[i].slots());
        }
    }

    /// One pass over every joint: biased (`soft` closes the position errors) or relaxing
    /// (rigid, no bias); the batches, then per joint its motor and limits and the rows that
    /// hold it together, the point rows last (Box2D's order: the hard rows last, so they win).
    pub(super) fn solve(
        &mut self,
        states: &mut [BodyState],
        soft: Softness,
        h: f32,
        use_bias: bool,
    ) {
        for batch in &mut self.batches {
            batch.solve(states, soft, use_bias);
        }
        for &i in self.batching.one_by_one() {
            let joint = &mut self.joints[i as usize];
            if let Some(x) = joint.extra {
                let ab = joint.slots();
                let pass = Pass {
                    masses: &joint.masses,
                    point: &joint.point,
                    ab,
                    soft,
                    h,
                    use_bias,
                };
                self.extras[x as usize].solve(&pass, states, &mut joint.impulses);
            }
            joint.solve_point(states, soft, use_bias);
        }
    }

    /// Takes the inverse inertias `params` hold now into the joints solved one at a time
    /// whose bodies `turned` says turned within the step (`turned_rows.rs`); [`Self::refresh`]
    /// then builds their rows with them. The free ball joints solved four at a time keep the
    /// step's: a ball joint's point rows gained no energy from it (the fourth probe's rods).
    pub(super) fn take_turned_inertia(&mut self, params: &[BodyParams], turned: &[bool]) {
        for &i in self.batching.one_by_one() {
            let joint = &mut self.joints[i as usize];
            let (a, b) = joint.slots();
            if !(turned[a] || turned[b]) {
                continue;
            }
            joint.masses.fill(params, a, b);
            if let Some(x) = joint.extra {
                self.extras[x as usize].take_masses(&joint.masses);
            }
        }
    }

    /// Takes every joint's rows where the bodies are now (after their positions moved).
    pub(super) fn refresh(&mut self, states: &[BodyState]) {
        for batch in &mut self.batches {
            batch.refresh(states);
        }
        for &i in self.batching.one_by_one() {
            let joint = &mut self.joints[i as usize];
            let (a, b) = joint.slots();
            let (sa, sb) = (&states[a], &states[b]);
            joint.refresh(sa, sb);
            if let Some(x) = joint.extra {
                let extra = &mut self.extras[x as usize];
                extra.refresh(&joint.masses, (sa, sb), &joint.point, &joint.impulses);
            }
        }
    }

    /// [`Self::bound`] on the joints' impulses as they are now, repacked after.
    #[cfg(test)]
    pub(super) fn bound_impulses(&mut self, max_speed: f32, max_spin: f32) -> usize {
        let bounded = self.bound(max_speed, max_spin);
        self.pack(self.batching.bodies());
        bounded
    }

    /// Sets joint `i`'s carried point impulse (a test's stand-in for a bad warm start), in the
    /// joint and its batch.
    #[cfg(test)]
    pub(super) fn set_impulses(&mut self, i: usize, point: glam::Vec3) {
        self.joints[i].impulses.point = point;
        self.pack(self.batching.bodies());
    }

    /// Joint `i`'s impulses, to set by hand (a test's stand-in for a kept impulse); only for a
    /// joint solved one at a time (a batch keeps its own copy of its joints' impulses).
    #[cfg(test)]
    pub(super) fn impulses_mut(&mut self, i: usize) -> &mut JointImpulses {
        &mut self.joints[i].impulses
    }

    /// Sets every joint's point impulse to `point(i)`, in the joints and their batches.
    #[cfg(test)]
    pub(super) fn set_impulses_all(&mut self, point: impl Fn(usize) -> glam::Vec3) {
        for (i, j) in self.joints.iter_mut().enumerate() {
            j.impulses.point = point(i);
        }
        let bodies = self.batching.bodies();
        self.pack(bodies);
    }

    /// The batches, and the joints solved one at a time.
    #[cfg(test)]
    pub(super) fn packing(&self) -> (&[JointBatch], &[u32]) {
        (&self.batches, self.batching.one_by_one())
    }

    /// How many joints ride in lanes next to another.
    #[cfg(test)]
    pub(super) fn batch_lanes(&self) -> usize {
        self.batching
            .batches()
            .filter(|b| b.len() > 1)
            .map(<[u32]>::len)
            .sum()
    }

    /// Keeps the joints' impulses for the next step's warm start, by key.
    pub(super) fn store(&mut self) {
        for batch in &self.batches {
            batch.unpack(&mut self.joints);
        }
        self.cache.clear();
        self.cache
            .extend(self.joints.iter().map(|j| (j.key, j.impulses)));
        self.cache.sort_unstable_by_key(|e| e.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::solver::{BodyInput, JointFrame, JointKind, JointLimit};
    use glam::Quat;

    #[test]
    fn joints_refilled_over_last_steps_equal_fresh_ones_on_every_value() {
        let mut bodies = SolverBodies::default();
        for i in 0..4 {
            let f = i as f32;
            bodies.push(BodyInput {
                center: Vec3::new(f, 0.1 * f, 0.0),
                orientation: Quat::from_rotation_z(0.3 * f),
                inverse_mass: 1.0 / (1.0 + f),
                inverse_principal_inertia: Vec3::new(1.0, 2.0, 3.0),
                ..Default::default()
            });
        }
        let frame = |x: f32| JointFrame {
            anchor: Vec3::new(x, 0.2, -0.1),
            basis: Quat::IDENTITY,
        };
        let joint = |a, b, kind, key| JointInput {
            a,
            b,
            frame_a: frame(0.5),
            frame_b: frame(-0.5),
            kind,
            key,
        };
        let limit = Some(JointLimit {
            min: -0.5,
            max: 0.5,
        });
        let hinge = JointKind::Revolute { limit, motor: None };
        let ball = JointKind::Spherical {
            swing: None,
            twist: None,
        };
        // Last step: limited hinges (with extra rows) around a ball joint; this step: two
        // ball joints between other bodies, in the first two places.
        let last = [
            joint(0, 1, hinge, 1),
            joint(1, 2, ball, 2),
            joint(2, 3, hinge, 3),
        ];
        let now = [joint(0, 2, ball, 4), joint(1, 3, ball, 5)];
        let bound = (400.0, 100.0);
        let mut reused = JointList::default();
        reused.prepare(&bodies, &last, bound);
        assert!(reused.joints()[0].extra.is_some());
        reused.prepare(&bodies, &now, bound);
        let mut fresh = JointList::default();
        fresh.prepare(&bodies, &now, bound);
        assert_eq!(reused.joints(), fresh.joints());
        assert_eq!(reused.joints().len(), 2);
    }
}
