//! Which broad-phase structure holds each collider, under which id.
//!
//! Moving bodies live in the sweep and prune, bounded static scenery in the uniform grid, and
//! unbounded scenery (half-spaces) in a plain list paired with every moving body. Ids are dense
//! slot numbers (the structures size arrays by the largest id), and an id freed during a step is
//! reused only after the step's commit, as the sweep and prune requires.

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

/// Entity ↔ proxy id, with deferred id reuse.
#[derive(Default, Debug)]
pub(crate) struct ProxyTable {
    by_entity: EntityHashMap<Proxy>,
    entity_of: Vec<Entity>,
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
                Proxy::Moving(id)
            } else {
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

    /// Ids of registered moving bodies, ascending.
    pub fn moving_ids(&self) -> impl Iterator<Item = ProxyId> + '_ {
        (0..self.entity_of.len() as ProxyId).filter(|&id| {
            let e = self.entity_of[id as usize];
            e != Entity::PLACEHOLDER && matches!(self.by_entity.get(&e), Some(Proxy::Moving(_)))
        })
    }

    fn allocate(&mut self, e: Entity) -> ProxyId {
        match self.free.pop() {
            Some(id) => {
                self.entity_of[id as usize] = e;
                id
            }
            None => {
                self.entity_of.push(e);
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
        assert_eq!(t.moving_ids().collect::<Vec<_>>(), vec![0, 2]);
        assert_eq!(t.register(d, false, false), Proxy::Unbounded);
        assert_eq!(t.unbounded(), &[d]);
    }
}
