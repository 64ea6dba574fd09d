//! A bounding-volume tree over colliders' boxes, for queries (rapier's query pipeline, Avian's
//! collider trees): a ray visits the boxes it enters nearest first and stops once the nearest
//! hit is closer than the next box; a volume visits the boxes it overlaps.
//!
//! Built top-down by binned surface-area splits along the longest axis of the boxes' centres
//! (Wald 2007; a median split where the centres do not spread), stored in a flat array whose children follow their parent, so a
//! refit (the same colliders, new boxes) is one backward pass in `O(n)`: the query index of a
//! scene whose bodies only moved is refitted every step; how it follows colliders that come
//! and go is [`ColliderTree`](super::ColliderTree)'s.

use crate::bounding::{Aabb, WideBox};
use glam::{Vec3, Vec3A};

/// Most items in a leaf.
const LEAF_SIZE: usize = 4;

/// The id of a retired item (see [`AabbTree::retire`]).
pub(crate) const RETIRED: u32 = u32::MAX;

/// A node: a leaf holds `count > 0` items from `first`; an inner node's children are
/// `first` and `first + 1`.
#[derive(Clone, Copy, Debug)]
struct Node {
    aabb: WideBox,
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
    boxes: Vec<WideBox>,
    /// Where each input item went in the leaf order (for refits).
    slot_of_input: Vec<u32>,
}

/// A ray against boxes: `origin + t·direction`, `t` in `[0, max]`.
#[derive(Clone, Copy, Debug)]
pub struct RaySegment {
    origin: Vec3A,
    inverse_direction: Vec3A,
}

impl RaySegment {
    /// The ray from `origin` along `direction` (need not be unit; `t` is in its lengths).
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        // An axis the ray does not move along gets the largest finite inverse instead of
        // infinity: `0 · ∞` (an origin on a slab's face) would be NaN, while `0 · MAX` is 0, so
        // the slab test below needs no special case: it holds the ray inside a slab it starts
        // strictly in and outside one it starts beyond, and one starting on a face is leaving
        // (callers grow the boxes by their tolerance, which puts it strictly inside).
        let inverse = direction.recip();
        let finite = |x: f32| {
            if x.is_finite() {
                x
            } else {
                f32::MAX.copysign(x)
            }
        };
        Self {
            origin: origin.into(),
            inverse_direction: Vec3A::new(finite(inverse.x), finite(inverse.y), finite(inverse.z)),
        }
    }

    /// Where the ray enters `aabb` if it does within `[0, max]` (the slab test, Kay and Kajiya
    /// 1986: the latest entry into the three slabs against the earliest exit).
    pub fn entry(&self, aabb: &Aabb, max: f32) -> Option<f32> {
        let t = self.enter(&WideBox::from(*aabb), Vec3A::ZERO, max);
        (t <= max).then_some(t)
    }

    /// [`Self::entry`] of `b` grown by `grow` on every side, with `f32::INFINITY` for a miss
    /// (the traversal's inner loop: no option, no grown box built).
    #[inline(always)]
    fn enter(&self, b: &WideBox, grow: Vec3A, max: f32) -> f32 {
        let t1 = (b.min - grow - self.origin) * self.inverse_direction;
        let t2 = (b.max + grow - self.origin) * self.inverse_direction;
        let near = t1.min(t2).max_element().max(0.0);
        let far = t1.max(t2).min_element().min(max);
        if near <= far { near } else { f32::INFINITY }
    }
}

impl AabbTree {
    /// Rebuilds the tree over `items` (ids need not be distinct or dense).
    pub fn build(&mut self, items: &[(u32, Aabb)]) {
        self.nodes.clear();
        let mut order: Vec<u32> = (0..items.len() as u32).collect();
        if !items.is_empty() {
            self.nodes.push(Node {
                aabb: WideBox::EMPTY,
                first: 0,
                count: 0,
            });
            self.split(0, &mut order, 0, items);
        }
        self.ids = order.iter().map(|&i| items[i as usize].0).collect();
        self.boxes = order.iter().map(|&i| items[i as usize].1.into()).collect();
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
        let half = sah_partition(order, items).unwrap_or_else(|| median_partition(order, items));
        let children = self.nodes.len() as u32;
        self.nodes[node].first = children;
        let empty = Node {
            aabb: WideBox::EMPTY,
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
            self.boxes[slot as usize] = (*aabb).into();
        }
        self.refit_nodes();
        true
    }

    /// Recomputes every node's box, children before parents (children follow their parent).
    pub(crate) fn refit_nodes(&mut self) {
        for n in (0..self.nodes.len()).rev() {
            let Node { first, count, .. } = self.nodes[n];
            let (first, count) = (first as usize, count as usize);
            self.nodes[n].aabb = if count > 0 {
                self.boxes[first..first + count]
                    .iter()
                    .fold(WideBox::EMPTY, |a, b| a.union(b))
            } else {
                self.nodes[first].aabb.union(&self.nodes[first + 1].aabb)
            };
        }
    }

    /// The leaf slot the last build gave its `input`-th item.
    pub(crate) fn slot_of_input(&self, input: usize) -> usize {
        self.slot_of_input[input] as usize
    }

    /// A new box for the item in `slot` (the nodes are refitted by [`Self::refit_nodes`]).
    pub(crate) fn set_box(&mut self, slot: usize, aabb: &Aabb) {
        self.boxes[slot] = (*aabb).into();
    }

    /// The box of the item in `slot`.
    pub(crate) fn box_at(&self, slot: usize) -> Aabb {
        self.boxes[slot].into()
    }

    /// Takes the item in `slot` out: its id becomes [`RETIRED`] and its box empty, so no
    /// overlap query reaches it and the next refit leaves it out of its parents' boxes (a ray
    /// may still be handed it: callers skip the id).
    pub(crate) fn retire(&mut self, slot: usize) {
        self.ids[slot] = RETIRED;
        self.boxes[slot] = WideBox::EMPTY;
    }

    /// The surface area heuristic's cost of the tree relative to its root: the sum of the
    /// nodes' surface areas over the root's, the expected number of nodes a random ray through
    /// the root visits (MacDonald and Booth 1990). A refit tree whose boxes moved apart grows
    /// it; `None` for an empty tree or a root without a finite, positive area.
    pub fn relative_cost(&self) -> Option<f32> {
        let root = self.nodes.first()?.aabb.surface_area();
        let sum: f64 = self
            .nodes
            .iter()
            .map(|n| n.aabb.surface_area() as f64)
            .sum();
        let cost = (sum / root as f64) as f32;
        (root > 0.0 && cost.is_finite()).then_some(cost)
    }

    /// Number of items (retired ones included).
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// Whether the tree holds no item.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The box around every item (`Aabb::EMPTY` when empty).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.aabb.into())
    }

    /// Calls `visit(id)` for every item whose box overlaps `aabb`.
    pub fn overlapping(&self, aabb: &Aabb, stack: &mut Vec<u32>, mut visit: impl FnMut(u32)) {
        stack.clear();
        if !self.is_empty() {
            stack.push(0);
        }
        let query = WideBox::from(*aabb);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node.aabb.intersects(&query) {
                continue;
            }
            if node.count == 0 {
                stack.extend([node.first, node.first + 1]);
                continue;
            }
            let range = node.first as usize..(node.first + node.count) as usize;
            for (id, b) in self.ids[range.clone()].iter().zip(&self.boxes[range]) {
                if b.intersects(&query) {
                    visit(*id);
                }
            }
        }
    }

    /// Walks the items whose box, grown by `grow` (a cast sphere's radius plus the tolerance),
    /// `ray` enters before `max`, nearer boxes first. `visit(id, entry)` returns the new `max`
    /// (a hit at `t` makes farther boxes irrelevant) or `None` to keep it, so a first-hit query
    /// prunes as it goes and an all-hits query sees every box.
    pub fn along_ray(
        &self,
        ray: &RaySegment,
        grow: f32,
        mut max: f32,
        stack: &mut Vec<(u32, f32)>,
        mut visit: impl FnMut(u32, f32) -> Option<f32>,
    ) {
        stack.clear();
        let Some(root) = self.nodes.first() else {
            return;
        };
        let grow = Vec3A::splat(grow);
        let mut next = Some((0u32, ray.enter(&root.aabb, grow, max)));
        // Descend into the nearer child at once and keep the farther one for later, so a
        // first-hit query goes straight to the nearest leaf and prunes the rest by its hit.
        while let Some((n, entry)) = next.take().or_else(|| stack.pop()) {
            if entry > max {
                continue;
            }
            let node = &self.nodes[n as usize];
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for (id, b) in self.ids[range.clone()].iter().zip(&self.boxes[range]) {
                    let t = ray.enter(b, grow, max);
                    if t <= max
                        && let Some(new_max) = visit(*id, t)
                    {
                        max = max.min(new_max);
                    }
                }
                continue;
            }
            let (a, b) = (node.first, node.first + 1);
            let ta = ray.enter(&self.nodes[a as usize].aabb, grow, max);
            let tb = ray.enter(&self.nodes[b as usize].aabb, grow, max);
            let ((near, t_near), (far, t_far)) = if tb < ta {
                ((b, tb), (a, ta))
            } else {
                ((a, ta), (b, tb))
            };
            if t_far <= max {
                stack.push((far, t_far));
            }
            if t_near <= max {
                next = Some((near, t_near));
            }
        }
    }
}

impl AabbTree {
    /// Walks the items whose box lies within `sqrt(max2)` of `p`, nearer boxes first.
    /// `visit(id, box_distance²)` returns a new `max2` (an item found at that squared distance
    /// makes farther boxes irrelevant) or `None` to keep it: a nearest-point query prunes as it
    /// goes.
    pub fn near_point(
        &self,
        p: Vec3,
        mut max2: f32,
        stack: &mut Vec<(u32, f32)>,
        mut visit: impl FnMut(u32, f32) -> Option<f32>,
    ) {
        stack.clear();
        let Some(root) = self.nodes.first() else {
            return;
        };
        let p = Vec3A::from(p);
        let mut next = Some((0u32, root.aabb.distance_squared(p)));
        while let Some((n, d2)) = next.take().or_else(|| stack.pop()) {
            if d2 > max2 {
                continue;
            }
            let node = &self.nodes[n as usize];
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for (id, b) in self.ids[range.clone()].iter().zip(&self.boxes[range]) {
                    let d2 = b.distance_squared(p);
                    if d2 <= max2
                        && let Some(new_max2) = visit(*id, d2)
                    {
                        max2 = max2.min(new_max2);
                    }
                }
                continue;
            }
            let (a, b) = (node.first, node.first + 1);
            let da = self.nodes[a as usize].aabb.distance_squared(p);
            let db = self.nodes[b as usize].aabb.distance_squared(p);
            let ((near, d_near), (far, d_far)) = if db < da {
                ((b, db), (a, da))
            } else {
                ((a, da), (b, db))
            };
            if d_far <= max2 {
                stack.push((far, d_far));
            }
            if d_near <= max2 {
                next = Some((near, d_near));
            }
        }
    }
}

/// Bins of the surface-area split.
const SAH_BINS: usize = 12;

/// Splits `order` in two halves by the median centre along the longest axis of the centres;
/// returns the size of the first half.
fn median_partition(order: &mut [u32], items: &[(u32, Aabb)]) -> usize {
    let centre = |i: &u32| items[*i as usize].1.center();
    let bounds = Aabb::from_points(order.iter().map(centre));
    let axis = bounds.longest_axis();
    let half = order.len() / 2;
    order.select_nth_unstable_by(half, |a, b| centre(a)[axis].total_cmp(&centre(b)[axis]));
    half
}

/// Splits `order` where the surface area heuristic (MacDonald and Booth 1990; binned, Wald
/// 2007) puts it: of the [`SAH_BINS`] − 1 bin boundaries along the longest axis of the
/// centres' box, the one minimising `area(left)·count(left) + area(right)·count(right)`, the
/// expected cost of a ray that reaches the node. Returns the size of the first part, or `None`
/// when the centres do not spread along that axis.
fn sah_partition(order: &mut [u32], items: &[(u32, Aabb)]) -> Option<usize> {
    let centre = |i: u32| items[i as usize].1.center();
    let bounds = Aabb::from_points(order.iter().map(|&i| centre(i)));
    // The longest axis only: binning all three made the tree 5 % faster to cast rays through
    // and 70 % slower to build (10,000 colliders, benches/spatial_queries.rs).
    let axis = bounds.longest_axis();
    let (_, boundary) = best_boundary(order, items, &bounds, axis)?;
    let bin_of = binner(&bounds, axis);
    // Two-pointer partition: the items of bins below the boundary first.
    let (mut front, mut back) = (0, order.len());
    while front < back {
        if bin_of(centre(order[front])) < boundary {
            front += 1;
        } else {
            back -= 1;
            order.swap(front, back);
        }
    }
    Some(front)
}

/// The bin of a centre along `axis` of the centres' box `bounds`.
fn binner(bounds: &Aabb, axis: usize) -> impl Fn(Vec3) -> usize {
    let (low, extent) = (bounds.min[axis], bounds.max[axis] - bounds.min[axis]);
    let scale = SAH_BINS as f32 / extent;
    move |c: Vec3| (((c[axis] - low) * scale) as usize).min(SAH_BINS - 1)
}

/// The cheapest bin boundary along `axis` and its cost, `None` if the centres do not spread
/// along it or every boundary leaves one side empty.
fn best_boundary(
    order: &[u32],
    items: &[(u32, Aabb)],
    bounds: &Aabb,
    axis: usize,
) -> Option<(f32, usize)> {
    let extent = bounds.max[axis] - bounds.min[axis];
    if !(extent > 0.0 && extent.is_finite()) {
        return None;
    }
    let bin_of = binner(bounds, axis);
    let mut boxes = [Aabb::EMPTY; SAH_BINS];
    let mut counts = [0usize; SAH_BINS];
    for &i in order {
        let b = bin_of(items[i as usize].1.center());
        boxes[b] = boxes[b].union(&items[i as usize].1);
        counts[b] += 1;
    }
    // Right-hand sums from the last bin down, then the left-hand sweep picks the boundary.
    let mut right_cost = [0.0f32; SAH_BINS];
    let (mut right_box, mut right_count) = (Aabb::EMPTY, 0);
    for b in (1..SAH_BINS).rev() {
        right_box = right_box.union(&boxes[b]);
        right_count += counts[b];
        right_cost[b] = right_box.surface_area() * right_count as f32;
    }
    let (mut left_box, mut left_count) = (Aabb::EMPTY, 0);
    let mut best: Option<(f32, usize)> = None;
    for b in 1..SAH_BINS {
        left_box = left_box.union(&boxes[b - 1]);
        left_count += counts[b - 1];
        if left_count == 0 || left_count == order.len() {
            continue;
        }
        let cost = left_box.surface_area() * left_count as f32 + right_cost[b];
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, b));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` boxes of sizes 0.1 to 1.1 scattered in a 20 m cube (a small LCG, fixed seed).
    fn scattered(n: usize, seed: u64) -> Vec<(u32, Aabb)> {
        let mut rng = crate::test_rng::TestRng::new(seed);
        (0..n)
            .map(|i| {
                let c = rng.vec3(-10.0, 10.0);
                let h = rng.vec3(0.05, 0.55);
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
        // Origin on the y = 1 face plane, moving along x: it counts as a ray leaving the slab
        // at once, so callers grow the boxes by their tolerance; grown, the box is entered.
        let ray = RaySegment::new(Vec3::new(-5.0, 1.0, 0.0), Vec3::X);
        assert_eq!(ray.entry(&b, 10.0), None);
        let t = ray.entry(&b.expanded(1e-6), 10.0).unwrap();
        assert!((t - 4.0).abs() < 1e-5);
        // Outside the slab and parallel to it: never.
        let beside = RaySegment::new(Vec3::new(-5.0, 1.5, 0.0), Vec3::X);
        assert_eq!(beside.entry(&b.expanded(1e-6), 10.0), None);
        let empty = AabbTree::default();
        let mut calls = 0;
        empty.along_ray(&ray, 0.0, 10.0, &mut Vec::new(), |_, _| {
            calls += 1;
            None
        });
        assert_eq!(calls, 0);
    }
}
