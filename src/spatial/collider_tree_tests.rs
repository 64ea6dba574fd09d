use super::*;
use crate::test_rng::TestRng;

/// A box of size 0.1 to 1.1 somewhere in a 20 m cube.
fn random_box(rng: &mut TestRng) -> Aabb {
    Aabb::from_center_half_extents(rng.vec3(-10.0, 10.0), rng.vec3(0.05, 0.55))
}

/// The ids (with repeats) of the items each query reaches, sorted, from the tree and by brute
/// force: overlaps with a box, entries of a ray (with their distances), boxes near a point.
fn assert_queries_match_brute_force(tree: &ColliderTree, items: &[(u32, Aabb)], rng: &mut TestRng) {
    let (mut nodes, mut pairs) = (Vec::new(), Vec::new());
    for _ in 0..20 {
        let query = random_box(rng).expanded(1.0);
        let mut found = Vec::new();
        tree.overlapping(&query, &mut nodes, |id| found.push(id));
        let expected = items.iter().filter(|(_, b)| b.intersects(&query));
        assert_same(found, expected.map(|&(id, _)| id).collect());

        let origin = rng.vec3(-15.0, 15.0);
        let ray = RaySegment::new(origin, rng.vec3(-10.0, 10.0) - origin);
        let mut entered = Vec::new();
        tree.along_ray(&ray, 0.0, 1.0, &mut pairs, |id, t| {
            entered.push((id, t));
            None
        });
        let expected: Vec<_> = items
            .iter()
            .filter_map(|&(id, b)| ray.entry(&b, 1.0).map(|t| (id, t)))
            .collect();
        let key =
            |v: &mut Vec<(u32, f32)>| v.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let (mut entered, mut expected) = (entered, expected);
        key(&mut entered);
        key(&mut expected);
        assert_eq!(entered, expected);

        let p = rng.vec3(-12.0, 12.0);
        let mut near = Vec::new();
        tree.near_point(p, 4.0, &mut pairs, |id, _| {
            near.push(id);
            None
        });
        let expected = items.iter().filter(|(_, b)| {
            let b = crate::bounding::WideBox::from(*b);
            b.distance_squared(p.into()) <= 4.0
        });
        assert_same(near, expected.map(|&(id, _)| id).collect());
    }
}

/// `n` random boxes with ids `0..n`, and a tree updated with them.
fn indexed(n: u32, rng: &mut TestRng) -> (Vec<(u32, Aabb)>, ColliderTree) {
    let items: Vec<(u32, Aabb)> = (0..n).map(|i| (i, random_box(rng))).collect();
    let mut tree = ColliderTree::default();
    assert_eq!(tree.update(&items), IndexUpdate::Rebuilt);
    (items, tree)
}

fn assert_same(mut found: Vec<u32>, mut expected: Vec<u32>) {
    found.sort_unstable();
    expected.sort_unstable();
    assert_eq!(found, expected);
}

#[test]
fn churn_of_up_to_12_ids_a_round_keeps_every_query_equal_to_brute_force_over_80_rounds() {
    let mut rng = TestRng::new(11);
    let mut items: Vec<(u32, Aabb)> = (0..600).map(|i| (i, random_box(&mut rng))).collect();
    let mut next_id = 600;
    let mut free = Vec::new();
    let mut tree = ColliderTree::default();
    let mut kinds = Vec::new();
    for _ in 0..80 {
        // Remove some (swap-removing, as an ECS table does), add some (reusing freed ids
        // first, as the ECS's stable ids do), move all.
        for _ in 0..rng.below(7) {
            let at = rng.below(items.len() as u32) as usize;
            free.push(items.swap_remove(at).0);
        }
        for _ in 0..rng.below(7) {
            let id = free.pop().unwrap_or_else(|| {
                next_id += 1;
                next_id
            });
            items.push((id, random_box(&mut rng)));
        }
        for (_, b) in &mut items {
            *b = Aabb::from_center_half_extents(b.center() + rng.vec3(-0.2, 0.2), b.half_extents());
        }
        kinds.push(tree.update(&items));
        assert_eq!(tree.len(), items.len());
        assert_queries_match_brute_force(&tree, &items, &mut rng);
        // The same ids again: a refit.
        assert_eq!(tree.update(&items), IndexUpdate::Refitted);
        assert_queries_match_brute_force(&tree, &items, &mut rng);
    }
    let rebuilds = kinds.iter().filter(|k| **k == IndexUpdate::Rebuilt).count();
    let updates = kinds.iter().filter(|k| **k == IndexUpdate::Updated).count();
    // The first update builds; ~6 changes a round pass the 16 + 2√600 ≈ 64 recent ones or
    // the quarter retired every ten rounds or so.
    assert!((2..=12).contains(&rebuilds), "{rebuilds} rebuilds");
    assert!(updates >= 60, "{updates} incremental updates");
}

#[test]
fn one_collider_added_a_round_to_1000_rebuilds_at_most_3_times_in_150_rounds() {
    let mut rng = TestRng::new(12);
    let (mut items, mut tree) = indexed(1000, &mut rng);
    let mut rebuilds = 0;
    for round in 0..150 {
        items.push((1000 + round, random_box(&mut rng)));
        match tree.update(&items) {
            IndexUpdate::Rebuilt => rebuilds += 1,
            IndexUpdate::Updated => assert!(tree.pending().0 > 0),
            IndexUpdate::Refitted => panic!("new ids refitted"),
        }
    }
    assert!(rebuilds <= 3, "{rebuilds} rebuilds");
    assert_queries_match_brute_force(&tree, &items, &mut rng);
}

#[test]
fn duplicate_sparse_and_extreme_ids_are_each_reported_once_per_item() {
    let mut rng = TestRng::new(13);
    // Ids 0 to 9 twice.
    let mut items: Vec<(u32, Aabb)> = (0..200).map(|i| (i % 190, random_box(&mut rng))).collect();
    let mut tree = ColliderTree::default();
    tree.update(&items);
    assert_queries_match_brute_force(&tree, &items, &mut rng);
    // A changed order with duplicates: incremental, every item still once.
    items.swap(3, 170);
    items.push((7, random_box(&mut rng)));
    assert_eq!(tree.update(&items), IndexUpdate::Updated);
    assert_queries_match_brute_force(&tree, &items, &mut rng);
    // The retired marker and other huge ids are ordinary ids (the sparse ones rebuild).
    items.push((u32::MAX, random_box(&mut rng)));
    items.push((u32::MAX - 1, random_box(&mut rng)));
    assert_eq!(tree.update(&items), IndexUpdate::Rebuilt);
    assert_queries_match_brute_force(&tree, &items, &mut rng);
    items.remove(0);
    tree.update(&items);
    assert_queries_match_brute_force(&tree, &items, &mut rng);
    // Emptied, then one item, then another: nothing to keep, then the one kept.
    assert_eq!(tree.update(&[]), IndexUpdate::Rebuilt);
    assert!(tree.is_empty() && tree.bounds() == Aabb::EMPTY);
    let mut few = vec![(5, random_box(&mut rng))];
    assert_eq!(tree.update(&few), IndexUpdate::Rebuilt);
    few.insert(0, (9, random_box(&mut rng)));
    assert_eq!(tree.update(&few), IndexUpdate::Updated);
    assert_queries_match_brute_force(&tree, &few, &mut rng);
}

#[test]
fn a_first_hit_walk_prunes_across_both_trees_to_the_nearest_entry() {
    let mut rng = TestRng::new(14);
    let (mut items, mut tree) = indexed(500, &mut rng);
    items.extend((500..520).map(|i| (i, random_box(&mut rng))));
    assert_eq!(tree.update(&items), IndexUpdate::Updated);
    assert_eq!(tree.pending(), (20, 0));
    let mut stack = Vec::new();
    for _ in 0..100 {
        let origin = rng.vec3(-15.0, 15.0);
        let ray = RaySegment::new(origin, rng.vec3(-10.0, 10.0) - origin);
        let mut best = f32::INFINITY;
        tree.along_ray(&ray, 0.0, 1.0, &mut stack, |_, t| {
            assert!(t <= best, "a box entered beyond the nearest so far");
            best = best.min(t);
            Some(t)
        });
        let nearest = items
            .iter()
            .filter_map(|(_, b)| ray.entry(b, 1.0))
            .fold(f32::INFINITY, f32::min);
        assert_eq!(best, nearest);
    }
}

#[test]
fn boxes_scattered_anew_under_the_same_ids_rebuild_within_8_updates_and_keep_the_cost_under_1_5x() {
    let mut rng = TestRng::new(15);
    let (mut items, mut tree) = indexed(1000, &mut rng);
    let built = tree.main.relative_cost().unwrap();
    // Every box moves to a random place of the same cube: the refit tree's nodes span it all.
    for (_, b) in &mut items {
        *b = random_box(&mut rng);
    }
    let kinds: Vec<_> = (0..8).map(|_| tree.update(&items)).collect();
    assert!(kinds.contains(&IndexUpdate::Rebuilt), "{kinds:?}");
    assert!(tree.main.relative_cost().unwrap() < 1.5 * built);
    assert_queries_match_brute_force(&tree, &items, &mut rng);
    // Boxes that keep still never rebuild.
    let still: Vec<_> = (0..24).map(|_| tree.update(&items)).collect();
    assert!(still.iter().all(|k| *k == IndexUpdate::Refitted));
}

/// An update as `SpatialIndex::update` makes it: boxes streamed while the ids are the last
/// update's, then the list.
fn streamed(tree: &mut ColliderTree, items: &[(u32, Aabb)]) -> IndexUpdate {
    let mut at = 0;
    while at < items.len() && tree.stream_box(at, items[at].0, &items[at].1) {
        at += 1;
    }
    if at == items.len() && tree.finish_stream(at) {
        return IndexUpdate::Refitted;
    }
    let mut list = Vec::new();
    tree.last_items(at, &mut list);
    list.extend_from_slice(&items[at..]);
    assert_eq!(list, items);
    tree.update(&list)
}

#[test]
fn streamed_updates_refit_keep_and_rebuild_as_listed_ones_and_a_worn_stream_rebuilds_within_8() {
    let mut rng = TestRng::new(16);
    let mut items: Vec<(u32, Aabb)> = (0..800).map(|i| (i, random_box(&mut rng))).collect();
    let (mut tree, mut listed) = (ColliderTree::default(), ColliderTree::default());
    for round in 0..40 {
        if round % 3 == 1 {
            let at = rng.below(items.len() as u32) as usize;
            items.swap_remove(at);
            items.push((900 + round, random_box(&mut rng)));
        }
        for (_, b) in &mut items {
            *b = Aabb::from_center_half_extents(b.center() + rng.vec3(-0.1, 0.1), b.half_extents());
        }
        assert_eq!(streamed(&mut tree, &items), listed.update(&items));
        assert_queries_match_brute_force(&tree, &items, &mut rng);
    }
    for (_, b) in &mut items {
        *b = random_box(&mut rng);
    }
    let kinds: Vec<_> = (0..8).map(|_| streamed(&mut tree, &items)).collect();
    assert!(kinds.contains(&IndexUpdate::Rebuilt), "{kinds:?}");
    assert_queries_match_brute_force(&tree, &items, &mut rng);
}
