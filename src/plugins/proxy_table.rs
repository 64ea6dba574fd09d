//! Which broad-phase structure holds each collider, under which id.
//!
//! Moving bodies live in the sweep and prune, bounded static scenery in the uniform grid, and
//! unbounded scenery (half-spaces) in a plain list checked against every moving body (a
//! half-space pairs with those whose volume reaches below its plane). Ids are dense
//! slot numbers (the structures size arrays by the largest id), and an id freed during a step is
//! reused only after the step's commit, as the sweep and prune requires. Each id also says
//! whether its moving body sleeps, so that pairs are found only where a body is awake.

use crate::broad_phase::ProxyId;
use bevy_ecs::entity::{Entity, EntityHashMap};

/// Where a collider is indexed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Proxy {
    /// In the moving-body broad phase under this id.
    Moving(ProxyId),
    /// In the static grid under this id.
    Static(ProxyId),
    /// In the unbounded list.
    Unbounded,
}

/// What an id holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum IdUse {
    /// Nothing (freed, or never used).
    #[default]
    Free,
    /// An awake moving body.
    Moving,
    /// A sleeping moving body.
    Asleep,
    /// Static scenery in the grid.
    Static,
}

/// Entity ↔ proxy id, with deferred id reuse.
#[derive(Default, Debug)]
pub(crate) struct ProxyTable {
    by_entity: EntityHashMap<Proxy>,
    entity_of: Vec<Entity>,
    uses: Vec<IdUse>,
    /// A bit per id, set for awake moving bodies: the awake ids are found a word of 64 ids at
    /// a time, so a scene at rest costs no pass over its sleeping bodies' ids.
    awake: Vec<u64>,
    free: Vec<ProxyId>,
    released: Vec<ProxyId>,
    unbounded: Vec<Entity>,
}

impl ProxyTable {
    /// Where `e` is indexed, if anywhere.
    pub fn get(&self, e: Entity) -> Option<Proxy> {
        self.by_entity.get(&e).copied()
    }

    /// The entity holding proxy id `id`.
    pub fn entity(&self, id: ProxyId) -> Entity {
        self.entity_of[id as usize]
    }

    /// Registers `e` (not registered yet); `moving` chooses the structure for a bounded collider.
    pub fn register(&mut self, e: Entity, bounded: bool, moving: bool) -> Proxy {
        let proxy = if !bounded {
            let at = self.unbounded.binary_search(&e).unwrap_or_else(|i| i);
            self.unbounded.insert(at, e);
            Proxy::Unbounded
        } else {
            let id = self.allocate(e);
            if moving {
                self.set_use(id, IdUse::Moving);
                Proxy::Moving(id)
            } else {
                self.set_use(id, IdUse::Static);
                Proxy::Static(id)
            }
        };
        self.by_entity.insert(e, proxy);
        proxy
    }

    /// Forgets `e`, returning where it was.
    pub fn unregister(&mut self, e: Entity) -> Option<Proxy> {
        let proxy = self.by_entity.remove(&e)?;
        match proxy {
            Proxy::Moving(id) | Proxy::Static(id) => {
                self.entity_of[id as usize] = Entity::PLACEHOLDER;
                self.set_use(id, IdUse::Free);
                self.released.push(id);
            }
            Proxy::Unbounded => {
                if let Ok(at) = self.unbounded.binary_search(&e) {
                    self.unbounded.remove(at);
                }
            }
        }
        Some(proxy)
    }

    /// Makes the ids freed this step available again (after the broad phase committed).
    pub fn end_step(&mut self) {
        self.free.append(&mut self.released);
        // Reuse the lowest ids first, in a fixed order, so runs are reproducible.
        self.free.sort_unstable_by(|a, b| b.cmp(a));
    }

    /// Unbounded colliders, in entity order.
    pub fn unbounded(&self) -> &[Entity] {
        &self.unbounded
    }

    /// Ids of awake moving bodies, ascending (a pass over a bit per id: no lookups).
    pub fn awake_moving_ids(&self) -> impl Iterator<Item = ProxyId> + '_ {
        self.awake.iter().enumerate().flat_map(|(word, &bits)| {
            let base = (word * 64) as ProxyId;
            // Each step clears the lowest set bit; `wrapping_sub`: `successors` computes one
            // step past the last bit (0 - 1 would overflow in a debug build).
            std::iter::successors(Some(bits), |b| Some(b & b.wrapping_sub(1)))
                .take_while(|&b| b != 0)
                .map(move |b| base + b.trailing_zeros() as ProxyId)
        })
    }

    /// Whether id `id` holds a sleeping moving body.
    pub fn is_asleep(&self, id: ProxyId) -> bool {
        self.uses[id as usize] == IdUse::Asleep
    }

    /// Records that the moving body `e` fell asleep or woke (nothing for other entities).
    pub fn set_asleep(&mut self, e: Entity, asleep: bool) {
        if let Some(Proxy::Moving(id)) = self.get(e) {
            self.set_use(id, if asleep { IdUse::Asleep } else { IdUse::Moving });
        }
    }

    /// Records what id `id` holds, and sets or clears its bit in `awake` to match.
    fn set_use(&mut self, id: ProxyId, to: IdUse) {
        self.uses[id as usize] = to;
        let (word, bit) = (id as usize / 64, 1u64 << (id % 64));
        if word >= self.awake.len() {
            self.awake.resize(word + 1, 0);
        }
        if to == IdUse::Moving {
            self.awake[word] |= bit;
        } else {
            self.awake[word] &= !bit;
        }
    }

    fn allocate(&mut self, e: Entity) -> ProxyId {
        match self.free.pop() {
            Some(id) => {
                self.entity_of[id as usize] = e;
                id
            }
            None => {
                self.entity_of.push(e);
                self.uses.push(IdUse::Free);
                (self.entity_of.len() - 1) as ProxyId
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy_ecs::world::World;

    #[test]
    fn ids_freed_in_a_step_are_reused_only_after_it() {
        let mut world = World::new();
        let [a, b, c, d] = [(); 4].map(|_| world.spawn_empty().id());
        let mut t = ProxyTable::default();
        assert_eq!(t.register(a, true, true), Proxy::Moving(0));
        assert_eq!(t.register(b, true, false), Proxy::Static(1));
        assert_eq!(t.unregister(a), Some(Proxy::Moving(0)));
        assert_eq!(
            t.register(c, true, true),
            Proxy::Moving(2),
            "0 is not free yet"
        );
        t.end_step();
        assert_eq!(t.register(a, true, true), Proxy::Moving(0));
        assert_eq!(t.entity(0), a);
        assert_eq!(t.awake_moving_ids().collect::<Vec<_>>(), vec![0, 2]);
        t.set_asleep(c, true);
        assert!(t.is_asleep(2) && !t.is_asleep(0));
        assert_eq!(t.awake_moving_ids().collect::<Vec<_>>(), vec![0]);
        t.set_asleep(b, true); // static: stays in the grid, unchanged
        assert!(!t.is_asleep(1));
        t.set_asleep(c, false);
        assert_eq!(t.awake_moving_ids().collect::<Vec<_>>(), vec![0, 2]);
        assert_eq!(t.register(d, false, false), Proxy::Unbounded);
        assert_eq!(t.unbounded(), &[d]);
    }

    #[test]
    fn awake_ids_across_many_words_are_those_marked_awake_in_ascending_order() {
        let mut world = World::new();
        let mut t = ProxyTable::default();
        let bodies: Vec<Entity> = (0..300).map(|_| world.spawn_empty().id()).collect();
        for (i, &e) in bodies.iter().enumerate() {
            t.register(e, true, i % 7 != 3);
        }
        for (i, &e) in bodies.iter().enumerate() {
            if i % 5 == 0 || (64..128).contains(&i) {
                t.set_asleep(e, true);
            }
        }
        t.set_asleep(bodies[65], false);
        t.unregister(bodies[299]);
        let expected: Vec<ProxyId> = (0..299)
            .filter(|&i| i % 7 != 3 && (i % 5 != 0 && !(64..128).contains(&i) || i == 65))
            .map(|i| i as ProxyId)
            .collect();
        assert_eq!(t.awake_moving_ids().collect::<Vec<_>>(), expected);
    }
}
