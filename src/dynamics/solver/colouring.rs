//! Graph colouring of the contacts, so that [`LANES`] contacts can be solved at once (Box2D v3's
//! `constraint_graph.c`; rapier's interaction groups).
//!
//! Two contacts of one colour never share a body the solver moves, so a batch of them reads
//! and writes disjoint velocities: solving them side by side gives what solving them one after
//! the other would. Static and kinematic bodies are read only, and any number of contacts of a
//! colour may touch the same floor. Contacts are coloured greedily in the caller's key order
//! (the first colour whose bodies are all free), so the colouring, and with it the solve order
//! (colour by colour, then the rest one at a time), depends on nothing but the keys.
//!
//! Box2D gives contacts with static bodies the last colours, so that the supports have the
//! last word in each sweep; tried here (with the colours swept forwards only, or alternately
//! forwards and backwards), it made a 20-row pyramid drift 1–3 cm in 3 s instead of 0.8 cm,
//! so every contact takes the first free colour.
//!
//! Contacts that no colour takes (a body in more than [`COLOURS`] contacts, as the bottom of a
//! pile can be) and contacts with rolling resistance (whose rows the batches do not carry) are
//! solved one at a time after the colours, as Box2D's overflow constraints are.

use super::contact::ContactConstraint;
use super::lanes::LANES;

/// How many colours are tried before a contact is left to the one-at-a-time pass (Box2D v3
/// has 24; a box in a pyramid has at most 6 neighbours and a ball in a pile about 12).
pub const COLOURS: usize = 16;

/// The step's contacts by colour, and those solved one at a time.
#[derive(Clone, Debug, Default)]
pub struct Colouring {
    /// Constraint indices of each colour, in key order.
    colours: Vec<Vec<u32>>,
    /// Constraint indices solved one at a time after the colours, in key order.
    one_by_one: Vec<u32>,
    /// Per colour, one bit per body slot: taken by a contact of that colour.
    taken: Vec<Vec<u64>>,
}

impl Colouring {
    /// Colours `constraints` over `bodies` slots (rebuilt from scratch each step: a few
    /// bit tests per contact).
    pub fn colour(&mut self, constraints: &[ContactConstraint], bodies: usize) {
        let words = bodies.div_ceil(64);
        self.colours.resize_with(COLOURS, Vec::new);
        self.taken.resize_with(COLOURS, Vec::new);
        for (members, taken) in self.colours.iter_mut().zip(&mut self.taken) {
            members.clear();
            taken.clear();
            taken.resize(words, 0);
        }
        self.one_by_one.clear();
        for (i, c) in constraints.iter().enumerate() {
            let moved = [(c.a, c.dynamic[0]), (c.b, c.dynamic[1])].map(|(slot, dynamic)| {
                (dynamic && (slot as usize) < bodies).then_some(slot as usize)
            });
            let colour = match moved {
                _ if c.rolling.arm != 0.0 => None,
                [None, None] => None,
                _ => self.free_colour(&moved),
            };
            match colour {
                Some(k) => {
                    for slot in moved.into_iter().flatten() {
                        self.taken[k][slot / 64] |= 1 << (slot % 64);
                    }
                    self.colours[k].push(i as u32);
                }
                None => self.one_by_one.push(i as u32),
            }
        }
    }

    /// The first colour in which none of `slots` is taken.
    fn free_colour(&self, slots: &[Option<usize>; 2]) -> Option<usize> {
        self.taken.iter().position(|taken| {
            slots
                .iter()
                .flatten()
                .all(|&slot| taken[slot / 64] & (1 << (slot % 64)) == 0)
        })
    }

    /// The batches to solve side by side: each colour cut into runs of at most [`LANES`].
    pub fn batches(&self) -> impl Iterator<Item = &[u32]> {
        self.colours
            .iter()
            .flat_map(|members| members.chunks(LANES))
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
        BodyInput, ContactInput, ContactPointInput, Softness, SolverBodies,
    };
    use glam::Vec3;

    /// Contacts between slots `(a, b)`; slot 0 is static, the rest dynamic.
    fn constraints(pairs: &[(u32, u32)]) -> Vec<ContactConstraint> {
        let mut bodies = SolverBodies::default();
        for i in 0..8 {
            let inverse_mass = if i == 0 { 0.0 } else { 1.0 };
            bodies.push(BodyInput {
                center: Vec3::new(i as f32, 0.0, 0.0),
                inverse_mass,
                inverse_principal_inertia: Vec3::splat(inverse_mass),
                ..Default::default()
            });
        }
        pairs
            .iter()
            .enumerate()
            .map(|(key, &(a, b))| {
                let input = ContactInput {
                    a,
                    b,
                    normal: Vec3::Z,
                    friction: 0.5,
                    restitution: 0.0,
                    rolling_resistance: 0.0,
                    points: [ContactPointInput::default(); 4],
                    count: 1,
                    key: key as u128,
                };
                ContactConstraint::prepare(
                    &input,
                    &bodies.centers,
                    &bodies.states,
                    &bodies.params,
                    Softness::RIGID,
                )
            })
            .collect()
    }

    #[test]
    fn no_colour_holds_two_contacts_moving_one_body_and_every_contact_is_placed_once() {
        // A chain 1-2-3-4-5, everything on the floor (slot 0), and a triangle 5-6-7.
        let mut pairs: Vec<(u32, u32)> = (1..5).map(|i| (i, i + 1)).collect();
        pairs.extend((1..8).map(|i| (0, i)));
        pairs.extend([(5, 6), (6, 7), (5, 7)]);
        let cs = constraints(&pairs);
        let mut colouring = Colouring::default();
        colouring.colour(&cs, 8);
        let mut seen = vec![0; cs.len()];
        for members in &colouring.colours {
            let mut used = [false; 8];
            for &i in members {
                seen[i as usize] += 1;
                for (slot, dynamic) in [(cs[i as usize].a, cs[i as usize].dynamic[0])]
                    .into_iter()
                    .chain([(cs[i as usize].b, cs[i as usize].dynamic[1])])
                {
                    if dynamic {
                        assert!(!used[slot as usize], "slot {slot} twice in a colour");
                        used[slot as usize] = true;
                    }
                }
            }
        }
        for &i in colouring.one_by_one() {
            seen[i as usize] += 1;
        }
        assert!(seen.iter().all(|&n| n == 1), "{seen:?}");
        // The floor is shared freely: the floor contacts fit in few colours.
        assert!(colouring.one_by_one().is_empty());
    }

    #[test]
    fn a_body_in_more_than_16_contacts_leaves_the_17th_to_the_one_at_a_time_pass() {
        // 20 contacts all moving slot 1 (against slots 2..8 repeated).
        let pairs: Vec<(u32, u32)> = (0..20).map(|i| (1, 2 + i % 6)).collect();
        let cs = constraints(&pairs);
        let mut colouring = Colouring::default();
        colouring.colour(&cs, 8);
        assert_eq!(colouring.batches().count(), COLOURS);
        assert_eq!(colouring.one_by_one(), &[16, 17, 18, 19]);
    }
}
