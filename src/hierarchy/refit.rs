//! Which nodes of a hierarchy to refit after some changed, and in which order.

use std::collections::HashMap;
use std::hash::Hash;

/// Longest path from a changed node up to its root that [`refit_order`] climbs.
pub const MAX_PATH: u32 = 1 << 16;

/// The nodes to refit when the nodes in `changed` had their own volume change: each of them and
/// every ancestor, once, deepest first (so a node is refit after all its changed children).
/// `parent` walks up the tree. Each node's depth is found once (`depths` memoises it across the
/// changed paths, which share their upper parts), so the cost is linear in the nodes on those
/// paths, not `changed × depth` (a 10,000-deep chain whose every node moved took 0.7 s a step);
/// nodes outside the changed paths are never looked at. `depths` is scratch, left filled.
pub fn refit_order<N: Copy + Ord + Hash>(
    changed: impl IntoIterator<Item = N>,
    parent: impl Fn(N) -> Option<N>,
    depths: &mut HashMap<N, u32>,
    out: &mut Vec<(u32, N)>,
) {
    out.clear();
    depths.clear();
    let mut path = Vec::new();
    for n in changed {
        record_depths(n, &parent, depths, &mut path);
    }
    out.extend(depths.iter().map(|(&n, &d)| (d, n)));
    out.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
}

/// Climbs from `start` towards its root, pushing onto `path` each node that `known` does not
/// answer for, and returns the answer for the first node it does (`None`: the climb ended at a
/// root, the last node of `path`, or after `MAX_PATH` nodes, on a loop of parents, which
/// validation quarantines). The memoised walk shared by the hierarchy's climbs: with `known`
/// filled from each climb's `path`, many climbs up one chain cost linear time together.
pub fn climb<N: Copy, V>(
    start: Option<N>,
    parent: impl Fn(N) -> Option<N>,
    known: impl Fn(N) -> Option<V>,
    path: &mut Vec<N>,
) -> Option<V> {
    path.clear();
    let mut up = start;
    while let Some(node) = up {
        if let Some(v) = known(node) {
            return Some(v);
        }
        path.push(node);
        if path.len() as u32 >= MAX_PATH {
            return None;
        }
        up = parent(node);
    }
    None
}

/// Records in `depths` the depth of `n` (its root: 0) and of every ancestor met on the way up;
/// the climb stops at the first node already there.
fn record_depths<N: Copy + Eq + Hash>(
    n: N,
    parent: &impl Fn(N) -> Option<N>,
    depths: &mut HashMap<N, u32>,
    path: &mut Vec<N>,
) {
    let base = climb(Some(n), parent, |x| depths.get(&x).copied(), path);
    // The last node of the path is a root (depth 0) or the child of a known node.
    let first = base.map_or(0, |d| d + 1);
    for (k, node) in path.iter().rev().enumerate() {
        depths.insert(*node, first + k as u32);
    }
}

/// The nodes of `marked` that have no marked ancestor, in `marked`'s order: updating each of
/// their subtrees top-down updates every marked node exactly once. `covered` memoises, per node
/// met, whether it or an ancestor is marked, so the cost is linear in the nodes on the marked
/// paths. Both scratch arguments are left filled.
pub fn topmost_marked<N: Copy + Eq + Hash>(
    marked: &[N],
    parent: impl Fn(N) -> Option<N>,
    covered: &mut HashMap<N, bool>,
    out: &mut Vec<N>,
) {
    out.clear();
    covered.clear();
    covered.extend(marked.iter().map(|&n| (n, true)));
    let mut path = Vec::new();
    for &n in marked {
        let above = climb(parent(n), &parent, |x| covered.get(&x).copied(), &mut path);
        let verdict = above.unwrap_or(false);
        for node in path.drain(..) {
            covered.insert(node, verdict);
        }
        if !verdict {
            out.push(n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn changed_nodes_and_their_ancestors_deepest_first_each_once() {
        // 0 ─ 1 ─ 2 ─ 3        and an untouched 0 ─ 4 ─ 5 branch, plus a lone root 9.
        let parent = |n: u32| match n {
            1 | 4 => Some(0),
            2 => Some(1),
            3 => Some(2),
            5 => Some(4),
            _ => None,
        };
        let mut out = Vec::new();
        refit_order([3, 2, 9], parent, &mut HashMap::new(), &mut out);
        let nodes: Vec<u32> = out.iter().map(|(_, n)| *n).collect();
        assert_eq!(nodes, vec![3, 2, 1, 0, 9]);
        assert!(!nodes.contains(&4) && !nodes.contains(&5));
        assert_eq!(out[0].0, 3, "3 is three below its root");
    }

    #[test]
    fn a_100000_deep_chain_all_changed_visits_each_node_once() {
        let n = 100_000u32;
        let calls = std::cell::Cell::new(0u64);
        let parent = |k: u32| {
            calls.set(calls.get() + 1);
            k.checked_sub(1)
        };
        let mut out = Vec::new();
        refit_order(0..n, parent, &mut HashMap::new(), &mut out);
        assert_eq!(out.len(), n as usize);
        assert_eq!(out[0], (n - 1, n - 1));
        assert!(
            calls.get() <= 2 * u64::from(n),
            "{} parent calls",
            calls.get()
        );
        calls.set(0);
        let marked: Vec<u32> = (0..n).rev().collect();
        let mut top = Vec::new();
        topmost_marked(&marked, parent, &mut HashMap::new(), &mut top);
        assert_eq!(top, vec![0]);
        assert!(
            calls.get() <= 2 * u64::from(n),
            "{} parent calls",
            calls.get()
        );
    }

    #[test]
    fn topmost_marked_keeps_marked_nodes_without_marked_ancestors() {
        let parent = |n: u32| match n {
            1 | 4 => Some(0),
            2 => Some(1),
            3 => Some(2),
            5 => Some(4),
            _ => None,
        };
        let mut top = Vec::new();
        topmost_marked(&[3, 1, 5, 9], parent, &mut HashMap::new(), &mut top);
        assert_eq!(top, vec![1, 5, 9]);
    }
}
