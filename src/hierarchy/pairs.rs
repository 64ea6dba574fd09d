//! The pair query between two bounding-volume hierarchies.

use crate::bounding::Aabb;

/// What the traversal needs to know of a hierarchy.
pub trait BvTree {
    /// A node handle.
    type Node: Copy;

    /// The volume bounding the node's own collider and its whole subtree.
    fn subtree_bv(&self, node: Self::Node) -> Aabb;

    /// The volume of the node's own collider, `None` when the node has none.
    fn own_bv(&self, node: Self::Node) -> Option<Aabb>;

    /// Appends the node's children to `out` (nothing for a leaf).
    fn children(&self, node: Self::Node, out: &mut Vec<Self::Node>);
}

/// Counters of one query, in the slides' cost model's terms.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HierarchyStats {
    /// Bounding-volume pairs tested (`Nn`).
    pub bv_tests: u64,
    /// Overlapping node pairs expanded or handed on (`Nv`).
    pub nodes_visited: u64,
    /// Collider pairs handed to the leaf test (`Ns`).
    pub leaf_pairs: u64,
}

impl std::ops::AddAssign for HierarchyStats {
    fn add_assign(&mut self, other: Self) {
        self.bv_tests += other.bv_tests;
        self.nodes_visited += other.nodes_visited;
        self.leaf_pairs += other.leaf_pairs;
    }
}

/// A node seen whole, or only its own collider (after its children were split off).
#[derive(Clone, Copy, Debug)]
enum Item<N> {
    Subtree(N),
    Own(N),
}

/// Reusable buffers of [`descend_pairs`], so a query allocates nothing once warm.
pub struct PairScratch<A, B> {
    stack: Vec<(Item<A>, Item<B>)>,
    children_a: Vec<A>,
    children_b: Vec<B>,
}

impl<A, B> Default for PairScratch<A, B> {
    fn default() -> Self {
        Self {
            stack: Vec::new(),
            children_a: Vec::new(),
            children_b: Vec::new(),
        }
    }
}

/// Calls `leaf_pair(a, b)` for every pair of colliders, one from each hierarchy, whose own
/// volumes overlap — the same pairs as testing every collider of one against every collider of
/// the other, found by descending only where volumes overlap.
pub fn descend_pairs<TA: BvTree, TB: BvTree>(
    tree_a: &TA,
    root_a: TA::Node,
    tree_b: &TB,
    root_b: TB::Node,
    scratch: &mut PairScratch<TA::Node, TB::Node>,
    mut leaf_pair: impl FnMut(TA::Node, TB::Node),
) -> HierarchyStats {
    let mut stats = HierarchyStats::default();
    scratch.stack.clear();
    scratch
        .stack
        .push((Item::Subtree(root_a), Item::Subtree(root_b)));
    while let Some((x, y)) = scratch.stack.pop() {
        let (Some(bx), Some(by)) = (bv(tree_a, x), bv(tree_b, y)) else {
            continue;
        };
        stats.bv_tests += 1;
        if !bx.intersects(&by) {
            continue;
        }
        stats.nodes_visited += 1;
        let split_x = splittable(tree_a, x, &mut scratch.children_a);
        let split_y = splittable(tree_b, y, &mut scratch.children_b);
        match (split_x, split_y) {
            (false, false) => {
                stats.leaf_pairs += 1;
                leaf_pair(node(x), node(y));
            }
            (true, false) => expand_a(tree_a, x, y, scratch),
            (false, true) => expand_b(tree_b, x, y, scratch),
            (true, true) if size(&bx) >= size(&by) => expand_a(tree_a, x, y, scratch),
            (true, true) => expand_b(tree_b, x, y, scratch),
        }
    }
    stats
}

fn node<N>(item: Item<N>) -> N {
    match item {
        Item::Subtree(n) | Item::Own(n) => n,
    }
}

/// The item's volume: the subtree's, or the own collider's (`None`: nothing to collide).
fn bv<T: BvTree>(tree: &T, item: Item<T::Node>) -> Option<Aabb> {
    match item {
        Item::Subtree(n) => Some(tree.subtree_bv(n)),
        Item::Own(n) => tree.own_bv(n),
    }
}

/// True for a whole subtree with children (it must be split before reaching colliders); a
/// childless subtree is just its own collider. Leaves the children in `buf`.
fn splittable<T: BvTree>(tree: &T, item: Item<T::Node>, buf: &mut Vec<T::Node>) -> bool {
    buf.clear();
    match item {
        Item::Subtree(n) => {
            tree.children(n, buf);
            !buf.is_empty()
        }
        Item::Own(_) => false,
    }
}

/// The size compared by the "split the larger volume" rule: half the box's diagonal.
fn size(b: &Aabb) -> f32 {
    b.half_extents().length()
}

fn expand_a<TA: BvTree, B: Copy>(
    tree: &TA,
    x: Item<TA::Node>,
    y: Item<B>,
    s: &mut PairScratch<TA::Node, B>,
) {
    let n = node(x);
    if tree.own_bv(n).is_some() {
        s.stack.push((Item::Own(n), y));
    }
    s.stack
        .extend(s.children_a.iter().map(|&c| (Item::Subtree(c), y)));
}

fn expand_b<A: Copy, TB: BvTree>(
    tree: &TB,
    x: Item<A>,
    y: Item<TB::Node>,
    s: &mut PairScratch<A, TB::Node>,
) {
    let n = node(y);
    if tree.own_bv(n).is_some() {
        s.stack.push((x, Item::Own(n)));
    }
    s.stack
        .extend(s.children_b.iter().map(|&c| (x, Item::Subtree(c))));
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A tree in arrays: node i has an optional own box and children.
    struct Arena {
        own: Vec<Option<Aabb>>,
        children: Vec<Vec<usize>>,
        subtree: Vec<Aabb>,
    }

    impl Arena {
        fn new(own: Vec<Option<Aabb>>, children: Vec<Vec<usize>>) -> Self {
            let mut a = Self {
                subtree: vec![Aabb::EMPTY; own.len()],
                own,
                children,
            };
            for i in (0..a.own.len()).rev() {
                // Children have larger indices in these tests, so reverse order is bottom-up.
                let mut b = a.own[i].unwrap_or(Aabb::EMPTY);
                for &c in &a.children[i] {
                    b = b.union(&a.subtree[c]);
                }
                a.subtree[i] = b;
            }
            a
        }

        fn leaves(&self) -> Vec<usize> {
            (0..self.own.len())
                .filter(|&i| self.own[i].is_some())
                .collect()
        }
    }

    impl BvTree for Arena {
        type Node = usize;
        fn subtree_bv(&self, n: usize) -> Aabb {
            self.subtree[n]
        }
        fn own_bv(&self, n: usize) -> Option<Aabb> {
            self.own[n]
        }
        fn children(&self, n: usize, out: &mut Vec<usize>) {
            out.extend_from_slice(&self.children[n]);
        }
    }

    fn cube(c: Vec3, h: f32) -> Option<Aabb> {
        Some(Aabb::from_center_half_extents(c, Vec3::splat(h)))
    }

    /// A wide tree (a root with `n` children in a row) and a chain of depth `d`.
    fn comb(n: usize, x0: f32) -> Arena {
        let mut own = vec![cube(Vec3::new(x0, 0.0, 0.0), 0.5)];
        own.extend((0..n).map(|i| cube(Vec3::new(x0 + i as f32 * 0.7, 1.0, 0.0), 0.4)));
        let mut children = vec![(1..=n).collect()];
        children.extend((0..n).map(|_| vec![]));
        Arena::new(own, children)
    }

    fn chain(d: usize, x0: f32) -> Arena {
        let own = (0..d)
            .map(|i| {
                if i % 2 == 0 {
                    cube(Vec3::new(x0 + i as f32 * 0.5, 1.0, 0.0), 0.3)
                } else {
                    None
                }
            })
            .collect();
        let children = (0..d)
            .map(|i| if i + 1 < d { vec![i + 1] } else { vec![] })
            .collect();
        Arena::new(own, children)
    }

    fn brute_force(a: &Arena, b: &Arena) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for i in a.leaves() {
            for j in b.leaves() {
                if a.own[i].unwrap().intersects(&b.own[j].unwrap()) {
                    out.push((i, j));
                }
            }
        }
        out
    }

    #[test]
    fn descending_finds_exactly_the_overlapping_collider_pairs() {
        let mut scratch = PairScratch::default();
        for (a, b) in [
            (comb(1000, 0.0), chain(8, 3.0)),
            (chain(9, 0.0), comb(50, -2.0)),
            (comb(30, 0.0), comb(30, 0.35)),
            (chain(8, 0.0), chain(8, 0.25)),
        ] {
            let mut found = Vec::new();
            let stats = descend_pairs(&a, 0, &b, 0, &mut scratch, |x, y| found.push((x, y)));
            found.sort_unstable();
            let expected = brute_force(&a, &b);
            assert!(!expected.is_empty());
            assert_eq!(found, expected);
            assert_eq!(stats.leaf_pairs, expected.len() as u64);
        }
    }

    #[test]
    fn disjoint_hierarchies_cost_one_test() {
        let (a, b) = (comb(1000, 0.0), comb(1000, 5000.0));
        let mut scratch = PairScratch::default();
        let stats = descend_pairs(&a, 0, &b, 0, &mut scratch, |_, _| panic!("no pair"));
        assert_eq!(
            stats,
            HierarchyStats {
                bv_tests: 1,
                nodes_visited: 0,
                leaf_pairs: 0
            }
        );
    }
}
