//! The bodies of the broad phases that recompute everything each commit ([`super::BruteForce`],
//! [`super::SortAndSweep`]): dense arrays of boxes, kinds and ids, plus an id → position table,
//! with swap-remove so that removal is O(1).

use super::{BodyKind, BroadPhaseError, ProxyId, check_aabb, check_bulk, check_id};
use crate::bounding::Aabb;
use std::mem::size_of;

/// Marks an id with no body in `position_of`.
const ABSENT: u32 = u32::MAX;

/// Dense body arrays indexed by position, and the position of each id.
#[derive(Debug, Default)]
pub struct BodyStore {
    position_of: Vec<u32>,
    ids: Vec<ProxyId>,
    aabbs: Vec<Aabb>,
    kinds: Vec<BodyKind>,
    seen: Vec<ProxyId>,
    /// Whether a body came, went or moved since [`Self::take_changed`].
    changed: bool,
}

impl BodyStore {
    /// Ids in position order.
    pub fn ids(&self) -> &[ProxyId] {
        &self.ids
    }

    /// Boxes in position order.
    pub fn aabbs(&self) -> &[Aabb] {
        &self.aabbs
    }

    /// Kinds in position order.
    pub fn kinds(&self) -> &[BodyKind] {
        &self.kinds
    }

    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// The position of a present id.
    fn position(&self, id: ProxyId) -> Option<usize> {
        match self.position_of.get(id as usize) {
            Some(&at) if at != ABSENT => Some(at as usize),
            _ => None,
        }
    }

    /// Whether the id is present.
    pub fn contains(&self, id: ProxyId) -> bool {
        self.position(id).is_some()
    }

    /// The box of a present id.
    pub fn aabb(&self, id: ProxyId) -> Option<Aabb> {
        self.position(id).map(|at| self.aabbs[at])
    }

    /// Adds a body (checked).
    pub fn insert(
        &mut self,
        id: ProxyId,
        aabb: Aabb,
        kind: BodyKind,
    ) -> Result<(), BroadPhaseError> {
        check_id(id)?;
        check_aabb(id, &aabb)?;
        if self.contains(id) {
            return Err(BroadPhaseError::DuplicateId(id));
        }
        self.push(id, aabb, kind);
        Ok(())
    }

    /// Adds many bodies (all checked before any is added).
    pub fn insert_bulk(
        &mut self,
        bodies: &[(ProxyId, Aabb, BodyKind)],
    ) -> Result<(), BroadPhaseError> {
        let mut seen = std::mem::take(&mut self.seen);
        let checked = check_bulk(bodies, |id| self.contains(id), &mut seen);
        self.seen = seen;
        checked?;
        for &(id, aabb, kind) in bodies {
            self.push(id, aabb, kind);
        }
        Ok(())
    }

    fn push(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) {
        let slot = id as usize;
        if slot >= self.position_of.len() {
            self.position_of.resize(slot + 1, ABSENT);
        }
        self.position_of[slot] = self.ids.len() as u32;
        self.changed = true;
        self.ids.push(id);
        self.aabbs.push(aabb);
        self.kinds.push(kind);
    }

    /// Replaces a body's box (checked).
    pub fn update(&mut self, id: ProxyId, aabb: Aabb) -> Result<(), BroadPhaseError> {
        let at = self.position(id).ok_or(BroadPhaseError::UnknownId(id))?;
        check_aabb(id, &aabb)?;
        self.changed |= self.aabbs[at] != aabb;
        self.aabbs[at] = aabb;
        Ok(())
    }

    /// Removes a body, moving the last one into its place.
    pub fn remove(&mut self, id: ProxyId) -> Result<(), BroadPhaseError> {
        let at = self.position(id).ok_or(BroadPhaseError::UnknownId(id))?;
        self.position_of[id as usize] = ABSENT;
        self.changed = true;
        self.ids.swap_remove(at);
        self.aabbs.swap_remove(at);
        self.kinds.swap_remove(at);
        if let Some(&moved) = self.ids.get(at) {
            self.position_of[moved as usize] = at as u32;
        }
        Ok(())
    }

    /// Whether a body came, went or moved since the last call (a rebuilder's commit with
    /// nothing changed keeps its pairs).
    pub fn take_changed(&mut self) -> bool {
        std::mem::take(&mut self.changed)
    }

    /// Heap bytes held.
    pub fn memory_bytes(&self) -> usize {
        (self.position_of.capacity() + self.ids.capacity() + self.seen.capacity())
            * size_of::<u32>()
            + self.aabbs.capacity() * size_of::<Aabb>()
            + self.kinds.capacity() * size_of::<BodyKind>()
    }
}
