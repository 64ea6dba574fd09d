//! Debug output of the scene-graph descent: which hierarchy nodes the narrow phase looked at.
//!
//! The pair query between two compound bodies ([`descend_pairs`](crate::hierarchy::descend_pairs))
//! tests bounding volumes from the roots down and enters only the nodes whose volume overlaps
//! the other side's (the slides' `Nv`). To show that descent, the narrow phase can run it through
//! a [`VisitRecorder`], a [`BvTree`] that forwards to the real tree and notes each node whose
//! volume was read for a test and each node that was entered. It does so only while
//! [`HierarchyVisits::enabled`], so the narrow phase pays nothing for it otherwise.

use crate::bounding::Aabb;
use crate::hierarchy::BvTree;
use bevy_ecs::prelude::*;
use std::cell::RefCell;

/// The scene-graph nodes the descent of compound pairs looked at in the last substep. Empty
/// unless `enabled` (the rerun recording enables it on request).
///
/// Pairs of two bodies without parts skip the descent and do not appear here.
#[derive(Resource, Debug, Default, Clone, PartialEq)]
pub struct HierarchyVisits {
    /// Fill the lists below (costs a little per node tested).
    pub enabled: bool,
    /// Nodes whose volume overlapped the other side's, so the descent entered them (split them
    /// or handed their collider on), with the volume they had then; sorted by entity, each once.
    pub entered: Vec<(Entity, Aabb)>,
    /// Nodes whose volume was tested but never overlapped: the descent stopped there and never
    /// looked below; sorted by entity, each once.
    pub pruned: Vec<(Entity, Aabb)>,
    /// The collider pairs handed to the exact shape test (the slides' `Ns`), in the order found.
    pub collider_pairs: Vec<(Entity, Entity)>,
}

impl HierarchyVisits {
    /// Empties the lists (start of a substep).
    pub(super) fn clear(&mut self) {
        self.entered.clear();
        self.pruned.clear();
        self.collider_pairs.clear();
    }

    /// Turns the raw notes of the substep into the published lists: `pruned` keeps the tested
    /// nodes that were never entered.
    pub(super) fn finish(&mut self, tested: &mut Vec<(Entity, Aabb)>) {
        sort_dedup(&mut self.entered);
        sort_dedup(tested);
        let entered = &self.entered;
        self.pruned.extend(
            tested
                .drain(..)
                .filter(|(e, _)| entered.binary_search_by_key(e, |(x, _)| *x).is_err()),
        );
    }
}

/// Sorts by entity and keeps the first volume seen for each (deterministic: the sort is stable
/// and the descent's order is).
fn sort_dedup(nodes: &mut Vec<(Entity, Aabb)>) {
    nodes.sort_by_key(|(e, _)| *e);
    nodes.dedup_by_key(|(e, _)| *e);
}

/// A [`BvTree`] that forwards to `tree` and notes what the descent reads: a subtree volume read
/// means the node was tested, a request for its children means its volume overlapped and the
/// descent entered it (that is when `descend_pairs` asks).
pub(super) struct VisitRecorder<'a, T> {
    tree: &'a T,
    tested: RefCell<&'a mut Vec<(Entity, Aabb)>>,
    entered: RefCell<&'a mut Vec<(Entity, Aabb)>>,
}

impl<'a, T: BvTree<Node = Entity>> VisitRecorder<'a, T> {
    pub(super) fn new(
        tree: &'a T,
        tested: &'a mut Vec<(Entity, Aabb)>,
        entered: &'a mut Vec<(Entity, Aabb)>,
    ) -> Self {
        Self {
            tree,
            tested: RefCell::new(tested),
            entered: RefCell::new(entered),
        }
    }
}

impl<T: BvTree<Node = Entity>> BvTree for VisitRecorder<'_, T> {
    type Node = Entity;

    fn subtree_bv(&self, n: Entity) -> Aabb {
        let bv = self.tree.subtree_bv(n);
        self.tested.borrow_mut().push((n, bv));
        bv
    }

    fn own_bv(&self, n: Entity) -> Option<Aabb> {
        self.tree.own_bv(n)
    }

    fn children(&self, n: Entity, out: &mut Vec<Entity>) {
        self.entered.borrow_mut().push((n, self.tree.subtree_bv(n)));
        self.tree.children(n, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hierarchy::{PairScratch, descend_pairs};
    use glam::Vec3;

    /// Node `i` is `Entity::from_raw(i)`; a root with two children, one far away.
    struct Tiny {
        boxes: Vec<Aabb>,
    }

    fn entity(i: u32) -> Entity {
        Entity::from_raw_u32(i + 1).expect("a valid index")
    }

    fn index(e: Entity) -> usize {
        e.index_u32() as usize - 1
    }

    impl BvTree for Tiny {
        type Node = Entity;
        fn subtree_bv(&self, n: Entity) -> Aabb {
            match index(n) {
                0 => self.boxes[1].union(&self.boxes[2]),
                i => self.boxes[i],
            }
        }
        fn own_bv(&self, n: Entity) -> Option<Aabb> {
            (index(n) != 0).then(|| self.boxes[index(n)])
        }
        fn children(&self, n: Entity, out: &mut Vec<Entity>) {
            if index(n) == 0 {
                out.extend([entity(1), entity(2)]);
            }
        }
    }

    #[test]
    fn the_near_child_is_entered_and_the_far_one_pruned() {
        let cube = |x: f32| Aabb::from_center_half_extents(Vec3::new(x, 0.0, 0.0), Vec3::ONE);
        // Nodes 0..3: a compound (root 0, near child 1, far child 2); node 3 is a lone ball
        // touching child 1 only.
        let tree = Tiny {
            boxes: vec![Aabb::EMPTY, cube(0.0), cube(10.0), cube(1.5)],
        };
        let (mut tested, mut visits) = (Vec::new(), HierarchyVisits::default());
        let recorder = VisitRecorder::new(&tree, &mut tested, &mut visits.entered);
        let mut scratch = PairScratch::default();
        descend_pairs(
            &recorder,
            entity(0),
            &recorder,
            entity(3),
            &mut scratch,
            |a, b| visits.collider_pairs.push((a, b)),
        );
        visits.finish(&mut tested);
        let names = |v: &[(Entity, Aabb)]| {
            let mut n: Vec<usize> = v.iter().map(|(e, _)| index(*e)).collect();
            n.sort_unstable();
            n
        };
        assert_eq!(names(&visits.entered), vec![0, 1, 3]);
        assert_eq!(names(&visits.pruned), vec![2]);
        assert_eq!(visits.collider_pairs, vec![(entity(1), entity(3))]);
        assert!(tested.is_empty(), "the notes are consumed");
    }
}
