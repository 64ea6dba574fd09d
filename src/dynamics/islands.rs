//! Islands: the groups of dynamic bodies that touch, directly or through one another. An island
//! sleeps and wakes as a unit (Box2D v3's `island.c`, rapier's and Jolt's islands): a box on a
//! settling pile must not fall asleep while the pile under it still moves, and a pile knocked
//! from below must not leave its top asleep in the air.
//!
//! Box2D keeps its islands persistent (merged when a contact begins, split lazily when one
//! ends). urto rebuilds the islands of the *awake* bodies every step instead, by union-find over
//! the step's touching contacts (Tarjan 1975: union by size and path halving, near-linear in the
//! contacts), which one pass over the contacts the narrow phase already made affords. Sleeping
//! islands are not rebuilt: their bodies keep the key of the island they fell asleep in, and
//! waking one wakes every body with that key (`plugins/sleep.rs`).
//!
//! Static and kinematic bodies link nothing (they are shared by every island resting on them,
//! as in Box2D), but a body touching one that can never sleep (a moving kinematic body, a body
//! on a spring) makes its island *restless*: it stays awake.
//!
//! An island pulled by gravity that touches nothing holding it (no static, kinematic or
//! sleeping body, no joint to the world) is falling, however still it has been: it never
//! sleeps. A still box whose floor the game removed in the step before it would have slept
//! moved 1.4 mm and 0.16 m/s in that step, within the stillness test, and slept in the air
//! for good (a user-style probe); so did a ball whose rope to the world was cut.

/// Union-find over bodies `0..n`, reused from step to step (no allocation once grown).
#[derive(Debug, Default, Clone)]
pub struct IslandBuilder {
    parent: Vec<u32>,
    size: Vec<u32>,
    /// Per root: may the island sleep (scratch of [`islands_to_sleep`]).
    may_sleep: Vec<bool>,
    /// Per root: [`PULLED`] and [`HELD`] of its members (scratch of [`islands_to_sleep`]).
    support: Vec<u8>,
}

/// Some member of the island is pulled.
const PULLED: u8 = 1;
/// Some member of the island is held.
const HELD: u8 = 2;

impl IslandBuilder {
    /// Forgets every link: `bodies` islands of one body each.
    pub fn reset(&mut self, bodies: usize) {
        self.parent.clear();
        self.parent.extend(0..bodies as u32);
        self.size.clear();
        self.size.resize(bodies, 1);
    }

    /// The number of bodies.
    pub fn len(&self) -> usize {
        self.parent.len()
    }

    /// True without bodies.
    pub fn is_empty(&self) -> bool {
        self.parent.is_empty()
    }

    /// The island's representative body (the same for every member until the next link).
    pub fn root(&mut self, body: usize) -> usize {
        let mut x = body;
        while self.parent[x] as usize != x {
            // Path halving: point every other body on the path at its grandparent.
            let grand = self.parent[self.parent[x] as usize];
            self.parent[x] = grand;
            x = grand as usize;
        }
        x
    }

    /// Puts the islands of `a` and `b` together (the smaller under the larger).
    pub fn link(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        if ra == rb {
            return;
        }
        let (big, small) = if self.size[ra] >= self.size[rb] {
            (ra, rb)
        } else {
            (rb, ra)
        };
        self.parent[small] = big as u32;
        self.size[big] += self.size[small];
    }
}

/// What decides whether one body lets its island sleep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stillness {
    /// Seconds it has been still ([`crate::dynamics::stillness`]).
    pub still_for: f32,
    /// It touches a body that never sleeps, or cannot sleep itself.
    pub restless: bool,
    /// It touches what stays put without it: a static, kinematic or sleeping body, or the
    /// world through a joint.
    pub held: bool,
    /// A steady pull (gravity) acts on it along an axis it may move along.
    pub pulled: bool,
}

/// Which bodies fall asleep now (`asleep[i]`): those whose whole island has been still for
/// `time` seconds, no member restless, and held if pulled (module docs). `islands` holds the
/// step's links over the same bodies as `bodies`.
pub fn islands_to_sleep(
    islands: &mut IslandBuilder,
    bodies: &[Stillness],
    time: f32,
    asleep: &mut Vec<bool>,
) {
    let n = bodies.len().min(islands.len());
    // Per root: may the island sleep? Yes, unless a member vetoes it.
    let mut may_sleep = std::mem::take(&mut islands.may_sleep);
    let mut support = std::mem::take(&mut islands.support);
    may_sleep.clear();
    may_sleep.resize(n, true);
    support.clear();
    support.resize(n, 0);
    for (i, b) in bodies.iter().enumerate().take(n) {
        let root = islands.root(i);
        if b.restless || b.still_for < time || b.still_for.is_nan() {
            may_sleep[root] = false;
        }
        support[root] |= if b.pulled { PULLED } else { 0 } | if b.held { HELD } else { 0 };
    }
    asleep.clear();
    asleep.extend((0..n).map(|i| {
        let root = islands.root(i);
        may_sleep[root] && support[root] != PULLED
    }));
    islands.may_sleep = may_sleep;
    islands.support = support;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn still(still_for: f32) -> Stillness {
        Stillness {
            still_for,
            ..Stillness::default()
        }
    }

    #[test]
    fn a_pile_sleeps_only_when_its_last_body_is_still_and_apart_islands_do_not_wait() {
        let mut islands = IslandBuilder::default();
        islands.reset(5);
        // A pile 0-1-2 (linked through 1) and a pair 3-4.
        islands.link(0, 1);
        islands.link(2, 1);
        islands.link(3, 4);
        assert_eq!(islands.root(0), islands.root(2));
        assert_ne!(islands.root(0), islands.root(3));
        let mut asleep = Vec::new();
        let bodies = [still(0.6), still(0.2), still(0.9), still(0.5), still(0.7)];
        islands_to_sleep(&mut islands, &bodies, 0.5, &mut asleep);
        assert_eq!(asleep, [false, false, false, true, true]);
        let mut bodies = bodies;
        bodies[1].still_for = 0.5;
        bodies[4].restless = true;
        islands_to_sleep(&mut islands, &bodies, 0.5, &mut asleep);
        assert_eq!(asleep, [true, true, true, false, false]);
    }

    #[test]
    fn an_island_pulled_by_gravity_sleeps_only_if_a_member_is_held() {
        let mut islands = IslandBuilder::default();
        islands.reset(4);
        // A stack 0-1 (0 on the ground) and a pair 2-3 touching nothing.
        islands.link(0, 1);
        islands.link(2, 3);
        let pulled = |held: bool| Stillness {
            still_for: 1.0,
            pulled: true,
            held,
            ..Stillness::default()
        };
        let mut bodies = [pulled(true), pulled(false), pulled(false), pulled(false)];
        let mut asleep = Vec::new();
        islands_to_sleep(&mut islands, &bodies, 0.5, &mut asleep);
        assert_eq!(asleep, [true, true, false, false]);
        // Without gravity a still pair floating apart sleeps.
        bodies[2].pulled = false;
        bodies[3].pulled = false;
        islands_to_sleep(&mut islands, &bodies, 0.5, &mut asleep);
        assert_eq!(asleep, [true, true, true, true]);
    }

    #[test]
    fn a_long_chain_links_in_near_linear_time_and_stays_one_island() {
        let n = 100_000;
        let mut islands = IslandBuilder::default();
        islands.reset(n);
        for i in 1..n {
            islands.link(i - 1, i);
        }
        let root = islands.root(0);
        assert!((0..n).all(|i| islands.root(i) == root));
        islands.reset(3);
        assert_eq!(
            (islands.root(0), islands.root(1), islands.root(2)),
            (0, 1, 2)
        );
    }
}
