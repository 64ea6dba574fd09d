//! Tests of [`GridQueryCache`]: its answers are [`StaticGrid::query`]'s, whatever the motion of
//! the queried boxes and the edits of the grid between rounds; it reuses a list only when it may.

use super::*;
use crate::broad_phase::grid::StaticGridConfig;
use crate::test_rng::TestRng;
use glam::Vec3;

fn cubes(size: f32) -> StaticGrid {
    StaticGrid::new(StaticGridConfig::with_cell_size(size)).unwrap()
}

fn boxed(min: Vec3, size: Vec3) -> Aabb {
    Aabb::new(min, min + size)
}

/// A grid of 1 m cells holding one static, and an empty cache.
fn one_static(id: u32, aabb: Aabb) -> (StaticGrid, GridQueryCache) {
    let mut grid = cubes(1.0);
    grid.insert(id, aabb).unwrap();
    (grid, GridQueryCache::default())
}

fn direct(grid: &mut StaticGrid, aabb: &Aabb) -> Vec<u32> {
    let mut out = Vec::new();
    grid.query(aabb, &mut out).unwrap();
    out
}

fn cached(cache: &mut GridQueryCache, grid: &mut StaticGrid, key: u32, aabb: &Aabb) -> Vec<u32> {
    let mut out = Vec::new();
    cache.query(grid, key, aabb, &mut out).unwrap();
    out
}

/// A grid of small statics over a 40 m cube, a few of them oversize.
fn scenery(rng: &mut TestRng, count: u32) -> StaticGrid {
    let mut grid = cubes(2.0);
    for id in 0..count {
        let size = if id % 17 == 0 {
            Vec3::splat(60.0)
        } else {
            rng.vec3(0.1, 3.0)
        };
        grid.insert(id * 3, boxed(rng.vec3(-20.0, 20.0), size))
            .unwrap();
    }
    grid
}

/// One random edit: a new static, a moved one or a removed one.
fn edit(grid: &mut StaticGrid, rng: &mut TestRng, next_id: &mut u32) {
    let live: Vec<u32> = (0..*next_id).filter(|&id| grid.contains(id)).collect();
    let pick = live[rng.below(live.len() as u32) as usize];
    match rng.below(3) {
        0 => {
            grid.insert(*next_id, boxed(rng.vec3(-20.0, 20.0), rng.vec3(0.1, 3.0)))
                .unwrap();
            *next_id += 1;
        }
        1 => grid
            .update(pick, boxed(rng.vec3(-20.0, 20.0), rng.vec3(0.1, 3.0)))
            .unwrap(),
        _ => {
            grid.remove(pick).unwrap();
        }
    }
}

#[test]
fn answers_equal_direct_queries_over_300_rounds_of_motion_and_edits() {
    let mut rng = TestRng::new(11);
    let mut grid = scenery(&mut rng, 400);
    let mut next_id = 400 * 3;
    let mut cache = GridQueryCache::default();
    let mut boxes: Vec<Aabb> = (0..60)
        .map(|_| boxed(rng.vec3(-25.0, 25.0), rng.vec3(0.2, 4.0)))
        .collect();
    let (mut reused, mut queries) = (0, 0);
    for round in 0..300 {
        if round % 7 == 3 {
            edit(&mut grid, &mut rng, &mut next_id);
        }
        cache.begin_round();
        for (key, aabb) in boxes.iter_mut().enumerate() {
            // Most bodies jitter, some drift, a few jump; every third sits out a round now and
            // then (asleep), and some are asked twice in a round.
            let step = match rng.below(10) {
                0 => rng.vec3(-8.0, 8.0),
                1..=3 => rng.vec3(-0.5, 0.5),
                _ => rng.vec3(-0.01, 0.01),
            };
            *aabb = Aabb::new(aabb.min + step, aabb.max + step);
            if key % 3 == 0 && rng.below(4) == 0 {
                continue;
            }
            let asks = 1 + u32::from(rng.below(8) == 0);
            for _ in 0..asks {
                let mut out = Vec::new();
                let stats = cache.query(&mut grid, key as u32, aabb, &mut out).unwrap();
                assert_eq!(out, direct(&mut grid, aabb), "round {round}, key {key}");
                reused += stats.reused_queries;
                queries += 1;
            }
        }
    }
    // Most bodies barely move: most answers must come from kept lists.
    assert!(reused * 2 > queries, "{reused} of {queries} reused");
    // Two rounds of lists at most, not 300: a few hundred bytes per key.
    let bytes = cache.memory_bytes();
    assert!(bytes > 0 && bytes < 64 * 1024, "{bytes} bytes");
}

#[test]
fn a_box_inside_its_fattened_box_visits_no_cell() {
    let (mut grid, mut cache) = one_static(7, boxed(Vec3::ZERO, Vec3::ONE));
    let body = boxed(Vec3::new(0.5, 0.0, 0.9), Vec3::ONE);
    cache.begin_round();
    let first = {
        let mut out = Vec::new();
        let stats = cache.query(&mut grid, 0, &body, &mut out).unwrap();
        assert_eq!(out, vec![7]);
        stats
    };
    assert_eq!(first.reused_queries, 0);
    // The grid read cells (or, holding one object, scanned it).
    assert!(first.cells_visited + first.object_scans > 0);
    cache.begin_round();
    // Moved by less than a quarter of its size: still inside, and off the static now.
    let moved = boxed(Vec3::new(0.5, 0.0, 1.1), Vec3::ONE);
    let mut out = Vec::new();
    let stats = cache.query(&mut grid, 0, &moved, &mut out).unwrap();
    assert_eq!(
        (
            stats.reused_queries,
            stats.cells_visited,
            stats.object_scans
        ),
        (1, 0, 0)
    );
    assert!(out.is_empty());
}

#[test]
fn a_static_moved_into_a_kept_box_is_found_in_the_next_round() {
    let (mut grid, mut cache) = one_static(1, boxed(Vec3::splat(10.0), Vec3::ONE));
    let body = boxed(Vec3::ZERO, Vec3::ONE);
    cache.begin_round();
    assert!(cached(&mut cache, &mut grid, 4, &body).is_empty());
    grid.update(1, boxed(Vec3::splat(0.5), Vec3::ONE)).unwrap();
    cache.begin_round();
    assert_eq!(cached(&mut cache, &mut grid, 4, &body), vec![1]);
    grid.remove(1).unwrap();
    cache.begin_round();
    assert!(cached(&mut cache, &mut grid, 4, &body).is_empty());
}

#[test]
fn a_key_left_out_of_one_round_queries_the_grid_again() {
    let (mut grid, mut cache) = one_static(2, boxed(Vec3::ZERO, Vec3::ONE));
    let body = boxed(Vec3::splat(0.5), Vec3::ONE);
    cache.begin_round();
    assert_eq!(cached(&mut cache, &mut grid, 9, &body), vec![2]);
    cache.begin_round();
    // Another key fills this round's buffer where key 9's list was.
    assert!(
        cached(
            &mut cache,
            &mut grid,
            3,
            &boxed(Vec3::splat(5.0), Vec3::ONE)
        )
        .is_empty()
    );
    cache.begin_round();
    let mut out = Vec::new();
    let stats = cache.query(&mut grid, 9, &body, &mut out).unwrap();
    assert_eq!((out, stats.reused_queries), (vec![2], 0));
}

#[test]
fn another_grid_with_the_same_objects_is_not_mistaken_for_the_first() {
    let mut first = cubes(1.0);
    first.insert(1, boxed(Vec3::ZERO, Vec3::ONE)).unwrap();
    let mut second = cubes(1.0);
    second
        .insert(1, boxed(Vec3::splat(20.0), Vec3::ONE))
        .unwrap();
    second.insert(5, boxed(Vec3::ZERO, Vec3::ONE)).unwrap();
    let mut cache = GridQueryCache::default();
    let body = boxed(Vec3::splat(0.2), Vec3::ONE);
    cache.begin_round();
    assert_eq!(cached(&mut cache, &mut first, 0, &body), vec![1]);
    cache.begin_round();
    assert_eq!(cached(&mut cache, &mut second, 0, &body), vec![5]);
}

#[test]
fn bad_boxes_are_refused_and_leave_the_output_untouched() {
    let (mut grid, mut cache) = one_static(1, boxed(Vec3::ZERO, Vec3::ONE));
    cache.begin_round();
    let mut out = vec![42];
    let nan = Aabb::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ONE);
    assert_eq!(
        cache.query(&mut grid, 0, &nan, &mut out),
        Err(GridError::NonFiniteAabb { id: None })
    );
    let inverted = Aabb::new(Vec3::ONE, Vec3::ZERO);
    assert_eq!(
        cache.query(&mut grid, 0, &inverted, &mut out),
        Err(GridError::InvertedAabb { id: None })
    );
    assert_eq!(out, vec![42]);
}

#[test]
fn boxes_near_the_float_range_are_answered_exactly() {
    let mut grid = cubes(1.0);
    grid.insert(1, boxed(Vec3::ZERO, Vec3::ONE)).unwrap();
    grid.insert(2, Aabb::new(Vec3::splat(-3e38), Vec3::splat(3e38)))
        .unwrap();
    let mut cache = GridQueryCache::default();
    let huge = Aabb::new(Vec3::splat(-3e38), Vec3::splat(3e38));
    for _ in 0..3 {
        cache.begin_round();
        assert_eq!(cached(&mut cache, &mut grid, 0, &huge), vec![1, 2]);
        let far = boxed(Vec3::splat(1e30), Vec3::splat(1e29));
        assert_eq!(cached(&mut cache, &mut grid, 1, &far), vec![2]);
    }
}

#[test]
fn a_key_beyond_the_proxy_bound_is_answered_without_a_list_of_4_billion_entries() {
    let (mut grid, mut cache) = one_static(3, boxed(Vec3::ZERO, Vec3::ONE));
    let body = boxed(Vec3::splat(0.5), Vec3::ONE);
    for _ in 0..2 {
        cache.begin_round();
        let mut out = Vec::new();
        let stats = cache.query(&mut grid, u32::MAX, &body, &mut out).unwrap();
        assert_eq!((out, stats.reused_queries), (vec![3], 0));
    }
    assert!(cache.memory_bytes() < 1024);
}

#[test]
fn a_grid_edited_without_a_new_round_is_answered_afresh() {
    let (mut grid, mut cache) = one_static(1, boxed(Vec3::splat(10.0), Vec3::ONE));
    let body = boxed(Vec3::ZERO, Vec3::ONE);
    cache.begin_round();
    assert!(cached(&mut cache, &mut grid, 0, &body).is_empty());
    // The static moves under the body within the round: the kept list must not answer.
    grid.update(1, boxed(Vec3::splat(0.5), Vec3::ONE)).unwrap();
    assert_eq!(cached(&mut cache, &mut grid, 0, &body), vec![1]);
    // And a query before any round is answered too.
    let mut fresh = GridQueryCache::default();
    assert_eq!(cached(&mut fresh, &mut grid, 0, &body), vec![1]);
}
