//! Contacts (and free ball joints) packed [`LANES`] at a time without changing the result of
//! solving them one by one in key order.
//!
//! Two contacts that move no common body commute: solving them in either order, or side by
//! side, gives the same velocities. So each contact, taken in key order, may join any batch
//! after the last batch holding a contact that moves one of its bodies: it lands in the first
//! such batch with a free lane (found through a path-compressed "next batch with room" array).
//! Solving the batches in order is then exactly the key-order Gauss–Seidel sweep of the scalar
//! solver, and solving them backwards exactly its reverse, with the lanes filled wherever the
//! contact graph lets independent contacts run side by side. (A greedy graph colouring, as
//! Box2D's, fills the lanes better but reorders the sweep into colours; measured here, that
//! made a 100:1 heavy box on a light one bounce by 2 cm and a 20-box stack sway 1.4 cm, where
//! the key order holds both within a centimetre.)
//!
//! Static and kinematic bodies are read only, so any number of contacts of a batch may touch
//! the same floor. Contacts with rolling resistance (whose rows the batches do not carry) and
//! those of a body locked along some translation axes (whose per-axis `1/m` the lanes do not carry)
//! are solved one at a time after the batches.

use super::contact::ContactConstraint;
use super::lanes::LANES;

/// The step's contacts in batches of up to [`LANES`], and those solved one at a time.
#[derive(Clone, Debug, Default)]
pub struct OrderedBatches {
    /// `LANES` slots per batch.
    members: Vec<u32>,
    /// Lanes used in each batch.
    used: Vec<u8>,
    /// Per batch, a batch at or after it with a free lane (path-compressed).
    room: Vec<u32>,
    /// Per body slot, one past the last batch that moves it (0: none yet).
    after: Vec<u32>,
    /// Constraint indices solved one at a time after the batches, in key order.
    one_by_one: Vec<u32>,
}

impl OrderedBatches {
    /// Packs `constraints` over `bodies` slots (from scratch each step: a few array lookups per
    /// contact).
    pub fn pack(&mut self, constraints: &[ContactConstraint], bodies: usize) {
        self.pack_by(constraints.len(), bodies, |i| {
            let c = &constraints[i];
            let moved = [(c.a, c.dynamic[0]), (c.b, c.dynamic[1])]
                .map(|(slot, dynamic)| dynamic.then_some(slot as usize));
            (c.rolling.arm == 0.0 && !c.translation_locked).then_some(moved)
        });
    }

    /// Packs `count` constraints over `bodies` slots: `moved(i)` gives the slots constraint
    /// `i` moves (a static or kinematic side as `None`), or `None` for a constraint the
    /// batches do not carry; it and those that move no body are solved one at a time.
    pub fn pack_by(
        &mut self,
        count: usize,
        bodies: usize,
        moved: impl Fn(usize) -> Option<[Option<usize>; 2]>,
    ) {
        self.members.clear();
        self.used.clear();
        self.room.clear();
        self.one_by_one.clear();
        self.after.clear();
        self.after.resize(bodies, 0);
        for i in 0..count {
            let slots = moved(i).map(|m| m.map(|s| s.filter(|&s| s < bodies)));
            let Some(moved) = slots.filter(|m| m.iter().any(Option::is_some)) else {
                self.one_by_one.push(i as u32);
                continue;
            };
            let earliest = moved
                .iter()
                .flatten()
                .map(|&s| self.after[s])
                .max()
                .unwrap_or(0);
            let k = self.with_room(earliest as usize);
            self.members[k * LANES + self.used[k] as usize] = i as u32;
            self.used[k] += 1;
            if self.used[k] as usize == LANES {
                self.room[k] = k as u32 + 1;
            }
            for &s in moved.iter().flatten() {
                self.after[s] = k as u32 + 1;
            }
        }
    }

    /// The first batch at or after `k` with a free lane, made if need be.
    fn with_room(&mut self, k: usize) -> usize {
        let mut at = k;
        loop {
            if at == self.used.len() {
                self.used.push(0);
                self.room.push(at as u32);
                self.members.extend([0; LANES]);
            }
            let next = self.room[at] as usize;
            if next == at {
                break;
            }
            at = next;
        }
        // Path compression: every batch passed on the way points at the one found.
        let mut step = k;
        while step != at {
            let next = self.room[step] as usize;
            self.room[step] = at as u32;
            step = next;
        }
        at
    }

    /// The batches in solving order, each the indices of its contacts.
    pub fn batches(&self) -> impl Iterator<Item = &[u32]> {
        self.used
            .iter()
            .enumerate()
            .map(|(k, &n)| &self.members[k * LANES..k * LANES + n as usize])
    }

    /// Refills `batches` in place from the packing, one per batch of indices, through
    /// `repack` (the solver reuses last step's batches: a batch is a few hundred bytes to a few
    /// kilobytes, and building each anew copied it twice).
    pub fn refill<B: Default>(
        &self,
        batches: &mut Vec<B>,
        mut repack: impl FnMut(&mut B, &[u32]) -> bool,
    ) {
        let mut used = 0;
        for indices in self.batches() {
            if used == batches.len() {
                batches.push(B::default());
            }
            let packed = repack(&mut batches[used], indices);
            debug_assert!(packed, "the packing hands out 1 to 4 valid indices");
            used += usize::from(packed);
        }
        batches.truncate(used);
    }

    /// The body slots of the last packing.
    pub fn bodies(&self) -> usize {
        self.after.len()
    }

    /// The contacts solved one at a time, after the batches.
    pub fn one_by_one(&self) -> &[u32] {
        &self.one_by_one
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::solver::{
        BodyInput, ContactInput, ContactPointInput, FrictionModel, RowSettings, Softness,
        SolverBodies,
    };
    use glam::{Quat, Vec3};

    /// Moving, turning bodies (slot 0 static) and contacts between the given slot pairs, one or
    /// two points each, carrying warm-start impulses.
    fn scene(pairs: &[(u32, u32)]) -> (SolverBodies, Vec<ContactConstraint>) {
        let mut bodies = SolverBodies::default();
        for i in 0..10 {
            let f = i as f32;
            let inverse_mass = if i == 0 { 0.0 } else { 1.0 / (1.0 + f) };
            bodies.push(BodyInput {
                center: Vec3::new(f, 0.2 * f, 0.0),
                orientation: Quat::from_rotation_z(0.1 * f),
                linear_velocity: Vec3::new(0.3 - 0.1 * f, 0.05 * f, -0.5),
                angular_velocity: Vec3::new(0.2, -0.1 * f, 0.3),
                inverse_mass,
                inverse_principal_inertia: Vec3::splat(inverse_mass * 2.0),
                ..Default::default()
            });
        }
        let softness = Softness::new(60.0, 10.0, 1.0 / 240.0);
        let constraints = pairs
            .iter()
            .enumerate()
            .map(|(k, &(a, b))| {
                let mut input = ContactInput {
                    a,
                    b,
                    normal: Vec3::new(0.1 * k as f32, 0.3, 1.0).normalize(),
                    friction: 0.5,
                    restitution: 0.0,
                    rolling_resistance: 0.0,
                    rounding: [0.0; 2],
                    points: [ContactPointInput::default(); 4],
                    count: 1 + (k % 2) as u8,
                    key: k as u128,
                };
                for (j, p) in input.points.iter_mut().enumerate() {
                    *p = ContactPointInput {
                        point: Vec3::new(0.5 * (a + b) as f32, 0.1 * j as f32, 0.0),
                        separation: -0.01 + 0.004 * j as f32,
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
                        friction: FrictionModel::PerPoint,
                        step: 1.0 / 60.0,
                    },
                );
                c.points[0].normal_impulse = 0.05;
                c
            })
            .collect();
        (bodies, constraints)
    }

    /// Pairs over slots 0..10 from a small generator: chains, stars and repeats.
    fn pairs(n: usize, seed: u64) -> Vec<(u32, u32)> {
        let mut rng = crate::test_rng::TestRng::new(seed);
        (0..n)
            .map(|_| {
                let (a, b) = (rng.below(10), rng.below(10));
                if a == b { (a, (b + 1) % 10) } else { (a, b) }
            })
            .collect()
    }

    #[test]
    fn batches_move_no_body_twice_and_hold_every_contact_once() {
        for seed in 0..20 {
            let (_, cs) = scene(&pairs(40, seed));
            let mut packing = OrderedBatches::default();
            packing.pack(&cs, 10);
            let mut seen = vec![0; cs.len()];
            for batch in packing.batches() {
                assert!(!batch.is_empty() && batch.len() <= LANES);
                let mut moved = [false; 10];
                for &i in batch {
                    seen[i as usize] += 1;
                    let c = &cs[i as usize];
                    for (slot, dynamic) in [(c.a, c.dynamic[0]), (c.b, c.dynamic[1])] {
                        if dynamic {
                            assert!(!moved[slot as usize], "slot {slot} twice in a batch");
                            moved[slot as usize] = true;
                        }
                    }
                }
            }
            for &i in packing.one_by_one() {
                seen[i as usize] += 1;
            }
            assert!(seen.iter().all(|&n| n == 1), "{seen:?}");
        }
    }

    #[test]
    fn solving_the_batches_in_order_equals_the_key_order_sweep_within_1e_5_on_20_graphs() {
        for seed in 0..20 {
            let (bodies, cs) = scene(&pairs(40, seed));
            let (h, push) = (1.0 / 240.0, 3.0);
            let mut scalar_states = bodies.states.clone();
            let mut scalar = cs.clone();
            for use_bias in [true, false, false] {
                for c in &mut scalar {
                    c.solve(&mut scalar_states, (1.0 / h, push), use_bias, 1.0);
                }
            }
            let mut packing = OrderedBatches::default();
            packing.pack(&cs, 10);
            let mut batches = crate::dynamics::solver::ContactBatches::default();
            assert!(batches.pack(packing.batches(), &cs));
            let mut states = bodies.states.clone();
            for use_bias in [true, false, false] {
                batches.solve(&mut states, (1.0 / h, push), use_bias, false, 1.0);
            }
            for (s, b) in scalar_states.iter().zip(&states) {
                assert!(
                    (s.linear_velocity - b.linear_velocity).length() < 1e-5,
                    "seed {seed}"
                );
                assert!((s.angular_velocity - b.angular_velocity).length() < 1e-5);
            }
            assert_ne!(states, bodies.states);
        }
    }

    #[test]
    fn a_chain_takes_one_batch_per_contact_and_independent_contacts_fill_four_lanes() {
        let chain: Vec<(u32, u32)> = (1..9).map(|i| (i, i + 1)).collect();
        let (_, cs) = scene(&chain);
        let mut packing = OrderedBatches::default();
        packing.pack(&cs, 10);
        assert!(packing.batches().all(|b| b.len() == 1));
        // Eight contacts on the floor, each with its own body: two full batches.
        let floor: Vec<(u32, u32)> = (1..9).map(|i| (0, i)).collect();
        let (_, cs) = scene(&floor);
        packing.pack(&cs, 10);
        let sizes: Vec<usize> = packing.batches().map(<[u32]>::len).collect();
        assert_eq!(sizes, [4, 4]);
    }
}
