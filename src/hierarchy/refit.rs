//! Which nodes of a hierarchy to refit after some changed, and in which order.

/// Longest path from a changed node up to its root that [`refit_order`] climbs.
pub const MAX_PATH: u32 = 1 << 16;

/// The nodes to refit when the nodes in `changed` had their own volume change: each of them and
/// every ancestor, once, deepest first (so a node is refit after all its changed children).
/// `parent` walks up the tree. Runs in O(changed × depth); nodes outside the changed paths are
/// never looked at.
pub fn refit_order<N: Copy + Ord>(
    changed: impl IntoIterator<Item = N>,
    parent: impl Fn(N) -> Option<N>,
    out: &mut Vec<(u32, N)>,
) {
    out.clear();
    for n in changed {
        let mut path_depth = 0u32;
        let mut up = Some(n);
        let start = out.len();
        while let Some(node) = up {
            out.push((0, node));
            path_depth += 1;
            // A loop of parents would climb for ever: stop, as the ECS walks do (the loop's
            // nodes are quarantined there).
            if path_depth >= MAX_PATH {
                break;
            }
            up = parent(node);
        }
        // Depths are measured from the root: the last node pushed is the root, depth 0.
        for (k, item) in out[start..].iter_mut().enumerate() {
            item.0 = path_depth - 1 - k as u32;
        }
    }
    out.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    out.dedup_by(|a, b| a.1 == b.1);
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
        refit_order([3, 2, 9], parent, &mut out);
        let nodes: Vec<u32> = out.iter().map(|(_, n)| *n).collect();
        assert_eq!(nodes, vec![3, 2, 1, 0, 9]);
        assert!(!nodes.contains(&4) && !nodes.contains(&5));
    }
}
