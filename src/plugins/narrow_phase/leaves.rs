//! The colliders a step's pair tests read: each body that is its own only collider has its
//! shape, world pose and change flag taken from the world once a step, with its other facts,
//! and lent to the pair loop by index (two queries of the world per pair were a tenth of a
//! falling pile's narrow phase). The buffer holding these borrows is kept between steps.

use super::{Node, Quarantined};
use crate::components::{Collider, GlobalPose};
use crate::geometry::{Isometry, Shape};
use bevy_ecs::prelude::*;

/// A collider as a pair test reads it.
#[derive(Clone, Copy)]
pub(super) struct Leaf<'a> {
    pub shape: &'a Shape,
    pub pose: &'a Isometry,
    /// Changed since the last step (a cached test of it is stale).
    pub changed: bool,
}

impl<'a> Leaf<'a> {
    /// Collider `e` of `nodes`, if it has one.
    pub fn of(nodes: &'a Query<Node, Without<Quarantined>>, e: Entity) -> Option<Self> {
        let (Some(collider), global, ..) = nodes.get(e).ok()? else {
            return None;
        };
        Some(Self::new(collider, global))
    }

    /// The collider and its world pose, as one query item gives them.
    pub fn new(collider: Ref<'a, Collider>, global: &'a GlobalPose) -> Self {
        let changed = collider.is_changed();
        let shape = &collider.into_inner().shape;
        Self {
            shape,
            pose: &global.0,
            changed,
        }
    }
}

/// The index a body's facts hold for a body without a leaf of its own (no collider, or parts).
pub(super) const NO_LEAF_OF_ITS_OWN: u32 = u32::MAX;

/// `v`'s buffer, emptied, for items of another lifetime: a `Vec` collected from its own
/// iterator with items of the same size and alignment reuses its allocation (the standard
/// library's in-place collection), so the buffer lent to a step's borrows is kept between
/// steps without a reference outliving them.
#[allow(clippy::unnecessary_filter_map)] // the map is what changes the items' lifetime
pub(super) fn emptied<'a>(mut v: Vec<Leaf<'a>>) -> Vec<Leaf<'static>> {
    v.clear();
    v.into_iter().filter_map(|_| None).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_leaves_buffer_lent_to_a_step_comes_back_with_its_allocation_and_no_items() {
        let (shape, pose) = (Shape::sphere(1.0), Isometry::IDENTITY);
        let leaf = Leaf {
            shape: &shape,
            pose: &pose,
            changed: false,
        };
        let mut lent: Vec<Leaf<'_>> = Vec::with_capacity(64);
        lent.extend([leaf; 10]);
        let (buffer, capacity) = (lent.as_ptr() as usize, lent.capacity());
        let kept = emptied(lent);
        assert!(kept.is_empty());
        assert_eq!(
            (kept.as_ptr() as usize, kept.capacity()),
            (buffer, capacity)
        );
    }
}
