//! The static grid against brute force: for random static scenes and random moving query
//! boxes, a grid query must return exactly the objects a scan over every object finds
//! (closed boxes, ascending ids), through insertions, removals, updates and re-insertions.
//!
//! Coordinates are multiples of 1/4 around an origin that may be negative or far away (1e5,
//! 1e6, where f32 still holds quarters exactly; 3e9, where cell coordinates saturate), so boxes
//! touching exactly, and faces lying on cell boundaries, are common rather than measure-zero
//! accidents.

use glam::Vec3;
use proptest::prelude::*;
use std::collections::BTreeMap;
use urto::bounding::Aabb;
use urto::broad_phase::grid::{GridError, StaticGrid, StaticGridConfig, suggest_cell_size};

/// Where a scene sits: at the origin, on negative coordinates, or far from the origin.
fn origin() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        Just(Vec3::ZERO),
        Just(Vec3::new(-37.0, -1000.0, -12.5)),
        Just(Vec3::new(1.0e5, -1.0e5, 250.0)),
        Just(Vec3::new(-1.0e6, 1.0e6, -1.0e6)),
        // Beyond the i32 cell range for small cells: coordinates saturate (and f32 rounds the
        // quarter lattice to multiples of 256, so many boxes collapse to points).
        Just(Vec3::new(3.0e9, -3.0e9, 0.0)),
    ]
}

/// A box on the quarter lattice: mostly small, sometimes spanning many cells, sometimes flat
/// or a point.
fn lattice_box(origin: Vec3) -> impl Strategy<Value = Aabb> {
    let extent = prop_oneof![
        6 => 0i32..8,
        2 => 0i32..1,
        1 => 0i32..400,
    ];
    (
        [-120i32..120, -120i32..120, -40i32..40],
        [extent.clone(), extent.clone(), extent],
    )
        .prop_map(move |(corner, size)| {
            let min =
                origin + Vec3::new(corner[0] as f32, corner[1] as f32, corner[2] as f32) * 0.25;
            let extent = Vec3::new(size[0] as f32, size[1] as f32, size[2] as f32) * 0.25;
            Aabb::new(min, min + extent)
        })
}

/// A grid layout: automatic or explicit cells (dyadic and not), and a cell budget that sends
/// some objects to the oversize list.
fn config() -> impl Strategy<Value = StaticGridConfig> {
    let cell = prop_oneof![
        Just(None),
        Just(Some(Vec3::splat(0.25))),
        Just(Some(Vec3::splat(1.0))),
        Just(Some(Vec3::new(1.3, 0.7, 3.0))),
        Just(Some(Vec3::splat(10.0))),
    ];
    let budget = prop_oneof![Just(0u32), Just(8), Just(64), Just(1000)];
    (cell, budget).prop_map(|(cell_size, max_cells_per_object)| StaticGridConfig {
        cell_size,
        max_cells_per_object,
    })
}

/// A static scene: distinct ids (sparse, not 0..n) and boxes around one origin.
fn scene() -> impl Strategy<Value = (Vec3, Vec<(u32, Aabb)>)> {
    origin().prop_flat_map(|origin| {
        let objects = prop::collection::vec(lattice_box(origin), 0..60).prop_map(|boxes| {
            boxes
                .into_iter()
                .enumerate()
                .map(|(i, aabb)| ((i as u32).wrapping_mul(2_654_435_761), aabb))
                .collect::<Vec<_>>()
        });
        (Just(origin), objects)
    })
}

/// A moving query: a start box and a per-step displacement on the quarter lattice.
fn moving_query(origin: Vec3) -> impl Strategy<Value = (Aabb, Vec3)> {
    (lattice_box(origin), [-8i32..8, -8i32..8, -8i32..8]).prop_map(|(start, v)| {
        (
            start,
            Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32) * 0.25,
        )
    })
}

fn brute_force(model: &BTreeMap<u32, Aabb>, query: &Aabb) -> Vec<u32> {
    model
        .iter()
        .filter(|(_, aabb)| aabb.intersects(query))
        .map(|(&id, _)| id)
        .collect()
}

/// Asserts the grid answers `query` as brute force does, and its candidates are the objects
/// sharing a cell with the query plus the oversize ones.
fn assert_query_matches(grid: &mut StaticGrid, model: &BTreeMap<u32, Aabb>, query: &Aabb) {
    let mut found = Vec::new();
    let stats = grid.query(query, &mut found).unwrap();
    assert_eq!(found, brute_force(model, query), "query {query:?}");
    assert!(stats.exact_tests <= model.len());

    let mut candidates = Vec::new();
    grid.query_candidates(query, &mut candidates).unwrap();
    let query_cells = grid.cells_touching(query).unwrap();
    let expected: Vec<u32> = model
        .iter()
        .filter(|(id, aabb)| {
            grid.is_oversize(**id).unwrap()
                || grid.cells_touching(aabb).unwrap().overlaps(&query_cells)
        })
        .map(|(&id, _)| id)
        .collect();
    assert_eq!(candidates, expected, "candidates of {query:?}");
    assert!(found.iter().all(|id| candidates.binary_search(id).is_ok()));
}

proptest! {
    #[test]
    fn queries_of_a_built_grid_equal_brute_force(
        (objects, walks) in scene().prop_flat_map(|(origin, objects)| {
            (Just(objects), prop::collection::vec(moving_query(origin), 1..4))
        }),
        config in config(),
    ) {
        let mut grid = StaticGrid::build_with(&objects, config).unwrap();
        let model: BTreeMap<u32, Aabb> = objects.iter().copied().collect();
        prop_assert_eq!(grid.len(), model.len());
        // Every object's own box (it must find itself), then boxes wandering through the scene.
        for aabb in model.values() {
            assert_query_matches(&mut grid, &model, aabb);
        }
        for (start, step) in walks {
            for k in 0..12 {
                let shift = step * k as f32;
                assert_query_matches(&mut grid, &model, &Aabb::new(start.min + shift, start.max + shift));
            }
        }
    }

    #[test]
    fn moving_queries_equal_brute_force(
        (origin, objects) in scene(),
        config in config(),
        moves in prop::collection::vec(any::<(u8, i8, i8, i8)>(), 1..6),
        extra in prop::collection::vec(lattice_box(Vec3::ZERO), 1..6),
    ) {
        let mut grid = StaticGrid::build_with(&objects, config).unwrap();
        let model: BTreeMap<u32, Aabb> = objects.iter().copied().collect();
        for ((size, dx, dy, dz), shape) in moves.iter().zip(extra.iter().cycle()) {
            // Start at an object (or the origin) and walk in quarter steps.
            let start = objects.get(*size as usize % objects.len().max(1)).map_or(origin, |o| o.1.min);
            let extent = shape.extents();
            let step = Vec3::new(f32::from(*dx), f32::from(*dy), f32::from(*dz)) * 0.25;
            for k in 0..16 {
                let min = start + step * k as f32;
                assert_query_matches(&mut grid, &model, &Aabb::new(min, min + extent));
            }
        }
    }

    #[test]
    fn edits_keep_the_grid_equal_to_brute_force(
        (origin, objects) in scene(),
        config in config(),
        edits in prop::collection::vec((0u8..4, 0u32..24, any::<prop::sample::Index>()), 1..60),
        boxes in prop::collection::vec(lattice_box(Vec3::ZERO), 8),
    ) {
        let mut grid = StaticGrid::new(config).unwrap();
        let mut model = BTreeMap::new();
        // Ids from a small range, so that duplicates, unknown ids and re-insertions happen.
        let objects: Vec<(u32, Aabb)> = objects.into_iter().take(24).enumerate()
            .map(|(i, (_, aabb))| (i as u32, aabb)).collect();
        for (kind, id, pick) in edits {
            let aabb = {
                let b = boxes[pick.index(boxes.len())];
                Aabb::new(b.min + origin, b.max + origin)
            };
            let aabb = objects.get(id as usize).filter(|_| pick.index(2) == 0).map_or(aabb, |o| o.1);
            match kind {
                0 => {
                    let expected = if model.contains_key(&id) { Err(GridError::DuplicateId(id)) } else { Ok(()) };
                    prop_assert_eq!(grid.insert(id, aabb), expected);
                    model.entry(id).or_insert(aabb);
                }
                1 => {
                    let expected = model.remove(&id).ok_or(GridError::UnknownId(id));
                    prop_assert_eq!(grid.remove(id), expected);
                }
                2 => {
                    let expected = if model.contains_key(&id) { Ok(()) } else { Err(GridError::UnknownId(id)) };
                    prop_assert_eq!(grid.update(id, aabb), expected);
                    if let Some(slot) = model.get_mut(&id) { *slot = aabb; }
                }
                _ => assert_query_matches(&mut grid, &model, &aabb),
            }
            prop_assert_eq!(grid.len(), model.len());
        }
        for aabb in boxes {
            let shifted = Aabb::new(aabb.min + origin, aabb.max + origin);
            assert_query_matches(&mut grid, &model, &shifted);
        }
        for (&id, aabb) in &model {
            prop_assert_eq!(grid.aabb(id), Some(*aabb));
        }
    }

    #[test]
    fn bulk_and_one_by_one_insertion_give_the_same_answers(
        (origin, objects) in scene(),
        query in lattice_box(Vec3::ZERO),
    ) {
        let config = StaticGridConfig::with_cell_size(suggest_cell_size(objects.iter().map(|o| &o.1)).x);
        let mut bulk = StaticGrid::new(config).unwrap();
        bulk.insert_bulk(&objects).unwrap();
        let mut single = StaticGrid::new(config).unwrap();
        for &(id, aabb) in objects.iter().rev() {
            single.insert(id, aabb).unwrap();
        }
        let query = Aabb::new(query.min + origin, query.max + origin);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let stats_a = bulk.query(&query, &mut a).unwrap();
        let stats_b = single.query(&query, &mut b).unwrap();
        prop_assert_eq!(a, b);
        prop_assert_eq!(stats_a, stats_b);
        prop_assert_eq!(bulk.occupied_cell_count(), single.occupied_cell_count());
    }

    #[test]
    fn the_automatic_cell_fits_most_objects_on_every_axis(
        (_origin, objects) in scene(),
    ) {
        prop_assume!(!objects.is_empty());
        let size = suggest_cell_size(objects.iter().map(|o| &o.1));
        prop_assert!(size.is_finite() && size.cmpgt(Vec3::ZERO).all());
        // Per-axis 90th percentile: at least 90% fit on each axis, so at least 70% on all three
        // (and those touch at most 2 cells per axis).
        let fitting = objects.iter().filter(|(_, aabb)| aabb.extents().cmple(size).all()).count();
        prop_assert!(fitting * 10 >= objects.len() * 7, "{fitting} of {} fit {size}", objects.len());
    }
}

/// A huge query over a sparse scene with tiny cells: answered by scanning, not by visiting
/// the ~10³⁰ cells it touches.
#[test]
fn a_query_covering_the_world_answers_quickly() {
    let objects: Vec<(u32, Aabb)> = (0..50u32)
        .map(|i| {
            let p = Vec3::new(i as f32 * 1.0e4, -(i as f32) * 3.0e3, 1.0e6);
            (i, Aabb::new(p, p + Vec3::splat(0.01)))
        })
        .collect();
    let mut grid = StaticGrid::build(&objects).unwrap();
    let world = Aabb::new(Vec3::splat(-1.0e20), Vec3::splat(1.0e20));
    let mut found = Vec::new();
    let stats = grid.query(&world, &mut found).unwrap();
    assert_eq!(found, (0..50).collect::<Vec<_>>());
    assert_eq!(stats.object_scans, 1);
    assert_eq!(stats.exact_tests, 50);
}
