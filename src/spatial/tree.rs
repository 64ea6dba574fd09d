//! A bounding-volume tree over colliders' boxes, for queries (rapier's query pipeline, Avian's
//! collider trees): a ray visits the boxes it enters nearest first and stops once the nearest
//! hit is closer than the next box; a volume visits the boxes it overlaps.
//!
//! Built top-down by median splits along the longest axis of the boxes' centres (balanced,
//! `O(n log n)`, no tuning), stored in a flat array whose children follow their parent, so a
//! refit (the same colliders, new boxes) is one backward pass in `O(n)`: the query index of a
//! scene whose bodies only moved is refitted every step, rebuilt only when colliders come or
//! go.

use crate::bounding::Aabb;
use glam::Vec3;

/// Most items in a leaf.
const LEAF_SIZE: usize = 4;

/// A node: a leaf holds `count > 0` items from `first`; an inner node's children are
/// `first` and `first + 1`.
#[derive(Clone, Copy, Debug)]
struct Node {
    aabb: Aabb,
    first: u32,
    count: u32,
}

/// A tree over `(id, box)` items.
#[derive(Clone, Debug, Default)]
pub struct AabbTree {
    nodes: Vec<Node>,
    /// Item ids in leaf order.
    ids: Vec<u32>,
    /// Their boxes, in the same order.
    boxes: Vec<Aabb>,
    /// Where each input item went in the leaf order (for refits).
    slot_of_input: Vec<u32>,
}

/// A ray against boxes: `origin + t·direction`, `t` in `[0, max]`.
#[derive(Clone, Copy, Debug)]
pub struct RaySegment {
    origin: Vec3,
    inverse_direction: Vec3,
}

impl RaySegment {
    /// The ray from `origin` along `direction` (need not be unit; `t` is in its lengths).
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Self {
            origin,
            inverse_direction: direction.recip(),
        }
    }

    /// Where the ray enters `aabb` if it does within `[0, max]` (slab test; an axis the ray
    /// does not move along holds it inside its slab or never).
    pub fn entry(&self, aabb: &Aabb, max: f32) -> Option<f32> {
        let t1 = (aabb.min - self.origin) * self.inverse_direction;
        let t2 = (aabb.max - self.origin) * self.inverse_direction;
        let (mut near, mut far) = (0.0f32, max);
        for axis in 0..3 {
            let (a, b) = (t1[axis], t2[axis]);
            // 0·∞ (origin on a slab face, ray parallel to it) is NaN: the slab holds the ray.
            if a.is_nan() || b.is_nan() {
                continue;
            }
            near = near.max(a.min(b));
            far = far.min(a.max(b));
        }
        (near <= far).then_some(near)
    }
}

impl AabbTree {
    /// Rebuilds the tree over `items` (ids need not be distinct or dense).
    pub fn build(&mut self, items: &[(u32, Aabb)]) {
        self.nodes.clear();
        let mut order: Vec<u32> = (0..items.len() as u32).collect();
        if !items.is_empty() {
            self.nodes.push(Node {
                aabb: Aabb::EMPTY,
                first: 0,
                count: 0,
            });
            self.split(0, &mut order, 0, items);
        }
        self.ids = order.iter().map(|&i| items[i as usize].0).collect();
        self.boxes = order.iter().map(|&i| items[i as usize].1).collect();
        self.slot_of_input = vec![0; items.len()];
        for (slot, &i) in order.iter().enumerate() {
            self.slot_of_input[i as usize] = slot as u32;
        }
        self.refit_nodes();
    }

    /// Splits the items `order` (starting at `offset` in the leaf order) under `node`.
    fn split(&mut self, node: usize, order: &mut [u32], offset: u32, items: &[(u32, Aabb)]) {
        if order.len() <= LEAF_SIZE {
            self.nodes[node].first = offset;
            self.nodes[node].count = order.len() as u32;
            return;
        }
        let centre = |i: &u32| items[*i as usize].1.center();
        let bounds = Aabb::from_points(order.iter().map(centre));
        let axis = bounds.longest_axis();
        let half = order.len() / 2;
        order.select_nth_unstable_by(half, |a, b| centre(a)[axis].total_cmp(&centre(b)[axis]));
        let children = self.nodes.len() as u32;
        self.nodes[node].first = children;
        let empty = Node {
            aabb: Aabb::EMPTY,
            first: 0,
            count: 0,
        };
        self.nodes.extend([empty, empty]);
        let (left, right) = order.split_at_mut(half);
        self.split(children as usize, left, offset, items);
        self.split(children as usize + 1, right, offset + half as u32, items);
    }

    /// New boxes for the items of the last build, given in the same order; `false` (and the
    /// tree unchanged) when the ids differ, so the caller rebuilds.
    pub fn refit(&mut self, items: &[(u32, Aabb)]) -> bool {
        let same = items.len() == self.slot_of_input.len()
            && items
                .iter()
                .zip(&self.slot_of_input)
                .all(|((id, _), &slot)| self.ids[slot as usize] == *id);
        if !same {
            return false;
        }
        for ((_, aabb), &slot) in items.iter().zip(&self.slot_of_input) {
            self.boxes[slot as usize] = *aabb;
        }
        self.refit_nodes();
        true
    }

    /// Recomputes every node's box, children before parents (children follow their parent).
    fn refit_nodes(&mut self) {
        for n in (0..self.nodes.len()).rev() {
            let Node { first, count, .. } = self.nodes[n];
            let (first, count) = (first as usize, count as usize);
            self.nodes[n].aabb = if count > 0 {
                self.boxes[first..first + count]
                    .iter()
                    .fold(Aabb::EMPTY, |a, b| a.union(b))
            } else {
                self.nodes[first].aabb.union(&self.nodes[first + 1].aabb)
            };
        }
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// Whether the tree holds no item.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The box around every item (`Aabb::EMPTY` when empty).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.aabb)
    }

    /// Calls `visit(id)` for every item whose box overlaps `aabb`.
    pub fn overlapping(&self, aabb: &Aabb, stack: &mut Vec<u32>, mut visit: impl FnMut(u32)) {
        stack.clear();
        if !self.is_empty() {
            stack.push(0);
        }
        while let Some(n) = stack.pop() {
            let node = self.nodes[n as usize];
            if !node.aabb.intersects(aabb) {
                continue;
            }
            if node.count == 0 {
                stack.extend([node.first, node.first + 1]);
                continue;
            }
            let range = node.first as usize..(node.first + node.count) as usize;
            for (id, b) in self.ids[range.clone()].iter().zip(&self.boxes[range]) {
                if b.intersects(aabb) {
                    visit(*id);
                }
            }
        }
    }

    /// Walks the items whose box, grown by `grow` (a cast sphere's radius), `ray` enters before
    /// `max`, nearer boxes first. `visit(id, entry)` returns the new `max` (a hit at `t` makes
    /// farther boxes irrelevant) or `None` to keep it, so a first-hit query prunes as it goes
    /// and an all-hits query sees every box.
    pub fn along_ray(
        &self,
        ray: &RaySegment,
        grow: f32,
        mut max: f32,
        stack: &mut Vec<(u32, f32)>,
        mut visit: impl FnMut(u32, f32) -> Option<f32>,
    ) {
        stack.clear();
        let enters = |b: &Aabb, max: f32| ray.entry(&b.expanded(grow), max);
        if let Some(t) = self.nodes.first().and_then(|root| enters(&root.aabb, max)) {
            stack.push((0, t));
        }
        while let Some((n, entry)) = stack.pop() {
            if entry > max {
                continue;
            }
            let node = self.nodes[n as usize];
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for (id, b) in self.ids[range.clone()].iter().zip(&self.boxes[range]) {
                    if let Some(t) = enters(b, max)
                        && let Some(new_max) = visit(*id, t)
                    {
                        max = max.min(new_max);
                    }
                }
                continue;
            }
            let [a, b] = [node.first, node.first + 1]
                .map(|c| (c, enters(&self.nodes[c as usize].aabb, max)));
            // The nearer child is pushed last, so it is visited first.
            let (near, far) = match (a.1, b.1) {
                (Some(ta), Some(tb)) if tb < ta => (b, a),
                _ => (a, b),
            };
            for (child, t) in [far, near] {
                if let Some(t) = t {
                    stack.push((child, t));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` boxes of sizes 0.1 to 1.1 scattered in a 20 m cube (a small LCG, fixed seed).
    fn scattered(n: usize, seed: u64) -> Vec<(u32, Aabb)> {
        let mut s = seed;
        let mut next = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|i| {
                let c = Vec3::new(next(), next(), next()) * 20.0 - 10.0;
                let h = Vec3::new(next(), next(), next()) * 0.5 + 0.05;
                (i as u32 * 3 + 7, Aabb::from_center_half_extents(c, h))
            })
            .collect()
    }

    #[test]
    fn overlap_finds_exactly_the_brute_force_set_on_200_queries_over_1000_boxes() {
        let items = scattered(1000, 1);
        let mut tree = AabbTree::default();
        tree.build(&items);
        let mut stack = Vec::new();
        for (_, query) in scattered(200, 2) {
            let query = query.expanded(1.0);
            let mut found = Vec::new();
            tree.overlapping(&query, &mut stack, |id| found.push(id));
            found.sort_unstable();
            let mut expected: Vec<u32> = items
                .iter()
                .filter(|(_, b)| b.intersects(&query))
                .map(|(id, _)| *id)
                .collect();
            expected.sort_unstable();
            assert_eq!(found, expected);
        }
    }

    #[test]
    fn ray_walk_sees_every_box_the_ray_enters_and_nearest_first_prunes_to_the_brute_force_min() {
        let mut items = scattered(1000, 3);
        let mut tree = AabbTree::default();
        tree.build(&items);
        // Move every box and refit: the queries must see the new boxes.
        for (_, b) in &mut items {
            *b = b.transformed(&crate::geometry::Isometry::from_translation(Vec3::X));
        }
        assert!(tree.refit(&items));
        let mut stack = Vec::new();
        for (k, (_, start)) in scattered(100, 4).into_iter().enumerate() {
            let origin = start.center() * 1.5;
            let direction = (-origin + Vec3::new(k as f32 * 0.1, 1.0, -0.5)).normalize();
            let ray = RaySegment::new(origin, direction);
            let entries: Vec<(u32, f32)> = items
                .iter()
                .filter_map(|(id, b)| ray.entry(b, 40.0).map(|t| (*id, t)))
                .collect();
            let mut all = Vec::new();
            tree.along_ray(&ray, 0.0, 40.0, &mut stack, |id, t| {
                all.push((id, t));
                None
            });
            all.sort_by_key(|a| a.0);
            let mut expected = entries.clone();
            expected.sort_by_key(|a| a.0);
            assert_eq!(all, expected);
            // First hit = the box entered first (each box "hit" at its entry).
            let mut best = f32::INFINITY;
            tree.along_ray(&ray, 0.0, 40.0, &mut stack, |_, t| {
                best = best.min(t);
                Some(t)
            });
            let nearest = entries.iter().map(|e| e.1).fold(f32::INFINITY, f32::min);
            assert_eq!(best, nearest);
        }
    }

    #[test]
    fn refit_refuses_other_ids_and_an_axis_parallel_ray_on_a_face_still_enters() {
        let items = scattered(50, 5);
        let mut tree = AabbTree::default();
        tree.build(&items);
        let mut other = items.clone();
        other[3].0 += 1;
        assert!(!tree.refit(&other));
        let b = Aabb::from_center_half_extents(Vec3::ZERO, Vec3::ONE);
        // Origin on the y = 1 face plane, moving along x: inside the y slab.
        let ray = RaySegment::new(Vec3::new(-5.0, 1.0, 0.0), Vec3::X);
        assert_eq!(ray.entry(&b, 10.0), Some(4.0));
        let empty = AabbTree::default();
        let mut calls = 0;
        empty.along_ray(&ray, 0.0, 10.0, &mut Vec::new(), |_, _| {
            calls += 1;
            None
        });
        assert_eq!(calls, 0);
    }
}
