//! The step's solver slots: the bodies in entity order, and each entity's slot found in one
//! read.
//!
//! The solver's bodies are ordered by entity (never by archetype), so the step's result does
//! not depend on which components a game adds. The gather looks a slot up for every joint end,
//! contact side, force and spring: by binary search over the sorted entities that was about 30
//! comparisons per joint, a twentieth of a 10,000-ball net's step (`valgrind --tool=callgrind`).
//! Here a table indexed by the entity's index holds its slot, and the slot's entity confirms it
//! (a stale entry from another step, or a recycled index, never matches), so nothing is cleared
//! between steps. The table covers indices below [`TABLE_LIMIT`] (16 MB at most): an entity
//! past it (a joint naming `Entity::PLACEHOLDER` before validation quarantines it) is found by
//! binary search instead of growing the table to gigabytes.

use bevy_ecs::entity::Entity;

/// Entity indices the table covers (4 bytes each).
const TABLE_LIMIT: usize = 1 << 22;

/// The bodies of this step in slot order (sorted by entity) and a slot per entity index.
#[derive(Debug, Default)]
pub(super) struct BodySlots {
    entities: Vec<Entity>,
    /// Slot by `Entity::index_u32`; an entry is valid only if its slot holds that entity.
    by_index: Vec<u32>,
}

impl BodySlots {
    /// The entities, slot by slot.
    pub(super) fn entities(&self) -> &[Entity] {
        &self.entities
    }

    /// The list to fill for a new step; [`Self::index`] must follow before [`Self::slot`] is
    /// asked.
    pub(super) fn entities_mut(&mut self) -> &mut Vec<Entity> {
        &mut self.entities
    }

    /// Records each entity's slot (the entities sorted and free of duplicates).
    pub(super) fn index(&mut self) {
        let top = self
            .entities
            .iter()
            .map(|e| e.index_u32() as usize + 1)
            .filter(|&top| top <= TABLE_LIMIT)
            .max()
            .unwrap_or(0);
        if self.by_index.len() < top {
            self.by_index.resize(top, u32::MAX);
        }
        for (slot, e) in self.entities.iter().enumerate() {
            if let Some(entry) = self.by_index.get_mut(e.index_u32() as usize) {
                *entry = slot as u32;
            }
        }
    }

    /// `e`'s slot this step, if it has one.
    pub(super) fn slot(&self, e: Entity) -> Option<usize> {
        let index = e.index_u32() as usize;
        if index >= TABLE_LIMIT {
            return self.entities.binary_search(&e).ok();
        }
        let slot = *self.by_index.get(index)? as usize;
        (self.entities.get(slot) == Some(&e)).then_some(slot)
    }

    /// How many slots there are.
    pub(super) fn len(&self) -> usize {
        self.entities.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy_ecs::world::World;

    #[test]
    fn slots_match_binary_search_and_refuse_stale_and_recycled_entities() {
        let mut world = World::new();
        let all: Vec<Entity> = (0..50).map(|_| world.spawn_empty().id()).collect();
        let mut slots = BodySlots::default();
        // Step one: every third entity.
        slots.entities_mut().extend(all.iter().step_by(3));
        slots.entities_mut().sort_unstable();
        slots.index();
        let first: Vec<Entity> = slots.entities().to_vec();
        for e in &all {
            assert_eq!(slots.slot(*e), first.binary_search(e).ok(), "{e:?}");
        }
        // Step two: fewer bodies; the old table entries past them must not answer.
        slots.entities_mut().clear();
        slots.entities_mut().extend(all.iter().skip(1).step_by(7));
        slots.entities_mut().sort_unstable();
        slots.index();
        let second: Vec<Entity> = slots.entities().to_vec();
        for e in &all {
            assert_eq!(slots.slot(*e), second.binary_search(e).ok(), "{e:?}");
        }
        // An entity of a later generation on a slot's index (the index recycled) has no slot.
        let old = second[0];
        let recycled = Entity::from_bits(old.to_bits() + (1 << 32));
        assert_eq!(recycled.index_u32(), old.index_u32());
        assert_ne!(recycled, old);
        assert_eq!(slots.slot(recycled), None);
        assert_eq!(slots.slot(old), Some(0));
        // An index past the table (the placeholder's) is searched, and grows nothing.
        slots.entities_mut().push(Entity::PLACEHOLDER);
        slots.entities_mut().sort_unstable();
        slots.index();
        let at = slots.entities().binary_search(&Entity::PLACEHOLDER).ok();
        assert!(at.is_some());
        assert_eq!(slots.slot(Entity::PLACEHOLDER), at);
        assert!(slots.by_index.len() <= TABLE_LIMIT);
        assert_eq!(slots.len(), second.len() + 1);
    }
}
